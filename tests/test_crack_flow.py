"""Cracking-enhanced permeability and damaged poroelastic coefficients (eqs. 5.7-5.13)."""
import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.materials.crack_flow import (biot_coefficient, crack_aperture, fracture_permeability, normal_strain,
                                       permeability_tensor, storage_coefficient)

RNG = np.random.default_rng(5)


def unit(angle):
    return np.column_stack([np.cos(angle), np.sin(angle)])


def test_opening_is_the_damaged_normal_strain_over_the_band():
    # A band opening along its normal: eps_yy = e with n = y gives w = D L_s e (5.13) ...
    w = crack_aperture(np.array([0.5, 1.0]), np.array([2e-3, 2e-3]), unit(np.full(2, np.pi / 2)),
                      np.array([[0.0, 1e-3, 0.0], [3e-4, 1e-3, 0.0]]))
    assert w == pytest.approx([0.5 * 2e-3 * 1e-3, 2e-3 * 1e-3], rel=1e-14)
    # ... the normal strain does not depend on the frame ...
    theta = RNG.uniform(0, np.pi, 20)
    c, s = np.cos(theta), np.sin(theta)
    e1 = RNG.uniform(-1e-3, 1e-3, 20)  # strain e1 along n, e2 along t, no shear in that frame
    e2 = RNG.uniform(-1e-3, 1e-3, 20)
    voigt = np.column_stack([e1 * c * c + e2 * s * s, e1 * s * s + e2 * c * c, 2 * (e1 - e2) * c * s])
    assert normal_strain(voigt, unit(theta)) == pytest.approx(e1, abs=1e-18)
    # ... and a closing band has no aperture.
    assert crack_aperture(np.ones(1), np.ones(1), unit(np.zeros(1)), np.array([[-1e-3, 0, 0]]))[0] == 0.0


def test_band_carries_the_parallel_plate_flux():
    """q_s = -k_f grad p . t L_s equals the cubic law q_c = -w^3 / (12 mu) grad p . t (5.9-5.11),
    and across the crack the band keeps the intact mobility."""
    w, ls, mu, k0 = 1e-4, 5e-3, 1e-3, 1e-12
    theta = RNG.uniform(0, np.pi, 8)
    n = unit(theta)
    t = np.column_stack([-n[:, 1], n[:, 0]])
    k = permeability_tensor(k0, fracture_permeability(np.full(8, w), np.full(8, ls), mu), n)
    grad = RNG.standard_normal((8, 2))
    q_band = -np.einsum("mi,mij,mj->m", t, k, grad) * ls
    q_plate = -w**3 / (12 * mu) * np.einsum("mi,mi->m", grad, t)
    assert q_band == pytest.approx(q_plate, rel=1e-12)
    assert np.einsum("mi,mij,mj->m", n, k, n) == pytest.approx(np.full(8, k0), rel=1e-12)
    assert np.allclose(k, np.transpose(k, (0, 2, 1)))


def test_intact_and_barely_open_cracks_keep_the_intact_permeability():
    k = permeability_tensor(np.array([1e-12, 2e-12]), np.array([0.0, 1e-15]), unit(np.array([0.3, 1.2])))
    assert np.allclose(k, np.array([1e-12, 2e-12])[:, None, None] * np.eye(2), rtol=0, atol=1e-27)


def test_damaged_biot_coefficient_and_storage():
    alpha = biot_coefficient(np.array([0.0, 0.5, 1.0]), 10e9, 40e9)
    assert alpha == pytest.approx([0.75, 0.875, 1.0], rel=1e-15)
    s = storage_coefficient(alpha, 0.2, 2.2e9, 40e9)
    assert s == pytest.approx(0.2 / 2.2e9 + (alpha - 0.2) / 40e9, rel=1e-15)
    assert np.all(np.diff(s) > 0)  # a damaged particle stores more fluid


@pytest.mark.parametrize("call, match", [
    (lambda: crack_aperture(np.array([1.5]), np.ones(1), unit(np.zeros(1)), np.zeros((1, 3))), "damage"),
    (lambda: crack_aperture(np.ones(1), np.zeros(1), unit(np.zeros(1)), np.zeros((1, 3))), "band width"),
    (lambda: fracture_permeability(np.ones(1), np.ones(1), 0.0), "viscosity"),
    (lambda: fracture_permeability(-np.ones(1), np.ones(1), 1e-3), "opening"),
    (lambda: permeability_tensor(1e-12, np.ones(2), np.zeros((3, 2))), "normals"),
    (lambda: biot_coefficient(np.zeros(1), 10e9, 5e9), "K_s"),
    (lambda: storage_coefficient(np.array([0.1]), 0.2, 2.2e9, 40e9), r"\[n_f, 1\]"),
    (lambda: storage_coefficient(np.array([0.5]), 1.2, 2.2e9, 40e9), "porosity"),
])
def test_bad_input_names_the_culprit(call, match):
    with pytest.raises(InputError, match=match):
        call()
