"""Explicit central differences (eq. 4.35): wave speed, energy, constraints, checkpoints."""
import numpy as np
import pytest

from rkfx.assembly.boundary import boundary_quadrature, traction_load
from rkfx.conditions import Displacement, Traction, Velocity
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.errors import InputError
from rkfx.assembly.smeared_strain import (constraint, dilatational_wave_speed, elastic_force, lumped_mass, max_frequency,
                           smeared_strain, stable_time_step)
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.assembly.operators import stiffness, strain_matrix
from rkfx.geometry.particles import structured
from rkfx.integration.quadrature import scni, smoothed_gradients
from rkfx.approximation.shape_functions import evaluate, rk_approximation
from rkfx.solvers.central_difference import Constraint, ExplicitDynamics, run_explicit
from rkfx.solvers.checkpoint import CHECKPOINT
from rkfx.solvers.checkpoint import load_arrays as load_checkpoint


def setup(p, material, rho=1.0):
    rk = rk_approximation(p.x, p.spacing)
    dom = nodal_domains(p)
    op = smeared_strain(p, rk, dom)
    return rk, dom, op, lumped_mass(dom.area, rho), elastic_force(op, material.D())


def test_smeared_strain_operator_is_the_scni_stiffness():
    p = structured(1.0, 0.7, 12, 9)
    mat = ElasticMaterial(3.0, 0.25)
    rk, dom, op, _, f_int = setup(p, mat)
    d = np.random.default_rng(0).standard_normal(2 * p.num_nodes)
    k = stiffness([scni(p, rk, dom)], mat.D())
    assert np.abs(f_int(d) - k @ d).max() <= 1e-12 * np.abs(k @ d).max()
    assert np.abs(op.strain(d).ravel() - op.B @ d).max() <= 1e-12 * np.abs(d).max() * 20
    assert np.abs(op.BT @ np.ones(3 * p.num_nodes) - op.B.T @ np.ones(3 * p.num_nodes)).max() == 0.0


@pytest.mark.parametrize("cells", ["median-dual", "grid with a slit"])
def test_mscni_operator_from_subcell_rows_is_the_mscni_stiffness(cells):
    """One product with the subcell rows gives the cell strains, the MSCNI differences and,
    transposed, the force of SCNI plus eq. (3.56), on both kinds of nodal domains."""
    from rkfx.approximation.diffraction import cracks
    from rkfx.geometry.grid_cells import grid_domains
    from rkfx.geometry.particles import graded
    from rkfx.integration.quadrature import mscni_stabilization
    if cells == "median-dual":
        p = structured(1.0, 0.7, 12, 9)
        rk, dom = rk_approximation(p.x, p.spacing), nodal_domains(p)
    else:
        xs, ys = np.linspace(0.0, 1.0, 12), np.linspace(0.0, 0.75, 10)
        p = graded(xs, ys)
        slit = ((0.0, 0.375), (0.5, 0.375))
        rk = rk_approximation(p.x, p.spacing, 1.75, cracks=cracks([np.array(slit)], [(False, True)]))
        dom = grid_domains(xs, ys, [slit])
    mat = ElasticMaterial(3.0, 0.25)
    op = smeared_strain(p, rk, dom, eps_p=0.7)
    d = np.random.default_rng(1).standard_normal(2 * p.num_nodes)
    e, diff = op.strains(d)
    assert np.abs(e.ravel() - op.B @ d).max() <= 1e-12 * np.abs(e).max()
    stab = mscni_stabilization(p, rk, dom, eps_p=0.7)
    order = np.argsort(dom.subcell_node, kind="stable")
    reference = (strain_matrix(stab.gradients) @ d).reshape(-1, 3)[order]
    assert np.abs(diff - reference).max() <= 1e-12 * np.abs(reference).max()
    k = stiffness([scni(p, rk, dom), stab], mat.D())
    f = elastic_force(op, mat.D())(d)
    assert np.abs(f - k @ d).max() <= 1e-11 * np.abs(k @ d).max()


def test_lumped_masses_carry_the_total_mass():
    p = structured(2.0, 1.0, 11, 6)
    rk = rk_approximation(p.x, p.spacing)
    dom = nodal_domains(p)
    nodal = lumped_mass(dom.area, 7.0)
    rowsum = lumped_mass(dom.area, 7.0, node_values=smoothed_gradients(p, rk, dom, subcells=False).node_values)
    assert nodal.sum() == pytest.approx(2 * 7.0 * 2.0) and rowsum.sum() == pytest.approx(2 * 7.0 * 2.0)
    with pytest.raises(InputError, match="rho"):
        lumped_mass(dom.area, 0.0)


def test_cfl_time_step_and_stability_margin():
    mat = ElasticMaterial(1.9e11, 0.3)
    rho = 8000.0
    c_d = dilatational_wave_speed(mat, rho)
    assert c_d == pytest.approx(np.sqrt(1.9e11 * 0.7 / (1.3 * 0.4 * 8000.0)))  # (lambda + 2 mu) / rho
    assert dilatational_wave_speed(ElasticMaterial(4.0, 0.0), 1.0) == pytest.approx(2.0)  # sqrt(E / rho)
    h = np.array([3e-3, 1e-3, 2e-3])
    assert stable_time_step(h, mat, rho) == pytest.approx(0.5 * 1e-3 / c_d)
    assert stable_time_step(h, mat, rho, courant=0.9) == pytest.approx(0.9 * 1e-3 / c_d)
    with pytest.raises(InputError, match="Courant"):
        stable_time_step(h, mat, rho, courant=1.5)
    # The CFL step is inside the exact bound 2 / omega_max of the SCNI system, with a margin.
    p = structured(1.0, 1.0, 21, 21)
    _, _, _, m, f_int = setup(p, ElasticMaterial(1.0, 0.3))
    omega = max_frequency(m, f_int)
    dt = stable_time_step(p.spacing, ElasticMaterial(1.0, 0.3), 1.0)
    assert omega * dt < 1.2
    # Beyond 2 / omega_max the scheme blows up, and the driver says so.
    with pytest.raises(InputError, match="blew up"):
        run_explicit(ExplicitDynamics(m, f_int, 2.2 / omega), 2000,
                     v0=np.random.default_rng(0).standard_normal(2 * p.num_nodes))


def _bar(nx=101, ny=5, length=1.0, height=0.04):
    """A strip with nu = 0 between rollers: 1-D waves at c = sqrt(E / rho) = 1."""
    p = structured(length, height, nx, ny)
    mat = ElasticMaterial(1.0, 0.0)
    rk, dom, op, m, f_int = setup(p, mat)
    rollers = constraint(p, rk, [Displacement("bottom", 0.0, (1,)), Displacement("top", 0.0, (1,))])
    return p, mat, rk, dom, m, f_int, rollers


def _arrival(times, signal, level):
    """First time a signal crosses level (linear interpolation between steps)."""
    i = int(np.argmax(signal > level))
    return times[i - 1] + (level - signal[i - 1]) / (signal[i] - signal[i - 1]) * (times[i] - times[i - 1])


@pytest.mark.parametrize("drive", ["velocity", "traction"])
def test_pulse_travels_at_the_bar_wave_speed(drive):
    p, mat, rk, dom, m, f_int, rollers = _bar()
    c = dilatational_wave_speed(mat, 1.0)  # = sqrt(E / rho) = 1 for nu = 0
    dt = stable_time_step(p.spacing, mat, 1.0)
    v0 = 1e-3  # particle velocity behind the front
    if drive == "velocity":
        push = constraint(p, rk, [Velocity("left", v0, (0,))])
        problem = ExplicitDynamics(m, f_int, dt, constraints=[rollers, push])
    else:  # a suddenly applied pressure rho c v0 on the left end
        f = traction_load(p, boundary_quadrature(p, dom, rk),
                          [Traction("left", (c * v0, 0.0))])
        problem = ExplicitDynamics(m, f_int, dt, external_force=lambda t: f, constraints=[rollers])
    probes = np.array([[0.25, 0.02], [0.75, 0.02], [1.0, 0.02]])
    n_probe = evaluate(rk, probes).matrix(0)
    samples = []
    res = run_explicit(problem, int(np.ceil(1.2 / dt)), output_every=1,
                       on_output=lambda s: samples.append((s.time, *(n_probe @ s.v[0::2]))))
    t, vq1, vq3, vend = np.array(samples).T
    # Front speed between two interior probes (half amplitude), and arrival at the free end,
    # where the velocity doubles to 2 v0.
    speed = 0.5 / (_arrival(t, vq3, 0.5 * v0) - _arrival(t, vq1, 0.5 * v0))
    assert speed == pytest.approx(c, rel=0.03)
    assert _arrival(t, vend, v0) == pytest.approx(1.0 / c, rel=0.03)
    assert vend[(t > 1.1) & (t < 1.2)].mean() == pytest.approx(2 * v0, rel=0.05)
    # Rollers hold to round-off; the energy balance closes (input by the constraint or the load).
    assert np.abs(rollers.G @ res.state.d).max() <= 1e-15
    assert res.relative_energy_error() < 1e-3


def test_free_vibration_conserves_energy():
    p = structured(1.0, 1.0, 17, 17)
    mat = ElasticMaterial(1.0, 0.25)
    rk, dom, op, m, f_int = setup(p, mat)
    clamp = constraint(p, rk, [Displacement("left", 0.0)])
    dt = stable_time_step(p.spacing, mat, 1.0)
    x, y = p.x[:, 0], p.x[:, 1]
    v0 = np.column_stack([0.01 * np.sin(np.pi * y) * x, 0.02 * x**2]).ravel()
    # The lowest period is about 9: run about 11 of them (3500 steps).
    res = run_explicit(ExplicitDynamics(m, f_int, dt, constraints=[clamp]), int(100.0 / dt), v0=v0)
    total = res.energy[:, 0] + res.energy[:, 1]
    assert res.energy[:, 1].max() > 0.5 * total[0]  # energy really moves into strain and back
    assert np.abs(total - total[0]).max() < 0.01 * total[0]
    assert res.relative_energy_error() < 0.01
    assert np.abs(clamp.G @ res.state.d).max() <= 1e-15


def _history_problem(p, mat):
    """Elastic force softened by a history variable updated in place (a damage stand-in)."""
    _, _, op, m, _ = setup(p, mat)
    kappa = np.zeros(p.num_nodes)
    dm = mat.D()

    def f_int(d):
        e = op.strain(d)
        np.maximum(kappa, np.abs(e).max(axis=1), out=kappa)
        return op.force((e @ dm.T) / (1.0 + 50.0 * kappa[:, None]))
    return m, f_int, kappa


def test_checkpoint_resume_reaches_the_identical_state(tmp_path):
    p = structured(1.0, 0.5, 13, 7)
    mat = ElasticMaterial(1.0, 0.3)
    rk = rk_approximation(p.x, p.spacing)
    clamp = constraint(p, rk, [Displacement("left", 0.0)])
    pull = constraint(p, rk, [Velocity("right", 0.05, (0,))])
    dt = stable_time_step(p.spacing, mat, 1.0)
    n_steps = 60

    m, f_int, kappa = _history_problem(p, mat)
    straight = run_explicit(ExplicitDynamics(m, f_int, dt, constraints=[clamp, pull]), n_steps)
    kappa_straight = kappa.copy()
    assert kappa_straight.max() > 0

    # Crash at step 47 with checkpoints every 20 steps: the last checkpoint is step 40.
    m, f_int, kappa = _history_problem(p, mat)
    calls = [0]

    def crashing(d):
        calls[0] += 1
        if calls[0] > 47:  # call 0 is the initial state
            raise KeyboardInterrupt
        return f_int(d)
    with pytest.raises(KeyboardInterrupt):
        run_explicit(ExplicitDynamics(m, crashing, dt, constraints=[clamp, pull]), n_steps,
                     extra_state={"kappa": kappa}, checkpoint_every=20, checkpoint_dir=tmp_path)
    assert not (tmp_path / (CHECKPOINT + ".tmp")).exists()
    assert int(load_checkpoint(tmp_path)["step"]) == 40

    # A fresh process would rebuild the problem and resume: the history array is restored
    # in place from the checkpoint, not kept from the crashed run.
    m, f_int, kappa = _history_problem(p, mat)
    resumed = run_explicit(ExplicitDynamics(m, f_int, dt, constraints=[clamp, pull]), n_steps,
                           extra_state={"kappa": kappa}, resume=tmp_path)
    assert resumed.resumed_from == 40
    for name in ("d", "v", "a", "f_int", "f_ext", "energy"):
        assert np.array_equal(getattr(straight.state, name), getattr(resumed.state, name)), name
    assert np.array_equal(kappa, kappa_straight)
    assert np.array_equal(straight.energy, resumed.energy) and np.array_equal(straight.time, resumed.time)

    with pytest.raises(InputError, match="dt"):
        run_explicit(ExplicitDynamics(m, f_int, 0.5 * dt), n_steps, resume=tmp_path)
    with pytest.raises(InputError, match="extra state"):
        run_explicit(ExplicitDynamics(m, f_int, dt), n_steps, extra_state={"damage": kappa}, resume=tmp_path)


def test_prescribed_displacement_history_is_met_exactly():
    p = structured(1.0, 0.25, 21, 6)
    mat = ElasticMaterial(1.0, 0.2)
    rk, dom, op, m, f_int = setup(p, mat)
    dt = stable_time_step(p.spacing, mat, 1.0)
    g = constraint(p, rk, [Displacement("left", 0.0),
                           Displacement("right", lambda x, t: np.full(len(x), 1e-3 * np.sin(2.0 * t)), (0,))])
    snaps = run_explicit(ExplicitDynamics(m, f_int, dt, constraints=[g]), 150, output_every=50).snapshots
    for step, t, d, v in snaps:
        assert np.abs(g.G @ d - g.displacement(t)).max() <= 1e-15
        assert np.abs(g.G @ v - 2e-3 * np.cos(2.0 * t) * (g.displacement(1.0) != 0)).max() < 1e-6
    with pytest.raises(InputError, match="all of one kind, got Displacement, Velocity; build one"):
        constraint(p, rk, [Displacement("left", 0.0), Velocity("right", 1.0, (0,))])
    with pytest.raises(InputError, match="Displacement or Velocity conditions, all of one kind, got Traction"):
        constraint(p, rk, [Traction("right", (1.0, 0.0))])
    dep = Constraint(g.G[[0, 0]])
    with pytest.raises(InputError, match="dependent"):
        run_explicit(ExplicitDynamics(m, f_int, dt, constraints=[dep]), 1)
