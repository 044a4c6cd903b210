"""Crossing criteria (verification/crossing.py): the tip field by Westergaard's potential, the
amplitudes and the decision by second routes, theta = 90 deg against Renshaw & Pollard, the two
initiation stresses, monotonicity, the asymptote theta* = arctan(1/mu), Blanton's tests, bad input."""
import numpy as np
import pytest
from scipy.optimize import brentq

from rkfx.errors import InputError
from verification import crossing as cx

A = 1.0 / (2.0 * np.sqrt(2.0))          # f_xx = -f_xy = A, f_yy = 3A at phi = 90 deg


def _sample(n, seed, cohesion=True):
    """Random problems with T0 = 1: theta [deg], sigma_H, sigma_h, mu, S0."""
    rng = np.random.default_rng(seed)
    theta = rng.uniform(1.0, 90.0, n)
    sigma_h = rng.uniform(0.0, 5.0, n)
    sigma_H = sigma_h + rng.uniform(0.0, 12.0, n)
    mu = rng.uniform(0.2, 2.0, n)
    S0 = rng.uniform(0.0, 2.0, n) if cohesion else np.zeros(n)
    return theta, sigma_H, sigma_h, mu, S0


def _tensor(s, phi, sigma_H, sigma_h):
    """Tip field plus far field as (..., 2, 2) tensors, tension positive."""
    fxx, fyy, fxy = cx.tip_factors(phi)
    sig = np.empty(np.broadcast(s, phi, sigma_H).shape + (2, 2))
    sig[..., 0, 0] = s * fxx - sigma_H
    sig[..., 1, 1] = s * fyy - sigma_h
    sig[..., 0, 1] = sig[..., 1, 0] = s * fxy
    return sig


def _traction(sig, theta_deg):
    """(sigma_n, tau) on the interface by rotating the tensor into its frame (t, n)."""
    th = np.radians(theta_deg)
    c, s = np.cos(th), np.sin(th)
    R = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)      # columns t, n
    rot = np.swapaxes(R, -1, -2) @ sig @ R
    return rot[..., 1, 1], rot[..., 0, 1]


def _bisect(g, lo, hi, n=200):
    """Vectorised bisection for the first sign change of a monotone-in-bracket predicate g(s) >= 0."""
    for _ in range(n):
        mid = 0.5 * (lo + hi)
        up = g(mid)
        lo, hi = np.where(up, lo, mid), np.where(up, mid, hi)
    return 0.5 * (lo + hi)


# --------------------------------------------------------------------------------------------
# the tip field
# --------------------------------------------------------------------------------------------
def test_tip_field_is_westergaards():
    """s f(phi) = the field of Z = K/sqrt(2 pi z): sxx = Re Z - y Im Z', syy = Re Z + y Im Z', sxy = -y Re Z'."""
    rng = np.random.default_rng(1)
    r, phi = rng.uniform(0.01, 3.0, 500), rng.uniform(-0.999 * np.pi, 0.999 * np.pi, 500)
    z = r * np.exp(1j * phi)
    Z = 1.0 / np.sqrt(2 * np.pi * z)
    dZ = -0.5 / np.sqrt(2 * np.pi) * z**-1.5
    y = z.imag
    ref = np.stack([Z.real - y * dZ.imag, Z.real + y * dZ.imag, -y * dZ.real])
    got = np.stack(cx.tip_factors(phi)) / np.sqrt(2 * np.pi * r)
    assert np.abs(got - ref).max() < 1e-12 * np.abs(ref).max()
    # Renshaw & Pollard's constants are f(90 deg) rounded: 0.35, 1.06, 0.35.
    f90 = np.array(cx.tip_factors(np.pi / 2))
    assert np.allclose(f90, [A, 3 * A, -A], rtol=0, atol=1e-15)
    assert np.allclose(np.round(np.abs(f90), 2), [0.35, 1.06, 0.35])


# --------------------------------------------------------------------------------------------
# the two amplitudes and the decision, by second routes
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("initiation", cx.INITIATIONS)
def test_amplitudes_by_bisection(initiation):
    """s_init by bisection on eigenvalues (or sigma_yy), s_slip by bisection on rotated tractions."""
    theta, sH, sh, mu, S0 = _sample(400, 2)
    state = cx.gu_weng_state(theta, sH, sh, 1.0, mu, S0, initiation)
    s_i, s_s = np.full(400, np.inf), np.full(400, np.inf)
    for phi in (np.radians(theta), np.radians(theta) - np.pi):
        if initiation == "principal":
            stress = lambda s: np.linalg.eigvalsh(_tensor(s, phi, sH, sh))[:, -1]
        else:
            stress = lambda s: _tensor(s, phi, sH, sh)[:, 1, 1]
        s_i = np.minimum(s_i, _bisect(lambda s: stress(s) >= 1.0, np.zeros(400), np.full(400, 1e6)))

        def slip(s):
            n, t = _traction(_tensor(s, phi, sH, sh), theta)
            return np.abs(t) + mu * n - S0 >= 0
        first = np.where(slip(np.zeros(400)), 0.0, _bisect(slip, np.zeros(400), np.full(400, 1e6)))
        s_s = np.minimum(s_s, np.where(slip(np.full(400, 1e6)) | (first == 0), first, np.inf))
    assert np.allclose(state.s_init, s_i, rtol=1e-10, atol=0)
    fin = np.isfinite(s_s)
    assert np.array_equal(fin, np.isfinite(state.s_slip))
    assert np.allclose(state.s_slip[fin], s_s[fin], rtol=1e-10, atol=1e-12)
    assert (state.s_slip == 0).any() and (state.s_slip > 0).any()    # some slip under the far field alone


def test_decision_by_stepwise_loading():
    """Raise s step by step at both intersection points; crossing = sigma_1 reaches T0 before any slip.

    No convexity is used: slip is looked for at every step from s = 0 (every r >= r_c).
    """
    n = 150
    theta, sH, sh, mu, S0 = _sample(n, 3)
    s = np.concatenate([[0.0], np.geomspace(1e-3, 1e3, 7000)])[:, None]
    init_step = np.full(n, len(s))
    slip_step = np.full(n, len(s))
    for phi in (np.radians(theta), np.radians(theta) - np.pi):
        sig = _tensor(s, phi, sH, sh)                                   # (steps, n, 2, 2)
        s1 = np.linalg.eigvalsh(sig)[..., -1]
        nn, tt = _traction(sig, theta)
        for arr, hit in ((init_step, s1 >= 1.0), (slip_step, np.abs(tt) + mu * nn - S0 >= 0)):
            np.minimum(arr, np.where(hit.any(0), hit.argmax(0), len(s)), out=arr)
    brute = init_step < slip_step
    state = cx.gu_weng_state(theta, sH, sh, 1.0, mu, S0)
    clear = np.abs(np.log(state.s_init / np.maximum(state.s_slip, 1e-300))) > 0.01   # not a tie on the grid
    assert clear.sum() > 0.9 * n
    assert np.array_equal(brute[clear], state.crosses[clear])
    assert 0.1 < brute.mean() < 0.9


def test_scale_invariance():
    theta, sH, sh, mu, S0 = _sample(300, 4)
    a = cx.gu_weng_state(theta, sH, sh, 1.0, mu, S0)
    b = cx.gu_weng_state(theta, 3e6 * sH, 3e6 * sh, 3e6, mu, 3e6 * S0)
    assert np.allclose(b.s_init, 3e6 * a.s_init, rtol=1e-12)
    assert np.allclose(b.s_slip, 3e6 * a.s_slip, rtol=1e-12)
    assert np.array_equal(a.mode, b.mode)


# --------------------------------------------------------------------------------------------
# theta = 90 deg: Renshaw & Pollard
# --------------------------------------------------------------------------------------------
def test_renshaw_pollard_is_the_published_inequality():
    mu = np.array([0.3, 0.5, 0.7, 1.0, 2.0])
    R = (0.35 + 0.35 / mu) / 1.06
    assert np.allclose(cx.renshaw_pollard_ratio(mu), R, rtol=1e-15)
    sh, T0 = 4e6, 5e6
    assert not cx.renshaw_pollard(sh + 0 * mu, sh, T0, mu).any() or R.min() * (T0 + sh) < sh
    assert cx.renshaw_pollard((1 + 1e-9) * R * (T0 + sh), sh, T0, mu).all()
    assert not cx.renshaw_pollard((1 - 1e-9) * R * (T0 + sh), sh, T0, mu).any()


def test_gu_weng_at_90_deg_is_renshaw_pollard():
    """With RP's stress, the construction at 90 deg is RP with exact constants (1 + 1/mu)/3 to 1e-12,
    and within 1 % of the published ratio (rounded constants: 0.94 % lower)."""
    mu = np.array([0.3, 0.5, 0.7, 1.0, 1.5])[:, None, None]
    sh = np.array([0.0, 0.25, 0.5])[None, :, None]
    S0 = np.array([0.0, 0.1])[None, None, :]
    got = cx.critical_stress_ratio(90.0, mu, sh, S0, initiation="normal")
    exact = (1 + 1 / mu) / 3 - S0 / (mu * (1 + sh))
    assert np.allclose(got, exact, rtol=1e-12, atol=0)
    published = cx.renshaw_pollard_ratio(mu)
    assert np.allclose(published / ((1 + 1 / mu) / 3), 1.05 / 1.06, rtol=1e-14)
    assert np.all(np.abs(published / got[..., :1] - 1) < 0.01)
    # The modes agree wherever the ratio is more than 1 % away from the threshold.
    rng = np.random.default_rng(5)
    m, h = rng.uniform(0.2, 2.0, 2000), rng.uniform(0.0, 3.0, 2000)
    ratio = rng.uniform(0.2, 3.0, 2000)
    H = np.maximum(ratio * (1 + h), h)
    rp = cx.renshaw_pollard(H, h, 1.0, m)
    gw = cx.gu_weng(90.0, H, h, 1.0, m, initiation="normal") == "cross"
    far = np.abs(H / (1 + h) / cx.renshaw_pollard_ratio(m) - 1) > 0.01
    assert far.sum() > 1800 and np.array_equal(rp[far], gw[far])


def test_principal_stress_at_90_deg_by_hand():
    """sigma_1 initiation at 90 deg: the interface slips at s = (mu sH + S0)/(A (1 + mu)); crossing
    iff sigma_1 there exceeds T0. Solve that for sH by brentq and compare with the window; sigma_1
    > sigma_yy puts R* 6-11 % below RP's (exact) here."""
    for mu in (0.5, 0.75, 1.0):
        for sh in (0.0, 0.5, 1.0):
            for S0 in (0.0, 0.3):
                def t_star(sH):
                    s = (mu * sH + S0) / (A * (1 + mu))
                    sxx, syy, sxy = A * s - sH, 3 * A * s - sh, -A * s
                    return 0.5 * (sxx + syy) + np.hypot(0.5 * (sxx - syy), sxy) - 1.0
                ref = max(sh, brentq(t_star, 0.0, 100.0, xtol=1e-15, rtol=1e-15))
                w = cx.crossing_window(90.0, sh, 1.0, mu, S0)
                assert w.lower == pytest.approx(ref, rel=1e-10) and w.upper == np.inf and w.always == w.lower
                if S0 == 0.0:
                    rp = cx.critical_stress_ratio(90.0, mu, sh, initiation="normal")
                    assert 0.88 < w.lower / (1 + sh) / rp < 0.95


def test_initiation_stresses_agree_at_60_deg():
    """f_xy(60 deg) = 0: sigma_1 = sigma_yy at the acute point, which starts first; same state."""
    assert abs(cx.tip_factors(np.pi / 3)[2]) < 1e-16
    _, sH, sh, mu, S0 = _sample(500, 6)
    p = cx.gu_weng_state(60.0, sH, sh, 1.0, mu, S0, "principal")
    q = cx.gu_weng_state(60.0, sH, sh, 1.0, mu, S0, "normal")
    assert np.allclose(p.s_init, q.s_init, rtol=1e-13) and np.array_equal(p.s_slip, q.s_slip)


@pytest.mark.parametrize("initiation", cx.INITIATIONS)
def test_acute_point_starts_first_and_principal_is_earlier(initiation):
    theta, sH, sh, _, _ = _sample(2000, 7)
    th = np.radians(theta)
    acute = cx._initiation_amplitude(th, sH, sh, 1.0, initiation)
    obtuse = cx._initiation_amplitude(th - np.pi, sH, sh, 1.0, initiation)
    assert np.all(acute <= obtuse * (1 + 1e-12))
    if initiation == "normal":        # sigma_1 >= sigma_yy: the principal construction starts sooner
        assert np.all(cx._initiation_amplitude(th, sH, sh, 1.0, "principal") <= acute * (1 + 1e-12))


def test_obtuse_point_never_decides():
    """The obtuse intersection (phi = theta - 180 deg) never slips before the acute one."""
    rng = np.random.default_rng(9)
    n = 200_000
    th = np.radians(rng.uniform(0.01, 90.0, n))
    sh = rng.uniform(0, 50, n) * rng.integers(0, 2, n)
    sH = sh + 100 * rng.uniform(0, 1, n) ** 3
    mu, S0 = rng.uniform(0.05, 5.0, n), rng.uniform(0, 10, n) * rng.integers(0, 2, n)
    acute = cx._slip_amplitude(th, th, sH, sh, mu, S0)
    obtuse = cx._slip_amplitude(th, th - np.pi, sH, sh, mu, S0)
    assert np.all(obtuse >= acute)


# --------------------------------------------------------------------------------------------
# the critical curve
# --------------------------------------------------------------------------------------------
def test_normal_window_in_closed_form():
    """RP's stress: s_i = (T0 + sh)/f_yy(theta) does not depend on sH, so each slip condition
    +-tau + mu sigma_n - S0 < 0 at s in {0, s_i} on both points is alpha + beta sH < 0: the window is
    an intersection of half-lines."""
    theta, _, sh, mu, S0 = _sample(600, 8)
    th = np.radians(theta)
    s_c = (1 + sh) / cx.tip_factors(th)[1]
    lower, upper = sh.copy(), np.full_like(sh, np.inf)
    empty = np.zeros(sh.shape, bool)
    for phi in (th, th - np.pi):
        for s in (0 * s_c, s_c):
            n0, t0 = _traction(_tensor(s, phi, 0.0, sh), theta)        # sH = 0 part
            n1, t1 = _traction(_tensor(0 * s, phi, 1.0, 0.0), theta)    # d/d sH
            for sign in (1.0, -1.0):
                alpha, beta = sign * t0 + mu * n0 - S0, sign * t1 + mu * n1
                root = -alpha / np.where(beta == 0, 1.0, beta)
                lower = np.where(beta < 0, np.maximum(lower, root), lower)
                upper = np.where(beta > 0, np.minimum(upper, root), upper)
                empty |= (beta == 0) & (alpha >= 0)
    empty |= lower >= upper
    w = cx.crossing_window(theta, sh, 1.0, mu, S0, "normal")
    assert np.array_equal(empty, np.isinf(w.lower))
    ok = ~empty
    assert np.allclose(w.lower[ok], lower[ok], rtol=1e-9)
    assert np.array_equal(np.isinf(w.upper[ok]), np.isinf(upper[ok]))
    fin = ok & np.isfinite(upper)
    assert np.allclose(w.upper[fin], upper[fin], rtol=1e-9)
    assert 0.2 < empty.mean() < 0.8 and fin.any()
    # One interval: every sH above crosses iff it is unbounded above.
    always = np.where(ok & np.isinf(upper), lower, np.inf)
    assert np.array_equal(np.isinf(w.always), np.isinf(always))
    assert np.allclose(w.always[np.isfinite(always)], always[np.isfinite(always)], rtol=1e-9)


@pytest.mark.parametrize("initiation", cx.INITIATIONS)
def test_asymptote_at_arctan_one_over_mu(initiation):
    """R* grows like 1/(theta - theta*) above theta* = arctan(1/mu); just below, no sH crosses."""
    for mu in (0.5, 0.7, 1.0):
        ts = np.degrees(np.arctan(1 / mu))
        R = cx.critical_stress_ratio(ts + np.array([1.0, 0.1, 0.01]), mu, 1.0, initiation=initiation)
        assert np.all(np.isfinite(R)) and R[1] / R[0] == pytest.approx(10, rel=0.2)
        assert R[2] / R[1] == pytest.approx(10, rel=0.05)
        assert cx.crossing_window(ts - 0.01, 1.0, 1.0, mu, initiation=initiation).lower == np.inf
    assert np.degrees(np.arctan(1 / 0.7)) == pytest.approx(55.008, abs=1e-3)


@pytest.mark.parametrize("initiation", cx.INITIATIONS)
def test_monotonicity_cohesionless(initiation):
    """Larger mu and larger theta favour crossing; a larger stress difference does above theta*,
    and favours arrest below it; the crossing set in sH switches at most once; R* falls with theta."""
    th = np.linspace(1.0, 90.0, 90)[:, None, None, None]
    dH = np.geomspace(1e-3, 1e3, 80)[None, :, None, None]
    sh = np.array([0.0, 0.5, 2.0, 8.0, 30.0])[None, None, :, None]
    mu = np.array([0.3, 0.5, 0.7, 0.9, 1.2, 2.0])[None, None, None, :]
    cross = cx.gu_weng_state(th, sh + dH, sh, 1.0, mu, 0.0, initiation).crosses.astype(int)
    assert np.all(np.diff(cross, axis=3) >= 0)          # mu
    assert np.all(np.diff(cross, axis=0) >= 0)          # theta
    above = np.broadcast_to(th > np.degrees(np.arctan(1 / mu)), cross[:, 1:].shape)
    d = np.diff(cross, axis=1)
    switches = np.broadcast_to(np.abs(d).sum(axis=1, keepdims=True), d.shape)
    assert np.all(d[above & (switches <= 1)] >= 0) and np.all(d[~above] <= 0)
    # Two switches (cross, arrest, cross again) only with sigma_1, high confinement and mu >= 1.5,
    # within 5 deg above theta*: see test_two_windows_near_theta_star.
    two = np.argwhere(switches[:, 0] > 1)
    if initiation == "normal":
        assert two.size == 0
    else:
        t, h, m = th.ravel()[two[:, 0]], sh.ravel()[two[:, 1]], mu.ravel()[two[:, 2]]
        assert len(two) > 0
        assert np.all(m >= 1.5) and np.all(h >= 6) and np.all(t < np.degrees(np.arctan(1 / m)) + 5)
    assert np.abs(d).sum(axis=1).max() <= 2
    assert cross.any() and not cross.all()
    h = np.array([[0.0], [1.0], [3.0]])
    R = cx.critical_stress_ratio(np.linspace(56.0, 90.0, 35), 0.7, h, initiation=initiation)
    floor = h / (1 + h)                        # R* = sigma_h/(T0 + sigma_h): every sigma_H crosses
    dR = np.diff(R, axis=1)
    assert np.all(np.isfinite(R)) and np.all(R >= floor) and np.all(dR <= 0)
    assert np.all(dR[R[:, 1:] > floor + 1e-12] < 0)


@pytest.mark.parametrize("initiation", cx.INITIATIONS)
def test_crossing_below_theta_star_needs_confinement(initiation):
    """Cohesionless, below theta*: no sH crosses for mu <= 0.5, nor for mu = 0.7 unless sigma_h > 15 T0."""
    for mu, sh_none, sh_some in ((0.3, 1e3, None), (0.5, 1e3, None), (0.7, 15.0, 30.0)):
        ts = np.degrees(np.arctan(1 / mu))
        th = np.linspace(0.5, ts - 1e-6, 60)[:, None]
        sh = np.linspace(0.0, 15.0, 16) if sh_none == 15.0 else np.geomspace(1e-2, sh_none, 16)
        sh = sh[None, :]
        assert np.all(np.isinf(cx.crossing_window(th, sh, 1.0, mu, initiation=initiation).lower))
        if sh_some:
            w = cx.crossing_window(th, sh_some, 1.0, mu, initiation=initiation)
            assert np.any(np.isfinite(w.lower)) and np.all(np.isinf(w.always))


def test_two_windows_near_theta_star():
    """sigma_1 initiation, mu = 2 (theta* = 26.57 deg), sigma_h = 8 T0, theta = 27 deg: crossing at
    small stress differences, arrest at intermediate ones, crossing again at large ones."""
    w = cx.crossing_window(27.0, 8.0, 1.0, 2.0)
    assert w.lower == 8.0 and 8.0 < w.upper < w.always < np.inf
    probe = np.array([0.5 * (w.lower + w.upper), 0.5 * (w.upper + w.always), 2.0 * w.always])
    assert list(cx.gu_weng(27.0, probe, 8.0, 1.0, 2.0)) == ["cross", "arrest", "cross"]
    assert cx.critical_stress_ratio(27.0, 2.0, 8.0) == pytest.approx(w.always / 9.0, rel=1e-14)
    n = cx.crossing_window(27.0, 8.0, 1.0, 2.0, initiation="normal")        # one interval with sigma_yy
    assert n.lower == n.always and n.upper == np.inf


# --------------------------------------------------------------------------------------------
# Blanton's tests (Wei 2018 Table 5.1), mu = 0.7, T0 = 5 MPa
# --------------------------------------------------------------------------------------------
def test_blanton_table():
    assert [t.observed for t in cx.BLANTON] == ["arrest", "arrest", "cross", "arrest"]
    rows = cx.blanton_modes()
    assert [r.ratio for r in rows] == pytest.approx([0.8, 19 / 15, 2.0, 2.0], rel=1e-14)
    # Renshaw & Pollard, the angle ignored: 2 of 4 (CT-7 and CT-9 predicted to cross).
    assert [r.rp for r in rows] == ["arrest", "cross", "cross", "cross"]
    assert rows[0].rp_critical == pytest.approx(0.80189, abs=1e-5)
    # Gu & Weng: 3 of 4, CT-8 predicted arrested (sH/(T0 + sh) = 2.00 against R* = 3.64).
    assert [r.gw for r in rows] == ["arrest"] * 4
    assert [r.gw_critical for r in rows] == pytest.approx([2.5366, np.inf, 3.6382, np.inf], rel=1e-4)
    assert [r.gw_margin for r in rows] == pytest.approx([0.74988, 0.41881, 0.76405, 0.0], abs=1e-5)
    assert [r.gw for r in cx.blanton_modes(initiation="normal")] == ["arrest"] * 4
    # The fluid pressure opens the interface in the three arrested tests, not in CT-8.
    assert [r.opens for r in rows] == [True, True, False, True]
    # CT-9: the far field alone slips the interface, tau = 6.50 MPa > mu sigma_n = 6.13 MPa.
    th = np.radians(30.0)
    assert 15e6 * np.sin(th) * np.cos(th) > 0.7 * (20e6 * np.sin(th) ** 2 + 5e6 * np.cos(th) ** 2)


def test_blanton_what_would_flip_ct8():
    """CT-8 crosses for mu > 0.834 or T0 < 2.64 MPa; CT-4 stays arrested below mu = 1.30, above
    T0 = 1.25 MPa; CT-7 and CT-9 only for mu > 8.8 (none of this is fitted, it is reported)."""
    def margin(t, mu=0.7, T0=5e6):
        s = cx.gu_weng_state(t.theta, t.sigma_H, t.sigma_h, T0, mu)
        return np.log(s.s_slip / s.s_init)
    ct4, ct7, ct8, ct9 = cx.BLANTON
    assert brentq(lambda m: margin(ct8, mu=m), 0.7, 1.0) == pytest.approx(0.83395, abs=1e-4)
    assert brentq(lambda x: margin(ct8, T0=x), 1e6, 5e6) == pytest.approx(2.6405e6, rel=1e-4)
    assert brentq(lambda m: margin(ct4, mu=m), 1.0, 2.0) == pytest.approx(1.29904, abs=1e-4)
    assert brentq(lambda x: margin(ct4, T0=x), 1e5, 5e6) == pytest.approx(1.2482e6, rel=1e-3)
    for t in (ct7, ct9):
        assert cx.gu_weng(t.theta, t.sigma_H, t.sigma_h, 5e6, 8.8) == "arrest"


# --------------------------------------------------------------------------------------------
# bad input
# --------------------------------------------------------------------------------------------
GOOD = dict(theta=60.0, sigma_H=20e6, sigma_h=5e6, T0=5e6, mu=0.7)


@pytest.mark.parametrize("change, culprit", [
    (dict(theta=0.0), "theta = 0 deg must lie in (0, 90]"),
    (dict(theta=[45.0, 95.0]), "theta = 95 deg must lie in (0, 90]"),
    (dict(theta=np.nan), "theta = nan is not finite"),
    (dict(sigma_H=4e6), "sigma_H = 4e+06 Pa < sigma_h = 5e+06 Pa"),
    (dict(sigma_h=-1e6, sigma_H=2e6), "sigma_h = -1e+06 Pa must be >= 0"),
    (dict(mu=0.0), "mu = 0 must be > 0"),
    (dict(mu=-0.5), "mu = -0.5 must be > 0"),
    (dict(T0=0.0), "T0 = 0 must be > 0"),
    (dict(cohesion=-1.0), "cohesion = -1 must be >= 0"),
    (dict(initiation="tangential"), "initiation = 'tangential' not offered"),
])
def test_bad_input_gu_weng(change, culprit):
    with pytest.raises(InputError) as err:
        cx.gu_weng(**{**GOOD, **change})
    msg = str(err.value)
    assert msg.startswith("gu_weng: ") and culprit in msg and "\n" not in msg


@pytest.mark.parametrize("call, culprit", [
    (lambda: cx.renshaw_pollard(20e6, 5e6, 5e6, 0.0), "renshaw_pollard: mu = 0 must be > 0"),
    (lambda: cx.renshaw_pollard(4e6, 5e6, 5e6, 0.7), "renshaw_pollard: sigma_H = 4e+06 Pa < sigma_h"),
    (lambda: cx.renshaw_pollard(20e6, 5e6, -5e6, 0.7), "renshaw_pollard: T0 = -5e+06 must be > 0"),
    (lambda: cx.critical_stress_ratio(120.0, 0.7), "crossing_window: theta = 120 deg must lie in (0, 90]"),
    (lambda: cx.critical_stress_ratio(60.0, 0.7, -1.0), "crossing_window: sigma_h = -1 Pa must be >= 0"),
    (lambda: cx.interface_opens(60.0, 20e6, 5e6, np.inf), "interface_opens: pressure = inf is not finite"),
    (lambda: cx.blanton_modes(mu=0.0), "mu = 0 must be > 0"),
])
def test_bad_input_others(call, culprit):
    with pytest.raises(InputError, match=None) as err:
        call()
    assert culprit in str(err.value) and "\n" not in str(err.value)
