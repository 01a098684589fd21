"""Two deformable bodies and their conforming interface in one DOLFINx mesh.

One parent mesh (gmsh, shared-facet ghosting) holds both bodies; each body is a codim-0 submesh
(its function spaces live there), the interface a codim-1 submesh (per-facet DG0 fields live
there). Every integral is written on the parent: ``dx(tag)`` over material regions, ``ds(tag)`` on
named faces, and the interface measure ``dS`` whose integration rows are reordered so that "+"
is always body 0 and "−" body 1 (DOLFINx orders them arbitrarily). Forms get
``entity_maps=tm.entity_maps``.

Per-facet data are keyed by a global facet index that does not depend on the number of MPI ranks:
facets sorted lexicographically by their (rounded) midpoints. ``Interface.midpoints`` (global,
every rank) tells which facet is which.

``TwoBodyMesh.notes`` says what the run's warnings should: interfaces and load faces whose meshes
cover less (or more) than their faces (``macro.coverage``).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from types import ModuleType

import numpy as np

import dolfinx
import ufl
from dolfinx import fem, geometry, la
from dolfinx import mesh as dmesh
from mpi4py import MPI

from multiscale.errors import InputError, MultiscaleError
from multiscale.geometry import CROSSES, BodySpec, GeometrySpec, check_cells, crossed, gmsh_session
from multiscale.macro.coverage import coverage_notes, face_coverage
from multiscale.held import check_held


INTERFACE_QUADRATURE = 2      # exact for P1 displacements times P1 tests on a facet




@dataclass
class Crossing:
    """Where a rigid motion w crosses a surface of triangles (``crossing``)."""

    share: float          # share of the surface, weighted by the speed |w|, with |w.n| > CROSSES |w| [-]
    worst: float          # largest |w.n|/|w| of a triangle [-]
    where: np.ndarray     # centroid of that triangle [m]


def vector_areas(triangles: np.ndarray) -> np.ndarray:
    """Vector areas [m^2] of straight-sided triangles (n, 3, 3) [m]: half the cross product of
    two edges, (n, 3), along the normal of the vertices' right-hand order."""
    x = np.asarray(triangles, dtype=float).reshape(-1, 3, 3)
    return 0.5 * np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])


def _attached_cells(f2c, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(number of cells, first cell) of each of ``facets`` by the facet-to-cell connectivity ``f2c``
    (one cell: an exterior facet)."""
    offsets = f2c.offsets
    return offsets[facets + 1] - offsets[facets], f2c.array[offsets[facets]].astype(np.int32)


def crossing(triangles: np.ndarray, motion, comm) -> Crossing:
    """How much of a surface, the (owned) ``triangles`` (n, 3, 3) [m] of every rank, the rigid
    ``motion`` crosses: |w.n| > ``CROSSES`` |w| at a triangle's centroid (collective)."""
    x = np.asarray(triangles, dtype=float).reshape(-1, 3, 3)
    n = vector_areas(x)
    mid = x.mean(axis=1)
    cos, weight = crossed(mid, n, np.linalg.norm(n, axis=1), motion)
    sums = comm.allreduce(np.array([weight[cos > CROSSES].sum(), weight.sum()]), op=MPI.SUM)
    k = int(np.argmax(cos)) if len(cos) else -1
    worst, where = max(comm.allgather((cos[k], tuple(mid[k])) if k >= 0 else (-1.0, (np.nan,) * 3)))
    return Crossing(float(sums[0] / sums[1]) if sums[1] > 0 else 0.0, float(worst), np.array(where))


def bounds(x: np.ndarray, comm) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners of the points ``x`` (n, d) of every rank (collective; inf and -inf
    where no rank has one)."""
    lo, hi = np.empty(x.shape[1]), np.empty(x.shape[1])
    comm.Allreduce(x.min(axis=0, initial=np.inf), lo, op=MPI.MIN)
    comm.Allreduce(x.max(axis=0, initial=-np.inf), hi, op=MPI.MAX)
    return lo, hi


def swept_area(lo, hi) -> float:
    """Area [m^2] of the surface of revolution over the (radius r, axial position a) box ``lo``,
    ``hi`` of what sweeps it (``Interface.box`` about the axis): the frustum pi (r_lo + r_hi)
    sqrt((r_hi - r_lo)^2 + (a_hi - a_lo)^2) — a disc's annular track pi (r_hi^2 - r_lo^2), a
    drum's band 2 pi r (a_hi - a_lo)."""
    return float(np.pi * (lo[0] + hi[0]) * np.hypot(hi[0] - lo[0], hi[1] - lo[1]))


@dataclass
class Body:
    """One body: its submesh and the maps to the parent mesh."""

    spec: BodySpec
    mesh: dmesh.Mesh
    cell_map: dmesh.EntityMap          # submesh cells -> parent cells
    vertex_map: dmesh.EntityMap
    facet_tags: dmesh.MeshTags         # parent facet tags moved to the submesh
    region_tags: np.ndarray            # region (cell) tag of every local submesh cell

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def owned_parent_cells(self) -> np.ndarray:
        """Parent-mesh indices of the body's owned cells (sorted)."""
        n = self.mesh.topology.index_map(self.mesh.topology.dim).size_local
        return np.sort(self.cell_map.sub_topology_to_topology(np.arange(n, dtype=np.int32), inverse=False))

    @property
    def region_space(self) -> fem.FunctionSpace:
        return fem.functionspace(self.mesh, ("DG", 0))

    def region_cells(self, by: str) -> dict:
        """{group: mask of the local cells} of the regions grouped by their ``by``: "material", or
        "name" (a geometry file's parts, a brake's pads), in the regions' order."""
        groups = dict.fromkeys(getattr(r, by) for r in self.spec.regions)
        return {g: np.isin(self.region_tags, [r.tag for r in self.spec.regions if getattr(r, by) == g]) for g in groups}

    def cell_field(self, name: str, by_region: dict) -> fem.Function:
        """DG0 field on the body, constant per region: ``by_region`` maps region tag -> value."""
        f = fem.Function(self.region_space, name=name)
        values = np.full(len(self.region_tags), np.nan)
        for tag, value in by_region.items():
            values[self.region_tags == tag] = value
        if np.isnan(values).any():
            missing = sorted(set(self.region_tags[np.isnan(values)]) - set(by_region))
            raise InputError(name, by_region, f"a value for every region of {self.name!r} (missing tags {missing})")
        f.x.array[self.region_space.dofmap.list[:, 0]] = values
        return f

    def crossing(self, motion) -> Crossing:
        """Where the rigid ``motion`` (a ``Rotation`` or ``Translation``) crosses the body's
        surface: for a rotation, how far it departs from a surface of revolution (vanes, holes,
        slots; a faceted circle stays below 0.08 at the demos' meshes). Collective."""
        m, tdim = self.mesh, self.mesh.topology.dim
        m.topology.create_connectivity(tdim - 1, tdim)
        facets = dmesh.exterior_facet_indices(m.topology)
        facets = facets[facets < m.topology.index_map(tdim - 1).size_local]       # owned: each once
        return crossing(m.geometry.x[dmesh.entities_to_geometry(m, tdim - 1, facets)], motion, m.comm)

    def box(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners (3-vectors) [m] of the body's nodes (collective)."""
        return bounds(self.mesh.geometry.x, self.mesh.comm)

    def has_face(self, tag: int) -> bool:
        """True if the face ``tag`` belongs to this body (on any rank)."""
        return bool(self.mesh.comm.allreduce(len(self.facet_tags.find(tag)), op=MPI.SUM))


@dataclass
class Interface:
    """The contact interface: a facet submesh, its measure and a rank-independent facet ordering.

    ``dS`` integrates over all interfaces ("+" = body 0); ``dS_tag[name]`` over one. The measure's
    subdomain ids are the interfaces' positions in ``tags`` (0, 1, ...), not the geometry's tags: a
    tag is a number of the compiled form, and scenes whose interfaces are tagged otherwise share it.
    ``midpoints`` (n_facets, 3), ``areas`` (n_facets,) and ``tag_index`` (n_facets,: position of
    each facet's tag in ``tags``) are global and the same on every rank; ``owned_index`` gives the
    global index of each owned facet of the submesh.
    """

    mesh: dmesh.Mesh
    facet_map: dmesh.EntityMap         # submesh cells -> parent facets
    tags: dict
    measure: ufl.Measure
    midpoints: np.ndarray              # m, global
    areas: np.ndarray                  # m^2, global
    owned_index: np.ndarray            # global index of the owned submesh cells 0..n_owned-1
    tag_index: np.ndarray              # global: index into ``tags`` of every facet
    plus_regions: dict                 # interface name -> region (cell) tags of body 0 along it
    _dg0: fem.FunctionSpace = field(default=None, repr=False)
    _dg0_blocked: dict = field(default_factory=dict, repr=False)

    @property
    def dS(self):
        return self.measure(tuple(range(len(self.tags))))

    @property
    def dS_tag(self) -> dict:
        return {name: self.measure(k) for k, name in enumerate(self.tags)}

    @property
    def n_facets(self) -> int:
        return len(self.midpoints)

    @property
    def comm(self):
        return self.mesh.comm

    @property
    def space(self) -> fem.FunctionSpace:
        """DG0 space of per-facet fields."""
        if self._dg0 is None:
            self._dg0 = fem.functionspace(self.mesh, ("DG", 0))
        return self._dg0

    def blocked_space(self, components: int) -> fem.FunctionSpace:
        """DG0 space of per-facet arrays of ``components`` values."""
        if components not in self._dg0_blocked:
            self._dg0_blocked[components] = fem.functionspace(self.mesh, ("DG", 0, (components,)))
        return self._dg0_blocked[components]

    def masks(self) -> dict:
        """{interface name: boolean mask over the global facets}."""
        return {name: self.tag_index == k for k, name in enumerate(self.tags)}

    def crossing(self, name: str, motion) -> Crossing:
        """Where body 1's rigid ``motion`` crosses interface ``name`` instead of sliding along it
        (``crossing``; collective)."""
        return crossing(self._owned_nodes(name), motion, self.comm)

    def _owned_nodes(self, name: str) -> np.ndarray:
        """Nodes (facets, nodes, 3) [m] of the owned facets of interface ``name``."""
        owned = self.tag_index[self.owned_index] == list(self.tags).index(name)
        return self.mesh.geometry.x[self.mesh.geometry.dofmaps[0][:len(self.owned_index)][owned]]

    def triangles(self, name: str) -> np.ndarray:
        """Corners (facets, 3, 3) [m] of every facet of interface ``name``, in no particular order, the
        same on every rank (collective)."""
        return np.concatenate(self.comm.allgather(self._owned_nodes(name)[:, :3])).reshape(-1, 3, 3)

    def box(self, name: str, axis=None, centre=None) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners (3-vectors) [m] of the vertices of interface ``name`` (collective);
        with ``axis`` (unit vector) and ``centre``: of their (radius, axial position) about that axis."""
        x = self._owned_nodes(name).reshape(-1, 3)
        if axis is not None:
            e, x = np.asarray(axis, dtype=float) / np.linalg.norm(axis), x - np.asarray(centre, dtype=float)
            a = x @ e
            x = np.column_stack([np.linalg.norm(x - np.outer(a, e), axis=1), a])
        return bounds(x, self.comm)

    def distance(self, points) -> float:
        """The least distance [m] from ``points`` (n, 3) [m] to a facet of the interfaces (collective)."""
        m, tdim = self.mesh, self.mesh.topology.dim
        owned = np.arange(len(self.owned_index), dtype=np.int32)
        d = np.inf
        if len(owned):
            points = np.asarray(points, dtype=float)
            near = geometry.compute_closest_entity(geometry.bb_tree(m, tdim, entities=owned),
                                                   geometry.create_midpoint_tree(m, tdim, owned), m, points)
            d = float(np.sqrt(geometry.squared_distance(m, tdim, near, points).min()))
        return self.comm.allreduce(d, op=MPI.MIN)

    def _owned_dofs(self, space=None) -> np.ndarray:
        n = len(self.owned_index)
        return (space or self.space).dofmap.list[:n, 0]

    def field(self, name: str, value=0.0) -> fem.Function:
        """A new per-facet (DG0) field set to ``value`` (scalar or global per-facet array)."""
        f = fem.Function(self.space, name=name)
        self.set_field(f, value)
        return f

    def set_field(self, f: fem.Function, value) -> None:
        """Set a DG0 field from a scalar or a global per-facet array (length n_facets)."""
        value = np.asarray(value, dtype=float)
        if value.ndim == 0:
            f.x.array[:] = value
        else:
            if value.shape != (self.n_facets,):
                raise InputError(f.name, value.shape, f"one value per interface facet ({self.n_facets})")
            f.x.array[self._owned_dofs()] = value[self.owned_index]
        f.x.scatter_forward()

    def values(self, f: fem.Function) -> np.ndarray:
        """Global per-facet array of a DG0 field (every rank)."""
        return self.gather(f.x.array[self._owned_dofs()])

    def gather(self, owned: np.ndarray) -> np.ndarray:
        """Global per-facet array (n_facets, ...) from the values of the owned facets (every rank)."""
        owned = np.asarray(owned, dtype=float)
        parts = self.comm.allgather(owned)
        index = np.concatenate(self.comm.allgather(self.owned_index))
        out = np.empty((self.n_facets,) + owned.shape[1:])
        out[index] = np.concatenate(parts)
        return out

    def owned_values(self, vec, space=None) -> np.ndarray:
        """Global per-facet array from a vector assembled on ``space`` (DG0 scalar or vector)."""
        space = space or self.space
        vec.scatter_reverse(dolfinx.la.InsertMode.add)
        values = vec.array.reshape(-1, space.dofmap.bs)[self._owned_dofs(space)]
        return self.gather(values if space.dofmap.bs > 1 else values[:, 0])


@dataclass
class TwoBodyMesh:
    """Parent mesh, its tags, the two bodies and the interface (see module docstring)."""

    spec: GeometrySpec
    parent: dmesh.Mesh
    cell_tags: dmesh.MeshTags
    facet_tags: dmesh.MeshTags
    bodies: tuple[Body, Body]
    interface: Interface
    notes: tuple = ()                  # what the run's warnings add (module docstring)
    sole_holds: dict = field(default_factory=dict)   # interface -> the parts only it holds (``held.check_held``)
    _bodies_dx: ufl.Measure = field(init=False, repr=False)

    def __post_init__(self):
        self._bodies_dx = ufl.Measure("dx", domain=self.parent,
                                      subdomain_data=[(i, b.owned_parent_cells) for i, b in enumerate(self.bodies)])

    @property
    def comm(self):
        return self.parent.comm

    def body_dx(self, i: int, degree: int | None = None, scheme: str | None = None) -> ufl.Measure:
        """Volume measure of body ``i`` (optionally a quadrature degree and scheme). Its subdomain
        ids are the bodies' indices (0, 1), not the geometry's region tags: a tag is a number of the
        compiled form, and scenes whose regions are tagged otherwise share it."""
        return self._bodies_dx(i, degree=degree, scheme=scheme)

    @property
    def entity_maps(self) -> list:
        return [self.bodies[0].cell_map, self.bodies[1].cell_map, self.interface.facet_map]

    @property
    def dx(self) -> ufl.Measure:
        """Volume measure of the geometry's region tags (``body_dx``: of a body)."""
        return ufl.Measure("dx", domain=self.parent, subdomain_data=self.cell_tags)

    @property
    def ds(self) -> ufl.Measure:
        return ufl.Measure("ds", domain=self.parent, subdomain_data=self.facet_tags)

    def face(self, name: str) -> int:
        """Facet tag of the named face."""
        if name not in self.spec.faces:
            raise InputError("face", name, f"one of {', '.join(self.spec.faces)}")
        return self.spec.faces[name]

    def surface(self, name: str) -> ufl.Measure:
        """Boundary measure of a named surface: a named face (``ds(tag)``), or "free:<region or body>"
        (a region first: the pin-on-disc's "free:pin" is its pin, not housing and plate too), every
        exterior facet bounding its cells (touching nothing else: not the interfaces, not the faces
        bonded to another part) but its symmetry planes (``GeometrySpec.symmetry``: the model's cut)."""
        if not name.startswith("free:"):
            return self.ds(self.face(name))
        who = name[len("free:"):]
        tags = [r.tag for b in self.bodies for r in b.spec.regions if r.name == who] or \
            [r.tag for b in self.bodies if b.name == who for r in b.spec.regions]
        if not tags:
            known = [b.name for b in self.bodies] + [r.name for b in self.bodies for r in b.spec.regions]
            raise InputError("surfaces", name, f"free:<region or body>, one of {', '.join(dict.fromkeys(known))}")
        tdim = self.parent.topology.dim
        facets = dmesh.exterior_facet_indices(self.parent.topology)
        cells = _attached_cells(self.parent.topology.connectivity(tdim - 1, tdim), facets)[1]
        region = np.full(self.parent.topology.index_map(tdim).size_local
                         + self.parent.topology.index_map(tdim).num_ghosts, -1)
        region[self.cell_tags.indices] = self.cell_tags.values
        cut = self.facet_tags.indices[np.isin(self.facet_tags.values, [self.face(n) for n in self.spec.symmetry])]
        chosen = facets[np.isin(region[cells], tags) & ~np.isin(facets, cut)].astype(np.int32)
        rows = fem.compute_integration_domains(fem.IntegralType.exterior_facet, self.parent.topology, chosen)
        return ufl.Measure("ds", domain=self.parent, subdomain_data=[(1, np.asarray(rows, dtype=np.int32))])(1)

    def face_vector_areas(self, name: str) -> np.ndarray:
        """Vector area n dA [m^2] of each owned facet of the named face (n, 3): its area times its
        unit normal out of the mesh, what ``ufl.FacetNormal`` on ``ds(tag)`` integrates. Exact:
        the model is meshed with linear tetrahedra (straight-sided triangles, a constant normal), so
        no form is compiled for the geometry of a face (one per face and component compiled ~0.4 s
        each; forms differ by the face's tag alone). This rank's facets; sums need an allreduce."""
        m, tdim = self.parent, self.parent.topology.dim
        facets = self.facet_tags.find(self.face(name))
        facets = facets[facets < m.topology.index_map(tdim - 1).size_local]      # owned: each once
        count, cells = _attached_cells(m.topology.connectivity(tdim - 1, tdim), facets)
        facets, cells = facets[count == 1], cells[count == 1]                              # what ds sees
        x = m.geometry.x[dmesh.entities_to_geometry(m, tdim - 1, facets)]                     # (n, 3, 3)
        inside = m.geometry.x[dmesh.entities_to_geometry(m, tdim, cells)].mean(axis=1)    # a point of the cell
        n = vector_areas(x)
        return np.where((((inside - x[:, 0]) * n).sum(axis=1) > 0)[:, None], -n, n)

    def inner_facets(self, name: str) -> int:
        """Number of the named face's facets between two cells (bonded parts; no ``ds`` sees them),
        over every rank (collective)."""
        m, tdim = self.parent, self.parent.topology.dim
        facets = self.facet_tags.find(self.face(name))
        count = _attached_cells(m.topology.connectivity(tdim - 1, tdim), facets[facets < m.topology.index_map(
            tdim - 1).size_local])[0]
        return self.comm.allreduce(int((count == 2).sum()), op=MPI.SUM)

    def body_of_face(self, name: str) -> int:
        """Index of the body that holds the named (load) face; a face on no body's surface (an
        interface, a face between two parts, or one another surface of the scene already names)
        or on both is an InputError (collective)."""
        tag = self.face(name)
        owners = [i for i, b in enumerate(self.bodies) if b.has_face(tag)]
        if len(owners) != 1:
            where = ("is on no body's free surface: an interface, a face between two parts, or a face "
                     "another surface already names" if not owners else "lies on both bodies")
            raise InputError("loading.faces", name, f"the load face {where}; name a free face of one body")
        return owners[0]

    def assemble_scalar(self, expr) -> float:
        """Integral of a scalar form over the whole parent mesh, summed over ranks (compiles it)."""
        return FormCache(self).scalar(None, lambda: expr)


class FormCache:
    """Compiled diagnostic forms of a TwoBodyMesh, built once per key and reassembled on demand."""

    def __init__(self, tm: TwoBodyMesh):
        self.tm = tm
        self.forms: dict = {}

    def _form(self, key, make):
        if key is None or key not in self.forms:
            compiled = fem.form(make(), entity_maps=self.tm.entity_maps)
            if key is None:
                return compiled
            self.forms[key] = compiled
        return self.forms[key]

    def scalar(self, key, make) -> float:
        """Integral of the scalar form ``make()`` (summed over ranks)."""
        local = fem.assemble_scalar(self._form(key, make))
        return self.tm.comm.allreduce(local, op=MPI.SUM)

    def vector(self, key, make) -> np.ndarray:
        """Local array (owned and ghost entries) of the vector form ``make()`` assembled, the ghost
        contributions added to their owners."""
        vec = fem.assemble_vector(self._form(key, make))
        vec.scatter_reverse(la.InsertMode.add)
        return vec.array

    def facet_integrals(self, key, make, components: int = 1) -> np.ndarray:
        """Global per-facet integrals of the interface expression ``make()``: (n_facets,) for a
        scalar, (n_facets, components) for a vector of ``components``."""
        iface = self.tm.interface
        space = iface.space if components == 1 else iface.blocked_space(components)
        q = ufl.TestFunction(space)
        form = self._form(None if key is None else ("per facet", key),
                          lambda: ufl.inner(make(), q("+")) * iface.dS)
        return iface.owned_values(fem.assemble_vector(form), space)


def build(builder: ModuleType, params=None, comm=MPI.COMM_WORLD, spec: GeometrySpec | None = None,
          max_cells: int | None = None, sliding: bool = False, pressed: bool = True) -> TwoBodyMesh:
    """Run a gmsh builder (``multiscale.geometry``) on rank 0 and distribute the mesh (shared-facet
    ghosting); ``spec`` (default: the builder's ``describe``) tags bodies, faces and interfaces.
    With ``max_cells``, a mesh estimated larger is refused before meshing (``check_cells``: an
    InputError on every rank); the trial meshes and the mesh share one gmsh session (a CAD file is
    read once). ``sliding`` (friction): the interfaces do not hold body 1 in its motion
    (``check_held``). ``pressed``: the load faces take a given pressure, whose force their faceting
    lowers (said in ``notes``); a force spread over them is applied whole (False: not said)."""
    spec = spec or builder.describe(params)
    name = getattr(builder, "NAME", builder.__name__)
    error, coverage, alone = None, ({}, {}), {}
    if comm.rank == 0:
        import gmsh   # rank 0 alone builds the geometry
        try:
            if max_cells is not None:
                check_cells(builder, params, max_cells, keep=True,    # its trials' session holds the mesh
                            length_scale=spec.length_scale)
            else:
                gmsh_session(builder)
                builder.generate(gmsh.model, params)
            alone = check_held(gmsh.model, spec, sliding)
            coverage = face_coverage(gmsh.model, spec if pressed else replace(spec, load_faces=()))
        except Exception as exc:  # re-raised on every rank below
            error = exc
    failed = comm.bcast(error if isinstance(error, MultiscaleError) else repr(error) if error is not None else None,
                        root=0)
    try:
        if isinstance(failed, MultiscaleError):
            raise failed
        if failed:
            if error is not None:
                raise error
            raise RuntimeError(f"mesh builder {name!r} failed on rank 0: {failed}")
        partitioner = dmesh.create_cell_partitioner(dolfinx.graph.partitioner(),
                                                    dmesh.GhostMode.shared_facet, 2)
        model = gmsh.model if comm.rank == 0 else None
        data = dolfinx.io.gmsh.model_to_mesh(model, comm, 0, gdim=3, partitioner=partitioner)
    finally:
        if comm.rank == 0 and gmsh.isInitialized():
            gmsh.finalize()
    tm = from_mesh(spec, data.mesh, data.cell_tags, data.facet_tags)
    coverage, alone = comm.bcast((coverage, alone) if comm.rank == 0 else None, root=0)
    return replace(tm, notes=coverage_notes(tm, coverage), sole_holds=alone)


def from_mesh(spec: GeometrySpec, parent: dmesh.Mesh, cell_tags: dmesh.MeshTags,
              facet_tags: dmesh.MeshTags) -> TwoBodyMesh:
    """Bodies and interface of a parent mesh tagged according to ``spec``."""
    tdim = parent.topology.dim
    parent.topology.create_connectivity(tdim - 1, tdim)
    parent.topology.create_connectivity(tdim, tdim - 1)
    bodies = tuple(_body(parent, cell_tags, facet_tags, b) for b in spec.bodies)
    interface = _interface(parent, cell_tags, facet_tags, spec, bodies)
    return TwoBodyMesh(spec, parent, cell_tags, facet_tags, bodies, interface)


def _body(parent, cell_tags, facet_tags, spec: BodySpec) -> Body:
    tdim = parent.topology.dim
    cells = np.unique(np.concatenate([cell_tags.find(r.tag) for r in spec.regions])).astype(np.int32)
    sub, cell_map, vertex_map, _ = dmesh.create_submesh(parent, tdim, cells)
    sub.topology.create_connectivity(tdim - 1, tdim)
    tags = dmesh.transfer_meshtags_to_submesh(facet_tags, sub, vertex_map, cell_map)
    tags = tags[0] if isinstance(tags, tuple) else tags
    n_cells = sub.topology.index_map(tdim).size_local + sub.topology.index_map(tdim).num_ghosts
    parent_cells = cell_map.sub_topology_to_topology(np.arange(n_cells, dtype=np.int32), inverse=False)
    tag_of = np.full(parent.topology.index_map(tdim).size_local + parent.topology.index_map(tdim).num_ghosts, -1)
    tag_of[cell_tags.indices] = cell_tags.values
    return Body(spec, sub, cell_map, vertex_map, tags, tag_of[parent_cells])


def _interface(parent, cell_tags, facet_tags, spec: GeometrySpec, bodies) -> Interface:
    tdim = parent.topology.dim
    comm = parent.comm
    facets = {name: facet_tags.find(tag) for name, tag in spec.interfaces.items()}
    all_facets = np.unique(np.concatenate(list(facets.values()))).astype(np.int32)
    sub, facet_map, _, _ = dmesh.create_submesh(parent, tdim - 1, all_facets)
    data, plus = [], {}
    n_owned = sub.topology.index_map(tdim - 1).size_local
    tag_of_cell = np.full(n_owned, -1)
    region_of = np.full(parent.topology.index_map(tdim).size_local + parent.topology.index_map(tdim).num_ghosts, -1)
    region_of[cell_tags.indices] = cell_tags.values
    for k, name in enumerate(spec.interfaces):
        cells = facet_map.sub_topology_to_topology(facets[name].astype(np.int32), inverse=True)
        cells = cells[(cells >= 0) & (cells < n_owned)]
        tag_of_cell[cells] = k
        rows = fem.compute_integration_domains(fem.IntegralType.interior_facet, parent.topology,
                                               facets[name].astype(np.int32))
        rows = _orient(np.asarray(rows, dtype=np.int32).reshape(-1, 4), bodies, name)
        data.append((k, rows.ravel()))         # ids 0, 1, ...: scenes of other tags share the forms
        plus[name] = tuple(sorted(set().union(*comm.allgather(set(region_of[rows[:, 0]].tolist())))))
    measure = ufl.Measure("dS", domain=parent, subdomain_data=data,
                          metadata={"quadrature_degree": INTERFACE_QUADRATURE})
    # vertex coordinates summed in sorted order: a midpoint independent of the partition's vertex
    # order (compute_midpoints' sums differed in the last bit between 1 and 2 ranks, which moved a
    # facet on a zone border into the next zone)
    corners = sub.geometry.x[dmesh.entities_to_geometry(sub, tdim - 1, np.arange(n_owned, dtype=np.int32))]
    mid_local = np.sort(corners, axis=1).mean(axis=1)
    midpoints = np.concatenate(comm.allgather(mid_local)).reshape(-1, 3)
    areas = np.concatenate(comm.allgather(np.linalg.norm(vector_areas(sub.geometry.x[sub.geometry.dofmaps[0][:n_owned]]),
                                                         axis=1)))
    counts = comm.allgather(n_owned)
    key = np.round(midpoints / spec.length_scale, 9)
    order = np.lexsort(key.T[::-1])                  # sort by x, then y, then z
    rank_of_sorted = np.empty_like(order)
    rank_of_sorted[order] = np.arange(len(order))
    start = int(np.sum(counts[:comm.rank]))
    owned_index = rank_of_sorted[start:start + n_owned]
    tag_index = np.empty(len(order), dtype=int)
    tag_index[np.concatenate(comm.allgather(owned_index))] = np.concatenate(comm.allgather(tag_of_cell))
    return Interface(sub, facet_map, dict(spec.interfaces), measure, midpoints[order], areas[order], owned_index,
                     tag_index, plus)


def _orient(rows: np.ndarray, bodies, name: str) -> np.ndarray:
    """Swap the two sides of each interior-facet row so that "+" (first pair) lies in body 0."""
    inside0 = bodies[0].cell_map.sub_topology_to_topology(rows[:, 0], inverse=True) >= 0
    rows = rows.copy()
    rows[~inside0] = rows[~inside0][:, [2, 3, 0, 1]]
    ok0 = bodies[0].cell_map.sub_topology_to_topology(rows[:, 0], inverse=True) >= 0
    ok1 = bodies[1].cell_map.sub_topology_to_topology(rows[:, 2], inverse=True) >= 0
    if not (ok0.all() and ok1.all()):
        raise RuntimeError(f"interface {name!r} has facets that do not separate "
                           f"{bodies[0].name!r} from {bodies[1].name!r}")
    return rows
