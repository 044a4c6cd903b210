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

B(g) of a gradient g = (g_x, g_y) is the Voigt strain matrix [[g_x, 0], [0, g_y], [g_y, g_x]].
"""
import numba
import numpy as np
import scipy.sparse as sp

from rkfx.approximation.sparse_rows import SparseRows, work_items


@numba.njit(parallel=True, cache=True)
def _stiffness(ptr, idx, grad, point_of, t_ptr, t_entry, weight, d, per_point, num_nodes, nchunks,
               node_ptr, out_idx, out_data, fill):
    """Count (``fill`` False: node_ptr[I + 1] = distinct J of row I) or fill the CSR of K."""
    chunk = (num_nodes + nchunks - 1) // nchunks
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
                    for e in range(ptr[q], ptr[q + 1]):
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
                if fill:
                    # t = B_I^T (w D): 2 x 3.
                    m = d[q] if per_point else d[0]
                    gx, gy, w = grad[p, 0], grad[p, 1], weight[q]
                    for s in range(3):
                        t[0, s] = w * (gx * m[0, s] + gy * m[2, s])
                        t[1, s] = w * (gy * m[1, s] + gx * m[2, s])
                for e in range(ptr[q], ptr[q + 1]):
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


def elastic_stiffness(rows: SparseRows, weights: np.ndarray, d: np.ndarray) -> sp.csr_matrix:
    """K = sum_q w_q B_q^T D_q B_q, shape ``(2 n, 2 n)`` over interleaved unknowns, sorted indices.

    Args:
        rows: Gradient rows grad N_I(x_q), 2 components, shape ``(m, n)``.
        weights: w_q, shape ``(m,)`` [m^2].
        d: D [Pa], shape ``(3, 3)`` or one per point ``(m, 3, 3)``.
    """
    n, m = rows.num_cols, rows.num_rows
    d = np.ascontiguousarray(d, dtype=np.float64)
    per_point = d.ndim == 3
    d = d if per_point else d.reshape(1, 3, 3)
    idx = np.ascontiguousarray(rows.indices)
    point_of = np.repeat(np.arange(m, dtype=np.int64), np.diff(rows.indptr))
    t_ptr = np.zeros(n + 1, np.int64)
    np.cumsum(np.bincount(idx, minlength=n), out=t_ptr[1:])
    t_entry = _transposed_entries(idx, t_ptr)
    args = (rows.indptr, idx, np.ascontiguousarray(rows.data, dtype=np.float64), point_of, t_ptr, t_entry,
            np.ascontiguousarray(weights, dtype=np.float64), d, per_point, n,
            work_items(n))
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


@numba.njit(cache=True)
def _transposed_entries(idx, t_ptr):
    """The entries e of each column idx[e], in order of e (a stable counting sort): the entries
    of node I are ``out[t_ptr[I]:t_ptr[I + 1]]``."""
    cursor = t_ptr[:-1].copy()
    out = np.empty(len(idx), np.int64)
    for e in range(len(idx)):
        out[cursor[idx[e]]] = e
        cursor[idx[e]] += 1
    return out
