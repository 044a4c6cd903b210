"""The Jaumann rotation (6.13): a rigid spin strains nothing and turns a stress as R sigma R^T
(first order in dt), keeping its invariants to O(dt); pure stretch does not rotate."""
import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.materials import jaumann


def _tensor(s):
    return np.array([[s[0], s[3]], [s[3], s[1]]])


def _spun(steps, rate=1.3, t_end=1.0):
    """Error of the stress after a rigid spin v = rate (-y, x) over t_end in `steps` steps."""
    L = np.array([[[0.0, -rate], [rate, 0.0]]])
    s0 = np.array([[-3.0, 1.0, -0.5, 2.0]])
    dt = t_end / steps
    assert np.allclose(jaumann.strain_increment(L, dt), 0.0)
    s = s0.copy()
    for _ in range(steps):
        s = jaumann.rotated(s, L, dt)
    assert s[0, 2] == s0[0, 2]
    c, si = np.cos(rate * t_end), np.sin(rate * t_end)
    R = np.array([[c, -si], [si, c]])
    return np.abs(_tensor(s[0]) - R @ _tensor(s0[0]) @ R.T).max()


def test_rigid_spin_turns_the_stress_to_first_order():
    e = [_spun(n) for n in (200, 400, 800)]
    assert e[-1] < 12.0 / 800
    rates = np.log2(np.array(e[:-1]) / np.array(e[1:]))
    assert np.all((rates > 0.9) & (rates < 1.1)), rates


def test_stretch_does_not_rotate():
    L = np.array([[[0.2, 0.1], [0.1, -0.3]]])
    s = np.array([[1.0, 2.0, 3.0, 4.0]])
    assert np.array_equal(jaumann.rotated(s, L, 0.01), s)
    assert np.allclose(jaumann.strain_increment(L, 0.01), [[0.002, -0.003, 0.002]])


def test_bad_shapes_named():
    with pytest.raises(InputError, match="velocity gradients"):
        jaumann.spin(np.zeros((3, 3)))
    with pytest.raises(InputError, match="stresses"):
        jaumann.rotated(np.zeros((2, 4)), np.zeros((3, 2, 2)), 0.1)
