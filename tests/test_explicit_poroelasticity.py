"""Explicit u-p dynamics on nodal integration: a laterally confined column under a step load on
its drained top (the set-up of §6.4.1). Before the fast wave returns from the top, the base sees
twice the undrained pressure jump alpha Q q / M_u (the fixed impermeable base reflects it), and
nothing arrives there before L / c_fast."""
import numpy as np
import pytest

from rkfx.approximation.semi_lagrangian import evaluate_moving, moving_rk
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import structured
from rkfx.integration.nodal_stabilized import boundary_rule, nodal_cells, nodal_integration
from rkfx.models.explicit_poroelasticity import Constituents, ExplicitPoroDynamics, collocation_rows
from rkfx.solvers.central_difference import Constraint
from rkfx.solvers.explicit_up import ExplicitUP, stable_steps

SOARES = Constituents(E=254423076.9, nu=0.298, rho_s=2700.0, rho_f=1000.0, porosity=0.48, k=3.55e-9,
                      K_s=1.1e10, K_f=3.3e9)
L, Q_LOAD = 10.0, 3000.0


def _column(ny, rule):
    h = L / (ny - 1)
    p = structured(2 * h, L, 3, ny)
    cells = nodal_cells(p.x, nodal_domains(p).area)
    rk = moving_rk(p.x, 2.0 * h, 0.5 * h, reach=cells.reach)
    r = nodal_integration(rk, cells, boundary_rule(p.x, p.boundary_edges), rule)
    x, n = p.x, p.num_nodes
    size = 3 * n
    bottom = np.flatnonzero(x[:, 1] < 1e-9)
    top = np.flatnonzero(x[:, 1] > L - 1e-9)
    sides = np.flatnonzero((x[:, 0] < 1e-9) | (x[:, 0] > 2 * h - 1e-9))
    essential = [Constraint(collocation_rows(rk, bottom, 1, n, 0, size)),      # u_y = 0 at the base
                 Constraint(collocation_rows(rk, sides, 0, n, 0, size)),       # rollers
                 Constraint(collocation_rows(rk, top, None, n, 2 * n, size))]  # drained top
    top_edges = p.boundary_edges[np.all(x[p.boundary_edges][:, :, 1] > L - 1e-9, axis=1)]
    tb = boundary_rule(x, top_edges)
    f = np.zeros(size)
    f[1:2 * n:2] = evaluate_moving(rk, tb.points, tb.owner).matrix().T @ (-Q_LOAD * np.abs(tb.normal_length[:, 1]))
    return ExplicitPoroDynamics(r, SOARES, essential, load=lambda t: f), top[0], bottom[0], n


def test_the_base_sees_twice_the_undrained_pressure_after_the_fast_wave():
    model, i_top, i_bot, n = _column(121, "nsni")
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
    # The top goes down until the wave reflected at the base returns (2 L / c_fast).
    before = t < 1.9 * L / c_fast
    assert np.all(np.diff(run.samples[before, 1]) <= 1e-12)
    assert run.samples[before, 1][-1] < 0


def test_incompressible_constituents_are_refused():
    with pytest.raises(InputError, match="porosity"):
        Constituents(1e8, 0.3, 2700.0, 1000.0, 1.2, 1e-9, 1e10, 3e9)
