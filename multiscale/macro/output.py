"""Fields for ParaView: XDMF time series of the bodies and of the interface.

``FieldWriter`` writes ``<body>.xdmf`` per body and ``interface.xdmf`` (per-facet cell data);
``FieldOutput`` picks a model's requested fields (displacement, temperature, von Mises stress,
contact pressure, frictional heat flux, and per-facet extras such as the zone laws' stiffness),
refreshes the derived ones and writes them at each output time; ``write_modes_xdmf`` writes complex
mode shapes. XDMF writes are collective.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np
from dolfinx import fem
from dolfinx.io import XDMFFile

from multiscale.errors import InputError


class FieldWriter:
    """XDMF time series: ``<folder>/<body>.xdmf`` per body and ``<folder>/interface.xdmf``.

    The files are closed after every write, so that a run killed between two writes leaves them
    readable; ``append`` continues existing files (a resumed run: no new mesh)."""

    def __init__(self, folder: Path, tm, body_functions, interface_functions, append: bool = False):
        self.files, self.groups = [], []
        self.append, self.comm = append, tm.comm
        for body, functions in zip(tm.bodies, body_functions):
            self._open(Path(folder) / f"{body.name}.xdmf", body.mesh, functions)
        self._open(Path(folder) / "interface.xdmf", tm.interface.mesh, interface_functions)

    def _open(self, path, mesh, functions):
        if not self.append:
            with XDMFFile(self.comm, str(path), "w") as f:
                f.write_mesh(mesh)
        self.files.append(path)
        self.groups.append((path, list(functions)))

    def write(self, time: float) -> None:
        for path, functions in self.groups:
            with XDMFFile(self.comm, str(path), "a") as f:
                for u in functions:
                    f.write_function(u, time)


class FieldOutput:
    """The requested ``fields`` of a ``MacroModel``, refreshed and written at each output time.

    ``extra``: {interface field name: callable returning its global per-facet array}, written when
    the name is among ``fields``; ``append``: continue existing XDMF files (a resumed run)."""

    def __init__(self, model, folder: Path, fields, extra: Mapping[str, Callable] | None = None,
                 append: bool = False):
        self.model = model
        tm, mech, th = model.tm, model.mechanics, model.thermal
        fields = set(fields)
        body = [[], []]
        self.von_mises = []
        for i, b in enumerate(tm.bodies):
            if "displacement" in fields:
                body[i].append(mech.u[i])
            if "temperature" in fields and th is not None:
                body[i].append(th.T[i])
            if "von_mises" in fields:
                V = b.region_space
                f = fem.Function(V, name=f"von_mises_{b.name}")
                self.von_mises.append((f, fem.Expression(mech.von_mises(i), V.element.interpolation_points)))
                body[i].append(f)
        self.pressure = tm.interface.field("contact_pressure") if "contact_pressure" in fields else None
        self.flux = tm.interface.field("heat_flux") if "heat_flux" in fields and th is not None else None
        self.extra = [(tm.interface.field(name), make) for name, make in (extra or {}).items() if name in fields]
        iface = [f for f in (self.pressure, self.flux) if f is not None] + [f for f, _ in self.extra]
        self.writer = FieldWriter(folder, tm, body, iface, append=append)
        self.files = self.writer.files

    def write(self) -> None:
        m = self.model
        for f, expr in self.von_mises:
            f.interpolate(expr)
        if self.pressure is not None:
            m.tm.interface.set_field(self.pressure, m.contact.facet_pressure())
        if self.flux is not None:
            m.tm.interface.set_field(self.flux, m.contact.facet_heat_flux())
        for f, make in self.extra:
            m.tm.interface.set_field(f, make())
        self.writer.write(m.time)


def write_modes_xdmf(path: str | Path, result, functions: Sequence,
                     modes: Sequence[int] | None = None) -> list[Path]:
    """Mode shapes of ``result`` (``eigen.ModalResult``) to XDMF, one file per body mesh: real and
    imaginary parts, "time" = mode number.

    ``functions`` are displacement Functions of the bodies in the block order of the matrices (the
    owned dofs of body 0, then of body 1, ... on each rank). Shapes are interpolated to linear
    vertex values (XDMF stores the mesh's own degree). Returns the written paths.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    sel = range(1, len(result) + 1) if modes is None else modes
    sizes = [u.function_space.dofmap.bs * u.function_space.dofmap.index_map.size_local
             for u in functions]
    if sum(sizes) != result.modes.shape[0]:
        raise InputError("functions", len(functions), "must span the dof layout of the modes")
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    files = []
    for k, u in enumerate(functions):
        mesh = u.function_space.mesh
        work = fem.Function(u.function_space)
        W = fem.functionspace(mesh, ("Lagrange", 1, (mesh.geometry.dim,)))
        parts = (fem.Function(W, name="mode_re"), fem.Function(W, name="mode_im"))
        out = path.with_name(f"{path.stem}_body{k}.xdmf")
        with XDMFFile(mesh.comm, str(out), "w") as w:
            w.write_mesh(mesh)
            for j in sel:
                block = result.modes[offsets[k]:offsets[k + 1], j - 1]
                for f, values in zip(parts, (block.real, block.imag)):
                    work.x.array[:sizes[k]] = values
                    work.x.scatter_forward()
                    f.interpolate(work)
                    w.write_function(f, float(j))
        files.append(out)
    return files
