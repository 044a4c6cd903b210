"""Retention laws of chapter 6 (6.7, 6.80-6.83): saturated below zero suction, slopes equal to
difference quotients, the two published Liakopoulos forms, Mualem's k_rw end points, 1/Q."""
import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.materials.retention import GAMMA_W, Liakopoulos, Retention, VanGenuchten, storage, storage_slope

LAWS = [Liakopoulos(), Liakopoulos.lewis_schrefler(), VanGenuchten(S_rw=0.0842, n=2.0, beta=0.7)]


@pytest.mark.parametrize("law", LAWS)
def test_saturated_at_and_below_zero_suction(law):
    assert isinstance(law, Retention)
    s = np.array([-5e3, -1.0, 0.0])
    assert np.all(law.saturation(s) == 1.0) and np.all(law.relative_permeability(s) == 1.0)
    assert np.all(law.saturation_slope(s) == 0.0) and np.all(law.relative_permeability_slope(s) == 0.0)


@pytest.mark.parametrize("law", LAWS)
def test_slope_is_the_derivative(law):
    s = np.linspace(500.0, 2.0e4, 40)
    h = 1e-3 * s
    fd = (law.saturation(s + h) - law.saturation(s - h)) / (2 * h)
    assert np.allclose(law.saturation_slope(s), fd, rtol=1e-6)
    assert np.all(np.diff(law.saturation(s)) < 0) and np.all(np.diff(law.relative_permeability(s)) <= 0)


@pytest.mark.parametrize("law", LAWS)
def test_permeability_and_storage_slopes_are_the_derivatives(law):
    s = np.linspace(500.0, 1.2e4, 40)
    h = 1e-3 * s
    fd = (law.relative_permeability(s + h) - law.relative_permeability(s - h)) / (2 * h)
    live = law.relative_permeability(s) > law.k_min
    assert live.sum() > 10
    assert np.allclose(law.relative_permeability_slope(s)[live], fd[live], rtol=1e-5)
    assert np.all(law.relative_permeability_slope(s[~live]) == 0.0)
    p = -s
    args = (0.3, 1.0, 2e9, 1e12)
    fd = (storage(law, p + h, *args) - storage(law, p - h, *args)) / (2 * h)
    assert np.allclose(storage_slope(law, p, *args), fd, rtol=1e-3)


def test_the_two_liakopoulos_forms():
    s = np.array([1e3, 5e3, 1e4])
    assert np.allclose(1 - Liakopoulos.lewis_schrefler().saturation(s), 1.9722e-11 * s ** 2.4279, rtol=1e-3)
    seed = Liakopoulos()
    assert np.allclose(1 - seed.saturation(s), 0.10152 * (s / GAMMA_W) ** 2.4279)
    assert np.allclose(seed.relative_permeability(s), 1 - 2.207 * (1 - seed.saturation(s)))
    # about 5 % apart in 1 - S_w: (1e4 / 9806)^2.4279
    ratio = (1 - seed.saturation(s)) / (1 - Liakopoulos.lewis_schrefler().saturation(s))
    assert np.allclose(ratio, (1e4 / GAMMA_W) ** 2.4279)


def test_mualem_end_points_and_floor():
    law = VanGenuchten(S_rw=0.0842, n=2.0, beta=0.7)
    assert law.saturation(1e12) == pytest.approx(law.S_rw, abs=1e-6)
    assert law.relative_permeability(1e12) == law.k_min
    se = law.effective_saturation(1e4)
    assert se == pytest.approx((1 + (0.7 * 1e4 / GAMMA_W) ** 2) ** -0.5)


def test_storage_reduces_to_the_saturated_modulus():
    n, alpha, K_w, K_s = 0.3, 0.95, 2e9, 1e12
    assert storage(Liakopoulos(), 0.0, n, alpha, K_w, K_s) == pytest.approx(n / K_w + (alpha - n) / K_s)
    unsat = storage(Liakopoulos(), -5e3, n, alpha, K_w, K_s)
    assert unsat > n / K_w  # the retention slope adds storage


@pytest.mark.parametrize("make, match", [(lambda: VanGenuchten(1.0, 2.0, 0.7), "S_rw"),
                                         (lambda: VanGenuchten(0.1, 1.0, 0.7), "n = "),
                                         (lambda: VanGenuchten(0.1, 2.0, -1.0), "beta"),
                                         (lambda: Liakopoulos(b=0.5), "b = ")])
def test_bad_parameters_named(make, match):
    with pytest.raises(InputError, match=match):
        make()
