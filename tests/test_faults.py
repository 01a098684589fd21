"""Faults that used to hang a parallel job (issue 21): an error met by one rank only, and a NaN on
one rank. Each runs ``multiscale run`` under ``mpiexec -n 2`` in a subprocess and asserts that the
job ends within seconds, with one clear message and a non-zero exit code."""
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from test_macro_run import BLOCK  # noqa: E402

MPIEXEC = Path(sys.executable).with_name("mpiexec")
COMMAND = Path(sys.executable).with_name("multiscale")
# test_macro_run's block, cooling 3 s from a hot top face
SCENE = (BLOCK.replace("{effects}", '"contact", "thermal"').replace('name = "block"', 'name = "cooling_block"')
         .replace('mesh_size = "2.5 mm"', 'mesh_size = "5 mm"')
         .replace('end = "1 s"\n', 'end = "3 s"\nsteps = 3\n[[boundary]]\nsurfaces = ["block_top"]\n'
                  'temperature = "80 degC"\n'))
# the fault, injected on rank 1 only at the second heat step, then the ordinary CLI run
DRIVER = """
import sys
from mpi4py import MPI
from multiscale.cli import main
from multiscale.errors import ConvergenceError
from multiscale.macro import thermal
step, calls = thermal.Thermal.step, []

def faulty(self, dt):
    calls.append(dt)
    if MPI.COMM_WORLD.rank == 1 and len(calls) == 2:
        if sys.argv[2] == "raise":
            raise ConvergenceError("injected failure on rank 1")
        self.T[0].x.array[:] = float("nan")           # a NaN in this rank's temperatures only
    return step(self, dt)

thermal.Thermal.step = faulty
sys.exit(main(["run", sys.argv[1], "--overwrite"]))
"""


def run_faulty(tmp_path, mode):
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.format(folder=tmp_path / "out"))
    driver = tmp_path / "driver.py"
    driver.write_text(DRIVER)
    start = time.monotonic()
    done = subprocess.run([str(MPIEXEC), "-n", "2", sys.executable, str(driver), str(scene), mode],
                          capture_output=True, text=True, timeout=300, start_new_session=True)
    return done, time.monotonic() - start


def test_an_error_on_one_rank_ends_the_job(tmp_path):
    """Rank 1 raises while rank 0 goes on into the next collective: rank 1 says so and aborts."""
    done, seconds = run_faulty(tmp_path, "raise")
    assert done.returncode != 0 and seconds < 120
    assert done.stderr.count("injected failure on rank 1") == 1
    assert "error (rank 1 of 2)" in done.stderr


def test_a_nan_on_one_rank_fails_on_every_rank_with_one_message(tmp_path):
    """The finiteness of a heat step is decided by every rank together: both raise, rank 0 prints
    one line, the job exits with code 2 (no abort needed)."""
    done, seconds = run_faulty(tmp_path, "nan")
    assert done.returncode == 2 and seconds < 120, done.stderr[-2000:]
    errors = [line for line in done.stderr.splitlines() if line.startswith("error")]
    assert len(errors) == 1 and "heat step at t = 2 s failed" in errors[0]


# ---------------------------------------------------------------- checkpoints and full disks
@pytest.fixture(scope="module")
def stopped(tmp_path_factory):
    """A rough pin-on-disc run stopped after its first step: the checkpoint to resume from."""
    from test_coupling import POD

    from multiscale.scene import loads
    from multiscale.workflows.multiscale import run
    folder = tmp_path_factory.mktemp("stopped") / "out"
    scene = loads(POD.format(folder=folder))
    run(scene, verbose=False, stop_after=1)
    return scene, folder / "checkpoint.h5"


def flipped_data(path) -> bytes:
    """The file's bytes with those of its largest dataset flipped: the HDF5 structure intact, its
    data not (the file's last 4096 bytes held data once, HDF5 metadata since the attributes moved)."""
    import h5py
    sets = []
    with h5py.File(path) as h5:
        h5.visititems(lambda name, item: sets.append((item.id.get_storage_size(), item.id.get_offset()))
                      if isinstance(item, h5py.Dataset) else None)
    size, offset = max(sets)
    b = bytearray(path.read_bytes())
    b[offset:offset + size] = bytes(x ^ 0x5A for x in b[offset:offset + size])
    return bytes(b)


@pytest.mark.parametrize("damage, message", [
    (lambda p: p.read_bytes()[: p.stat().st_size // 2], "cannot be read"),   # truncated
    (lambda p: b"", "cannot be read"),                                      # empty
    (flipped_data, "corrupted"),                                            # damaged data
])
def test_a_damaged_checkpoint_is_one_clear_error(stopped, tmp_path, damage, message):
    import shutil

    from multiscale.errors import InputError
    from multiscale.workflows.multiscale import run
    scene, checkpoint = stopped
    folder = tmp_path / "copy"
    shutil.copytree(checkpoint.parent, folder)
    path = folder / "checkpoint.h5"
    path.write_bytes(damage(path))
    with pytest.raises(InputError, match=message):
        run(_with_folder(scene, folder), resume=True, verbose=False)


def test_a_checkpoint_of_another_format_is_one_clear_error(stopped, tmp_path):
    """A checkpoint written before ``checkpoint.FORMAT`` 2 (P1 disc temperatures, no
    min_temperature columns) would resume into "the mesh changed" or a KeyError at the first row
    (found in review); it is refused naming its format."""
    import shutil

    import h5py

    from multiscale.errors import InputError
    from multiscale.workflows.multiscale import run
    scene, checkpoint = stopped
    folder = tmp_path / "copy"
    shutil.copytree(checkpoint.parent, folder)
    with h5py.File(folder / "checkpoint.h5", "a") as h5:
        del h5.attrs["format"]                                  # as written before the format existed
    from multiscale.checkpoint import FORMAT
    with pytest.raises(InputError, match=r"written by another version of multiscale \(checkpoint format 1, this "
                                         rf"one reads {FORMAT}\); start again with --overwrite"):
        run(_with_folder(scene, folder), resume=True, verbose=False)


def _with_folder(scene, folder):
    import dataclasses
    return dataclasses.replace(scene, output=dataclasses.replace(scene.output, folder=folder))


def test_a_full_disk_keeps_the_previous_checkpoint(stopped, tmp_path, monkeypatch):
    """No space left while the next checkpoint is written (simulated ENOSPC at its rename): an
    OutputError naming the file and the cause; the step's previous checkpoint is intact."""
    import errno
    import os
    import shutil

    from multiscale.errors import OutputError
    from multiscale.workflows.multiscale import run
    scene, checkpoint = stopped
    folder = tmp_path / "copy"
    shutil.copytree(checkpoint.parent, folder)
    before = (folder / "checkpoint.h5").read_bytes()

    replace = os.replace

    def full(src, dst, *args, **kw):         # the checkpoint's rename (the resumed part's provenance is written before)
        if os.path.basename(dst) == "checkpoint.h5":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return replace(src, dst, *args, **kw)
    monkeypatch.setattr(os, "replace", full)
    with pytest.raises(OutputError, match="cannot write the checkpoint .*No space left on device"):
        run(_with_folder(scene, folder), resume=True, verbose=False)
    assert (folder / "checkpoint.h5").read_bytes() == before
    assert not (folder / "checkpoint.h5.part").exists()


def test_a_read_only_output_folder_is_one_clear_error(tmp_path, monkeypatch):
    """A folder the run cannot write into (simulated: root may write anywhere) is an OutputError
    before any work."""
    import errno
    import os
    from pathlib import Path

    from multiscale.errors import OutputError
    from multiscale.scene import loads
    from multiscale.workflows import run
    write_bytes = Path.write_bytes

    def read_only(self, data):
        if "locked" in str(self):
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(self))
        return write_bytes(self, data)
    monkeypatch.setattr(Path, "write_bytes", read_only)
    scene = loads(SCENE.format(folder=tmp_path / "locked"))
    with pytest.raises(OutputError, match="cannot write into the output folder .*Permission denied"):
        run(scene, verbose=False)


def test_a_full_disk_at_the_history_is_one_clear_error(tmp_path, monkeypatch):
    """The history (rank 0 writes it) on a full disk: an OutputError naming the file and the cause
    (collective: on 2 ranks the other rank raises it too, through io.on_root)."""
    import errno
    import os

    from multiscale import io
    from multiscale.errors import OutputError
    from multiscale.scene import loads
    from multiscale.workflows import run

    def full(self, path, attrs=None):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(io.History, "write", full)
    with pytest.raises(OutputError, match="cannot write the history .*history.h5: No space left on device"):
        run(loads(SCENE.format(folder=tmp_path / "out")), verbose=False)



def test_a_factorisation_package_petsc_lacks_ends_both_ranks_with_one_input_error(tmp_path):
    """``PETSC_OPTIONS="-heat_pc_factor_mat_solver_type superlu"`` (a package this PETSc lacks,
    ``kept_cells.check_user_options``) for ``multiscale run`` under mpiexec -n 2: every rank meets
    the InputError building the model, so the job ends within the timeout, exit code 2, with the
    one line of rank 0 (not a rank's own "error (rank k of 2)" and an abort) and no PETSc error."""
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.format(folder=tmp_path / "out"))
    command = [str(MPIEXEC), "-n", "2", str(Path(sys.executable).with_name("multiscale")), "run", str(scene)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120, start_new_session=True,
                          env={**os.environ, "PETSC_OPTIONS": "-heat_pc_factor_mat_solver_type superlu"})
    lines = [line for line in done.stderr.splitlines() if line.startswith("error")]
    assert done.returncode == 2 and len(lines) == 1, done.stderr[-3000:]
    assert re.fullmatch(r"error: PETSC_OPTIONS = '-heat_pc_factor_mat_solver_type superlu': this PETSc cannot "
                        r"factorise \(pc_type lu\) .*; it has .*mumps.* for this factorisation on 2 ranks", lines[0])
    assert "PETSC ERROR" not in done.stderr and "Traceback" not in done.stderr, done.stderr[-3000:]


# ---------------------------------------------------------------- Ctrl-C
def interrupt(tmp_path, ranks: int, sent_signal: str = "SIGINT"):
    """``multiscale run`` of the cooling block in 4000 heat steps, sent SIGINT (Ctrl-C; under
    mpiexec to the launcher, which hands it to every rank), or ``sent_signal``, once the steps have
    begun."""
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.format(folder=tmp_path / "out").replace("steps = 3\n", "steps = 4000\n")
                     .replace("[output]\n", "[output]\nevery = 1000\n"))
    command = [str(Path(sys.executable).with_name("multiscale")), "run", str(scene)]
    command = [str(MPIEXEC), "-n", str(ranks), *command] if ranks > 1 else command
    job = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           start_new_session=True)
    for line in job.stdout:                 # stage lines; the macro steps' bar comes after these
        if line.startswith(("first contact solve", "model set-up")):
            break
    time.sleep(1.0)
    sent = time.monotonic()
    job.send_signal(getattr(signal, sent_signal))
    try:
        out, err = job.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(job.pid, signal.SIGKILL)
        raise
    return job.returncode, err, time.monotonic() - sent, tmp_path / "out"


@pytest.mark.parametrize("ranks, sent_signal", [(1, "SIGINT"), (2, "SIGINT"), (1, "SIGTERM")])
def test_ctrl_c_stops_the_run_after_its_step_with_the_results_written(tmp_path, ranks, sent_signal):
    """Ctrl-C during the steps: every rank stops after the same step, the history, its plot, the
    fields of that step and open_in_paraview.py are written, and the job ends with exit code 130 and one
    line saying where the results are (before: a Python traceback per rank, or PETSc's "error code
    101" when the signal came inside a Newton callback, and no plot); provenance.json says so.
    SIGTERM (a batch scheduler's time limit) does the same: it killed the run, its provenance left
    "running" and no plot (a user trial)."""
    import json

    from multiscale.io import History
    code, err, seconds, folder = interrupt(tmp_path, ranks, sent_signal)
    assert code == 130 and seconds < 30, err[-3000:]
    assert "Traceback" not in err and "PETSC ERROR" not in err and "error code" not in err, err[-3000:]
    assert err.count(f"{'Ctrl-C' if sent_signal == 'SIGINT' else sent_signal}: stopping after this step") == 1
    if sent_signal == "SIGTERM":          # (it said "Ctrl-C twice more abandons the step")
        assert "(SIGTERM twice more abandons the step)" in err
    record = json.loads((folder / "provenance.json").read_text())
    done = int(record["status"].split()[3])
    assert record["status"] == f"interrupted after step {done} of 4000" and 1 <= done < 4000
    lines = [line for line in err.splitlines() if line.startswith("interrupted")]
    launcher = f"{MPIEXEC} -n {ranks} " if ranks > 1 else ""         # the command goes on as it ran (a user trial)
    assert lines == [f"interrupted after step {done} of 4000: what was written stays in {folder} (its "
                     f"provenance.json says so); {launcher}{COMMAND} run {tmp_path / 'scene.toml'} --resume "
                     "continues from the last finished step"]        # (a thermal run had to start again: a trial)
    import h5py
    with h5py.File(folder / "checkpoint.h5") as h5:                  # what --resume continues from
        assert h5.attrs["step"] == done
    assert len(History.read(folder / "history.h5")) == done + 1
    assert (folder / "history.png").stat().st_size > 0 and (folder / "open_in_paraview.py").exists()
    import meshio
    with meshio.xdmf.TimeSeriesReader(str(folder / "block.xdmf")) as reader:
        reader.read_points_cells()
        assert reader.read_data(reader.num_steps - 1)[0] == pytest.approx(done * 3 / 4000)   # the stop's fields


def test_ctrl_c_while_the_end_is_written_lets_it_finish(tmp_path, monkeypatch, capfd):
    """Ctrl-C after the last step, while the history and plots are written: the writing finishes
    and the run ends as finished (before: a KeyboardInterrupt inside the writing, MPI_Abort under
    mpiexec, provenance "interrupted" without a step; an adversarial docs audit), and the console
    says so (it said "stopping after this step": a user trial). Ctrl-C during the last step
    finishes the run too (it ended "interrupted after step 3 of 3", exit 130)."""
    import json

    from multiscale.io import History
    from multiscale.scene import loads
    from multiscale.workflows import run, transient
    written = transient.write_history

    titles = []

    def interrupted_write(history, folder, name, comm, plot=True, title=None):
        if plot:                                     # the final write, after the steps
            titles.append(title)
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)
        return written(history, folder, name, comm, plot=plot, title=title)
    monkeypatch.setattr(transient, "write_history", interrupted_write)
    result = run(loads(SCENE.format(folder=tmp_path / "out")), verbose=False)
    folder = tmp_path / "out"
    assert json.loads((folder / "provenance.json").read_text())["status"] == "finished"
    assert len(History.read(folder / "history.h5")) == 4 and (folder / "history.png").stat().st_size > 0
    assert result.history_file == folder / "history.h5" and titles == ["cooling_block"]
    err = capfd.readouterr().err
    assert "Ctrl-C: the steps are done; held until their results are written" in err and "stopping" not in err
    from multiscale.io import StepStop
    from multiscale.macro.model import MacroModel as Model
    step = Model.macro_step

    def last_step_interrupted(self, *args):
        if self.time > 1.5:                          # the third and last step (end 3 s)
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)
        return step(self, *args)
    monkeypatch.setattr(Model, "macro_step", last_step_interrupted)
    result = run(loads(SCENE.format(folder=tmp_path / "last")), overwrite=True, verbose=False)
    assert json.loads((tmp_path / "last" / "provenance.json").read_text())["status"] == "finished"
    assert len(result.history) == 4 and "stopping after this step" in capfd.readouterr().err
    monkeypatch.setattr(Model, "macro_step", step)
    # stopped during the steps (after the first): the figure's title says so (it said nothing: a user trial)
    from multiscale.errors import Interrupted
    monkeypatch.setattr(transient, "write_history", lambda *a, **k: titles.append(k.get("title")) or written(*a, **k))
    monkeypatch.setattr(StepStop, "requested", lambda self: True)
    with pytest.raises(Interrupted, match="after step 1 of 3"):
        run(loads(SCENE.format(folder=tmp_path / "stopped")), verbose=False)
    assert titles[-1] == "cooling_block (stopped after step 1 of 3)"


@pytest.fixture
def python_sigint():
    """SIGINT taken by Python's handler during the test, as in a job started in the foreground (one
    started with ``&`` ignores it, and ``CtrlCWatch`` leaves an ignored SIGINT alone); put back after."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_a_second_ctrl_c_is_held_and_a_third_abandons_the_step_but_not_a_write(python_sigint):
    """StepStop: the first SIGINT is a request (collective ``requested()``), the second is held
    (the step ends with its results written), a third abandons the step in progress, naming the last
    step written, except inside ``writing()``, which it lets finish (before: the second raised
    wherever it came, inside the writing of a step's results too)."""

    from mpi4py import MPI

    from multiscale.io import StepStop

    def ctrl_c():
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)
    with StepStop(MPI.COMM_SELF) as stop:
        assert not stop.requested()
        ctrl_c()
        assert stop.requested()
        ctrl_c()                                  # held
        with stop.writing(5):
            ctrl_c()                              # held: the results of step 5 are being written
        with pytest.raises(KeyboardInterrupt, match="during step 6, abandoned: the results of step 5 are the last "
                                                    "written"):
            ctrl_c()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler      # restored


def test_a_second_sigterm_is_named_as_itself(capfd):
    """The second SIGTERM said "Ctrl-C: still finishing the step ...; Ctrl-C again abandons the step"
    (an MPI trial): each line names the signal that came."""
    from mpi4py import MPI

    from multiscale.io import StepStop
    with StepStop(MPI.COMM_SELF) as stop:
        for _ in range(2):
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.01)
        assert stop.requested()
    err = capfd.readouterr().err
    assert "SIGTERM: stopping after this step" in err and "SIGTERM again abandons the step" in err
    assert "Ctrl-C" not in err


def test_the_watcher_leaves_a_ctrl_c_a_step_stop_took_even_when_it_reads_it_late(monkeypatch, python_sigint):
    """``CtrlCWatch`` reads a SIGINT's wake-up byte when its thread runs, maybe after the
    ``StepStop`` that took the signal put the default handler back: it then took the signal for
    one the main thread never met and aborted the run while its end was written (1 in 6 quick
    multi-Ctrl-C tries: provenance.json left "running", no open_in_paraview.py). The byte is fed here by
    hand after the StepStop ended: left alone; a further SIGINT nobody took still ends the job."""
    import threading

    from mpi4py import MPI

    from multiscale import io

    aborted = []
    monkeypatch.setattr(io, "abort", lambda comm, code, **kw: aborted.append(code))
    watch = io.CtrlCWatch(MPI.COMM_SELF, lambda: "interrupted: test", 130)
    watch.WAIT = 0.2
    read, write = os.pipe()
    watcher = threading.Thread(target=watch._watch, args=(read,), daemon=True)
    watcher.start()
    with io.StepStop(MPI.COMM_SELF) as stop:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)
        assert stop.asked
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    os.write(write, bytes([signal.SIGINT]))           # the StepStop's signal, read late
    time.sleep(0.6)
    assert aborted == []
    os.write(write, bytes([signal.SIGINT]))           # one the main thread never meets
    time.sleep(0.6)
    assert aborted == [130]
    os.close(write)
    watcher.join(5)
    assert not watcher.is_alive()


@pytest.mark.parametrize("kind", ["transient", "multiscale"])
def test_an_abandoned_step_leaves_the_plots_and_paraview_script_of_what_was_written(tmp_path, monkeypatch, kind):
    """Three Ctrl-C during step 2 abandon it (``StepStop``): history.png (and multiscale.png) are
    drawn from history.h5 as written (t = 0 and step 1) and open_in_paraview.py opens the fields written,
    as after a stop at the end of a step (before: the run ended with neither history.png nor
    open_in_paraview.py; the loop writes history.h5 alone)."""
    import json

    from test_coupling import POD

    from multiscale import outputs
    from multiscale.coupling import Multiscale
    from multiscale.io import History
    from multiscale.macro.model import MacroModel
    from multiscale.plots.history import history_figure, multiscale_figure
    from multiscale.scene import loads
    from multiscale.workflows import run
    folder = tmp_path / "out"
    scene = loads((SCENE if kind == "transient" else POD).format(folder=folder), overrides={"output.figures": True})
    cls, name = (MacroModel, "macro_step") if kind == "transient" else (Multiscale, "step")
    original, calls = getattr(cls, name), []

    def abandoned(self, *args):
        calls.append(args)
        if len(calls) == 2:
            for _ in range(3):                   # the third abandons the step
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.01)
        return original(self, *args)
    monkeypatch.setattr(cls, name, abandoned)
    with pytest.raises(KeyboardInterrupt, match="during step 2, abandoned: the results of step 1 are the last "
                                                "written"):
        run(scene, verbose=False)
    status = json.loads((folder / "provenance.json").read_text())["status"]
    assert status == "interrupted during step 2, abandoned: the results of step 1 are the last written"
    history = History.read(folder / "history.h5")
    assert len(history) == 2
    plots = [("history.png", history_figure)] + ([("multiscale.png", multiscale_figure)] if kind == "multiscale"
                                                 else [])
    for png, figure in plots:                    # the figure of the history written, its title saying so
        figure(history, tmp_path / png, f"{scene.name} (stopped at t = {history['time'][-1]:g} s)")
        assert (folder / png).read_bytes() == (tmp_path / png).read_bytes(), png
    assert (folder / "open_in_paraview.py").read_text() == outputs.paraview_script(outputs.plan(scene))


def test_a_second_ctrl_c_while_the_run_stops_leaves_its_results_whole(tmp_path):
    """Two Ctrl-C a moment apart (the second once the first is acknowledged): the run still stops
    after its step with every result of that step written: history, fields, plot, open_in_paraview.py and
    provenance.json agree (before: the second interrupted the writing: fields of t = 30.0 s beside a
    history to 30.6 s, provenance "interrupted" without the step, no history.png nor open_in_paraview.py)."""
    import json

    import h5py
    import meshio
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.format(folder=tmp_path / "out").replace("steps = 3\n", "steps = 4000\n")
                     .replace("[output]\n", "[output]\nevery = 1000\n"))
    folder = tmp_path / "out"
    job = subprocess.Popen([str(Path(sys.executable).with_name("multiscale")), "run", str(scene)],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        rows, start = 0, time.monotonic()
        while rows < 3 and time.monotonic() - start < 120:    # the steps have begun: their history is written
            time.sleep(0.05)
            try:
                with h5py.File(folder / "history.h5", "r") as f:
                    rows = len(f["time"])
            except (OSError, KeyError):
                pass
        job.send_signal(signal.SIGINT)
        for line in job.stderr:                               # the first is acknowledged
            if line.startswith("Ctrl-C: stopping after this step"):
                break
        job.send_signal(signal.SIGINT)
        err = line + job.stderr.read()
        job.wait(timeout=120)
    finally:
        if job.poll() is None:
            os.killpg(job.pid, signal.SIGKILL)
    assert job.returncode == 130, err[-3000:]
    assert "Traceback" not in err and "Ctrl-C: still finishing the step and writing its results" in err, err[-3000:]
    status = json.loads((folder / "provenance.json").read_text())["status"]
    done = int(status.split()[3])
    assert status == f"interrupted after step {done} of 4000"
    with h5py.File(folder / "history.h5", "r") as f:
        assert f["time"][-1] == pytest.approx(done * 3 / 4000) and len(f["time"]) == done + 1
    with meshio.xdmf.TimeSeriesReader(str(folder / "block.xdmf")) as reader:
        reader.read_points_cells()
        assert reader.read_data(reader.num_steps - 1)[0] == pytest.approx(done * 3 / 4000)   # the stop's fields
    assert (folder / "history.png").stat().st_size > 0 and (folder / "open_in_paraview.py").exists()


# the mesh build of the cooling block held up: one rank in a collective operation that waits for
# the other, which sleeps (where Ctrl-C reaches Python); as rank 0 meshing with gmsh while rank 1
# waits for the mesh, or rank 1 assembling while rank 0 waits
HELD_UP = """
import os, sys, time
from mpi4py import MPI
from multiscale.cli import main
from multiscale.workflows import transient

def held_up(scene, comm):
    print(f"held up on rank {comm.rank}: pid {os.getpid()}", flush=True)
    if comm.rank == int(sys.argv[2]):
        comm.bcast(None, root=1 - comm.rank)  # never completes: Python never regains this rank
    time.sleep(120)

transient.build_mesh = held_up
sys.exit(main(["run", sys.argv[1], "--overwrite"]))
"""


@pytest.mark.parametrize("waiting", [0, 1])
def test_an_early_ctrl_c_ends_every_rank_at_once_with_one_line(tmp_path, waiting):
    """Ctrl-C under mpiexec -n 2 while one rank waits inside a collective operation (the rank
    ``waiting``) and the other meets the signal: the job ends within seconds, with exit code 130 and
    the one line saying what was written (before: 11 s, ended_together's 10 s and MPI_Abort, then
    MPICH's "Abort(130) ... MPI_Abort" line; with rank 0 waiting, no line of ours at all)."""
    import contextlib
    scene, driver = tmp_path / "scene.toml", tmp_path / "driver.py"
    scene.write_text(SCENE.format(folder=tmp_path / "out"))
    driver.write_text(HELD_UP)
    job = subprocess.Popen([str(MPIEXEC), "-n", "2", sys.executable, str(driver), str(scene), str(waiting)],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        pids = set()
        for line in job.stdout:                  # mpiexec may join the ranks' lines into one
            pids |= {int(pid) for pid in re.findall(r"held up on rank \d: pid (\d+)", line)}
            if len(pids) == 2:
                break
        time.sleep(0.5)                          # into the broadcast
        sent = time.monotonic()
        job.send_signal(signal.SIGINT)
        err = job.communicate(timeout=60)[1]
        seconds = time.monotonic() - sent
    finally:
        for pid in pids | {job.pid}:             # the ranks run in sessions of their own
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
    assert job.returncode == 130 and seconds < 8, (seconds, err[-3000:])
    assert [line for line in err.splitlines() if line.strip()] == [
        f"interrupted: no macro step ended, there is nothing to resume; {MPIEXEC} -n 2 {COMMAND} run {scene} "
        "starts again"], err[-3000:]
    # (before: "what was written stays in ... (its provenance.json says so)" of a folder still empty)


ABORT_IN_GMSH = """
import threading, time
import gmsh
from mpi4py import MPI
from multiscale import io
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.01)
threading.Thread(target=lambda: (time.sleep(1.0), io.abort(MPI.COMM_WORLD, 130, quiet=True)), daemon=True).start()
gmsh.model.mesh.generate(3)
print("meshed")
"""


def test_a_serial_run_ended_from_the_watcher_inside_gmsh_exits_with_its_code(tmp_path):
    """The Ctrl-C watcher ends a job whose main thread is inside a C call; serial, its MPI_Abort
    while gmsh meshed ended the process in a segmentation fault (exit 139, 6 of 9 Ctrl-Cs during
    meshing, a user trial) instead of the documented 130. One rank now simply exits."""
    driver = tmp_path / "driver.py"
    driver.write_text(ABORT_IN_GMSH)
    started = time.monotonic()
    done = subprocess.run([sys.executable, str(driver)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 130 and "meshed" not in done.stdout, (done.returncode, done.stderr[-2000:])
    assert time.monotonic() - started < 60


# the mesh build of the cooling block held up in Python (a sleep) or inside a C call (gmsh meshing a
# fine box, where no Python signal handler runs)
HELD_UP_SERIAL = """
import os, sys, time
from multiscale.cli import main
from multiscale.workflows import transient

def held_up(scene, comm):
    print(f"held up: pid {os.getpid()}", flush=True)
    if sys.argv[2] == "python":
        time.sleep(120)
    import gmsh
    from multiscale.geometry import start_gmsh
    start_gmsh()
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.01)
    gmsh.model.mesh.generate(3)

transient.build_mesh = held_up
sys.exit(main(["run", sys.argv[1], "--overwrite"]))
"""


@pytest.mark.parametrize("where", ["python", "gmsh"])
def test_sigterm_before_the_steps_ends_the_run_with_one_line(tmp_path, where):
    """SIGTERM (a batch scheduler's time limit) during a run's set-up ended it without a word (exit
    -15) and its provenance said "running" (a user trial). It is a Ctrl-C now: in Python the run
    stops with the line saying what was written, by SIGTERM; inside a C call (meshing, a
    factorisation) the watcher ends it within seconds with that line. Exit code 130."""
    scene, driver = tmp_path / "scene.toml", tmp_path / "driver.py"
    scene.write_text(SCENE.format(folder=tmp_path / "out"))
    driver.write_text(HELD_UP_SERIAL)
    job = subprocess.Popen([sys.executable, str(driver), str(scene), where], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        for line in job.stdout:
            if line.startswith("held up"):
                break
        time.sleep(1.0)                          # into the sleep, or into gmsh
        sent = time.monotonic()
        job.send_signal(signal.SIGTERM)
        err = job.communicate(timeout=60)[1]
        seconds = time.monotonic() - sent
    finally:
        if job.poll() is None:
            os.killpg(job.pid, signal.SIGKILL)
    assert job.returncode == 130 and seconds < 10, (job.returncode, seconds, err[-3000:])
    said = "interrupted by SIGTERM" if where == "python" else "interrupted"
    assert [line for line in err.splitlines() if line.strip()] == [
        f"{said}: no macro step ended, there is nothing to resume; {COMMAND} run {scene} starts again"], err[-3000:]


KEPT_HANDLER = """
import os, signal, sys
signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(f"kept {signum}"))
import multiscale.macro
os.kill(os.getpid(), signal.SIGTERM)
"""


def test_petsc_leaves_python_its_sigterm_handler():
    """PETSc's initialisation installs its own SIGTERM handler (MPI_Abort): the command line's watch,
    set before the workflows import PETSc, lost it, and a 2-rank squeal run sent SIGTERM in its eigen
    solve ended in "Caught signal number 15" and MPI_Abort (a trial). Importing the macro package
    puts Python's handler back."""
    done = subprocess.run([sys.executable, "-c", KEPT_HANDLER], capture_output=True, text=True, timeout=120)
    assert done.returncode == 1 and done.stderr.strip().endswith(f"kept {int(signal.SIGTERM)}"), done.stderr[-2000:]


CLOSED_PIPE = """
import os
import multiscale.macro
from multiscale.geometry import start_gmsh
start_gmsh()
read, write = os.pipe()
os.close(read)
try:
    os.write(write, b"x")
except BrokenPipeError:
    print("raised")
"""


def test_a_python_session_with_petsc_and_gmsh_raises_on_a_closed_pipe():
    """A write into a closed pipe in a session that had loaded PETSc printed "Caught signal number 13
    Broken Pipe" and called MPI_Abort (exit code 15); after gmsh's initialisation it ended silently
    (status 141). A notebook kernel died instead of raising; now it is Python's BrokenPipeError."""
    done = subprocess.run([sys.executable, "-c", CLOSED_PIPE], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == "raised", (done.returncode, done.stderr[-2000:])


def test_an_interrupt_is_recognised_through_the_errors_it_caused():
    """petsc4py raises PETSc.Error(101) from a KeyboardInterrupt met in an SNES callback: that is a
    Ctrl-C too; an ordinary error is not, and a cycle of causes ends the search."""
    from petsc4py import PETSc

    from multiscale.errors import ConvergenceError, interrupted
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            raise PETSc.Error(101) from exc
    except PETSc.Error as exc:
        assert interrupted(exc)
    plain = ConvergenceError("no")
    looped = RuntimeError("a")
    looped.__context__ = plain
    plain.__context__ = looped
    assert not interrupted(plain) and not interrupted(ValueError()) and interrupted(KeyboardInterrupt())


def test_marking_a_checkpoint_is_all_or_nothing(tmp_path, monkeypatch):
    """``checkpoint.mark`` edits a copy and replaces the file: a failure while the attributes are
    written (here at the second) leaves the checkpoint as it was. It edited the only checkpoint in
    place, where a run killed mid-edit could leave it half written (an adversarial review)."""
    import h5py
    from mpi4py import MPI

    from multiscale import checkpoint as ckpt
    from multiscale.errors import OutputError
    path = ckpt.save(tmp_path / "checkpoint.h5", MPI.COMM_SELF, attrs={"step": 3, "fields_written": 2},
                     arrays={"x": np.arange(4.0)}, functions={})
    before = path.read_bytes()
    setitem = h5py.AttributeManager.__setitem__

    def failing(self, key, value):
        if key == "finished":
            raise OSError(28, "No space left on device")
        setitem(self, key, value)
    monkeypatch.setattr(h5py.AttributeManager, "__setitem__", failing)
    with pytest.raises(OutputError, match="cannot write the checkpoint"):
        ckpt.mark(path, MPI.COMM_SELF, fields_written=3, finished=True)
    assert path.read_bytes() == before and not path.with_name("checkpoint.h5.part").exists()
    monkeypatch.setattr(h5py.AttributeManager, "__setitem__", setitem)
    ckpt.mark(path, MPI.COMM_SELF, fields_written=3, finished=True)
    attrs, arrays = ckpt.load(path, MPI.COMM_SELF, {})
    assert (attrs["fields_written"], bool(attrs["finished"]), list(arrays["x"])) == (3, True, [0, 1, 2, 3])


ONE_RANK_FAILS = """
from mpi4py import MPI


def test_fails_on_rank_1():
    assert MPI.COMM_WORLD.rank == 0, "only rank 1 fails"
    MPI.COMM_WORLD.barrier()                  # rank 0 waits here for a rank that left the test


def test_never_reached():
    MPI.COMM_WORLD.barrier()
"""


def test_a_test_failing_on_one_rank_ends_the_mpi_test_job(tmp_path):
    """tests/mpi/conftest.py: a test failing on rank 1 alone, while rank 0 waits in a collective,
    ends the ``mpiexec -n 2 pytest`` job within seconds, exit code 1, with the failure's report.
    Without that conftest the job hangs (CI at 8a694ab: 38 minutes, until killed)."""
    conftest = Path(__file__).with_name("mpi") / "conftest.py"
    (tmp_path / "conftest.py").write_text(conftest.read_text())
    (tmp_path / "test_one_rank.py").write_text(ONE_RANK_FAILS)
    job = subprocess.Popen([str(MPIEXEC), "-n", "2", sys.executable, "-m", "pytest", "-q", "-p",
                            "no:cacheprovider", "-o", "addopts=", str(tmp_path)], cwd=tmp_path,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        out, err = job.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(job.pid, signal.SIGKILL)      # the ranks too, not only mpiexec
        raise
    assert job.returncode == 1, err
    assert "[rank 1] FAILED test_one_rank.py::test_fails_on_rank_1 (call)" in err
    assert "only rank 1 fails" in err and "passed" not in out      # ended there: no rank finished its run
