"""CSR rows with vector-valued entries, and their sparse linear combinations.

Every integration rule in rkfx reduces to ``SparseRows``: for each integration point, the
nodes it couples to and a small vector per node (N_I, or the gradient of N_I). Smoothed
gradients (eq. 3.55) and MSCNI differences (3.56) are sparse linear combinations of such
rows, formed by ``combine_rows`` in parallel with a sparse accumulator.
"""
from dataclasses import dataclass

import numba
import numpy as np
import scipy.sparse as sp

CHUNK = 1024  # rows per parallel work item


@dataclass(frozen=True)
class SparseRows:
    """Rows of ``(node, vector)`` entries.

    Attributes:
        indptr: Row pointers, shape ``(num_rows + 1,)`` int64.
        indices: Column (node) index of each entry, shape ``(nnz,)`` int32.
        data: Entry vectors, shape ``(nnz, num_components)``.
        num_cols: Number of columns (nodes).
    """

    indptr: np.ndarray
    indices: np.ndarray
    data: np.ndarray
    num_cols: int

    @property
    def num_rows(self) -> int:
        return len(self.indptr) - 1

    @property
    def num_components(self) -> int:
        return self.data.shape[1]

    def component(self, k: int) -> "SparseRows":
        """The rows restricted to component k (a view sharing the sparsity)."""
        return SparseRows(self.indptr, self.indices, self.data[:, k:k + 1], self.num_cols)

    def matrix(self, k: int = 0) -> sp.csr_matrix:
        """Component k as a ``(num_rows, num_cols)`` scipy CSR matrix."""
        return sp.csr_matrix((self.data[:, k], self.indices, self.indptr),
                             shape=(self.num_rows, self.num_cols))

    def __matmul__(self, coefficients: np.ndarray) -> np.ndarray:
        """Apply to nodal coefficients ``(num_cols,)`` or ``(num_cols, k)``: shape ``(num_rows, num_components, ...)``."""
        return np.stack([self.matrix(k) @ coefficients for k in range(self.num_components)], axis=1)


@numba.njit(parallel=True, cache=True)
def _combine(src_ptr, src_idx, src_data, term_ptr, term_row, term_w, num_cols, out_ptr, out_idx, out_data, fill):
    nrows = len(term_ptr) - 1
    nc_src = src_data.shape[1]
    nc_w = term_w.shape[1]
    nc = max(nc_src, nc_w)
    nchunks = (nrows + CHUNK - 1) // CHUNK
    for c in numba.prange(nchunks):
        marker = np.full(num_cols, -1, np.int64)
        for r in range(c * CHUNK, min(nrows, (c + 1) * CHUNK)):
            base = out_ptr[r] if fill else 0
            k = 0
            for t in range(term_ptr[r], term_ptr[r + 1]):
                s = term_row[t]
                for q in range(src_ptr[s], src_ptr[s + 1]):
                    j = src_idx[q]
                    if marker[j] < 0:
                        marker[j] = base + k
                        if fill:
                            out_idx[base + k] = j
                            for d in range(nc):
                                out_data[base + k, d] = 0.0
                        k += 1
                    if fill:
                        pos = marker[j]
                        for d in range(nc):
                            out_data[pos, d] += src_data[q, d if nc_src > 1 else 0] * term_w[t, d if nc_w > 1 else 0]
            if fill:
                # Reset markers of this row for the next rows of the chunk.
                for q in range(base, base + k):
                    marker[out_idx[q]] = -1
            else:
                out_ptr[r + 1] = k
                for t in range(term_ptr[r], term_ptr[r + 1]):
                    s = term_row[t]
                    for q in range(src_ptr[s], src_ptr[s + 1]):
                        marker[src_idx[q]] = -1


def combine_rows(source: SparseRows, term_ptr: np.ndarray, term_row: np.ndarray,
                 term_weight: np.ndarray) -> SparseRows:
    """Rows formed as weighted sums of source rows.

    Output row r is ``sum_t w_t * source[term_row[t]]`` for t in ``term_ptr[r]:term_ptr[r+1]``,
    with duplicate columns merged. Weights of shape ``(num_terms, c)`` times scalar source rows
    give c-vector rows (e.g. N times n*l gives a gradient); scalar weights times c-vector
    source rows scale them (e.g. differences of gradients).

    Args:
        source: Rows to combine.
        term_ptr: Shape ``(num_out_rows + 1,)``.
        term_row: Source row of each term, shape ``(num_terms,)``.
        term_weight: Shape ``(num_terms,)`` or ``(num_terms, c)``.
    """
    w = np.ascontiguousarray(term_weight, dtype=np.float64)
    if w.ndim == 1:
        w = w[:, None]
    term_ptr = np.ascontiguousarray(term_ptr, dtype=np.int64)
    term_row = np.ascontiguousarray(term_row, dtype=np.int64)
    nc = max(source.num_components, w.shape[1])
    nrows = len(term_ptr) - 1
    out_ptr = np.zeros(nrows + 1, np.int64)
    dummy_i = np.empty(0, np.int32)
    dummy_d = np.empty((0, nc))
    args = (source.indptr, source.indices, np.ascontiguousarray(source.data), term_ptr, term_row, w,
            source.num_cols)
    _combine(*args, out_ptr, dummy_i, dummy_d, False)
    np.cumsum(out_ptr, out=out_ptr)
    out_idx = np.empty(out_ptr[-1], np.int32)
    out_data = np.empty((out_ptr[-1], nc))
    _combine(*args, out_ptr, out_idx, out_data, True)
    return SparseRows(out_ptr, out_idx, out_data, source.num_cols)


def stack_rows(*blocks: SparseRows) -> SparseRows:
    """Concatenate row blocks with equal columns and components."""
    ptrs = [blocks[0].indptr]
    offset = blocks[0].indptr[-1]
    for b in blocks[1:]:
        ptrs.append(b.indptr[1:] + offset)
        offset += b.indptr[-1]
    return SparseRows(np.concatenate(ptrs), np.concatenate([b.indices for b in blocks]),
                      np.concatenate([b.data for b in blocks]), blocks[0].num_cols)
