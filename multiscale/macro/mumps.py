"""Direct factorisations (a PETSc LU or Cholesky PC, MUMPS) that survive a too-small workspace.

MUMPS sizes its workspace from the analysis' estimate plus ICNTL(14) percent (default 20). Pivots
delayed by the numerical pivoting of an indefinite matrix (the LDL^T of the brake's frictionless
tangent, K - theta M inside the spectrum, a 2-rank LU) can need more, and the factorisation then
stops with INFOG(1) = -9 (at 249k dofs, 2 ranks: 1.57M reals short). As the MUMPS user guide
advises, ``factorise`` repeats it with ICNTL(14) doubled, up to ``WORKSPACE_RETRIES`` times (INFOG is
global: every rank retries alike). PETSc's numeric phase returns at once while INFOG(1) < 0, so a
retry resets the PC (a new analysis); an explicit ``<prefix>mat_mumps_icntl_14`` option overrides
the retries' margin. A PC that failed otherwise applies NaN: ``describe`` names the failure for
the caller's error.
"""
from __future__ import annotations

from contextlib import contextmanager

from petsc4py import PETSc

from multiscale.errors import ConvergenceError

WORKSPACE_ERRORS = (-8, -9, -11, -14, -15, -17, -20)   # MUMPS INFOG(1): a workspace or buffer too small
WORKSPACE_RETRIES = 4
MEANINGS = {-10: "numerically singular", -13: "not enough memory", -19: "more memory than ICNTL(23) allows"}
MEMORY_ERRORS = (-13, -19)    # MUMPS INFOG(1): the factors did not fit in memory


def status(pc: PETSc.PC) -> int:
    """MUMPS' INFOG(1) of the PC's last factorisation, the same on every rank (0: none yet, or not
    a MUMPS factorisation)."""
    if pc.getType() not in ("lu", "cholesky") or pc.getFactorSolverType() != "mumps":
        return 0
    factors = pc.getFactorMatrix()
    return 0 if factors is None else factors.getMumpsInfog(1)


def factorise(pc: PETSc.PC, workspace: int | None = None) -> tuple[int | None, int]:
    """``pc.setUp()`` (operators set), MUMPS' ICNTL(14) at ``workspace`` [%] if given, a workspace
    error retried with the margin doubled. Returns (the margin used, None: MUMPS' default; the
    number of retries); the PC's failed reason tells whether the last attempt failed."""
    if workspace is not None:
        _set_margin(pc, workspace)
    _set_up(pc)
    for retry in range(WORKSPACE_RETRIES):
        if status(pc) not in WORKSPACE_ERRORS:
            return workspace, retry
        workspace = 2 * max(pc.getFactorMatrix().getMumpsIcntl(14), 20)
        operators = pc.getOperators()
        pc.reset()                                   # drops the operators and the factors
        pc.setOperators(*operators)
        _set_margin(pc, workspace)
        _set_up(pc)
    return workspace, WORKSPACE_RETRIES


def direct_solver(A: PETSc.Mat, what: str) -> PETSc.KSP:
    """A KSP applying the LU factors of ``A`` (``preonly``; MUMPS when PETSc has it), factorised at
    once by ``factorise``. A failed factorisation raises ``MemoryError`` (``check_memory``) or
    ``ConvergenceError`` naming ``what`` and ``describe``'s reason, on every rank (MUMPS' status
    is global); before, a singular matrix gave inf and NaN solutions, said by nobody (a review)."""
    ksp = PETSc.KSP().create(A.getComm())
    ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("lu")
    if PETSc.Sys.hasExternalPackage("mumps"):
        pc.setFactorSolverType("mumps")
    try:
        factorise(pc)
        failed = describe(pc)
    except PETSc.Error as exc:
        failed = str(exc).strip()
    if failed:
        try:
            check_memory(pc, what)
        finally:
            ksp.destroy()
        raise ConvergenceError(f"{what} could not be factorised [{failed}]")
    return ksp


def _set_up(pc: PETSc.PC) -> None:
    """``pc.setUp()``; a PC set to raise on a failed factorisation (a SLEPc ST's) raises only if
    MUMPS has no status to tell the failure by."""
    try:
        pc.setUp()
    except PETSc.Error:
        if status(pc) >= 0:
            raise


@contextmanager
def precision(prefix: str, value: str):
    """``<prefix>pc_precision`` = ``value`` ("single": MUMPS' SMUMPS on the double matrix, PETSc
    3.25) in PETSc's options database for the block: MUMPS reads it there when it analyses, after
    DOLFINx has removed the options it was given, and a numeric refactorisation keeps the
    precision of its analysis. An option the user set already wins (left as it is)."""
    options = PETSc.Options(prefix)
    if options.hasName("pc_precision"):
        yield
        return
    options["pc_precision"] = value
    try:
        yield
    finally:
        options.delValue("pc_precision")


def check_memory(pc: PETSc.PC, what: str) -> None:
    """Raise ``MemoryError`` (on every rank: INFOG is global) when the PC's factorisation of ``what``
    did not fit in memory (``MEMORY_ERRORS``): a squeal run under ``ulimit -v`` was told to choose
    another shift target (a user trial)."""
    code = status(pc)
    if code in MEMORY_ERRORS:
        cap = "; or raise the cap mat_mumps_icntl_23 (MB a rank)" if code == -19 else ""
        raise MemoryError(f"the factors of {what} did not fit [{describe(pc)}]{cap}")


def describe(pc: PETSc.PC) -> str:
    """Why the PC's factorisation failed ("" if it did not): PETSc's failed reason and MUMPS' INFOG(1)."""
    reason, code = pc.getFailedReason(), status(pc)
    if reason == PETSc.PC.FailedReason.NOERROR and code >= 0:
        return ""
    meaning = MEANINGS.get(code, "workspace too small after retries" if code in WORKSPACE_ERRORS else "")
    detail = f", MUMPS INFOG(1) = {code}" + (f" ({meaning})" if meaning else "") if code < 0 else ""
    return f"PC failed reason {reason}{detail}"


def _set_margin(pc: PETSc.PC, workspace: int) -> None:
    pc.setFactorSetUpSolverType()
    pc.getFactorMatrix().setMumpsIcntl(14, workspace)
