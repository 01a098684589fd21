"""How much of their faces the meshes of the interfaces and the load faces cover (``TwoBodyMesh.notes``).

Round faces meshed by straight edges cover less than the faces: an interface by more than
``COVERAGE_TOLERANCE`` carries its force on less area (24 mm pucks at 8 mm elements: 6.5 % less, so
6.9 % more pressure under the same force; a user audit, 2026-12-01), and a pressure on a load face
pushes with less force (the brake demo's piston at 20 mm: 1.14 % less than p pi r^2; a user audit,
2026-12-04). A script scaled to metres is made of B-splines, whose OpenCASCADE areas are ~0.2 %
coarse (``meshes/from_file.py``): its ratio is that good.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

COVERAGE_TOLERANCE = 0.01    # a meshed area this share off its faces' is said


def face_coverage(model, spec) -> tuple[dict, dict]:
    """({interface: its meshed area / its faces' area}, {load face: the same}) of the gmsh ``model``
    (rank 0) described by the ``geometry.GeometrySpec`` ``spec``, for those whose faces are
    OpenCASCADE's (the built-in kernel has no exact area: left out)."""
    def ratio(tag: int) -> float | None:
        faces = model.getEntitiesForPhysicalGroup(2, tag)
        try:
            exact = sum(model.occ.getMass(2, int(f)) for f in faces)
        except Exception:          # gmsh raises a bare Exception for an entity OCC does not hold
            return None
        meshed = 0.0
        for f in faces:
            nodes, xyz, _ = model.mesh.getNodes(2, int(f), includeBoundary=True)
            x, order = np.reshape(xyz, (-1, 3)), np.argsort(nodes)
            for kind, _, corners in zip(*model.mesh.getElements(2, int(f))):
                tri = np.reshape(corners, (-1, model.mesh.getElementProperties(kind)[3]))[:, :3]
                p = x[order[np.searchsorted(nodes, tri, sorter=order)]]
                meshed += 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
        return meshed / exact if exact > 0 else None

    def ratios(tags: dict) -> dict:
        return {name: r for name, tag in tags.items() if (r := ratio(tag)) is not None}
    return ratios(spec.interfaces), ratios({n: spec.faces[n] for n in spec.load_faces if n in spec.faces})


def coverage_notes(tm, coverage: tuple[dict, dict]) -> tuple:
    """The notes on the interfaces and the load faces of ``tm`` (``mesh.TwoBodyMesh``) whose meshed
    area is more than ``COVERAGE_TOLERANCE`` off their faces' (``face_coverage``; areas in mm^2 from
    the distributed mesh: the ratio is gmsh's, free of its units). Collective."""
    masks, notes = tm.interface.masks(), []
    meshed = {**{n: tm.interface.areas[m].sum() for n, m in masks.items()},
              **{f: tm.comm.allreduce(float(np.linalg.norm(tm.face_vector_areas(f), axis=1).sum()), op=MPI.SUM)
                 for f in coverage[1]}}
    for kind, ratios, effect in (
            ("interface meshes", coverage[0], "their contact pressures are that much higher under the same force "
             "(round edges meshed by straight ones): a finer geometry.interface_mesh_size brings them closer, the "
             "loss falling with its square"),
            ("load faces' meshes", coverage[1], "a pressure on them pushes with that much less force than on the "
             "faces (round edges meshed by straight ones): a finer mesh brings them closer")):
        alike: dict = {}
        for n, r in ratios.items():                  # equal pucks said once
            if abs(r - 1) > COVERAGE_TOLERANCE:
                mesh = meshed[n] * 1e6
                alike.setdefault(f"{100 * (1 - r):.3g} % ({mesh:.4g} of {mesh / r:.4g} mm^2)", []).append(n)
        said = [f"{', '.join(names[:3])}{f' and {len(names) - 3} more' * (len(names) > 3)}: {loss}"
                f"{' each' * (len(names) > 1)}" for loss, names in alike.items()]
        if said:
            notes.append(f"{kind} cover less than their faces (negative: more): {'; '.join(said)}; {effect}")
    return tuple(notes)
