"""Macro scale (DOLFINx): bodies coupled through flat contact interfaces; never sees a scene.

``mesh`` (bodies, interface measure, per-facet fields), ``interface`` (penalty/law contact,
friction, frictional heat), ``laws_ufl`` (tabulated zone laws in UFL), ``mechanics``, ``thermal``,
``model`` (the sequential thermo-mechanical step of thesis Fig. 7.4), ``output`` (XDMF fields),
``eigen`` (SLEPc eigensolvers), ``preload`` (steady sliding state and its linearisation) and
``modal`` (MAC, strain energies, mode shapes). The scene is read by ``multiscale.workflows``.

Importing this package loads what DOLFINx's PyPI wheel needs first, before any submodule imports
DOLFINx (every DOLFINx import of the package lives in ``multiscale.macro``):

- ``dolfinx_solver`` must precede ``dolfinx``/``petsc4py``/``slepc4py`` (absent on a conda-forge
  FEniCSx install, where this is a no-op);
- h5py must precede ``dolfinx.fem.petsc``: with numba installed, that module loads libpetsc with
  global symbols (``llvmlite.binding.load_library_permanently``), and PETSc's HDF5 then shadows the
  one bundled with h5py ("ValueError: Not a datatype" on ``import h5py``).
"""
import h5py  # noqa: F401,I001  (before DOLFINx, see above)

try:
    import dolfinx_solver  # noqa: F401
except ImportError:  # pragma: no cover  (conda-forge FEniCSx)
    pass

import os  # noqa: E402

from mpi4py import MPI  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

from multiscale.signals import keep_python_handlers  # noqa: E402

# One BLAS thread per MPI rank unless the user chose a number: OpenBLAS' threads otherwise spin on
# the cores of the other ranks (dense block products of the modal analysis measured 21x slower with
# 2 ranks on the 2-core machine; docs/architecture.md).
if MPI.COMM_WORLD.size > 1 and not {"OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"} & set(os.environ):
    threadpool_limits(1, user_api="blas")

from petsc4py import PETSc  # noqa: E402

# PETSc's initialisation takes SIGPIPE, which Python ignores (a write into a closed pipe raises
# BrokenPipeError, on which the command line ends quietly with status 141): a run piped into
# ``head``, or into a ``tee`` that died, was aborted by PETSc ("Caught signal number 13 Broken
# Pipe", MPI_Abort) wherever it was, its files half written; and SIGTERM and SIGHUP, which the
# command line takes as Ctrl-Cs (a 2-rank squeal run sent SIGTERM in its eigen solve was aborted
# by PETSc, "Caught signal number 15", its provenance left "running"). Python's handling is restored.
keep_python_handlers()

# PETSc (3.25; option -vec_mdot_use_gemv, on by default) computes VecMDot, the orthogonalisation
# of (F)GMRES, by BLAS gemv over runs of vectors that happen to lie at one stride in memory and by
# its own loops otherwise: its rounding followed the heap's layout, and two serial runs of the same
# scene differed from the first macro Newton solve on (docs/architecture.md, "Repeatability"). Its
# loops always, unless the user chose (vectors read the option when created: before any DOLFINx
# object exists; read here once, so that a process that makes no vector is not warned of an unused
# option at exit).
for _option in ("vec_mdot_use_gemv", "vec_maxpy_use_gemv"):
    if not PETSc.Options().hasName(_option):
        PETSc.Options()[_option] = False
    PETSc.Options().getBool(_option)
