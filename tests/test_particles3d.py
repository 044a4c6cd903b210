"""3-D particles: Kuhn-split grids, the gmsh solid reader, and bad input refused by name."""
import functools

import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.geometry.particles3d import (TET_FACES, box, graded_box, jittered_box, particles3d,
                                       tetrahedron_volumes)

NORMALS = {"left": (-1, 0, 0), "right": (1, 0, 0), "front": (0, -1, 0), "back": (0, 1, 0),
           "bottom": (0, 0, -1), "top": (0, 0, 1)}


def face_vectors(p):
    """Area vectors (right-hand normal x area) and centroids of the boundary faces."""
    x, f = p.x, p.boundary_faces
    return 0.5 * np.cross(x[f[:, 1]] - x[f[:, 0]], x[f[:, 2]] - x[f[:, 0]]), x[f].mean(axis=1)


def assert_closed_outward(p, volume):
    """The boundary faces close the solid (sum n A = 0) with outward normals: by the divergence
    theorem with the field x / 3, sum (x_c . n) A / 3 is the solid's volume."""
    s, c = face_vectors(p)
    assert np.abs(s.sum(axis=0)).max() <= 1e-13 * volume ** (2 / 3)
    assert abs(np.einsum("ij,ij->", c, s) / 3.0 - volume) <= 1e-12 * volume


@functools.cache
def gmsh_solid(name, **kw):
    pytest.importorskip("gmsh")
    from rkfx.geometry import gmsh_solids  # noqa: PLC0415
    from rkfx.geometry.gmsh_nodes import from_gmsh_3d, scratch_model  # noqa: PLC0415

    with scratch_model(name) as model:
        getattr(gmsh_solids, name)(model=model, **kw)
        return from_gmsh_3d(model)


def test_grid_counts_numbering_and_orientation():
    p = box(2.0, 3.0, 1.0, 5, 4, 3, origin=(1.0, -1.0, 0.5))
    assert p.num_nodes == 60 and p.tetrahedra.shape == (6 * 4 * 3 * 2, 4)
    # x fastest, then y, then z.
    assert np.allclose(p.x[[0, 1, 5, 20, 59]], [[1, -1, 0.5], [1.5, -1, 0.5], [1, 0, 0.5], [1, -1, 1.0], [3, 2, 1.5]])
    vol = tetrahedron_volumes(p.x, p.tetrahedra)
    assert np.all(vol > 0) and np.allclose(vol, 0.5 * 1.0 * 0.5 / 6, rtol=1e-13)
    assert abs(p.volume() - 6.0) <= 1e-12 * 6.0
    assert [len(c) for c in p.grid] == [5, 4, 3]
    # Kuhn split: every tetrahedron holds the main diagonal of its hexahedron (length of the
    # hexahedron's diagonal = longest edge).
    edges = p.x[p.tetrahedra[:, [0, 1, 2, 3, 0, 1]]] - p.x[p.tetrahedra[:, [1, 2, 3, 0, 2, 3]]]
    assert np.allclose(np.linalg.norm(edges, axis=2).max(axis=1), np.sqrt(0.5**2 + 1.0**2 + 0.5**2))


def test_boundary_faces_outward_and_tagged_by_side():
    p = box(2.0, 3.0, 1.0, 5, 4, 3)
    assert len(p.boundary_faces) == 2 * 2 * (4 * 3 + 4 * 2 + 3 * 2)
    assert_closed_outward(p, 6.0)
    s, _ = face_vectors(p)
    n = s / np.linalg.norm(s, axis=1)[:, None]
    area = {"left": 3.0, "right": 3.0, "front": 2.0, "back": 2.0, "bottom": 6.0, "top": 6.0}
    assert set(p.boundary_names) == set(NORMALS) and np.all(p.boundary_tags > 0)
    for name, normal in NORMALS.items():
        mine = p.boundary_tags == p.tag(name)
        assert np.allclose(n[mine], normal, atol=1e-15)
        assert abs(np.linalg.norm(s[mine], axis=1).sum() - area[name]) < 1e-13
    assert len(p.boundary_nodes("left")) == 4 * 3 and len(p.boundary_nodes("left", "right")) == 2 * 4 * 3
    assert np.array_equal(p.boundary_nodes(), np.flatnonzero(
        (p.x == p.x.min(axis=0)).any(axis=1) | (p.x == p.x.max(axis=0)).any(axis=1)))
    with pytest.raises(InputError, match=r"unknown boundary 'side'.*'back', 'bottom', 'front'"):
        p.tag("side")


def test_graded_box_spacing_is_the_largest_adjacent_interval():
    xs, ys, zs = [0.0, 0.1, 0.5, 1.0], [0.0, 2.0], [0.0, 0.2, 0.3]
    p = graded_box(xs, ys, zs)
    assert abs(p.volume() - 0.6) < 1e-14
    h = p.spacing.reshape(3, 2, 4)  # (z, y, x)
    assert np.allclose(h, 2.0)  # the single y interval dominates everywhere
    q = graded_box(xs, [0.0, 0.05], [0.0, 0.02])
    assert np.allclose(q.spacing.reshape(2, 2, 4)[0, 0], [0.1, 0.4, 0.5, 0.5])
    assert_closed_outward(p, 0.6)


def test_default_spacing_is_the_mean_edge_length():
    p = box(1.0, 1.0, 1.0, 3, 3, 3)
    q = particles3d(p.x, p.tetrahedra)
    # Corner (0,0,0) of the Kuhn grid: edges along x, y, z (0.5) and the face and main diagonals.
    assert abs(q.spacing[0] - (3 * 0.5 + 3 * 0.5 * np.sqrt(2) + 0.5 * np.sqrt(3)) / 7) < 1e-15
    assert q.grid is None and len(q.boundary_names) == 0 and np.all(q.boundary_tags == 0)


def test_orientation_is_fixed_and_faces_follow():
    p = box(1.0, 1.0, 1.0, 3, 3, 3)
    tet = p.tetrahedra.copy()
    tet[::2] = tet[::2, [1, 0, 2, 3]]  # every second tetrahedron inside out
    q = particles3d(p.x, tet)
    assert np.all(tetrahedron_volumes(q.x, q.tetrahedra) > 0)
    assert_closed_outward(q, 1.0)


def test_jittered_box_moves_interior_nodes_only():
    p = jittered_box(6, 0.2, seed=3)
    q = box(1.0, 1.0, 1.0, 6, 6, 6)
    moved = np.abs(p.x - q.x).max(axis=1)
    inner = np.setdiff1d(np.arange(p.num_nodes), q.boundary_nodes())
    assert p.grid is None and np.all(moved[q.boundary_nodes()] == 0)
    assert np.all(moved[inner] > 0) and moved.max() <= 0.2 * 0.2
    assert np.all(tetrahedron_volumes(p.x, p.tetrahedra) > 0) and abs(p.volume() - 1.0) < 1e-13
    assert np.array_equal(p.boundary_tags, q.boundary_tags)
    assert_closed_outward(p, 1.0)


def test_jittered_box_refuses_an_inverting_draw():
    with pytest.raises(InputError, match=r"amplitude = 0.3 with seed = 0 inverts tetrahedron \d+.*amplitude < 1/6"):
        jittered_box(16, 0.3, seed=0)
    with pytest.raises(InputError, match="0 <= amplitude < 0.5"):
        jittered_box(5, 0.5)


@pytest.mark.parametrize("name, kw, volume, parts", [
    ("sphere_octant", dict(radius=1.0, mesh_size=0.15), np.pi / 6, {"x0", "y0", "z0", "surface"}),
    ("box", dict(lx=2.0, ly=1.0, lz=0.5, mesh_size=0.2), 1.0, set(NORMALS)),
    ("l_block", dict(size=1.0, notch=0.5, height=1.0, mesh_size=0.2), 0.75, set(NORMALS) | {"notch"}),
])
def test_gmsh_solids(name, kw, volume, parts):
    p = gmsh_solid(name, **kw)
    assert set(p.boundary_names) == parts and p.num_nodes > 200
    assert np.all(tetrahedron_volumes(p.x, p.tetrahedra) > 0)
    assert np.all(p.boundary_tags > 0)  # every boundary face belongs to a named part
    assert set(np.unique(p.boundary_tags)) == set(p.boundary_names.values())
    if name == "sphere_octant":
        # Inscribed faceting: the surface nodes lie on the sphere, the flat facets inside it.
        assert 0 < volume - p.volume() < 0.02 * volume
        r = np.linalg.norm(p.x[p.boundary_nodes("surface")], axis=1)
        assert np.allclose(r, 1.0, atol=1e-6)
        assert np.allclose(p.x[p.boundary_nodes("z0"), 2], 0.0, atol=1e-12)
    else:
        assert abs(p.volume() - volume) <= 1e-12 * volume
    assert_closed_outward(p, p.volume())
    s, c = face_vectors(p)
    n = s / np.linalg.norm(s, axis=1)[:, None]
    for part, normal in NORMALS.items():
        if part in parts:
            assert np.allclose(n[p.boundary_tags == p.tag(part)], normal, atol=1e-9)
    if name == "l_block":  # the notch faces look into the cut-out column
        assert np.all(n[p.boundary_tags == p.tag("notch")] @ [1.0, 1.0, 0.0] > 0.99)


def test_gmsh_reader_broadcasts_from_rank_0():
    pytest.importorskip("gmsh")
    from rkfx.geometry import gmsh_solids  # noqa: PLC0415
    from rkfx.geometry.gmsh_nodes import from_gmsh_3d, scratch_model  # noqa: PLC0415

    class Comm:
        """One rank of a 2-rank communicator whose broadcasts pass through ``channel``."""

        def __init__(self, rank, channel):
            self.rank, self.size, self.channel = rank, 2, channel

        def bcast(self, data, root):
            assert root == 0
            if self.rank == 0:
                self.channel.append(data)
            return self.channel[0]

    channel = []
    with scratch_model("bcast") as model:
        gmsh_solids.box(mesh_size=0.5, model=model)
        p0 = from_gmsh_3d(model, Comm(0, channel))
    p1 = from_gmsh_3d(None, Comm(1, channel))  # rank 1 reads nothing from gmsh
    assert np.array_equal(p0.x, p1.x) and np.array_equal(p0.tetrahedra, p1.tetrahedra)
    assert p0.boundary_names == p1.boundary_names


def test_gmsh_without_a_3d_mesh_or_with_quadratic_tetrahedra():
    gmsh = pytest.importorskip("gmsh")
    from rkfx.geometry.gmsh_nodes import from_gmsh_3d, scratch_model  # noqa: PLC0415

    with scratch_model("flat") as model:
        model.occ.addBox(0, 0, 0, 1, 1, 1)
        model.occ.synchronize()
        with pytest.raises(InputError, match=r"no mesh; call gmsh.model.mesh.generate\(3\) first"):
            from_gmsh_3d(model)
        model.mesh.generate(2)
        with pytest.raises(InputError, match=r"no 3-D mesh .*generate\(3\) first"):
            from_gmsh_3d(model)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        model.mesh.generate(3)
        model.mesh.setOrder(2)
        try:
            with pytest.raises(InputError, match=r"element type 11 .*linear tetrahedra"):
                from_gmsh_3d(model)
        finally:
            gmsh.option.setNumber("Mesh.ElementOrder", 1)


# --- bad input: one error per kind, naming the culprit ---------------------------------------------

UNIT = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])


def test_non_finite_node():
    x = UNIT.copy()
    x[2, 1] = np.nan
    with pytest.raises(InputError, match=r"node 2 has non-finite coordinates \(0, nan, 0\)"):
        particles3d(x, [[0, 1, 2, 3]])


def test_node_in_no_tetrahedron():
    with pytest.raises(InputError, match=r"node 4 at \(2, 2, 2\) belongs to no tetrahedron"):
        particles3d(np.vstack([UNIT, [2.0, 2, 2]]), [[0, 1, 2, 3]])


def test_vertex_index_out_of_range():
    with pytest.raises(InputError, match=r"tetrahedron 0 has vertices \[0, 1, 2, 4\] outside 0..3"):
        particles3d(UNIT, [[0, 1, 2, 4]])


def test_degenerate_tetrahedron():
    x = np.vstack([UNIT, [0.5, 0.5, 0.0]])  # node 4 in the plane of 0, 1, 2
    with pytest.raises(InputError, match=r"degenerate tetrahedron 1 .*nodes \[0, 1, 2, 4\].*coplanar"):
        particles3d(x, [[0, 1, 2, 3], [0, 1, 2, 4]])


def test_face_shared_by_three_tetrahedra():
    x = np.vstack([UNIT, [0.2, 0.2, -1.0], [0.3, 0.3, 2.0]])
    with pytest.raises(InputError, match=r"face \[0, 1, 2\] is shared by 3 tetrahedra"):
        particles3d(x, [[0, 1, 2, 3], [0, 1, 2, 4], [0, 1, 2, 5]])


def test_overlapping_tetrahedra():
    x = np.vstack([UNIT, [0.3, 0.3, 2.0]])  # nodes 3 and 4 on the same side of face (0, 1, 2)
    with pytest.raises(InputError, match=r"tetrahedra 0 and 1 lie on the same side of their common face \[0, 1, 2\]"):
        particles3d(x, [[0, 1, 2, 3], [0, 2, 1, 4]])


def test_tagged_face_not_on_the_boundary():
    p = box(1.0, 1.0, 1.0, 3, 3, 3)
    inner = p.tetrahedra[0, TET_FACES[0]]
    interior = np.setdiff1d(np.arange(27), p.boundary_nodes())  # the centre node 13
    assert 13 in inner and interior.tolist() == [13]
    with pytest.raises(InputError, match=rf"face \[{inner[0]}, {inner[1]}, {inner[2]}\] of boundary 'load' is not a "
                                         "boundary face"):
        particles3d(p.x, p.tetrahedra, {"top": p.boundary_faces[:2], "load": [inner]})


def test_bad_grid_coordinates():
    with pytest.raises(InputError, match="ys must be a finite, strictly increasing"):
        graded_box([0, 1], [0, 1, 1], [0, 1])
    with pytest.raises(InputError, match="nz = 1"):
        box(1, 1, 1, 3, 3, 1)
