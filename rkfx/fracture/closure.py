"""Crack closure of a smeared crack band: a closed crack carries compression across it.

Isotropic damage (4.30, 5.3) takes the stiffness (1 - D) C in compression as in tension, so a
failed band squeezed across its crack gives way although its faces are in contact. With
closure the free energy of a damaged point is

    psi = (1 - D) psi_0(eps) + D (M / 2) <n . eps . n>_-^2,

with psi_0 the elastic energy, n the crack normal, <x>_- = min(x, 0) and M = lambda + 2 mu the
stiffness across a crack under uniaxial strain. The stress and its tangent gain

    sigma_c = D M <eps_nn>_- v,      C_c = D M H(-eps_nn) v (x) v,      v = (n_x^2, n_y^2, n_x n_y),

(Voigt, engineering shear; eps_nn = v . eps), so an open crack (eps_nn > 0) is unchanged and a
closed, fully damaged one carries sigma_nn = M eps_nn. The damage itself evolves as before (the
equivalent strain reads the positive principal strains); ``damaged`` is the fraction of
stiffness the damage removed, 1 - max(1 - D, residual) where a residual stiffness is kept. The
tangent leaves out the change of D within a step (exact under the impl-ex update, where D is
fixed over a step's iterates).
"""
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError
from rkfx.materials.crack_flow import normal_strain


@dataclass(frozen=True)
class CrackClosure:
    """The closure terms of the module docstring.

    Attributes:
        modulus: M, the stiffness across a closed crack [Pa] (``for_material``: lambda + 2 mu).
    """

    modulus: float

    def __post_init__(self):
        if not (np.isfinite(self.modulus) and self.modulus > 0):
            raise InputError(f"closure modulus = {self.modulus!r} must be positive and finite [Pa]")

    @classmethod
    def for_material(cls, elasticity: np.ndarray) -> "CrackClosure":
        """M = C_11 of the Voigt elasticity ``elasticity`` (lambda + 2 mu in plane strain)."""
        return cls(float(np.asarray(elasticity)[0, 0]))

    def stress(self, strain: np.ndarray, normal: np.ndarray, damaged: np.ndarray) -> np.ndarray:
        """sigma_c of every point, shape ``(m, 3)`` [Pa].

        Args:
            strain: Voigt strains, shape ``(m, 3)``.
            normal: Unit crack normals, shape ``(m, 2)`` (any unit vector where ``damaged`` is 0).
            damaged: The stiffness fraction the damage removed, shape ``(m,)``.
        """
        v = direction(normal)
        closed = np.minimum(normal_strain(strain, normal), 0.0)
        return (np.asarray(damaged, float) * self.modulus * closed)[:, None] * v

    def tangent(self, strain: np.ndarray, normal: np.ndarray, damaged: np.ndarray) -> np.ndarray:
        """C_c of every point, shape ``(m, 3, 3)`` [Pa] (arguments as ``stress``)."""
        v = direction(normal)
        return self.normal_stiffness(strain, normal, damaged)[:, None, None] * v[:, :, None] * v[:, None, :]

    def normal_stiffness(self, strain: np.ndarray, normal: np.ndarray, damaged: np.ndarray) -> np.ndarray:
        """D M H(-eps_nn) of every point, shape ``(m,)`` [Pa]: C_c = this times v (x) v."""
        return (normal_strain(strain, normal) < 0.0) * np.asarray(damaged, float) * self.modulus


def direction(normal: np.ndarray) -> np.ndarray:
    """v = (n_x^2, n_y^2, n_x n_y) with eps_nn = v . eps, shape ``(m, 3)``."""
    n = np.asarray(normal, float)
    return np.column_stack([n[:, 0] ** 2, n[:, 1] ** 2, n[:, 0] * n[:, 1]])
