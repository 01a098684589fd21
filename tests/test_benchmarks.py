"""The benchmark scripts stay runnable: each one imports what it uses and answers ``--help``
(bench_heating imported a helper another script had dropped and did not run for days)."""
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCRIPTS = sorted(p.name for p in (ROOT / "benchmarks").glob("*.py") if p.name != "timing.py")
PEERS = ("tamaas", "ContactMechanics", "contactmechanics")   # the bench extra: not in every environment


@pytest.mark.parametrize("script", SCRIPTS)
def test_benchmark_script_imports_and_answers_help(script):
    done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), "--help"], capture_output=True,
                          text=True, timeout=120, cwd=ROOT)
    if done.returncode != 0 and any(f"No module named '{peer}" in done.stderr for peer in PEERS):
        pytest.skip(f"{script} needs the bench extra")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "usage:" in done.stdout
