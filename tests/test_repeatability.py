"""Sums that round alike wherever their vectors lie in memory (docs/architecture.md, "Repeatability").

PETSc (3.25; option ``-vec_mdot_use_gemv``, on by default) computes ``VecMDot``, the
orthogonalisation of (F)GMRES, by BLAS gemv over runs of vectors that happen to lie at one stride in
memory and by its own loops otherwise, so its rounding followed the heap's layout: two serial runs
of the same scene differed from the first macro Newton solve on (2e-13, up to 4e-10 once a solve
took a Newton iteration more). ``multiscale.macro`` turns the gemv path off; the same vectors, rows
of one array or separate arrays, then give the same dot products (they did not with gemv)."""
import numpy as np

import multiscale.macro  # noqa: F401,I001  (DOLFINx's prerequisites and PETSc's options first)
from petsc4py import PETSc


def test_multi_dot_products_do_not_depend_on_where_the_vectors_lie():
    n, k = 40_003, 5
    rng = np.random.default_rng(1)
    values = rng.standard_normal((k, n)) * np.exp(rng.uniform(-20, 20, (k, n)))
    x = PETSc.Vec().createWithArray(rng.standard_normal(n), comm=PETSc.COMM_SELF)
    block = values.copy()                    # rows of one array, at one stride: gemv's case
    packed = [PETSc.Vec().createWithArray(row, comm=PETSc.COMM_SELF) for row in block]
    rows = [np.concatenate([a, np.zeros(1000 * (i + 1))]) for i, a in enumerate(values)]  # no one stride
    apart = [PETSc.Vec().createWithArray(r[:n], comm=PETSc.COMM_SELF) for r in rows]
    together, separately = np.asarray(x.mDot(packed)), np.asarray(x.mDot(apart))
    assert together.tobytes() == separately.tobytes()
    alphas = rng.standard_normal(k)
    sums = []
    for vectors in (packed, apart):         # VecMAXPY, GMRES's update, alike
        y = x.duplicate()
        y.set(1.0)
        y.maxpy(alphas, vectors)
        sums.append(y.getArray().copy())
    assert sums[0].tobytes() == sums[1].tobytes()
