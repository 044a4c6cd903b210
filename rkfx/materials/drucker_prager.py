"""Drucker-Prager plasticity in plane strain with the return map of an explicit stress update.

Stresses are effective, tension positive, as arrays ``(m, 4)`` of (sigma_xx, sigma_yy,
sigma_zz, sigma_xy); strain increments are Voigt ``(m, 3)`` (d eps_xx, d eps_yy, d gamma_xy)
with d eps_zz = 0. With I_1 = tr sigma, s = sigma - I_1 I / 3 and J_2 = s : s / 2,

    f = sqrt(J_2) + a_phi I_1 - k_c,      g = sqrt(J_2) + a_psi I_1   (plastic potential)

and the constants fitted to Mohr-Coulomb in plane strain (the match at which associated flow
gives Mohr-Coulomb's limit load; as Bui et al. 2008 use them for soil):

    a_phi = tan(phi) / sqrt(9 + 12 tan^2 phi),   k_c = 3 c / sqrt(9 + 12 tan^2 phi),

a_psi the same of the dilatancy angle psi (psi = phi: associated; psi = 0: no dilatancy).

``update`` is one explicit step: the elastic trial sigma* = sigma + D d eps; where it lies
beyond the apex of the cone (I_1* > k_c / a_phi, more tension than a cohesionless or weakly
cohesive soil carries) its mean stress is brought back to the apex, the tension cut-off; then,
where f(sigma*) > 0, the return along dg/dsigma,

    d lambda = f* / (G + 9 K a_phi a_psi),  s = s* (1 - G d lambda / sqrt(J_2*)),
    I_1 = I_1* - 9 K a_psi d lambda,

which ends on f = 0 exactly; a return that would pass the apex ends at the apex. The
equivalent plastic strain grows by sqrt(2/3) |dev d eps^p| = d lambda / sqrt(3). A rotation
of the stress (the Jaumann rate of eq. 6.13) belongs to the model and is applied to sigma
before ``update``.
"""
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError
from rkfx.materials.elasticity import ElasticMaterial


def plane_strain_fit(angle_deg: float) -> float:
    """tan(angle) / sqrt(9 + 12 tan^2 angle): a_phi (or a_psi) of the plane-strain match."""
    t = np.tan(np.radians(angle_deg))
    return float(t / np.sqrt(9.0 + 12.0 * t * t))


def invariants(stress: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """I_1, sqrt(J_2) and the deviator s (m, 4) of stresses ``(m, 4)``."""
    stress = np.asarray(stress, float)
    i1 = stress[:, :3].sum(axis=1)
    s = stress.copy()
    s[:, :3] -= i1[:, None] / 3.0
    j2 = 0.5 * (s[:, 0] ** 2 + s[:, 1] ** 2 + s[:, 2] ** 2) + s[:, 3] ** 2
    return i1, np.sqrt(j2), s


@dataclass(frozen=True)
class StressUpdate:
    """The end of an explicit step at every point.

    Attributes:
        stress: sigma_{n+1}, shape ``(m, 4)`` [Pa].
        plastic_strain: Equivalent plastic strain after the step, shape ``(m,)``.
        yielded: Points that returned to the cone (or its apex), shape ``(m,)``.
    """

    stress: np.ndarray
    plastic_strain: np.ndarray
    yielded: np.ndarray


@dataclass(frozen=True)
class DruckerPrager:
    """An elastic-perfectly plastic Drucker-Prager soil in plane strain (see the module docstring).

    Attributes:
        E: Young's modulus [Pa].
        nu: Poisson's ratio [-].
        phi: Friction angle [degrees], in [0, 90).
        c: Cohesion [Pa], >= 0.
        psi: Dilatancy angle [degrees], in [0, phi].
    """

    E: float
    nu: float
    phi: float
    c: float = 0.0
    psi: float = 0.0

    def __post_init__(self):
        ElasticMaterial(self.E, self.nu)  # validates E and nu
        if not 0.0 <= self.phi < 90.0:
            raise InputError(f"friction angle phi = {self.phi!r} must lie in [0, 90) degrees")
        if not (np.isfinite(self.c) and self.c >= 0.0):
            raise InputError(f"cohesion c = {self.c!r} must be >= 0 Pa")
        if not 0.0 <= self.psi <= self.phi:
            raise InputError(f"dilatancy angle psi = {self.psi!r} must lie in [0, phi = {self.phi}] degrees")
        if self.phi == 0.0 and self.c == 0.0:
            raise InputError("phi = 0 and c = 0 leave the soil no strength; give a friction angle or a cohesion")

    @property
    def shear_modulus(self) -> float:
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def bulk_modulus(self) -> float:
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    @property
    def a_phi(self) -> float:
        return plane_strain_fit(self.phi)

    @property
    def a_psi(self) -> float:
        return plane_strain_fit(self.psi)

    @property
    def k_c(self) -> float:
        t = np.tan(np.radians(self.phi))
        return float(3.0 * self.c / np.sqrt(9.0 + 12.0 * t * t))

    @property
    def apex(self) -> float:
        """I_1 at the apex of the cone, k_c / a_phi (inf without friction) [Pa]."""
        return self.k_c / self.a_phi if self.a_phi > 0 else np.inf

    def yield_function(self, stress: np.ndarray) -> np.ndarray:
        """f of stresses ``(m, 4)`` [Pa]."""
        i1, q, _ = invariants(stress)
        return q + self.a_phi * i1 - self.k_c

    def elastic_increment(self, d_strain: np.ndarray) -> np.ndarray:
        """D d eps in the (xx, yy, zz, xy) components, shape ``(m, 4)`` [Pa]."""
        d = np.asarray(d_strain, float)
        G, K = self.shear_modulus, self.bulk_modulus
        lam = K - 2.0 * G / 3.0
        tr = d[:, 0] + d[:, 1]
        return np.column_stack([lam * tr + 2 * G * d[:, 0], lam * tr + 2 * G * d[:, 1], lam * tr, G * d[:, 2]])

    def update(self, stress: np.ndarray, d_strain: np.ndarray, plastic_strain: np.ndarray) -> StressUpdate:
        """One explicit step from ``stress`` (m, 4) by the strain increments ``d_strain`` (m, 3)."""
        stress, d_strain = np.asarray(stress, float), np.asarray(d_strain, float)
        if stress.ndim != 2 or stress.shape[1] != 4 or d_strain.shape != (len(stress), 3):
            raise InputError(f"stresses {stress.shape} and strain increments {d_strain.shape}: give (m, 4) "
                             "(xx, yy, zz, xy) and (m, 3) (xx, yy, gamma_xy)")
        G, K, a, b, k = self.shear_modulus, self.bulk_modulus, self.a_phi, self.a_psi, self.k_c
        trial = stress + self.elastic_increment(d_strain)
        i1, q, s = invariants(trial)
        yielded = np.zeros(len(trial), bool)
        # Tension cut-off: the mean stress back to the apex.
        over = i1 > self.apex
        if over.any():
            i1 = np.where(over, self.apex, i1)
            yielded |= over
        f = q + a * i1 - k
        dlam = np.zeros(len(trial))
        ret = f > 1e-12 * max(k, 1.0) + 1e-14 * np.abs(i1)
        if ret.any():
            dlam[ret] = f[ret] / (G + 9.0 * K * a * b)
            i1 = np.where(ret, i1 - 9.0 * K * b * dlam, i1)
            scale = np.where(ret, 1.0 - G * dlam / np.where(q > 0, q, 1.0), 1.0)
            past = ret & (scale < 0.0)  # beyond the apex: end there
            scale = np.maximum(scale, 0.0)
            if past.any():
                i1 = np.where(past, self.apex if np.isfinite(self.apex) else i1, i1)
            s = s * scale[:, None]
            yielded |= ret
        out = s.copy()
        out[:, :3] += i1[:, None] / 3.0
        return StressUpdate(out, np.asarray(plastic_strain, float) + dlam / np.sqrt(3.0), yielded)

    def algorithmic_tangent(self, stress: np.ndarray, yielded: np.ndarray, d_lambda: np.ndarray) -> np.ndarray:
        """d sigma / d(d eps) of ``update`` at its result, shape ``(m, 4, 3)`` [Pa]: the stress
        components (xx, yy, zz, xy) against the strain increment's (xx, yy, gamma_xy), for a
        Newton iteration on a finite step.

        ``stress`` and ``yielded`` are the update's, ``d_lambda`` its plastic multiplier
        (sqrt(3) times the growth of the equivalent plastic strain). With n = s / q and
        q* = q + G d lambda the trial's sqrt(J_2):

        * on the cone the return's s = s* (1 - G d lambda / q*) adds to the continuum tangent
          (``tangent_increment``) -(G d lambda / q*) (2 G dev d eps - G (n : d eps) n): the
          deviatoric stiffness across the radial direction falls by that factor;
        * after the tension cut-off (a trial beyond the apex, recognized by I_1 + 9 K a_psi
          d lambda at or above it) the mean stress of the trial is gone: sigma = s* beta_0 +
          (apex - 9 K a_psi q* / H) I / 3 with beta_0 = 9 K a_phi a_psi / H, H = G + 9 K a_phi
          a_psi, so d sigma = beta_0 2 G dev d eps - (3 K a_psi G / H) (n : d eps) I;
        * at the apex 0, and D at the points that stayed elastic.
        """
        stress = np.asarray(stress, float)
        d_lambda = np.asarray(d_lambda, float)
        m = len(stress)
        out = np.empty((m, 4, 3))
        for j in range(3):
            unit = np.zeros((m, 3))
            unit[:, j] = 1.0
            out[:, :, j] = self.tangent_increment(stress, yielded, unit)
        i1, q, s = invariants(stress)
        G, K, a, b = self.shear_modulus, self.bulk_modulus, self.a_phi, self.a_psi
        tiny = 1e-9 * np.maximum(np.abs(i1), max(self.k_c, 1e-300))
        on = np.asarray(yielded, bool) & (q > tiny) & (d_lambda > 0.0)
        cut = on & (i1 + 9.0 * K * b * d_lambda >= self.apex - tiny)
        cone = on & ~cut
        dev = np.zeros((4, 3))                                  # 2 G dev(d eps) per unit strain
        dev[:3, :2] = -2.0 * G / 3.0
        dev[0, 0] += 2.0 * G
        dev[1, 1] += 2.0 * G
        dev[3, 2] = G
        n = s / np.where(q > 0, q, 1.0)[:, None]                # (xx, yy, zz, xy)
        n_de = n[:, [0, 1, 3]]                                  # n : d eps per unit strain (gamma engineering)
        if cone.any():
            factor = G * d_lambda[cone] / (q[cone] + G * d_lambda[cone])
            out[cone] -= factor[:, None, None] * (dev - G * n[cone, :, None] * n_de[cone, None, :])
        if cut.any():
            h = G + 9.0 * K * a * b
            ones = np.array([1.0, 1.0, 1.0, 0.0])
            out[cut] = (9.0 * K * a * b / h) * dev - (3.0 * K * b * G / h) * ones[None, :, None] * n_de[cut, None, :]
        return out

    def tangent_increment(self, stress: np.ndarray, yielded: np.ndarray, d_strain: np.ndarray) -> np.ndarray:
        """C_T : d eps at the stresses of an update, shape ``(m, 4)`` [Pa].

        Off the cone C_T is the elastic D; on it the continuum elastic-plastic tangent
        D - (D : n_g)(n_f : D) / (n_f : D : n_g) with n_f, n_g the gradients of f and g
        (n_f : D : n_g = G + 9 K a_phi a_psi, the denominator of the return); at the apex 0.
        It is not symmetric for non-associated flow (psi < phi).
        """
        out = self.elastic_increment(d_strain)
        yielded = np.asarray(yielded, bool)
        if not yielded.any():
            return out
        G, K, a, b = self.shear_modulus, self.bulk_modulus, self.a_phi, self.a_psi
        d = np.asarray(d_strain, float)
        i1, q, s = invariants(stress)
        tiny = 1e-9 * np.maximum(np.abs(i1), max(self.k_c, 1e-300))
        cone = yielded & (q > tiny)
        apex = yielded & ~cone
        if cone.any():
            sc, qc, dc = s[cone], q[cone], d[cone]
            s_de = sc[:, 0] * dc[:, 0] + sc[:, 1] * dc[:, 1] + sc[:, 3] * dc[:, 2]
            nf_de = G * s_de / qc + 3.0 * K * a * (dc[:, 0] + dc[:, 1])
            d_ng = G * sc / qc[:, None]
            d_ng[:, :3] += 3.0 * K * b
            out[cone] -= d_ng * (nf_de / (G + 9.0 * K * a * b))[:, None]
        out[apex] = 0.0
        return out
