"""A pressurized slit in a fixed square with dolfinx: the discrete-crack reference of Sneddon's problem.

Problem (seed 5.3.1). The square [-L/2, L/2]^2 in plane strain, fixed on its outer boundary,
with a straight slit y = 0, |x| <= c whose two faces carry the pressure p_bar (traction
-p_bar n, n the outward normal of the solid). On an unbounded plane the opening is Sneddon's
COD = 4 (1 - nu^2) p_bar sqrt(c^2 - x^2) / E (``verification.sneddon``); the fixed square
closes it by a few percent, which is why the smeared RKPM crack is compared with this
solution on the same square.

Mesh. gmsh (OpenCASCADE, headless) embeds the slit in the square (``fragment``, with a vertex
at the centre x = 0), grades the size from ``h_tip`` at the two tips to ``h`` at distance
``c`` from them and beyond (the tips carry the sqrt(r) singularity), and its ``Crack`` plugin
duplicates the slit's interior nodes so that the two faces share only the tips. The faces
are the physical groups ``slit`` (one side) and ``slit_other`` (the duplicated side).

Discretisation. Vector Lagrange P``degree`` triangles, MUMPS LU. The outputs are read off
the faces: the opening u_y^+ - u_y^- at the face dofs (each dof is on the side of the cells
that hold it), the centre opening at the vertex x = 0, and the crack area
int (u_y^+ - u_y^-) dx = -int_faces u . n ds, assembled.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import gmsh
import numpy as np
from mpi4py import MPI

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.geometry
import dolfinx.io.gmsh
import dolfinx.mesh
import ufl

from fem_baselines.elasticity import FemElasticityResult, stress_law
from rkfx.errors import InputError
from rkfx.geometry.gmsh_nodes import scratch_model
from rkfx.materials.elasticity import ElasticMaterial

__all__ = ["SlitResult", "pressurized_slit"]

_MUMPS = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps",
          "ksp_error_if_not_converged": True}
_SLIT, _OTHER, _SQUARE = 2, 4, 1


@dataclass
class SlitResult:
    """Opening of the pressurized slit.

    Attributes:
        x: Abscissae of the face dofs, ascending, shape ``(m,)`` [m].
        cod: Opening u_y^+ - u_y^- there, shape ``(m,)`` [m].
        centre_cod: Opening at x = 0 [m].
        crack_area: int_{-c}^{c} (u_y^+ - u_y^-) dx [m^2].
        n_dofs: Displacement unknowns.
        num_cells: Triangles.
        wall_time_s: Mesh, assembly and solve [s] (max over ranks).
        solution: The displacement (``FemElasticityResult``: evaluate u at points).
        sigma_yy: sigma_yy as a DG``degree - 1`` function (for maps).
    """

    x: np.ndarray
    cod: np.ndarray
    centre_cod: float
    crack_area: float
    n_dofs: int
    num_cells: int
    wall_time_s: float
    solution: FemElasticityResult
    sigma_yy: dolfinx.fem.Function
    timings: dict[str, float] = field(default_factory=dict)

    def stress_yy(self, points: np.ndarray) -> np.ndarray:
        """sigma_yy at points, shape ``(m,)`` (NaN outside the mesh) [Pa]. Collective: a point in
        cells of several ranks takes the value of the lowest such rank."""
        mesh = self.solution.mesh
        pts = np.zeros((len(points), 3))
        pts[:, :2] = points
        tree = dolfinx.geometry.bb_tree(mesh, mesh.topology.dim)
        cand = dolfinx.geometry.compute_collisions_points(tree, pts)
        cells = dolfinx.geometry.compute_colliding_cells(mesh, cand, pts)
        off = np.asarray(cells.offsets)
        comm = mesh.comm
        owner = np.where(np.diff(off) > 0, comm.rank, comm.size).astype(np.int32)
        comm.Allreduce(MPI.IN_PLACE, owner, op=MPI.MIN)
        mine = owner == comm.rank
        out = np.zeros(len(points))
        if np.any(mine):
            out[mine] = self.sigma_yy.eval(pts[mine], np.asarray(cells.array)[off[:-1][mine]]).ravel()
        comm.Allreduce(MPI.IN_PLACE, out, op=MPI.SUM)
        out[owner == comm.size] = np.nan
        return out


def _check(L: float, c: float, h: float, h_tip: float, degree: int) -> None:
    if not (L > 0 and 0 < c < L / 2):
        raise InputError(f"slit half-length c = {c!r} must lie in (0, L/2) = (0, {L / 2:g}); shorten it or widen L")
    if not (0 < h_tip <= h <= L / 4):
        raise InputError(f"mesh sizes h_tip = {h_tip!r}, h = {h!r}: need 0 < h_tip <= h <= L/4 = {L / 4:g}")
    if degree not in (1, 2, 3):
        raise InputError(f"FEM degree {degree!r} not offered; use 1, 2 or 3")


def _mesh(L: float, c: float, h: float, h_tip: float, comm: MPI.Comm):
    """The square with the opened slit as a dolfinx MeshData (meshed on rank 0)."""
    with scratch_model("pressurized_slit"):
        if comm.rank == 0:
            occ = gmsh.model.occ
            square = occ.addRectangle(-L / 2, -L / 2, 0.0, L, L)
            left, mid, right = (occ.addPoint(x, 0.0, 0.0) for x in (-c, 0.0, c))
            lines = [occ.addLine(left, mid), occ.addLine(mid, right)]
            occ.fragment([(2, square)], [(1, t) for t in lines])
            occ.synchronize()
            tol = 1e-6 * L
            on_slit = [t for _, t in gmsh.model.getEntities(1)
                       if (lambda b: abs(b[1]) < tol and abs(b[4]) < tol and b[0] > -c - tol and b[3] < c + tol)(
                           gmsh.model.getBoundingBox(1, t))]
            tips = [t for _, t in gmsh.model.getEntities(0)
                    if abs(abs(gmsh.model.getValue(0, t, [])[0]) - c) < tol and abs(gmsh.model.getValue(0, t, [])[1]) < tol]
            if len(on_slit) != 2 or len(tips) != 2:
                raise RuntimeError(f"gmsh did not embed the slit (curves {on_slit}, tips {tips})")
            gmsh.model.addPhysicalGroup(2, [t for _, t in gmsh.model.getEntities(2)], _SQUARE, name="square")
            gmsh.model.addPhysicalGroup(1, on_slit, _SLIT, name="slit")
            outer = [t for _, t in gmsh.model.getEntities(1) if t not in on_slit]
            gmsh.model.addPhysicalGroup(1, outer, 3, name="outer")
            field_ = gmsh.model.mesh.field
            dist = field_.add("Distance")
            field_.setNumbers(dist, "PointsList", tips)
            thr = field_.add("Threshold")
            field_.setNumber(thr, "InField", dist)
            field_.setNumber(thr, "SizeMin", h_tip)
            field_.setNumber(thr, "SizeMax", h)
            field_.setNumber(thr, "DistMin", 0.0)
            field_.setNumber(thr, "DistMax", c)
            field_.setAsBackgroundMesh(thr)
            for opt in ("MeshSizeFromPoints", "MeshSizeFromCurvature", "MeshSizeExtendFromBoundary"):
                gmsh.option.setNumber(f"Mesh.{opt}", 0)
            gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)  # the field alone sizes the mesh
            gmsh.option.setNumber("Mesh.MeshSizeMax", h)
            gmsh.model.mesh.generate(2)
            gmsh.plugin.setNumber("Crack", "Dimension", 1)
            gmsh.plugin.setNumber("Crack", "PhysicalGroup", _SLIT)
            gmsh.plugin.setNumber("Crack", "NewPhysicalGroup", _OTHER)
            # Plugin options outlive gmsh sessions: clear those an earlier caller may have set.
            gmsh.plugin.setNumber("Crack", "OpenBoundaryPhysicalGroup", 0)
            gmsh.plugin.run("Crack")
            gmsh.model.mesh.renumberNodes()  # dolfinx wants contiguous node tags
        return dolfinx.io.gmsh.model_to_mesh(gmsh.model, comm, 0, gdim=2)


def pressurized_slit(E: float, nu: float, pressure: float, *, L: float = 4.0, c: float = 0.5,
                     h: float = 0.1, h_tip: float = 0.01, degree: int = 2,
                     comm: MPI.Comm | None = None) -> SlitResult:
    """Solve the fixed square with a pressurized slit (collective on ``comm``).

    Args:
        E, nu: Elastic constants (plane strain) [Pa], [-].
        pressure: p_bar on both faces [Pa].
        L: Side of the square [m]; c: half-length of the slit [m].
        h, h_tip: Mesh size away from the tips and at the tips [m].
        degree: Lagrange degree of the displacement.
        comm: MPI communicator (default COMM_WORLD).
    """
    _check(L, c, h, h_tip, degree)
    material = ElasticMaterial(E, nu)
    comm = MPI.COMM_WORLD if comm is None else comm
    t0 = time.perf_counter()
    md = _mesh(L, c, h, h_tip, comm)
    mesh, tags = md.mesh, md.facet_tags
    t_mesh = time.perf_counter()
    fdim = mesh.topology.dim - 1
    mesh.topology.create_connectivity(fdim, mesh.topology.dim)
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", degree, (2,)))
    outer = tags.indices[tags.values == 3]
    zero = dolfinx.fem.Function(V)
    bc = dolfinx.fem.dirichletbc(zero, dolfinx.fem.locate_dofs_topological(V, fdim, outer))
    sigma = stress_law(mesh, material)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    n = ufl.FacetNormal(mesh)
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=tags)
    faces = ds(_SLIT) + ds(_OTHER)
    p = dolfinx.fem.Constant(mesh, dolfinx.default_scalar_type(pressure))
    a = ufl.inner(sigma(u), ufl.sym(ufl.grad(v))) * ufl.dx
    rhs = -p * ufl.dot(n, v) * faces
    uh = dolfinx.fem.Function(V, name="u")
    problem = dolfinx.fem.petsc.LinearProblem(a, rhs, bcs=[bc], u=uh, petsc_options=dict(_MUMPS),
                                              petsc_options_prefix="rkfx_fem_slit_")
    problem.solve()
    del problem
    t_solve = time.perf_counter()
    area = comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(-ufl.dot(uh, n) * faces)), op=MPI.SUM)
    x, cod = _opening(V, uh, mesh, c, comm)
    centre = float(np.interp(0.0, x, cod))
    S = dolfinx.fem.functionspace(mesh, ("DG", max(degree - 1, 0)))
    syy = dolfinx.fem.Function(S, name="sigma_yy")
    syy.interpolate(dolfinx.fem.Expression(sigma(uh)[1, 1], S.element.interpolation_points))
    t_end = time.perf_counter()
    wall = comm.allreduce(t_end - t0, op=MPI.MAX)
    imap = V.dofmap.index_map
    cells = mesh.topology.index_map(mesh.topology.dim).size_global
    sol = FemElasticityResult(mesh, uh, int(imap.size_global * 2), wall, degree)
    return SlitResult(x, cod, centre, float(area), sol.n_dofs, int(cells), wall, sol, syy,
                      {"mesh": t_mesh - t0, "solve": t_solve - t_mesh, "post": t_end - t_solve})


def _opening(V, uh, mesh, c: float, comm: MPI.Comm) -> tuple[np.ndarray, np.ndarray]:
    """Face dofs' abscissae and u_y^+ - u_y^- (gathered on every rank)."""
    xd = V.tabulate_dof_coordinates()
    num_owned = V.dofmap.index_map.size_local
    tol = 1e-9 * max(c, 1.0)
    on = np.flatnonzero((np.abs(xd[:num_owned, 1]) < tol) & (np.abs(xd[:num_owned, 0]) < c - tol))
    # The side of a face dof: that of the cells holding it (the plugin split the slit's nodes).
    num_cells = mesh.topology.index_map(mesh.topology.dim).size_local
    dofs = np.asarray(V.dofmap.list)[:num_cells]
    cy = dolfinx.mesh.compute_midpoints(mesh, mesh.topology.dim, np.arange(num_cells, dtype=np.int32))[:, 1]
    above = np.zeros(len(xd), bool)
    np.logical_or.at(above, dofs.ravel(), np.repeat(cy > 0, dofs.shape[1]))
    below = np.zeros(len(xd), bool)
    np.logical_or.at(below, dofs.ravel(), np.repeat(cy < 0, dofs.shape[1]))
    uy = uh.x.array.reshape(-1, 2)[:, 1]
    top = on[above[on] & ~below[on]]
    bot = on[below[on] & ~above[on]]
    parts = comm.allgather((xd[top, 0], uy[top], xd[bot, 0], uy[bot]))
    xt, ut, xb, ub = (np.concatenate([q[i] for q in parts]) for i in range(4))
    it, ib = np.argsort(xt), np.argsort(xb)
    xt, ut, xb, ub = xt[it], ut[it], xb[ib], ub[ib]
    if len(xt) != len(xb) or not np.allclose(xt, xb, atol=tol):
        raise RuntimeError("the slit's faces do not carry matching dofs; the Crack plugin did not split the slit")
    x = np.r_[-c, xt, c]
    return x, np.r_[0.0, ut - ub, 0.0]
