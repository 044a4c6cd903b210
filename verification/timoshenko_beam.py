"""Timoshenko's cantilever: a beam of length L and depth D under a parabolic shear load at its end.

The beam occupies 0 <= x <= L, -D/2 <= y <= D/2; its face x = 0 holds the exact displacement,
the face x = L carries the parabolic shear traction of resultant P, top and bottom are free.
With I = D^3 / 12, in plane stress [Timoshenko & Goodier, *Theory of Elasticity*, 3rd ed.,
Sec. 21; in the meshfree literature e.g. Belytschko, Lu & Gu, IJNME 37 (1994) 229]:

    u_x = -P y / (6 E I) [ (6 L - 3 x) x + (2 + nu) (y^2 - D^2/4) ]
    u_y =  P / (6 E I) [ 3 nu y^2 (L - x) + (4 + 5 nu) D^2 x / 4 + (3 L - x) x^2 ]
    sigma_xx = -P (L - x) y / I,   sigma_yy = 0,   sigma_xy = P / (2 I) (D^2/4 - y^2)

In plane strain E and nu become E / (1 - nu^2) and nu / (1 - nu). The tip deflection at y = 0
is P L^3 / (3 E I) from bending plus (4 + 5 nu) P L / (2 E D) from shear (for nu = 0.3 and
L/D = 4 the shear term is 4.3 % of the bending term). Units: lengths [m], E [Pa], P [N/m]
(a load per unit thickness), u [m].
"""
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TimoshenkoBeam:
    """The cantilever and its load.

    Attributes:
        L: Length [m].
        D: Depth [m].
        E: Young's modulus [Pa].
        nu: Poisson's ratio [-].
        P: Resultant of the end shear per unit thickness [N/m].
        plane: ``"stress"`` or ``"strain"``.
    """

    L: float = 48.0
    D: float = 12.0
    E: float = 3.0e7
    nu: float = 0.3
    P: float = 1000.0
    plane: str = "stress"

    @property
    def inertia(self) -> float:
        """I = D^3 / 12 [m^3]."""
        return self.D**3 / 12.0

    def _moduli(self) -> tuple[float, float]:
        """(E, nu) of the plane-stress formulas: the material's, or the plane-strain substitutes."""
        if self.plane == "stress":
            return self.E, self.nu
        return self.E / (1.0 - self.nu**2), self.nu / (1.0 - self.nu)

    def displacement(self, x: np.ndarray) -> np.ndarray:
        """u(x), shape ``(m, 2)`` [m]."""
        return np.column_stack(self.displacement_xy(x[:, 0], x[:, 1]))

    def displacement_xy(self, X, Y) -> tuple:
        """(u_x, u_y) at coordinates X, Y: arrays, or UFL expressions for a FEM error norm."""
        e, nu = self._moduli()
        L, D, P, c = self.L, self.D, self.P, 6.0 * e * self.inertia
        ux = -P * Y / c * ((6 * L - 3 * X) * X + (2 + nu) * (Y**2 - D**2 / 4))
        uy = P / c * (3 * nu * Y**2 * (L - X) + (4 + 5 * nu) * D**2 * X / 4 + (3 * L - X) * X**2)
        return ux, uy

    def gradient(self, x: np.ndarray) -> np.ndarray:
        """grad u(x), shape ``(m, 2, 2)`` with [i, j] = du_i/dx_j."""
        e, nu = self._moduli()
        L, D, P, c = self.L, self.D, self.P, 6.0 * e * self.inertia
        X, Y = x[:, 0], x[:, 1]
        g = np.empty((len(x), 2, 2))
        g[:, 0, 0] = -P * Y / c * (6 * L - 6 * X)
        g[:, 0, 1] = -P / c * ((6 * L - 3 * X) * X + (2 + nu) * (3 * Y**2 - D**2 / 4))
        g[:, 1, 0] = P / c * (-3 * nu * Y**2 + (4 + 5 * nu) * D**2 / 4 + 6 * L * X - 3 * X**2)
        g[:, 1, 1] = P / c * 6 * nu * Y * (L - X)
        return g

    def stress(self, x: np.ndarray) -> np.ndarray:
        """(sigma_xx, sigma_yy, sigma_xy) at x, shape ``(m, 3)`` [Pa]."""
        X, Y = x[:, 0], x[:, 1]
        i = self.inertia
        return np.column_stack([-self.P * (self.L - X) * Y / i, np.zeros(len(x)),
                                self.P / (2 * i) * (self.D**2 / 4 - Y**2)])

    def traction(self, x: np.ndarray, n: np.ndarray) -> np.ndarray:
        """sigma n at boundary points x with outward normals n, shape ``(m, 2)`` [Pa]."""
        s = self.stress(x)
        return np.column_stack([s[:, 0] * n[:, 0] + s[:, 2] * n[:, 1], s[:, 2] * n[:, 0] + s[:, 1] * n[:, 1]])

    def tip_deflection(self) -> float:
        """u_y(L, 0) [m]."""
        return float(self.displacement(np.array([[self.L, 0.0]]))[0, 1])

    def nodes(self, nx: int, ny: int):
        """An ``nx`` x ``ny`` grid of nodes on the beam (``rkfx.geometry.particles.structured``)."""
        from rkfx.geometry.particles import structured  # noqa: PLC0415

        return structured(self.L, self.D, nx, ny, origin=(0.0, -self.D / 2))

    def conditions(self) -> list:
        """The exact displacement on the face x = 0 and the end shear on x = L (top and bottom free)."""
        from rkfx.conditions import Displacement, Traction  # noqa: PLC0415

        return [Displacement("left", lambda x, t: self.displacement(x)),
                Traction("right", lambda x, t, n: self.traction(x, n))]

    def material(self):
        """The beam's ``rkfx.materials.elasticity.ElasticMaterial``."""
        from rkfx.materials.elasticity import ElasticMaterial  # noqa: PLC0415

        return ElasticMaterial(self.E, self.nu, self.plane)
