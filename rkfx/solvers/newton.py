"""The one nonlinear solve: Newton's method with an optional backtracking line search.

Every stepper hands Newton a ``System`` over its unknowns z (state increments, multipliers,
load factors): the residual F(z), the Jacobian dF/dz, and its own convergence test. Linear
solves go through ``rkfx.linalg.linear_solver.Factorizations`` (PETSc with the caller's communicator
when installed), which also reuses the factorization of a linear system.
"""
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
import scipy.sparse as sp

from rkfx.errors import InputError, SolverError
from rkfx.linalg.linear_solver import Factorizations

# Why a Newton solve ended.
CONVERGED = "converged"      # the system's convergence test passed
LINEAR = "linear"            # one iteration of a linear (affine) system
MAX_ITERATIONS = "max-iterations"
NOT_FINITE = "not-finite"    # residual or step with inf/NaN
LINE_SEARCH = "line-search"  # no step length reduced the residual
SINGULAR = "singular"        # the linear solve failed
DIVERGED = "diverged"        # the residual grew past options.divergence times its start
REASONS = (CONVERGED, LINEAR, MAX_ITERATIONS, NOT_FINITE, LINE_SEARCH, SINGULAR, DIVERGED)


class System(Protocol):
    """A nonlinear system F(z) = 0 for Newton.

    Attributes:
        linear: F is affine in z (one iteration solves it).
    """

    linear: bool

    def residual(self, z: np.ndarray) -> np.ndarray:
        """F(z)."""

    def jacobian(self, z: np.ndarray) -> sp.spmatrix:
        """dF/dz at the last ``residual`` point."""

    def jacobian_key(self):
        """A hashable key under which the Jacobian may be reused, or ``None``."""

    def converged(self, z: np.ndarray, r: np.ndarray, iteration: int) -> bool:
        """The convergence test at iterate ``iteration`` (0: the initial guess)."""

    # Optional: ``norm(r)``, the largest |entry| of a vector of the system over all MPI ranks
    # when each rank holds its part of z (default: of the whole vector on this process).


@dataclass(frozen=True)
class NewtonOptions:
    """Newton's settings.

    Attributes:
        max_iterations: Iterations before giving up.
        line_search: Backtrack (halve the step) while the residual norm grows.
        max_backtracks: Halvings per iteration.
        divergence: Give up when ||F|| exceeds this multiple of the initial norm.
    """

    max_iterations: int = 25
    line_search: bool = False
    max_backtracks: int = 8
    divergence: float = 1e12

    def __post_init__(self):
        if int(self.max_iterations) != self.max_iterations or self.max_iterations < 1:
            raise InputError(f"max_iterations = {self.max_iterations!r} must be a positive integer")
        if int(self.max_backtracks) != self.max_backtracks or self.max_backtracks < 0:
            raise InputError(f"max_backtracks = {self.max_backtracks!r} must be a non-negative integer")


@dataclass
class NewtonResult:
    """How a Newton solve ended.

    Attributes:
        z: The last iterate.
        converged: The convergence test passed.
        reason: One of ``REASONS``.
        iterations: Linear solves made.
        norms: ||F||_inf per iterate, the initial guess first.
        message: Why it failed, or ``""``.
    """

    z: np.ndarray
    converged: bool
    reason: str
    iterations: int
    norms: list[float] = field(default_factory=list)
    message: str = ""

    def error(self, where: str) -> SolverError:
        """A one-line error naming ``where`` (the step), the iteration and the residual."""
        norm = self.norms[-1] if self.norms else float("nan")
        return SolverError(f"Newton failed at {where}, iteration {self.iterations}: {self.reason} "
                           f"(residual {norm:.3e}){': ' + self.message if self.message else ''}; "
                           "reduce the step or check the model's parameters")


def _local_norm(r: np.ndarray) -> float:
    return float(np.abs(r).max()) if r.size else 0.0


def newton(system: System, z0: np.ndarray, solves: Factorizations,
           options: NewtonOptions = NewtonOptions()) -> NewtonResult:
    """Solve F(z) = 0 from ``z0``.

    Each iteration solves J dz = -F; with ``options.line_search`` the step is halved while
    ||F(z + s dz)|| does not decrease. A linear system returns after its first solve without
    evaluating F again.

    Args:
        system: The residual, Jacobian and convergence test.
        z0: Initial guess (not modified).
        solves: Where the Jacobians are factorized (and reused under their key).
        options: Iteration limits and line search.
    """
    _norm = getattr(system, "norm", _local_norm)
    z = np.array(z0, float)
    r = system.residual(z)
    norms = [_norm(r)]
    if not np.isfinite(norms[0]):
        return NewtonResult(z, False, NOT_FINITE, 0, norms, "the residual at the initial guess is not finite")
    for it in range(options.max_iterations):
        if system.converged(z, r, it):
            return NewtonResult(z, True, CONVERGED, it, norms)
        try:
            ls = solves.get(system.jacobian_key(), lambda: system.jacobian(z))
            dz = ls.solve(-r)
        except (SolverError, InputError) as err:
            return NewtonResult(z, False, SINGULAR, it, norms, str(err))
        if not np.isfinite(_norm(dz)):
            return NewtonResult(z, False, NOT_FINITE, it + 1, norms, "the Newton step is not finite")
        if system.linear:
            return NewtonResult(z + dz, True, LINEAR, it + 1, norms)
        z_new = z + dz
        r_new = system.residual(z_new)
        if options.line_search:
            s = 1.0
            for _ in range(options.max_backtracks):
                if np.isfinite(_norm(r_new)) and _norm(r_new) < norms[-1]:
                    break
                s *= 0.5
                z_new = z + s * dz
                r_new = system.residual(z_new)
            else:
                if not _norm(r_new) < norms[-1]:
                    return NewtonResult(z, False, LINE_SEARCH, it + 1, norms + [_norm(r_new)],
                                        f"no step length down to 2^-{options.max_backtracks} reduced the residual")
        z, r = z_new, r_new
        norms.append(_norm(r))
        if not np.isfinite(norms[-1]):
            return NewtonResult(z, False, NOT_FINITE, it + 1, norms, "the residual is not finite")
        if norms[-1] > options.divergence * max(norms[0], 1e-300):
            return NewtonResult(z, False, DIVERGED, it + 1, norms,
                                f"the residual grew {norms[-1] / max(norms[0], 1e-300):.2e} times")
    if system.converged(z, r, options.max_iterations):
        return NewtonResult(z, True, CONVERGED, options.max_iterations, norms)
    return NewtonResult(z, False, MAX_ITERATIONS, options.max_iterations, norms,
                        f"not converged in {options.max_iterations} iterations")
