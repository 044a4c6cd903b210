"""Pre-existing cracks by the diffraction method (Organ et al. 1996) in the RK kernels."""
from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from rkfx.assembly.boundary import boundary_quadrature, nitsche_terms, traction_load
from rkfx.conditions import Displacement, Traction
from rkfx.approximation.diffraction import cracks
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.assembly.operators import stiffness
from rkfx.geometry.particles import cut_triangulation, structured
from rkfx.integration.quadrature import scni, smoothed_gradients
from rkfx.approximation.shape_functions import evaluate, rk_approximation

CENTRAL = [[0.25, 0.5], [0.75, 0.5]]  # interior crack with two tips
EDGE = [[0.0, 0.5], [0.5, 0.5]]  # edge crack: mouth on the left side, tip at (0.5, 0.5)
KINKED = [[0.0, 0.5], [0.4, 0.5], [0.6, 0.7]]  # along grid lines and triangle diagonals


def cracked_square(crack, n=21, exponent=2.0):
    p, c = cut_triangulation(structured(1.0, 1.0, n, n), [crack], exponent=exponent)
    return p, rk_approximation(p.x, p.spacing, cracks=c), c


def near_crack_points(m=3000, seed=0):
    rng = np.random.default_rng(seed)
    pts = np.column_stack([rng.uniform(0.05, 0.95, m), 0.5 + rng.uniform(-0.2, 0.2, m)])
    return pts[np.abs(pts[:, 1] - 0.5) > 1e-4]


def test_cut_triangulation_splits_the_nodes_on_the_crack():
    p0 = structured(1.0, 1.0, 21, 21)
    p, c = cut_triangulation(p0, [CENTRAL])
    assert p.num_nodes == p0.num_nodes + 9  # interior crack nodes duplicated, the two tips not
    assert c.tips.tolist() == [[True, True]]
    q, c_edge = cut_triangulation(p0, [EDGE])
    assert q.num_nodes == p0.num_nodes + 10 and c_edge.tips.tolist() == [[False, True]]  # mouth is no tip
    for part in (p, q):
        # No triangle edge crosses the crack line strictly inside the crack.
        e = part.x[part.edges]
        ys = e[:, :, 1] - 0.5
        cross = ys[:, 0] * ys[:, 1] < 0
        xc = e[cross, 0, 0] + (e[cross, 1, 0] - e[cross, 0, 0]) * (-ys[cross, 0]) / (ys[cross, 1] - ys[cross, 0])
        lo, hi = (0.25, 0.75) if part is p else (0.0, 0.5)
        assert not np.any((xc > lo + 1e-9) & (xc < hi - 1e-9))
        # The faces are boundary edges named "crack", one per side of every crack edge.
        faces = part.boundary_tags == part.tag("crack")
        assert faces.sum() == 20
        assert part.area() == pytest.approx(1.0, abs=1e-4)
    # The edge crack's mouth splits the left side into two tagged parts.
    assert len(q.boundary_nodes("left")) == 22
    with pytest.raises(InputError, match="along"):
        cut_triangulation(p0, [[[0.25, 0.52], [0.75, 0.52]]])  # not on a grid line


@pytest.mark.parametrize("exponent", [1.0, 2.0])
@pytest.mark.parametrize("crack", [CENTRAL, EDGE, KINKED])
def test_reproducing_conditions_hold_near_a_crack(crack, exponent):
    p, rk, _ = cracked_square(crack, exponent=exponent)
    pts = near_crack_points()
    rows = evaluate(rk, pts, gradients=True)
    n, nx, ny = rows.matrix(0), rows.matrix(1), rows.matrix(2)
    one = np.ones(p.num_nodes)
    for nodal, value, dx, dy in ((one, 1.0, 0.0, 0.0), (p.x[:, 0], pts[:, 0], 1.0, 0.0),
                                 (p.x[:, 1], pts[:, 1], 0.0, 1.0)):
        assert np.abs(n @ nodal - value).max() <= 1e-12
        assert np.abs(nx @ nodal - dx).max() <= 1e-10
        assert np.abs(ny @ nodal - dy).max() <= 1e-10


def test_quadratic_basis_reproduces_quadratics_near_a_crack():
    p, c = cut_triangulation(structured(1.0, 1.0, 21, 21), [EDGE])
    rk = rk_approximation(p.x, p.spacing, 2.5, 2, cracks=c)
    pts = near_crack_points(1000)
    rows = evaluate(rk, pts, gradients=True)
    x, y = p.x[:, 0], p.x[:, 1]
    assert np.abs(rows.matrix(0) @ (x * y) - pts[:, 0] * pts[:, 1]).max() <= 1e-12
    assert np.abs(rows.matrix(1) @ (x * x) - 2 * pts[:, 0]).max() <= 1e-10


@pytest.mark.parametrize("exponent", [1.0, 2.0])
def test_direct_gradients_match_finite_differences_around_the_tip(exponent):
    p, rk, _ = cracked_square(CENTRAL, exponent=exponent)
    rng = np.random.default_rng(1)
    r, th = rng.uniform(0.01, 0.12, 400), rng.uniform(-np.pi, np.pi, 400)
    pts = np.array([0.75, 0.5]) + np.column_stack([r * np.cos(th), r * np.sin(th)])
    g = evaluate(rk, pts, gradients=True)
    eps = 1e-6
    # Dense copies: in-place canonicalisation (e.g. by .max()) of a matrix(k) would reorder the
    # index array it shares with the other components.
    values = lambda q: evaluate(rk, q).matrix(0).toarray()  # noqa: E731
    for k, shift in ((1, [eps, 0.0]), (2, [0.0, eps])):
        fd = (values(pts + shift) - values(pts - shift)) / (2 * eps)
        exact = g.matrix(k).toarray()
        # The diffracted distance has kinks on the shadow lines through the tip; random
        # points fall there with probability zero.
        assert np.abs(fd - exact).max() <= 1e-5 * np.abs(exact).max()


def test_nodes_are_invisible_across_the_crack_far_from_the_tips():
    p, rk, _ = cracked_square(CENTRAL)
    x = np.linspace(0.4, 0.6, 9)
    above = np.column_stack([x, np.full_like(x, 0.52)])
    below = np.column_stack([x, np.full_like(x, 0.48)])
    n_above, n_below = evaluate(rk, above).matrix(0), evaluate(rk, below).matrix(0)
    lower, upper = np.flatnonzero(p.x[:, 1] < 0.5), np.flatnonzero(p.x[:, 1] > 0.5)
    assert abs(n_above[:, lower]).max() == 0.0 and abs(n_below[:, upper]).max() == 0.0
    # Without the crack the same nodes reach across.
    plain = rk_approximation(p.x, p.spacing)
    assert abs(evaluate(plain, above).matrix(0)[:, lower]).max() > 0.05


def test_shape_functions_wrap_continuously_around_the_tip():
    p, rk, _ = cracked_square(CENTRAL, n=21)
    tip = np.array([0.75, 0.5])

    def around(m):  # a circle round the tip from just above the crack to just below it
        theta = np.linspace(np.pi - 0.02, -np.pi + 0.02, m)
        pts = tip + 0.02 * np.column_stack([np.cos(theta), np.sin(theta)])
        return theta, evaluate(rk, pts).matrix(0).toarray()

    theta, n = around(2001)
    _, fine = around(4001)
    # Continuous: halving the spacing of the points halves the largest change between
    # neighbours (a jump would stay).
    coarse_step, fine_step = np.abs(np.diff(n, axis=0)).max(), np.abs(np.diff(fine, axis=0)).max()
    assert coarse_step < 5e-3 and fine_step < 0.6 * coarse_step
    # The node on the lower face next to the tip reaches points above the crack line ahead of
    # the tip, whose straight path to it crosses the crack: its support wraps round the tip.
    lower = np.flatnonzero(np.all(np.isclose(p.x, [0.7, 0.5], atol=1e-6), axis=1) & (p.x[:, 1] < 0.5))
    above_ahead = (theta > 0.05) & (theta < 0.3)
    assert lower.size == 1 and n[above_ahead, lower[0]].min() > 0.0
    # Behind the tip the two faces see different nodes: the values jump across the crack.
    assert np.abs(n[0] - n[-1]).max() > 0.05


def test_no_crack_or_a_far_crack_leaves_the_shape_functions_unchanged():
    p = structured(1.0, 1.0, 15, 15)
    pts = near_crack_points(500)
    plain = evaluate(rk_approximation(p.x, p.spacing), pts, gradients=True)
    far = rk_approximation(p.x, p.spacing, cracks=cracks([[[3.0, 3.0], [4.0, 3.0]]]))
    empty = rk_approximation(p.x, p.spacing, cracks=cracks([]))
    assert empty.cracks is None
    got = evaluate(far, pts, gradients=True)
    assert np.array_equal(plain.indptr, got.indptr) and np.array_equal(plain.indices, got.indices)
    assert np.array_equal(plain.data, got.data)


def test_rows_hold_exactly_the_nodes_within_the_diffracted_distance():
    """Against a direct evaluation of Organ's distance for a straight crack with two tips."""
    p, rk, c = cracked_square(CENTRAL)
    pts = near_crack_points(300)
    rows = evaluate(rk, pts)
    a0, b0 = c.segments[0]
    tips = c.tip_points()  # both ends of the segment

    def crosses(xi, x):  # strict crossing of segment xi -> x with the crack line segment
        o = lambda p_, q_, r_: (q_[0] - p_[0]) * (r_[1] - p_[1]) - (q_[1] - p_[1]) * (r_[0] - p_[0])  # noqa: E731
        return o(a0, b0, xi) * o(a0, b0, x) < 0 and o(xi, x, a0) * o(xi, x, b0) <= 0

    for k, x in enumerate(pts):
        s0 = np.linalg.norm(p.x - x, axis=1)
        d = s0.copy()
        for i in np.flatnonzero(s0 < rk.support):
            if crosses(p.x[i], x):
                d[i] = min(((np.linalg.norm(p.x[i] - t) + np.linalg.norm(x - t)) / s0[i]) ** 2 * s0[i] for t in tips)
        expected = np.flatnonzero(d < rk.support)
        got = np.sort(rows.indices[rows.indptr[k]:rows.indptr[k + 1]])
        assert np.array_equal(got, expected), k
    # Hidden nodes are left out of the rows, not stored as zeros.
    assert rows.indices.size < evaluate(replace(rk, cracks=None), pts).indices.size


def _static_solve(p, rk, material, displacements, tractions):
    """SCNI plane-strain solve with Nitsche conditions (variationally consistent)."""
    dom = nodal_domains(p)
    k = stiffness([scni(p, rk, dom)], material.D())
    bq = boundary_quadrature(p, dom, rk)
    kn, fn = nitsche_terms(p, bq, material.D(), displacements)
    d = spla.spsolve((k + kn).tocsc(), traction_load(p, bq, tractions) + fn)
    cell = smoothed_gradients(p, rk, dom, subcells=False).cell
    gx, gy = cell.matrix(0), cell.matrix(1)
    strain = np.column_stack([gx @ d[0::2], gy @ d[1::2], gy @ d[0::2] + gx @ d[1::2]])
    return d.reshape(-1, 2), strain @ material.D().T


def test_crack_parallel_to_tension_leaves_the_stress_uniform():
    """Patch test: a crack along the load direction carries no traction in the exact
    (uniform) solution, so SCNI with diffraction reproduces it."""
    p, rk, _ = cracked_square(CENTRAL, n=21)
    mat = ElasticMaterial(1000.0, 0.3)
    s0 = 2.0
    exx = (1 - mat.nu**2) / mat.E * s0
    eyy = -mat.nu * (1 + mat.nu) / mat.E * s0
    exact = lambda x, t: np.column_stack([exx * x[:, 0], eyy * x[:, 1]])  # noqa: E731
    _, stress = _static_solve(p, rk, mat, [Displacement("left", exact, (0,)), Displacement("bottom", exact, (1,))],
                              [Traction("right", (s0, 0.0))])
    # Not round-off: the slit's faces next to the tips are inclined by gap / h = 1e-8.
    assert np.abs(stress[:, 0] - s0).max() <= 1e-6 * s0
    assert np.abs(stress[:, 1:]).max() <= 1e-6 * s0


def test_edge_crack_opens_under_tension_normal_to_it():
    p, rk, _ = cracked_square(EDGE, n=21)
    mat = ElasticMaterial(1000.0, 0.3)
    d, _ = _static_solve(p, rk, mat, [Displacement("bottom", 0.0)], [Traction("top", (0.0, 1.0))])
    sol_pts = lambda xs, dy: np.column_stack([xs, np.full_like(xs, 0.5 + dy)])  # noqa: E731
    faces = np.array([0.05, 0.25, 0.45])
    ahead = np.array([0.6, 0.75, 0.9])
    uy = lambda pts: evaluate(rk, pts).matrix(0) @ d[:, 1]  # noqa: E731
    top = uy(np.array([[0.5, 1.0]]))[0]
    opening = uy(sol_pts(faces, 1e-3)) - uy(sol_pts(faces, -1e-3))
    jump_ahead = uy(sol_pts(ahead, 1e-3)) - uy(sol_pts(ahead, -1e-3))
    assert np.all(opening > 0.1 * top)  # the faces separate ...
    assert np.all(np.diff(opening) < 0)  # ... most at the mouth, closing towards the tip
    # Ahead of the tip u is continuous: the difference over 2e-3 is just the strain times it.
    assert np.all(np.abs(jump_ahead) < 0.05 * opening.min())
    # The uncracked plate does not open.
    plain = rk_approximation(p.x, p.spacing)
    d0, _ = _static_solve(p, plain, mat, [Displacement("bottom", 0.0)], [Traction("top", (0.0, 1.0))])
    n_plain = lambda pts: evaluate(plain, pts).matrix(0) @ d0[:, 1]  # noqa: E731
    assert np.all(np.abs(n_plain(sol_pts(faces, 1e-3)) - n_plain(sol_pts(faces, -1e-3))) < 0.05 * opening.min())


def test_gmsh_mesh_with_an_embedded_crack():
    gmsh = pytest.importorskip("gmsh")
    from rkfx.geometry.gmsh_nodes import from_gmsh

    gmsh.initialize(interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.model.add("edge_crack")
        geo = gmsh.model.geo
        h = 0.08
        pts = [geo.addPoint(x, y, 0.0, h) for x, y in [(0, 0), (1, 0), (1, 1), (0, 1)]]
        sides = [geo.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
        surf = geo.addPlaneSurface([geo.addCurveLoop(sides)])
        a, b = geo.addPoint(0.2, 0.45, 0.0, h / 2), geo.addPoint(0.7, 0.6, 0.0, h / 2)
        crack_line = geo.addLine(a, b)
        geo.synchronize()
        gmsh.model.mesh.embed(1, [crack_line], 2, surf)
        for name, line in zip(["bottom", "right", "top", "left"], sides):
            gmsh.model.setPhysicalName(1, gmsh.model.addPhysicalGroup(1, [line]), name)
        gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [surf]), "domain")
        gmsh.model.mesh.generate(2)
        p0 = from_gmsh(gmsh.model)
    finally:
        gmsh.finalize()
    p, c = cut_triangulation(p0, [[[0.2, 0.45], [0.7, 0.6]]])
    assert c.tips.tolist() == [[True, True]] and p.num_nodes > p0.num_nodes
    rk = rk_approximation(p.x, p.spacing, cracks=c)
    rng = np.random.default_rng(3)
    pts = rng.uniform(0.1, 0.9, (2000, 2))
    rows = evaluate(rk, pts, gradients=True)
    assert np.abs(rows.matrix(0) @ p.x[:, 0] - pts[:, 0]).max() <= 1e-12
    assert np.abs(rows.matrix(2) @ p.x[:, 1] - 1.0).max() <= 1e-10
    # SCNI on the slit geometry: the divergence consistency sum_L grad~N_I V_L = int N_I n dGamma
    # holds with the crack faces as boundary, so a linear field's smoothed gradient is exact.
    dom = nodal_domains(p)
    cell = smoothed_gradients(p, rk, dom, subcells=False).cell
    u = 0.3 * p.x[:, 0] - 0.7 * p.x[:, 1]
    assert np.abs(cell.matrix(0) @ u - 0.3).max() <= 1e-10 and np.abs(cell.matrix(1) @ u + 0.7).max() <= 1e-10
