"""Fluid flow and poroelastic coupling of damaged particles (chapter 5: eqs. 5.2, 5.7-5.13).

A smeared crack at particle I is a band of width L_s = V_I / A_I (its nodal volume over the
chord of its domain along the crack, ``rkfx.fracture.damage.chord_lengths``) with the unit
normal n_I fixed when it initiated. The functions below evaluate, in bulk over particles:

* the crack aperture w = D L_s (n . eps~ . n) from the smeared strain (5.13), never negative
  (a closing band has no aperture). Not to be confused with the normalized opening w / w_c of
  ``rkfx.fracture.damage.crack_opening``, which shows where the cracks are;
* the cubic law of a fracture of opening w smeared over the band, k_fC = w^3 / (12 mu_f L_s)
  (5.12), which makes the band carry the flux of the parallel-plate fracture (5.9)-(5.11);
* the anisotropic permeability k_f = (k_fC - k_f0) t (x) t + k_f0 I along the crack direction
  t (5.8), and the intact k_f0 I (5.7) with k_f0 = k_h / gamma_f. Along t the band conducts at
  least as well as the intact rock (k_fC below k_f0 is raised to k_f0), so that a crack that
  has barely opened never blocks the flow;
* the modified Biot coefficient alpha = 1 - (1 - D) K / K_s (section 5.1.2) and the Biot
  modulus 1/Q = n_f / K_w + (alpha - n_f) / K_s of the storage term.

Permeabilities here are mobilities [m^2/(Pa s)], as in ``rkfx.models.poroelasticity``.
Voigt strains are (eps_xx, eps_yy, gamma_xy) with the engineering shear.
"""
import numpy as np

from rkfx.errors import InputError


def _positive(name: str, value, allow_zero: bool = False) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64)
    ok = np.all(np.isfinite(v)) and (np.all(v >= 0) if allow_zero else np.all(v > 0))
    if not ok:
        raise InputError(f"{name} must be {'non-negative' if allow_zero else 'positive'} and finite; "
                         f"got {v.min() if v.size else v!r}")
    return v


def normal_strain(strain: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """n . eps . n for Voigt strains ``(m, 3)`` and unit normals ``(m, 2)``, shape ``(m,)``."""
    e, n = np.asarray(strain, float), np.asarray(normal, float)
    return n[:, 0] ** 2 * e[:, 0] + n[:, 1] ** 2 * e[:, 1] + n[:, 0] * n[:, 1] * e[:, 2]


def crack_aperture(damage: np.ndarray, band_width: np.ndarray, normal: np.ndarray,
                  strain: np.ndarray) -> np.ndarray:
    """w = D L_s max(n . eps~ . n, 0) (5.13) [m], shape ``(m,)``.

    Args:
        damage: D of each particle, in [0, 1], shape ``(m,)``.
        band_width: L_s = V_I / A_I [m], shape ``(m,)``.
        normal: Unit crack normals n_I, shape ``(m, 2)`` (any vector where D = 0).
        strain: Smeared strains eps~(x_I), Voigt, shape ``(m, 3)``.
    """
    d = np.asarray(damage, float)
    if np.any(~np.isfinite(d)) or np.any((d < 0) | (d > 1)):
        raise InputError("damage must lie in [0, 1]")
    return d * _positive("band width L_s", band_width) * np.maximum(normal_strain(strain, normal), 0.0)


def fracture_permeability(opening: np.ndarray, band_width: np.ndarray, viscosity: float) -> np.ndarray:
    """k_fC = w^3 / (12 mu_f L_s) (5.12) [m^2/(Pa s)], shape like ``opening``.

    Args:
        opening: Crack openings w >= 0 [m].
        band_width: L_s [m].
        viscosity: Dynamic viscosity mu_f of the fluid [Pa s].
    """
    w = _positive("crack opening w", opening, allow_zero=True)
    return w**3 / (12.0 * float(_positive("fluid viscosity mu_f", viscosity)) * _positive("band width L_s", band_width))


def permeability_tensor(k_f0: float | np.ndarray, k_fc: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """k_f = (max(k_fC, k_f0) - k_f0) t (x) t + k_f0 I (5.8) with t the crack direction, the
    normal turned by +90 degrees, shape ``(m, 2, 2)`` [m^2/(Pa s)] (k_fC = 0 gives k_f0 I, 5.7).

    Args:
        k_f0: Intact mobility k_h / gamma_f, a scalar or one per particle ``(m,)``.
        k_fc: Crack mobilities k_fC along t, shape ``(m,)``.
        normal: Unit crack normals, shape ``(m, 2)``.
    """
    k_fc = _positive("crack permeability k_fC", k_fc, allow_zero=True)
    k0 = np.broadcast_to(_positive("intact permeability k_f0", k_f0), k_fc.shape)
    n = np.asarray(normal, float)
    if n.shape != (len(k_fc), 2):
        raise InputError(f"crack normals have shape {n.shape}; give one (n_x, n_y) per particle: ({len(k_fc)}, 2)")
    t = np.column_stack([-n[:, 1], n[:, 0]])
    extra = np.maximum(k_fc, k0) - k0
    return extra[:, None, None] * t[:, :, None] * t[:, None, :] + k0[:, None, None] * np.eye(2)


def biot_coefficient(damage: np.ndarray, bulk_modulus: float, grain_modulus: float) -> np.ndarray:
    """alpha = 1 - (1 - D) K / K_s (section 5.1.2) [-]: 1 - K/K_s intact, 1 fully damaged.

    Args:
        damage: D in [0, 1], shape ``(m,)``.
        bulk_modulus: Drained bulk modulus K of the skeleton [Pa].
        grain_modulus: Bulk modulus K_s of the solid grains [Pa], K_s >= K.
    """
    k, ks = float(_positive("bulk modulus K", bulk_modulus)), float(_positive("grain modulus K_s", grain_modulus))
    if ks < k:
        raise InputError(f"grain modulus K_s = {ks!r} must be at least the skeleton's bulk modulus K = {k!r}")
    d = np.asarray(damage, float)
    if np.any(~np.isfinite(d)) or np.any((d < 0) | (d > 1)):
        raise InputError("damage must lie in [0, 1]")
    return 1.0 - (1.0 - d) * k / ks


def storage_coefficient(alpha: np.ndarray, porosity: float, fluid_modulus: float, grain_modulus: float) -> np.ndarray:
    """1/Q = n_f / K_w + (alpha - n_f) / K_s [1/Pa], the storage S of ``PoroMaterial``.

    Args:
        alpha: Biot coefficients, in [n_f, 1].
        porosity: n_f in (0, 1).
        fluid_modulus: Bulk modulus K_w of the fluid [Pa].
        grain_modulus: K_s [Pa].
    """
    nf = float(porosity)
    if not 0.0 < nf < 1.0:
        raise InputError(f"porosity n_f = {porosity!r} must lie in (0, 1)")
    a = np.asarray(alpha, float)
    if np.any(~np.isfinite(a)) or np.any((a < nf) | (a > 1.0)):
        raise InputError(f"Biot coefficient alpha must lie in [n_f, 1] = [{nf}, 1]")
    return nf / float(_positive("fluid modulus K_w", fluid_modulus)) + (a - nf) / float(
        _positive("grain modulus K_s", grain_modulus))
