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

# One BLAS thread per MPI rank unless the user chose a number: OpenBLAS' threads otherwise spin on
# the cores of the other ranks (dense block products of the modal analysis measured 21x slower with
# 2 ranks on the 2-core machine; docs/architecture.md).
if MPI.COMM_WORLD.size > 1 and not {"OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"} & set(os.environ):
    threadpool_limits(1, user_api="blas")
