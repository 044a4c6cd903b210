"""A factorized linear system reused over right-hand sides: PETSc when installed, else SciPy.

The core stays importable without PETSc; with ``rkfx[fem]`` installed every solve goes through
``rkfx.linalg.petsc`` (MUMPS LU by default, distributed over the communicator's ranks).
``solver="serial"`` factorizes a small system that every rank holds whole (the projection onto
the essential conditions, k x k for k constrained values) by SuperLU on each rank, with no
communication in its solves. A ``rkfx.parallel.unknowns.RowSystem`` (a rank's block of rows of
a distributed system) is solved on local vectors: its owned entries go to PETSc, and the
solution comes back with the ghost entries filled by their owners.
"""
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rkfx.errors import InputError
from rkfx.parallel.unknowns import RowSystem

# The PETSc solvers by name (``rkfx.linalg.petsc.make_ksp``).
SOLVERS = ("mumps", "gmres-ilu", "cg-gamg", "fieldsplit")


@dataclass(frozen=True)
class DisplacementSplit:
    """The block structure that the ``fieldsplit`` solver preconditions: the first g n unknowns
    (g = 2 or 3) are the displacements, interleaved per node; the others (pressures, multipliers
    of collocated conditions) form the second block.

    Attributes:
        coordinates: The n nodes, shape ``(n, 2)`` or ``(n, 3)`` [m]: their rigid-body modes are
            the near null space of the displacement block's multigrid.
        fixed_stress: The fixed-stress estimate of the coupling's share of the pressure Schur
            complement, alpha^2 / K_dr int N_I (K_dr the drained bulk modulus), per pressure
            unknown, shape ``(n,)``; the second block's own diagonal block, so shifted (away
            from zero, in its sign), preconditions the Schur complement. ``None``: PETSc's
            A_pp - A_pu diag(A_uu)^-1 A_up.
    """

    coordinates: np.ndarray
    fixed_stress: np.ndarray | None = None

    @property
    def dim(self) -> int:
        """Displacement components per node, 2 or 3."""
        return self.coordinates.shape[1]

    @property
    def size(self) -> int:
        """The displacement unknowns, g n (g = 2, or 3 for coordinates of shape ``(n, 3)``)."""
        return self.coordinates.shape[1] * len(self.coordinates)


class _ScipyLU:
    iterations, reason = 1, "direct"  # of every solve, as reported by the PETSc solvers

    def __init__(self, a: sp.spmatrix):
        import scipy.sparse.linalg as spla  # noqa: PLC0415

        try:
            self._lu = spla.splu(sp.csc_matrix(a))
        except RuntimeError as err:
            raise InputError(f"the system matrix is singular ({err}); essential boundary conditions must "
                             "remove all rigid-body modes") from None

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(np.asarray(b, float))

    def matches(self, a: sp.spmatrix) -> bool:
        return False  # SuperLU has no numerical refactorization to reuse

    def pivot_ratio(self) -> float:
        """Smallest over largest |pivot| of the factorization (0 for a numerically singular matrix)."""
        pivots = np.abs(self._lu.U.diagonal())
        return float(pivots.min() / pivots.max()) if pivots.size and pivots.max() > 0 else 0.0

    def destroy(self) -> None:
        pass


class _RowSystemSolver:
    """A distributed system given by each rank's ``RowSystem``, solved on local vectors."""

    def __init__(self, system, comm, solver: str, mumps_icntl):
        from rkfx.linalg import petsc  # noqa: PLC0415 - a distributed system needs PETSc

        self.system = system
        self._ls = petsc.LinearSolver(system.block, comm, solver, mumps_icntl, owned_rows=True)

    def solve(self, b: np.ndarray) -> np.ndarray:
        x = self._ls.solve(self.system.owned_values(b), whole=False)
        return self.system.local_values(x)

    @property
    def iterations(self) -> int:
        return self._ls.iterations

    @property
    def reason(self) -> str:
        return self._ls.reason

    def matches(self, a) -> bool:
        return False

    def destroy(self) -> None:
        self._ls.destroy()


def linear_solver(a: sp.spmatrix, comm=None, solver: str = "mumps", mumps_icntl: Mapping[int, int] | None = None,
                  owned_rows: bool = False, coordinates: np.ndarray | None = None,
                  split: DisplacementSplit | None = None):
    """An object with ``.solve(b)``, ``.destroy()`` and its last solve's ``.iterations`` and
    ``.reason`` for the matrix ``a`` (``mumps_icntl``:
    further MUMPS controls, see ``rkfx.linalg.petsc.make_ksp``; ignored without PETSc).
    ``solver="serial"``: SuperLU on each rank, for a small system every rank holds whole.
    ``owned_rows``: ``a`` and every ``b`` are this rank's block of rows of a distributed system
    (``rkfx.parallel.rows.owned_block``); ``solve`` still returns the whole solution.
    ``coordinates``: the nodes of this rank's rows of a 2-D displacement system, for the
    rigid-body modes of ``cg-gamg`` (see ``rkfx.linalg.petsc.make_ksp``). ``split``: the
    blocks of ``fieldsplit`` (required by it)."""
    if solver == "serial":
        return _ScipyLU(a)
    if solver == "fieldsplit" and split is None:
        raise InputError("solver='fieldsplit' needs its displacement block: pass split=DisplacementSplit(coordinates)")
    if split is not None and solver != "fieldsplit":
        raise InputError(f"split= is for solver='fieldsplit', not {solver!r}")
    if split is not None and (owned_rows or isinstance(a, RowSystem)):
        raise InputError("solver='fieldsplit' takes the whole system on every rank; solve with distributed=False, "
                         "or use solver='mumps' on distributed rows")
    if isinstance(a, RowSystem):
        try:
            return _RowSystemSolver(a, comm if comm is not None else a.share.comm, solver, mumps_icntl)
        except ImportError:
            raise InputError("a system distributed over MPI ranks needs PETSc: pip install 'rkfx[fem]'") from None
    try:
        from rkfx.linalg import petsc  # noqa: PLC0415
    except ImportError:
        if solver != "mumps" or (owned_rows and comm is not None and comm.size > 1):
            raise InputError(f"solver {solver!r}{' on distributed rows' * owned_rows} needs PETSc: pip install 'rkfx[fem]'") from None
        return _ScipyLU(a)
    return petsc.LinearSolver(a, comm if comm is not None else petsc.MPI.COMM_WORLD, solver, mumps_icntl, owned_rows,
                              coordinates, split=split)



class Factorizations:
    """The linear-solver door of the steppers: one factorization per key, a few kept.

    A linear model keyed by its step size reuses the factorization of every step of that size;
    ``key=None`` factorizes anew (a Newton iteration of a nonlinear model), and when the matrix
    has the sparsity pattern of the last unkeyed one, in that solver's PETSc objects with its
    symbolic analysis (a numerical refactorization: the same solution, a fraction of the set-up).

    Args:
        comm: Communicator (PETSc when installed).
        solver: ``mumps``, ``gmres-ilu`` or ``cg-gamg`` (see ``rkfx.linalg.petsc``).
        keep: Factorizations kept at once (the oldest is freed first).
        mumps_icntl: Further MUMPS controls, e.g. ``{7: 2}`` for the AMF ordering.
        reuse_analysis: A keyed matrix that takes the place of the oldest one when ``keep``
            are cached, with its sparsity pattern (a new step size of a linear model), is
            refactorized in that solver's objects like an unkeyed one.
    """

    def __init__(self, comm=None, solver: str = "mumps", keep: int = 5, mumps_icntl: Mapping[int, int] | None = None,
                 reuse_analysis: bool = False, split: DisplacementSplit | None = None):
        self.comm, self.solver, self.keep, self.mumps_icntl = comm, solver, int(keep), mumps_icntl
        self.reuse_analysis, self.split = reuse_analysis, split
        self._cache: dict = {}
        self.count = 0  # factorizations made
        self._retired = [0, 0]  # solves and Krylov iterations of the solvers freed so far
        # Set-up that steppers reuse from step to step of one run (keyed by the stepper).
        self.memo: dict = {}

    def get(self, key, build):
        """The solver for ``key``, factorizing ``build()`` when it is not cached."""
        if key is not None and key in self._cache:
            return self._cache[key]
        a = build()
        # The solver whose objects and analysis the matrix may take: the last unkeyed one or,
        # with reuse_analysis, the oldest keyed one, which is about to be freed.
        reusable = key is None or (self.reuse_analysis and len(self._cache) >= self.keep)
        old = None if key is None else next(iter(self._cache), None)
        spare = self._cache.get(old) if reusable else None
        if spare is not None and spare.matches(a):
            spare.refactor(a)
            self.count += 1
            if key is not None:  # the freed key's solver now serves this one
                del self._cache[old]
                self._cache[key] = spare
            return spare
        ls = linear_solver(a, self.comm, self.solver, self.mumps_icntl, split=self.split)
        self.count += 1
        if key is None:
            self._drop(None)
        elif len(self._cache) >= self.keep:
            self._drop(next(iter(self._cache)))
        self._cache[key] = ls
        return ls

    def linear_iterations(self) -> tuple[int, int]:
        """(solves, Krylov iterations) over every solver this object made (1 per direct solve)."""
        live = [(getattr(ls, "solves", 0), getattr(ls, "total_iterations", 0)) for ls in self._cache.values()]
        return self._retired[0] + sum(a for a, _ in live), self._retired[1] + sum(b for _, b in live)

    def _drop(self, key) -> None:
        old = self._cache.pop(key, None)
        if old is not None:
            self._retired[0] += getattr(old, "solves", 0)
            self._retired[1] += getattr(old, "total_iterations", 0)
            old.destroy()

    def destroy(self) -> None:
        for key in list(self._cache):
            self._drop(key)
