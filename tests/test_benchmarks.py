"""The benchmark scripts stay runnable: each one imports what it uses and answers ``--help``
(bench_heating imported a helper another script had dropped and did not run for days). They run
one after another in one subprocess, each as ``python SCRIPT --help`` would (a process each took
about 3 s of imports: 28 s for the 16 scripts)."""
import json
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCRIPTS = sorted(p.name for p in (ROOT / "benchmarks").glob("*.py") if p.name != "timing.py")
PEERS = ("tamaas", "ContactMechanics", "contactmechanics")   # the bench extra: not in every environment
# {script: [exit code, stdout, stderr]} of each script run with --help, as JSON on the last line
HELP = """
import contextlib, io, json, runpy, sys, traceback
import h5py  # noqa: F401  (first, as tests/conftest.py: see multiscale/macro/__init__.py)
folder, out = sys.argv[1], {}
sys.path.insert(0, folder)                 # as for `python folder/script.py`
for name in sys.argv[2:]:
    sys.argv, stdout, stderr = [f"{folder}/{name}", "--help"], io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        try:
            runpy.run_path(sys.argv[0], run_name="__main__")
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
        except BaseException:
            traceback.print_exc()
            code = 1
    out[name] = [code, stdout.getvalue(), stderr.getvalue()]
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def answers() -> dict:
    done = subprocess.run([sys.executable, "-c", HELP, str(ROOT / "benchmarks"), *SCRIPTS], capture_output=True,
                          text=True, timeout=300, cwd=ROOT)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.splitlines()[-1])


@pytest.mark.parametrize("script", SCRIPTS)
def test_benchmark_script_imports_and_answers_help(answers, script):
    code, out, err = answers[script]
    if code != 0 and any(f"No module named '{peer}" in err for peer in PEERS):
        pytest.skip(f"{script} needs the bench extra")
    assert code == 0, err[-2000:]
    assert "usage:" in out
