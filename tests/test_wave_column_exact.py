"""The exact u-p column of verification.wave_column: its limits and its numerical inversion."""
import numpy as np
import pytest

from verification.wave_column import WaveColumn

# The data of §6.4.1 as moduli: E = 254423076.9 Pa, nu = 0.298, K_s = 1.1e10, K_f = 3.3e9, n = 0.48.
_E, _NU = 254423076.9, 0.298
_K = _E / (3 * (1 - 2 * _NU))
_M = _K + 4 * _E / (2 * (1 + _NU)) / 3
_ALPHA = 1 - _K / 1.1e10
_S = 0.48 / 3.3e9 + (_ALPHA - 0.48) / 1.1e10
_RHO = 0.52 * 2700 + 0.48 * 1000


def _column(k=3.55e-9, rho=_RHO):
    return WaveColumn(_M, _ALPHA, _S, k, rho, 10.0, 3000.0)


def _away(times, arrivals, width=1e-3):
    return np.all(np.abs(times[:, None] - arrivals[None, :]) > width, axis=1) & (times > 0)


def test_the_published_limits():
    c = _column()
    assert c.undrained_pressure == pytest.approx(2864.7, abs=0.1)
    assert c.drained_settlement == pytest.approx(8.81e-5, rel=1e-3)
    assert c.fast_speed == pytest.approx(1690, rel=1e-3)
    assert c.c_v == pytest.approx(1.18, rel=5e-3)


def test_transform_limits():
    c = _column()
    s = np.array([1e-7])
    U, _ = c.transform(s, [10.0])
    assert (s * U)[0, 0].real == pytest.approx(-c.drained_settlement, rel=1e-5)
    # The top starts at the undrained impedance's speed q / (rho c) once the drained layer,
    # sqrt(c_v / s) thick, is thin beside a wavelength c / s (here 2e-8 against 0.17 m).
    c = _column(k=1e-18)
    s = np.array([1e4])
    U, _ = c.transform(s, [10.0])
    assert (s * s * U)[0, 0].real == pytest.approx(-c.q / (c.rho * c.fast_speed), rel=1e-3)


def test_quasi_static_limit_is_terzaghi():
    c = _column(rho=1e-9)
    s = np.array([0.01, 0.3, 5.0]) + 0.2j
    y = np.array([0.0, 3.0, 9.0])
    _, P = c.transform(s, y)
    p0 = _ALPHA * c.q / (_ALPHA ** 2 + _S * _M)
    xi = np.sqrt(s / c.c_v)[:, None]
    terzaghi = p0 / s[:, None] * (1 - np.cosh(xi * y) / np.cosh(xi * c.L))
    assert np.allclose(P, terzaghi, rtol=1e-6)


def test_inversion_against_the_undrained_rod():
    # k small enough that the drained layer at the top is thinner than 1e-6 m.
    c = _column(k=1e-22)
    t = np.linspace(0.0, 0.05, 1001)
    u_exact, p_exact = c.undrained_rod([10.0, 0.0], t)
    u, p = c.histories([10.0, 0.0], t)
    top, base = _away(t, c.arrivals(10.0, 0.05)), _away(t, c.arrivals(0.0, 0.05))
    assert np.abs(u[top, 0] - u_exact[top, 0]).max() < 1e-4 * 2 * c.q * c.L / c.M_u
    assert np.abs(p[base, 1] - p_exact[base, 1]).max() < 1e-4 * 2 * c.undrained_pressure
    assert p_exact[:, 1].max() == pytest.approx(2 * c.undrained_pressure)
    assert u_exact[:, 0].min() == pytest.approx(-2 * c.q * c.L / c.M_u, rel=1e-2)


def test_inversion_converges():
    c = _column()
    t = np.linspace(0.0, 0.1, 801)
    base = _away(t, c.arrivals(0.0, 0.1))
    _, p = c.histories([0.0], t)
    _, finer = c.histories([0.0], t, terms=2 ** 18, damping=8.0)
    assert np.abs(p[base] - finer[base]).max() < 1e-4 * c.undrained_pressure


def test_bad_data_named():
    with pytest.raises(ValueError, match="k = "):
        WaveColumn(_M, _ALPHA, _S, 0.0, _RHO, 10.0, 3000.0)
