"""Operators of the linearised sliding system beyond the tangent K and the mass M (issue 20).

About the preloaded state of a ``Mechanics`` the free vibrations obey

    M u'' + C u' + (K + K_sigma + K_w + i H) u = 0,

and this module assembles the optional parts (PETSc matrices with the block layout of the
Newton matrix; Dirichlet rows and columns are zero, so constrained modes stay at infinity):

- ``material_damping``: viscous C = sum_b (alpha_b M_b + beta_b K_b) and hysteretic (structural)
  H = sum_b eta_b K_b of each material (``damping_alpha`` [1/s], ``damping_beta`` [s],
  ``loss_factor`` [-]; K_b the material's elastic stiffness, M_b its mass). Contact stiffness and
  friction carry no material damping.
- ``geometric_stiffness``: the initial-stress (prestress) stiffness
  K_sigma(du, v) = int sigma_0 : (grad du^T grad v) dx of the stress sigma_0 at the preload, and
  optionally of the centrifugal stress of the rotating body (``centrifugal_displacement``).
- ``rotation_matrices``: the rotating body (body 1) in the fixed (Eulerian) frame the mesh and the
  pads live in. Its material derivative (d/dt + w.grad)^2 u, w = Omega e x (x - c), gives the
  gyroscopic (Coriolis) matrix G(du, v) = int rho [(grad du w).v - du.(grad v w)] (skew: exactly
  2 int rho ((w.grad) du).v when w.n = 0 on the body's boundary, i.e. for an axisymmetric body)
  and the centrifugal (transport) stiffness K_w(du, v) = -int rho (grad du w).(grad v w). In the
  fixed frame an n-nodal-diameter wave of a thin disc splits into f_r +- n Omega / 2 pi
  (forward and backward travelling waves; ``references.stability.spinning_disc_split``).

The UFL-level pieces (``geometric_form``, ``rotation_forms``) take plain UFL arguments, so the
closed-form checks run them on a single-body mesh.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc
from petsc4py import PETSc

from multiscale.errors import InputError
from multiscale.geometry import Rotation
from multiscale.macro import mumps
from multiscale.macro.materials import body_fields
from multiscale.macro.mechanics import Mechanics


# ---------------------------------------------------------------- UFL pieces
def geometric_form(stress, du, v, dx):
    """int sigma_0 : (grad du^T grad v) dx = int (grad du sigma_0) : grad v dx (initial-stress stiffness)."""
    return ufl.inner(ufl.grad(du) * stress, ufl.grad(v)) * dx


def rotation_forms(rho, w, du, v, dx):
    """(gyroscopic G, transport K_w) bilinear forms of a body moving with the velocity field ``w``
    through a fixed mesh (see module docstring)."""
    g = rho * (ufl.dot(ufl.grad(du) * w, v) - ufl.dot(du, ufl.grad(v) * w)) * dx
    k = -rho * ufl.dot(ufl.grad(du) * w, ufl.grad(v) * w) * dx
    return g, k


def rotation_velocity(motion: Rotation, x, omega: float):
    """w = Omega e x (x - c) [m/s] at the spatial coordinate ``x``."""
    axis = np.asarray(motion.axis, float)
    e = ufl.as_vector(axis / np.linalg.norm(axis))
    return float(omega) * ufl.cross(e, x - ufl.as_vector(motion.centre))


# ---------------------------------------------------------------- assembly
def _zero(mech: Mechanics, i: int):
    """A zero block on body i (keeps the row's space known to the block assembler)."""
    V = mech.spaces[i]
    return fem.Constant(mech.tm.parent, 0.0) * ufl.inner(ufl.TrialFunction(V), ufl.TestFunction(V)) * mech.dx(i)


def assemble_block(mech: Mechanics, blocks) -> PETSc.Mat:
    """Block form [[a00, a01], [a10, a11]] (None: empty; a zero block keeps a row alive) assembled
    with the Newton matrix's layout, Dirichlet rows and columns zero (diag 0)."""
    blocks = [list(row) for row in blocks]
    for i in range(2):
        if blocks[i][i] is None:
            blocks[i][i] = _zero(mech, i)
    A = fpetsc.assemble_matrix(fem.form(blocks, entity_maps=mech.tm.entity_maps), bcs=mech.bcs, diag=0.0)
    A.assemble()
    return A


def elastic_form(mech: Mechanics, i: int, weight=None):
    """int w sigma(du) : eps(v) over body i: its elastic stiffness (the linear part of the stress;
    thermal strains, which do not depend on u, drop out), weighted by a DG0 field ``weight``."""
    V = mech.spaces[i]
    v = ufl.TestFunction(V)
    sigma = mech.stress(i) if weight is None else weight * mech.stress(i)
    return ufl.derivative(ufl.inner(sigma, ufl.sym(ufl.grad(v))) * mech.dx(i), mech.u[i], ufl.TrialFunction(V))


def mass_form(mech: Mechanics, i: int, density):
    V = mech.spaces[i]
    return density * ufl.inner(ufl.TrialFunction(V), ufl.TestFunction(V)) * mech.dx(i)


def _property(mech: Mechanics, materials, name: str) -> tuple[list, bool]:
    """Per-body DG0 fields of a damping property (0 where a material does not give it), and
    whether any material gives a non-zero value."""
    given = any(getattr(materials[m], name, None) for m in mech.tm.spec.materials if m in materials)
    if not given:
        return [], False
    return body_fields(mech.tm, materials, name, mech.reference_temperature,
                       of=lambda m: float(getattr(m, name, None) or 0.0)), True


def material_damping(mech: Mechanics, materials: Mapping[str, object]) -> tuple[PETSc.Mat | None, PETSc.Mat | None]:
    """(C, H): per-material Rayleigh damping sum_b alpha_b M_b + beta_b K_b and hysteretic
    stiffness sum_b eta_b K_b (None when no material gives the property)."""
    alpha, has_a = _property(mech, materials, "damping_alpha")
    beta, has_b = _property(mech, materials, "damping_beta")
    eta, has_e = _property(mech, materials, "loss_factor")
    C = H = None
    if has_a or has_b:
        rho = body_fields(mech.tm, materials, "rho", mech.reference_temperature)
        blocks = [[None, None], [None, None]]
        for i in range(2):
            terms = []
            if has_a:
                terms.append(mass_form(mech, i, alpha[i] * rho[i]))
            if has_b:
                terms.append(elastic_form(mech, i, beta[i]))
            blocks[i][i] = sum(terms[1:], terms[0])
        C = assemble_block(mech, blocks)
    if has_e:
        H = assemble_block(mech, [[elastic_form(mech, 0, eta[0]), None], [None, elastic_form(mech, 1, eta[1])]])
    return C, H


def body_stress_increment(mech: Mechanics, i: int, du):
    """Stress increment of body i for a displacement increment ``du`` (a Function of its space)."""
    return ufl.derivative(mech.stress(i), mech.u[i], du)


def geometric_stiffness(mech: Mechanics, extra=None) -> PETSc.Mat:
    """K_sigma of the current stress of both bodies (``extra``: a pair of displacement increments,
    e.g. the centrifugal one, whose stress is added)."""
    blocks = [[None, None], [None, None]]
    for i in range(2):
        V = mech.spaces[i]
        sigma = mech.stress(i)
        if extra is not None:
            sigma = sigma + body_stress_increment(mech, i, extra[i])
        blocks[i][i] = geometric_form(sigma, ufl.TrialFunction(V), ufl.TestFunction(V), mech.dx(i))
    return assemble_block(mech, blocks)


def _rotation(mech: Mechanics) -> Rotation:
    motion = mech.tm.spec.motion
    if not isinstance(motion, Rotation):
        raise InputError("stability.gyroscopic", None, "needs a rotating body (the geometry's body 1 translates)")
    return motion


def rotation_matrices(mech: Mechanics, materials: Mapping[str, object], omega: float) -> tuple[PETSc.Mat, PETSc.Mat]:
    """(G, K_w) of the rotating body 1 at Omega [rad/s] (see module docstring)."""
    rho = body_fields(mech.tm, materials, "rho", mech.reference_temperature)[1]
    V = mech.spaces[1]
    w = rotation_velocity(_rotation(mech), ufl.SpatialCoordinate(mech.tm.parent), omega)
    g, k = rotation_forms(rho, w, ufl.TrialFunction(V), ufl.TestFunction(V), mech.dx(1))
    return assemble_block(mech, [[None, None], [None, g]]), assemble_block(mech, [[None, None], [None, k]])


def centrifugal_displacement(mech: Mechanics, materials: Mapping[str, object], omega: float, K: PETSc.Mat) -> list:
    """Displacement increments (one Function per body) under the centrifugal body force
    rho Omega^2 r e_r of the rotating body, solved with the tangent ``K`` (linear about the preload);
    ``ConvergenceError`` on every rank if ``K`` cannot be factorised (``mumps.direct_solver``)."""
    motion = _rotation(mech)
    rho = body_fields(mech.tm, materials, "rho", mech.reference_temperature)[1]
    axis = np.asarray(motion.axis, float) / np.linalg.norm(motion.axis)
    e = ufl.as_vector(axis)
    r = ufl.SpatialCoordinate(mech.tm.parent) - ufl.as_vector(motion.centre)
    radial = r - ufl.dot(r, e) * e
    v = [ufl.TestFunction(V) for V in mech.spaces]
    forms = fem.form([fem.Constant(mech.tm.parent, 0.0) * v[0][0] * mech.dx(0),
                      rho * float(omega) ** 2 * ufl.dot(radial, v[1]) * mech.dx(1)], entity_maps=mech.tm.entity_maps)
    b = fpetsc.assemble_vector(forms, kind="mpi")
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    fpetsc.set_bc(b, fem.bcs_by_block(fem.extract_function_spaces(forms), mech.bcs))
    x = b.duplicate()
    ksp = mumps.direct_solver(K, "the stiffness of the centrifugal preload")
    ksp.solve(b, x)
    ksp.destroy()
    out = [fem.Function(V) for V in mech.spaces]
    fpetsc.assign(x, out)
    for f in out:
        f.x.scatter_forward()
    b.destroy(), x.destroy()
    return out
