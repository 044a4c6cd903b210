"""The unsaturated u-p model (eqs. 6.15-6.16) on NSNI: its Jacobian is the derivative of its
residual and rate terms, a saturated hydrostatic column carries no flux, and a saturated column
without gravity reduces to the linear u-p forms."""
import numpy as np
import pytest
import scipy.sparse as sp

from rkfx.assembly import nodal_forms
from rkfx.cases._confined_column import column_discretization
from rkfx.errors import InputError
from rkfx.materials.retention import Liakopoulos, VanGenuchten
from rkfx.models.explicit_poroelasticity import Constituents
from rkfx.models.unsaturated_poroelasticity import UnsaturatedBiotModel, UnsaturatedSoil
from rkfx.solvers.model import no_constraints

SAND = Constituents(E=1.3e6, nu=0.4, rho_s=2000.0, rho_f=1000.0, porosity=0.2975, k=4.5e-10, K_s=1e12, K_f=2e9)


def model(law=Liakopoulos(), rule="nsni", gravity=9.806):
    d = column_discretization(0.2, 1.0, 3, 11, rule)
    return d, UnsaturatedBiotModel(d.rule, UnsaturatedSoil(SAND, law, gravity), no_constraints(3 * d.particles.num_nodes))


def state(d, seed=0):
    rng = np.random.default_rng(seed)
    n = d.particles.num_nodes
    y = d.particles.x[:, 1]
    p = -1.5e4 * y + 500.0 * rng.standard_normal(n)  # drying upwards, some nodes saturated
    return np.r_[1e-4 * rng.standard_normal(2 * n), p], np.r_[1e-6 * rng.standard_normal(2 * n), 10 * rng.standard_normal(n)]


@pytest.mark.parametrize("law", [Liakopoulos(), VanGenuchten(S_rw=0.0842, n=2.0, beta=0.7)])
@pytest.mark.parametrize("rule", ["nsni", "dni"])
def test_jacobian_is_the_derivative(law, rule):
    d, m = model(law, rule)
    x, v = state(d)
    r0 = m.residual(x, 0.0)
    K = m.tangent(x, 0.0).toarray()
    f0 = m.rate_force(x, v)
    dx, dv = (a.toarray() for a in m.rate_tangents())
    rng = np.random.default_rng(1)
    n = d.particles.num_nodes

    def close(a, b, rtol):  # block by block: the flux rows are ~1e-10 of the force rows
        return all(np.abs(a[s] - b[s]).max() <= rtol * np.abs(a[s]).max() for s in (slice(0, 2 * n), slice(2 * n, None))
                   if np.abs(a[s]).max() > 0)

    for _ in range(3):
        dir_ = np.r_[1e-6 * rng.standard_normal(2 * d.particles.num_nodes), 1.0 * rng.standard_normal(d.particles.num_nodes)]
        h = 1e-3
        fd = (m.residual(x + h * dir_, 0.0) - m.residual(x - h * dir_, 0.0)) / (2 * h)
        assert close(fd, K @ dir_, 1e-6)
        fd = (m.rate_force(x + h * dir_, v) - m.rate_force(x - h * dir_, v)) / (2 * h)
        assert close(fd, dx @ dir_, 1e-4)
        fd = (m.rate_force(x, v + h * dir_) - m.rate_force(x, v - h * dir_)) / (2 * h)
        assert close(fd, dv @ dir_, 1e-8)
    m.residual(x, 0.0)  # r is unchanged by a rate evaluation
    assert np.array_equal(m.residual(x, 0.0), r0)


def test_saturated_hydrostatic_column_has_no_flux():
    d, m = model()
    n = d.particles.num_nodes
    p = 1000.0 * 9.806 * (1.0 - d.particles.x[:, 1]) + 2e3  # saturated everywhere
    r = m.residual(np.r_[np.zeros(2 * n), p], 0.0)
    assert np.abs(r[2 * n:]).max() <= 1e-12 * (SAND.k * 1000 * 9.806)


def test_saturated_without_gravity_is_the_linear_model():
    d, m = model(gravity=0.0)
    n = d.particles.num_nodes
    x, v = state(d)
    x[2 * n:] = np.abs(x[2 * n:])  # saturated
    mat = SAND.material
    K = sp.bmat([[nodal_forms.stiffness(d.rule, mat.elastic.D()), -nodal_forms.coupling(d.rule, mat.alpha)],
                 [None, nodal_forms.laplacian(d.rule, mat.k)]])
    r = m.residual(x, 0.0)
    assert np.allclose(r, K @ x, rtol=0, atol=1e-10 * np.abs(K @ x).max())
    c = m.rate_force(x, v)[2 * n:]
    N = d.rule.values.matrix()
    lin = nodal_forms.divergence(d.rule, mat.alpha) @ v[:2 * n] + mat.S * (N.T @ sp.diags(d.rule.weights) @ N) @ v[2 * n:]
    assert np.allclose(c, lin, rtol=1e-9, atol=1e-12 * np.abs(lin).max())


def test_bad_input_named():
    with pytest.raises(InputError, match="retention"):
        UnsaturatedSoil(SAND, object())
    with pytest.raises(InputError, match="gravity"):
        UnsaturatedSoil(SAND, Liakopoulos(), gravity=-1.0)
    d = column_discretization(0.2, 1.0, 3, 11)
    with pytest.raises(InputError, match="columns"):
        UnsaturatedBiotModel(d.rule, UnsaturatedSoil(SAND, Liakopoulos()), no_constraints(5))
    with pytest.raises(InputError, match="unequal spacings"):
        column_discretization(0.25, 1.0, 3, 11)


@pytest.mark.parametrize("rule", ["nsni", "dni"])
def test_the_contributions_of_a_split_of_the_points_add_up_to_the_whole_model(rule):
    """What the MPI ranks rely on (each integrates over its own nodes' cells and the steppers add
    the contributions): residual, rate terms and their Jacobians of the models on two halves of
    the points sum to the whole model's."""
    from rkfx.integration.nodal_stabilized import boundary_rule, nodal_cells, nodal_integration

    d, whole = model(rule=rule)
    p, soil = d.particles, whole.soil
    cells = nodal_cells(p.x, whole.rule.weights)
    halves = np.array_split(np.arange(p.num_nodes), 2)
    parts = [UnsaturatedBiotModel(nodal_integration(d.rk, cells, boundary_rule(p.x, p.boundary_edges), rule, points=h),
                                  soil, no_constraints(3 * p.num_nodes)) for h in halves]
    assert [len(m.rule.weights) for m in parts] == [len(h) for h in halves]
    x, v = state(d)
    scale = lambda a: np.abs(a).max()  # noqa: E731
    r = whole.residual(x, 0.0)
    assert scale(sum(m.residual(x, 0.0) for m in parts) - r) <= 1e-12 * scale(r)
    k = whole.tangent(x, 0.0)
    assert abs(sum(m.tangent(x, 0.0) for m in parts) - k).max() <= 1e-12 * abs(k).max()
    f = whole.rate_force(x, v)
    assert scale(sum(m.rate_force(x, v) for m in parts) - f) <= 1e-12 * scale(f)
    for a, b in zip(whole.rate_tangents(), zip(*(m.rate_tangents() for m in parts))):
        assert abs(sum(b) - a).max() <= 1e-12 * abs(a).max()


def _plastic(rule="nsni", ramp=None, c=20.0):
    from rkfx.materials.drucker_prager import DruckerPrager
    d = column_discretization(0.2, 1.0, 3, 11, rule)
    soil = UnsaturatedSoil(SAND, VanGenuchten(S_rw=0.0842, n=2.0, beta=0.7))
    dp = DruckerPrager(E=SAND.E, nu=SAND.nu, phi=30.0, c=c, psi=10.0)
    return d, dp, UnsaturatedBiotModel(d.rule, soil, no_constraints(3 * d.particles.num_nodes), weight="full",
                                       plasticity=dp, ramp=ramp)


@pytest.mark.parametrize("rule", ["nsni", "dni"])
def test_plastic_jacobian_is_the_derivative(rule):
    """With a Drucker-Prager skeleton on a step that yields most points, the Jacobian (the
    return map's algorithmic tangent, the load factor on the weight and the pore pressure's
    force) is the derivative of the residual; the committed history moves only on commit."""
    d, dp, m = _plastic(rule, ramp=lambda t: 0.7)
    x, _ = state(d)
    x[:2 * d.particles.num_nodes] *= 30.0  # strains of a few 1e-3: past the cone at most points
    m.residual(x, 0.0)
    K = m.tangent(x, 0.0).toarray()
    n = d.particles.num_nodes
    rng = np.random.default_rng(2)
    for _ in range(3):
        dir_ = np.r_[1e-6 * rng.standard_normal(2 * n), 1.0 * rng.standard_normal(n)]
        h = 1e-3
        fd = (m.residual(x + h * dir_, 0.0) - m.residual(x - h * dir_, 0.0)) / (2 * h)
        for s in (slice(0, 2 * n), slice(2 * n, None)):
            assert np.abs(fd[s] - (K @ dir_)[s]).max() <= 1e-6 * np.abs(fd[s]).max()
    assert not np.any(m.plastic_state[1])  # nothing committed yet
    m.residual(x, 0.0)
    m.commit()
    stress, plastic = m.plastic_state
    assert np.all(dp.yield_function(stress) <= 1e-9 * np.abs(stress).max()) and plastic.max() > 0
    assert np.mean(plastic > 0) > 0.5  # the step yielded most points
    saved = {k: v.copy() for k, v in m.state().items()}
    r1 = m.residual(2.0 * x, 0.0)  # from the committed state
    m.residual(1.5 * x, 0.0)
    m.commit()
    assert not np.array_equal(m.residual(2.0 * x, 0.0), r1)  # from the new one: another path
    m.restore(saved)
    assert np.array_equal(m.residual(2.0 * x, 0.0), r1)


def test_plasticity_needs_the_whole_weight_and_the_same_elasticity():
    from rkfx.materials.drucker_prager import DruckerPrager
    d = column_discretization(0.2, 1.0, 3, 11)
    soil = UnsaturatedSoil(SAND, Liakopoulos())
    with pytest.raises(InputError, match="weight='full'"):
        UnsaturatedBiotModel(d.rule, soil, no_constraints(3 * d.particles.num_nodes),
                             plasticity=DruckerPrager(E=SAND.E, nu=SAND.nu, phi=30.0))
    with pytest.raises(InputError, match="differ from the medium"):
        UnsaturatedBiotModel(d.rule, soil, no_constraints(3 * d.particles.num_nodes), weight="full",
                             plasticity=DruckerPrager(E=2 * SAND.E, nu=SAND.nu, phi=30.0))


def test_the_stabilization_alone_is_the_stiffness_less_its_smoothed_part():
    from dataclasses import replace
    d = column_discretization(0.2, 1.0, 3, 11, "nsni")
    D = SAND.material.elastic.D()
    whole = nodal_forms.stiffness(d.rule, D)
    smoothed = nodal_forms.stiffness(replace(d.rule, moments=None, trial_x=None, trial_y=None), D)
    stab = nodal_forms.stabilization_stiffness(d.rule, D)
    assert abs(stab + smoothed - whole).max() <= 1e-12 * abs(whole).max() and abs(stab).max() > 0
