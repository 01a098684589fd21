"""The scene problem's subprocess: ``python -m multiscale.studies.scene_run TASK_JSON`` loads the
scene with its overrides (``{"scene": path, "overrides": {dotted path: raw value}}``, the output
folder among them) and runs it with its workflow (``multiscale.workflows.run``), overwriting that folder."""
from __future__ import annotations

import json
import os
import sys

from multiscale.scene import load

__all__ = ["main"]


def main(task: str) -> int:
    """Run the scene of ``task`` (JSON); 0 on success, an exception otherwise."""
    spec = json.loads(task)
    scene = load(spec["scene"], overrides=spec["overrides"])
    from multiscale.workflows import run  # DOLFINx: optional, and loaded only in this subprocess
    run(scene, overwrite=True, verbose=False)
    return 0


if __name__ == "__main__":  # pragma: no cover
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    sys.exit(main(sys.argv[1]))
