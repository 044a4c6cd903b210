"""RK shape functions reproduce polynomials of their basis degree (eqs. 3.22, 3.25)."""
import numpy as np
import pytest

from conftest import l_shape, random_points, unit_square
from rkfx.approximation.kernel import cubic_spline_values
from rkfx.approximation.shape_functions import evaluate, rk_approximation
from rkfx.errors import InputError


def test_cubic_spline_kernel_values():
    s = np.array([0.0, 0.25, 0.5, 0.75, 1.0, 1.2])
    expected = [2 / 3, 2 / 3 - 4 / 16 + 4 / 64, 1 / 6, 4 / 3 * 0.25**3, 0.0, 0.0]
    assert np.allclose(cubic_spline_values(s), expected, atol=1e-15)


@pytest.mark.parametrize("geometry", [unit_square, l_shape])
@pytest.mark.parametrize("order, factor", [(1, 1.5), (2, 2.5)])
def test_reproducing_conditions_on_unstructured_nodes(geometry, order, factor):
    p = geometry(0.1)
    rk = rk_approximation(p.x, p.spacing, factor, order)
    pts = random_points(p, 3000)
    rows = evaluate(rk, pts, gradients=True)
    n, nx, ny = rows.matrix(0), rows.matrix(1), rows.matrix(2)
    x, y = p.x[:, 0], p.x[:, 1]
    px, py = pts[:, 0], pts[:, 1]
    monomials = [(np.ones_like(x), np.ones_like(px), 0 * px, 0 * px), (x, px, 1 + 0 * px, 0 * px),
                 (y, py, 0 * px, 1 + 0 * px)]
    if order == 2:
        monomials += [(x * x, px * px, 2 * px, 0 * px), (x * y, px * py, py, px), (y * y, py * py, 0 * px, 2 * py)]
    for nodal, value, dx, dy in monomials:
        assert np.abs(n @ nodal - value).max() <= 1e-12
        # Gradients reproduce the monomials' gradients (identity for the linear ones).
        assert np.abs(nx @ nodal - dx).max() <= 1e-10
        assert np.abs(ny @ nodal - dy).max() <= 1e-10


def test_linear_basis_does_not_reproduce_quadratics():
    p = unit_square(0.1)
    rk = rk_approximation(p.x, p.spacing)
    pts = random_points(p, 500)
    n = evaluate(rk, pts).matrix(0)
    assert np.abs(n @ p.x[:, 0] ** 2 - pts[:, 0] ** 2).max() > 1e-4


def test_neighbour_count_is_bounded_under_refinement():
    """Supports scale with the local spacing: rows stay short as nodes are added (O(N) cost)."""
    counts = []
    for h in (0.1, 0.05, 0.025):
        p = unit_square(h)
        rows = evaluate(rk_approximation(p.x, p.spacing), p.x)
        counts.append(np.diff(rows.indptr).mean())
    assert max(counts) < 12 and max(counts) / min(counts) < 1.3


def test_component_matrices_do_not_share_index_arrays():
    """Sorting one component's matrix in place must leave the rows of the others intact."""
    p = unit_square(0.2)
    rows = evaluate(rk_approximation(p.x, p.spacing), random_points(p, 50), gradients=True)
    before = rows.matrix(1).toarray()
    m0 = rows.matrix(0)
    m0.sort_indices()
    m0.max()
    assert np.array_equal(rows.matrix(1).toarray(), before)


@pytest.mark.parametrize("order, factor", [(1, 2.0), (2, 3.0)])
def test_implicit_gradients_reproduce_the_gradients_of_the_basis(order, factor):
    """Eq. (6.28): the implicit gradient rows (6.29) give the exact gradient of every field the
    basis holds; with the linear basis a quadratic's gradient is only approximate."""
    p = unit_square(0.1)
    rk = rk_approximation(p.x, p.spacing, factor, order)
    pts = random_points(p, 300)
    rows = evaluate(rk, pts, implicit=True)
    x, y = rk.x[:, 0], rk.x[:, 1]
    fields = [(1 + 0 * x, 0 * pts[:, 0], 0 * pts[:, 0]), (2 * x - 3 * y, 2 + 0 * pts[:, 0], -3 + 0 * pts[:, 0]),
              (x * y, pts[:, 1], pts[:, 0])]
    errors = [max(abs((rows @ f)[:, 1] - gx).max(), abs((rows @ f)[:, 2] - gy).max()) for f, gx, gy in fields]
    assert max(errors[:2]) < 1e-11
    assert (errors[2] < 1e-11) == (order == 2)
    with pytest.raises(InputError, match="not both"):
        evaluate(rk, pts, gradients=True, implicit=True)
