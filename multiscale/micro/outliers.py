"""Outliers of a measured topography: isolated points and small clusters (spikes, pits) an
instrument made, found as a Hampel filter finds them and reported; ``topography.condition`` removes
them on request (marked undefined, then filled like the instrument's missing points).

A point is an outlier when its height deviates from the median of its 9 x 9 neighbourhood by more
than k times the Sq of the other heights (found to a fixed point): the Hampel identifier (Pearson
2002, IEEE Trans. Control Syst. Technol. 10, 55-63) with the heights' scale instead of the
residuals' robust one, 1.4826 times their median absolute deviation: on the shared files that is
the instrument's noise, 7e-4 to 0.14 Sq, and k = 8 times it flagged 126 to 170 000 real points;
the heights' robust one is 0.3 Sq on tests/data/top-1.top (its edge points on slopes were flagged).
The median is the separable one (the median along y of the medians along x, Narendra 1981, IEEE
Trans. PAMI 3, 20-29), several times cheaper than the 9 x 9 one and as robust to the pits of 2 x 2
to 6 x 6 points of sur-2.sur (a 3 x 3 median kept its Sku at 690, a 5 x 5 one at 165). ISO 25178-3
counts outlier removal among the pre-processing before the F-operator, prescribing no method.
Features narrower than half the neighbourhood (a scratch of a few pixels) are outliers too:
nothing is removed unless asked.

False positives: a Gaussian surface of uncorrelated heights is the worst case (correlated heights
deviate less from their neighbours' median): a point deviates from a median of about 0, at a rate
of about 2Φ(−k) a point, 2.6e-12 at the default k = 7: none expected on maps below 1e11 points.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multiscale.micro.surface import defined_sums, row_blocks

HALO = 4                # the median's neighbourhood: (2 HALO + 1)² points
DESPIKE = 7.0           # default threshold k [Sq of the other heights]
CLIP = 2.0              # the Sq without the outliers is taken no lower than the Sq with them / CLIP
DOMINATED = 0.5         # outliers carrying more of the 3rd or 4th absolute moment dominate Ssk or Sku
SLOPES = 0.1            # a share of Sdq² above which the warning names the slopes and the spectrum


@dataclass(frozen=True)
class Outliers:
    """Outliers of a height map (``find_outliers``): their ``rows`` and ``cols``, ``deviations`` [m]
    from their neighbourhood's median (+: a spike, −: a pit), the threshold ``k`` in units of ``sq``
    [m], the Sq of the other defined heights, and the ``shares`` of the heights' third and fourth
    absolute central moments (Ssk's, Sku's) the outliers carry."""

    rows: np.ndarray
    cols: np.ndarray
    deviations: np.ndarray
    k: float
    sq: float
    shares: tuple[float, float]
    sq_of: str = ""            # what the Sq is of, if not the heights ("the roughness at λc = 0.5 mm")

    @property
    def count(self) -> int:
        return int(self.rows.size)

    @property
    def largest(self) -> float:
        """The deviation [m] of largest magnitude (0 without outliers)."""
        return float(self.deviations[np.argmax(np.abs(self.deviations))]) if self.count else 0.0

    @property
    def dominated(self) -> bool:
        """Whether Ssk or Sku are the outliers' rather than the surface's."""
        return max(self.shares) > DOMINATED

    def describe(self) -> str:
        """What they are: "points deviating from the median of ... (Sq 13.8 nm without them), up to -89 Sq"."""
        side = 2 * HALO + 1
        return (f"point{'s' if self.count != 1 else ''} deviating from the median of their {side} x {side} "
                f"neighbourhood by more than {self.k:g} Sq (Sq {self.sq * 1e9:.3g} nm"
                f"{f' {self.sq_of}' if self.sq_of else ''} without them), up to "
                f"{self.largest / self.sq:+.3g} Sq ({self.largest * 1e9:+.4g} nm)")

    def gradient_share(self, heights: np.ndarray, dx: float, dy: float) -> float:
        """The share of Sdq² (the mean squared slope of the forward differences of ``heights`` [m],
        pixels ``dx`` x ``dy`` [m]; pairs with an undefined point left out) that the outliers carry:
        what it loses when each takes its neighbourhood's median. The map's sum in row blocks, the
        change on the differences next to the outliers."""
        total = 0.0
        for rows in row_blocks(*heights.shape):
            block = heights[rows.start:min(rows.stop + 1, heights.shape[0])]
            total += np.nansum((np.diff(block[:rows.stop - rows.start], axis=1) / dx) ** 2) \
                + np.nansum((np.diff(block, axis=0) / dy) ** 2)
        if not self.count or total <= 0:
            return 0.0
        fixed = {(i, j): heights[i, j] - d for i, j, d in zip(self.rows, self.cols, self.deviations)}
        starts = {(i + a, j + b) for i, j in fixed for a in (-1, 0) for b in (-1, 0) if i + a >= 0 and j + b >= 0}
        ny, nx = heights.shape
        lost = 0.0
        for i, j in starts:             # the pairs (i, j)-(i, j+1) and (i, j)-(i+1, j) an outlier is in
            for (a, b), step in (((i, j + 1), dx), ((i + 1, j), dy)):
                if a < ny and b < nx and ((i, j) in fixed or (a, b) in fixed):
                    before = (heights[a, b] - heights[i, j]) / step
                    after = (fixed.get((a, b), heights[a, b]) - fixed.get((i, j), heights[i, j])) / step
                    lost += np.nan_to_num(before ** 2 - after ** 2)
        return float(min(max(lost / total, 0.0), 1.0))

    def note(self, name: str, option: str, slope_share: float = 0.0) -> str:
        """The warning for file ``name``: how many, what they are, whether they dominate Ssk and Sku,
        the share of Sdq² they carry (``gradient_share``) and that ``option`` (e.g. "--despike 7")
        removes them."""
        share3, share4 = self.shares
        dominates = (f"; they carry {share3:.0%} of the heights' third and {share4:.0%} of their fourth absolute "
                     "moment: Ssk and Sku are theirs, not the surface's" if self.dominated else "")
        slopes = (f"; {slope_share:.0%} of Sdq² is theirs: the slopes, the spectrum's short wavelengths and a "
                  "surface drawn from it (cover = \"equivalent\") are theirs too" if slope_share > SLOPES else "")
        return (f"outliers in '{name}': {self.count} {self.describe()}, spikes or pits an instrument makes"
                f"{dominates}{slopes}; kept ({option} removes them and fills them as undefined points)")


def find_outliers(heights: np.ndarray, k: float = DESPIKE, scale: np.ndarray | None = None, sq_of: str = "") -> Outliers:
    """The outliers (module docstring) of ``heights`` [m] (ny, nx), NaN where undefined (never
    outliers; left out of the medians), at ``k`` times the Sq of the other heights, or of the other
    points of ``scale`` [m] (the same map's roughness, when a waviness filter follows: its Sq and
    moments are the statistics'; ``sq_of`` says so). In row blocks with a halo of ``HALO`` rows: no
    temporaries of the map's size."""
    of = heights if scale is None else scale
    count, mean, (squares, *absolute) = defined_sums(of, (2, 3, 4))   # |h - mean|^2, ^3, ^4 summed
    sq = np.sqrt(squares / count)
    found = [[], [], []]        # candidates: rows, columns, deviations beyond k Sq / CLIP
    for rows in row_blocks(*heights.shape):
        d = _deviations(heights, rows)
        with np.errstate(invalid="ignore"):
            i, j = np.nonzero(np.isfinite(d) & (np.abs(d) > k * sq / CLIP))
        for part, values in zip(found, (i + rows.start, j, d[i, j])):
            part.append(values)
    rows, cols, deviations = (np.concatenate(part) for part in found)
    c = of[rows, cols] - mean
    out = np.zeros(rows.size, dtype=bool)
    for _ in range(rows.size + 1):      # Sq without the outliers, to a fixed point (it only falls)
        n = count - out.sum()
        clean = max(np.sqrt(max((squares - np.sum(c[out] ** 2)) / n - (np.sum(c[out]) / n) ** 2, 0.0)), sq / CLIP)
        if np.array_equal(more := np.abs(deviations) > k * clean, out):
            break
        out = more
    shares = tuple(float(np.sum(np.abs(c[out]) ** n) / total) if total > 0 else 0.0
                   for n, total in zip((3, 4), absolute))
    return Outliers(rows[out], cols[out], deviations[out], float(k), float(clean), shares, sq_of)


def _deviations(heights: np.ndarray, rows: slice) -> np.ndarray:
    """Heights [m] of ``rows`` minus the separable median of their neighbourhood (mirrored at the edges);
    undefined neighbours are ±inf in a checkerboard, so that the median is about the defined
    neighbours'; NaN or ±inf where a point or most of its neighbours are undefined."""
    import scipy.ndimage  # local: ~0.4 s to import, only when a measurement is conditioned
    a, b = max(rows.start - HALO, 0), min(rows.stop + HALO, heights.shape[0])
    block = heights[a:b].copy()
    i, j = np.nonzero(np.isnan(block))
    block[i, j] = np.where((i + a + j) % 2, np.inf, -np.inf)
    width = 2 * HALO + 1
    median = scipy.ndimage.median_filter(scipy.ndimage.median_filter(block, size=(1, width), mode="mirror"),
                                         size=(width, 1), mode="mirror")[rows.start - a:rows.stop - a]
    with np.errstate(invalid="ignore"):
        return heights[rows] - median
