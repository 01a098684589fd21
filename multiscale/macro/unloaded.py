"""The bodies' thermo-elastic state without contact and load: what a released step shows.

While the contact is released (load factor 0) each body is strained by its temperature and held by
its supports alone: K u = f, with K the elasticity of both bodies (no contact terms: block-
diagonal) and f the thermal load (``Mechanics.cell_system``). A part that its supports leave free
(a pin or a pad pushed by the load and held sideways only) makes K singular in its free rigid
motions, but its stress is well defined: a rigid motion r has no strain, so the thermal load does
no work in it (r . f = 0) and u is unique up to the free motions, which carry no stress.

How it is solved, and why (as an analyst would pin a free body without loading it):

- the free motions are found, not guessed: each body's parts (cells joined through shared faces,
  as ``held.Parts``) and the combinations of a part's six rigid motions that vanish at its
  supports' fixed components (the null space of the supports' rows of ``held.Holding``,
  ``held.motion_rows``), found again on the distributed mesh (``held`` sees the gmsh model on
  rank 0 before DOLFINx has it); every other rigid motion is held, and a supported body has none;
- K u = f is solved on the complement of the free motions N (orthonormal): iterative refinement
  u += (I − N N^T) P^-1 (f − K u) with P = K + ``SHIFT`` diag(K) factorised once (MUMPS, double).
  Each pass reduces the error by about SHIFT/lambda_min (lambda_min of diag(K)^-1 K off the free
  motions), so a few passes reach ``TOL`` (2 measured on the test pin-on-disc and on the disc
  brake at 6 mm, 75k dofs); the answer is K's, not a regularised system's (that of K + eps M
  depends on eps, its rigid part is round-off over eps), and no null-pivot threshold decides the
  rank (MUMPS' ICNTL(24) on a stiff matrix with unit support rows). Lagrange constraints would
  border the sparse matrix with 6 dense rows per free part.
- the free motions are then set to those of the last loaded state (least squares over the nodes):
  their position is not determined without the contact, and the loaded one keeps a free pin where
  it was (the minimal-norm answer would move it by the contact's whole approach between two
  frames); the stress does not depend on this choice.

Cost: one factorisation of the bodies' stiffness per released output time, freed after it, while
the Newton's factors are kept (the disc brake at 75k dofs: 1.9 s, its loaded solve from rest
5.3 s). Not handled: a part joined to another only at an edge or a vertex (a hinge; its motion is
no rigid motion of one part, not built): ``solve`` is then expected to miss ``TOL`` and return
None, and the fields are NaN (``output.FieldOutput.unloaded``).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse
from dolfinx import fem
from dolfinx.cpp.mesh import cell_num_entities
from dolfinx.fem import petsc as fpetsc
from mpi4py import MPI
from petsc4py import PETSc
from scipy.sparse.csgraph import connected_components

from multiscale.errors import ConvergenceError
from multiscale.held import FREE, motion_rows
from multiscale.macro import mumps

SHIFT = 1e-8       # P = K + SHIFT diag(K), the factorised operator of the refinement
TOL = 1e-10        # the refinement stops at ||f − K u|| <= TOL ||f||
PASSES = 30        # at most this many refinement passes


class UnloadedWarning(UserWarning):
    """The unloaded state could not be solved (its fields are written NaN)."""


def cell_parts(mesh) -> tuple[np.ndarray, int]:
    """Part of each local cell (owned, then ghost) of ``mesh`` and the number of parts: cells joined
    through shared facets (collective; the cells' facets are gathered to rank 0, the labels
    broadcast)."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim, tdim - 1)
    cells, facets = mesh.topology.index_map(tdim), mesh.topology.index_map(tdim - 1)
    owned, per_cell = cells.size_local, cell_num_entities(mesh.topology.cell_type, tdim - 1)
    c2f = mesh.topology.connectivity(tdim, tdim - 1).array.reshape(-1, per_cell)   # a rank may hold no cells
    mine = (cells.local_to_global(np.arange(owned, dtype=np.int32)),
            facets.local_to_global(c2f[:owned].ravel()).reshape(owned, per_cell))
    gathered = mesh.comm.gather(mine, root=0)
    labels = None
    if mesh.comm.rank == 0:
        ids = np.concatenate([g for g, _ in gathered])
        faces = np.concatenate([f for _, f in gathered])
        n, m = cells.size_global, facets.size_global
        rows = np.repeat(ids, faces.shape[1])
        graph = scipy.sparse.coo_matrix((np.ones(rows.size), (rows, n + faces.ravel())), shape=(n + m,) * 2)
        count, label = connected_components(graph, directed=False)
        used, labels = np.unique(label[:n], return_inverse=True)      # parts of cells only
        labels = (labels.astype(np.int32), len(used))
    labels, count = mesh.comm.bcast(labels, root=0)
    return labels[cells.local_to_global(np.arange(owned + cells.num_ghosts, dtype=np.int32))], count


class Unloaded:
    """The thermo-elastic state of the bodies of ``mechanics`` (``macro.mechanics.Mechanics`` with
    temperatures) without contact and load (module docstring); its free motions are found on the
    first ``solve``."""

    def __init__(self, mechanics):
        self.mech = mechanics
        self._modes: list | None = None      # orthonormal free motions (block vectors)
        self.passes = 0                       # refinement passes of the last solve
        self.failure = ""                     # why the last solve gave None: a failed factorisation's reason

    def free_motions(self, template: PETSc.Vec) -> list:
        """Orthonormal block vectors (of ``template``'s layout) spanning the rigid motions of the
        parts that the supports do not hold (collective; computed once)."""
        if self._modes is not None:
            return self._modes
        mech = self.mech
        by_body = mech.bcs_by_body
        fields = []
        for i, (V, bcs) in enumerate(zip(mech.spaces, by_body)):
            label, count = cell_parts(V.mesh)
            imap, bs = V.dofmap.index_map, V.dofmap.bs
            owned, n = imap.size_local, imap.size_local + imap.num_ghosts
            part = np.empty(n, dtype=np.int64)
            part[V.dofmap.list] = label[:, None]
            x = V.tabulate_dof_coordinates()[:n]
            low, high = np.full((count, 3), np.inf), np.full((count, 3), -np.inf)
            np.minimum.at(low, part[:owned], x[:owned])
            np.maximum.at(high, part[:owned], x[:owned])
            comm = V.mesh.comm
            comm.Allreduce(MPI.IN_PLACE, low, op=MPI.MIN)
            comm.Allreduce(MPI.IN_PLACE, high, op=MPI.MAX)
            centre, size = (low + high) / 2, (high - low).max(axis=1)
            nodes = np.bincount(part[:owned], minlength=count).astype(float)
            comm.Allreduce(MPI.IN_PLACE, nodes, op=MPI.SUM)
            holding = np.zeros((count, 6, 6))
            for bc in bcs:
                dofs, first_ghost = bc.dof_indices()
                node, component = np.divmod(dofs[:first_ghost], bs)
                p = part[node]
                r = motion_rows(x[node], np.eye(3)[component], centre[p], size[p][:, None])
                np.add.at(holding, p, r[:, :, None] * r[:, None, :])
            comm.Allreduce(MPI.IN_PLACE, holding, op=MPI.SUM)
            for p in range(count):
                values, vectors = np.linalg.eigh(holding[p])
                for a in vectors[:, values <= FREE * nodes[p]].T:
                    u = np.zeros((n, 3))
                    at = part == p
                    u[at] = a[:3] + np.cross(a[3:], (x[at] - centre[p]) / size[p])
                    fields.append((i, u.ravel()))
        self._modes = []
        for i, values in fields:
            functions = [fem.Function(W) for W in mech.spaces]
            functions[i].x.array[:] = values
            v = template.duplicate()
            fpetsc.assign(functions, v)
            for w in self._modes:                      # Gram-Schmidt (twice is enough)
                v.axpy(-w.dot(v), w)
            for w in self._modes:
                v.axpy(-w.dot(v), w)
            v.scale(1.0 / v.norm())
            self._modes.append(v)
        return self._modes

    def _project(self, v) -> None:
        """``v`` without its free motions (I − N N^T) v."""
        for w in self._modes:
            v.axpy(-w.dot(v), w)

    def solve(self) -> list[np.ndarray] | None:
        """Per body, the displacement [m] (arrays of the ``u`` layout) of the unloaded state, with
        the free motions of the current displacements (the last loaded state, kept); None if the
        refinement did not reach ``TOL`` (a mechanism) or the shifted stiffness could not be
        factorised (``mumps.direct_solver``, its reason in ``failure``: the output writes NaN, the
        run goes on). Collective."""
        mech = self.mech
        K, r = mech.cell_system()
        modes = self.free_motions(r)
        f = r.copy()
        f.scale(-1.0)
        P = K.copy()
        d = K.getDiagonal()
        d.scale(SHIFT)
        P.setDiagonal(d, addv=PETSc.InsertMode.ADD_VALUES)
        try:
            ksp = mumps.direct_solver(P, "the shifted stiffness of the unloaded state")
        except ConvergenceError as exc:
            for v in (P, d, f, r):
                v.destroy()
            self.failure = str(exc)
            return None
        self.failure = ""
        u, du = f.duplicate(), f.duplicate()
        u.set(0.0)
        self._project(f)                # round-off of r . f = 0
        f.copy(r)
        goal, converged = TOL * f.norm(), f.norm() == 0.0
        self.passes = 0
        for self.passes in range(1, 1 + (0 if converged else PASSES)):
            ksp.solve(r, du)
            self._project(du)
            u.axpy(1.0, du)
            K.mult(u, r)
            r.aypx(-1.0, f)             # f − K u
            converged = r.norm() <= goal
            if converged:
                break
        loaded = u.duplicate()
        fpetsc.assign(mech.u, loaded)
        for w in modes:                  # the free motions of the loaded state
            u.axpy(w.dot(loaded), w)
        out = [fem.Function(V) for V in mech.spaces]
        fpetsc.assign(u, out)
        for g in out:
            g.x.scatter_forward()
        for v in (P, d, f, r, u, du, loaded):
            v.destroy()
        ksp.destroy()
        return [g.x.array.copy() for g in out] if converged else None
