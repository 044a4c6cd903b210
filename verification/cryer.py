"""Cryer's problem: a poroelastic sphere under a sudden uniform compressive load, drained surface.

A sphere 0 <= r <= a, unloaded at rest, carries from t = 0+ a normal compressive total traction
sigma0 > 0 on r = a, where p = 0 for t > 0 (Cryer, Q. J. Mech. Appl. Math. 16 (1963) 401-412).
Conventions of rkfx (``PoroMaterial``): tensile effective stress positive, compressive pore
pressure positive, sigma = sigma'' - alpha p I, storage alpha de/dt + S dp/dt = k lap p with
S = 1/Q [1/Pa] (0: incompressible constituents) and k the mobility [m^2/(Pa s)]. K, G and
K_v = K + 4G/3 are the drained moduli, K_u = K + alpha^2/S the undrained bulk modulus.

Derivation (redone here for compressible constituents; Cryer 1963 is the case S = 0, alpha = 1;
Verruijt, *Theory and Problems of Poroelasticity*, TU Delft 2013/2016, sec. 3.3, gives the same
characteristic equation and centre-pressure series with his eta = 2 beta; Detournay & Cheng,
*Fundamentals of poroelasticity*, Comprehensive Rock Engineering vol. 2, 1993, the parameters
B, nu_u, c). The radial displacement is irrotational, so equilibrium integrates to
K_v e - alpha p = f(t), e = (r^2 u)'/r^2, and the surface traction fixes
f = -sigma0 K_v/K + 4 G alpha pbar/(3K), pbar the volume mean of p. The storage equation becomes

    dp/dt = c lap p - eta d(pbar)/dt,     eta = 4 G alpha^2 / (3 K (alpha^2 + S K_v)),
    c = k K_v / (alpha^2 + S K_v) = k M K_v / (K_u + 4G/3)   (= PoroMaterial's c_v, Terzaghi's c_v).

The jump at t = 0+ gives the uniform undrained pressure p0 = B sigma0 with Skempton's
B = alpha / (alpha^2 + S K) = alpha M / K_u (B = 1 for S = 0, alpha = 1). With rho = r/a,
T = c t/a^2, s the Laplace variable of T and x = sqrt(s), regularity and p(a) = 0 give

    p^/p0 = [1 - sinh(x rho)/(rho sinh x)] / D,      D = s - (x coth x - 1)/beta,
    beta  = (1 + eta)/(3 eta) = K_v (alpha^2 + S K)/(4 G alpha^2) = (1-nu)(1+nu_u)/(6 (nu_u - nu))

(beta = (1-nu)/(2(1-2nu)) for S = 0). p^ is single-valued in s; its poles s = -xi_n^2 solve

    (1 - beta xi^2) tan xi = xi,   i.e.  F(xi) = xi cos xi - (1 - beta xi^2) sin xi = 0,

with exactly one root in each ((n-1) pi, n pi), n = 1, 2, ..., because beta > 1/3 and
(1 - xi cot xi)/xi^2 = 2 sum_m 1/(m^2 pi^2 - xi^2) rises from -inf to inf between its poles.
Residues give, with C_n = 2/((2 - 1/beta) sin xi_n + xi_n cos xi_n), e_n = exp(-xi_n^2 T) and
j0, j1 the spherical Bessel functions,

    p/p0 = sum_n C_n (sin xi_n - xi_n j0(xi_n rho)) e_n                   (centre: j0 = 1)
    J    = rho^-2 int_0^rho (p/p0) rho'^2 drho' = sum_n C_n (rho sin xi_n/3 - j1(xi_n rho)) e_n
    u_r  = -sigma0 r/(3K) + 4 G alpha p0 r J(1,T)/(3 K K_v) + alpha p0 a J(rho,T)/K_v
    pbar = 3 p0 J(1,T),   u_r(a) = -(sigma0 - alpha pbar) a/(3K),
    -a dp/dr(a) = -p0 sum_n C_n xi_n^2 j1(xi_n) e_n,

and in the Laplace domain J^ = [rho/3 - i1(x rho)/sinh x]/D, (-dp/drho(1))^ = (x coth x - 1)/D.
Limits: t = 0+: p = p0 (r < a), u_r = -sigma0 r/(3 K_u) (0 for S = 0); t -> inf: p = 0,
u_r = -sigma0 r/(3K). For small T the interior follows D ~ s - (sqrt(s) - 1)/beta:
p/p0 = 1 + (2/beta) sqrt(T/pi) + (1/beta^2 - 1/beta) T + O(T^3/2) (Mandel-Cryer effect).

Evaluation. Series: the first N roots with (N pi)^2 T_min >= 40 (xi_n > (n-1) pi, so every
neglected term is below e^-40 times its coefficient, which is O(1) for all three kernels), at
least 50, at most 200,000 (T >= 1e-10); the roots by 64 vectorised bisections of F on
((n-1) pi, n pi), where F has the sign (-1)^(n-1) at the left end, to machine precision.
Laplace: fixed Talbot contour (Abate & Valko, Int. J. Numer. Meth. Eng. 60 (2004) 979-993),
M = 20 nodes (measured best in double precision: 2e-13 p0 against the series; 16 and 24 nodes
give 2e-11 and 2e-12), transforms written with exp(-2x) so that large |s| cannot overflow.
``method="auto"`` uses the series for T >= 1e-4 (at most 204 roots) and Talbot below, where the
series cost grows as T^-1/2. t = 0 is read as t = 0+.

Checks (tests/test_cryer_exact.py, four parameter sets, beta = 0.34..1.8; measured): series and
Talbot agree to 5e-13 p0 (p) and 2e-13 sigma0 a/(3K) (u) for T in 1e-7..3, the outflow to 1e-12
of its size; for T <= 1e-3 the centre pressure equals a closed short-time form (Faddeeva
function, exact up to e^(-1/(4T))) to 1.3e-13 p0; a P2/P1 finite-element solution of the radial
u-p equations (backward Euler, Richardson in time and space) agrees to 1.0e-4 p0 (centre history,
T >= 1e-3), 7e-5 p0 (profiles), 1.4e-5 sigma0 a/(3K) (u) and 4e-6 p0 (peak value); the fields
satisfy equilibrium and storage by finite differences (residuals 1e-7, 3e-8 relative), the
traction (1e-10) and the fluid balance (3e-11).
Units: r, a, u [m]; E, p, sigma0 [Pa]; k [m^2/(Pa s)]; t [s].
"""
import functools
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.special import spherical_jn

from rkfx.errors import InputError
from rkfx.materials.elasticity import ElasticMaterial
from verification.moduli import BiotModuli

_DECAY_EXPONENT = 40.0   # keep roots with xi^2 T <= 40
_MIN_ROOTS = 50
_MAX_ROOTS = 200_000
_AUTO_SWITCH_T = 1e-4    # method="auto": series for T >= 1e-4, Talbot below
_TALBOT_NODES = 20
METHODS = ("auto", "series", "laplace")


@functools.lru_cache(maxsize=32)
def _roots(beta: float, n: int) -> np.ndarray:
    """First n positive roots of xi cos xi = (1 - beta xi^2) sin xi (beta > 1/3), shape ``(n,)``.

    One root lies in each ((m-1) pi, m pi); F = xi cos xi - (1 - beta xi^2) sin xi has the sign
    (-1)^(m-1) just right of the left end (F ~ (beta - 1/3) xi^3 > 0 near 0) and the opposite one
    at m pi, so 64 bisections reach machine precision without any starting guess.
    """
    m = np.arange(1, n + 1, dtype=float)
    lo, hi = (m - 1.0) * np.pi, m * np.pi
    sign_lo = np.where(m % 2 == 1, 1.0, -1.0)
    for _ in range(64):
        mid = 0.5 * (lo + hi)
        f = mid * np.cos(mid) - (1.0 - beta * mid * mid) * np.sin(mid)
        same = np.sign(f) == sign_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    xi = 0.5 * (lo + hi)
    xi.flags.writeable = False
    return xi


def _laplace_kernel(kind: str, s, rho, beta: float):
    """Transforms (in T) of p/p0 ("p"), J ("J") and -d(p/p0)/drho at rho = 1 ("q"), complex s.

    sinh and coth are written with E = exp(-2x), Re x > 0, so large |s| (small T) cannot overflow.
    """
    x = np.sqrt(s)
    E = np.exp(-2.0 * x)
    xcoth_m1 = x * (1.0 + E) / (1.0 - E) - 1.0
    den = s - xcoth_m1 / beta
    if kind == "q":
        return xcoth_m1 / den
    z = x * rho
    decay = np.exp(-x * (1.0 - rho)) / (1.0 - E)          # = e^(x rho)/(2 sinh x), without overflow
    if kind == "p":     # sinh(x rho)/(rho sinh x) = decay (1 - e^(-2 x rho))/rho, -> 2x decay at rho = 0
        ratio = np.where(rho > 0, -np.expm1(-2.0 * z) / np.where(rho > 0, rho, 1.0), 2.0 * x)
        return (1.0 - decay * ratio) / den
    # i1(z)/sinh x = decay * 2 e^-z i1(z), i1(z) = (z cosh z - sinh z)/z^2; its Taylor series
    # where |z| < 0.1 and the closed form would lose (0.1/|z|)^2 digits to cancellation
    zs = np.where(np.abs(z) < 0.1, 1.0, z)
    closed = (zs * (1.0 + np.exp(-2.0 * zs)) + np.expm1(-2.0 * zs)) / zs**2
    series = 2.0 * np.exp(-z) * (z / 3.0 + z**3 / 30.0 + z**5 / 840.0 + z**7 / 45360.0)
    return (rho / 3.0 - decay * np.where(np.abs(z) < 0.1, series, closed)) / den


class CryerPeak(NamedTuple):
    """Maximum of the centre pressure: time t [s], value p [Pa], T = t c/a^2 [-], p/p0 [-]."""
    t: float
    p: float
    T: float
    ratio: float


@dataclass(frozen=True)
class Cryer(BiotModuli):
    """Cryer's sphere for general Biot parameters (S = 0 allowed).

    Attributes:
        E: Drained Young's modulus [Pa].
        nu: Drained Poisson's ratio, -1 < nu < 0.5 [-].
        k: Mobility k_h / gamma_f [m^2/(Pa s)].
        radius: Sphere radius a [m].
        load: Compressive surface traction sigma0 > 0 [Pa].
        alpha: Biot coefficient, 0 < alpha <= 1 [-].
        S: Storage coefficient 1/Q [1/Pa]; 0 for incompressible constituents.
    """

    E: float
    nu: float
    k: float
    radius: float
    load: float
    alpha: float = 1.0
    S: float = 0.0

    def __post_init__(self):
        ElasticMaterial(self.E, self.nu)                  # one-line InputError for E and nu
        for name, unit in (("k", "m^2/(Pa s)"), ("radius", "m"), ("load", "Pa")):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"Cryer: {name} = {v!r} must be positive and finite [{unit}]")
        if not 0.0 < self.alpha <= 1.0:
            raise InputError(f"Cryer: Biot coefficient alpha = {self.alpha!r} must lie in (0, 1]")
        if not (np.isfinite(self.S) and self.S >= 0.0):
            raise InputError(f"Cryer: storage coefficient S = {self.S!r} must be >= 0 [1/Pa] "
                             "(0: incompressible constituents)")

    # ----- parameters -----
    @property
    def p0(self) -> float:
        """Uniform undrained pressure at t = 0+: B sigma0 [Pa]."""
        return self.B * self.load

    @property
    def time_scale(self) -> float:
        """a^2/c [s]: T = t/time_scale."""
        return self.radius**2 / self.c

    @property
    def beta(self) -> float:
        """K_v (alpha^2 + S K)/(4 G alpha^2) [-], of the characteristic equation."""
        return self.K_v * (self.alpha**2 + self.S * self.K) / (4.0 * self.G * self.alpha**2)

    def roots(self, n: int = _MIN_ROOTS) -> np.ndarray:
        """First n roots xi_n of (1 - beta xi^2) tan xi = xi, shape ``(n,)``."""
        return _roots(float(self.beta), int(n))

    def dimensionless_time(self, t):
        """T = c t/a^2 [-], shaped like t."""
        return np.asarray(t, float) / self.time_scale

    # ----- evaluation -----
    def _kernel(self, kind, r, t, method):
        """Dimensionless kernel ("p", "J" or "q") at broadcast r [m], t [s]; t = 0 is 0+."""
        if method not in METHODS:
            raise InputError(f"Cryer: method = {method!r} is unknown; choose one of {METHODS}")
        r, t = np.broadcast_arrays(np.asarray(r, float), np.asarray(t, float))
        if not np.all(np.isfinite(t) & (t >= 0.0)):
            raise InputError("Cryer: times t must be finite and >= 0 [s] (t = 0 is read as 0+)")
        if not np.all((r >= 0.0) & (r <= self.radius * (1.0 + 1e-12))):
            raise InputError(f"Cryer: radii r must lie in [0, a = {self.radius:g}] [m]")
        rho, T = np.minimum(r / self.radius, 1.0).ravel(), self.dimensionless_time(t).ravel()
        out = np.empty_like(T)
        zero = T == 0.0
        out[zero] = {"p": np.where(rho[zero] < 1.0, 1.0, 0.0), "J": rho[zero] / 3.0, "q": np.inf}[kind]
        use_laplace = ~zero & {"auto": T < _AUTO_SWITCH_T, "laplace": True, "series": False}[method]
        use_series = ~zero & ~use_laplace
        if use_series.any():
            out[use_series] = self._series(kind, rho[use_series], T[use_series])
        if use_laplace.any():
            out[use_laplace] = self._talbot(kind, rho[use_laplace], T[use_laplace])
        return out.reshape(r.shape)

    def n_roots(self, T_min: float) -> int:
        """Roots the series keeps for times T >= T_min: max(50, N), (N pi)^2 T_min >= 40."""
        n = max(_MIN_ROOTS, int(np.ceil(np.sqrt(_DECAY_EXPONENT / T_min) / np.pi)) + 1)
        if n > _MAX_ROOTS:
            raise InputError(f"Cryer: T = {T_min:.3g} needs {n} > {_MAX_ROOTS} roots; use method='laplace'")
        return n

    def _series(self, kind, rho, T):
        xi_all = self.roots(self.n_roots(T.min()))
        out = np.zeros_like(T)
        chunk = max(1, 1_000_000 // len(T))                   # bound the (points x roots) arrays
        for j in range(0, len(xi_all), chunk):
            xi = xi_all[j:j + chunk]
            sn, cs = np.sin(xi), np.cos(xi)
            coef = 2.0 / ((2.0 - 1.0 / self.beta) * sn + xi * cs)
            z = np.outer(rho, xi)
            if kind == "p":
                w = sn - xi * np.sinc(z / np.pi)
            elif kind == "J":
                w = np.outer(rho, sn / 3.0) - spherical_jn(1, z)
            else:
                w = -(xi * xi * spherical_jn(1, xi))[None, :]
            out += np.sum(coef * w * np.exp(-np.outer(T, xi * xi)), axis=1)
        return out

    def _talbot(self, kind, rho, T, M: int = _TALBOT_NODES):
        theta = np.arange(1, M) * np.pi / M
        cot = 1.0 / np.tan(theta)
        nodes = np.concatenate([[1.0 + 0j], theta * (cot + 1j)])       # s / r on the contour
        weights = np.concatenate([[0.5 + 0j], 1.0 + 1j * (theta + (theta * cot - 1.0) * cot)])
        r = 2.0 * M / (5.0 * T)
        s = r[:, None] * nodes[None, :]
        F = _laplace_kernel(kind, s, rho[:, None], self.beta)
        return r / M * np.real(np.sum(weights * np.exp(s * T[:, None]) * F, axis=1))

    def pressure(self, r, t, method: str = "auto"):
        """Pore pressure.

        Args:
            r: Radii, any shape, 0 <= r <= a [m].
            t: Times, any shape broadcastable with r, t >= 0 (t = 0 is read as 0+) [s].
            method: "auto" (series for T >= 1e-4, Talbot below), "series" or "laplace".

        Returns:
            p(r, t), shaped like the broadcast of r and t [Pa]; exactly 0 at r = a for t > 0.
        """
        return self.p0 * self._kernel("p", r, t, method)

    def centre_pressure(self, t, method: str = "auto"):
        """p(0, t) [Pa], shaped like t [s]."""
        return self.pressure(0.0, t, method)

    def mean_pressure(self, t, method: str = "auto"):
        """Volume mean of p, 3 p0 J(1, T) [Pa], shaped like t [s]."""
        return 3.0 * self.p0 * self._kernel("J", self.radius, t, method)

    def radial_displacement(self, r, t, method: str = "auto"):
        """Radial displacement, negative inward.

        Args:
            r, t, method: As for ``pressure``.

        Returns:
            u_r(r, t), shaped like the broadcast of r and t [m]: -sigma0 r/(3 K_u) at t = 0+,
            -sigma0 r/(3K) as t -> inf.
        """
        r = np.asarray(r, float)
        J1 = self._kernel("J", self.radius, t, method)
        J = self._kernel("J", r, t, method)
        return (-self.load * r / (3.0 * self.K)
                + 4.0 * self.G * self.alpha * self.p0 * r * J1 / (3.0 * self.K * self.K_v)
                + self.alpha * self.p0 * self.radius * J / self.K_v)

    def outflow(self, t, method: str = "auto"):
        """Fluid volume leaving the sphere per unit time, 4 pi a^2 (-k dp/dr)(a) [m^3/s], shaped like
        t [s]; inf at t = 0 (it falls like t^-1/2)."""
        q = self._kernel("q", self.radius, t, method)
        return 4.0 * np.pi * self.radius * self.k * self.p0 * q

    def peak(self) -> CryerPeak:
        """Maximum of the centre pressure (Mandel-Cryer effect), always above p0.

        81-point grid in log10 T over [-7, 1], then bounded Brent between the neighbours of the best
        grid point (log10 T to 1e-10).

        Returns:
            ``CryerPeak(t [s], p [Pa], T [-], ratio = p/p0 [-])``.
        """
        logT = np.linspace(-7.0, 1.0, 81)
        pc = self._kernel("p", 0.0, 10.0**logT * self.time_scale, "auto")
        i = int(np.clip(np.argmax(pc), 1, len(logT) - 2))
        res = minimize_scalar(lambda lt: -self._kernel("p", 0.0, 10.0**lt * self.time_scale, "auto"),
                              bounds=(logT[i - 1], logT[i + 1]), method="bounded",
                              options={"xatol": 1e-10})
        T = 10.0**res.x
        return CryerPeak(t=T * self.time_scale, p=-res.fun * self.p0, T=T, ratio=-res.fun)
