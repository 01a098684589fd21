"""Squeal analysis on 2 ranks equals the serial one (preload forces, complex modes, MAC, energies)."""
from types import SimpleNamespace as NS

import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from mpi4py import MPI  # noqa: E402

from multiscale.geometry import builder  # noqa: E402
from multiscale.macro import mesh as two_body  # noqa: E402
from multiscale.macro import modal  # noqa: E402
from multiscale.macro.mechanics import Mechanics  # noqa: E402
from multiscale.workflows.squeal import squeal_case  # noqa: E402

STEEL = NS(E=210e9, nu=0.3, rho=7850.0)
MATERIALS = {"disc": NS(E=125e9, nu=0.25, rho=7200.0), "pad": NS(E=5e9, nu=0.25, rho=2500.0),
             "backplate": STEEL, "piston": STEEL, "caliper": STEEL}


def case(comm, prefix):
    tm = two_body.build(builder("disc_brake"), {"mesh_size": 0.02}, comm)
    mech = Mechanics(tm, MATERIALS, stiffness=1e13, friction=0.4, speed=5.0, load_kind="fluid", prefix=prefix)
    return squeal_case(mech, MATERIALS, "mpi", load=1e6, n_modes=20)


def test_two_ranks_reproduce_the_serial_squeal_analysis():
    comm = MPI.COMM_WORLD
    assert comm.size == 2
    par = case(comm, "squeal_mpi_par_")
    ref = comm.bcast(None if comm.rank else _summary(case(MPI.COMM_SELF, "squeal_mpi_ser_")), root=0)
    got = _summary(par)
    np.testing.assert_allclose(got["eigenvalues"], ref["eigenvalues"], rtol=1e-8, atol=1e-6)
    np.testing.assert_allclose(got["forces"], ref["forces"], rtol=1e-10)
    np.testing.assert_allclose(got["energy"], ref["energy"], atol=1e-6)
    assert got["unstable"] == ref["unstable"]
    np.testing.assert_allclose(np.diag(modal.mac_matrix(par.modes, par.modes)), 1.0, rtol=1e-12)


def _summary(c):
    return {"eigenvalues": c.modes.eigenvalues, "forces": list(c.preload.normal_force.values()),
            "energy": c.energy.share, "unstable": c.report.unstable.tolist()}
