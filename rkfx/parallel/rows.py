"""Rows of a distributed sparse system: each rank's contributions sent to the rows' owners.

A rank integrates over its owned points only, so its contribution to a matrix (or vector)
touches the rows of its owned and ghost unknowns. ``owned_block`` sends the rows owned
elsewhere to their owners and sums what each rank receives into the block of rows it owns,
which is what a row-distributed PETSc matrix needs (``rkfx.linalg.petsc.LinearSolver`` with
``owned_rows=True``). ``comm`` is any mpi4py-style communicator (``rank``, ``size``,
``alltoall``) or ``None``; this module does not import MPI.
"""
import numba
import numpy as np
import scipy.sparse as sp

from rkfx.approximation.sparse_rows import sort_by_column

# Above this share of rows whose columns the new numbering leaves unsorted, ``renumbered``
# sorts every row by scipy's sort (blocks of unknowns interleaved); below it, only those rows.
UNSORTED_SHARE = 0.05


def owned_block(a: sp.spmatrix, ranges: np.ndarray, comm=None) -> sp.csr_matrix:
    """The rows ``ranges[rank]:ranges[rank + 1]`` of the sum over ranks of ``a``.

    Args:
        a: This rank's contribution in the global numbering, shape ``(num_rows, num_cols)``.
        ranges: Rank r owns rows ``ranges[r]:ranges[r + 1]``, shape ``(comm.size + 1,)``.
        comm: Communicator, or ``None`` for one rank.

    Returns:
        Shape ``(ranges[rank + 1] - ranges[rank], num_cols)``, sorted indices, duplicates summed.
    """
    a = sp.csr_matrix(a)
    rank, size = (0, 1) if comm is None else (comm.rank, comm.size)
    lo, hi = int(ranges[rank]), int(ranges[rank + 1])
    first, last = a.indptr[lo], a.indptr[hi]  # the block's rows as views (scipy's slice checks every column)
    mine = sp.csr_matrix((a.data[first:last], a.indices[first:last], a.indptr[lo:hi + 1] - first),
                         shape=(hi - lo, a.shape[1]))
    if size > 1:
        filled = np.flatnonzero(np.diff(a.indptr))
        owner = np.searchsorted(ranges, filled, side="right") - 1
        sends = []
        for r in range(size):
            rows = filled[owner == r] if r != rank else filled[:0]
            sub = a[rows]
            sends.append((rows - ranges[r], sub.indptr, sub.indices, sub.data))
        for rows, indptr, indices, data in comm.alltoall(sends):
            if len(rows):
                got = sp.csr_matrix((data, indices, indptr), shape=(len(rows), a.shape[1])).tocoo()
                mine = mine + sp.csr_matrix((got.data, (rows[got.row], got.col)), shape=mine.shape)
    mine = sp.csr_matrix(mine)
    if not mine.has_canonical_format:
        if np.shares_memory(mine.data, a.data):
            mine = mine.copy()  # a's own arrays stay as they are
        mine.sum_duplicates()
        mine.sort_indices()
    return mine


def renumbered(a: sp.spmatrix, new: np.ndarray, size: int) -> sp.csr_matrix:
    """``a`` with row and column i moved to ``new[i]``, shape ``(size, size)``, sorted indices.

    Args:
        a: Square, shape ``(m, m)``.
        new: Distinct new indices of a's rows and columns, shape ``(m,)``, in ``0..size-1``.
        size: Rows and columns of the result (the rows not in ``new`` are empty).
    """
    a = sp.csr_matrix(a)
    new = np.asarray(new, np.int64)
    lengths = np.zeros(size, np.int64)
    lengths[new] = np.diff(a.indptr)
    index = np.int32 if max(size, a.nnz) <= np.iinfo(np.int32).max else np.int64  # as scipy would pick
    indptr = np.zeros(size + 1, index)
    np.cumsum(lengths, out=indptr[1:])
    indices, data = np.empty(indptr[-1], index), np.empty(indptr[-1], a.dtype)
    unsorted = np.zeros(size, np.bool_)
    _moved(a.indptr, a.indices, a.data, new, indptr, indices, data, unsorted)
    out = sp.csr_matrix((data, indices, indptr), shape=(size, size))
    rows = np.flatnonzero(unsorted)
    if len(rows) > UNSORTED_SHARE * len(new):  # rows of interleaved blocks (u and p): scipy sorts them all
        out.has_sorted_indices = False
        out.sort_indices()
    else:  # a few rows where the new numbering moves columns past others (a partition's cut)
        sort_by_column(indptr, indices, data, rows)
        out.has_sorted_indices = True
    return out


def owned_entries(v: np.ndarray, ranges: np.ndarray, comm=None) -> np.ndarray:
    """The entries ``ranges[rank]:ranges[rank + 1]`` of the sum over ranks of the vector ``v``
    (this rank's contribution, nonzero on its owned and ghost unknowns only)."""
    v = np.asarray(v, dtype=np.float64)
    column = sp.csr_matrix(v.reshape(-1, 1))
    return owned_block(column, ranges, comm).toarray().ravel()


@numba.njit(parallel=True, cache=True)
def _moved(indptr, indices, data, new, out_ptr, out_idx, out_data, unsorted):
    """Row i of (indptr, indices, data) to row new[i] at out_ptr, its columns j to new[j] in
    their order; ``unsorted[new[i]]`` tells whether they are no longer ascending."""
    for i in numba.prange(len(indptr) - 1):
        at = out_ptr[new[i]] - indptr[i]
        last = -1
        for q in range(indptr[i], indptr[i + 1]):
            c = new[indices[q]]
            out_idx[at + q] = c
            out_data[at + q] = data[q]
            if c < last:
                unsorted[new[i]] = True
            last = c
