"""Fields for ParaView: one XDMF time series per body and one for the interface; mode shapes in VTX.

Every field file holds ONE mesh and, at each output time, ONE grid carrying every field as a named
point array (nodal fields: displacement, temperature) or cell array (von Mises stress per cell,
the interface's per-facet values), named with its unit ("temperature [K]", ``outputs.FIELDS``):
ParaView's XDMF reader shows one block per file whose arrays colour it directly, and meshio's
``TimeSeriesReader`` or h5py read it back. The times are the model's exact output times.
``<name>.xdmf`` is the index and ``<name>.h5`` the data (``/mesh/geometry``, ``/mesh/topology``,
``/times``, ``/data/<k>/<field>``; a body of several parts ``/mesh/part``, its cells' part numbers,
shown at every time); the writer is ours, not DOLFINx's ``XDMFFile``, because that one
writes every function as its own grid (coincident unnamed blocks in ParaView).

- ``FieldWriter``: the series of a set of meshes; the mesh is gathered to rank 0 once in a
  rank-independent order (nodes sorted by coordinates, cells by their nodes; quadratic cells
  where a body has a quadratic field: ``MeshLayout``), so that a run resumed on another number
  of ranks appends to the same files. Files are closed after every
  write: a run killed between two writes leaves them readable; the resumed run drops the times
  the killed one wrote after its checkpoint, and replaces a time written again: no time twice.
- ``FieldOutput``: a model's requested fields (``output.fields``) refreshed and written at each
  output time; ``write_state`` writes one state (the squeal analysis' preload).
- ``write_modes``: complex mode shapes, one VTX (ADIOS2, ``.bp``) file per body holding the real and
  imaginary parts on the mesh of the displacement (quadratic shapes exactly), "time" = mode number.
  ParaView opens it with its ADIOS2 VTX reader.
"""
from __future__ import annotations

import warnings
from pathlib import Path
from typing import Callable, Mapping, Sequence
from xml.sax.saxutils import quoteattr

import basix
import h5py
import numpy as np
from dolfinx import fem
from dolfinx import mesh as dmesh
from dolfinx.io import VTXMeshPolicy, VTXWriter
from mpi4py import MPI

from multiscale import io
from multiscale.arrays import unique_rows
from multiscale.errors import InputError, OutputError
from multiscale.macro.unloaded import Unloaded, UnloadedWarning
from multiscale.outputs import FIELDS, MODE_ARRAYS, PART_ARRAY, array_name

# DOLFINx cell name -> (XDMF topology type, DOLFINx vertex order -> XDMF/VTK order)
CELLS = {"tetrahedron": ("Tetrahedron", [0, 1, 2, 3]), "triangle": ("Triangle", [0, 1, 2]),
         "hexahedron": ("Hexahedron", [0, 1, 3, 2, 4, 5, 7, 6]), "quadrilateral": ("Quadrilateral", [0, 1, 3, 2])}
# the edges of VTK's (and XDMF's) quadratic cells, in the order of their midpoint nodes
QUADRATIC = {"tetrahedron": ("Tetrahedron_10", [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]),
             "triangle": ("Triangle_6", [(0, 1), (1, 2), (0, 2)])}


class MeshLayout:
    """The nodes of a mesh gathered on rank 0 in a rank-independent order, and the maps that gather
    point values (at the nodes) and cell values into that order (collective). ``degree`` 1: the
    vertices of a linear mesh; 2: the nodes of quadratic Lagrange elements (XDMF ``Tetrahedron_10``,
    ``Triangle_6``), so that a quadratic field keeps its values at the edge midpoints too (ParaView
    draws and integrates it on the quadratic cells) and a linear one is interpolated exactly."""

    def __init__(self, mesh, degree: int = 1):
        if mesh.geometry.cmaps[0].degree != 1:
            raise InputError("mesh", mesh.geometry.cmaps[0].degree, "field files need a linear mesh geometry")
        tdim, cell = mesh.topology.dim, mesh.topology.cell_name()
        kinds = CELLS if degree == 1 else QUADRATIC if degree == 2 else {}
        if cell not in kinds:
            raise InputError("mesh", f"{cell} of degree {degree}",
                             f"field files support {', '.join(kinds) or 'degrees 1 and 2'}")
        self.mesh, self.comm, self.degree, self.cell_type = mesh, mesh.comm, degree, kinds[cell][0]
        self.n_cells = mesh.topology.index_map(tdim).size_local
        x, corners = mesh.geometry.x, mesh.geometry.dofmaps[0]
        if degree == 1:
            self.n_nodes, self.xdofs = mesh.geometry.index_map().size_local, corners
            order = CELLS[cell][1]
        else:
            self.n_nodes, self.xdofs, x, order = quadratic_nodes(mesh, x[corners], kinds[cell][1])
        parts = self.comm.gather((x[:self.n_nodes], x[self.xdofs[:self.n_cells]]), root=0)
        self._spaces = {}
        io.collective(self.comm, lambda: self._order(parts, order) if self.comm.rank == 0 else None)

    def _order(self, parts, order) -> None:
        """On rank 0: the nodes sorted by coordinates, the cells by their nodes (``order``: the cell's
        node order -> XDMF/VTK order)."""
        nodes = np.concatenate([p[0] for p in parts])
        corners = np.concatenate([p[1] for p in parts])
        distinct = unique_rows(np.vstack([nodes, corners.reshape(-1, 3)]))
        unique, inverse = distinct.values, distinct.inverse
        if len(unique) != len(nodes):
            raise InputError("mesh", len(nodes), "nodes of the field mesh must have distinct coordinates")
        self.node_position = inverse[:len(nodes)]
        topology = inverse[len(nodes):].reshape(len(corners), -1)
        cells = np.lexsort(np.sort(topology, axis=1).T[::-1])
        self.cell_position = np.empty(len(cells), dtype=np.int64)
        self.cell_position[cells] = np.arange(len(cells))
        self.geometry = unique
        self.topology = topology[cells][:, order].astype(np.int64)


    def _gather(self, owned: np.ndarray, position_name: str):
        parts = self.comm.gather(owned, root=0)
        if self.comm.rank != 0:
            return None
        values = np.concatenate(parts)
        out = np.empty_like(values)
        out[getattr(self, position_name)] = values
        return out

    def point_values(self, f: fem.Function) -> np.ndarray | None:
        """Values of a Lagrange function at the layout's nodes (interpolated to its degree), on
        rank 0: (nodes,) or (nodes, components)."""
        shape = f.function_space.value_shape
        if shape not in self._spaces:
            V = fem.functionspace(self.mesh, ("Lagrange", self.degree, shape))
            node_dof = np.empty(int(self.xdofs.max(initial=-1)) + 1, dtype=np.int64)
            node_dof[self.xdofs] = V.dofmap.list
            self._spaces[shape] = (fem.Function(V), node_dof[:self.n_nodes])
        work, node_dof = self._spaces[shape]
        work.interpolate(f)
        bs = work.function_space.dofmap.bs
        return self._gather(components(work.x.array, bs)[node_dof], "node_position")

    def cell_values(self, f: fem.Function) -> np.ndarray | None:
        """Values of a DG0 function per cell, on rank 0."""
        bs = f.function_space.dofmap.bs
        dofs = f.function_space.dofmap.list[:self.n_cells, 0]
        return self._gather(components(f.x.array, bs)[dofs], "cell_position")


def quadratic_nodes(mesh, vertices: np.ndarray, edges) -> tuple:
    """The nodes of the scalar quadratic Lagrange space of ``mesh`` (vertices (cells, corners, 3) the
    cells' corner coordinates): owned count, cell dofmap, coordinates of every local dof, and the
    cell's dof order -> VTK order for its ``edges``. A midpoint is (x_a + x_b) / 2, the same bits
    from every cell and rank (``tabulate_dof_coordinates`` differs in the last bit between cells,
    and the ranks' copies of a node would not match)."""
    V = fem.functionspace(mesh, ("Lagrange", 2))
    cell_edges = [tuple(e) for e in basix.topology(V.element.basix_element.cell_type)[1]]
    n = vertices.shape[1]
    local = np.concatenate([vertices, np.stack([(vertices[:, a] + vertices[:, b]) / 2 for a, b in cell_edges],
                                               axis=1)], axis=1)
    dofs = V.dofmap.list
    x = np.empty((V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts, 3))
    x[dofs] = local
    order = list(range(n)) + [n + cell_edges.index(e) for e in edges]    # both list edges as (low, high)
    return V.dofmap.index_map.size_local, dofs, x, order

def components(values: np.ndarray, bs: int) -> np.ndarray:
    """A function's dof array as (dofs,) for a scalar, (dofs, bs) otherwise (``squeeze`` would also
    drop the first axis where a rank owns one node or cell)."""
    values = values.reshape(-1, bs)
    return values[:, 0] if bs == 1 else values


def is_cell_field(f: fem.Function) -> bool:
    """True for a DG0 function (written as cell data)."""
    return f.function_space.element.basix_element.degree == 0


def layout_degree(functions) -> int:
    """Degree of the layout of a set of functions of one mesh: 2 when one is quadratic (or more:
    its values at the quadratic nodes), else 1."""
    return 2 if any(f.function_space.element.basix_element.degree >= 2 for f in functions) else 1


class SeriesFile:
    """One XDMF/HDF5 time series of one mesh (rank 0 writes; see module docstring); ``parts``: the
    cells' part numbers (``outputs.PART_ARRAY``, in the layout's cell order; None: one part), kept
    once in ``/mesh/part`` and shown at every time; ``names``: {array: the names of its numbers 1,
    2, ...}, as string datasets ``/names/<array>`` (a reader finds which part or interface a number
    is without the console of ``multiscale check``: a user audit)."""

    def __init__(self, path: Path, layout: MeshLayout, parts: np.ndarray | None = None,
                 names: Mapping[str, Sequence[str]] | None = None):
        self.path, self.h5, self.layout, self.parts = Path(path), Path(path).with_suffix(".h5"), layout, parts
        self.names = dict(names or {})

    def start(self, resume_at: float | None = None) -> None:
        """Create the files (rank 0), or with ``resume_at`` [s] continue those of a run resumed from
        a checkpoint at that time: the times after it, written by the run that was killed, are dropped
        (the resumed run writes them again, once). A file that cannot be read (a run killed while
        writing it) is an OSError saying how to go on (it said only what HDF5 found)."""
        if resume_at is None or not self.h5.is_file():
            with h5py.File(self.h5, "w") as f:
                f.create_dataset("mesh/geometry", data=self.layout.geometry).attrs["unit"] = "m"
                f.create_dataset("mesh/topology", data=self.layout.topology).attrs["cell_type"] = self.layout.cell_type
                f.create_dataset("times", data=np.zeros(0), maxshape=(None,)).attrs["unit"] = "s"
                if self.parts is not None:
                    f.create_dataset("mesh/part", data=self.parts).attrs.update(name=PART_ARRAY, unit="-")
                for array, names in self.names.items():
                    f.create_dataset(f"names/{array}", data=list(names), dtype=h5py.string_dtype())
            self._mesh, self._grids = self._mesh_xml(self.parts is not None), []
            self._write_xml()
            return
        try:
            with h5py.File(self.h5, "r") as f:
                shape, times = f["mesh/geometry"].shape, f["times"][...]
                self._mesh = self._mesh_xml("mesh/part" in f)
                grids = [self._grid(k, t, f[f"data/{k}"] if f"data/{k}" in f else {}) for k, t in enumerate(times)]
        except (OSError, KeyError) as exc:
            raise OSError(f"{self.h5.name} is damaged ({exc}; a run killed while writing it?): delete it and "
                          f"{self.path.name} to resume without the fields it held, or start again with "
                          "--overwrite") from None
        if shape != self.layout.geometry.shape:
            raise OutputError(f"{self.h5} holds another mesh than this run's (resume with the same scene)")
        keep = int(np.argmin(np.append(times <= resume_at, False)))     # the leading run of such times (a junk
        #                                                                     time after them counted before: a review)
        self._grids = grids[:keep]
        if keep < len(times):
            with h5py.File(self.h5, "a") as f:
                for k in range(keep, len(times)):
                    if f"data/{k}" in f:
                        del f[f"data/{k}"]
                f["times"].resize((keep,))
            self._write_xml()

    def write(self, time: float, arrays: Mapping[str, tuple]) -> None:
        """Write ``arrays`` {field: (values, "Node" or "Cell")} at ``time`` (an existing time is
        replaced); rank 0 only. The index gets that time's grid alone: reading every time's
        datasets back for it took 5.6 ms per time already written (a 400-step run spent 80 % of
        its wall time there; a long-run trial)."""
        with h5py.File(self.h5, "a") as f:
            times = list(f["times"][...])
            k = times.index(time) if time in times else len(times)
            if k == len(times):
                f["times"].resize((k + 1,))
                f["times"][k] = time
            group = f.require_group(f"data/{k}")
            for field, (values, centre) in arrays.items():
                if field in group:
                    del group[field]
                d = group.create_dataset(field, data=values)
                d.attrs.update(name=array_name(field), unit=FIELDS[field][1], centre=centre)
            grid = self._grid(k, time, group)
        self._grids[k:k + 1] = [grid]
        self._write_xml()

    def _item(self, path: str, shape, kind: str = "Float") -> str:
        return (f'<DataItem Dimensions="{" ".join(str(s) for s in shape)}" NumberType="{kind}" Precision="8" '
                f'Format="HDF">{self.h5.name}:{path}</DataItem>')

    def _mesh_xml(self, parts: bool) -> str:
        """The mesh of every grid (and its part numbers, ``parts``)."""
        lay = self.layout
        cells = lay.topology.shape
        mesh = (f'<Topology TopologyType="{lay.cell_type}" NumberOfElements="{cells[0]}" '
                f'NodesPerElement="{cells[1]}">{self._item("/mesh/topology", cells, "Int")}</Topology>'
                f'<Geometry GeometryType="XYZ">{self._item("/mesh/geometry", lay.geometry.shape)}</Geometry>')
        if parts:
            mesh += (f'<Attribute Name={quoteattr(PART_ARRAY)} AttributeType="Scalar" Center="Cell">'
                     f'{self._item("/mesh/part", (cells[0],))}</Attribute>')
        return mesh

    def _grid(self, k: int, time: float, group) -> str:
        """The grid of time ``k`` holding the datasets of ``group`` (h5py group of /data/<k>)."""
        attrs = []
        for field, d in group.items():
            kind = "Scalar" if d.ndim == 1 else "Vector" if d.shape[1] == 3 else "Matrix"
            attrs.append(f'<Attribute Name={quoteattr(array_name(field))} AttributeType="{kind}" '
                         f'Center="{d.attrs["centre"]}">{self._item(f"/data/{k}/{field}", d.shape)}</Attribute>')
        return (f'<Grid Name="{self.path.stem}" GridType="Uniform"><Time Value="{float(time)!r}"/>' + self._mesh
                + "".join(attrs) + "</Grid>")

    def _write_xml(self) -> None:
        text = ('<?xml version="1.0"?>\n<Xdmf Version="3.0">\n<Domain>\n'
                f'<Grid Name="{self.path.stem}" GridType="Collection" CollectionType="Temporal">\n'
                + "\n".join(self._grids) + "\n</Grid>\n</Domain>\n</Xdmf>\n")
        with io.replacing(self.path) as part:
            part.write_text(text)


class FieldWriter:
    """Time series ``<folder>/<name>.xdmf`` (+ ``.h5``) of named meshes, each with its fields
    (``{field: Function}``, the keys among ``io.FIELDS``); ``resume_at`` [s]: continue the existing
    files of a run resumed from a checkpoint at that time (``SeriesFile.start``). Collective: a file
    that cannot be written or continued is an ``OutputError`` on every rank. ``parts``: {name: DG0
    function of its cells' part numbers} of the meshes of several parts; ``names``: {name: {array:
    names of its numbers}} (``SeriesFile``)."""

    def __init__(self, folder: Path, groups: Sequence[tuple], resume_at: float | None = None,
                 parts: Mapping[str, fem.Function] | None = None, names: Mapping[str, Mapping] | None = None):
        self.groups = []
        for name, mesh, functions in groups:
            if functions:
                layout = MeshLayout(mesh, layout_degree(functions.values()))
                numbers = layout.cell_values(parts[name]) if name in (parts or {}) else None
                self.groups.append((SeriesFile(Path(folder) / f"{name}.xdmf", layout, numbers,
                                               (names or {}).get(name)), dict(functions)))
        self.files = [s.path for s, _ in self.groups]
        if self.groups:
            io.on_root(self.groups[0][0].layout.comm, lambda: [s.start(resume_at) for s, _ in self.groups],
                       f"the field files in {folder}")

    def write(self, time: float) -> None:
        """Every group's fields at ``time`` [s] (collective; a failed write is an OutputError on every rank)."""
        written = []
        for series, functions in self.groups:
            lay = series.layout
            written.append((series, {k: (lay.cell_values(f), "Cell") if is_cell_field(f) else
                                     (lay.point_values(f), "Node") for k, f in functions.items()}))
        if self.groups:
            io.on_root(self.groups[0][0].layout.comm, lambda: [s.write(float(time), a) for s, a in written],
                       f"the fields at t = {time:g} s")


class FieldOutput:
    """The requested ``fields`` of a model (``tm``, ``mechanics``, optional ``thermal``), refreshed
    and written at each output time.

    ``extra``: {interface field name: callable returning its global per-facet array}, written when
    the name is among ``fields`` (they replace the built-in ones of the same name: the frictional
    ``heat_flux`` and ``partition``); ``resume_at`` [s]: continue the files of a run resumed at that
    time (``FieldWriter``)."""

    def __init__(self, model, folder: Path, fields, extra: Mapping[str, Callable] | None = None,
                 resume_at: float | None = None, mechanics=None, thermal=None):
        self.model = model
        tm = model.tm if model is not None else mechanics.tm
        mech = model.mechanics if model is not None else mechanics
        th = model.thermal if model is not None else thermal
        self.tm, self.mech, fields = tm, mech, list(fields)
        body = [{} for _ in tm.bodies]
        self.von_mises = []
        for i, b in enumerate(tm.bodies):
            if "displacement" in fields:
                body[i]["displacement"] = mech.u[i]
            if "temperature" in fields and th is not None:
                body[i]["temperature"] = th.T[i]
            if "von_mises" in fields:
                V = b.region_space
                f = fem.Function(V, name=f"von_mises_{b.name}")
                self.von_mises.append((f, fem.Expression(mech.von_mises(i), V.element.interpolation_points)))
                body[i]["von_mises"] = f
        contact = mech.contact
        makers = {"contact_pressure": lambda: contact.facet_pressure() * (contact.engaged.value != 0.0),   # 0 released
                  "friction_coefficient": lambda: tm.interface.values(contact.friction),   # its facets' own, fade
                  "interface": lambda: tm.interface.tag_index + 1.0}     # 1, 2, ... in the order of tm.interface.tags
        if th is not None:
            makers["heat_flux"] = contact.facet_heat_flux
            makers["partition"] = lambda: tm.interface.values(contact.partition)
        makers.update(extra or {})
        self.interface = [(tm.interface.field(name), make) for name, make in makers.items() if name in fields]
        groups = [(b.name, b.mesh, body[i]) for i, b in enumerate(tm.bodies)]
        groups.append(("interface", tm.interface.mesh, {f.name: f for f, _ in self.interface}))
        parts = {b.name: b.cell_field("part", {r.tag: float(k) for k, r in enumerate(b.spec.regions, 1)})
                 for b in tm.bodies if len(b.spec.regions) > 1}
        names = {b.name: {PART_ARRAY: [r.name for r in b.spec.regions]} for b in tm.bodies if b.name in parts}
        names["interface"] = {array_name("interface"): list(tm.interface.tags)} if "interface" in fields else {}
        self.writer = FieldWriter(folder, groups, resume_at=resume_at, parts=parts, names=names)
        self.files = self.writer.files
        self.body_fields = "displacement" in fields or bool(self.von_mises)   # a released state to write
        self._unloaded = None                   # its solver (``unloaded``), made on first use

    def write(self, time: float | None = None) -> None:
        """Refresh the derived fields and write them at ``time`` (default: the model's time). While
        the model's contact is released the bodies are written unloaded (``unloaded``); the
        displacements the next solve starts from are kept."""
        for f, make in self.interface:
            self.tm.interface.set_field(f, make())
        released = self.model is not None and self.model.released and self.body_fields
        kept = self.mech.displacements() if released else []
        try:
            self.mech.set_displacements(self.unloaded() if released else ())
            for f, expr in self.von_mises:
                f.interpolate(expr)
            self.writer.write(self.model.time if time is None else time)
        finally:
            self.mech.set_displacements(kept)

    def unloaded(self) -> list:
        """Per body, the displacement [m] written while released (and so the von Mises stress): the
        bodies under their supports alone, without contact and load: the thermo-elastic state of
        ``unloaded.Unloaded`` (one linear solve; without thermal expansion no strain and no solve:
        no load, zero supports, no body force), a part the supports leave free keeping the rigid
        motion of the last loaded state (without expansion it was set to 0 too: a car brake's pads
        jumped back in ParaView, a user trial), NaN with an ``UnloadedWarning`` if that fails (a
        mechanism beyond rigid motions). Collective."""
        if self._unloaded is None:
            self._unloaded = Unloaded(self.mech)
        out = self._unloaded.solve()
        if out is None:
            if self.tm.comm.rank == 0:
                why = self._unloaded.failure or ("did not converge (a part held by neither supports nor rigid "
                                                 "motions alone: two parts joined at an edge or a vertex?)")
                warnings.warn(UnloadedWarning(f"the released bodies' thermo-elastic state: {why}: their "
                                              "displacement and von Mises stress are written NaN"), stacklevel=2)
            return [np.nan] * len(self.mech.u)
        return out


def write_state(folder: Path, mechanics, fields) -> list[Path]:
    """The ``fields`` of one mechanical state (e.g. the squeal preload), at time 0; the files."""
    out = FieldOutput(None, folder, fields, mechanics=mechanics)
    out.write(0.0)
    return out.files


def write_modes(folder: str | Path, result, functions: Sequence, names: Sequence[str],
                modes: Sequence[int] | None = None) -> list[Path]:
    """Mode shapes of ``result`` (``eigen.ModalResult``) to ``<folder>/modes_<name>.bp`` (VTX, one
    per body): arrays "mode shape real part" and "... imaginary part" [1/kg^0.5] on the space of
    the displacement, "time" = mode number (1, 2, ...), each mode's sign that of ``orientation``
    (the eigensolver's is arbitrary: the same mode was written as +phi or -phi by runs on other
    ranks), on each rank's owned cells (``owned_space``). Collective; returns the written paths.

    ``functions`` are displacement Functions of the bodies in the block order of the matrices (the
    owned dofs of body 0, then of body 1, ... on each rank)."""
    folder = Path(folder)
    sel = range(1, len(result) + 1) if modes is None else modes
    sizes = [u.function_space.dofmap.bs * u.function_space.dofmap.index_map.size_local for u in functions]
    if sum(sizes) != result.modes.shape[0]:
        raise InputError("functions", len(functions), "must span the dof layout of the modes")
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    sign = orientation(result.modes, functions, sizes)
    files = []
    for k, (u, name) in enumerate(zip(functions, names)):
        V = u.function_space
        W, cells = owned_space(V)
        into = np.arange(len(cells), dtype=np.int32)
        shape = fem.Function(V)
        parts = tuple(fem.Function(W, name=name) for name in MODE_ARRAYS)
        out = folder / f"modes_{name}.bp"
        with VTXWriter(V.mesh.comm, out, list(parts), engine="BP4", mesh_policy=VTXMeshPolicy.reuse) as w:
            for j in sel:
                block = sign[j - 1] * result.modes[offsets[k]:offsets[k + 1], j - 1]
                for f, values in zip(parts, (block.real, block.imag)):
                    shape.x.array[:sizes[k]] = values
                    shape.x.scatter_forward()
                    f.interpolate(shape, cells0=cells, cells1=into)
                w.write(float(j))
        files.append(out)
    return files


def owned_space(V):
    """The space of V's element on the cells each rank owns, and those cells in V's mesh. VTX
    writes every local cell, ghosts too, with no cell ghost mark (DOLFINx 0.11): on 2 ranks the
    car brake's mode files held 122 of 5877 cells twice, and a mass integral of a mode read from
    them gave up to 1.053 instead of 1 (a user audit)."""
    mesh = V.mesh
    tdim = mesh.topology.dim
    owned = np.arange(mesh.topology.index_map(tdim).size_local, dtype=np.int32)
    sub, cell_map, _, _ = dmesh.create_submesh(mesh, tdim, owned)
    cells = cell_map.sub_topology_to_topology(np.arange(len(owned), dtype=np.int32), inverse=False)
    return fem.functionspace(sub, V.ufl_element()), cells.astype(np.int32)


def orientation(modes: np.ndarray, functions: Sequence, sizes: Sequence[int]) -> np.ndarray:
    """Per mode (column of ``modes``: owned dofs of the bodies' ``functions`` in block order, ``sizes``
    each), the sign +-1 that makes sum Re(phi) w positive, w = sin(k . x / L + 1.1 c + 0.37) a
    fixed weight of each dof's point x [m] and component c, L the bodies' largest extent: the same
    sign on any partition and for a mirrored shape (collective)."""
    weights, lo, hi = [], np.full(3, np.inf), np.full(3, -np.inf)
    for u, n in zip(functions, sizes):
        V = u.function_space
        bs = V.dofmap.bs
        x = V.tabulate_dof_coordinates()[:n // bs]
        lo, hi = np.minimum(lo, x.min(axis=0, initial=np.inf)), np.maximum(hi, x.max(axis=0, initial=-np.inf))
        weights.append((x, bs))
    comm = functions[0].function_space.mesh.comm
    extent = [comm.allreduce(float(h), op=MPI.MAX) - comm.allreduce(float(g), op=MPI.MIN) for g, h in zip(lo, hi)]
    L = max(max(extent), np.finfo(float).tiny)      # (an array's allreduce with MAX fails on 2 ranks)
    w = np.concatenate([np.sin((x @ np.array([7.31, 11.93, 5.17]) / L)[:, None] + 1.1 * np.arange(bs) + 0.37).ravel()
                        for x, bs in weights])
    total = comm.allreduce(w @ modes.real)
    return np.where(total < 0, -1.0, 1.0)

