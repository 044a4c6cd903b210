"""Poroelastic exact solutions (Terzaghi, Mandel, strip load) checked against the reference
numbers of /work/shared/NOTES.md, their limits, and the governing equations by finite differences."""
import time

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from verification.mandel import Mandel, _roots
from verification.strip_load import StripLoad, pressure_kernel, pressure_kernel_laplace
from verification.terzaghi import Terzaghi

# --------------------------------------------------------------------------------------------
# Terzaghi
# --------------------------------------------------------------------------------------------
TERZAGHI = [
    Terzaghi(E=1.0e3, nu=0.0, k=1.0e-6, H=10.0, q=1.0e3),                      # seed: 1 kPa, k_h/gamma_f
    Terzaghi(E=2.0e7, nu=0.3, k=3.0e-10, H=4.0, q=5.0e4, alpha=0.8, S=4.0e-9),   # compressible
]


def _times(tz: Terzaghi, T):
    return np.asarray(T) * tz.H**2 / tz.c_v


@pytest.mark.parametrize("tz", TERZAGHI)
def test_terzaghi_parameters(tz):
    K = tz.E / (3 * (1 - 2 * tz.nu))
    G = tz.E / (2 * (1 + tz.nu))
    Kv = K + 4 * G / 3
    assert tz.K_v == pytest.approx(Kv, rel=1e-14)
    # eq. 3.54 of the seed: c_v = k_f (K + 4G/3) / ((K + 4G/3)/Q + alpha^2), 1/Q = S.
    assert tz.c_v == pytest.approx(tz.k * Kv / (Kv * tz.S + tz.alpha**2), rel=1e-14)
    assert tz.p0 == pytest.approx(tz.alpha * tz.q / (tz.alpha**2 + tz.S * Kv), rel=1e-14)


@pytest.mark.parametrize("tz", TERZAGHI)
def test_terzaghi_fourier_and_erfc_series_agree(tz):
    z = np.linspace(0.0, tz.H, 41)
    for T in [1e-8, 1e-6, 1e-4, 1e-2, 0.1, 0.5, 1.0, 3.0]:
        t = _times(tz, T)
        pf, pe = tz.pressure(z, t, "fourier"), tz.pressure(z, t, "erfc")
        assert np.abs(pf - pe).max() < 1e-12 * tz.p0
        uf, ue = tz.displacement(z, t, "fourier"), tz.displacement(z, t, "erfc")
        assert np.abs(uf - ue).max() < 1e-12 * tz.q * tz.H / tz.K_v
        assert tz.degree_of_consolidation(t, "fourier") == pytest.approx(
            tz.degree_of_consolidation(t, "erfc"), abs=1e-13)
    with pytest.raises(ValueError):
        tz.pressure(z, _times(tz, 1e-12), "fourier")          # would need > 1e5 terms


@pytest.mark.parametrize("tz", TERZAGHI)
def test_terzaghi_satisfies_diffusion_storage_and_equilibrium(tz):
    """dp/dt = c_v p_zz; alpha d(eps)/dt + S dp/dt = k p_zz; K_v eps - alpha p = -q."""
    z = tz.H * np.linspace(0.05, 0.95, 19)
    hz = 1e-3 * tz.H
    for T in [2e-3, 0.05, 0.4]:
        t = _times(tz, T)
        dt = 1e-4 * t
        p = tz.pressure(z, t)
        p_t = (tz.pressure(z, t + dt) - tz.pressure(z, t - dt)) / (2 * dt)
        p_zz = (tz.pressure(z + hz, t) - 2 * p + tz.pressure(z - hz, t)) / hz**2
        scale = np.abs(p_t).max()
        assert np.abs(p_t - tz.c_v * p_zz).max() < 1e-4 * scale

        def eps(tt):
            return (tz.displacement(z + hz, tt) - tz.displacement(z - hz, tt)) / (2 * hz)

        eps_t = (eps(t + dt) - eps(t - dt)) / (2 * dt)
        assert np.abs(tz.alpha * eps_t + tz.S * p_t - tz.k * p_zz).max() < 1e-4 * tz.k * np.abs(p_zz).max()
        he = 1e-5 * tz.H
        eps_fine = (tz.displacement(z + he, t) - tz.displacement(z - he, t)) / (2 * he)
        assert np.abs(tz.K_v * eps_fine - tz.alpha * p + tz.q).max() < 1e-6 * tz.q


@pytest.mark.parametrize("tz", TERZAGHI)
def test_terzaghi_limits(tz):
    z = np.linspace(0.0, tz.H, 11)
    # t = 0+: undrained, p = p0 (0 on the drained top), u = -q z S/(alpha^2 + S K_v).
    p = tz.pressure(z, 0.0)
    assert np.all(p[:-1] == tz.p0) and p[-1] == 0.0
    u0 = -tz.q * z * tz.S / (tz.alpha**2 + tz.S * tz.K_v)
    assert np.abs(tz.displacement(z, 0.0) - u0).max() < 1e-14 * tz.q * tz.H / tz.K_v
    assert np.abs(tz.displacement(z, _times(tz, 1e-12)) - u0).max() < 1e-5 * tz.q * tz.H / tz.K_v
    # t -> inf: drained.
    t_inf = _times(tz, 50.0)
    assert np.abs(tz.pressure(z, t_inf)).max() < 1e-15 * tz.p0
    assert np.abs(tz.displacement(z, t_inf) + tz.q * z / tz.K_v).max() < 1e-14 * tz.q * tz.H / tz.K_v
    # Drained top, impermeable base, monotone decay at the base.
    for T in [1e-5, 0.01, 0.3, 2.0]:
        t = _times(tz, T)
        assert abs(tz.pressure(tz.H, t)) < 1e-12 * tz.p0
        h = 1e-4 * tz.H
        assert abs(tz.pressure(h, t) - tz.pressure(0.0, t)) < 1e-7 * tz.p0
    # Degree of consolidation: 2 sqrt(T/pi) early, 1 - 8/pi^2 exp(-pi^2 T/4) late.
    for T in [1e-6, 1e-3, 1e-2]:
        assert tz.degree_of_consolidation(_times(tz, T)) == pytest.approx(2 * np.sqrt(T / np.pi), rel=1e-12)
    T = 2.0
    assert tz.degree_of_consolidation(_times(tz, T)) == pytest.approx(
        1 - 8 / np.pi**2 * np.exp(-np.pi**2 * T / 4), abs=1e-12)


# --------------------------------------------------------------------------------------------
# Mandel
# --------------------------------------------------------------------------------------------
PREISIG = Mandel(E=1.0e4, nu=0.0, k=1.0e-4, a=10.0, b=1.0, F=20.0)


def test_mandel_preisig_prevost_reference_numbers():
    m = PREISIG
    assert m.B == 1.0 and m.nu_u == 0.5
    assert m.c == pytest.approx(1.0, rel=1e-14) and m.c_cheng == pytest.approx(1.0, rel=1e-14)
    assert m.p0 == pytest.approx(1.0, rel=1e-14)
    assert m.roots(1)[0] == pytest.approx(1.16556, abs=5e-6)
    t = np.array([0.01, 0.1, 1.0]) * m.a**2 / m.c
    p_ref = [1.05902, 1.15179, 0.35628]
    u_ref = [-1.0590e-4, -1.2067e-4, -1.7681e-4]
    assert np.abs(m.pressure(0.0, t) - p_ref).max() < 5e-6          # all digits quoted
    assert np.abs(m.plate_displacement(t) - u_ref).max() < 5e-9
    # Limits: exact undrained -F(1-nu_u)b/(2Ga) = -1e-4 and drained -2e-4.
    assert m.plate_displacement(0.0) == pytest.approx(-1.0e-4, rel=1e-14)
    assert m.plate_displacement(1e3 * m.a**2 / m.c) == pytest.approx(-2.0e-4, rel=1e-14)
    assert m.plate_displacement(1e-9 * m.a**2 / m.c) == pytest.approx(-1.0e-4 * (1 + np.sqrt(1e-9 / np.pi)),
                                                                     rel=1e-9)
    # NOTES' "-1.0003e-4 at 0+" is the t = 0 series truncated at a few hundred roots.
    for n in (300, 338, 400):
        al = m.roots(n)
        s, c = np.sin(al), np.cos(al)
        uy = (-m.F * (1 - m.nu) / (2 * m.G * m.a) + m.F * (1 - m.nu_u) / (m.G * m.a)
              * np.sum(s * c / (al - s * c))) * m.b
        assert round(uy, 8) == -1.0003e-4


def test_mandel_seed_setup():
    m = Mandel(E=1.0e4, nu=0.0, k=1.0e-4, a=20.0, b=2.0, F=40.0)
    assert m.c == pytest.approx(1.0, rel=1e-14) and m.p0 == pytest.approx(1.0, rel=1e-14)


@pytest.mark.parametrize("ratio", [2.0, 1.0 + 1e-6, 1.25, 37.0])
def test_mandel_roots(ratio):
    """One root of tan(x)/x = ratio in each (n pi, n pi + pi/2), for thousands of n."""
    x = _roots(ratio, 2000)
    n = np.arange(2000)
    assert np.all(x > n * np.pi) and np.all(x < n * np.pi + np.pi / 2)
    res = np.sin(x) - ratio * x * np.cos(x)
    assert np.abs(res).max() < 1e-11 * ratio * x.max()
    # Through the class: nu = 0.2, incompressible -> ratio (1 - nu)/(nu_u - nu) = 0.8/0.3.
    m = Mandel(E=1.0, nu=0.2, k=1.0, a=1.0, b=1.0, F=1.0)
    assert np.array_equal(m.roots(700), _roots(0.8 / 0.3, 700))


MANDEL_CASES = [
    PREISIG,
    Mandel(E=1.0e4, nu=0.2, k=1.0e-4, a=10.0, b=1.0, F=20.0),
    Mandel(E=3.0e4, nu=0.25, k=2.0e-5, a=3.0, b=1.5, F=7.0, alpha=0.8, S=2.0e-5),
    Mandel(E=3.0e4, nu=-0.2, k=2.0e-5, a=3.0, b=1.5, F=7.0, alpha=0.6, S=1.0e-4),
]


@pytest.mark.parametrize("m", MANDEL_CASES)
def test_mandel_parameters(m):
    K, G = m.K, m.G
    assert m.c == pytest.approx(m.c_cheng, rel=1e-12)
    # Detournay & Cheng: nu_u = (3 nu + alpha B (1 - 2 nu)) / (3 - alpha B (1 - 2 nu)).
    ab = m.alpha * m.B * (1 - 2 * m.nu)
    assert m.nu_u == pytest.approx((3 * m.nu + ab) / (3 - ab), rel=1e-12)
    if m.S > 0:
        Ku = K + m.alpha**2 / m.S
        assert m.B == pytest.approx(m.alpha / m.S / Ku, rel=1e-12)
        assert m.nu_u == pytest.approx((3 * Ku - 2 * G) / (2 * (3 * Ku + G)), rel=1e-12)
        assert m.c == pytest.approx(m.k / m.S * m.K_v / (Ku + 4 * G / 3), rel=1e-12)


def _mandel_strains(m, x, y, t, h):
    ux = lambda xx: m.displacement(xx, y, t)[0]                        # noqa: E731
    uy = lambda yy: m.displacement(x, yy, t)[1]                        # noqa: E731
    return (ux(x + h) - ux(x - h)) / (2 * h), (uy(y + h) - uy(y - h)) / (2 * h)


@pytest.mark.parametrize("m", MANDEL_CASES)
def test_mandel_stress_storage_and_volume_balance(m):
    """sigma_xx = 0, Hooke gives sigma_yy, int sigma_yy = -F, storage equation, volume balance."""
    G, lam = m.G, m.K - 2 * m.G / 3
    x = m.a * np.linspace(0.05, 0.95, 9)
    y = 0.7 * m.b
    h = 1e-5 * m.a
    xg, wg = np.polynomial.legendre.leggauss(200)
    xg, wg = (xg + 1) * m.a / 2, wg * m.a / 2
    for ts in [1e-3, 0.05, 0.5]:
        t = ts * m.a**2 / m.c
        exx, eyy = _mandel_strains(m, x, y, t, h)
        p = m.pressure(x, t)
        assert np.abs((lam + 2 * G) * exx + lam * eyy - m.alpha * p).max() < 1e-7 * m.p0
        syy = lam * exx + (lam + 2 * G) * eyy - m.alpha * p
        assert np.abs(syy - m.stress_yy(x, t)).max() < 1e-7 * m.p0
        assert wg @ m.stress_yy(xg, t) == pytest.approx(-m.F, rel=1e-12)
        # Storage: alpha de/dt + S dp/dt = k p_xx.
        dt = 1e-4 * t

        def zeta(tt):
            ex, ey = _mandel_strains(m, x, y, tt, h)
            return m.alpha * (ex + ey) + m.S * m.pressure(x, tt)

        hp = 1e-3 * m.a
        p_xx = (m.pressure(x + hp, t) - 2 * p + m.pressure(x - hp, t)) / hp**2
        lhs = (zeta(t + dt) - zeta(t - dt)) / (2 * dt)
        assert np.abs(lhs - m.k * p_xx).max() < 2e-4 * m.k * np.abs(p_xx).max()

        # Volume balance on 0 < x < a: d/dt int (alpha e + S p) dx = k dp/dx(a) (outflow).
        def stored(tt):
            return m.alpha * (m.displacement(m.a, 0.0, tt)[0] + m.a * m.plate_displacement(tt) / m.b) \
                + m.S * (wg @ m.pressure(xg, tt))

        dVdt = (stored(t + dt) - stored(t - dt)) / (2 * dt)
        p_x = (m.pressure(m.a + h, t) - m.pressure(m.a - h, t)) / (2 * h)
        assert dVdt == pytest.approx(m.k * p_x, rel=1e-6)


@pytest.mark.parametrize("m", MANDEL_CASES)
def test_mandel_limits(m):
    x = m.a * np.linspace(0.0, 0.9, 10)
    F, G, a, b = m.F, m.G, m.a, m.b
    # t = 0+: uniform p0 inside, undrained elasticity; small t* approaches it like sqrt(t*).
    assert np.all(m.pressure(x, 0.0) == m.p0) and m.pressure(a, 0.0) == 0.0
    p_small = m.pressure(x, 1e-8 * a**2 / m.c)
    assert np.abs(p_small / m.p0 - 1).max() < 1e-3
    ux0, uy0 = m.displacement(a, b, 0.0)
    assert ux0 == pytest.approx(F * m.nu_u / (2 * G), rel=1e-14)
    assert uy0 == pytest.approx(-F * (1 - m.nu_u) * b / (2 * G * a), rel=1e-14)
    ux, uy = m.displacement(a, b, 1e-8 * a**2 / m.c)
    assert ux == pytest.approx(ux0, rel=1e-3) and uy == pytest.approx(uy0, rel=1e-3)
    # Drained side and t -> inf.
    assert abs(m.pressure(a, 0.3 * a**2 / m.c)) < 1e-14 * m.p0
    t_inf = 100.0 * a**2 / m.c
    assert np.abs(m.pressure(x, t_inf)).max() < 1e-14 * m.p0
    ux, uy = m.displacement(a, b, t_inf)
    assert ux == pytest.approx(F * m.nu / (2 * G), abs=1e-14 * F / G)
    assert uy == pytest.approx(-F * (1 - m.nu) * b / (2 * G * a), rel=1e-12)
    # Mandel-Cryer: the centre pressure first rises above p0.
    assert m.pressure(0.0, 0.05 * a**2 / m.c) > m.p0


# --------------------------------------------------------------------------------------------
# Strip load
# --------------------------------------------------------------------------------------------
SEED_STRIP = StripLoad(E=1.0e4, nu=0.0, k=5.0e-8 / 9.8, b=0.2, q=10.0)   # kPa, m, s
STRIP_CASES = [SEED_STRIP, StripLoad(E=2.0e7, nu=0.3, k=1.0e-10, b=1.5, q=1.0e5)]


def test_strip_seed_time_scale():
    s = SEED_STRIP
    assert s.dimensionless_time(19.6) == pytest.approx(0.025, rel=1e-12)       # the seed's step
    assert s.c * 19.6 / s.b**2 == pytest.approx(0.025, rel=1e-12)             # nu = 0: same as c t/b^2
    assert s.time(s.dimensionless_time(3.0)) == pytest.approx(3.0)


def _talbot(F, t, N=40):
    """Fixed-Talbot inversion (Abate & Valko 2004) of F(s) at t > 0."""
    r = 2 * N / (5 * t)
    th = np.pi * np.arange(1, N) / N
    cot = 1 / np.tan(th)
    s = r * th * (cot + 1j)
    sig = th + (th * cot - 1) * cot
    return r / N * (0.5 * np.exp(r * t) * F(r).real
                    + np.sum((np.exp(t * s) * F(s) * (1 + 1j * sig)).real))


@pytest.mark.parametrize("eta", [0.0, 0.25 / 0.75, -0.2])
def test_strip_kernel_is_the_laplace_inverse(eta):
    for Xi in [0.01, 0.5, 3.0, 20.0]:
        for Y in [0.05, 1.0, 4.0]:
            for T in [1e-3, 0.1, 5.0]:
                ref = _talbot(lambda s: pressure_kernel_laplace(Xi, Y, s, eta), T)
                assert pressure_kernel(np.array(Xi), Y, T, eta) == pytest.approx(ref, abs=1e-8)


def _fd_laplace_pressure(xi, s, E, nu, k, L, N):
    """Amplitude P(y) of p = P cos(xi x) under sigma_yy(0) = -cos(xi x)/s, Laplace domain.

    Independent of the closed form: the three coupled ODEs for u_x = U sin, u_y = V cos, p = P cos
    by second-order finite differences on 0 <= y <= L (fields zero at L).
    """
    G = E / (2 * (1 + nu))
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    Kv = lam + 2 * G
    y = np.linspace(0, L, N + 1)
    h, n = y[1] - y[0], N + 1
    I = sp.identity(n)
    D1 = sp.diags([-np.ones(n - 1), np.ones(n - 1)], [-1, 1], shape=(n, n)) / (2 * h)
    D2 = sp.diags([np.ones(n - 1), -2 * np.ones(n), np.ones(n - 1)], [-1, 0, 1], shape=(n, n)) / h**2
    A = sp.bmat([[G * D2 - Kv * xi**2 * I, -(lam + G) * xi * D1, xi * I],
                 [(lam + G) * xi * D1, Kv * D2 - G * xi**2 * I, -D1],
                 [s * xi * I, s * D1, -k * (D2 - xi**2 * I)]], format="lil")
    rhs = np.zeros(3 * n)
    d0 = np.zeros(n)
    d0[:3] = np.array([-3.0, 4.0, -1.0]) / (2 * h)
    U, V, P = 0, n, 2 * n
    A[U, :] = 0
    A[U, U:U + n] = d0                                      # sigma_xy = 0: U' - xi V = 0
    A[U, V] = -xi
    A[V, :] = 0
    A[V, V:V + n] = (lam + 2 * G) * d0                      # sigma_yy = -1/s
    A[V, U] = lam * xi
    A[V, P] = -1.0
    rhs[V] = -1.0 / s
    A[P, :] = 0
    A[P, P] = 1.0                                           # drained surface
    for off in (U, V, P):
        A[off + n - 1, :] = 0
        A[off + n - 1, off + n - 1] = 1.0
    sol = spl.spsolve(A.tocsr(), rhs)
    return y, sol[P:P + n]


@pytest.mark.parametrize("nu", [0.0, 0.25])
def test_strip_laplace_solution_against_finite_differences(nu):
    E, k = 1.0e4, 1.0e-4
    s_ = StripLoad(E=E, nu=nu, k=k, b=1.0, q=1.0)
    for xi, s in [(1.0, 0.5), (2.0, 5.0), (0.5, 0.05)]:
        errs = []
        for N in (1000, 2000):
            y, P = _fd_laplace_pressure(xi, s, E, nu, k, 40.0 / xi, N)
            exact = pressure_kernel_laplace(xi, y, s / s_.c, s_.eta) / s_.c
            errs.append(np.abs(P - exact).max() / np.abs(exact).max())
        assert errs[1] < 5e-4 and errs[0] / errs[1] > 3.5          # second-order convergence


@pytest.mark.parametrize("s", STRIP_CASES)
def test_strip_limits_and_symmetry(s):
    x = s.b * np.array([0.0, 0.5, 0.95, 1.05, 2.0, 6.0])
    y = s.b * np.array([0.05, 0.3, 1.0, 2.5, 8.0])
    X, Y = np.meshgrid(x, y)
    pu = s.undrained_pressure(X, Y)
    assert np.allclose(s.pressure(X, Y, 0.0), pu, rtol=1e-14, atol=0.0)
    assert pu[0, 0] == pytest.approx(s.q / np.pi * (np.arctan(1 / 0.05) * 2), rel=1e-14)
    # Early time: p - p_u = 2 sqrt(T)(1 - eta)/pi^1.5 [(1+X)/((1+X)^2+Y^2) + (1-X)/((1-X)^2+Y^2)] q.
    T = 1e-8
    t = T * s.b**2 / s.c
    Xd, Yd = X / s.b, Y / s.b
    lead = 2 * np.sqrt(T) * (1 - s.eta) / np.pi**1.5 * (
        (1 + Xd) / ((1 + Xd) ** 2 + Yd**2) + (1 - Xd) / ((1 - Xd) ** 2 + Yd**2))
    dp = (s.pressure(X, Y, t) - pu) / s.q
    assert np.abs(dp - lead).max() < 0.02 * np.abs(lead).max()
    # Late time: drained.
    assert np.abs(s.pressure(X, Y, 1e6 * s.b**2 / s.c)).max() < 1e-3 * s.q
    # Surface drained, symmetric in x; quadrature converged.
    t = 0.1 * s.b**2 / s.c
    assert np.all(s.pressure(x, 0.0, t) == 0.0)
    assert np.array_equal(s.pressure(X, Y, t), s.pressure(-X, Y, t))
    assert np.abs(s.pressure(X, Y, t) - s.pressure(X, Y, t, refine=2.0)).max() < 1e-10 * s.q


def test_strip_boundary_layer_matches_terzaghi():
    """Near the surface under a wide load, early times: the 1-D drained boundary layer erf."""
    s = SEED_STRIP
    T = 1e-6
    t = T * s.b**2 / s.c
    y = s.b * np.sqrt(T) * np.array([0.2, 1.0, 3.0, 6.0])
    tz = Terzaghi(E=s.E, nu=s.nu, k=s.k, H=1.0, q=1.0)        # p0 = 1, c_v = c: semi-infinite at T'<<1
    one_d = tz.pressure(1.0 - y, t)
    undrained_defect = 1.0 - s.undrained_pressure(0.0, y) / s.q   # O(y/b)
    assert np.abs(s.pressure(0.0, y, t) / s.q - (one_d - undrained_defect)).max() < 2e-3


def test_strip_speed_and_seed_values():
    s = SEED_STRIP
    y = np.linspace(0.002, 1.0, 100)
    t = s.time(0.1)
    s.pressure(0.0 * y, y, t)
    t0 = time.perf_counter()
    for T_D in (0.001, 0.1, 10.0):
        s.pressure(0.0 * y, y, s.time(T_D))
    assert time.perf_counter() - t0 < 1.0
    # Regression of the values reported for Figs. 3.11-3.12 of the seed (this implementation).
    assert s.pressure(0.0, 0.2, t) / s.q == pytest.approx(0.58123, abs=5e-6)
    assert s.pressure(0.0, 0.1, t) / s.q == pytest.approx(0.57795, abs=5e-6)
    hist = s.pressure(0.0, 0.2, s.time(np.array([0.001, 0.01, 1.0, 10.0]))) / s.q
    assert np.abs(hist - [0.51135, 0.53580, 0.21367, 0.02876]).max() < 5e-6
