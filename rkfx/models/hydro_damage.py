"""Damaged poroelastic particles (chapter 5): the per-particle u-p fields of the hydro-mechanically
coupled damage particle method.

The u-p equations are those of chapter 3 (``rkfx.models.poroelasticity``, eqs. 5.14-5.15), with
each particle's material degraded by its damage D:

* the effective stress (1 - D) C eps~ (5.3)-(5.5), with 1 - D kept at or above ``residual``
  (the seed's low residual strength: a fully cracked particle keeps a trace of stiffness, so
  that the stiffness matrix stays regular however many particles fail);
* the Biot coefficient alpha = 1 - (1 - D) K / K_s and the storage 1/Q = n_f / K_w +
  (alpha - n_f) / K_s (``rkfx.materials.crack_flow``), when the grains' modulus is given;
  otherwise the material's constants;
* the anisotropic permeability (5.8) of the cracked band, k_fC = w^3 / (12 mu_f L_s) (5.12)
  along the crack with the aperture w = D L_s n . eps~ . n (5.13), when the crack bands are given.

``damaged_fields`` returns them as the ``NodalFields`` that ``biot_operators`` and ``solve_biot``
integrate. ``crack_apertures`` gives w of every particle from a solution's smeared strain.
"""
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError
from rkfx.fracture.damage import band_widths, cell_geometry
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.materials import crack_flow
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.poroelasticity import NodalFields

RESIDUAL_STIFFNESS = 1e-6  # 1 - D never below this [-]


@dataclass(frozen=True)
class CrackBands:
    """The smeared crack of each particle: its normal and band width.

    Attributes:
        normal: Unit crack normals n_I, shape ``(n, 2)`` (any unit vector where D = 0).
        width: L_s = V_I / A_I [m], shape ``(n,)``.
    """

    normal: np.ndarray
    width: np.ndarray

    def __post_init__(self):
        n, w = np.asarray(self.normal, float), np.asarray(self.width, float)
        if n.ndim != 2 or n.shape[1] != 2 or w.shape != (len(n),):
            raise InputError(f"crack bands: normals of shape {n.shape} and widths of shape {w.shape}; give "
                             "(n, 2) unit normals and (n,) widths")
        if not np.allclose(np.hypot(n[:, 0], n[:, 1]), 1.0, atol=1e-9):
            raise InputError("crack bands: the normals must be unit vectors")


def crack_bands(domains: NodalDomains, normal: np.ndarray) -> CrackBands:
    """The bands of the nodal domains for crack normals ``(n, 2)`` (L_s from the chords, chapter 4)."""
    normal = np.asarray(normal, float)
    nodes = np.arange(len(domains.area))
    return CrackBands(normal, band_widths(cell_geometry(domains), domains.area, nodes, normal))


def crack_apertures(damage: np.ndarray, bands: CrackBands, strain: np.ndarray) -> np.ndarray:
    """w = D L_s max(n . eps~ . n, 0) (5.13) of every particle [m], shape ``(n,)``."""
    return crack_flow.crack_aperture(damage, bands.width, bands.normal, strain)


def crack_permeability(mobility: float, damage: np.ndarray, bands: CrackBands, strain: np.ndarray,
                       viscosity: float) -> np.ndarray:
    """k_f (5.8) of every particle, shape ``(n, 2, 2)`` [m^2/(Pa s)]: k_fC = w^3 / (12 mu_f L_s)
    (5.12) along the crack with w (5.13) from the smeared ``strain``, k_f0 = ``mobility`` across."""
    w = crack_apertures(damage, bands, strain)
    return crack_flow.permeability_tensor(mobility, crack_flow.fracture_permeability(w, bands.width, viscosity),
                                          bands.normal)


def _damage(damage, n: int | None = None) -> np.ndarray:
    d = np.asarray(damage, float).reshape(-1)
    if n is not None and len(d) != n:
        raise InputError(f"damage has {len(d)} values; give one per particle ({n})")
    if np.any(~np.isfinite(d)) or np.any((d < 0) | (d > 1)):
        raise InputError("damage must lie in [0, 1] at every particle")
    return d


def damaged_fields(elastic: ElasticMaterial, damage: np.ndarray, *, residual: float = RESIDUAL_STIFFNESS,
                   grain_modulus: float | None = None, porosity: float | None = None,
                   fluid_modulus: float | None = None, mobility: float | None = None,
                   bands: CrackBands | None = None, strain: np.ndarray | None = None,
                   viscosity: float | None = None) -> NodalFields:
    """Per-particle u-p fields of damaged particles.

    Args:
        elastic: The intact skeleton (drained E, nu).
        damage: D of each particle, in [0, 1], shape ``(n,)``.
        residual: Least stiffness fraction 1 - D, in (0, 1).
        grain_modulus: K_s [Pa]: alpha = 1 - (1 - D) K / K_s; with ``porosity`` and
            ``fluid_modulus`` (K_w [Pa]) also the storage 1/Q. ``None``: the material's constants.
        mobility: Intact k_f0 = k_h / gamma_w [m^2/(Pa s)]; with ``bands``, the smeared
            ``strain`` (Voigt, ``(n, 3)``) and ``viscosity`` mu_f [Pa s], the anisotropic
            permeability (5.8) with k_fC (5.12) from the aperture (5.13).
    """
    if not 0.0 < residual < 1.0:
        raise InputError(f"residual = {residual!r}: the least stiffness fraction 1 - D must lie in (0, 1)")
    d = _damage(damage)
    n = len(d)
    stiffness = np.maximum(1.0 - d, residual)[:, None, None] * elastic.D()[None]
    alpha = storage = k = None
    if grain_modulus is not None:
        alpha = crack_flow.biot_coefficient(d, elastic.bulk_modulus, grain_modulus)
        if porosity is not None or fluid_modulus is not None:
            if porosity is None or fluid_modulus is None:
                raise InputError("the storage 1/Q needs both porosity and fluid_modulus (with grain_modulus)")
            storage = crack_flow.storage_coefficient(alpha, porosity, fluid_modulus, grain_modulus)
    if bands is not None:
        if mobility is None or strain is None or viscosity is None:
            raise InputError("the crack permeability (5.8) needs mobility, strain and viscosity with the bands")
        if len(bands.width) != n:
            raise InputError(f"crack bands for {len(bands.width)} particles; give one per particle ({n})")
        k = crack_permeability(mobility, d, bands, strain, viscosity)
    return NodalFields(D=stiffness, k=k, alpha=alpha, S=storage)
