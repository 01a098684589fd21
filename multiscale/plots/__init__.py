"""Figures of the package, one module per results family (matplotlib ``Figure`` objects, no pyplot
state); solver, workflow and study modules never draw. Only rank 0 calls these."""
from __future__ import annotations

from pathlib import Path


def path_problem(path: Path) -> str | None:
    """Why a file cannot be written at ``path`` (a folder, no such folder), or None: said before the
    work, not after it (a user trial)."""
    if path.is_dir():
        return "a folder: give a file name"
    if not path.parent.is_dir():
        return f"no folder {path.parent}"
    return None


def figure_problem(path: Path) -> str | None:
    """Why a figure cannot be written at ``path`` (``path_problem``, or a format matplotlib does
    not write), or None."""
    from matplotlib.backend_bases import FigureCanvasBase   # local: the package imports no matplotlib
    kinds = FigureCanvasBase.get_supported_filetypes()
    if (why := path_problem(path)) is not None:
        return why
    if path.suffix[1:].lower() not in kinds:     # none: matplotlib wrote PATH.png, not the PATH said
        return (f"a figure is a .{', .'.join(sorted(kinds))} file (matplotlib), not "
                f"{'.' + path.suffix[1:] if path.suffix else 'a name without extension'}")
    return None
