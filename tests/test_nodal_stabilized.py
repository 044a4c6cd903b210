"""Nodal integration on non-conforming cells (eqs. 6.50-6.79): the linear patch test passes with
the VC-corrected test gradients and fails without them; the natural stabilization removes the
spurious low-energy modes that DNI and SNNI have.

Patch test: the boundary coefficients are set to a linear field (RK coefficients of a linear
field are its nodal values), the interior ones solved for with the boundary tractions of its
constant stress (flux, for the pressure form); the rule passes when the interior coefficients
come out linear to round-off. Energy ratios: as in ``tests/test_spurious_modes.py``, a mode is
spurious when the rule sees under 10% of its Gauss-4 strain energy.
"""
import numpy as np
import pytest
import scipy.linalg as sl
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from rkfx.approximation.semi_lagrangian import evaluate_moving, moving_rk
from rkfx.approximation.sparse_rows import gathered_rows
from rkfx.approximation.shape_functions import RKApproximation
from rkfx.assembly import nodal_forms, operators
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import jittered, structured
from rkfx.integration.nodal_stabilized import RULES, boundary_rule, nodal_cells, nodal_integration
from rkfx.integration.quadrature import integration_rules
from rkfx.materials.elasticity import ElasticMaterial

D = ElasticMaterial(1.0, 0.3).D()
CORRECTED = {"snni-vc", "nsni"}


def _set_up(p, x=None, factor=2.0):
    """Cells of the nodal areas (squares: non-conforming), the boundary and the approximation at ``x``."""
    x = p.x if x is None else x
    cells = nodal_cells(x, nodal_domains(p).area)
    rk = moving_rk(x, factor * p.spacing, skin=0.5 * float(p.spacing.mean()), reach=cells.reach)
    return rk, cells, boundary_rule(x, p.boundary_edges)


def _patch_errors(p, rule, x=None):
    rk, cells, bnd = _set_up(p, x)
    x = rk.x
    r = nodal_integration(rk, cells, bnd, rule)
    on_boundary = np.zeros(len(x), bool)
    on_boundary[np.unique(p.boundary_edges)] = True
    nb = evaluate_moving(rk, bnd.points, bnd.owner).matrix()
    # displacement u = c + G x with the constant stress D eps(G)
    g = np.array([[0.3, -0.2], [0.15, 0.25]])
    u = (np.array([0.1, -0.05]) + x @ g.T).ravel()
    s = D @ np.array([g[0, 0], g[1, 1], g[0, 1] + g[1, 0]])
    t = bnd.normal_length @ np.array([[s[0], s[2]], [s[2], s[1]]])
    f = np.stack([nb.T @ t[:, 0], nb.T @ t[:, 1]], axis=1).ravel()
    k = nodal_forms.stiffness(r, D)
    fixed = np.repeat(on_boundary, 2)
    ui = spl.spsolve(k[~fixed][:, ~fixed].tocsc(), f[~fixed] - k[~fixed][:, fixed] @ u[fixed])
    # pressure q = 1 + 2x - 3y with the flux grad q . n on the boundary
    q = 1.0 + 2.0 * x[:, 0] - 3.0 * x[:, 1]
    flux = nb.T @ (bnd.normal_length @ np.array([2.0, -3.0]))
    a = nodal_forms.laplacian(r, 1.0)
    qi = spl.spsolve(a[~on_boundary][:, ~on_boundary].tocsc(), flux[~on_boundary] - a[~on_boundary][:, on_boundary] @ q[on_boundary])
    return np.abs(ui - u[~fixed]).max(), np.abs(qi - q[~on_boundary]).max()


def _sheared(p):
    return p.x + np.c_[0.8 * p.x[:, 1], np.zeros(p.num_nodes)]  # area preserving: the cells keep V_L


@pytest.mark.parametrize("configuration", ["initial", "sheared"])
@pytest.mark.parametrize("rule", sorted(RULES))
def test_linear_patch_test_passes_exactly_when_the_test_gradients_are_corrected(rule, configuration):
    p = jittered(11, 0.3, seed=1)
    eu, ep = _patch_errors(p, rule, None if configuration == "initial" else _sheared(p))
    if rule in CORRECTED:
        assert max(eu, ep) < 1e-10
    else:
        assert min(eu, ep) > 1e-3  # the integration constraint (6.66) fails on these cells


def _energy_ratios(k, p, factor):
    k_ref = operators.stiffness(integration_rules("gauss4", p, RKApproximation(p.x, factor * p.spacing),
                                                  nodal_domains(p)), D).toarray()
    k = 0.5 * (k + k.T)  # the corrected rules are slightly unsymmetric: their symmetric part
    ev = np.linalg.eigvalsh(k)
    rigid = int(np.sum(ev < 1e-10 * ev.max()))
    q = np.linalg.eigh(k_ref)[1][:, 3:]
    return rigid, sl.eigh(q.T @ k @ q, q.T @ k_ref @ q, eigvals_only=True)


@pytest.mark.parametrize("rule", sorted(RULES))
def test_natural_stabilization_leaves_only_the_rigid_modes(rule):
    p = structured(1.0, 1.0, 9, 9)
    rk, cells, bnd = _set_up(p, factor=1.5)
    rigid, ratios = _energy_ratios(nodal_forms.stiffness(nodal_integration(rk, cells, bnd, rule), D).toarray(), p, 1.5)
    assert rigid == 3
    if rule in ("dni-ns", "nsni-novc", "nsni"):
        assert ratios.min() > 0.5
    else:
        assert int(np.sum(ratios < 0.1)) >= 8  # DNI and SNNI: spurious low-energy modes


def test_implicit_gradients_of_nodal_gradient_samples_would_not_stabilize():
    """Why the expansion uses the derivatives of the implicit gradients: the implicit gradient of
    B~ sampled at the nodes vanishes on the modes that are zero at the nodes."""
    p = structured(1.0, 1.0, 9, 9)
    rk, cells, bnd = _set_up(p, factor=1.5)
    r = nodal_integration(rk, cells, bnd, "snni")
    psi = evaluate_moving(rk, implicit=True)
    k = nodal_forms.stiffness(r, D)
    m = cells.second_moments[:, 0]
    for j in (1, 2):
        gx, gy = (psi.matrix(j) @ r.trial.matrix(c) for c in (0, 1))  # d/dx_j of N_I,x and N_I,y
        b = _strain_matrix(gx, gy)
        k = k + b.T @ operators.block_diagonal(m[:, None, None] * D) @ b
    assert int(np.sum(_energy_ratios(k.toarray(), p, 1.5)[1] < 0.1)) >= 8


def _strain_matrix(gx, gy):
    """Voigt strain rows (3 per point) from the (points x nodes) matrices of d/dx and d/dy."""
    ex, ey = sp.csr_matrix([[1.0, 0.0]]), sp.csr_matrix([[0.0, 1.0]])
    rows = [sp.kron(gx, ex), sp.kron(gy, ey), sp.kron(gy, ex) + sp.kron(gx, ey)]
    order = np.arange(3 * gx.shape[0]).reshape(3, -1).T.ravel()
    return sp.vstack(rows).tocsr()[order]


def test_bad_rules_and_missing_boundaries_are_named():
    p = structured(1.0, 1.0, 5, 5)
    rk, cells, bnd = _set_up(p)
    with pytest.raises(InputError, match="unknown nodal integration rule"):
        nodal_integration(rk, cells, bnd, "scni")
    with pytest.raises(InputError, match="boundary"):
        nodal_integration(rk, cells, None, "nsni")
    small = moving_rk(p.x, 2.0 * p.spacing, skin=0.1)
    with pytest.raises(InputError, match="reach"):
        nodal_integration(small, cells, bnd, "snni")
    with pytest.raises(InputError, match="volume"):
        nodal_cells(p.x, np.zeros(p.num_nodes))


def _same_rows(a, b):
    return (np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)
            and np.array_equal(a.data, b.data) and a.num_cols == b.num_cols)


@pytest.mark.parametrize("rule", sorted(RULES))
def test_a_subset_of_points_gets_the_whole_rules_rows_there_bit_for_bit(rule):
    """An MPI rank integrates over its own nodes' cells: rows, weights and moments at a subset
    equal the whole rule's there, the VC-corrected test rows included (their column sums
    gather every term of the whole rule's, in its order), here on a sheared jittered patch."""
    p = jittered(13, 0.25, seed=3)
    rk, cells, bnd = _set_up(p, _sheared(p))
    whole = nodal_integration(rk, cells, bnd, rule)
    points = np.flatnonzero(p.x[:, 0] < 0.3)  # a strip of the reference patch
    part = nodal_integration(rk, cells, bnd, rule, points=points)
    for name in ("values", "trial", "test", "trial_x", "trial_y"):
        w = getattr(whole, name)
        if w is None:
            assert getattr(part, name) is None
            continue
        assert _same_rows(getattr(part, name), gathered_rows(w, points)), name
    assert np.array_equal(part.weights, whole.weights[points])
    assert (part.moments is None) == (whole.moments is None)
    if whole.moments is not None:
        assert np.array_equal(part.moments, whole.moments[points])
    with pytest.raises(InputError, match="increasing node indices"):
        nodal_integration(rk, cells, bnd, rule, points=points[::-1])
