"""Import first in every module that imports DOLFINx: the PyPI wheel needs ``dolfinx_solver``
loaded before ``dolfinx``/``petsc4py`` (absent on a conda-forge FEniCSx install, where this is a no-op)."""
try:
    import dolfinx_solver  # noqa: F401
except ImportError:  # pragma: no cover
    pass
