"""Boundary conditions: one vocabulary for every model, RKPM and FEM alike.

A condition names a boundary part and a value. The part is the name of a tagged boundary
(``"left"``, a gmsh physical group) or a marker ``marker(x) -> bool (m,)``; an essential
condition may also hold on a ``Region``, particles anywhere in the domain (a pressurized
notch or crack). The value is a
number, a constant vector, or a function: ``value(x, t)`` for essential conditions and
``value(x, t, n)`` for tractions and fluxes, with x and the outward normals n of shape
``(m, gdim)`` [m] and t [s]. ``values(condition, x, t, n)`` evaluates any of them to an array with
one row per point and one column per prescribed component.

Essential: ``Displacement`` (and ``Velocity`` for explicit dynamics, e.g. an impact),
``Pressure``. Natural: ``Traction`` (total traction (sigma'' - alpha p I) n in u-p models),
``Flux`` (outward normal fluid flux q . n).
"""
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rkfx.errors import InputError



@dataclass(frozen=True)
class Region:
    """The particles anywhere in the domain (not only on its boundary) whose coordinates
    ``marker(x) -> bool (m,)`` accepts: where an essential condition prescribes a field inside
    the domain, e.g. the fluid pressure in a notch or a pre-existing crack (seed 5.3).

    Attributes:
        marker: Takes x of shape ``(m, gdim)`` [m], returns a bool array of shape ``(m,)``.
        name: How messages and reports name the region.
    """

    marker: Callable[[np.ndarray], np.ndarray]
    name: str = "region"

    def __post_init__(self):
        if not callable(self.marker):
            raise InputError(f"Region {self.name!r}: marker {self.marker!r} is not callable; give a function "
                             "marker(x) -> bool (m,)")


Boundary = str | Callable[[np.ndarray], np.ndarray] | Region
Value = float | Sequence[float] | np.ndarray | Callable[..., Any]


def _check_value(condition) -> None:
    """A constant value must be finite numbers (a function of x and t is checked where evaluated)."""
    if callable(condition.value):
        return
    try:
        v = np.asarray(condition.value, dtype=float)
    except (TypeError, ValueError):
        v = None
    if v is None or not np.all(np.isfinite(v)):
        raise InputError(f"{type(condition).__name__} on {condition.boundary!r}: value {condition.value!r} must be "
                         "finite numbers or a function of (x, t); list the prescribed components in components=")


@dataclass(frozen=True)
class _Vectorial:
    """A condition on some components of a vector field; ``components=None`` (the default) means
    every component: x and y in 2-D, x, y and z in 3-D (``prescribed(dim)``)."""

    boundary: Boundary
    value: Value = 0.0
    components: tuple[int, ...] | None = None

    def __post_init__(self):
        _check_value(self)
        if self.components is None:
            return
        comps = tuple(self.components)
        if not comps or len(set(comps)) != len(comps) or any(int(k) != k or k < 0 or k > 2 for k in comps):
            raise InputError(f"{type(self).__name__} on {self.boundary!r}: components {self.components!r} must be "
                             "distinct indices 0 (x), 1 (y) or 2 (z)")

    def prescribed(self, dim: int) -> tuple[int, ...]:
        """The prescribed components in ``dim`` dimensions (all of them when ``components`` is None)."""
        return tuple(range(dim)) if self.components is None else tuple(self.components)


@dataclass(frozen=True)
class _Scalar:
    """A condition on a scalar field."""

    boundary: Boundary
    value: Value = 0.0
    components: tuple[int, ...] = (0,)

    def __post_init__(self):
        _check_value(self)

    def prescribed(self, dim: int) -> tuple[int, ...]:
        """The one component of the scalar field, ``(0,)``."""
        return (0,)


class Displacement(_Vectorial):
    """u_c = value for the listed components c on a boundary part [m].

    ``value(x, t)`` may return every component ``(m, gdim)``, the prescribed ones
    ``(m, len(components))``, or ``(m,)`` for one component.
    """


class Velocity(_Vectorial):
    """du_c/dt = value for the listed components c on a boundary part [m/s] (explicit dynamics)."""


class Traction(_Vectorial):
    """Traction t = value(x, t, n) (total traction in u-p models) on a boundary part [Pa]."""


class Pressure(_Scalar):
    """p = value on a boundary part (drained when 0) [Pa]."""


class Flux(_Scalar):
    """Outward normal fluid flux q . n = value(x, t, n) on a boundary part [m/s]."""


Condition = Displacement | Velocity | Pressure | Traction | Flux
ESSENTIAL = (Displacement, Velocity, Pressure)
NATURAL = (Traction, Flux)


def values(condition: Condition, x: np.ndarray, t: float = 0.0, n: np.ndarray | None = None) -> np.ndarray:
    """The condition's value at points x and time t, shape ``(m, len(components))`` (the
    prescribed components in the dimension of x, ``condition.prescribed(gdim)``).

    Args:
        condition: Any condition of this module.
        x: Points, shape ``(m, gdim)`` [m].
        t: Time [s].
        n: Outward unit normals at x, shape ``(m, gdim)`` (tractions and fluxes that use them).
    """
    x = np.asarray(x, float)
    m = len(x)
    comps = list(condition.prescribed(x.shape[1]))
    v = condition.value
    if not callable(v):
        out = v
    elif isinstance(condition, NATURAL):
        if n is None:
            raise InputError(f"{type(condition).__name__} on {condition.boundary!r}: value(x, t, n) is evaluated "
                             "on boundary points with normals; pass n")
        out = v(x, t, n)
    else:
        out = v(x, t)
    out = np.asarray(out, float)
    if out.ndim == 0:
        return np.full((m, len(comps)), float(out))
    if out.ndim == 1 and out.shape[0] == x.shape[1] and m != x.shape[1] and len(comps) > 1:
        out = np.broadcast_to(out, (m, x.shape[1]))  # a constant vector
    if out.ndim == 1:
        if out.shape[0] != m or len(comps) != 1:
            if out.shape[0] == len(comps):
                return np.broadcast_to(out, (m, len(comps))).copy()
            raise InputError(f"{type(condition).__name__} on {condition.boundary!r}: value has shape "
                             f"{out.shape} for {m} points and components {tuple(comps)}")
        return out.reshape(m, 1)
    if out.shape == (m, len(comps)):
        return out
    if out.shape[0] == m and out.shape[1] > max(comps):
        return out[:, comps]
    raise InputError(f"{type(condition).__name__} on {condition.boundary!r}: value has shape {out.shape} for "
                     f"{m} points and components {tuple(comps)}; return (m,), (m, {len(comps)}) or (m, gdim)")


def split(conditions: Sequence[Condition]) -> dict[type, list[Condition]]:
    """The conditions grouped by kind, in their order; unknown objects raise a one-line error."""
    out: dict[type, list[Condition]] = {k: [] for k in (Displacement, Velocity, Pressure, Traction, Flux)}
    for c in conditions:
        if type(c) not in out:
            raise InputError(f"{c!r} is not a boundary condition; use rkfx.conditions.Displacement, Velocity, "
                             "Pressure, Traction or Flux")
        out[type(c)].append(c)
    return out
