"""Kirsch's plate-with-a-hole solution checked against itself: Hooke, equilibrium, boundary data."""
import numpy as np
import pytest

from verification.kirsch import Kirsch

CASES = [Kirsch(E=1.0e3, nu=0.3, a=1.0, T=1.0), Kirsch(E=2.5e7, nu=0.45, a=0.3, T=-4.0e4),
         Kirsch(E=1.0, nu=0.0, a=2.0, T=1.0)]


def _ring_points(k: Kirsch, n=400, r_max=6.0, seed=0):
    rng = np.random.default_rng(seed)
    r = k.a * rng.uniform(1.0, r_max, n)
    th = rng.uniform(0.0, 2 * np.pi, n)
    return np.column_stack([r * np.cos(th), r * np.sin(th)])


def _fd_gradient(f, x, step):
    """Central differences of f: (m, 2) -> (m, c); returns (m, c, 2)."""
    return np.stack([(f(x + step * e) - f(x - step * e)) / (2 * step) for e in np.eye(2)], axis=-1)


def _hooke(k: Kirsch, grad):
    """Plane-strain stress (xx, yy, xy) from displacement gradients (m, 2, 2)."""
    lam = k.E * k.nu / ((1 + k.nu) * (1 - 2 * k.nu))
    mu = k.mu
    exx, eyy, exy = grad[:, 0, 0], grad[:, 1, 1], 0.5 * (grad[:, 0, 1] + grad[:, 1, 0])
    tr = exx + eyy
    return np.column_stack([lam * tr + 2 * mu * exx, lam * tr + 2 * mu * eyy, 2 * mu * exy])


@pytest.mark.parametrize("k", CASES)
def test_displacement_strain_gives_the_stress(k):
    """Finite-difference strain of u through plane-strain Hooke = the stress formula."""
    x = _ring_points(k)
    grad = _fd_gradient(k.displacement, x, 1e-6 * k.a)
    scale = abs(k.T)
    assert np.abs(_hooke(k, grad) - k.stress(x)).max() < 1e-6 * scale
    # The complex-step gradient agrees with finite differences, and is exact through Hooke.
    g = k.displacement_gradient(x)
    assert np.abs(g - grad).max() < 1e-7 * np.abs(g).max()
    assert np.abs(_hooke(k, g) - k.stress(x)).max() < 1e-12 * scale


@pytest.mark.parametrize("k", CASES)
def test_equilibrium(k):
    """div sigma = 0 (no body force), by central differences of the stress formula."""
    x = _ring_points(k)
    d = _fd_gradient(k.stress, x, 1e-5 * k.a)  # (m, 3, 2)
    div = np.column_stack([d[:, 0, 0] + d[:, 2, 1], d[:, 2, 0] + d[:, 1, 1]])
    assert np.abs(div).max() < 1e-6 * abs(k.T) / k.a


@pytest.mark.parametrize("k", CASES)
def test_boundary_and_far_field(k):
    th = np.linspace(0.0, 2 * np.pi, 97)
    n = np.column_stack([np.cos(th), np.sin(th)])
    # Traction-free hole (outward normal of the plate points into the hole: -n; sign irrelevant).
    assert np.abs(k.traction(k.a * n, -n)).max() < 1e-13 * abs(k.T)
    # Stress concentration 3T at (0, +-a), -T at (+-a, 0).
    s = k.stress(np.array([[0.0, k.a], [0.0, -k.a], [k.a, 0.0]]))
    np.testing.assert_allclose(s[:, 0], [3 * k.T, 3 * k.T, 0.0], atol=1e-12 * abs(k.T))
    np.testing.assert_allclose(s[2, 1], -k.T, atol=1e-12 * abs(k.T))
    # Remote uniaxial tension.
    far = k.stress(1e4 * k.a * n)
    np.testing.assert_allclose(far, np.tile([k.T, 0.0, 0.0], (len(n), 1)), atol=1e-7 * abs(k.T))
    # Symmetry planes of the quarter model: u_x = 0 on x = 0 and u_y = 0 on y = 0.
    s_line = k.a * np.linspace(1.0, 5.0, 9)
    assert np.abs(k.displacement(np.column_stack([0 * s_line, s_line]))[:, 0]).max() < 1e-15 * abs(k.T)
    assert np.abs(k.displacement(np.column_stack([s_line, 0 * s_line]))[:, 1]).max() < 1e-15 * abs(k.T)


def test_remote_strain_is_uniaxial_plane_strain():
    """Far away u tends to the uniform plane-strain field of sigma_xx = T."""
    k = CASES[0]
    x = np.array([[3.0e3, 4.0e3], [-5.0e3, 1.0e3]])
    g = k.displacement_gradient(x)
    exx = (1 - k.nu**2) * k.T / k.E
    eyy = -k.nu * (1 + k.nu) * k.T / k.E
    np.testing.assert_allclose(g[:, 0, 0], exx, rtol=1e-5)
    np.testing.assert_allclose(g[:, 1, 1], eyy, rtol=1e-5)
