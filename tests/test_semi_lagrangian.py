"""Semi-Lagrangian RK (eqs. 6.22-6.29): after large prescribed motions the shape functions rebuilt
in the current configuration reproduce linear fields and their gradients, and the incremental
neighbour lists give the same rows as a search from scratch."""
import numpy as np
import pytest

from rkfx.approximation.semi_lagrangian import evaluate_moving, moved, moving_rk
from rkfx.approximation.shape_functions import RKApproximation, evaluate
from rkfx.errors import InputError, SingularMomentMatrix
from rkfx.geometry.particles import jittered, structured


def _rotation(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, s], [-s, c]])  # row vectors: x @ R


MOTIONS = {
    "shear": lambda X, t: X + np.c_[1.0 * t * X[:, 1], np.zeros(len(X))],  # engineering shear 1
    "rotation": lambda X, t: (X - 0.5) @ _rotation(t * np.pi / 2) + 0.5,  # a quarter turn
}


def _linear_errors(rows, x, points=None):
    """Largest error of the rows (nodes ``x``, at ``points``, the nodes by default) on 1, x, y and
    a general linear field, values and gradients."""
    points = x if points is None else points
    worst = 0.0
    for c, g in (((1.0, 0.0, 0.0), (0.0, 0.0)), ((0.0, 1.0, 0.0), (1.0, 0.0)), ((0.0, 0.0, 1.0), (0.0, 1.0)),
                 ((0.7, -2.0, 3.0), (-2.0, 3.0))):
        v = rows @ (c[0] + c[1] * x[:, 0] + c[2] * x[:, 1])
        exact = c[0] + c[1] * points[:, 0] + c[2] * points[:, 1]
        worst = max(worst, np.abs(v[:, 0] - exact).max(), np.abs(v[:, 1] - g[0]).max(), np.abs(v[:, 2] - g[1]).max())
    return worst


@pytest.mark.parametrize("motion", sorted(MOTIONS))
def test_rebuilt_shape_functions_reproduce_linear_fields_after_large_motion(motion):
    p = jittered(21, 0.25, seed=4)
    X, h = p.x, float(p.spacing.mean())
    a = 2.0 * p.spacing
    rk = moving_rk(X, a, skin=0.4 * h)
    searched, worst_rows = 0, 0.0
    for t in np.linspace(0.0, 1.0, 81)[1:]:
        rk = moved(rk, MOTIONS[motion](X, t))
        searched += rk.searched
        rows = evaluate_moving(rk, implicit=True)
        assert _linear_errors(rows, rk.x) < 1e-10
        fresh = evaluate(RKApproximation(rk.x, a), rk.x, implicit=True)
        worst_rows = max(worst_rows, max(abs(rows.matrix(k) - fresh.matrix(k)).max() for k in range(3)))
    assert worst_rows < 1e-12, "the Verlet rows missed or misplaced a neighbour"
    # A support radius stays a_I: the motion changed who covers whom (so the lists had to move).
    assert searched > len(X)
    # The direct gradients of the current configuration reproduce linear fields too.
    assert _linear_errors(evaluate_moving(rk, gradients=True), rk.x) < 1e-10


def test_small_steps_search_nothing_and_large_ones_only_near_what_moved():
    p = structured(1.0, 1.0, 41, 41)
    h = 1.0 / 40
    rk = moving_rk(p.x, 2.0 * h, skin=0.5 * h)
    rk = moved(rk, p.x + 0.15 * h)  # a rigid shift inside skin / 2
    assert rk.searched == 0
    x = rk.x.copy()
    corner = np.flatnonzero((p.x[:, 0] < 0.1) & (p.x[:, 1] < 0.1))
    x[corner] += 0.3 * h  # 0.5 h from the reference: beyond skin / 2
    rk = moved(rk, x)
    assert len(corner) <= rk.searched < 0.1 * len(x)
    fresh = evaluate(RKApproximation(x, np.full(len(x), 2.0 * h)), x)
    assert abs(evaluate_moving(rk).matrix() - fresh.matrix()).max() < 1e-14


def test_points_off_the_nodes_need_reach_and_an_owner():
    p = structured(1.0, 1.0, 11, 11)
    h = 0.1
    rk = moving_rk(p.x, 2.0 * h, skin=0.5 * h, reach=0.5 * h)
    pts = p.x + 0.3 * h * np.array([0.6, -0.8])
    rows = evaluate_moving(rk, pts, np.arange(len(pts)), implicit=True)
    assert _linear_errors(rows, p.x, pts) < 1e-12
    with pytest.raises(InputError, match="reach"):
        evaluate_moving(rk, p.x + 0.6 * h, np.arange(len(pts)))
    with pytest.raises(InputError, match="owner"):
        evaluate_moving(rk, pts)


def test_torn_apart_nodes_give_a_one_line_singular_moment_error():
    p = structured(1.0, 1.0, 11, 11)
    rk = moving_rk(p.x, 1.5 * 0.1, skin=0.05)
    x = p.x.copy()
    x[60] += 5.0  # one node flung far from all others
    with pytest.raises(SingularMomentMatrix, match="current configuration"):
        evaluate_moving(moved(rk, x))
    x[60] = np.nan
    with pytest.raises(InputError, match="node 60"):
        moved(rk, x)


@pytest.mark.parametrize("kw, word", [(dict(skin=0.0), "skin"), (dict(skin=0.1, reach=-1.0), "reach"),
                                      (dict(skin=0.1, support=0.0), "support")])
def test_bad_parameters_are_named(kw, word):
    p = structured(1.0, 1.0, 5, 5)
    args = dict(support=0.4) | kw
    with pytest.raises(InputError, match=word):
        moving_rk(p.x, **args)


def test_torn_points_get_sheet_or_shepard_rows_when_counted():
    """Collinear neighbours: a singular moment matrix raises, or, with a counter, gives the row
    along the line; a lone point gets the constant-basis (Shepard) row."""
    x = np.array([[0.0, 0.0], [0.1, 0.0], [0.2, 0.0], [0.3, 0.0], [2.0, 0.0]])
    with pytest.raises(SingularMomentMatrix):
        evaluate_moving(moving_rk(x, 0.25, 0.02), gradients=True)
    counter = np.zeros(2, np.int64)
    rows = evaluate_moving(moving_rk(x, 0.25, 0.02, torn=counter), gradients=True)
    assert counter.tolist() == [1, 4]
    assert np.allclose(rows.matrix(0).sum(axis=1).A.ravel(), 1.0)
    v = rows @ x
    assert np.allclose(v[:4, 0, 0], x[:4, 0], atol=1e-14) and np.allclose(v[:4, 1, 0], 1.0, atol=1e-12)
    assert np.allclose(v[:, 2], 0.0, atol=1e-14) and v[4, 1, 0] == 0.0  # nothing across the line; the lone point
    with pytest.raises(InputError, match="counter"):
        moving_rk(x, 0.25, 0.02, torn=np.zeros(1, np.int64))


@pytest.mark.parametrize("angle", [0.0, 0.5, np.pi / 2])
def test_a_sheet_along_any_direction_gets_rows_along_it(angle):
    """Grains in a line with offsets of 1e-4 h across it (a toe sliding on a floor): the moment
    matrix scaled by its diagonal is far from singular along an axis, yet its gradients across
    the line would be ~1e4 / h; the sheet rows reproduce linear fields along the line (to the
    offsets) with gradients along it only, in any orientation. A grid is left as it was."""
    rng = np.random.default_rng(3)
    t, n = np.array([np.cos(angle), np.sin(angle)]), np.array([-np.sin(angle), np.cos(angle)])
    s, e = np.linspace(0.0, 1.0, 11), 1e-5 * rng.standard_normal(11)
    x = s[:, None] * t + e[:, None] * n
    counter = np.zeros(2, np.int64)
    for kw in ({}, {"gradients": True}, {"implicit": True}, {"second": True}):
        rows = evaluate_moving(moving_rk(x, 0.25, 0.02, torn=counter), **kw)
        v = rows @ (x @ t)  # the coordinate along the line
        assert np.allclose(v[:, 0], s, atol=1e-4)
        if kw:
            assert np.allclose(v[:, 1:3], t, atol=1e-3)  # along the offsets' principal direction
            assert np.abs(rows @ (x @ n)[:, None])[:, 1:3].max() < 1e-3  # not 1e4 / h
        if "second" in kw:
            assert np.array_equal(rows.data[:, 3:], np.zeros_like(rows.data[:, 3:]))
        if "implicit" in kw:  # entries of order 1 / h, where the full rows carry 8e4 (h = 0.1)
            full = evaluate_moving(moving_rk(x, 0.25, 0.02), **kw)
            assert np.abs(rows.data[:, 1:]).max() < 20.0 < 1e4 < np.abs(full.data[:, 1:]).max()
    assert counter.tolist() == [0, 44]
    p = structured(1.0, 1.0, 11, 11)
    counted = evaluate_moving(moving_rk(p.x, 0.2, 0.02, torn=counter), second=True)
    assert counter.tolist() == [0, 44]
    assert np.array_equal(counted.data, evaluate_moving(moving_rk(p.x, 0.2, 0.02), second=True).data)
