"""The damage particle method's explicit internal force: kernels against the reference damage
code, particle tracking (4.22), the history arrays and their checkpoints."""
import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.fracture import damage as dm
from rkfx.fracture.tracking import tracking
from rkfx.assembly.smeared_strain import elastic_force, smeared_strain
from rkfx.models.damage_dynamics import DamageForce, damage_field
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.particles import graded
from rkfx.approximation.shape_functions import rk_approximation

MATERIAL = dm.DamageMaterial(E=1.0e4, nu=0.25, ft=1.0, GF=0.05, plane="strain")


@pytest.fixture(scope="module")
def square():
    xs = ys = np.linspace(0.0, 1.0, 11)
    p = graded(xs, ys)
    domains = grid_domains(xs, ys)
    op = smeared_strain(p, rk_approximation(p.x, p.spacing, 1.75), domains)
    model = dm.damage_model(MATERIAL, domains.area, geometry=dm.cell_geometry(domains))
    return p, op, model


def test_stress_and_damage_match_the_reference_update(square):
    """Every particle allowed: the compiled kernels give rkfx.fracture.damage.update's stress, damage,
    normals and kappa_c (4.2), (4.6), (4.28) for an inhomogeneous strain history."""
    p, op, model = square
    field = damage_field(model)  # no tracking: all allowed
    force = DamageForce(op, model, field)
    state = dm.initial_state(model)
    rng = np.random.default_rng(3)
    d = np.zeros(2 * p.num_nodes)
    for _ in range(6):
        d += 2e-6 * rng.standard_normal(2 * p.num_nodes)
        d[0::2] += 3e-5 * p.x[:, 0] ** 2  # eps_xx grows with x: damage on part of the square
        force(d)
        ref = dm.update(model, state, op.strain(d), tangent=False)
        state = ref.state
        np.testing.assert_allclose(force.stress, ref.stress, rtol=1e-12, atol=1e-12 * np.abs(ref.stress).max())
        np.testing.assert_allclose(field.damage, ref.state.damage, atol=1e-13)
        np.testing.assert_array_equal(field.damaged, ref.state.damaged)
    assert 0 < field.damaged.sum() < p.num_nodes, "the test must see partial damage"
    np.testing.assert_allclose(field.kappa_c[field.damaged], state.kappa_c[state.damaged], rtol=1e-12)
    np.testing.assert_allclose(np.abs(field.normal[field.damaged]), np.abs(state.normal[state.damaged]), atol=1e-12)
    assert np.isclose(field.dissipated(model), state.dissipated.sum(), rtol=1e-10)
    np.testing.assert_allclose(field.dissipation(model), state.dissipated, rtol=1e-10, atol=1e-14)


def test_only_allowed_particles_initiate(square):
    """Tracking: a uniform tension beyond the threshold damages the seeds and the particles
    the seeds' cracks make candidates, not the rest."""
    p, op, model = square
    seed = int(np.argmin(np.linalg.norm(p.x - [0.5, 0.5], axis=1)))
    track = tracking(p.x, p.spacing, 0.3, seeds=np.array([seed]), radius=1.5)
    field = damage_field(model, track, dt=1e-3)
    force = DamageForce(op, model, field, track, dt=1e-3)
    force(np.zeros(2 * p.num_nodes))
    d = np.zeros(2 * p.num_nodes)
    d[1::2] = 1.2 * MATERIAL.kappa0 * p.x[:, 1]  # eps_yy = 1.2 kappa0: crack normal along y
    force(d)
    assert np.flatnonzero(field.damaged).tolist() == [seed]
    assert field.initiation_time[seed] == pytest.approx(1e-3)
    np.testing.assert_allclose(np.abs(field.normal[seed]), [0.0, 1.0], atol=1e-9)
    # Its horizontal neighbours (1.5 h: left and right, not the diagonals) are candidates now.
    allowed = np.flatnonzero(field.allowed)
    assert sorted(np.round((p.x[allowed] - p.x[seed]) / 0.1).astype(int).tolist()) == [[-1, 0], [0, 0], [1, 0]]
    assert field.parent[allowed].tolist() == [seed, -1, seed]
    force(d)
    assert field.damaged.sum() == 3
    # The new crack tips grow away from the seed: the next candidates lie outside, not back.
    assert sorted(np.round((p.x[field.allowed] - p.x[seed]) / 0.1).astype(int)[:, 0].tolist()) == [-2, -1, 0, 1, 2]
    # Without tracking every particle past its threshold initiates at once.
    free = damage_field(model)
    DamageForce(op, model, free)(d)
    assert free.damaged.sum() > 100


def test_history_arrays_are_named_views(square):
    _, _, model = square
    field = damage_field(model, dt=2.0)
    arrays = field.arrays
    assert set(arrays) == {"kappa", "damage", "normal", "kappa_c", "chord", "damaged", "allowed",
                           "initiation_time", "parent", "clock"}
    arrays["kappa"][0] = 7.0
    assert field.kappa[0] == 7.0
    assert field.clock[0] == -2.0  # the evaluation of the initial state reads t = 0


def test_mscni_terms_stiffen_the_checkerboard_not_the_smooth_modes():
    """Plain SCNI on a grid barely sees a checkerboard u_x = (-1)^(i+j): its strain energy per
    unit norm is that of a smooth half sine (measured 469 vs 430), so explicit dynamics and
    damage can feed on it. The MSCNI terms (eps_p = 1) raise it ~4.6x and leave the smooth
    mode alone."""
    n = 17
    xs = ys = np.linspace(0.0, 1.0, n)
    p = graded(xs, ys)
    rk = rk_approximation(p.x, p.spacing, 1.75)
    i, j = np.arange(n ** 2) % n, np.arange(n ** 2) // n
    checker, smooth = np.zeros(2 * n * n), np.zeros(2 * n * n)
    checker[0::2] = (-1.0) ** (i + j)
    smooth[0::2] = np.sin(np.pi * xs[i])
    energy = {}
    for eps_p in (0.0, 1.0):
        f = elastic_force(smeared_strain(p, rk, grid_domains(xs, ys), eps_p), MATERIAL.elasticity())
        energy[eps_p] = [v @ f(v) / (v @ v) for v in (checker, smooth)]
    assert energy[0.0][0] < 1.5 * energy[0.0][1]
    assert energy[1.0][0] > 4.0 * energy[1.0][1]
    assert abs(energy[1.0][1] / energy[0.0][1] - 1) < 0.01


def test_failed_particles_lose_their_stabilization(square):
    """Under damage the MSCNI terms carry (1 - D_L): a fully failed particle adds nothing."""
    p, _, model = square
    xs = ys = np.linspace(0.0, 1.0, 11)
    op = smeared_strain(p, rk_approximation(p.x, p.spacing, 1.75), grid_domains(xs, ys), 1.0)
    field = damage_field(model)
    force = DamageForce(op, model, field)
    rng = np.random.default_rng(0)
    d = 1e-6 * rng.standard_normal(2 * p.num_nodes)
    field.damaged[:] = True
    field.kappa[:] = 1.0
    field.kappa_c[:] = 0.5  # kappa >= kappa_c: D = 1 everywhere once evaluated
    field.allowed[:] = True
    assert np.allclose(force(d), 0.0, atol=1e-30)
    assert np.all(field.damage == 1.0)


def test_a_residual_stiffness_keeps_that_share_of_a_failed_particles_force(square):
    """residual eta: a failed particle (D = 1) carries eta C e, subcell terms included, so the
    force of a fully failed square is eta times the elastic one; eta = 0 is the law (4.30)."""
    from dataclasses import replace  # noqa: PLC0415

    p, _, model = square
    xs = ys = np.linspace(0.0, 1.0, 11)
    op = smeared_strain(p, rk_approximation(p.x, p.spacing, 1.75), grid_domains(xs, ys), 1.0)
    d = 1e-6 * np.random.default_rng(1).standard_normal(2 * p.num_nodes)
    elastic = elastic_force(op, MATERIAL.elasticity())(d)
    for eta in (0.0, 1e-2):
        kept = replace(model, residual=eta)
        field = damage_field(kept)
        field.damaged[:] = field.allowed[:] = True
        field.kappa[:], field.kappa_c[:] = 1.0, 0.5  # D = 1 everywhere
        assert np.allclose(DamageForce(op, kept, field)(d), eta * elastic, rtol=1e-12, atol=1e-30)
        assert np.all(field.damage == 1.0)  # the history is the law's


@pytest.mark.parametrize("eta", [-0.1, 1.0, float("nan")])
def test_a_residual_stiffness_outside_0_1_is_refused_in_one_line(square, eta):
    from dataclasses import replace  # noqa: PLC0415

    with pytest.raises(InputError, match="residual stiffness") as e:
        replace(square[2], residual=eta)
    assert "\n" not in str(e.value)
