"""Semi-Lagrangian RK approximation (eqs. 6.22-6.29): nodes move with the material, supports stay.

The nodes follow the material points while each support radius a_I keeps its initial size, so
the neighbours of a point are those whose support covers it in the *current* configuration, and
the shape functions (6.23) and implicit gradients (6.29) are rebuilt there at every step.

The neighbour search is incremental (Verlet lists). Every node P keeps a row of candidates J
found at reference positions X_P, X_J (the positions at P's or J's last search) within
a_J + skin + reach, where ``reach`` bounds how far P's evaluation points lie from P. While no
node has moved more than skin / 2 from its reference position, every pair in reach in the
current configuration is among the candidates, and a step only filters them by distance. When
some nodes have moved farther, only their rows and the rows of the nodes near them are searched
again (``moved``); the rest of the lists is copied. Shape functions are then evaluated from the
candidate rows (``evaluate_moving``) with the closed-form linear basis of
``rkfx.approximation.shape_functions``.
"""
from dataclasses import dataclass

import numba
import numpy as np

from rkfx.approximation.kernel import cubic_spline
from rkfx.approximation.neighbours import CHUNK, support_neighbours
from rkfx.approximation.shape_functions import DIRECT, IMPLICIT, RCOND_MIN, SECOND, VALUES, moments, row_from_moments
from rkfx.approximation.sparse_rows import SparseRows
from rkfx.errors import InputError, SingularMomentMatrix, point_str


@dataclass(frozen=True)
class MovingRK:
    """A linear-basis RK approximation on moving nodes, with its candidate neighbour rows.

    Attributes:
        x: Current node positions, shape ``(num_nodes, 2)`` [m].
        support: Support radii a_I, constant in time, shape ``(num_nodes,)`` [m].
        reference: Position of each node at its last search, shape ``(num_nodes, 2)`` [m].
        indptr: Candidate rows, shape ``(num_nodes + 1,)`` int64.
        indices: Candidate nodes J of each row, shape ``(nnz,)`` int32.
        skin: Extra search radius [m]; a row stays valid while nodes move less than skin / 2.
        reach: Largest distance of an evaluation point from the node whose row it uses [m].
        searched: Rows searched when this state was made (all of them for a new one).
        torn: ``None``: a point whose moment matrix is singular (too few or collinear
            neighbours) raises ``SingularMomentMatrix``. Otherwise a two-element int64 counter
            [Shepard rows, sheet rows] for a cohesionless material whose grains may leave the
            bulk. A point whose neighbours lie nearly on a line (their kernel-weighted spread
            across it below ``SHEET_SPREAD``: a sheet of grains, e.g. the toe of a flow along
            a floor) gets the one-dimensional row along that line, which reproduces linear
            fields along it and has gradients along it only (``_sheet_row``); a point with too
            few neighbours even for that, or whose scaled moment matrix has a reciprocal
            condition below ``TORN_RCOND``, gets the constant-basis (Shepard) row N_I =
            phi_I / sum phi with zero gradients: a torn-off particle carries no strain and
            flies until it rejoins neighbours. Each such row adds one to its counter.
    """

    x: np.ndarray
    support: np.ndarray
    reference: np.ndarray
    indptr: np.ndarray
    indices: np.ndarray
    skin: float
    reach: float
    searched: int
    torn: np.ndarray | None = None

    @property
    def num_nodes(self) -> int:
        return len(self.x)


def _search_radius(support: np.ndarray, skin: float, reach: float) -> np.ndarray:
    return support + (skin + reach)


def moving_rk(x: np.ndarray, support: np.ndarray, skin: float, reach: float = 0.0,
              torn: np.ndarray | None = None) -> MovingRK:
    """Candidate rows of every node at positions ``x``.

    Args:
        x: Node positions, shape ``(num_nodes, 2)`` [m].
        support: Support radii a_I [m], shape ``(num_nodes,)`` (or a scalar).
        skin: Extra search radius [m] > 0; larger means fewer searches and longer rows (e.g.
            0.5 of the nodal spacing).
        reach: Farthest evaluation point from its node [m] (0 when shape functions are needed at
            the nodes only; the half-diagonal of a smoothing cell for SNNI).
        torn: ``None`` to raise at singular points, or a two-element int64 counter for the
            Shepard and the sheet rows of torn-off points (see ``MovingRK``).
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 2:
        raise InputError(f"x has shape {x.shape}; moving nodes need (num_nodes, 2) coordinates")
    support = np.ascontiguousarray(np.broadcast_to(np.asarray(support, dtype=np.float64), (len(x),)))
    if not np.all(support > 0):
        raise InputError(f"support radius {support.min()} at node {int(np.argmin(support))}; supports must be positive")
    if not (np.isfinite(skin) and skin > 0):
        raise InputError(f"skin = {skin!r}: the Verlet skin must be a positive length, e.g. half the nodal spacing")
    if not (np.isfinite(reach) and reach >= 0):
        raise InputError(f"reach = {reach!r}: must be a length >= 0")
    indptr, indices = support_neighbours(x, _search_radius(support, skin, reach), x)
    if torn is not None and (not isinstance(torn, np.ndarray) or torn.shape != (2,) or torn.dtype != np.int64):
        raise InputError("torn must be None or a two-element int64 counter, np.zeros(2, np.int64)")
    return MovingRK(x, support, x.copy(), indptr, indices, float(skin), float(reach), len(x), torn)


@numba.njit(parallel=True, cache=True)
def _spliced(old_ptr, old_idx, new_ptr, new_idx, slot, out_ptr, out_idx):
    """Rows with ``slot[r] >= 0`` come from row ``slot[r]`` of the new rows, the rest are copied."""
    n = len(out_ptr) - 1
    for c in numba.prange((n + CHUNK - 1) // CHUNK):
        for r in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            if slot[r] >= 0:
                lo, hi = new_ptr[slot[r]], new_ptr[slot[r] + 1]
                out_idx[out_ptr[r]:out_ptr[r + 1]] = new_idx[lo:hi]
            else:
                out_idx[out_ptr[r]:out_ptr[r + 1]] = old_idx[old_ptr[r]:old_ptr[r + 1]]


def moved(rk: MovingRK, x: np.ndarray) -> MovingRK:
    """The approximation at new node positions ``x``, with the candidate rows brought up to date.

    Nodes that moved more than skin / 2 from their reference positions take ``x`` as their
    new reference; their rows, and the rows of every node within a search radius of them, are
    searched again; all other rows are kept as they are.
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    if x.shape != rk.x.shape:
        raise InputError(f"x has shape {x.shape}; the approximation has {rk.x.shape}")
    if not np.all(np.isfinite(x)):
        bad = int(np.flatnonzero(~np.isfinite(x).all(axis=1))[0])
        raise InputError(f"node {bad} has a non-finite position {x[bad]}; the motion diverged (reduce the time step)")
    d = x - rk.reference
    far = np.flatnonzero(d[:, 0] ** 2 + d[:, 1] ** 2 > (0.5 * rk.skin) ** 2)
    if far.size == 0:
        return MovingRK(x, rk.support, rk.reference, rk.indptr, rk.indices, rk.skin, rk.reach, 0, rk.torn)
    reference = rk.reference.copy()
    reference[far] = x[far]
    radius = _search_radius(rk.support, rk.skin, rk.reach)
    # Rows that may gain a moved node: P with |X_P - X_J| < a_J + skin + reach for a moved J;
    # the largest radius gives a superset (an extra row searched is harmless).
    near_ptr, near_idx = support_neighbours(reference[far], np.full(far.size, radius.max()), reference)
    stale = np.diff(near_ptr) > 0
    stale[far] = True
    rows = np.flatnonzero(stale)
    new_ptr, new_idx = support_neighbours(reference, radius, reference[rows])
    slot = np.full(len(x), -1, np.int64)
    slot[rows] = np.arange(len(rows))
    counts = np.diff(rk.indptr)
    counts[rows] = np.diff(new_ptr)
    out_ptr = np.zeros(len(x) + 1, np.int64)
    np.cumsum(counts, out=out_ptr[1:])
    out_idx = np.empty(out_ptr[-1], np.int32)
    _spliced(rk.indptr, rk.indices, new_ptr, new_idx, slot, out_ptr, out_idx)
    return MovingRK(x, rk.support, reference, out_ptr, out_idx, rk.skin, rk.reach, len(rows), rk.torn)


@numba.njit(inline="always")
def _gather_listed(px, py, x, a, cand, lo, hi, idx, dxs, dys, phis, dphis, inv):
    """The candidates in ``cand[lo:hi]`` whose supports cover (px, py), as ``_gather`` of
    ``rkfx.approximation.shape_functions`` gives them (scaled offsets, kernel and its gradient)."""
    k = 0
    for e in range(lo, hi):
        j = cand[e]
        dx = px - x[j, 0]
        dy = py - x[j, 1]
        if not dx * dx + dy * dy < a[j] * a[j]:  # the test of ``_count_listed`` and of the cell list
            continue
        r = np.sqrt(dx * dx + dy * dy)
        phi, dphi = cubic_spline(r / a[j])
        g = dphi / (r * a[j]) if r > 0.0 else 0.0
        idx[k] = j
        dxs[k] = dx * inv
        dys[k] = dy * inv
        phis[k] = phi
        dphis[k, 0] = g * dx
        dphis[k, 1] = g * dy
        k += 1
    return k


@numba.njit(parallel=True, cache=True)
def _count_listed(x, a, points, owner, cand_ptr, cand_idx, counts):
    m = points.shape[0]
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            k = 0
            for e in range(cand_ptr[owner[p]], cand_ptr[owner[p] + 1]):
                j = cand_idx[e]
                dx = points[p, 0] - x[j, 0]
                dy = points[p, 1] - x[j, 1]
                if dx * dx + dy * dy < a[j] * a[j]:
                    k += 1
            counts[p] = k


#: With a ``torn`` counter, points whose scaled moment matrix is this close to singular get the
#: Shepard row: near-collinear neighbours give gradients large enough to turn a particle
#: inside out in one step long before the matrix is singular to round-off.
TORN_RCOND = 1e-4

#: With a ``torn`` counter, the smallest kernel-weighted variance of a point's neighbour offsets,
#: in units of the median support squared, below which they form a sheet. The reciprocal
#: condition above is scaled by the diagonal and misses a sheet along x or y (a toe sliding on a
#: floor: 7 particles on a line with offsets of 1e-3 h across it give it 5e-3); on a grid at
#: a = 2h the variance is 0.080 inside, 0.038 at edges and corners, 1.5e-10 on that line.
SHEET_SPREAD = 5e-3


@numba.njit(inline="always")
def _spread(sums):
    """The smallest kernel-weighted variance of the (scaled) offsets and the unit direction
    (tx, ty) of the largest, from the moment sums of ``moments``: a sheet's spread across it and
    its direction along it."""
    m0, mx, my, mxx, mxy, myy = sums
    if not m0 > 0.0:
        return 0.0, 1.0, 0.0
    cxx = mxx / m0 - (mx / m0) ** 2
    cyy = myy / m0 - (my / m0) ** 2
    cxy = mxy / m0 - (mx / m0) * (my / m0)
    mid = 0.5 * (cxx + cyy)
    half = np.sqrt(max(0.0, 0.25 * (cxx - cyy) ** 2 + cxy * cxy))
    if abs(cxy) > 0.0:
        tx, ty = cxy, mid + half - cxx
    elif cxx >= cyy:
        tx, ty = 1.0, 0.0
    else:
        tx, ty = 0.0, 1.0
    norm = np.sqrt(tx * tx + ty * ty)
    return mid - half, tx / norm, ty / norm


@numba.njit(inline="always")
def _sheet_row(n, idx, dxs, dys, phis, tx, ty, inv, base, indices, out):
    """The row of a sheet point along the unit direction (tx, ty), written at ``base``; False
    when its neighbours are too few even for that.

    Basis [1, s] with s the offset along t: N_k = (b0 + b1 s_k) phi_k reproduces constants and
    linear fields along t, and the gradient rows t (g0 + g1 s_k) phi_k (the implicit gradient
    (6.29) along t) reproduce d/dt; the derivatives of the gradients (``SECOND``) are zero: no
    second-gradient stabilization there.
    """
    a0 = a1 = a2 = 0.0
    for k in range(n):
        s = dxs[k] * tx + dys[k] * ty
        a0 += phis[k]
        a1 += phis[k] * s
        a2 += phis[k] * s * s
    det = a0 * a2 - a1 * a1
    if not det > 1e-6 * SHEET_SPREAD * a0 * a0:
        return False
    b0, b1 = a2 / det, -a1 / det
    g0, g1 = inv * a1 / det, -inv * a0 / det
    for k in range(n):
        s = dxs[k] * tx + dys[k] * ty
        indices[base + k] = idx[k]
        out[base + k, 0] = (b0 + b1 * s) * phis[k]
        if out.shape[1] > 1:
            g = (g0 + g1 * s) * phis[k]
            out[base + k, 1] = tx * g
            out[base + k, 2] = ty * g
            for c in range(3, out.shape[1]):
                out[base + k, c] = 0.0
    return True


@numba.njit(inline="always")
def _shepard_row(n, idx, phis, base, indices, out):
    """Constant-basis entries N = phi / sum(phi) and zero derivatives, written at ``base``."""
    total = 0.0
    for k in range(n):
        total += phis[k]
    for k in range(n):
        indices[base + k] = idx[k]
        out[base + k, 0] = phis[k] / total if total > 0.0 else 1.0 / n
        for c in range(1, out.shape[1]):
            out[base + k, c] = 0.0


@numba.njit(parallel=True, cache=True)
def _rows_listed(x, a, points, owner, scale, cand_ptr, cand_idx, indptr, kmax, mode, indices, out, ratio, shepard):
    m = points.shape[0]
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        idx = np.empty(kmax, np.int64)
        dxs = np.empty(kmax)
        dys = np.empty(kmax)
        phis = np.empty(kmax)
        dphis = np.empty((kmax, 2))
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            inv = 1.0 / scale
            o = owner[p]
            n = _gather_listed(points[p, 0], points[p, 1], x, a, cand_idx, cand_ptr[o], cand_ptr[o + 1],
                               idx, dxs, dys, phis, dphis, inv)
            sums = moments(n, dxs, dys, phis)
            if shepard > 0.0 and n > 0:
                across, tx, ty = _spread(sums)
                if across < SHEET_SPREAD:
                    if _sheet_row(n, idx, dxs, dys, phis, tx, ty, inv, indptr[p], indices, out):
                        ratio[p] = -2.0
                    else:
                        _shepard_row(n, idx, phis, indptr[p], indices, out)
                        ratio[p] = -1.0
                    continue
            ratio[p] = row_from_moments(sums, n, idx, dxs, dys, phis, dphis, inv, mode, indptr[p], indices, out)
            if shepard > 0.0 and n > 0 and not ratio[p] >= shepard:
                _shepard_row(n, idx, phis, indptr[p], indices, out)
                ratio[p] = -1.0


def evaluate_moving(rk: MovingRK, points: np.ndarray | None = None, owner: np.ndarray | None = None,
                    gradients: bool = False, implicit: bool = False, second: bool = False) -> SparseRows:
    """Shape functions of the current configuration at points, from the candidate rows.

    Args:
        rk: The moving approximation.
        points: Evaluation points, shape ``(num_points, 2)`` [m]; the current nodes when ``None``.
        owner: The node whose candidate row serves each point, shape ``(num_points,)``; each
            point must lie within ``rk.reach`` of its owner's current position (the node itself
            when ``points`` is ``None``).
        gradients: Entries ``[N_I, N_I,x, N_I,y]`` (direct gradients).
        implicit: Entries ``[N_I, N^∇_Ix, N^∇_Iy]`` (implicit gradients, eq. 6.29).
        second: Entries ``[N_I, N^∇_Ix, N^∇_Iy, N^∇_Ix,x, N^∇_Ix,y, N^∇_Iy,x, N^∇_Iy,y]``: the implicit
            gradients and their derivatives, which stand for the second derivatives N_I,ij.

    Raises:
        SingularMomentMatrix: At a point covered by too few, or collinear, supports (nodes
            tangled or torn apart by the motion); the message names the point.
    """
    if gradients + implicit + second > 1:
        raise InputError("evaluate_moving: ask for one of gradients, implicit or second")
    mode = DIRECT if gradients else IMPLICIT if implicit else SECOND if second else VALUES
    if points is None:
        points, owner = rk.x, np.arange(rk.num_nodes)
    elif owner is None:
        raise InputError("evaluate_moving: points need an owner node each (whose candidate row serves them)")
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    owner = np.ascontiguousarray(owner, dtype=np.int64)
    slack = 1e-12 * float(rk.support.max())  # round-off in points computed from the node positions
    far = np.sum((points - rk.x[owner]) ** 2, axis=1) > (rk.reach + slack) ** 2
    if far.any():
        p = int(np.flatnonzero(far)[0])
        raise InputError(f"point {p} {point_str(points[p])} lies farther than reach = {rk.reach:.4g} from its "
                         f"owner node {owner[p]}; build the approximation with a larger reach")
    counts = np.zeros(len(points), np.int64)
    _count_listed(rk.x, rk.support, points, owner, rk.indptr, rk.indices, counts)
    indptr = np.zeros(len(points) + 1, np.int64)
    np.cumsum(counts, out=indptr[1:])
    indices = np.empty(indptr[-1], np.int32)
    out = np.empty((indptr[-1], {VALUES: 1, DIRECT: 3, IMPLICIT: 3, SECOND: 7}[mode]))
    ratio = np.zeros(len(points))
    kmax = int(counts.max()) if len(counts) else 0
    # Basis scale: any length of the order of the supports; N_I does not depend on it.
    scale = float(np.median(rk.support))
    _rows_listed(rk.x, rk.support, points, owner, scale, rk.indptr, rk.indices, indptr, kmax, mode,
                 indices, out, ratio, TORN_RCOND if rk.torn is not None else 0.0)
    if rk.torn is not None:
        rk.torn[:] += [np.count_nonzero(ratio == -1.0), np.count_nonzero(ratio == -2.0)]
    bad = np.flatnonzero(~((ratio >= RCOND_MIN) | ((ratio < 0.0) & (rk.torn is not None))))
    if bad.size:
        p = bad[0]
        raise SingularMomentMatrix(
            f"singular moment matrix at point {p} {point_str(points[p])} ({len(bad)} such points) in the "
            f"current configuration: covered by {counts[p]} supports (owner node {owner[p]}); the nodes "
            "there are too few or in a line: larger supports, or a smaller time step if the motion tangled them")
    return SparseRows(indptr, indices, out, rk.num_nodes)
