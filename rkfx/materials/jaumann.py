"""The Jaumann rate of the stress (eqs. 6.8-6.13) for explicit steps in the current configuration.

With the velocity gradient L = grad_x v (6.10), the rate of deformation D = (L + L^T) / 2 (6.12)
and the spin omega = (L - L^T) / 2 (6.9), the stress rate is (6.13)

    d sigma / dt = C_T : D + omega . sigma - sigma . omega,

so a step of dt takes the strain increment D dt to the constitutive update (e.g.
``rkfx.materials.drucker_prager``) and adds the rotation dt (omega . sigma - sigma . omega) to
the stress. In plane strain the spin has one component w = (L_xy - L_yx) / 2 and the rotation
is dt (2 w s_xy, -2 w s_xy, 0, w (s_yy - s_xx)) on (xx, yy, zz, xy). Arrays over points:
stresses ``(m, 4)``, velocity gradients ``(m, 2, 2)`` with L[:, i, j] = d v_i / d x_j.
"""
import numpy as np

from rkfx.errors import InputError


def _gradients(L) -> np.ndarray:
    L = np.asarray(L, float)
    if L.ndim != 3 or L.shape[1:] != (2, 2):
        raise InputError(f"velocity gradients of shape {L.shape}: give (m, 2, 2) with L[:, i, j] = d v_i / d x_j")
    return L


def strain_increment(L, dt: float) -> np.ndarray:
    """D dt as Voigt (d eps_xx, d eps_yy, d gamma_xy), shape ``(m, 3)``."""
    L = _gradients(L)
    return dt * np.column_stack([L[:, 0, 0], L[:, 1, 1], L[:, 0, 1] + L[:, 1, 0]])


def spin(L) -> np.ndarray:
    """w = omega_xy = (L_xy - L_yx) / 2, shape ``(m,)`` [1/s]."""
    L = _gradients(L)
    return 0.5 * (L[:, 0, 1] - L[:, 1, 0])


def rotated(stress, L, dt: float) -> np.ndarray:
    """sigma + dt (omega . sigma - sigma . omega), shape ``(m, 4)``."""
    stress = np.asarray(stress, float)
    w = dt * spin(L)
    if stress.shape != (len(w), 4):
        raise InputError(f"stresses of shape {stress.shape} for {len(w)} velocity gradients: give (m, 4)")
    out = stress.copy()
    out[:, 0] += 2.0 * w * stress[:, 3]
    out[:, 1] -= 2.0 * w * stress[:, 3]
    out[:, 3] += w * (stress[:, 1] - stress[:, 0])
    return out
