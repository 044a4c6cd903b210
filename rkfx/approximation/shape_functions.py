"""Reproducing kernel shape functions, eqs. (3.17)-(3.25), evaluated in bulk.

``N_I(x) = H(0)^T A(x)^-1 H(x - x_I) Phi_a(x - x_I)`` with the cubic B-spline kernel and a
linear (default) or quadratic monomial basis. Values and direct gradients at any number of
points come out as CSR rows over the node index (points x neighbours), computed in parallel
by compiled kernels. The basis is scaled by a length local to each point so that the moment
matrix stays well conditioned for any node spacing; the shape functions do not depend on
that scale. Pre-existing cracks (``rkfx.approximation.diffraction``) cut the supports by the diffraction
method: only the kernel distance changes, so the reproducing conditions still hold.
"""
from dataclasses import dataclass

import numba
import numpy as np

from rkfx.approximation.diffraction import Cracks, blocked, diffracted_distance, kernel_arrays, near_segments
from rkfx.errors import InputError, SingularMomentMatrix, point_str
from rkfx.approximation.kernel import cubic_spline
from rkfx.approximation.sparse_rows import SparseRows
from rkfx.approximation.neighbours import CHUNK, cell_grid, count_covering, covering

# Reciprocal condition number of the scaled moment matrix below which it counts as singular.
RCOND_MIN = 1e-10


@dataclass(frozen=True)
class RKApproximation:
    """Nodes, supports and basis order of an RK approximation.

    Attributes:
        x: Node coordinates, shape ``(num_nodes, 2)`` or ``(num_nodes, 3)`` [m].
        support: Support radius a_I of each node, shape ``(num_nodes,)`` [m].
        order: Degree of the complete monomial basis H (1 linear, 2 quadratic; 3-D: linear).
        cracks: Pre-existing cracks cutting the supports (diffraction method, 2-D), or ``None``.
    """

    x: np.ndarray
    support: np.ndarray
    order: int = 1
    cracks: Cracks | None = None

    @property
    def num_nodes(self) -> int:
        return len(self.x)

    @property
    def dim(self) -> int:
        """Spatial dimension, 2 or 3."""
        return self.x.shape[1]


def rk_approximation(x: np.ndarray, spacing: np.ndarray, support_factor: float = 1.5,
                     order: int = 1, cracks: Cracks | None = None) -> RKApproximation:
    """RK approximation with support a_I = c * h_I.

    Args:
        x: Node coordinates, shape ``(num_nodes, 2)``, or ``(num_nodes, 3)`` in 3-D [m].
        spacing: Nodal spacing h_I, shape ``(num_nodes,)`` [m].
        support_factor: c > 0; 1.5 is the seed's choice for the linear basis.
        order: 1 (linear) or 2 (quadratic) basis; 3-D takes the linear basis.
        cracks: Pre-existing cracks (diffraction method); nodes must not lie on them
            (``rkfx.geometry.particles.cut_triangulation`` splits a node set along a crack).
    """
    if not np.isfinite(support_factor) or support_factor <= 0:
        raise InputError(f"support_factor = {support_factor!r} must be positive; use e.g. 1.5 "
                         "(linear basis) or 2.5 (quadratic)")
    if order not in (1, 2):
        raise InputError(f"order = {order!r} is not supported; use 1 (linear) or 2 (quadratic)")
    x = np.ascontiguousarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] not in (2, 3):
        raise InputError(f"nodes of shape {x.shape}: give (num_nodes, 2) or (num_nodes, 3) coordinates")
    if x.shape[1] == 3 and (order != 1 or cracks is not None):
        raise InputError("3-D RK approximations take the linear basis (order=1) and no cracks; "
                         f"got order={order!r}, cracks={'given' if cracks is not None else None}")
    spacing = np.broadcast_to(np.asarray(spacing, dtype=np.float64), (len(x),))
    bad = np.flatnonzero(~(spacing > 0))
    if bad.size:
        i = bad[0]
        raise InputError(f"node {i} at {point_str(x[i])} has spacing h = {spacing[i]}; spacings must be "
                         "positive (check for duplicate nodes)")
    if cracks is not None and cracks.num_segments == 0:
        cracks = None
    return RKApproximation(x, np.ascontiguousarray(support_factor * spacing), order, cracks)


@numba.njit(cache=True)
def _cholesky_solve(m, rhs, nb):
    """Solve the small SPD system m y = rhs in place; returns det(m) / prod(diag(m))."""
    ratio = 1.0
    for j in range(nb):
        s = m[j, j]
        for k in range(j):
            s -= m[j, k] * m[j, k]
        if not s > 0.0:
            return 0.0
        ratio *= s / m[j, j]
        d = np.sqrt(s)
        m[j, j] = d
        for i in range(j + 1, nb):
            t = m[i, j]
            for k in range(j):
                t -= m[i, k] * m[j, k]
            m[i, j] = t / d
    for c in range(rhs.shape[1]):
        for i in range(nb):
            t = rhs[i, c]
            for k in range(i):
                t -= m[i, k] * rhs[k, c]
            rhs[i, c] = t / m[i, i]
        for i in range(nb - 1, -1, -1):
            t = rhs[i, c]
            for k in range(i + 1, nb):
                t -= m[k, i] * rhs[k, c]
            rhs[i, c] = t / m[i, i]
    return ratio


@numba.njit(inline="always")
def _gather(px, py, x, a, origin, cell, nx, ny, start, order, idx, dxs, dys, phis, dphis, inv,
            segments, tips, exponent, near):
    """Nodes covering (px, py) with scaled offsets, kernel values and kernel gradients.

    With crack segments near the point, a node whose straight path to the point is cut gets
    the diffraction distance of ``rkfx.approximation.diffraction`` (or is dropped when invisible).
    The buffers hold the Euclidean neighbour count of the point.
    """
    # Segments within one cell (>= every support radius) of the point are all a path of
    # length < a_J can meet.
    nnear = near_segments(px, py, cell, segments, near) if segments.shape[0] else 0
    found = covering(px, py, x, a, origin, cell, nx, ny, start, order, idx, True)
    k = 0
    for q in range(found):
        j = idx[q]
        dx = px - x[j, 0]
        dy = py - x[j, 1]
        r = np.sqrt(dx * dx + dy * dy)
        # No crack near the point (the common case) costs one integer test.
        if nnear > 0 and blocked(x[j, 0], x[j, 1], px, py, segments, near, nnear, np.nan, np.nan):
            dist, ex, ey = diffracted_distance(px, py, x[j, 0], x[j, 1], r, segments, tips,
                                               exponent, near, nnear)
            if not dist < a[j]:
                continue
            phi, dphi = cubic_spline(dist / a[j])
            g = dphi / a[j]
            dphis[k, 0] = g * ex
            dphis[k, 1] = g * ey
        else:
            phi, dphi = cubic_spline(r / a[j])
            g = dphi / (r * a[j]) if r > 0.0 else 0.0
            dphis[k, 0] = g * dx
            dphis[k, 1] = g * dy
        idx[k] = j  # k <= q: compacted in place
        dxs[k] = dx * inv
        dys[k] = dy * inv
        phis[k] = phi
        k += 1
    return k


@numba.njit(inline="always")
def _scratch(kmax, num_segments):
    """Per-work-item buffers of ``_gather``: indices, offsets, kernel values and gradients, segments."""
    return (np.empty(kmax, np.int64), np.empty(kmax), np.empty(kmax), np.empty(kmax), np.empty((kmax, 2)),
            np.empty(num_segments, np.int64))


@numba.njit(parallel=True, cache=True)
def _count_cut(x, a, points, origin, cell, nx, ny, start, order, segments, tips, exponent, counts):
    """Lower the Euclidean counts of points near a crack to the nodes actually in reach."""
    m = points.shape[0]
    kmax = 0
    for p in range(m):
        kmax = max(kmax, counts[p])
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        idx, dxs, dys, phis, dphis, near = _scratch(kmax, segments.shape[0])
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            if near_segments(points[p, 0], points[p, 1], cell, segments, near):
                counts[p] = _gather(points[p, 0], points[p, 1], x, a, origin, cell, nx, ny, start, order,
                                    idx, dxs, dys, phis, dphis, 1.0, segments, tips, exponent, near)


# What a row's entry vector holds: [N_I]; [N_I, N_I,x, N_I,y] (direct); [N_I, N^∇_Ix, N^∇_Iy]
# (implicit, eq. 6.29); or SECOND: the implicit ones followed by their derivatives
# [N^∇_Ix,x, N^∇_Ix,y, N^∇_Iy,x, N^∇_Iy,y] (linear basis only).
VALUES, DIRECT, IMPLICIT, SECOND = 0, 1, 2, 3


@numba.njit(inline="always")
def moments(n, dxs, dys, phis):
    """The distinct entries m00, m01, m02, m11, m12, m22 of the linear-basis moment matrix
    sum_k phi_k [1, dx_k, dy_k] x [1, dx_k, dy_k] of gathered neighbours."""
    m00 = m01 = m02 = m11 = m12 = m22 = 0.0
    for k in range(n):
        f = phis[k]
        m00 += f
        m01 += f * dxs[k]
        m02 += f * dys[k]
        m11 += f * dxs[k] * dxs[k]
        m12 += f * dxs[k] * dys[k]
        m22 += f * dys[k] * dys[k]
    return m00, m01, m02, m11, m12, m22


@numba.njit(inline="always")
def linear_row(n, idx, dxs, dys, phis, dphis, inv, mode, base, indices, out):
    """One point's linear-basis RK entries from its gathered neighbours, written at ``base``.

    The 3 x 3 moment matrix is inverted by cofactors. Returns det(A) / prod(diag(A)) (0 when A
    is singular, and nothing is written then).
    """
    return row_from_moments(moments(n, dxs, dys, phis), n, idx, dxs, dys, phis, dphis, inv, mode, base, indices, out)


@numba.njit(inline="always")
def row_from_moments(sums, n, idx, dxs, dys, phis, dphis, inv, mode, base, indices, out):
    """``linear_row`` with the moment sums of ``moments`` already formed."""
    m00, m01, m02, m11, m12, m22 = sums
    c00 = m11 * m22 - m12 * m12
    c01 = m02 * m12 - m01 * m22
    c02 = m01 * m12 - m02 * m11
    det = m00 * c00 + m01 * c01 + m02 * c02
    hd = m00 * m11 * m22
    ratio = det / hd if hd > 0.0 else 0.0
    if not ratio > 1e-14:
        return 0.0
    b0 = c00 / det
    b1 = c01 / det
    b2 = c02 / det
    if mode == VALUES:
        for k in range(n):
            indices[base + k] = idx[k]
            out[base + k, 0] = (b0 + b1 * dxs[k] + b2 * dys[k]) * phis[k]
        return ratio
    c11 = m00 * m22 - m02 * m02
    c12 = m01 * m02 - m00 * m12
    c22 = m00 * m11 - m01 * m01
    if mode == IMPLICIT:
        # eq. (6.29): A^-1 H_bar_i with H_bar = [0, -1, 0], [0, 0, -1] in the scaled basis,
        # so the gradient rows reproduce grad(x) = I and grad(1) = 0 (6.28).
        gx0, gx1, gx2 = -inv * c01 / det, -inv * c11 / det, -inv * c12 / det
        gy0, gy1, gy2 = -inv * c02 / det, -inv * c12 / det, -inv * c22 / det
        for k in range(n):
            indices[base + k] = idx[k]
            out[base + k, 0] = (b0 + b1 * dxs[k] + b2 * dys[k]) * phis[k]
            out[base + k, 1] = (gx0 + gx1 * dxs[k] + gx2 * dys[k]) * phis[k]
            out[base + k, 2] = (gy0 + gy1 * dxs[k] + gy2 * dys[k]) * phis[k]
        return ratio
    # Gradients of a coefficient vector c (b for N, g_i for N^∇_i): c_,j = -A^-1 A_,j c, with
    # A^-1 = cofactors / det (symmetric).
    dm = np.empty((2, 6))
    _moment_gradient(n, dxs, dys, phis, dphis, inv, dm)
    db = np.empty((2, 3))
    if mode == DIRECT:
        _coefficient_gradient(dm, b0, b1, b2, c00, c01, c02, c11, c12, c22, det, db)
        for k in range(n):
            bh = b0 + b1 * dxs[k] + b2 * dys[k]
            indices[base + k] = idx[k]
            out[base + k, 0] = bh * phis[k]
            out[base + k, 1] = ((db[0, 0] + db[0, 1] * dxs[k] + db[0, 2] * dys[k]) * phis[k]
                                + b1 * inv * phis[k] + bh * dphis[k, 0])
            out[base + k, 2] = ((db[1, 0] + db[1, 1] * dxs[k] + db[1, 2] * dys[k]) * phis[k]
                                + b2 * inv * phis[k] + bh * dphis[k, 1])
        return ratio
    # SECOND: the implicit gradients (6.29) and their direct derivatives at the point, which
    # approximate N_I,ij and vanish on linear fields (the derivative of (6.28)).
    gx0, gx1, gx2 = -inv * c01 / det, -inv * c11 / det, -inv * c12 / det
    gy0, gy1, gy2 = -inv * c02 / det, -inv * c12 / det, -inv * c22 / det
    dgx = np.empty((2, 3))
    dgy = np.empty((2, 3))
    _coefficient_gradient(dm, gx0, gx1, gx2, c00, c01, c02, c11, c12, c22, det, dgx)
    _coefficient_gradient(dm, gy0, gy1, gy2, c00, c01, c02, c11, c12, c22, det, dgy)
    for k in range(n):
        u, v, f = dxs[k], dys[k], phis[k]
        hx = gx0 + gx1 * u + gx2 * v
        hy = gy0 + gy1 * u + gy2 * v
        indices[base + k] = idx[k]
        out[base + k, 0] = (b0 + b1 * u + b2 * v) * f
        out[base + k, 1] = hx * f
        out[base + k, 2] = hy * f
        out[base + k, 3] = (dgx[0, 0] + dgx[0, 1] * u + dgx[0, 2] * v) * f + gx1 * inv * f + hx * dphis[k, 0]
        out[base + k, 4] = (dgx[1, 0] + dgx[1, 1] * u + dgx[1, 2] * v) * f + gx2 * inv * f + hx * dphis[k, 1]
        out[base + k, 5] = (dgy[0, 0] + dgy[0, 1] * u + dgy[0, 2] * v) * f + gy1 * inv * f + hy * dphis[k, 0]
        out[base + k, 6] = (dgy[1, 0] + dgy[1, 1] * u + dgy[1, 2] * v) * f + gy2 * inv * f + hy * dphis[k, 1]
    return ratio


@numba.njit(inline="always")
def _moment_gradient(n, dxs, dys, phis, dphis, inv, dm):
    """The six distinct entries of dA/dx_i of the scaled linear moment matrix, as ``dm[i]``."""
    for i in range(2):
        d00 = d01 = d02 = d11 = d12 = d22 = 0.0
        for k in range(n):
            f = phis[k]
            g = dphis[k, i]
            u = dxs[k]
            v = dys[k]
            hu = inv if i == 0 else 0.0
            hv = inv if i == 1 else 0.0
            d00 += g
            d01 += hu * f + u * g
            d02 += hv * f + v * g
            d11 += 2.0 * u * hu * f + u * u * g
            d12 += (hu * v + u * hv) * f + u * v * g
            d22 += 2.0 * v * hv * f + v * v * g
        dm[i, 0] = d00
        dm[i, 1] = d01
        dm[i, 2] = d02
        dm[i, 3] = d11
        dm[i, 4] = d12
        dm[i, 5] = d22


@numba.njit(inline="always")
def _coefficient_gradient(dm, q0, q1, q2, c00, c01, c02, c11, c12, c22, det, dq):
    """dq[i] = -A^-1 (dA/dx_i) q for a coefficient vector q."""
    for i in range(2):
        r0 = dm[i, 0] * q0 + dm[i, 1] * q1 + dm[i, 2] * q2
        r1 = dm[i, 1] * q0 + dm[i, 3] * q1 + dm[i, 4] * q2
        r2 = dm[i, 2] * q0 + dm[i, 4] * q1 + dm[i, 5] * q2
        dq[i, 0] = -(c00 * r0 + c01 * r1 + c02 * r2) / det
        dq[i, 1] = -(c01 * r0 + c11 * r1 + c12 * r2) / det
        dq[i, 2] = -(c02 * r0 + c12 * r1 + c22 * r2) / det


@numba.njit(parallel=True, cache=True)
def _rows_linear(x, a, points, scale, origin, cell, nx, ny, start, order, indptr, kmax, mode,
                 segments, tips, exponent, indices, out, ratio):
    """Linear-basis RK rows in closed form (``linear_row``) at points found through the cell grid."""
    m = points.shape[0]
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        idx, dxs, dys, phis, dphis, near = _scratch(kmax, segments.shape[0])
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            inv = 1.0 / scale[p]
            n = _gather(points[p, 0], points[p, 1], x, a, origin, cell, nx, ny, start, order,
                        idx, dxs, dys, phis, dphis, inv, segments, tips, exponent, near)
            ratio[p] = linear_row(n, idx, dxs, dys, phis, dphis, inv, mode, indptr[p], indices, out)


@numba.njit(inline="always")
def _basis(u, v, order, h):
    """Monomials H at scaled offsets (u, v) and their derivatives w.r.t. (u, v)."""
    if order == 1:
        h[0, 0] = 1.0; h[0, 1] = u; h[0, 2] = v
        h[1, 0] = 0.0; h[1, 1] = 1.0; h[1, 2] = 0.0
        h[2, 0] = 0.0; h[2, 1] = 0.0; h[2, 2] = 1.0
    else:
        h[0, 0] = 1.0; h[0, 1] = u; h[0, 2] = v; h[0, 3] = u * u; h[0, 4] = u * v; h[0, 5] = v * v
        h[1, 0] = 0.0; h[1, 1] = 1.0; h[1, 2] = 0.0; h[1, 3] = 2 * u; h[1, 4] = v; h[1, 5] = 0.0
        h[2, 0] = 0.0; h[2, 1] = 0.0; h[2, 2] = 1.0; h[2, 3] = 0.0; h[2, 4] = u; h[2, 5] = 2 * v


@numba.njit(parallel=True, cache=True)
def _rows_generic(x, a, points, scale, origin, cell, nx, ny, start, order, indptr, kmax, mode,
                  basis_order, segments, tips, exponent, indices, out, ratio):
    """RK rows for any basis order: moment matrix (3.24) solved by Cholesky."""
    nb = 3 if basis_order == 1 else 6
    with_grad = mode == DIRECT
    m = points.shape[0]
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        idx, dxs, dys, phis, dphis, near = _scratch(kmax, segments.shape[0])
        mom = np.empty((nb, nb))
        dmom = np.empty((2, nb, nb))
        fac = np.empty((nb, nb))
        rhs = np.empty((nb, 3))
        h = np.empty((3, nb))
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            inv = 1.0 / scale[p]
            n = _gather(points[p, 0], points[p, 1], x, a, origin, cell, nx, ny, start, order,
                        idx, dxs, dys, phis, dphis, inv, segments, tips, exponent, near)
            mom[:] = 0.0
            dmom[:] = 0.0
            for k in range(n):
                _basis(dxs[k], dys[k], basis_order, h)
                for i in range(nb):
                    for j in range(i, nb):
                        hh = h[0, i] * h[0, j]
                        mom[i, j] += hh * phis[k]
                        if with_grad:
                            for d in range(2):
                                dmom[d, i, j] += ((h[d + 1, i] * h[0, j] + h[0, i] * h[d + 1, j]) * inv * phis[k]
                                                  + hh * dphis[k, d])
            for i in range(nb):
                for j in range(i):
                    mom[i, j] = mom[j, i]
                    dmom[0, i, j] = dmom[0, j, i]
                    dmom[1, i, j] = dmom[1, j, i]
            rhs[:] = 0.0
            rhs[0, 0] = 1.0
            fac[:] = mom
            ratio[p] = _cholesky_solve(fac, rhs[:, :1], nb)
            if not ratio[p] > 1e-14:
                ratio[p] = 0.0
                continue
            if with_grad:
                for d in range(2):
                    for i in range(nb):
                        t = 0.0
                        for j in range(nb):
                            t -= dmom[d, i, j] * rhs[j, 0]
                        rhs[i, d + 1] = t
            elif mode == IMPLICIT:  # eq. (6.29): A^-1 H_bar_i, H_bar_i = -e_(i+1) in the scaled basis
                rhs[:, 1:] = 0.0
                rhs[1, 1] = -inv
                rhs[2, 2] = -inv
            if mode != VALUES:
                fac[:] = mom
                _cholesky_solve(fac, rhs[:, 1:], nb)
            base = indptr[p]
            for k in range(n):
                _basis(dxs[k], dys[k], basis_order, h)
                bh = 0.0
                for i in range(nb):
                    bh += rhs[i, 0] * h[0, i]
                indices[base + k] = idx[k]
                out[base + k, 0] = bh * phis[k]
                if with_grad:
                    for d in range(2):
                        t = 0.0
                        hd = 0.0
                        for i in range(nb):
                            t += rhs[i, d + 1] * h[0, i]
                            hd += rhs[i, 0] * h[d + 1, i]
                        out[base + k, d + 1] = t * phis[k] + hd * inv * phis[k] + bh * dphis[k, d]
                elif mode == IMPLICIT:
                    for d in range(2):
                        t = 0.0
                        for i in range(nb):
                            t += rhs[i, d + 1] * h[0, i]
                        out[base + k, d + 1] = t * phis[k]


def evaluate(rk: RKApproximation, points: np.ndarray, gradients: bool = False, implicit: bool = False) -> SparseRows:
    """Shape functions N_I (and their direct or implicit gradients) at points.

    Returns rows over nodes whose entry vectors are ``[N_I]``, or ``[N_I, N_I,x, N_I,y]`` with
    ``gradients=True``, or ``[N_I, N^∇_Ix, N^∇_Iy]`` with ``implicit=True``.

    In 3-D (``rk.dim == 3``) the entry vectors carry three gradient components
    (``rkfx.approximation.shape_functions3d``).

    Args:
        rk: The approximation.
        points: Evaluation points, shape ``(num_points, rk.dim)`` [m].
        gradients: Also compute direct gradients (3.25 differentiated).
        implicit: Also compute implicit gradients (6.29): the rows that reproduce the gradients
            of linear (or, with ``order=2``, quadratic) fields, at almost no cost beyond N_I.

    Raises:
        SingularMomentMatrix: At a point covered by too few, or collinear, supports; the
            message names the point and its nearest node and suggests a larger support.
    """
    if gradients and implicit:
        raise InputError("evaluate: ask for direct (gradients=True) or implicit gradients, not both")
    mode = DIRECT if gradients else IMPLICIT if implicit else VALUES
    if rk.dim == 3:
        return _evaluate_3d(rk, points, mode)
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    g = cell_grid(rk.x, rk.support, points)
    grid = (g.origin, g.cell, *g.shape, g.start, g.order)
    counts = count_covering(rk.x, rk.support, points, *grid)
    kmax = int(counts.max()) if len(counts) else 0  # Euclidean: the buffers of _gather
    cut = kernel_arrays(rk.cracks)
    if rk.cracks is not None:
        # The Euclidean search over-counts nodes that a crack hides or diffracts out of reach.
        _count_cut(rk.x, rk.support, points, *grid, *cut, counts)
    indptr = np.zeros(len(points) + 1, np.int64)
    np.cumsum(counts, out=indptr[1:])
    nnz = int(indptr[-1])
    indices = np.empty(nnz, np.int32)
    out = np.empty((nnz, 1 if mode == VALUES else 3))
    ratio = np.zeros(len(points))
    # Basis scale: any length of the order of the supports; N_I does not depend on it.
    scale = np.full(len(points), float(np.median(rk.support)))
    if rk.order == 1:
        _rows_linear(rk.x, rk.support, points, scale, *grid, indptr, kmax, mode, *cut,
                     indices, out, ratio)
    else:
        _rows_generic(rk.x, rk.support, points, scale, *grid, indptr, kmax, mode, rk.order, *cut,
                      indices, out, ratio)
    _check_conditioning(rk, points, ratio, counts)
    return SparseRows(indptr, indices, out, rk.num_nodes)


def _evaluate_3d(rk: RKApproximation, points: np.ndarray, mode: int) -> SparseRows:
    from rkfx.approximation.shape_functions3d import evaluate_3d  # noqa: PLC0415 (it imports this module)

    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    rows, ratio, counts = evaluate_3d(rk.x, rk.support, rk.num_nodes, points, mode, RCOND_MIN)
    _check_conditioning(rk, points, ratio, counts)
    return rows


def _check_conditioning(rk: RKApproximation, points: np.ndarray, ratio: np.ndarray, counts: np.ndarray) -> None:
    """Raise ``SingularMomentMatrix`` naming the first point whose moment matrix is singular."""
    bad = np.flatnonzero(~(ratio >= RCOND_MIN))
    if bad.size:
        p = bad[0]
        near = int(np.argmin(np.sum((rk.x - points[p]) ** 2, axis=1)))
        need = rk.dim + 1 if rk.order == 1 else (rk.order + 1) * (rk.order + 2) // 2
        flat = "non-coplanar" if rk.dim == 3 else "non-collinear"
        raise SingularMomentMatrix(
            f"singular moment matrix at point {p} {point_str(points[p])} "
            f"({len(bad)} such points): covered by {counts[p]} node supports "
            f"(nearest node {near} at {point_str(rk.x[near])}, support "
            f"{rk.support[near]:.4g}); increase support_factor, it needs >= "
            f"{need} {flat} nodes in reach of every point")
