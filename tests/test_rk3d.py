"""The 3-D RK core: reproducing conditions, the 3-D stiffness kernel, SCNI's linear patch test
(passed to round-off, failed by DNI) and the rigid-mode check.

The node sets are irregular: a jittered grid (Kuhn-split tetrahedra) and gmsh's unstructured
tetrahedra of a cube and of a non-convex L-shaped block.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from rkfx.approximation.shape_functions import evaluate, rk_approximation
from rkfx.assembly.galerkin import elastic_stiffness
from rkfx.assembly.operators import strain_matrix
from rkfx.conditions import Displacement, Traction
from rkfx.errors import InputError, SingularMomentMatrix
from rkfx.geometry.gmsh_nodes import from_gmsh_3d, scratch_model
from rkfx.geometry.gmsh_solids import box as gmsh_box, l_block
from rkfx.geometry.nodal_cells3d import box_cells, median_dual_cells
from rkfx.geometry.particles3d import box, jittered_box
from rkfx.integration.nodal_rules3d import mscni_rules_3d
from rkfx.integration.quadrature import Quadrature
from rkfx.approximation.sparse_rows import SparseRows, difference_rows
from rkfx.assembly.operators import stiffness
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_elasticity

MATERIAL = ElasticMaterial(E=2.0, nu=0.3)
GRAD = np.array([[0.1, 0.02, -0.03], [0.04, -0.05, 0.01], [0.02, 0.03, 0.07]])
SHIFT = np.array([0.01, -0.02, 0.03])


def linear(x, t=0.0):
    return x @ GRAD.T + SHIFT


def _gmsh(builder, h):
    with scratch_model("rk3d") as m:
        builder(mesh_size=h, model=m)
        return from_gmsh_3d(m)


@pytest.fixture(scope="module")
def node_sets():
    return {"jittered": jittered_box(7, 0.15, seed=3), "cube": _gmsh(gmsh_box, 0.25),
            "l_block": _gmsh(l_block, 0.25)}


@pytest.mark.parametrize("name", ["jittered", "cube", "l_block"])
def test_shape_functions_reproduce_linear_fields(node_sets, name):
    """Values, direct and implicit gradients reproduce a linear field to round-off at random
    points, at the nodes and on the boundary (the cells' boundary facet centroids)."""
    p = node_sets[name]
    rk = rk_approximation(p.x, p.spacing, 1.5)
    cells = median_dual_cells(p)
    rng = np.random.default_rng(0)
    lo, hi = p.x.min(axis=0), p.x.max(axis=0)
    inside = rng.uniform(lo, hi, (3000, 3))
    if name == "l_block":  # the notch column [0.5, 1]^2 x [0, 1] is outside the solid
        inside = inside[~((inside[:, 0] > 0.5) & (inside[:, 1] > 0.5))]
    points = np.vstack([inside, p.x, cells.points[cells.boundary.point]])
    u = linear(p.x)
    for kind in ("values", "direct", "implicit"):
        rows = evaluate(rk, points, gradients=kind == "direct", implicit=kind == "implicit")
        fit = rows @ u  # (m, components, 3)
        assert np.abs(fit[:, 0] - linear(points)).max() <= 1e-12
        assert np.abs(rows.matrix(0).sum(axis=1) - 1.0).max() <= 1e-13
        if kind != "values":
            assert rows.num_components == 4
            grads = np.transpose(fit[:, 1:], (0, 2, 1))  # [point, i, j] = du_i/dx_j
            assert np.abs(grads - GRAD).max() <= 1e-10


def test_direct_gradients_are_the_derivatives_of_the_values():
    """Central differences of N_I applied to a non-linear field match the direct gradients."""
    rng = np.random.default_rng(1)
    x = rng.uniform(0.0, 1.0, (800, 3))
    rk = rk_approximation(x, np.full(len(x), 0.11), 2.0)
    f = np.sin(3.0 * x[:, 0]) + x[:, 1] ** 2 * x[:, 2]
    p = np.array([[0.5, 0.4, 0.45], [0.3, 0.7, 0.6]])
    direct = (evaluate(rk, p, gradients=True) @ f)[:, 1:]
    eps = 1e-6
    for d in range(3):
        e = np.zeros(3)
        e[d] = eps
        fd = ((evaluate(rk, p + e) @ f) - (evaluate(rk, p - e) @ f))[:, 0] / (2 * eps)
        assert np.allclose(direct[:, d], fd, rtol=1e-6, atol=1e-8)


def test_a_point_too_few_supports_reach_is_named():
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.5, 0.5, 0.0]])
    rk = rk_approximation(x, np.full(5, 1.0), 1.5)  # all nodes in one plane
    with pytest.raises(SingularMomentMatrix, match=r"point 0 \(0.5, 0.5, 0.5\).*4 non-coplanar nodes"):
        evaluate(rk, np.array([[0.5, 0.5, 0.5]]))


def test_3d_takes_the_linear_basis_only():
    with pytest.raises(InputError, match="3-D RK approximations take the linear basis"):
        rk_approximation(np.zeros((5, 3)), np.ones(5), 1.5, order=2)


def test_compiled_stiffness_equals_the_sparse_product(node_sets):
    """The 3 x 3 block kernel gives B^T diag(w) D B of the Voigt strain rows, with a constant and
    a per-point D."""
    p = node_sets["jittered"]
    rk = rk_approximation(p.x, p.spacing, 1.5)
    pts = np.random.default_rng(2).uniform(0.0, 1.0, (400, 3))
    rows = evaluate(rk, pts, gradients=True)
    grad = SparseRows(rows.indptr, rows.indices, rows.data[:, 1:], rows.num_cols)
    w = np.random.default_rng(3).uniform(0.5, 1.5, len(pts))
    d = MATERIAL.D3()
    b = strain_matrix(grad)
    ref = b.T @ sp.kron(sp.diags(w), sp.csr_matrix(d)) @ b
    assert abs(elastic_stiffness(grad, w, d) - ref).max() <= 1e-12 * abs(ref).max()
    dq = d[None] * np.random.default_rng(4).uniform(0.2, 1.0, (len(pts), 1, 1))
    ref = b.T @ sp.block_diag([sp.csr_matrix(m) for m in w[:, None, None] * dq]) @ b
    assert abs(elastic_stiffness(grad, w, dq) - ref).max() <= 1e-12 * abs(ref).max()


def test_mscni_rules_sum_to_the_seeds_stabilization(node_sets):
    """The three stabilization rules of ``mscni_rules_3d`` give SCNI + sum_C V_C (B~_L - B_C)^T
    D (B~_L - B_C) of eq. (3.56) (direct gradients at the subcell centroids)."""
    p = node_sets["l_block"]
    rk = rk_approximation(p.x, p.spacing, 1.5)
    cells = median_dual_cells(p)
    nodal, rules, _ = mscni_rules_3d(p, rk, cells, with_values=False)
    at = evaluate(rk, cells.subcell_centroid, gradients=True)
    grads = SparseRows(at.indptr, at.indices, at.data[:, 1:], at.num_cols)
    seed = [nodal, Quadrature(cells.subcell_centroid, cells.subcell_volume, None,
                              difference_rows(nodal.gradients, cells.subcell_node, grads), "seed")]
    d = MATERIAL.D3()
    a, b = stiffness(rules, d), stiffness(seed, d)
    assert abs(a - b).max() <= 1e-12 * abs(b).max()


def _patch(p, cells, rule, bc_method):
    bcs = [Displacement(name, linear) for name in p.boundary_names]
    sol = solve_elasticity(p, MATERIAL, bcs, rule=rule, bc_method=bc_method, domains=cells)
    pts = np.vstack([p.x, cells.points[cells.boundary.point]])
    return (np.abs(sol.displacement(pts) - linear(pts)).max() / np.abs(linear(pts)).max(),
            np.abs(sol.gradient(pts) - GRAD).max() / np.abs(GRAD).max())


@pytest.mark.parametrize("name", ["jittered", "cube", "l_block"])
@pytest.mark.parametrize("rule", ["scni", "mscni"])
def test_scni_passes_the_linear_patch_test(node_sets, name, rule):
    """SCNI with the facet-smoothed gradients of eq. (3.55), and MSCNI, reproduce a linear
    displacement and its gradient to round-off with Nitsche's conditions."""
    p = node_sets[name]
    err_u, err_g = _patch(p, median_dual_cells(p), rule, "nitsche")
    assert err_u <= 1e-10 and err_g <= 1e-10, (err_u, err_g)


def test_scni_on_box_cells_passes_the_patch_test():
    """The seed's 13-point rule on the box cells of a graded grid."""
    p = box(1.0, 2.0, 1.5, 5, 7, 6)
    for rule in ("scni", "mscni"):
        err_u, err_g = _patch(p, box_cells(p), rule, "nitsche")
        assert err_u <= 1e-10 and err_g <= 1e-10, (rule, err_u, err_g)


@pytest.mark.parametrize("name", ["jittered", "cube", "l_block"])
def test_dni_fails_the_linear_patch_test(node_sets, name):
    """Direct nodal integration violates the integration constraint: its gradient error is far
    above round-off on these node sets."""
    p = node_sets[name]
    err_u, err_g = _patch(p, median_dual_cells(p), "dni", "nitsche")
    assert err_g > 1e-3, err_g


def test_a_free_rigid_mode_is_named():
    p = box(1.0, 1.0, 1.0, 3, 3, 3)
    with pytest.raises(InputError, match="leave z-translation free"):
        solve_elasticity(p, MATERIAL, [Displacement("left", 0.0, (0, 1))], rule="scni")
    corner = Displacement(lambda x: np.all(np.isclose(x, 0.0), axis=1), 0.0)  # one node: rotations free
    with pytest.raises(InputError, match="leave a combination of rigid motions free, so the stiffness is singular"):
        solve_elasticity(p, MATERIAL, [corner], rule="scni", bc_method="transformation")


def test_rules_of_other_dimensions_are_refused():
    p = box(1.0, 1.0, 1.0, 3, 3, 3)
    with pytest.raises(InputError, match="rule 'gauss2' is not available in 3-D"):
        solve_elasticity(p, MATERIAL, [Displacement("left", 0.0), Traction("right", (1.0, 0.0, 0.0))],
                         rule="gauss2")
