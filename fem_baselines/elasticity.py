"""Linear elasticity with dolfinx, plane strain (2-D) and 3-D: the FEM baseline for RKPM runs.

The geometry is the one the RKPM solvers use: a gmsh model with one physical group
of the top dimension for the domain and groups one dimension lower naming boundary
parts -- a 2D model of triangles, or a 3D solid of tetrahedra from
``rkfx.geometry.gmsh_solids``. The model is converted with
:func:`dolfinx.io.gmsh.model_to_mesh` (read on rank 0, distributed over ``comm``;
``fem_baselines.gmsh_mesh``), then the problem

    -div sigma(u) = f   in Omega,
    u_c = g_c           on Gamma_D (the listed components c),
    sigma(u) n = t      on Gamma_N,

is solved with vector Lagrange P``degree`` elements on triangles
(:func:`solve_plane_strain`) or tetrahedra (:func:`solve_elasticity_3d`) and a
direct MUMPS LU factorisation, with the law ``sigma = lambda tr(eps) I + 2 mu eps``:
in 2-D lambda and mu of the plane-strain law of
:class:`rkfx.materials.elasticity.ElasticMaterial` (the law of the RKPM solvers),
in 3-D the Lame constants of the same isotropic solid (:func:`stress_law`).
:func:`errors` measures L2, H1 and energy errors against an exact displacement.

Boundary conditions are ``Displacement`` and ``Traction`` of ``rkfx.conditions``,
the RKPM solvers' vocabulary; ``fem_baselines.conditions`` resolves their parts
and evaluates their values on the dolfinx mesh.

Units are whatever the caller uses consistently (e.g. m, Pa, N/m^3); the
module never rescales anything.

The other dolfinx-specific calls of the elastic FEM baseline live in this module
(and in :mod:`fem_baselines.assembly_timing`). Importing it has no side effects
beyond importing dolfinx (``dolfinx_solver`` is imported first, as it must be).
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import numpy as np
from mpi4py import MPI

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.geometry
import dolfinx.io.gmsh
import dolfinx.mesh
import ufl

from fem_baselines.conditions import BoundaryParts, check_kinds
from fem_baselines.gmsh_mesh import mesh_from_gmsh, mesh_parts
from rkfx.conditions import Condition, Displacement, Traction
from rkfx.materials.elasticity import ElasticMaterial

__all__ = [
    "FemElasticityResult",
    "errors",
    "solve_elasticity_3d",
    "solve_plane_strain",
    "strain",
    "stress_law",
]

#: A vector field given as a callable ``g(x)``, ``x`` of shape (gdim, npts),
#: returning shape (gdim, npts) (or (gdim,) for a constant), or as a constant
#: array-like of shape (gdim,).
VectorData = Callable[[np.ndarray], np.ndarray] | Any

_prefix_counter = itertools.count()

_MUMPS_OPTIONS = {
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
    "ksp_error_if_not_converged": True,
}


def strain(w):
    """Small strain eps(w) = sym(grad w) of a UFL vector field."""
    return ufl.sym(ufl.grad(w))


def _law_of_strain(mesh: dolfinx.mesh.Mesh, material: ElasticMaterial) -> Callable:
    """``sigma(eps) = lambda tr(eps) I + 2 mu eps`` of a UFL strain, as :func:`stress_law` sets it up."""
    scalar = dolfinx.default_scalar_type
    gdim = mesh.geometry.dim
    # 2-D: the plane law (plane strain or plane stress); 3-D: the solid's own Lame constants.
    lam_v, mu_v = material.lame if gdim == 2 else (material.lame_lambda, material.shear_modulus)
    lam = dolfinx.fem.Constant(mesh, scalar(lam_v))
    mu = dolfinx.fem.Constant(mesh, scalar(mu_v))

    def law(eps):
        return lam * ufl.tr(eps) * ufl.Identity(gdim) + 2.0 * mu * eps

    return law


def stress_law(mesh: dolfinx.mesh.Mesh, material: ElasticMaterial) -> Callable:
    """The law ``sigma(w) = lambda tr(eps(w)) I + 2 mu eps(w)`` of ``material`` in UFL.

    On a 2-D mesh lambda and mu are :attr:`rkfx.materials.elasticity.ElasticMaterial.lame`
    (plane strain or plane stress); on a 3-D mesh they are the Lame constants of the isotropic
    solid, ``material.lame_lambda`` and ``material.shear_modulus`` (``material.plane`` plays no
    part). They are dolfinx Constants on ``mesh``: forms built with other values share one
    compiled kernel.

    Returns:
        ``sigma(w)``: the stress tensor (gdim x gdim UFL expression) of a vector field ``w`` [Pa].
    """
    law = _law_of_strain(mesh, material)

    def sigma(w):
        return law(strain(w))

    return sigma


@dataclass
class FemElasticityResult:
    """Solution of an elastic FEM baseline (plane strain or 3-D).

    Attributes:
        mesh: The distributed dolfinx mesh (triangles, gdim 2, or tetrahedra, gdim 3).
        u: Displacement, a dolfinx vector P``degree`` Function on ``mesh``
            (ghost values up to date).
        n_dofs: Global number of scalar degrees of freedom (gdim per node).
        wall_time_s: Wall-clock seconds of the whole call (mesh conversion,
            setup incl. form JIT, assembly and solve), max over ranks.
        degree: Polynomial degree of the elements.
        timings: Wall-clock breakdown (max over ranks) with keys ``"mesh"``
            (gmsh -> dolfinx), ``"setup"`` (spaces, data interpolation, BCs,
            form compilation) and ``"solve"`` (assembly, LU factorisation,
            solve), all in seconds.
        facet_tags: Facet MeshTags from gmsh, or None.
        physical_groups: Physical-group name -> (dim, tag) from gmsh
            (empty for a bare mesh).
        material: The elastic solid (for the energy norm of :func:`errors`),
            or None.
    """

    mesh: dolfinx.mesh.Mesh
    u: dolfinx.fem.Function
    n_dofs: int
    wall_time_s: float
    degree: int = 1
    timings: dict[str, float] = field(default_factory=dict)
    facet_tags: Any = None
    physical_groups: dict[str, Any] = field(default_factory=dict)
    material: ElasticMaterial | None = None
    _tree: Any = field(default=None, init=False, repr=False)

    @property
    def comm(self) -> MPI.Comm:
        """MPI communicator of the mesh."""
        return self.mesh.comm

    def evaluate(self, points: np.ndarray) -> np.ndarray:
        """Evaluate the displacement at arbitrary points.

        Collective: every rank must call it with the same points, and every
        rank gets the full result. A point found in cells of several ranks
        takes the value of the lowest such rank.

        Args:
            points: Coordinates, shape (npts, gdim) (a single point of shape
                (gdim,) is accepted; in 2-D also (npts, 3) with z ignored), in
                mesh length units.

        Returns:
            Displacements, shape (npts, gdim); rows of points lying in no cell
            of the mesh are NaN.
        """
        gdim = self.mesh.geometry.dim
        pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
        if pts.ndim != 2 or pts.shape[1] not in (gdim, 3):
            raise ValueError(f"points must have shape (npts, {gdim}), got {np.shape(points)}")
        npts = pts.shape[0]
        x3 = np.zeros((npts, 3), dtype=self.mesh.geometry.x.dtype)
        x3[:, : pts.shape[1]] = pts
        x3[:, gdim:] = 0.0

        tdim = self.mesh.topology.dim
        if self._tree is None:
            self._tree = dolfinx.geometry.bb_tree(self.mesh, tdim)
        candidates = dolfinx.geometry.compute_collisions_points(self._tree, x3)
        colliding = dolfinx.geometry.compute_colliding_cells(self.mesh, candidates, x3)
        offsets = np.asarray(colliding.offsets)
        found = np.diff(offsets) > 0

        comm = self.comm
        rank, size = comm.rank, comm.size
        owner = np.where(found, rank, size).astype(np.int32)
        if size > 1:
            comm.Allreduce(MPI.IN_PLACE, owner, op=MPI.MIN)
        mine = owner == rank

        values = np.zeros((npts, gdim), dtype=np.float64)
        if np.any(mine):
            cells = np.asarray(colliding.array)[offsets[:-1][mine]]
            values[mine] = self.u.eval(x3[mine], cells).reshape(-1, gdim)
        if size > 1:
            comm.Allreduce(MPI.IN_PLACE, values, op=MPI.SUM)
        values[owner == size] = np.nan
        return values


def _vector_values(data: VectorData, x: np.ndarray, gdim: int = 2) -> np.ndarray:
    """Evaluate vector data at dolfinx interpolation points.

    Args:
        data: Callable of x (gdim, npts) or constant array-like of shape (gdim,).
        x: Interpolation points from dolfinx, shape (3, npts).
        gdim: Geometric dimension (components of the field, rows of x passed on).

    Returns:
        Array of shape (gdim, npts).
    """
    npts = x.shape[1]
    val = np.asarray(data(x[:gdim]) if callable(data) else data, dtype=np.float64)
    if val.shape == (gdim,):
        val = val[:, None]
    try:
        return np.ascontiguousarray(np.broadcast_to(val, (gdim, npts)))
    except ValueError:
        raise ValueError(f"body_force gave shape {val.shape} for {npts} points; return ({gdim}, npts) for x of "
                         f"shape ({gdim}, npts), or give a constant of shape ({gdim},)") from None


def _to_mesh_data(model_or_mesh: Any, comm: MPI.Comm, gdim: int = 2):
    """Normalise the geometry argument to (mesh, facet_tags, physical_groups)."""
    if isinstance(model_or_mesh, (dolfinx.io.gmsh.MeshData, dolfinx.mesh.Mesh)):
        return mesh_parts(model_or_mesh)
    # A gmsh model (the ``gmsh.model`` module object); only rank 0 reads it.
    return mesh_parts(mesh_from_gmsh(model_or_mesh, comm, gdim))


def solve_plane_strain(
    model_or_mesh: Any,
    E: float,
    nu: float,
    conditions: Sequence[Condition],
    body_force: VectorData | None = None,
    degree: int = 1,
    comm: MPI.Comm | None = None,
) -> FemElasticityResult:
    """Solve plane-strain linear elasticity with vector Lagrange elements.

    Collective on ``comm``.

    Args:
        model_or_mesh: The geometry: the ``gmsh.model`` module object of a
            model already meshed in 2D (triangles) with one 2D physical group
            for the domain and 1D physical groups naming boundary parts (only
            rank 0 needs the model; it is distributed over ``comm``); or a
            :class:`dolfinx.io.gmsh.MeshData` already converted; or a bare
            :class:`dolfinx.mesh.Mesh` (boundaries then given by the sides of
            its bounding box or by markers).
        E: Young's modulus (stress units, e.g. Pa).
        nu: Poisson's ratio (dimensionless, < 0.5).
        conditions: ``rkfx.conditions.Displacement`` (the listed components;
            one component is a roller) and ``rkfx.conditions.Traction`` objects,
            evaluated at t = 0: values are constants or ``value(x, t)``
            (displacements, length units) and ``value(x, t, n)`` (tractions,
            stress units), x and the outward unit normals n of shape
            (m, 2). Parts are physical-group names, facet tags (int), sides of
            the bounding box or markers ``x (m, 2) -> bool`` (see
            ``fem_baselines.conditions``); traction parts must be disjoint.
            Boundaries without conditions are traction-free.
        body_force: Body force per unit volume ``f(x)``, x of shape (2, npts),
            returning shape (2, npts) (or a constant of shape (2,)), e.g. N/m^3.
            None for no body force.
        degree: Polynomial degree of the displacement elements (>= 1).
        comm: MPI communicator; defaults to ``MPI.COMM_WORLD``. Ignored for
            an already-built mesh (its communicator is used).

    Returns:
        The solution; see :class:`FemElasticityResult`.

    Note:
        Tractions and body forces are interpolated into a vector Lagrange
        space of degree ``degree + 1`` (so that data interpolation does not
        limit the convergence rate), tractions on the cells next to their
        parts only; Dirichlet data is interpolated into the solution space
        on the cells next to its part. E and nu enter the forms as dolfinx
        Constants, so changing them does not trigger a new form compilation.
    """
    return _solve(model_or_mesh, E, nu, conditions, body_force, degree, comm, gdim=2, name="solve_plane_strain")


def solve_elasticity_3d(
    model_or_mesh: Any,
    E: float,
    nu: float,
    conditions: Sequence[Condition],
    degree: int = 1,
    body_force: VectorData | None = None,
    comm: MPI.Comm | None = None,
) -> FemElasticityResult:
    """Solve 3-D linear elasticity with vector Lagrange elements on tetrahedra.

    Collective on ``comm``. The law is sigma = lambda tr(eps) I + 2 mu eps with the Lame
    constants of the isotropic solid (E, nu). Everything else is as in
    :func:`solve_plane_strain`, one dimension up.

    Args:
        model_or_mesh: The geometry: a ``gmsh.model`` meshed in 3-D with tetrahedra, a 3-D
            physical group for the solid and 2-D groups naming boundary parts (e.g. built by
            ``rkfx.geometry.gmsh_solids``; only rank 0 needs it); or its ``MeshData`` from
            ``fem_baselines.gmsh_mesh.mesh_from_gmsh`` / ``build_mesh``; or a bare tetrahedral
            :class:`dolfinx.mesh.Mesh` (parts are then the sides ``left``/``right``,
            ``front``/``back``, ``bottom``/``top`` of its bounding box, or markers).
        E: Young's modulus [Pa].
        nu: Poisson's ratio [-] (< 0.5).
        conditions: ``Displacement`` (the listed components among 0, 1, 2; one component is a
            roller) and ``Traction`` of ``rkfx.conditions``, evaluated at t = 0; x and the
            outward unit normals n of shape (m, 3) [m]. Traction parts must be disjoint.
            Boundaries without conditions are traction-free.
        degree: Polynomial degree of the displacement elements (1: P1, 2: P2, ...).
        body_force: Body force per unit volume ``f(x)`` [N/m^3], x of shape (3, npts),
            returning shape (3, npts), or a constant of shape (3,); None for none.
        comm: MPI communicator; defaults to ``MPI.COMM_WORLD``. Ignored for an already-built
            mesh (its communicator is used).

    Returns:
        The solution; see :class:`FemElasticityResult` (``u`` of 3 components, ``evaluate``
        at points (npts, 3), ``material`` set for the energy norm of :func:`errors`).
    """
    return _solve(model_or_mesh, E, nu, conditions, body_force, degree, comm, gdim=3, name="solve_elasticity_3d")


#: The cells each solver takes.
_CELLS = {2: (dolfinx.mesh.CellType.triangle, "a 2D triangle mesh (gdim 2)"),
          3: (dolfinx.mesh.CellType.tetrahedron, "a 3D tetrahedral mesh (gdim 3)")}


def _solve(model_or_mesh: Any, E: float, nu: float, conditions: Sequence[Condition], body_force: VectorData | None,
           degree: int, comm: MPI.Comm | None, gdim: int, name: str) -> FemElasticityResult:
    """The elastic solve of :func:`solve_plane_strain` (gdim 2) and :func:`solve_elasticity_3d` (gdim 3)."""
    if degree < 1:
        raise ValueError(f"degree must be >= 1, got {degree}")
    comm = MPI.COMM_WORLD if comm is None else comm
    t_start = time.perf_counter()

    mesh, facet_tags, physical_groups = _to_mesh_data(model_or_mesh, comm, gdim)
    comm = mesh.comm
    cell, what = _CELLS[gdim]
    if mesh.geometry.dim != gdim or mesh.topology.cell_type != cell:
        raise ValueError(f"{name} expects {what}")
    tdim = mesh.topology.dim
    fdim = tdim - 1
    mesh.topology.create_connectivity(fdim, tdim)
    t_mesh = time.perf_counter()

    V = dolfinx.fem.functionspace(mesh, ("Lagrange", degree, (gdim,)))
    W = dolfinx.fem.functionspace(mesh, ("Lagrange", degree + 1, (gdim,)))
    scalar = dolfinx.default_scalar_type

    # Dirichlet conditions: all components on V, one component (a roller) on its subspace.
    kinds = check_kinds(conditions, (Displacement, Traction), name, gdim=gdim)
    parts = BoundaryParts(mesh, facet_tags, physical_groups)
    bcs = []
    for c in kinds[Displacement]:
        facets = parts.facets(c.boundary)
        components = c.prescribed(gdim)
        if len(components) == 1:
            comp = components[0]
            Vc, _ = V.sub(comp).collapse()
            gc = dolfinx.fem.Function(Vc)
            parts.interpolate(gc, c, 0.0)
            dofs = dolfinx.fem.locate_dofs_topological((V.sub(comp), Vc), fdim, facets)
            bcs.append(dolfinx.fem.dirichletbc(gc, dofs, V.sub(comp)))
        else:  # the unlisted components of the value are 0 on V and are not prescribed
            gv = dolfinx.fem.Function(V)
            parts.interpolate(gv, c, 0.0)
            if len(components) == gdim:
                dofs = dolfinx.fem.locate_dofs_topological(V, fdim, facets)
                bcs.append(dolfinx.fem.dirichletbc(gv, dofs))
            else:  # two components of three: each a roller with its part of gv
                for comp in components:
                    Vc, to_parent = V.sub(comp).collapse()
                    gc = dolfinx.fem.Function(Vc)
                    gc.x.array[:] = gv.x.array[to_parent]
                    dofs = dolfinx.fem.locate_dofs_topological((V.sub(comp), Vc), fdim, facets)
                    bcs.append(dolfinx.fem.dirichletbc(gc, dofs, V.sub(comp)))

    # Constitutive law (Constants: no recompilation for new E, nu).
    material = ElasticMaterial(E, nu)
    sigma = stress_law(mesh, material)

    u = ufl.TrialFunction(V)
    v = ufl.TestFunction(V)
    a = ufl.inner(sigma(u), strain(v)) * ufl.dx

    rhs = []
    if body_force is not None:
        f = dolfinx.fem.Function(W, name="body_force")
        f.interpolate(lambda x: _vector_values(body_force, x, gdim))
        rhs.append(ufl.inner(f, v) * ufl.dx)
    if kinds[Traction]:
        tags = parts.tags([c.boundary for c in kinds[Traction]], "traction")
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=tags)
        for i, c in enumerate(kinds[Traction]):
            t = dolfinx.fem.Function(W, name=f"traction_{i}")
            parts.interpolate(t, c, 0.0)
            rhs.append(ufl.inner(t, v) * ds(i + 1))
    if rhs:
        L = sum(rhs[1:], rhs[0])
    else:
        L = ufl.inner(dolfinx.fem.Constant(mesh, np.zeros(gdim, dtype=scalar)), v) * ufl.dx

    uh = dolfinx.fem.Function(V, name="u")
    problem = dolfinx.fem.petsc.LinearProblem(
        a,
        L,
        bcs=bcs,
        u=uh,
        petsc_options_prefix=f"rkfx_fem_elasticity_{next(_prefix_counter)}_",
        petsc_options=dict(_MUMPS_OPTIONS),
    )
    t_setup = time.perf_counter()
    problem.solve()
    reason = problem.solver.getConvergedReason()
    if reason <= 0:
        raise RuntimeError(f"linear solve failed (KSP reason {reason})")
    del problem
    t_end = time.perf_counter()

    local = np.array([t_mesh - t_start, t_setup - t_mesh, t_end - t_setup, t_end - t_start])
    glob = np.empty_like(local)
    comm.Allreduce(local, glob, op=MPI.MAX)
    imap = V.dofmap.index_map
    return FemElasticityResult(
        mesh=mesh,
        u=uh,
        n_dofs=int(imap.size_global * V.dofmap.index_map_bs),
        wall_time_s=float(glob[3]),
        degree=degree,
        timings={"mesh": float(glob[0]), "setup": float(glob[1]), "solve": float(glob[2])},
        facet_tags=facet_tags,
        physical_groups=physical_groups,
        material=material,
    )


def _max_cell_diameter(mesh: dolfinx.mesh.Mesh) -> float:
    """Largest edge length over owned simplices (vertex-based), global max."""
    tdim, gdim = mesh.topology.dim, mesh.geometry.dim
    ncells = mesh.topology.index_map(tdim).size_local
    x = mesh.geometry.x[:, :gdim]
    conn = mesh.geometry.dofmaps[0][:ncells, : tdim + 1]  # a simplex's vertices come first
    h = 0.0
    if ncells:
        p = x[conn]  # (ncells, tdim + 1, gdim)
        i, j = np.triu_indices(tdim + 1, 1)  # every edge of the simplex
        edges = p[:, i] - p[:, j]
        h = float(np.sqrt((edges**2).sum(axis=2)).max())
    return mesh.comm.allreduce(h, op=MPI.MAX)


def errors(
    result: FemElasticityResult,
    u_exact: Callable[[Any], Any],
    grad_exact: Callable[[Any], Any] | None = None,
) -> dict[str, float]:
    """Relative L2, H1-seminorm and energy errors against an exact solution.

    Collective on the mesh communicator. Integrals use quadrature degree
    ``result.degree + 3``.

    Args:
        result: A solution from :func:`solve_plane_strain` or
            :func:`solve_elasticity_3d`.
        u_exact: ``u_exact(X)`` takes ``X = ufl.SpatialCoordinate(mesh)`` and
            returns a UFL vector expression of shape (gdim,) (a list/tuple of
            gdim UFL scalars is accepted), e.g.
            ``lambda X: ufl.as_vector((ufl.sin(ufl.pi * X[0]), X[1]))``.
        grad_exact: ``grad_exact(X)`` returns the gdim x gdim UFL displacement
            gradient, ``G[i, j] = d u_i / d x_j`` (nested lists accepted). If
            None, ``ufl.grad(u_exact(X))`` is used.

    Returns:
        Dict with ``"l2"`` = ||u_h - u|| / ||u||, ``"h1"`` =
        |u_h - u|_1 / |u|_1 (relative, dimensionless), the absolute values
        ``"l2_abs"`` (length * length^(gdim/2) units) and ``"h1_abs"``, the
        exact norms ``"l2_norm"``, ``"h1_norm"``, and ``"h_max"`` (largest cell
        edge). When the result knows its material (both solvers set it), also
        the energy error ``"energy"`` = ||u_h - u||_E / ||u||_E (relative) with
        ||w||_E^2 = int sigma(w) : eps(w), and ``"energy_abs"`` [sqrt(J)],
        ``"energy_norm"``.
    """
    mesh, uh = result.mesh, result.u
    X = ufl.SpatialCoordinate(mesh)
    ue = u_exact(X)
    if isinstance(ue, (list, tuple)):
        ue = ufl.as_vector(ue)
    if grad_exact is None:
        Ge = ufl.grad(ue)
    else:
        Ge = grad_exact(X)
        if isinstance(Ge, (list, tuple)):
            Ge = ufl.as_matrix(Ge)
    dx = ufl.Measure("dx", domain=mesh, metadata={"quadrature_degree": result.degree + 3})
    eu = uh - ue
    eg = ufl.grad(uh) - Ge
    integrands = [
        ufl.inner(eu, eu) * dx,
        ufl.inner(ue, ue) * dx,
        ufl.inner(eg, eg) * dx,
        ufl.inner(Ge, Ge) * dx,
    ]
    if result.material is not None:
        law = _law_of_strain(mesh, result.material)
        for G in (eg, Ge):
            eps = ufl.sym(G)
            integrands.append(ufl.inner(law(eps), eps) * dx)
    vals = [
        mesh.comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(F)), op=MPI.SUM)
        for F in integrands
    ]
    e_l2, n_l2, e_h1, n_h1, *energy = (float(np.sqrt(max(val, 0.0))) for val in vals)
    out = {
        "l2": e_l2 / n_l2 if n_l2 > 0 else float("nan"),
        "h1": e_h1 / n_h1 if n_h1 > 0 else float("nan"),
        "l2_abs": e_l2,
        "h1_abs": e_h1,
        "l2_norm": n_l2,
        "h1_norm": n_h1,
        "h_max": _max_cell_diameter(mesh),
    }
    if energy:
        e_en, n_en = energy
        out.update({"energy": e_en / n_en if n_en > 0 else float("nan"), "energy_abs": e_en, "energy_norm": n_en})
    return out
