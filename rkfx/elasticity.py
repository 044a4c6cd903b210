"""Linear plane-strain elasticity assembled from RK quadratures (eqs. 3.8, 3.32)."""
from dataclasses import dataclass

import numpy as np

from .errors import InputError


@dataclass(frozen=True)
class ElasticMaterial:
    """Isotropic linear elastic solid in plane strain.

    Attributes:
        E: Young's modulus [Pa].
        nu: Poisson's ratio [-].
    """

    E: float
    nu: float

    def __post_init__(self):
        if not (np.isfinite(self.E) and self.E > 0):
            raise InputError(f"Young's modulus E = {self.E!r} must be positive and finite")
        if not (-1.0 < self.nu < 0.5):
            raise InputError(f"Poisson's ratio nu = {self.nu!r} must lie in (-1, 0.5); "
                             "0.5 (incompressible) is not admissible in a displacement formulation")

    @property
    def shear_modulus(self) -> float:
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def lame_lambda(self) -> float:
        return self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    @property
    def bulk_modulus(self) -> float:
        """Drained bulk modulus K = E / (3 (1 - 2 nu)) [Pa]."""
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    @property
    def constrained_modulus(self) -> float:
        """Oedometric modulus K + 4G/3 [Pa]."""
        return self.lame_lambda + 2.0 * self.shear_modulus

    def D(self) -> np.ndarray:
        """Plane-strain elasticity matrix in Voigt form (eps_xx, eps_yy, gamma_xy), shape ``(3, 3)``."""
        lam, mu = self.lame_lambda, self.shear_modulus
        return np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])


def traction_operator(normal: np.ndarray) -> np.ndarray:
    """Maps Voigt stress to traction t = sigma n, shape ``(m, 2, 3)`` for normals ``(m, 2)``."""
    nx, ny = normal[:, 0], normal[:, 1]
    z = np.zeros_like(nx)
    return np.stack([np.stack([nx, z, ny], -1), np.stack([z, ny, nx], -1)], axis=1)
