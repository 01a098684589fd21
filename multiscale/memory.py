"""How much memory this process may use [bytes]: the machine's, or less where a container or a
batch job (a cgroup's limit, v1 or v2: Docker, Kubernetes, Slurm) or ``ulimit -v`` sets less. A
guard that compared with the machine's memory let a job ask for more than its container holds,
to be ended by the OOM killer without a word (a review, 2026-12-04)."""
from __future__ import annotations

import os
import resource
from pathlib import Path

CGROUP, OWN = Path("/sys/fs/cgroup"), Path("/proc/self/cgroup")    # the mount; this process's cgroups
V2, V1 = ("memory.max", "memory.current"), ("memory.limit_in_bytes", "memory.usage_in_bytes")


def _number(path: Path) -> float | None:
    """A cgroup file's number [bytes]: inf for "max" or v1's page-rounded 2^63; None where absent."""
    try:
        text = path.read_text().split()[0]
    except (OSError, IndexError):
        return None
    value = float("inf") if text == "max" else float(text) if text.isdecimal() else None
    return float("inf") if value is not None and value >= 2 ** 62 else value


def _limit_files() -> list[tuple[Path, Path]]:
    """(limit, usage) files of the cgroups that may bound this process: the mount's root (a
    container's own cgroup is its root), the process's own (/proc/self/cgroup) and those between
    (a Slurm job's limit is its job's, above its step's and task's), v2 and v1."""
    folders = [(CGROUP, V2), (CGROUP / "memory", V1)]
    try:
        lines = OWN.read_text().splitlines()
    except OSError:
        lines = []
    for line in lines:
        _, controllers, where = line.split(":", 2)
        if controllers == "" or "memory" in controllers.split(","):
            base, files = (CGROUP, V2) if controllers == "" else (CGROUP / "memory", V1)
            parts = [p for p in where.split("/") if p]
            folders += [(base.joinpath(*parts[:k]), files) for k in range(1, len(parts) + 1)]
    return [(folder / cap, folder / used) for folder, (cap, used) in folders]


def _cgroup_limits() -> tuple[float, float]:
    """(the lowest cgroup memory limit, the least room under one: its limit less its usage)
    [bytes]; (inf, inf) where none is set."""
    limit = room = float("inf")
    for cap_file, used_file in _limit_files():
        if (cap := _number(cap_file)) is not None and cap < float("inf"):
            limit, room = min(limit, cap), min(room, cap - (_number(used_file) or 0.0))
    return limit, room


def memory_limit() -> float:
    """The most memory this process may hold [bytes]: the least of the machine's, a cgroup's limit
    and ``ulimit -v`` (inf where none can be read)."""
    try:
        machine = float(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        machine = float("inf")
    soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    return min(machine, _cgroup_limits()[0], float("inf") if soft == resource.RLIM_INFINITY else float(soft))


def beyond_limit(need: float) -> float | None:
    """The most memory this process may hold [bytes] (``memory_limit``) if ``need`` [bytes] exceeds it,
    else None. Below 1 GiB, which any machine holds, the limit is not read (a read takes 0.13 ms:
    the contact solver asks at every solve)."""
    if need <= 2**30:
        return None
    have = memory_limit()
    return have if need > have else None


def memory_available() -> float | None:
    """Memory this process can take now without swapping or the OOM killer [bytes]: Linux's
    MemAvailable (/proc/meminfo), or a cgroup's limit less its usage where that is less; None
    where MemAvailable cannot be read (not Linux)."""
    try:
        with open("/proc/meminfo") as f:
            free = next(float(line.split()[1]) * 1024 for line in f if line.startswith("MemAvailable:"))
    except (OSError, StopIteration, ValueError, IndexError):
        return None
    return min(free, _cgroup_limits()[1])


# Peak memory [bytes] of a run with n displacement dofs: ranks x BASE + SCALE (n / 1e5)^(4/3), the
# factors' fill under nested dissection in 3-D (George 1973; MUMPS orders by METIS), for a squeal run
# MODE_MEMORY n m for m modes asked for (the eigensolver's subspace and the modes kept), and for a
# transient run with heat HEAT_MEMORY (n_T / 1e5)^(4/3) for n_T temperature dofs, twice that where the
# heat problem is linear (constant properties, no radiation: macro.thermal keeps double-precision LU
# factors, the Newton's are single). Fitted to runs measured serially (peak RSS by /usr/bin/time -v,
# docs/performance.rst): "squeal" (2026-12-05), quadratic tetrahedra, the default method, the demo car
# brake (35k-253k dofs, 60 modes) and the built-in brake (49k-106k dofs, 40 and 100 modes), within 7 %;
# "transient" (2026-12-05, refitted after a user trial measured the thesis pin-on-disc at 1.5x the
# estimate: its linear heat's factors are double), the car brake (nonlinear heat) and the perfect-contact
# pin-on-disc (linear), 8k-60k dofs, each with and without heat, -12 % to +10 %: the pin-on-disc's
# factors fill more than the car brake's at the same dofs. Other shapes fill otherwise and larger models
# are extrapolated: an estimate, not a bound; a run warns when SPREAD times it exceeds the free memory.
RUN_MEMORY = {"squeal": (0.56e9, 1.66e9), "transient": (0.33e9, 1.20e9)}
MODE_MEMORY = 89.0       # bytes a displacement dof and a mode asked for (stability.modes)
HEAT_MEMORY = 0.36e9     # bytes per (temperature dofs / 1e5)^(4/3), single-precision factors
HEAT_DOFS = 1.7          # temperature dofs a displacement dof (P2 in the rotating body): 1.4-1.8 measured
DOFS_PER_CELL = {"squeal": 5.0, "transient": 0.64}     # displacement dofs per tetrahedron (the larger meshes)
SPREAD = 1.15            # the measured runs' largest under-estimate (12 %), with a margin
# A stability map's peak over its single analysis' (two points' systems and modes held at once, and a
# point's refinement): the built-in brake at 20 mm, 30 modes to 8 kHz, 1.30 GB alone; a friction map
# ("each") of 3 and 5 points 1.72 and 1.76 GB, a speed map ("once") of 3 points 1.50 GB (2026-12-05,
# /usr/bin/time -v, serial; a user trial measured 1.35x where check said the single analysis' figure)
MAP_MEMORY = {"each": 1.36, "once": 1.16}


# The multiscale loop's micro part [bytes], ranks x base + per_point x its zones' grid points, fitted to
# peaks measured serially above the macro run's (/usr/bin/time -v, 2026-12-05, docs/performance.rst): the
# rough pin-on-disc of 6 606 dofs (measured face, wear, partition law, 6 law points; 0.39 GB without its
# roughness) at 3x3 zones of 16^2, 8x8 of 64^2 and 8x8 of 128^2 points, +0.147 / 0.458 / 1.352 GB, within 4 %.
MICRO_MEMORY = (0.15e9, 1140.0)


def micro_memory(points: float, ranks: int = 1) -> float:
    """The estimated memory [bytes] the multiscale loop's zones of ``points`` grid points in all add to
    the macro run's on ``ranks`` processes (``MICRO_MEMORY``; their points counted whole on each rank)."""
    base, per_point = MICRO_MEMORY
    return ranks * base + per_point * points


def run_memory(dofs: float, kind: str, ranks: int = 1, modes: int = 0, heat_dofs: float = 0.0,
               linear_heat: bool = False, sweep: str | None = None) -> float:
    """The estimated peak memory [bytes] of a run of ``kind`` ("squeal" or "transient") with
    ``dofs`` displacement dofs on ``ranks`` processes, a squeal run asking for ``modes`` modes, and
    with a stability map of preload ``sweep`` ("each", "once"), a transient one with ``heat_dofs``
    temperature dofs, their problem linear or not (``RUN_MEMORY``, ``MODE_MEMORY``, ``MAP_MEMORY``,
    ``HEAT_MEMORY``)."""
    base, scale = RUN_MEMORY[kind]
    heat = HEAT_MEMORY * (2 if linear_heat else 1) * (heat_dofs / 1e5) ** (4 / 3)
    one = ranks * base + scale * (dofs / 1e5) ** (4 / 3) + MODE_MEMORY * dofs * modes + heat
    return one * MAP_MEMORY.get(sweep, 1.0)


def remedy(squeal: bool) -> str:
    """What lowers a run's memory, as the messages that warn of it or report its lack say it."""
    return "a coarser mesh (geometry.mesh_size)" + (', stability.method = "subspace" (a squeal run)' * squeal) + \
        " or ranks on more machines (docs/performance.rst, Memory)"
