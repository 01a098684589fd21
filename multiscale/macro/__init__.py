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
