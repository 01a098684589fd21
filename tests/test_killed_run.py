"""A run killed and resumed writes what the uninterrupted run writes (issues 21 and 22).

A rough pin-on-disc (4 macro steps, fields at every step) is started by ``multiscale run`` in a
subprocess (alone, and under ``mpiexec -n 2``); one process is killed with SIGKILL while it
computes step 3 (after the checkpoint and the fields of step 2), and the run is continued with
``multiscale run --resume``: the history equals that of the uninterrupted run on as many processes
(to the solver tolerance of the recomputed zone laws, as in test_coupling), every field file holds
each output time exactly once, the same times, and nothing printed an HDF5 error. A second test
leaves the field files AHEAD of the checkpoint (the state of a run killed after writing fields but
before its next checkpoint was complete): the resumed run drops those ghost times (they are gone
when it stops again) and writes them again, once; a --resume after the end writes nothing."""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from io import BytesIO
from pathlib import Path

import h5py
import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from test_coupling import POD, resumed_rtol  # noqa: E402

from multiscale.io import History, solver_statistic  # noqa: E402
from multiscale.outputs import plan  # noqa: E402
from multiscale.scene import loads  # noqa: E402

MULTISCALE = Path(sys.executable).with_name("multiscale")
MPIEXEC = Path(sys.executable).with_name("mpiexec")


def scene_text(folder: Path) -> str:
    """test_coupling's rough pin-on-disc with 4 steps of 0.6 s and 3 x 3 zones."""
    text = POD.format(folder=folder)
    for old, new in (('end = "1.2 s"\nsteps = 2', 'end = "2.4 s"\nsteps = 4'), ("zones = [5, 5]", "zones = [3, 3]")):
        assert old in text
        text = text.replace(old, new)
    return text


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    return tmp_path_factory.mktemp("killed")


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


def uninterrupted_run(base: Path, ranks: int) -> Path:
    """The results folder of the scene run without interruption on ``ranks`` processes (1: in this
    process, which saves the subprocess' imports, 4 s)."""
    folder = base / f"straight{ranks}" / "out"
    if not folder.is_dir():
        folder.parent.mkdir(parents=True)
        if ranks == 1:
            from multiscale import workflows
            workflows.run(loads(scene_text(folder)), verbose=False)
            return folder
        path = folder.parent / "scene.toml"
        path.write_text(scene_text(folder))
        done = subprocess.run([str(MPIEXEC), "-n", str(ranks), str(MULTISCALE), "run", str(path), "--quiet"],
                              capture_output=True, text=True, timeout=300, start_new_session=True)
        assert done.returncode == 0, done.stderr
    return folder


def stopped_after_step_1(base: Path) -> Path:
    """The results folder of the scene run in this process to the end of step 1 (``stop_after=1``),
    as that run left it: computed once (kept in ``base``), copied anew into the folder on every call."""
    folder, kept = base / "step1" / "out", base / "step1_kept"
    if not kept.is_dir():
        from multiscale.workflows.multiscale import run
        run(loads(scene_text(folder)), verbose=False, stop_after=1)
        shutil.copytree(folder, kept)
    shutil.rmtree(folder)
    shutil.copytree(kept, folder)
    return folder


def same_results(folder: Path, reference: Path, rtol: float = 1e-6) -> None:
    """History (to ``rtol``) and field times (exactly) of ``folder`` as in ``reference``."""
    scene = loads(scene_text(folder))
    h, r = History.read(folder / "history.h5"), History.read(reference / "history.h5")
    assert set(h.columns) == set(r.columns) and len(h) == len(r) == scene.time.steps + 1
    for key in r.columns:
        if not solver_statistic(key):                # wall times, Newton iteration counts
            # (the coupling residual measured 4.6e-6 relative here)
            np.testing.assert_allclose(h[key], r[key], rtol=resumed_rtol(key, rtol), atol=1e-12, err_msg=key)
    times = field_times(folder)
    assert times == field_times(reference)
    assert all(t == list(plan(scene).times) for t in times.values())   # each time once, exact


def ranks_of(pid: int) -> list[int]:
    """The processes below ``pid`` that run multiscale (the ranks under mpiexec), from /proc."""
    children = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    out, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            todo.append(child)
            try:
                command = (Path("/proc") / str(child) / "cmdline").read_bytes().split(b"\0")
            except OSError:
                continue
            if any(part.endswith(b"multiscale") for part in command) and b"mpiexec" not in command[0]:
                out.append(child)
    return out


def checkpoint_step(ckpt: Path) -> int:
    """The step of the running job's checkpoint (-1: none yet; its fields are written before it);
    read from a copy of the checkpoint's bytes, so that no HDF5 lock is taken on the file the job
    rewrites."""
    try:
        with h5py.File(BytesIO(ckpt.read_bytes()), "r") as f:
            return int(f.attrs["step"])
    except (OSError, KeyError, ValueError):
        return -1


@pytest.mark.parametrize("ranks", [1, 2])
def test_killed_mid_run_and_resumed_writes_the_uninterrupted_results(base, tmp_path, ranks):
    """``ranks`` 2: one rank of ``mpiexec -n 2`` is killed (mpiexec ends the other), the run resumed
    under ``mpiexec -n 2``."""
    folder = tmp_path / "out"
    path = tmp_path / "scene.toml"
    path.write_text(scene_text(folder))
    ckpt = folder / "checkpoint.h5"
    launcher = [str(MPIEXEC), "-n", str(ranks)] if ranks > 1 else []
    job = subprocess.Popen(launcher + [str(MULTISCALE), "run", str(path), "--quiet"], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and job.poll() is None and checkpoint_step(ckpt) < 2:
            time.sleep(0.05)                    # after step 2's checkpoint and fields: computing step 3
        victims = ranks_of(job.pid)[-1:] if ranks > 1 else [job.pid]
        assert victims and job.poll() is None, "the run was to be killed mid-run; it ended"
        os.kill(victims[0], signal.SIGKILL)
        _, err = job.communicate(timeout=60)
    finally:
        if job.poll() is None:
            os.killpg(job.pid, signal.SIGKILL)
    assert job.returncode != 0, err
    with h5py.File(ckpt, "r") as f:
        assert 2 <= int(f.attrs["step"]) < 4 and "finished" not in f.attrs
    record = json.loads((folder / "provenance.json").read_text())       # written when the run began
    assert record["status"] == "running (or killed: no end was recorded)" and "checkpoint.h5" in record["files"]
    assert record["end"] is None
    resumed = subprocess.run(launcher + [str(MULTISCALE), "run", str(path), "--resume", "--quiet"],
                             capture_output=True, text=True, timeout=300, start_new_session=True)
    assert resumed.returncode == 0, resumed.stderr
    assert "HDF5" not in resumed.stderr + resumed.stdout
    # the killed part stays in the record, as it was recorded when it began (before: the resumed part only)
    parts = json.loads((folder / "provenance.json").read_text())["parts"]
    assert [p["status"] for p in parts] == [record["status"], "resumed and finished"]
    assert parts[0] == record["parts"][0] and parts[0]["end"] is None and parts[1]["ranks"] == ranks
    # 2 ranks: MUMPS' parallel factorisation is not bitwise repeatable (two perfect-contact 2-rank
    # runs differ by ~4e-15), and the rough loop's discrete decisions (an iteration more or less near
    # a tolerance) amplify that: 4 uninterrupted 2-rank runs of this scene agreed to 8.6e-7 (heat
    # exchanged per step; 1.2e-5 the coupling residual); 1 rank holds 1e-6 (docs/architecture.md §8, "Repeatability")
    same_results(folder, uninterrupted_run(base, ranks), rtol=1e-6 if ranks == 1 else 1e-5)


def test_field_times_after_the_checkpoint_are_dropped_and_written_once(base, tmp_path):
    from multiscale import provenance, workflows
    from multiscale.workflows.multiscale import run
    folder = stopped_after_step_1(base)                 # run(scene, stop_after=1)
    scene = loads(scene_text(folder))
    early = tmp_path / "checkpoint_step1.h5"
    shutil.copy(folder / "checkpoint.h5", early)
    run(scene, resume=True, verbose=False)              # fields at every time, then the step-1 checkpoint
    shutil.copy(early, folder / "checkpoint.h5")
    assert all(len(t) == 5 for t in field_times(folder).values())
    run(scene, resume=True, verbose=False, stop_after=2)   # the ghosts of steps 3 and 4 are gone
    assert all(t == list(plan(scene).times[:3]) for t in field_times(folder).values())
    # each part as a killed one leaves it, its own (before: the first part's record alone)
    parts = json.loads((folder / "provenance.json").read_text())["parts"]
    assert [(p["status"], p["end"]) for p in parts] == [(provenance.RUNNING, None)] * 3
    result = workflows.run(scene, resume=True, verbose=False)
    statuses = [p["status"] for p in json.loads((folder / "provenance.json").read_text())["parts"]]
    assert statuses == [provenance.RUNNING] * 3 + ["resumed and finished"]
    same_results(folder, uninterrupted_run(base, 1))
    # --resume once more: nothing to do, nothing written, the provenance of the run stays as it was
    before = {f.name: f.read_bytes() for f in folder.iterdir()}
    again = workflows.run(scene, resume=True, verbose=False)
    assert {f.name: f.read_bytes() for f in folder.iterdir()} == before
    assert sorted(f.name for f in again.files) == sorted(f.name for f in result.files) == sorted(plan(scene).files)


def test_a_stop_between_output_times_writes_its_fields_and_a_resume_drops_them(base, monkeypatch):
    """Ctrl-C after step 1 of a run writing fields every 2 steps: ParaView's files hold the state at
    the stop (they held only the output times: a user trial), and the resumed run drops it, ending
    with the field times of an uninterrupted run."""
    from multiscale.errors import Interrupted
    from multiscale.io import StepStop
    from multiscale.workflows.multiscale import run
    folder = base / "every2" / "out"
    scene = loads(scene_text(folder), overrides={"output.every": 2})
    every = list(plan(scene).times)
    assert every == [0.0, 1.2, 2.4]
    with monkeypatch.context() as patch:
        patch.setattr(StepStop, "requested", lambda self: True)
        with pytest.raises(Interrupted, match="after step 1 of 4"):
            run(scene, verbose=False)
    assert all(t == [0.0, 0.6] for t in field_times(folder).values())
    assert run(scene, resume=True, verbose=False).steps_done == 4
    assert all(t == every for t in field_times(folder).values())


def test_a_run_stopped_before_its_first_step_is_not_advised_to_resume(tmp_path, capsys, monkeypatch):
    """Ctrl-C before the first macro step ended (no checkpoint) advises running again, not --resume;
    a --resume there says why and leaves the folder as it was. Before: 'multiscale run --resume
    continues', which then wrote a failed provenance and the scene copies into the empty folder,
    so that the plain run was refused for those 3 entries (adversarial test)."""
    from multiscale import workflows
    from multiscale.cli import main
    from multiscale.errors import InputError
    folder = tmp_path / "out"
    path = tmp_path / "scene.toml"
    path.write_text(scene_text(folder))
    folder.mkdir()                                    # as the interrupted run left it: empty
    with pytest.raises(InputError, match="no checkpoint.h5 in the output folder to resume from"):
        workflows.run(loads(path.read_text()), resume=True, verbose=False)
    assert list(folder.iterdir()) == []

    def interrupted(scene, **kw):
        raise KeyboardInterrupt
    monkeypatch.setattr(workflows, "run", interrupted)
    assert main(["run", str(path)]) == 130
    err = capsys.readouterr().err
    assert "no macro step ended, there is nothing to resume" in err and "--resume" not in err
    assert f"multiscale run {path} starts again" in err               # the folder is empty: a plain run
    (folder / "provenance.json").write_text("{}")    # an interrupted run's record: the plain run is refused
    assert main(["run", str(path)]) == 130
    assert f"multiscale run {path} --overwrite starts again" in capsys.readouterr().err     # (a user trial)
    monkeypatch.chdir(tmp_path)
    assert main(["run", "scene.toml"]) == 130
    assert f"multiscale run {path} --overwrite starts again" in capsys.readouterr().err     # from any folder
    # --overwrite stopped before it replaced a finished run's results: they stay, no --resume advised
    (folder / "provenance.json").write_text('{"status": "finished"}')     # (it said "--resume continues", which
    (folder / "checkpoint.h5").write_bytes(b"")                           # then had nothing to do: an MPI trial)
    assert main(["run", "scene.toml", "--overwrite"]) == 130
    err = capsys.readouterr().err
    assert f"the earlier results in {folder} stay as they were; " in err and "--resume" not in err
    assert main(["run", "scene.toml"]) == 130 and "--resume continues" in capsys.readouterr().err   # without it


def test_a_damaged_field_file_says_how_to_resume(base):
    """A field file cut short (a run killed while writing it) is named with the way on: delete it to
    resume without its fields, which then start at the next output time (before: only HDF5's
    'truncated file: eof = ...' after 'cannot write the field files'; adversarial test)."""
    from multiscale import workflows
    from multiscale.errors import OutputError
    folder = stopped_after_step_1(base)                 # run(scene, stop_after=1)
    scene = loads(scene_text(folder))
    size = (folder / "pin.h5").stat().st_size
    with open(folder / "pin.h5", "r+b") as f:
        f.truncate(size // 2)
    with pytest.raises(OutputError, match=r"pin.h5 is damaged \(.*truncated.*\): delete it and pin.xdmf to resume"):
        workflows.run(scene, resume=True, verbose=False)
    for name in ("pin.h5", "pin.xdmf"):
        (folder / name).unlink()
    assert workflows.run(scene, resume=True, verbose=False).steps_done == 4
    times = field_times(folder)
    assert times["pin.xdmf"] == list(plan(scene).times[2:]) and times["disc.xdmf"] == list(plan(scene).times)


def test_a_resumed_run_says_the_heat_warnings_of_the_whole_run_once(tmp_path, monkeypatch):
    """The first heat step that needed the backtracking line search is said once per run
    (``Thermal.notes``; test_macro_thermal.py): a run stopped after step 2 (Ctrl-C) and resumed says
    the one of step 1, as the run straight through does, once, in its warnings and its provenance;
    the stopped run's provenance says it too. The pin radiates (a Newton heat step), and its full
    Newton steps are said to fail at steps 1 and 3. Before: the resumed run lost step 1's note and
    said step 3's as the first ("t = 1.8 s"); the stopped run's provenance said nothing.
    The resumed run's provenance keeps the stopped part (command, ranks, start, end, status, its
    stages: the zone laws) beside its own, and its times are the sums (before: the resumed part's only)."""
    from multiscale import io, workflows
    from multiscale.macro import thermal
    radiating = '[[boundary]]\nsurfaces = ["free:pin"]\nemissivity = 0.5\nambient = "20 degC"\n[output]'
    solve = thermal.Thermal._solve

    def full_steps_said_to_fail(th):
        ok = solve(th)
        step = round((th.time + float(th.dt.value)) / 0.6)          # the macro step solved, of 0.6 s
        return ok and not (step in (1, 3) and th.problem.solver.getLineSearch().getType() != "bt")
    monkeypatch.setattr(thermal.Thermal, "_solve", full_steps_said_to_fail)
    said = {}
    for how in ("straight", "stopped"):
        folder = tmp_path / how / "out"
        scene = loads(scene_text(folder).replace("[output]", radiating))
        if how == "stopped":
            asked = iter([False, True])                                 # Ctrl-C during step 2
            with monkeypatch.context() as m:
                m.setattr(io.StepStop, "requested", lambda self: next(asked))
                with pytest.raises(KeyboardInterrupt, match="after step 2 of 4"):
                    workflows.run(scene, verbose=False)
            stopped = json.loads((folder / "provenance.json").read_text())
            said["interrupted"] = stopped["warnings"]
        result = workflows.run(scene, resume=how == "stopped", verbose=False)
        record = json.loads((folder / "provenance.json").read_text())
        said[how] = ([w for w in result.warnings if "too long for full Newton steps" in w], record["warnings"])
    first, last = record["parts"]
    assert first == stopped["parts"][0] and first["status"] == "interrupted after step 2 of 4"
    assert "zone laws and first solve" in first["stage_wall_time_s"] and first["end"] is not None
    assert last["status"] == record["status"] == "resumed and finished" and last["ranks"] == record["ranks"] == 1
    assert "restoring the checkpoint" in last["stage_wall_time_s"] and (record["start"], record["end"]) == (
        first["start"], last["end"])
    assert first["code"] == last["code"] == record["code"]["sha1"]     # each part's code (one record's hash:
    #                                                                    a resume after a change hid it; a user trial)
    assert record["total_wall_time_s"] == pytest.approx(first["total_wall_time_s"] + last["total_wall_time_s"],
                                                        abs=2e-3)
    for stage, seconds in record["stage_wall_time_s"].items():
        assert seconds == pytest.approx(sum(p["stage_wall_time_s"].get(stage, 0.0) for p in (first, last)), abs=2e-3)
    notes, provenance = said["straight"]
    assert len(notes) == 1 and notes[0].startswith("the heat step to t = 0.6 s was too long") and notes[0] in provenance
    assert said["stopped"] == said["straight"]
    assert [w for w in said["interrupted"] if "too long for full Newton steps" in w] == notes


def test_a_stopped_squeal_analysis_lists_only_the_files_it_wrote(tmp_path, monkeypatch):
    """A squeal analysis stopped in its eigen solve keeps the preload's fields; its record listed the
    mode files, figures and script it never wrote as well (a user audit: 16 files listed, 10 there)."""
    from multiscale import io, outputs, workflows
    from multiscale.workflows import squeal
    folder = tmp_path / "out"
    scene = loads((Path(__file__).resolve().parents[1] / "demos" / "brake_squeal.toml").read_text().replace(
        'folder = "../results/brake_squeal"', f'folder = "{folder}"'))
    preload = outputs.plan(scene).field_files

    def stopped_in_the_eigen_solve(scene, **kw):
        io.reporter().folder = folder
        folder.mkdir(exist_ok=True)
        for name in preload:
            (folder / name).write_text("")
        raise KeyboardInterrupt("eigen solve: stopped after 1.5 s")
    monkeypatch.setattr(squeal, "run", stopped_in_the_eigen_solve)
    with pytest.raises(KeyboardInterrupt):
        workflows.run(scene, verbose=False)
    record = json.loads((folder / "provenance.json").read_text())
    assert record["status"].startswith("interrupted") and "modes.csv" in outputs.plan(scene).files
    assert sorted(record["files"]) == sorted(p.name for p in folder.iterdir()) == sorted(
        [*preload, "provenance.json", "scene.toml", "scene_resolved.toml"])


def test_a_ctrl_c_inside_a_petsc_solve_and_a_full_disk_keep_their_own_words(tmp_path, capsys, monkeypatch):
    """A third Ctrl-C met inside a PETSc solve comes out as PETSc's error 101 around it: the run's
    status was PETSc's stack ("interrupted error code 101 [0] SNESSolve() ..."), not the step
    abandoned; the Ctrl-C itself is raised on. A full disk that also stops the failed run's record
    from being written gave that OSError's traceback instead of the run's own error: the error stays,
    and a warning says the record is missing (both found by a user trial)."""
    from multiscale import errors, io, provenance, workflows
    from multiscale.workflows import transient
    folder = tmp_path / "out"
    scene = loads((Path(__file__).resolve().parents[1] / "demos" / "block_on_flat.toml").read_text().replace(
        'folder = "../results/block_on_flat"', f'folder = "{folder}"'))
    step = "during step 3, abandoned: the results of step 2 are the last written"

    def ctrl_c_in_petsc(scene, **kw):
        io.reporter().folder = folder
        folder.mkdir(exist_ok=True)
        try:
            raise KeyboardInterrupt(step)
        except KeyboardInterrupt as inner:
            raise RuntimeError("error code 101\n[0] SNESSolve() at snes.c:4951") from inner
    monkeypatch.setattr(transient, "run", ctrl_c_in_petsc)
    with pytest.raises(KeyboardInterrupt, match=step):
        workflows.run(scene, verbose=False)
    assert json.loads((folder / "provenance.json").read_text())["status"] == f"interrupted {step}"

    def full_disk(scene, **kw):
        io.reporter().folder = folder
        raise errors.OutputError("cannot write the fields at t = 0 s: No space left on device")

    def no_space(*args, **kwargs):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(transient, "run", full_disk)
    monkeypatch.setattr(provenance, "write", no_space)
    with pytest.raises(errors.OutputError, match="cannot write the fields"):
        workflows.run(scene, verbose=False)
    assert "warning: the record of this run was not written ([Errno 28] No space left on device)" in \
        capsys.readouterr().err
