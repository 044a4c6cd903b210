"""Matrices of a nodal integration (``rkfx.integration.nodal_stabilized``), with test and trial
gradients apart (the VC correction changes only the test side, eqs. 6.78-6.79).

    K = sum_L V_L B^c_L^T D B_L + sum_L (m_Lx B_L,x^T D B_L,x + m_Ly B_L,y^T D B_L,y)
    A = sum_L V_L (grad^c N)_L^T k (grad N)_L + the same expansion terms with k

Degrees of freedom of vector fields are interleaved per node, strains in Voigt order, as in
``rkfx.assembly.operators``.
"""
import numpy as np
import scipy.sparse as sp

from rkfx.approximation.sparse_rows import SparseRows
from rkfx.assembly.operators import block_diagonal, strain_matrix
from rkfx.integration.nodal_stabilized import NodalIntegration


def _gradient_matrix(rows: SparseRows) -> sp.csr_matrix:
    """(grad N) with rows (d/dx, d/dy) per point, shape ``(2 m, n)``."""
    return sp.vstack([rows.matrix(0), rows.matrix(1)]).tocsr()[
        np.ravel(np.stack([np.arange(rows.num_rows), rows.num_rows + np.arange(rows.num_rows)], axis=1))]


def _weighted(blocks: np.ndarray, w: np.ndarray) -> sp.csr_matrix:
    return block_diagonal(w[:, None, None] * np.broadcast_to(blocks, (len(w), *blocks.shape[-2:])))


def _form(rule: NodalIntegration, matrix_of, metric: np.ndarray, smoothed: bool = True) -> sp.csr_matrix:
    """``T^T W T'`` of the test and trial rows plus the expansion terms, with ``matrix_of`` the
    point operator of a row set (strains or gradients) and ``metric`` its coefficient
    (``smoothed=False``: the expansion terms alone)."""
    test = matrix_of(rule.test)
    form = (test.T @ _weighted(metric, rule.weights) @ matrix_of(rule.trial) if smoothed
            else sp.csr_matrix((test.shape[1],) * 2))
    if rule.moments is not None:
        for j, rows in enumerate((rule.trial_x, rule.trial_y)):
            b = matrix_of(rows)
            form = form + b.T @ _weighted(metric, rule.moments[:, j]) @ b
    return form.tocsr()


def stiffness(rule: NodalIntegration, d: np.ndarray) -> sp.csr_matrix:
    """Elastic stiffness of the rule, shape ``(2 n, 2 n)``; ``d``: ``(3, 3)`` or ``(n, 3, 3)`` [Pa]."""
    return _form(rule, strain_matrix, np.asarray(d, dtype=float))


def stabilization_stiffness(rule: NodalIntegration, d: np.ndarray) -> sp.csr_matrix:
    """The expansion terms of ``stiffness`` alone (NSNI's sum_L m_Lj B_j^T D B_j; zero without
    moments), shape ``(2 n, 2 n)``: the elastic stabilization of a skeleton whose smoothed part
    is nonlinear."""
    return _form(rule, strain_matrix, np.asarray(d, dtype=float), smoothed=False)


def laplacian(rule: NodalIntegration, k=1.0) -> sp.csr_matrix:
    """Diffusion matrix of the rule, shape ``(n, n)``; ``k``: a scalar or ``(2, 2)`` tensor [m^2/(Pa s)]."""
    kt = np.asarray(k, dtype=float) * np.eye(2) if np.ndim(k) == 0 else np.asarray(k, dtype=float)
    return _form(rule, _gradient_matrix, kt)


def _divergence_matrix(rows: SparseRows) -> sp.csr_matrix:
    """div u at each point, shape ``(m, 2 n)``: m^T B with m = (1, 1, 0)."""
    b = strain_matrix(rows)
    return (b[0::3] + b[1::3]).tocsr()


def coupling(rule: NodalIntegration, alpha: float) -> sp.csr_matrix:
    """``sum_L V_L alpha (B^c_L)^T m N_L``: the pressure's force on u, shape ``(2 n, n)`` [m^2]
    (the internal force is K u - coupling p, eq. 6.78)."""
    return (alpha * _divergence_matrix(rule.test).T @ sp.diags(rule.weights) @ rule.values.matrix()).tocsr()


def divergence(rule: NodalIntegration, alpha: float) -> sp.csr_matrix:
    """``sum_L V_L alpha N_L^T m^T B_L``: the storage rows' alpha div u' term, shape ``(n, 2 n)`` [m^2]
    (eq. 6.79; the test functions are values, so no correction enters)."""
    return (alpha * rule.values.matrix().T @ sp.diags(rule.weights) @ _divergence_matrix(rule.trial)).tocsr()


def lumped(rule: NodalIntegration, c: float = 1.0) -> np.ndarray:
    """Row-sum lumped mass ``sum_L V_L c N_I(x_L)`` per node, shape ``(n,)``."""
    return c * (rule.values.matrix().T @ rule.weights)


def pressure_projection(rule: NodalIntegration, eps_f) -> sp.csr_matrix:
    """The fluid pressure projection ``int eps_f (N_I - Pi N_I)(N_J - Pi N_J)`` of (6.49) on the
    rule's cells, shape ``(n, n)`` [m^3/Pa]; ``eps_f``: a scalar or one value per point [1/Pa].

    Pi is the mean over a node's cell. With N expanded about x_L as in (6.52), N - Pi N =
    (x - x_L) . grad N (the cell's first moments vanish, 6.58), so the cell's term is
    ``m_Lx N_I,x N_J,x + m_Ly N_I,y N_J,y`` with the trial gradients at x_L: symmetric, positive
    semi-definite, zero on constants. The moments are the rule's; a rule without them (DNI,
    SNNI) takes those of a square cell of its weight, m = V_L^2 / 12.
    """
    w = rule.weights
    m = np.column_stack([w * w / 12.0] * 2) if rule.moments is None else rule.moments
    eps = np.broadcast_to(np.asarray(eps_f, dtype=float), w.shape)
    form = sp.csr_matrix((rule.values.num_cols,) * 2)
    for j in range(2):
        b = rule.trial.matrix(j)
        form = form + b.T @ sp.diags(eps * m[:, j]) @ b
    return form.tocsr()
