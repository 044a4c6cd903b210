"""Reproducing kernel shape functions in three dimensions, eqs. (3.17)-(3.25) with x, y, z.

``N_I(x) = H(0)^T A(x)^-1 H(x - x_I) Phi_a(x - x_I)`` with the linear basis
H = [1, x, y, z] (scaled by a length local to the point, as in 2-D) and the cubic B-spline
kernel of |x - x_I| / a_I. The 4 x 4 moment matrix is factorized by Cholesky per point; values,
direct gradients (3.25 differentiated) and implicit gradients (6.29) come out as CSR rows over
the node index, computed in parallel by compiled kernels. ``rkfx.approximation.shape_functions``
dispatches here for nodes of shape ``(n, 3)``, so ``evaluate`` serves both dimensions.
"""
import numba
import numpy as np

from rkfx.approximation.kernel import cubic_spline
from rkfx.approximation.neighbours import CHUNK
from rkfx.approximation.neighbours3d import cell_grid_3d, count_covering_3d, covering_3d
from rkfx.approximation.shape_functions import _cholesky_solve
from rkfx.approximation.sparse_rows import SparseRows

VALUES, DIRECT, IMPLICIT = 0, 1, 2
NB = 4  # linear basis size in 3-D


@numba.njit(inline="always")
def _gather(px, py, pz, x, a, grid_origin, cell, nx, ny, nz, start, order, idx, offs, phis, dphis, inv):
    """Nodes covering p with scaled offsets (p - x_J) / s, kernel values and kernel gradients."""
    n = covering_3d(px, py, pz, x, a, grid_origin, cell, nx, ny, nz, start, order, idx, True)
    for k in range(n):
        j = idx[k]
        dx = px - x[j, 0]
        dy = py - x[j, 1]
        dz = pz - x[j, 2]
        r = np.sqrt(dx * dx + dy * dy + dz * dz)
        phi, dphi = cubic_spline(r / a[j])
        g = dphi / (r * a[j]) if r > 0.0 else 0.0
        offs[k, 0] = dx * inv
        offs[k, 1] = dy * inv
        offs[k, 2] = dz * inv
        phis[k] = phi
        dphis[k, 0] = g * dx
        dphis[k, 1] = g * dy
        dphis[k, 2] = g * dz
    return n


@numba.njit(inline="always")
def _h(offs, k, i):
    """Basis entry H_i at the scaled offset of neighbour k: [1, u, v, w]."""
    return 1.0 if i == 0 else offs[k, i - 1]


@numba.njit(parallel=True, cache=True)
def _rows(x, a, points, scale, grid_origin, cell, nx, ny, nz, start, order, indptr, kmax, mode,
          indices, out, ratio):
    """Linear-basis RK rows at the points: out[:, 0] = N_I, then 3 gradient components (direct
    or implicit) unless ``mode == VALUES``."""
    m = points.shape[0]
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        idx = np.empty(kmax, np.int64)
        offs = np.empty((kmax, 3))
        phis = np.empty(kmax)
        dphis = np.empty((kmax, 3))
        mom = np.empty((NB, NB))
        fac = np.empty((NB, NB))
        dmom = np.empty((3, NB, NB))
        rhs = np.empty((NB, 4))
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            inv = 1.0 / scale[p]
            n = _gather(points[p, 0], points[p, 1], points[p, 2], x, a, grid_origin, cell, nx, ny, nz, start,
                        order, idx, offs, phis, dphis, inv)
            mom[:] = 0.0
            for k in range(n):
                for i in range(NB):
                    hi = _h(offs, k, i) * phis[k]
                    for j in range(i, NB):
                        mom[i, j] += hi * _h(offs, k, j)
            for i in range(NB):
                for j in range(i):
                    mom[i, j] = mom[j, i]
            fac[:] = mom
            rhs[:] = 0.0
            rhs[0, 0] = 1.0
            ratio[p] = _cholesky_solve(fac, rhs[:, :1], NB)
            if not ratio[p] > 1e-14:
                ratio[p] = 0.0
                continue
            if mode == DIRECT:
                # b_,d = -A^-1 (dA/dx_d) b, with dA/dx_d = sum (dH_d H^T + H dH_d^T) phi + H H^T phi_,d
                # and dH/dx_d = inv e_(d+1) in the scaled basis.
                dmom[:] = 0.0
                for k in range(n):
                    for d in range(3):
                        for i in range(NB):
                            hi = _h(offs, k, i)
                            for j in range(i, NB):
                                v = hi * _h(offs, k, j) * dphis[k, d]
                                if i == d + 1:
                                    v += inv * _h(offs, k, j) * phis[k]
                                if j == d + 1:
                                    v += hi * inv * phis[k]
                                dmom[d, i, j] += v
                for d in range(3):
                    for i in range(NB):
                        t = 0.0
                        for j in range(NB):
                            t -= (dmom[d, i, j] if j >= i else dmom[d, j, i]) * rhs[j, 0]
                        rhs[i, d + 1] = t
            elif mode == IMPLICIT:  # eq. (6.29): A^-1 H_bar_i, H_bar_i = -inv e_(i+1)
                rhs[:, 1:] = 0.0
                for d in range(3):
                    rhs[d + 1, d + 1] = -inv
            if mode != VALUES:
                fac[:] = mom
                _cholesky_solve(fac, rhs[:, 1:], NB)
            base = indptr[p]
            for k in range(n):
                bh = rhs[0, 0]
                for i in range(1, NB):
                    bh += rhs[i, 0] * offs[k, i - 1]
                indices[base + k] = idx[k]
                out[base + k, 0] = bh * phis[k]
                if mode == VALUES:
                    continue
                for d in range(3):
                    t = rhs[0, d + 1]
                    for i in range(1, NB):
                        t += rhs[i, d + 1] * offs[k, i - 1]
                    if mode == DIRECT:
                        out[base + k, d + 1] = t * phis[k] + rhs[d + 1, 0] * inv * phis[k] + bh * dphis[k, d]
                    else:
                        out[base + k, d + 1] = t * phis[k]


def evaluate_3d(x: np.ndarray, support: np.ndarray, num_nodes: int, points: np.ndarray, mode: int,
                rcond_min: float) -> tuple[SparseRows, np.ndarray, np.ndarray]:
    """Rows of N_I (``mode`` VALUES), [N_I, N_I,x, N_I,y, N_I,z] (DIRECT) or [N_I, N^∇_I] (IMPLICIT)
    at ``points`` (``(m, 3)``), with the reciprocal-condition ratio of each point's moment matrix
    and its neighbour count (``rkfx.approximation.shape_functions.evaluate`` checks them)."""
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    g = cell_grid_3d(x, support, points)
    counts = count_covering_3d(x, support, points, *g.args)
    kmax = int(counts.max()) if len(counts) else 0
    indptr = np.zeros(len(points) + 1, np.int64)
    np.cumsum(counts, out=indptr[1:])
    indices = np.empty(indptr[-1], np.int32)
    out = np.empty((indptr[-1], 1 if mode == VALUES else 4))
    ratio = np.zeros(len(points))
    scale = np.full(len(points), float(np.median(support)))
    _rows(x, support, points, scale, *g.args, indptr, kmax, mode, indices, out, ratio)
    return SparseRows(indptr, indices, out, num_nodes), ratio, counts
