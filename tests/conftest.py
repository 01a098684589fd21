"""Loaded by pytest before any test module (tests/mpi included)."""
# h5py before anything imports dolfinx.fem.petsc: see multiscale/macro/__init__.py
import h5py  # noqa: F401
import os

# CI (.ci/run) sets MULTISCALE_REQUIRE_DOLFINX=1: the DOLFINx tests must then run, not skip.
if os.environ.get("MULTISCALE_REQUIRE_DOLFINX") == "1":
    import dolfinx_solver  # noqa: F401  (a missing DOLFINx fails the run instead of skipping tests)

# pytest.approx adds an absolute tolerance of 1e-12 unless told otherwise: with SI values (a worn
# volume of 1e-12 m^3, a compliance of 1e-15 m/Pa) that makes a relative check unable to fail. Here
# the tolerance is what the test states: relative only, unless it gives ``abs`` itself.
import pytest  # noqa: E402

_approx = pytest.approx


def _relative_approx(expected, rel=None, abs=None, nan_ok=False):
    return _approx(expected, rel=rel, abs=0.0 if abs is None and rel is not None else abs, nan_ok=nan_ok)


pytest.approx = _relative_approx


@pytest.fixture
def petsc_options():
    """``petsc_options(name=value, ...)`` puts options into PETSc's database for one test; they are
    removed after it (petsc4py imported on use: after h5py, as above)."""
    from petsc4py import PETSc
    names = []

    def put(**options):
        for name, value in options.items():
            PETSc.Options()[name] = value
            names.append(name)
    yield put
    for name in names:
        PETSc.Options().delValue(name)


@pytest.fixture
def free_communicators():
    """``free_communicators()``: the MPI communicators this process can still create (MPICH: 2048
    in all), found by duplicating COMM_SELF until MPI refuses (mpi4py raises) and freeing them."""
    from mpi4py import MPI    # on use: after h5py, as above

    def count() -> int:
        made = []
        try:
            while len(made) < 10000:
                made.append(MPI.COMM_SELF.Dup())
        except MPI.Exception:
            pass
        for comm in made:
            comm.Free()
        return len(made)
    return count


@pytest.fixture(scope="session")
def documented():
    """``documented(name)``: whether docs/results.rst names a results file's column or dataset
    ``name`` as a literal, ``<body>``, ``<name>``, ``<material>`` standing for any name."""
    import re
    from pathlib import Path
    doc = (Path(__file__).resolve().parents[1] / "docs" / "results.rst").read_text()
    literals = [re.sub(r"<(body|name|material)>", "[A-Za-z0-9_.-]+", re.escape(literal))
                for literal in re.findall(r"``([^`]+)``", doc) if not re.fullmatch(r"<\w+>", literal)]
    return lambda name: any(re.fullmatch(literal, name) for literal in literals)


@pytest.fixture(scope="module", autouse=True)
def models_closed():
    """Every ``Mechanics`` and ``Thermal`` a test module builds is closed after the module (their
    ``close``: collective, in the same order on every rank). A model not closed keeps its MPI
    communicators (about 35-100 of MPICH's 2048; docs/architecture.md §7, known problems), so
    several test modules in one pytest process ended in MPICH's abort (exit code 15). Held by weak
    references: a model closed and dropped by a test is freed (tests check that); one not closed is
    kept alive by PETSc, on every rank."""
    import sys
    import weakref
    built, patched = [], []
    for name, kind in (("multiscale.macro.mechanics", "Mechanics"), ("multiscale.macro.thermal", "Thermal")):
        module = sys.modules.get(name)           # imported by the test module, if it builds models
        if module is None:
            continue
        cls = getattr(module, kind)
        patched.append((cls, cls.__init__))

        def tracked(self, *args, __init__=cls.__init__, **kwargs):
            __init__(self, *args, **kwargs)
            built.append(weakref.ref(self))
        cls.__init__ = tracked
    yield
    for cls, init in patched:
        cls.__init__ = init
    for ref in reversed(built):
        if (model := ref()) is not None:
            model.close()


@pytest.fixture
def keep_figures(monkeypatch):
    """``keep(module)``: the matplotlib ``Figure`` objects that ``module`` (a ``multiscale.plots``
    module) makes from then on, kept in the list returned, to be inspected."""
    def keep(module) -> list:
        figures = []

        class Kept(module.Figure):
            def __init__(self, *args, **kwargs):
                super().__init__(*args, **kwargs)
                figures.append(self)
        monkeypatch.setattr(module, "Figure", Kept)
        return figures
    return keep
