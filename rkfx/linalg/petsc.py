"""PETSc glue: scipy CSR -> distributed ``PETSc.Mat``, vectors, and KSP solves.

Import on purpose (``import rkfx.linalg.petsc``); the numerical core never imports PETSc. Every
function takes an MPI communicator. Matrices are distributed by contiguous row blocks
(PETSc's default ownership); each rank inserts only the rows it owns from the CSR data it
holds, so the same code runs serially and under ``mpiexec -n P``. A rank that holds only its
own block of rows (``rkfx.parallel.rows.owned_block``) builds the matrix with ``owned_rows_mat``,
preallocated from the block's diagonal and off-diagonal counts.
"""
import warnings
from collections.abc import Mapping

import dolfinx_solver  # noqa: F401  (orders MPI before petsc4py)
import numba
import numpy as np
import scipy.sparse as sp
from mpi4py import MPI
from petsc4py import PETSc

from rkfx.errors import InputError, SolverError
from rkfx.linalg.linear_solver import SOLVERS, DisplacementSplit
from rkfx.linalg.symmetry import is_symmetric

# Relative residual at which the Krylov solvers stop. CG + GAMG stops at 1e-8: on Timoshenko's
# beam (bench/beam_scale.py, 263k nodes) the displacement error is the same to three digits
# as at 1e-12 (4.5e-6), in 25 iterations instead of 40.
RTOL = {"gmres-ilu": 1e-12, "cg-gamg": 1e-8, "fieldsplit": 1e-10}

# GAMG drops the graph edges weaker than this before it aggregates: with 0.02 the iterations on
# the beam stay at 11-14 from 10^3 to 10^6 nodes (PETSc's default: 33 at 16k, 40 at 263k).
GAMG_THRESHOLD = 0.02

# Chebyshev sweeps per level and V-cycle (PETSc's default 2): one costs a few more iterations
# and less time on the beam, CG + GAMG back to back: 263k nodes 13 -> 15 iterations, 2.9 ->
# 2.0 s; 10^6 nodes 14 -> 16 iterations, 12.9 -> 9.0 s (bench/beam_scale.py).
GAMG_SMOOTHING_STEPS = 1


# PETSc's KSPConvergedReason codes by name (e.g. 2: CONVERGED_RTOL).
_REASONS = {code: name for name, code in vars(PETSc.KSP.ConvergedReason).items()
            if isinstance(code, int) and not name.startswith("_")}


class SolverDiverged(SolverError):
    """A PETSc linear solve did not converge."""


def to_petsc_mat(a: sp.spmatrix, comm=MPI.COMM_WORLD, even_below: int = 0, block: int = 2) -> PETSc.Mat:
    """Distributed AIJ matrix from a global scipy sparse matrix held on every rank.

    ``even_below``: below this row, every rank's rows start at a multiple of ``block`` (the
    interleaved displacements of a node, 2 or 3 of them, stay on one rank)."""
    a = _sorted_csr(a)
    n_rows, n_cols = a.shape
    mat = PETSc.Mat().create(comm=comm)
    local = PETSc.DECIDE
    if even_below and comm.size > 1:
        cuts = [n_rows * r // comm.size for r in range(comm.size + 1)]
        cuts = [c + (-c % block if c < even_below else 0) for c in cuts]
        local = cuts[comm.rank + 1] - cuts[comm.rank]
    mat.setSizes(((local, n_rows), (local, n_cols)))
    mat.setType(PETSc.Mat.Type.AIJ)
    mat.setUp()
    mat.setPreallocationCSR(_owned_rows(a, mat))
    mat.assemble()
    return mat


def owned_rows_mat(block: sp.spmatrix, comm=MPI.COMM_WORLD) -> PETSc.Mat:
    """Distributed square AIJ matrix from this rank's block of rows, shape ``(local_rows, n)``
    in a global numbering where the ranks' blocks follow each other in rank order; preallocated
    exactly (d_nnz: columns inside the block's own range, o_nnz: the others)."""
    block = _sorted_csr(block)
    m, n = block.shape
    mat = PETSc.Mat().create(comm=comm)
    mat.setSizes(((m, n), (m, n)))
    mat.setType(PETSc.Mat.Type.AIJ)
    lo = (comm.exscan(m) or 0) if comm.size > 1 else 0  # the block's first global row
    d_nnz = np.empty(m, PETSc.IntType)
    _columns_within(block.indptr, block.indices, lo, lo + m, d_nnz)
    o_nnz = (np.diff(block.indptr) - d_nnz).astype(PETSc.IntType)
    mat.setPreallocationNNZ((d_nnz, o_nnz))
    mat.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
    mat.setValuesCSR(block.indptr.astype(PETSc.IntType), block.indices.astype(PETSc.IntType, copy=False),
                     block.data.astype(PETSc.ScalarType, copy=False))
    mat.assemble()
    return mat


@numba.njit(cache=True)
def _columns_within(indptr, indices, lo, hi, out):
    """out[row] = the number of the row's columns in lo..hi-1."""
    for row in range(len(indptr) - 1):
        count = 0
        for q in range(indptr[row], indptr[row + 1]):
            if lo <= indices[q] < hi:
                count += 1
        out[row] = count


def _sorted_csr(a: sp.spmatrix) -> sp.csr_matrix:
    a = sp.csr_matrix(a)
    a.sort_indices()
    return a


def _owned_rows(a: sp.csr_matrix, mat: PETSc.Mat):
    """The CSR arrays (local row pointer, global columns, values) of the rows this rank owns."""
    lo, hi = mat.getOwnershipRange()
    ptr = a.indptr[lo:hi + 1]
    return ((ptr - ptr[0]).astype(PETSc.IntType), a.indices[ptr[0]:ptr[-1]].astype(PETSc.IntType, copy=False),
            a.data[ptr[0]:ptr[-1]].astype(PETSc.ScalarType, copy=False))


def to_petsc_vec(v: np.ndarray, mat: PETSc.Mat) -> PETSc.Vec:
    """Vector with the row layout of ``mat``, from a global array held on every rank."""
    vec = mat.createVecLeft()
    lo, hi = vec.getOwnershipRange()
    vec.array[:] = np.asarray(v, dtype=PETSc.ScalarType)[lo:hi]
    return vec


def gather(vec: PETSc.Vec) -> np.ndarray:
    """The whole vector on every rank."""
    comm = vec.getComm().tompi4py()
    if comm.size == 1:
        return vec.array_r.copy()
    return np.concatenate(comm.allgather(vec.array_r.copy()))


def make_ksp(mat: PETSc.Mat, solver: str = "mumps", rtol: float | None = None, prefix: str = "rkfx_",
             mumps_icntl: Mapping[int, int] | None = None, coordinates: np.ndarray | None = None,
             symmetric: bool = False, split: DisplacementSplit | None = None,
             whole: sp.csr_matrix | None = None) -> PETSc.KSP:
    """A KSP for ``mat``: MUMPS LU (default), GMRES with ILU/ASM, CG with GAMG, or GMRES
    with a Schur-complement field split (``fieldsplit``, ``_field_split``).

    ``symmetric`` (mumps): ``mat`` equals its transpose, and MUMPS factorizes it as L D L^T
    with pivoting (its symmetric indefinite mode), from the upper triangle only.

    ``mumps_icntl`` sets further MUMPS controls, e.g. ``{7: 2}`` for the AMF ordering.
    ``coordinates`` (cg-gamg on a displacement system, unknowns interleaved per node): the
    coordinates of the nodes of this rank's rows, shape ``(local_rows / g, g)`` for g = 2 or 3;
    GAMG then aggregates node blocks and keeps the rigid-body modes (3 or 6) on every level. ``rtol``: the
    relative residual to stop at (default ``RTOL[solver]``). PETSc options given with
    ``-rkfx_...`` on the command line or in ``PETSC_OPTIONS`` refine the choice, e.g.
    ``-rkfx_ksp_rtol 1e-10`` or ``-rkfx_pc_gamg_threshold 0.05``.
    """
    if solver not in SOLVERS:
        raise InputError(f"unknown linear solver {solver!r}; choose one of {', '.join(SOLVERS)}")
    ksp = PETSc.KSP().create(mat.getComm())
    ksp.setOperators(mat)
    ksp.setOptionsPrefix(prefix)
    rtol = RTOL.get(solver) if rtol is None else rtol
    pc = ksp.getPC()
    if solver == "mumps":
        ksp.setType("preonly")
        if symmetric:
            mat.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        pc.setType("cholesky" if symmetric else "lu")
        pc.setFactorSolverType("mumps")
        pc.setFactorSetUpSolverType()
        # Saddle-point systems (multiplier constraints, u-p coupling) delay pivots: give MUMPS
        # room for them (ICNTL(14): % extra workspace) instead of failing with INFOG(1) = -9.
        factor = pc.getFactorMatrix()
        factor.setOptionsPrefix(prefix)  # -<prefix>mat_mumps_icntl_<i> and _cntl_<i> reach MUMPS
        factor.setMumpsIcntl(14, 200)
        # Detect null pivots so that a singular system is reported, not "solved".
        factor.setMumpsIcntl(24, 1)
        for key, value in (mumps_icntl or {}).items():
            factor.setMumpsIcntl(key, value)
    elif solver == "gmres-ilu":
        ksp.setType("gmres")
        pc.setType("asm" if mat.getComm().size > 1 else "ilu")
        ksp.setTolerances(rtol=rtol, max_it=10000)
    elif solver == "fieldsplit":
        if split is None:
            raise InputError("solver='fieldsplit' needs split=DisplacementSplit(coordinates)")
        _field_split(ksp, mat, split, rtol, prefix, whole)
    else:
        ksp.setType("cg")
        pc.setType("gamg")
        ksp.setTolerances(rtol=rtol, max_it=10000)
        _gamg_defaults(prefix)
        if coordinates is not None:
            _rigid_body_modes(mat, coordinates)
    ksp.setFromOptions()
    return ksp


def _gamg_defaults(prefix: str) -> None:
    """GAMG_THRESHOLD and GAMG_SMOOTHING_STEPS under ``prefix``, unless the user set them."""
    options = PETSc.Options(prefix)
    for name, value in (("pc_gamg_threshold", GAMG_THRESHOLD), ("mg_levels_ksp_max_it", GAMG_SMOOTHING_STEPS)):
        if not options.hasName(name):
            options.setValue(name, value)


def _field_split(ksp: PETSc.KSP, mat: PETSc.Mat, split: DisplacementSplit, rtol: float, prefix: str,
                 a: sp.csr_matrix | None = None) -> None:
    """GMRES on [[A_uu, A_up], [A_pu, A_pp]] (u: the first ``split.size`` rows), preconditioned
    by the full Schur factorization: A_uu by one V-cycle of smoothed aggregation (GAMG, the
    nodes' rigid-body modes as near null space), the Schur complement through the fixed-stress
    approximation: A_pp with alpha^2 / K_dr int N_I added to its pressure diagonal, away from
    zero in that diagonal's sign (``DisplacementSplit.fixed_stress``, with the whole matrix
    ``a`` held on every rank), or else PETSc's A_pp - A_pu diag(A_uu)^-1 A_up
    ("selfp", poor for RK's overlapping supports), factorized by MUMPS. The second block, the
    pressures (and multipliers), is a scalar field: a third of the unknowns and a fraction of
    the fill of the whole system's LU. GMRES is preconditioned on the right, so that it stops
    on the true residual. Options under ``-rkfx_fieldsplit_u_`` and ``-rkfx_fieldsplit_p_``
    refine either block."""
    comm = mat.getComm()
    lo, hi = mat.getOwnershipRange()
    n_u, g = split.size, split.dim
    u_lo, u_hi = min(lo, n_u), min(hi, n_u)
    if u_lo % g:
        raise InputError("fieldsplit: a rank's rows begin inside a node's displacement components; build the "
                         "matrix with to_petsc_mat(..., even_below=g n, block=g)")
    is_u = PETSc.IS().createStride(u_hi - u_lo, u_lo, 1, comm=comm)
    p_lo = min(max(lo, n_u), hi)
    is_p = PETSc.IS().createStride(hi - p_lo, p_lo, 1, comm=comm)
    x = np.ascontiguousarray(split.coordinates[u_lo // g:u_hi // g], dtype=PETSc.ScalarType)
    modes = PETSc.Vec().createMPI((u_hi - u_lo, PETSc.DECIDE), bsize=g, comm=comm)
    modes.array[:] = x.ravel()
    is_u.setBlockSize(g)
    is_u.compose("nearnullspace", PETSc.NullSpace().createRigidBody(modes))
    modes.destroy()
    ksp.setType("gmres")
    ksp.setGMRESRestart(100)
    ksp.setPCSide(PETSc.PC.Side.RIGHT)
    ksp.setTolerances(rtol=rtol, max_it=1000)
    pc = ksp.getPC()
    pc.setType("fieldsplit")
    pc.setFieldSplitIS(("u", is_u), ("p", is_p))
    pc.setFieldSplitType(PETSc.PC.CompositeType.SCHUR)
    pc.setFieldSplitSchurFactType(PETSc.PC.FieldSplitSchurFactType.FULL)
    if split.fixed_stress is not None and a is not None:
        a11 = sp.csr_matrix(a[n_u:, n_u:])
        shift = np.zeros(a11.shape[0])
        m = len(split.fixed_stress)
        pp = a11.diagonal()[:m]
        shift[:m] = np.where(pp < 0, -1.0, 1.0) * np.asarray(split.fixed_stress, float)
        schur = _block_mat(a11 + sp.diags(shift), is_p, n_u, comm)
        pc.setFieldSplitSchurPreType(PETSc.PC.FieldSplitSchurPreType.USER, schur)
        schur.destroy()  # the PC holds its own reference
    else:
        pc.setFieldSplitSchurPreType(PETSc.PC.FieldSplitSchurPreType.SELFP)
    options = PETSc.Options(prefix)
    for name, value in (("fieldsplit_u_ksp_type", "preonly"), ("fieldsplit_u_pc_type", "gamg"),
                        ("fieldsplit_p_ksp_type", "preonly"), ("fieldsplit_p_pc_type", "lu"),
                        ("fieldsplit_p_pc_factor_mat_solver_type", "mumps"),
                        ("fieldsplit_p_mat_mumps_icntl_14", 200)):
        if not options.hasName(name):
            options.setValue(name, value)
    _gamg_defaults(prefix + "fieldsplit_u_")


def _block_mat(block: sp.csr_matrix, rows: PETSc.IS, first: int, comm) -> PETSc.Mat:
    """The AIJ matrix of a diagonal block held whole on every rank, whose global rows begin at
    ``first``; each rank takes the rows of ``rows`` (its contiguous range of them)."""
    block = _sorted_csr(block)
    m = rows.getLocalSize()
    lo = rows.getIndices()[0] - first if m else 0
    mat = PETSc.Mat().create(comm=comm)
    mat.setSizes(((m, block.shape[0]), (m, block.shape[1])))
    mat.setType(PETSc.Mat.Type.AIJ)
    mat.setUp()
    ptr = block.indptr[lo:lo + m + 1]
    mat.setPreallocationCSR(((ptr - ptr[0]).astype(PETSc.IntType),
                             block.indices[ptr[0]:ptr[-1]].astype(PETSc.IntType),
                             block.data[ptr[0]:ptr[-1]].astype(PETSc.ScalarType)))
    mat.assemble()
    return mat


def _rigid_body_modes(mat: PETSc.Mat, coordinates: np.ndarray) -> None:
    """Give ``mat`` (interleaved 2-D or 3-D displacements, as ``coordinates`` has 2 or 3 columns)
    the rigid-body modes of its nodes (3 or 6) as its near null space, for smoothed aggregation."""
    g = np.shape(coordinates)[-1]
    x = np.ascontiguousarray(coordinates, dtype=PETSc.ScalarType).reshape(-1, g)
    lo, hi = mat.getOwnershipRange()
    if g * len(x) != hi - lo:
        raise InputError(f"coordinates of {len(x)} nodes for {hi - lo} rows; give the nodes of this rank's rows "
                         f"({g} unknowns per node, no multiplier rows)")
    vec = PETSc.Vec().createMPI((g * len(x), PETSc.DECIDE), bsize=g, comm=mat.getComm())
    vec.array[:] = x.ravel()
    mat.setBlockSize(g)
    mat.setNearNullSpace(PETSc.NullSpace().createRigidBody(vec))
    vec.destroy()


class LinearSolver:
    """A factorized (or preconditioned) system ``a x = b`` reused for many right-hand sides.

    Time-stepping loops keep one per distinct matrix (e.g. per time-step size), so MUMPS
    factorizes once. Every solve is checked: null pivots, divergence and a large residual
    raise ``SolverDiverged``.
    """

    def __init__(self, a: sp.spmatrix, comm=MPI.COMM_WORLD, solver: str = "mumps",
                 mumps_icntl: Mapping[int, int] | None = None, owned_rows: bool = False,
                 coordinates: np.ndarray | None = None, symmetric: bool = False,
                 split: DisplacementSplit | None = None):
        self.solver, self.owned_rows = solver, owned_rows
        a = _sorted_csr(a)
        if owned_rows:  # a is this rank's block of rows (owned_rows_mat); b is too
            self.pattern = None
            self.mat = owned_rows_mat(a, comm)
        else:
            self.pattern = (a.shape, a.indptr.copy(), a.indices.copy())
            self.mat = to_petsc_mat(a, comm, even_below=0 if split is None else split.size,
                                    block=2 if split is None else split.dim)
        # symmetric=True: L D L^T for a matrix that is (``is_symmetric``), whole on every rank.
        # Not the default: on the saddle points of the transformation method (zero diagonal
        # block) MUMPS's pivoting L D L^T took 36.9 s where LU took 4.2 s (Sneddon, 99,844
        # unknowns); on Mandel's u-p steps it saved memory (docs/verification.md).
        self.symmetric = symmetric and solver == "mumps" and not owned_rows and is_symmetric(a)
        self.ksp = make_ksp(self.mat, solver, mumps_icntl=mumps_icntl, coordinates=coordinates,
                            symmetric=self.symmetric, split=split, whole=a if split is not None else None)
        self.rhs = self.mat.createVecLeft()
        self.x = self.mat.createVecRight()
        self.residual = self.mat.createVecLeft()
        self._norm = self.mat.norm(PETSc.NormType.NORM_INFINITY)
        self._warned = False
        self.iterations = 0  # Krylov iterations of the last solve (1 for a direct solve)
        self.reason = ""  # PETSc's name of why the last solve stopped
        self.solves = self.total_iterations = 0  # over this solver's life

    def solve(self, b: np.ndarray, whole: bool = True) -> np.ndarray:
        """The whole solution on every rank (``b``: the whole right-hand side, or this rank's
        entries of it when the solver was built from owned rows); ``whole=False``: this
        rank's entries of it only."""
        lo, hi = self.rhs.getOwnershipRange()
        b = np.asarray(b, dtype=PETSc.ScalarType)
        self.rhs.array[:] = b if self.owned_rows else b[lo:hi]
        try:
            self.ksp.solve(self.rhs, self.x)
        except PETSc.Error as err:
            raise SolverDiverged(f"PETSc solver {self.solver!r} failed ({err}); the system may be singular: "
                                 "check that essential boundary conditions remove all rigid-body modes") from None
        null_pivots = self.ksp.getPC().getFactorMatrix().getMumpsInfog(28) if self.solver == "mumps" else 0
        reason = self.ksp.getConvergedReason()
        self.iterations = max(self.ksp.getIterationNumber(), 1 if self.solver == "mumps" else 0)
        self.reason = _REASONS.get(reason, str(reason))
        self.solves += 1
        self.total_iterations += self.iterations
        if reason < 0:
            raise SolverDiverged(f"PETSc solver {self.solver!r} diverged (KSPConvergedReason {reason}) after "
                                 f"{self.ksp.getIterationNumber()} iterations; try solver='mumps' or check the "
                                 "boundary conditions")
        self.mat.mult(self.x, self.residual)
        self.residual.axpy(-1.0, self.rhs)
        # Normwise backward error ||A x - b|| / (||A|| ||x|| + ||b||): independent of whether b
        # is a whole right-hand side or a Newton residual of a nearly converged state.
        inf = PETSc.NormType.NORM_INFINITY
        scale = max(self._norm * self.x.norm(inf) + self.rhs.norm(inf), 1e-300)
        error = self.residual.norm(inf) / scale
        if error > 1e-6:
            what = f"singular ({null_pivots} null pivots)" if null_pivots else "singular or ill-conditioned"
            raise SolverDiverged(f"PETSc solver {self.solver!r} left a backward error of {error:.2e}: the system "
                                 f"is {what}; check that the essential boundary conditions remove all rigid-body "
                                 "modes")
        if null_pivots and not self._warned:
            # Consistent but nearly singular, e.g. the spurious modes of direct nodal integration.
            warnings.warn(f"system matrix has {null_pivots} null pivot(s) (nearly singular); the solution "
                          "satisfies the equations but is not unique in those modes", RuntimeWarning, stacklevel=2)
            self._warned = True
        return gather(self.x) if whole else self.x.array_r.copy()

    def matches(self, a: sp.spmatrix) -> bool:
        """Whether ``a`` has this system's sparsity pattern (so ``refactor`` may take it)."""
        if self.pattern is None or self.solver == "fieldsplit":  # its Schur preconditioner is built once
            return False
        a = _sorted_csr(a)
        shape, indptr, indices = self.pattern
        return (a.shape == shape and np.array_equal(a.indptr, indptr) and np.array_equal(a.indices, indices)
                and (not self.symmetric or is_symmetric(a)))

    def refactor(self, a: sp.spmatrix) -> None:
        """Take the values of ``a`` (same pattern): the next solve factorizes anew, reusing the
        symbolic analysis and the PETSc objects."""
        self.mat.zeroEntries()
        self.mat.setValuesCSR(*_owned_rows(_sorted_csr(a), self.mat))
        self.mat.assemble()
        self._norm = self.mat.norm(PETSc.NormType.NORM_INFINITY)
        self.ksp.setOperators(self.mat)

    def destroy(self) -> None:
        for obj in (self.ksp, self.mat, self.rhs, self.x, self.residual):
            obj.destroy()


def solve(a: sp.spmatrix, b: np.ndarray, comm=MPI.COMM_WORLD, solver: str = "mumps") -> np.ndarray:
    """Solve ``a x = b`` through PETSc; returns the whole solution on every rank.

    Raises:
        SolverDiverged: Naming PETSc's reason and what to try instead.
    """
    ls = LinearSolver(a, comm, solver)
    try:
        return ls.solve(b)
    finally:
        ls.destroy()
