"""A bar under tension that breaks along a cohesive crack: the reference of the cracked bar.

A bar of length L and cross-section A (Young's modulus E) is fixed at x = 0 and pulled by a
tip displacement u_T at x = L. It stays elastic until the force reaches f_t A; then a crack
opens at one section with the linear cohesive law (Wei 2018, eq. 4.7)

    t(w) = f_t (1 - w / w_c),    w_c = 2 G_F / f_t,

so that the crack dissipates G_F A when it opens fully. The bar unloads elastically on
either side of the crack, and the tip displacement is the elastic elongation plus the
opening (eqs. 4.8-4.9):

    u_T = F L / (E A) + w,    w = w_c (1 - F / (f_t A)),

i.e. F = E A u_T / L up to the peak u_T = f_t L / E, then F = (u_T - w_c) /
(L / (E A) - w_c / (f_t A)) down to F = 0 at u_T^max = w_c. The softening branch is
continuous in u_T only when w_c > f_t L / E (otherwise the bar snaps back at the peak).

The seed's data (section 4.3.1, dimensionless units): L = 100, A = 10, E = 2e6, G_F = 1.885,
f_t = 200, so w_c = u_T^max = 1.885e-2 and the peak force is f_t A = 2000.
"""
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError


@dataclass(frozen=True)
class CohesiveBar:
    """The bar with one cohesive crack of the linear law (4.7).

    Attributes:
        L: Bar length [m].
        A: Cross-section [m^2].
        E: Young's modulus [Pa].
        GF: Fracture energy G_F [N/m].
        ft: Tensile strength f_t [Pa].
    """

    L: float = 100.0
    A: float = 10.0
    E: float = 2.0e6
    GF: float = 1.885
    ft: float = 200.0

    def __post_init__(self):
        for name in ("L", "A", "E", "GF", "ft"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name} = {v!r} must be positive and finite")
        if not self.critical_opening > self.ft * self.L / self.E:
            raise InputError(f"w_c = 2 GF / ft = {self.critical_opening:.3g} must exceed the elastic elongation "
                             f"ft L / E = {self.peak_displacement:.3g}, or the bar snaps back at the peak whatever "
                             "the model; raise GF or lower L")

    @property
    def critical_opening(self) -> float:
        """w_c = 2 G_F / f_t, the opening at which the crack is traction free [m] (4.7)."""
        return 2.0 * self.GF / self.ft

    @property
    def peak_displacement(self) -> float:
        """Tip displacement at the peak force f_t A: f_t L / E [m]."""
        return self.ft * self.L / self.E

    def force(self, u: np.ndarray) -> np.ndarray:
        """Tip force F(u_T) (4.9): elastic up to f_t A, then linear softening to 0 at w_c.

        Args:
            u: Tip displacements u_T >= 0, any shape [m].

        Returns:
            F, shaped like ``u`` [N].
        """
        u = np.asarray(u, float)
        L, A, E, ft = self.L, self.A, self.E, self.ft
        wc = self.critical_opening
        soft = (u - wc) / (L / (E * A) - wc / (ft * A))
        return np.clip(np.minimum(E * A * u / L, soft), 0.0, None)

    def opening(self, u: np.ndarray) -> np.ndarray:
        """Crack opening w = u_T - F L / (E A) (4.8), shaped like ``u`` [m]."""
        return np.asarray(u, float) - self.force(u) * self.L / (self.E * self.A)
