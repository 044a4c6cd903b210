"""The compiled stiffness is the product B^T diag(w D) B, entry for entry to round-off, for
constant and per-point D, over one or several quadratures, the same on any number of threads."""
import numba
import pytest
import numpy as np
import scipy.sparse as sp

from conftest import unit_square
from rkfx.approximation.shape_functions import rk_approximation
from rkfx.assembly.galerkin import elastic_stiffness
from rkfx.assembly.operators import block_diagonal, stiffness, strain_matrix
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.integration.quadrature import integration_rules
from rkfx.materials.elasticity import ElasticMaterial


def product(q, d):
    d = np.broadcast_to(d, (len(q.weights), 3, 3))
    b = strain_matrix(q.gradients)
    return b.T @ block_diagonal(q.weights[:, None, None] * d) @ b


def test_compiled_stiffness_is_the_matrix_product():
    p = unit_square(0.08)
    rk, dom = rk_approximation(p.x, p.spacing), nodal_domains(p)
    quads = integration_rules("mscni", p, rk, dom)
    d = ElasticMaterial(2.0, 0.3).D()
    rng = np.random.default_rng(3)
    per_point = [d * rng.uniform(0.1, 1.0, (len(q.weights), 1, 1)) for q in quads]
    for coefficient in (d, per_point):
        ds = coefficient if isinstance(coefficient, list) else [d] * len(quads)
        expected = sum(product(q, dq) for q, dq in zip(quads, ds))
        got = stiffness(quads, coefficient)
        assert got.has_sorted_indices and got.shape == expected.shape
        assert abs(got - expected).max() <= 1e-13 * abs(expected).max()
        # Every pair of nodes sharing a point keeps its whole 2 x 2 block (a fixed pattern).
        assert got.nnz >= sp.csr_matrix(expected).nnz and got.nnz % 4 == 0
    k = elastic_stiffness(quads[1].gradients, quads[1].weights, d)
    assert abs(k - product(quads[1], d)).max() <= 1e-13 * abs(k).max()
    assert abs(k - k.T).max() <= 1e-13 * abs(k).max()


def test_compiled_stiffness_does_not_depend_on_the_thread_count():
    p = unit_square(0.08)
    rk, dom = rk_approximation(p.x, p.spacing), nodal_domains(p)
    quads = integration_rules("mscni", p, rk, dom)
    d = ElasticMaterial(2.0, 0.3).D()
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = stiffness(quads, d)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = stiffness(quads, d)
    finally:
        numba.set_num_threads(threads)
    assert np.array_equal(one.indptr, many.indptr) and np.array_equal(one.indices, many.indices)
    assert np.array_equal(one.data, many.data)


def test_rows_read_in_their_sets_give_the_stiffness_of_one_joined_set():
    """The SCNI and MSCNI rows are read where they are, in two sets (and a third is joined to
    the second): K is the one of all the rows copied into one list, bit for bit."""
    from rkfx.assembly.galerkin import _joined  # noqa: PLC0415

    p = unit_square(0.08)
    rk, dom = rk_approximation(p.x, p.spacing), nodal_domains(p)
    cell, sub = integration_rules("mscni", p, rk, dom)
    gauss = integration_rules("gauss2", p, rk, dom)[0]
    d = ElasticMaterial(2.0, 0.3).D()
    for quads in ([cell, sub], [cell, sub, gauss]):
        w = np.concatenate([q.weights for q in quads])
        parts = elastic_stiffness([q.gradients for q in quads], w, d)
        joined = elastic_stiffness(_joined([q.gradients for q in quads]), w, d)
        for name in ("indptr", "indices", "data"):
            assert np.array_equal(getattr(parts, name), getattr(joined, name)), name


def test_boundary_terms_added_into_the_stiffness_pattern_equal_the_sum():
    """``add_into`` adds a matrix whose entries lie in K's pattern in K's own arrays (equal to
    K + B entry for entry) and falls back to K + B when one does not."""
    from rkfx.assembly.operators import add_into  # noqa: PLC0415

    p = unit_square(0.1)
    rk, dom = rk_approximation(p.x, p.spacing), nodal_domains(p)
    k = stiffness(integration_rules("mscni", p, rk, dom), ElasticMaterial(2.0, 0.3).D())
    rows = np.repeat(np.arange(k.shape[0]), np.diff(k.indptr))
    pick = np.random.default_rng(1).choice(k.nnz, 50, replace=False)
    inside = sp.coo_matrix((np.arange(1.0, 51.0), (rows[pick], k.indices[pick])), shape=k.shape)
    expected = (k + inside).toarray()
    got = add_into(k.copy(), inside)
    assert np.array_equal(got.toarray(), expected)
    summed = (k + inside).tocsr()  # the pattern of scipy's sum: exact zeros dropped
    assert np.array_equal(got.indptr, summed.indptr) and np.array_equal(got.indices, summed.indices)
    outside = sp.coo_matrix(([1.0], ([0], [k.shape[1] - 1])), shape=k.shape)
    assert k[0, k.shape[1] - 1] == 0
    assert np.array_equal(add_into(k.copy(), outside).toarray(), (k + outside).toarray())


def test_compiled_darcy_matrix_is_the_matrix_product():
    """``laplacian`` (compiled ``scalar_form``) equals sum_q w_q G^T k G from scipy products to
    round-off, for a scalar, a tensor, and per-point scalars and tensors, over the MSCNI rules."""
    from rkfx.assembly.operators import laplacian  # noqa: PLC0415

    p = unit_square(0.08)
    rk, dom = rk_approximation(p.x, p.spacing), nodal_domains(p)
    quads = integration_rules("mscni", p, rk, dom)
    rng = np.random.default_rng(5)
    tensor = np.array([[2.0, 0.3], [0.3, 1.0]])
    for k in (2.5, tensor, [rng.uniform(1, 2, len(q.weights)) for q in quads],
              [rng.uniform(1, 2, (len(q.weights), 1, 1)) * tensor for q in quads]):
        ks = k if isinstance(k, list) else [k] * len(quads)
        expected = 0
        for q, kq in zip(quads, ks):
            kq = np.asarray(kq, float)
            kk = np.broadcast_to(kq.reshape(-1, 1, 1) * np.eye(2) if kq.ndim < 2 else kq, (len(q.weights), 2, 2))
            g = (q.gradients.matrix(0), q.gradients.matrix(1))
            expected = expected + sum(g[a].T @ sp.diags(q.weights * kk[:, a, b]) @ g[b]
                                      for a in range(2) for b in range(2))
        got = laplacian(quads, k)
        assert got.has_sorted_indices
        assert abs(got - expected).max() <= 1e-13 * abs(expected).max()


def test_mscni_stiffness_is_the_subcell_rule_stiffness():
    """At eps_p = 1 the MSCNI stiffness A_L B_L^T D B_L + sum_C A_C (B_L - B_C)^T D (B_L - B_C)
    is sum_C A_C B_C^T D B_C (the subcells partition each cell), on median-dual and grid cells;
    the elastic model assembles it so."""
    from rkfx.geometry.grid_cells import grid_domains  # noqa: PLC0415
    from rkfx.geometry.particles import graded  # noqa: PLC0415
    from rkfx.integration.quadrature import subcell_rule  # noqa: PLC0415

    d = ElasticMaterial(2.0, 0.3).D()
    p = unit_square(0.08)
    xs, ys = np.linspace(0.0, 1.0, 13), np.linspace(0.0, 0.5, 7) ** 1.2
    g = graded(xs, ys)
    for pts, dom in ((p, nodal_domains(p)), (g, grid_domains(xs, ys))):
        rk = rk_approximation(pts.x, pts.spacing)
        mscni = stiffness(integration_rules("mscni", pts, rk, dom), d)
        sub = stiffness([subcell_rule(rk, dom)], d)
        assert abs(mscni - sub).max() <= 1e-13 * abs(mscni).max()


@pytest.mark.parametrize("eps_p", [1.0, 0.5])
def test_mscni_rules_give_the_mscni_forms(eps_p):
    """``mscni_rules`` (SCNI weighted 1 - eps_p and the subcell gradients weighted eps_p A_C)
    give eq. (3.56)'s stiffness and eq. (3.59)'s Darcy matrix with a per-particle field, and
    eq. (3.58)'s value rows, as the difference rows of ``mscni_stabilization`` give them."""
    from rkfx.assembly.operators import laplacian, mass  # noqa: PLC0415
    from rkfx.integration.quadrature import mscni_rules, mscni_stabilization, scni, smoothed_gradients  # noqa: PLC0415

    p = unit_square(0.08)
    rk = rk_approximation(p.x, p.spacing)
    dom = nodal_domains(p)
    s = smoothed_gradients(p, rk, dom)
    old = [scni(p, rk, dom, s), mscni_stabilization(p, rk, dom, s, eps_p, with_values=True)]
    nodal, rules, values = mscni_rules(p, rk, dom, eps_p)
    k_node = 1.0 + np.random.default_rng(0).uniform(size=p.num_nodes)  # a permeability per particle
    owners = {"scni": np.arange(p.num_nodes), "mscni-stabilization": dom.subcell_node,
              "mscni-subcells": dom.subcell_node}
    d = ElasticMaterial(2.0, 0.3).D()
    for a, b in ((stiffness(old, d), stiffness(rules, d)),
                 (laplacian(old, [k_node[owners[q.name]] for q in old]),
                  laplacian(rules, [k_node[owners[q.name]] for q in rules])),
                 (mass(old), mass([nodal, values]))):
        assert abs(a - b).max() <= 1e-12 * abs(a).max()
    assert len(rules) == (1 if eps_p == 1.0 else 2)


@pytest.mark.parametrize("dim", [2, 3])
def test_mixed_form_is_the_coupling_product(dim):
    """``mixed_form``: gradient rows against value rows of the same points equal the product
    div^T diag(w) N (the u-p coupling of eq. 3.57), in 2-D and 3-D."""
    from rkfx.assembly.galerkin import mixed_form
    from rkfx.approximation.shape_functions import evaluate
    from rkfx.approximation.sparse_rows import SparseRows

    rng = np.random.default_rng(5)
    x = rng.uniform(0.0, 1.0, (300, dim))
    rk = rk_approximation(x, np.full(len(x), 0.15 if dim == 2 else 0.3), 1.5)
    pts = rng.uniform(0.2, 0.8, (200, dim))
    grads = evaluate(rk, pts, gradients=True)
    values = evaluate(rk, pts)
    test = SparseRows(grads.indptr, grads.indices, grads.data[:, 1:], grads.num_cols)
    w = rng.uniform(0.5, 2.0, len(pts))
    got = mixed_form(test, values, w)
    div = sp.hstack([test.matrix(c) for c in range(dim)]).tocsr()  # (m, g n) in component blocks
    order = np.arange(dim * len(x)).reshape(dim, -1).T.ravel()  # to interleaved unknowns
    expected = (div[:, order].T @ sp.diags(w) @ values.matrix()).tocsr()
    assert got.shape == (dim * len(x), len(x)) and got.has_sorted_indices
    assert abs(got - expected).max() <= 1e-14 * abs(expected).max()
