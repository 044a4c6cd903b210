"""Cryer's sphere (verification/cryer.py): parameters, roots, limits, the Mandel-Cryer peak, an
independent finite-element solution of the radial u-p equations, series vs Laplace inversion vs
a closed short-time form, the governing equations by finite differences, bad input."""
import functools

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spl
from scipy.optimize import brentq
from scipy.special import wofz

from rkfx.errors import InputError
from rkfx.models.poroelasticity import PoroMaterial
from verification.cryer import Cryer, _roots

BASE = dict(E=1.0e4, k=1.0e-4, radius=1.0, load=1.0)
INCOMPRESSIBLE = {nu: Cryer(nu=nu, **BASE) for nu in (0.0, 0.1, 0.25)}
COMPRESSIBLE = Cryer(nu=0.2, alpha=0.8, S=1.0e-5, **BASE)
ROCK = Cryer(E=3.0e10, nu=0.3, k=1.0e-18, radius=2.0, load=1.0e6, alpha=0.7, S=2.0e-11)   # SI scales
AUXETIC = Cryer(nu=-0.9, **BASE)                         # beta = 0.339, close to the bound 1/3
SETS = [INCOMPRESSIBLE[0.0], COMPRESSIBLE, ROCK, AUXETIC]
IDS = ["nu0", "compressible", "rock", "auxetic"]


def _t(cr, T):
    return np.asarray(T, float) * cr.time_scale


# --------------------------------------------------------------------------------------------
# parameters and roots
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("cr", SETS, ids=IDS)
def test_parameters(cr):
    K, G = cr.E / (3 * (1 - 2 * cr.nu)), cr.E / (2 * (1 + cr.nu))
    Kv = K + 4 * G / 3
    assert cr.p0 == pytest.approx(cr.alpha * cr.load / (cr.alpha**2 + cr.S * K), rel=1e-14)   # Skempton
    mat = PoroMaterial(cr.E, cr.nu, cr.k, cr.alpha, cr.S)
    assert cr.c == pytest.approx(mat.consolidation_coefficient, rel=1e-14)
    assert cr.time_scale == pytest.approx(cr.radius**2 / cr.c, rel=1e-14)
    eta = 4 * G * cr.alpha**2 / (3 * K * (cr.alpha**2 + cr.S * Kv))
    assert cr.beta == pytest.approx((1 + eta) / (3 * eta), rel=1e-13)
    nu_u = 0.5 if cr.S == 0 else (3 * cr.K_u - 2 * G) / (2 * (3 * cr.K_u + G))
    assert cr.nu_u == pytest.approx(nu_u, rel=1e-13)
    # Detournay & Cheng's parameter group (1-nu)(1+nu_u)/(6(nu_u-nu)) is the same beta
    assert cr.beta == pytest.approx((1 - cr.nu) * (1 + nu_u) / (6 * (nu_u - cr.nu)), rel=1e-12)


def test_incompressible_constituents():
    for nu, cr in INCOMPRESSIBLE.items():
        assert cr.B == 1.0 and cr.nu_u == 0.5 and cr.p0 == cr.load
        assert cr.beta == pytest.approx((1 - nu) / (2 * (1 - 2 * nu)), rel=1e-14)
        u0 = cr.radial_displacement(np.linspace(0, 1, 5), 0.0)               # undrained: no volume change
        assert np.abs(u0).max() < 1e-14 * cr.load * cr.radius / (3 * cr.K)


@pytest.mark.parametrize("beta", [0.34, 0.5, 0.7245, 3.0, 500.0])
def test_roots_one_per_interval_and_match_brentq(beta):
    xi = _roots(beta, 2000)
    n = np.arange(1, 2001)
    assert np.all(xi > (n - 1) * np.pi) and np.all(xi < n * np.pi)
    F = lambda x: x * np.cos(x) - (1 - beta * x * x) * np.sin(x)      # noqa: E731
    assert np.all(np.abs(F(xi)) <= 1e-12 * beta * xi**2)
    for m in range(1, 21):
        ref = brentq(F, (m - 1) * np.pi + 0.05, m * np.pi, xtol=1e-15, rtol=1e-15)   # F = O(xi^3) near 0
        assert xi[m - 1] == pytest.approx(ref, rel=1e-14, abs=1e-14)
    # tan xi -> -1/(beta xi): xi_n -> n pi - 1/(beta n pi)
    assert xi[-1] == pytest.approx(2000 * np.pi - 1 / (beta * 2000 * np.pi), abs=1e-6 / beta)


# --------------------------------------------------------------------------------------------
# 1, 2: limits
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("cr", SETS, ids=IDS)
def test_undrained_limit_and_early_rise(cr):
    rho = np.linspace(0.0, 0.8, 9)
    p0plus = cr.pressure(np.append(rho, 1.0) * cr.radius, 0.0)
    assert np.all(p0plus[:-1] == cr.p0) and p0plus[-1] == 0.0
    r = rho * cr.radius
    assert cr.radial_displacement(r, 0.0) == pytest.approx(-cr.load * r / (3 * cr.K_u), abs=1e-15)
    b = cr.beta
    for T in [1e-8, 1e-7, 1e-6, 1e-5, 1e-4]:
        p = cr.pressure(r, _t(cr, T)) / cr.p0
        # interior: p/p0 = 1 + (2/beta) sqrt(T/pi) + (1/beta^2 - 1/beta) T + O(T^1.5), uniform in r
        asym = 1 + 2 / b * np.sqrt(T / np.pi) + (1 / b**2 - 1 / b) * T
        assert np.abs(p - asym).max() < 10 * T**1.5
        # surface: u(a) - u(a, 0+) = alpha a (pbar - p0)/(3K), pbar/p0 = 1 + (2/beta - 6) sqrt(T/pi) + O(T)
        du = cr.radial_displacement(cr.radius, _t(cr, T)) - cr.radial_displacement(cr.radius, 0.0)
        lead = cr.alpha * cr.radius * cr.p0 * (2 / b - 6) * np.sqrt(T / np.pi) / (3 * cr.K)
        assert abs(du / lead - 1) < 3 * np.sqrt(T)


@pytest.mark.parametrize("cr", SETS[:3], ids=IDS[:3])
def test_drained_limit(cr):
    r = np.linspace(0, cr.radius, 11)
    t = _t(cr, 6.0)
    assert np.abs(cr.pressure(r, t)).max() < 1e-10 * cr.p0
    u_inf = -cr.load * r / (3 * cr.K)
    assert np.abs(cr.radial_displacement(r, t) - u_inf).max() < 1e-10 * abs(u_inf[-1])
    assert cr.outflow(t) < 1e-10 * cr.outflow(_t(cr, 0.1))
    # late decay on the first mode
    xi1 = cr.roots(1)[0]
    ratio = cr.centre_pressure(_t(cr, 2.0)) / cr.centre_pressure(_t(cr, 1.0))
    assert ratio == pytest.approx(np.exp(-xi1**2), rel=1e-6)


# --------------------------------------------------------------------------------------------
# 3: Mandel-Cryer peak. Reference numbers: the finite-element solver below with 200 and 400
# elements (block 64), Richardson-extrapolated in time and space; peak by a parabola in log T.
# --------------------------------------------------------------------------------------------
PEAKS_FE = [(INCOMPRESSIBLE[0.0], 0.06270, 1.575418), (INCOMPRESSIBLE[0.1], 0.05755, 1.472763),
            (INCOMPRESSIBLE[0.25], 0.04939, 1.307537), (COMPRESSIBLE, 0.05020, 1.322930)]


@pytest.mark.parametrize("cr, T_fe, ratio_fe", PEAKS_FE, ids=["nu0", "nu0.1", "nu0.25", "compressible"])
def test_mandel_cryer_peak(cr, T_fe, ratio_fe):
    pk = cr.peak()
    assert pk.ratio > 1.25                                               # well above p0
    assert pk.ratio == pytest.approx(ratio_fe, abs=2e-5)
    assert pk.T == pytest.approx(T_fe, rel=2e-3)
    assert pk.p == pytest.approx(pk.ratio * cr.p0, rel=1e-15) and pk.t == pytest.approx(pk.T * cr.time_scale)
    T = pk.T * np.array([0.9, 1.0, 1.1])
    pc = cr.centre_pressure(_t(cr, T))
    assert pc[1] >= pc[0] and pc[1] >= pc[2]


def test_peak_falls_with_poisson_ratio():
    ratios = [INCOMPRESSIBLE[nu].peak().ratio for nu in (0.0, 0.1, 0.25)]
    assert ratios[0] > ratios[1] > ratios[2] > 1.0
    assert 1.0 < Cryer(nu=0.45, **BASE).peak().ratio < ratios[2]


# --------------------------------------------------------------------------------------------
# 4: independent finite-element solution of the spherically symmetric u-p equations
# --------------------------------------------------------------------------------------------
_GP, _GW = np.polynomial.legendre.leggauss(3)


def _fe_run(cr: Cryer, n_el: int, T_end: float, dt0: float, block: int, grading: float = 1.5):
    """P2 displacement / P1 pressure Galerkin elements in r (weight r^2) and backward Euler.

    Weak form: int [sigma''_rr de_rr + 2 sigma''_tt de_tt - alpha p de] r^2 dr = -sigma0 a^2 du(a),
    int [(alpha de/dt + S dp/dt) dq + k p' dq'] r^2 dr = 0; u(0) = 0, p(a) = 0. Nodes graded
    towards the drained surface, r = a (1 - (1 - i/n)^grading). The step dt starts at dt0 T-units
    and doubles after every ``block`` steps (one factorization per block).
    Returns r_p (n+1,), T (steps,), p (steps, n+1) [Pa], u at the vertices (steps, n+1) [m].
    """
    a, lam, G = cr.radius, cr.K - 2 * cr.G / 3, cr.G
    rv = a * (1 - (1 - np.linspace(0, 1, n_el + 1)) ** grading)
    h = np.diff(rv)
    iu = 2 * np.arange(n_el)[:, None] + np.arange(3)
    ip = np.arange(n_el)[:, None] + np.arange(2)
    kuu, q, m, hh = (np.zeros((n_el, 3, 3)), np.zeros((n_el, 3, 2)), np.zeros((n_el, 2, 2)), np.zeros((n_el, 2, 2)))
    for g, w in zip(_GP, _GW):
        r = rv[:-1] + (g + 1) * h / 2
        wr = (w * h / 2 * r * r)[:, None, None]
        N = np.array([g * (g - 1) / 2, 1 - g * g, g * (g + 1) / 2])
        dN = np.outer(2 / h, [g - 0.5, -2 * g, g + 0.5])
        Nr = N[None, :] / r[:, None]
        P, dP = np.array([(1 - g) / 2, (1 + g) / 2]), np.outer(2 / h, [-0.5, 0.5])
        out = lambda x, y: x[:, :, None] * y[:, None, :]              # noqa: E731
        kuu += wr * ((lam + 2 * G) * out(dN, dN) + 2 * lam * (out(dN, Nr) + out(Nr, dN)) + 4 * (lam + G) * out(Nr, Nr))
        q += wr * cr.alpha * out(dN + 2 * Nr, np.broadcast_to(P, (n_el, 2)))
        m += wr * np.outer(P, P)
        hh += wr * cr.k * out(dP, dP)

    def assemble(ke, rows, cols, shape):
        R = np.broadcast_to(rows[:, :, None], ke.shape)
        C = np.broadcast_to(cols[:, None, :], ke.shape)
        return sp.coo_matrix((ke.ravel(), (R.ravel(), C.ravel())), shape=shape).tocsc()

    nu_, np_ = 2 * n_el + 1, n_el + 1
    Kuu = assemble(kuu, iu, iu, (nu_, nu_))[1:, 1:]                  # u(0) = 0
    Q = assemble(q, iu, ip, (nu_, np_))[1:, :-1]                    # p(a) = 0
    Ms = cr.S * assemble(m, ip, ip, (np_, np_))[:-1, :-1]
    H = assemble(hh, ip, ip, (np_, np_))[:-1, :-1]
    f = np.zeros(nu_ - 1)
    f[-1] = -cr.load * a**2
    u, p, t, dt = np.zeros(nu_ - 1), np.zeros(np_ - 1), 0.0, dt0 * cr.time_scale
    T, Ps, Us = [], [], []
    while t < T_end * cr.time_scale * (1 - 1e-12):
        lu = spl.splu(sp.bmat([[Kuu, -Q], [-Q.T, -(Ms + dt * H)]], format="csc"))
        for _ in range(block):
            x = lu.solve(np.concatenate([f, -Q.T @ u - Ms @ p]))
            u, p, t = x[:nu_ - 1], x[nu_ - 1:], t + dt
            T.append(t / cr.time_scale)
            Ps.append(np.append(p, 0.0))
            Us.append(np.concatenate([[0.0], u])[::2])
        dt *= 2
    return rv, np.array(T), np.array(Ps), np.array(Us)


@functools.lru_cache(maxsize=4)
def _fe_extrapolated(cr: Cryer, n_el: int = 60, T_end: float = 1.0, block: int = 32):
    """Richardson in time (dt, dt/2: 2 fine - coarse) and in space (n, 2n: (4 fine - coarse)/3)."""
    def in_time(n):
        r, Tc, pc, uc = _fe_run(cr, n, T_end, 1e-7, block)
        _, Tf, pf, uf = _fe_run(cr, n, T_end, 0.5e-7, 2 * block)
        k = len(Tc)
        assert np.allclose(Tf[1::2][:k], Tc, rtol=1e-12)
        return r, Tc, 2 * pf[1::2][:k] - pc, 2 * uf[1::2][:k] - uc

    r, T, p1, u1 = in_time(n_el)
    _, _, p2, u2 = in_time(2 * n_el)
    return r, T, (4 * p2[:, ::2] - p1) / 3, (4 * u2[:, ::2] - u1) / 3


@pytest.mark.parametrize("cr", [INCOMPRESSIBLE[0.0], COMPRESSIBLE], ids=["nu0", "compressible"])
def test_finite_elements_centre_history_and_displacement(cr):
    r, T, p_fe, u_fe = _fe_extrapolated(cr)
    sel = T >= 1e-3
    pc = cr.centre_pressure(_t(cr, T[sel]))
    assert np.abs(p_fe[sel, 0] - pc).max() < 3e-4 * cr.p0                    # measured 1.0e-4
    ua = cr.radial_displacement(cr.radius, _t(cr, T[sel]))
    assert np.abs(u_fe[sel, -1] - ua).max() < 3e-4 * cr.load * cr.radius / (3 * cr.K)
    # the peak of the FE history (parabola in log T through the three highest samples)
    i = int(np.argmax(p_fe[:, 0]))
    c2, c1, c0 = np.polyfit(np.log(T[i - 1:i + 2]), p_fe[i - 1:i + 2, 0], 2)
    pk = cr.peak()
    assert (c0 - c1**2 / (4 * c2)) / cr.p0 == pytest.approx(pk.ratio, abs=3e-4)
    assert np.exp(-c1 / (2 * c2)) == pytest.approx(pk.T, rel=1e-2)


@pytest.mark.parametrize("cr", [INCOMPRESSIBLE[0.0], COMPRESSIBLE], ids=["nu0", "compressible"])
def test_finite_elements_radial_profiles(cr):
    r, T, p_fe, u_fe = _fe_extrapolated(cr)
    for T_out in [0.003, 0.03, 0.1, 0.4]:
        j = int(np.argmin(np.abs(np.log(T / T_out))))
        p = cr.pressure(r, _t(cr, T[j]))
        assert np.abs(p_fe[j] - p).max() < 3e-4 * cr.p0                     # measured 1.0e-4
        u = cr.radial_displacement(r, _t(cr, T[j]))
        assert np.abs(u_fe[j] - u).max() < 3e-4 * cr.load * cr.radius / (3 * cr.K)


# --------------------------------------------------------------------------------------------
# 5: series vs Talbot inversion vs closed short-time form
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("cr", SETS, ids=IDS)
def test_series_and_laplace_inversion_agree(cr):
    r = np.linspace(0, cr.radius, 41)
    u_scale = cr.load * cr.radius / (3 * cr.K)
    for T in [1e-7, 1e-5, 1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0, 3.0]:
        t = _t(cr, T)
        ps, pl = cr.pressure(r, t, "series"), cr.pressure(r, t, "laplace")
        assert np.abs(ps - pl).max() < 1e-11 * cr.p0
        us, ul = cr.radial_displacement(r, t, "series"), cr.radial_displacement(r, t, "laplace")
        assert np.abs(us - ul).max() < 1e-11 * u_scale
        qs, ql = cr.outflow(t, "series"), cr.outflow(t, "laplace")
        assert abs(qs - ql) < 1e-11 * 4 * np.pi * cr.radius * cr.k * cr.p0 * max(1.0, T**-0.5)
        assert cr.mean_pressure(t, "series") == pytest.approx(cr.mean_pressure(t, "laplace"), abs=1e-11 * cr.p0)
    # "auto" is one or the other
    t = _t(cr, np.array([5e-5, 2e-4]))
    p_auto = cr.pressure(0.3 * cr.radius, t)
    assert p_auto[0] == pytest.approx(cr.pressure(0.3 * cr.radius, t[0], "laplace"), abs=1e-15 * cr.p0)
    assert p_auto[1] == pytest.approx(cr.pressure(0.3 * cr.radius, t[1], "series"), abs=1e-15 * cr.p0)


@pytest.mark.parametrize("cr", SETS, ids=IDS)
def test_centre_pressure_matches_closed_short_time_form(cr):
    """For small T, D = s - (sqrt(s) - 1)/beta up to e^-2x, so p_c/p0 is inverted exactly:
    [x1 w(-i x1 sqrt T) - x2 w(-i x2 sqrt T)]/(x1 - x2), x1,2 the roots of x^2 - x/beta + 1/beta,
    w the Faddeeva function; neglected terms are O(exp(-1/(4T)))."""
    b = cr.beta
    d = np.sqrt(complex(1 / b**2 - 4 / b))
    x1, x2 = (1 / b + d) / 2, (1 / b - d) / 2
    T = np.logspace(-9, -2, 15)
    closed = ((x1 * wofz(-1j * x1 * np.sqrt(T)) - x2 * wofz(-1j * x2 * np.sqrt(T))) / (x1 - x2)).real
    pc = cr.centre_pressure(_t(cr, T)) / cr.p0
    assert np.abs(pc - closed)[T <= 1e-3].max() < 1e-12
    assert np.abs(pc - closed).max() < 1e-9                                 # T = 1e-2: e^-25


def test_centre_series_in_verruijt_notation_with_brentq_roots():
    """p_c/p0 = sum eta (sin xi - xi)/((eta - 1) sin xi + eta xi cos xi/2) e^(-xi^2 T), eta = 2 beta,
    roots of (1 - eta xi^2/2) tan xi = xi found here by brentq."""
    for cr in [INCOMPRESSIBLE[0.1], COMPRESSIBLE]:
        eta = 2 * cr.beta
        g = lambda x: (1 - eta * x * x / 2) * np.sin(x) - x * np.cos(x)    # noqa: E731
        # brackets ((n-1) pi + 0.1, n pi): g(xi) ~ -(eta/2 - 1/3) xi^3 is round-off near 0
        xi = np.array([brentq(g, (n - 1) * np.pi + 0.1, n * np.pi - 1e-12, xtol=1e-15) for n in range(1, 201)])
        for T in [2e-3, 0.05, 0.3]:
            ref = np.sum(eta * (np.sin(xi) - xi) / ((eta - 1) * np.sin(xi) + eta * xi * np.cos(xi) / 2)
                         * np.exp(-xi**2 * T))
            assert cr.centre_pressure(_t(cr, T)) / cr.p0 == pytest.approx(ref, abs=1e-12)


# --------------------------------------------------------------------------------------------
# 6: governing equations, boundary conditions, fluid balance, compressibility limit
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("cr", [COMPRESSIBLE, ROCK], ids=["compressible", "rock"])
def test_fields_satisfy_equilibrium_storage_and_boundary_conditions(cr):
    a, lam, G = cr.radius, cr.K - 2 * cr.G / 3, cr.G
    r = a * np.linspace(0.05, 0.95, 19)
    h = 1e-4 * a
    for T in [0.02, 0.2]:
        t = _t(cr, T)
        u = lambda rr, tt=t: cr.radial_displacement(rr, tt)                  # noqa: E731
        p = lambda rr, tt=t: cr.pressure(rr, tt)                             # noqa: E731
        u1, u2 = (u(r + h) - u(r - h)) / (2 * h), (u(r + h) - 2 * u(r) + u(r - h)) / h**2
        p1, p2 = (p(r + h) - p(r - h)) / (2 * h), (p(r + h) - 2 * p(r) + p(r - h)) / h**2
        # equilibrium d(sigma_rr)/dr + 2 (sigma_rr - sigma_tt)/r = (lam + 2G)(u'' + 2u'/r - 2u/r^2) - alpha p' = 0
        res = (lam + 2 * G) * (u2 + 2 * u1 / r - 2 * u(r) / r**2) - cr.alpha * p1
        assert np.abs(res).max() < 1e-6 * cr.p0 / a
        # storage alpha de/dt + S dp/dt = k (p'' + 2p'/r), e = u' + 2u/r
        dt = 1e-4 * t
        e = lambda tt: (u(r + h, tt) - u(r - h, tt)) / (2 * h) + 2 * u(r, tt) / r   # noqa: E731
        lhs = cr.alpha * (e(t + dt) - e(t - dt)) / (2 * dt) + cr.S * (p(r, t + dt) - p(r, t - dt)) / (2 * dt)
        rhs = cr.k * (p2 + 2 * p1 / r)
        assert np.abs(lhs - rhs).max() < 1e-5 * np.abs(rhs).max()
        # surface: total traction -sigma0 (p(a) = 0) and drained
        hs = 1e-5 * a
        du_a = (3 * u(a) - 4 * u(a - hs) + u(a - 2 * hs)) / (2 * hs)
        assert (lam + 2 * G) * du_a + 2 * lam * u(a) / a == pytest.approx(-cr.load, rel=1e-6)
        for method in ("series", "laplace"):
            assert abs(cr.pressure(a, t, method)) < 1e-13 * cr.p0
        # regularity: u(0) = 0
        assert u(0.0) == 0.0


@pytest.mark.parametrize("cr", SETS, ids=IDS)
def test_fluid_balance_and_mean_pressure(cr):
    """Fluid content zeta = alpha e + S p: d/dt int zeta dV = -outflow, int e dV = 4 pi a^2 u(a)."""
    a = cr.radius

    def content(t):
        return 4 * np.pi * (cr.alpha * a**2 * cr.radial_displacement(a, t) + cr.S * a**3 * cr.mean_pressure(t) / 3)

    x, w = np.polynomial.legendre.leggauss(60)
    for T1, T2 in [(1e-6, 1e-3), (1e-3, 0.1), (0.1, 2.0)]:
        lo, hi = np.log(T1), np.log(T2)                                       # quadrature in log t
        Ts = np.exp(lo + (x + 1) * (hi - lo) / 2)
        expelled = np.sum(w * (hi - lo) / 2 * Ts * cr.time_scale * cr.outflow(_t(cr, Ts)))
        change = content(_t(cr, T2)) - content(_t(cr, T1))
        assert expelled == pytest.approx(-change, rel=1e-9)
    # mean pressure = (3/a^3) int p r^2 dr
    xr, wr = np.polynomial.legendre.leggauss(80)
    rr = a * (xr + 1) / 2
    for T in [1e-3, 0.05, 0.5]:
        integral = 3 / a**3 * np.sum(wr * a / 2 * rr**2 * cr.pressure(rr, _t(cr, T)))
        assert cr.mean_pressure(_t(cr, T)) == pytest.approx(integral, abs=1e-12 * cr.p0)


def test_incompressible_volume_change_equals_expelled_fluid():
    cr = INCOMPRESSIBLE[0.25]
    a, t = cr.radius, _t(cr, np.array([1e-4, 0.01, 0.1, 1.0]))
    dV = 4 * np.pi * a**2 * cr.radial_displacement(a, t)                      # sphere volume change
    x, w = np.polynomial.legendre.leggauss(80)
    for tj, dVj in zip(t, dV):
        lo, hi = np.log(1e-20 * cr.time_scale), np.log(tj)
        ts = np.exp(lo + (x + 1) * (hi - lo) / 2)
        expelled = np.sum(w * (hi - lo) / 2 * ts * cr.outflow(ts))          # misses ~1e-10 sqrt(T) before
        assert expelled == pytest.approx(-dVj, rel=1e-7)


def test_slightly_compressible_converges_to_incompressible():
    ref = INCOMPRESSIBLE[0.25]
    r = np.linspace(0, 1, 21)[:, None]
    T = np.array([1e-3, 0.03, 0.3])[None, :]
    p_ref = ref.pressure(r, _t(ref, T)) / ref.p0
    dev = []
    for S in (1e-9, 1e-8):
        cr = Cryer(nu=0.25, S=S, **BASE)
        assert cr.p0 == pytest.approx(cr.load / (1 + S * cr.K), rel=1e-14)
        dev.append(np.abs(cr.pressure(r, _t(cr, T)) / cr.p0 - p_ref).max())
    assert 0 < dev[1] < 1e-3 and dev[1] / dev[0] == pytest.approx(10, rel=0.05)   # linear in S


# --------------------------------------------------------------------------------------------
# 7: bad input
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("bad, name", [
    (dict(radius=0.0), "radius"), (dict(radius=-1.0), "radius"), (dict(radius=np.nan), "radius"),
    (dict(load=0.0), "load"), (dict(load=-5.0), "load"), (dict(k=0.0), "k"), (dict(E=-1.0), "E"),
    (dict(alpha=0.0), "alpha"), (dict(alpha=1.2), "alpha"), (dict(nu=0.5), "nu"), (dict(nu=-1.0), "nu"),
    (dict(S=-1e-9), "S"), (dict(S=np.inf), "S"),
])
def test_bad_parameters_raise_input_error(bad, name):
    kw = dict(E=1.0e4, nu=0.2, k=1.0e-4, radius=1.0, load=1.0) | bad
    with pytest.raises(InputError) as err:
        Cryer(**kw)
    msg = str(err.value)
    assert "\n" not in msg and f"{name} = " in msg


def test_bad_arguments_raise_input_error():
    cr = COMPRESSIBLE
    for call in [lambda: cr.pressure(1.5 * cr.radius, 1.0), lambda: cr.pressure(-0.1, 1.0),
                 lambda: cr.pressure(0.5, -1.0), lambda: cr.pressure(0.5, np.nan),
                 lambda: cr.pressure(0.5, 1.0, method="fourier"),
                 lambda: cr.pressure(0.5, 1e-12 * cr.time_scale, method="series")]:
        with pytest.raises(InputError):
            call()


def test_shapes_broadcast():
    cr = COMPRESSIBLE
    r, t = np.linspace(0, 1, 7)[:, None], np.array([0.0, 1e-5, 0.1])[None, :]
    assert cr.pressure(r, t).shape == (7, 3) and cr.radial_displacement(r, t).shape == (7, 3)
    assert cr.centre_pressure(t[0]).shape == (3,) and np.ndim(cr.centre_pressure(0.1)) == 0
    assert cr.outflow(t[0]).shape == (3,) and cr.outflow(0.0) == np.inf
