"""Explicit-dynamics crack-band finite elements for the slit plates of seed 4.3.2 and 4.3.3.

Two problems on a plate with an edge slit: Kalthoff's impact (``kalthoff_crack_band``) and
the crack-branching plate (``branching_crack_band``: [0, 0.1] x [0, 0.04] m, slit along
y = 0.02 m to x = 0.05 m, a step traction sigma on the top and bottom edges as consistent
nodal forces ``edge_traction``, no supports). Kalthoff's problem (Kalthoff and Winkler's
edge-cracked plate, upper half by symmetry; plane strain):

    domain        [0, side] x [0, side] (0.1 m x 0.1 m)
    slit          y = a2 (0.025 m) for 0 <= x <= a1 (0.05 m): two traction-free faces
    symmetry      y = 0: u_y = 0
    impact        x = 0, 0 <= y < a2 (the edge below the slit, including the slit's lower
                  face end at y = a2^-): u_x velocity v0 (16.5 m/s) from t = 0, u_y free
    elsewhere     traction free

Mesh. gmsh (OpenCASCADE kernel, headless) meshes the rectangle with the slit line embedded
(``fragment``) at a uniform target size h; gmsh's ``Crack`` plugin then duplicates the nodes
of the slit (both ends stay single except the mouth at x = 0, which lies on the outer
boundary and is opened through ``OpenBoundaryPhysicalGroup``), so the two faces share only
the tip node (a1, a2). ``dolfinx.io.gmsh.model_to_mesh`` converts the model.

Discretisation. Linear triangles (vector P1): constant strain per cell. dolfinx assembles

    * the lumped mass, M_i = rho int N_i dx per component (row sums of the consistent
      mass), interleaved per node like the particle models of ``rkfx.assembly.smeared_strain``;
    * the strain operator B (rows (eps_xx, eps_yy, gamma_xy) of each cell, columns the
      interleaved nodal displacements) from the mixed form int eps(u) : tau dx with tau
      in a DG0 (3,) space, divided by the cell areas; it is kept as scipy CSR with B^T.

Material (``rkfx.fracture.damage``): sigma = (1 - D) C eps, C plane strain; Mazars' equivalent strain
(4.6) of the cell strain; history kappa = max(kappa_old, eps_eq) (4.3)-(4.5); linear
softening D(kappa) (4.2) between kappa0 = f_t / E and kappa_c. Crack-band scaling (Bazant
and Oh 1983): kappa_c = (G_F / f_t) / h_e with h_e the chord of the triangle through its
centroid perpendicular to the crack normal n, so that a band of completely failed cells
dissipates G_F per unit crack length (f_t kappa_c / 2 per unit volume times the band area
h_e x length). n is fixed when the cell's damage initiates (kappa first reaches kappa0), along
the major principal direction of the effective stress C eps. Any cell may damage: there is
no crack tracking. ``regularized=False`` uses one given kappa_c for every cell instead (the
mesh-dependent, unregularized comparison).

Time integration: central differences with the lumped mass
(``rkfx.solvers.central_difference.CentralDifference``), driven through the explicit model
``rkfx.models.damage_dynamics.DamageDynamics`` by ``run_damage`` as for the particles, with
essential conditions as rows of the identity (``Constraint``): for Kalthoff u_y = 0 on y = 0
and the impact velocity on the impact edge; the branching plate has none. The internal force
updates the damage history in place (it is called once per step with the new displacement);
the history arrays are the model's ``state()``, so checkpoints and ``resume`` restore them.
The dissipated energy is the exact dissipation density (``dissipation_density``) of the
cells, summed at every sample.

Stable step: dt = courant * min_e(a_e) / c_d with a_e the smallest altitude of cell e and
c_d = sqrt((lambda + 2 mu) / rho).

Parallelism: with a communicator of several ranks every rank meshes the plate and assembles
the operators itself (on ``MPI.COMM_SELF``; the ranks check that their meshes agree), and the
time loop is distributed (``rkfx.models.damage_ranks`` with the cell strains as a
``rkfx.assembly.matrix_strain.MatrixStrain``): the vertices are split by recursive coordinate
bisection, each rank steps its vertices' unknowns and the damage of its cells, and exchanges the
loads of the cells and the forces at the vertices along its cuts each step. Every sum keeps the
serial order, so the run is the serial one bit for bit; the result is on every rank.

Units: SI (m, s, kg, Pa, N/m); energies are per unit thickness [J/m].
"""
from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import gmsh
import numpy as np
import scipy.sparse as sp
from mpi4py import MPI

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.io.gmsh
import dolfinx.mesh
import ufl

from rkfx.fracture import damage as dm
from rkfx.errors import InputError
from rkfx.geometry.gmsh_nodes import scratch_model
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.assembly.smeared_strain import dilatational_wave_speed
from rkfx.models.damage_dynamics import DamageRun, run_damage
from rkfx.solvers.checkpoint import run_folder
from rkfx.assembly.matrix_strain import MatrixStrain
from rkfx.solvers.central_difference import Constraint
from rkfx.solvers.checkpoint import writes

__all__ = [
    "CrackedPlateMesh",
    "DynamicCrackBandResult",
    "FemOperators",
    "cracked_plate_mesh",
    "fem_operators",
    "branching_crack_band",
    "cell_strain",
    "edge_traction",
    "kalthoff_crack_band",
    "slit_sides",
    "stable_time_step",
    "triangle_geometry",
]



MESH_FILE = "mesh.npz"  # the nodes and cells of a finished run, beside its result.npz


# --------------------------------------------------------------------------- geometry


def triangle_geometry(vertices: np.ndarray) -> dm.CellGeometry:
    """Each triangle as three convex quadrilaterals about its centroid g, (g, m_ca, a, m_ab)
    and so on (counter-clockwise), so that ``rkfx.fracture.damage.chord_lengths`` gives the exact chord
    of the triangle through its centroid.

    Args:
        vertices: Triangle vertices, shape ``(m, 3, 2)`` [m] (either orientation).
    """
    v = np.asarray(vertices, float).reshape(-1, 3, 2).copy()
    e1, e2 = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
    flip = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
    v[flip] = v[flip][:, ::-1]
    g = np.broadcast_to(v.mean(axis=1, keepdims=True), v.shape)
    nxt, prv = np.roll(v, -1, axis=1), np.roll(v, 1, axis=1)
    quads = np.stack([g, 0.5 * (prv + v), v, 0.5 * (v + nxt)], axis=2)   # (m, 3, 4, 2)
    return dm.CellGeometry(np.repeat(np.arange(len(v)), 3), quads.reshape(-1, 4, 2), len(v))


def _altitudes(vertices: np.ndarray) -> np.ndarray:
    """Smallest altitude 2 A / (longest side) of each triangle, shape ``(m,)`` [m]."""
    e = np.roll(vertices, -1, axis=1) - vertices
    area = 0.5 * np.abs(e[:, 0, 0] * e[:, 1, 1] - e[:, 0, 1] * e[:, 1, 0])
    return 2.0 * area / np.linalg.norm(e, axis=2).max(axis=1)


@dataclass
class CrackedPlateMesh:
    """The slit plate as a dolfinx mesh with its vector P1 space.

    Attributes:
        mesh: dolfinx mesh (triangles) on ``MPI.COMM_SELF``.
        V: Vector P1 space; node i carries unknowns 2 i (u_x) and 2 i + 1 (u_y).
        x: Node coordinates, shape ``(n, 2)`` [m].
        triangles: Node indices of each cell, shape ``(m, 3)``.
        h: Target element size [m].
    """

    mesh: dolfinx.mesh.Mesh
    V: dolfinx.fem.FunctionSpace
    x: np.ndarray
    triangles: np.ndarray
    h: float

    @property
    def num_nodes(self) -> int:
        return len(self.x)

    @property
    def num_cells(self) -> int:
        return len(self.triangles)

    @property
    def vertices(self) -> np.ndarray:
        """Cell vertices, shape ``(m, 3, 2)`` [m]."""
        return self.x[self.triangles]

    @property
    def centroids(self) -> np.ndarray:
        """Cell centroids, shape ``(m, 2)`` [m]."""
        return self.vertices.mean(axis=1)


def _check_geometry(h: float, width: float, height: float, a1: float, a2: float) -> None:
    for name, val in (("width", width), ("height", height), ("a1", a1), ("a2", a2)):
        if not (np.isfinite(val) and val > 0):
            raise InputError(f"{name} = {val!r} must be positive and finite (lengths in m)")
    if not (a1 < width and a2 < height):
        raise InputError(f"slit end (a1, a2) = ({a1:g}, {a2:g}) must lie inside the plate "
                         f"{width:g} x {height:g} m")
    if not (np.isfinite(h) and h > 0):
        raise InputError(f"element size h = {h!r} must be positive and finite (e.g. h=1e-3 m)")
    coarse = 0.5 * min(a1, a2, width - a1, height - a2)
    if h > coarse:
        raise InputError(f"element size h = {h:g} m is too coarse for the slit geometry; "
                         f"use h <= {coarse:g} m (two elements across its shortest distance to an edge)")


def cracked_plate_mesh(h: float, *, width: float = 0.1, height: float = 0.1, a1: float = 0.05,
                       a2: float = 0.025) -> CrackedPlateMesh:
    """Mesh [0, width] x [0, height] with a slit along y = a2, 0 <= x <= a1, whose faces share
    only the tip.

    Args:
        h: Uniform target element size [m].
        width, height: Plate size [m].
        a1: Slit length from x = 0 (x of the tip) [m].
        a2: Height of the slit [m].
    """
    _check_geometry(h, width, height, a1, a2)
    side = max(width, height)
    with scratch_model("slit_plate"):
        occ = gmsh.model.occ
        square = occ.addRectangle(0.0, 0.0, 0.0, width, height)
        slit = occ.addLine(occ.addPoint(0.0, a2, 0.0), occ.addPoint(a1, a2, 0.0))
        occ.fragment([(2, square)], [(1, slit)])
        occ.synchronize()
        tol = 1e-4 * side   # OpenCASCADE pads bounding boxes
        curves = [t for _, t in gmsh.model.getEntities(1)
                  if _box_on_slit(gmsh.model.getBoundingBox(1, t), a1, a2, tol)]
        mouth = [t for _, t in gmsh.model.getEntities(0)
                 if np.allclose(gmsh.model.getValue(0, t, []), [0.0, a2, 0.0], atol=tol)]
        if len(curves) != 1 or len(mouth) != 1:
            raise RuntimeError(f"gmsh did not embed the slit (curves {curves}, mouth {mouth})")
        gmsh.model.addPhysicalGroup(2, [t for _, t in gmsh.model.getEntities(2)], 1, name="plate")
        gmsh.model.addPhysicalGroup(1, curves, 2, name="slit")
        gmsh.model.addPhysicalGroup(0, mouth, 3, name="mouth")
        gmsh.option.setNumber("Mesh.MeshSizeMin", h)
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.model.mesh.generate(2)
        gmsh.plugin.setNumber("Crack", "Dimension", 1)
        gmsh.plugin.setNumber("Crack", "PhysicalGroup", 2)
        gmsh.plugin.setNumber("Crack", "OpenBoundaryPhysicalGroup", 3)
        # Plugin options outlive gmsh sessions: clear those an earlier caller may have set.
        gmsh.plugin.setNumber("Crack", "NewPhysicalGroup", 0)
        gmsh.plugin.run("Crack")
        gmsh.model.mesh.renumberNodes()   # dolfinx wants contiguous node tags
        md = dolfinx.io.gmsh.model_to_mesh(gmsh.model, MPI.COMM_SELF, 0, gdim=2)
    mesh = md.mesh
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (2,)))
    x = V.tabulate_dof_coordinates()[:, :2].copy()
    tri = np.asarray(V.dofmap.list, np.int64).copy()
    return CrackedPlateMesh(mesh, V, x, tri, float(h))


def _box_on_slit(box, a1: float, a2: float, tol: float) -> bool:
    x0, y0, _, x1, y1, _ = box
    return abs(y0 - a2) < tol and abs(y1 - a2) < tol and x0 < tol and abs(x1 - a1) < tol


def slit_sides(m: CrackedPlateMesh, a1: float, a2: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodes on the slit line y = a2, x < a1 of the upper face, of the lower face, and the tip.

    A node belongs to the upper (lower) face if all its cells lie above (below) the slit.

    Returns:
        ``(upper, lower, tip)`` node indices.
    """
    tol = 1e-9 * max(1.0, a1)
    on = np.flatnonzero(np.isclose(m.x[:, 1], a2, atol=tol) & (m.x[:, 0] < a1 - tol))
    cy = m.centroids[:, 1]
    above = np.zeros(m.num_nodes, bool)
    below = np.zeros(m.num_nodes, bool)
    np.logical_or.at(above, m.triangles.ravel(), np.repeat(cy > a2, 3))
    np.logical_or.at(below, m.triangles.ravel(), np.repeat(cy < a2, 3))
    tip = np.flatnonzero(np.hypot(m.x[:, 0] - a1, m.x[:, 1] - a2) < tol)
    return on[above[on] & ~below[on]], on[below[on] & ~above[on]], tip


# --------------------------------------------------------------------------- operators


@dataclass
class FemOperators:
    """Assembled P1 operators on a mesh.

    Attributes:
        mass: Lumped mass per interleaved unknown, shape ``(2 n,)`` [kg/m].
        B: Cell strains (eps_xx, eps_yy, gamma_xy) of cell c in rows 3 c .. 3 c + 2 from the
            interleaved nodal displacements, scipy CSR ``(3 m, 2 n)`` [1/m].
        BT: B^T as CSR.
        area: Cell areas, shape ``(m,)`` [m^2].
    """

    mass: np.ndarray
    B: sp.csr_matrix
    BT: sp.csr_matrix
    area: np.ndarray


def fem_operators(m: CrackedPlateMesh, rho: float) -> FemOperators:
    """Assemble the lumped mass and the cell strain operator with dolfinx (see module doc)."""
    mesh, V = m.mesh, m.V
    v = ufl.TestFunction(V)
    ones = ufl.as_vector((1.0, 1.0))
    mass = dolfinx.fem.assemble_vector(dolfinx.fem.form(rho * ufl.inner(ones, v) * ufl.dx)).array.copy()

    Q = dolfinx.fem.functionspace(mesh, ("DG", 0, (3,)))
    u, tau = ufl.TrialFunction(V), ufl.TestFunction(Q)
    g = ufl.grad(u)
    voigt = ufl.as_vector((g[0, 0], g[1, 1], g[0, 1] + g[1, 0]))
    # PETSc storage: dolfinx's own CSR matrix refuses the non-square (3, 2) blocks
    pmat = dolfinx.fem.petsc.assemble_matrix(dolfinx.fem.form(ufl.inner(voigt, tau) * ufl.dx))
    pmat.assemble()
    indptr, indices, values = pmat.getValuesCSR()
    mat = sp.csr_matrix((values, indices, indptr), shape=pmat.getSize())
    pmat.destroy()

    Q0 = dolfinx.fem.functionspace(mesh, ("DG", 0))
    q = ufl.TestFunction(Q0)
    area_dof = dolfinx.fem.assemble_vector(dolfinx.fem.form(q * ufl.dx)).array.copy()
    num_cells = m.num_cells
    cell_dof = np.asarray(Q.dofmap.list, np.int64)[:num_cells, 0]
    area = area_dof[np.asarray(Q0.dofmap.list, np.int64)[:num_cells, 0]]
    rows = (3 * cell_dof[:, None] + np.arange(3)).ravel()
    B = sp.csr_matrix(mat[rows])
    B = sp.csr_matrix(sp.diags(np.repeat(1.0 / area, 3)) @ B)
    B.eliminate_zeros()
    B.sort_indices()
    return FemOperators(mass, B, B.T.tocsr(), area)


def stable_time_step(m: CrackedPlateMesh, E: float, nu: float, rho: float, courant: float = 0.5) -> float:
    """dt = courant * (smallest altitude of any cell) / c_d [s], c_d = sqrt((lambda + 2 mu) / rho)."""
    if not 0 < courant <= 1:
        raise InputError(f"courant = {courant!r} must lie in (0, 1]; 0.5 is the default")
    c_d = dilatational_wave_speed(ElasticMaterial(E, nu), rho)
    return float(courant * _altitudes(m.vertices).min() / c_d)


# --------------------------------------------------------------------------- damage force



def cell_strain(ops: FemOperators) -> MatrixStrain:
    """The cell strains of linear triangles as the strain operator of ``rkfx.models.damage_dynamics``:
    damage points are the cells, ``strain`` = B d, ``force`` = B^T (sigma area)."""
    return MatrixStrain(ops.B, ops.BT, ops.area)


# --------------------------------------------------------------------------- driver


@dataclass
class DynamicCrackBandResult:
    """A crack-band run of a slit plate (Kalthoff's or the branching plate).

    Attributes:
        num_nodes, num_cells: Mesh size (slit nodes counted twice).
        h: Target element size [m].
        run: The explicit damage run (history, final damage per cell, steps, dt, wall time).
        centroids: Cell centroids, shape ``(m, 2)`` [m].
        x: Node coordinates, shape ``(n, 2)`` [m].
        triangles: Node indices per cell, shape ``(m, 3)`` (for matplotlib ``tripcolor``).
        wall_time_s: Wall time of the whole call (mesh, assembly, time loop) [s].
    """

    num_nodes: int
    num_cells: int
    h: float
    run: DamageRun
    centroids: np.ndarray
    x: np.ndarray
    triangles: np.ndarray
    wall_time_s: float

    @property
    def time(self) -> np.ndarray:
        """Sample times [s]."""
        return self.run.column("time")

    @property
    def dissipated(self) -> np.ndarray:
        """Dissipated energy at the sample times [J/m]."""
        return self.run.column("dissipated")

    @property
    def damage(self) -> np.ndarray:
        """Final damage per cell, shape ``(m,)``."""
        return self.run.damage


def _same_mesh(m: CrackedPlateMesh, comm: MPI.Comm) -> None:
    """Raise unless every rank of ``comm`` meshed the plate alike (collective)."""
    if comm is None or comm.size == 1:
        return
    mine = hashlib.sha256(m.x.tobytes() + m.triangles.tobytes()).hexdigest()
    if len(set(comm.allgather(mine))) > 1:
        raise InputError("the ranks meshed the plate differently (gmsh or dolfinx not deterministic here); "
                         "run the crack-band FEM on one rank")


def _identity_rows(dofs: np.ndarray, n2: int) -> sp.csr_matrix:
    k = len(dofs)
    return sp.csr_matrix((np.ones(k), (np.arange(k), dofs)), shape=(k, n2))


def _check_run(material: dm.DamageMaterial, rho: float, t_end: float, samples: int, regularized: bool,
               kappa_c: float | None) -> None:
    if not (np.isfinite(rho) and rho > 0):
        raise InputError(f"density rho = {rho!r} must be positive (kg/m^3, e.g. rho=8000)")
    if not (np.isfinite(t_end) and t_end > 0):
        raise InputError(f"t_end = {t_end!r} must be positive (seconds, e.g. t_end=80e-6)")
    if int(samples) != samples or samples < 1:
        raise InputError(f"samples = {samples!r} must be a positive integer")
    if regularized:
        if kappa_c is not None:
            raise InputError("kappa_c is only used with regularized=False; drop it or set regularized=False")
    elif kappa_c is None or not (np.isfinite(kappa_c) and kappa_c > material.kappa0):
        raise InputError(f"regularized=False needs kappa_c > kappa0 = f_t / E = {material.kappa0:.4g}; "
                         f"got kappa_c = {kappa_c!r}")


def _crack_band(mesh, material: dm.DamageMaterial, rho: float, t_end: float, regularized: bool,
                kappa_c: float | None, courant: float, samples: int, label: str, conditions, io: dict,
                wall: float, comm: MPI.Comm) -> DynamicCrackBandResult:
    """The explicit crack-band run on the mesh ``mesh()``; ``conditions(m, ops) -> (constraints,
    external_force)`` sets up the problem's loads. A finished run in ``io["resume"]`` is read
    back with its mesh's nodes and cells, without meshing again. On several ranks every rank
    meshes, and the time loop is distributed (module docstring)."""
    work_dir, resume = io.get("work_dir"), io.get("resume")
    done = None if resume is None else Path(resume) / run_folder(label)
    if done is not None and (done / "result.npz").is_file() and (done / MESH_FILE).is_file():
        with np.load(done / MESH_FILE) as z:
            x, tri, h = z["x"], z["triangles"], float(z["h"])
        run = DamageRun.load(done / "result.npz")
        if io.get("frames") is not None:
            io["frames"](x, tri).last(run)
        return DynamicCrackBandResult(len(x), len(tri), h, run, x[tri].mean(axis=1), x, tri,
                                      time.perf_counter() - wall)
    m = mesh()
    _same_mesh(m, comm)
    if regularized:
        # the band width area / chord stays below the longest side
        h_max = 2.0 * material.E * material.GF / material.ft**2
        longest = np.linalg.norm(np.roll(m.vertices, -1, axis=1) - m.vertices, axis=2).max()
        if longest >= h_max:
            raise InputError(f"band too wide: elements up to {longest:.3g} m long may have h_e > 2 E G_F / f_t^2 "
                             f"= {h_max:.3g} m, where kappa_c <= kappa0 (snap-back); use h < {h_max / 1.5:.3g} m")
    ops = fem_operators(m, rho)
    dt = stable_time_step(m, material.E, material.nu, rho, courant)
    model = dm.damage_model(material, ops.area, geometry=triangle_geometry(m.vertices) if regularized else None,
                            kappa_c=kappa_c, regularized=regularized, band_factor=2.0)
    constraints, external_force = conditions(m, ops)
    frames = io.get("frames")
    run = run_damage(label, cell_strain(ops), ops.mass, dt, model, None, constraints, t_end, external_force,
                     samples=samples, checkpoint_every=io.get("checkpoint_every", 0),
                     work_dir=None if work_dir is None else Path(work_dir),
                     resume=None if resume is None else Path(resume), comm=comm, x=m.x,
                     frames=None if frames is None else frames(m.x, m.triangles))
    if work_dir is not None and writes(comm):  # beside result.npz, so that a resume reads the run back without meshing
        folder = Path(work_dir) / run_folder(label)
        folder.mkdir(parents=True, exist_ok=True)  # a run read back from elsewhere wrote nothing here
        np.savez(folder / MESH_FILE, x=m.x, triangles=m.triangles, h=m.h)
    return DynamicCrackBandResult(m.num_nodes, m.num_cells, m.h, run, m.centroids, m.x, m.triangles,
                                  time.perf_counter() - wall)


def kalthoff_crack_band(h: float, t_end: float = 80e-6, *, E: float = 1.9e11, nu: float = 0.3,
                        rho: float = 8000.0, ft: float = 9.5e8, GF: float = 2e4, v0: float = 16.5,
                        side: float = 0.1, a1: float = 0.05, a2: float = 0.025, regularized: bool = True,
                        kappa_c: float | None = None, courant: float = 0.5, samples: int = 200,
                        label: str | None = None, checkpoint_every: int = 0, work_dir: str | Path | None = None,
                        resume: str | Path | None = None, comm: MPI.Comm = MPI.COMM_SELF, frames=None
                        ) -> DynamicCrackBandResult:
    """Run Kalthoff's impact problem with explicit crack-band finite elements (module doc).

    Args:
        h: Uniform target element size [m].
        t_end: Final time [s] (rounded up to whole steps).
        E, nu, rho: Young's modulus [Pa], Poisson's ratio [-], density [kg/m^3].
        ft, GF: Tensile strength [Pa] and fracture energy [N/m].
        v0: Impact velocity [m/s].
        side, a1, a2: Plate side, slit length and slit height [m].
        regularized: Crack-band kappa_c = 2 G_F / (f_t h_e) per cell; if ``False`` every cell
            uses the given ``kappa_c``.
        kappa_c: Critical strain of the unregularized model [-] (only with ``regularized=False``).
        courant: Fraction of the stable step (0, 1].
        samples: History samples over the run.
        label, checkpoint_every, work_dir, resume: As for ``rkfx.models.damage_dynamics.run_damage``
            (default label ``fem-crack-band h=<h>``).
        comm: Communicator; on several ranks the time loop is distributed (module docstring).
        frames: ``frames(x, triangles)`` gives the ``rkfx.models.damage_dynamics.Frames`` that
            receive the fields through time on the mesh (``None``: none are written).

    Returns:
        The run's result on every rank of ``comm``.
    """
    def run() -> DynamicCrackBandResult:
        wall = time.perf_counter()
        material = dm.DamageMaterial(E=E, nu=nu, ft=ft, GF=GF, plane="strain")
        _check_run(material, rho, t_end, samples, regularized, kappa_c)
        if not np.isfinite(v0):
            raise InputError(f"impact velocity v0 = {v0!r} must be finite (m/s, e.g. v0=16.5)")
        _check_geometry(h, side, side, a1, a2)
        mesh = partial(cracked_plate_mesh, h, width=side, height=side, a1=a1, a2=a2)

        def conditions(m: CrackedPlateMesh, ops: FemOperators):
            n2, tol = 2 * m.num_nodes, 1e-9 * side
            bottom = np.flatnonzero(np.abs(m.x[:, 1]) < tol)
            _, lower, _ = slit_sides(m, a1, a2)
            impact = np.flatnonzero((np.abs(m.x[:, 0]) < tol) & (m.x[:, 1] < a2 - tol))
            impact = np.union1d(impact, lower[np.abs(m.x[lower, 0]) < tol])   # the slit's lower face end
            v_impact = np.full(len(impact), float(v0))
            return [Constraint(_identity_rows(2 * bottom + 1, n2)),
                    Constraint(_identity_rows(2 * impact, n2), velocity=lambda t: v_impact)], None

        io = {"checkpoint_every": checkpoint_every, "work_dir": work_dir, "resume": resume, "frames": frames}
        return _crack_band(mesh, material, rho, t_end, regularized, kappa_c, courant, samples,
                           label or f"fem-crack-band h={h:g}", conditions, io, wall, comm)

    return run()


def edge_traction(m: CrackedPlateMesh, sigma: float) -> np.ndarray:
    """Consistent nodal forces of a normal traction ``sigma`` [Pa] on the bottom (y = 0) and top
    (y = height) edges, pulling outward: sum_e int_e N_i t ds per interleaved unknown [N/m]."""
    mesh = m.mesh
    y0, y1 = m.x[:, 1].min(), m.x[:, 1].max()
    tol = 1e-9 * (y1 - y0)
    mesh.topology.create_connectivity(1, 2)
    facets = dolfinx.mesh.locate_entities_boundary(
        mesh, 1, lambda x: (np.abs(x[1] - y0) < tol) | (np.abs(x[1] - y1) < tol))
    tags = dolfinx.mesh.meshtags(mesh, 1, np.sort(facets).astype(np.int32), np.ones(len(facets), np.int32))
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=tags)
    v = ufl.TestFunction(m.V)
    n = ufl.FacetNormal(mesh)
    t = float(sigma) * n[1] * ufl.as_vector((0.0, 1.0))   # +sigma on top, -sigma on the bottom
    return dolfinx.fem.assemble_vector(dolfinx.fem.form(ufl.inner(t, v) * ds(1))).array.copy()


def branching_crack_band(h: float, t_end: float = 80e-6, *, E: float = 3.2e10, nu: float = 0.2,
                         rho: float = 2450.0, ft: float = 2.72e6, GF: float = 3.0, sigma: float = 1.0e6,
                         plane: str = "strain", width: float = 0.1, height: float = 0.04, a1: float = 0.05,
                         a2: float = 0.02, regularized: bool = True, kappa_c: float | None = None,
                         courant: float = 0.5, samples: int = 200, label: str | None = None,
                         checkpoint_every: int = 0, work_dir: str | Path | None = None,
                         resume: str | Path | None = None, comm: MPI.Comm = MPI.COMM_SELF, frames=None
                         ) -> DynamicCrackBandResult:
    """Run the crack-branching plate (seed 4.3.3) with explicit crack-band finite elements: an
    edge slit along y = a2 from x = 0 to a1, a step traction ``sigma`` [Pa] on the top and
    bottom edges from t = 0, no supports (the loads are self-equilibrated).

    Arguments as for ``kalthoff_crack_band``; ``plane`` is ``strain`` or ``stress``, and
    ``width``, ``height`` give the plate [m].
    """
    def run() -> DynamicCrackBandResult:
        wall = time.perf_counter()
        material = dm.DamageMaterial(E=E, nu=nu, ft=ft, GF=GF, plane=plane)
        _check_run(material, rho, t_end, samples, regularized, kappa_c)
        if not (np.isfinite(sigma) and sigma > 0):
            raise InputError(f"traction sigma = {sigma!r} must be positive (Pa, e.g. sigma=1e6)")
        _check_geometry(h, width, height, a1, a2)
        mesh = partial(cracked_plate_mesh, h, width=width, height=height, a1=a1, a2=a2)

        def conditions(m: CrackedPlateMesh, ops: FemOperators):
            f = edge_traction(m, sigma)
            return [], lambda t: f

        io = {"checkpoint_every": checkpoint_every, "work_dir": work_dir, "resume": resume, "frames": frames}
        return _crack_band(mesh, material, rho, t_end, regularized, kappa_c, courant, samples,
                           label or f"fem-crack-band h={h:g}", conditions, io, wall, comm)

    return run()
