"""Published run-outs of two-dimensional granular columns collapsing onto a horizontal floor.

A column of height H and length L (aspect ratio a = H / L) against a wall, released at t = 0,
spreads to a deposit of length L_inf; the normalized run-out is (L_inf - L) / L.

Lube, Huppert, Sparks & Freundt (2005), "Collapses of two-dimensional granular columns",
Phys. Rev. E 72, 041301 (quasi-2D channel, several granular materials):

    (L_inf - L) / L = 1.2 a            for a < 2.3
    (L_inf - L) / L = 1.9 a^(2/3)      for a > 2.3

Bui, Nguyen & Fukagawa (2015), "Failure mechanism of true 2D granular flows" (aluminium rods,
arXiv 1512.05180): for a < 0.65 the column keeps its height at the wall (H_inf / H = 1); above,
(L_inf - L) / L = 3.25 a^0.96 for 0.65 < a < 1.5 and 3.80 a^0.73 for a > 1.5, and
H / H_inf = 1.42 a^(2/3).
"""
import numpy as np

#: The aspect ratio where Lube et al. (2005)'s two regimes meet.
LUBE_BREAK = 2.3


def lube_runout(a) -> np.ndarray:
    """(L_inf - L) / L of Lube et al. (2005) at aspect ratios ``a``."""
    a = np.asarray(a, dtype=float)
    return np.where(a < LUBE_BREAK, 1.2 * a, 1.9 * a ** (2.0 / 3.0))


def bui_runout(a) -> np.ndarray:
    """(L_inf - L) / L of Bui et al. (2015)'s aluminium rods at ``a`` (NaN below a = 0.65,
    where they give no fit)."""
    a = np.asarray(a, dtype=float)
    return np.where(a < 0.65, np.nan, np.where(a < 1.5, 3.25 * a ** 0.96, 3.80 * a ** 0.73))


def bui_final_height(a) -> np.ndarray:
    """H_inf / H of Bui et al. (2015)'s aluminium rods at ``a``."""
    a = np.asarray(a, dtype=float)
    return np.where(a < 0.65, 1.0, 1.0 / (1.42 * a ** (2.0 / 3.0)))
