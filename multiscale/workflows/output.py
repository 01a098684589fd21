"""Where a run writes: the output-folder check (the only one), the result every workflow returns and
the fingerprint its checkpoints hold."""
from __future__ import annotations

import dataclasses
import fcntl
import json
import os
import shutil
import tomllib
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from multiscale import checkpoint, io, outputs, provenance
from multiscale.applications import applications, hottest_columns, write_csv
from multiscale.errors import InputError, SceneError
from multiscale.geometry import MAX_CELLS


@dataclass
class RunResult:
    """What a run wrote: its folder, the files (fields for ParaView, tables, plots) and its wall time;
    ``warnings``, once ``workflows.run`` returns it, every warning of the run, one line each (the
    scene's, what the model noted, what the results leave out: those it printed on rank 0 and
    provenance.json records)."""

    folder: Path
    files: list            #: written paths
    wall_time: float       #: s
    warnings: tuple = field(default=(), kw_only=True)
    ended: str = field(default="", kw_only=True)   #: why it ended before its last step ("" if it did not)


def totals(history) -> str:
    """The run's headline numbers for its last console lines (a trial found only file paths there):
    the frictional work [J] (the rough interfaces', else the frictional heat into the bodies), each
    body's highest temperature [degC] over the run and the worn volume [mm^3]; "" without any."""
    cols, last = history.columns, lambda key: float(history[key][-1])
    heat = [k for k in cols if k.startswith("heat_total_")]
    out = [f"frictional work {last('frictional_work'):.4g} J" if "frictional_work" in cols else
           f"frictional heat {sum(last(k) for k in heat):.4g} J" if heat else ""]
    out += [f"hottest {k.removeprefix('max_temperature_')} {max(history[k]) - 273.15:.4g} degC"
            for k in hottest_columns(cols)]
    out += [f"wear volume {last('wear_volume') * 1e9:.4g} mm^3"] if "wear_volume" in cols else []
    return ", ".join(o for o in out if o)


def write_applications(scene, history, folder: Path) -> list:
    """``applications.csv`` in ``folder``: the braking applications of ``scene``'s cycle that ``history``
    reached (``multiscale.applications``; call on rank 0, for a scene of ``outputs.per_application``);
    none reached, no file. Returns them."""
    motion = scene.geometry.motion
    apps = applications(history, scene.loading, motion, scene.time.end)
    if apps:
        with io.replacing(Path(folder) / outputs.APPLICATIONS) as part:
            write_csv(apps, motion, part)
    return apps


@dataclass
class OutputFolder:
    """A run's output folder, prepared (checked, created, writable) but not yet written into.
    ``claim`` is called when the run has its first result to write: only then does ``--overwrite``
    delete the earlier results and the new provenance appear, so a run that fails before (a scene
    the mesh refuses, a first solve that does not converge, Ctrl-C) leaves the folder as it was."""

    path: Path
    scene: object
    comm: object
    replace: list          # names of earlier results that claim deletes (--overwrite)
    resume: bool = False
    seen: list = field(default_factory=list)     # the entries the folder held at ``prepare_folder``

    def claim(self) -> Path:
        """Delete the earlier results (``--overwrite``: every entry the earlier run recorded writing,
        ``provenance.results_of``, so no stale field file, figure or checkpoint of another scene stays
        beside the new results; entries no run recorded, the user's own, stay with a message) and
        write the new run's provenance with status ``provenance.RUNNING`` (what a killed run leaves;
        resumed, a part of that status after the earlier parts). A ``SceneError`` on every rank, with
        nothing written, when another run has since begun writing into the folder or has written
        entries into it (``exclusive``: of two runs started at once, one). Collective; once per run."""
        scene, comm = self.scene, self.comm

        def start():
            with exclusive(self.path):            # the check and the record at once: no run between
                busy = busy_message(self.path)    # (one that began since ``prepare_folder``)
                if busy:
                    return busy
                appeared = sorted(set(scene.earlier_results()) - set(self.seen))
                if appeared:                      # a run that began and ended since ``prepare_folder``
                    shown = ", ".join(appeared[:3]) + (", ..." if len(appeared) > 3 else "")
                    return (f'output.folder = "{self.path}": {provenance.entries(len(appeared))} appeared in '
                            f"it while this run prepared ({shown}), written by another run: run again to see "
                            "what it holds, or choose another folder")
                if self.replace:
                    clear(self.path, self.replace)
                provenance.write(self.path, scene, ranks=comm.size, started=provenance.now(), stages={},
                                 wall_time=0.0, status=provenance.RUNNING, analysis=outputs.analysis(scene),
                                 warnings=scene.warnings,
                                 earlier=provenance.parts_of(self.path) if self.resume else ())
                return None
        refused = comm.bcast(io.on_root(comm, start, f"into the output folder {self.path}"), root=0)
        if refused:
            raise SceneError(refused)
        io.reporter().folder = self.path        # where a failed run leaves its provenance
        return self.path


def prepare_folder(scene, overwrite: bool, resume: bool, comm) -> OutputFolder:
    """The scene's output folder, created and tested for writing (a read-only folder fails here,
    before any work); refuses to touch earlier results unless ``overwrite`` (replace them, at
    ``OutputFolder.claim``) or ``resume`` (continue them; a missing folder is then an error and is
    not created). The folder is claimed when the run first writes (resumed: once it has steps
    left), so that a run refused before (at meshing, in its first solve) leaves no entry that
    would make the next run need ``--overwrite``.
    Rank 0 decides for every rank (collective)."""
    folder = Path(scene.output.folder)
    if resume and not comm.bcast(folder.is_dir() if comm.rank == 0 else None, root=0):
        raise InputError("--resume", str(folder), "the output folder does not exist: there is nothing to resume "
                         "(run without --resume)")
    busy = comm.bcast(busy_message(folder) if comm.rank == 0 else None, root=0)
    if busy:
        raise SceneError(busy)
    existing = comm.bcast(scene.earlier_results() if comm.rank == 0 else None, root=0)
    taken = comm.bcast([n for n in provenance.inputs_in(folder) if n in outputs.plan(scene).files
                        and (folder / n).resolve() not in scene.inputs] if comm.rank == 0 and existing else [], root=0)
    if taken:                        # this run would write over them: the scene of a run in its own folder
        raise SceneError(f'output.folder = "{folder}": holds {", ".join(taken)}, an input of the run before (a '
                         "scene run in its own folder); this run would write over it: choose another folder")
    own = comm.bcast(provenance.unrecorded_results(scene, existing) if comm.rank == 0 and not resume else [], root=0)
    unreadable = comm.bcast(provenance.record_problem(folder) if comm.rank == 0 and existing else None, root=0)
    if own:
        why = (f"; {unreadable}: which of them a run wrote is unknown" if unreadable else
               " but not written by a run (no record of it in provenance.json)")
        raise SceneError(f'output.folder = "{folder}": holds {", ".join(own)}, named as this run\'s results{why}: a '
                         "run would write over them, --overwrite too; move them or choose another folder")
    if resume and unreadable and comm.rank == 0:      # the checkpoint resumes; the record of the parts before is gone
        io.reporter().warn(f"{unreadable}: the record of the run's earlier parts is lost; the new provenance.json "
                           "records the resumed part only")
    if existing and not (overwrite or resume):
        shown = ", ".join(existing[:3]) + (", ..." if len(existing) > 3 else "")
        ran = comm.bcast(bool(set(existing) & set(provenance.results_of(folder))) if comm.rank == 0 else None, root=0)
        resumes = ran and outputs.checkpointed(scene)                  # the analyses with checkpoints
        held = f"results ({provenance.entries(len(existing))}: {shown})" if ran else \
            f"{provenance.entries(len(existing))} that no run wrote ({shown})"    # the user's own files: not "results"
        advice = ("use --overwrite to replace them, --resume to continue the run (in Python: overwrite=True, "
                  "resume=True)" if resumes else "use --overwrite to replace them (in Python: overwrite=True)" if ran
                  else "use --overwrite to write beside them (it deletes only what a run wrote; in Python: "
                  "overwrite=True)")
        raise SceneError(f'output.folder = "{folder}": already holds {held}; {advice}, or choose another folder')

    def create():
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".multiscale_write_test"
        probe.write_bytes(b"")
        probe.unlink()
    io.on_root(comm, create, f"into the output folder {folder}")
    return OutputFolder(folder, scene, comm, [] if resume else existing, resume, existing)


@contextmanager
def exclusive(folder: Path):
    """Hold an exclusive advisory lock (``flock``) on the directory ``folder`` for the block, waiting
    for another process's (rank 0). Two runs started at the same instant into one new folder both
    passed the record check and both failed, the second's record over the first's (a user trial):
    under the lock one of them finds the other's record. A file system without ``flock`` on
    directories (some NFS mounts) gives no lock: the record check alone, as before."""
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError:
            pass
        yield
    finally:
        os.close(fd)                              # (releases the lock)


def busy_message(folder: Path) -> str | None:
    """Why a run cannot write into ``folder``: another process of this host is (``provenance.writer``),
    or None (call on rank 0)."""
    record = provenance.writer(folder) if folder.is_dir() else None
    if record is None:
        return None
    who = record["process"]
    return (f'output.folder = "{folder}": another run writes into it (process {who["pid"]} on this host, '
            f"started {record.get('start')}, command {' '.join(map(str, record.get('command') or []))}): two runs "
            "would write over each other's files; wait for it to end, or choose another folder")


def clear(folder: Path, existing: list[str]) -> None:
    """Delete the entries of ``existing`` (names in ``folder``) that the run before recorded writing;
    say which others stay (call on rank 0)."""
    earlier = set(provenance.results_of(folder))
    for name in existing:
        if name in earlier:
            path = folder / name
            shutil.rmtree(path) if path.is_dir() and not path.is_symlink() else path.unlink()
    kept = [name for name in existing if name not in earlier]
    if kept:
        shown = ", ".join(kept[:3]) + (", ..." if len(kept) > 3 else "")
        why = "not written by the run before" if earlier else "no record of a run (provenance.json with its files)"
        io.reporter().say(f"--overwrite: {provenance.entries(len(kept))} of {folder} stay{'s' * (len(kept) == 1)} "
                          f"({why}): {shown}")


def fingerprint(scene) -> checkpoint.Fingerprint:
    """What the results depend on: the scene but the keys a resume may change (``provenance.free``:
    the output section but its probes, whose history columns a resumed run continues: one added
    failed in the history's first row, one moved mixed two places in a column, a review; ``name``,
    ``description`` and ``geometry.max_cells``: a long-run trial's resume was refused for a changed
    description; ``wear.limit``, which ends a run and may be lowered to resume it; effects sorted:
    a set's order changes between processes) and the bytes of every file it reads (a measured
    surface rewritten under the same name was resumed into wrong wear depths: the checkpoint holds the worn heights, the unworn ones are read again); its
    inputs by name: every key of the resolved scene but those, and each file's SHA-1."""
    s = dataclasses.replace(scene, output=None, source=None, overrides=(), warnings=(), name=None, description="",
                            geometry=dataclasses.replace(scene.geometry, max_cells=MAX_CELLS),
                            wear=dataclasses.replace(scene.wear, limit=0.0) if scene.wear is not None else None,
                            effects=tuple(sorted(scene.effects)))
    source = scene.source.resolve() if scene.source is not None else None
    files = {p: checkpoint.file_digest(p) for p in sorted(p for p in scene.inputs if p != source and p.is_file())}
    resolved = tomllib.loads(provenance.resolved_toml(scene))
    provenance.free(resolved)
    inputs = {**{k: json.dumps(v, default=str) for k, v in provenance.dotted(resolved).items()},
              **{f"file {p}": digest for p, digest in files.items()}}
    text = repr(s) + (repr(scene.output.probes) if scene.output.probes else "") + \
        "".join(f"{p}:{d}" for p, d in files.items())
    return checkpoint.Fingerprint(checkpoint.fingerprint(text), inputs)

