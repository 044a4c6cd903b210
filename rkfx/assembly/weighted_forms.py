"""Sums of weighted row products on one fixed sparsity pattern, for Jacobians re-assembled in
every Newton iteration.

A nodal-integration form whose coefficients change with the state is

    J(w_1, ..., w_k) = sum_j A_j^T diag(w_j) B_j  (+ a constant matrix)

with fixed point rows A_j, B_j (values, gradients, divergences at the nodes) and per-point
weights w_j (V_L times S_w, k_rw, ... at x_L). ``WeightedForm`` finds the pattern of the sum
and the contribution of every point to every entry once; each evaluation is then one sparse
matrix-vector product into the entries, with no sparse-matrix products.
"""
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from rkfx.errors import InputError


def _triplets(a: sp.csr_matrix, b: sp.csr_matrix):
    """(i, j, L, a_Li b_Lj) over every point L and every pair of its entries."""
    ca, cb = np.diff(a.indptr), np.diff(b.indptr)
    per = ca * cb
    point = np.repeat(np.arange(a.shape[0]), per)
    start = np.repeat(np.cumsum(per) - per, per)
    local = np.arange(per.sum()) - start
    cbp = cb[point]
    ia = a.indptr[point] + local // np.maximum(cbp, 1)
    ib = b.indptr[point] + local % np.maximum(cbp, 1)
    return a.indices[ia], b.indices[ib], point, a.data[ia] * b.data[ib]


class WeightedForm:
    """``sum_j A_j^T diag(w_j) B_j + constant`` for weights given at each call.

    Args:
        pairs: (A_j, B_j) with as many rows as points each; A_j's columns are the rows of the
            result, B_j's its columns.
        shape: Shape of the result.
        constant: A matrix added to every evaluation, or ``None``.
    """

    def __init__(self, pairs: Sequence[tuple[sp.spmatrix, sp.spmatrix]], shape: tuple[int, int],
                 constant: sp.spmatrix | None = None):
        rows, cols, wcol, vals, self.sizes = [], [], [], [], []
        offset = 0
        for a, b in pairs:
            a, b = sp.csr_matrix(a), sp.csr_matrix(b)
            if a.shape[0] != b.shape[0] or a.shape[1] != shape[0] or b.shape[1] != shape[1]:
                raise InputError(f"a pair of shapes {a.shape} and {b.shape} does not form a {shape} matrix")
            i, j, point, v = _triplets(a, b)
            rows.append(i), cols.append(j), wcol.append(point + offset), vals.append(v)
            self.sizes.append(a.shape[0])
            offset += a.shape[0]
        if constant is not None:
            c = sp.coo_matrix(constant)
            rows.append(c.row), cols.append(c.col), wcol.append(np.full(c.nnz, offset)), vals.append(c.data)
        self._weights = offset + 1  # the last weight is the constant's, 1
        i, j = np.concatenate(rows).astype(np.int64), np.concatenate(cols).astype(np.int64)
        keys, where = np.unique(i * shape[1] + j, return_inverse=True)
        self.shape = shape
        self.indices = (keys % shape[1]).astype(np.int32)
        self.indptr = np.r_[0, np.cumsum(np.bincount(keys // shape[1], minlength=shape[0]))].astype(np.int32)
        self._entries = sp.csr_matrix((np.concatenate(vals), (where, np.concatenate(wcol))),
                                      shape=(len(keys), self._weights))

    def __call__(self, weights: Sequence[np.ndarray]) -> sp.csr_matrix:
        if len(weights) != len(self.sizes):
            raise InputError(f"{len(weights)} weight vectors for a form of {len(self.sizes)} products")
        w = np.concatenate([np.broadcast_to(np.asarray(x, float), (n,)) for x, n in zip(weights, self.sizes)]
                           + [np.ones(1)])
        return sp.csr_matrix((self._entries @ w, self.indices.copy(), self.indptr.copy()), shape=self.shape)


def placed(a: sp.spmatrix, columns: int, offset: int = 0, stride: int = 1) -> sp.csr_matrix:
    """``a`` with its column c moved to ``offset + stride c`` of ``columns`` columns (a
    pressure row onto [u, p], or a value row onto one interleaved displacement component)."""
    a = sp.csr_matrix(a)
    return sp.csr_matrix((a.data, offset + stride * a.indices, a.indptr), shape=(a.shape[0], columns))
