"""Errors raised for bad input, each naming the culprit and the fix."""


class InputError(ValueError):
    """Invalid user input: the message names the parameter or node and how to fix it."""


class SolverError(RuntimeError):
    """A linear or nonlinear solve failed: the message names the reason and what to change."""


class SingularMomentMatrix(InputError):
    """The RK moment matrix (eq. 3.24) is singular at an evaluation point."""


def point_str(p) -> str:
    """Coordinates as a short plain tuple, for error messages."""
    return "(" + ", ".join(f"{float(v):.6g}" for v in p) + ")"
