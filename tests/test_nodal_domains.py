"""Median-dual nodal domains: conforming, closed, exact areas and moments, also non-convex."""
import numpy as np
import pytest

from conftest import l_shape, unit_square
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import graded, geometric_spacing, structured


@pytest.mark.parametrize("make, area", [(lambda: unit_square(0.08), 1.0), (lambda: l_shape(0.1), 3.0),
                                        (lambda: structured(3.0, 10.0, 7, 21), 30.0),
                                        (lambda: graded(geometric_spacing(2.0, 9, 1.3), np.linspace(0, 1, 5)), 2.0)])
def test_areas_sum_to_domain_area(make, area):
    p = make()
    d = nodal_domains(p)
    assert np.all(d.area > 0) and np.all(d.subcell_area > 0)
    assert abs(d.area.sum() - area) <= 1e-13 * area
    assert np.allclose(np.bincount(d.subcell_node, d.subcell_area, p.num_nodes), d.area, rtol=1e-13)


def test_cells_are_closed_and_boundary_is_the_perimeter():
    p = l_shape(0.1)
    d = nodal_domains(p)
    # sum of n*l over a closed polygon vanishes: for every cell and every subcell.
    assert np.abs(np.add.reduceat(d.cell_normal_length, d.cell_ptr[:-1])).max() < 1e-15
    assert np.abs(d.subcell_normal_length.sum(axis=1)).max() < 1e-15
    assert abs(d.boundary.length.sum() - 8.0) < 1e-13
    assert set(np.unique(d.boundary.tag)) == {p.tag(n) for n in ("bottom", "right", "inner", "top", "left")}
    # Every boundary node is a vertex of its own cell: it owns the half-segments touching it.
    assert np.all(np.linalg.norm(d.boundary.ends[:, 0] - p.x[d.boundary.node], axis=1)
                  * np.linalg.norm(d.boundary.ends[:, 1] - p.x[d.boundary.node], axis=1) == 0)
    # Outward normals: on the L's inner corner sides they point into the cut-out quadrant.
    inner = d.boundary.tag == p.tag("inner")
    assert np.all((d.boundary.normal[inner] @ [1.0, 1.0]) > 0)


def test_uniform_grid_interior_cells_have_area_h_squared():
    p = structured(1.0, 1.0, 11, 11)
    d = nodal_domains(p).area.reshape(11, 11)
    assert np.allclose(d[1:-1, 1:-1], 0.01, rtol=1e-12)
    assert np.allclose(d[0, 1:-1], 0.005, rtol=1e-12)


def test_second_moments_match_independent_quadrature():
    """Moments from the polygon formula vs a degree-2 Gauss rule on the subcells' triangles."""
    p = l_shape(0.2)
    d = nodal_domains(p)
    xt = p.x[p.triangles]
    g = xt.mean(axis=1)
    mid = 0.5 * (xt + np.roll(xt, -1, axis=1))
    quads = np.stack([xt, mid, np.broadcast_to(g[:, None], xt.shape), np.roll(mid, 1, axis=1)], 2).reshape(-1, 4, 2)
    bary = np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])
    moments = np.zeros((p.num_nodes, 3))
    for tri in ([0, 1, 2], [0, 2, 3]):
        v = quads[:, tri]
        e1, e2 = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
        area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        for b in bary:
            r = b @ v - p.x[d.subcell_node]
            for c, f in enumerate((r[:, 0] ** 2, r[:, 0] * r[:, 1], r[:, 1] ** 2)):
                moments[:, c] += np.bincount(d.subcell_node, area / 3 * f, p.num_nodes)
    assert np.allclose(d.second_moment, moments, rtol=1e-12, atol=1e-16)


def test_domains_around_some_nodes_give_their_cells_as_the_whole_build():
    """A rank's build (``nodes=``) holds fewer subcells, and its nodes' areas, moments and
    smoothed gradients are the whole build's."""
    from rkfx.approximation.shape_functions import rk_approximation  # noqa: PLC0415
    from rkfx.integration.quadrature import smoothed_gradients  # noqa: PLC0415
    from rkfx.parallel.partition import rcb  # noqa: PLC0415

    p = unit_square(0.08)
    rk = rk_approximation(p.x, p.spacing)
    whole = nodal_domains(p)
    mine = np.flatnonzero(rcb(p.x, 3) == 1)
    part = nodal_domains(p, nodes=mine)
    assert len(part.subcell_area) < len(whole.subcell_area)
    assert np.array_equal(part.area[mine], whole.area[mine])
    assert np.array_equal(part.second_moment[mine], whole.second_moment[mine])
    a, b = (smoothed_gradients(p, rk, d, subcells=True, nodes=mine) for d in (whole, part))
    for x, y in ((a.cell, b.cell), (a.cell_minus_subcell, b.cell_minus_subcell)):
        assert np.array_equal(x.indptr, y.indptr) and np.array_equal(x.indices, y.indices)
        assert np.abs(x.data - y.data).max() <= 1e-12 * np.abs(x.data).max()
