"""The contact solve after the zone laws changed (wear, plastic flattening): directly, and where
that fails by continuation from the pressures of the laws they replaced.

Why. Worn laws first touch closer than the old ones (their highest asperities are gone). At the
last displacements every facet of the rough body can then be open: the contact tangent is
singular along the load, and Newton's first step runs away (the coarse test pin with
k_w = 1e-12 /Pa: all 162 facets open, the residual 48 N -> 1.7e15 N), with fresh factors and
backtracking too (``Mechanics.solve``'s retries).

How. Natural-parameter continuation (an embedding, Allgower & Georg, *Introduction to Numerical
Continuation Methods*, SIAM 2003, §1.1 and ch. 2): the laws shifted by per-facet offsets s,
L(g − s), carry at the last gaps the pressures of the laws they replaced
(``FacetLaw.carried_offsets``), so the last state nearly balances them (λ = 0, a short solve).
The offsets are then scaled by 1 − λ and λ stepped to 1: the first step ``FIRST_STEP``, doubled
after a converged step, halved after a failed one, and the continuation given up below
``SMALLEST_STEP``. Each step's Newton corrector starts from the last converged state or, once
there are two, from the secant predictor u_k + Δλ (u_k − u_{k−1}) / (λ_k − λ_{k−1}) where its
residual is smaller (A & G ch. 2's predictor-corrector, the secant for the tangent). A failed
step costs ``Mechanics.solve``'s three attempts (the last two with fresh factors at every
iteration), a converged one 5-10 iterations: the first step is small (five steps reach λ = 1
when all converge). The railway demo's first update at 2e-13 /Pa (one rank, 2026-12-03): from 0.5 without the
predictor, 13 steps failed and 14 solves converged (159 Newton iterations, 43 s); now 0 and 6
(71 iterations, 3.3 s), the same answers to 1e-10. Its end, λ = 1, is the solve on the new laws
themselves: the same discrete answer as a direct solve that converged.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from multiscale.errors import ConvergenceError
from multiscale.macro.laws_ufl import FacetLaw
from multiscale.macro.mechanics import Mechanics, SolveResult

FIRST_STEP, SMALLEST_STEP = 1 / 16, 1 / 64
LEAST_STEP = 1 / 4096      # the smallest step once one converged (a first step below 4x it halves twice)


def solve_on_new_laws(mech: Mechanics, law: FacetLaw, guess: list | None = None, released: bool = False) -> SolveResult:
    """``mech.solve(guess=guess)`` after ``law.set_laws`` replaced the laws, by continuation where
    it fails (module docstring; collective). The result's ``iterations`` sum the Newton
    iterations of every solve, the failed direct one's included. Raises ``ConvergenceError``
    naming both failures and the update that led to them; ``released``: the update came while
    the load is released, and the load its message names is the last one kept."""
    start = mech.displacements()
    try:
        return mech.solve(guess=guess)
    except ConvergenceError as exc:
        direct = exc
    mech.set_displacements(start)
    gap = mech.contact.facet_gap()
    offset = law.carried_offsets(gap)
    step, smallest = first_steps(law.depths(gap, offset), offset)   # (at the gaps the offsets carry: after the
    done, iterations = 0.0, direct.result.iterations if direct.result is not None else 0   # solve the facets' mean
    try:                                                     # gaps carried nothing by the laws: a review)
        law.shift(offset)
        result = mech.solve()
        iterations += result.iterations
        rate = None                 # m per unit of lambda: the secant of the last two converged states
        while done < 1.0:
            target, kept = min(1.0, done + step), mech.displacements()
            law.shift((1.0 - target) * offset)
            try:
                result = mech.solve(guess=None if rate is None else [(target - done) * r for r in rate])
            except ConvergenceError:
                mech.set_displacements(kept)
                if step / 2 < smallest:
                    raise
                step /= 2
                continue
            rate = [(u - x) / (target - done) for u, x in zip(mech.displacements(), kept)]
            done, step, iterations = target, 2 * step, iterations + result.iterations
            smallest = max(smallest, LEAST_STEP)     # (a stuck point later gives up in at most 12 halvings)
    except ConvergenceError as exc:
        law.shift(None)
        raise ConvergenceError(
            f"the contact solve on new zone laws (a wear update or plastic flattening: the laws changed, no support "
            f"did{'; released: solved at the last load, kept for the next engagement' if released else ''}) failed: "
            f"{direct}; continued from the pressures of the laws before, it stopped at {done:.3g} of "
            f"the way (its last step {step:.3g}): {exc}; smaller wear steps change the laws less at an update "
            "(more time.steps, or a lower wear rate; wear.substeps divide the micro wear, not the update)",
            exc.history, exc.result) from exc
    return dataclasses.replace(result, iterations=iterations)


def first_steps(depth, offset) -> tuple[float, float]:
    """The first and the smallest step of lambda: ``FIRST_STEP`` and ``SMALLEST_STEP``, or less where a
    step of lambda would open the facets that carry at lambda = 0 (``depth`` [m]: their interpenetration
    of the shifted laws, ``offset`` [m]: their shifts; a shift s moves a facet by d lambda s): a fraction
    of the median depth per unit shift over the shifted facets in contact, at the gaps the offsets were
    taken at (``LEAST_STEP`` at least, unless a quarter of the first step is less: a failed first
    step is halved twice before the continuation gives up, below the smallest it gave up at once,
    a review; ``LEAST_STEP`` again once a step converged). Worn-flat laws rise from 0
    to their pressure within nm (a light load's run-in: all facets open at lambda = 1/64, the pin then
    free along the load; a trial)."""
    depth, offset = np.asarray(depth, dtype=float), np.asarray(offset, dtype=float)
    carrying = (offset > 0) & (depth > 0)
    if not carrying.any():
        return FIRST_STEP, SMALLEST_STEP
    reach = float(np.median(depth[carrying] / offset[carrying]))    # lambda that opens half of them
    first = min(FIRST_STEP, reach / 2)
    return first, min(max(min(SMALLEST_STEP, reach / 16), LEAST_STEP), first / 4)
