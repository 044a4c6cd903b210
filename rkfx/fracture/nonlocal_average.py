"""Integral-type nonlocal equivalent strain: the damage history driven by a weighted average of
Mazars' strain over a physical radius R instead of the particle's own value.

The local law softens every particle that passes its threshold, with the slope of (4.28): its
critical strain kappa_c grows as 1 / h so that one particle-wide band dissipates G_F. Particles
beside a crack that soften without being the crack then take a slope meant for a band one
particle wide, and their share of the dissipation grows with refinement (docs/fracture.md,
"Branching at fine spacings"). Averaging the equivalent strain over a fixed radius makes the
softening zone take a physical width instead (Pijaudier-Cabot and Bazant's nonlocal damage):

    epsbar_L = sum_J w(|x_L - x_J|) V_J eps_eq,J / sum_J w(|x_L - x_J|) V_J,
    w(r) = (1 - r^2 / R^2)^2 for r < R (a bell), 0 beyond,

kappa_L = max(kappa_L, epsbar_L), and the critical strain is that of a band of width b:
kappa_c = 2 G_F / (f_t b), b = band_factor R, so that a band of the nonlocal model's width
dissipates G_F per unit crack area. ``verification.nonlocal_band`` measures b / R of this law in
one dimension (the 2-D bell projected on the crack normal): 1.23-1.70 as kappa_c / kappa0 goes
from 2 to 50 (``band_factor`` solves for it).

Failed particles (D = 1) take no part in their neighbours' averages, and particles on the two
sides of a pre-existing crack do not average each other: a crack cuts the interaction across it. Without that, the strain of an open crack, which grows without bound,
enters the averages of the particles beside it and damages them: on the branching plate at
h = 0.2 mm and R = 2 mm the damaged zone swells to 10 mm across and the dissipation grows
with refinement (docs/fracture.md).

Only the particles allowed to damage need the average (``rkfx.fracture.tracking``), so the rows
are stored for every particle (for one rank's particles, ``restricted``) and evaluated for the
allowed ones.
"""
from dataclasses import dataclass

import numba
import numpy as np

from rkfx.approximation.neighbours import support_neighbours
from rkfx.approximation.sparse_rows import ranges
from rkfx.errors import InputError


@dataclass(frozen=True)
class NonlocalAverage:
    """The averaging rows w_LJ V_J as CSR.

    Attributes:
        radius: Interaction radius R [m].
        band_factor: Band width b / R of the critical strain kappa_c = 2 G_F / (f_t b).
        indptr, indices, weights: CSR rows of w_LJ V_J, shapes ``(n + 1,)`` int64, ``(nnz,)`` int32
            and ``(nnz,)`` (normalized when averaging, over the particles taking part).
        points: The particles whose rows these are, ascending (``None``: every particle, row L
            of particle L): a rank of a distributed run builds those of its own particles only.
    """

    radius: float
    band_factor: float
    indptr: np.ndarray
    indices: np.ndarray
    weights: np.ndarray
    points: np.ndarray | None = None

    @property
    def band_width(self) -> float:
        """b = band_factor R [m]."""
        return self.band_factor * self.radius

    def average(self, values: np.ndarray, rows: np.ndarray, out: np.ndarray, failed: np.ndarray | None = None) -> None:
        """out[rows] = the averages of rows ``rows`` over ``values`` (of every particle; ``out``
        must not be ``values``).

        ``failed`` (bool, of every particle): particles left out of their neighbours' averages
        (a crack cuts the interaction across it), the weights renormalized over the rest; a
        row whose particles have all failed averages to 0.
        """
        if self.points is not None:
            raise InputError("these nonlocal rows are some particles' only: take a rank's share (restricted) first")
        rows = np.asarray(rows, np.int64)
        if failed is None:
            failed = np.zeros(len(values), np.bool_)
        _average_rows(self.indptr, self.indices, self.weights, values, rows, failed, out)

    def restricted(self, points: np.ndarray) -> "NonlocalAverage":
        """The rows of ``points`` only (row k averages around particle ``points[k]``; the columns
        stay the particles' indices): one rank's share."""
        points = np.asarray(points, np.int64)
        rows = points
        if self.points is not None:  # rows held for some particles only: find theirs
            rows = np.minimum(np.searchsorted(self.points, points), max(len(self.points) - 1, 0))
            if len(points) and (len(self.points) == 0 or np.any(self.points[rows] != points)):
                raise InputError("the nonlocal rows were built for other particles than this share's; "
                                 "build them for these (nonlocal_average(..., points=))")
        count = self.indptr[rows + 1] - self.indptr[rows]
        at = ranges(self.indptr[rows], count)
        indptr = np.zeros(len(points) + 1, np.int64)
        np.cumsum(count, out=indptr[1:])
        return NonlocalAverage(self.radius, self.band_factor, indptr, self.indices[at], self.weights[at])


# b / R of the law against kappa_c / kappa0, measured in one dimension by verification.nonlocal_band
# (h / R = 1/20; 1/40 moves them by < 1e-4).
_RATIOS = np.array([2.0, 3.0, 4.0, 6.0, 10.0, 15.0, 20.0, 30.0, 50.0])
_WIDTHS = np.array([1.2281, 1.3207, 1.3779, 1.4497, 1.5281, 1.5820, 1.6161, 1.6590, 1.7049])


def band_factor(length_over_radius: float) -> float:
    """b / R for a material of characteristic length l = E G_F / f_t^2 and the radius R.

    The band's critical strain is kappa_c = 2 G_F / (f_t b), so kappa_c / kappa0 = 2 l / b, and b / R
    itself grows with kappa_c / kappa0 (the table above, interpolated in log(kappa_c / kappa0),
    extended beyond 50 along its last segment): the ratio r solves r b(r) = 2 l / R.

    Raises:
        InputError: a radius so large against l that kappa_c / kappa0 would fall below 2.
    """
    target = 2.0 * length_over_radius
    product = _RATIOS * _WIDTHS
    if not target >= product[0]:
        raise InputError(f"nonlocal radius is {1 / length_over_radius:.3g} characteristic lengths E G_F / f_t^2: "
                         f"its band would leave kappa_c < 2 kappa0; use a radius below "
                         f"{2 * length_over_radius / product[0]:.3g} of the present one")
    logs = np.log(_RATIOS)
    slope = (_WIDTHS[-1] - _WIDTHS[-2]) / (logs[-1] - logs[-2])

    def width(log_ratio: float) -> float:
        if log_ratio <= logs[-1]:
            return float(np.interp(log_ratio, logs, _WIDTHS))
        return float(_WIDTHS[-1] + slope * (log_ratio - logs[-1]))

    lo, hi = logs[0], max(logs[-1], np.log(target / _WIDTHS[-1]) + 1.0)
    for _ in range(100):  # r b(r) grows with r: bisection in log r
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if np.exp(mid) * width(mid) < target else (lo, mid)
    return width(0.5 * (lo + hi))


def nonlocal_average(x: np.ndarray, volume: np.ndarray, radius: float, band_factor: float,
                     cracks: np.ndarray | None = None, points: np.ndarray | None = None) -> NonlocalAverage:
    """The bell-weighted averaging rows of the particles ``x`` with volumes ``volume`` over ``radius``;
    pairs whose joining segment crosses one of the pre-existing ``cracks`` (segments, shape
    ``(k, 2, 2)`` [m]) do not interact. ``points``: build the rows of these particles only
    (ascending; a rank's own), default all.

    Raises:
        InputError: a radius that is not positive, or one below the largest particle spacing
            (sqrt V) that would leave a particle averaging itself alone.
    """
    x = np.ascontiguousarray(x, float)
    volume = np.ascontiguousarray(volume, float).reshape(-1)
    if not (np.isfinite(radius) and radius > 0):
        raise InputError(f"nonlocal radius = {radius!r} must be a positive length [m] (e.g. 2e-3)")
    if not (np.isfinite(band_factor) and band_factor > 0):
        raise InputError(f"nonlocal band_factor = {band_factor!r} must be positive "
                         "(b / R of the law, from python -m verification.nonlocal_band)")
    h = float(np.sqrt(volume.max()))
    if radius < 1.5 * h:
        raise InputError(f"nonlocal radius {radius:g} m is below 1.5 particle spacings ({1.5 * h:g} m): "
                         "refine the particles or enlarge the radius")
    rows = np.arange(len(x)) if points is None else np.asarray(points, np.int64)
    if points is not None and np.any(np.diff(rows) <= 0):
        raise InputError("nonlocal_average: points must be distinct particle indices in ascending order")
    indptr, indices = support_neighbours(x, np.full(len(x), float(radius)), x[rows])
    segments = np.zeros((0, 2, 2)) if cracks is None else np.ascontiguousarray(cracks, float).reshape(-1, 2, 2)
    w = np.empty(len(indices))
    _bell_weights(indptr, indices, rows, x, volume, float(radius) ** 2, segments, w)
    return NonlocalAverage(float(radius), float(band_factor), indptr, indices, w, None if points is None else rows)


@numba.njit(cache=True, inline="always")
def _cross(ux, uy, vx, vy):
    return ux * vy - uy * vx


@numba.njit(parallel=True, cache=True)
def _bell_weights(indptr, indices, rows, x, volume, radius2, segments, out):
    """out[e] = (1 - r^2 / R^2)^2 V_J of every entry e = (L, J) of the rows (row k: particle
    L = rows[k]; 0 beyond R, and 0 where the segment x_L-x_J properly crosses one of
    ``segments``: the pair sits on the two sides of a crack), one pass without temporaries."""
    for k in numba.prange(len(indptr) - 1):
        i = rows[k]
        ax, ay = x[i, 0], x[i, 1]
        for e in range(indptr[k], indptr[k + 1]):
            j = indices[e]
            bx, by = x[j, 0], x[j, 1]
            r2 = ((ax - bx) ** 2 + (ay - by) ** 2) / radius2
            w = max(1.0 - r2, 0.0) ** 2 * volume[j]
            abx, aby = bx - ax, by - ay
            for c in range(segments.shape[0]):
                cx, cy, dx, dy = segments[c, 0, 0], segments[c, 0, 1], segments[c, 1, 0], segments[c, 1, 1]
                o1 = _cross(abx, aby, cx - ax, cy - ay)
                o2 = _cross(abx, aby, dx - ax, dy - ay)
                o3 = _cross(dx - cx, dy - cy, ax - cx, ay - cy)
                o4 = _cross(dx - cx, dy - cy, bx - cx, by - cy)
                if o1 * o2 < 0 and o3 * o4 < 0:
                    w = 0.0
            out[e] = w


@numba.njit(parallel=True, cache=True)
def _average_rows(indptr, indices, weights, values, rows, failed, out):
    for k in numba.prange(rows.shape[0]):
        i = rows[k]
        s = 0.0
        total = 0.0
        for e in range(indptr[i], indptr[i + 1]):
            j = indices[e]
            if not failed[j]:
                s += weights[e] * values[j]
                total += weights[e]
        out[i] = s / total if total > 0.0 else 0.0
