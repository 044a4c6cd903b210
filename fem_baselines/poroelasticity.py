"""Linear Biot poroelasticity with dolfinx, plane strain and 3-D: the FEM baseline for the RKPM u-p solver.

Governing equations (the seed's conventions, Wei 2018, ch. 3, eqs. 3.1-3.16; tensile effective
stress positive, pore pressure compressive positive, no gravity):

    div(sigma''(u) - alpha p I) = 0,
    alpha div(du/dt) + S dp/dt - div(k grad p) = 0,

with the drained law ``sigma'' = lambda tr(eps) I + 2 mu eps`` (E, nu drained;
``fem_baselines.elasticity.stress_law`` of ``rkfx.materials.elasticity.ElasticMaterial``: the
plane-strain law on a 2-D mesh, the isotropic solid's on a 3-D one),
Biot coefficient ``alpha``, storage coefficient ``S = 1/Q`` [1/Pa] (0 = incompressible
constituents) and mobility ``k`` [m^2/(Pa s)] (permeability / viscosity, i.e. ``k_h/gamma_f``).

Time is discretised with backward Euler and the displacement-pressure system is solved
monolithically at every step (eqs. 3.38-3.44):

    [ K_uu      -K_up                  ] [U_n+1]   [ F_n+1                                 ]
    [ -K_up^T   -K_S - dt K_H (- dt S) ] [P_n+1] = [ -K_up^T U_n - K_S P_n - dt Q_n+1       ]

where ``S`` (only for ``element="q1q1-fpp"``) is the fluid-pressure-projection stabilisation of
White & Borja (2008) as the seed writes it in eqs. 3.49-3.52,
``S = int eps_f (psi - Pi psi)(p - Pi p)`` with ``Pi`` the cell-wise L2 projection onto constants
and ``eps_f`` from eqs. 3.53-3.54 (``rkfx.models.poroelasticity.fpp_parameter``, ``h = sqrt(cell
area)``; in 3-D ``h = cbrt(cell volume)``, the same cell size for quadrilaterals and hexahedra,
about half the edge of a regular tetrahedron). It is assembled exactly as
``S = M_eps - C diag(eps_f / |K|) C^T`` (``M_eps`` the eps_f-weighted Q1 mass matrix, ``C`` the
Q1 x DG0 mixed mass matrix).

Two FPP variants (``fpp_form``): ``"seed"`` is eq. 3.51 literally (``-dt S`` in the p-p block);
``"rate"`` is White & Borja's original, where the term acts on the pressure rate
(``-S (P_n+1 - P_n)``). They coincide for dt = 1 in the time unit used (the seed's Terzaghi step
is 1 s). Since eps_f has units 1/Pa, the seed form changes with the time unit: on the seed's
Terzaghi column at c dt / h^2 = 0.1 (dt = 6250 s) it suppresses the undrained pressure (max p =
0.53 p0), and on the seed's Mandel set-up (dt = 4e-4) it has no visible effect; the rate form is
unit-invariant and removes the Q1-Q1 oscillations in both (see tests/test_fem_poroelasticity.py).

Implementation: dolfinx assembly plugs into the shared solvers of ``rkfx.solvers`` as a model
(:class:`FemBiotModel`): the blocks are assembled once by dolfinx (FPP once per step size) and
gathered into scipy CSR on every rank in the global numbering ``[u, p]``, the Dirichlet
conditions are constraint rows with their values at t, and :func:`solve_biot` steps the model
with ``rkfx.solvers.integrate`` and ``backward_euler()``: one Newton iteration per step and one
MUMPS factorisation per distinct dt through ``rkfx.linalg.linear_solver.Factorizations`` (a new dt
reuses the ordering of the matrix it replaces), with checkpoints and resume. The matrix is
held whole on every rank and its rows distributed to MUMPS by ``rkfx.linalg.petsc``.

Elements: ``"taylor-hood"`` (P2-P1 on triangles and tetrahedra, Q2-Q1 on quadrilaterals;
inf-sup stable), ``"q1q1"`` (equal-order Q1-Q1 on quadrilaterals, P1-P1 on triangles and
tetrahedra; unstabilised, oscillates in the undrained limit) and ``"q1q1-fpp"`` (the same with
FPP).

Meshes: 2-D (gdim 2) from :func:`rectangle_mesh` or gmsh, and 3-D tetrahedral meshes (gdim 3) of
the gmsh solids of ``rkfx.geometry.gmsh_solids``, given as the ``MeshData`` of
``fem_baselines.gmsh_mesh.build_mesh`` / ``mesh_from_gmsh`` so that conditions name the parts
by their physical names (``x0``, ``surface``, ``top``, ...). Everything with a dimension
follows the mesh's: displacements, sample points and condition components have gdim entries.

Boundary conditions are those of ``rkfx.conditions``, the RKPM model's; parts and values reach
dolfinx through ``fem_baselines.conditions``. The other dolfinx-specific calls of the poroelastic
FEM baseline live in this module. Importing it has no side effects beyond importing dolfinx
(``dolfinx_solver`` first, as it must be).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import basix.ufl
import numpy as np
import scipy.sparse as sp
from mpi4py import MPI

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.geometry
import dolfinx.la
import dolfinx.mesh
import ufl

from fem_baselines.conditions import BoundaryParts, check_kinds
from fem_baselines.elasticity import strain, stress_law
from fem_baselines.gmsh_mesh import mesh_parts
from rkfx.conditions import Condition, Displacement, Flux, Pressure, Traction, values
from rkfx.errors import InputError
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.linalg.linear_solver import Factorizations
from rkfx.models.poroelasticity import PoroMaterial, fpp_parameter
from rkfx.solvers.fields import Field, FieldLayout
from rkfx.solvers.integrate import integrate
from rkfx.solvers.model import Constraints, PerStepSize
from rkfx.solvers.newmark import Newmark, StepState, backward_euler

__all__ = [
    "BiotResult",
    "FemBiotModel",
    "rectangle_mesh",
    "triangle_mesh",
    "NaturalLoads",
    "solve_biot",
]

ELEMENTS = ("taylor-hood", "q1q1", "q1q1-fpp")

#: MUMPS controls beyond ``rkfx.linalg.petsc``'s: the AMF ordering (ICNTL(7) = 2) factorises the
#: Mandel Taylor-Hood system 4x faster than the default.
_MUMPS_ICNTL = {7: 2}

#: In 3-D the METIS ordering (ICNTL(7) = 5) instead: it factorises the Taylor-Hood sphere octant
#: (40k dofs) in 2.0 s where AMF takes 3.1 s.
_MUMPS_ICNTL_3D = {7: 5}

@dataclass
class BiotResult:
    """Sampled history and final fields of a Biot FEM run.

    Attributes:
        output_times: Times at which fields were sampled, shape (n_out,) [s].
        p: Pore pressure at the sample points, shape (n_out, m) [Pa]; NaN for points outside
            the mesh.
        u: Displacement at the sample points, shape (n_out, m, gdim) [m].
        n_dofs: Global number of unknowns (gdim per displacement node + 1 per pressure node).
        wall_time_s: Wall-clock seconds of the whole call (setup incl. form JIT, all
            assemblies, factorisations and solves, sampling), max over ranks.
        mesh: The dolfinx mesh.
        u_h: Final displacement, a vector Lagrange Function (ghosts up to date).
        p_h: Final pressure, a scalar Lagrange Function (ghosts up to date).
        element: The element name used.
        n_steps: Number of time steps taken.
        n_factorizations: Number of matrices factorised (one per distinct time step).
        timings: Wall-clock breakdown [s], max over ranks: ``"setup"`` (spaces, forms incl.
            JIT, assembly, everything before the first step), ``"steps"`` (the time loop:
            data at t, FPP per distinct dt, factorisations and solves), ``"sample"`` (point
            evaluation).
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
    (x_i+1, y_j+1) -- the same split everywhere, as in :func:`rkfx.geometry.particles.graded`.
    The sides are found by coordinates (boundary parts ``"left"``, ``"right"``, ``"bottom"``,
    ``"top"`` of ``fem_baselines.conditions``).

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


def triangle_mesh(x: np.ndarray, triangles: np.ndarray, comm: MPI.Comm | None = None) -> dolfinx.mesh.Mesh:
    """A mesh of linear triangles whose vertices are exactly ``x`` (e.g. the particles of
    ``rkfx.geometry``, cut along fractures), built on rank 0 and distributed by dolfinx.

    Args:
        x: Vertex coordinates, shape ``(n, 2)`` [m].
        triangles: Vertex triples, shape ``(m, 3)``.
        comm: MPI communicator; defaults to ``MPI.COMM_WORLD``.
    """
    comm = MPI.COMM_WORLD if comm is None else comm
    x = np.asarray(x, dtype=np.float64)
    tri = np.asarray(triangles, dtype=np.int64)
    if x.ndim != 2 or x.shape[1] != 2 or tri.ndim != 2 or tri.shape[1] != 3 or len(tri) == 0:
        raise InputError(f"vertices of shape {x.shape} and triangles of shape {tri.shape}: give (n, 2) and (m, 3)")
    if tri.min() < 0 or tri.max() >= len(x):
        raise InputError(f"triangles refer to vertices 0..{tri.max()} of {len(x)}")
    if comm.rank != 0:
        x, tri = np.zeros((0, 2)), np.zeros((0, 3), dtype=np.int64)
    domain = ufl.Mesh(basix.ufl.element("Lagrange", "triangle", 1, shape=(2,)))
    return dolfinx.mesh.create_mesh(comm, tri, domain, x)


# --------------------------------------------------------------------------- helpers


def _initial(field_of_x: Callable[[np.ndarray], Any], x: np.ndarray, shape: tuple[int, ...],
             gdim: int = 2) -> np.ndarray:
    """An initial field ``field_of_x(x (gdim, n)) -> shape + (n,)`` at dolfinx's points x (3, n).

    Returns:
        Array of shape ``shape + (n,)``.
    """
    n = x.shape[1]
    val = np.asarray(field_of_x(x[:gdim]), dtype=np.float64)
    if val.shape == shape:
        val = val[..., None]
    return np.ascontiguousarray(np.broadcast_to(val, (*shape, n)))


class _Sampler:
    """Point evaluation of (u, p) at fixed points; every rank gets the full arrays."""

    def __init__(self, mesh: dolfinx.mesh.Mesh, points: np.ndarray):
        gdim = self.gdim = mesh.geometry.dim
        pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
        if pts.ndim != 2 or pts.shape[1] != gdim:
            raise ValueError(f"sample_points must have shape (m, {gdim}) on a {gdim}D mesh, got {np.shape(points)}")
        self.comm = mesh.comm
        m = pts.shape[0]
        self.x3 = np.zeros((m, 3), dtype=mesh.geometry.x.dtype)
        self.x3[:, :gdim] = pts
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
        m, gdim = self.x3.shape[0], self.gdim
        vals = np.zeros((m, gdim + 1), dtype=np.float64)  # [u, p] per point
        if np.any(self.mine):
            vals[self.mine, :gdim] = uh.eval(self.x3[self.mine], self.cells).reshape(-1, gdim)
            vals[self.mine, gdim] = ph.eval(self.x3[self.mine], self.cells).reshape(-1)
        if self.comm.size > 1:
            self.comm.Allreduce(MPI.IN_PLACE, vals, op=MPI.SUM)
        vals[self.missing] = np.nan
        return vals[:, gdim].copy(), vals[:, :gdim].copy()

    def field(self, f: dolfinx.fem.Function) -> np.ndarray:
        """Any Function's values at the points, shape ``(m, value size)`` (NaN where no cell holds
        a point); on a cell boundary a discontinuous field takes the value of one of its cells."""
        size = int(np.prod(f.function_space.value_shape, dtype=int))
        vals = np.zeros((self.x3.shape[0], size), dtype=np.float64)
        if np.any(self.mine):
            vals[self.mine] = f.eval(self.x3[self.mine], self.cells).reshape(-1, size)
        if self.comm.size > 1:
            self.comm.Allreduce(MPI.IN_PLACE, vals, op=MPI.SUM)
        vals[self.missing] = np.nan
        return vals


# --------------------------------------------------------------------------- the model


def _gather(comm: MPI.Comm, owned: np.ndarray) -> np.ndarray:
    """The owned parts of a distributed array, concatenated in rank order: the global array."""
    return np.concatenate(comm.allgather(np.ascontiguousarray(owned))) if comm.size > 1 else owned.copy()


def _global_matrix(form: dolfinx.fem.Form, comm: MPI.Comm) -> sp.csr_matrix:
    """A bilinear form assembled by dolfinx (PETSc AIJ, rows by owner) as one scipy CSR on every rank."""
    A = dolfinx.fem.petsc.assemble_matrix(form)
    A.assemble()
    indptr, indices, data = A.getValuesCSR()
    (lo, hi), (_, n_cols) = A.getOwnershipRange(), A.getSize()
    A.destroy()
    local = sp.csr_matrix((data, indices, indptr), shape=(hi - lo, n_cols))
    return sp.vstack(comm.allgather(local), format="csr") if comm.size > 1 else local


def _global_vector(form: dolfinx.fem.Form, comm: MPI.Comm) -> np.ndarray:
    """A linear form assembled by dolfinx as one global array on every rank."""
    b = dolfinx.fem.assemble_vector(form)
    b.scatter_reverse(dolfinx.la.InsertMode.add)
    return _gather(comm, b.array[: b.index_map.size_local * b.block_size])


def _in_order(comm: MPI.Comm, parts: list[np.ndarray]) -> np.ndarray:
    """Per-part arrays of every rank concatenated part by part, ranks in order within a part."""
    ranks = comm.allgather(parts) if comm.size > 1 else [parts]
    return np.concatenate([np.zeros(0)] + [r[i] for i in range(len(parts)) for r in ranks])


class NaturalLoads:
    """The natural conditions of a u-p model: F(t) of tractions, tested with the displacement
    space V, and Q(t) of fluxes, tested with the pressure space Q, from ``rkfx.conditions``
    ``Traction`` and ``Flux`` on boundary parts. The data are interpolated into Lagrange spaces
    on the cells next to each part (tractions of V's degree, fluxes P2), at the first
    assembly and again at every t where they are callables of t."""

    def __init__(self, mesh: dolfinx.mesh.Mesh, boundary: BoundaryParts, V: dolfinx.fem.FunctionSpace,
                 Q: dolfinx.fem.FunctionSpace, tractions: Sequence[Traction] = (), fluxes: Sequence[Flux] = ()):
        self.comm, self.boundary = mesh.comm, boundary
        self._data: list[tuple[dolfinx.fem.Function, Traction | Flux]] = []
        gdim = mesh.geometry.dim
        v, q = ufl.TestFunction(V), ufl.TestFunction(Q)
        degree = V.ufl_element().embedded_superdegree
        linear = {}
        for what, parts, space, term in (("traction", tractions, ("Lagrange", degree, (gdim,)),
                                          lambda f: ufl.inner(f, v)),
                                         ("flux", fluxes, ("Lagrange", 2), lambda f: -f * q)):
            if not parts:
                continue
            ds = ufl.Measure("ds", domain=mesh, subdomain_data=boundary.tags([b.boundary for b in parts], what))
            W = dolfinx.fem.functionspace(mesh, space)
            forms = []
            for i, bc in enumerate(parts):
                fn = dolfinx.fem.Function(W)
                self._data.append((fn, bc))
                forms.append(term(fn) * ds(i + 1))
            linear[what] = dolfinx.fem.form(sum(forms[1:], forms[0]))
        self._L_u, self._L_p = linear.get("traction"), linear.get("flux")
        self._interpolated = False

    @property
    def varies(self) -> bool:
        """Whether any load depends on t."""
        return any(callable(bc.value) for _, bc in self._data)

    def assemble(self, t: float, n_u: int, size: int) -> np.ndarray:
        """[F(t), Q(t)] over ``size`` unknowns, the first ``n_u`` the displacements (collective)."""
        for fn, bc in self._data:
            if callable(bc.value) or not self._interpolated:
                self.boundary.interpolate(fn, bc, t)
        self._interpolated = True
        f = np.zeros(size)
        if self._L_u is not None:
            f[:n_u] = _global_vector(self._L_u, self.comm)
        if self._L_p is not None:
            f[n_u:] = _global_vector(self._L_p, self.comm)
        return f


class FemBiotModel:
    """Biot's u-p equations assembled by dolfinx, as a model for the steppers of ``rkfx.solvers``.

    The unknowns, the same on every rank, are ``[u, p]`` in dolfinx's global dof numbering: u
    interleaved per node of the displacement space V (gdim components), then p per node of Q;
    both of time order 1 (u is quasi-static; its rate enters the storage equation), or u of order 2 with the
    consistent mass rho int v . u when ``density`` > 0 (u-p dynamics, eqs. 6.42-6.44). As in
    ``rkfx.models.poroelasticity.BiotModel``, C x' + r(x, t) = 0 with

        r = [K_uu u - K_up p - F(t), K_H p - Q(t)],   C(dt) = [[0, 0], [K_up^T, K_S + S(dt)]],

    K_up = int alpha div(v) p, F = int t . v ds, Q = -int (q . n) psi ds and S(dt) the FPP term
    ``M_eps - C diag(eps_f / |K|) C^T`` (``element="q1q1-fpp"``) with eps_f of the step size.
    ``fpp_form="seed"`` moves S(dt) from C into K (eq. 3.51 as printed); its step size is the
    one from the committed time, which is this model's history. The storage rows are weighted
    by -theta dt, so that backward Euler's Jacobian is the symmetric matrix of eq. 3.43.

    The blocks are assembled once (S per step size) by dolfinx into PETSc and gathered into
    scipy CSR on every rank; the loads and Dirichlet data are evaluated at t. Dirichlet
    conditions are unit rows G x = g(t) on their dofs, one row per prescribed component (a dof
    named by several conditions takes the last one's value, as dolfinx's ``set_bc``).

    Args: as :func:`solve_biot`, plus ``facet_tags`` and ``physical_groups`` (from gmsh, e.g.
        ``fem_baselines.gmsh_mesh.mesh_from_gmsh``) that let conditions name parts.
    """

    def __init__(self, mesh: dolfinx.mesh.Mesh, E: float, nu: float, k: float, alpha: float, S: float,
                 element: str, conditions: Sequence[Condition], fpp_form: str = "rate", t0: float = 0.0,
                 density: float = 0.0, facet_tags: Any = None, physical_groups: dict[str, Any] | None = None):
        if not (np.isfinite(density) and density >= 0):
            raise ValueError(f"density = {density!r} must be >= 0 (0: quasi-static)")
        self.comm, self.material, self.density = mesh.comm, (E, nu, k, alpha, S), float(density)
        gdim = self.gdim = mesh.geometry.dim
        mesh.topology.create_connectivity(mesh.topology.dim - 1, mesh.topology.dim)
        self._degree = 2 if element == "taylor-hood" else 1  # of u
        self.V = dolfinx.fem.functionspace(mesh, ("Lagrange", self._degree, (gdim,)))
        self.Q = dolfinx.fem.functionspace(mesh, ("Lagrange", 1))
        # Local (owned + ghost) dofs -> global unknowns.
        v_map, q_map = self.V.dofmap.index_map, self.Q.dofmap.index_map
        v_nodes = v_map.local_to_global(np.arange(v_map.size_local + v_map.num_ghosts, dtype=np.int32))
        self._n_u = gdim * v_map.size_global
        self.u_index = (gdim * v_nodes[:, None] + np.arange(gdim)).ravel()
        self.p_index = self._n_u + q_map.local_to_global(np.arange(q_map.size_local + q_map.num_ghosts,
                                                                   dtype=np.int32))
        self.layout = FieldLayout((Field("u", gdim, 2 if density > 0 else 1, v_map.size_global),
                                   Field("p", 1, 1, q_map.size_global)))
        self.linear = True
        self.fpp = element == "q1q1-fpp"
        self.seed = self.fpp and fpp_form == "seed"
        kinds = check_kinds(conditions, (Displacement, Pressure, Traction, Flux), "the Biot FEM", gdim=gdim)
        self.boundary = BoundaryParts(mesh, facet_tags, physical_groups)
        self._assemble(mesh)
        self._natural = NaturalLoads(mesh, self.boundary, self.V, self.Q, kinds[Traction], kinds[Flux])
        self._essential_conditions(mesh, kinds[Displacement] + kinds[Pressure])
        self._t = float(t0)  # committed time (the seed form's step starts there)
        self._t_trial = self._t
        self._at: dict[str, tuple[float, Any]] = {}  # loads and constraints at the last t
        self._per_step = PerStepSize(keep=4)

    def _assemble(self, mesh: dolfinx.mesh.Mesh) -> None:
        """K, C without FPP, and what FPP needs per step size."""
        E, nu, k, alpha, S = self.material
        comm, n_u = self.comm, self._n_u

        def constant(value):  # a Constant, not a literal: one compiled form for all parameters
            return dolfinx.fem.Constant(mesh, dolfinx.default_scalar_type(value))

        sigma = stress_law(mesh, ElasticMaterial(E, nu))
        u, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        p, q = ufl.TrialFunction(self.Q), ufl.TestFunction(self.Q)
        dx = ufl.dx(domain=mesh)
        kuu = _global_matrix(dolfinx.fem.form(ufl.inner(sigma(u), strain(v)) * dx), comm)
        kup = _global_matrix(dolfinx.fem.form(constant(alpha) * p * ufl.div(v) * dx), comm)
        kh = _global_matrix(dolfinx.fem.form(constant(k) * ufl.inner(ufl.grad(p), ufl.grad(q)) * dx), comm)
        n_p = kh.shape[0]
        ks = _global_matrix(dolfinx.fem.form(constant(S) * p * q * dx), comm) if S > 0 else sp.csr_matrix((n_p, n_p))
        self._K = sp.bmat([[kuu, -kup], [None, kh]], format="csr")
        self._C = sp.bmat([[sp.csr_matrix((n_u, n_u)), None], [kup.T, ks]], format="csr")
        self._M = None
        if self.density > 0:  # consistent mass of the mixture on u (eq. 6.44)
            muu = _global_matrix(dolfinx.fem.form(constant(self.density) * ufl.inner(u, v) * dx), comm)
            self._M = sp.bmat([[muu, None], [None, sp.csr_matrix((n_p, n_p))]], format="csr")
        if self.fpp:
            DG0 = dolfinx.fem.functionspace(mesh, ("DG", 0))
            self._eps_f = dolfinx.fem.Function(DG0, name="eps_f")
            mu0 = ufl.TestFunction(DG0)
            self._ct = _global_matrix(dolfinx.fem.form(p * mu0 * dx), comm)  # (cells, Q dofs)
            area = dolfinx.fem.assemble_vector(dolfinx.fem.form(mu0 * dx))
            area.scatter_reverse(dolfinx.la.InsertMode.add)
            area.scatter_forward()
            self._cell_area = area.array.copy()  # owned + ghost cells [m^2] (volumes [m^3] in 3-D)
            self._cell_area_global = _gather(comm, self._cell_area[: DG0.dofmap.index_map.size_local])
            self._m_eps = dolfinx.fem.form(self._eps_f * p * q * dx)

    def _essential_conditions(self, mesh: dolfinx.mesh.Mesh, essential: Sequence[Displacement | Pressure]) -> None:
        """Unit rows G on the owned dofs of each Dirichlet condition, data evaluated at their coordinates."""
        fdim, gdim = mesh.topology.dim - 1, self.gdim
        self._dirichlet = []  # (condition, coordinates (m, gdim), global rows (m,), value column (m,)) of each
        v_owned, q_owned = gdim * self.V.dofmap.index_map.size_local, self.Q.dofmap.index_map.size_local
        v_points, q_points = self.V.tabulate_dof_coordinates(), self.Q.tabulate_dof_coordinates()
        for bc in essential:
            facets = self.boundary.facets(bc.boundary)
            if isinstance(bc, Displacement):  # the rows of every component, component by component
                dofs = [dolfinx.fem.locate_dofs_topological(self.V.sub(c), fdim, facets) for c in bc.prescribed(gdim)]
                dofs = [d[d < v_owned] for d in dofs]  # unrolled
                column = np.concatenate([np.full(d.size, j) for j, d in enumerate(dofs)])
                dofs = np.concatenate(dofs)
                self._dirichlet.append((bc, v_points[dofs // gdim, :gdim], self.u_index[dofs], column))
            else:
                dofs = dolfinx.fem.locate_dofs_topological(self.Q, fdim, facets)
                dofs = dofs[dofs < q_owned]
                self._dirichlet.append((bc, q_points[dofs, :gdim], self.p_index[dofs], np.zeros(dofs.size, int)))
        rows = _in_order(self.comm, [r for _, _, r, _ in self._dirichlet]).astype(np.int64)
        self._bc_rows, last = np.unique(rows[::-1], return_index=True)
        self._bc_last = len(rows) - 1 - last  # where each constrained dof's value stands in the gathered list
        k = len(self._bc_rows)
        self._G = sp.csr_matrix((np.ones(k), (np.arange(k), self._bc_rows)), shape=(k, self.layout.size))
        self._bc_values = [None] * len(self._dirichlet)  # on the owned dofs, at the last t

    # ------------------------------------------------------------------ fields

    @property
    def num_constraints(self) -> int:
        return self._G.shape[0]

    def vector(self, uh: dolfinx.fem.Function, ph: dolfinx.fem.Function) -> np.ndarray:
        """The global unknowns of (u_h, p_h)."""
        n_v, n_q = self.V.dofmap.index_map.size_local, self.Q.dofmap.index_map.size_local
        return np.concatenate([_gather(self.comm, uh.x.array[: self.gdim * n_v]),
                               _gather(self.comm, ph.x.array[:n_q])])

    def assign(self, x: np.ndarray, uh: dolfinx.fem.Function, ph: dolfinx.fem.Function) -> None:
        """(u_h, p_h), ghosts included, from the global unknowns."""
        uh.x.array[:] = x[self.u_index]
        ph.x.array[:] = x[self.p_index]

    # ------------------------------------------------------------------ data at t

    def _cached(self, what: str, t: float, varies: bool, build):
        hit = self._at.get(what)
        if hit is None or (varies and hit[0] != t):
            hit = self._at[what] = (t, build(t))
        return hit[1]

    def loads(self, t: float) -> np.ndarray:
        """[F(t), Q(t)], shape ``(size,)``."""
        return self._cached("loads", t, self._natural.varies,
                            lambda t: self._natural.assemble(t, self._n_u, self.layout.size))

    def constraints(self, t: float) -> Constraints:
        def build(t):
            self._bc_values = [values(bc, x, t)[np.arange(len(x)), column] if callable(bc.value) or old is None
                               else old for (bc, x, _, column), old in zip(self._dirichlet, self._bc_values)]
            return Constraints(self._G, _in_order(self.comm, self._bc_values)[self._bc_last])

        return self._cached("constraints", t, any(callable(bc.value) for bc, _, _, _ in self._dirichlet), build)

    # ------------------------------------------------------------------ matrices

    def stabilization(self, dt: float) -> sp.csr_matrix:
        """The FPP matrix S = M_eps - C diag(eps_f / |K|) C^T for steps of dt, shape ``(n_p, n_p)``."""
        # h of eq. 3.53: sqrt(area) in 2-D, cbrt(volume) in 3-D (the cell's edge length either way)
        size = np.sqrt if self.gdim == 2 else np.cbrt

        def build(dt):
            poro = PoroMaterial(*self.material)  # eps_f of eq. 3.53
            self._eps_f.x.array[:] = fpp_parameter(poro, dt, size(self._cell_area))
            eps = fpp_parameter(poro, dt, size(self._cell_area_global))
            projection = self._ct.T @ sp.diags(eps / self._cell_area_global) @ self._ct
            return (_global_matrix(self._m_eps, self.comm) - projection).tocsr()

        return self._per_step.get("fpp", dt, build)

    def _on_pressure(self, a: sp.csr_matrix) -> sp.csr_matrix:
        """A p-p block as a matrix over all unknowns."""
        a = sp.csr_matrix(a)
        return sp.csr_matrix((a.data, a.indices + self._n_u, np.r_[np.zeros(self._n_u, a.indptr.dtype), a.indptr]),
                             shape=(self.layout.size, self.layout.size))

    def tangent(self, x: np.ndarray, t: float) -> sp.csr_matrix:
        if not self.seed:
            return self._K
        return self._per_step.get("K", t - self._t, lambda dt: self._K + self._on_pressure(self.stabilization(dt)))

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        self._t_trial = t
        return self.tangent(x, t) @ x - self.loads(t)

    def mass(self) -> sp.csr_matrix | None:
        """rho int v . u over [u, p] (``density`` > 0), else ``None`` (quasi-static)."""
        return self._M

    def capacity(self, dt: float) -> sp.csr_matrix:
        if not self.fpp or self.seed:
            return self._C
        return self._per_step.get("C", dt, lambda dt: self._C + self._on_pressure(self.stabilization(dt)))

    def equation_weights(self, co) -> np.ndarray:
        """-1 / (dp'/dp) on the storage rows: the symmetric Jacobian of eq. 3.43."""
        return self._per_step.get("W", co.dt, lambda dt: np.r_[np.ones(self._n_u),
                                                       np.full(self.layout.size - self._n_u, -1.0 / co.dv[-1])])

    # ------------------------------------------------------------------ history

    def commit(self) -> None:
        self._t = self._t_trial

    def state(self) -> dict[str, np.ndarray]:
        return {"t": np.float64(self._t)}

    def restore(self, arrays) -> None:
        self._t = self._t_trial = float(arrays["t"])


class _Samples:
    """Point values of (u, p) at the output steps, for ``rkfx.solvers.integrate``."""

    def __init__(self, model: FemBiotModel, sampler: _Sampler, steps: np.ndarray,
                 uh: dolfinx.fem.Function, ph: dolfinx.fem.Function, vtk=None):
        self.model, self.sampler, self.steps, self.uh, self.ph = model, sampler, steps, uh, ph
        self.vtk = vtk
        m = sampler.x3.shape[0]
        self.p = np.full((len(steps), m), np.nan)
        self.u = np.full((len(steps), m, sampler.gdim), np.nan)
        self.seconds = 0.0

    def record(self, s: StepState) -> None:
        t0 = time.perf_counter()
        for j in np.flatnonzero(self.steps == s.step):
            self.model.assign(s.x, self.uh, self.ph)
            self.p[j], self.u[j] = self.sampler(self.uh, self.ph)
            if self.vtk is not None:
                self.vtk.write(s.t, displacement=self.uh, pressure=self.ph)
        self.seconds += time.perf_counter() - t0

    def arrays(self) -> dict[str, np.ndarray]:
        return {"p": self.p, "u": self.u}

    def restore(self, arrays) -> None:
        self.p[...] = arrays["p"]
        self.u[...] = arrays["u"]


# --------------------------------------------------------------------------- solver


def solve_biot(
    mesh: dolfinx.mesh.Mesh | dolfinx.io.gmsh.MeshData,
    E: float,
    nu: float,
    k: float,
    alpha: float,
    S: float,
    element: str,
    conditions: Sequence[Condition],
    times: np.ndarray,
    sample_points: np.ndarray,
    output_times: np.ndarray,
    comm: MPI.Comm | None = None,
    initial_u: Callable[[np.ndarray], np.ndarray] | None = None,
    initial_p: Callable[[np.ndarray], np.ndarray] | None = None,
    fpp_form: str = "rate",
    checkpoint_every: int = 0,
    checkpoint_dir: str | Path | None = None,
    resume: str | Path | None = None,
    vtk=None,
    progress: Callable | None = None,
    density: float = 0.0,
    stepper: Newmark | None = None,
) -> BiotResult:
    """Solve Biot consolidation (plane strain or 3-D) with backward Euler and a monolithic u-p solve.

    Collective on the mesh communicator. Boundaries not mentioned in ``conditions`` are traction-free
    and impermeable. The :class:`FemBiotModel` is stepped by ``rkfx.solvers.integrate`` with
    ``backward_euler()``: one Newton iteration per step, one MUMPS factorisation per distinct
    time step.

    Args:
        mesh: A 2D dolfinx mesh (e.g. from :func:`rectangle_mesh`), triangles or quadrilaterals;
            or a 3D one of tetrahedra; or the ``MeshData`` of a gmsh model (2D or 3D) from
            ``fem_baselines.gmsh_mesh.mesh_from_gmsh`` / ``build_mesh``, whose physical names
            then name boundary parts.
        E: Drained Young's modulus [Pa].
        nu: Drained Poisson's ratio [-] (< 0.5).
        k: Mobility k_h / gamma_f [m^2/(Pa s)].
        alpha: Biot coefficient [-].
        S: Storage coefficient 1/Q [1/Pa]; 0 for incompressible constituents.
        element: ``"taylor-hood"`` (P2-P1 / Q2-Q1), ``"q1q1"`` (equal order, unstabilised) or
            ``"q1q1-fpp"`` (equal order with fluid pressure projection, eqs. 3.49-3.54).
        conditions: Boundary conditions of ``rkfx.conditions``: ``Displacement`` (a row per
            listed component, components below gdim), ``Pressure``, ``Traction`` (total
            traction) and ``Flux`` (outward normal flux). Parts are physical-group names (gmsh
            ``MeshData``), facet tags, the sides of the mesh's bounding box (``"left"``,
            ``"right"``, ``"bottom"``, ``"top"`` in 2-D; ``"left"``/``"right"``,
            ``"front"``/``"back"``, ``"bottom"``/``"top"`` along x, y, z in 3-D) or markers
            ``x (m, gdim) -> bool`` (see ``fem_baselines.conditions``). Functions of x and t (of
            x, t and n for tractions and fluxes), with x and n of shape (m, gdim), are evaluated
            at t_{n+1} in step n+1.
        times: Time levels t_0 < t_1 < ... < t_N, shape (N+1,) [s]; the initial state is at t_0.
        sample_points: Points where fields are sampled, shape (m, gdim) [m].
        output_times: Times at which to sample, each exactly equal to an entry of ``times``,
            shape (n_out,) [s].
        comm: Unused beyond a consistency check (the mesh's communicator is used); kept for the
            house signature.
        initial_u: Initial displacement ``u0(x) -> (gdim, n)`` with x of shape (gdim, n); default 0.
        initial_p: Initial pressure ``p0(x) -> (n,)`` with x of shape (gdim, n); default 0.
        fpp_form: ``"rate"`` (default, as in ``rkfx.models.poroelasticity``): ``-S`` acting on
            ``P_n+1 - P_n`` (White & Borja's form, stabilising the pressure rate; dimensionally
            consistent with eps_f in 1/Pa); ``"seed"``: ``-dt S`` in the p-p block as eq. 3.51
            is printed, which depends on the unit of time (kept for comparison). Ignored unless
            ``element == "q1q1-fpp"``.
        checkpoint_every, checkpoint_dir: Write a checkpoint (state and samples so far) every
            so many steps, and at the last one, into the folder. Every rank writes the whole
            state: under MPI give each rank a folder of its own.
        resume: A checkpoint folder to continue from (same mesh, data and times); the result
            equals that of an uninterrupted run.
        vtk: A ``fem_baselines.paraview.FemSeries`` on ``mesh`` that receives u and p at the
            output times (a resumed run writes the times after its checkpoint), or ``None``.
        progress: Optional wrapper of the step iterator (a progress bar).
        density: Mixture density rho [kg/m^3]; > 0 adds the inertia of the skeleton (u of
            time order 2, consistent mass), 0 (default) is quasi-static consolidation.
        stepper: The time stepper; default backward Euler when quasi-static, the trapezoid
            (Newmark beta = 1/4, gamma = 1/2, theta = 1/2) with inertia. The initial
            acceleration follows from the loads at times[0].

    Returns:
        The sampled history and final fields; see :class:`BiotResult`.

    Raises:
        ValueError: On inconsistent input (``rkfx.errors.InputError`` for the conditions).
        rkfx.errors.SolverError: If a linear solve fails.
    """
    t_start = time.perf_counter()
    mesh, facet_tags, physical_groups = mesh_parts(mesh)
    if comm is not None and comm.size != mesh.comm.size:
        raise ValueError("comm must be the mesh's communicator")
    comm = mesh.comm
    if element not in ELEMENTS:
        raise ValueError(f"element must be one of {ELEMENTS}, got {element!r}")
    if fpp_form not in ("seed", "rate"):
        raise ValueError(f"fpp_form must be 'seed' or 'rate', got {fpp_form!r}")
    gdim = mesh.geometry.dim
    if gdim not in (2, 3) or mesh.topology.dim != gdim:
        raise ValueError(f"solve_biot expects a 2D or 3D mesh whose cells fill it (gdim = tdim), got gdim {gdim} "
                         f"and tdim {mesh.topology.dim}")
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

    model = FemBiotModel(mesh, E, nu, k, alpha, S, element, conditions, fpp_form, t0=float(times[0]),
                         density=density, facet_tags=facet_tags, physical_groups=physical_groups)
    if stepper is None:
        stepper = backward_euler() if density == 0 else Newmark(beta=0.25, gamma=0.5, theta=0.5)
    uh = dolfinx.fem.Function(model.V, name="u")
    ph = dolfinx.fem.Function(model.Q, name="p")
    if initial_u is not None:
        uh.interpolate(lambda x: _initial(initial_u, x, (gdim,), gdim))
    if initial_p is not None:
        ph.interpolate(lambda x: _initial(initial_p, x, (), gdim))
    n = model.layout.size
    start = stepper.start(model, model.vector(uh, ph), t0=float(times[0]), comm=comm)
    kept = _Samples(model, _Sampler(mesh, sample_points), out_index, uh, ph, vtk)
    kept.record(start)
    t_setup, sampled = time.perf_counter() - t_start, kept.seconds

    solves = Factorizations(comm, "mumps", keep=2, mumps_icntl=_MUMPS_ICNTL if gdim == 2 else _MUMPS_ICNTL_3D,
                            reuse_analysis=True)
    try:
        run = integrate(stepper, model, times, start=start, recorder=kept, solves=solves, max_cuts=0,
                        checkpoint_every=checkpoint_every, checkpoint_dir=checkpoint_dir, resume=resume,
                        progress=progress)
    finally:
        solves.destroy()
    model.assign(run.state.x, uh, ph)

    t_sample = kept.seconds - sampled
    local = np.array([t_setup, run.wall_time_s - t_sample, t_sample, time.perf_counter() - t_start])
    glob = np.empty_like(local)
    comm.Allreduce(local, glob, op=MPI.MAX)
    return BiotResult(
        output_times=output_times.copy(),
        p=kept.p,
        u=kept.u,
        n_dofs=n,
        wall_time_s=float(glob[3]),
        mesh=mesh,
        u_h=uh,
        p_h=ph,
        element=element,
        n_steps=len(times) - 1,
        n_factorizations=run.factorizations,
        timings=dict(zip(("setup", "steps", "sample"), map(float, glob[:3]))),
    )
