"""Crack-band finite elements in dolfinx for the bar under tension: the FEM baseline of seed 4.3.1.

The bar [0, L] x [0, h] (one row of square cells of side h = L / elements, split into two
linear triangles each; thickness A / h so that the cross-section is A) is pulled by a
prescribed tip displacement u_T:

    left  (x = 0)   u_x = 0, u_y = 0
    right (x = L)   u_x = u_T, u_y = 0

Plane stress with nu = 0 (so the bar is uniaxial and u_y = 0 adds no reaction). Each element
carries the damage law of ``rkfx.fracture.damage`` (Mazars' equivalent strain (4.6), linear softening
(4.2), irreversibility (4.3)-(4.5)) evaluated with its constant strain. Crack-band scaling
(Bazant and Oh 1983): kappa_c = w_c / h_e with w_c = 2 G_F / f_t and the band width h_e = h,
the element length along the bar, so that an element column failing completely dissipates
G_F A. ``elements`` is odd, so x = L / 2 is the middle of a column; the two triangles of that
column get a damage threshold ``weak_factor`` kappa0 and localize the crack.

Solution: ``rkfx.solvers.quasi_static.march`` on ``CrackBandModel``, the same stepper as the
RKPM bar: displacement control in sub-steps with step cutting (a crack band of one element
column never snaps back when w_c > f_t L / E), each solved by the shared Newton with the
consistent tangent (1 - D) C - D' (C eps) (x) d eps_eq / d eps (non-symmetric; MUMPS LU through
``rkfx.linalg.linear_solver``). dolfinx assembles the residual and tangent; the Dirichlet conditions are
unit rows of their dofs imposed with multipliers, whose sum over the right-end u_x dofs (times
the thickness) is the tip force. The strain, stress and tangent live in DG0 spaces; the
material update is ``rkfx.fracture.damage.update``, the law of the particles.

The mesh lives on one process (``MPI.COMM_SELF``): the bar has a few hundred unknowns; the
linear solves take a communicator.
"""
from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import numpy as np
import scipy.sparse as sp
from mpi4py import MPI

import dolfinx
import dolfinx.fem
import dolfinx.mesh
import ufl

from rkfx.fracture import damage as dm
from rkfx.models.damage_bar import DamageHistory, LoadCurve
from rkfx.errors import InputError
from rkfx.solvers.fields import single
from rkfx.solvers.model import Constraints
from rkfx.solvers.newton import NewtonOptions
from rkfx.solvers.quasi_static import QuasiStatic, march

__all__ = ["CrackBandModel", "CrackBandResult", "solve_crack_band"]


@dataclass
class CrackBandResult:
    """Load path of the crack-band bar.

    Attributes:
        elements: Elements along the bar.
        h: Element length (band width) [m].
        u: Tip displacements of the accepted steps, shape ``(k,)`` [m] (starts at 0).
        force: Tip force, shape ``(k,)`` [N].
        cod: Crack opening w = int D eps_xx dx (4.13), shape ``(k,)`` [m].
        dissipated: Energy dissipated so far, shape ``(k,)`` [J].
        elastic: Elastic energy stored, shape ``(k,)`` [J].
        x: Element centroids along the bar, shape ``(num_cells,)`` [m].
        damage_profile: Element damage at ``u_profile``, shape ``(num_cells,)``.
        u_profile: Tip displacement of the damage profile [m].
        u_T_max: Tip displacement at complete failure (``rkfx.fracture.damage.failure_displacement``) [m].
        n_dofs: Displacement unknowns.
        wall_time_s: Wall time of the load path (mesh, forms and solves) [s].
        iterations: Newton iterations over all steps.
        cuts: Step cuts.
        snapshots: Requested tip displacement -> (stress (num_cells, 3) [Pa], damage
            (num_cells,), u_T reached [m]).
        vertices, cells: The mesh, shape ``(num_vertices, 2)`` [m] and ``(num_cells, 3)``;
            cell_dofs: the element (DG0 dof, the index of ``x`` and the snapshots) of each cell.
    """

    elements: int
    h: float
    u: np.ndarray
    force: np.ndarray
    cod: np.ndarray
    dissipated: np.ndarray
    elastic: np.ndarray
    x: np.ndarray
    damage_profile: np.ndarray
    u_profile: float
    u_T_max: float
    n_dofs: int
    wall_time_s: float
    iterations: int = 0
    cuts: int = 0
    timings: dict[str, float] = field(default_factory=dict)
    snapshots: dict = field(default_factory=dict)
    vertices: np.ndarray | None = None
    cells: np.ndarray | None = None
    cell_dofs: np.ndarray | None = None


class CrackBandModel(DamageHistory):
    """The crack-band bar (module docstring) as a quasi-static model of ``rkfx.solvers``; the
    load factor is the tip displacement u_T.

    Args:
        L, A: Bar length and cross-section [m], [m^2].
        E, GF, ft: Young's modulus [Pa], fracture energy [N/m], tensile strength [Pa].
        elements: Elements along the bar (odd, >= 3).
        weak_factor: kappa0 multiplier of the middle column (< 1 localizes the crack there).

    Attributes:
        h, thickness: Element length (band width) and thickness A / h [m].
        x_cells: Element centroids along the bar, shape ``(num_cells,)`` [m].
        force_scale: f_t h (residual entries are forces per unit thickness).
        reaction_weights: The thickness on the right-end u_x rows: F = t sum mu_right.

    Raises:
        InputError: Bad element count or a band too wide for G_F (w_c / h <= kappa0).
    """

    linear = False

    def __init__(self, L: float, A: float, E: float, GF: float, ft: float, elements: int,
                 weak_factor: float = 0.999):
        if int(elements) != elements or elements < 3 or elements % 2 == 0:
            raise InputError(f"elements = {elements!r}: use an odd number >= 3 so that x = L/2 is mid-element")
        n_el = int(elements)
        h = L / n_el
        material = dm.DamageMaterial(E, 0.0, ft, GF, "stress")
        kappa_c = material.critical_opening / h
        if not kappa_c > material.kappa0:
            raise InputError(f"crack band h = {h:.3g} is too wide for G_F: w_c / h = {kappa_c:.3g} <= kappa0 = "
                             f"{material.kappa0:.3g}; use more elements (h < 2 E G_F / f_t^2)")
        self.elements, self.h, self.thickness = n_el, h, A / h
        self.mesh = mesh = dolfinx.mesh.create_rectangle(MPI.COMM_SELF, [np.array([0.0, 0.0]), np.array([L, h])], [n_el, 1],
                                             dolfinx.mesh.CellType.triangle)
        V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (2,)))
        Q = dolfinx.fem.functionspace(mesh, ("DG", 0, (3,)))
        T = dolfinx.fem.functionspace(mesh, ("DG", 0, (3, 3)))
        Q0 = dolfinx.fem.functionspace(mesh, ("DG", 0))
        self._u = dolfinx.fem.Function(V, name="u")
        self._stress = dolfinx.fem.Function(Q, name="stress")
        self._tangent = dolfinx.fem.Function(T, name="tangent")

        def voigt(w):
            return ufl.as_vector([w[0].dx(0), w[1].dx(1), w[0].dx(1) + w[1].dx(0)])

        v = ufl.TestFunction(V)
        du = ufl.TrialFunction(V)
        self._a = dolfinx.fem.form(ufl.inner(ufl.dot(self._tangent, voigt(du)), voigt(v)) * ufl.dx)
        self._r = dolfinx.fem.form(ufl.inner(self._stress, voigt(v)) * ufl.dx)
        self._K = dolfinx.fem.create_matrix(self._a)  # one sparsity pattern for every assembly
        self._strain_expr = dolfinx.fem.Expression(voigt(self._u), Q.element.interpolation_points)
        self._strain = dolfinx.fem.Function(Q)
        # Per-element data in DG0 dof order (one dof per cell).
        volume = dolfinx.fem.assemble_vector(dolfinx.fem.form(ufl.TestFunction(Q0) * ufl.dx)).array.copy()
        xc = dolfinx.fem.Function(Q0)
        xc.interpolate(dolfinx.fem.Expression(ufl.SpatialCoordinate(mesh)[0], Q0.element.interpolation_points))
        self.x_cells = xc.x.array.copy()
        self.cell_dofs = Q0.dofmap.list[:, 0].copy()  # the DG0 dof of each cell
        weak = np.abs(self.x_cells - 0.5 * L) < 0.5 * h
        self._start_history(dm.damage_model(material, volume, np.where(weak, weak_factor, 1.0), kappa_c=kappa_c,
                                            regularized=False))

        fdim = mesh.topology.dim - 1
        left = dolfinx.mesh.locate_entities_boundary(mesh, fdim, lambda x: np.isclose(x[0], 0.0))
        right = dolfinx.mesh.locate_entities_boundary(mesh, fdim, lambda x: np.isclose(x[0], L))
        # Unit rows of the Dirichlet dofs: u_x = u_T on the right end, u = 0 on the left one, u_y = 0 on the right.
        dofs, g_hat = [], []
        for facets, comp, value in ((right, 0, 1.0), (left, 0, 0.0), (left, 1, 0.0), (right, 1, 0.0)):
            d = np.sort(dolfinx.fem.locate_dofs_topological(V.sub(comp), fdim, facets))
            dofs.append(d)
            g_hat.append(np.full(len(d), value))
        dofs, self._g_hat = np.concatenate(dofs), np.concatenate(g_hat)
        self.n_dofs = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
        self.layout = single("u", 2, 0, self.n_dofs // 2)
        self._G = sp.csr_matrix((np.ones(len(dofs)), (np.arange(len(dofs)), dofs)), shape=(len(dofs), self.n_dofs))
        self.force_scale = ft * h
        self.reaction_weights = self.thickness * self._g_hat

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        self._u.x.array[:] = x
        self._strain.interpolate(self._strain_expr)
        upd = self.update(self._strain.x.array.reshape(-1, 3).copy())
        self._stress.x.array[:] = upd.stress.ravel()
        self._tangent.x.array[:] = upd.tangent.ravel()
        return dolfinx.fem.assemble_vector(self._r).array[:self.n_dofs].copy()

    def tangent(self, x: np.ndarray, t: float) -> sp.csr_matrix:
        self._K.set_value(0.0)
        dolfinx.fem.assemble_matrix(self._K, self._a)
        return sp.csr_matrix(self._K.to_scipy(), copy=True)

    def constraints(self, t: float) -> Constraints:
        return Constraints(self._G, t * self._g_hat, self._g_hat)


def solve_crack_band(L: float, A: float, E: float, GF: float, ft: float, elements: int,
                     targets: np.ndarray, weak_factor: float = 0.999, u_profile: float | None = None,
                     rtol: float = 1e-10, max_iterations: int = 24, comm=MPI.COMM_SELF, checkpoint_every: int = 0,
                     checkpoint_dir: Path | None = None, resume: Path | None = None,
                     snapshots: Sequence[float] = ()) -> CrackBandResult:
    """Crack-band FEM load path of the bar through the tip displacements ``targets``.

    Args:
        L: Bar length [m].
        A: Cross-section [m^2].
        E, GF, ft: Young's modulus [Pa], fracture energy [N/m], tensile strength [Pa].
        elements: Elements along the bar (odd, >= 3).
        targets: Increasing tip displacements every one of which is reached, shape ``(k,)`` [m].
        weak_factor: kappa0 multiplier of the middle column (< 1 localizes the crack there).
        u_profile: Tip displacement at which the damage profile is recorded (default: the last).
        rtol: Newton tolerance on the residual, relative to f_t h.
        max_iterations: Newton iterations per sub-step before the step is cut.
        comm: Communicator of the linear solves.
        checkpoint_every, checkpoint_dir, resume: Checkpoints every so many accepted steps
            into ``checkpoint_dir``; continue from the checkpoint folder ``resume``.
        snapshots: Further tip displacements [m] at which stress and damage are kept (each one
            is also a target of the path: give some of ``targets`` to leave the path as it is).

    Raises:
        InputError: Bad element count or a band too wide for G_F (w_c / h <= kappa0).
    """
    t_start = time.perf_counter()
    model = CrackBandModel(L, A, E, GF, ft, elements, weak_factor)
    u_profile = float(targets[-1] if u_profile is None else u_profile)
    curve = LoadCurve(model, model.thickness, model.h, sorted({u_profile, *map(float, snapshots)}))
    t_setup = time.perf_counter()
    out = march(model, np.unique(np.r_[np.asarray(targets, float), u_profile, np.asarray(snapshots, float)]),
                QuasiStatic(NewtonOptions(max_iterations=max_iterations), rtol=rtol), recorder=curve, comm=comm,
                checkpoint_every=checkpoint_every, checkpoint_dir=checkpoint_dir, resume=resume)
    c = curve.series()
    profile = curve.snapshots.get(u_profile)
    return CrackBandResult(
        elements=model.elements, h=model.h, u=c["u"], force=c["force"], cod=c["cod"], dissipated=c["dissipated"],
        elastic=c["elastic"], x=model.x_cells,
        damage_profile=profile[1] if profile else np.zeros(model.points.num_points),
        u_profile=profile[2] if profile else float(c["u"][-1]),
        u_T_max=dm.failure_displacement(c["u"], c["force"]), n_dofs=model.n_dofs,
        wall_time_s=t_setup - t_start + out.wall_time_s, iterations=out.iterations, cuts=out.cuts,
        timings={"setup": t_setup - t_start, "path": out.wall_time_s}, snapshots=dict(curve.snapshots),
        vertices=model.mesh.geometry.x[:, :2].copy(), cells=model.mesh.geometry.dofmaps[0].copy(),
        cell_dofs=model.cell_dofs)
