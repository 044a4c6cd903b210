"""Neighbour search: which nodes' supports cover each evaluation point.

A uniform cell list (``CellGrid``) with cell size equal to the largest support radius; a
point visits the 3 x 3 block of cells around it. Compiled loops run in parallel over
chunks of points, so the cost is O(N) for node sets of bounded grading.
"""
from dataclasses import dataclass

import numba
import numpy as np

CHUNK = 2048  # points per parallel work item


@dataclass(frozen=True)
class CellGrid:
    """Nodes binned into square cells; cell c holds ``order[start[c]:start[c + 1]]``."""

    origin: np.ndarray  # (2,) lower-left corner [m]
    cell: float  # cell size [m]
    shape: tuple[int, int]  # (nx, ny)
    start: np.ndarray  # (nx * ny + 1,) int64
    order: np.ndarray  # (num_nodes,) int64


@numba.njit(cache=True)
def _bin_nodes(x, origin, cell, nx, ny):
    n = x.shape[0]
    cell_of = np.empty(n, np.int64)
    for i in range(n):
        cx = min(max(int((x[i, 0] - origin[0]) / cell), 0), nx - 1)
        cy = min(max(int((x[i, 1] - origin[1]) / cell), 0), ny - 1)
        cell_of[i] = cy * nx + cx
    start = np.zeros(nx * ny + 1, np.int64)
    for i in range(n):
        start[cell_of[i] + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(n, np.int64)
    for i in range(n):
        order[fill[cell_of[i]]] = i
        fill[cell_of[i]] += 1
    return start, order


def cell_grid(x: np.ndarray, a: np.ndarray, points: np.ndarray) -> CellGrid:
    """Bin nodes ``x`` (shape ``(num_nodes, 2)``) with support radii ``a`` for queries at ``points``."""
    # Column-wise reductions: numpy's axis-0 reduction of an (m, 2) array is ~50x slower.
    lo = np.array([x[:, 0].min(), x[:, 1].min()])
    hi = np.array([x[:, 0].max(), x[:, 1].max()])
    if len(points):
        lo = np.minimum(lo, [points[:, 0].min(), points[:, 1].min()])
        hi = np.maximum(hi, [points[:, 0].max(), points[:, 1].max()])
    cell = float(a.max())
    extent = np.maximum(hi - lo, cell)
    # Cap the grid at ~4 cells per node so sparse clouds in large boxes stay cheap.
    cell = max(cell, float(np.sqrt(extent[0] * extent[1] / (4.0 * len(x)))))
    nx, ny = (int(e / cell) + 1 for e in extent)
    start, order = _bin_nodes(x, lo, cell, nx, ny)
    return CellGrid(lo, cell, (nx, ny), start, order)


@numba.njit(inline="always")
def cell_range(px, py, origin, cell, nx, ny):
    """Index bounds of the 3 x 3 cell block around a point."""
    cx = int((px - origin[0]) / cell)
    cy = int((py - origin[1]) / cell)
    return max(cx - 1, 0), min(cx + 2, nx), max(cy - 1, 0), min(cy + 2, ny)


@numba.njit(inline="always")
def covering(px, py, x, a, origin, cell, nx, ny, start, order, out, store):
    """The nodes J with |p - x_J| < a_J for the point p = (px, py), in cell-list order.

    Writes them to ``out[:k]`` when ``store`` (``out`` may be empty otherwise) and returns k.
    This is the one traversal of the cell list; counting, filling and the shape-function
    kernels all visit nodes through it, so they agree on the neighbours and their order.
    """
    x0, x1, y0, y1 = cell_range(px, py, origin, cell, nx, ny)
    k = 0
    for jy in range(y0, y1):
        for jx in range(x0, x1):
            cc = jy * nx + jx
            for q in range(start[cc], start[cc + 1]):
                j = order[q]
                dx = px - x[j, 0]
                dy = py - x[j, 1]
                if dx * dx + dy * dy < a[j] * a[j]:
                    if store:
                        out[k] = j
                    k += 1
    return k


@numba.njit(parallel=True, cache=True)
def count_covering(x, a, points, origin, cell, nx, ny, start, order):
    """Number of nodes J with |p - x_J| < a_J for each point p."""
    m = points.shape[0]
    counts = np.zeros(m, np.int64)
    none = np.empty(0, np.int32)
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            counts[p] = covering(points[p, 0], points[p, 1], x, a, origin, cell, nx, ny, start, order, none, False)
    return counts


@numba.njit(parallel=True, cache=True)
def _fill(x, a, points, origin, cell, nx, ny, start, order, indptr, indices):
    m = points.shape[0]
    for c in numba.prange((m + CHUNK - 1) // CHUNK):
        for p in range(c * CHUNK, min(m, (c + 1) * CHUNK)):
            covering(points[p, 0], points[p, 1], x, a, origin, cell, nx, ny, start, order,
                     indices[indptr[p]:indptr[p + 1]], True)


def _covering_counts(x: np.ndarray, a: np.ndarray, points: np.ndarray):
    """The 2-D inputs as contiguous float arrays, their cell grid and the number of nodes whose
    support covers each point: ``(x, a, points, grid, counts)``."""
    x = np.ascontiguousarray(x, dtype=np.float64)
    a = np.ascontiguousarray(a, dtype=np.float64)
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    g = cell_grid(x, a, points)
    return x, a, points, g, count_covering(x, a, points, g.origin, g.cell, *g.shape, g.start, g.order)


def covered(x: np.ndarray, a: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Whether the support of some node J covers each point p, |p - x_J| < a_J (2-D), shape
    ``(num_points,)`` bool; ``x``, ``a``, ``points`` as for ``support_neighbours``."""
    if len(x) == 0:
        return np.zeros(len(np.reshape(points, (-1, 2))), bool)
    return _covering_counts(x, a, points)[-1] > 0


def support_neighbours(x: np.ndarray, a: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodes J with |p - x_J| < a_J for every point p.

    Args:
        x: Node coordinates, shape ``(num_nodes, 2)`` [m] (or ``(num_nodes, 3)``: the search of
            ``rkfx.approximation.neighbours3d``).
        a: Support radii, shape ``(num_nodes,)`` [m].
        points: Evaluation points, shape ``(num_points, 2)`` [m] (``(num_points, 3)`` in 3-D).

    Returns:
        ``(indptr, indices)``: CSR rows, shapes ``(num_points + 1,)`` int64 and ``(nnz,)`` int32.
    """
    if np.shape(x)[1] == 3:
        from rkfx.approximation.neighbours3d import support_neighbours_3d  # noqa: PLC0415 (imports this module)

        return support_neighbours_3d(x, a, points)
    x, a, points, g, counts = _covering_counts(x, a, points)
    indptr = np.zeros(len(points) + 1, np.int64)
    np.cumsum(counts, out=indptr[1:])
    indices = np.empty(indptr[-1], np.int32)
    _fill(x, a, points, g.origin, g.cell, *g.shape, g.start, g.order, indptr, indices)
    return indptr, indices
