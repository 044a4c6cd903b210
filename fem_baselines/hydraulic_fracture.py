"""Crack-band u-p finite elements in dolfinx for hydraulic fracture: the FEM baseline of seed chapter 5.

The physics of ``rkfx.models.hydraulic_fracture`` (eqs. 5.1-5.36) on a triangular mesh, as a model
of the shared steppers: Newmark for u, the generalized trapezoid for p
(``rkfx.solvers.newmark``, eqs. 5.18-5.24) and Newton (``rkfx.solvers.newton``):

    M u'' + f_int(u) - K_C p = 0,       K_C^T u' + (S + S_fpp) p' + K_H p = 0,

with the essential conditions of ``rkfx.conditions`` (``Displacement`` and ``Pressure`` on
boundary parts, or on a ``Region`` of dofs inside the domain: the pressurized notch). Per
element e:

* damage: Mazars' equivalent strain (4.6) of the element's strain, linear softening (4.2) and
  the history kappa = max(kappa_old, eps_eq) (4.3)-(4.5), all from ``rkfx.fracture.damage``
  (``update``, the law of the particles). Crack band: kappa_c = w_c / h_e with w_c = 2 G_F / f_t
  and h_e the element's width across its crack (below), so that a straight band of failed
  elements dissipates G_F per unit length. The crack normal n_e is fixed at initiation along
  the major principal direction of the effective stress. P1 elements have one strain each;
  for Taylor-Hood P2 elements the damage is that of the element's mean strain
  (1/A_e) int_e eps dx, and the stress (1 - D_e) C eps(x) varies inside the element.
* effective stress (5.3)-(5.5): (1 - D) C eps with 1 - D kept at or above ``residual``
  (1e-6, the RKPM model's low residual strength); with ``closure`` a closed crack carries
  compression across it (``rkfx.fracture.closure``, on the element's mean strain);
* Biot coefficient and storage: ``FracturingRock.biot`` (alpha = 1 - (1 - D) K / K_s or the
  rock's constant) and ``FracturingRock.storage`` (1/Q, 5.29);
* permeability (5.8) from ``rkfx.materials.crack_flow`` through
  ``rkfx.models.hydro_damage.crack_permeability`` (the RKPM model's call): along the crack
  k_fC = w^3 / (12 mu_f L_s) (5.12) with w = D L_s max(n . eps . n, 0) (5.13), k_f0 across.

* a pre-existing fracture (``contact``, ``fracture``): the mesh is cut along it (its vertices
  the particles of ``rkfx.geometry.particles.cut_triangulation``), its faces are paired node
  to node (``fem_baselines.fracture_faces``) and carry the penalty frictional contact
  (5.38)-(5.39) of ``rkfx.fracture.contact`` and the fluid pressure, its tangent and pressure
  coupling join the Jacobian, its slip is history; the elements touching its faces carry its
  permeability (open: (5.8) with w = g_N; closed: k_f0 / 100), as the particles covering it do
  in the RKPM model. Tractions and fluxes on boundary parts are the loads of
  ``fem_baselines.poroelasticity.NaturalLoads``.

Band width. L_s = h_e = the width of the element measured along its crack normal n,
max(n . x_v) - min(n . x_v) over its vertices (equivalently its area over its mean chord along
the crack, for a triangle A_e / (L_max / 2) with L_max its longest chord parallel to the
crack). Why: a crack band of elements that each span the band (the row of cells a horizontal
crack runs through, both triangles of every cell) has exactly this width, so (i) the aperture
w = D L_s eps_nn is the opening across the band, and the band carries the cubic-law flux
w^3 / (12 mu_f) (test: ``tests/test_fem_hydraulic_fracture.py``), and (ii) kappa_c = w_c / h_e
dissipates G_F per unit crack length, with sum_e A_e / h_e over the band equal to its
length. On the notch's grid-aligned band h_e = h, the RKPM particles' L_s = V_I / A_I = h. The
chord through the centroid that ``fem_baselines.crack_band_dynamics`` uses gives 3h/4 for
these right triangles and a crack along x: a third more dissipation per unit length and a
quarter less aperture. The width enters ``rkfx.fracture.damage`` (which regularizes with
kappa_c = band_factor (G_F / f_t) A / V with A the chord through a point) through
``band_geometry``: each element's "cell" is a quarter of its difference body T - T (a hexagon
about the centroid) whose chord along any direction t is half the triangle's longest chord
along t, i.e. A_e / h_e; with ``band_factor`` 2 this gives kappa_c = w_c / h_e, and L_s =
A_e / chord = h_e is kept in ``DamageState.chord`` from initiation on.

Elements (``element``):

* ``"p1p1-fpp"``: P1 displacement and P1 pressure with the fluid pressure projection (5.30,
  as ``fem_baselines.poroelasticity`` does it, in the rate form: S_fpp = M_eps -
  C diag(eps_f / A) C^T in the capacity) with eps_f of (3.53)-(3.54) from the intact rock and
  h = sqrt(A_e), and eps_f = 0 in damaged elements (5.30): the equal-order pair of the RKPM model.
* ``"taylor-hood"``: P2 displacement, P1 pressure, no stabilization; damage of the element's
  mean strain.

Mass (``mass``): ``"lumped"`` (rho int N_i per component, the RKPM model's choice; P1 only,
the row sums of P2 vanish at vertices) or ``"consistent"`` (rho int u . v, that of
``fem_baselines.poroelasticity``), rho the mixture density.

Jacobian (``jacobian``): ``"symmetrized"`` (5.36; also named ``"symmetric"`` as in the RKPM
model): [[K_U, -K_C], [0, K_H]] with K_U the consistent tangent (5.34)-(5.35), including the
softening term -D' (C eps) (x) d eps_eq / d eps of loading elements; ``"full"`` adds
dK_H/dU P (5.33), the dependence of k_fC on the aperture through the strain and the damage of
loading elements. Both are the derivatives of the residual except for the normal of elements
initiating within the trial (it follows the stress and is not differentiated) and, where alpha
follows the damage (``FracturingRock.alpha`` is None), the dependence of K_C on D (the RKPM
model leaves it out too). The storage rows are weighted by -beta_2 dt / beta_1 (5.24).

History follows trial/commit (``rkfx.solvers.model``): every ``residual`` evaluates the damage
from the committed state; the stepper ``commit()``s once it accepts a step, so a failed Newton
iteration or a cut step never touches the committed damage, and checkpoints save it. alpha, 1/Q
and eps_f of a step's capacity are those of the committed damage (built once per step), as in
the RKPM model.

The injection set-up of ``rkfx.cases.injection`` (``solve_hydraulic_fracture``): the plate
[-L/2, L/2]^2 as a structured mesh whose vertices are the RKPM particles (the square grid of
spacing h with a row on y = 0; ``fem_baselines.poroelasticity.rectangle_mesh``, every cell
split along the same diagonal, so the mesh is symmetric under x -> -x, y -> -y like the
problem); outer edges fixed and drained; the notch as in the RKPM case: the pressure
p_bar = rate t prescribed at the vertices within 1.5 h of the notch line with |x| <= c (the
RKPM case's particles), and the elements whose three vertices are among them (|y| <= h,
|x| <= c: the band the pressurized vertices span) damaged from the start, D = 1 across
n = (0, 1) (``rkfx.models.hydraulic_fracture.initial_damage``). Rate-driven
(``injection_rate`` > 0): fluid injected at Q = injection_rate t into those elements, evenly
over their area, in place of the notch pressure (``FemHydraulicFractureModel(injection=)``;
with the implicit damage update Newton stops near the strength pressure, at 265-353 s for
h = 0.05 m with residual stiffnesses from 1e-6 to 1e-2 and at 228 s for h = 0.025 m; impl-ex
runs it through).

Time steps (``stepper``). The seed's trapezoidal rule (beta_2 = 1/4, beta_1 = 1/2, theta = 1/2,
``rkfx.solvers.newmark.trapezoidal``), Newton started from the last step's unknowns
(``guess="previous"``), the default. The steps of 50-100 s exceed the plate's elastic periods
(~1e-4 s) a million times, and there the trapezoid damps nothing: the accelerations of those
stiff modes grow by about one displacement increment per step, so the Newmark predictor
x_n + dt v_n + dt^2 a_n / 4 misses x_{n+1} by n increments (measured, elastic, h = 0.05 m:
2.6e-6 m increments, predictor off by 2.3e-5 m at step 8; the RKPM model shows the same,
3.5e-6 and 3.1e-5 m). From it the strains overshoot kappa0 many times over, and Newton finds
its way back through hundreds of trial damage states; from x_n it does not. The step's solution
is the same. Measured, injection to 2000 s, full Jacobian, h = 0.05 m, steps of 50 s: predictor
15,364 Newton iterations, 77 cuts, 136 s; last step 280 iterations, 2.8 s; h = 0.025 m, steps of
100 s: predictor 7,476 iterations, 62 cuts, 188 s; last step 300 iterations, 8.1 s, the same
crack (0.75 m at 2000 s). The damped Newmark of ``rkfx.solvers.newmark.damped`` (gamma = 0.6,
beta = 0.3025, theta = 0.6) also avoids the drift (293 and 484 iterations) but integrates with an
O(dt) lag of (gamma - 1/2) dt in the rates: at h = 0.05 m its crack is 0.70 m at 2000 s against
the trapezoid's 0.60 m.

Tracking (``track``). By default any element may damage, as in the chapter-4 crack-band
baselines: the band localizes into one row of elements along the notch line (one row above
y = 0 on one wing, below on the other: the diagonal split is symmetric under x, y -> -x, -y).
The tracking of the RKPM case (4.22, ``rkfx.fracture.tracking`` over the element centroids,
spacing sqrt(2 A_e), seeded by the notch) is an option; it does not narrow the band further
here and costs Newton iterations: its admissions persist over a step's iterates, and the
trial states of the first iterates admit elements all round the tips (h = 0.05 m, damped: 502
iterations and 17 cuts against 293 and 11; h = 0.025 m: the same tips at every step to 2250 s;
with the trapezoid's predictor every element of the plate was admitted within the first
iterate).

Measured on the injection set-up (the default: trapezoidal steps of 50 s, Newton from the last
step, full Jacobian; cracked: w / w_c >= 0.5; one thread):

| h [m] | dofs | onset t [s], p_bar [Pa] | length at 2000/2250 s [m] | stops at | Newton, median/step | wall |
|---|---|---|---|---|---|---|
| 0.025 | 5,043 | 1600, 8.8e7 | 0.75 / 0.85 | 2450 s | 387, 6 | 13 s |
| 0.01 | 30,603 | 1450, 8.0e7 | 0.76 / 0.88 | 2288 s | 414, 8 | 126 s |

The RKPM case (docs/hydraulic_fracture.md): onset 1900 s at h = 0.025 m and 1750 s at
0.01 m; at 0.01 m the crack is 0.31 / 0.49 / 0.65 m long at 2000 / 2250 / 2500 s. The crack
band starts earlier and runs about twice as fast. The likely reason (not isolated by a run):
a row of P1 elements with D -> 1 opens as freely as a slit, so the crack's aperture, its
cubic-law conductivity and the fluid pressure carried to its tips (p ~ p_bar along the
crack) are those of a discrete fracture, while the RK field, smooth over supports of 1.5 h,
lets a crack one or two particles wide open only partly (the Sneddon case's one-row band:
5.2, 2.7, 1.4 % of the slit's opening at h = 0.111, 0.053, 0.026 m). Both stop when the
damage ahead of the tips meets the fixed, drained edges. The symmetrized Jacobian (5.36), which
leaves out the dependence of the notch band's conductivity (w^3) on its opening, stops before
the onset with these steps (h = 0.025 m: at 794 s); with the damped steps it reached 2261 s
(0.025 m) and 1835 s (0.01 m), at 2-3 times the full Jacobian's iterations.

Parallelism: the mesh and the assembly are distributed by dolfinx; the matrices are gathered
into scipy on every rank (as ``fem_baselines.poroelasticity.FemBiotModel``), the damage state
of every element is held on every rank, and the linear solves go through MUMPS on the mesh's
communicator.

Units: SI (m, s, kg, Pa); forces and fluxes per unit thickness.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import numpy as np
import scipy.sparse as sp
from mpi4py import MPI

import dolfinx
import dolfinx.fem
import dolfinx.mesh
import ufl

from fem_baselines.conditions import BoundaryParts, check_kinds
from fem_baselines.elasticity import strain, stress_law
from fem_baselines.fracture_faces import FractureFaces, nodal_interface, touching
from fem_baselines.poroelasticity import (NaturalLoads, _gather, _global_matrix, _global_vector, _in_order, _Sampler,
                                          rectangle_mesh)
from rkfx.conditions import Condition, Displacement, Flux, Pressure, Region, Traction, values
from rkfx.errors import InputError, SolverError
from rkfx.fracture import damage as dm
from rkfx.fracture.closure import CrackClosure, direction
from rkfx.fracture.contact import FractureContact, FrictionalContact
from rkfx.fracture.history import DamageHistory
from rkfx.fracture.tracking import tracking
from rkfx.linalg.linear_solver import Factorizations
from rkfx.materials import crack_flow
from rkfx.models.hydraulic_fracture import FracturingRock, initial_damage
from rkfx.models.hydro_damage import RESIDUAL_STIFFNESS, CrackBands, crack_permeability
from rkfx.models.poroelasticity import fpp_parameter
from rkfx.solvers.fields import Field, FieldLayout
from rkfx.solvers.integrate import integrate
from rkfx.solvers.model import Constraints, PerStepSize
from rkfx.solvers.newmark import Newmark, StepState, trapezoidal
from rkfx.solvers.newton import NewtonOptions

__all__ = [
    "CRACKED",
    "ELEMENTS",
    "FemHydraulicFractureModel",
    "FemInjectionResult",
    "JACOBIANS",
    "MASSES",
    "band_geometry",
    "solve_hydraulic_fracture",
]

ELEMENTS = ("p1p1-fpp", "taylor-hood")
MASSES = ("lumped", "consistent")
JACOBIANS = ("symmetrized", "symmetric", "full")  # the first two are one Jacobian (5.36)
CRACKED = 0.5  # w / w_c from which an element counts as cracked (as the RKPM case)
_MUMPS_ICNTL = {7: 2}  # AMF ordering, as the Biot baseline's 2-D runs


# --------------------------------------------------------------------------- band geometry


def band_geometry(vertices: np.ndarray) -> dm.CellGeometry:
    """Each triangle's regularization cell: a quarter of its difference body T - T about its centroid.

    ``rkfx.fracture.damage.chord_lengths`` measures the chord of a point's cell through the point
    perpendicular to the crack normal n. The difference body of a triangle is the hexagon with
    vertices +-(a - b), +-(b - c), +-(c - a); its radius along t is the triangle's longest chord
    L_max(t) parallel to t, so a quarter of it has the chord L_max / 2 = A_e / h_e(n) through its
    centre, h_e(n) the triangle's width along n. Hence kappa_c = 2 (G_F / f_t) chord / A_e =
    w_c / h_e (``band_factor`` 2) and L_s = A_e / chord = h_e (module docstring).

    Args:
        vertices: Triangle vertices, shape ``(m, 3, 2)`` [m].

    Returns:
        Six subcells (centre, hexagon vertex k, edge midpoint, hexagon vertex k + 1) per
        triangle, counter-clockwise; node e of element e.
    """
    v = np.asarray(vertices, float)
    if v.ndim != 3 or v.shape[1:] != (3, 2):
        raise InputError(f"triangle vertices have shape {v.shape}; give (m, 3, 2)")
    a, b, c = v[:, 0], v[:, 1], v[:, 2]
    d = np.stack([a - b, b - c, c - a, b - a, c - b, a - c], axis=1) / 4.0  # (m, 6, 2)
    order = np.argsort(np.arctan2(d[..., 1], d[..., 0]), axis=1)
    d = np.take_along_axis(d, order[..., None], axis=1)
    nxt = np.roll(d, -1, axis=1)
    g = np.broadcast_to(v.mean(axis=1)[:, None, :], d.shape)
    quads = np.stack([g, g + d, g + 0.5 * (d + nxt), g + nxt], axis=2)  # (m, 6, 4, 2)
    return dm.CellGeometry(np.repeat(np.arange(len(v)), 6), quads.reshape(-1, 4, 2), len(v))


def _widths(vertices: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Width of each triangle along its unit normal, shape ``(m,)`` [m]."""
    s = np.einsum("mvk,mk->mv", vertices, normal)
    return s.max(axis=1) - s.min(axis=1)


def _unit(normal: np.ndarray) -> np.ndarray:
    """Normals with zero rows (elements that never initiated) replaced by (0, 1): unused where D = 0."""
    n = np.array(normal, float)
    n[np.hypot(n[:, 0], n[:, 1]) == 0] = (0.0, 1.0)
    return n


# --------------------------------------------------------------------------- the model


class FemHydraulicFractureModel(DamageHistory):
    """The chapter-5 crack-band u-p model (module docstring) for the steppers of ``rkfx.solvers``.

    Unknowns ``[u, p]`` in dolfinx's global numbering, the same on every rank: u interleaved per
    node of V (time order 2), then p per node of Q (order 1).

    Args:
        mesh: A 2-D dolfinx mesh of triangles (e.g. ``rectangle_mesh``).
        rock: The material (``FracturingRock``).
        conditions: ``Displacement`` and ``Pressure`` of ``rkfx.conditions`` on boundary parts
            (names, tags or markers as ``fem_baselines.conditions``) or on a ``Region``: every
            dof whose point the region's marker accepts (a notch inside the domain); ``Traction``
            (total stress) and ``Flux`` on boundary parts.
        precracked: Elements damaged from the start (D = 1): those whose three vertices the
            region's marker accepts; ``None``: none.
        precrack_normal: Their crack normal (unit).
        element: ``"p1p1-fpp"`` or ``"taylor-hood"``.
        mass: ``"lumped"`` (P1 only) or ``"consistent"``.
        jacobian: ``"symmetrized"`` (= ``"symmetric"``, 5.36) or ``"full"`` (5.33).
        residual: Least stiffness fraction 1 - D, in (0, 1).
        track: ``(tol, radius)`` of the crack tracking (4.22) over the element centroids
            (``rkfx.fracture.tracking``, spacing sqrt(2 A_e), the grid spacing of the
            structured mesh), seeded by the pre-cracked elements, as the RKPM model tracks its
            particles; ``None``: every element may damage (see the module docstring).
        damage_update: ``"implicit"`` or ``"impl-ex"`` (``rkfx.fracture.history``), as the
            RKPM model.
        injection: ``(region, rate)``: fluid injected at ``rate(t)`` [m^2/s per metre of
            thickness] into the elements whose three vertices the region's marker accepts,
            spread evenly over their area (the RKPM model's ``injection``, shared by volume).
        contact, fracture: A pre-existing fracture (P1 only): the frictional contact law
            (5.38)-(5.39) of ``rkfx.fracture.contact`` on the vertex pairs of a mesh cut along it
            (``fem_baselines.fracture_faces``); the elements with a vertex on its faces carry its
            flow (open: (5.8) with w = g_N; closed: k_f0 / 100), as the RKPM model's particles
            covering it do. ``None``: no such fracture.
        closure: A closed crack carries compression across it (``rkfx.fracture.closure``, on the
            element's mean strain), as the RKPM model's ``closure``.

    Attributes:
        committed: The committed ``rkfx.fracture.damage.DamageState`` of the elements (element
            e = global DG0 dof e).
        trial: The ``DamageUpdate`` of the last ``residual`` call.
        iterations: Newton iterations of every committed step.
        points: The damage points (``DamageModel``): volumes = element areas.
        vertices: Vertices of every element, shape ``(m, 3, 2)`` [m]; ``area`` ``(m,)`` [m^2].
        precracked: Pre-cracked elements, shape ``(m,)`` bool.
        u_nodes, p_nodes: Coordinates of the nodes of V and Q in global order, shapes
            ``(n_u / 2, 2)`` and ``(n_p, 2)`` [m].
        fracture: The pre-existing fracture's ``FractureContact`` (or ``None``).
    """

    linear = False

    def __init__(self, mesh: dolfinx.mesh.Mesh, rock: FracturingRock, conditions: Sequence[Condition], *,
                 precracked: Region | None = None, precrack_normal: Sequence[float] = (0.0, 1.0),
                 element: str = "p1p1-fpp", mass: str = "lumped", jacobian: str = "full",
                 residual: float = RESIDUAL_STIFFNESS, track: tuple[float, float] | None = None,
                 damage_update: str = "implicit",
                 injection: tuple[Region, Callable[[float], float]] | None = None,
                 contact: FrictionalContact | None = None, fracture: FractureFaces | None = None,
                 closure: bool = False):
        if not isinstance(rock, FracturingRock):
            raise InputError(f"rock = {rock!r}: give a rkfx.models.hydraulic_fracture.FracturingRock")
        if element not in ELEMENTS:
            raise InputError(f"element = {element!r}; choose one of {', '.join(ELEMENTS)}")
        if mass not in MASSES:
            raise InputError(f"mass = {mass!r}; choose one of {', '.join(MASSES)}")
        if mass == "lumped" and element != "p1p1-fpp":
            raise InputError("mass = 'lumped' needs P1 displacements (the row sums of P2 vanish at the vertices); "
                             "use mass='consistent' with element='taylor-hood'")
        if jacobian not in JACOBIANS:
            raise InputError(f"jacobian = {jacobian!r}; choose one of {', '.join(JACOBIANS)}")
        self.use_damage_update(damage_update)
        if not 0.0 < residual < 1.0:
            raise InputError(f"residual = {residual!r}: the least stiffness fraction 1 - D must lie in (0, 1)")
        if mesh.geometry.dim != 2 or mesh.topology.cell_type != dolfinx.mesh.CellType.triangle:
            raise InputError("the crack-band u-p baseline needs a 2-D mesh of triangles; mesh the plate with "
                             "fem_baselines.poroelasticity.rectangle_mesh(xs, ys, 'triangle')")
        kinds = check_kinds(conditions, (Displacement, Pressure, Traction, Flux), "the crack-band u-p FEM")
        if (contact is None) != (fracture is None):
            raise InputError("a pre-existing fracture needs both contact= (the law) and fracture= (its faces)")
        if contact is not None and element != "p1p1-fpp":
            raise InputError(f"element = {element!r}: the pre-existing fracture's node-to-node contact needs P1 "
                             "displacements; use element='p1p1-fpp'")
        if not kinds[Displacement]:
            raise InputError("no Displacement condition: the rigid motions are free; fix a part of the boundary")
        self.comm, self.rock, self.element, self.mass_kind = mesh.comm, rock, element, mass
        self.jacobian = "full" if jacobian == "full" else "symmetrized"
        self.residual_fraction = float(residual)
        self.closure = CrackClosure.for_material(rock.damage_material.elasticity()) if closure else None
        self.mesh = mesh
        tdim = mesh.topology.dim
        mesh.topology.create_connectivity(tdim - 1, tdim)
        degree = 2 if element == "taylor-hood" else 1
        self.V = dolfinx.fem.functionspace(mesh, ("Lagrange", degree, (2,)))
        self.Q = dolfinx.fem.functionspace(mesh, ("Lagrange", 1))
        self.E0 = dolfinx.fem.functionspace(mesh, ("DG", 0))  # one dof per element: the element's number
        v_map, q_map, e_map = self.V.dofmap.index_map, self.Q.dofmap.index_map, self.E0.dofmap.index_map
        v_nodes = v_map.local_to_global(np.arange(v_map.size_local + v_map.num_ghosts, dtype=np.int32))
        self.n_u, self.n_p, self.m = 2 * v_map.size_global, q_map.size_global, e_map.size_global
        self.u_index = (2 * v_nodes[:, None] + np.arange(2)).ravel()
        self.p_index = self.n_u + q_map.local_to_global(np.arange(q_map.size_local + q_map.num_ghosts, dtype=np.int32))
        self._e_index = e_map.local_to_global(np.arange(e_map.size_local + e_map.num_ghosts, dtype=np.int32))
        self.layout = FieldLayout((Field("u", 2, 2, v_map.size_global), Field("p", 1, 1, q_map.size_global)))
        self.n_dofs = self.n_u + self.n_p
        self.u_nodes = _gather(self.comm, self.V.tabulate_dof_coordinates()[:v_map.size_local, :2])
        self.p_nodes = _gather(self.comm, self.Q.tabulate_dof_coordinates()[:q_map.size_local, :2])
        self._element_data(mesh)
        self._forms(mesh)
        self.points = dm.damage_model(rock.damage_material, self.area, geometry=band_geometry(self.vertices),
                                      band_factor=2.0)
        self.precracked = np.zeros(self.m, bool) if precracked is None else self._elements_in(precracked, "precracked")
        self._injection = None
        if injection is not None:
            region, rate = injection
            inside = self._elements_in(region, "injection")
            share = np.where(inside, 1.0 / self.area[inside].sum(), 0.0)  # per unit area, of a unit volume
            self._injection = (self._ct.T @ share, rate)  # int_e N_I s dx per unit injected volume
        self.committed = initial_damage(self.points, np.flatnonzero(self.precracked), precrack_normal)
        self.trial: dm.DamageUpdate | None = None
        self.track, self.allowed, self.parent = None, None, np.full(self.m, -1, np.int64)
        self._trial_tracking: tuple[np.ndarray, np.ndarray] | None = None
        if track is not None:
            try:
                tol, radius = (float(v) for v in track)
            except (TypeError, ValueError):
                raise InputError(f"track = {track!r}: give (tol, radius), e.g. (0.3, 3.5), or None") from None
            self.track = tracking(self.centroids, np.sqrt(2.0 * self.area), tol, seeds=self.precracked, radius=radius)
            self.allowed = self.precracked | self.committed.damaged
            self._admit(np.flatnonzero(self.committed.damaged), self.committed.normal, self.allowed, self.parent)
        self.strain = np.zeros((self.m, 3))
        self.boundary = BoundaryParts(mesh)
        self._essential(mesh, kinds[Displacement] + kinds[Pressure])
        self._natural = NaturalLoads(mesh, self.boundary, self.V, self.Q, kinds[Traction], kinds[Flux]) \
            if kinds[Traction] or kinds[Flux] else None
        self._loads_at: tuple[float, np.ndarray] | None = None
        self._no_loads = np.zeros(self.n_dofs)
        if contact is not None:
            self.fracture = FractureContact(nodal_interface(fracture, self.u_nodes, self.p_nodes), contact,
                                            self.centroids, self.area, carriers=touching(fracture, self.vertices))
        self._mass = self._assemble_mass()
        self._per_step = PerStepSize(keep=2)
        self._capacity: tuple[float, dm.DamageState, sp.csr_matrix] | None = None
        self._constraints: tuple[float, Constraints] | None = None
        self.iterations: list[int] = []
        self._count = 0

    # ------------------------------------------------------------------ set-up

    def _elements_in(self, region: Region, what: str) -> np.ndarray:
        """The elements whose three vertices ``region``'s marker accepts, shape ``(m,)`` bool."""
        if not isinstance(region, Region):
            raise InputError(f"{what} = {region!r}: give a rkfx.conditions.Region (the elements whose three "
                             "vertices it holds)")
        inside = np.asarray(region.marker(self.vertices.reshape(-1, 2)), bool)
        if inside.shape != (3 * self.m,):
            raise InputError(f"region {region.name!r}: its marker returned shape {inside.shape} for "
                             f"{3 * self.m} points; return a bool array (m,)")
        inside = inside.reshape(-1, 3).all(axis=1)
        if not inside.any():
            raise InputError(f"region {region.name!r} holds no element's three vertices; widen it to span "
                             "at least one element")
        return inside

    def _element_data(self, mesh: dolfinx.mesh.Mesh) -> None:
        """Areas, vertices and the mean-strain rows of every element, in element order on every rank."""
        comm, E0 = self.comm, self.E0
        mu = ufl.TestFunction(E0)
        self.area = _global_vector(dolfinx.fem.form(mu * ufl.dx(domain=mesh)), comm)
        owned = E0.dofmap.index_map.size_local
        cells = mesh.topology.index_map(mesh.topology.dim).size_local
        dof = np.asarray(E0.dofmap.list, np.int64)[:, 0]
        if cells != owned or np.any(dof[:cells] >= owned):
            raise RuntimeError("DG0 dofs of owned cells are not owned; the element numbering assumes they are")
        local = np.empty((owned, 3, 2))
        local[dof[:cells]] = mesh.geometry.x[np.asarray(mesh.geometry.dofmaps[0])[:cells], :2]
        self.vertices = _gather(comm, local.reshape(owned, 6)).reshape(-1, 3, 2)
        self.centroids = self.vertices.mean(axis=1)
        # Mean strains (eps_xx, eps_yy, gamma_xy) of each element: (1/A_e) int_e eps(u) dx.
        u = ufl.TrialFunction(self.V)
        g = ufl.grad(u)
        rows = (g[0, 0], g[1, 1], g[0, 1] + g[1, 0])
        inv = sp.diags(1.0 / self.area)
        self._B = [sp.csr_matrix(inv @ _global_matrix(dolfinx.fem.form(mu * r * ufl.dx), comm)) for r in rows]

    def _forms(self, mesh: dolfinx.mesh.Mesh) -> None:
        """The forms assembled during the run, with their per-element coefficients (DG0 Functions)."""
        def dg0(name):
            return dolfinx.fem.Function(self.E0, name=name)

        self._frac, self._alpha, self._storage, self._eps_f = dg0("1-D"), dg0("alpha"), dg0("1/Q"), dg0("eps_f")
        self._k = [dg0(f"k_{ij}") for ij in ("xx", "xy", "yy")]
        self._t = [dg0("t_x"), dg0("t_y")]
        self._uh = dolfinx.fem.Function(self.V, name="u")
        self._ph = dolfinx.fem.Function(self.Q, name="p")
        sigma = stress_law(mesh, self.rock.damage_material.elastic)  # C of the plane-strain rock (5.5)
        u, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        p, q = ufl.TrialFunction(self.Q), ufl.TestFunction(self.Q)
        lam, mu = ufl.TrialFunction(self.E0), ufl.TestFunction(self.E0)
        dx = ufl.dx(domain=mesh)
        k = ufl.as_matrix([[self._k[0], self._k[1]], [self._k[1], self._k[2]]])
        t = ufl.as_vector(self._t)
        form = dolfinx.fem.form
        self._a_ku = form(self._frac * ufl.inner(sigma(u), strain(v)) * dx)        # (5.34) at 1 - D
        self._a_force = form(lam * ufl.inner(sigma(self._uh), strain(v)) * dx)    # int_e eps(v) : C eps(u_h)
        self._a_kc = form(self._alpha * p * ufl.div(v) * dx)                      # (5.27)
        self._a_kh = form(ufl.inner(k * ufl.grad(p), ufl.grad(q)) * dx)           # (5.28)
        self._a_flow = form(lam * ufl.dot(t, ufl.grad(self._ph)) * ufl.dot(t, ufl.grad(q)) * dx)
        self._a_ks = form(self._storage * p * q * dx)                             # (5.29)
        self._a_meps = form(self._eps_f * p * q * dx)                             # (5.30)
        self._ct = _global_matrix(form(p * mu * dx), self.comm)                   # (cells, p): int_e N
        self._kc_constant = None
        if self.rock.alpha is not None:  # a constant alpha: K_C once
            self._set(self._alpha, np.full(self.m, self.rock.alpha))
            self._kc_constant = _global_matrix(self._a_kc, self.comm)

    def _assemble_mass(self) -> sp.csr_matrix:
        rho = dolfinx.fem.Constant(self.mesh, dolfinx.default_scalar_type(self.rock.density))
        v = ufl.TestFunction(self.V)
        dx = ufl.dx(domain=self.mesh)
        if self.mass_kind == "lumped":  # rho int N_i per component (row sums of the consistent mass)
            lumped = _global_vector(dolfinx.fem.form(rho * ufl.inner(ufl.as_vector((1.0, 1.0)), v) * dx), self.comm)
            muu = sp.diags(lumped, format="csr")
        else:
            u = ufl.TrialFunction(self.V)
            muu = _global_matrix(dolfinx.fem.form(rho * ufl.inner(u, v) * dx), self.comm)
        return sp.bmat([[muu, None], [None, sp.csr_matrix((self.n_p, self.n_p))]], format="csr")

    def _essential(self, mesh: dolfinx.mesh.Mesh, essential: Sequence[Displacement | Pressure]) -> None:
        """Unit rows G on the owned dofs of each condition (the last condition on a dof wins)."""
        fdim = mesh.topology.dim - 1
        v_owned, q_owned = 2 * self.V.dofmap.index_map.size_local, self.Q.dofmap.index_map.size_local
        v_points, q_points = self.V.tabulate_dof_coordinates()[:, :2], self.Q.tabulate_dof_coordinates()[:, :2]
        self._dirichlet = []  # (condition, points (k, 2), global rows (k,), value column (k,))
        for bc in essential:
            vector = isinstance(bc, Displacement)
            comps = bc.prescribed(2) if vector else (0,)
            if isinstance(bc.boundary, Region):
                pts = v_points[: v_owned // 2] if vector else q_points[:q_owned]
                inside = np.asarray(bc.boundary.marker(pts), bool) if len(pts) else np.zeros(0, bool)
                if inside.shape != (len(pts),):
                    raise InputError(f"region {bc.boundary.name!r}: its marker returned shape {inside.shape} for "
                                     f"{len(pts)} points; return a bool array (m,)")
                if self.comm.allreduce(int(inside.sum()), op=MPI.SUM) == 0:
                    raise InputError(f"region {bc.boundary.name!r} holds no {'displacement' if vector else 'pressure'}"
                                     " dof; widen its marker")
                nodes = np.flatnonzero(inside)
                per = [2 * nodes + c for c in comps] if vector else [nodes]
            else:
                facets = self.boundary.facets(bc.boundary)
                if vector:
                    per = [dolfinx.fem.locate_dofs_topological(self.V.sub(c), fdim, facets) for c in comps]
                    per = [d[d < v_owned] for d in per]
                else:
                    d = dolfinx.fem.locate_dofs_topological(self.Q, fdim, facets)
                    per = [d[d < q_owned]]
            column = np.concatenate([np.full(d.size, j) for j, d in enumerate(per)]).astype(np.int64)
            dofs = np.concatenate(per).astype(np.int64)
            if vector:
                self._dirichlet.append((bc, v_points[dofs // 2], self.u_index[dofs], column))
            else:
                self._dirichlet.append((bc, q_points[dofs], self.p_index[dofs], column))
        rows = _in_order(self.comm, [r for _, _, r, _ in self._dirichlet]).astype(np.int64)
        self._bc_rows, last = np.unique(rows[::-1], return_index=True)
        self._bc_last = len(rows) - 1 - last
        k = len(self._bc_rows)
        self._G = sp.csr_matrix((np.ones(k), (np.arange(k), self._bc_rows)), shape=(k, self.n_dofs))

    # ------------------------------------------------------------------ helpers

    def _set(self, fn: dolfinx.fem.Function, per_element: np.ndarray) -> None:
        """A DG0 Function from values of every element (element order), ghosts included."""
        fn.x.array[:] = per_element[self._e_index]

    def assign(self, x: np.ndarray) -> tuple[dolfinx.fem.Function, dolfinx.fem.Function]:
        """(u_h, p_h) of the unknowns ``x`` (ghosts included); the model's own Functions."""
        self._uh.x.array[:] = x[self.u_index]
        self._ph.x.array[:] = x[self.p_index]
        return self._uh, self._ph

    def element_strains(self, u: np.ndarray) -> np.ndarray:
        """Mean strains (eps_xx, eps_yy, gamma_xy) of every element, shape ``(m, 3)`` [-]."""
        return np.column_stack([b @ u for b in self._B])

    def _rows(self, coefficients: np.ndarray, on: np.ndarray) -> sp.csr_matrix:
        """Rows c_e . eps_e(du) of the elements ``on`` over the displacements, shape ``(len(on), n_u)``."""
        out = None
        for k, b in enumerate(self._B):
            term = sp.diags(coefficients[:, k]) @ b[on]
            out = term if out is None else out + term
        return out.tocsr()

    def band_widths(self, state: dm.DamageState) -> np.ndarray:
        """L_s = A_e / chord = h_e of the damaged elements (1 elsewhere, unused), shape ``(m,)`` [m]."""
        w = np.ones(self.m)
        on = np.flatnonzero(state.damaged)
        w[on] = self.area[on] / state.chord[on]
        return w

    def permeability(self, state: dm.DamageState, eps: np.ndarray) -> np.ndarray:
        """k_f (5.8) of every element, shape ``(m, 2, 2)`` [m^2/(Pa s)]: the crack bands' and, at
        the elements next to a pre-existing fracture, the fracture's at the last residual."""
        k = crack_permeability(self.rock.mobility, state.damage, CrackBands(_unit(state.normal),
                               self.band_widths(state)), eps, self.rock.viscosity)
        if self.fracture is not None:
            self.fracture.added_permeability(k, self.rock.mobility, self.rock.viscosity)
        return k

    def element_pressures(self, x: np.ndarray) -> np.ndarray:
        """The mean pressure of every element for the unknowns ``x`` [Pa], shape ``(m,)``."""
        return (self._ct @ x[self.n_u:]) / self.area

    def loads(self, t: float) -> np.ndarray:
        """[F(t), Q(t)] of the tractions and fluxes (zero without them), shape ``(n_dofs,)``."""
        if self._natural is None:
            return self._no_loads
        if self._loads_at is None or (self._loads_at[0] != t and self._natural.varies):
            self._loads_at = (t, self._natural.assemble(t, self.n_u, self.n_dofs))
        return self._loads_at[1]

    # ------------------------------------------------------------------ model protocol

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        u, P = x[:self.n_u], x[self.n_u:]
        eps = self.element_strains(u)
        self.strain = eps
        self.trial = upd = self._damage(eps)
        st = upd.state
        self._set(self._frac, self.stiffness_fraction(st.damage))
        self._ku = _global_matrix(self._a_ku, self.comm)  # (1 - D) C, so f_int = K_D u (5.25)
        if self._kc_constant is None:
            self._set(self._alpha, self.rock.biot(st.damage))
            self._kc = _global_matrix(self._a_kc, self.comm)
        else:
            self._kc = self._kc_constant
        self._x = x
        f_u = self._ku @ u - self._kc @ P
        if self.closure is not None:  # int_e sigma_c : eps(v) with the element's mean strain
            s_c = self.closure.stress(eps, _unit(st.normal), 1.0 - self.stiffness_fraction(st.damage))
            f_u = f_u + sum(b.T @ (self.area * s_c[:, k]) for k, b in enumerate(self._B))
        if self.fracture is not None:
            f_u = f_u + self.fracture.forces(u, P)  # before the permeability: it reads the apertures
        k = self.permeability(st, eps)
        for fn, (i, j) in zip(self._k, ((0, 0), (0, 1), (1, 1))):
            self._set(fn, k[:, i, j])
        self._kh = _global_matrix(self._a_kh, self.comm)
        q_ext = 0.0 if self._injection is None else float(self._injection[1](t)) * self._injection[0]
        return np.r_[f_u, self._kh @ P - q_ext] - self.loads(t)

    def _damage(self, eps: np.ndarray) -> dm.DamageUpdate:
        """The damage of the elements' strains ``eps``: the trial from the committed state with
        the tracking admissions of the RKPM model, or the step's impl-ex extrapolation
        (``rkfx.fracture.history.DamageHistory.step_damage``)."""
        return self.step_damage(eps, tangent=False)

    def _loading(self) -> tuple[np.ndarray, np.ndarray]:
        """Elements softening in the trial (kappa grew, 1 - D above the residual) and their
        dD/d eps (slope (4.2) times d eps_eq / d eps (4.6)), shape ``(k,)`` and ``(k, 3)``."""
        st, old = self.trial.state, self.committed
        on = np.flatnonzero((st.kappa > old.kappa) & (1.0 - st.damage > self.residual_fraction))
        slope = dm.damage_slope(st.kappa[on], self.points.kappa0[on], st.kappa_c[on])
        keep = slope > 0
        on, slope = on[keep], slope[keep]
        mat = self.rock.damage_material
        grad = dm.equivalent_strain_gradient(self.strain[on], mat.nu, mat.plane)
        return on, slope[:, None] * grad

    def tangent(self, x: np.ndarray, t: float) -> sp.csr_matrix:
        """The Jacobian's blocks [[K_U, -K_C], [dK_H/dU P or 0, K_H]] at the last residual."""
        self._count += 1
        k_u = self._ku
        on, dd = self._loading()
        if on.size:  # -D' (C eps) (x) d eps_eq / d eps (5.35), element by element
            self.assign(self._x)
            force = _global_matrix(self._a_force, self.comm).tocsc()[:, on]
            k_u = (k_u - force @ self._rows(dd, on)).tocsr()
        if self.closure is not None:
            k_u = k_u + self._closure_stiffness()
        k_up = -self._kc
        if self.fracture is not None:
            k_u, k_up = k_u + self.fracture.stiffness(), k_up + self.fracture.pressure_coupling()
        k_pu = self._flow_derivative(on, dd) if self.jacobian == "full" else None
        return sp.bmat([[k_u, k_up], [k_pu, self._kh]], format="csr")

    def _closure_stiffness(self) -> sp.csr_matrix:
        """sum_e A_e D M H(-eps_nn) (v . eps_e(du)) (v . eps_e(dv)) at the last residual."""
        st = self.trial.state
        normal = _unit(st.normal)
        c = self.closure.normal_stiffness(self.strain, normal, 1.0 - self.stiffness_fraction(st.damage))
        on = np.flatnonzero(c)
        if on.size == 0:
            return sp.csr_matrix((self.n_u, self.n_u))
        rows = self._rows(direction(normal[on]), on)
        return (rows.T @ sp.diags(self.area[on] * c[on]) @ rows).tocsr()

    def _flow_derivative(self, loading: np.ndarray, dd: np.ndarray) -> sp.csr_matrix | None:
        """d(K_H P)/dU (5.33) at the last residual, shape ``(n_p, n_u)``, or ``None`` where no
        crack conducts beyond the intact rock.

        Along t of an element, k = k_f0 + (k_fC - k_f0) t t where k_fC > k_f0, with
        dk_fC/deps = w^2 / (4 mu_f L_s) dw/deps and dw/deps = L_s (D n n + (n . eps . n) dD/deps).
        """
        st, eps = self.trial.state, self.strain
        normal, ls = _unit(st.normal), self.band_widths(st)
        w = crack_flow.crack_aperture(st.damage, ls, normal, eps)
        kfc = crack_flow.fracture_permeability(w, ls, self.rock.viscosity)
        on = np.flatnonzero(kfc > self.rock.mobility)
        if on.size == 0:
            return None
        n = normal[on]
        dwde = (st.damage[on] * ls[on])[:, None] * np.column_stack([n[:, 0] ** 2, n[:, 1] ** 2, n[:, 0] * n[:, 1]])
        slot = np.full(self.m, -1)
        slot[loading] = np.arange(len(loading))
        soft = slot[on] >= 0
        if soft.any():
            j = on[soft]
            dwde[soft] += (ls[j] * crack_flow.normal_strain(eps[j], normal[j]))[:, None] * dd[slot[j]]
        factor = w[on] ** 2 / (4.0 * self.rock.viscosity * ls[on])
        self._set(self._t[0], -normal[:, 1])
        self._set(self._t[1], normal[:, 0])
        self.assign(self._x)
        flow = _global_matrix(self._a_flow, self.comm).tocsc()[:, on]  # int_e (t . grad q)(t . grad p_h)
        return (flow @ self._rows(factor[:, None] * dwde, on)).tocsr()

    def mass(self) -> sp.csr_matrix:
        return self._mass

    def capacity(self, dt: float) -> sp.csr_matrix:
        """[[0, 0], [K_C^T, S + S_fpp(dt)]] of the committed damage (built once per step)."""
        if self._capacity is not None and self._capacity[0] == dt and self._capacity[1] is self.committed:
            return self._capacity[2]
        st = self.committed
        alpha = self.rock.biot(st.damage)
        if self._kc_constant is None:
            self._set(self._alpha, alpha)
            kc = _global_matrix(self._a_kc, self.comm)
        else:
            kc = self._kc_constant
        self._set(self._storage, self.rock.storage(alpha))
        storage = _global_matrix(self._a_ks, self.comm)
        if self.element == "p1p1-fpp":
            eps_f = fpp_parameter(self.rock.intact(), dt, np.sqrt(self.area))  # (3.53)-(3.54), h = sqrt(A_e)
            eps_f[st.damaged] = 0.0  # no projection where the crack conducts (5.30)
            self._set(self._eps_f, eps_f)
            storage = storage + _global_matrix(self._a_meps, self.comm) \
                - self._ct.T @ sp.diags(eps_f / self.area) @ self._ct
        cap = sp.bmat([[sp.csr_matrix((self.n_u, self.n_u)), None], [kc.T, storage]], format="csr")
        self._capacity = (dt, st, cap)
        return cap

    def constraints(self, t: float) -> Constraints:
        if self._constraints is None or self._constraints[0] != t:
            vals = [values(bc, x, t)[np.arange(len(x)), column] for bc, x, _, column in self._dirichlet]
            self._constraints = (t, Constraints(self._G, _in_order(self.comm, vals)[self._bc_last]))
        return self._constraints[1]

    def equation_weights(self, co) -> np.ndarray:
        """-beta_2 dt / beta_1 = -1 / (dp'/dp) on the storage rows, as in (5.24)."""
        return self._per_step.get("W", co.dt, lambda dt: np.r_[np.ones(self.n_u), np.full(self.n_p, -1.0 / co.dv[-1])])

    # commit, state and restore: rkfx.fracture.history.DamageHistory


# --------------------------------------------------------------------------- the injection set-up


@dataclass
class FemInjectionResult:
    """A crack-band FEM run of the injection set-up (``solve_hydraulic_fracture``).

    Per recorded step (every step of ``times`` after the first), arrays of shape ``(k,)``:
    ``t`` [s], ``notch_p`` (p at the notch's centre [Pa]), ``left``/``right`` (the crack's tips:
    the outermost x of the cracked elements, w / w_c >= 0.5, the notch included [m]), ``cracked``
    (cracked elements outside the notch), ``iterations`` (Newton iterations of the step, its cut
    substeps and failed attempts included).

    Attributes:
        h: Grid spacing [m]; element, jacobian, mass: the model's choices.
        onset_t, onset_p: Time [s] and notch pressure [Pa] of the first step with a cracked
            element outside the notch (``None``: none).
        output_times: Times of the fields, shape ``(n_out,)`` [s].
        sample_points: Where p is sampled, shape ``(s, 2)`` [m]; p: shape ``(n_out, s)`` [Pa].
        damage, opening: D and w / w_c per element at the output times, shape ``(n_out, m)``,
            elements in the order of ``centroids`` ``(m, 2)`` [m] (sorted by y, then x: the same
            order on any number of ranks); precracked: the notch's elements, shape ``(m,)``.
        n_dofs, n_elements, n_vertices: Sizes.
        newton: Newton iterations of the run; cuts: step halvings.
        wall_time_s: Wall time of the call (mesh, forms, steps), max over ranks [s].
        stopped: Why the run stopped early (Newton failed at the smallest cut), else ``None``;
            t_reached: the last committed time [s].
    """

    h: float
    element: str
    jacobian: str
    mass: str
    t: np.ndarray
    notch_p: np.ndarray
    left: np.ndarray
    right: np.ndarray
    cracked: np.ndarray
    iterations: np.ndarray
    onset_t: float | None
    onset_p: float | None
    output_times: np.ndarray
    sample_points: np.ndarray
    p: np.ndarray
    damage: np.ndarray
    opening: np.ndarray
    centroids: np.ndarray
    precracked: np.ndarray
    n_dofs: int
    n_elements: int
    n_vertices: int
    newton: int
    cuts: int
    wall_time_s: float
    stopped: str | None
    t_reached: float

    @property
    def length(self) -> np.ndarray:
        """Crack length right - left per recorded step [m]."""
        return self.right - self.left

    def length_at(self, t: float) -> float:
        """The crack length at the recorded step time ``t`` [s] (NaN if not reached)."""
        hit = np.flatnonzero(np.isclose(self.t, t, rtol=1e-12, atol=1e-9))
        return float(self.length[hit[0]]) if hit.size else float("nan")


class _Record:
    """Per committed grid step: tips, cracked count, notch pressure, Newton iterations; at the
    output times: p at the sample points, D and w / w_c per element."""

    KEYS = ("t", "left", "right", "cracked", "iterations", "notch_p")

    def __init__(self, model: FemHydraulicFractureModel, sampler: _Sampler, output_times: np.ndarray,
                 order: np.ndarray):
        self.model, self.sampler, self.output_times, self.order = model, sampler, output_times, order
        self.rows = {k: [] for k in self.KEYS}
        self.maps = {"t": [], "p": [], "damage": [], "opening": []}
        self._seen = 0
        self.last_x = None

    def record(self, s: StepState) -> None:
        m = self.model
        self.last_x = s.x
        opening = m.opening()
        cracked = opening >= CRACKED
        xs = m.vertices[cracked, :, 0]
        left, right = (float(xs.min()), float(xs.max())) if cracked.any() else (0.0, 0.0)
        spent = sum(m.iterations[self._seen:])
        self._seen = len(m.iterations)
        p = self.sampler(*m.assign(s.x))[0]
        for key, v in zip(self.KEYS, (s.t, left, right, int((cracked & ~m.precracked).sum()), spent, float(p[0]))):
            self.rows[key].append(v)
        if np.any(np.isclose(self.output_times, s.t, rtol=1e-12, atol=1e-9)):
            self.maps["t"].append(s.t)
            self.maps["p"].append(p[1:])
            self.maps["damage"].append(m.committed.damage[self.order])
            self.maps["opening"].append(opening[self.order])

    def arrays(self) -> dict[str, np.ndarray]:
        out = {f"row_{k}": np.array(v, float) for k, v in self.rows.items()}
        for k, v in self.maps.items():
            out[f"map_{k}"] = np.array(v, float) if v else np.zeros((0,))
        return out

    def restore(self, a) -> None:
        self.rows = {k: list(a[f"row_{k}"]) for k in self.KEYS}
        self.maps = {k: list(a[f"map_{k}"]) for k in self.maps}
        self._seen = len(self.model.iterations)


def _check_injection(h: float, L: float, c: float, rate: float, times: np.ndarray) -> None:
    if not (np.isfinite(L) and L > 0 and np.isfinite(c) and 0 < c < L / 2):
        raise InputError(f"c = {c!r}, L = {L!r}: the notch's half-length must lie in (0, L/2)")
    n, k = int(round(L / h)) if h > 0 else 0, int(round(c / h)) if h > 0 else 0
    if not (np.isfinite(h) and h > 0 and abs(n * h - L) < 1e-9 * L and abs(k * h - c) < 1e-9 * L and n % 2 == 0
            and k >= 2):
        raise InputError(f"h = {h!r} must divide c = {c:g} (at least twice) and L / 2 = {L / 2:g}; e.g. h = {c / 4:g}")
    if not (np.isfinite(rate) and rate > 0):
        raise InputError(f"rate = {rate!r}: the notch pressure must rise (rate > 0) [Pa/s]")
    if times.ndim != 1 or len(times) < 2 or not np.all(np.diff(times) > 0):
        raise InputError("times must be a strictly increasing 1-D array of >= 2 step times [s]")


def solve_hydraulic_fracture(h: float, rock: FracturingRock, rate: float = 5.5e4,
                             times: Sequence[float] | np.ndarray = np.arange(0.0, 2001.0, 100.0), *,
                             L: float = 1.0, c: float = 0.1, notch_width: float = 1.5,
                             element: str = "p1p1-fpp", mass: str = "lumped", jacobian: str = "full",
                             residual: float = RESIDUAL_STIFFNESS, track: tuple[float, float] | None = None,
                             damage_update: str = "implicit", injection_rate: float = 0.0,
                             closure: bool = False, output_times: Sequence[float] = (),
                             sample_points: np.ndarray | None = None, line_search: bool = True,
                             max_cuts: int = 12, comm: MPI.Comm | None = None, checkpoint_every: int = 0,
                             checkpoint_dir: str | Path | None = None, resume: str | Path | None = None,
                             progress: Callable | None = None, stepper: Newmark | None = None
                             ) -> FemInjectionResult:
    """The injection set-up of ``rkfx.cases.injection`` by crack-band u-p finite elements.

    The plate [-L/2, L/2]^2 meshed on the RKPM case's particles (square grid of spacing h);
    outer edges fixed and drained; p = ``rate`` t at the vertices within ``notch_width`` h of the
    notch line with |x| <= c, and the elements they span damaged from the start (module
    docstring). Collective on ``comm``.

    Args:
        h: Grid spacing [m]; divides c (at least twice) and L / 2.
        rock: The material (the case's: ``rkfx.cases.injection.default_rock()``).
        rate: Notch pressure rate [Pa/s].
        times: Step times t_0 = 0 < t_1 < ... [s] (each interval is one step, halved when
            Newton fails, up to ``max_cuts`` times).
        L, c: Plate side and notch half-length [m].
        notch_width: Half-width of the pressurized vertices about the notch line [spacings]
            (the RKPM case's 1.5 support radii).
        element, mass, jacobian, residual, track, damage_update, closure: As
            ``FemHydraulicFractureModel`` (``track``: ``None``, the default, lets every element damage;
            ``(0.3, 3.5)`` is the RKPM case's).
        injection_rate: > 0: fluid injected into the notch's elements at Q = injection_rate t
            [m^2/s per metre of thickness] in place of the notch pressure (``rate`` then unused).
        output_times: Step times at which p, D and w / w_c are kept.
        sample_points: Where p is sampled at the output times, shape ``(s, 2)`` [m] (default a
            21 x 21 grid over the plate).
        line_search: Backtracking in Newton (as the RKPM case: near the threshold the loading
            set can flip between iterates).
        max_cuts: Halvings of a failing step before the run stops (it then keeps what it
            reached: ``stopped``, ``t_reached``).
        comm: Communicator (default ``MPI.COMM_WORLD``).
        checkpoint_every, checkpoint_dir, resume: Checkpoints of the committed state every so
            many steps into ``checkpoint_dir`` (written by rank 0); continue from ``resume``.
        progress: Optional wrapper of the step iterator.
        stepper: Default ``trapezoidal(guess="previous", newton=NewtonOptions(line_search=line_search))``,
            the seed's scheme with Newton started from the last step (module docstring).

    Returns:
        ``FemInjectionResult`` on every rank.
    """
    t_start = time.perf_counter()
    comm = MPI.COMM_WORLD if comm is None else comm
    times = np.asarray(times, float)
    _check_injection(h, L, c, rate, times)
    out_t = np.atleast_1d(np.asarray(output_times, float))
    if np.any([not np.any(np.isclose(times[1:], t, rtol=1e-12, atol=1e-9)) for t in out_t]):
        raise InputError(f"output_times = {[float(t) for t in out_t]}: each must be one of the step times after "
                         "the first")
    if not (np.isfinite(notch_width) and 1.0 <= notch_width < 2.0):
        raise InputError(f"notch_width = {notch_width!r} must lie in [1, 2) spacings (1.5: the RKPM case's band)")
    if int(max_cuts) != max_cuts or max_cuts < 0:
        raise InputError(f"max_cuts = {max_cuts!r} must be a whole number >= 0")
    n = int(round(L / h))
    xs = -L / 2 + h * np.arange(n + 1)
    xs[n // 2] = 0.0
    mesh = rectangle_mesh(xs, xs, "triangle", comm)
    tol = 1e-9 * L

    def in_notch(x):
        return (np.abs(x[:, 1]) < notch_width * h - tol) & (np.abs(x[:, 0]) <= c + tol)

    notch = Region(in_notch, "notch")
    sides = ("left", "right", "bottom", "top")
    conditions = [Displacement(s) for s in sides] + [Pressure(s) for s in sides]
    if not (np.isfinite(injection_rate) and injection_rate >= 0.0):
        raise InputError(f"injection_rate = {injection_rate!r} must be >= 0 [m^2/s^2] (0: the notch pressure)")
    injection = None
    if injection_rate > 0:  # the fluid enters the notch's elements; their pressure is free
        injection = (notch, lambda t: injection_rate * t)
    else:
        conditions.append(Pressure(notch, lambda x, t: np.full(len(x), rate * t)))
    model = FemHydraulicFractureModel(mesh, rock, conditions, precracked=notch, element=element, mass=mass,
                                      jacobian=jacobian, residual=residual, track=track,
                                      damage_update=damage_update, injection=injection, closure=closure)
    if sample_points is None:
        g = np.linspace(-L / 2, L / 2, 21)
        sample_points = np.column_stack([np.repeat(g, 21), np.tile(g, 21)])
    sample_points = np.asarray(sample_points, float)
    if sample_points.ndim != 2 or sample_points.shape[1] != 2:
        raise InputError(f"sample_points have shape {sample_points.shape}; give (s, 2)")
    sampler = _Sampler(mesh, np.vstack([[0.0, 0.0], sample_points]))  # the notch's centre first
    order = np.lexsort((np.round(model.centroids[:, 0] / h, 6), np.round(model.centroids[:, 1] / h, 6)))
    rec = _Record(model, sampler, out_t, order)
    stepper = stepper or trapezoidal(guess="previous", newton=NewtonOptions(line_search=line_search))
    solves = Factorizations(comm, "mumps", keep=2, mumps_icntl=_MUMPS_ICNTL)
    stopped, run = None, None
    try:
        run = integrate(stepper, model, times, recorder=rec, solves=solves, comm=comm, max_cuts=max_cuts,
                        checkpoint_every=checkpoint_every, checkpoint_dir=checkpoint_dir, resume=resume,
                        progress=progress)
    except SolverError as err:  # keep what the run reached; the message says where and why
        stopped = str(err)
    finally:
        solves.destroy()
    rows = {k: np.asarray(v, float) for k, v in rec.rows.items()}
    outside = np.flatnonzero(rows["cracked"] > 0)
    onset = int(outside[0]) if outside.size else None
    m = model.m
    maps = {k: (np.asarray(rec.maps[k], float) if rec.maps[k] else np.zeros((0, w)))
            for k, w in (("p", len(sample_points)), ("damage", m), ("opening", m))}
    wall = comm.allreduce(time.perf_counter() - t_start, op=MPI.MAX)
    return FemInjectionResult(
        h=float(h), element=element, jacobian=model.jacobian, mass=mass, t=rows["t"], notch_p=rows["notch_p"],
        left=rows["left"], right=rows["right"], cracked=rows["cracked"].astype(int),
        iterations=rows["iterations"].astype(int), onset_t=None if onset is None else float(rows["t"][onset]),
        onset_p=None if onset is None else float(rows["notch_p"][onset]),
        output_times=np.asarray(rec.maps["t"], float), sample_points=sample_points, p=maps["p"],
        damage=maps["damage"], opening=maps["opening"], centroids=model.centroids[order],
        precracked=model.precracked[order], n_dofs=model.n_dofs, n_elements=m, n_vertices=model.n_p,
        newton=int(sum(model.iterations)), cuts=0 if run is None else run.cuts, wall_time_s=wall, stopped=stopped,
        t_reached=float(rows["t"][-1]) if len(rows["t"]) else float(times[0]))
