"""3-D nodal domains for SCNI: closed, conforming, planar facets, exact smoothed gradients of
linear fields (eq. 3.55), subcells filling the cells; median-dual cells and grid boxes."""
import time

import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.geometry.nodal_cells3d import box_cells, median_dual_cells
from rkfx.geometry.particles3d import TET_EDGES, box, graded_box, jittered_box, particles3d
from test_particles3d import NORMALS, face_vectors, gmsh_solid

GRADED = ([0.0, 0.1, 0.5, 1.0, 1.2], [0.0, 0.3, 0.4, 1.0], [0.0, 0.5, 0.6, 0.7, 1.1])
CASES = {
    "median uniform": lambda: (box(2.0, 3.0, 1.0, 6, 5, 4, origin=(10.0, -5.0, 3.0)), median_dual_cells),
    "median graded": lambda: (graded_box(*GRADED), median_dual_cells),
    "median jittered": lambda: (jittered_box(7, 0.2, seed=1), median_dual_cells),
    "median octant": lambda: (gmsh_solid("sphere_octant", radius=1.0, mesh_size=0.15), median_dual_cells),
    "median l_block": lambda: (gmsh_solid("l_block", size=1.0, notch=0.5, height=1.0, mesh_size=0.2),
                               median_dual_cells),
    "box uniform": lambda: (box(2.0, 3.0, 1.0, 6, 5, 4, origin=(10.0, -5.0, 3.0)), box_cells),
    "box graded": lambda: (graded_box(*GRADED), box_cells),
}


def residuals(p, c):
    """Per cell, relative to V_L: the closure sum_G S_G (/ V_L^(2/3)) and the first moment
    sum_G (x_G - x_L) (outer) S_G - V_L I (/ V_L); the divergence theorem makes both zero."""
    n = p.num_nodes
    node = c.facet_node
    s = c.facet_vector
    closure = np.column_stack([np.bincount(node, s[:, d], n) for d in range(3)])
    r = c.points[c.facet_point] - p.x[node]  # about the node: no loss to a far origin
    moment = np.stack([np.stack([np.bincount(node, r[:, i] * s[:, j], n) for j in range(3)], -1)
                       for i in range(3)], 1) - c.volume[:, None, None] * np.eye(3)
    return (np.abs(closure).max(axis=1) / c.volume ** (2 / 3)).max(), (np.abs(moment).max(axis=(1, 2)) / c.volume).max()


@pytest.mark.parametrize("case", CASES)
def test_volumes_subcells_and_divergence_identities(case):
    p, build = CASES[case]()
    c = build(p)
    n = p.num_nodes
    assert c.volume.shape == (n,) and np.all(c.volume > 0)
    assert abs(c.volume.sum() - p.volume()) <= 1e-12 * p.volume()
    assert np.all(c.subcell_volume > 0) and np.all(np.diff(c.subcell_node) >= 0)
    assert np.allclose(np.bincount(c.subcell_node, c.subcell_volume, n), c.volume, rtol=1e-13, atol=0)
    assert np.array_equal(np.diff(c.subcell_ptr), np.bincount(c.subcell_node, minlength=n))
    closure, moment = residuals(p, c)
    assert closure < 1e-13 and moment < 1e-12, (closure, moment)


@pytest.mark.parametrize("case", CASES)
def test_smoothed_gradient_of_a_linear_field_is_exact(case):
    p, build = CASES[case]()
    c = build(p)
    rng = np.random.default_rng(7)
    a, b = rng.normal(size=3), rng.normal(size=(3, 3))  # three linear fields a_k + b_k . x
    g = c.smoothed_gradient(a + c.points @ b.T)
    assert g.shape == (p.num_nodes, 3, 3)
    assert np.abs(g - b).max() <= 1e-12 * np.abs(b).max()
    assert np.abs(c.smoothed_gradient(np.full(len(c.points), 2.5))).max() < 1e-12  # constants: zero


@pytest.mark.parametrize("case", CASES)
def test_cells_conform_and_the_boundary_is_the_surface(case):
    p, build = CASES[case]()
    c = build(p)
    q = len(c.points)
    bd = c.boundary
    use = np.bincount(c.facet_point, minlength=q)
    on_boundary = np.zeros(q, bool)
    on_boundary[bd.point] = True
    assert np.all(use[on_boundary] == 1) and np.all(use[~on_boundary] == 2)  # every point is used
    # The two uses of an interior point: two different cells, opposite vectors.
    vsum = np.column_stack([np.bincount(c.facet_point, c.facet_vector[:, d], q) for d in range(3)])
    assert np.all(vsum[~on_boundary] == 0)
    node = c.facet_node
    owners = np.bincount(c.facet_point, node, q)  # a + b, and a^2 + b^2 below: a != b
    squares = np.bincount(c.facet_point, node.astype(float) ** 2, q)
    assert np.all(2 * squares[~on_boundary] > owners[~on_boundary] ** 2)
    # Boundary facets: in their node's cell with vector n A, areas summing to the surface area.
    facet_of = np.full(q, -1)
    facet_of[c.facet_point] = np.arange(len(c.facet_point))
    f = facet_of[bd.point]
    assert np.array_equal(node[f], bd.node)
    assert np.allclose(c.facet_vector[f], bd.normal * bd.area[:, None], rtol=0, atol=1e-15)
    assert np.allclose(np.linalg.norm(bd.normal, axis=1), 1.0, rtol=0, atol=1e-15) and np.all(bd.area > 0)
    s, _ = face_vectors(p)
    surface = np.linalg.norm(s, axis=1).sum()
    assert abs(bd.area.sum() - surface) <= 1e-13 * surface
    assert set(np.unique(bd.tag)) == set(np.unique(p.boundary_tags))
    for name, normal in NORMALS.items():  # the planar sides' facets carry the side's normal and tag
        if name in p.boundary_names:
            assert np.allclose(bd.normal[bd.tag == p.tag(name)], normal, rtol=0, atol=1e-9)
    for tag in np.unique(p.boundary_tags):
        area = np.linalg.norm(s[p.boundary_tags == tag], axis=1).sum()
        assert abs(bd.area[bd.tag == tag].sum() - area) <= 1e-13 * surface


def _lookup(c, point, node):
    """Facet entries (index into facet_point) of the pairs (point, cell)."""
    n = c.num_nodes
    key = c.facet_point.astype(np.int64) * n + c.facet_node
    order = np.argsort(key)
    at = order[np.searchsorted(key[order], point * n + node)]
    assert np.array_equal(key[at], point * n + node)
    return at


@pytest.mark.parametrize("case", ["median jittered", "median octant"])
def test_median_dual_quadrilaterals_are_planar_and_their_points_area_centroids(case):
    """Rebuild each quadrilateral (m_ab, c_abc, g, c_abd) of each tetrahedron from its corners:
    planar, its point at the area centroid, its vector n A pointing from a's cell to b's."""
    p, _ = CASES[case]()
    c = median_dual_cells(p)
    x, tet = p.x, p.tetrahedra
    scale = np.ptp(x, axis=0).max()
    g = x[tet].mean(axis=1)
    for e, (ia, ib, ic, id_) in enumerate(TET_EDGES):
        xa, xb, xc, xd = x[tet[:, ia]], x[tet[:, ib]], x[tet[:, ic]], x[tet[:, id_]]
        m, c1, c2 = 0.5 * (xa + xb), (xa + xb + xc) / 3, (xa + xb + xd) / 3
        s1 = 0.5 * np.cross(c1 - m, g - m)  # triangles (m, c1, g) and (m, g, c2)
        s2 = 0.5 * np.cross(g - m, c2 - m)
        planar = np.einsum("ij,ij->i", np.cross(c1 - m, g - m), c2 - m)  # 6 x volume of the 4 corners
        assert np.abs(planar).max() <= 1e-14 * scale**3
        a1, a2 = np.linalg.norm(s1, axis=1), np.linalg.norm(s2, axis=1)
        assert np.allclose(np.einsum("ij,ij->i", s1, s2), a1 * a2, rtol=1e-12)  # same normal: convex
        centroid = (a1[:, None] * (m + c1 + g) + a2[:, None] * (m + g + c2)) / (3 * (a1 + a2)[:, None])
        pid = 6 * np.arange(len(tet)) + e
        assert np.allclose(c.points[pid], centroid, rtol=0, atol=1e-14 * scale)
        sa = c.facet_vector[_lookup(c, pid, tet[:, ia])]
        sb = c.facet_vector[_lookup(c, pid, tet[:, ib])]
        assert np.array_equal(sa, -sb)
        assert np.all(np.einsum("ij,ij->i", sa, xb - xa) > 0)
        assert np.allclose(np.abs(np.einsum("ij,ij->i", sa, s1 + s2)), np.linalg.norm(sa, axis=1) * (a1 + a2),
                           rtol=1e-12)
        assert np.allclose(np.linalg.norm(sa, axis=1), a1 + a2, rtol=1e-12)


@pytest.mark.parametrize("case", ["median jittered", "median octant"])
def test_median_dual_boundary_facets_and_subcells_rebuilt_from_the_definition(case):
    p, _ = CASES[case]()
    c = median_dual_cells(p)
    x, tet, n = p.x, p.tetrahedra, p.num_nodes
    scale = np.ptp(x, axis=0).max()
    # Boundary quadrilateral (v, m_vb, centroid, m_vc) of each boundary triangle at each vertex.
    f = p.boundary_faces
    s, cen = face_vectors(p)
    for j in range(3):
        v, w1, w2 = x[f[:, j]], x[f[:, (j + 1) % 3]], x[f[:, (j + 2) % 3]]
        m1, m2 = 0.5 * (v + w1), 0.5 * (v + w2)
        t1 = 0.5 * np.cross(m1 - v, cen - v)
        t2 = 0.5 * np.cross(cen - v, m2 - v)
        a1, a2 = np.linalg.norm(t1, axis=1), np.linalg.norm(t2, axis=1)
        k = 3 * np.arange(len(f)) + j
        assert np.array_equal(c.boundary.node[k], f[:, j])
        assert np.allclose(c.points[c.boundary.point[k]],
                           (a1[:, None] * (v + m1 + cen) + a2[:, None] * (v + cen + m2)) / (3 * (a1 + a2)[:, None]),
                           rtol=0, atol=1e-14 * scale)
        assert np.allclose(c.boundary.area[k, None] * c.boundary.normal[k], t1 + t2, rtol=0, atol=1e-15 * scale**2)
        assert np.allclose(t1 + t2, s / 3, rtol=0, atol=1e-15 * scale**2)
    # Subcell of edge (v, w) at v: the pyramids with apex x_v over the edge's quadrilaterals,
    # volume (1/3) (c_q - x_v) . S_q and centroid x_v + 3/4 (c_q - x_v), volume-weighted.
    pid = np.arange(6 * len(tet))
    ends = np.concatenate([tet[:, TET_EDGES[:, :2]].reshape(-1, 2), tet[:, TET_EDGES[:, 1::-1]].reshape(-1, 2)])
    pid = np.concatenate([pid, pid])
    sq = c.facet_vector[_lookup(c, pid, ends[:, 0])]
    cq, xv = c.points[pid], x[ends[:, 0]]
    vol = np.einsum("ij,ij->i", cq - xv, sq) / 3
    assert np.all(vol > 0)
    key, inv = np.unique(ends[:, 0] * n + ends[:, 1], return_inverse=True)  # sorted by (v, w)
    volume = np.bincount(inv, vol)
    centroid = np.column_stack([np.bincount(inv, vol * (xv + 0.75 * (cq - xv))[:, d]) for d in range(3)])
    assert np.array_equal(c.subcell_node, key // n)
    assert np.allclose(c.subcell_volume, volume, rtol=1e-12, atol=0)
    assert np.allclose(c.subcell_centroid, centroid / volume[:, None], rtol=0, atol=1e-13 * scale)


def test_median_dual_cells_of_a_uniform_grid():
    """Kuhn split: every interior cell has volume h_x h_y h_z; an interior node has 14 edges
    (14 subcells) and lies in 24 tetrahedra (72 facets)."""
    p = box(2.0, 3.0, 1.0, 6, 5, 4)
    c = median_dual_cells(p)
    h = 0.4 * 0.75 * (1.0 / 3.0)
    inner = np.setdiff1d(np.arange(p.num_nodes), p.boundary_nodes())
    assert len(inner) == 4 * 3 * 2
    assert np.allclose(c.volume[inner], h, rtol=1e-13)
    assert np.all(np.diff(c.subcell_ptr)[inner] == 14)
    assert np.all(np.diff(c.facet_ptr)[inner] == 72)
    assert len(c.points) == 6 * len(p.tetrahedra) + 3 * len(p.boundary_faces)


def test_box_cells_are_the_13_point_rule():
    p = graded_box(*GRADED)
    c = box_cells(p)
    xs, ys, zs = (np.asarray(v) for v in GRADED)
    nx, ny, nz = len(xs), len(ys), len(zs)
    i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    i, j, k = (v.transpose(2, 1, 0).ravel() for v in (i, j, k))  # x fastest

    def widths(v):
        mid = np.r_[v[0], 0.5 * (v[1:] + v[:-1]), v[-1]]
        return np.diff(mid)

    assert np.allclose(c.volume, widths(xs)[i] * widths(ys)[j] * widths(zs)[k], rtol=1e-14)
    on = (i == 0).astype(int) + (i == nx - 1) + (j == 0) + (j == ny - 1) + (k == 0) + (k == nz - 1)
    assert np.array_equal(np.diff(c.subcell_ptr), 6 - on)  # interior 6, face 5, edge 4, corner 3
    assert np.array_equal(np.diff(c.facet_ptr), np.full(p.num_nodes, 6))
    inner = np.flatnonzero(on == 0)
    # Interior box: its node, 6 face centres (distinct, at the faces of the box) and 6 pyramid centroids.
    fp = c.facet_point.reshape(-1, 6)[inner]
    assert np.all(np.sort(fp, axis=1)[:, 1:] != np.sort(fp, axis=1)[:, :-1])
    d = c.points[fp[:, 1]] - p.x[inner]
    assert np.allclose(d[:, 0], 0.5 * (xs[i[inner] + 1] - xs[i[inner]]))  # +x face on the mid-plane
    sub = c.subcell_centroid[c.subcell_ptr[inner][:, None] + np.arange(6)]
    assert np.allclose(sub - p.x[inner][:, None], 0.75 * (c.points[fp] - p.x[inner][:, None]))
    assert np.allclose(c.subcell_volume[c.subcell_ptr[inner][:, None] + np.arange(6)].sum(axis=1), c.volume[inner])
    # Uniform grid: interior volume h_x h_y h_z; one point per box face.
    u = box_cells(box(2.0, 3.0, 1.0, 6, 5, 4))
    inner_u = np.setdiff1d(np.arange(120), box(2.0, 3.0, 1.0, 6, 5, 4).boundary_nodes())
    assert np.allclose(u.volume[inner_u], 0.4 * 0.75 * 1.0 / 3.0, rtol=1e-14)
    assert len(u.points) == 7 * 5 * 4 + 6 * 6 * 4 + 6 * 5 * 5


def test_box_cells_need_a_tensor_grid():
    with pytest.raises(InputError, match="box_cells needs a tensor-grid node set.*median_dual_cells"):
        box_cells(jittered_box(4, 0.1))
    p = box(1.0, 1.0, 1.0, 3, 3, 3)
    x = p.x.copy()
    x[13] += 0.01
    with pytest.raises(InputError, match="not the tensor grid p.grid"):
        box_cells(particles3d(x, p.tetrahedra, grid=p.grid))


@pytest.mark.slow
def test_build_times_and_points_per_node_at_scale():
    """~10^5-node grid (median-dual and box cells) and a ~2 x 10^4-node gmsh mesh: built in
    seconds, identities to round-off. Prints the numbers (node set: gmsh meshing included)."""
    median_dual_cells(box(1.0, 1.0, 1.0, 3, 3, 3))  # compile outside the clock
    rows = []

    def measure(label, make, build):
        t0 = time.perf_counter()
        p = make()
        t1 = time.perf_counter()
        c = build(p)
        t2 = time.perf_counter()
        closure, moment = residuals(p, c)
        n = p.num_nodes
        rows.append(f"{label}: {n} nodes, node set {t1 - t0:.2f} s, cells {t2 - t1:.2f} s, "
                    f"{len(c.points) / n:.1f} smoothing points, {len(c.subcell_volume) / n:.1f} subcells, "
                    f"{len(c.facet_point) / n:.1f} facets per node; closure {closure:.1e}, moment {moment:.1e}")
        assert closure < 1e-13 and moment < 1e-12
        assert abs(c.volume.sum() - p.volume()) <= 1e-12 * p.volume()
        return t2 - t1

    grid = {}  # built once, timed in the first row
    assert measure("median-dual 47^3", lambda: grid.setdefault("p", box(1.0, 1.0, 1.0, 47, 47, 47)),
                   median_dual_cells) < 20.0
    assert measure("box 47^3", lambda: grid["p"], box_cells) < 5.0
    assert measure("median-dual octant", lambda: gmsh_solid("sphere_octant", radius=1.0, mesh_size=0.028),
                   median_dual_cells) < 10.0
    print("\n" + "\n".join(rows))


@pytest.mark.parametrize("case", ["median jittered", "median octant", "box graded"])
def test_cells_of_some_nodes_equal_the_whole_builds(case):
    """A rank's build (``nodes=``): its nodes' volumes, facets (points by coordinates) and
    subcells equal the whole build's value for value, in order; nothing else is built; and the
    MSCNI rules over those nodes are the whole build's bit for bit."""
    from rkfx.approximation.shape_functions import rk_approximation
    from rkfx.integration.nodal_rules3d import mscni_rules_3d

    p, build = CASES[case]()
    whole = build(p)
    nodes = np.flatnonzero(p.x[:, 0] < np.quantile(p.x[:, 0], 0.3))  # a rank's part: a slab
    part = build(p, nodes)
    assert np.array_equal(part.volume[nodes], whole.volume[nodes])
    for i in nodes:
        a, b = slice(whole.facet_ptr[i], whole.facet_ptr[i + 1]), slice(part.facet_ptr[i], part.facet_ptr[i + 1])
        assert np.array_equal(part.points[part.facet_point[b]], whole.points[whole.facet_point[a]])
        assert np.array_equal(part.facet_vector[b], whole.facet_vector[a])
    mine = np.isin(whole.subcell_node, nodes)
    kept = np.isin(part.subcell_node, nodes)
    assert np.array_equal(part.subcell_node[kept], whole.subcell_node[mine])
    assert np.array_equal(part.subcell_volume[kept], whole.subcell_volume[mine])
    assert np.array_equal(part.subcell_centroid[kept], whole.subcell_centroid[mine])
    assert len(part.facet_point) < 0.8 * len(whole.facet_point)
    assert np.array_equal(part.boundary.area, whole.boundary.area)
    rk = rk_approximation(p.x, p.spacing, 1.5)
    _, rules_w, values_w = mscni_rules_3d(p, rk, whole, nodes=nodes)
    _, rules_p, values_p = mscni_rules_3d(p, rk, part, nodes=nodes)
    for qw, qp in zip([*rules_w, values_w], [*rules_p, values_p]):
        assert np.array_equal(qw.weights, qp.weights) and np.array_equal(qw.points, qp.points)
        for rw, rp in ((qw.values, qp.values), (qw.gradients, qp.gradients)):
            if rw is not None:
                assert np.array_equal(rw.indptr, rp.indptr) and np.array_equal(rw.indices, rp.indices)
                assert np.array_equal(rw.data, rp.data)
