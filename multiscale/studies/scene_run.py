"""The scene problem's subprocess: ``python -m multiscale.studies.scene_run TASK_JSON`` loads the
scene with its overrides (``{"scene": path, "overrides": {dotted path: raw value}}``, the output
folder among them) and runs it with its workflow (``multiscale.workflows.run``), overwriting that folder."""
from __future__ import annotations

import json
import os
import sys

from mpi4py import MPI

from multiscale.errors import MultiscaleError
from multiscale.scene import load

__all__ = ["main"]


def main(task: str) -> int:
    """Run the scene of ``task`` (JSON); 0 on success; 2 after a ``MultiscaleError``, raised on every
    rank, said once by rank 0 as ``Kind: message`` (every rank printed its traceback into the run's
    log: a user trial); any other exception as it is."""
    spec = json.loads(task)
    try:
        scene = load(spec["scene"], overrides=spec["overrides"])
        from multiscale.workflows import run  # DOLFINx: optional, and loaded only in this subprocess
        run(scene, overwrite=True, verbose=False)
    except MultiscaleError as exc:
        if MPI.COMM_WORLD.rank == 0:
            print(f"{type(exc).__name__}: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":  # pragma: no cover
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    sys.exit(main(sys.argv[1]))
