"""Rigid motions a meshed geometry leaves free, found before anything is solved.

A part is a set of one body's cells joined through shared faces. Each part has six rigid motions:
translations along x, y, z and rotations about x, y, z through its centre. They are held by:

- a support: the components it fixes, at every node of its face;
- an interface: the normal component of the motion of the part on one side relative to the part
  on the other (penalty contact, thesis §1.4); friction holds nothing, and with friction no
  interface holds a part in body 1's motion along it, however the mesh facets a curved interface;
- a joint, a node shared by two parts of one body (along an edge or at a vertex): their relative
  translation there, not a rotation about it.

With r(x, d) = [d, ((x − c)/L) × d] the work-conjugate of the motions along direction d at point x
(c the centre of the part's bounding box, L its largest side), the holding matrix
N = sum_rows w r r^T (w the area [m^2] a node stands for; at a joint, the squared size of its
cells) is singular exactly in the motions nothing holds.

Why (adversarial tests): a singular stiffness made the first Newton solve of two pads without side
supports fail on one machine and end 'converged' on another, with interface forces 1098.9 and
1135.5 N for 1000 N in repeated runs; a squeal analysis reported rigid motions as unstable 0 Hz
modes; a box touching another of its body along an edge turned about it (30 Newton iterations,
forces 999.98-1001.33 N); a shaft turning in a bush, its end held along z alone, was held about its
axis only by the facets of the cylinder, and friction turned it against them (SNES -6, residual
stuck near 7.8); so did the bush around a held shaft. All are refused here, before the mesh is
handed to DOLFINx. The interfaces that alone hold a part are returned (N without each one's rows):
a run refuses such an interface if its contact carries no force (``workflows.strain.idle_holder``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multiscale.arrays import unique_rows
from multiscale.errors import InputError
from multiscale.geometry import GeometrySpec, Rotation, loose_bodies

MOTIONS = ("translation along x", "translation along y", "translation along z",
           "rotation about x", "rotation about y", "rotation about z")
FREE = 1e-10       # eigenvalues of N below FREE * its largest are motions nothing holds


def _elements(model, dim: int, tag: int | None = None):
    """Corner nodes (n, dim + 1) and the entity's physical tag (-1: none) of the dim-cells of
    physical group ``tag`` (default: every entity)."""
    entities = (model.getEntitiesForPhysicalGroup(dim, tag) if tag is not None
                else [e for _, e in model.getEntities(dim)])
    out, groups = [], []
    for entity in entities:
        tags = model.getPhysicalGroupsForEntity(dim, entity)
        for kind, nodes in zip(*model.mesh.getElements(dim, entity)[::2]):
            per = model.mesh.getElementProperties(kind)[3]
            out.append(np.asarray(nodes, dtype=np.int64).reshape(-1, per)[:, :dim + 1])
            groups.append(np.full(len(out[-1]), tags[0] if len(tags) else -1))
    if not out:
        return np.zeros((0, dim + 1), np.int64), np.zeros(0, np.int64)
    return np.concatenate(out), np.concatenate(groups)


def _records(rows) -> np.ndarray:
    """Integer rows (n, 4) as one record each, ordered like the rows (for ``np.searchsorted``)."""
    return np.ascontiguousarray(rows, dtype=np.int64).view([(f"f{k}", np.int64) for k in range(4)]).ravel()


def motion_rows(points, directions, centre, size) -> np.ndarray:
    """r(x, d) = [d, ((x − c)/L) × d] per row (m, 6): d · (translation e_k, rotation e_k × (x − c)/L)."""
    return np.hstack([directions, np.cross((points - centre) / size, directions)])


@dataclass
class Parts:
    """The parts of a meshed model: cells of one body joined through shared faces."""

    model: object              # gmsh.model, meshed
    xyz: np.ndarray            # (n_nodes, 3) node positions [m], rows in the order of ``tags``
    tags: np.ndarray           # sorted gmsh node tags
    body: np.ndarray           # body of each cell
    index: np.ndarray          # (n_cells, 4) corner nodes as rows of xyz
    label: np.ndarray          # part of each cell
    region: np.ndarray         # physical tag of each cell
    centre: np.ndarray         # (n_parts, 3) bounding-box centres [m]
    size: np.ndarray           # (n_parts,) largest bounding-box sides [m]
    faces: np.ndarray          # the cells' faces as sorted records (body, 3 nodes)
    face_part: np.ndarray      # part of each face

    @classmethod
    def of(cls, model, spec: GeometrySpec) -> Parts | None:
        """The parts of the bodies of ``spec`` (None: no cell in a body)."""
        import scipy.sparse  # local: scipy only once a mesh exists (scene reading stays light)
        from scipy.sparse.csgraph import connected_components  # local: as above
        body_of = {r.tag: i for i, b in enumerate(spec.bodies) for r in b.regions}
        tets, region = _elements(model, 3)
        body = np.array([body_of.get(int(t), -1) for t in region], dtype=np.int64)
        tets, region, body = tets[body >= 0], region[body >= 0], body[body >= 0]
        if not len(tets):
            return None
        tags, xyz, _ = model.mesh.getNodes()
        order = np.argsort(tags)
        tags, xyz = tags[order], xyz.reshape(-1, 3)[order]
        faces = np.sort(tets[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
        distinct = unique_rows(np.hstack([np.repeat(body, 4)[:, None], faces]))
        rows, face_of, n = distinct.values, distinct.inverse, len(tets)
        graph = scipy.sparse.coo_matrix((np.ones(face_of.size), (np.repeat(np.arange(n), 4), n + face_of)),
                                        shape=(n + len(rows),) * 2)
        n_parts, label = connected_components(graph, directed=False)
        label = label[:n]
        index = np.searchsorted(tags, tets)
        corner = xyz[index]
        low, high = np.full((n_parts, 3), np.inf), np.full((n_parts, 3), -np.inf)
        np.minimum.at(low, label, corner.min(axis=1))
        np.maximum.at(high, label, corner.max(axis=1))
        face_part = np.full(len(rows), -1)
        face_part[face_of] = np.repeat(label, 4)
        return cls(model, xyz, tags, body, index, label, region, (low + high) / 2, (high - low).max(axis=1),
                   _records(rows), face_part)

    def __len__(self) -> int:
        return len(self.centre)

    def of_triangles(self, b: int, tri) -> np.ndarray:
        """Part of body b whose cells the triangles ``tri`` (m, 3) bound (-1: none)."""
        rows = _records(np.hstack([np.full((len(tri), 1), b), np.sort(tri, axis=1)]))
        at = np.minimum(np.searchsorted(self.faces, rows), len(self.faces) - 1)
        return np.where(self.faces[at] == rows, self.face_part[at], -1)

    def triangles(self, tag: int):
        """Corner nodes (m, 3), node positions (m, 3, 3), unit normals and areas of a face group."""
        tri = _elements(self.model, 2, tag)[0]
        x = self.xyz[np.searchsorted(self.tags, tri)]
        n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        area = np.linalg.norm(n, axis=1) / 2
        return tri, x, n / np.maximum(2 * area, 1e-300)[:, None], area

    def where(self, p: int, names) -> str:
        """Part p's region (its first cell's; the others it holds in parentheses) and the centre of its
        bounding box [mm]."""
        tags = self.region[self.label == p]
        more = ", ".join(repr(names.get(int(t), "?")) for t in dict.fromkeys(tags.tolist()) if t != tags[0])
        return (f"{names.get(int(tags[0]), '?')!r}{f' (with {more})' if more else ''} around "
                f"{(np.round(self.centre[p] * 1e3, 1) + 0.0).tolist()} mm")


class Holding:
    """The holding matrix N of the parts' rigid motions (module docstring), row by row."""

    def __init__(self, parts: Parts, motion):
        self.parts, n = parts, len(parts)
        self.N = np.zeros((6 * n, 6 * n))
        self.lost = np.zeros(n)              # what the facets of curved interfaces held of body 1's motion
        self.joined: dict[int, set] = {}     # part -> parts it shares only nodes with
        turns = isinstance(motion, Rotation)
        axis = np.asarray(motion.axis, float) / np.linalg.norm(motion.axis) if turns else np.zeros(3)
        slides = np.hstack([motion.velocity(parts.centre), parts.size[:, None] * axis])   # body 1's motion
        self.slides = slides / np.linalg.norm(slides, axis=1, keepdims=True)             # per part

    def hold(self, p: int, q: int, x, d, w, slide: bool = False) -> None:
        """Add rows r_p(x, d) − r_q(x, d) (q = -1: the ground) with weights w; ``slide``: the rows
        hold neither part in body 1's motion (their components along it removed)."""
        c, s = self.parts.centre, self.parts.size
        blocks = [(p, motion_rows(x, d, c[p], s[p]), 1.0)]
        blocks += [(q, motion_rows(x, d, c[q], s[q]), -1.0)] if q >= 0 else []
        if slide:
            for k, (a, ra, sa) in enumerate(blocks):
                along = ra @ self.slides[a]
                self.lost[a] += np.sum(w * along ** 2)
                blocks[k] = (a, ra - np.outer(along, self.slides[a]), sa)
        for a, ra, sa in blocks:
            for b, rb, sb in blocks:
                self.N[6 * a:6 * a + 6, 6 * b:6 * b + 6] += sa * sb * np.einsum("i,ij,ik->jk", w, ra, rb)

    def joints(self) -> None:
        """Nodes shared by parts of one body: their relative translation (weight: the squared size
        of the cells at the node)."""
        P = self.parts
        keys = unique_rows(np.stack([np.repeat(P.body, 4), P.index.ravel(), np.repeat(P.label, 4)], axis=1)).values
        nodes = unique_rows(keys[:, :2])
        first, count = nodes.first, nodes.counts
        corner = P.xyz[P.index]
        volume = np.abs(np.einsum("ij,ij->i", corner[:, 1] - corner[:, 0],
                                  np.cross(corner[:, 2] - corner[:, 0], corner[:, 3] - corner[:, 0]))) / 6
        cell_size = np.zeros(len(P.tags))
        np.maximum.at(cell_size, P.index.ravel(), np.repeat(volume ** (2 / 3), 4))
        for k in np.flatnonzero(count > 1):
            node, p = keys[first[k], 1], int(keys[first[k], 2])
            for q in keys[first[k] + 1:first[k] + count[k], 2]:
                self.hold(p, int(q), np.tile(P.xyz[node], (3, 1)), np.eye(3), np.full(3, cell_size[node]))
                self.joined.setdefault(int(q), set()).add(p)
                self.joined.setdefault(p, set()).add(int(q))

    def supports(self, spec: GeometrySpec) -> None:
        """The fixed components of the supports, on the bodies whose cells their faces bound."""
        for sup in spec.supports:
            if sup.face not in spec.faces:
                continue
            tri, x, _, area = self.parts.triangles(spec.faces[sup.face])
            for b in range(len(spec.bodies)):
                owner = self.parts.of_triangles(b, tri)
                for p in np.unique(owner[owner >= 0]):
                    at = owner == p
                    for c in sup.components:
                        for k in range(3):      # each corner stands for a third of its triangle
                            self.hold(int(p), -1, x[at, k], np.tile(np.eye(3)[c], (at.sum(), 1)), area[at] / 3)

    def interfaces(self, spec: GeometrySpec, sliding: bool) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """The interfaces' normals, relative between the parts on both sides; ``sliding``: not
        along body 1's motion. Returns each interface's share of N and of ``lost``."""
        shares = {}
        for name, tag in spec.interfaces.items():
            before, lost = self.N.copy(), self.lost.copy()
            tri, x, n, area = self.parts.triangles(tag)
            pair = np.stack([self.parts.of_triangles(0, tri), self.parts.of_triangles(1, tri)], axis=1)
            for p, q in unique_rows(pair[(pair >= 0).all(axis=1)]).values if len(tri) else ():
                on = (pair == (p, q)).all(axis=1)
                for k in range(3):      # each corner stands for a third of its triangle
                    self.hold(int(p), int(q), x[on, k], n[on], area[on] / 3, sliding)
            shares[name] = (self.N - before, self.lost - lost)
        return shares

    def free(self, names, without=None) -> tuple[str, str, bool] | None:
        """What nothing holds: the region of the freest part, the parts and their free motions, and
        whether they touch nothing at all (None: every part held). ``without``: an interface's share
        of N and ``lost`` (``interfaces``) taken out."""
        N, lost, P = self.N, self.lost, self.parts
        if without is not None:
            N, lost = N - without[0], lost - without[1]
        values, vectors = np.linalg.eigh(N)
        free = vectors[:, values <= FREE * max(values[-1], 0.0)]
        if not free.shape[1]:
            return None
        share = np.sum(free ** 2, axis=1).reshape(len(P), 6)   # how far each motion is free
        loose = [p for p in range(len(P)) if share[p].sum() > 1e-6]
        first = max(loose, key=lambda p: share[p].sum())
        block = slice(6 * first, 6 * first + 6)
        region = names.get(int(P.region[P.label == first][0]), "a part")
        if not np.diag(N)[block].any():
            untouched = sum(not np.diag(N)[6 * p:6 * p + 6].any() for p in loose)
            return region, (f"{untouched} part(s) touch no interface and no support (one of region "
                            f"{P.where(first, names)})"), True
        own, alone = np.linalg.eigh(N[block, block])
        alone = alone[:, own <= FREE * values[-1]]       # its motions free while every other part stays
        if alone.shape[1]:
            mode, together = np.sum(alone ** 2, axis=1), []
        else:                                            # it moves only together with others
            mode = free[:, np.argmax(np.sum(free[block] ** 2, axis=0))]
            together = [p for p in range(len(P)) if p != first and np.sum(mode[6 * p:6 * p + 6] ** 2) > 1e-6]
            mode = mode[block] ** 2
        motions = [m for m, s in zip(MOTIONS, mode) if s > 0.5 * mode.max()]
        region_of = [names.get(int(P.region[P.label == p][0]), "?") for p in range(len(P))]
        along = f", together with region(s) {', '.join(repr(region_of[p]) for p in together)}" if together else ""
        apart = [P.where(p, names) for p in loose if p != first and p not in together]
        along += f"; also region(s) {', '.join(apart)}" if apart else ""   # (it named one of them: a user trial)
        if lost[first] > FREE * values[-1]:
            along += "; the facets of its curved interfaces alone held its sliding along them"
        if first in self.joined:
            at = ", ".join(P.where(q, names) for q in sorted(self.joined[first]))
            along += f"; it shares only an edge or a vertex with the part(s) of {at}: a joint holds no turn about it"
        return region, (f"{len(loose)} part(s) could move as rigid bodies (one of region {P.where(first, names)}: "
                        f"{', '.join(motions)}{along})"), False

    def refusal(self, names, causes=None) -> InputError | None:
        """The error naming the parts with a free motion and what it is (None: every part held); with
        ``causes`` (region -> what check warned of it, ``geometry.loose_bodies``) that cause first."""
        found = self.free(names)
        if found is None:
            return None
        region, what, untouched = found
        if untouched:
            return InputError("geometry", region, f"{what}: they could move freely; remove them from the geometry "
                                                  "or hold them ([[boundary]] fix)")
        cause = (causes or {}).get(region)
        if cause:                # its real cause, warned of at check (a user trial fixed the sides, as it advised;
            return InputError("geometry", region, f"{what}, likely because {cause}")   # a later one saw z free)
        return InputError("geometry", region,
                          f"{what}: nothing holds them there; a support holds the components it fixes on its face, "
                          "an interface only along its normal, and friction does not hold: add a [[boundary]] fix that "
                          "holds these motions (e.g. fix = [\"x\", \"y\"] on a pad's sides)")


HELD_LOAD = 1e-6   # a load face whose load the supports' fixed components take but this share of is refused


def check_load_free(parts: Parts, spec: GeometrySpec) -> None:
    """InputError if the supports of a load face fix every component its load pushes along (a fluid
    load's normal at each facet, else ``spec.load_direction``), to ``HELD_LOAD`` of its area: they
    would take the load and the contact none. The scene refuses it for a given direction or all
    components fixed; a fluid load needs the faces' normals (a trial fixed the abutments in x and y,
    loaded by a pressure along their normals y: passed, and the pad carried no force)."""
    fixed = {}
    for sup in spec.supports:
        fixed.setdefault(sup.face, set()).update(sup.components)
    for face in spec.load_faces:
        if face not in fixed or face not in spec.faces:
            continue
        free = [c for c in range(3) if c not in fixed[face]]
        _, _, n, area = parts.triangles(spec.faces[face])
        d = n if spec.fluid_load else np.broadcast_to(np.asarray(spec.load_direction, dtype=float), n.shape)
        if area.sum() > 0 and area @ np.linalg.norm(d[:, free], axis=1) <= HELD_LOAD * area.sum():
            along = "along its normals" if spec.fluid_load else f"along {list(spec.load_direction)}"
            raise InputError("loading.faces", face, f"a load face whose supports fix {sorted('xyz'[c] for c in fixed[face])},"
                             f" every component the load pushes {along}: they would take the load and the contact "
                             "none; load another face, or fix another")


def check_held(model, spec: GeometrySpec, sliding: bool = False) -> dict[str, str]:
    """Every part of the meshed ``model`` (gmsh, linear or quadratic cells) is held against its six
    rigid motions by the joints, supports and interfaces of ``spec`` (module docstring); otherwise
    an InputError names a free part's region, a point and its free motions (a part touching
    nothing: that it touches nothing). ``sliding`` (friction): the interfaces hold no part, on
    either side, in body 1's motion along them (``spec.motion``). Returns the interfaces that alone
    hold a part, each with what would move without it (``sole_holds``). A load face its supports hold
    along the load is refused first (``check_load_free``)."""
    parts = Parts.of(model, spec)
    if parts is None:
        return {}
    check_load_free(parts, spec)
    holding = Holding(parts, spec.motion)
    holding.joints()
    holding.supports(spec)
    shares = holding.interfaces(spec, sliding)
    names = {r.tag: r.name for b in spec.bodies for r in b.regions}
    error = holding.refusal(names, loose_bodies(spec.warnings))
    if error is None:
        alone = {name: holding.free(names, share) for name, share in shares.items()}
        return {name: f"without it {found[1]}" for name, found in alone.items() if found is not None}
    raise error
