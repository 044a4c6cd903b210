"""Whether a sparse matrix equals its transpose, judged against its rows' scales.

Steppers hand the linear solvers matrices that are symmetric by construction (the u-p
Jacobians with their row weights, ``rkfx.solvers.newmark``) up to the round-off of their
assembly; a direct solver may then factorize them as L D L^T at half the work of LU.
"""
import numba
import numpy as np
import scipy.sparse as sp

# |a_ij - a_ji| <= SYMMETRY_RTOL max(r_i, r_j), r_i the largest |a_ik| of row i.
SYMMETRY_RTOL = 1e-12


@numba.njit(cache=True)
def _symmetric(indptr, indices, data, scale, rtol):
    n = len(indptr) - 1
    for i in range(n):
        for t in range(indptr[i], indptr[i + 1]):
            j = indices[t]
            # a_ji by bisection in row j (sorted indices); 0 where it is not stored.
            lo, hi = indptr[j], indptr[j + 1]
            while lo < hi:
                mid = (lo + hi) // 2
                if indices[mid] < i:
                    lo = mid + 1
                else:
                    hi = mid
            other = data[lo] if lo < indptr[j + 1] and indices[lo] == i else 0.0
            if abs(data[t] - other) > rtol * max(scale[i], scale[j]):
                return False
    return True


def is_symmetric(a: sp.spmatrix, rtol: float = SYMMETRY_RTOL) -> bool:
    """Whether |a_ij - a_ji| <= ``rtol`` max(r_i, r_j) for every entry, r_i the largest |a_ik| of
    row i: equal to its transpose up to the round-off of its rows' scales (an entry that
    cancels to 1e-19 on one side and to zero on the other is round-off, not asymmetry). One pass
    over the entries, stopping at the first that differs."""
    if a.shape[0] != a.shape[1]:
        return False
    a = sp.csr_matrix(a)
    if not a.has_sorted_indices:
        a = a.sorted_indices()
    if a.nnz == 0:
        return True
    scale = np.zeros(a.shape[0])
    filled = np.diff(a.indptr) > 0
    scale[filled] = np.maximum.reduceat(np.abs(a.data), a.indptr[:-1][filled])
    return bool(_symmetric(a.indptr, a.indices, np.ascontiguousarray(a.data, dtype=np.float64), scale, float(rtol)))
