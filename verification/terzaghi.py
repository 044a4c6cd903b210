"""Terzaghi's one-dimensional consolidation of a poroelastic column, general Biot parameters.

A column 0 <= z <= H (z upward from the base) under zero lateral strain. At t = 0+ a compressive
load q [Pa] is applied to the top z = H, which is drained (p = 0); the base z = 0 is fixed and
impermeable. Conventions of the seed (Wei 2018, eqs. 3.1-3.10): tensile effective stress positive,
pore pressure p compressive positive, total stress sigma = sigma'' - alpha p I, storage equation

    alpha d(eps_zz)/dt + S dp/dt - k d2p/dz2 = 0,

S = 1/Q the storage coefficient [1/Pa] (S = 0: incompressible constituents), k = k_h / gamma_f the
mobility [m^2/(Pa s)]. With the constrained (oedometric) modulus K_v = K + 4G/3 = E(1-nu)/((1+nu)
(1-2nu)), equilibrium gives sigma_zz = K_v eps_zz - alpha p = -q, hence (Verruijt, *Theory and
Problems of Poroelasticity*, ch. 2; Wang, *Theory of Linear Poroelasticity*, sec. 6.2)

    dp/dt = c_v d2p/dz2,  c_v = k K_v / (alpha^2 + S K_v)          (= eq. 3.54 of the seed)
    p(z, 0+) = p0 = alpha q / (alpha^2 + S K_v)                     (undrained response)

With zeta = z/H, T = c_v t / H^2 and M_m = (2m + 1) pi / 2, the Fourier series is

    p / p0 = sum_m 2 (-1)^m / M_m  cos(M_m zeta) exp(-M_m^2 T)

and the short-time (image / erfc) series [Carslaw & Jaeger, *Conduction of Heat in Solids*,
sec. 3.3 eq. (12), slab -H < z < H with both faces at zero]

    p / p0 = 1 - sum_n (-1)^n [erfc((2n + 1 - zeta)/(2 sqrt T)) + erfc((2n + 1 + zeta)/(2 sqrt T))].

Integrating eps_zz = (alpha p - q)/K_v from the fixed base:

    u_z = -q z / K_v + (alpha p0 H / K_v) * I(zeta, T),   I = int_0^zeta p/p0 dzeta'
    I   = sum_m 2 (-1)^m / M_m^2 sin(M_m zeta) exp(-M_m^2 T)                    (Fourier)
        = zeta - 2 sqrt(T) sum_n (-1)^n [ierfc((2n+1-zeta)/(2 sqrt T)) - ierfc((2n+1+zeta)/(2 sqrt T))]
                                                                               (erfc form)

with ierfc(x) = exp(-x^2)/sqrt(pi) - x erfc(x). u_z(z, 0+) = -q z S / (alpha^2 + S K_v) (zero for
incompressible constituents) and u_z(z, inf) = -q z / K_v. The degree of consolidation is
U(T) = 1 - I(1, T) = 1 - sum_m 2/M_m^2 exp(-M_m^2 T).

Truncation (both series are evaluated with enough terms for an error below 1e-10 p0 at every
t > 0): the Fourier series keeps the N terms with M_N^2 T <= 40 (e^-40 = 4e-18; at most 10^5
terms, evaluated in chunks, so valid for T >= 4e-10); the erfc series keeps the n with
2n / (2 sqrt T) <= 6.5 (erfc(6.5) = 4e-20). ``method="auto"`` uses erfc for T < 0.5 (a handful of
terms) and Fourier above. t = 0 is read as t = 0+ (undrained state; p = 0 exactly at z = H).
Units: lengths [m], E, q, p [Pa], k [m^2/(Pa s)], t [s].
"""
from dataclasses import dataclass

import numpy as np
from scipy.special import erfc

from verification.moduli import DrainedModuli

_FOURIER_EXPONENT = 40.0     # keep terms with M^2 T <= 40
_FOURIER_MAX_TERMS = 100_000
_ERFC_ARGUMENT = 6.5         # drop image terms with argument > 6.5
_AUTO_SWITCH_T = 0.5         # method="auto": erfc below, Fourier above


def _ierfc(x):
    """First repeated integral of erfc: int_x^inf erfc(s) ds = exp(-x^2)/sqrt(pi) - x erfc(x)."""
    return np.exp(-x * x) / np.sqrt(np.pi) - x * erfc(x)


def _fourier_terms(T_min: float) -> int:
    """Number of Fourier terms with M_N^2 T_min > 40 (so the tail is below 1e-16)."""
    n = int(np.ceil(np.sqrt(_FOURIER_EXPONENT / T_min) / np.pi + 0.5)) + 1
    if n > _FOURIER_MAX_TERMS:
        raise ValueError(f"Fourier series needs {n} > {_FOURIER_MAX_TERMS} terms at T = {T_min:.3g}; "
                         "use method='erfc'")
    return n


def _fourier_sum(zeta, T, integral: bool):
    """sum_m 2(-1)^m/M^j cos|sin(M zeta) exp(-M^2 T), j = 1 (pressure) or 2 (its integral).

    zeta, T: 1-D arrays of equal length, T > 0. Terms in chunks to bound memory.
    """
    out = np.zeros_like(zeta)
    n_terms = _fourier_terms(T.min())
    chunk = max(1, 2_000_000 // max(len(zeta), 1))
    for m0 in range(0, n_terms, chunk):
        m = np.arange(m0, min(m0 + chunk, n_terms))
        M = (2 * m + 1) * np.pi / 2
        sign = np.where(m % 2 == 0, 1.0, -1.0)
        arg = np.outer(zeta, M)
        decay = np.exp(-np.outer(T, M * M))
        if integral:
            out += (np.sin(arg) * decay) @ (2 * sign / M**2)
        else:
            out += (np.cos(arg) * decay) @ (2 * sign / M)
    return out


def _erfc_sum(zeta, T, integral: bool):
    """Image series: p/p0 (integral=False) or I = int_0^zeta p/p0 (integral=True); T > 0."""
    s = 2.0 * np.sqrt(T)
    n_max = int(np.ceil(_ERFC_ARGUMENT * s.max() / 2.0)) + 1
    acc = np.zeros_like(zeta)
    for n in range(n_max + 1):
        a = 2 * n + 1
        sign = 1.0 if n % 2 == 0 else -1.0
        if integral:
            acc += sign * (_ierfc((a - zeta) / s) - _ierfc((a + zeta) / s))
        else:
            acc += sign * (erfc((a - zeta) / s) + erfc((a + zeta) / s))
    return zeta - s * acc if integral else 1.0 - acc


@dataclass(frozen=True)
class Terzaghi(DrainedModuli):
    """One-dimensional consolidation of a column of height H under a step load q.

    Attributes:
        E: Drained Young's modulus [Pa].
        nu: Drained Poisson's ratio [-].
        k: Mobility k_h / gamma_f [m^2/(Pa s)].
        H: Column height [m]; z = 0 fixed impermeable base, z = H drained loaded top.
        q: Applied load, compressive positive [Pa].
        alpha: Biot coefficient [-].
        S: Storage coefficient 1/Q [1/Pa]; 0 for incompressible constituents.
    """

    E: float
    nu: float
    k: float
    H: float
    q: float
    alpha: float = 1.0
    S: float = 0.0

    @property
    def p0(self) -> float:
        """Undrained pressure at t = 0+: alpha q / (alpha^2 + S K_v) [Pa]."""
        return self.alpha * self.q / (self.alpha**2 + self.S * self.K_v)

    @property
    def c_v(self) -> float:
        """Consolidation coefficient k K_v / (alpha^2 + S K_v) [m^2/s]."""
        return self.k * self.K_v / (self.alpha**2 + self.S * self.K_v)

    def dimensionless_time(self, t):
        """T = c_v t / H^2 [-]."""
        return self.c_v * np.asarray(t, float) / self.H**2

    def _series(self, z, t, integral: bool, method: str):
        z, t = np.broadcast_arrays(np.asarray(z, float), np.asarray(t, float))
        shape = z.shape
        zeta = (z / self.H).ravel()
        T = self.dimensionless_time(t).ravel()
        if np.any(T < 0):
            raise ValueError("t must be >= 0 (t = 0 is read as 0+)")
        out = np.empty_like(zeta)
        zero = T == 0.0
        # t = 0+: undrained, p/p0 = 1 inside and 0 on the drained top; I = zeta.
        out[zero] = zeta[zero] if integral else np.where(zeta[zero] < 1.0, 1.0, 0.0)
        if method == "auto":
            use_erfc = (T < _AUTO_SWITCH_T) & ~zero
            use_fourier = (T >= _AUTO_SWITCH_T)
        elif method == "erfc":
            use_erfc, use_fourier = ~zero, np.zeros_like(zero)
        elif method == "fourier":
            use_erfc, use_fourier = np.zeros_like(zero), ~zero
        else:
            raise ValueError(f"method must be 'auto', 'fourier' or 'erfc', not {method!r}")
        if use_erfc.any():
            out[use_erfc] = _erfc_sum(zeta[use_erfc], T[use_erfc], integral)
        if use_fourier.any():
            out[use_fourier] = _fourier_sum(zeta[use_fourier], T[use_fourier], integral)
        return out.reshape(shape)

    def pressure(self, z, t, method: str = "auto"):
        """Pore pressure p(z, t) [Pa]; z [m] in [0, H], t [s] >= 0, broadcast together.

        ``method``: "auto" (erfc series for T < 0.5, Fourier above), "fourier" or "erfc";
        all are truncated below 1e-10 p0 (module docstring).
        """
        return self.p0 * self._series(z, t, False, method)

    def displacement(self, z, t, method: str = "auto"):
        """Vertical displacement u_z(z, t) [m], negative (downward) under compression; u_z(0) = 0."""
        z = np.asarray(z, float)
        I = self._series(z, t, True, method)
        return -self.q * z / self.K_v + self.alpha * self.p0 * self.H / self.K_v * I

    def settlement(self, t, method: str = "auto"):
        """Downward displacement of the top, -u_z(H, t) [m]."""
        return -self.displacement(self.H, t, method)

    def degree_of_consolidation(self, t, method: str = "auto"):
        """U(t) = (u(H,t) - u(H,0+)) / (u(H,inf) - u(H,0+)) = 1 - mean(p)/p0 [-]."""
        return 1.0 - self._series(np.full_like(np.asarray(t, float), self.H), t, True, method)
