"""Central differences with a lumped mass: M d'' = f_ext(t) - f_int(d) (eq. 4.35).

The stepper advances an explicit model (``ExplicitModel``): the fields of its ``layout``
(every field of time order 2: d, v = d', a = d''; any sizes and components), a lumped mass
per unknown, the internal force f_int(d), the external force f_ext(t) and essential
conditions (``Constraint``). The internal force is any callable of d, so a damage law plugs
in (``rkfx.models.damage_dynamics.DamageDynamics``): it is called exactly once per step, with the new
coefficients, and may update history in place, which commits it (an explicit step is never
retried). ``ExplicitBase`` gives such a model the rest of the protocol of
``rkfx.solvers.model`` (mass, capacity, residual, constraints, commit, restore).

One step n -> n+1 (Belytschko, Liu & Moran, Box 6.1), with a_n = M^-1 (f_ext_n - f_int_n):

    v_{n+1/2} = v_n + dt/2 a_n,  projected so that G v_{n+1/2} = (g(t_{n+1}) - G d_n) / dt
    d_{n+1}   = d_n + dt v_{n+1/2}                  (so G d_{n+1} = g(t_{n+1}) exactly)
    a_{n+1}   = M^-1 (f_ext(t_{n+1}) - f_int(d_{n+1}))
    v_{n+1}   = v_{n+1/2} + dt/2 a_{n+1},  projected so that G v_{n+1} = g'(t_{n+1})

Essential conditions are rows G (collocation rows u^h(x_I) = g(t) at boundary nodes, as in
``rkfx.assembly.boundary``, or rows of the identity for nodal unknowns), imposed by projection with
the lumped mass: w <- w + M^-1 G^T lambda with (G M^-1 G^T) lambda = target - G w,
factorized once. A prescribed velocity (e.g. an impact) replaces the half-step target by
v_bar(t_{n+1/2}). The full-step projection only changes the reported velocity, never the
trajectory (the next half-step projection removes the same component).

Energies per step: kinetic 1/2 v^T M v; internal = work of f_int (trapezoidal in d: stored
plus dissipated energy; exact 1/2 d^T K d for a linear force); external work of f_ext;
work of the constraint forces, the impulses M (v+ - v-) of the two projections of a step
over dt (zero for fixed supports). ``balance`` = kinetic + internal - external - constraint
- initial kinetic stays near zero. On MPI ranks each step's increments are summed over the
ranks in one all-reduce per ``SETTLE_EVERY`` steps (and at outputs, checkpoints and the
end), which gives the sums of a per-step all-reduce with fewer synchronizations.

Stability: dt < 2 / omega_max (``rkfx.assembly.smeared_strain.stable_time_step``, ``max_frequency``).

Checkpoints (``checkpoint_every``) hold the whole state at a step boundary through
``rkfx.solvers.checkpoint``: d, v, a, the forces, step, time, energies and their history, the
model's ``state()`` arrays (history such as damage, under ``model__``) and the recorder's
``arrays()`` (under ``kept__``); ``resume`` restores them and the run continues exactly as an
uninterrupted one would (bitwise, with the same thread count).

The step is tuned for large particle counts: fused parallel vector kernels, no temporaries
of the size of d in the loop, and reductions in a fixed number of chunks summed in order,
so that results do not depend on the thread count.
"""
import time as _time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol, runtime_checkable

import numba
import numpy as np
import scipy.sparse as sp

from rkfx.errors import InputError
from rkfx.linalg.linear_solver import linear_solver
from rkfx.solvers.checkpoint import RankFiles, copy_into, restore_run, save_run
from rkfx.solvers.fields import FieldLayout, single
from rkfx.solvers.model import Constraints, no_constraints

ENERGIES = ("kinetic", "internal", "external", "constraint")
SETTLE_EVERY = 16  # steps whose energies a distributed run sums over the ranks at once


# --------------------------------------------------------------------------- kernels


@numba.njit(cache=True)
def _wdot(a, w, b):
    """sum_i a_i w_i b_i, in order (reproducible; and no BLAS call, whose threads would
    contend with numba's on small machines)."""
    s = 0.0
    for i in range(len(a)):
        s += a[i] * w[i] * b[i]
    return s


# Per-step vector updates, fused and parallel (numpy temporaries cost ~1 ms each at 10^5
# nodes). Reductions use a fixed number of chunks summed in order, so results do not
# depend on the thread count.
_CHUNKS = 64


@numba.njit(parallel=True, cache=True)
def _kick(v, a, half, out):
    for i in numba.prange(len(v)):
        out[i] = v[i] + half * a[i]


@numba.njit(parallel=True, cache=True)
def _drift(d, vh, dt, d_new, dd):
    for i in numba.prange(len(d)):
        dd[i] = dt * vh[i]
        d_new[i] = d[i] + dd[i]


@numba.njit(parallel=True, cache=True)
def _accelerate(f_ext, f_int, mass, vh, half, a, v):
    for i in numba.prange(len(mass)):
        a[i] = (f_ext[i] - f_int[i]) / mass[i]
        v[i] = vh[i] + half * a[i]


@numba.njit(parallel=True, cache=True)
def _energy_increments(v, mass, dd, f_int0, f_int1, f_ext0, f_ext1, dv, share):
    """(kinetic, internal, external, constraint) increments of a step (dv empty: no constraints;
    ``share`` empty, or 1 on the unknowns this rank owns and 0 on its ghost copies)."""
    n = len(v)
    part = np.zeros((_CHUNKS, 4))
    size = (n + _CHUNKS - 1) // _CHUNKS
    with_dv = len(dv) > 0
    shared = len(share) > 0
    for c in numba.prange(_CHUNKS):
        k = w = x = r = 0.0
        for i in range(c * size, min(n, (c + 1) * size)):
            if shared and share[i] == 0.0:
                continue
            k += mass[i] * v[i] * v[i]
            w += dd[i] * (f_int0[i] + f_int1[i])
            x += dd[i] * (f_ext0[i] + f_ext1[i])
            if with_dv:
                r += dd[i] * mass[i] * dv[i]
        part[c, 0] = k
        part[c, 1] = w
        part[c, 2] = x
        part[c, 3] = r
    out = np.zeros(4)
    for c in range(_CHUNKS):
        for j in range(4):
            out[j] += part[c, j]
    out[0] *= 0.5
    out[1] *= 0.5
    out[2] *= 0.5
    return out


# --------------------------------------------------------------------------- models


@dataclass(frozen=True)
class Constraint:
    """Essential conditions G d = g(t) on the unknowns: the stepper's algebraic form of them.

    Built from ``rkfx.conditions`` (``Displacement`` or ``Velocity``) by
    ``rkfx.assembly.smeared_strain.constraint`` (collocation rows at boundary nodes), or from
    unit rows for nodal unknowns.

    Attributes:
        G: Rows over the unknowns of the model's layout, shape ``(k, size)``.
        displacement: g(t) [m], shape ``(k,)``; ``None`` with no ``velocity`` means g = 0.
        velocity: g'(t) [m/s], shape ``(k,)``. Alone, it prescribes the velocity (the
            displacement follows by integration); with ``displacement``, it is its rate
            (default: a central difference of ``displacement``).
    """

    G: sp.csr_matrix
    displacement: Callable[[float], np.ndarray] | None = None
    velocity: Callable[[float], np.ndarray] | None = None

    @property
    def prescribes_velocity(self) -> bool:
        return self.velocity is not None and self.displacement is None

    @property
    def count(self) -> int:
        return self.G.shape[0]

    def value(self, t: float) -> np.ndarray:
        """g(t), shape ``(k,)`` (zero when homogeneous; not defined for a prescribed velocity)."""
        if self.displacement is None:
            return np.zeros(self.count)
        return np.broadcast_to(np.asarray(self.displacement(t), float), (self.count,))

    def rate(self, t: float, dt: float) -> np.ndarray:
        """g'(t), shape ``(k,)``: the given velocity, else the central difference of g over dt."""
        k = self.count
        if self.velocity is not None:
            return np.broadcast_to(np.asarray(self.velocity(t), float), (k,))
        if self.displacement is None:
            return np.zeros(k)
        return (np.asarray(self.displacement(t + 0.5 * dt), float)
                - np.asarray(self.displacement(t - 0.5 * dt), float)) / dt * np.ones(k)


@runtime_checkable
class ExplicitModel(Protocol):
    """What ``CentralDifference`` needs of a model (the explicit parts of ``rkfx.solvers.model``).

    Attributes:
        layout: The fields, all of time order 2.
        essential: The essential conditions, imposed by projection.
    """

    layout: FieldLayout
    essential: Sequence[Constraint]

    # Optional: ``share``, a ``RankShare`` when the model is one rank's part of a problem
    # distributed over MPI ranks (its unknowns are local: owned and ghost copies).

    def lumped_mass(self) -> np.ndarray:
        """M per unknown, shape ``(size,)`` [kg], positive."""

    def internal_force(self, d: np.ndarray) -> np.ndarray:
        """f_int(d), shape ``(size,)`` [N]; called once for the initial state and once per
        step with the new d: it may update history in place (the commit of the step)."""

    def external_force(self, t: float) -> np.ndarray | None:
        """f_ext(t), shape ``(size,)`` [N], or ``None`` for no load."""

    def state(self) -> Mapping[str, np.ndarray]:
        """The history arrays (checkpointed; ``restore`` sets them in place)."""

    def restore(self, arrays: Mapping[str, np.ndarray]) -> None:
        """Set the history from ``state()`` arrays."""


class RankShare(Protocol):
    """A rank's part of an explicit model distributed over MPI ranks.

    The model's vectors are local: the unknowns the rank owns and ghost copies of unknowns
    owned elsewhere, which its internal force keeps equal to the owners' (a halo exchange),
    so the stepper's updates keep them equal too. Energies sum the owned unknowns over the
    ranks; checkpoints are one file per rank.

    Attributes:
        owned: 1.0 on owned unknowns, 0.0 on ghost copies, shape ``(size,)``.
        rank, size: This rank and the number of ranks.
    """

    owned: np.ndarray
    rank: int
    size: int

    def sum(self, values: np.ndarray) -> np.ndarray:
        """``values`` summed over the ranks (collective)."""

    def least(self, value: int) -> int:
        """The smallest ``value`` over the ranks (collective)."""


class ExplicitBase:
    """The protocol of ``rkfx.solvers.model.Model`` from the explicit parts of a model.

    M is the diagonal of ``lumped_mass()``, there is no capacity, r(x, t) = f_int(x) - f_ext(t)
    and the essential conditions are those of ``essential``. The internal force commits its
    history itself, so ``commit`` does nothing and ``residual`` advances the history too:
    run these models with explicit steppers (``CentralDifference``, or ``newmark.explicit``
    without prescribed velocities). ``restore`` copies into the ``state()`` arrays in place.
    """

    linear = False

    def mass(self) -> sp.csr_matrix:
        return sp.diags(self.lumped_mass()).tocsr()

    def capacity(self, dt: float) -> None:
        return None

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        f, load = self.internal_force(x), self.external_force(t)
        return f if load is None else f - load

    def tangent(self, x: np.ndarray, t: float) -> sp.spmatrix:
        raise InputError(f"{type(self).__name__} has no tangent stiffness; run it with an explicit stepper "
                         "(CentralDifference, or newmark.explicit)")

    def constraints(self, t: float) -> Constraints:
        parts = list(self.essential)
        if not parts:
            return no_constraints(self.layout.size)
        if any(c.prescribes_velocity for c in parts):
            raise InputError("a prescribed velocity has no value g(t) of its own; only CentralDifference imposes it")
        rate = None
        if all(c.velocity is not None or c.displacement is None for c in parts):
            rate = np.concatenate([c.rate(t, 0.0) for c in parts])
        return Constraints(sp.vstack([c.G for c in parts]).tocsr(), np.concatenate([c.value(t) for c in parts]), rate)

    def commit(self) -> None:
        pass

    def restore(self, arrays: Mapping[str, np.ndarray]) -> None:
        copy_into(self.state(), arrays, "extra state")


def _no_load(t: float) -> None:
    return None


class ExplicitDynamics(ExplicitBase):
    """M d'' = f_ext(t) - f_int(d) from a lumped mass and force callables, with its time step.

    Args:
        mass: Lumped mass per unknown, shape ``(size,)`` [kg].
        internal_force: f_int(d), shape ``(size,)``; called exactly once per step with the new
            coefficients, so it may update history variables (damage) in place.
        dt: Time step of ``run_explicit`` [s] (see ``rkfx.assembly.smeared_strain.stable_time_step``).
        external_force: f_ext(t), shape ``(size,)`` [N]; ``None`` for none.
        constraints: Essential conditions.
        history: Named arrays the force updates in place (the model's ``state()``:
            checkpointed, restored in place on resume).
        layout: The fields (default: u with 2 components, interleaved per node, on size / 2
            nodes).
    """

    def __init__(self, mass: np.ndarray, internal_force: Callable[[np.ndarray], np.ndarray], dt: float,
                 external_force: Callable[[float], np.ndarray] | None = None, constraints: Sequence[Constraint] = (),
                 history: Mapping[str, np.ndarray] | None = None, layout: FieldLayout | None = None):
        self.mass_vector = np.asarray(mass, float)
        if layout is None:
            if self.mass_vector.ndim != 1 or len(self.mass_vector) % 2:
                raise InputError(f"mass of shape {self.mass_vector.shape} is not two components per node; "
                                 "give layout= for other fields")
            layout = single("u", 2, 2, len(self.mass_vector) // 2)
        self.layout = layout
        self.internal_force = internal_force
        self.external_force = _no_load if external_force is None else external_force
        self.dt = dt
        self.essential = tuple(constraints)
        self.history = dict(history or {})

    def lumped_mass(self) -> np.ndarray:
        return self.mass_vector

    def state(self) -> dict[str, np.ndarray]:
        return self.history

    def with_history(self, history: Mapping[str, np.ndarray]) -> "ExplicitDynamics":
        """The same problem whose force updates the arrays ``history``."""
        f_ext = None if self.external_force is _no_load else self.external_force
        return ExplicitDynamics(self.mass_vector, self.internal_force, self.dt, f_ext, self.essential, history,
                                self.layout)


# --------------------------------------------------------------------------- the stepper


@dataclass
class ExplicitState:
    """The state at a step boundary; everything a checkpoint holds besides the history.

    Attributes:
        step, time: Step index n and t_n = n dt [s].
        d, v, a: Coefficients [m], velocities [m/s] and unconstrained accelerations
            M^-1 (f_ext - f_int) [m/s^2], shapes ``(size,)``.
        f_int, f_ext: Forces at t_n [N].
        energy: Kinetic, internal, external and constraint work [J per unit thickness].
    """

    step: int
    time: float
    d: np.ndarray
    v: np.ndarray
    a: np.ndarray
    f_int: np.ndarray
    f_ext: np.ndarray
    energy: np.ndarray

    def energies(self) -> dict[str, float]:
        return dict(zip(ENERGIES, map(float, self.energy)))

    def arrays(self, dt: float) -> dict[str, np.ndarray]:
        return {"d": self.d, "v": self.v, "a": self.a, "f_int": self.f_int, "f_ext": self.f_ext,
                "energy": self.energy, "step": np.int64(self.step), "time": np.float64(self.time),
                "dt": np.float64(dt)}

    @classmethod
    def from_arrays(cls, z: Mapping[str, np.ndarray]) -> "ExplicitState":
        return cls(int(z["step"]), float(z["time"]), z["d"].copy(), z["v"].copy(), z["a"].copy(),
                   z["f_int"].copy(), z["f_ext"].copy(), z["energy"].copy())


@dataclass
class ExplicitResult:
    """A run: final state, per-step energy history and outputs.

    Attributes:
        state: Final state.
        dt: Time step [s].
        time: t_n of every step 0..N [s], shape ``(N + 1,)``.
        energy: Energies per step, shape ``(N + 1, 4)`` (columns ``ENERGIES``).
        snapshots: ``(step, time, d, v)`` every ``output_every`` steps (without a recorder).
        resumed_from: Step of the checkpoint the run resumed from, or ``None``.
        wall_time_s: Wall time of the steps run here [s].
    """

    state: ExplicitState
    dt: float
    time: np.ndarray
    energy: np.ndarray
    snapshots: list = field(default_factory=list)
    resumed_from: int | None = None
    wall_time_s: float = 0.0

    @property
    def balance(self) -> np.ndarray:
        """kinetic + internal - external - constraint - initial kinetic, per step [J]."""
        e = self.energy
        return e[:, 0] + e[:, 1] - e[:, 2] - e[:, 3] - e[0, 0]

    def relative_energy_error(self) -> float:
        """max |balance| / max(kinetic, internal, external) over the run (the energy check
        of Belytschko, Liu & Moran, ch. 6)."""
        scale = np.abs(self.energy[:, :3]).max()
        return float(np.abs(self.balance).max() / scale) if scale > 0 else 0.0


class _Projection:
    """M-orthogonal projection onto {G w = target}, G M^-1 G^T factorized once. ``inverse``:
    z = M^-1 b for a mass M other than diag(``mass``) (e.g. a consistent capacity), which then
    gives the metric."""

    def __init__(self, constraints: Sequence[Constraint], mass: np.ndarray,
                 inverse: Callable[[np.ndarray], np.ndarray] | None = None):
        self.parts = list(constraints)
        self.G = sp.vstack([c.G for c in self.parts]).tocsr() if self.parts else None
        if self.G is None or self.G.shape[0] == 0:
            self.G = None
            return
        if self.G.shape[1] != len(mass):
            raise InputError(f"constraint rows have {self.G.shape[1]} columns for {len(mass)} unknowns")
        self.GT = self.G.T.tocsr()
        if inverse is None:
            self.minv_gt = sp.diags(1.0 / mass) @ self.GT
        else:
            self.minv_gt = sp.csr_matrix(np.column_stack([inverse(self.GT[:, [i]].toarray().ravel())
                                                          for i in range(self.GT.shape[1])]))
        try:
            self.lu = linear_solver(self.G @ self.minv_gt, solver="serial")
            singular = not self.lu.pivot_ratio() > 1e-12
        except InputError:
            singular = True
        if singular:
            raise InputError("the constraint rows are linearly dependent (G M^-1 G^T is singular); "
                             "prescribe each (node, component) once")
        self.sizes = [c.count for c in self.parts]
        # The corrections touch only the unknowns in the supports of the constraint rows:
        # M^-1 G^T is kept as its nonzero rows, and each correction in a whole-length buffer
        # that is zero elsewhere for good (a step makes two and their sum).
        self.rows = np.flatnonzero(np.diff(self.minv_gt.indptr))
        self.minv_gt_rows = self.minv_gt[self.rows]
        self._buffers = [np.zeros(len(mass)) for _ in range(3)]
        self._next = 0

    def project(self, w: np.ndarray, target: np.ndarray) -> np.ndarray:
        """w + M^-1 G^T lambda with G (w + ...) = target; returns the correction (a buffer that
        the third call after this one overwrites)."""
        lam = self.lu.solve(target - self.G @ w)
        dw = self.minv_gt_rows @ lam
        w[self.rows] += dw
        return self._correction(dw)

    def combined(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """a + b of two corrections of ``project``."""
        return self._correction(a[self.rows] + b[self.rows])

    def _correction(self, values: np.ndarray) -> np.ndarray:
        out = self._buffers[self._next]
        self._next = (self._next + 1) % len(self._buffers)
        out[self.rows] = values
        return out

    def half_step_target(self, d: np.ndarray, t_next: float, dt: float) -> np.ndarray:
        """Velocity target for v_{n+1/2}: G v = (g(t_{n+1}) - G d_n) / dt, or v_bar(t_{n+1/2})."""
        gd = self.G @ d
        out, i = [], 0
        for c, k in zip(self.parts, self.sizes):
            if c.prescribes_velocity:
                out.append(c.rate(t_next - 0.5 * dt, dt))
            else:
                out.append((c.value(t_next) - gd[i:i + k]) / dt)
            i += k
        return np.concatenate(out)

    def velocity_target(self, t: float, dt: float) -> np.ndarray:
        return np.concatenate([c.rate(t, dt) for c in self.parts])

    def displacement_target(self, d: np.ndarray, t: float) -> np.ndarray:
        """g(t) where a displacement is prescribed; G d elsewhere (left unchanged)."""
        gd = self.G @ d
        out, i = [], 0
        for c, k in zip(self.parts, self.sizes):
            out.append(gd[i:i + k] if c.prescribes_velocity else c.value(t))
            i += k
        return np.concatenate(out)


def _added(energy: np.ndarray, inc: np.ndarray, dt: float) -> np.ndarray:
    """The energies after a step with increments ``inc`` (the kinetic energy is the step's own;
    the constraint work's increment is an impulse times a displacement, over dt)."""
    return np.array([inc[0], energy[1] + inc[1], energy[2] + inc[2], energy[3] + inc[3] / dt])


def _check_finite(energies: np.ndarray, first: int, dt: float) -> None:
    """Raise at the first of the rows ``energies`` (steps from ``first`` on) that is not finite."""
    bad = np.flatnonzero(~np.all(np.isfinite(energies), axis=1))
    if bad.size:
        step = first + int(bad[0])
        raise InputError(f"the solution blew up at step {step} (t = {step * dt:.4g} s); reduce dt below "
                         "the stable step (stable_time_step / max_frequency)")


def _vector(f, n: int, what: str) -> np.ndarray:
    f = np.ascontiguousarray(f, dtype=np.float64)
    if f.shape != (n,):
        raise InputError(f"{what} returned shape {f.shape}; expected ({n},), the unknowns of the model's layout")
    return f


class Workspace:
    """What central differences keep across the steps of one model: the lumped mass, the
    projection onto the essential conditions (factorized once) and the work buffers that the
    state's arrays are swapped with (a step allocates no vector of the model's size)."""

    def __init__(self, model: ExplicitModel):
        layout = model.layout
        if not np.all(layout.orders == 2):
            raise InputError("central differences advance fields of time order 2; "
                             f"{', '.join(f.name for f in layout.fields if f.order != 2)} are not")
        self.model = model
        self.size = n = layout.size
        self.mass = np.asarray(model.lumped_mass(), float)
        if self.mass.shape != (n,):
            raise InputError(f"lumped mass has shape {self.mass.shape} for the {n} unknowns of the model's layout")
        self.proj = _Projection(model.essential, self.mass)
        self.share = getattr(model, "share", None)
        self.owned = np.empty(0) if self.share is None else np.ascontiguousarray(self.share.owned, dtype=np.float64)
        if self.share is not None and self.owned.shape != (n,):
            raise InputError(f"the model's share marks {self.owned.size} unknowns as owned or ghost; it has {n}")
        self.d_new, self.a_new, self.vh, self.dd = (np.empty(n) for _ in range(4))
        # On ranks the energy increments of up to SETTLE_EVERY steps wait for one all-reduce.
        self.unsettled = np.empty((SETTLE_EVERY, len(ENERGIES)))
        self.pending = 0
        self.zeros = np.zeros(n)
        self.no_dv = np.empty(0)

    def external_force(self, t: float) -> np.ndarray:
        f = self.model.external_force(t)
        return self.zeros if f is None else _vector(f, self.size, "external_force(t)")

    def total(self, values: np.ndarray) -> np.ndarray:
        """Energies of this rank's unknowns summed over the ranks (as is on one)."""
        return values if self.share is None else np.asarray(self.share.sum(values), float)

    def settle(self, s: "ExplicitState", history: np.ndarray, done: int, dt: float) -> None:
        """On ranks: sum the energy increments of the steps since the last settlement over
        the ranks (one all-reduce for all of them), add them to ``s.energy`` step by step (the
        sums of a per-step all-reduce) and write the energies of those steps to ``history``
        up to row ``done``. Raises if they blew up (collective: every rank settles at the same
        steps and sees the same sums)."""
        k, self.pending = self.pending, 0
        if k == 0:
            return
        inc = self.total(np.ascontiguousarray(self.unsettled[:k]))
        first = done - k + 1
        for j in range(k):
            s.energy = _added(s.energy, inc[j], dt)
            history[first + j] = s.energy
        _check_finite(history[first:done + 1], first, dt)

    @property
    def files(self) -> RankFiles:
        """Where this process keeps its checkpoints (one per rank on several ranks)."""
        return RankFiles(self.share)


@dataclass(frozen=True)
class CentralDifference:
    """Central differences with a lumped mass (see the module docstring).

    Attributes:
        dt: Time step [s] (``rkfx.assembly.smeared_strain.stable_time_step``).
    """

    dt: float

    def __post_init__(self):
        dt = float(self.dt)
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"time step dt = {self.dt!r} must be positive; see stable_time_step")
        object.__setattr__(self, "dt", dt)

    def start(self, model: ExplicitModel, d0: np.ndarray | None = None, v0: np.ndarray | None = None,
              work: Workspace | None = None) -> ExplicitState:
        """The state at t = 0 from initial coefficients and velocities (projected on the
        essential conditions); evaluates f_int(d0) once."""
        work = work or Workspace(model)
        n, proj, mass = work.size, work.proj, work.mass
        d = np.zeros(n) if d0 is None else np.array(d0, float).reshape(n)
        v = np.zeros(n) if v0 is None else np.array(v0, float).reshape(n)
        if proj.G is not None:
            proj.project(d, proj.displacement_target(d, 0.0))
            proj.project(v, proj.velocity_target(0.0, self.dt))
        f_int = _vector(model.internal_force(d), n, "internal_force(d)")
        f_ext = work.external_force(0.0)
        a = (f_ext - f_int) / mass
        kinetic = 0.5 * (_wdot(v, mass, v) if work.share is None else _wdot(v, mass * work.owned, v))
        energy = work.total(np.array([kinetic, 0.0, 0.0, 0.0]))
        return ExplicitState(0, 0.0, d, v, a, f_int, f_ext, energy)

    def advance(self, model: ExplicitModel, s: ExplicitState, work: Workspace) -> None:
        """Step ``s`` from t_n to t_{n+1} in place (its arrays swap with the work buffers); on
        ranks the step's energy increments wait in ``work`` for ``Workspace.settle``."""
        dt = self.dt
        half = 0.5 * dt
        proj, mass = work.proj, work.mass
        t_next = (s.step + 1) * dt
        _kick(s.v, s.a, half, work.vh)
        dv = work.no_dv
        if proj.G is not None:
            dv = proj.project(work.vh, proj.half_step_target(s.d, t_next, dt))
        _drift(s.d, work.vh, dt, work.d_new, work.dd)
        f_int = _vector(model.internal_force(work.d_new), work.size, "internal_force(d)")
        f_ext = work.external_force(t_next)
        _accelerate(f_ext, f_int, mass, work.vh, half, work.a_new, s.v)
        if proj.G is not None:
            # Constraint force over the step: the impulses of the half-step projection and of
            # the full-step one at its end (each carries half of it for a steady reaction).
            dv = proj.combined(dv, proj.project(s.v, proj.velocity_target(t_next, dt)))
        inc = _energy_increments(s.v, mass, work.dd, s.f_int, f_int, s.f_ext, f_ext, dv, work.owned)
        if work.share is None:
            s.energy = _added(s.energy, inc, dt)
        else:  # summed over the ranks when settled (Workspace.settle)
            work.unsettled[work.pending] = inc
            work.pending += 1
        s.d, work.d_new = work.d_new, s.d
        s.a, work.a_new = work.a_new, s.a
        s.f_int, s.f_ext = f_int, f_ext
        s.step += 1
        s.time = t_next

    def run(self, model: ExplicitModel, num_steps: int, *, d0: np.ndarray | None = None,
            v0: np.ndarray | None = None, output_every: int = 0, recorder=None, checkpoint_every: int = 0,
            checkpoint_dir: str | Path | None = None, resume: str | Path | None = None) -> ExplicitResult:
        """Integrate ``model`` to step ``num_steps`` (t = num_steps dt).

        Args:
            model: An ``ExplicitModel``.
            num_steps: Final step index N.
            d0, v0: Initial coefficients and velocities, shape ``(size,)`` (default zero).
            output_every: Every so many steps (and at step 0 and the end), hand the state to
                ``recorder.record(state)`` or, without a recorder, keep a snapshot
                ``(step, time, d, v)`` in the result. The state's arrays are the stepper's
                work buffers: copy what you keep.
            recorder: Keeps outputs, as ``rkfx.solvers.integrate.Recorder``: ``record(state)``,
                and ``arrays()`` / ``restore(arrays)`` for checkpoints.
            checkpoint_every: Write ``checkpoint_dir/checkpoint.npz`` every so many steps.
            checkpoint_dir: Directory of the checkpoint.
            resume: A checkpoint directory to continue from (``d0``/``v0`` are then ignored);
                the model's history and the recorder's arrays are restored from it.
        """
        dt = self.dt
        if int(num_steps) != num_steps or num_steps < 0:
            raise InputError(f"num_steps = {num_steps!r} must be a non-negative integer")
        if checkpoint_every and checkpoint_dir is None:
            raise InputError("checkpoint_every needs checkpoint_dir")
        work = Workspace(model)
        n = work.size
        hist_t = np.empty(num_steps + 1)
        hist_e = np.empty((num_steps + 1, len(ENERGIES)))
        resumed = None
        files = work.files
        checkpoint_dir = files.folder(checkpoint_dir)
        if resume is not None:
            ck = files.load(resume)
            if ck["d"].shape != (n,) or float(ck["dt"]) != dt:
                raise InputError(f"checkpoint in {str(resume)!r} has {ck['d'].size} unknowns and dt = "
                                 f"{float(ck['dt']):.6g}; this problem has {n} and dt = {dt:.6g}")
            s = ExplicitState.from_arrays(ck)
            if s.step > num_steps:
                raise InputError(f"checkpoint is at step {s.step}, beyond num_steps = {num_steps}")
            restore_run(ck, model, recorder)
            hist_t[:s.step + 1] = ck["history_time"]
            hist_e[:s.step + 1] = ck["history_energy"]
            resumed = s.step
        else:
            s = self.start(model, d0, v0, work)
            hist_t[0] = 0.0
            hist_e[0] = s.energy
        snapshots = []
        record = recorder.record if recorder is not None else \
            (lambda out: snapshots.append((out.step, out.time, out.d.copy(), out.v.copy())))
        if output_every and resumed is None:
            record(s)
        t_wall = _time.perf_counter()
        for step in range(s.step, num_steps):
            self.advance(model, s, work)
            done = step + 1
            hist_t[done] = s.time
            output = bool(output_every) and (done % output_every == 0 or done == num_steps)
            checkpoint = bool(checkpoint_every) and done % checkpoint_every == 0
            if work.share is None:
                hist_e[done] = s.energy
                if not np.all(np.isfinite(s.energy)):
                    _check_finite(hist_e[done:done + 1], done, dt)
            elif output or checkpoint or done == num_steps or work.pending == len(work.unsettled):
                work.settle(s, hist_e, done, dt)
            if output:
                record(s)
            if checkpoint:
                save_run(checkpoint_dir, s.arrays(dt) | {"history_time": hist_t[:done + 1],
                                                         "history_energy": hist_e[:done + 1]}, model, recorder,
                         comm=files.writer)
        wall = _time.perf_counter() - t_wall
        final = ExplicitState(num_steps, num_steps * dt, s.d, s.v, s.a, s.f_int.copy(), s.f_ext.copy(), s.energy)
        return ExplicitResult(final, dt, hist_t, hist_e, snapshots, resumed, wall)


class _Callback:
    """A recorder that hands every output to a function and keeps nothing itself."""

    def __init__(self, fn: Callable[[ExplicitState], None]):
        self.record = fn

    def arrays(self) -> dict[str, np.ndarray]:
        return {}

    def restore(self, arrays: Mapping[str, np.ndarray]) -> None:
        pass


def run_explicit(problem: ExplicitDynamics, num_steps: int, *, d0: np.ndarray | None = None,
                 v0: np.ndarray | None = None, extra_state: Mapping[str, np.ndarray] | None = None,
                 output_every: int = 0, on_output: Callable[[ExplicitState], None] | None = None,
                 checkpoint_every: int = 0, checkpoint_dir: str | Path | None = None,
                 resume: str | Path | None = None) -> ExplicitResult:
    """``CentralDifference(problem.dt).run(problem, num_steps, ...)`` for a problem of callables.

    Args:
        extra_state: Named arrays the force callable updates in place (e.g. damage
            variables): the model's history, checkpointed and restored in place on resume.
        on_output: Called with the state every ``output_every`` steps (instead of snapshots).
        Others: As for ``CentralDifference.run``.
    """
    model = problem if extra_state is None else problem.with_history(extra_state)
    return CentralDifference(problem.dt).run(
        model, num_steps, d0=d0, v0=v0, output_every=output_every,
        recorder=None if on_output is None else _Callback(on_output), checkpoint_every=checkpoint_every,
        checkpoint_dir=checkpoint_dir, resume=resume)
