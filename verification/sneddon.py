"""Sneddon's pressurized crack: the opening of a straight crack under internal pressure (seed eq. 5.37).

A crack |x| <= c, y = 0 in an unbounded plane-strain solid (E, nu) whose faces carry the
pressure p opens by (Sneddon 1946)

    COD(x) = 4 (1 - nu^2) p sqrt(c^2 - x^2) / E,

the full opening u_y^+ - u_y^- (not the half-opening some codes call COD). Its maximum at the
centre is 4 (1 - nu^2) p c / E and the crack area int COD dx is 2 pi (1 - nu^2) p c^2 / E.
A bounded domain opens the crack less (a fixed square four crack lengths wide, by about 9 %);
``fem_baselines.pressurized_slit`` gives the discrete-crack solution on such a square.
"""
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError


@dataclass(frozen=True)
class Sneddon:
    """The unbounded-plane solution.

    Attributes:
        E: Young's modulus [Pa]; nu: Poisson's ratio [-] (plane strain).
        pressure: p on the faces [Pa]; c: half-length of the crack [m].
    """

    E: float
    nu: float
    pressure: float
    c: float

    def __post_init__(self):
        if not (self.E > 0 and -1.0 < self.nu < 0.5 and self.c > 0):
            raise InputError(f"Sneddon: need E > 0, -1 < nu < 0.5, c > 0 (got E={self.E!r}, nu={self.nu!r}, "
                             f"c={self.c!r})")

    @property
    def scale(self) -> float:
        """4 (1 - nu^2) p / E [-]."""
        return 4.0 * (1.0 - self.nu**2) * self.pressure / self.E

    def opening(self, x: np.ndarray) -> np.ndarray:
        """COD(x) (5.37) [m]; 0 beyond the tips."""
        x = np.asarray(x, float)
        return self.scale * np.sqrt(np.maximum(self.c**2 - x**2, 0.0))

    @property
    def centre_opening(self) -> float:
        """COD(0) [m]."""
        return self.scale * self.c

    @property
    def crack_area(self) -> float:
        """int COD dx = pi c^2 scale / 2 [m^2]."""
        return 0.5 * np.pi * self.c**2 * self.scale
