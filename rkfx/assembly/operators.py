"""Sparse operators as ``B^T D B w`` products over quadratures (the stiffness compiled:
``rkfx.assembly.galerkin``).

Degrees of freedom of vector fields are interleaved per node: (u_x0, u_y0, u_x1, ...).
Strains use Voigt order (eps_xx, eps_yy, gamma_xy); in 3-D (gradient rows of three components)
(eps_xx, eps_yy, eps_zz, gamma_yz, gamma_xz, gamma_xy).
"""
import numba
import numpy as np
import scipy.sparse as sp

from rkfx.assembly.galerkin import elastic_stiffness, scalar_form
from rkfx.errors import InputError
from rkfx.integration.quadrature import Quadrature
from rkfx.approximation.sparse_rows import SparseRows


# (Voigt row, displacement component, gradient component) of the entries of B(g).
_STRAIN_ENTRIES = {2: ((0, 0, 0), (1, 1, 1), (2, 0, 1), (2, 1, 0)),
                   3: ((0, 0, 0), (1, 1, 1), (2, 2, 2), (3, 1, 2), (3, 2, 1), (4, 0, 2), (4, 2, 0), (5, 0, 1),
                       (5, 1, 0))}


def voigt_size(dim: int) -> int:
    """Components of a symmetric tensor in Voigt form: 3 in 2-D, 6 in 3-D."""
    return 3 if dim == 2 else 6


def strain_matrix(grad: SparseRows) -> sp.csr_matrix:
    """B with the Voigt strain rows per point, shape ``(v m, g n)``: v = 3, g = 2 for 2-D
    gradient rows, v = 6, g = 3 for 3-D ones (see the module docstring for the order)."""
    m, n, g = grad.num_rows, grad.num_cols, grad.num_components
    v = voigt_size(g)
    row = np.repeat(np.arange(m), np.diff(grad.indptr))
    col = g * grad.indices.astype(np.int64)
    entries = _STRAIN_ENTRIES[g]
    rows = np.concatenate([v * row + s for s, _, _ in entries])
    cols = np.concatenate([col + c for _, c, _ in entries])
    vals = np.concatenate([grad.data[:, k] for _, _, k in entries])
    return sp.csr_matrix((vals, (rows, cols)), shape=(v * m, g * n))


def block_diagonal(blocks: np.ndarray) -> sp.csr_matrix:
    """Sparse block-diagonal matrix of ``m`` dense blocks, ``blocks`` of shape ``(m, r, c)``."""
    m, r, c = blocks.shape
    rows = np.broadcast_to((r * np.arange(m))[:, None, None] + np.arange(r)[None, :, None], blocks.shape)
    cols = np.broadcast_to((c * np.arange(m))[:, None, None] + np.arange(c)[None, None, :], blocks.shape)
    return sp.csr_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(m * r, m * c))


def _per_quadrature(c, quadratures: list[Quadrature]) -> list:
    """A coefficient for each quadrature: ``c`` itself, or ``c[i]`` when given as a list (one
    array of point values per quadrature, e.g. per-particle fields mapped to the points)."""
    if isinstance(c, (list, tuple)):
        if len(c) != len(quadratures):
            raise InputError(f"{len(c)} coefficient arrays for {len(quadratures)} quadratures; give one each")
        return list(c)
    return [c] * len(quadratures)


def stiffness(quadratures: list[Quadrature], d) -> sp.csr_matrix:
    """Elastic stiffness ``sum_q w_q B_q^T D B_q`` (eqs. 3.32 and 3.56), shape ``(g n, g n)``
    for gradient rows of g = 2 or 3 components.

    ``d``: one ``(v, v)`` Voigt matrix [Pa] (v = 3 in 2-D, 6 in 3-D), or a list with a ``(v, v)``
    or ``(m_q, v, v)`` array per quadrature (a stiffness per point, e.g. degraded by damage).
    """
    ds = [np.asarray(dq, float) for dq in _per_quadrature(d, quadratures)]
    if len(quadratures) == 1:
        return elastic_stiffness(quadratures[0].gradients, quadratures[0].weights, ds[0])
    # One pass over all the points (cell and subcell rows, read where they are): no sum of
    # whole matrices, no copy of the rows into one list.
    v = ds[0].shape[-1]
    same = all(dq.shape == (v, v) and np.array_equal(dq, ds[0]) for dq in ds)
    d_all = ds[0] if same else np.concatenate([np.broadcast_to(dq, (len(q.weights), v, v))
                                               for q, dq in zip(quadratures, ds)])
    return elastic_stiffness([q.gradients for q in quadratures], np.concatenate([q.weights for q in quadratures]),
                             d_all)


@numba.njit(cache=True)
def _add_into(a_ptr, a_idx, a_data, b_ptr, b_idx, b_data):
    """a += b where every entry of b lies in a's pattern (rows of a sorted); False (a untouched
    from the first entry of b outside it on) when one does not."""
    for r in range(len(b_ptr) - 1):
        lo, hi = a_ptr[r], a_ptr[r + 1]
        for e in range(b_ptr[r], b_ptr[r + 1]):
            k = lo + np.searchsorted(a_idx[lo:hi], b_idx[e])
            if k == hi or a_idx[k] != b_idx[e]:
                return False
    for r in range(len(b_ptr) - 1):
        lo, hi = a_ptr[r], a_ptr[r + 1]
        for e in range(b_ptr[r], b_ptr[r + 1]):
            a_data[lo + np.searchsorted(a_idx[lo:hi], b_idx[e])] += b_data[e]
    return True


def add_into(a: sp.csr_matrix, b: sp.spmatrix) -> sp.csr_matrix:
    """a + b, in a's arrays when b's entries lie in a's pattern (a small b, e.g. boundary terms
    added to a stiffness: no copy of a), else as a new matrix; either way without the entries
    that are exactly zero, as scipy's sum drops them (fewer entries for the solver: on the beam
    of ``bench/beam_scale.py`` keeping them made CG + GAMG 15% slower)."""
    b = sp.csr_matrix(b)
    b.sum_duplicates()
    if not (a.has_sorted_indices and a.shape == b.shape):
        return (a + b).tocsr()
    if _add_into(a.indptr, a.indices, a.data, b.indptr.astype(np.int64), b.indices.astype(a.indices.dtype), b.data):
        a.eliminate_zeros()  # in place
        return a
    return (a + b).tocsr()


def laplacian(quadratures: list[Quadrature], k=1.0) -> sp.csr_matrix:
    """Diffusion matrix ``sum_q w_q (grad N)^T k grad N`` (eqs. 3.35 and 3.59), shape ``(n, n)``,
    compiled (``rkfx.assembly.galerkin.scalar_form``).

    ``k``: a scalar or ``(g, g)`` tensor (g = 2, or 3 in 3-D), or a list with a ``(m_q,)`` or
    ``(m_q, g, g)`` array per quadrature (an isotropic or anisotropic permeability per point).
    """
    metrics = []
    g = quadratures[0].gradients.num_components
    for q, kq in zip(quadratures, _per_quadrature(k, quadratures)):
        kq = np.asarray(kq, float)
        m = len(q.weights)
        if kq.ndim == 0 or kq.shape == (m,):
            kq = (kq.reshape(-1, 1, 1) if kq.ndim else kq) * np.eye(g)
        metrics.append(np.broadcast_to(kq, (m, g, g)) if kq.ndim == 3 else kq)
    a = _form([q.gradients for q in quadratures], quadratures, metrics)
    a.eliminate_zeros()  # as scipy's sums did (no entries that are exactly zero for the solvers)
    return a


def mass(quadratures: list[Quadrature], c=1.0) -> sp.csr_matrix:
    """``sum_q w_q c N^T N`` over the value rows (eqs. 3.34 and 3.58), shape ``(n, n)``.

    ``c``: a scalar, or a list with a ``(m_q,)`` array per quadrature.

    One scipy product per quadrature: the value rows are short, and at 263k nodes (MSCNI) the
    product takes 0.61 s where the compiled ``scalar_form`` takes 0.9-1.2 s (its cost is per
    (node, point, node) triple, as for ``laplacian``, which it makes 1.7 times faster).
    """
    total = None
    for q, cq in zip(quadratures, _per_quadrature(c, quadratures)):
        if q.values is None:
            continue
        nmat = q.values.matrix()
        term = nmat.T @ sp.diags(np.asarray(cq, float) * q.weights) @ nmat
        total = term if total is None else total + term
    return total.tocsr()


def _form(rows: list[SparseRows], quadratures: list[Quadrature], metrics: list[np.ndarray]) -> sp.csr_matrix:
    """``scalar_form`` over the points of all the quadratures, with one metric (``(c, c)``) or
    one per point (``(m_q, c, c)``) for each."""
    if all(mq.ndim == 2 and np.array_equal(mq, metrics[0]) for mq in metrics):
        metric = metrics[0]
    else:
        c = metrics[0].shape[-1]
        metric = np.concatenate([np.broadcast_to(mq, (len(q.weights), c, c)) for q, mq in zip(quadratures, metrics)])
    return scalar_form(rows, np.concatenate([q.weights for q in quadratures]), metric)


def load_vector(values: SparseRows, weights: np.ndarray, f: np.ndarray) -> np.ndarray:
    """``sum_q w_q N_I(x_q) f(x_q)`` for point data ``f`` of shape ``(m,)`` or ``(m, k)``; interleaved."""
    f = np.asarray(f, float)
    out = values.matrix().T @ (weights[:, None] * f.reshape(len(weights), -1))
    return out.ravel()
