"""The zone-law pool under MPI (run by ``mpiexec -n 2 python -m pytest tests/mpi``; also passes on
one process): same laws as one process, each distinct zone solved once, failures reported on every
rank without deadlock."""
import numpy as np
import pytest
from mpi4py import MPI

from multiscale.errors import InputError
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.laws import ExtraLaw, LawSpec, compute_laws
from multiscale.micro.surface import Surface, fractal_surface
from multiscale.micro.zones import Zone, cut_zones
from multiscale.pool import CACHE_CALLS, MicroPool, PoolError

comm = MPI.COMM_WORLD
E = HalfSpace(1e9)
SPEC = LawSpec(E, p_max=3e6, n_points=8)


@pytest.fixture(scope="module")
def zones():
    s = fractal_surface(96, 1e-3, 0.8, 12, 24, 1e-6, seed=3)
    return cut_zones(s, (4, 4))[1]


def test_laws_equal_one_process_and_are_shared_out(zones):
    pool = MicroPool(SPEC)
    mine = zones[comm.rank::comm.size]
    laws = pool.laws(mine, gather="all")
    assert sorted(laws.ids.tolist()) == list(range(16))
    assert pool.stats.computed == 16 and pool.stats.failed == 0
    assert len(pool.stats.compute_seconds) == comm.size and min(pool.stats.compute_seconds) > 0
    serial = compute_laws(zones, SPEC)           # this process alone, other batches
    rows = serial.rows(laws.ids)
    # FFT round-off differs with the batches (and FFTW's measured plans): usually ~1e-13, at worst
    # one solver iteration more or less somewhere, i.e. the solver tolerance (~1e-7 in p)
    np.testing.assert_allclose(laws.mechanical.pressure, serial.mechanical.pressure[rows], rtol=2e-6)
    np.testing.assert_allclose(laws.mechanical.gap, serial.mechanical.gap[rows], rtol=2e-6)
    g = np.linspace(laws.mechanical.gap.min() - 1e-7, laws.mechanical.g_open.max(), 200)
    for zid in (0, 9):
        np.testing.assert_allclose(laws.pressure(g, np.full(200, zid)).pressure,
                                   serial.pressure(g, np.full(200, zid)).pressure, rtol=1e-5, atol=1e-3)
    own = pool.laws(mine)                        # nothing changed: all from the caches
    assert own.ids.tolist() == [z.id for z in mine]
    assert pool.stats.computed == 0 and pool.stats.cached == 16


def test_shared_zones_are_solved_once(zones):
    pool = MicroPool(SPEC)
    laws = pool.laws(zones[:3] + zones[3 + comm.rank:4 + comm.rank])
    assert pool.stats.computed == 3 + comm.size
    assert laws.ids.tolist() == [0, 1, 2, 3 + comm.rank]


def test_the_ranks_caches_stay_alike_over_many_gathered_calls(zones):
    """Zones 0-3 split over the ranks, zone 0 worn at every call, laws gathered from all: the
    bounded cache (``CACHE_CALLS`` x 4 laws) kept each rank's own requests longest, the ranks'
    caches parted, and a law one rank found cached the other could not return ("no law for these
    zones": a 2-rank coupling study). Every call returns the four laws; only zone 0 is solved."""
    pool = MicroPool(SPEC)
    for k in range(2 * CACHE_CALLS * 4):
        worn = [zones[0].with_heights(zones[0].surface.heights - k * 1e-9)] + zones[1:4]
        laws = pool.laws(worn[comm.rank::comm.size], gather="all")
        assert sorted(laws.ids.tolist()) == [0, 1, 2, 3]
        assert pool.stats.computed == (4 if k == 0 else 1)
    assert len(pool) == CACHE_CALLS * 4


class Fragile(ExtraLaw):
    """Raises for one zone (an unexpected exception inside a batch)."""

    tables = {"fragile": "hold"}

    def __init__(self, zone_id: int):
        self.zone_id = zone_id

    def key(self):
        return ("fragile", self.zone_id)

    def values(self, result, zones):
        if any(z.id == self.zone_id for z in zones):
            raise RuntimeError(f"boom in zone {self.zone_id}")
        return {"fragile": result.area_fraction}


def test_a_failing_zone_is_reported_on_every_rank_without_deadlock(zones):
    pool = MicroPool(LawSpec(E, p_max=3e6, n_points=8, extras=(Fragile(99),)))
    last = comm.size - 1
    s = zones[0].surface
    odd = Zone(99, Surface(s.heights[::-1].copy(), s.dx, s.dy, periodic=False))     # a topography of its own
    request = zones[comm.rank::comm.size] + ([odd] if comm.rank == last else [])
    with pytest.raises(PoolError) as info:
        pool.laws(request)
    assert [f.zone_id for f in info.value.failures] == [99]          # the same on every rank
    assert "boom in zone 99" in info.value.failures[0].message
    assert info.value.result.ids.tolist() == [z.id for z in zones[comm.rank::comm.size]]
    fragile = LawSpec(E, p_max=3e6, n_points=6, extras=(Fragile(5),))
    with pytest.raises(PoolError) as info:
        pool.laws(zones[comm.rank::comm.size], spec=fragile, gather="all")
    assert [(f.zone_id, f.kind) for f in info.value.failures] == [(5, "RuntimeError")]
    assert len(info.value.result) == 15
    comm.barrier()                                                   # everyone got here
    assert len(pool.laws(zones[:2])) == 2                            # and the pool still works


def test_ranks_must_agree_on_the_spec(zones):
    spec = SPEC if comm.rank == 0 else LawSpec(E, p_max=4e6, n_points=8)
    if comm.size == 1:
        pytest.skip("needs two ranks")
    with pytest.raises(InputError, match="same LawSpec"):
        MicroPool(SPEC).laws(zones[:1], spec=spec)
