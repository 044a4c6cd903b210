"""Water retention and relative permeability of unsaturated soil (eqs. 6.7, 6.14, 6.80-6.83).

A retention law gives, as functions of the suction s = p_a - p_w [Pa] (zero air pressure, so
s = -p_w; s <= 0 is saturated), evaluated in bulk over arrays:

    saturation(s)            S_w in (0, 1]
    saturation_slope(s)      dS_w / ds  (<= 0; dS_w / dp_w = -dS_w / ds)
    relative_permeability(s) k_rw in (0, 1], scaling the permeability k^w = (k_rw / mu_w) k_in (6.14)
    relative_permeability_slope(s)  dk_rw / ds (0 where k_rw is floored)

Laws:

* ``Liakopoulos`` — (6.80)-(6.81), S_w = 1 - a (s / gamma_w)^b, k_rw = 1 - c (1 - S_w)^d with
  a = 0.10152, b = 2.4279, c = 2.207, d = 1 and gamma_w = 9806 N/m^3 as the seed prints them.
  The form used by codes citing Lewis & Schrefler (1998) is
  ``Liakopoulos.lewis_schrefler()``: S_w = 1 - 1.9722e-11 s^2.4279 (s in Pa), which is the
  seed's with gamma_w = 1e4 (about 5 % apart in S_w), and d = 1.0121.
* ``VanGenuchten`` — (6.82)-(6.83) with Mualem's k_rw: S_w = S_rw + (1 - S_rw) [1 + (beta s /
  gamma_w)^n]^-m, m = 1 - 1/n, S_e = (S_w - S_rw) / (1 - S_rw),
  k_rw = S_e^(1/2) [1 - (1 - S_e^(1/m))^m]^2.

Both floor k_rw at ``k_min`` (default 1e-4), so that a drying particle keeps a positive
diffusion term; the floor is reached only far outside the Liakopoulos experiment's range
(S_w < 0.547 for the seed's law).

``storage`` is the inverse modulus 1/Q of (6.7), which reduces to n / K_w + (alpha - n) / K_s
when saturated.
"""
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from rkfx.errors import InputError

#: Specific weight of water as the seed uses it, rho_w g [N/m^3].
GAMMA_W = 9806.0


@runtime_checkable
class Retention(Protocol):
    """What a model asks of a retention law (arrays of suction s [Pa] in, arrays out)."""

    def saturation(self, s: np.ndarray) -> np.ndarray: ...

    def saturation_slope(self, s: np.ndarray) -> np.ndarray: ...

    def relative_permeability(self, s: np.ndarray) -> np.ndarray: ...

    def relative_permeability_slope(self, s: np.ndarray) -> np.ndarray: ...


def _positive(name: str, value: float) -> None:
    if not (np.isfinite(value) and value > 0):
        raise InputError(f"{name} = {value!r} must be a positive number")


@dataclass(frozen=True)
class Liakopoulos:
    """S_w = 1 - a (s / gamma_w)^b, k_rw = max(k_min, 1 - c (1 - S_w)^d) (6.80-6.81)."""

    a: float = 0.10152
    b: float = 2.4279
    c: float = 2.207
    d: float = 1.0
    gamma_w: float = GAMMA_W
    k_min: float = 1e-4

    def __post_init__(self):
        for name in ("a", "b", "c", "d", "gamma_w"):
            _positive(name, getattr(self, name))
        if not self.b > 1:
            raise InputError(f"b = {self.b!r} must exceed 1 (a continuous slope dS_w/ds at saturation)")
        if not 0 < self.k_min < 1:
            raise InputError(f"k_min = {self.k_min!r} must lie in (0, 1)")

    @classmethod
    def lewis_schrefler(cls) -> "Liakopoulos":
        """The form of Lewis & Schrefler (1998): gamma_w = 1e4, k_rw exponent 1.0121."""
        return cls(d=1.0121, gamma_w=1.0e4)

    def _head(self, s):
        return np.maximum(np.asarray(s, float), 0.0) / self.gamma_w

    def saturation(self, s):
        return np.maximum(1.0 - self.a * self._head(s) ** self.b, 0.0)

    def saturation_slope(self, s):
        h = self._head(s)
        slope = -self.a * self.b * h ** (self.b - 1.0) / self.gamma_w
        return np.where(1.0 - self.a * h ** self.b > 0.0, slope, 0.0)

    def relative_permeability(self, s):
        return np.maximum(1.0 - self.c * (1.0 - self.saturation(s)) ** self.d, self.k_min)

    def relative_permeability_slope(self, s):
        dry = 1.0 - self.saturation(s)
        slope = self.c * self.d * dry ** (self.d - 1.0) * self.saturation_slope(s) if self.d != 1.0 \
            else self.c * self.saturation_slope(s)
        return np.where(1.0 - self.c * dry ** self.d > self.k_min, slope, 0.0)


@dataclass(frozen=True)
class VanGenuchten:
    """van Genuchten's retention with Mualem's k_rw (6.82-6.83); beta [1/m], m = 1 - 1/n."""

    S_rw: float
    n: float
    beta: float
    gamma_w: float = GAMMA_W
    k_min: float = 1e-4

    def __post_init__(self):
        if not 0 <= self.S_rw < 1:
            raise InputError(f"S_rw = {self.S_rw!r}: the residual saturation must lie in [0, 1)")
        if not (np.isfinite(self.n) and self.n > 1):
            raise InputError(f"n = {self.n!r} must exceed 1 (m = 1 - 1/n > 0)")
        _positive("beta", self.beta)
        _positive("gamma_w", self.gamma_w)
        if not 0 < self.k_min < 1:
            raise InputError(f"k_min = {self.k_min!r} must lie in (0, 1)")

    @property
    def m(self) -> float:
        return 1.0 - 1.0 / self.n

    def _x(self, s):
        return self.beta * np.maximum(np.asarray(s, float), 0.0) / self.gamma_w

    def effective_saturation(self, s):
        """S_e = [1 + (beta s / gamma_w)^n]^-m."""
        return (1.0 + self._x(s) ** self.n) ** -self.m

    def saturation(self, s):
        return self.S_rw + (1.0 - self.S_rw) * self.effective_saturation(s)

    def saturation_slope(self, s):
        x = self._x(s)
        dse_dx = -self.m * self.n * x ** (self.n - 1.0) * (1.0 + x ** self.n) ** (-self.m - 1.0)
        return (1.0 - self.S_rw) * dse_dx * self.beta / self.gamma_w

    def _mualem(self, x, slope: bool = False):
        """k_rw before the floor (and dk_rw/dx with ``slope``), with 1 - S_e^(1/m) = x^n / (1 + x^n) written out
        (no cancellation near saturation)."""
        n, m = self.n, self.m
        xn = x ** n
        se = (1.0 + xn) ** -m
        f = 1.0 - (xn / (1.0 + xn)) ** m
        if not slope:
            return np.sqrt(se) * f * f
        dse = -m * n * x ** (n - 1.0) * (1.0 + xn) ** (-m - 1.0)
        df = -m * n * x ** (n * m - 1.0) * (1.0 + xn) ** (-m - 1.0)
        return np.sqrt(se) * f * f, 0.5 * dse * f * f / np.sqrt(se) + 2.0 * np.sqrt(se) * f * df

    def relative_permeability(self, s):
        return np.maximum(self._mualem(self._x(s)), self.k_min)

    def relative_permeability_slope(self, s):
        """dk_rw/ds: 0 while saturated (s <= 0); from the dry side of s = 0 it is finite for
        n >= 2 and taken at x = 1e-12 (it is unbounded there for n < 2)."""
        x = self._x(s)
        k, dk = self._mualem(np.maximum(x, 1e-12), slope=True)
        return np.where((k > self.k_min) & (x > 0), dk * self.beta / self.gamma_w, 0.0)


def storage_slope(law: Retention, p_w, porosity: float, alpha: float, K_w: float, K_s: float) -> np.ndarray:
    """d(1/Q)/dp_w [1/Pa^2] by central differences of ``storage`` (steps of 1e-4 gamma_w, or
    1e-6 |p_w| where larger), for Newton's Jacobian."""
    p_w = np.asarray(p_w, float)
    h = np.maximum(1e-4 * getattr(law, "gamma_w", GAMMA_W), 1e-6 * np.abs(p_w))
    return (storage(law, p_w + h, porosity, alpha, K_w, K_s) - storage(law, p_w - h, porosity, alpha, K_w, K_s)) \
        / (2.0 * h)


def storage(law: Retention, p_w, porosity: float, alpha: float, K_w: float, K_s: float) -> np.ndarray:
    """1/Q of (6.7) [1/Pa] at water pressures p_w [Pa] (suction -p_w):

        1/Q = C_s + n S_w / K_w + S_w (alpha - n)(S_w + C_s p_w / n) / K_s,  C_s = n dS_w/dp_w.
    """
    p_w = np.asarray(p_w, float)
    s = -p_w
    S = law.saturation(s)
    C_s = -porosity * law.saturation_slope(s)
    return C_s + porosity * S / K_w + S * (alpha - porosity) * (S + C_s * p_w / porosity) / K_s
