"""The Drucker-Prager solid on moving particles: free fall, a block at rest on a floor, a torn-off
particle, checkpoints, walls and bad input."""
import numpy as np
import pytest

from rkfx.assembly.rigid_walls import Wall, wall_forces
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import structured
from rkfx.materials.drucker_prager import DruckerPrager
from rkfx.models.lagrangian_plasticity import LagrangianPlasticity
from rkfx.solvers.central_difference import CentralDifference

SAND = DruckerPrager(E=1e6, nu=0.3, phi=30.0, c=0.0)
RHO, G = 2000.0, 9.81


def _block(nx=9, ny=9, width=0.08, height=0.08, soil=SAND, rule="nsni", walls=(), stress=None, dt=None, **kw):
    p = structured(width, height, nx, ny)
    h = width / (nx - 1)
    c = np.sqrt((soil.bulk_modulus + 4 * soil.shear_modulus / 3) / RHO)
    dt = 0.3 * h / c if dt is None else dt
    model = LagrangianPlasticity(p.x, nodal_domains(p).area, 2.0 * h, p.boundary_edges, soil, RHO, dt, rule=rule,
                                 walls=walls, stress=stress, gravity=(0.0, -G), **kw)
    return p, model, dt


def test_free_fall_is_exact_and_strain_free():
    p, model, dt = _block()
    n = 200
    CentralDifference(dt).run(model, n)
    t = n * dt
    assert np.allclose(model.x[:, 1], p.x[:, 1] - 0.5 * G * t * t, rtol=0, atol=1e-12)
    assert np.allclose(model.x[:, 0], p.x[:, 0], rtol=0, atol=1e-12)
    assert np.abs(model.stress).max() < 1e-6 and model.plastic_strain.max() < 1e-12


def _geostatic(p, height, k0):
    sy = -RHO * G * (height - p.x[:, 1])
    return np.column_stack([k0 * sy, sy, k0 * sy, 0.0 * sy])


@pytest.mark.parametrize("rule", ["nsni", "snni-vc", "dni"])
def test_confined_block_at_rest_stays_at_rest(rule):
    """Geostatic stress between smooth side walls on a rough floor: nothing moves (beyond the
    wall springs taking the weight) and nothing yields (a little cohesion holds the unconfined
    top, where a cohesionless soil sits at the apex of its cone)."""
    width = height = 0.08
    p = structured(width, height, 9, 9)
    k0 = SAND.nu / (1 - SAND.nu)
    stress = _geostatic(p, height, k0)
    walls = [Wall((0, 0), (0, 1), 0.5, "floor"), Wall((0, 0), (1, 0), 0.0, "left"),
             Wall((width, 0), (-1, 0), 0.0, "right")]
    soil = DruckerPrager(E=SAND.E, nu=SAND.nu, phi=SAND.phi, c=2e3)
    _, model, dt = _block(soil=soil, rule=rule, walls=walls, stress=stress)
    run = CentralDifference(dt).run(model, 400)
    drop = np.abs(model.x - p.x).max()
    # the floor's springs carry the weight at a penetration g H dt^2 / (kappa h) ~ 1e-5 m, and the
    # block rings about it
    assert drop < 1e-3 * height, drop
    assert model.plastic_strain.max() == 0.0
    assert np.abs(run.state.v).max() < 0.1 * G * run.state.time  # elastic ringing, far from a fall


def test_unsupported_slope_collapses_and_yields():
    """A cohesionless block released on one side slumps: it yields and spreads."""
    width = height = 0.08
    p = structured(width, height, 9, 9)
    stress = _geostatic(p, height, 1 - np.sin(np.radians(SAND.phi)))
    walls = [Wall((0, 0), (0, 1), 0.5, "floor"), Wall((0, 0), (1, 0), 0.0, "left")]
    _, model, dt = _block(walls=walls, stress=stress)
    CentralDifference(dt).run(model, 600)
    assert model.x[:, 0].max() > width + 0.002
    assert model.plastic_strain.max() > 0.01
    assert model.neighbour_rebuilds["steps"] == 600


def test_torn_off_particle_flies_free():
    """A particle far from the rest has a Shepard row and falls like a stone."""
    p, model, dt = _block(nx=5, ny=5)
    x = np.vstack([p.x, [[1.0, 1.0]]])
    area = np.append(nodal_domains(p).area, 4e-4)
    h = 0.02
    boundary = p.boundary_edges
    lone = LagrangianPlasticity(x, area, 2.0 * h, boundary, SAND, RHO, dt, rule="nsni", gravity=(0.0, -G))
    CentralDifference(dt).run(lone, 50)
    t = 50 * dt
    assert abs(lone.x[-1, 1] - (1.0 - 0.5 * G * t * t)) < 1e-12
    assert lone.neighbour_rebuilds["torn_point_evaluations"] > 0


def test_resume_continues_the_run(tmp_path):
    width = height = 0.08
    p = structured(width, height, 7, 7)
    stress = _geostatic(p, height, 0.5)
    walls = [Wall((0, 0), (0, 1), 0.5, "floor"), Wall((0, 0), (1, 0), 0.0, "left")]
    _, whole, dt = _block(7, 7, walls=walls, stress=stress)
    a = CentralDifference(dt).run(whole, 120)
    _, first, _ = _block(7, 7, walls=walls, stress=stress)
    CentralDifference(dt).run(first, 60, checkpoint_every=60, checkpoint_dir=tmp_path)
    _, second, _ = _block(7, 7, walls=walls, stress=stress)
    b = CentralDifference(dt).run(second, 120, resume=tmp_path)
    assert b.resumed_from == 60
    assert np.allclose(b.state.d, a.state.d, rtol=0, atol=1e-14)
    assert np.allclose(second.x, whole.x, rtol=0, atol=1e-14)


def test_a_checkpoint_without_sheet_counts_restores():
    """States written before sheet rows were counted hold a one-element counter."""
    _, model, _ = _block(5, 5)
    arrays = dict(model.state()) | {"torn": np.array([7], np.int64)}
    model.restore(arrays)
    counts = model.neighbour_rebuilds
    assert (counts["torn_point_evaluations"], counts["sheet_point_evaluations"]) == (7, 0)


def test_wall_friction_caps_at_coulomb():
    floor = Wall((0, 0), (0, 1), 0.5, "floor")
    x = np.array([[0.0, -1e-4], [0.0, -1e-4], [0.0, 1e-3]])
    du = np.array([[1e-3, 0.0], [1e-9, 0.0], [1.0, 0.0]])
    m, dt = np.ones(3), 1e-3
    c = wall_forces([floor], x, du, m, dt)
    fn = 0.1 * 1e-4 / dt ** 2
    assert np.allclose(c.force[:, 1], [fn, fn, 0.0])
    assert np.isclose(c.force[0, 0], -0.5 * fn) and c.sliding[0]
    assert np.isclose(c.force[1, 0], -1e-9 / dt ** 2) and not c.sliding[1]
    assert list(c.touching) == [True, True, False]


def test_bad_input_is_named():
    p = structured(0.04, 0.04, 3, 3)
    area = nodal_domains(p).area
    with pytest.raises(InputError, match="unknown nodal integration rule"):
        LagrangianPlasticity(p.x, area, 0.04, p.boundary_edges, SAND, RHO, 1e-5, rule="gauss")
    with pytest.raises(InputError, match="density"):
        LagrangianPlasticity(p.x, area, 0.04, p.boundary_edges, SAND, -1.0, 1e-5)
    with pytest.raises(InputError, match="volume"):
        LagrangianPlasticity(p.x, 0 * area, 0.04, p.boundary_edges, SAND, RHO, 1e-5)
    with pytest.raises(InputError, match="normal"):
        Wall((0, 0), (0, 0))
    with pytest.raises(InputError, match="friction"):
        Wall((0, 0), (0, 1), -0.1)


@pytest.mark.parametrize("viscous", [{"viscosity": 0.2}, {"eta": 100.0}])
def test_viscosity_damps_the_ringing(viscous):
    """The artificial viscosity (beta rho c h, here 104 Pa s inside) and a fixed one each take
    energy out of an elastic block bouncing on the floor."""
    soil = DruckerPrager(E=SAND.E, nu=SAND.nu, phi=SAND.phi, c=2e3)
    walls = [Wall((0, 0), (0, 1), 0.5, "floor")]
    ke = []
    for kw in ({}, viscous):
        _, model, dt = _block(soil=soil, walls=walls, **kw)
        run = CentralDifference(dt).run(model, 400)
        ke.append(run.state.energies()["kinetic"])
    assert ke[1] < 0.5 * ke[0], ke


def test_viscosity_bad_input():
    with pytest.raises(InputError, match="viscosity"):
        _block(viscosity=-1.0)
    with pytest.raises(InputError, match="eta"):
        _block(eta=np.nan)
    # a fixed viscosity beyond the explicit step's limit at the corner particles
    _block(eta=300.0)
    with pytest.raises(InputError, match="explicit limit of elasticity and viscosity"):
        _block(eta=600.0)


def test_the_step_limit_takes_elasticity_and_viscosity_together():
    """Without viscosity a step of about h / c is the limit; a viscosity within its own limit
    2 rho V / eta still lowers it (the damped oscillator's (2 / omega)(sqrt(1 + xi^2) - xi))."""
    p, model, dt = _block()
    h = 0.08 / 8
    c = np.sqrt((SAND.bulk_modulus + 4 * SAND.shear_modulus / 3) / RHO)
    assert 0.9 * h / c < model.stable_step < 1.2 * h / c
    with pytest.raises(InputError, match="explicit limit"):
        _block(dt=1.3 * h / c)
    small = (nodal_domains(p).area / model.max_dilation).min()
    eta = 0.5 * 2 * RHO * small / (0.9 * h / c)  # dt = 0.9 h / c is half of the viscous limit alone
    with pytest.raises(InputError, match="explicit limit"):
        _block(dt=0.9 * h / c, eta=eta)


@pytest.mark.parametrize("rule", ["nsni", "dni"])
@pytest.mark.parametrize("viscosity, eta", [(0.0, 0.0), (0.3, 0.0), (0.0, 50.0)])
def test_the_step_limit_is_where_the_step_becomes_unstable(rule, viscosity, eta):
    """The limit is measured on the rows, not estimated: a free elastic block excited by a small
    random stress rings within its amplitude at 0.97 of ``stable_step`` and blows up at 1.03
    (no dilation bound to allow for, so the limit is that of the initial rows)."""
    p = structured(0.08, 0.08, 9, 9)
    h = 0.01
    soil = DruckerPrager(E=1e6, nu=0.3, phi=30.0, c=1e6)  # stays elastic
    stress = 1e-3 * np.random.default_rng(1).standard_normal((81, 4))
    stress[:, 2] = 0.0

    def block(dt):
        return LagrangianPlasticity(p.x, nodal_domains(p).area, 2 * h, p.boundary_edges, soil, RHO, dt, rule=rule,
                                    stress=stress, gravity=(0.0, 0.0), max_dilation=1.000001, viscosity=viscosity,
                                    eta=eta)

    limit = block(1e-9).stable_step
    stable = block(0.97 * limit)
    CentralDifference(0.97 * limit).run(stable, 300)
    assert np.abs(stable.x - p.x).max() < 1e-8
    beyond = block(limit)
    beyond.dt = 1.03 * limit  # beyond the limit, which the constructor refuses
    with pytest.raises(InputError, match="turned inside out"):
        CentralDifference(1.03 * limit).run(beyond, 300)
