"""MPI-parallel pool of zone micro solves (thesis §7.2: one micro-contact analysis per zone).

Each macro step, every rank hands the pool the zones it needs laws for (its own facets' zones, or
all of them); the pool computes each distinct topography once, spread over the ranks, and hands
every rank back the laws it asked for. Collective: every rank of ``comm`` must call ``laws``.

- Work: zones not in the cache, deduplicated by (topography hash, spec), sorted by zone id and cut
  into batches of equal grids (``laws.batches``); the batches go to ranks by a greedy
  longest-first partition on their expected cost (the measured time of the zone's previous law,
  else its grid size). The costs of the work are known on every rank, so every rank derives the
  same partition without a master; zones change slowly between steps (wear), so the last
  measured times predict the next ones well — a static partition then balances as well as a
  dynamic queue (mpi4py.futures) would, without a scheduler rank or a process spawn.
- Results do not depend on the number of ranks or on the partition beyond round-off: a zone's
  solve does not depend on its batch-mates (the batched solver iterates each patch on its own),
  only the rounding of the batched FFTs does (the FFT plans are the same in every process:
  ``micro.fft``). Laws agree to ~1e-13, not bitwise (to the solver tolerance in the rare case
  where round-off moves a residual across it and an iteration count changes); on a given number
  of ranks the batches are the same in every run. Batches hold at most a quarter
  of a rank's share, so that the partition can balance.
- Cache: every rank keeps the laws it received (least recently requested out first), keyed by
  (topography hash, ``LawSpec.key()``: kernel, E*, p_max, nodes, Love variant, tolerances,
  extra laws); a zone whose topography did not change is not recomputed. It holds ``cache_size``
  laws, by default ``CACHE_CALLS`` times the most any call asked for: a worn zone's earlier
  topographies are never asked for again, and a fixed 100 000 laws grew a 800-step run by
  70 kB a step toward ~0.5 GB per rank (a long-run trial).
- Failures (non-convergence, non-monotone law, any exception in a zone's solve) are caught per
  batch, gathered with their zone ids, and raised as ``PoolError`` on every rank after the
  collective exchange: no rank is left waiting.

The pool imports numpy, mpi4py and ``multiscale.micro`` only, never DOLFINx. Use, each step::

    pool = MicroPool(LawSpec(HalfSpace.from_materials(5e9, 0.3, 220e9, 0.3), p_max=10e6))
    laws = pool.laws(my_zones)                   # collective; unchanged zones come from the cache
    value = laws.pressure(gap, zone_of_facet)    # p_n and K_n per facet (ZoneGrid.zone_of)
"""
from __future__ import annotations

import hashlib
import time
from collections import OrderedDict
from dataclasses import dataclass, replace

import numpy as np
from mpi4py import MPI

from multiscale import io
from multiscale.errors import InputError
from multiscale.micro.laws import (LawError, LawSpec, ZoneFailure, ZoneLaws, ZoneNodes, batch_signature,
                                   batches, zone_nodes)
from multiscale.micro.zones import Zone


class PoolError(LawError):
    """Some zones' laws failed (on any rank); raised on every rank with the same failures."""


@dataclass(frozen=True)
class PoolStats:
    """What the last ``laws`` call did (identical on every rank)."""

    requested: int              # distinct zones asked for, over all ranks
    cached: int                 # of which found in the requesting ranks' caches
    computed: int               # solved in this call (including failures)
    failed: int
    compute_seconds: tuple      # per rank, time spent in micro solves
    wall_seconds: float         # of the whole call on this rank


CACHE_CALLS = 4      # the default cache holds this many times the laws of the largest call


class MicroPool:
    """Distributes the laws of zones over the ranks of ``comm`` (default COMM_WORLD).

    ``spec``: default ``LawSpec`` of every call; ``cache_size``: laws remembered per rank (None:
    ``CACHE_CALLS`` times the most distinct topographies a call has asked for).
    """

    def __init__(self, spec: LawSpec, comm=None, cache_size: int | None = None, progress: bool = False):
        self.spec = spec
        self.comm = comm if comm is not None else MPI.COMM_WORLD
        self.cache_size = None if cache_size is None else int(cache_size)
        self._largest = 0                        # distinct topographies of the largest call, over the ranks
        self.progress = progress
        self._cache: OrderedDict[tuple, ZoneNodes] = OrderedDict()
        self._seconds: dict[int, float] = {}     # zone id -> last measured solve time
        self.stats: PoolStats | None = None

    def __len__(self) -> int:
        """Laws remembered on this rank."""
        return len(self._cache)

    def laws(self, zones: list[Zone], spec: LawSpec | None = None, gather: str = "own") -> ZoneLaws:
        """Laws of ``zones`` (this rank's request), computed once across all ranks.

        ``gather='own'`` returns the laws of this rank's zones (possibly none);
        ``'all'`` those of every zone requested by any rank. Raises ``PoolError`` (on every
        rank) if any zone failed; its ``result`` holds the laws that succeeded.
        """
        t0 = time.perf_counter()
        spec = spec or self.spec
        if gather not in ("own", "all"):
            raise InputError("gather", gather, "one of 'own', 'all'")
        comm = self.comm
        spec_key = hashlib.sha1(repr(spec.key()).encode()).hexdigest()
        zones = list(zones)
        requested = [(z.id, (z.topography_hash, spec_key)) for z in zones]
        misses: dict[tuple, Zone] = {}
        for z, (_, key) in zip(zones, requested):
            if key not in self._cache:
                misses.setdefault(key, z)
        # every rank learns every request: its misses (zone id, key, batch signature, expected cost)
        mine = [(z.id, key, batch_signature(z), self._expected_cost(z, spec)) for key, z in misses.items()]
        shared = comm.allgather((spec_key, mine, len(zones) - sum(k in misses for _, k in requested),
                                 requested if gather == "all" else None))
        if len({sk for sk, _, _, _ in shared}) != 1:
            raise InputError("spec", spec, "every rank must ask for the same LawSpec")
        asked = {k for _, m, _, _ in shared for _, k, _, _ in m} | ({k for _, _, _, req in shared for _, k in req}
                                                                   if gather == "all" else {k for _, k in requested})
        self._largest = max(self._largest, len(asked))
        # asked for again: kept longest, in one order on every rank (with gather 'all' the ranks' caches must
        # stay alike: a law one rank finds cached, every rank returns; refreshed by each rank's own requests,
        # they parted, and a 2-rank run stopped with "no law for these zones")
        for key in sorted(k for k in asked if k in self._cache):
            self._cache.move_to_end(key)
        known = {k: self._cache[k] for k in asked if k in self._cache}
        work, owner = self._plan_work([m for _, m, _, _ in shared])
        plan = self._partition(work, spec)

        # move each batch's zones from the rank holding them to the rank solving them
        outgoing = [[] for _ in range(comm.size)]
        for rank, batch in plan:
            outgoing[rank] += [misses[key] for _, key, _, _ in batch if owner[key] == comm.rank]
        received = {z.topography_hash: z for sent in comm.alltoall(outgoing) for z in sent}

        t1 = time.perf_counter()
        nodes, failures = [], []
        name = "zone laws" if spec.p_max == self.spec.p_max else f"zone laws up to p_max = {spec.p_max:.3g} Pa"
        for batch in _progress([b for rank, b in plan if rank == comm.rank], self.progress and comm.rank == 0, name):
            key_of = {zid: key for zid, key, _, _ in batch}
            try:
                n, f = zone_nodes([received[key[0]] for _, key, _, _ in batch], spec)
            except Exception as exc:  # never leave the other ranks waiting in the exchange below
                n, f = [], [ZoneFailure(zid, type(exc).__name__, str(exc)) for zid in key_of]
            nodes += [(nd, key_of[nd.zone_id]) for nd in n]
            failures += f
        seconds = time.perf_counter() - t1

        gathered = comm.allgather((nodes, failures, seconds))
        all_failures = [f for _, fs, _ in gathered for f in fs]
        for ns, _, _ in gathered:
            for nd, key in ns:
                self._remember(key, nd)
                known[key] = nd
        self.stats = PoolStats(
            requested=sum(len(m) for _, m, _, _ in shared) + sum(h for _, _, h, _ in shared),
            cached=sum(h for _, _, h, _ in shared), computed=len(work), failed=len(all_failures),
            compute_seconds=tuple(s for _, _, s in gathered), wall_seconds=time.perf_counter() - t0)

        if gather == "all":
            requested = sorted({item for _, _, _, req in shared for item in req})
        key_of = {zid: key for zid, key, _, _ in work}     # a failed topography fails every zone that has it
        by_key = {key_of[f.zone_id]: f for f in all_failures}
        shared_failures = {zid: replace(by_key[key], zone_id=zid) for zid, key in requested if key in by_key}
        all_failures = sorted(({f.zone_id: f for f in all_failures} | shared_failures).values(),
                              key=lambda f: f.zone_id)
        failed = {f.zone_id for f in all_failures}
        found = [replace(known[key], zone_id=zid) for zid, key in requested if zid not in failed and key in known]
        result = ZoneLaws(found, spec)
        if all_failures:
            raise PoolError(all_failures, result)
        return result

    # ------------------------------------------------------------------ internals
    def _plan_work(self, requests):
        """Distinct uncached topographies over all ranks, sorted by (zone id, key), and the rank
        holding each one's data (the lowest requesting rank)."""
        work, owner, ids = {}, {}, {}
        for rank, req in enumerate(requests):
            for zid, key, sig, cost in req:
                if key not in owner:
                    owner[key] = rank
                    work[key] = (zid, key, sig, cost)
                if ids.setdefault(zid, key) != key:
                    raise InputError("zones", zid, "two ranks sent different topographies for one zone id")
        return sorted(work.values(), key=lambda item: (item[0], item[1])), owner

    def _partition(self, work, spec):
        """Batches of the work list, assigned longest-first to the least-loaded rank."""
        size = self.comm.size
        share = -(-len(work) // (4 * size)) if size > 1 else None   # >= 4 batches per rank
        groups = [[work[i] for i in idx] for idx in batches([w[2] for w in work], spec.batch_cells, share)]
        cost = [sum(item[3] for item in g) for g in groups]
        load = np.zeros(size)
        plan = []
        for g in sorted(range(len(groups)), key=lambda i: (-cost[i], i)):
            rank = int(np.argmin(load))
            load[rank] += cost[g]
            plan.append((rank, groups[g]))
        return sorted(plan, key=lambda rb: rb[1][0][0])

    def _expected_cost(self, zone: Zone, spec: LawSpec) -> float:
        """Seconds of the zone's previous solve, else its size times the measured mean rate."""
        if zone.id in self._seconds:
            return self._seconds[zone.id][0]
        size = zone.shape[0] * zone.shape[1] * spec.n_points
        if not self._seconds:
            return 1e-6 * size
        rates = np.array([sec / cells for sec, cells in self._seconds.values()])
        return float(np.median(rates)) * size

    def _remember(self, key, nodes: ZoneNodes):
        self._cache[key] = nodes
        self._cache.move_to_end(key)
        self._seconds[nodes.zone_id] = (nodes.seconds, nodes.cells * len(nodes.pressure))
        while len(self._cache) > (self.cache_size or CACHE_CALLS * self._largest):
            self._cache.popitem(last=False)


def _progress(items, show: bool, name: str):
    """The active reporter's bar (one line under a terminal, inside the running stage's line);
    ``name`` says a halved p_max (the retry of failed laws printed a second "zone laws: 1/1
    batches" line, as if the same were said twice; a user trial)."""
    return io.bar(items, name, unit="batch") if show else items
