"""Rigid motions a meshed geometry leaves free, found before anything is solved.

A part is a set of one body's cells joined through shared faces. Parts of one body that share
only nodes (along an edge or at a vertex) share those nodes' displacements: such a joint holds
their relative translation there, not a rotation about it (a box touching another of its body
along an edge turned about it, unheld, when parts were cells joined through nodes: the check
passed and repeated runs ended with different forces; an adversarial test). Each
part has six rigid motions: translations along x, y, z and rotations about x, y, z through its
centre. A support holds the components it fixes at every node of its face; an interface holds the
normal component of the motion of the part on one side relative to the part on the other (penalty
contact, thesis §1.4); friction holds nothing. With r(x, d) = [d, ((x − c)/L) × d] the
work-conjugate of the motions along direction d at point x (c the centre of the part's bounding
box, L its largest side), the holding matrix N = sum_rows w r r^T (w the area [m^2] a node
stands for; at a joint, the squared size of its cells) is singular exactly in the motions nothing
holds. With friction, no interface holds a part in body 1's motion along it (``check_held``). A singular stiffness made the first
Newton solve fail on one machine and run with arbitrary sideways pad positions on another, and a
squeal analysis report rigid motions as unstable 0 Hz modes (adversarial tests); both are refused
here, before meshing is handed to DOLFINx.
"""
from __future__ import annotations

import numpy as np

from multiscale.errors import InputError
from multiscale.geometry import GeometrySpec, Rotation

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


def _rows(points, directions, centre, size) -> np.ndarray:
    """r(x, d) = [d, ((x − c)/L) × d] per row (m, 6): d · (translation e_k, rotation e_k × (x − c)/L)."""
    return np.hstack([directions, np.cross((points - centre) / size, directions)])


def check_held(model, spec: GeometrySpec, sliding: bool = False) -> None:
    """Every part of the meshed ``model`` (gmsh, linear or quadratic cells) is held against its six
    rigid motions by the supports and interfaces of ``spec`` (module docstring); otherwise an
    InputError names a free part's region, a point and its free motions (a part touching nothing:
    that it touches nothing). With ``sliding`` (friction), the interfaces hold no part, on either
    side, in body 1's motion along them (``spec.motion``), however the mesh facets a curved
    interface: a shaft turning in a bush, its end held along z alone, was held about its axis only
    by the facets of the cylinder; friction turned it against them and Newton stalled (SNES -6,
    residual stuck near 7.8 from the 5th iteration on); so did the bush, held along z alone
    around a held shaft (SNES -6 and -5 on two runs: adversarial tests)."""
    import scipy.sparse  # local: scipy only once a mesh exists (scene reading stays light)
    from scipy.sparse.csgraph import connected_components  # local: as above
    body_of = {r.tag: i for i, b in enumerate(spec.bodies) for r in b.regions}
    names = {r.tag: r.name for b in spec.bodies for r in b.regions}
    tets, regions = _elements(model, 3)
    body = np.array([body_of.get(int(t), -1) for t in regions], dtype=np.int64)
    tets, regions, body = tets[body >= 0], regions[body >= 0], body[body >= 0]
    if not len(tets):
        return
    all_tags, xyz, _ = model.mesh.getNodes()
    order = np.argsort(all_tags)
    xyz = xyz.reshape(-1, 3)[order]
    all_tags = all_tags[order]
    n_tets = len(tets)
    # parts: cells of one body joined through shared faces (triangles keyed by body and sorted nodes)
    faces = np.sort(tets[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    face_keys = np.hstack([np.repeat(body, 4)[:, None], faces])
    face_rows, face_of = np.unique(face_keys, axis=0, return_inverse=True)
    face_of = face_of.ravel()
    graph = scipy.sparse.coo_matrix((np.ones(face_of.size), (np.repeat(np.arange(n_tets), 4), n_tets + face_of)),
                                    shape=(n_tets + len(face_rows),) * 2)
    n_parts, label = connected_components(graph, directed=False)
    label = label[:n_tets]
    index = np.searchsorted(all_tags, tets)                               # nodes as rows of xyz
    corner = xyz[index]                                                    # (n_tets, 4, 3)
    low, high = np.full((n_parts, 3), np.inf), np.full((n_parts, 3), -np.inf)
    np.minimum.at(low, label, corner.min(axis=1))
    np.maximum.at(high, label, corner.max(axis=1))
    centre, size = (low + high) / 2, (high - low).max(axis=1)            # bounding-box centre and size
    face_part = np.full(len(face_rows), -1)
    face_part[face_of] = np.repeat(label, 4)

    known = _records(face_rows)                  # sorted, as np.unique returns them

    def part(b: int, tri) -> np.ndarray:
        """Part of body b whose cells the triangles ``tri`` (m, 3) bound (-1: none)."""
        rows = _records(np.hstack([np.full((len(tri), 1), b), np.sort(tri, axis=1)]))
        at = np.minimum(np.searchsorted(known, rows), len(known) - 1)
        return np.where(known[at] == rows, face_part[at], -1)

    def triangles(tag: int):
        """Corner nodes (m, 3), node positions (m, 3, 3), unit normals and areas of a face group."""
        tri = _elements(model, 2, tag)[0]
        x = xyz[np.searchsorted(all_tags, tri)]
        n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        area = np.linalg.norm(n, axis=1) / 2
        return tri, x, n / np.maximum(2 * area, 1e-300)[:, None], area

    N = np.zeros((6 * n_parts, 6 * n_parts))
    turns = isinstance(spec.motion, Rotation)
    axis = np.asarray(spec.motion.axis, float) / np.linalg.norm(spec.motion.axis) if turns else np.zeros(3)
    slides = np.hstack([spec.motion.velocity(centre), size[:, None] * axis])     # body 1's motion, per part
    slides /= np.linalg.norm(slides, axis=1, keepdims=True)
    lost = np.zeros(n_parts)

    def hold(p: int, q: int, x, d, w, slide: bool = False) -> None:
        """Add rows r_p(x, d) − r_q(x, d) (q = -1: the ground) with weights w to N; ``slide``: the
        rows hold neither part in body 1's motion (their components along it removed)."""
        blocks = [(p, _rows(x, d, centre[p], size[p]), 1.0)] + ([(q, _rows(x, d, centre[q], size[q]), -1.0)]
                                                                 if q >= 0 else [])
        if slide:
            for k, (a, ra, sa) in enumerate(blocks):
                lost[a] += np.sum(w * (ra @ slides[a]) ** 2)      # what the facets held of it
                blocks[k] = (a, ra - np.outer(ra @ slides[a], slides[a]), sa)
        for a, ra, sa in blocks:
            for b, rb, sb in blocks:
                N[6 * a:6 * a + 6, 6 * b:6 * b + 6] += sa * sb * np.einsum("i,ij,ik->jk", w, ra, rb)

    # joints: a node shared by parts of one body (along an edge or at a vertex) is one displacement
    # of both: it holds their relative translation there, not the rotation about it (weight: the
    # squared size of the cells at the node)
    keys = np.unique(np.stack([np.repeat(body, 4), index.ravel(), np.repeat(label, 4)], axis=1), axis=0)
    _, first, count = np.unique(keys[:, :2], axis=0, return_index=True, return_counts=True)
    cell_size = np.zeros(len(all_tags))
    volume = np.abs(np.einsum("ij,ij->i", corner[:, 1] - corner[:, 0],
                              np.cross(corner[:, 2] - corner[:, 0], corner[:, 3] - corner[:, 0]))) / 6
    np.maximum.at(cell_size, index.ravel(), np.repeat(volume ** (2 / 3), 4))
    joined = {}                                 # part -> parts it shares only nodes with
    for k in np.flatnonzero(count > 1):
        node = keys[first[k], 1]
        x = np.tile(xyz[node], (3, 1))
        for other in keys[first[k] + 1:first[k] + count[k], 2]:
            hold(int(keys[first[k], 2]), int(other), x, np.eye(3), np.full(3, cell_size[node]))
            joined.setdefault(int(other), set()).add(int(keys[first[k], 2]))
            joined.setdefault(int(keys[first[k], 2]), set()).add(int(other))
    for sup in spec.supports:
        if sup.face not in spec.faces:
            continue
        tri, x, _, area = triangles(spec.faces[sup.face])
        for b in range(len(spec.bodies)):       # a support holds the bodies whose cells the face bounds
            owner = part(b, tri)
            for p in np.unique(owner[owner >= 0]):
                at = owner == p
                for c in sup.components:
                    for corner_ in range(3):      # each corner stands for a third of its triangle
                        hold(int(p), -1, x[at, corner_], np.tile(np.eye(3)[c], (at.sum(), 1)), area[at] / 3)
    for tag in spec.interfaces.values():
        tri, x, n, area = triangles(tag)
        if not len(tri):
            continue
        pair = np.stack([part(0, tri), part(1, tri)], axis=1)
        for p, q in np.unique(pair[(pair >= 0).all(axis=1)], axis=0):
            on = (pair == (p, q)).all(axis=1)
            for corner_ in range(3):      # each corner stands for a third of its triangle
                hold(int(p), int(q), x[on, corner_], n[on], area[on] / 3, sliding)
    values, vectors = np.linalg.eigh(N)
    free = vectors[:, values <= FREE * max(values[-1], 0.0)]
    if not free.shape[1]:
        return
    share = np.sum(free ** 2, axis=1).reshape(n_parts, 6)   # how far each motion is free
    loose = [p for p in range(n_parts) if share[p].sum() > 1e-6]
    first = max(loose, key=lambda p: share[p].sum())

    def region(p: int) -> str:
        return names.get(int(regions[label == p][0]), "?")

    block = slice(6 * first, 6 * first + 6)
    where = f"of region {region(first)!r} around {(np.round(centre[first] * 1e3, 1) + 0.0).tolist()} mm"
    if not np.diag(N)[block].any():
        untouched = sum(not np.diag(N)[6 * p:6 * p + 6].any() for p in loose)
        raise InputError("geometry", region(first),
                         f"{untouched} part(s) touch no interface and no support (one {where}): they could move "
                         "freely; remove them from the geometry or hold them ([[boundary]] fix)")
    own, alone = np.linalg.eigh(N[block, block])
    alone = alone[:, own <= FREE * values[-1]]       # its motions free while every other part stays
    if alone.shape[1]:
        mode, others = np.sum(alone ** 2, axis=1), []
    else:                                            # it moves only together with others
        mode = free[:, np.argmax(np.sum(free[block] ** 2, axis=0))]
        others = [region(p) for p in range(n_parts) if p != first and np.sum(mode[6 * p:6 * p + 6] ** 2) > 1e-6]
        mode = mode[block] ** 2
    motions = [m for m, s in zip(MOTIONS, mode) if s > 0.5 * mode.max()]
    along = f", together with region(s) {', '.join(map(repr, others))}" if others else ""
    if lost[first] > FREE * values[-1]:
        along += "; the facets of its curved interfaces alone held its sliding along them"
    if first in joined:
        at = ", ".join(f"{region(q)!r} around {(np.round(centre[q] * 1e3, 1) + 0.0).tolist()} mm"
                       for q in sorted(joined[first]))
        along += f"; it shares only an edge or a vertex with the part(s) of {at}: a joint holds no turn about it"
    raise InputError("geometry", region(first),
                     f"{len(loose)} part(s) could move as rigid bodies (one {where}: {', '.join(motions)}{along}): "
                     "nothing holds them there; a support holds the components it fixes on its face, an "
                     "interface only along its normal, and friction does not hold: add a [[boundary]] fix "
                     "that holds these motions (e.g. fix = [\"x\", \"y\"] on a pad's sides)")
