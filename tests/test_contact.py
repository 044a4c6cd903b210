"""Frictional contact on a pre-existing fracture (rkfx.fracture.contact, eqs. 5.38-5.39).

The law is checked point-wise (states, return mapping, derivatives); the interface on a square
cut through by a fracture at 45 degrees, with SCNI and the faces' own quadrature, reproduces
exactly the displacement that is linear on each side and jumps by what the law balances: stick,
slip at the friction limit, and an open fracture loaded by fluid pressure.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from rkfx.approximation.shape_functions import evaluate, rk_approximation
from rkfx.conditions import Displacement
from rkfx.errors import InputError
from rkfx.fracture.contact import OPEN, SLIP, STICK, FractureContact, FrictionalContact, interface, respond
from rkfx.geometry.cells import nodal_cells
from rkfx.geometry.particles import cut_triangulation, structured
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import elastic_terms

LAW = FrictionalContact(k_N=1e3, k_T=5e2, mu=0.7)


def test_law_states_and_return_mapping():
    g_n = np.array([1e-3, -1e-3, -1e-3, -1e-3])
    g_t = np.array([5e-3, 1e-4, 5e-3, -5e-3])
    r = respond(LAW, g_n, g_t, np.zeros(4))
    np.testing.assert_array_equal(r.status, [OPEN, STICK, SLIP, SLIP])
    np.testing.assert_allclose(r.pressure, [0, 1.0, 1.0, 1.0])
    np.testing.assert_allclose(r.shear, [0, 0.05, 0.7, -0.7])
    # the slip leaves exactly the stick shear the friction allows; an open point forgets its shear
    np.testing.assert_allclose(r.slip, [5e-3, 0, 5e-3 - 0.7 / 5e2, -5e-3 + 0.7 / 5e2])
    # from the new slip the same jump sticks at the limit
    again = respond(LAW, g_n[2:], g_t[2:], r.slip[2:])
    np.testing.assert_allclose(again.shear, [0.7, -0.7])


def test_touching_faces_stick_and_a_point_at_the_limit_slides():
    # zero aperture is contact: the penalties act (Newton from an unloaded fracture has them)
    r = respond(LAW, np.zeros(1), np.zeros(1), np.zeros(1))
    assert r.status[0] == STICK and r.d_pressure[0] == -LAW.k_N and r.d_shear_slip[0] == LAW.k_T
    # a slip returned to the limit is still sliding at the committed state, whatever the round-off
    g_n, g_t = np.array([-1e-3, -1e-3]), np.array([5e-3, -5e-3])
    slipped = respond(LAW, g_n, g_t, np.zeros(2)).slip
    for wobble in (0.0, 1e-15, -1e-15):
        again = respond(LAW, g_n, g_t + wobble, slipped)
        np.testing.assert_array_equal(again.status, [SLIP, SLIP])
        np.testing.assert_allclose(again.shear, [0.7, -0.7])
    # unloading from there sticks
    back = respond(LAW, g_n, g_t - np.sign(g_t) * 1e-4, slipped)
    np.testing.assert_array_equal(back.status, [STICK, STICK])


@pytest.mark.parametrize("g_t", [1e-4, 4e-3, -4e-3])
def test_law_derivatives_match_differences(g_t):
    g_n, s, d = np.array([-1e-3]), np.array([2e-4]), 1e-9
    r = respond(LAW, g_n, np.array([g_t]), s)
    up_n, dn_n = respond(LAW, g_n + d, np.array([g_t]), s), respond(LAW, g_n - d, np.array([g_t]), s)
    up_t, dn_t = respond(LAW, g_n, np.array([g_t + d]), s), respond(LAW, g_n, np.array([g_t - d]), s)
    np.testing.assert_allclose(r.d_pressure, (up_n.pressure - dn_n.pressure) / (2 * d), rtol=1e-6)
    np.testing.assert_allclose(r.d_shear_normal, (up_n.shear - dn_n.shear) / (2 * d), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(r.d_shear_slip, (up_t.shear - dn_t.shear) / (2 * d), rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("bad", [dict(k_N=0.0), dict(k_T=-1.0), dict(mu=-0.1), dict(k_N=np.inf)])
def test_law_refuses_bad_parameters(bad):
    with pytest.raises(InputError, match="k_N|k_T|mu"):
        FrictionalContact(**({"k_N": 1.0, "k_T": 1.0} | bad))


MATERIAL = ElasticMaterial(1e4, 0.25)
N_C = np.array([-1.0, 1.0]) / np.sqrt(2.0)  # left normal of the fracture from (0, 0) to (1, 1)
T_C = np.array([-N_C[1], N_C[0]])


@pytest.fixture(scope="module")
def cut_square():
    p0 = structured(1.0, 1.0, 13, 13)
    p, cracks = cut_triangulation(p0, [np.array([[0.0, 0.0], [1.0, 1.0]])])
    rk = rk_approximation(p.x, p.spacing, 1.5, cracks=cracks)
    return p, rk, nodal_cells(p)


def _stress(s_n: float, tau: float) -> np.ndarray:
    """sigma with sigma n_C = -s_n n_C + tau t_C and sigma_tt = -0.4 s_n (Voigt xx, yy, xy)."""
    sig = -s_n * np.outer(N_C, N_C) + tau * (np.outer(N_C, T_C) + np.outer(T_C, N_C)) - 0.4 * s_n * np.outer(T_C, T_C)
    return np.array([sig[0, 0], sig[1, 1], sig[0, 1]])


def _solve(cut_square, law, s_n, tau, jump, pressure=0.0):
    """The square with u = eps x (+ jump on the + side) prescribed on its outer edges, solved by
    Newton with the contact forces; returns the nodal displacements and the contact."""
    p, rk, domains = cut_square
    d = MATERIAL.voigt(2)
    e = np.linalg.solve(d, _stress(s_n, tau))
    grad = np.array([[e[0], e[2] / 2], [e[2] / 2, e[1]]])

    def exact(x, t=0.0):
        plus = (x @ N_C) > 0
        return x @ grad.T + plus[:, None] * jump[None, :]

    conds = [Displacement(part, exact) for part in ("bottom", "right", "top", "left")]
    k, f, _, _ = elastic_terms(p, rk, domains, MATERIAL, conds, [], None, "scni", "nitsche", 100.0)
    contact = FractureContact(interface(p, domains, rk), law)
    pres = np.full(p.num_nodes, pressure)
    u = np.zeros(2 * p.num_nodes)
    for _ in range(20):
        r = k @ u + contact.forces(u, pres) - f
        if np.abs(r).max() <= 1e-10 * np.abs(f).max():
            break
        u -= sp.linalg.spsolve((k + contact.stiffness()).tocsc(), r)
    # sampled at the particles drawn a little towards the centre: the face copies at the
    # fracture's ends lie a gap beyond the cut, where both sides are in sight
    x = 0.5 + (p.x - 0.5) * (1.0 - 1e-6)
    return evaluate(rk, x).matrix() @ u.reshape(-1, 2), exact(x), contact


def test_stick_reproduces_the_penalty_jump_exactly(cut_square):
    s_n, tau = 2.0, 0.5  # |tau| < mu s_n: stick
    jump = -s_n / LAW.k_N * N_C + tau / LAW.k_T * T_C
    u, exact, contact = _solve(cut_square, LAW, s_n, tau, jump)
    assert np.abs(u - exact).max() <= 1e-10 * np.abs(exact).max()
    assert (contact.status() == STICK).all()
    np.testing.assert_allclose(contact.trial.pressure, s_n, rtol=1e-9)
    np.testing.assert_allclose(contact.trial.shear, tau, rtol=1e-9)


def test_slip_at_the_friction_limit_is_reproduced_exactly(cut_square):
    s_n = 2.0
    tau = LAW.mu * s_n
    slid = 10 * tau / LAW.k_T  # far more tangential jump than sticking would allow
    jump = -s_n / LAW.k_N * N_C + slid * T_C
    u, exact, contact = _solve(cut_square, LAW, s_n, tau, jump)
    assert np.abs(u - exact).max() <= 1e-10 * np.abs(exact).max()
    assert (contact.status() == SLIP).all()
    contact.commit()
    np.testing.assert_allclose(contact.slip, slid - tau / LAW.k_T, rtol=1e-9)
    # with friction enough to stick, the same boundary data give another field
    u_stuck, _, stuck = _solve(cut_square, FrictionalContact(LAW.k_N, LAW.k_T, mu=20.0), s_n, tau, jump)
    assert (stuck.status() == STICK).all()
    assert np.abs(u_stuck - exact).max() > 1e-3 * np.abs(exact).max()


def test_open_fracture_carries_the_fluid_pressure(cut_square):
    p_f = 3.0  # sigma n_C = -p_f n_C: the faces carry the pressure, any opening balances
    jump = 2e-3 * N_C + 1e-3 * T_C
    u, exact, contact = _solve(cut_square, LAW, p_f, 0.0, jump, pressure=p_f)
    assert np.abs(u - exact).max() <= 1e-10 * np.abs(exact).max()
    assert (contact.status() == OPEN).all()
    np.testing.assert_allclose(contact.aperture(), 2e-3, rtol=1e-9)


def test_covering_particles_take_the_fracture_permeability(cut_square):
    p, rk, domains = cut_square
    volume = domains.area
    contact = FractureContact(interface(p, domains, rk), LAW, p.x, volume)
    k0, mu_f = 1e-12, 1e-3
    closing = np.zeros((p.num_nodes, 2))
    closing[(p.x @ N_C) > 0] = -1e-4 * N_C  # the + side pressed into the - side
    contact.forces(closing.ravel())
    cover, k = contact.permeability(k0, mu_f)
    assert cover.size > 0 and (contact.status() == STICK).all()
    np.testing.assert_allclose(k, np.broadcast_to(0.01 * k0 * np.eye(2), k.shape))
    w = 1e-4
    contact.forces(-w / 1e-4 * closing.ravel())  # opened by w
    cover, k = contact.permeability(k0, mu_f)
    k_fc = w**3 / (12 * mu_f * contact.band_width)
    np.testing.assert_allclose(k, np.broadcast_to(k0 * np.eye(2) + (k_fc - k0) * np.outer(T_C, T_C), k.shape),
                               rtol=1e-9)
    # the band width spreads the covering particles' area over the fracture's length
    assert np.isclose(contact.band_width * np.sqrt(2.0), volume[cover].sum())


def test_a_confined_fractured_rock_drains_to_the_exact_sticking_state(cut_square):
    """The u-p model of chapter 5 with the fracture: the boundary prescribes the stick solution's
    displacement, the pore pressure of loading drains away, and the state is the exact one."""
    from rkfx.conditions import Pressure
    from rkfx.models.hydraulic_fracture import FracturingRock, HydraulicFractureModel
    from rkfx.solvers.integrate import integrate
    from rkfx.solvers.newmark import damped

    p, rk, domains = cut_square
    # light and permeable, so 0.5 s is quasi-static and drained; no damage at these strains
    rock = FracturingRock(1e4, 0.25, 1e-3, 1e-3, 0.2, 1e4, 1e4, 1e4, 1e12, 1e3, 1e3)
    s_n, tau = 2.0, 0.5
    law = FrictionalContact(k_N=1e3, k_T=5e2, mu=0.7)
    jump = -s_n / law.k_N * N_C + tau / law.k_T * T_C
    e = np.linalg.solve(MATERIAL.voigt(2), _stress(s_n, tau))  # MATERIAL: same E, nu as the rock
    grad = np.array([[e[0], e[2] / 2], [e[2] / 2, e[1]]])

    def exact(x, t=1.0):
        return min(t / 0.05, 1.0) * (x @ grad.T + ((x @ N_C) > 0)[:, None] * jump[None, :])

    sides = ("bottom", "right", "top", "left")
    model = HydraulicFractureModel(p, rk, domains, rock, displacements=[Displacement(s, exact) for s in sides],
                                   pressures=[Pressure(s) for s in sides], contact=law)
    run = integrate(damped(0.9, 1.0), model, np.linspace(0.0, 0.5, 21))
    x = 0.5 + (p.x - 0.5) * (1.0 - 1e-6)
    values = evaluate(rk, x).matrix()
    u = values @ run.state.x[:2 * p.num_nodes].reshape(-1, 2)
    assert np.abs(u - exact(x)).max() <= 1e-7 * np.abs(exact(x)).max()
    assert np.abs(values @ run.state.x[2 * p.num_nodes:]).max() <= 1e-6 * s_n
    assert (model.fracture.status() == STICK).all()
    # the model's permeability (the Darcy output's too) holds the closed fracture's k_f0 / 100
    k = model.permeability(model.committed, model.strain)
    cover = model.fracture.cover
    assert cover.size and np.allclose(k[cover], 0.01 * rock.mobility * np.eye(2))
    others = np.setdiff1d(np.arange(p.num_nodes), cover)
    assert np.allclose(k[others], rock.mobility * np.eye(2))
    saved = model.state()
    assert "contact_slip" in saved
    model.fracture.slip[:] = 1.0
    model.restore(saved)
    np.testing.assert_array_equal(model.fracture.slip, saved["contact_slip"])
