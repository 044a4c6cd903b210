"""CSR rows with vector-valued entries, and their sparse linear combinations.

Every integration rule in rkfx reduces to ``SparseRows``: for each integration point, the
nodes it couples to and a small vector per node (N_I, or the gradient of N_I). Smoothed
gradients (eq. 3.55) and MSCNI differences (3.56) are sparse linear combinations of such
rows, formed by ``combine_rows`` in parallel with a sparse accumulator.
"""
from collections.abc import Iterable
from dataclasses import dataclass

import numba
import numpy as np
import scipy.sparse as sp

# Rows are split into this many parallel work items per thread; each item allocates one
# node-sized marker array, so items must be few and large.
ITEMS_PER_THREAD = 4


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
        """Component k as a ``(num_rows, num_cols)`` scipy CSR matrix.

        The matrix owns copies of the index arrays: scipy sorts indices in place, which would
        otherwise scramble the rows shared by the other components.
        """
        return sp.csr_matrix((self.data[:, k].copy(), self.indices.copy(), self.indptr.copy()),
                             shape=(self.num_rows, self.num_cols))

    def __matmul__(self, coefficients: np.ndarray) -> np.ndarray:
        """Apply to nodal coefficients ``(num_cols,)`` or ``(num_cols, k)``: shape ``(num_rows, num_components, ...)``."""
        return np.stack([self.matrix(k) @ coefficients for k in range(self.num_components)], axis=1)


@numba.njit(inline="always")
def _put(out_idx, out_data, pos, j, src, q, sign):
    """Entry ``pos`` of the output: column j with the components ``sign * src[q]``."""
    out_idx[pos] = j
    for d in range(out_data.shape[1]):
        out_data[pos, d] = sign * src[q, d]


@numba.njit(parallel=True, cache=True)
def _combine(src_ptr, src_idx, src_val, term_ptr, term_row, term_w, num_cols, nchunks,
             base_ptr, base_idx, base_data, base_row, out_ptr, out_idx, out_data, fill):
    """Row r = base[base_row[r]] + sum_t w_t (vector) * src[term_row[t]] (scalar rows).

    Sparse accumulator with row stamps: ``stamp[j] == r`` marks column j as present in row r
    at local position ``slot[j]``, so nothing needs resetting between rows.
    """
    nrows = len(term_ptr) - 1
    nc = term_w.shape[1]
    has_base = len(base_row) > 0
    chunk = (nrows + nchunks - 1) // nchunks
    for c in numba.prange(nchunks):
        stamp = np.full(num_cols, -1, np.int64)
        slot = np.empty(num_cols, np.int32)
        for r in range(c * chunk, min(nrows, (c + 1) * chunk)):
            base = out_ptr[r] if fill else 0
            k = 0
            if has_base:
                rb = base_row[r]
                for q in range(base_ptr[rb], base_ptr[rb + 1]):
                    j = base_idx[q]
                    stamp[j] = r
                    slot[j] = k
                    if fill:
                        _put(out_idx, out_data, base + k, j, base_data, q, 1.0)
                    k += 1
            for t in range(term_ptr[r], term_ptr[r + 1]):
                s = term_row[t]
                for q in range(src_ptr[s], src_ptr[s + 1]):
                    j = src_idx[q]
                    if stamp[j] != r:
                        stamp[j] = r
                        slot[j] = k
                        if fill:
                            out_idx[base + k] = j
                            for d in range(nc):
                                out_data[base + k, d] = 0.0
                        k += 1
                    if fill:
                        pos = base + slot[j]
                        v = src_val[q]
                        for d in range(nc):
                            out_data[pos, d] += v * term_w[t, d]
            if not fill:
                out_ptr[r + 1] = k


def work_items(nrows: int) -> int:
    """Parallel work items for ``nrows`` rows: ``ITEMS_PER_THREAD`` per thread, at most one per row."""
    return max(1, min(nrows, ITEMS_PER_THREAD * numba.get_num_threads()))


@dataclass(frozen=True)
class RowJob:
    """The rows a two-pass row kernel forms (``kernel(*args, out_ptr, out_idx, out_data, fill)``):
    ``count`` their lengths, then ``fill`` arrays of the counted size, its own (``rows``) or the
    next part of a buffer shared by many jobs (``stacked_rows``)."""

    kernel: object
    args: tuple
    num_rows: int
    num_components: int
    num_cols: int

    def count(self) -> np.ndarray:
        """Row pointers of the rows, shape ``(num_rows + 1,)`` (from 0)."""
        out_ptr = np.zeros(self.num_rows + 1, np.int64)
        self.kernel(*self.args, out_ptr, np.empty(0, np.int32), np.empty((0, self.num_components)), False)
        np.cumsum(out_ptr, out=out_ptr)
        return out_ptr

    def fill(self, out_ptr: np.ndarray, out_idx: np.ndarray, out_data: np.ndarray) -> None:
        """Write the rows' entries to ``out_idx[:out_ptr[-1]]``, ``out_data[:out_ptr[-1]]``."""
        self.kernel(*self.args, out_ptr, out_idx, out_data, True)

    def rows(self) -> SparseRows:
        out_ptr = self.count()
        out_idx = np.empty(out_ptr[-1], np.int32)
        out_data = np.empty((out_ptr[-1], self.num_components))
        self.fill(out_ptr, out_idx, out_data)
        return SparseRows(out_ptr, out_idx, out_data, self.num_cols)


class RowStack:
    """Rows appended a job at a time into buffers that grow, for rows formed in pieces whose
    sizes are known only once each piece is counted (``stacked_rows``).

    The buffers are allocated at the first job, for its entries per row times ``num_rows``
    (the rows expected in all) times ``slack``; the operating system backs only the pages
    written, so the slack costs address space, not memory. A job that overflows them grows
    them by half (a copy).
    """

    def __init__(self, num_rows: int, slack: float = 1.25):
        self.indptr = np.zeros(num_rows + 1, np.int64)
        self.indices = self.data = None
        self.num_rows_expected, self.slack = num_rows, slack
        self.count = self.nnz = 0
        self.num_cols, self.num_components = 0, 1

    def append(self, job: RowJob) -> None:
        """Count and fill the rows of ``job`` after those appended so far."""
        ptr = job.count()
        m, k = job.num_rows, int(ptr[-1])
        self.num_cols, self.num_components = job.num_cols, job.num_components
        if self.indices is None:
            capacity = max(k, int(self.slack * k / max(m, 1) * self.num_rows_expected) + 1)
            self.indices, self.data = np.empty(capacity, np.int32), np.empty((capacity, job.num_components))
        if self.nnz + k > len(self.indices):
            capacity = max(self.nnz + k, int(1.5 * len(self.indices)))
            self.indices, self.data = _grown(self.indices, self.nnz, capacity), _grown(self.data, self.nnz, capacity)
        if self.count + m > self.num_rows_expected:
            raise ValueError(f"RowStack: {self.count + m} rows appended, {self.num_rows_expected} were announced")
        job.fill(ptr, self.indices[self.nnz:self.nnz + k], self.data[self.nnz:self.nnz + k])
        self.indptr[self.count + 1:self.count + m + 1] = ptr[1:] + self.nnz
        self.count, self.nnz = self.count + m, self.nnz + k

    def rows(self) -> SparseRows:
        """The rows appended so far (views of the buffers)."""
        if self.indices is None:
            return SparseRows(self.indptr[:1], np.empty(0, np.int32), np.empty((0, self.num_components)), self.num_cols)
        return SparseRows(self.indptr[:self.count + 1], self.indices[:self.nnz], self.data[:self.nnz], self.num_cols)


def stacked_rows(jobs: Iterable[RowJob], num_rows: int, slack: float = 1.25) -> SparseRows:
    """The rows of ``jobs`` (consecutive, ``num_rows`` in all), one after another, each job's
    rows written straight into the result (a ``RowStack``) and the job dropped before the next
    is made, so that no more than the result and one job's inputs are held at a time."""
    stack = RowStack(num_rows, slack)
    for job in jobs:
        stack.append(job)
        del job
    if stack.count != num_rows:
        raise ValueError(f"stacked_rows: the jobs form {stack.count} rows, {num_rows} were announced")
    return stack.rows()


@numba.njit(parallel=True, cache=True)
def _gather(indptr, indices, data, rows, column, out_ptr, out_idx, out_data):
    renumber = len(column) > 0
    for r in numba.prange(len(rows)):
        src = indptr[rows[r]]
        for k in range(out_ptr[r + 1] - out_ptr[r]):
            j = indices[src + k]
            out_idx[out_ptr[r] + k] = column[j] if renumber else j
            for c in range(data.shape[1]):
                out_data[out_ptr[r] + k, c] = data[src + k, c]


def gathered_rows(rows: SparseRows, which: np.ndarray, column: np.ndarray | None = None,
                  num_cols: int | None = None) -> SparseRows:
    """The rows ``which`` of ``rows``, in that order, each row's entries in their order; with
    ``column`` (new index of every column) over ``num_cols`` renumbered columns."""
    which = np.ascontiguousarray(which, dtype=np.int64)
    out_ptr = np.zeros(len(which) + 1, np.int64)
    np.cumsum(np.diff(rows.indptr)[which], out=out_ptr[1:])
    out_idx = np.empty(out_ptr[-1], np.int32)
    out_data = np.empty((out_ptr[-1], rows.num_components))
    col = np.empty(0, np.int32) if column is None else np.ascontiguousarray(column, dtype=np.int32)
    _gather(rows.indptr, rows.indices, np.ascontiguousarray(rows.data), which, col, out_ptr, out_idx, out_data)
    return SparseRows(out_ptr, out_idx, out_data, rows.num_cols if num_cols is None else num_cols)


@numba.njit(parallel=True, cache=True)
def _sort_by_column(indptr, indices, data, rows):
    for k in numba.prange(len(rows)):  # insertion sort, stable: rows are short or nearly sorted
        r = rows[k]
        held = np.empty(data.shape[1], data.dtype)
        for q in range(indptr[r] + 1, indptr[r + 1]):
            i = indices[q]
            held[:] = data[q]
            p = q - 1
            while p >= indptr[r] and indices[p] > i:
                indices[p + 1] = indices[p]
                data[p + 1] = data[p]
                p -= 1
            indices[p + 1] = i
            data[p + 1] = held


def sort_by_column(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, rows: np.ndarray | None = None) -> None:
    """Order the entries of ``rows`` (default all) of CSR-like arrays by column, in place and
    stably; ``data`` has one value per entry, or a row of values ``(nnz, k)``."""
    rows = np.arange(len(indptr) - 1) if rows is None else np.asarray(rows, np.int64)
    _sort_by_column(indptr, indices, data[:, None] if data.ndim == 1 else data, rows)


def ranges(starts: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """The concatenation of ``arange(s, s + c)`` over ``zip(starts, counts)`` (e.g. the entry
    positions of some rows: their ``indptr`` starts and lengths), int64."""
    starts, counts = np.asarray(starts, np.int64), np.asarray(counts, np.int64)
    return np.arange(counts.sum()) + np.repeat(starts - (np.cumsum(counts) - counts), counts)


def spread_rows(rows: SparseRows, at: np.ndarray, num_rows: int) -> SparseRows:
    """``rows`` placed as the rows ``at`` (ascending) of ``num_rows`` rows, the others empty
    (the same entry arrays)."""
    lengths = np.zeros(num_rows, np.int64)
    lengths[at] = np.diff(rows.indptr)
    indptr = np.zeros(num_rows + 1, np.int64)
    np.cumsum(lengths, out=indptr[1:])
    return SparseRows(indptr, rows.indices, rows.data, rows.num_cols)


def _grown(a: np.ndarray, used: int, capacity: int) -> np.ndarray:
    """A buffer of ``capacity`` rows holding the first ``used`` rows of ``a`` (the rest unwritten)."""
    out = np.empty((capacity, *a.shape[1:]), a.dtype)
    out[:used] = a[:used]
    return out


def combine_rows(source: SparseRows, term_ptr: np.ndarray, term_row: np.ndarray,
                 term_weight: np.ndarray, base: SparseRows | None = None,
                 base_row: np.ndarray | None = None) -> SparseRows:
    """Rows formed as weighted sums of source rows (``combine_job``, formed at once)."""
    return combine_job(source, term_ptr, term_row, term_weight, base, base_row).rows()


def combine_job(source: SparseRows, term_ptr: np.ndarray, term_row: np.ndarray,
                term_weight: np.ndarray, base: SparseRows | None = None,
                base_row: np.ndarray | None = None) -> RowJob:
    """Rows formed as weighted sums of scalar source rows, optionally added to base rows.

    Output row r is ``base[base_row[r]] + sum_t w_t * source[term_row[t]]`` for t in
    ``term_ptr[r]:term_ptr[r+1]``, with duplicate columns merged; vector weights of shape
    ``(num_terms, c)`` give c-vector rows (e.g. N times n*l gives a smoothed gradient, eq. 3.55).

    Args:
        source: Rows with one component.
        term_ptr: Shape ``(num_out_rows + 1,)``.
        term_row: Source row of each term, shape ``(num_terms,)``.
        term_weight: Shape ``(num_terms,)`` or ``(num_terms, c)``.
        base: Rows with c components added to the output, selected by ``base_row``.
        base_row: Base row of each output row, shape ``(num_out_rows,)``.
    """
    w = np.ascontiguousarray(term_weight, dtype=np.float64)
    if w.ndim == 1:
        w = w[:, None]
    term_ptr = np.ascontiguousarray(term_ptr, dtype=np.int64)
    term_row = np.ascontiguousarray(term_row, dtype=np.int64)
    nrows = len(term_ptr) - 1
    if base is None:
        base_args = (np.zeros(1, np.int64), np.empty(0, np.int32), np.empty((0, w.shape[1])), np.empty(0, np.int64))
    else:
        base_args = (base.indptr, base.indices, np.ascontiguousarray(base.data),
                     np.ascontiguousarray(base_row, dtype=np.int64))
    args = (source.indptr, source.indices, np.ascontiguousarray(source.data[:, 0]), term_ptr, term_row, w,
            source.num_cols, work_items(nrows), *base_args)
    return RowJob(_combine, args, nrows, w.shape[1], source.num_cols)


@numba.njit(parallel=True, cache=True)
def _difference(a_ptr, a_idx, a_data, a_row, b_ptr, b_idx, b_data, num_cols, nchunks,
                out_ptr, out_idx, out_data, fill):
    """Row r = a[a_row[r]] - b[r]."""
    nrows = len(a_row)
    nc = a_data.shape[1]
    chunk = (nrows + nchunks - 1) // nchunks
    for c in numba.prange(nchunks):
        marker = np.full(num_cols, -1, np.int64)
        for r in range(c * chunk, min(nrows, (c + 1) * chunk)):
            base = out_ptr[r] if fill else 0
            k = 0
            ra = a_row[r]
            for q in range(a_ptr[ra], a_ptr[ra + 1]):
                j = a_idx[q]
                marker[j] = base + k
                if fill:
                    _put(out_idx, out_data, base + k, j, a_data, q, 1.0)
                k += 1
            for q in range(b_ptr[r], b_ptr[r + 1]):
                j = b_idx[q]
                pos = marker[j]
                if pos < 0:
                    pos = base + k
                    k += 1
                    if fill:
                        _put(out_idx, out_data, pos, j, b_data, q, -1.0)
                elif fill:
                    for d in range(nc):
                        out_data[pos, d] -= b_data[q, d]
            if not fill:
                out_ptr[r + 1] = k
            for q in range(a_ptr[ra], a_ptr[ra + 1]):
                marker[a_idx[q]] = -1


def difference_rows(a: SparseRows, a_row: np.ndarray, b: SparseRows) -> SparseRows:
    """Rows ``a[a_row[r]] - b[r]`` (same columns and components), e.g. the MSCNI terms of eq. (3.56)."""
    a_row = np.ascontiguousarray(a_row, dtype=np.int64)
    nrows = len(a_row)
    nc = a.num_components
    args = (a.indptr, a.indices, np.ascontiguousarray(a.data), a_row, b.indptr, b.indices,
            np.ascontiguousarray(b.data), a.num_cols, work_items(nrows))
    return RowJob(_difference, args, nrows, nc, a.num_cols).rows()
