"""Import first in every module that imports DOLFINx.

- The PyPI wheel needs ``dolfinx_solver`` loaded before ``dolfinx``/``petsc4py`` (absent on a
  conda-forge FEniCSx install, where this is a no-op).
- h5py must be loaded before ``dolfinx.fem.petsc``: with numba installed, that module loads
  libpetsc with global symbols (``llvmlite.binding.load_library_permanently``), and PETSc's HDF5
  then shadows the one bundled with h5py ("ValueError: Not a datatype" on ``import h5py``).
"""
import h5py  # noqa: F401,I001
try:
    import dolfinx_solver  # noqa: F401
except ImportError:  # pragma: no cover
    pass
