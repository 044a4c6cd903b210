"""Explicit u-p dynamics on nodal integration: a laterally confined column under a step load on
its drained top (the set-up of §6.4.1). Before the fast wave returns from the top, the base sees
twice the undrained pressure jump alpha Q q / M_u (the fixed impermeable base reflects it), and
nothing arrives there before L / c_fast."""
import numpy as np
import pytest

from rkfx.cases._confined_column import SOARES, confined_column
from rkfx.errors import InputError
from rkfx.models.explicit_poroelasticity import Constituents
from rkfx.solvers.explicit_up import ExplicitUP, stable_steps

L, Q_LOAD = 10.0, 3000.0


@pytest.mark.parametrize("fpp", [False, True])
def test_the_base_sees_twice_the_undrained_pressure_after_the_fast_wave(fpp):
    """With or without the fluid pressure projection in the storage rows."""
    model, i_top, i_bot, _ = confined_column(121, "nsni", height=L, load=Q_LOAD, fpp=fpp)
    n = model.layout.field("p").nodes
    limits = stable_steps(model)
    assert limits["governs"] == "wave"
    mat = SOARES.material
    m_u = mat.elastic.constrained_modulus + mat.alpha ** 2 / mat.S
    c_fast = np.sqrt(m_u / SOARES.density)
    p_undrained = mat.alpha / mat.S * Q_LOAD / m_u
    assert p_undrained == pytest.approx(2864.7, rel=1e-3)
    t_end = 2.5 * L / c_fast
    steps = int(np.ceil(t_end / (0.5 * limits["wave"])))
    run = ExplicitUP(t_end / steps).run(model, steps, record=lambda x, r, t: [x[2 * n + i_bot], x[2 * i_top + 1]])
    t, p_base = run.times, run.samples[:, 0]
    assert np.abs(p_base[t < 0.8 * L / c_fast]).max() < 0.02 * p_undrained
    behind = (t > 1.3 * L / c_fast) & (t < 2.4 * L / c_fast)
    assert np.mean(p_base[behind]) == pytest.approx(2 * p_undrained, rel=0.03)
    # The top goes down until the wave reflected at the base returns (2 L / c_fast); with the
    # projection (which slows the pressure's response to the skeleton) it rings on the way.
    before = t < 1.9 * L / c_fast
    rise = np.diff(run.samples[before, 1]).max()
    assert rise <= (1e-3 * abs(run.samples[before, 1][-1]) if fpp else 1e-12), rise
    assert run.samples[before, 1][-1] < 0


def test_incompressible_constituents_are_refused():
    with pytest.raises(InputError, match="porosity"):
        Constituents(1e8, 0.3, 2700.0, 1000.0, 1.2, 1e-9, 1e10, 3e9)


def test_the_contributions_of_a_split_of_the_points_add_up_to_the_whole_model():
    """What the MPI ranks rely on (each integrates over its own nodes' cells and the stepper adds
    the contributions): masses, forces and fluxes of the models on two halves of the points sum
    to the whole model's."""
    from rkfx.cases._confined_column import column_discretization
    from rkfx.integration.nodal_stabilized import boundary_rule, nodal_cells, nodal_integration
    from rkfx.models.explicit_poroelasticity import ExplicitPoroDynamics

    d = column_discretization(0.2, 2.0, 3, 21, "nsni")
    p = d.particles
    whole = ExplicitPoroDynamics(d.rule, SOARES)
    cells = nodal_cells(p.x, d.rule.weights)
    parts = [ExplicitPoroDynamics(nodal_integration(d.rk, cells, boundary_rule(p.x, p.boundary_edges), "nsni",
                                                    points=h), SOARES)
             for h in np.array_split(np.arange(p.num_nodes), 2)]
    rng = np.random.default_rng(1)
    u, v, q = rng.standard_normal(2 * p.num_nodes), rng.standard_normal(2 * p.num_nodes), rng.standard_normal(p.num_nodes)
    for name, call in [("mass", lambda m: m.lumped_mass()), ("solid", lambda m: m.solid_force(u, q)),
                       ("fluid", lambda m: m.fluid_flux(v, q))]:
        a = call(whole)
        assert np.abs(sum(call(m) for m in parts) - a).max() <= 1e-12 * np.abs(a).max(), name


@pytest.mark.parametrize("rule", ["nsni", "dni"])
def test_the_pressure_projection_is_positive_zero_on_constants_and_sums_the_moments(rule):
    """S of (6.49) on the rule's cells: symmetric, positive semi-definite, zero on a constant
    pressure, and on the linear pressure p = y (RK coefficients y_I) its energy is
    sum_L eps_L m_Ly (the gradient rows reproduce grad y); the parts of a split of the points
    add up to it (what the MPI ranks rely on)."""
    from rkfx.assembly.nodal_forms import pressure_projection
    from rkfx.cases._confined_column import column_discretization
    from rkfx.integration.nodal_stabilized import boundary_rule, nodal_cells, nodal_integration

    d = column_discretization(0.2, 2.0, 3, 21, rule)
    x, r = d.particles.x, d.rule
    eps = np.random.default_rng(2).uniform(1.0, 2.0, len(x))
    S = pressure_projection(r, eps).toarray()
    assert np.abs(S - S.T).max() <= 1e-12 * np.abs(S).max()
    assert np.linalg.eigvalsh(S).min() >= -1e-12 * np.abs(S).max()
    assert np.abs(S @ np.ones(len(x))).max() <= 1e-12 * np.abs(S).max()
    m_y = r.weights ** 2 / 12 if r.moments is None else r.moments[:, 1]
    assert x[:, 1] @ S @ x[:, 1] == pytest.approx(np.sum(eps * m_y), rel=1e-12)
    cells = nodal_cells(x, r.weights)
    halves = np.array_split(np.arange(len(x)), 2)
    parts = [pressure_projection(nodal_integration(d.rk, cells, boundary_rule(x, d.particles.boundary_edges), rule,
                                                   points=h), eps[h]) for h in halves]
    assert np.abs((parts[0] + parts[1]).toarray() - S).max() <= 1e-12 * np.abs(S).max()
