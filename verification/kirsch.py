"""Kirsch's solution: an infinite plate with a circular hole under remote uniaxial tension.

A traction-free hole of radius ``a`` centred at the origin, remote stress sigma_xx -> T,
sigma_yy = sigma_xy -> 0, plane strain (kappa = 3 - 4 nu, mu = E / (2 (1 + nu))). In polar
coordinates (r, theta) [Barber, *Elasticity*, 3rd ed., Sec. 8.4.1; Timoshenko & Goodier,
*Theory of Elasticity*, Sec. 35]:

    sigma_rr = T/2 (1 - a^2/r^2) + T/2 (1 - 4 a^2/r^2 + 3 a^4/r^4) cos 2theta
    sigma_tt = T/2 (1 + a^2/r^2) - T/2 (1 + 3 a^4/r^4) cos 2theta
    sigma_rt = -T/2 (1 + 2 a^2/r^2 - 3 a^4/r^4) sin 2theta

    u_r = T a / (8 mu) [ (r/a) (kappa - 1 + 2 cos 2theta) + 2 (a/r) (1 + (kappa + 1) cos 2theta)
                         - 2 (a/r)^3 cos 2theta ]
    u_t = -T a / (8 mu) [ 2 r/a + 2 (kappa - 1) a/r + 2 (a/r)^3 ] sin 2theta

In Cartesian components (the form used in the meshfree literature, e.g. Belytschko, Lu & Gu,
IJNME 37 (1994) 229):

    sigma_xx = T [1 - a^2/r^2 (3/2 cos 2theta + cos 4theta) + 3/2 a^4/r^4 cos 4theta]
    sigma_yy = T [ - a^2/r^2 (1/2 cos 2theta - cos 4theta) - 3/2 a^4/r^4 cos 4theta]
    sigma_xy = T [ - a^2/r^2 (1/2 sin 2theta + sin 4theta) + 3/2 a^4/r^4 sin 4theta]
    u_x = T a / (8 mu) [ (r/a)(kappa + 1) cos theta + 2 (a/r)((1 + kappa) cos theta + cos 3theta)
                         - 2 (a/r)^3 cos 3theta ]
    u_y = T a / (8 mu) [ (r/a)(kappa - 3) sin theta + 2 (a/r)((1 - kappa) sin theta + sin 3theta)
                         - 2 (a/r)^3 sin 3theta ]

The displacement is the one that vanishes in rigid-body rotation and translation (u_x = 0 on
x = 0, u_y = 0 on y = 0), so it is the exact solution of the symmetric quarter plate too. The
maximum stress is sigma_xx(0, +-a) = 3 T. Units: lengths [m], E and T [Pa], u [m].
"""
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Kirsch:
    """Kirsch plate with a hole in plane strain.

    Attributes:
        E: Young's modulus [Pa].
        nu: Poisson's ratio [-].
        a: Hole radius [m].
        T: Remote tension sigma_xx at infinity [Pa].
    """

    E: float = 1.0e3
    nu: float = 0.3
    a: float = 1.0
    T: float = 1.0

    @property
    def mu(self) -> float:
        """Shear modulus [Pa]."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def kappa(self) -> float:
        """Kolosov constant of plane strain, 3 - 4 nu [-]."""
        return 3.0 - 4.0 * self.nu

    def displacement_xy(self, x, y, sqrt: Callable = np.sqrt):
        """(u_x, u_y) [m] from coordinates x, y; only arithmetic and ``sqrt``.

        Written with cos n theta as polynomials of cos theta = x / r, sin theta = y / r, so the
        same formula evaluates numpy arrays (complex ones too) or UFL expressions
        (``sqrt=ufl.sqrt``).
        """
        a, k = self.a, self.kappa
        r = sqrt(x * x + y * y)
        c, s = x / r, y / r
        c3 = 4.0 * c**3 - 3.0 * c
        s3 = 3.0 * s - 4.0 * s**3
        f = self.T * a / (8.0 * self.mu)
        ar, ar3 = a / r, (a / r) ** 3
        ux = f * ((r / a) * (k + 1.0) * c + 2.0 * ar * ((1.0 + k) * c + c3) - 2.0 * ar3 * c3)
        uy = f * ((r / a) * (k - 3.0) * s + 2.0 * ar * ((1.0 - k) * s + s3) - 2.0 * ar3 * s3)
        return ux, uy

    def displacement(self, x: np.ndarray) -> np.ndarray:
        """Displacement at points x of shape ``(m, 2)`` [m]; returns ``(m, 2)`` [m]."""
        x = np.asarray(x)
        return np.stack(self.displacement_xy(x[:, 0], x[:, 1]), axis=-1)

    def displacement_gradient(self, x: np.ndarray) -> np.ndarray:
        """du_i/dx_j at x ``(m, 2)``, shape ``(m, 2, 2)`` [-].

        Complex-step differentiation of the analytic displacement: exact to round-off.
        """
        x = np.asarray(x, float)
        step = 1e-30 * max(self.a, 1.0)
        g = np.empty((len(x), 2, 2))
        for j in range(2):
            z = x.astype(complex)
            z[:, j] += 1j * step
            g[:, :, j] = np.stack(self.displacement_xy(z[:, 0], z[:, 1]), axis=-1).imag / step
        return g

    def stress(self, x: np.ndarray) -> np.ndarray:
        """(sigma_xx, sigma_yy, sigma_xy) at x ``(m, 2)``, shape ``(m, 3)`` [Pa]."""
        x = np.asarray(x, float)
        r2 = x[:, 0] ** 2 + x[:, 1] ** 2
        th = np.arctan2(x[:, 1], x[:, 0])
        q2, q4 = self.a**2 / r2, 1.5 * self.a**4 / r2**2
        c2, c4, s2, s4 = np.cos(2 * th), np.cos(4 * th), np.sin(2 * th), np.sin(4 * th)
        sxx = 1.0 - q2 * (1.5 * c2 + c4) + q4 * c4
        syy = -q2 * (0.5 * c2 - c4) - q4 * c4
        sxy = -q2 * (0.5 * s2 + s4) + q4 * s4
        return self.T * np.stack([sxx, syy, sxy], axis=-1)

    def traction(self, x: np.ndarray, n: np.ndarray) -> np.ndarray:
        """sigma n at x ``(m, 2)`` for unit outward normals n ``(m, 2)``; shape ``(m, 2)`` [Pa]."""
        s = self.stress(x)
        return np.stack([s[:, 0] * n[:, 0] + s[:, 2] * n[:, 1], s[:, 2] * n[:, 0] + s[:, 1] * n[:, 1]], -1)
