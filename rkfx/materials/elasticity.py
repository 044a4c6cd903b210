"""Linear isotropic elasticity in 2-D, plane strain or plane stress (eqs. 3.8, 3.32), and the
principal directions of Voigt tensors.

One law for the RK solvers and the FEM baselines: ``ElasticMaterial`` gives the Lame
constants of the 2-D law and its Voigt matrix D (eps_xx, eps_yy, gamma_xy). In plane stress
(sigma_zz = 0) the law keeps the form sigma = lambda* tr(eps) I + 2 mu eps with the effective
lambda* = 2 lambda mu / (lambda + 2 mu) = E nu / (1 - nu^2).
"""
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError

PLANES = ("strain", "stress")


def check_plane(plane: str) -> None:
    """Raise an InputError unless ``plane`` is ``"strain"`` or ``"stress"``."""
    if plane not in PLANES:
        raise InputError(f"plane = {plane!r} is not a 2-D idealization; choose 'strain' or 'stress'")


def out_of_plane_ratio(nu: float, plane: str = "strain") -> float:
    """r with eps_zz = -r (eps_xx + eps_yy): nu / (1 - nu) in plane stress, 0 in plane strain [-]."""
    check_plane(plane)
    return nu / (1.0 - nu) if plane == "stress" else 0.0


@dataclass(frozen=True)
class ElasticMaterial:
    """Isotropic linear elastic solid in plane strain or plane stress.

    Attributes:
        E: Young's modulus [Pa].
        nu: Poisson's ratio [-].
        plane: ``"strain"`` (eps_zz = 0) or ``"stress"`` (sigma_zz = 0): the 2-D idealization.
    """

    E: float
    nu: float
    plane: str = "strain"

    def __post_init__(self):
        if not (np.isfinite(self.E) and self.E > 0):
            raise InputError(f"Young's modulus E = {self.E!r} must be positive and finite")
        if not (-1.0 < self.nu < 0.5):
            raise InputError(f"Poisson's ratio nu = {self.nu!r} must lie in (-1, 0.5); "
                             "0.5 (incompressible) is not admissible in a displacement formulation")
        check_plane(self.plane)

    @property
    def shear_modulus(self) -> float:
        """Shear modulus mu = E / (2 (1 + nu)) [Pa], the same in both 2-D laws."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def lame_lambda(self) -> float:
        """Lame's first constant lambda = E nu / ((1 + nu) (1 - 2 nu)) of the 3-D solid [Pa]."""
        return self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    @property
    def plane_lambda(self) -> float:
        """lambda of the 2-D law [Pa]: lambda in plane strain, lambda* = 2 lambda mu / (lambda + 2 mu)
        in plane stress."""
        lam, mu = self.lame_lambda, self.shear_modulus
        return lam if self.plane == "strain" else 2.0 * lam * mu / (lam + 2.0 * mu)

    @property
    def lame(self) -> tuple[float, float]:
        """``(lambda, mu)`` of the 2-D law sigma = lambda tr(eps) I + 2 mu eps [Pa]."""
        return self.plane_lambda, self.shear_modulus

    @property
    def out_of_plane_ratio(self) -> float:
        """r with eps_zz = -r (eps_xx + eps_yy) (``out_of_plane_ratio``) [-]."""
        return out_of_plane_ratio(self.nu, self.plane)

    @property
    def bulk_modulus(self) -> float:
        """Drained bulk modulus K = E / (3 (1 - 2 nu)) of the 3-D solid [Pa]."""
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    @property
    def constrained_modulus(self) -> float:
        """Oedometric modulus K + 4G/3 = lambda + 2 mu of the 3-D solid [Pa] (either plane)."""
        return self.lame_lambda + 2.0 * self.shear_modulus

    def D(self) -> np.ndarray:
        """Elasticity matrix of the 2-D law in Voigt form (eps_xx, eps_yy, gamma_xy), shape ``(3, 3)`` [Pa]."""
        lam, mu = self.lame
        return np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])

    def D3(self) -> np.ndarray:
        """Elasticity matrix of the 3-D solid in Voigt form (eps_xx, eps_yy, eps_zz, gamma_yz, gamma_xz,
        gamma_xy), shape ``(6, 6)`` [Pa] (``plane`` plays no part)."""
        lam, mu = self.lame_lambda, self.shear_modulus
        d = np.zeros((6, 6))
        d[:3, :3] = lam
        d[[0, 1, 2], [0, 1, 2]] = lam + 2 * mu
        d[[3, 4, 5], [3, 4, 5]] = mu
        return d

    def voigt(self, dim: int) -> np.ndarray:
        """D of the 2-D law (``dim`` 2) or of the 3-D solid (``dim`` 3) [Pa]."""
        return self.D() if dim == 2 else self.D3()


def principal_direction(voigt: np.ndarray, kind: str = "stress") -> np.ndarray:
    """Unit direction of the major principal value of Voigt tensors: the crack normal n_L.

    theta = atan2(2 t_xy, t_xx - t_yy) / 2 with the tensor shear t_xy: sigma_xy for a stress,
    gamma_xy / 2 for a strain in engineering shear.

    Args:
        voigt: Voigt tensors, shape ``(m, 3)``: (sigma_xx, sigma_yy, sigma_xy) or
            (eps_xx, eps_yy, gamma_xy).
        kind: ``"stress"`` (tensor shear) or ``"strain"`` (engineering shear gamma_xy).

    Returns:
        (cos theta, sin theta), shape ``(m, 2)``.
    """
    v = np.asarray(voigt, float).reshape(-1, 3)
    if kind == "stress":
        theta = 0.5 * np.arctan2(2.0 * v[:, 2], v[:, 0] - v[:, 1])
    elif kind == "strain":
        theta = 0.5 * np.arctan2(v[:, 2], v[:, 0] - v[:, 1])
    else:
        raise InputError(f"kind = {kind!r}: choose 'stress' (shear sigma_xy) or 'strain' (shear gamma_xy)")
    return np.column_stack([np.cos(theta), np.sin(theta)])


def traction_operator(normal: np.ndarray) -> np.ndarray:
    """Maps Voigt stress to traction t = sigma n, shape ``(m, 2, 3)`` for normals ``(m, 2)``, or
    ``(m, 3, 6)`` for normals ``(m, 3)`` (Voigt order xx, yy, zz, yz, xz, xy)."""
    if normal.shape[1] == 3:
        nx, ny, nz = normal[:, 0], normal[:, 1], normal[:, 2]
        z = np.zeros_like(nx)
        return np.stack([np.stack([nx, z, z, z, nz, ny], -1), np.stack([z, ny, z, nz, z, nx], -1),
                         np.stack([z, z, nz, ny, nx, z], -1)], axis=1)
    nx, ny = normal[:, 0], normal[:, 1]
    z = np.zeros_like(nx)
    return np.stack([np.stack([nx, z, ny], -1), np.stack([z, ny, nx], -1)], axis=1)
