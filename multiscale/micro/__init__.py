"""Micro scale: one rough patch (or a batch of patches) at a time.

numpy/scipy/pyfftw only: nothing here imports DOLFINx or MPI, so a micro solve runs in any
worker process. Arrays are ``h[..., ny, nx]`` in metres; leading axes are batches of patches.
"""
