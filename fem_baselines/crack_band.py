"""Crack-band finite elements in dolfinx for the bar under tension: the FEM baseline of seed 4.3.1.

The bar [0, L] x [0, h] (one row of square cells of side h = L / elements, split into two
linear triangles each; thickness A / h so that the cross-section is A) is pulled by a
prescribed tip displacement u_T:

    left  (x = 0)   u_x = 0, u_y = 0
    right (x = L)   u_x = u_T, u_y = 0

Plane stress with nu = 0 (so the bar is uniaxial and u_y = 0 adds no reaction). Each element
carries the damage law of ``rkfx.damage`` (Mazars' equivalent strain (4.6), linear softening
(4.2), irreversibility (4.3)-(4.5)) evaluated with its constant strain. Crack-band scaling
(Bazant and Oh 1983): kappa_c = w_c / h_e with w_c = 2 G_F / f_t and the band width h_e = h,
the element length along the bar, so that an element column failing completely dissipates
G_F A. ``elements`` is odd, so x = L / 2 is the middle of a column; the two triangles of that
column get a damage threshold ``weak_factor`` kappa0 and localize the crack.

Solution: displacement control in sub-steps (``rkfx.damage.march``; a crack band of one
element column never snaps back when w_c > f_t L / E), each solved by Newton's
method with the consistent tangent (1 - D) C - D' (C eps) (x) d eps_eq / d eps (non-symmetric;
MUMPS LU through PETSc), following dolfinx's Newton convention for the Dirichlet data
(lifting with x0 = u, alpha = -1). The strain, stress and tangent live in DG0 spaces; the
material update is ``rkfx.damage.update``, the law of the particles. The tip force is the virtual
work of the stresses on v = (x / L, 0): F = t sum_e sigma_xx,e V_e / L.

Runs on one process (``MPI.COMM_SELF``): the bar has a few hundred unknowns.
"""
from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.mesh
import ufl

from rkfx import damage as dm
from rkfx.errors import InputError

__all__ = ["CrackBandResult", "solve_crack_band"]

_prefix_counter = itertools.count()


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
        u_T_max: Tip displacement at complete failure (``rkfx.damage.failure_displacement``) [m].
        n_dofs: Displacement unknowns.
        wall_time_s: Wall time of the load path (mesh, forms and solves) [s].
        iterations: Newton iterations over all steps.
        cuts: Step cuts.
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


@dataclass(frozen=True)
class _Trial:
    u: float
    force: float
    x: np.ndarray
    update: dm.DamageUpdate
    damage_increment: float
    iterations: int


def solve_crack_band(L: float, A: float, E: float, GF: float, ft: float, elements: int,
                     targets: np.ndarray, weak_factor: float = 0.999, u_profile: float | None = None,
                     rtol: float = 1e-10, max_iterations: int = 25) -> CrackBandResult:
    """Crack-band FEM load path of the bar through the tip displacements ``targets``.

    Args:
        L: Bar length [m].
        A: Cross-section [m^2].
        E, GF, ft: Young's modulus [Pa], fracture energy [N/m], tensile strength [Pa].
        elements: Elements along the bar (odd, >= 3).
        targets: Increasing tip displacements every one of which is reached, shape ``(k,)`` [m].
        weak_factor: kappa0 multiplier of the middle column (< 1 localizes the crack there).
        u_profile: Tip displacement at which the damage profile is recorded (default: the last).
        rtol: Newton tolerance on the residual, relative to f_t A.
        max_iterations: Newton iterations per sub-step before the step is cut.

    Raises:
        InputError: Bad element count or a band too wide for G_F (w_c / h <= kappa0).
    """
    if int(elements) != elements or elements < 3 or elements % 2 == 0:
        raise InputError(f"elements = {elements!r}: use an odd number >= 3 so that x = L/2 is mid-element")
    t_start = time.perf_counter()
    comm = MPI.COMM_SELF
    n_el = int(elements)
    h = L / n_el
    thickness = A / h
    material = dm.DamageMaterial(E, 0.0, ft, GF, "stress")
    kappa_c = material.critical_opening / h
    if not kappa_c > material.kappa0:
        raise InputError(f"crack band h = {h:.3g} is too wide for G_F: w_c / h = {kappa_c:.3g} <= kappa0 = "
                         f"{material.kappa0:.3g}; use more elements (h < 2 E G_F / f_t^2)")
    mesh = dolfinx.mesh.create_rectangle(comm, [np.array([0.0, 0.0]), np.array([L, h])], [n_el, 1],
                                         dolfinx.mesh.CellType.triangle)
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (2,)))
    Q = dolfinx.fem.functionspace(mesh, ("DG", 0, (3,)))
    T = dolfinx.fem.functionspace(mesh, ("DG", 0, (3, 3)))
    Q0 = dolfinx.fem.functionspace(mesh, ("DG", 0))
    u = dolfinx.fem.Function(V, name="u")
    stress = dolfinx.fem.Function(Q, name="stress")
    tangent = dolfinx.fem.Function(T, name="tangent")

    def voigt(w):
        return ufl.as_vector([w[0].dx(0), w[1].dx(1), w[0].dx(1) + w[1].dx(0)])

    v = ufl.TestFunction(V)
    du = ufl.TrialFunction(V)
    a_form = dolfinx.fem.form(ufl.inner(ufl.dot(tangent, voigt(du)), voigt(v)) * ufl.dx)
    r_form = dolfinx.fem.form(ufl.inner(stress, voigt(v)) * ufl.dx)
    strain_expr = dolfinx.fem.Expression(voigt(u), Q.element.interpolation_points)
    strain = dolfinx.fem.Function(Q)
    # Per-element data in DG0 dof order (one dof per cell).
    volume = dolfinx.fem.assemble_vector(dolfinx.fem.form(ufl.TestFunction(Q0) * ufl.dx)).array.copy()
    xc = dolfinx.fem.Function(Q0)
    xc.interpolate(dolfinx.fem.Expression(ufl.SpatialCoordinate(mesh)[0], Q0.element.interpolation_points))
    x_cells = xc.x.array.copy()
    weak = np.abs(x_cells - 0.5 * L) < 0.5 * h
    model = dm.damage_model(material, volume, np.where(weak, weak_factor, 1.0), kappa_c=kappa_c, regularized=False)

    fdim = mesh.topology.dim - 1
    left = dolfinx.mesh.locate_entities_boundary(mesh, fdim, lambda x: np.isclose(x[0], 0.0))
    right = dolfinx.mesh.locate_entities_boundary(mesh, fdim, lambda x: np.isclose(x[0], L))
    tip = dolfinx.fem.Constant(mesh, PETSc.ScalarType(0.0))
    bcs = []
    for facets, comp, value in ((left, 0, PETSc.ScalarType(0.0)), (right, 0, tip), (left, 1, PETSc.ScalarType(0.0)),
                                (right, 1, PETSc.ScalarType(0.0))):
        dofs = dolfinx.fem.locate_dofs_topological(V.sub(comp), fdim, facets)
        bcs.append(dolfinx.fem.dirichletbc(value, dofs, V.sub(comp)))
    n_dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs

    ksp = PETSc.KSP().create(comm)
    ksp.setOptionsPrefix(f"rkfx_crack_band_{next(_prefix_counter)}_")
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    b = dolfinx.fem.petsc.create_vector(V)
    dx = dolfinx.fem.petsc.create_vector(V)
    t_setup = time.perf_counter()

    scale = ft * h  # residual entries are forces per unit thickness
    state = dm.initial_state(model)
    history = {"u": [0.0], "force": [0.0], "cod": [0.0], "dissipated": [0.0], "elastic": [0.0]}
    profile = {"u": None, "D": np.zeros(len(volume))}
    u_profile = float(targets[-1] if u_profile is None else u_profile)
    counters = {"iterations": 0}
    accepted = {"u": np.zeros_like(u.x.array)}

    def material_at(x_array):
        u.x.array[:] = x_array
        strain.interpolate(strain_expr)
        return dm.update(model, state, strain.x.array.reshape(-1, 3), tangent=True, tangent_floor=1e-8,
                         loading_tolerance=1e-9)

    def attempt(u_target):
        tip.value = u_target
        x = accepted["u"].copy()
        for it in range(max_iterations):
            upd = material_at(x)
            stress.x.array[:] = upd.stress.ravel()
            tangent.x.array[:] = upd.tangent.ravel()
            with b.localForm() as b_local:
                b_local.set(0.0)
            dolfinx.fem.petsc.assemble_vector(b, r_form)
            dolfinx.fem.petsc.apply_lifting(b, [a_form], bcs=[bcs], x0=[u.x.petsc_vec], alpha=-1.0)
            b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            dolfinx.fem.petsc.set_bc(b, bcs, u.x.petsc_vec, -1.0)
            if it > 0 and b.norm(PETSc.NormType.NORM_INFINITY) <= rtol * scale:
                counters["iterations"] += it
                force = thickness * float(np.sum(upd.stress[:, 0] * volume)) / L
                return _Trial(u_target, force, x, upd, float(np.max(upd.state.damage - state.damage)), it)
            mat = dolfinx.fem.petsc.assemble_matrix(a_form, bcs=bcs)
            mat.assemble()
            ksp.setOperators(mat)
            ksp.solve(b, dx)
            mat.destroy()
            step = dx.array_r.copy()
            if not np.all(np.isfinite(step)):
                return None
            x = x - step
            u.x.array[:] = x
        return None

    def accept(trial):
        nonlocal state
        accepted["u"] = trial.x.copy()
        state = trial.update.state
        eps = strain.x.array.reshape(-1, 3)
        u_t = trial.u
        history["u"].append(u_t)
        history["force"].append(trial.force)
        history["cod"].append(float(np.sum(state.damage * eps[:, 0] * volume)) / h)
        history["dissipated"].append(thickness * float(state.dissipated.sum()))
        history["elastic"].append(0.5 * thickness * float(np.sum(trial.update.stress * eps * volume[:, None])))
        if profile["u"] is None and u_t >= u_profile * (1 - 1e-12):
            profile["u"], profile["D"] = u_t, state.damage.copy()

    targets = np.unique(np.r_[np.asarray(targets, float), u_profile])
    cuts = dm.march(targets, attempt, accept)["cuts"]
    ksp.destroy()
    b.destroy()
    dx.destroy()
    wall = time.perf_counter() - t_start
    u_hist, force = np.array(history["u"]), np.array(history["force"])
    return CrackBandResult(
        elements=n_el, h=h, u=u_hist, force=force, cod=np.array(history["cod"]),
        dissipated=np.array(history["dissipated"]), elastic=np.array(history["elastic"]), x=x_cells,
        damage_profile=profile["D"],
        u_profile=profile["u"] if profile["u"] is not None else float(u_hist[-1]),
        u_T_max=dm.failure_displacement(u_hist, force), n_dofs=int(n_dofs), wall_time_s=wall,
        iterations=counters["iterations"], cuts=cuts,
        timings={"setup": t_setup - t_start, "path": time.perf_counter() - t_setup})
