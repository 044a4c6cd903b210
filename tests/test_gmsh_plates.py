"""gmsh squares with embedded fractures: cut along them, the fracture's quadrature covers its length."""
import numpy as np
import pytest

from rkfx.approximation.shape_functions import rk_approximation
from rkfx.errors import InputError
from rkfx.fracture.contact import interface
from rkfx.geometry.cells import nodal_cells
from rkfx.geometry.gmsh_nodes import from_gmsh, scratch_model
from rkfx.geometry.gmsh_plates import clip_to_square, fractured_square
from rkfx.geometry.particles import cut_triangulation


def test_chord_of_the_square_through_a_point():
    seg = clip_to_square((0.05, 0.0), np.radians(60.0), 0.3)
    d = seg[1] - seg[0]
    assert np.isclose(np.degrees(np.arctan2(d[1], d[0])), 60.0)
    r = np.array([0.05, 0.0]) - seg[0]
    assert np.isclose(d[0] * r[1] - d[1] * r[0], 0.0, atol=1e-15)  # the point lies on the chord
    assert np.isclose(np.abs(seg).max(axis=1), 0.15).all()  # both ends on the edges
    with pytest.raises(InputError, match="outside the square"):
        clip_to_square((0.2, 0.0), 0.3, 0.3)


@pytest.mark.parametrize("angle", [30.0, 60.0])
def test_fracture_through_a_meshed_square_is_cut_and_integrated(angle):
    seg = clip_to_square((0.05, 0.0), np.radians(angle), 0.3)
    with scratch_model("fractured") as model:
        fractured_square(0.3, [seg], 0.02, model)
        p0 = from_gmsh(model)
    assert set(p0.boundary_names) == {"bottom", "right", "top", "left"}
    p, cracks = cut_triangulation(p0, [seg], name="fracture")
    assert p.num_nodes > p0.num_nodes  # the face copies
    rk = rk_approximation(p.x, p.spacing, 1.5, cracks=cracks)
    f = interface(p, nodal_cells(p), rk, "fracture")
    assert np.isclose(f.weights.sum(), np.linalg.norm(seg[1] - seg[0]), rtol=1e-6)
    d = (seg[1] - seg[0]) / np.linalg.norm(seg[1] - seg[0])
    np.testing.assert_allclose(f.tangent, np.broadcast_to(d, f.tangent.shape), atol=1e-12)
    # a rigid translation of one side is a pure jump: g = its components along n_C and t_C
    plus = (p.x - seg[0]) @ np.array([d[1], -d[0]]) > 0  # right of the polyline
    u = np.zeros((p.num_nodes, 2))
    u[plus] = (3e-3, -1e-3)
    np.testing.assert_allclose(f.jump_normal @ u.ravel(), f.normal @ np.array([3e-3, -1e-3]), atol=1e-14)
    np.testing.assert_allclose(f.jump_tangent @ u.ravel(), f.tangent @ np.array([3e-3, -1e-3]), atol=1e-14)


def test_bad_sizes_are_refused():
    with pytest.raises(InputError, match="mesh_size"):
        with scratch_model("bad") as model:
            fractured_square(0.3, [], 0.5, model)
