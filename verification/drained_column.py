"""The steady state of an unsaturated soil column drained at its base: exact by quadrature.

A laterally confined column of height L (rollers on the sides, u_y = 0 and p = 0 at the base,
no flow through the top and the sides, traction-free top) of the unsaturated u-p equations of
``rkfx.models.unsaturated_poroelasticity`` comes to rest when Darcy's flux
-k k_rw (dp/dy + S_w rho_w g) vanishes everywhere, i.e. on the profile

    dp/dy = -S_w(-p) rho_w g,   p(0) = 0,

(p < 0 above the base: suction grows with height and the soil desaturates). Measured from the
saturated state in equilibrium with gravity, the skeleton carries the change of the mixture's
weight, b_y = n rho_w (1 - S_w) g upward, and with the top traction-free the total stress is
sigma_yy(y) = int_y^L b_y; the effective stress sigma''_yy = sigma_yy + alpha S_w p (Bishop)
strains the confined skeleton by eps_yy = sigma''_yy / M (M = lambda + 2 mu), and the top moves
by u_y(L) = int_0^L eps_yy dy.

Both ordinary integrals are taken by ``scipy.integrate.solve_ivp`` (DOP853, rtol 1e-12) on
the retention law of the soil, so the reference is exact to that tolerance for any law.
Checked in ``tests/test_steady_state.py``: saturated (S_w = 1) the profile is hydrostatic,
p = -rho_w g y, and the settlement has its closed form.
"""
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp


@dataclass(frozen=True)
class DrainedColumn:
    """The exact steady state, sampled.

    Attributes:
        y: Heights [m], increasing from 0 to L.
        p: Water pressure p(y) [Pa] (negative: suction).
        saturation: S_w(y) [-].
        top_displacement: u_y(L) [m] (positive up).
    """

    y: np.ndarray
    p: np.ndarray
    saturation: np.ndarray
    top_displacement: float


def drained_column(soil, height: float, num: int = 401) -> DrainedColumn:
    """The steady state of ``soil`` (``rkfx.models.unsaturated_poroelasticity.UnsaturatedSoil``)
    in a column of ``height`` [m], sampled at ``num`` heights."""
    medium, law = soil.medium, soil.retention
    rho_w, g, n = medium.rho_f, soil.gravity, medium.porosity
    alpha, modulus = soil.alpha, medium.material.elastic.constrained_modulus
    y = np.linspace(0.0, height, num)

    def saturation(p):
        return float(law.saturation(np.array([-p]))[0])

    flow = solve_ivp(lambda _, p: [-saturation(p[0]) * rho_w * g], (0.0, height), [0.0], method="DOP853",
                     rtol=1e-12, atol=1e-12, dense_output=True)
    p = flow.sol(y)[0]
    s_w = np.array([saturation(v) for v in p])

    # sigma_yy(y) = int_y^L b: integrate db from the top down, then the strain from the base up.
    def load(t, _):
        return [n * rho_w * (1.0 - saturation(flow.sol(t)[0])) * g]
    weight = solve_ivp(load, (height, 0.0), [0.0], method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)

    def strain(t, _):
        pt = flow.sol(t)[0]
        return [(-weight.sol(t)[0] + alpha * saturation(pt) * pt) / modulus]
    # -weight: sigma_yy(y) = int_y^L b = -(the integral from L down to y)
    top = solve_ivp(strain, (0.0, height), [0.0], method="DOP853", rtol=1e-12, atol=1e-16)
    return DrainedColumn(y, p, s_w, float(top.y[0, -1]))
