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
    ptr, _, normal_length = d.cell_segments(np.arange(p.num_nodes))
    assert np.array_equal(np.diff(ptr), d.segment_counts()) and np.all(np.diff(ptr) >= 2)
    assert np.abs(np.add.reduceat(normal_length, ptr[:-1])).max() < 1e-15
    assert np.abs(d.side_normal_length().sum(axis=1)).max() < 1e-15
    assert abs(d.boundary.length.sum() - 8.0) < 1e-13
    assert set(np.unique(d.boundary.tag)) == {p.tag(n) for n in ("bottom", "right", "inner", "top", "left")}
    # Every boundary node is a vertex of its own cell: it owns the half-segments touching it.
    assert np.all(np.linalg.norm(d.boundary.ends[:, 0] - p.x[d.boundary.node], axis=1)
                  * np.linalg.norm(d.boundary.ends[:, 1] - p.x[d.boundary.node], axis=1) == 0)
    # Outward normals: on the L's inner corner sides they point into the cut-out quadrant.
    inner = d.boundary.tag == p.tag("inner")
    assert np.all((d.boundary.normal[inner] @ [1.0, 1.0]) > 0)


def test_sides_computed_on_request_are_the_subcell_quadrilaterals():
    """The side normals (not stored: ``side_normal_length``) are those of the quadrilaterals
    (v, m_k, g, m_k-1) built independently (``cell_geometry``), for any selection of subcells;
    each cell's segments are its subcells' outer sides, whose midpoints are the smoothing points."""
    from rkfx.fracture.damage import cell_geometry  # noqa: PLC0415

    p = l_shape(0.1)
    d = nodal_domains(p)
    quads = cell_geometry(p).vertices
    edge = np.roll(quads, -1, axis=1) - quads
    assert np.allclose(d.side_normal_length(), np.stack([edge[..., 1], -edge[..., 0]], -1), rtol=0, atol=1e-15)
    some = np.array([7, 3, 3, len(d.subcell_area) - 1])
    assert np.array_equal(d.side_normal_length(some), d.side_normal_length()[some])
    assert np.allclose(d.smoothing_points[d.subcell_point], 0.5 * (quads + np.roll(quads, -1, axis=1)), atol=1e-15)
    node = int(d.boundary.node[0])  # its cell is bounded by two of its subcells' half-edges too
    ptr, point, _ = d.cell_segments([node])
    mine = np.flatnonzero(d.subcell_node == node)
    assert np.array_equal(point, d.subcell_point[mine][d.subcell_outer[mine]]) and ptr[-1] == len(point)
    assert np.isin(d.boundary.point[d.boundary.node == node], point).all()
    assert ptr[-1] == 2 * len(mine) + 2


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


@pytest.mark.parametrize("nodes", [None, "some"])
def test_smoothed_gradients_in_blocks_of_points_equal_one_block(monkeypatch, nodes):
    """N is evaluated a block of smoothing points at a time (``POINTS_PER_BLOCK``); the cell
    rows, MSCNI rows, subcell rows and their order are the same bit for bit as from one block."""
    from rkfx.approximation.shape_functions import rk_approximation  # noqa: PLC0415
    import rkfx.integration.quadrature as quadrature  # noqa: PLC0415

    p = unit_square(0.05)
    rk = rk_approximation(p.x, p.spacing)
    d = nodal_domains(p)
    sel = None if nodes is None else np.arange(3, p.num_nodes, 2)
    one = quadrature.smoothed_gradients(p, rk, d, nodes=sel)
    one_sub = quadrature.subcell_gradients(rk, d, nodes=sel)
    monkeypatch.setattr(quadrature, "POINTS_PER_BLOCK", 37)
    many = quadrature.smoothed_gradients(p, rk, d, nodes=sel)
    many_sub = quadrature.subcell_gradients(rk, d, nodes=sel)
    assert np.array_equal(one.subcells, many.subcells)
    assert np.array_equal(one_sub[2], many_sub[2])
    alone = quadrature.subcell_gradients(rk, d, nodes=sel, with_cells=False)  # the subcell rule's build
    assert alone[0] is None
    for name in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(alone[1], name), getattr(many_sub[1], name)), name
    for x, y in ((one.cell, many.cell), (one.cell_minus_subcell, many.cell_minus_subcell),
                 (one_sub[0], many_sub[0]), (one_sub[1], many_sub[1])):
        assert x.num_rows > 0
        for name in ("indptr", "indices", "data"):
            assert np.array_equal(getattr(x, name), getattr(y, name)), name


def test_cell_rows_come_in_node_order_without_a_reordering_copy(monkeypatch):
    """Blocks form the cell rows in the order of the nodes (a cell before or at the first block
    that needs it): no reordering copy on grids and gmsh meshes; with the triangles shuffled
    (subcells far from the nodes' order) each block forms the cells it first needs, and the
    rows are reordered: the same rows either way."""
    from dataclasses import replace  # noqa: PLC0415

    from rkfx.approximation.shape_functions import rk_approximation  # noqa: PLC0415
    import rkfx.integration.quadrature as quadrature  # noqa: PLC0415

    p = structured(1.0, 0.6, 23, 14)
    rk = rk_approximation(p.x, p.spacing)
    d = nodal_domains(p)
    one = quadrature.smoothed_gradients(p, rk, d)
    monkeypatch.setattr(quadrature, "POINTS_PER_BLOCK", 97)
    copies = []
    gather = quadrature.gathered_rows
    monkeypatch.setattr(quadrature, "gathered_rows", lambda *a: copies.append(len(a[1])) or gather(*a))
    many = quadrature.smoothed_gradients(p, rk, d)
    assert copies == []
    for name in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(one.cell, name), getattr(many.cell, name)), name
    perm = np.random.default_rng(1).permutation(len(p.triangles))
    q = replace(p, triangles=p.triangles[perm], triangle_edges=p.triangle_edges[perm])
    shuffled = quadrature.smoothed_gradients(q, rk, nodal_domains(q))
    assert copies == [p.num_nodes]
    for k in range(2):
        a, b = one.cell.matrix(k), shuffled.cell.matrix(k)
        assert abs(a - b).max() <= 1e-12 * abs(a).max()


def test_stacked_rows_grow_past_a_short_first_guess():
    """Rows stacked from jobs whose later rows are longer than the first job's outgrow the
    first allocation and still come out whole, in order."""
    from rkfx.approximation.sparse_rows import SparseRows, combine_job, stacked_rows  # noqa: PLC0415

    src = SparseRows(np.arange(0, 21, 1, dtype=np.int64), np.arange(20, dtype=np.int32), np.ones((20, 1)), 20)
    rows = [[0], [1], [2, 3, 4, 5], [6, 7, 8, 9, 10, 11, 12], [13, 14, 15, 16, 17, 18, 19]]

    def job(rs):
        ptr = np.cumsum([0] + [len(r) for r in rs])
        terms = np.concatenate([np.array(r) for r in rs])
        return combine_job(src, ptr, terms, np.arange(1.0, len(terms) + 1))

    out = stacked_rows((job(rows[i:i + 2]) for i in range(0, 5, 2)), len(rows), slack=1.0)
    assert np.array_equal(out.indptr, np.cumsum([0] + [len(r) for r in rows]))
    assert np.array_equal(out.indices, np.arange(20))
    expected = np.concatenate([np.arange(1.0, 3.0), np.arange(1.0, 12.0), np.arange(1.0, 8.0)])
    assert np.array_equal(out.data[:, 0], expected)
