"""Drucker-Prager return map (plane strain): elastic inside the cone, on the cone after a
return, Mohr-Coulomb's limit in a plane-strain biaxial test with associated flow, the tension
cut-off of a cohesionless soil, the plastic strain, and bad parameters named."""
import numpy as np
import pytest
from scipy.optimize import brentq

from rkfx.errors import InputError
from rkfx.materials.drucker_prager import DruckerPrager, invariants

SOIL = DruckerPrager(E=1.0e7, nu=0.3, phi=20.0, c=300.0)


def test_elastic_inside_the_cone():
    s0 = np.array([[-1e4, -2e4, -1.5e4, 1e3]])
    d = np.array([[1e-6, -2e-6, 5e-7]])
    out = SOIL.update(s0, d, np.zeros(1))
    assert np.allclose(out.stress, s0 + SOIL.elastic_increment(d)) and not out.yielded[0]
    assert out.plastic_strain[0] == 0.0


@pytest.mark.parametrize("psi", [0.0, 10.0, 20.0])
def test_returns_onto_the_cone(psi):
    soil = DruckerPrager(E=1.0e7, nu=0.3, phi=20.0, c=300.0, psi=psi)
    rng = np.random.default_rng(0)
    s0 = np.column_stack([-1e4 * np.ones(50), -1e4 * np.ones(50), -1e4 * np.ones(50), np.zeros(50)])
    d = 1e-2 * rng.standard_normal((50, 3))
    out = soil.update(s0, d, np.zeros(50))
    f = soil.yield_function(out.stress)
    assert np.all(f <= 1e-8 * 1e4)
    on = out.yielded & (invariants(out.stress)[1] > 0)
    assert on.sum() > 20 and np.all(np.abs(f[on]) < 1e-8 * 1e4)
    assert np.all(out.plastic_strain[out.yielded] > 0) and np.all(out.plastic_strain[~out.yielded] == 0)
    # the volumetric change of the return is the dilatancy's: none for psi = 0
    i1_trial = invariants(s0 + soil.elastic_increment(d))[0]
    moved = on & (i1_trial < soil.apex)
    if psi == 0.0:
        assert np.allclose(invariants(out.stress)[0][moved], i1_trial[moved])
    else:
        assert np.all(invariants(out.stress)[0][moved] < i1_trial[moved])


def test_plane_strain_biaxial_reaches_mohr_coulomb():
    """Associated flow: the limit stress of a plane-strain test under a held confining stress
    meets Mohr-Coulomb's (sigma_1 - sigma_3) / 2 = c cos phi - (sigma_1 + sigma_3) / 2 sin phi."""
    soil = DruckerPrager(E=1.0e7, nu=0.3, phi=30.0, c=1000.0, psi=30.0)
    p0 = 2.0e4
    s = np.array([[-p0, -p0, -p0, 0.0]])
    eps_p = np.zeros(1)
    for _ in range(1500):
        def sxx(dx):
            return soil.update(s, np.array([[dx, -2e-5, 0.0]]), eps_p).stress[0, 0] + p0
        dx = brentq(sxx, -1e-3, 1e-3, xtol=1e-16)
        out = soil.update(s, np.array([[dx, -2e-5, 0.0]]), eps_p)
        s, eps_p = out.stress, out.plastic_strain
    s1, s3 = s[0, 0], s[0, 1]  # the confined side is the larger (less compressive) principal stress
    phi = np.radians(30.0)
    lhs, rhs = 0.5 * (s1 - s3), 1000.0 * np.cos(phi) - 0.5 * (s1 + s3) * np.sin(phi)
    assert lhs == pytest.approx(rhs, rel=1e-6)
    assert eps_p[0] > 1e-3


def test_tension_cut_off_without_cohesion():
    sand = DruckerPrager(E=1.0e7, nu=0.3, phi=30.0, c=0.0)
    out = sand.update(np.zeros((1, 4)), np.array([[1e-3, 1e-3, 0.0]]), np.zeros(1))
    assert np.allclose(out.stress, 0.0, atol=1e-9) and out.yielded[0]


@pytest.mark.parametrize("kw, word", [(dict(phi=95.0), "friction"), (dict(c=-1.0), "cohesion"),
                                      (dict(psi=25.0), "dilatancy"), (dict(phi=0.0, c=0.0), "no strength"),
                                      (dict(nu=0.5), "nu")])
def test_bad_parameters_named(kw, word):
    args = dict(E=1e7, nu=0.3, phi=20.0, c=300.0) | kw
    with pytest.raises(InputError, match=word):
        DruckerPrager(**args)
    with pytest.raises(InputError, match="stresses"):
        SOIL.update(np.zeros((2, 3)), np.zeros((2, 3)), np.zeros(2))


def test_tangent_increment_is_the_rate_of_the_return():
    """On the cone, C_T : d eps matches (update(sigma, h d eps) - sigma) / h as h -> 0."""
    soil = DruckerPrager(E=1e6, nu=0.3, phi=30.0, c=500.0, psi=10.0)
    rng = np.random.default_rng(3)
    start = soil.update(np.tile([-2e3, -5e3, -3e3, 0.0], (40, 1)), rng.normal(size=(40, 3)) * 2e-2,
                        np.zeros(40))
    on = start.yielded & (invariants(start.stress)[1] > 1.0)
    assert on.sum() > 20
    sig = start.stress[on]
    d = rng.normal(size=(on.sum(), 3))
    # loading directions: those whose elastic trial leaves the cone
    load = soil.yield_function(sig + 1e-6 * soil.elastic_increment(d)) > 0
    h = 1e-7
    rate = (soil.update(sig[load], h * d[load], np.zeros(load.sum())).stress - sig[load]) / h
    tangent = soil.tangent_increment(sig[load], np.ones(load.sum(), bool), d[load])
    assert load.sum() > 5
    assert np.abs(rate - tangent).max() < 1e-4 * np.abs(tangent).max()
    assert np.array_equal(soil.tangent_increment(sig, np.zeros(len(sig), bool), d), soil.elastic_increment(d))


def test_algorithmic_tangent_is_the_derivative_of_a_finite_return():
    """After a finite step that yields, d sigma / d(d eps) of the whole return matches central
    differences of ``update`` (the continuum tangent does not: it misses the curvature term)."""
    soil = DruckerPrager(E=1e6, nu=0.3, phi=30.0, c=500.0, psi=10.0)
    rng = np.random.default_rng(5)
    m = 60
    start = np.tile([-2e3, -5e3, -3e3, 0.0], (m, 1))
    d = rng.normal(size=(m, 3)) * 3e-3
    step = soil.update(start, d, np.zeros(m))
    trial_i1 = invariants(start + soil.elastic_increment(d))[0]
    # returned to the cone, from inside the apex's mean stress or cut off in tension first (not
    # returned to the apex itself, where the tangent is 0)
    cone = step.yielded & (invariants(step.stress)[1] > 1.0)
    assert np.sum(cone & (trial_i1 < soil.apex)) > 10 and np.sum(cone & (trial_i1 > soil.apex)) > 5
    d_lambda = np.sqrt(3.0) * step.plastic_strain
    tangent = soil.algorithmic_tangent(step.stress, step.yielded, d_lambda)
    h = 1e-8
    for j in range(3):
        e = np.zeros((m, 3))
        e[:, j] = h
        fd = (soil.update(start, d + e, np.zeros(m)).stress - soil.update(start, d - e, np.zeros(m)).stress) / (2 * h)
        scale = np.abs(fd[cone]).max()
        assert np.abs(fd[cone] - tangent[cone, :, j]).max() < 1e-5 * scale
        continuum = soil.tangent_increment(step.stress, step.yielded, e / h)
        assert np.abs(fd[cone] - continuum[cone]).max() > 1e-2 * scale
    elastic = ~step.yielded
    assert elastic.any()
    unit = soil.algorithmic_tangent(step.stress, step.yielded, d_lambda)[elastic]
    assert np.allclose(unit[:, :, 0], soil.elastic_increment(np.tile([1.0, 0.0, 0.0], (elastic.sum(), 1))))
