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
from rkfx.approximation.shape_functions import DIRECT, IMPLICIT, RCOND_MIN, SECOND, VALUES, linear_row
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
            neighbours) raises ``SingularMomentMatrix``. Otherwise a one-element int64 counter:
            such a point, and one whose scaled moment matrix has a reciprocal condition below
            ``TORN_RCOND``, gets the constant-basis (Shepard) row instead, N_I = phi_I / sum phi
            with zero gradients, and the counter grows by one. This is the choice for a
            cohesionless material whose grains may leave the bulk: a torn-off particle then
            carries no strain and flies until it rejoins neighbours.
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
        torn: ``None`` to raise at singular points, or a one-element int64 counter for the
            Shepard rows of torn-off points (see ``MovingRK``).
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
    if torn is not None and (not isinstance(torn, np.ndarray) or torn.shape != (1,) or torn.dtype != np.int64):
        raise InputError("torn must be None or a one-element int64 counter, np.zeros(1, np.int64)")
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
            ratio[p] = linear_row(n, idx, dxs, dys, phis, dphis, inv, mode, indptr[p], indices, out)
            if shepard > 0.0 and not ratio[p] >= shepard and n > 0:
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
        rk.torn[0] += int(np.count_nonzero(ratio == -1.0))
    bad = np.flatnonzero(~((ratio >= RCOND_MIN) | ((ratio == -1.0) & (rk.torn is not None))))
    if bad.size:
        p = bad[0]
        raise SingularMomentMatrix(
            f"singular moment matrix at point {p} {point_str(points[p])} ({len(bad)} such points) in the "
            f"current configuration: covered by {counts[p]} supports (owner node {owner[p]}); the nodes "
            "there are too few or in a line: larger supports, or a smaller time step if the motion tangled them")
    return SparseRows(indptr, indices, out, rk.num_nodes)
