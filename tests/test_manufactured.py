"""The manufactured solutions satisfy their equations (checked by finite differences)."""
import numpy as np

from verification.manufactured import SineField


def test_body_force_is_minus_div_sigma():
    f = SineField(lam=1.3, mu=0.7)
    rng = np.random.default_rng(0)
    x = rng.uniform(-1, 2, (50, 2))
    h = 1e-5
    div = np.zeros((50, 2))
    for j in range(2):
        e = np.zeros(2)
        e[j] = h
        ds = (f.stress(x + e) - f.stress(x - e)) / (2 * h)  # d(sigma_xx, sigma_yy, sigma_xy)/dx_j
        div[:, 0] += ds[:, 0] if j == 0 else ds[:, 2]
        div[:, 1] += ds[:, 2] if j == 0 else ds[:, 1]
    assert np.abs(f.body_force(x) + div).max() < 1e-7


def test_gradient_matches_finite_differences():
    f = SineField(lam=1.0, mu=1.0)
    x = np.random.default_rng(1).uniform(0, 1, (20, 2))
    h = 1e-6
    fd = np.stack([(f.displacement(x + h * e) - f.displacement(x - h * e)) / (2 * h) for e in np.eye(2)], axis=2)
    assert np.abs(fd - f.gradient(x)).max() < 1e-8
