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


def test_a_repeatable_scene_repeats_bit_for_bit_whatever_the_clock(tmp_path, monkeypatch):
    """``output.repeatable = true``: the macro Newton renews its factors by a count
    (``REPEATABLE_REFRESH``), not by the times it measures. With the clock the timed rule reads made
    random (a busy machine's), two runs of the coarse pin-on-disc with heat (4 steps) agree bit for
    bit in every history column but the wall times; without the key the same clocks give runs
    that differ (the timed rule's decisions)."""
    import sys
    from multiscale.macro import mechanics
    from multiscale.scene import loads
    from multiscale.workflows import run
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    from test_macro_run import pin_on_disc
    text = pin_on_disc(tmp_path / "pod").replace("[output]", "[output]\nrepeatable = FLAG")

    def histories(flag):
        out = []
        for seed in (1, 2):
            clock = iter(np.cumsum(np.random.default_rng(seed).exponential(1.0, 100000)))
            monkeypatch.setattr(mechanics.time, "perf_counter", lambda: next(clock))
            h = run(loads(text.replace("FLAG", flag), overrides={"time.steps": 4}), verbose=False, overwrite=True).history
            out.append({k: np.asarray(v) for k, v in h.columns.items() if not k.startswith("time_")})
            monkeypatch.undo()
        return out

    first, second = histories("true")
    assert first.keys() == second.keys() and len(first["time"]) == 5
    assert all(np.array_equal(first[k], second[k]) for k in first)
    first, second = histories("false")
    assert not all(np.array_equal(first[k], second[k]) for k in first)
