"""Rigid plane walls touched by moving particles: a penalty normal force and Coulomb friction.

A wall is the half-plane (x - point) . normal >= 0 with ``normal`` pointing into the material.
A particle L with gap g_L = (x_L - point) . normal < 0 is pushed back by

    F_n = -kappa m_L / dt^2 g_L        (kappa in (0, 1): a spring a particle's mass tolerates at dt)

and, over a step in which it slid by the tangential increment du_t, held by the friction force
that would stop it within the step, capped by Coulomb's limit:

    F_t = -sign(du_t) min(m_L |du_t| / dt^2, mu F_n).

The forces act at the particles; a model spreads them to the RK coefficients by the transpose of
the interpolation rows (the virtual work of u^h(x_L) . F_L). A penalty in units of the particle's
own mass keeps the explicit step stable: the wall adds kappa / dt^2 < (2 / dt)^2 to the largest
frequency of a particle in contact.
"""
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError


@dataclass(frozen=True)
class Wall:
    """A rigid wall through ``point`` with unit ``normal`` into the material.

    Attributes:
        point: A point of the wall, shape ``(2,)`` [m].
        normal: Direction into the material, shape ``(2,)`` (normalized here).
        friction: Coulomb coefficient mu = tan(delta) >= 0 (0: a smooth wall).
        name: For messages and reports.
    """

    point: tuple[float, float]
    normal: tuple[float, float]
    friction: float = 0.0
    name: str = "wall"

    def __post_init__(self):
        n = np.asarray(self.normal, float)
        if n.shape != (2,) or not np.linalg.norm(n) > 0:
            raise InputError(f"wall {self.name!r} has normal {self.normal!r}; give a nonzero 2-vector into the material")
        if not (np.isfinite(self.friction) and self.friction >= 0):
            raise InputError(f"wall {self.name!r} has friction {self.friction!r}; give mu = tan(delta) >= 0")
        object.__setattr__(self, "normal", tuple(n / np.linalg.norm(n)))
        object.__setattr__(self, "point", tuple(np.asarray(self.point, float)))

    def gap(self, x: np.ndarray) -> np.ndarray:
        """(x - point) . normal of points ``(m, 2)`` [m]; negative inside the wall."""
        return (x - np.asarray(self.point)) @ np.asarray(self.normal)


@dataclass(frozen=True)
class WallContact:
    """The forces of all walls on the particles after a step.

    Attributes:
        force: Shape ``(num_particles, 2)`` [N per unit thickness].
        touching: Particles in contact with any wall, shape ``(num_particles,)`` bool.
        sliding: Particles at Coulomb's limit on some wall, shape ``(num_particles,)`` bool.
    """

    force: np.ndarray
    touching: np.ndarray
    sliding: np.ndarray


def wall_forces(walls: Sequence[Wall], x: np.ndarray, du: np.ndarray, mass: np.ndarray, dt: float,
                kappa: float = 0.1) -> WallContact:
    """Contact forces at particles ``x`` (m, 2) [m] that moved by ``du`` (m, 2) [m] in the last step.

    Args:
        walls: The walls.
        x: Particle positions after the step.
        du: Their displacement over the step.
        mass: Particle masses, shape ``(m,)`` [kg per unit thickness].
        dt: The time step [s].
        kappa: The penalty in units of m / dt^2, in (0, 1).
    """
    if not 0.0 < kappa < 1.0:
        raise InputError(f"wall penalty kappa = {kappa!r} must lie in (0, 1) (units of the particle mass / dt^2)")
    force = np.zeros_like(x)
    touching = np.zeros(len(x), bool)
    sliding = np.zeros(len(x), bool)
    stiff = mass / (dt * dt)
    for w in walls:
        g = w.gap(x)
        hit = np.flatnonzero(g < 0.0)
        if hit.size == 0:
            continue
        n = np.asarray(w.normal)
        t = np.array([-n[1], n[0]])
        fn = -kappa * stiff[hit] * g[hit]
        force[hit] += fn[:, None] * n
        touching[hit] = True
        if w.friction > 0.0:
            slip = du[hit] @ t
            stop = stiff[hit] * np.abs(slip)
            limit = w.friction * fn
            ft = -np.sign(slip) * np.minimum(stop, limit)
            force[hit] += ft[:, None] * t
            sliding[hit[stop > limit]] = True
    return WallContact(force, touching, sliding)
