"""Where a run writes: the output-folder check (the only one) and the result every workflow returns."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from multiscale import io
from multiscale.errors import InputError, SceneError


@dataclass
class RunResult:
    """What a run wrote: its folder, the files (fields for ParaView, tables, plots) and its wall time."""

    folder: Path
    files: list            # written paths
    wall_time: float       # s


def prepare_folder(scene, overwrite: bool, resume: bool, comm) -> Path:
    """The scene's output folder, created; refuses to touch earlier results unless ``overwrite``
    (replace them) or ``resume`` (continue them; a missing folder is then an error and is not
    created). Rank 0 decides for every rank (collective)."""
    folder = Path(scene.output.folder)
    if resume and not comm.bcast(folder.is_dir() if comm.rank == 0 else None, root=0):
        raise InputError("--resume", str(folder), "the output folder does not exist: there is nothing to resume "
                         "(run without --resume)")
    existing = comm.bcast(sorted(p.name for p in folder.iterdir()) if comm.rank == 0 and folder.is_dir() else [],
                          root=0)
    if existing and not (overwrite or resume):
        shown = ", ".join(existing[:3]) + (", ..." if len(existing) > 3 else "")
        raise SceneError(f'output.folder = "{folder}": already holds results ({len(existing)} entries: {shown}); '
                         "use --overwrite to replace them, --resume to continue the run, or choose another folder")

    def create():
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".multiscale_write_test"
        probe.write_bytes(b"")              # a read-only folder fails here, before any work
        probe.unlink()
    io.on_root(comm, create, f"into the output folder {folder}")
    io.reporter().folder = folder         # where a failed run leaves its provenance
    return folder
