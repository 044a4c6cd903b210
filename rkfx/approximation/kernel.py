"""Cubic B-spline kernel Phi_a of eq. (3.19), as a compiled scalar function."""
import numba
import numpy as np


@numba.njit(inline="always", cache=True)
def cubic_spline(s: float) -> tuple[float, float]:
    """Kernel value and derivative d(Phi)/ds at normalised distance s = |x - x_I| / a_I >= 0."""
    if s <= 0.5:
        return 2.0 / 3.0 - 4.0 * s * s + 4.0 * s * s * s, -8.0 * s + 12.0 * s * s
    if s <= 1.0:
        t = 1.0 - s
        return 4.0 / 3.0 * t * t * t, -4.0 * t * t
    return 0.0, 0.0


def cubic_spline_values(s: np.ndarray) -> np.ndarray:
    """Vectorised kernel values for an array of normalised distances (for plotting and tests)."""
    s = np.abs(np.asarray(s, dtype=float))
    return np.where(
        s <= 0.5,
        2.0 / 3.0 - 4.0 * s**2 + 4.0 * s**3,
        np.where(s <= 1.0, 4.0 / 3.0 * (1.0 - s) ** 3, 0.0),
    )
