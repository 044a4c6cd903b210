"""Manufactured elasticity solutions (plane strain and 3-D) for convergence studies.

``sine_field``: u = (A sin(pi x) cos(pi y), B x^2 y) with the body force f = -div sigma
that makes it exact for any Lame constants (plane strain, Voigt strain with engineering shear).
``linear_field``: an arbitrary linear displacement, the linear patch test.
``SineField3D``: a smooth 3-D displacement with its body force.
"""
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SineField:
    """u = (A sin(pi x) cos(pi y), B x^2 y) on any domain; lam, mu Lame constants [Pa]."""

    lam: float
    mu: float
    A: float = 0.1
    B: float = 0.05

    def displacement(self, x: np.ndarray) -> np.ndarray:
        """Shape ``(m, 2)`` [m] at ``x`` of shape ``(m, 2)``."""
        px, py = np.pi * x[:, 0], np.pi * x[:, 1]
        return np.column_stack([self.A * np.sin(px) * np.cos(py), self.B * x[:, 0] ** 2 * x[:, 1]])

    def gradient(self, x: np.ndarray) -> np.ndarray:
        """du_i/dx_j, shape ``(m, 2, 2)``."""
        px, py = np.pi * x[:, 0], np.pi * x[:, 1]
        g = np.empty((len(x), 2, 2))
        g[:, 0, 0] = self.A * np.pi * np.cos(px) * np.cos(py)
        g[:, 0, 1] = -self.A * np.pi * np.sin(px) * np.sin(py)
        g[:, 1, 0] = 2.0 * self.B * x[:, 0] * x[:, 1]
        g[:, 1, 1] = self.B * x[:, 0] ** 2
        return g

    def body_force(self, x: np.ndarray) -> np.ndarray:
        """f = -div sigma, shape ``(m, 2)`` [N/m^3]."""
        lam, mu, a, b = self.lam, self.mu, self.A, self.B
        px, py = np.pi * x[:, 0], np.pi * x[:, 1]
        pi2 = np.pi ** 2
        # div sigma_x = (lam + 2 mu) e_xx,x + lam e_yy,x + mu gamma_,y
        dsx = (lam + 2 * mu) * (-a * pi2 * np.sin(px) * np.cos(py)) + lam * 2 * b * x[:, 0] \
            + mu * (-a * pi2 * np.sin(px) * np.cos(py) + 2 * b * x[:, 0])
        # div sigma_y = mu gamma_,x + lam e_xx,y + (lam + 2 mu) e_yy,y
        dsy = mu * (-a * pi2 * np.cos(px) * np.sin(py) + 2 * b * x[:, 1]) \
            + lam * (-a * pi2 * np.cos(px) * np.sin(py)) + (lam + 2 * mu) * 0.0
        return -np.column_stack([dsx, dsy])

    def stress(self, x: np.ndarray) -> np.ndarray:
        """Voigt stress (sigma_xx, sigma_yy, sigma_xy), shape ``(m, 3)`` [Pa]."""
        g = self.gradient(x)
        exx, eyy, gxy = g[:, 0, 0], g[:, 1, 1], g[:, 0, 1] + g[:, 1, 0]
        tr = exx + eyy
        return np.column_stack([self.lam * tr + 2 * self.mu * exx, self.lam * tr + 2 * self.mu * eyy, self.mu * gxy])

    def traction(self, x: np.ndarray, n: np.ndarray) -> np.ndarray:
        """sigma n, shape ``(m, 2)``."""
        s = self.stress(x)
        return np.column_stack([s[:, 0] * n[:, 0] + s[:, 2] * n[:, 1], s[:, 2] * n[:, 0] + s[:, 1] * n[:, 1]])


@dataclass(frozen=True)
class LinearField:
    """u = c + G x with constant gradient G (shape (2, 2)) and offset c (shape (2,))."""

    G: np.ndarray
    c: np.ndarray
    lam: float
    mu: float

    def displacement(self, x: np.ndarray) -> np.ndarray:
        return self.c + x @ np.asarray(self.G).T

    def gradient(self, x: np.ndarray) -> np.ndarray:
        return np.broadcast_to(self.G, (len(x), 2, 2))

    def traction(self, x: np.ndarray, n: np.ndarray) -> np.ndarray:
        g = np.asarray(self.G)
        eps = 0.5 * (g + g.T)
        sigma = self.lam * np.trace(eps) * np.eye(2) + 2 * self.mu * eps
        return n @ sigma.T


@dataclass(frozen=True)
class SineField3D:
    """A smooth 3-D elastic solution with its body force, for any Lame constants.

    u = A (sin(pi x_i) prod_(j != i) cos(pi x_j))_i + B (x^2 y, y^2 z, z^2 x). The first part is
    -grad(Phi)/pi with Phi = cos(pi x) cos(pi y) cos(pi z), so Lap u = grad div u = -3 pi^2 u
    there; the second is not a gradient. f = -div sigma = -(lam + mu) grad div u - mu Lap u.
    """

    lam: float
    mu: float
    A: float = 0.1
    B: float = 0.05

    def displacement(self, x: np.ndarray) -> np.ndarray:
        """Shape ``(m, 3)`` [m] at ``x`` of shape ``(m, 3)``."""
        s, c = np.sin(np.pi * x), np.cos(np.pi * x)
        wave = np.column_stack([s[:, 0] * c[:, 1] * c[:, 2], c[:, 0] * s[:, 1] * c[:, 2], c[:, 0] * c[:, 1] * s[:, 2]])
        X, Y, Z = x.T
        return self.A * wave + self.B * np.column_stack([X**2 * Y, Y**2 * Z, Z**2 * X])

    def gradient(self, x: np.ndarray) -> np.ndarray:
        """du_i/dx_j, shape ``(m, 3, 3)``."""
        s, c = np.sin(np.pi * x), np.cos(np.pi * x)
        g = np.empty((len(x), 3, 3))
        for i in range(3):
            for j in range(3):
                k = 3 - i - j  # the third axis when i != j
                if i == j:
                    g[:, i, j] = np.pi * np.prod(c, axis=1)
                else:
                    g[:, i, j] = -np.pi * s[:, i] * s[:, j] * c[:, k]
        X, Y, Z = x.T
        zero = np.zeros(len(x))
        poly = np.stack([np.column_stack([2 * X * Y, X**2, zero]), np.column_stack([zero, 2 * Y * Z, Y**2]),
                         np.column_stack([Z**2, zero, 2 * Z * X])], axis=1)
        return self.A * g + self.B * poly

    def body_force(self, x: np.ndarray) -> np.ndarray:
        """f = -div sigma, shape ``(m, 3)`` [N/m^3]."""
        lam, mu = self.lam, self.mu
        s, c = np.sin(np.pi * x), np.cos(np.pi * x)
        wave = np.column_stack([s[:, 0] * c[:, 1] * c[:, 2], c[:, 0] * s[:, 1] * c[:, 2], c[:, 0] * c[:, 1] * s[:, 2]])
        X, Y, Z = x.T
        grad_div = np.column_stack([2 * Y + 2 * Z, 2 * X + 2 * Z, 2 * X + 2 * Y])  # of the polynomial part
        lap = np.column_stack([2 * Y, 2 * Z, 2 * X])
        div_sigma = -3 * np.pi**2 * (lam + 2 * mu) * self.A * wave + self.B * ((lam + mu) * grad_div + mu * lap)
        return -div_sigma

    def stress(self, x: np.ndarray) -> np.ndarray:
        """Voigt stress (xx, yy, zz, yz, xz, xy), shape ``(m, 6)`` [Pa]."""
        g = self.gradient(x)
        eps = 0.5 * (g + np.transpose(g, (0, 2, 1)))
        sig = self.lam * np.trace(eps, axis1=1, axis2=2)[:, None, None] * np.eye(3) + 2 * self.mu * eps
        return np.column_stack([sig[:, 0, 0], sig[:, 1, 1], sig[:, 2, 2], sig[:, 1, 2], sig[:, 0, 2], sig[:, 0, 1]])
