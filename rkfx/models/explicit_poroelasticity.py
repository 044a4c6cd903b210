"""Explicit u-p dynamics of a saturated poroelastic solid on nodal integration (eqs. 6.42-6.49, 6.78-6.79).

Linear elastic skeleton, small deformation: the matrices of ``rkfx.assembly.nodal_forms`` on one
``NodalIntegration`` (DNI, SNNI or NSNI with its correction and stabilization), lumped masses by
row sums, and the two halves of the internal force that ``rkfx.solvers.explicit_up`` asks for:

    f_u = K u - C_up p                       (K, C_up with the test gradients of the rule)
    f_p = C_pu u' + H p                      (H: k grad N . grad N)

with the storage 1/Q in M_p and the density rho = (1 - n) rho_s + n rho_f in M_u. Essential
conditions are collocation rows at boundary nodes (the shape functions do not interpolate).

With ``fpp=True`` the storage rows carry the fluid pressure projection of (6.49) on the rates,
eps_f int (psi - Pi psi)(p' - Pi p'), the stabilization of chapter 3 for equal-order u-p in
the nearly undrained limit: ``pressure_stabilization(dt)`` gives its matrix S
(``nodal_forms.pressure_projection``, eps_f of (3.53) with h = sqrt(V_L)), which the stepper
adds to the lumped storage (M_p + S) p' = r. S has zero row sums, so lumping would erase it.
"""
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rkfx.approximation.semi_lagrangian import MovingRK, evaluate_moving
from rkfx.assembly import nodal_forms
from rkfx.errors import InputError
from rkfx.integration.nodal_stabilized import NodalIntegration
from rkfx.models.poroelasticity import PoroMaterial, fpp_parameter
from rkfx.parallel.unknowns import LocalUnknowns
from rkfx.solvers.central_difference import Constraint
from rkfx.solvers.fields import layout


@dataclass(frozen=True)
class Constituents:
    """A saturated porous medium from its constituents (the data of §6.4.1).

    Attributes:
        E: Drained Young's modulus [Pa].
        nu: Drained Poisson's ratio [-].
        rho_s: Solid grain density [kg/m^3].
        rho_f: Fluid density [kg/m^3].
        porosity: n [-], in (0, 1).
        k: Mobility [m^4/(N s)].
        K_s: Grain bulk modulus [Pa].
        K_f: Fluid bulk modulus [Pa].
    """

    E: float
    nu: float
    rho_s: float
    rho_f: float
    porosity: float
    k: float
    K_s: float
    K_f: float

    def __post_init__(self):
        for name in ("rho_s", "rho_f", "K_s", "K_f"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name} = {v!r} must be positive")
        if not 0.0 < self.porosity < 1.0:
            raise InputError(f"porosity = {self.porosity!r} must lie in (0, 1)")
        self.material  # validates E, nu, k and the derived alpha

    @property
    def density(self) -> float:
        """rho = (1 - n) rho_s + n rho_f [kg/m^3] (6.5, saturated)."""
        return (1.0 - self.porosity) * self.rho_s + self.porosity * self.rho_f

    @property
    def material(self) -> PoroMaterial:
        """alpha = 1 - K / K_s and 1/Q = n / K_f + (alpha - n) / K_s (6.7 with S_w = 1, C_s = 0)."""
        bulk = self.E / (3.0 * (1.0 - 2.0 * self.nu))
        alpha = 1.0 - bulk / self.K_s
        if not alpha > self.porosity:
            raise InputError(f"alpha = 1 - K/K_s = {alpha:.4g} is not above the porosity {self.porosity}: "
                             "the grains are too soft for these data (check K_s)")
        return PoroMaterial(self.E, self.nu, self.k, alpha, self.porosity / self.K_f + (alpha - self.porosity) / self.K_s)


def collocation_rows(rk: MovingRK, nodes: np.ndarray, component: int | None, num_nodes: int,
                     offset: int, size: int) -> sp.csr_matrix:
    """Rows ``u^h_c(x_I)`` (``component`` c of an interleaved vector field) or ``p^h(x_I)``
    (``component=None``) at ``nodes``, over a vector of ``size`` unknowns whose field starts at ``offset``."""
    nodes = np.asarray(nodes, dtype=np.int64)
    rows = evaluate_moving(rk, rk.x[nodes], nodes).matrix().tocoo()
    cols = rows.col if component is None else 2 * rows.col + component
    return sp.csr_matrix((rows.data, (rows.row, offset + cols)), shape=(len(nodes), size))


class ExplicitPoroDynamics:
    """The model of ``rkfx.solvers.explicit_up`` for linear u-p dynamics on one nodal rule.

    Args:
        rule: The nodal integration (weights, rows) of the particles.
        medium: Constituents of the saturated medium.
        essential: Essential conditions (collocation rows, ``collocation_rows``).
        load: f_ext over the whole vector at time t, or ``None``.
        local: On MPI ranks, the rank's local unknowns (``rkfx.parallel.unknowns``) and ``rule``
            its own points' rows over the whole node set (``nodal_integration(..., points=)``):
            masses, forces and fluxes are then the contributions of the rank's points over its
            local unknowns, the load the owned entries of ``load``'s (``share`` tells the
            stepper, which adds them up), and ``essential`` holds every condition's rows over
            the local unknowns (the rank's local nodes cover their columns). ``None``: the
            whole model.
        fpp: Stabilize the storage rows by the fluid pressure projection (see the module).
    """

    def __init__(self, rule: NodalIntegration, medium: Constituents, essential: Sequence[Constraint] = (),
                 load=None, local: LocalUnknowns | None = None, fpp: bool = False):
        self.local = local
        self.fpp = bool(fpp)
        self.share = None if local is None else local.share
        if local is not None:
            rule = rule.localized(local.nodes)
        n = rule.values.num_cols
        mat = medium.material
        self.layout = layout(("u", 2, 2), ("p", 1, 1), nodes=n)
        self.essential = list(essential)
        self.medium = medium
        self.rule = rule
        self.K = nodal_forms.stiffness(rule, mat.elastic.D())
        self.C_up = nodal_forms.coupling(rule, mat.alpha)
        self.C_pu = nodal_forms.divergence(rule, mat.alpha)
        self.H = nodal_forms.laplacian(rule, mat.k)
        volume = nodal_forms.lumped(rule)
        bad = np.flatnonzero(~(volume > 0))
        if bad.size and rule.values.num_rows == n:  # a part of the points: the stepper checks the summed masses
            raise InputError(f"node {bad[0]} has a non-positive lumped volume {volume[bad[0]]:.3g}; "
                             "the supports are too small for the node set (raise the support factor)")
        self._mass = np.concatenate([np.repeat(medium.density * volume, 2), mat.S * volume])
        if not mat.S > 0:
            raise InputError("explicit u-p stepping needs compressible constituents (1/Q > 0) for the pressure mass")
        self._load = load
        if local is not None:
            self._owned = np.zeros(self.layout.size, bool)
            self._owned[local.share.owned] = True

    def lumped_mass(self) -> np.ndarray:
        return self._mass

    def pressure_stabilization(self, dt: float) -> sp.csr_matrix | None:
        """S of the fluid pressure projection for the step ``dt`` [s] over the p unknowns, or
        ``None`` without it (on ranks: the rank's points' part)."""
        if not self.fpp:
            return None
        eps_f = fpp_parameter(self.medium.material, dt, np.sqrt(self.rule.weights))
        return nodal_forms.pressure_projection(self.rule, eps_f)

    def solid_force(self, u: np.ndarray, p: np.ndarray) -> np.ndarray:
        return self.K @ u - self.C_up @ p

    def fluid_flux(self, v: np.ndarray, p: np.ndarray) -> np.ndarray:
        return self.C_pu @ v + self.H @ p

    def external_force(self, t: float) -> np.ndarray | None:
        if self._load is None:
            return None
        f = self._load(t)
        return f if self.local is None else np.where(self._owned, np.asarray(f)[self.local.index], 0.0)
