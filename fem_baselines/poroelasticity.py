"""Plane-strain linear Biot poroelasticity with dolfinx: the FEM baseline for the RKPM u-p solver.

Governing equations (the seed's conventions, Wei 2018, ch. 3, eqs. 3.1-3.16; tensile effective
stress positive, pore pressure compressive positive, no gravity):

    div(sigma''(u) - alpha p I) = 0,
    alpha div(du/dt) + S dp/dt - div(k grad p) = 0,

with the drained plane-strain law ``sigma'' = lambda tr(eps) I + 2 mu eps`` (E, nu drained;
``fem_baselines.elasticity.stress_law`` of ``rkfx.elasticity.ElasticMaterial``),
Biot coefficient ``alpha``, storage coefficient ``S = 1/Q`` [1/Pa] (0 = incompressible
constituents) and mobility ``k`` [m^2/(Pa s)] (permeability / viscosity, i.e. ``k_h/gamma_f``).

Time is discretised with backward Euler and the displacement-pressure system is solved
monolithically at every step (eqs. 3.38-3.44):

    [ K_uu      -K_up                  ] [U_n+1]   [ F_n+1                                 ]
    [ -K_up^T   -K_S - dt K_H (- dt S) ] [P_n+1] = [ -K_up^T U_n - K_S P_n - dt Q_n+1       ]

where ``S`` (only for ``element="q1q1-fpp"``) is the fluid-pressure-projection stabilisation of
White & Borja (2008) as the seed writes it in eqs. 3.49-3.52,
``S = int eps_f (psi - Pi psi)(p - Pi p)`` with ``Pi`` the cell-wise L2 projection onto constants
and ``eps_f`` from eqs. 3.53-3.54 (``rkfx.poroelasticity.fpp_parameter``, ``h = sqrt(cell
area)``). It is assembled exactly as
``S = M_eps - C diag(eps_f / |K|) C^T`` (``M_eps`` the eps_f-weighted Q1 mass matrix, ``C`` the
Q1 x DG0 mixed mass matrix), the second term by PETSc sparse products.

Two FPP variants (``fpp_form``): ``"seed"`` is eq. 3.51 literally (``-dt S`` in the p-p block);
``"rate"`` is White & Borja's original, where the term acts on the pressure rate
(``-S (P_n+1 - P_n)``). They coincide for dt = 1 in the time unit used (the seed's Terzaghi step
is 1 s). Since eps_f has units 1/Pa, the seed form changes with the time unit: on the seed's
Terzaghi column at c dt / h^2 = 0.1 (dt = 6250 s) it suppresses the undrained pressure (max p =
0.53 p0), and on the seed's Mandel set-up (dt = 4e-4) it has no visible effect; the rate form is
unit-invariant and removes the Q1-Q1 oscillations in both (see tests/test_fem_poroelasticity.py).

Implementation: the dt-independent part of the monolithic matrix is assembled once (a dolfinx
nest converted to AIJ; rows ``[u owned, p owned]`` per rank, the layout of
``dolfinx.fem.petsc.create_vector([V, Q], kind="mpi")``); the dt-dependent p-p part (``-dt K_H``
and FPP) is assembled on the pressure space and added through an injection matrix, then
factorised with MUMPS LU once per distinct dt.

Elements: ``"taylor-hood"`` (P2-P1 on triangles, Q2-Q1 on quadrilaterals; inf-sup stable),
``"q1q1"`` (equal-order Q1-Q1 on quadrilaterals, P1-P1 on triangles; unstabilised, oscillates
in the undrained limit) and ``"q1q1-fpp"`` (the same with FPP).

All dolfinx-specific calls of the poroelastic FEM baseline live in this module. Importing it has
no side effects beyond importing dolfinx (``dolfinx_solver`` first, as it must be).
"""

from __future__ import annotations

import itertools
import time
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import basix.ufl
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.geometry
import dolfinx.la
import dolfinx.mesh
import ufl

from fem_baselines.elasticity import strain, stress_law
from rkfx.elasticity import ElasticMaterial
from rkfx.poroelasticity import PoroMaterial, fpp_parameter

__all__ = [
    "BiotResult",
    "Displacement",
    "Flux",
    "Pressure",
    "Traction",
    "rectangle_mesh",
    "solve_biot",
]

#: A boundary part: one of ``"left"``, ``"right"``, ``"bottom"``, ``"top"`` (the sides of the
#: mesh's bounding box, located by coordinates), or a marker ``m(x) -> bool array`` with ``x`` of
#: shape (3, npts) selecting boundary facets geometrically.
BoundaryKey = str | Callable[[np.ndarray], np.ndarray]

ELEMENTS = ("taylor-hood", "q1q1", "q1q1-fpp")

_prefix_counter = itertools.count()

_MUMPS_OPTIONS = {
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
    # Saddle-point systems: MUMPS' default workspace estimate can be too small (INFOG(1) = -9).
    "mat_mumps_icntl_14": 200,
    # AMF ordering: 1.7x faster factorisations than the default on the Mandel Taylor-Hood system.
    "mat_mumps_icntl_7": 2,
}

#: Number of factorised systems (one per distinct time step) kept alive at once.
_CACHE_SIZE = 2


# --------------------------------------------------------------------------- boundary data


@dataclass(frozen=True)
class Displacement:
    """Prescribed displacement component on a boundary part.

    Attributes:
        boundary: Boundary part (see :data:`BoundaryKey`).
        component: 0 (x) or 1 (y).
        value: ``value(x, t) -> (n,)`` [m] with ``x`` of shape (2, n) [m] and ``t`` [s], or a
            number.
    """

    boundary: BoundaryKey
    component: int
    value: Callable[[np.ndarray, float], np.ndarray] | float = 0.0


@dataclass(frozen=True)
class Traction:
    """Prescribed total traction ``(sigma'' - alpha p I) n`` on a boundary part.

    Attributes:
        boundary: Boundary part (see :data:`BoundaryKey`).
        value: ``value(x, t) -> (2, n)`` [Pa] with ``x`` of shape (2, n) [m], or a constant
            array-like of shape (2,).
    """

    boundary: BoundaryKey
    value: Callable[[np.ndarray, float], np.ndarray] | Any


@dataclass(frozen=True)
class Pressure:
    """Prescribed pore pressure on a boundary part (a drained boundary for value 0).

    Attributes:
        boundary: Boundary part (see :data:`BoundaryKey`).
        value: ``value(x, t) -> (n,)`` [Pa] with ``x`` of shape (2, n) [m], or a number.
    """

    boundary: BoundaryKey
    value: Callable[[np.ndarray, float], np.ndarray] | float = 0.0


@dataclass(frozen=True)
class Flux:
    """Prescribed outward normal fluid flux ``q . n = -k grad p . n`` on a boundary part.

    Attributes:
        boundary: Boundary part (see :data:`BoundaryKey`).
        value: ``value(x, t) -> (n,)`` [m/s] with ``x`` of shape (2, n) [m], or a number.
    """

    boundary: BoundaryKey
    value: Callable[[np.ndarray, float], np.ndarray] | float


BoundaryCondition = Displacement | Traction | Pressure | Flux


@dataclass
class BiotResult:
    """Sampled history and final fields of a Biot FEM run.

    Attributes:
        output_times: Times at which fields were sampled, shape (n_out,) [s].
        p: Pore pressure at the sample points, shape (n_out, m) [Pa]; NaN for points outside
            the mesh.
        u: Displacement at the sample points, shape (n_out, m, 2) [m].
        n_dofs: Global number of unknowns (2 per displacement node + 1 per pressure node).
        wall_time_s: Wall-clock seconds of the whole call (setup incl. form JIT, all
            assemblies, factorisations and solves, sampling), max over ranks.
        mesh: The dolfinx mesh.
        u_h: Final displacement, a vector Lagrange Function (ghosts up to date).
        p_h: Final pressure, a scalar Lagrange Function (ghosts up to date).
        element: The element name used.
        n_steps: Number of time steps taken.
        n_factorizations: Number of distinct matrices assembled and factorised.
        timings: Wall-clock breakdown [s], max over ranks: ``"setup"`` (spaces, forms incl.
            JIT, everything before the first step), ``"matrix"`` (assembly, FPP products and
            MUMPS factorisation, per distinct dt), ``"solve"`` (data interpolation, RHS
            assembly, triangular solves), ``"sample"`` (point evaluation).
    """

    output_times: np.ndarray
    p: np.ndarray
    u: np.ndarray
    n_dofs: int
    wall_time_s: float
    mesh: dolfinx.mesh.Mesh
    u_h: dolfinx.fem.Function
    p_h: dolfinx.fem.Function
    element: str = "taylor-hood"
    n_steps: int = 0
    n_factorizations: int = 0
    timings: dict[str, float] = field(default_factory=dict)


# --------------------------------------------------------------------------- mesh


def rectangle_mesh(
    xs: np.ndarray,
    ys: np.ndarray,
    cell: str = "triangle",
    comm: MPI.Comm | None = None,
) -> dolfinx.mesh.Mesh:
    """A structured mesh whose vertices are exactly the tensor grid ``xs`` x ``ys``.

    Cells are built on rank 0 and distributed by :func:`dolfinx.mesh.create_mesh`. For
    triangles every grid rectangle is split along its diagonal from (x_i, y_j) to
    (x_i+1, y_j+1) -- the same split everywhere, as in :func:`rkfx.particles.graded`.
    The sides are found by coordinates in :func:`solve_biot` (names ``"left"``, ``"right"``,
    ``"bottom"``, ``"top"``).

    Args:
        xs: Strictly increasing x coordinates, shape (nx,) [m], nx >= 2 (may be non-uniform).
        ys: Strictly increasing y coordinates, shape (ny,) [m], ny >= 2.
        cell: ``"triangle"`` or ``"quadrilateral"``.
        comm: MPI communicator; defaults to ``MPI.COMM_WORLD``.

    Returns:
        A dolfinx mesh (gdim 2) with ``nx * ny`` vertices and ``(nx-1)(ny-1)`` quadrilaterals or
        ``2 (nx-1)(ny-1)`` triangles.
    """
    comm = MPI.COMM_WORLD if comm is None else comm
    xs = np.asarray(xs, dtype=np.float64)
    ys = np.asarray(ys, dtype=np.float64)
    for name, c in (("xs", xs), ("ys", ys)):
        if c.ndim != 1 or len(c) < 2 or not np.all(np.diff(c) > 0):
            raise ValueError(f"{name} must be a strictly increasing 1-D array of >= 2 coordinates")
    if cell not in ("triangle", "quadrilateral"):
        raise ValueError(f"cell must be 'triangle' or 'quadrilateral', got {cell!r}")
    nv = 3 if cell == "triangle" else 4
    if comm.rank == 0:
        nx, ny = len(xs), len(ys)
        X, Y = np.meshgrid(xs, ys)
        x = np.column_stack([X.ravel(), Y.ravel()])
        node = np.arange(nx * ny, dtype=np.int64).reshape(ny, nx)
        a, b = node[:-1, :-1], node[:-1, 1:]  # (i, j), (i+1, j)
        c, d = node[1:, 1:], node[1:, :-1]  # (i+1, j+1), (i, j+1)
        if cell == "triangle":
            cells = np.concatenate(
                [np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
            )
        else:  # dolfinx's tensor-product vertex order: (0,0), (1,0), (0,1), (1,1)
            cells = np.stack([a, b, d, c], -1).reshape(-1, 4)
    else:
        x = np.zeros((0, 2), dtype=np.float64)
        cells = np.zeros((0, nv), dtype=np.int64)
    domain = ufl.Mesh(basix.ufl.element("Lagrange", cell, 1, shape=(2,)))
    return dolfinx.mesh.create_mesh(comm, cells, domain, x)


# --------------------------------------------------------------------------- helpers


def _values(data: Any, x: np.ndarray, t: float, shape: tuple[int, ...]) -> np.ndarray:
    """Evaluate boundary data ``data(x, t)`` (or a constant) at interpolation points.

    Args:
        data: Callable ``(x (2, n), t) -> shape + (n,)`` or a constant of shape ``shape``.
        x: Interpolation points from dolfinx, shape (3, n).
        t: Time [s].
        shape: Value shape, ``()`` or ``(2,)``.

    Returns:
        Array of shape ``shape + (n,)``.
    """
    n = x.shape[1]
    val = np.asarray(data(x[:2], t) if callable(data) else data, dtype=np.float64)
    if val.shape == shape:
        val = val[..., None]
    return np.ascontiguousarray(np.broadcast_to(val, (*shape, n)))


def _boundary_marker(key: BoundaryKey, mesh: dolfinx.mesh.Mesh) -> Callable[[np.ndarray], np.ndarray]:
    """Marker callable of a named side of the mesh's bounding box (or the marker itself)."""
    if callable(key):
        return key
    sides = ("left", "right", "bottom", "top")
    if key not in sides:
        raise ValueError(f"boundary must be one of {sides} or a marker callable, got {key!r}")
    x = mesh.geometry.x[:, :2]
    lo = np.full(2, np.inf) if x.size == 0 else x.min(axis=0)
    hi = np.full(2, -np.inf) if x.size == 0 else x.max(axis=0)
    mesh.comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
    mesh.comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
    tol = 1e-10 * float(np.max(hi - lo))
    axis, value = {"left": (0, lo[0]), "right": (0, hi[0]), "bottom": (1, lo[1]), "top": (1, hi[1])}[key]
    return lambda X: np.abs(X[axis] - value) <= tol


class _Sampler:
    """Point evaluation of (u, p) at fixed points; every rank gets the full arrays."""

    def __init__(self, mesh: dolfinx.mesh.Mesh, points: np.ndarray):
        pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise ValueError(f"sample_points must have shape (m, 2), got {np.shape(points)}")
        self.comm = mesh.comm
        m = pts.shape[0]
        self.x3 = np.zeros((m, 3), dtype=mesh.geometry.x.dtype)
        self.x3[:, :2] = pts
        tree = dolfinx.geometry.bb_tree(mesh, mesh.topology.dim)
        candidates = dolfinx.geometry.compute_collisions_points(tree, self.x3)
        colliding = dolfinx.geometry.compute_colliding_cells(mesh, candidates, self.x3)
        offsets = np.asarray(colliding.offsets)
        found = np.diff(offsets) > 0
        rank, size = self.comm.rank, self.comm.size
        owner = np.where(found, rank, size).astype(np.int32)
        if size > 1:
            self.comm.Allreduce(MPI.IN_PLACE, owner, op=MPI.MIN)
        self.mine = owner == rank  # a point on a partition interface goes to the lowest rank
        self.missing = owner == size
        self.cells = np.asarray(colliding.array)[offsets[:-1][self.mine]].astype(np.int32)

    def __call__(self, uh: dolfinx.fem.Function, ph: dolfinx.fem.Function) -> tuple[np.ndarray, np.ndarray]:
        m = self.x3.shape[0]
        vals = np.zeros((m, 3), dtype=np.float64)
        if np.any(self.mine):
            vals[self.mine, :2] = uh.eval(self.x3[self.mine], self.cells).reshape(-1, 2)
            vals[self.mine, 2] = ph.eval(self.x3[self.mine], self.cells).reshape(-1)
        if self.comm.size > 1:
            self.comm.Allreduce(MPI.IN_PLACE, vals, op=MPI.SUM)
        vals[self.missing] = np.nan
        return vals[:, 2].copy(), vals[:, :2].copy()


def _facet_tags(mesh: dolfinx.mesh.Mesh, keys: Sequence[BoundaryKey], what: str):
    """Facet MeshTags giving boundary part i the tag i + 1 (parts must be disjoint)."""
    fdim = mesh.topology.dim - 1
    parts = [
        np.asarray(dolfinx.mesh.locate_entities_boundary(mesh, fdim, _boundary_marker(key, mesh)), np.int32)
        for key in keys
    ]
    facets = np.concatenate(parts)
    values = np.concatenate([np.full(p.size, i + 1, dtype=np.int32) for i, p in enumerate(parts)])
    order = np.argsort(facets, kind="stable")
    facets, values = facets[order], values[order]
    if np.any(np.diff(facets) == 0):
        raise ValueError(f"{what} boundaries overlap; give each facet one {what}")
    return dolfinx.mesh.meshtags(mesh, fdim, facets, values)


# --------------------------------------------------------------------------- solver


def solve_biot(
    mesh: dolfinx.mesh.Mesh,
    E: float,
    nu: float,
    k: float,
    alpha: float,
    S: float,
    element: str,
    bcs: Sequence[BoundaryCondition],
    times: np.ndarray,
    sample_points: np.ndarray,
    output_times: np.ndarray,
    comm: MPI.Comm | None = None,
    initial_u: Callable[[np.ndarray], np.ndarray] | None = None,
    initial_p: Callable[[np.ndarray], np.ndarray] | None = None,
    fpp_form: str = "rate",
) -> BiotResult:
    """Solve plane-strain Biot consolidation with backward Euler and a monolithic u-p solve.

    Collective on the mesh communicator. Boundaries not mentioned in ``bcs`` are traction-free
    and impermeable. Each linear system is factorised with MUMPS once per distinct time step
    (matrices are cached by dt, the last two kept).

    Args:
        mesh: A 2D dolfinx mesh (e.g. from :func:`rectangle_mesh`), triangles or quadrilaterals.
        E: Drained Young's modulus [Pa].
        nu: Drained Poisson's ratio [-] (< 0.5).
        k: Mobility k_h / gamma_f [m^2/(Pa s)].
        alpha: Biot coefficient [-].
        S: Storage coefficient 1/Q [1/Pa]; 0 for incompressible constituents.
        element: ``"taylor-hood"`` (P2-P1 / Q2-Q1), ``"q1q1"`` (equal order, unstabilised) or
            ``"q1q1-fpp"`` (equal order with fluid pressure projection, eqs. 3.49-3.54).
        bcs: Boundary conditions: :class:`Displacement`, :class:`Traction`, :class:`Pressure`,
            :class:`Flux` instances. Data callables are evaluated at t_{n+1} in step n+1.
        times: Time levels t_0 < t_1 < ... < t_N, shape (N+1,) [s]; the initial state is at t_0.
        sample_points: Points where fields are sampled, shape (m, 2) [m].
        output_times: Times at which to sample, each exactly equal to an entry of ``times``,
            shape (n_out,) [s].
        comm: Unused beyond a consistency check (the mesh's communicator is used); kept for the
            house signature.
        initial_u: Initial displacement ``u0(x) -> (2, n)`` with x of shape (2, n); default 0.
        initial_p: Initial pressure ``p0(x) -> (n,)``; default 0.
        fpp_form: ``"rate"`` (default, as in ``rkfx.poroelasticity``): ``-S`` acting on
            ``P_n+1 - P_n`` (White & Borja's form, stabilising the pressure rate; dimensionally
            consistent with eps_f in 1/Pa); ``"seed"``: ``-dt S`` in the p-p block as eq. 3.51
            is printed, which depends on the unit of time (kept for comparison). Ignored unless
            ``element == "q1q1-fpp"``.

    Returns:
        The sampled history and final fields; see :class:`BiotResult`.

    Raises:
        ValueError: On inconsistent input.
        RuntimeError: If a linear solve fails (KSP reason < 0).
    """
    t_start = time.perf_counter()
    if comm is not None and comm.size != mesh.comm.size:
        raise ValueError("comm must be the mesh's communicator")
    comm = mesh.comm
    if element not in ELEMENTS:
        raise ValueError(f"element must be one of {ELEMENTS}, got {element!r}")
    if fpp_form not in ("seed", "rate"):
        raise ValueError(f"fpp_form must be 'seed' or 'rate', got {fpp_form!r}")
    if mesh.geometry.dim != 2:
        raise ValueError("solve_biot expects a 2D mesh (gdim 2)")
    times = np.asarray(times, dtype=np.float64)
    if times.ndim != 1 or len(times) < 2 or not np.all(np.diff(times) > 0):
        raise ValueError("times must be a strictly increasing 1-D array with at least 2 entries")
    output_times = np.atleast_1d(np.asarray(output_times, dtype=np.float64))
    out_index = np.searchsorted(times, output_times)
    clipped = np.minimum(out_index, len(times) - 1)
    if np.any(out_index >= len(times)) or np.any(times[clipped] != output_times):
        raise ValueError("every output time must be exactly equal to an entry of times")
    if not (E > 0 and -1.0 < nu < 0.5 and k >= 0 and S >= 0):
        raise ValueError(f"need E > 0, -1 < nu < 0.5, k >= 0, S >= 0; got E={E}, nu={nu}, k={k}, S={S}")

    tdim = mesh.topology.dim
    fdim = tdim - 1
    mesh.topology.create_connectivity(fdim, tdim)
    deg_u = 2 if element == "taylor-hood" else 1
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", deg_u, (2,)))
    Q = dolfinx.fem.functionspace(mesh, ("Lagrange", 1))
    scalar = dolfinx.default_scalar_type

    # -- Dirichlet conditions (data Functions re-interpolated at every t_n+1) ----------------
    updates: list[tuple[dolfinx.fem.Function, Any, tuple[int, ...]]] = []
    dirichlet: list[dolfinx.fem.DirichletBC] = []
    p_dirichlet: list[dolfinx.fem.DirichletBC] = []
    tractions = [bc for bc in bcs if isinstance(bc, Traction)]
    fluxes = [bc for bc in bcs if isinstance(bc, Flux)]
    for bc in bcs:
        if isinstance(bc, (Traction, Flux)):
            continue
        if not isinstance(bc, (Displacement, Pressure)):
            raise TypeError(f"unknown boundary condition {bc!r}")
        facets = dolfinx.mesh.locate_entities_boundary(mesh, fdim, _boundary_marker(bc.boundary, mesh))
        if isinstance(bc, Displacement):
            if bc.component not in (0, 1):
                raise ValueError(f"Displacement component must be 0 or 1, got {bc.component}")
            Vc, _ = V.sub(bc.component).collapse()
            g = dolfinx.fem.Function(Vc)
            dofs = dolfinx.fem.locate_dofs_topological((V.sub(bc.component), Vc), fdim, facets)
            dirichlet.append(dolfinx.fem.dirichletbc(g, dofs, V.sub(bc.component)))
        else:
            g = dolfinx.fem.Function(Q)
            dofs = dolfinx.fem.locate_dofs_topological(Q, fdim, facets)
            p_dirichlet.append(dolfinx.fem.dirichletbc(g, dofs))
            dirichlet.append(p_dirichlet[-1])
        updates.append((g, bc.value, ()))

    # -- forms -------------------------------------------------------------------------------
    sigma = stress_law(mesh, ElasticMaterial(E, nu))
    k_c = dolfinx.fem.Constant(mesh, scalar(k))
    alpha_c = dolfinx.fem.Constant(mesh, scalar(alpha))
    S_c = dolfinx.fem.Constant(mesh, scalar(S))
    dt_c = dolfinx.fem.Constant(mesh, scalar(times[1] - times[0]))

    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    p, q = ufl.TrialFunction(Q), ufl.TestFunction(Q)
    dx = ufl.dx(domain=mesh)
    uh = dolfinx.fem.Function(V, name="u")
    ph = dolfinx.fem.Function(Q, name="p")
    u_n = dolfinx.fem.Function(V)
    p_n = dolfinx.fem.Function(Q)

    fpp = element == "q1q1-fpp"
    theta = dt_c if fpp_form == "seed" else dolfinx.fem.Constant(mesh, scalar(1.0))
    if fpp:
        DG0 = dolfinx.fem.functionspace(mesh, ("DG", 0))
        eps_f = dolfinx.fem.Function(DG0, name="eps_f")
        poro = PoroMaterial(E, nu, k, alpha, S)  # eps_f of eq. 3.53

    # Storage equation multiplied by -1 so that the system is symmetric (eq. 3.43). The p-p
    # block is split into its dt-independent part (in A0, assembled once) and the part that
    # changes with dt (K_H and FPP, assembled on Q only and added per distinct dt).
    a_uu = ufl.inner(sigma(u), strain(v)) * dx
    a_up = -alpha_c * p * ufl.div(v) * dx
    a_pu = -alpha_c * q * ufl.div(u) * dx
    a_pp0 = -S_c * p * q * dx
    a_k = -k_c * ufl.inner(ufl.grad(p), ufl.grad(q)) * dx
    a_pp = a_pp0 + dt_c * a_k  # the full p-p form, used for lifting Dirichlet data
    L_p = -(alpha_c * q * ufl.div(u_n) + S_c * p_n * q) * dx
    if fpp:  # the int eps_f psi p part of eq. 3.52; the projection part is added with PETSc
        a_eps = -eps_f * p * q * dx
        a_pp = a_pp + theta * a_eps
        if fpp_form == "rate":
            L_p = L_p - eps_f * p_n * q * dx

    W = dolfinx.fem.functionspace(mesh, ("Lagrange", deg_u, (2,)))
    L_u = ufl.inner(dolfinx.fem.Constant(mesh, np.zeros(2, dtype=scalar)), v) * dx
    if tractions:
        tags = _facet_tags(mesh, [b.boundary for b in tractions], "traction")
        ds_t = ufl.Measure("ds", domain=mesh, subdomain_data=tags)
        for i, bc in enumerate(tractions):
            t_fn = dolfinx.fem.Function(W)
            updates.append((t_fn, bc.value, (2,)))
            L_u = L_u + ufl.inner(t_fn, v) * ds_t(i + 1)
    if fluxes:
        Qf = dolfinx.fem.functionspace(mesh, ("Lagrange", 2))
        tags = _facet_tags(mesh, [b.boundary for b in fluxes], "flux")
        ds_q = ufl.Measure("ds", domain=mesh, subdomain_data=tags)
        for i, bc in enumerate(fluxes):
            q_fn = dolfinx.fem.Function(Qf)
            updates.append((q_fn, bc.value, ()))
            L_p = L_p + dt_c * q_fn * q * ds_q(i + 1)

    a_forms = dolfinx.fem.form([[a_uu, a_up], [a_pu, a_pp]])
    L_forms = dolfinx.fem.form([L_u, L_p])
    bcs0 = dolfinx.fem.bcs_by_block(dolfinx.fem.extract_function_spaces(L_forms), dirichlet)
    bcs1 = dolfinx.fem.bcs_by_block(dolfinx.fem.extract_function_spaces(a_forms, 1), dirichlet)

    # -- dt-independent part A0 (Dirichlet rows/columns replaced by the identity) -----------
    t0 = time.perf_counter()
    a0_forms = dolfinx.fem.form([[a_uu, a_up], [a_pu, a_pp0]])
    A0 = dolfinx.fem.petsc.assemble_matrix(a0_forms, bcs=dirichlet, kind="nest")
    A0.assemble()
    A0.convert(PETSc.Mat.Type.AIJ)  # in place; rows [u owned, p owned] per rank, as create_vector
    # K_H on Q with the pressure-Dirichlet rows/columns zeroed (diagonal 0: A0 holds the 1).
    Kk = dolfinx.fem.petsc.assemble_matrix(dolfinx.fem.form(a_k), bcs=p_dirichlet, diag=0.0)
    Kk.assemble()
    # Injection of Q into the monolithic numbering: P[i, g(i)] = 1, so P^T X P embeds X.
    n_u = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
    q_imap = Q.dofmap.index_map
    n_q = q_imap.size_local
    mono_start = A0.getOwnershipRange()[0]
    inject = PETSc.Mat().createAIJ(
        ((n_q, q_imap.size_global), A0.getSizes()[1]),
        csr=(
            np.arange(n_q + 1, dtype=PETSc.IntType),
            (mono_start + n_u + np.arange(n_q)).astype(PETSc.IntType),
            np.ones(n_q, dtype=PETSc.ScalarType),
        ),
        comm=comm,
    )
    t_matrix = time.perf_counter() - t0

    # -- FPP projection part: R = C diag(eps_f / |K|) C^T with C the Q1 x DG0 mixed mass ------
    if fpp:
        mu0 = ufl.TestFunction(DG0)
        Ct = dolfinx.fem.petsc.assemble_matrix(dolfinx.fem.form(p * mu0 * dx))  # (cells, Q dofs)
        Ct.assemble()
        area = dolfinx.fem.assemble_vector(dolfinx.fem.form(mu0 * dx))
        area.scatter_reverse(dolfinx.la.InsertMode.add)
        area.scatter_forward()
        cell_area = area.array.copy()  # owned + ghost cells [m^2]
        n_cells_owned = DG0.dofmap.index_map.size_local
        p_bc_rows = np.unique(
            np.concatenate(
                [np.zeros(0, dtype=np.int64)]
                + [
                    q_imap.local_to_global(bc.dof_indices()[0][: bc.dof_indices()[1]].astype(np.int32))
                    for bc in p_dirichlet
                ]
            )
        ).astype(PETSc.IntType)
        a_eps_form = dolfinx.fem.form(a_eps)

    def fpp_matrices(dt: float):
        """eps_f of this dt into the DG0 Function; returns (R, Meps - R with p-BC rows/cols zeroed).

        ``Meps = int eps_f psi p`` enters with a minus sign (``a_eps``), so the second matrix is
        ``-S_fpp`` of eq. 3.52 with Dirichlet rows/columns zeroed.
        """
        eps_f.x.array[:] = fpp_parameter(poro, dt, np.sqrt(cell_area))
        d = Ct.createVecLeft()
        d.array[:] = eps_f.x.array[:n_cells_owned] / cell_area[:n_cells_owned]
        Cs = Ct.copy()
        Cs.diagonalScale(L=d)
        R = Ct.transposeMatMult(Cs)  # Ct^T diag(eps/|K|) Ct, Q x Q
        Cs.destroy()
        d.destroy()
        minus_S = dolfinx.fem.petsc.assemble_matrix(a_eps_form, bcs=p_dirichlet, diag=0.0)
        minus_S.assemble()
        R0 = R.copy()
        R0.zeroRowsColumns(p_bc_rows, diag=0.0)
        minus_S.axpy(1.0, R0, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        R0.destroy()
        return R, minus_S

    # -- matrix cache by dt ----------------------------------------------------------------
    cache: OrderedDict[float, dict[str, Any]] = OrderedDict()
    n_factorizations = 0

    def system(dt: float) -> dict[str, Any]:
        nonlocal n_factorizations, t_matrix
        key = float(f"{dt:.12g}")
        if key in cache:
            cache.move_to_end(key)
            return cache[key]
        t0 = time.perf_counter()
        entry: dict[str, Any] = {"dt": dt}
        X = Kk.copy()
        X.scale(dt)  # -dt K_H
        if fpp:
            R, minus_S = fpp_matrices(dt)
            # eq. 3.51: -dt S ("seed"); White & Borja's rate form: -S on P_n+1 - P_n ("rate").
            theta_v = dt if fpp_form == "seed" else 1.0
            X.axpy(theta_v, minus_S, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            minus_S.destroy()
            entry["R"] = R
        X_mono = X.PtAP(inject)
        X.destroy()
        A = A0.copy()
        A.axpy(1.0, X_mono, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        X_mono.destroy()
        prefix = f"rkfx_fem_biot_{next(_prefix_counter)}_"
        opts = PETSc.Options()
        for name, val in _MUMPS_OPTIONS.items():
            opts[prefix + name] = val
        A.setOptionsPrefix(prefix)
        A.setFromOptions()
        ksp = PETSc.KSP().create(comm)
        ksp.setOptionsPrefix(prefix)
        ksp.setOperators(A)
        ksp.setFromOptions()
        ksp.setUp()  # factorise now: MUMPS reads its options (ICNTL) at factorisation time
        for name in _MUMPS_OPTIONS:
            del opts[prefix + name]
        entry["A"], entry["ksp"] = A, ksp
        cache[key] = entry
        n_factorizations += 1
        while len(cache) > _CACHE_SIZE:
            _, old = cache.popitem(last=False)
            for obj in ("ksp", "A", "R"):
                if obj in old:
                    old[obj].destroy()
        t_matrix += time.perf_counter() - t0
        return entry

    # -- initial state ---------------------------------------------------------------------
    if initial_u is not None:
        u_n.interpolate(lambda x: _values(lambda X, t: initial_u(X), x, times[0], (2,)))
    if initial_p is not None:
        p_n.interpolate(lambda x: _values(lambda X, t: initial_p(X), x, times[0], ()))
    uh.x.array[:] = u_n.x.array
    ph.x.array[:] = p_n.x.array

    sampler = _Sampler(mesh, sample_points)
    m = sampler.x3.shape[0]
    out_p = np.full((len(output_times), m), np.nan)
    out_u = np.full((len(output_times), m, 2), np.nan)
    t_sample = 0.0

    def record(n: int) -> None:
        nonlocal t_sample
        t0 = time.perf_counter()
        for j in np.flatnonzero(out_index == n):
            out_p[j], out_u[j] = sampler(uh, ph)
        t_sample += time.perf_counter() - t0

    record(0)
    b = dolfinx.fem.petsc.create_vector([V, Q], kind="mpi")
    x = dolfinx.fem.petsc.create_vector([V, Q], kind="mpi")
    off0, _ = b.getAttr("_blocks")
    if fpp and p_dirichlet:
        g_vec = dolfinx.fem.petsc.create_vector(Q)  # p-BC values, zero elsewhere (for lifting R)
        Rg = g_vec.duplicate()
    if fpp and fpp_form == "rate":
        Pn = dolfinx.fem.petsc.create_vector(Q)
        RPn = Pn.duplicate()
    t_setup = time.perf_counter() - t_start - t_matrix  # t_matrix so far: A0, Kk, injection
    t_solve = 0.0

    try:
        for n in range(1, len(times)):
            dt = float(times[n] - times[n - 1])
            t_new = float(times[n])
            entry = system(dt)
            t0 = time.perf_counter()
            dt_c.value = entry["dt"]
            for fn, data, shape in updates:
                if callable(data) or n == 1:
                    fn.interpolate(lambda X, data=data, shape=shape: _values(data, X, t_new, shape))
            if fpp:  # eps_f of this dt (the RHS of the rate form uses it)
                eps_f.x.array[:] = fpp_parameter(poro, entry["dt"], np.sqrt(cell_area))
            with b.localForm() as b_loc:
                b_loc.set(0.0)
            dolfinx.fem.petsc.assemble_vector(b, L_forms)
            dolfinx.fem.petsc.apply_lifting(b, a_forms, bcs=bcs1)
            b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            if fpp:
                scale = entry["dt"] if fpp_form == "seed" else 1.0
                b_p = b.array[off0[1] : off0[2]].copy()
                if p_dirichlet:  # lifting of the projection part: b_p -= (theta R)[:, bc] g
                    with g_vec.localForm() as g_loc:
                        g_loc.set(0.0)
                    for bc in p_dirichlet:
                        bc.set(g_vec.array_w)
                    entry["R"].mult(g_vec, Rg)
                    b_p -= scale * Rg.array_r
                if fpp_form == "rate":  # -(Meps - R) P_n: the Meps part is in L_p
                    Pn.array[:] = p_n.x.array[: q_imap.size_local]
                    entry["R"].mult(Pn, RPn)
                    b_p += RPn.array_r
                b.array[off0[1] : off0[2]] = b_p
            dolfinx.fem.petsc.set_bc(b, bcs0)
            ksp = entry["ksp"]
            ksp.solve(b, x)
            reason = ksp.getConvergedReason()
            if reason < 0:
                raise RuntimeError(
                    f"Biot {element} solve failed at step {n} (t = {t_new:g}, dt = {dt:g}): "
                    f"KSP reason {reason}"
                )
            x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
            dolfinx.fem.petsc.assign(x, [uh, ph])
            u_n.x.array[:] = uh.x.array
            p_n.x.array[:] = ph.x.array
            t_solve += time.perf_counter() - t0
            record(n)
    finally:
        for entry in cache.values():
            for obj in ("ksp", "A", "R"):
                if obj in entry:
                    entry[obj].destroy()
        cache.clear()
        for obj in (b, x, A0, Kk, inject):
            obj.destroy()
        if fpp:
            Ct.destroy()
            if p_dirichlet:
                g_vec.destroy()
                Rg.destroy()
            if fpp_form == "rate":
                Pn.destroy()
                RPn.destroy()

    local = np.array([t_setup, t_matrix, t_solve, t_sample, time.perf_counter() - t_start])
    glob = np.empty_like(local)
    comm.Allreduce(local, glob, op=MPI.MAX)
    n_dofs = int(V.dofmap.index_map.size_global * V.dofmap.index_map_bs + q_imap.size_global)
    return BiotResult(
        output_times=output_times.copy(),
        p=out_p,
        u=out_u,
        n_dofs=n_dofs,
        wall_time_s=float(glob[4]),
        mesh=mesh,
        u_h=uh,
        p_h=ph,
        element=element,
        n_steps=len(times) - 1,
        n_factorizations=n_factorizations,
        timings=dict(zip(("setup", "matrix", "solve", "sample"), map(float, glob[:4]))),
    )
