"""A run killed and resumed writes what the uninterrupted run writes (issues 21 and 22).

A rough pin-on-disc (4 macro steps, fields at every step) is run once uninterrupted. The same scene
is started by ``multiscale run`` in a subprocess, killed with SIGKILL while it computes step 3
(after the checkpoint and the fields of step 2), and continued with ``multiscale run --resume``:
the history equals the uninterrupted one (to the solver tolerance of the recomputed zone laws, as
in test_coupling), every field file holds each output time exactly once, the same times, and
nothing printed an HDF5 error. A second test leaves the field files AHEAD of the checkpoint (the
state of a run killed after writing fields but before its next checkpoint was complete): the
resumed run drops those ghost times (they are gone when it stops again) and writes them again, once."""
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from test_coupling import POD  # noqa: E402

from multiscale.io import History  # noqa: E402
from multiscale.outputs import plan  # noqa: E402
from multiscale.scene import loads  # noqa: E402

MULTISCALE = Path(sys.executable).with_name("multiscale")


def scene_text(folder: Path) -> str:
    """test_coupling's rough pin-on-disc with 4 steps of 0.6 s and 3 x 3 zones."""
    text = POD.format(folder=folder)
    for old, new in (('end = "1.2 s"\nsteps = 2', 'end = "2.4 s"\nsteps = 4'), ("zones = [5, 5]", "zones = [3, 3]")):
        assert old in text
        text = text.replace(old, new)
    return text


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    from multiscale.workflows import run
    folder = tmp_path_factory.mktemp("straight") / "out"
    scene = loads(scene_text(folder))
    assert scene.time.steps == 4 and scene.output.every == 1
    return scene, run(scene, verbose=False)


def field_times(folder: Path) -> dict:
    """{field file: its times, from the .h5 and from the .xdmf index} of a results folder."""
    out = {}
    for xdmf in sorted(folder.glob("*.xdmf")):
        with h5py.File(xdmf.with_suffix(".h5"), "r") as f:
            times = list(f["times"][...])
            assert sorted(f["data"], key=int) == [str(k) for k in range(len(times))], xdmf.name
        shown = [float(t.split('"')[1]) for t in xdmf.read_text().split("<Time Value=")[1:]]
        assert shown == times, xdmf.name
        out[xdmf.name] = times
    return out


def same_results(folder: Path, reference) -> None:
    scene, ref = reference
    h, r = History.read(folder / "history.h5"), ref.history
    assert set(h.columns) == set(r.columns) and len(h) == len(r) == scene.time.steps + 1
    for key in r.columns:
        if not key.startswith("time_"):                # wall times differ
            np.testing.assert_allclose(h[key], r[key], rtol=1e-6, atol=1e-12, err_msg=key)
    times = field_times(folder)
    assert times == field_times(ref.folder)
    assert all(t == list(plan(scene).times) for t in times.values())   # each time once, exact


def test_killed_mid_run_and_resumed_writes_the_uninterrupted_results(uninterrupted, tmp_path):
    folder = tmp_path / "out"
    path = tmp_path / "scene.toml"
    path.write_text(scene_text(folder))
    ckpt = folder / "checkpoint.h5"
    job = subprocess.Popen([str(MULTISCALE), "run", str(path), "--quiet"], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and job.poll() is None:
            try:                                    # the checkpoint is replaced atomically
                with h5py.File(ckpt, "r") as f:
                    if int(f.attrs["fields_written"]) >= 2:     # step 2 done: now computing step 3
                        break
            except (OSError, KeyError):
                pass
            time.sleep(0.05)
        job.send_signal(signal.SIGKILL)
        _, err = job.communicate(timeout=60)
    finally:
        job.kill()
    assert job.returncode == -signal.SIGKILL, f"the run was to be killed mid-run; it ended: {err}"
    with h5py.File(ckpt, "r") as f:
        assert 2 <= int(f.attrs["step"]) < 4 and "finished" not in f.attrs
    resumed = subprocess.run([str(MULTISCALE), "run", str(path), "--resume", "--quiet"], capture_output=True,
                             text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    assert "HDF5" not in resumed.stderr + resumed.stdout
    same_results(folder, uninterrupted)


def test_field_times_after_the_checkpoint_are_dropped_and_written_once(uninterrupted, tmp_path):
    from multiscale.workflows.multiscale import run
    folder = tmp_path / "out"
    scene = loads(scene_text(folder))
    run(scene, verbose=False, stop_after=1)
    early = tmp_path / "checkpoint_step1.h5"
    shutil.copy(folder / "checkpoint.h5", early)
    run(scene, resume=True, verbose=False)              # fields at every time, then the step-1 checkpoint
    shutil.copy(early, folder / "checkpoint.h5")
    assert all(len(t) == 5 for t in field_times(folder).values())
    run(scene, resume=True, verbose=False, stop_after=2)   # the ghosts of steps 3 and 4 are gone
    assert all(t == list(plan(scene).times[:3]) for t in field_times(folder).values())
    run(scene, resume=True, verbose=False)
    same_results(folder, uninterrupted)
