"""Thermal boundary conditions on two MPI ranks give the serial history (convection, radiation, a fixed
temperature and its reaction, kappa(T) and c(T), the probes' readings; run: mpiexec -n 2 python -m
pytest tests/mpi)."""
import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from mpi4py import MPI  # noqa: E402

from multiscale.io import solver_statistic  # noqa: E402
from multiscale.scene import loads  # noqa: E402
from multiscale.workflows import run  # noqa: E402

SCENE = """
name = "stack_mpi"
effects = ["contact", "thermal", "conductance", "expansion"]
[geometry]
builder = "block_on_flat"
mesh_size = "2 mm"
[materials.block]
E = [["300 K", "200 GPa"], ["700 K", "150 GPa"]]
nu = 0.3
alpha = "1e-5 1/K"
kappa = [["300 K", 50], ["700 K", 30]]
rho = "7800 kg/m^3"
c = [["300 K", 450], ["700 K", 600]]
[materials.flat]
E = "200 GPa"
nu = 0.3
alpha = "1.2e-5 1/K"
kappa = "40 W/(m K)"
chi = "1e-5 m^2/s"
[interface]
penalty = "1e13 Pa/m"
conductance = "1e5 W/(m^2 K)"
[loading]
pressure = "1 MPa"
[time]
end = "20 s"
steps = 4
initial_temperature = "500 K"
[[boundary]]
surfaces = ["free:block"]
convection = "100 W/(m^2 K)"
emissivity = 0.8
ambient = "300 K"
[[boundary]]
surfaces = ["flat_bottom"]
temperature = "350 K"
[output]
folder = "{folder}"
fields = []
[output.probes.in_block]
point = ["3 mm", "4 mm", "2.5 mm"]
[output.probes.in_flat]
point = ["6 mm", "2 mm", "-1 mm"]
[output.probes.flat_face]
point = ["5 mm", "5 mm", "0 mm"]
body = "flat"
"""


def test_two_ranks_give_the_serial_thermal_history(tmp_path):
    world = MPI.COMM_WORLD
    assert world.size == 2, "run under mpiexec -n 2"
    base = world.bcast(str(tmp_path), root=0)
    parallel = run(loads(SCENE.format(folder=f"{base}/parallel")), comm=world, verbose=False).history
    serial = None
    if world.rank == 0:
        serial = run(loads(SCENE.format(folder=f"{base}/serial")), comm=MPI.COMM_SELF, verbose=False).history
    serial = world.bcast(serial.columns if serial is not None else None, root=0)
    assert set(serial) == set(parallel.columns) and "heat_lost_total_flat" in serial
    assert {"probe_temperature_in_block", "probe_temperature_in_flat", "probe_temperature_flat_face"} <= set(serial)
    for key in (k for k in serial if not solver_statistic(k)):
        np.testing.assert_allclose(parallel[key], serial[key], rtol=1e-8, atol=1e-8, err_msg=key)
    # energy: stored + lost = 0 in the stack (no frictional heat), to round-off
    stored = parallel["stored_heat_block"][-1] + parallel["stored_heat_flat"][-1]
    lost = parallel["heat_lost_total_block"][-1] + parallel["heat_lost_total_flat"][-1]
    assert stored + lost == pytest.approx(0.0, abs=1e-9 * abs(lost))


def test_runs_one_after_another_free_their_models(tmp_path, free_communicators):
    """Each run closes its model on every rank in the same order (``MacroModel.close``; MUMPS'
    destruction communicates): three runs in one two-rank process end, and from the second on a
    run leaves as many free communicators as it found. Before, every model stayed alive with about
    35 communicators (MPICH has 2048 per process); and models freed by each rank's collector, in
    its own order, hung a two-rank run at its end."""
    import gc      # local: this test alone looks at the collector
    world = MPI.COMM_WORLD
    base = world.bcast(str(tmp_path), root=0)
    scene = loads(SCENE.format(folder=f"{base}/again").replace("steps = 4", "steps = 1"))
    free = []
    for _ in range(3):
        run(scene, comm=world, verbose=False, overwrite=True)
        gc.collect()
        free.append(free_communicators())
    assert world.allgather(free[2] - free[1]) == [0, 0], free


def test_a_probe_outside_the_bodies_is_refused_on_every_rank(tmp_path):
    """Where a point lies is decided from every rank's cells: each rank raises the same error (none
    waits for another in a collective)."""
    from multiscale.errors import InputError
    from multiscale.workflows.model import build_model
    base = MPI.COMM_WORLD.bcast(str(tmp_path), root=0)
    scene = loads(SCENE.format(folder=f"{base}/out"), overrides={"output.probes.in_flat.point": ["6 mm", "2 mm", "-9 mm"]})
    with pytest.raises(InputError, match=r"output.probes.in_flat.point: \[6.0, 2.0, -9.0\] mm is in neither 'block' "
                                         r"nor 'flat': 4 mm outside its meshed surface \('block' spans \[0.0, 0.0, 0.0\] to \[10.0, 10.0, 5.0\] mm; "
                                         r"'flat' spans \[0.0, 0.0, -5.0\] to"):
        build_model(scene)
