"""The exact response of a one-dimensional saturated u-p column to a step load (the set-up of §6.4.1).

A column 0 <= y <= L (y up from the base) under zero lateral strain, the u-p equations of
chapter 6 (eqs. 6.1-6.7 with S_w = 1, small strain, no gravity; Darcy without the fluid's
relative acceleration, as in 6.49):

    rho u'' = d/dy (M du/dy - alpha p)                                  (momentum)
    S p' + alpha d(u')/dy - k d2p/dy2 = 0                               (storage, S = 1/Q)

with M the drained constrained modulus, tensile stress and compressive pore pressure positive.
The base y = 0 is fixed and impermeable (u = 0, dp/dy = 0); the top y = L is drained (p = 0) and
carries the total traction M du/dy - alpha p = -q from t = 0+ on; the column starts at rest.

Laplace domain (zero initial state, s the transform variable). Trial functions e^(lambda y) give

    M k lambda^4 - (M S s + rho k s^2 + alpha^2 s) lambda^2 + rho S s^3 = 0,

two roots lambda_1^2, lambda_2^2 (the fast wave, lambda ~ s / c_u as k -> 0, and the diffusive
slow wave). With the base conditions met by sinh for u and cosh for p,

    U = sum_i A_i sinh(lambda_i y) / cosh(lambda_i L),  P = sum_i beta_i A_i cosh(lambda_i y) / cosh(lambda_i L),
    beta_i = (M lambda_i^2 - rho s^2) / (alpha lambda_i),

and the top conditions give sum beta_i A_i = 0, M sum lambda_i A_i = -q / s. The ratios of
hyperbolic functions are evaluated as decaying exponentials (Re lambda >= 0), so no term
overflows at large |s|.

Inversion: the Fourier series of Durbin (1974) / Crump (1976) on [0, 2T],

    f(t) = e^(a t) / T [ F(a) / 2 + sum_{m >= 1} sigma_m Re(F(a + i m pi / T) e^(i m pi t / T)) ],

summed by FFT over ``terms`` terms with Lanczos' sigma factors sigma_m = sinc(m / terms), which
turn the Gibbs overshoot at a wave front into a ramp a few T / terms wide. The aliasing error is
about e^(-2 a T) of the response; a T = ``damping`` (default 6, aliasing ~6e-6) and T = 2 t_max.

Checks (``tests/test_wave_column_exact.py``):
* nearly impermeable (k -> 0): the undrained elastic rod of modulus M_u = M + alpha^2 / S, whose
  d'Alembert solution is known in closed form (``undrained_rod``): a triangle wave of the top
  displacement and a square wave of the base pressure 2 alpha q / (S M_u) <-> 0;
* the inversion against it away from the fronts, and unchanged when ``terms`` doubles or the
  damping moves;
* the transform's drained limit s U(L, s) -> -q L / M as s -> 0, and its undrained start
  s^2 U(L, s) -> -q / (rho c_u) for c_v / c_u << c_u / s << L (the top's first velocity, the
  undrained impedance, once the drained layer at the top is thin beside a wavelength; at
  still higher s the top is drained and starts at q / (rho c_drained));
* the quasi-static limit rho -> 0: Terzaghi's transform, p0 / s (1 - cosh(xi y) / cosh(xi L)),
  xi^2 = s / c_v.

Units: lengths [m], moduli, q and p [Pa], k [m^4/(N s)], rho [kg/m^3], t [s].
"""
from dataclasses import dataclass

import numpy as np

#: Fourier-series terms of the default inversion, and a T.
TERMS = 2 ** 17
DAMPING = 6.0


def _hyperbolic_ratios(lam: np.ndarray, y: np.ndarray, L: float) -> tuple[np.ndarray, np.ndarray]:
    """sinh(lam y) / cosh(lam L) and cosh(lam y) / cosh(lam L) without overflow (Re lam >= 0);
    ``lam`` of shape (m,), ``y`` of shape (k,), results (m, k)."""
    lam = lam[:, None]
    y = y[None, :]
    denominator = 1.0 + np.exp(-2.0 * lam * L)
    up, down = np.exp(lam * (y - L)), np.exp(-lam * (y + L))
    return (up - down) / denominator, (up + down) / denominator


@dataclass(frozen=True)
class WaveColumn:
    """The column and its data.

    Attributes:
        M: Drained constrained modulus K + 4G/3 [Pa].
        alpha: Biot coefficient [-].
        S: Storage 1/Q [1/Pa], positive.
        k: Mobility [m^4/(N s)], positive.
        rho: Mixture density [kg/m^3].
        L: Height [m].
        q: Compressive load on the top [Pa].
    """

    M: float
    alpha: float
    S: float
    k: float
    rho: float
    L: float
    q: float

    def __post_init__(self):
        for name in ("M", "alpha", "S", "k", "rho", "L"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name} = {v!r} must be positive")

    # ------------------------------------------------------------------ limits

    @property
    def M_u(self) -> float:
        """Undrained constrained modulus M + alpha^2 Q [Pa]."""
        return self.M + self.alpha ** 2 / self.S

    @property
    def fast_speed(self) -> float:
        """Undrained (fast) wave speed sqrt(M_u / rho) [m/s]."""
        return float(np.sqrt(self.M_u / self.rho))

    @property
    def undrained_pressure(self) -> float:
        """Pressure behind the first fast front, alpha Q q / M_u [Pa]."""
        return self.alpha * self.q / (self.S * self.M_u)

    @property
    def drained_settlement(self) -> float:
        """Final settlement of the top, q L / M [m] (downward positive)."""
        return self.q * self.L / self.M

    @property
    def c_v(self) -> float:
        """Consolidation coefficient k M / (alpha^2 + S M) [m^2/s]."""
        return self.k * self.M / (self.alpha ** 2 + self.S * self.M)

    def arrivals(self, y: float, t_end: float) -> np.ndarray:
        """Times [s] at which a fast front passes height y, up to t_end: (2j + 1) L - y and
        (2j + 1) L + y over the speed (down from the top, up after the base's reflection)."""
        c, L = self.fast_speed, self.L
        j = np.arange(int(t_end * c / (2 * L)) + 2)
        t = np.concatenate([((2 * j) * L + (L - y)) / c, ((2 * j) * L + (L + y)) / c])
        return np.unique(t[t <= t_end])

    # ------------------------------------------------------------------ transform

    def roots(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """lambda_1 (fast) and lambda_2 (slow), Re >= 0, at each s (complex, shape (m,))."""
        s = np.asarray(s, complex)
        a2 = self.M * self.k
        a1 = -(self.M * self.S * s + self.rho * self.k * s * s + self.alpha ** 2 * s)
        a0 = self.rho * self.S * s ** 3
        root = np.sqrt(a1 * a1 - 4.0 * a2 * a0)
        root = np.where((np.conj(a1) * root).real >= 0.0, root, -root)  # no cancellation in a1 + root
        big = -0.5 * (a1 + root)
        return np.sqrt(a0 / big), np.sqrt(big / a2)

    def transform(self, s: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """U(y, s) [m s] and P(y, s) [Pa s], shapes (m, k), for s of shape (m,) and y of shape (k,)."""
        s = np.atleast_1d(np.asarray(s, complex))
        y = np.atleast_1d(np.asarray(y, float))
        l1, l2 = self.roots(s)
        b1 = (self.M * l1 * l1 - self.rho * s * s) / (self.alpha * l1)
        b2 = (self.M * l2 * l2 - self.rho * s * s) / (self.alpha * l2)
        a1 = -self.q * b2 / (s * self.M * (l1 * b2 - l2 * b1))
        a2 = -b1 * a1 / b2
        sh1, ch1 = _hyperbolic_ratios(l1, y, self.L)
        sh2, ch2 = _hyperbolic_ratios(l2, y, self.L)
        U = a1[:, None] * sh1 + a2[:, None] * sh2
        P = (b1 * a1)[:, None] * ch1 + (b2 * a2)[:, None] * ch2
        return U, P

    # ------------------------------------------------------------------ time domain

    def histories(self, y, times, terms: int = TERMS, damping: float = DAMPING) -> tuple[np.ndarray, np.ndarray]:
        """u(y, t) [m] (upward positive: negative under the load) and p(y, t) [Pa], shapes
        (len(times), len(y)), by the Fourier-series inversion of the module docstring."""
        y = np.atleast_1d(np.asarray(y, float))
        times = np.asarray(times, float)
        t_max = float(times.max()) if times.size else 0.0
        if not t_max > 0:
            raise ValueError("give at least one positive time")
        T = 2.0 * t_max
        a = damping / T
        m = np.arange(terms)
        s = a + 1j * np.pi * m / T
        U, P = self.transform(s, y)
        sigma = np.sinc(m / terms)[:, None]
        out = []
        for F in (U, P):
            F = F * sigma
            F[0] *= 0.5
            # sum_m F_m e^(i m pi t / T) on the grid t_j = 2 T j / terms: terms * ifft
            series = np.fft.ifft(F, axis=0).real * terms
            grid = 2.0 * T * np.arange(terms) / terms
            f = np.exp(a * grid)[:, None] * series / T
            out.append(np.column_stack([np.interp(times, grid, f[:, j]) for j in range(len(y))]))
        return out[0], out[1]

    def undrained_rod(self, y, times) -> tuple[np.ndarray, np.ndarray]:
        """The k -> 0 limit in closed form (d'Alembert): u(y, t) and p(y, t) of the undrained
        rod of modulus M_u (no drained boundary layer), shapes (len(times), len(y)).

        With tau = L / c, the front f(z) = -(q c / M_u) max(z, 0) leaves the top and reflects
        at the fixed base (u flips sign) and the loaded top (stress flips sign):

            u = sum_j (-1)^j [f(t - 2 j tau - (L - y) / c) - f(t - 2 j tau - (L + y) / c)],

        so the top follows a triangle wave between 0 and -2 q L / M_u (period 4 tau), and the
        pressure, p = -alpha eps / S, is a square wave at the base between 2 alpha q / (S M_u)
        (tau < t < 3 tau) and 0 (3 tau < t < 5 tau)."""
        y = np.atleast_1d(np.asarray(y, float))[None, :]
        t = np.asarray(times, float)[:, None]
        c, L = self.fast_speed, self.L
        tau = L / c
        u = np.zeros((t.shape[0], y.shape[1]))
        eps = np.zeros_like(u)
        for j in range(int(np.ceil(float(t.max()) / (2 * tau))) + 1):
            z1, z2 = t - 2 * j * tau - (L - y) / c, t - 2 * j * tau - (L + y) / c
            sign = (-1.0) ** j
            u += sign * -(self.q * c / self.M_u) * (np.maximum(z1, 0.0) - np.maximum(z2, 0.0))
            eps += sign * -(self.q / self.M_u) * ((z1 > 0).astype(float) + (z2 > 0))
        return u, -self.alpha * eps / self.S
