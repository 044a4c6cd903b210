"""An elastic-plastic solid at finite deformation on moving RK particles (eqs. 6.8-6.13, 6.22-6.29, 6.50-6.79).

The updated-Lagrangian form of chapter 6 without the fluid: the particles move with the
material, the RK approximation and its nodal integration are rebuilt in the current
configuration after every step (``rkfx.approximation.semi_lagrangian``,
``rkfx.integration.nodal_stabilized``), and the stress is advanced by its Jaumann rate and a
Drucker-Prager return map. The model is an ``ExplicitBase`` model of
``rkfx.solvers.central_difference`` (d = the displacement coefficients since the start; its
internal force is called once per step with the new d and commits the step):

1. du = d - d_n; the velocity-gradient increment at each particle L from the trial gradients
   of the rule at x^n, dL = sum_I du_I (x) grad N_I(x_L), and the particle's move
   dx_L = sum_I N_I(x_L) du_I.
2. The stress: rotated by the spin of dL (6.13), then ``DruckerPrager.update`` with the strain
   increment sym(dL) (6.12). The volume V_L *= det(I + dL), kept within a factor
   ``max_dilation`` of V_L^0: beyond it the volume a particle gains is the void opened where
   grains part (the tension cut-off), not material; the mass m_L = rho V_L^0 stays.
3. NSNI only: the stress gradients tau_,x and tau_,y of the assumed stress (6.76) are the
   implicit gradients (6.29) of the particle stresses, sum_J N^∇_J(x_L) sigma_J, in the
   current configuration: no history, bounded by how the stress varies between particles.
4. The particles move, the approximation is rebuilt there (incremental neighbour search) and
   the internal force is evaluated in the new configuration (boundary segments stretched
   beyond the supports of their ends are left out of the corrected rules' boundary integral:
   grains have parted there):

       f_I = sum_L V_L B_I^c(x_L)^T sigma_L + sum_L [m_Lx B_I,x^T tau_,x + m_Ly B_I,y^T tau_,y]
             - sum_L N_I(x_L) F_L^wall,

   with the corrected test gradients of the rule, its second moments, and the wall forces of
   ``rkfx.assembly.rigid_walls``.

With ``viscosity`` beta > 0 a viscous stress 2 eta D (eta = beta rho c h_L, c the elastic
wave speed, h_L = sqrt(V_L), D the rate of deformation of the last step) is added to sigma in
the force: an artificial viscosity that vanishes with the particle spacing. ``eta`` [Pa s]
adds a fixed viscosity to it, the same at every spacing: a Kelvin-Voigt regularization of the
material itself (on the column collapse the run-out converges with it, 0.498 / 0.495 / 0.487
at 21 / 41 / 81 particles across, the finest at half the step; docs/large_deformation.md).

The lumped mass of coefficient I is the particle mass m_I (a constant; the row sums of the
moving approximation would change from step to step), and gravity is m_I g.

Status (measured on the collapse of a dry column, docs/large_deformation.md): with the sheet
rows of ``rkfx.approximation.semi_lagrangian`` SNNI and NSNI without the VC correction run the
collapse to the end at 21-81 particles across, far too mobile without viscosity and nearly to
rest near the published run-out with beta = 0.1 (not a converged result: eta falls with h);
the VC-corrected rules still fail (non-symmetric systems).
"""
from collections.abc import Mapping, Sequence

import numpy as np
import scipy.sparse.linalg as spla

from rkfx.approximation.semi_lagrangian import evaluate_moving, moved, moving_rk
from rkfx.assembly.rigid_walls import Wall, WallContact, wall_forces
from rkfx.errors import InputError, point_str
from rkfx.integration.nodal_stabilized import RULES, boundary_rule, nodal_cells, nodal_integration
from rkfx.materials import jaumann
from rkfx.materials.drucker_prager import DruckerPrager
from rkfx.solvers.central_difference import ExplicitBase
from rkfx.solvers.fields import single

def _largest_eigenvalue(force_of_strain, model: "LagrangianPlasticity") -> float:
    """|lambda|_max of M^-1 K for the linear force ``force_of_strain(Voigt strains of the
    points)`` of a displacement on ``model``'s current rows (ARPACK from a seeded start; dense
    for a few particles)."""
    mass = model.lumped_mass()
    size = mass.size

    def apply(v):
        strain = jaumann.strain_increment(_gradients(model.rule.trial, np.reshape(v, (-1, 2))), 1.0)
        return force_of_strain(strain).ravel() / mass

    if size <= 64:
        values = np.linalg.eigvals(np.column_stack([apply(e) for e in np.eye(size)]))
    else:
        op = spla.LinearOperator((size, size), matvec=apply, dtype=np.float64)
        start = np.random.default_rng(0).standard_normal(size)
        try:
            values = spla.eigs(op, k=1, which="LM", v0=start, tol=1e-4, return_eigenvectors=False)
        except spla.ArpackNoConvergence as err:
            if not len(err.eigenvalues):
                raise InputError("the explicit step's limit: ARPACK found no eigenvalue of the particles' "
                                 "operator; check the particles (a degenerate set?)") from err
            values = err.eigenvalues
    return float(np.abs(values).max())


def _gradients(rows, du: np.ndarray) -> np.ndarray:
    """L[:, c, k] = sum_I rows_k(I) du[I, c] for gradient rows with components (d/dx, d/dy)."""
    return np.transpose(rows @ du, (0, 2, 1))


def _rate(d: np.ndarray) -> np.ndarray:
    """2 D in the stress layout (xx, yy, zz, xy) from Voigt (d_xx, d_yy, gamma_xy)."""
    return np.column_stack([2.0 * d[:, 0], 2.0 * d[:, 1], np.zeros(len(d)), d[:, 2]])


def _divergence(rows, stress: np.ndarray) -> np.ndarray:
    """sum_L rows(I, L)^T (sigma_xx, sigma_xy; sigma_xy, sigma_yy)_L, per coefficient ``(n, 2)``:
    ``stress`` (m, 4) already weighted."""
    bx, by = rows.matrix(0).T, rows.matrix(1).T
    return np.column_stack([bx @ stress[:, 0] + by @ stress[:, 3], bx @ stress[:, 3] + by @ stress[:, 1]])


class LagrangianPlasticity(ExplicitBase):
    """The explicit model of a Drucker-Prager solid on moving particles (module docstring).

    Args:
        x: Initial particle positions, shape ``(n, 2)`` [m].
        volume: Their volumes (areas) V_L^0, shape ``(n,)`` [m^2].
        support: RK support radii a_I, shape ``(n,)`` or a scalar [m].
        boundary: Particle pairs along the boundary with the body on their left, ``(k, 2)``;
            they move with the particles (the corrected rules integrate N_I n over them).
        soil: The Drucker-Prager law.
        density: rho [kg/m^3].
        dt: The time step of the run [s] (the walls' penalty and friction use it); refused
            beyond ``stable_step``, the linear limit of elasticity and viscosity together on the
            initial rows, the particles shrunk to the dilation bound [s].
        rule: A nodal rule of ``rkfx.integration.nodal_stabilized.RULES``.
        walls: Rigid walls (``rkfx.assembly.rigid_walls.Wall``).
        gravity: (g_x, g_y) [m/s^2].
        stress: Initial effective stress, shape ``(n, 4)`` [Pa] (default 0).
        skin: Verlet skin of the neighbour search [m] (default half the smallest support / 2).
        kappa: Wall penalty in units of m / dt^2.
        max_dilation: Bound on V_L / V_L^0 and V_L^0 / V_L (see the module docstring).
        viscosity: beta of the artificial viscosity eta = beta rho c h_L (module docstring).
        eta: A fixed viscosity [Pa s] added to it.
    """

    def __init__(self, x: np.ndarray, volume: np.ndarray, support, boundary: np.ndarray, soil: DruckerPrager,
                 density: float, dt: float, *, rule: str = "nsni", walls: Sequence[Wall] = (),
                 gravity=(0.0, -9.81), stress: np.ndarray | None = None, skin: float | None = None,
                 kappa: float = 0.1, max_dilation: float = 1.25, viscosity: float = 0.0,
                 eta: float = 0.0):
        x = np.array(x, dtype=np.float64)
        n = len(x)
        if rule not in RULES:
            raise InputError(f"unknown nodal integration rule {rule!r}; choose one of {', '.join(RULES)}")
        if not (np.isfinite(density) and density > 0):
            raise InputError(f"density = {density!r} must be positive [kg/m^3]")
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"dt = {dt!r} must be a positive time step [s]")
        self.volume = np.array(np.broadcast_to(np.asarray(volume, float), (n,)))
        if not np.all(self.volume > 0):
            bad = int(np.flatnonzero(~(self.volume > 0))[0])
            raise InputError(f"particle {bad} has volume {self.volume[bad]!r}; particle volumes must be positive")
        self.support = np.ascontiguousarray(np.broadcast_to(np.asarray(support, float), (n,)))
        self.boundary = np.asarray(boundary, dtype=np.int64).reshape(-1, 2)
        self.soil, self.density, self.dt, self.rule_name = soil, float(density), float(dt), rule
        self.walls, self.kappa = tuple(walls), float(kappa)
        self.gravity = np.asarray(gravity, float)
        self.skin = float(0.25 * self.support.min() if skin is None else skin)
        if not (np.isfinite(max_dilation) and max_dilation > 1.0):
            raise InputError(f"max_dilation = {max_dilation!r} must be a ratio > 1 (e.g. 1.25)")
        self.volume0, self.max_dilation = self.volume.copy(), float(max_dilation)
        if not (np.isfinite(viscosity) and viscosity >= 0.0):
            raise InputError(f"viscosity = {viscosity!r} must be >= 0 (a fraction of rho c h)")
        if not (np.isfinite(eta) and eta >= 0.0):
            raise InputError(f"eta = {eta!r} must be a viscosity >= 0 [Pa s]")
        self.viscosity, self.eta, self.rate = float(viscosity), float(eta), None
        self._rho_c = density * np.sqrt((soil.bulk_modulus + 4.0 * soil.shear_modulus / 3.0) / density)
        self.particle_mass = self.density * self.volume
        self.layout = single("u", 2, 2, n)
        self.essential = ()
        self.x = x
        self.stress = np.zeros((n, 4)) if stress is None else np.array(stress, float)
        if self.stress.shape != (n, 4):
            raise InputError(f"initial stresses of shape {self.stress.shape} for {n} particles: give (n, 4) "
                             "(xx, yy, zz, xy)")
        self.plastic_strain = np.zeros(n)
        self.d_last = np.zeros(2 * n)
        self.counters = np.zeros(3, np.int64)  # steps, steps with a search, rows searched
        self.torn = np.zeros(2, np.int64)  # evaluation points given Shepard rows and sheet rows
        self.yielded = np.zeros(n, bool)
        self.contact: WallContact | None = None
        self._rebuild(fresh=True)
        self.stable_step = self._linear_limit()
        if dt > self.stable_step:
            raise InputError(f"dt = {dt:.3g} s is beyond the explicit limit of elasticity and viscosity on the "
                             f"particles, {self.stable_step:.3g} s; reduce dt (or eta, viscosity)")

    def _linear_limit(self) -> float:
        """The linear limit of the explicit step [s], elasticity and viscosity together, on the
        rows of the current configuration, its particles shrunk to the bound V_L^0 / max_dilation.

        The central difference step of a mode of frequency omega and viscous rate nu is stable
        for omega dt <= 2 (sqrt(1 + xi^2) - xi), xi = nu / 2 omega (alone: dt <= 2 / omega,
        dt <= 2 / nu). omega^2 is the largest eigenvalue (in size) of M^-1 K, K the force of the
        elastic stress of a displacement (NSNI: with its stress-gradient terms), and nu that of
        M^-1 K_eta, K_eta the force of its viscous stress 2 eta_L D with eta_L taken at the
        shrunk volume. Both operators scale as 1 / V when the particles shrink together by a
        factor, so omega^2 and nu are taken times ``max_dilation``. Necessary, not sufficient:
        the rows change as the particles move (docs/large_deformation.md).
        """
        shrunk = self.volume / self.max_dilation
        elastic = self.max_dilation * _largest_eigenvalue(
            lambda e: self._force(s := self.soil.elastic_increment(e), s), self)
        omega = np.sqrt(elastic)
        nu = 0.0
        if self.viscosity > 0.0 or self.eta > 0.0:
            nu = self.max_dilation * _largest_eigenvalue(
                lambda e: self._force(None, self._with_viscous(0.0, _rate(e), shrunk)), self)
        if omega == 0.0:
            return 2.0 / nu if nu > 0.0 else np.inf
        xi = nu / (2.0 * omega)
        return float(2.0 / omega * (np.sqrt(1.0 + xi * xi) - xi))

    # -- the approximation in the current configuration

    def _rebuild(self, fresh: bool = False) -> None:
        cells = nodal_cells(self.x, self.volume)
        if fresh or cells.reach > self.rk.reach:
            self.rk = moving_rk(self.x, self.support, self.skin, reach=1.5 * cells.reach, torn=self.torn)
            searched = self.rk.searched
        else:
            self.rk = moved(self.rk, self.x)
            searched = self.rk.searched
        if not fresh:
            self.counters += [1, searched > 0, searched]
        edges = None
        if len(self.boundary):
            # A boundary segment stretched beyond its end's support is no longer a surface of the
            # body but a gap between parted grains: its points are covered by no one.
            a, b = self.boundary[:, 0], self.boundary[:, 1]
            length = np.linalg.norm(self.x[b] - self.x[a], axis=1)
            edges = boundary_rule(self.x, self.boundary[length < np.minimum(self.support[a], self.support[b])])
        self.rule = nodal_integration(self.rk, cells, edges, self.rule_name)
        self.implicit = evaluate_moving(self.rk, implicit=True) if self.rule.moments is not None else None

    # -- the explicit model

    def lumped_mass(self) -> np.ndarray:
        return np.repeat(self.particle_mass, 2)

    def external_force(self, t: float) -> np.ndarray:
        return (self.particle_mass[:, None] * self.gravity[None, :]).ravel()

    def internal_force(self, d: np.ndarray) -> np.ndarray:
        du = (d - self.d_last).reshape(-1, 2)
        if np.any(du):
            self._advance(du)
            self.d_last = d.copy()
        f = self._force(self.stress, self._with_viscous(self.stress, self.rate, self.volume))
        self.contact = None
        if self.walls:
            dx = self.rule.values @ du
            self.contact = wall_forces(self.walls, self.x, dx[:, 0], self.particle_mass, self.dt, self.kappa)
            f -= self.rule.values.matrix().T @ self.contact.force
        return f.ravel()

    def _with_viscous(self, stress: np.ndarray, rate: np.ndarray | None, volume: np.ndarray) -> np.ndarray:
        """sigma + 2 eta_L D: the viscous stress of the rate of deformation ``rate`` (the stress
        layout (xx, yy, zz, xy), D_xy as gamma_xy / 2) at particles of ``volume``, eta_L =
        beta rho c sqrt(V_L) + eta."""
        if rate is None:
            return stress
        if self.viscosity > 0.0:
            stress = stress + (self._rho_c * rate) * (self.viscosity * np.sqrt(volume))[:, None]
        if self.eta > 0.0:
            stress = stress + self.eta * rate
        return stress

    def _force(self, stress: np.ndarray, total: np.ndarray) -> np.ndarray:
        """The internal force (n, 2) of the particle stresses ``total`` on the current rule, with
        the NSNI terms of the stress gradients of ``stress`` (``None``: without them)."""
        r = self.rule
        f = _divergence(r.test, r.weights[:, None] * total)
        if r.moments is not None and stress is not None:
            tau = self.implicit @ stress  # (n, 3, 4): [sigma, d sigma / dx, d sigma / dy] at the particles
            for k, rows in enumerate((r.trial_x, r.trial_y)):
                f += _divergence(rows, r.moments[:, k:k + 1] * tau[:, 1 + k])
        return f

    def _advance(self, du: np.ndarray) -> None:
        r = self.rule
        L = _gradients(r.trial, du)
        if self.viscosity > 0.0 or self.eta > 0.0:
            self.rate = _rate(jaumann.strain_increment(L, 1.0 / self.dt))
        rotated = jaumann.rotated(self.stress, L, 1.0)
        step = self.soil.update(rotated, jaumann.strain_increment(L, 1.0), self.plastic_strain)
        self.stress, self.plastic_strain, self.yielded = step.stress, step.plastic_strain, step.yielded
        jac = (1.0 + L[:, 0, 0]) * (1.0 + L[:, 1, 1]) - L[:, 0, 1] * L[:, 1, 0]
        if not np.all(jac > 0):
            bad = int(np.flatnonzero(~(jac > 0))[0])
            raise InputError(f"particle {bad} at {point_str(self.x[bad])} was turned inside out in one step "
                             f"(det F = {jac[bad]:.3g}); reduce the time step")
        self.volume = np.clip(self.volume * jac, self.volume0 / self.max_dilation, self.volume0 * self.max_dilation)
        self.x = self.x + (r.values @ du)[:, 0]
        self._rebuild()

    # -- history

    def state(self) -> dict[str, np.ndarray]:
        return {"x": self.x, "volume": self.volume, "stress": self.stress,
                "plastic_strain": self.plastic_strain, "d_last": self.d_last, "counters": self.counters,
                "torn": self.torn}

    def restore(self, arrays: Mapping[str, np.ndarray]) -> None:
        for key in self.state():
            setattr(self, key, np.array(arrays[key]))
        if self.torn.shape == (1,):  # a checkpoint written before sheet rows were counted
            self.torn = np.array([self.torn[0], 0], np.int64)
        self._rebuild(fresh=True)

    @property
    def neighbour_rebuilds(self) -> dict[str, int]:
        """Steps run, steps that searched some rows again, and rows searched in all."""
        steps, searches, rows = map(int, self.counters)
        return {"steps": steps, "steps_with_search": searches, "rows_searched": rows,
                "torn_point_evaluations": int(self.torn[0]), "sheet_point_evaluations": int(self.torn[1])}
