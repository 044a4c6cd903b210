"""Rectangular grid cells (``rkfx.geometry.grid_cells``): exact cells, SCNI/MSCNI patch tests, slits."""
import numpy as np
import pytest

from rkfx.fracture import damage as dm
from rkfx.approximation.diffraction import cracks
from rkfx.errors import InputError
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.particles import geometric_spacing, graded
from rkfx.integration.quadrature import smoothed_gradients
from rkfx.approximation.shape_functions import rk_approximation

XS = geometric_spacing(2.0, 9, 1.3)
YS = np.r_[0.0, 0.15, 0.25, 0.5, 0.6, 1.0]
# A grid whose midlines include y = 0.025 and x = 0.05: nodes at odd multiples of h / 2 in y.
H = 0.005
XC = np.r_[0.0, 0.0025 + H * np.arange(20), 0.1]  # columns at odd multiples of h/2, and the sides
YC = np.r_[0.0, 0.0025 + H * np.arange(12), 0.06]
SLIT = ((0.0, 0.025), (0.05, 0.025))  # edge crack from the left side to a cell corner
SUPPORT = 2.0  # the half-width first column needs more than 1.5 h next to the crack


def linear(x):
    return 0.3 + 2.0 * x[:, 0] - 1.5 * x[:, 1]


def test_cells_are_the_analytic_rectangles():
    d = grid_domains(XS, YS)
    p = graded(XS, YS)
    xm = np.r_[XS[0], 0.5 * (XS[1:] + XS[:-1]), XS[-1]]
    ym = np.r_[YS[0], 0.5 * (YS[1:] + YS[:-1]), YS[-1]]
    i, j = np.arange(p.num_nodes) % len(XS), np.arange(p.num_nodes) // len(XS)
    xl, xr, yb, yt = xm[i] - p.x[:, 0], xm[i + 1] - p.x[:, 0], ym[j] - p.x[:, 1], ym[j + 1] - p.x[:, 1]
    assert abs(d.area.sum() - 2.0) <= 1e-14 * 2.0
    assert np.allclose(d.area, (xr - xl) * (yt - yb), rtol=1e-13, atol=0)
    exact = np.column_stack([(xr**3 - xl**3) / 3 * (yt - yb), (xr**2 - xl**2) * (yt**2 - yb**2) / 4,
                             (xr - xl) * (yt**3 - yb**3) / 3])
    assert np.allclose(d.second_moment, exact, rtol=1e-12, atol=1e-16)
    # Quadrants: counter-clockwise, vertex 0 the node, all of positive area (4 / 2 / 1 per node).
    v = d.subcell_vertices
    assert np.array_equal(v[:, 0], p.x[d.subcell_node])
    signed = 0.5 * np.sum(v[:, :, 0] * np.roll(v[:, :, 1], -1, 1) - np.roll(v[:, :, 0], -1, 1) * v[:, :, 1], 1)
    assert np.allclose(signed, d.subcell_area, rtol=1e-13) and np.all(d.subcell_area > 0)
    assert np.array_equal(np.bincount(d.subcell_node), np.where((i % 8 == 0) ^ (j % 5 == 0), 2, 4) // np.where(
        (i % 8 == 0) & (j % 5 == 0), 4, 1))
    assert np.allclose(d.subcell_centroid, v.mean(axis=1), rtol=1e-14)
    # Every side's smoothing point is its midpoint; cells and subcells are closed polygons.
    assert np.allclose(d.smoothing_points[d.subcell_point], 0.5 * (v + np.roll(v, -1, axis=1)), rtol=0, atol=1e-15)
    ptr, _, normal_length = d.cell_segments(np.arange(p.num_nodes))
    assert np.abs(np.add.reduceat(normal_length, ptr[:-1])).max() < 1e-15
    assert np.abs(d.side_normal_length().sum(axis=1)).max() < 1e-15


def test_boundary_segments_match_graded_tags():
    d, p = grid_domains(XS, YS), graded(XS, YS)
    b = d.boundary
    assert abs(b.length.sum() - 2 * (XS[-1] + 1.0)) < 1e-13
    assert np.allclose(b.midpoint, d.smoothing_points[b.point], rtol=0, atol=1e-15)
    side = {"bottom": (b.midpoint[:, 1] == 0.0, [0, -1]), "top": (b.midpoint[:, 1] == 1.0, [0, 1]),
            "left": (b.midpoint[:, 0] == 0.0, [-1, 0]), "right": (b.midpoint[:, 0] == XS[-1], [1, 0])}
    for name, (on, normal) in side.items():
        assert on.sum() == 2 * ((len(XS) if name in ("bottom", "top") else len(YS)) - 1)
        assert np.all(b.tag[on] == p.tag(name)) and np.allclose(b.normal[on], normal)
    # Each half-segment is owned by the node at its end.
    assert np.all(np.min(np.linalg.norm(b.ends - p.x[b.node][:, None], axis=2), axis=1) == 0)


@pytest.mark.parametrize("slits", [(), (SLIT,)])
def test_scni_and_mscni_linear_patch(slits):
    p = graded(XC, YC)
    d = grid_domains(XC, YC, slits)
    c = cracks([np.array(SLIT)], [(False, True)]) if slits else None
    rk = rk_approximation(p.x, p.spacing, SUPPORT, cracks=c)
    s = smoothed_gradients(p, rk, d, subcells=True)
    coef = linear(p.x)
    err = np.abs(s.cell @ coef - [2.0, -1.5]).max(axis=1)
    assert s.cell_minus_subcell.num_rows == len(d.subcell_area)
    sub_err = np.bincount(d.subcell_node, np.abs(s.cell_minus_subcell @ coef).max(axis=1), p.num_nodes)
    if not slits:
        assert err.max() < 1e-12 and sub_err.max() < 1e-12
        return
    # Cells with a side on the slit evaluate it 1e-9 h off the face: O(1e-9) relative error;
    # every other cell is exact, the crack tip's included (the field is continuous).
    on_face = (np.abs(p.x[:, 1] - 0.025) < H) & (p.x[:, 0] < 0.05)
    assert on_face.sum() == 22  # 11 cells on either side
    assert err[~on_face].max() < 1e-12 and sub_err[~on_face].max() < 1e-12
    assert err[on_face].max() < 1e-8


def test_slit_faces_get_one_point_per_side_on_each_side():
    d = grid_domains(XC, YC, [SLIT])
    pts = d.smoothing_points
    below = np.flatnonzero(np.isclose(pts[:, 1], 0.025, rtol=0, atol=1e-10) & (pts[:, 1] < 0.025))
    above = np.flatnonzero(np.isclose(pts[:, 1], 0.025, rtol=0, atol=1e-10) & (pts[:, 1] > 0.025))
    assert len(below) == len(above) == 21  # the refined-grid segments from x = 0 to 0.05
    assert np.allclose(0.025 - pts[below, 1], 1e-9 * H, rtol=1e-6)
    assert np.allclose(pts[above, 1] - 0.025, 1e-9 * H, rtol=1e-6)
    assert np.array_equal(pts[below, 0], pts[above, 0])
    # Each cell uses the point on its own side: nodes below the slit the lower ones.
    node_y = np.repeat(graded(XC, YC).x[d.subcell_node, 1][:, None], 4, axis=1)
    for idx, side in ((below, -1), (above, 1)):
        users = np.isin(d.subcell_point, idx)
        assert users.sum() == 21 and np.all(np.sign(node_y[users] - 0.025) == side)
    # Beyond the tip the face is shared: one point per half-side, on the face.
    beyond = np.isclose(pts[:, 1], 0.025, rtol=0, atol=1e-10) & (pts[:, 0] > 0.05)
    assert beyond.sum() == 21 and np.all(pts[beyond, 1] == 0.025)


def test_slit_separates_a_jump_across_the_crack():
    """A field equal to 1 above the crack and 0 below it, far from the tip: the RK
    approximation with the crack reproduces it, and cells along the slit see no gradient."""
    p = graded(XC, YC)
    rk = rk_approximation(p.x, p.spacing, SUPPORT, cracks=cracks([np.array(SLIT)], [(False, True)]))
    coef = (p.x[:, 1] > 0.025).astype(float)
    far = (np.abs(p.x[:, 1] - 0.025) < H) & (p.x[:, 0] < 0.05 - 3 * H)
    split = smoothed_gradients(p, rk, grid_domains(XC, YC, [SLIT]), subcells=False).cell @ coef
    shared = smoothed_gradients(p, rk, grid_domains(XC, YC), subcells=False).cell @ coef
    assert np.abs(split[far]).max() < 1e-12
    assert np.abs(shared[far, 1]).min() > 10.0  # a point on the crack line is ambiguous


def test_chord_lengths_of_square_cells():
    xs = np.linspace(0.0, 1.0, 11)
    d = grid_domains(xs, xs)
    g = dm.cell_geometry(d)
    assert g.num_nodes == 121 and np.array_equal(g.vertices, d.subcell_vertices)
    node = np.array([60, 61, 5, 0])
    normals = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [1.0, -1.0]])
    chord = dm.chord_lengths(g, node, normals / np.linalg.norm(normals, axis=1)[:, None])
    # Interior: h along y, h sqrt(2) along the diagonal; bottom node along x: h; corner: h sqrt(2) / 2.
    assert np.allclose(chord, [0.1, 0.1 * np.sqrt(2), 0.1, 0.05 * np.sqrt(2)], rtol=1e-12)


def test_cell_geometry_of_median_dual_domains_needs_the_particles():
    from rkfx.geometry.nodal_domains import nodal_domains

    p = graded(XS, YS)
    with pytest.raises(InputError, match="pass the Particles"):
        dm.cell_geometry(nodal_domains(p))


@pytest.mark.parametrize("slit, words", [
    (((0.0, 0.0225), (0.05, 0.0225)), "not midway between two grid rows"),   # a node row
    (((0.0, 0.026), (0.05, 0.026)), "not midway"),
    (((0.0, 0.025), (0.051, 0.025)), "does not end on a cell corner"),
    (((0.0, 0.0), (0.05, 0.0)), "not midway"),                            # the domain boundary
    (((0.0, 0.02), (0.05, 0.025)), "not an axis-aligned segment"),
    (((0.05, 0.025), (0.05, 0.025)), "not an axis-aligned segment"),
    (((0.0, 0.025), (0.2, 0.025)), "does not end on a cell corner"),
    ((0.0, 0.025, 0.05), "two finite end points"),
])
def test_bad_slit_is_rejected_with_one_line(slit, words):
    with pytest.raises(InputError, match=words) as e:
        grid_domains(XC, YC, [slit])
    assert "slit 0" in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("xs", [[0.0], [0.0, 1.0, 1.0], [[0.0, 1.0]], [0.0, np.nan], [1.0, 0.0]])
def test_bad_coordinates_are_rejected(xs):
    with pytest.raises(InputError, match="xs must be"):
        grid_domains(xs, [0.0, 1.0])


def test_a_vertical_slit_ending_mid_face():
    ys = np.linspace(0.0, 1.0, 6)  # rows 0, 0.2, ...: refined y lines every 0.1
    xs = np.linspace(0.0, 1.0, 5)  # midlines at x = 0.125, 0.375, ...
    d = grid_domains(xs, ys, [((0.375, 1.0), (0.375, 0.4))])  # from the top to a node row
    assert len(d.smoothing_points) == len(grid_domains(xs, ys).smoothing_points) + 6
    p = graded(xs, ys)
    rk = rk_approximation(p.x, p.spacing, 2.0)
    assert np.abs(smoothed_gradients(p, rk, d, subcells=False).cell @ linear(p.x) - [2.0, -1.5]).max() < 1e-8


@pytest.mark.parametrize("slits", [(), (SLIT,)])
def test_cells_of_some_nodes_are_the_whole_builds(slits):
    """grid_domains(nodes=): those nodes' cells and subcells entry for entry, every area and moment."""
    whole = grid_domains(XC, YC, slits)
    n = len(whole.area)
    nodes = np.sort(np.random.default_rng(3).choice(n, n // 3, replace=False))
    some = grid_domains(XC, YC, slits, nodes=nodes)
    assert np.array_equal(some.area, whole.area) and np.array_equal(some.second_moment, whole.second_moment)
    kept = np.isin(whole.subcell_node, nodes)
    for name in ("subcell_node", "subcell_area", "subcell_centroid", "subcell_outer", "subcell_vertices"):
        assert np.array_equal(getattr(some, name), getattr(whole, name)[kept]), name
    assert np.array_equal(some.side_normal_length(), whole.side_normal_length(np.flatnonzero(kept)))
    assert np.array_equal(some.smoothing_points[some.subcell_point], whole.smoothing_points[whole.subcell_point[kept]])
    assert len(some.smoothing_points) < len(whole.smoothing_points)
    others = np.setdiff1d(np.arange(n), nodes)
    assert np.all(some.segment_counts()[others] == 0)
    for node in nodes:
        a, b = some.cell_segments([node]), whole.cell_segments([node])
        assert np.array_equal(some.smoothing_points[a[1]], whole.smoothing_points[b[1]])
        assert np.array_equal(a[2], b[2])
    assert np.array_equal(some.smoothing_points[some.boundary.point], whole.smoothing_points[whole.boundary.point])


def test_rows_of_nodes_without_cells_are_refused_in_one_line():
    from rkfx.assembly.smeared_strain import smeared_strain  # noqa: PLC0415

    p = graded(XC, YC)
    rk = rk_approximation(p.x, p.spacing, SUPPORT)
    d = grid_domains(XC, YC, nodes=np.arange(10))
    with pytest.raises(InputError, match=r"^\d+ of the particles whose rows are built \(first: 10\) have no cell.*nodes=") as e:
        smeared_strain(p, rk, d, 1.0, points=np.arange(20))
    assert "\n" not in str(e.value)
