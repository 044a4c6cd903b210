"""What a model gives the steppers.

A model is the semi-discrete system

    M x'' + C x' + r(x, t) = 0,   G x = g(t),

over the unknowns of its ``layout`` (``rkfx.solvers.fields``): r = f_int(x) - f_ext(t) is the
residual (internal minus external forces, and fluxes), K = dr/dx its tangent, M the mass (it
multiplies the second derivatives of second-order fields), C the capacity (first derivatives;
it may couple fields, e.g. the storage row alpha div u' of the u-p equations) and G x = g the
essential conditions, imposed with multipliers. A model with history (damage, crack normals,
plastic strain, saturation) evaluates it as a *trial* from the committed state in every
``residual`` call; the steppers ``commit()`` once a step is accepted, so a failed Newton
iteration or a cut step never touches committed state, and checkpoints save ``state()``.

A capacity that depends on the state (unsaturated storage) is the optional term c(x, v)
of ``rate_force(x, v)``, with ``rate_tangents()`` = (dc/dx, dc/dv) at its last point, added
to C x' (``rkfx.solvers.newmark``). A model whose history update depends on the step (the
impl-ex damage of ``rkfx.fracture.history``) has ``start_step(t, dt)``, which the Newmark
stepper calls before each step it tries.

The steppers only call the methods below; ``rkfx.solvers.newmark`` and
``rkfx.solvers.quasi_static`` document which they need.
"""
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp

from rkfx.solvers.fields import FieldLayout


@dataclass(frozen=True)
class Constraints:
    """Essential conditions G x = g at one time.

    Attributes:
        G: Constraint rows, shape ``(k, size)`` (collocation rows of the RK transformation
            method, or unit rows of nodal FEM unknowns).
        g: Prescribed values, shape ``(k,)``.
        rate: dg/dt, shape ``(k,)``, or ``None`` (explicit steppers then difference g).
    """

    G: sp.csr_matrix
    g: np.ndarray
    rate: np.ndarray | None = None

    @property
    def count(self) -> int:
        return self.G.shape[0]


def no_constraints(size: int) -> Constraints:
    """The empty set of essential conditions for ``size`` unknowns."""
    return Constraints(sp.csr_matrix((0, size)), np.zeros(0))


def step_key(dt: float) -> float:
    """dt to 10 significant digits: steps of one size taken as differences of step times, which
    differ in their last bits (by about 1e-16 t), share a key whatever the unit of time."""
    return float(f"{dt:.10g}")


class PerStepSize:
    """What a model builds for one step size (capacity, stabilization), kept for the last few sizes.

    Args:
        keep: How many step sizes to keep per kind; the oldest goes first.
    """

    def __init__(self, keep: int = 4):
        self.keep = keep
        self._values: dict[tuple[str, float], object] = {}

    def get(self, what: str, dt: float, build: Callable[[float], object]):
        """``build(dt)`` for this kind and step size, built once while kept."""
        key = (what, step_key(dt))
        if key not in self._values:
            same = [k for k in self._values if k[0] == what]
            if len(same) >= self.keep:
                del self._values[same[0]]
            self._values[key] = build(dt)
        return self._values[key]


@runtime_checkable
class Model(Protocol):
    """The protocol every model implements (see the module docstring).

    Attributes:
        layout: The fields and their blocks.
        linear: True when M, C(dt) and K do not depend on x or t, so a stepper may reuse one
            factorization per step size and take one Newton iteration per step.
    """

    layout: FieldLayout
    linear: bool

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        """r(x, t) = f_int(x) - f_ext(t), shape ``(size,)``, with trial history from ``x``."""

    def tangent(self, x: np.ndarray, t: float) -> sp.spmatrix:
        """K = dr/dx at the last ``residual`` point, shape ``(size, size)``."""

    def mass(self) -> sp.spmatrix | None:
        """M, shape ``(size, size)``, or ``None`` (no inertia)."""

    def capacity(self, dt: float) -> sp.spmatrix | None:
        """C, shape ``(size, size)``, or ``None``; may depend on the step size (stabilization)."""

    def constraints(self, t: float) -> Constraints:
        """Essential conditions at time t (the rows G must not change with t)."""

    def commit(self) -> None:
        """Make the trial history of the last ``residual`` call the committed one."""

    def state(self) -> Mapping[str, np.ndarray]:
        """Committed history arrays, for checkpoints (empty for models without history)."""

    def restore(self, arrays: Mapping[str, np.ndarray]) -> None:
        """Set the committed history from ``state()`` arrays."""


class Stateless:
    """Mixin for models without history: commit, state and restore do nothing."""

    def commit(self) -> None:
        pass

    def state(self) -> dict[str, np.ndarray]:
        return {}

    def restore(self, arrays: Mapping[str, np.ndarray]) -> None:
        pass


def equation_weights(model, coefficients) -> np.ndarray | None:
    """Row weights a model asks for (``model.equation_weights(coefficients)``), or ``None``.

    A u-p model scales its storage rows by -1 / (dv/dx of u) to make the Jacobian the
    symmetric saddle-point matrix of eqs. (3.50)-(3.51) and (5.24); the solution is unchanged.
    """
    fn = getattr(model, "equation_weights", None)
    return None if fn is None else fn(coefficients)


class WithoutRates:
    """A model's static equilibria: ``model`` with its rate terms (mass, capacity,
    ``rate_force``) dropped, everything else its own. A load ramp stepped through this is a
    sequence of equilibria of the loads alone (a drained loading of a u-p model: its pore
    pressures keep the steady flow), whatever the ramp's pseudo-time."""

    _dropped = ("rate_force", "rate_tangents")

    def __init__(self, model):
        self._model = model

    def __getattr__(self, name):
        if name in WithoutRates._dropped:
            raise AttributeError(name)
        return getattr(self._model, name)

    def mass(self) -> None:
        return None

    def capacity(self, dt: float) -> None:
        return None
