"""The demo scripts (demos/*.py) write under the repository's results/, whatever the working folder."""
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = sorted(p for p in (ROOT / "demos").glob("*.py")          # the runnable ones that write results
                 if "parse_args(" in p.read_text() and p.name != "cad_models.py")


def _help(script: Path, cwd: Path) -> str:
    env = {**os.environ, "COLUMNS": "1000", "MPLBACKEND": "Agg", "OMP_NUM_THREADS": "1"}
    done = subprocess.run([sys.executable, str(script), "--help"], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_cad_script_says_where_it_writes_and_its_help_writes_nothing(tmp_path):
    """demos/cad_models.py wrote its STEP files on any call, --help included (a user trial)."""
    text = _help(ROOT / "demos" / "cad_models.py", tmp_path)
    assert f"(default: {ROOT / 'demos' / 'cad'}, where the demo scenes read them)" in text
    assert list(tmp_path.iterdir()) == []


def test_every_demo_script_writes_under_the_repositorys_results_by_default(tmp_path):
    """ch1...ch6 and micro_contact wrote to results/<name> of the working folder, brake_squeal_study
    and measured_pin_on_disc to the repository's (an adversarial review): one convention now,
    demos/demo_output.py's, said by --help."""
    assert len(SCRIPTS) == 8, SCRIPTS
    with ThreadPoolExecutor(2) as pool:
        helps = list(pool.map(lambda s: _help(s, tmp_path), SCRIPTS))
    for script, text in zip(SCRIPTS, helps):
        assert f"(default: {ROOT / 'results' / script.stem}, whatever the working folder)" in text, script.name
    assert list(tmp_path.iterdir()) == []
