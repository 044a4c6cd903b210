"""Wall-clock cost of assembling a P1 plane-strain stiffness matrix with dolfinx.

The number is the FEM reference point for the RKPM stiffness-build benchmarks:
same problem size in vertices (= RKPM nodes), same physics (2D vector
elasticity, plane strain).
"""

from __future__ import annotations

import time

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.mesh
import ufl

from fem_baselines.elasticity import strain, stress_law
from rkfx.materials.elasticity import ElasticMaterial

__all__ = ["time_p1_assembly"]


def _stiffness_form(mesh: dolfinx.mesh.Mesh) -> ufl.Form:
    """UFL bilinear form of P1 plane-strain elasticity (E = 1, nu = 0.3) on ``mesh``.

    E and nu enter as Constants so every mesh shares one compiled kernel.
    """
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (2,)))
    sigma = stress_law(mesh, ElasticMaterial(1.0, 0.3))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    return ufl.inner(sigma(u), strain(v)) * ufl.dx


def _assemble(a_compiled) -> tuple[PETSc.Mat, float, float]:
    """Create the matrix (sparsity), then fill and finalise it; return timings."""
    t0 = time.perf_counter()
    A = dolfinx.fem.petsc.create_matrix(a_compiled)
    t1 = time.perf_counter()
    dolfinx.fem.petsc.assemble_matrix(A, a_compiled)
    A.assemble()
    t2 = time.perf_counter()
    return A, t1 - t0, t2 - t1


def time_p1_assembly(num_vertices: int, comm: MPI.Comm | None = None) -> dict:
    """Time assembly of the P1 vector plane-strain stiffness matrix.

    Builds ``create_unit_square(comm, n, n)`` (triangles) with
    ``n = max(1, round(sqrt(num_vertices)) - 1)``, i.e. ``(n + 1)^2`` vertices
    close to ``num_vertices``. The form is compiled once and a warm-up
    assembly runs on a 4 x 4 mesh first, so JIT compilation is not timed.
    The timed part is ``assemble_matrix(a)`` followed by ``A.assemble()``,
    done as ``create_matrix`` (sparsity pattern, preallocation) plus
    ``assemble_matrix(A, a)`` + ``A.assemble()`` (element kernels, insertion,
    parallel communication), so that both pieces are reported.
    Creating the dolfinx Form for the big mesh (cached-kernel lookup plus
    attaching mesh data) is timed separately as ``form_s``.

    Collective on ``comm``; all times are max over ranks, with a barrier
    before each timed section.

    Args:
        num_vertices: Target number of mesh vertices (>= 4).
        comm: MPI communicator; defaults to ``MPI.COMM_WORLD``.

    Returns:
        Dict with ``"vertices"`` (int, global), ``"dofs"`` (int, global,
        2 per vertex), ``"assembly_s"`` (float, seconds: sparsity +
        fill + finalise), ``"nnz"`` (int, global stored nonzeros of the
        assembled matrix), and the breakdown ``"sparsity_s"``, ``"fill_s"``,
        ``"form_s"``, ``"mesh_s"`` (mesh creation), ``"ranks"`` and ``"n"``
        (cells per side).
    """
    comm = MPI.COMM_WORLD if comm is None else comm
    if num_vertices < 4:
        raise ValueError(f"num_vertices must be >= 4, got {num_vertices}")
    n = max(1, int(round(np.sqrt(num_vertices))) - 1)

    # Warm-up: compile the kernel and run one small assembly (excluded).
    small = dolfinx.mesh.create_unit_square(comm, 4, 4)
    A_small, _, _ = _assemble(dolfinx.fem.form(_stiffness_form(small)))
    A_small.destroy()

    comm.Barrier()
    t0 = time.perf_counter()
    mesh = dolfinx.mesh.create_unit_square(comm, n, n, dolfinx.mesh.CellType.triangle)
    t1 = time.perf_counter()
    a_ufl = _stiffness_form(mesh)
    comm.Barrier()
    t2 = time.perf_counter()
    a = dolfinx.fem.form(a_ufl)
    t3 = time.perf_counter()
    comm.Barrier()
    A, sparsity_s, fill_s = _assemble(a)
    comm.Barrier()

    local = np.array([t1 - t0, t3 - t2, sparsity_s, fill_s])
    glob = np.empty_like(local)
    comm.Allreduce(local, glob, op=MPI.MAX)

    nnz = int(A.getInfo(PETSc.Mat.InfoType.GLOBAL_SUM)["nz_used"])
    rows, _ = A.getSize()
    A.destroy()
    vertices = mesh.topology.index_map(0).size_global
    return {
        "vertices": int(vertices),
        "dofs": int(rows),
        "assembly_s": float(glob[2] + glob[3]),
        "nnz": nnz,
        "sparsity_s": float(glob[2]),
        "fill_s": float(glob[3]),
        "form_s": float(glob[1]),
        "mesh_s": float(glob[0]),
        "ranks": comm.size,
        "n": n,
    }
