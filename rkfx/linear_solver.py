"""A factorized linear system reused over right-hand sides: PETSc when installed, else SciPy.

The core stays importable without PETSc; with ``rkfx[fem]`` installed every solve goes through
``rkfx.petsc`` (MUMPS LU by default, distributed over the communicator's ranks).
"""
import numpy as np
import scipy.sparse as sp

from .errors import InputError


class _ScipyLU:
    def __init__(self, a: sp.spmatrix):
        import scipy.sparse.linalg as spla  # noqa: PLC0415

        try:
            self._lu = spla.splu(sp.csc_matrix(a))
        except RuntimeError as err:
            raise InputError(f"the system matrix is singular ({err}); essential boundary conditions must "
                             "remove all rigid-body modes") from None

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(np.asarray(b, float))

    def destroy(self) -> None:
        pass


def linear_solver(a: sp.spmatrix, comm=None, solver: str = "mumps"):
    """An object with ``.solve(b)`` and ``.destroy()`` for the matrix ``a``."""
    try:
        from . import petsc  # noqa: PLC0415
    except ImportError:
        if solver != "mumps":
            raise InputError(f"solver {solver!r} needs PETSc: pip install 'rkfx[fem]'") from None
        return _ScipyLU(a)
    return petsc.LinearSolver(a, comm if comm is not None else petsc.MPI.COMM_WORLD, solver)
