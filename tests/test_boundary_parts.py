"""Boundary parts by name or by marker, resolved in one place for the RK models, and the
explicit constraints built from rkfx.conditions."""
import numpy as np
import pytest

from rkfx.assembly.boundary import (boundary_quadrature, collocation, nitsche_terms, part_nodes, part_points,
                                    traction_load, transformation_constraints)
from rkfx.assembly.smeared_strain import constraint
from rkfx.conditions import Displacement, Flux, Pressure, Traction, Velocity
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import structured
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_plane_strain
from rkfx.models.poroelasticity import PoroMaterial, solve_biot
from rkfx.approximation.shape_functions import rk_approximation

P = structured(2.0, 1.0, 9, 5)
RK = rk_approximation(P.x, P.spacing)
BQ = boundary_quadrature(P, nodal_domains(P), RK, points_per_segment=2)


def top_left_half(x):
    return np.isclose(x[:, 1], 1.0) & (x[:, 0] < 1.0)


def test_a_marked_part_of_an_edge_loads_like_a_value_that_is_zero_outside_it():
    marked = traction_load(P, BQ, [Traction(top_left_half, lambda x, t, n: np.column_stack([x[:, 0], -t - x[:, 0]]))],
                           t=2.0)
    inside = lambda x: (x[:, 0] < 1.0)[:, None]  # noqa: E731
    zero_outside = traction_load(P, BQ, [Traction("top", lambda x, t, n: inside(x) * np.column_stack(
        [x[:, 0], -t - x[:, 0]]))], t=2.0)
    assert np.any(marked != 0)
    assert np.array_equal(marked, zero_outside)
    assert not np.array_equal(marked, traction_load(P, BQ, [Traction("top", lambda x, t, n: np.column_stack(
        [x[:, 0], -t - x[:, 0]]))], t=2.0))
    # A traction on one component leaves the other unloaded.
    fy = traction_load(P, BQ, [Traction(top_left_half, -1.0, (1,))])
    assert np.all(fy[0::2] == 0) and fy[1::2].sum() == pytest.approx(-1.0)


def test_a_marker_selects_the_nodes_and_points_of_a_named_part():
    left = lambda x: x[:, 0] < 1e-12  # noqa: E731
    assert np.array_equal(part_nodes(P, left), P.boundary_nodes("left"))
    assert np.array_equal(part_points(P, BQ, left), np.flatnonzero(BQ.select([P.tag("left")])))
    g_name, v_name = transformation_constraints(P, RK, [Displacement("left", lambda x, t: x * t)], t=3.0)
    g_mark, v_mark = transformation_constraints(P, RK, [Displacement(left, lambda x, t: x * t)], t=3.0)
    assert (g_name != g_mark).nnz == 0 and np.array_equal(v_name, v_mark)
    d = ElasticMaterial(1.0, 0.3).D()
    k_name, f_name = nitsche_terms(P, BQ, d, [Displacement("left", 0.1, (0,))])
    k_mark, f_mark = nitsche_terms(P, BQ, d, [Displacement(left, 0.1, (0,))])
    assert abs(k_name - k_mark).max() == 0 and np.array_equal(f_name, f_mark)


def test_a_solve_on_marked_parts_equals_the_named_one():
    mat = ElasticMaterial(1.0, 0.3)
    named = solve_plane_strain(P, mat, [Displacement("left", 0.0), Traction("right", (0.0, -1.0))])
    marked = solve_plane_strain(P, mat, [Displacement(lambda x: x[:, 0] < 1e-12, 0.0),
                                         Traction(lambda x: x[:, 0] > 2.0 - 1e-12, (0.0, -1.0))])
    assert np.array_equal(named.coefficients, marked.coefficients)


def test_the_u_p_model_takes_marked_parts():
    column = structured(1.0, 4.0, 5, 17)
    material = PoroMaterial(E=1.0e6, nu=0.25, k=1.0e-6)
    times = np.array([0.0, 1.0e4, 1.0e5])
    fixed = [Displacement("bottom", 0.0), Displacement("left", 0.0, (0,)), Displacement("right", 0.0, (0,))]

    def run(bottom, top):
        return solve_biot(column, material, times, [times[-1]], fixed, [Pressure(top, 0.0)],
                          tractions=[Traction(top, (0.0, -1.0e3))],
                          fluxes=[Flux(bottom, lambda x, t, n: np.full(len(x), -1.0e-7))]).P

    named = run("bottom", "top")
    marked = run(lambda x: x[:, 1] < 1e-12, lambda x: x[:, 1] > 4.0 - 1e-12)
    assert np.any(named != 0) and np.array_equal(named, marked)


def test_unknown_names_and_empty_markers_name_the_part_and_the_fix():
    with pytest.raises(InputError, match=r"unknown boundary 'side'; this geometry names .* or a marker"):
        traction_load(P, BQ, [Traction("side", (1.0, 0.0))])
    with pytest.raises(InputError, match=r"unknown boundary 'side'.*or a marker"):
        solve_plane_strain(P, ElasticMaterial(1, 0.3), [Displacement("side", 0.0)])

    def nowhere(x):
        return x[:, 0] > 5.0
    with pytest.raises(InputError, match="marker nowhere selects no boundary node; make it accept"):
        collocation(P, RK, [([Displacement(nowhere, 0.0)], 0, 2)], 2 * P.num_nodes)
    with pytest.raises(InputError, match="marker nowhere selects no boundary quadrature point"):
        traction_load(P, BQ, [Traction(nowhere, (1.0, 0.0))])
    with pytest.raises(InputError, match=r"returned shape \(\) .* returns a bool array of shape \(m,\)"):
        part_nodes(P, lambda x: True)
    with pytest.raises(InputError, match="neither a name nor a marker"):
        part_nodes(P, 3)
    with pytest.raises(InputError, match="collocation takes .*Displacement or .*Velocity or .*Pressure"):
        transformation_constraints(P, RK, [Traction("top", (0.0, 1.0))])
    with pytest.raises(InputError, match="solve_elasticity takes .*Displacement and Traction conditions, not"):
        solve_plane_strain(P, ElasticMaterial(1, 0.3), [Displacement("left", 0.0), Velocity("right", 1.0)])


def test_explicit_constraints_from_conditions():
    # Constants: evaluated once; only zeros is homogeneous.
    fixed = constraint(P, RK, [Displacement("left", 0.0), Displacement("bottom", 0.0, (1,))])
    assert fixed.displacement is None and fixed.velocity is None and fixed.count > 0
    shifted = constraint(P, RK, [Displacement("left", 0.5, (0,))])
    assert shifted.displacement(0.0) is shifted.displacement(7.0) and np.all(shifted.value(1.0) == 0.5)
    # A zero velocity still prescribes the velocity.
    held = constraint(P, RK, [Velocity("left", 0.0, (0,))])
    assert held.prescribes_velocity and np.all(held.rate(0.0, 0.1) == 0)
    # Functions of (x, t) are evaluated at the boundary nodes when asked.
    ramp = constraint(P, RK, [Velocity("left", lambda x, t: np.where(x[:, 1] < 0.5, 2.0 * t, 0.0), (0,))])
    y = P.x[P.boundary_nodes("left"), 1]
    assert ramp.prescribes_velocity
    assert np.array_equal(ramp.rate(3.0, 0.1), np.where(y < 0.5, 6.0, 0.0))
    pulled = constraint(P, RK, [Displacement("right", lambda x, t: np.full(len(x), t), (0,))])
    assert np.array_equal(pulled.value(2.0), np.full(pulled.count, 2.0))
