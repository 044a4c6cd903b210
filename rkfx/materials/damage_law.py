"""Mazars' equivalent strain (4.6) and the linear-softening damage law (4.2), compiled.

The one implementation of the damage law at a point: the quasi-static update
(``rkfx.fracture.damage.update``), the explicit internal force (``rkfx.models.damage_dynamics.DamageForce``)
and the array functions of ``rkfx.fracture.damage`` (``equivalent_strain``, ``damage``) all evaluate
it through these functions.

* ``principal_strains_at``, ``equivalent_strain_at``, ``damage_at``: the law at one point
  (scalars in, scalars out), inlined into the loops below.
* ``strain_kernel`` and ``damage_kernel``: one pass over the damage points each, in
  parallel, writing into arrays the caller owns (no allocation), so that the explicit
  driver can call them at every step. Between the two passes the caller fixes the crack
  normal and kappa_c of the points that cross their threshold (``rkfx.fracture.damage.initiate``).
  ``strain_kernel_serial`` and ``damage_kernel_serial`` run the same point updates on the
  calling thread, for the quasi-static update.

Voigt strains are (eps_xx, eps_yy, gamma_xy) with the engineering shear; ``nu_zz`` is the
out-of-plane ratio r of eps_zz = -r (eps_xx + eps_yy) (``rkfx.materials.elasticity.out_of_plane_ratio``:
nu / (1 - nu) in plane stress, 0 in plane strain).
"""
import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def principal_strains_at(exx, eyy, gxy):
    """In-plane principal strains (major, minor) of a Voigt strain with engineering shear."""
    mean = 0.5 * (exx + eyy)
    r = np.sqrt(0.25 * (exx - eyy) ** 2 + 0.25 * gxy * gxy)
    return mean + r, mean - r


@numba.njit(cache=True, inline="always")
def equivalent_strain_at(exx, eyy, gxy, nu_zz):
    """Mazars' eps_eq = sqrt(sum <eps_I>^2) over the three principal strains (4.6) [-]."""
    e1, e2 = principal_strains_at(exx, eyy, gxy)
    e1 = max(e1, 0.0)
    e2 = max(e2, 0.0)
    ezz = max(-nu_zz * (exx + eyy), 0.0)
    return np.sqrt(e1 * e1 + e2 * e2 + ezz * ezz)


@numba.njit(cache=True, inline="always")
def damage_at(kappa, kappa0, kappa_c):
    """Linear-softening damage D(kappa) of (4.2) [-].

    0 below kappa0; 1 - (kappa0 / kappa) (kappa_c - kappa) / (kappa_c - kappa0) on
    [kappa0, kappa_c), where the stress E (1 - D) kappa falls linearly from f_t to 0; 1 from
    kappa_c on. Where kappa_c <= kappa0 (or NaN) the law has no softening branch and D jumps
    to 1 at kappa0 (perfectly brittle).
    """
    if not kappa >= kappa0:
        return 0.0
    if not kappa_c > kappa0 or kappa >= kappa_c:
        return 1.0
    return 1.0 - kappa0 / kappa * (kappa_c - kappa) / (kappa_c - kappa0)


@numba.njit(cache=True, inline="always")
def _strain_point(i, strain, c, nu_zz, allowed, damaged, kappa0, eq, effective, crossing):
    exx = strain[i, 0]
    eyy = strain[i, 1]
    gxy = strain[i, 2]
    eq[i] = equivalent_strain_at(exx, eyy, gxy, nu_zz)
    for j in range(3):
        effective[i, j] = c[j, 0] * exx + c[j, 1] * eyy + c[j, 2] * gxy
    crossing[i] = allowed[i] and not damaged[i] and eq[i] >= kappa0[i]


@numba.njit(cache=True, inline="always")
def _damage_point(i, eq, effective, allowed, damaged, kappa0, kappa_c, kappa, damage, stress):
    if allowed[i] and eq[i] > kappa[i]:
        kappa[i] = eq[i]
    d = 0.0
    if damaged[i]:
        d = damage_at(kappa[i], kappa0[i], kappa_c[i])
        damage[i] = d
    s = 1.0 - d
    for j in range(3):
        stress[i, j] = s * effective[i, j]


@numba.njit(parallel=True, cache=True)
def strain_kernel(strain, c, nu_zz, allowed, damaged, kappa0, eq, effective, crossing):
    """Mazars' eps_eq (4.6) and the effective stress C e of every point, in parallel.

    Args:
        strain: Voigt strains, shape ``(m, 3)``.
        c: Elasticity matrix, shape ``(3, 3)`` [Pa].
        nu_zz: Out-of-plane ratio (module docstring).
        allowed: Points that may damage, shape ``(m,)`` bool.
        damaged: Points that have initiated, shape ``(m,)`` bool.
        kappa0: Damage thresholds, shape ``(m,)``.
        eq: Out: eps_eq, shape ``(m,)``.
        effective: Out: C e, shape ``(m, 3)`` [Pa].
        crossing: Out: allowed undamaged points with eps_eq >= kappa0, shape ``(m,)`` bool.
    """
    for i in numba.prange(strain.shape[0]):
        _strain_point(i, strain, c, nu_zz, allowed, damaged, kappa0, eq, effective, crossing)


@numba.njit(parallel=True, cache=True)
def damage_kernel(eq, effective, allowed, damaged, kappa0, kappa_c, kappa, damage, stress):
    """History kappa = max(kappa, eps_eq) (4.3)-(4.5) where allowed, D(kappa) (4.2) where
    damaged, and the smeared stress (1 - D) C e (4.30) everywhere, in parallel.

    Args:
        eq, effective: From ``strain_kernel``.
        allowed, damaged, kappa0: As for ``strain_kernel``.
        kappa_c: Critical strains, shape ``(m,)`` (read where damaged only).
        kappa: In/out: the history, shape ``(m,)``.
        damage: Out where damaged (left alone elsewhere): D, shape ``(m,)``.
        stress: Out: (1 - D) C e, shape ``(m, 3)`` [Pa] (D = 0 where not damaged).
    """
    for i in numba.prange(eq.shape[0]):
        _damage_point(i, eq, effective, allowed, damaged, kappa0, kappa_c, kappa, damage, stress)


@numba.njit(cache=True)
def strain_kernel_serial(strain, c, nu_zz, allowed, damaged, kappa0, eq, effective, crossing):
    """``strain_kernel`` on the calling thread (a few hundred points inside a Newton loop,
    where waking the thread pool at every call costs more than the loop)."""
    for i in range(strain.shape[0]):
        _strain_point(i, strain, c, nu_zz, allowed, damaged, kappa0, eq, effective, crossing)


@numba.njit(cache=True)
def damage_kernel_serial(eq, effective, allowed, damaged, kappa0, kappa_c, kappa, damage, stress):
    """``damage_kernel`` on the calling thread (see ``strain_kernel_serial``)."""
    for i in range(eq.shape[0]):
        _damage_point(i, eq, effective, allowed, damaged, kappa0, kappa_c, kappa, damage, stress)


@numba.njit(cache=True)
def principal_strains_kernel(strain, values):
    """``principal_strains_at`` of every row of ``strain`` ``(m, 3)`` into ``values`` ``(m, 2)``."""
    for i in range(strain.shape[0]):
        values[i, 0], values[i, 1] = principal_strains_at(strain[i, 0], strain[i, 1], strain[i, 2])


@numba.njit(cache=True)
def equivalent_strain_kernel(strain, nu_zz, eq):
    """``equivalent_strain_at`` of every row of ``strain`` ``(m, 3)`` into ``eq`` ``(m,)``."""
    for i in range(strain.shape[0]):
        eq[i] = equivalent_strain_at(strain[i, 0], strain[i, 1], strain[i, 2], nu_zz)


@numba.njit(cache=True)
def damage_array_kernel(kappa, kappa0, kappa_c, out):
    """``damage_at`` elementwise over 1-D arrays of one length into ``out``."""
    for i in range(kappa.shape[0]):
        out[i] = damage_at(kappa[i], kappa0[i], kappa_c[i])
