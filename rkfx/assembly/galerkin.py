"""Galerkin matrices sum_q w_q B_q^T D_q B_q assembled straight into their CSR rows, compiled:
the elastic stiffness (``elastic_stiffness``) and the scalar forms sum_q w_q a_I^T M_q a_J of
one-field operators (``scalar_form``): the Darcy matrix over gradient rows. It takes value rows
too, but the mass stays one scipy product, measured faster (``rkfx.assembly.operators.mass``).

A product of scipy matrices (B^T, then diag(w D), then B) forms intermediates several times
the size of K: at 9 x 10^4 nodes with the MSCNI rows, 1.4 GB of transients for a K of 167 MB,
and most of the assembly's time. Here each node I owns its rows of K: one pass over the
points q whose rows hold I (the transposed entries, in point order) counts the distinct
nodes J they couple I to, a second pass adds the blocks a_I(q)^T w_q M_q a_J(q) in place.
Rows are independent, so they run in parallel, and every entry is summed in the same order
(points ascending, then the entries of each point's row) on any number of threads. The
columns of each row come out sorted, and the transposed entries come from a counting sort:
no sort of the whole entry list, no sort of K afterwards.

The points may come in two sets of rows (the SCNI cells and the MSCNI subcells of eq. 3.56),
read where they are: the points of the second follow those of the first, and nothing is
copied into one list. The transposed entries and the point of each entry are int32 (half of
int64's bytes, the largest arrays of the assembly after the rows) while they fit.

B(g) of a gradient g = (g_x, g_y) is the Voigt strain matrix [[g_x, 0], [0, g_y], [g_y, g_x]];
in 3-D, with g = (g_x, g_y, g_z) and the Voigt order (xx, yy, zz, yz, xz, xy) of engineering
shears, B(g) = [[g_x, 0, 0], [0, g_y, 0], [0, 0, g_z], [0, g_z, g_y], [g_z, 0, g_x], [g_y, g_x, 0]].
"""
from collections.abc import Sequence
from dataclasses import dataclass

import numba
import numpy as np
import scipy.sparse as sp

from rkfx.approximation.sparse_rows import SparseRows, work_items


@numba.njit(inline="always")
def _row(q, ptr_a, idx_a, val_a, ptr_b, idx_b, val_b):
    """The row of point q: its pointer, indices and values arrays and its place in them."""
    m_a = len(ptr_a) - 1
    if q < m_a:
        return ptr_a, idx_a, val_a, q
    return ptr_b, idx_b, val_b, q - m_a


@numba.njit(inline="always")
def _term(e_i, t_entry, point_of, ptr_a, idx_a, val_a, ptr_b, idx_b, val_b):
    """Transposed entry e_i: its point q, the row of q (pointer, indices, values, place) and
    the values array of the entry itself with its place in it (A's entries, then B's)."""
    p = t_entry[e_i]
    q = point_of[p]
    ptr, idx, val, off = _row(q, ptr_a, idx_a, val_a, ptr_b, idx_b, val_b)
    if p < len(val_a):
        return q, ptr, idx, val, off, val_a, p
    return q, ptr, idx, val, off, val_b, p - len(val_a)


@numba.njit(parallel=True, cache=True)
def _count(ptr_a, idx_a, val_a, ptr_b, idx_b, val_b, point_of, t_ptr, t_entry, num_nodes, nchunks, node_ptr):
    """node_ptr[I + 1] = the distinct J that the points of I couple it to."""
    chunk = (num_nodes + nchunks - 1) // nchunks
    for c in numba.prange(nchunks):
        stamp = np.full(num_nodes, -1, np.int64)
        for i in range(c * chunk, min(num_nodes, (c + 1) * chunk)):
            k = 0
            for e_i in range(t_ptr[i], t_ptr[i + 1]):
                ptr, idx, _, off = _row(point_of[t_entry[e_i]], ptr_a, idx_a, val_a, ptr_b, idx_b, val_b)
                for e in range(ptr[off], ptr[off + 1]):
                    if stamp[idx[e]] != i:
                        stamp[idx[e]] = i
                        k += 1
            node_ptr[i + 1] = k


@numba.njit(inline="always")
def _columns(i, width, ptr_a, idx_a, val_a, ptr_b, idx_b, val_b, point_of, t_ptr, t_entry, stamp, slot):
    """The columns J of row I, ascending (``width`` of them); slot[J] = rank of J among them."""
    cols = np.empty(width, np.int64)
    k = 0
    for e_i in range(t_ptr[i], t_ptr[i + 1]):
        ptr, idx, _, off = _row(point_of[t_entry[e_i]], ptr_a, idx_a, val_a, ptr_b, idx_b, val_b)
        for e in range(ptr[off], ptr[off + 1]):
            j = idx[e]
            if stamp[j] != i:
                stamp[j] = i
                cols[k] = j
                k += 1
    cols.sort()
    for s in range(width):
        slot[cols[s]] = s
    return cols


@numba.njit(parallel=True, cache=True)
def _elastic_fill(ptr_a, idx_a, grad_a, ptr_b, idx_b, grad_b, point_of, t_ptr, t_entry, weight, d, per_point,
                  num_nodes, nchunks, node_ptr, out_idx, out_data):
    """The 2 x 2 blocks sum_q B_I^T w_q D_q B_J of K's rows (interleaved unknowns)."""
    chunk = (num_nodes + nchunks - 1) // nchunks
    for c in numba.prange(nchunks):
        stamp = np.full(num_nodes, -1, np.int64)
        slot = np.empty(num_nodes, np.int64)
        t = np.empty((2, 3))
        for i in range(c * chunk, min(num_nodes, (c + 1) * chunk)):
            width = node_ptr[i + 1] - node_ptr[i]
            first = 4 * node_ptr[i]
            cols = _columns(i, width, ptr_a, idx_a, grad_a, ptr_b, idx_b, grad_b, point_of, t_ptr, t_entry, stamp, slot)
            for s in range(width):
                for a in range(2):
                    for b in range(2):
                        pos = first + 2 * a * width + 2 * s + b
                        out_idx[pos] = 2 * cols[s] + b
                        out_data[pos] = 0.0
            for e_i in range(t_ptr[i], t_ptr[i + 1]):
                q, ptr, idx, grad, off, gi, pe = _term(e_i, t_entry, point_of, ptr_a, idx_a, grad_a, ptr_b, idx_b,
                                                       grad_b)
                # t = B_I^T (w D): 2 x 3.
                m = d[q] if per_point else d[0]
                gx, gy, w = gi[pe, 0], gi[pe, 1], weight[q]
                for s in range(3):
                    t[0, s] = w * (gx * m[0, s] + gy * m[2, s])
                    t[1, s] = w * (gy * m[1, s] + gx * m[2, s])
                for e in range(ptr[off], ptr[off + 1]):
                    hx, hy = grad[e, 0], grad[e, 1]
                    base = first + 2 * slot[idx[e]]
                    for a in range(2):
                        row = base + 2 * a * width
                        out_data[row] += t[a, 0] * hx + t[a, 2] * hy
                        out_data[row + 1] += t[a, 1] * hy + t[a, 2] * hx


@numba.njit(parallel=True, cache=True)
def _elastic_fill_3d(ptr_a, idx_a, grad_a, ptr_b, idx_b, grad_b, point_of, t_ptr, t_entry, weight, d, per_point,
                     num_nodes, nchunks, node_ptr, out_idx, out_data):
    """The 3 x 3 blocks sum_q B_I^T w_q D_q B_J of K's rows (interleaved unknowns, 3-D Voigt)."""
    chunk = (num_nodes + nchunks - 1) // nchunks
    for c in numba.prange(nchunks):
        stamp = np.full(num_nodes, -1, np.int64)
        slot = np.empty(num_nodes, np.int64)
        t = np.empty((3, 6))
        for i in range(c * chunk, min(num_nodes, (c + 1) * chunk)):
            width = node_ptr[i + 1] - node_ptr[i]
            first = 9 * node_ptr[i]
            cols = _columns(i, width, ptr_a, idx_a, grad_a, ptr_b, idx_b, grad_b, point_of, t_ptr, t_entry, stamp, slot)
            for s in range(width):
                for a in range(3):
                    for b in range(3):
                        pos = first + 3 * a * width + 3 * s + b
                        out_idx[pos] = 3 * cols[s] + b
                        out_data[pos] = 0.0
            for e_i in range(t_ptr[i], t_ptr[i + 1]):
                q, ptr, idx, grad, off, gi, pe = _term(e_i, t_entry, point_of, ptr_a, idx_a, grad_a, ptr_b, idx_b,
                                                       grad_b)
                # t = B_I^T (w D): 3 x 6.
                m = d[q] if per_point else d[0]
                gx, gy, gz, w = gi[pe, 0], gi[pe, 1], gi[pe, 2], weight[q]
                for s in range(6):
                    t[0, s] = w * (gx * m[0, s] + gz * m[4, s] + gy * m[5, s])
                    t[1, s] = w * (gy * m[1, s] + gz * m[3, s] + gx * m[5, s])
                    t[2, s] = w * (gz * m[2, s] + gy * m[3, s] + gx * m[4, s])
                for e in range(ptr[off], ptr[off + 1]):
                    hx, hy, hz = grad[e, 0], grad[e, 1], grad[e, 2]
                    base = first + 3 * slot[idx[e]]
                    for a in range(3):
                        row = base + 3 * a * width
                        out_data[row] += t[a, 0] * hx + t[a, 4] * hz + t[a, 5] * hy
                        out_data[row + 1] += t[a, 1] * hy + t[a, 3] * hz + t[a, 5] * hx
                        out_data[row + 2] += t[a, 2] * hz + t[a, 3] * hy + t[a, 4] * hx


@numba.njit(parallel=True, cache=True)
def _scalar_fill(ptr_a, idx_a, val_a, ptr_b, idx_b, val_b, point_of, t_ptr, t_entry, weight, metric, per_point,
                 num_nodes, nchunks, node_ptr, out_idx, out_data):
    """The entries sum_q w_q a_I(q)^T M_q a_J(q) of the rows of a one-field matrix."""
    chunk = (num_nodes + nchunks - 1) // nchunks
    nc = val_a.shape[1]
    for c in numba.prange(nchunks):
        stamp = np.full(num_nodes, -1, np.int64)
        slot = np.empty(num_nodes, np.int64)
        t = np.empty(nc)
        for i in range(c * chunk, min(num_nodes, (c + 1) * chunk)):
            width = node_ptr[i + 1] - node_ptr[i]
            first = node_ptr[i]
            cols = _columns(i, width, ptr_a, idx_a, val_a, ptr_b, idx_b, val_b, point_of, t_ptr, t_entry, stamp, slot)
            for s in range(width):
                out_idx[first + s] = cols[s]
                out_data[first + s] = 0.0
            for e_i in range(t_ptr[i], t_ptr[i + 1]):
                q, ptr, idx, val, off, vi, pe = _term(e_i, t_entry, point_of, ptr_a, idx_a, val_a, ptr_b, idx_b, val_b)
                m = metric[q] if per_point else metric[0]
                w = weight[q]
                for b in range(nc):  # t = w a_I^T M
                    acc = 0.0
                    for a in range(nc):
                        acc += vi[pe, a] * m[a, b]
                    t[b] = w * acc
                for e in range(ptr[off], ptr[off + 1]):
                    acc = 0.0
                    for b in range(nc):
                        acc += t[b] * val[e, b]
                    out_data[first + slot[idx[e]]] += acc


@numba.njit(parallel=True, cache=True)
def _mixed_fill(t_ptr, t_entry, point_of, test_val, tr_ptr, tr_idx, tr_val, weight, num_nodes, nchunks, node_ptr,
                out_idx, out_data):
    """The rows (I, a) of sum_q w_q a_I(q)_a b_J(q): the g components of the test rows a against
    the scalar trial rows b of the same points (interleaved rows, g = test_val.shape[1])."""
    g = test_val.shape[1]
    empty_ptr = np.zeros(1, np.int64)
    empty_idx = np.empty(0, tr_idx.dtype)
    empty_val = np.empty((0, tr_val.shape[1]))
    chunk = (num_nodes + nchunks - 1) // nchunks
    for c in numba.prange(nchunks):
        stamp = np.full(num_nodes, -1, np.int64)
        slot = np.empty(num_nodes, np.int64)
        t = np.empty(g)
        for i in range(c * chunk, min(num_nodes, (c + 1) * chunk)):
            width = node_ptr[i + 1] - node_ptr[i]
            first = g * node_ptr[i]
            cols = _columns(i, width, tr_ptr, tr_idx, tr_val, empty_ptr, empty_idx, empty_val, point_of, t_ptr,
                            t_entry, stamp, slot)
            for a in range(g):
                for s in range(width):
                    out_idx[first + a * width + s] = cols[s]
                    out_data[first + a * width + s] = 0.0
            for e_i in range(t_ptr[i], t_ptr[i + 1]):
                p = t_entry[e_i]
                q = point_of[p]
                for a in range(g):
                    t[a] = weight[q] * test_val[p, a]
                for e in range(tr_ptr[q], tr_ptr[q + 1]):
                    base = first + slot[tr_idx[e]]
                    v = tr_val[e, 0]
                    for a in range(g):
                        out_data[base + a * width] += t[a] * v


@dataclass(frozen=True)
class _Points:
    """The rows of the points in at most two sets (A, then B), their transposed entries and
    the point of each entry: what both fills read."""

    a: SparseRows
    b: SparseRows
    point_of: np.ndarray
    t_ptr: np.ndarray
    t_entry: np.ndarray

    @property
    def num_nodes(self) -> int:
        return self.a.num_cols

    @property
    def rows(self) -> tuple:
        return (self.a.indptr, np.ascontiguousarray(self.a.indices), _values(self.a), self.b.indptr,
                np.ascontiguousarray(self.b.indices), _values(self.b))

    def pattern(self) -> np.ndarray:
        """node_ptr: the row pointer of the nodes' rows (one entry per coupled node)."""
        n = self.num_nodes
        node_ptr = np.zeros(n + 1, np.int64)
        _count(*self.rows, self.point_of, self.t_ptr, self.t_entry, n, work_items(n), node_ptr)
        np.cumsum(node_ptr, out=node_ptr)
        return node_ptr


def _points(rows: SparseRows | Sequence[SparseRows]) -> _Points:
    parts = [rows] if isinstance(rows, SparseRows) else list(rows)
    if len(parts) > 2:  # the kernels read two sets where they are; more are joined into the second
        parts = [parts[0], _joined(parts[1:])]
    a = parts[0]
    b = parts[1] if len(parts) > 1 else SparseRows(np.zeros(1, np.int64), a.indices[:0], a.data[:0], a.num_cols)
    n = a.num_cols
    nnz = a.indices.size + b.indices.size
    index = np.int32 if max(nnz, a.num_rows + b.num_rows) < 2**31 else np.int64
    t_ptr = np.zeros(n + 1, np.int64)
    np.cumsum(np.bincount(a.indices, minlength=n) + np.bincount(b.indices, minlength=n), out=t_ptr[1:])
    return _Points(a, b, _entry_points(a.indptr, b.indptr, np.empty(nnz, index)), t_ptr,
                   _transposed_entries(a.indices, b.indices, t_ptr, np.empty(nnz, index)))


def elastic_stiffness(rows: SparseRows | Sequence[SparseRows], weights: np.ndarray, d: np.ndarray) -> sp.csr_matrix:
    """K = sum_q w_q B_q^T D_q B_q, shape ``(g n, g n)`` over interleaved unknowns, sorted indices
    (g = 2, or 3 for gradient rows of 3 components).

    Args:
        rows: Gradient rows grad N_I(x_q), g components, shape ``(m, n)``; or a list of such
            rows over the same n nodes, whose points follow each other (m = their sum).
        weights: w_q, shape ``(m,)`` [m^2, or m^3 in 3-D].
        d: D [Pa] in Voigt form, shape ``(v, v)`` or one per point ``(m, v, v)``: v = 3 in 2-D,
            6 in 3-D.
    """
    pts = _points(rows)
    n = pts.num_nodes
    g = pts.a.num_components
    v = 3 if g == 2 else 6
    fill = _elastic_fill if g == 2 else _elastic_fill_3d
    d = np.ascontiguousarray(d, dtype=np.float64)
    if d.shape[-2:] != (v, v):
        raise ValueError(f"D of shape {d.shape} for gradient rows of {g} components; give ({v}, {v}) Voigt matrices")
    per_point = d.ndim == 3
    node_ptr = pts.pattern()
    out_idx = np.empty(g * g * node_ptr[-1], np.int32)
    out_data = np.empty(g * g * node_ptr[-1])
    fill(*pts.rows, pts.point_of, pts.t_ptr, pts.t_entry, np.ascontiguousarray(weights, dtype=np.float64),
         d if per_point else d.reshape(1, v, v), per_point, n, work_items(n), node_ptr, out_idx, out_data)
    indptr = np.empty(g * n + 1, np.int64)
    for a in range(g):
        indptr[a:-1:g] = g * g * node_ptr[:-1] + a * g * np.diff(node_ptr)
    indptr[-1] = g * g * node_ptr[-1]
    k = sp.csr_matrix((out_data, out_idx, indptr), shape=(g * n, g * n))
    k.has_sorted_indices = True
    return k


def scalar_form(rows: SparseRows | Sequence[SparseRows], weights: np.ndarray, metric: np.ndarray) -> sp.csr_matrix:
    """A = sum_q w_q a_I(q)^T M_q a_J(q), shape ``(n, n)``, sorted indices: the Darcy matrix
    over gradient rows (M the permeability, c = 2) or the mass over value rows (M a scalar
    coefficient, c = 1).

    Args:
        rows: Rows a_I(x_q) with c components, shape ``(m, n)``, or a list of such rows whose
            points follow each other.
        weights: w_q, shape ``(m,)``.
        metric: M, shape ``(c, c)`` or one per point ``(m, c, c)``.
    """
    pts = _points(rows)
    n = pts.num_nodes
    nc = pts.a.num_components
    metric = np.ascontiguousarray(metric, dtype=np.float64)
    per_point = metric.ndim == 3
    if metric.shape[-2:] != (nc, nc):
        raise ValueError(f"metric of shape {metric.shape} for rows of {nc} components")
    node_ptr = pts.pattern()
    out_idx = np.empty(node_ptr[-1], np.int32)
    out_data = np.empty(node_ptr[-1])
    _scalar_fill(*pts.rows, pts.point_of, pts.t_ptr, pts.t_entry, np.ascontiguousarray(weights, dtype=np.float64),
                 metric if per_point else metric.reshape(1, nc, nc), per_point, n, work_items(n), node_ptr, out_idx,
                 out_data)
    a = sp.csr_matrix((out_data, out_idx, node_ptr), shape=(n, n))
    a.has_sorted_indices = True
    return a


def mixed_form(test: SparseRows, trial: SparseRows, weights: np.ndarray) -> sp.csr_matrix:
    """B = sum_q w_q a_I(q)^T b_J(q) for test rows a with g components and scalar trial rows b of
    the same points: rows (I, component) interleaved, columns J, shape ``(g n, n)``, sorted
    indices. The u-p coupling int B^T alpha m N of eq. (3.57) is the gradient rows against the
    value rows of the nodal points, weights alpha V_L.

    Args:
        test: Rows a_I(x_q), g components, shape ``(m, n)``.
        trial: Rows b_J(x_q), one component, shape ``(m, n)``.
        weights: w_q, shape ``(m,)``.
    """
    if test.num_rows != trial.num_rows or test.num_cols != trial.num_cols or trial.num_components != 1:
        raise ValueError(f"test rows {test.num_rows} x {test.num_cols} and scalar trial rows {trial.num_rows} x "
                         f"{trial.num_cols} ({trial.num_components} components) of different points")
    pts = _points(test)
    n, g = pts.num_nodes, test.num_components
    tr_ptr, tr_idx, tr_val = trial.indptr, np.ascontiguousarray(trial.indices), _values(trial)
    empty = SparseRows(np.zeros(1, np.int64), tr_idx[:0], tr_val[:0], n)
    node_ptr = np.zeros(n + 1, np.int64)
    _count(tr_ptr, tr_idx, tr_val, empty.indptr, empty.indices, empty.data, pts.point_of, pts.t_ptr, pts.t_entry, n,
           work_items(n), node_ptr)
    np.cumsum(node_ptr, out=node_ptr)
    out_idx = np.empty(g * node_ptr[-1], np.int32)
    out_data = np.empty(g * node_ptr[-1])
    _mixed_fill(pts.t_ptr, pts.t_entry, pts.point_of, _values(test), tr_ptr, tr_idx, tr_val,
                np.ascontiguousarray(weights, dtype=np.float64), n, work_items(n), node_ptr, out_idx, out_data)
    indptr = np.empty(g * n + 1, np.int64)
    for a in range(g):
        indptr[a:-1:g] = g * node_ptr[:-1] + a * np.diff(node_ptr)
    indptr[-1] = g * node_ptr[-1]
    m = sp.csr_matrix((out_data, out_idx, indptr), shape=(g * n, n))
    m.has_sorted_indices = True
    m.eliminate_zeros()  # as a product of scipy matrices leaves them out (the same system for the solvers)
    return m


def _values(rows: SparseRows) -> np.ndarray:
    return np.ascontiguousarray(rows.data, dtype=np.float64)


def _joined(parts: list[SparseRows]) -> SparseRows:
    """One set of rows of several (a copy)."""
    starts = np.cumsum([0] + [g.indptr[-1] for g in parts[:-1]])
    return SparseRows(np.concatenate([parts[0].indptr[:1]] + [g.indptr[1:] + s for g, s in zip(parts, starts)]),
                      np.concatenate([g.indices for g in parts]), np.concatenate([g.data for g in parts]),
                      parts[0].num_cols)


@numba.njit(cache=True)
def _transposed_entries(idx_a, idx_b, t_ptr, out):
    """The entries e of each column, in order of e over the entries of A and then of B (a
    stable counting sort): the entries of node I are ``out[t_ptr[I]:t_ptr[I + 1]]``."""
    cursor = t_ptr[:-1].copy()
    nnz_a = len(idx_a)
    for e in range(nnz_a):
        out[cursor[idx_a[e]]] = e
        cursor[idx_a[e]] += 1
    for e in range(len(idx_b)):
        out[cursor[idx_b[e]]] = nnz_a + e
        cursor[idx_b[e]] += 1
    return out


@numba.njit(parallel=True, cache=True)
def _entry_points(ptr_a, ptr_b, out):
    """The point of every entry of A, then of B (whose points follow A's)."""
    m_a = len(ptr_a) - 1
    nnz_a = ptr_a[-1]
    for q in numba.prange(m_a):
        for e in range(ptr_a[q], ptr_a[q + 1]):
            out[e] = q
    for q in numba.prange(len(ptr_b) - 1):
        for e in range(ptr_b[q], ptr_b[q + 1]):
            out[nnz_a + e] = m_a + q
    return out
