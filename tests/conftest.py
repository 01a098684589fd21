"""Loaded by pytest before any test module (tests/mpi included)."""
# h5py before anything imports dolfinx.fem.petsc: see multiscale/macro/__init__.py
import h5py  # noqa: F401
