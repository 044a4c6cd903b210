"""The chapter-5 model (u-p with inertia and damage) on the Newmark/trapezoid stepper."""
import numpy as np
import pytest

from rkfx.approximation.shape_functions import rk_approximation
from rkfx.conditions import Displacement, Pressure, Region
from rkfx.errors import InputError
from rkfx.fracture import damage as dm
from rkfx.fracture.tracking import tracking
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.particles import graded
from rkfx.models.hydraulic_fracture import FracturingRock, HydraulicFractureModel
from rkfx.models.poroelasticity import biot_operators, fpp_parameter
from rkfx.solvers.integrate import integrate
from rkfx.solvers.newmark import trapezoidal

SIDES = ("left", "right", "bottom", "top")
# Ehlers and Luo's rock (seed 5.3.2) with a constant alpha: its K = 1.75e11 exceeds K_s = 1e11.
ROCK = FracturingRock(2.1e11, 0.3, 3000.0, 1000.0, 0.2, 1e-8, 1e4, 2e9, 1e11, 2.7e3, 2.1e7, alpha=1.0)


def _plate(n, c=0.1, rate=5.5e4, track=False, damage_update="implicit"):
    h = 1.0 / n
    xs = -0.5 + h * np.arange(n + 1)
    xs[n // 2] = 0.0
    p = graded(xs, xs)
    d = grid_domains(xs, xs)
    rk = rk_approximation(p.x, p.spacing, 1.5)
    notch = lambda x: (np.abs(x[:, 1]) < 1.5 * h - 1e-9) & (np.abs(x[:, 0]) <= c + 1e-9)  # noqa: E731
    model = HydraulicFractureModel(
        p, rk, d, ROCK, displacements=[Displacement(s) for s in SIDES], precracked=np.flatnonzero(notch(p.x)),
        pressures=[Pressure(Region(notch, "notch"), lambda x, t: rate * t * np.ones(len(x)))]
        + [Pressure(s) for s in SIDES], track=tracking(p.x, p.spacing, 0.3) if track else None,
        damage_update=damage_update)
    return p, model, notch, h


def test_undamaged_blocks_are_the_biot_operators():
    xs = np.linspace(0.0, 1.0, 11)
    p, d = graded(xs, xs), grid_domains(xs, xs)
    rk = rk_approximation(p.x, p.spacing, 1.5)
    rock = FracturingRock(1e9, 0.25, 2600, 1000, 0.2, 1e-8, 1e4, 2e9, 5e10, 100.0, 1e6)
    m = HydraulicFractureModel(p, rk, d, rock, displacements=[Displacement("bottom")], pressures=[Pressure("top")])
    n = p.num_nodes
    x = np.zeros(3 * n)
    m.residual(x, 0.0)
    k = m.tangent(x, 0.0)
    ops = biot_operators(p, rk, d, rock.intact(), "scni+fpp")
    scale = abs(ops.Kuu).max()
    assert abs(k[:2 * n, :2 * n] - ops.Kuu).max() < 1e-12 * scale
    assert abs(k[:2 * n, 2 * n:] + ops.Kup).max() < 1e-12 * abs(ops.Kup).max()
    assert abs(k[2 * n:, 2 * n:] - ops.Kh).max() < 1e-12 * abs(ops.Kh).max()
    assert k[2 * n:, :2 * n].nnz == 0  # symmetrized (5.36): no dK_H/dU
    c = m.capacity(0.1)
    storage = ops.Ks + ops.stabilization(fpp_parameter(rock.intact(), 0.1, ops.h))
    assert abs(c[2 * n:, 2 * n:] - storage).max() < 1e-12 * abs(storage).max()
    assert abs(c[2 * n:, :2 * n] - ops.Kup.T).max() < 1e-12 * abs(ops.Kup).max()
    # alpha = 1 - K / K_s intact (5.1.2)
    assert np.isclose(rock.intact().alpha, 1 - rock.elastic_bulk_modulus / 5e10)


def _damaging(m, p, jacobian):
    """A state whose particles ahead of the notch tips load past their threshold, committed, and a
    further stretch of it: every damaged particle loads again with its normal already fixed (the
    normal of a particle initiating within the trial follows the stress, which the Jacobian does
    not differentiate)."""
    n = p.num_nodes
    rng = np.random.default_rng(5)
    r2 = (p.x**2).sum(axis=1)
    u = np.zeros((n, 2))
    u[:, 1] = 6.0 * ROCK.ft / ROCK.E * p.x[:, 1] * np.exp(-r2 / 0.1)  # fades before the boundary
    P = 1e7 * np.exp(-r2 / 0.02) + 1e5 * rng.random(n)
    m.jacobian = jacobian
    m.residual(np.r_[u.ravel(), P], 0.0)
    m.commit()
    x = np.r_[1.05 * u.ravel(), P]
    m.residual(x, 0.0)
    k = m.tangent(x, 0.0).tocsr()
    loading = m.trial.state.kappa > m.committed.kappa
    v = np.r_[rng.standard_normal(2 * n), np.zeros(n)] * 1e-9
    fd = (m.residual(x + v, 0.0) - m.residual(x - v, 0.0)) / 2
    return k, fd, k @ v, loading


@pytest.mark.parametrize("jacobian", ["symmetric", "full"])
def test_jacobian_matches_finite_differences_while_damaging(jacobian):
    p, m, notch, h = _plate(12)
    n = p.num_nodes
    k, fd, kv, loading = _damaging(m, p, jacobian)
    assert loading.sum() > 100
    # The solid rows: the consistent tangent (5.35), subcell terms with the lagged damage.
    assert np.linalg.norm(fd[:2 * n] - kv[:2 * n]) < 1e-5 * np.linalg.norm(kv[:2 * n])
    if jacobian == "full":  # the p-u block: dK_H/dU P of the opening crack (5.33)
        assert k[2 * n:, :2 * n].nnz > 0
        assert np.linalg.norm(fd[2 * n:] - kv[2 * n:]) < 1e-5 * np.linalg.norm(kv[2 * n:])
    else:  # symmetrized (5.36): the block is dropped although the crack's flow depends on U
        assert k[2 * n:, :2 * n].nnz == 0 and np.linalg.norm(fd[2 * n:]) > 0


@pytest.mark.parametrize("track, update", [(False, "implicit"), (True, "implicit"), (True, "impl-ex")])
def test_notch_pressure_grows_a_symmetric_crack_along_the_notch(track, update):
    p, m, notch, h = _plate(20, track=track, damage_update=update)
    times = np.linspace(0.0, 1200.0, 13)
    onset = []

    class Tips:
        def record(self, s):
            cracked = (m.committed.damage > 0.5) & ~notch(p.x)
            if cracked.any() and not onset:
                onset.append(s.t)

        def arrays(self):
            return {}

        def restore(self, a):
            pass

    run = integrate(trapezoidal(), m, times, recorder=Tips(), max_cuts=4)
    st = m.committed
    cracked = (st.damage > 0.5) & ~notch(p.x)
    xc = p.x[cracked]
    assert len(xc) >= 4
    assert np.isclose(xc[:, 0].max(), -xc[:, 0].min())      # both wings alike
    # Along the notch: tracking keeps the crack in the notch's three particle rows; without it
    # the band grows to five.
    assert np.abs(xc[:, 1]).max() < (1.0 if track else 2.0) * h + 1e-9
    assert np.abs(xc[:, 0]).min() > 0.1                      # ahead of the tips
    assert 500.0 < onset[0] < 1200.0                         # 2.8e7 to 6.6e7 Pa at the notch
    assert len(m.iterations) == run.substeps and max(m.iterations) <= 25
    assert m.iterations[0] <= 3                              # elastic steps: few iterations
    arrays = m.state()
    m.restore(arrays)
    np.testing.assert_array_equal(m.committed.damage, st.damage)


def test_implex_steps_are_smooth_and_extrapolate_the_last_two():
    """Impl-ex (rkfx.fracture.history): within a step the damage is the extrapolation of the two
    committed steps before it, whatever the iterate, so the residual is smooth and the full
    Jacobian its derivative; the committed state is the implicit update, and a checkpoint
    carries the extrapolation's history."""
    p, m, notch, h = _plate(12, damage_update="impl-ex")
    n = p.num_nodes
    r2 = (p.x**2).sum(axis=1)
    u = np.zeros((n, 2))
    u[:, 1] = 6.0 * ROCK.ft / ROCK.E * p.x[:, 1] * np.exp(-r2 / 0.1)
    P = 1e7 * np.exp(-r2 / 0.02)
    for k, (scale, dt) in enumerate(((0.9, 10.0), (1.0, 10.0))):  # two committed steps, damage growing
        m.start_step(k * dt, dt)
        m.residual(np.r_[scale * u.ravel(), P], 0.0)
        m.commit()
    kappa_n, kappa_before = m.committed.kappa.copy(), m._kappa_before.copy()
    grown = m.committed.damaged & (kappa_n > np.maximum(kappa_before, m.points.kappa0))
    assert grown.sum() > 20
    m.start_step(20.0, 5.0)  # half the last step: half its growth
    x = np.r_[1.05 * u.ravel(), P]
    m.residual(x, 0.0)
    d = m.trial.state.damage
    k_expected = kappa_n + 0.5 * (kappa_n - np.maximum(kappa_before, m.points.kappa0))
    np.testing.assert_allclose(d[grown], dm.damage(k_expected, m.points.kappa0, m.committed.kappa_c)[grown])
    assert np.all(d >= m.committed.damage) and (d[grown] > m.committed.damage[grown]).all()
    # the same damage at another iterate; the Jacobian is the residual's derivative
    k = m.tangent(x, 0.0)
    rng = np.random.default_rng(3)
    v = np.r_[rng.standard_normal(2 * n), np.zeros(n)] * 1e-9
    fd = (m.residual(x + v, 0.0) - m.residual(x - v, 0.0)) / 2
    np.testing.assert_array_equal(m.trial.state.damage, d)
    assert np.linalg.norm(fd - k @ v) < 1e-6 * np.linalg.norm(k @ v)
    # committing takes the implicit update of the last strains; the checkpoint keeps the history
    m.residual(x, 0.0)
    implicit = m.trial_damage(m.strain, tangent_floor=m.residual_fraction).state
    m.commit()
    np.testing.assert_array_equal(m.committed.kappa, implicit.kappa)
    saved = m.state()
    np.testing.assert_array_equal(saved["implex_kappa_before"], kappa_n)
    m._kappa_before = None
    m.restore(saved)
    np.testing.assert_array_equal(m._kappa_before, kappa_n)
    assert m._dt_before == 5.0
    with pytest.raises(InputError, match="damage_update"):
        _plate(6, damage_update="explicit")


def test_bad_rock_is_refused_in_one_line():
    with pytest.raises(InputError, match="alpha = 1 - K / K_s < 0"):
        FracturingRock(2.1e11, 0.3, 3000.0, 1000.0, 0.2, 1e-8, 1e4, 2e9, 1e11, 2.7e3, 2.1e7)
    with pytest.raises(InputError, match="porosity"):
        FracturingRock(1e9, 0.3, 3000.0, 1000.0, 1.2, 1e-8, 1e4, 2e9, 1e11, 2.7e3, 2.1e6)


def test_unknown_jacobian_is_refused():
    p, m, notch, h = _plate(6)
    with pytest.raises(InputError, match="jacobian"):
        HydraulicFractureModel(p, m.rk, m.domains, ROCK, displacements=[Displacement("left")], jacobian="exact")


def test_injected_fluid_is_stored_exactly():
    """Sealed plate (no drained edge): the fluid content int (alpha div u + p / Q) of the
    trapezoidal steps equals the volume injected, int rate dt, to round-off."""
    xs = np.linspace(-0.5, 0.5, 13)
    p, d = graded(xs, xs), grid_domains(xs, xs)
    rk = rk_approximation(p.x, p.spacing, 1.5)
    rock = FracturingRock(1e10, 0.25, 2600.0, 1000.0, 0.2, 1e-8, 1e4, 2e9, 5e10, 100.0, 1e9)  # no damage
    centre = Region(lambda x: np.hypot(x[:, 0], x[:, 1]) < 0.1, "well")
    rate = 2e-6  # m^2/s per second: Q(t) = rate t
    m = HydraulicFractureModel(p, rk, d, rock, displacements=[Displacement(s) for s in SIDES],
                               injection=(centre, lambda t: rate * t))
    times = np.linspace(0.0, 50.0, 11)
    run = integrate(trapezoidal(), m, times)
    x = run.state.x
    content = np.ones(p.num_nodes) @ (m.capacity(5.0)[2 * p.num_nodes:] @ x)
    assert np.isclose(content, 0.5 * rate * times[-1] ** 2, rtol=1e-9)
    assert x[2 * p.num_nodes:].max() > 0
