"""Bad input raises one clear error naming the culprit and the fix — never a bare LinAlgError or NaN."""
import numpy as np
import pytest

from rkfx.conditions import Displacement
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_plane_strain
from rkfx.errors import InputError, SingularMomentMatrix
from rkfx.geometry.particles import from_points, particles, structured
from rkfx.integration.quadrature import integration_rules
from rkfx.approximation.shape_functions import evaluate, rk_approximation


def test_support_too_small_names_the_point_and_the_fix():
    p = structured(1.0, 1.0, 6, 6)
    rk = rk_approximation(p.x, p.spacing, support_factor=0.6)
    with pytest.raises(SingularMomentMatrix, match=r"singular moment matrix at point \d+ \(.*increase support_factor"):
        evaluate(rk, np.array([[0.1, 0.1]]))


def test_collinear_neighbours_are_singular():
    x = np.column_stack([np.linspace(0, 1, 11), np.zeros(11)])
    rk = rk_approximation(x, np.full(11, 0.1), support_factor=3.0)
    with pytest.raises(SingularMomentMatrix, match="non-collinear"):
        evaluate(rk, np.array([[0.5, 0.0]]))


def test_point_outside_every_support():
    p = structured(1.0, 1.0, 5, 5)
    rk = rk_approximation(p.x, p.spacing)
    with pytest.raises(SingularMomentMatrix, match="covered by 0 node supports"):
        evaluate(rk, np.array([[5.0, 5.0]]))


@pytest.mark.parametrize("factor", [0.0, -1.5, np.nan])
def test_non_positive_support_factor(factor):
    with pytest.raises(InputError, match="support_factor"):
        rk_approximation(np.zeros((3, 2)), np.ones(3), support_factor=factor)


@pytest.mark.parametrize("E, nu, name", [(0.0, 0.3, "Young"), (-1.0, 0.3, "Young"), (1.0, 0.5, "Poisson"),
                                         (1.0, -1.0, "Poisson"), (1.0, 0.7, "Poisson")])
def test_invalid_elastic_constants(E, nu, name):
    with pytest.raises(InputError, match=f"{name}.*= {E if name == 'Young' else nu}"):
        ElasticMaterial(E, nu)


def test_node_outside_the_geometry():
    poly = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    x = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [1.5, 0.5]], float)
    with pytest.raises(InputError, match=r"node 5 at \(1.5, 0.5\) lies outside the geometry"):
        from_points(x, poly)


def test_duplicate_nodes_are_degenerate():
    x = np.array([[0, 0], [1, 0], [0, 1], [0, 1]], float)
    with pytest.raises(InputError, match="degenerate triangle"):
        particles(x, np.array([[0, 1, 2], [1, 2, 3]]))


def test_unknown_options():
    p = structured(1.0, 1.0, 4, 4)
    rk = rk_approximation(p.x, p.spacing)
    with pytest.raises(InputError, match="unknown integration rule 'foo'; choose one of"):
        integration_rules("foo", p, rk, None)
    with pytest.raises(InputError, match="unknown boundary 'side'"):
        p.boundary_nodes("side")
    with pytest.raises(InputError, match="unknown bc_method"):
        solve_plane_strain(p, ElasticMaterial(1, 0.3), [], bc_method="lagrange")


def test_missing_constraints_name_the_free_rigid_mode():
    p = structured(1.0, 1.0, 5, 5)
    with pytest.raises(InputError, match="leave y-translation free"):
        solve_plane_strain(p, ElasticMaterial(1, 0.3), [Displacement("left", 0.0, (0,))])
    with pytest.raises(InputError, match="leave x-translation, y-translation, rotation free"):
        solve_plane_strain(p, ElasticMaterial(1, 0.3), [])


def test_singular_system_is_reported_by_the_solver():
    """Below the boundary-condition check: PETSc's solve flags a singular matrix itself."""
    pytest.importorskip("petsc4py")
    import scipy.sparse as sp

    from rkfx.linalg.petsc import SolverDiverged, solve

    a = sp.csr_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]))
    with pytest.raises(SolverDiverged, match="singular"):
        solve(a, np.array([1.0, 0.0]))


def test_a_jittered_grid_moves_only_its_interior_nodes_and_refuses_crossing_ones():
    from rkfx.geometry.particles import jittered, structured

    p, grid = jittered(5, amplitude=0.3, seed=1), structured(1.0, 1.0, 5, 5)
    moved = np.abs(p.x - grid.x).max(axis=1)
    on_edge = (np.abs(grid.x - 0.5) > 0.5 - 1e-12).any(axis=1)
    assert p.num_nodes == 25 and not moved[on_edge].any() and 0 < moved.max() <= 0.3 * 0.25
    assert len(p.boundary_nodes("left")) == 5
    with pytest.raises(InputError, match="amplitude = 0.5"):
        jittered(5, amplitude=0.5)
