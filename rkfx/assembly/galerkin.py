"""The elastic stiffness sum_q w_q B_q^T D_q B_q assembled straight into its CSR rows, compiled.

A product of scipy matrices (B^T, then diag(w D), then B) forms intermediates several times
the size of K: at 9 x 10^4 nodes with the MSCNI rows, 1.4 GB of transients for a K of 167 MB,
and most of the assembly's time. Here each node I owns its two rows of K: one pass over the
points q whose rows hold I (the transposed entries, in point order) counts the distinct
nodes J they couple I to, a second pass adds the 2 x 2 blocks B_I(q)^T w_q D_q B_J(q) in
place. Rows are independent, so they run in parallel, and every entry is summed in the same
order (points ascending, then the entries of each point's row) on any number of threads. The
columns of each row come out sorted, and the transposed entries come from a counting sort:
no sort of the whole entry list, no sort of K afterwards.

The points may come in two sets of rows (the SCNI cells and the MSCNI subcells of eq. 3.56),
read where they are: the points of the second follow those of the first, and nothing is
copied into one list. The transposed entries and the point of each entry are int32 (half of
int64's bytes, the largest arrays of the assembly after the rows) while they fit.

B(g) of a gradient g = (g_x, g_y) is the Voigt strain matrix [[g_x, 0], [0, g_y], [g_y, g_x]].
"""
from collections.abc import Sequence

import numba
import numpy as np
import scipy.sparse as sp

from rkfx.approximation.sparse_rows import SparseRows, work_items


@numba.njit(parallel=True, cache=True)
def _stiffness(ptr_a, idx_a, grad_a, ptr_b, idx_b, grad_b, point_of, t_ptr, t_entry, weight, d, per_point,
               num_nodes, nchunks, node_ptr, out_idx, out_data, fill):
    """Count (``fill`` False: node_ptr[I + 1] = distinct J of row I) or fill the CSR of K, over
    the points of rows A and then rows B (entry p >= len(idx_a) is entry p - len(idx_a) of B)."""
    chunk = (num_nodes + nchunks - 1) // nchunks
    m_a = len(ptr_a) - 1
    nnz_a = len(idx_a)
    for c in numba.prange(nchunks):
        stamp = np.full(num_nodes, -1, np.int64)
        slot = np.empty(num_nodes, np.int64)
        t = np.empty((2, 3))
        for i in range(c * chunk, min(num_nodes, (c + 1) * chunk)):
            k = 0
            width = node_ptr[i + 1] - node_ptr[i] if fill else 0
            first = 4 * node_ptr[i]
            if fill:  # the row's columns, ascending: slot[J] = rank of J among them
                cols = np.empty(width, np.int64)
                for e_i in range(t_ptr[i], t_ptr[i + 1]):
                    q = point_of[t_entry[e_i]]
                    ptr, idx, off = (ptr_a, idx_a, q) if q < m_a else (ptr_b, idx_b, q - m_a)
                    for e in range(ptr[off], ptr[off + 1]):
                        j = idx[e]
                        if stamp[j] != i:
                            stamp[j] = i
                            cols[k] = j
                            k += 1
                cols.sort()
                for s in range(width):
                    j = cols[s]
                    slot[j] = s
                    for a in range(2):
                        for b in range(2):
                            pos = first + 2 * a * width + 2 * s + b
                            out_idx[pos] = 2 * j + b
                            out_data[pos] = 0.0
            for e_i in range(t_ptr[i], t_ptr[i + 1]):
                p = t_entry[e_i]
                q = point_of[p]
                ptr, idx, grad, off = (ptr_a, idx_a, grad_a, q) if q < m_a else (ptr_b, idx_b, grad_b, q - m_a)
                if fill:
                    # t = B_I^T (w D): 2 x 3.
                    m = d[q] if per_point else d[0]
                    pe = p if p < nnz_a else p - nnz_a
                    gx, gy, w = grad[pe, 0], grad[pe, 1], weight[q]
                    for s in range(3):
                        t[0, s] = w * (gx * m[0, s] + gy * m[2, s])
                        t[1, s] = w * (gy * m[1, s] + gx * m[2, s])
                for e in range(ptr[off], ptr[off + 1]):
                    j = idx[e]
                    if not fill:
                        if stamp[j] != i:
                            stamp[j] = i
                            k += 1
                    else:
                        hx, hy = grad[e, 0], grad[e, 1]
                        base = first + 2 * slot[j]
                        for a in range(2):
                            row = base + 2 * a * width
                            out_data[row] += t[a, 0] * hx + t[a, 2] * hy
                            out_data[row + 1] += t[a, 1] * hy + t[a, 2] * hx
            if not fill:
                node_ptr[i + 1] = k


def elastic_stiffness(rows: SparseRows | Sequence[SparseRows], weights: np.ndarray, d: np.ndarray) -> sp.csr_matrix:
    """K = sum_q w_q B_q^T D_q B_q, shape ``(2 n, 2 n)`` over interleaved unknowns, sorted indices.

    Args:
        rows: Gradient rows grad N_I(x_q), 2 components, shape ``(m, n)``; or a list of such
            rows over the same n nodes, whose points follow each other (m = their sum).
        weights: w_q, shape ``(m,)`` [m^2].
        d: D [Pa], shape ``(3, 3)`` or one per point ``(m, 3, 3)``.
    """
    parts = [rows] if isinstance(rows, SparseRows) else list(rows)
    if len(parts) > 2:  # the kernel reads two sets where they are; more are joined into the second
        parts = [parts[0], _joined(parts[1:])]
    a = parts[0]
    b = parts[1] if len(parts) > 1 else SparseRows(np.zeros(1, np.int64), a.indices[:0], a.data[:0], a.num_cols)
    n = a.num_cols
    m = a.num_rows + b.num_rows
    nnz = a.indices.size + b.indices.size
    index = np.int32 if max(nnz, m) < 2**31 else np.int64
    d = np.ascontiguousarray(d, dtype=np.float64)
    per_point = d.ndim == 3
    d = d if per_point else d.reshape(1, 3, 3)
    t_ptr = np.zeros(n + 1, np.int64)
    np.cumsum(np.bincount(a.indices, minlength=n) + np.bincount(b.indices, minlength=n), out=t_ptr[1:])
    t_entry = _transposed_entries(a.indices, b.indices, t_ptr, np.empty(nnz, index))
    point_of = _entry_points(a.indptr, b.indptr, np.empty(nnz, index))
    args = (a.indptr, np.ascontiguousarray(a.indices), _grad(a), b.indptr, np.ascontiguousarray(b.indices), _grad(b),
            point_of, t_ptr, t_entry, np.ascontiguousarray(weights, dtype=np.float64), d, per_point, n, work_items(n))
    node_ptr = np.zeros(n + 1, np.int64)
    _stiffness(*args, node_ptr, np.empty(0, np.int32), np.empty(0), False)
    np.cumsum(node_ptr, out=node_ptr)
    out_idx = np.empty(4 * node_ptr[-1], np.int32)
    out_data = np.empty(4 * node_ptr[-1])
    _stiffness(*args, node_ptr, out_idx, out_data, True)
    indptr = np.empty(2 * n + 1, np.int64)
    indptr[0:-1:2] = 4 * node_ptr[:-1]
    indptr[1::2] = 4 * node_ptr[:-1] + 2 * np.diff(node_ptr)
    indptr[-1] = 4 * node_ptr[-1]
    k = sp.csr_matrix((out_data, out_idx, indptr), shape=(2 * n, 2 * n))
    k.has_sorted_indices = True
    return k


def _grad(rows: SparseRows) -> np.ndarray:
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
