"""Pre-existing cracks in RK supports: the diffraction method (Organ et al. 1996).

A crack is a polyline; each end is either a free *tip* inside the material or not (it reaches
the boundary or another crack). When the straight path from a node x_I to an evaluation
point x crosses a crack, the kernel distance |x - x_I| is replaced by the length of a path
bent around a tip x_c,

    d = ((s1 + s2(x)) / s0(x))^lambda s0(x),   s1 = |x_I - x_c|, s2 = |x - x_c|, s0 = |x - x_I|,

so supports wrap around the tip (lambda = 1 or 2; 2 makes N_I smoother there; seed section 4.3
uses this for the initial cracks of Kalthoff's and the branching problems). Only the kernel
changes: the basis stays the monomials of x - x_I, so the RK correction still reproduces
linear fields exactly. A tip qualifies when the two legs x_I -> x_c and x_c -> x cross no
crack; with none (e.g. the crossed segment reaches the boundary at both ends) node I is
invisible from x (the visibility method). d >= s0, so the Euclidean neighbour search stays
valid and only filters. For a straight crack this is exactly Organ's diffraction; for a
kinked one it is the shortest path with a single bend at a tip.

Nodes must not lie on a crack (a node there would see both faces): split the node set along
the crack first (``rkfx.geometry.particles.cut_triangulation``), which moves the face copies off the
crack line by a small gap.

Reference: Organ, Fleming, Terry, Belytschko (1996), Continuous meshless approximations for
nonconvex bodies by diffraction and transparency, Comput. Mech. 18, 225-235.
"""
from collections.abc import Sequence
from dataclasses import dataclass

import numba
import numpy as np

from rkfx.errors import InputError


@dataclass(frozen=True)
class Cracks:
    """Crack segments with free-tip flags.

    Attributes:
        segments: End points of each straight segment, shape ``(num_segments, 2, 2)`` [m].
        tips: ``tips[s, e]`` is True when end e of segment s is a free crack tip, shape
            ``(num_segments, 2)`` bool.
        exponent: lambda of the diffraction distance (1 or 2; default 2).
    """

    segments: np.ndarray
    tips: np.ndarray
    exponent: float = 2.0

    @property
    def num_segments(self) -> int:
        return len(self.segments)

    def tip_points(self) -> np.ndarray:
        """Coordinates of the free tips, shape ``(num_tips, 2)`` [m]."""
        return self.segments[self.tips]


def cracks(polylines: Sequence[np.ndarray], tips: Sequence[tuple[bool, bool]] | None = None,
           exponent: float = 2.0) -> Cracks:
    """Cracks from polylines.

    Args:
        polylines: Vertices of each crack, shapes ``(m_k >= 2, 2)`` [m].
        tips: Per polyline, whether its (first, last) vertex is a free tip; default both.
            A vertex on the domain boundary (an edge crack's mouth) is not a tip.
        exponent: lambda of the diffraction distance, >= 1 (Organ et al. use 1 or 2).
    """
    if not np.isfinite(exponent) or exponent < 1.0:
        raise InputError(f"diffraction exponent = {exponent!r} must be >= 1 (1 or 2 are usual)")
    tips = [(True, True)] * len(polylines) if tips is None else list(tips)
    if len(tips) != len(polylines):
        raise InputError(f"{len(tips)} tip flags for {len(polylines)} cracks; give (first, last) per crack")
    segs, flags = [], []
    for k, (line, (t0, t1)) in enumerate(zip(polylines, tips)):
        v = np.asarray(line, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 2 or len(v) < 2 or not np.isfinite(v).all():
            raise InputError(f"crack {k} must be a finite polyline of shape (m >= 2, 2), got {v.shape}")
        if np.any(np.linalg.norm(np.diff(v, axis=0), axis=1) == 0.0):
            raise InputError(f"crack {k} has a zero-length segment; remove repeated vertices")
        s = np.stack([v[:-1], v[1:]], axis=1)
        f = np.zeros((len(s), 2), bool)
        f[0, 0] = bool(t0)
        f[-1, 1] = bool(t1)
        segs.append(s)
        flags.append(f)
    if not segs:
        return Cracks(np.empty((0, 2, 2)), np.empty((0, 2), bool), float(exponent))
    return Cracks(np.ascontiguousarray(np.concatenate(segs)), np.ascontiguousarray(np.concatenate(flags)),
                  float(exponent))


def kernel_arrays(c: Cracks | None) -> tuple[np.ndarray, np.ndarray, float]:
    """(segments, tips, exponent) as the compiled kernels take them; empty without cracks."""
    if c is None:
        return np.empty((0, 2, 2)), np.empty((0, 2), np.bool_), 2.0
    return (np.ascontiguousarray(c.segments, dtype=np.float64), np.ascontiguousarray(c.tips, dtype=np.bool_),
            float(c.exponent))


@numba.njit(inline="always")
def _orient(ax, ay, bx, by, cx, cy):
    """Twice the signed area of (a, b, c): > 0 when c is left of a -> b."""
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@numba.njit(inline="always")
def _opposite(u, v):
    return (u > 0.0 and v < 0.0) or (u < 0.0 and v > 0.0)


@numba.njit(cache=True)
def near_segments(px, py, radius, segments, near):
    """Store in ``near`` the segments within ``radius`` of (px, py); returns their count."""
    k = 0
    r2 = radius * radius
    for s in range(segments.shape[0]):
        ax = segments[s, 0, 0]
        ay = segments[s, 0, 1]
        ex = segments[s, 1, 0] - ax
        ey = segments[s, 1, 1] - ay
        t = ((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey)
        t = min(max(t, 0.0), 1.0)
        dx = px - ax - t * ex
        dy = py - ay - t * ey
        if dx * dx + dy * dy < r2:
            near[k] = s
            k += 1
    return k


@numba.njit(cache=True)
def blocked(px, py, qx, qy, segments, near, count, skipx, skipy):
    """Whether the path p -> q crosses one of the segments ``near[:count]``.

    The path's ends must lie strictly on opposite sides of a segment's line; a segment end
    on the path counts as a crossing (so a path through a polyline vertex is caught).
    Segments with an end at (skipx, skipy) are ignored (the legs to a tip).
    """
    for t in range(count):
        s = near[t]
        ax = segments[s, 0, 0]
        ay = segments[s, 0, 1]
        bx = segments[s, 1, 0]
        by = segments[s, 1, 1]
        if (ax == skipx and ay == skipy) or (bx == skipx and by == skipy):
            continue
        if not _opposite(_orient(ax, ay, bx, by, px, py), _orient(ax, ay, bx, by, qx, qy)):
            continue
        o3 = _orient(px, py, qx, qy, ax, ay)
        o4 = _orient(px, py, qx, qy, bx, by)
        if not (o3 > 0.0 and o4 > 0.0) and not (o3 < 0.0 and o4 < 0.0):
            return True
    return False


@numba.njit(cache=True)
def diffracted_distance(px, py, xi, yi, s0, segments, tips, exponent, near, count):
    """Diffraction distance from node (xi, yi) to a point (px, py) whose straight path is cut.

    Args:
        s0: |x - x_I| > 0.

    Returns:
        ``(d, dd/dpx, dd/dpy)``; ``d = inf`` when no tip is visible from both (visibility).
    """
    best = np.inf
    gx = 0.0
    gy = 0.0
    nan = np.nan
    for t in range(count):
        s = near[t]
        for e in range(2):
            if not tips[s, e]:
                continue
            cx = segments[s, e, 0]
            cy = segments[s, e, 1]
            s1 = np.sqrt((xi - cx) ** 2 + (yi - cy) ** 2)
            s2 = np.sqrt((px - cx) ** 2 + (py - cy) ** 2)
            r = (s1 + s2) / s0
            d = s0 * r**exponent
            if not d < best:
                continue
            if blocked(xi, yi, cx, cy, segments, near, count, cx, cy) or \
                    blocked(cx, cy, px, py, segments, near, count, cx, cy):
                continue
            best = d
            # grad d = (1 - lambda) r^lambda e0 + lambda r^(lambda-1) e2, e0 = (x - x_I)/s0,
            # e2 = (x - x_c)/s2 (x_I and x_c fixed).
            a0 = (1.0 - exponent) * r**exponent / s0
            a2 = exponent * r ** (exponent - 1.0) / s2 if s2 > 0.0 else 0.0
            gx = a0 * (px - xi) + a2 * (px - cx)
            gy = a0 * (py - yi) + a2 * (py - cy)
    if best == np.inf:
        gx = nan
        gy = nan
    return best, gx, gy
