"""The 2-D elastic law (plane strain and plane stress) and the principal directions of Voigt tensors."""
import numpy as np
import pytest

from rkfx.materials.elasticity import ElasticMaterial, out_of_plane_ratio, principal_direction
from rkfx.errors import InputError


def test_plane_strain_matrix_from_lame_constants():
    m = ElasticMaterial(2.0e3, 0.3)
    lam = 2.0e3 * 0.3 / (1.3 * 0.4)
    mu = 2.0e3 / 2.6
    assert m.plane == "strain" and m.lame == (m.lame_lambda, m.shear_modulus)
    assert np.allclose(m.lame, (lam, mu), rtol=1e-14)
    assert np.allclose(m.D(), [[lam + 2 * mu, lam, 0], [lam, lam + 2 * mu, 0], [0, 0, mu]], rtol=1e-14)
    assert m.out_of_plane_ratio == 0.0


def test_plane_stress_matrix_is_the_textbook_one():
    """D = E / (1 - nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]], lambda* = E nu / (1 - nu^2)."""
    E, nu = 2.0e3, 0.3
    m = ElasticMaterial(E, nu, "stress")
    c = E / (1 - nu**2)
    assert np.allclose(m.D(), c * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, 0.5 * (1 - nu)]]), rtol=1e-14)
    lam, mu = m.lame
    assert np.isclose(lam, E * nu / (1 - nu**2), rtol=1e-14) and mu == m.shear_modulus
    # sigma_zz = 0: eps_zz = -lambda (eps_xx + eps_yy) / (lambda + 2 mu) of the 3-D solid.
    lam3 = m.lame_lambda
    assert np.isclose(m.out_of_plane_ratio, lam3 / (lam3 + 2 * mu), rtol=1e-14)
    assert np.isclose(out_of_plane_ratio(nu, "stress"), nu / (1 - nu), rtol=1e-14)
    # The 3-D moduli do not depend on the 2-D idealization.
    s = ElasticMaterial(E, nu)
    assert (m.constrained_modulus, m.bulk_modulus) == (s.constrained_modulus, s.bulk_modulus)


def test_uniaxial_stress_in_plane_stress():
    """eps = (sigma / E, -nu sigma / E, 0) carries sigma_xx = sigma alone."""
    m = ElasticMaterial(5.0, 0.25, "stress")
    assert np.allclose(m.D() @ [2.0 / 5.0, -0.25 * 2.0 / 5.0, 0.0], [2.0, 0.0, 0.0], atol=1e-14)


@pytest.mark.parametrize("plane", ["membrane", "", None])
def test_bad_plane_names_the_value_and_the_choices(plane):
    with pytest.raises(InputError, match=r"plane = .*choose 'strain' or 'stress'"):
        ElasticMaterial(1.0, 0.3, plane)
    with pytest.raises(InputError, match="plane"):
        out_of_plane_ratio(0.3, plane)


def test_principal_direction_of_stress_and_of_engineering_strain():
    """The same tensor as a stress (shear t_xy) and as a strain (gamma_xy = 2 t_xy) has one
    major direction, the rotation angle of its principal axes."""
    angles = np.array([0.0, 0.3, -1.0, np.pi / 2 - 0.01, 1.2])
    t1, t2 = 5.0, -2.0
    c, s = np.cos(angles), np.sin(angles)
    txx, tyy, txy = t1 * c**2 + t2 * s**2, t1 * s**2 + t2 * c**2, (t1 - t2) * s * c
    n_stress = principal_direction(np.column_stack([txx, tyy, txy]))
    n_strain = principal_direction(np.column_stack([txx, tyy, 2 * txy]), "strain")
    expected = np.column_stack([c, s])
    for n in (n_stress, n_strain):
        assert np.allclose(np.linalg.norm(n, axis=1), 1.0)
        assert np.allclose(np.abs(np.sum(n * expected, axis=1)), 1.0)
    assert np.allclose(n_stress, n_strain, atol=1e-15)
    with pytest.raises(InputError, match="kind"):
        principal_direction(np.zeros((1, 3)), "tension")
