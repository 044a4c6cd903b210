"""Neighbour search in three dimensions: which nodes' supports cover each evaluation point.

The 3-D counterpart of ``rkfx.approximation.neighbours``: a uniform cell list (``CellGrid3``)
with cell size equal to the largest support radius, a point visiting the 3 x 3 x 3 block of
cells around it; compiled loops run in parallel over chunks of points, so the cost is O(N)
for node sets of bounded grading.
"""
from dataclasses import dataclass

import numba
import numpy as np

from rkfx.approximation.neighbours import CHUNK


@dataclass(frozen=True)
class CellGrid3:
    """Nodes binned into cubic cells; cell c holds ``order[start[c]:start[c + 1]]``.

    Attributes:
        origin: Lower corner of the grid, shape ``(3,)`` [m].
        cell: Cell size [m].
        shape: Cells per direction ``(nx, ny, nz)``.
        start: Shape ``(nx * ny * nz + 1,)`` int64.
        order: Node indices sorted by cell, shape ``(num_nodes,)`` int64.
    """

    origin: np.ndarray
    cell: float
    shape: tuple[int, int, int]
    start: np.ndarray
    order: np.ndarray

    @property
    def args(self) -> tuple:
        """The grid as the compiled kernels take it: origin, cell, nx, ny, nz, start, order."""
        return (self.origin, self.cell, *self.shape, self.start, self.order)


@numba.njit(cache=True)
def _bin_nodes(x, origin, cell, nx, ny, nz):
    n = x.shape[0]
    cell_of = np.empty(n, np.int64)
    for i in range(n):
        cx = min(max(int((x[i, 0] - origin[0]) / cell), 0), nx - 1)
        cy = min(max(int((x[i, 1] - origin[1]) / cell), 0), ny - 1)
        cz = min(max(int((x[i, 2] - origin[2]) / cell), 0), nz - 1)
        cell_of[i] = (cz * ny + cy) * nx + cx
    start = np.zeros(nx * ny * nz + 1, np.int64)
    for i in range(n):
        start[cell_of[i] + 1] += 1
    for c in range(nx * ny * nz):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(n, np.int64)
    for i in range(n):
        order[fill[cell_of[i]]] = i
        fill[cell_of[i]] += 1
    return start, order


def cell_grid_3d(x: np.ndarray, a: np.ndarray, points: np.ndarray) -> CellGrid3:
    """Bin nodes ``x`` (``(num_nodes, 3)``) with support radii ``a`` for queries at ``points``."""
    lo = np.array([x[:, k].min() for k in range(3)])
    hi = np.array([x[:, k].max() for k in range(3)])
    if len(points):
        lo = np.minimum(lo, [points[:, k].min() for k in range(3)])
        hi = np.maximum(hi, [points[:, k].max() for k in range(3)])
    cell = float(a.max())
    extent = np.maximum(hi - lo, cell)
    # Cap the grid at ~4 cells per node so sparse clouds in large boxes stay cheap.
    cell = max(cell, float(np.cbrt(np.prod(extent) / (4.0 * len(x)))))
    nx, ny, nz = (int(e / cell) + 1 for e in extent)
    start, order = _bin_nodes(x, lo, cell, nx, ny, nz)
    return CellGrid3(lo, cell, (nx, ny, nz), start, order)


@numba.njit(inline="always")
def covering_3d(px, py, pz, x, a, origin, cell, nx, ny, nz, start, order, out, store):
    """The nodes J with |p - x_J| < a_J for the point p, in cell-list order.

    Writes them to ``out[:k]`` when ``store`` and returns k: the one traversal that counting,
    filling and the shape-function kernels share, so they agree on the neighbours and their order.
    """
    cx = int((px - origin[0]) / cell)
    cy = int((py - origin[1]) / cell)
    cz = int((pz - origin[2]) / cell)
    k = 0
    for jz in range(max(cz - 1, 0), min(cz + 2, nz)):
        for jy in range(max(cy - 1, 0), min(cy + 2, ny)):
            for jx in range(max(cx - 1, 0), min(cx + 2, nx)):
                cc = (jz * ny + jy) * nx + jx
                for q in range(start[cc], start[cc + 1]):
                    j = order[q]
                    dx = px - x[j, 0]
                    dy = py - x[j, 1]
                    dz = pz - x[j, 2]
                    if dx * dx + dy * dy + dz * dz < a[j] * a[j]:
                        if store:
                            out[k] = j
                        k += 1
    return k


@numba.njit(parallel=True, cache=True)
def count_covering_3d(x, a, points, origin, cell, nx, ny, nz, start, order):
    """Number of nodes J with |p - x_J| < a_J for each point p."""
    m = points.shape[0]
    counts = np.zeros(m, np.int64)
    none = np.empty(0, np.int32)
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            counts[p] = covering_3d(points[p, 0], points[p, 1], points[p, 2], x, a, origin, cell, nx, ny, nz,
                                    start, order, none, False)
    return counts


@numba.njit(parallel=True, cache=True)
def _fill(x, a, points, origin, cell, nx, ny, nz, start, order, indptr, indices):
    m = points.shape[0]
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            covering_3d(points[p, 0], points[p, 1], points[p, 2], x, a, origin, cell, nx, ny, nz, start, order,
                        indices[indptr[p]:indptr[p + 1]], True)


def support_neighbours_3d(x: np.ndarray, a: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodes J with |p - x_J| < a_J for every point p (3-D).

    Args:
        x: Node coordinates, shape ``(num_nodes, 3)`` [m].
        a: Support radii, shape ``(num_nodes,)`` [m].
        points: Evaluation points, shape ``(num_points, 3)`` [m].

    Returns:
        ``(indptr, indices)``: CSR rows, shapes ``(num_points + 1,)`` int64 and ``(nnz,)`` int32.
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    a = np.ascontiguousarray(a, dtype=np.float64)
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    g = cell_grid_3d(x, a, points)
    counts = count_covering_3d(x, a, points, *g.args)
    indptr = np.zeros(len(points) + 1, np.int64)
    np.cumsum(counts, out=indptr[1:])
    indices = np.empty(indptr[-1], np.int32)
    _fill(x, a, points, *g.args, indptr, indices)
    return indptr, indices
