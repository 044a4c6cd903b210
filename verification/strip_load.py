"""Consolidation of a poroelastic half-plane under a strip load, incompressible constituents.

Plane strain; the half-space is y >= 0 with **y the depth, measured downward from the surface**
(a model with the surface on top at y_model = Y0 passes depth = Y0 - y_model). At t = 0+ a uniform
compressive pressure q is applied on |x| <= b of the surface y = 0, which is drained (p = 0) and
free of shear; fields vanish at infinity. Incompressible constituents (alpha = 1, S = 0), mobility
k = k_h / gamma_f [m^2/(Pa s)]. The problem of Biot (1941) / McNamee & Gibson (1960) solved for a
strip by Chen (1966) and Schiffman, Chen & Jordan (1969), the reference of the seed (Wei 2018,
sec. 3.4.3, Figs. 3.11-3.12); see also Verruijt, *Theory and Problems of Poroelasticity*
(strip load on a half-plane) and Wang, *Theory of Linear Poroelasticity*, sec. 7.

Derivation (done here; every step is re-checked in tests/test_poro_exact.py). With lambda, G the
drained Lame constants, K_v = lambda + 2G, e = div u: equilibrium G lap u + (lambda + G) grad e
= grad p and storage de/dt = k lap p give de/dt = c lap e and lap(p - K_v e) = 0, where

    c = k K_v = k E (1 - nu) / ((1 + nu)(1 - 2 nu))      (consolidation coefficient, plane strain).

Fourier transform in x (f^(xi) = int f e^{-i xi x} dx) and Laplace transform in t, the three
decaying solutions (a diffusive mode e ~ e^{-m y}, m = sqrt(xi^2 + s/c), with u = (c/s) grad e,
p = K_v e; an irrotational mode u = grad e^{-|xi| y}; a harmonic-pressure mode) fitted to
sigma_xy = 0, sigma_yy = -q^/s, p = 0 at y = 0 give

    p^(xi, y, s) = q^(xi) (e^{-|xi| y} - e^{-m y}) / (c (m - |xi|)(m + eta |xi|)),
    eta = lambda / K_v = nu / (1 - nu),   q^(xi) = 2 q sin(xi b) / xi.

In tau = c t, with w = m, the partial fractions 1/((w - xi)(w + eta xi)) and the shifted form of
L^-1[e^{-k sqrt s}/(sqrt s + h)] (Abramowitz & Stegun 29.3.88) invert this in closed form:

    p~(xi, y, tau) = [e^{-xi y} D(0) - D(y)] / (1 + eta),
    D(z) = e^{-xi z} erfc(z/(2 sqrt tau) - xi sqrt tau)
           + eta e^{eta xi z - (1 - eta^2) xi^2 tau} erfc(z/(2 sqrt tau) + eta xi sqrt tau)

(the 1/sqrt(pi tau) terms cancel; both products are evaluated with erfcx, no overflow), and

    p(x, y, t) = (2q/pi) int_0^inf sin(xi b) cos(xi x) / xi  p~(xi, y, c t) dxi,

a smooth integral done by composite Gauss-Legendre quadrature (16 nodes per panel, panels shorter
than 2 pi/(b + |x|max), 2/sqrt(tau) and 1/8 of the range, range cut where the integrand is below
~e^-40: xi_max = min(42/y, sqrt(45/tau))). Limits: p~ -> e^{-|xi| y} as t -> 0+, so

    p(x, y, 0+) = (q/pi) [atan((b + x)/y) + atan((b - x)/y)]

(the undrained elastic value -(sigma_xx + sigma_yy)/2 with nu_u = 1/2, q theta/pi with theta the
angle the strip subtends); p~ -> 0 as t -> inf, p~ = 0 on y = 0 for t > 0.

Time scales: the solution depends on t through c t / b^2 and on nu through eta. The seed plots
against T_D = E k t / ((1 + nu) b^2) = 2 G k t / b^2 (``dimensionless_time``); it equals
c t / b^2 only for nu = 0 (the seed's case); in general c t / b^2 = T_D (1 - nu)/(1 - 2 nu).
Units: lengths [m], E, q, p [Pa], k [m^2/(Pa s)], t [s].
"""
from dataclasses import dataclass

import numpy as np
from scipy.special import erfc, erfcx

from verification.moduli import DrainedModuli

_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(16)


def _exp_erfc(pre, z, tail):
    """exp(pre) erfc(z) with exp(pre - z^2) = exp(tail) supplied; stable for any z."""
    pos = z > 0
    with np.errstate(over="ignore", under="ignore"):
        return np.where(pos, np.exp(tail) * erfcx(np.where(pos, z, 0.0)),
                        np.exp(np.where(pos, 0.0, pre)) * erfc(np.where(pos, 0.0, z)))


def _D(Xi, Z, T, eta):
    """D(z) of the module docstring in units of b: Xi = xi b, Z = z/b, T = c t/b^2 (> 0)."""
    rT = np.sqrt(T)
    tail = -Xi * Xi * T - Z * Z / (4.0 * T)
    first = _exp_erfc(-Xi * Z, Z / (2 * rT) - Xi * rT, tail)
    if eta == 0.0:
        return first
    second = _exp_erfc(eta * Xi * Z - (1 - eta * eta) * Xi * Xi * T, Z / (2 * rT) + eta * Xi * rT, tail)
    return first + eta * second


def pressure_kernel(Xi, Y, T, eta):
    """p~(xi, y, tau) of the module docstring (dimensionless): Xi = xi b, Y = y/b, T = c t/b^2 > 0."""
    return (np.exp(-Xi * Y) * _D(Xi, 0.0, T, eta) - _D(Xi, Y, T, eta)) / (1.0 + eta)


def pressure_kernel_laplace(Xi, Y, s, eta):
    """Laplace transform of p~ in T: (e^{-Xi Y} - e^{-m Y}) / ((m - Xi)(m + eta Xi)), m = sqrt(Xi^2 + s).

    Written as (m + Xi)(...)/(s (m + eta Xi)) to avoid the cancellation in m - Xi; complex s allowed.
    """
    m = np.sqrt(Xi * Xi + s)
    return (m + Xi) * (np.exp(-Xi * Y) - np.exp(-m * Y)) / (s * (m + eta * Xi))


@dataclass(frozen=True)
class StripLoad(DrainedModuli):
    """Strip load q on |x| <= b of a drained poroelastic half-plane (alpha = 1, S = 0).

    Attributes:
        E: Drained Young's modulus [Pa].
        nu: Drained Poisson's ratio [-], -1 < nu < 1/2.
        k: Mobility k_h / gamma_f [m^2/(Pa s)].
        b: Half-width of the strip [m].
        q: Load, compressive positive [Pa].
    """

    E: float
    nu: float
    k: float
    b: float
    q: float

    @property
    def c(self) -> float:
        """Consolidation coefficient k K_v [m^2/s]."""
        return self.k * self.K_v

    @property
    def eta(self) -> float:
        """lambda / K_v = nu / (1 - nu) [-]."""
        return self.nu / (1.0 - self.nu)

    def dimensionless_time(self, t):
        """The seed's T_D = E k t / ((1 + nu) b^2) = 2 G k t / b^2 [-] (= c t/b^2 only if nu = 0)."""
        return 2.0 * self.G * self.k * np.asarray(t, float) / self.b**2

    def time(self, T_D):
        """Inverse of ``dimensionless_time``: t [s] for the seed's T_D."""
        return np.asarray(T_D, float) * self.b**2 / (2.0 * self.G * self.k)

    def undrained_pressure(self, x, y):
        """p(x, y, 0+) = (q/pi)[atan((b+x)/y) + atan((b-x)/y)] [Pa]; y = depth > 0."""
        x, y = np.asarray(x, float), np.asarray(y, float)
        return self.q / np.pi * (np.arctan2(self.b + x, y) + np.arctan2(self.b - x, y))

    def pressure(self, x, y, t, refine: float = 1.0):
        """Pore pressure p(x, y, t) [Pa]; y = depth >= 0 (downward); x, y, t broadcast together.

        t = 0 is read as 0+ (``undrained_pressure``); p = 0 on y = 0 for t > 0. ``refine``
        multiplies the number of quadrature panels (convergence checks). Points sharing a time
        share one quadrature grid: ~100 points at one time take a few milliseconds.
        """
        x, y, t = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(t, float))
        if np.any(y < 0) or np.any(t < 0):
            raise ValueError("y is the depth (>= 0) and t must be >= 0")
        X, Y = np.abs(x.ravel()) / self.b, y.ravel() / self.b
        T = (self.c * t / self.b**2).ravel()
        out = np.zeros(X.shape)
        for Tj in np.unique(T):
            sel = np.flatnonzero(T == Tj)
            if Tj == 0.0:
                with np.errstate(divide="ignore", invalid="ignore"):
                    out[sel] = self.undrained_pressure(X[sel] * self.b, Y[sel] * self.b) / self.q
                continue
            sel = sel[Y[sel] > 0]                          # p = 0 on the drained surface
            if sel.size:
                out[sel] = self._integral(X[sel], Y[sel], Tj, refine)
        return self.q * out.reshape(x.shape)

    def _integral(self, X, Y, T, refine):
        """(2/pi) int_0^inf sin(Xi) cos(Xi X)/Xi p~ dXi for flat X, Y (> 0) at one T > 0."""
        xi_max = float(np.max(np.minimum(42.0 / Y, np.sqrt(45.0 / T))))
        length = min(2 * np.pi / (1.0 + X.max()), 2.0 / np.sqrt(T), xi_max / 8.0) / refine
        n_panels = int(np.ceil(xi_max / length))
        edges = np.linspace(0.0, xi_max, n_panels + 1)
        half = 0.5 * np.diff(edges)
        Xi = ((edges[:-1] + half)[:, None] + half[:, None] * _GL_NODES).ravel()
        w = (half[:, None] * _GL_WEIGHTS).ravel() * np.sin(Xi) / Xi
        out = np.empty(X.shape)
        chunk = max(1, 4_000_000 // Xi.size)
        for i0 in range(0, X.size, chunk):
            xs, ys = X[i0:i0 + chunk, None], Y[i0:i0 + chunk, None]
            kern = pressure_kernel(Xi[None, :], ys, T, self.eta)
            out[i0:i0 + chunk] = (np.cos(Xi[None, :] * xs) * kern) @ w
        return 2.0 / np.pi * out
