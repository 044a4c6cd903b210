"""The damage particle method in explicit dynamics: smeared-strain damage with particle tracking.

One internal-force evaluation of the damage particle method (eqs. 4.29-4.35) for the
central-difference stepper of ``rkfx.solvers.central_difference``:

1. smeared strains of every particle, e~_L = B~(x_L) d (4.31), one sparse product;
2. Mazars' equivalent strain (4.6) (with ``DamageModel.nonlocal_average``, its nonlocal
   average over a physical radius, ``rkfx.fracture.nonlocal_average``) and, for particles
   allowed to damage, the history kappa_L = max(kappa_L, eps_eq) (4.3)-(4.5);
3. particles crossing their threshold for the first time fix their crack normal n_L along
   the major principal direction of the effective stress C e~ and, regularized, their
   kappa_c = (G_F / f_t) A_L / V_L (4.28) from the chord A_L of the cell; their tracking
   neighbours satisfying (4.22) become candidates;
4. the smeared stress (1 - D) C e~ (4.30) and f_int = sum_L B~_L^T Sigma_L V_L (4.34);
5. with the MSCNI terms of eq. (3.56) in the operator (``smeared_strain(..., eps_p)``), the
   subcell strain differences (B~_L - B~_C) d and their force with (1 - D_L) C eps_p A_C;
   steps 1 and 4 then run over the subcell rows, one product each way giving the smeared
   strains, the differences and the whole force (``rkfx.assembly.smeared_strain.Stabilization``).

Steps 2, 4 and 5 are compiled loops over the particles (in parallel): steps 2 and 4 are the
kernels of ``rkfx.materials.damage_law``, whose point updates the quasi-static ``rkfx.fracture.damage.update``
runs too. Step 3 (``rkfx.fracture.damage.initiate``, as in ``update``) touches only the particles that
initiate in this step.

Why the stabilization. Plain SCNI on a particle grid has zero-energy modes (the
checkerboards that the cell-boundary integrals cannot see). Statics with supports hides
them; explicit dynamics excites them, and the damage law feeds on them: the strains of a
growing crack pick up alternating-row components, particles beside the crack initiate, and
the crack spreads into a fan of thin bands. On the crack-branching problem at h = 0.4 mm
plain SCNI gives two branches plus a central crack and striped damage; with eps_p = 1 the
two branches of the seed's Fig 4.18 alone. Damaged particles lose their stabilization with
their stiffness (factor 1 - D_L), so it never holds a crack closed.

Particle tracking (section 4.2.2, ``rkfx.fracture.tracking``): only allowed particles may
initiate, and a particle's initiation makes its candidates of (4.22) allowed.

``DamageDynamics`` is the explicit model (``rkfx.solvers.central_difference.ExplicitModel``):
lumped mass, essential conditions, external force and the ``DamageForce`` of a strain
operator. All history lives in the arrays of ``DamageField``, updated in place by the force
(the commit of an explicit step); they are the model's ``state()``, which the stepper
checkpoints and restores. ``run_damage`` runs a model and keeps finished work: with a work
directory each finished run is written to ``WORK/<label>/result.npz`` and, with
``checkpoint_every``, its state to ``WORK/<label>/checkpoint.npz`` as it runs; resuming reads
a finished run back and continues an interrupted one from its checkpoint. The sampled
history (time, dissipated energy, damaged points, energies, the strain energy still stored) is
the stepper's recorder, a fixed array checkpointed with the damage history, so a resumed run
reports the same history as an uninterrupted one.
"""
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numba
import numpy as np

from rkfx.fracture.tracking import Tracking, admit
from rkfx.fracture.damage import DamageModel, crack_opening, dissipation_density, initiate
from rkfx.materials.damage_law import damage_kernel, strain_kernel
from rkfx.errors import InputError
from rkfx.parallel.ranks import on_root
from rkfx.assembly.matrix_strain import MatrixStrain
from rkfx.assembly.smeared_strain import SmearedStrain, StrainRecipe
from rkfx.solvers.central_difference import CentralDifference, Constraint, ExplicitDynamics, ExplicitState
from rkfx.solvers.checkpoint import copy_into, has_checkpoint, log, read_arrays, run_folder, save_arrays

HISTORY = ("time", "dissipated", "damaged", "kinetic", "internal", "external", "stored")


class StrainOperator(Protocol):
    """Strains at the damage points and the internal force of their stresses: the SCNI smeared
    strain ``rkfx.assembly.smeared_strain.SmearedStrain`` (points = particles), or any operator with this
    shape (e.g. the cell strains of linear triangles)."""

    @property
    def num_nodes(self) -> int: ...  # the number of damage points

    def strain(self, d: np.ndarray) -> np.ndarray: ...  # (m, 3) Voigt strains

    def force(self, stress: np.ndarray) -> np.ndarray: ...  # sum_L B_L^T Sigma_L V_L, (2 n,)


@dataclass
class DamageField:
    """History of the damage particles, updated in place by ``DamageForce``.

    Attributes:
        kappa: History variable (largest equivalent strain reached while allowed), ``(n,)``.
        damage: D, ``(n,)``.
        normal: Crack normal n_L fixed at initiation, ``(n, 2)`` (zero before).
        kappa_c: Critical strain in force, ``(n,)`` (NaN before initiation when regularized).
        chord: A_L at initiation, ``(n,)`` [m] (NaN otherwise).
        damaged: Whether the particle has initiated, ``(n,)`` bool.
        allowed: Whether it may initiate (seeds, candidates, damaged), ``(n,)`` bool.
        initiation_time: Time of initiation [s] (NaN before), ``(n,)``.
        parent: The particle whose initiation made this one a candidate (-1: none, e.g. the
            seeds), ``(n,)`` int64 (``rkfx.fracture.tracking``: growth direction).
        clock: Time of the last force evaluation [s], shape ``(1,)`` (starts at -dt, so the
            evaluation of the initial state reads t = 0; checkpointed with the rest).
        released: With the nonlocal equivalent strain, the energy each particle has dissipated,
            sum over the steps of psi_L dD_L, psi_L = V_L e_L : C e_L / 2 (plus the MSCNI terms'
            energy, which (1 - D_L) scales too) at the step's strain, ``(n,)`` [J per unit
            thickness]; ``None`` for the local law, whose dissipation is the closed form
            V_L phi(kappa_L) (``rkfx.fracture.damage``). The closed form assumes the strain
            equals kappa while damage grows, which a nonlocal history breaks: in one dimension
            it under-reports by 25-44 % at failure (``verification.nonlocal_band``).
        psi: With ``released``, psi_L of the last step (the trapezoid in time), ``(n,)``.
    """

    kappa: np.ndarray
    damage: np.ndarray
    normal: np.ndarray
    kappa_c: np.ndarray
    chord: np.ndarray
    damaged: np.ndarray
    allowed: np.ndarray
    initiation_time: np.ndarray
    parent: np.ndarray
    clock: np.ndarray
    released: np.ndarray | None = None
    psi: np.ndarray | None = None

    @property
    def arrays(self) -> dict[str, np.ndarray]:
        """The arrays by name (the ``state()`` of ``DamageDynamics``: checkpointed, restored in place)."""
        names = ("kappa", "damage", "normal", "kappa_c", "chord", "damaged", "allowed", "initiation_time", "parent",
                 "clock") + (() if self.released is None else ("released", "psi"))
        return {k: getattr(self, k) for k in names}

    def dissipated(self, model: DamageModel) -> float:
        """Energy dissipated so far, sum_L V_L phi(kappa_L) [J per unit thickness] (``rkfx.fracture.damage``;
        with the nonlocal law the sum of ``released``)."""
        if self.released is not None:
            return float(self.released.sum())
        i = np.flatnonzero(self.damaged)
        if i.size == 0:
            return 0.0
        return float(np.sum(self._dissipation(model, i)))

    def dissipation(self, model: DamageModel) -> np.ndarray:
        """Energy dissipated so far per point, V_L phi(kappa_L) [J per unit thickness], ``(n,)``
        (with the nonlocal law ``released``)."""
        if self.released is not None:
            return self.released.copy()
        out = np.zeros(len(self.kappa))
        i = np.flatnonzero(self.damaged)
        out[i] = self._dissipation(model, i)
        return out

    def _dissipation(self, model: DamageModel, i: np.ndarray) -> np.ndarray:
        return model.volume[i] * dissipation_density(self.kappa[i], model.kappa0[i], self.kappa_c[i], model.material.E)


def damage_field(model: DamageModel, track: Tracking | None = None, dt: float = 0.0) -> DamageField:
    """Undamaged field; the seeds (every particle without tracking) are allowed. ``dt`` is the
    time step of the run (it only stamps initiation times)."""
    n = model.num_points
    kc = np.full(n, np.nan) if model.regularized else model.kappa_c.copy()
    allowed = np.ones(n, bool) if track is None or not track.enabled else track.seeds.copy()
    return DamageField(np.zeros(n), np.zeros(n), np.zeros((n, 2)), kc, np.full(n, np.nan), np.zeros(n, bool),
                       allowed, np.full(n, np.nan), np.full(n, -1, np.int64), np.array([-float(dt)]),
                       *((None, None) if model.nonlocal_average is None else (np.zeros(n), np.zeros(n))))


class DamageForce:
    """f_int(d) of the damage particle method (eq. 4.34), the internal force of ``DamageDynamics``.

    Called once per step with the new coefficients; it advances the history in ``field``
    and its clock by ``dt`` (the clock only stamps initiation times).
    """

    def __init__(self, op: StrainOperator, model: DamageModel, field: DamageField,
                 track: Tracking | None = None, dt: float = 0.0):
        if model.num_points != op.num_nodes:
            raise InputError(f"damage model has {model.num_points} points for {op.num_nodes} particles")
        self.op, self.model, self.field, self.track, self.dt = op, model, field, track, float(dt)
        if track is not None and track.enabled:
            track.neighbours  # noqa: B018 - built at set-up, not at the first initiation
        elastic = model.material.elastic
        self.c = np.ascontiguousarray(elastic.D())
        self.nu_zz = elastic.out_of_plane_ratio
        n = op.num_nodes
        self.kappa0 = np.ascontiguousarray(model.kappa0)
        self._eq = np.empty(n)
        self._effective = np.empty((n, 3))
        self._crossing = np.empty(n, np.bool_)
        self.stress = np.empty((n, 3))
        self.residual = float(model.residual)
        self._subcells = _subcell_terms(op) if model.nonlocal_average is not None else None

    def __call__(self, d: np.ndarray) -> np.ndarray:
        f, op = self.field, self.op
        stab = getattr(op, "stabilization", None)
        e, diff = op.strains(d) if stab is not None else (op.strain(d), None)
        strain_kernel(e, self.c, self.nu_zz, f.allowed, f.damaged, self.kappa0, self._eq, self._effective,
                      self._crossing)
        if self.model.nonlocal_average is not None:
            self._average()
        f.clock[0] += self.dt
        self._initiate_all(np.flatnonzero(self._crossing))
        before = f.damage[self._rows] if f.released is not None else None
        damage_kernel(self._eq, self._effective, f.allowed, f.damaged, self.kappa0, f.kappa_c, f.kappa, f.damage,
                      self.stress)
        if before is not None:  # psi dD at the step's strain (DamageField.released)
            ptr, weight, none = self._subcells
            _release(self._rows, before, f.damage, e, self._effective, none if diff is None else diff, ptr, weight,
                     self.c, self.model.volume, f.psi, f.released)
        damage = f.damage
        if self.residual > 0:  # max(1 - D, eta) C e
            kept = np.maximum(1.0 - f.damage, self.residual)
            np.multiply(self._effective, kept[:, None], out=self.stress)
            damage = 1.0 - kept
        if stab is None:
            return op.force(self.stress)
        return op.damaged_force(self.stress, diff, self.c, damage)

    def _average(self) -> None:
        """The allowed particles' equivalent strains replaced by their nonlocal averages
        (``rkfx.fracture.nonlocal_average``), and their threshold crossings taken on those."""
        f = self.field
        self._rows = rows = np.flatnonzero(f.allowed)
        values, failed = self._nonlocal_inputs()
        self.model.nonlocal_average.average(values, rows, self._eq, failed)
        self._crossing[rows] = ~f.damaged[rows] & (self._eq[rows] >= self.kappa0[rows])
        # A particle admitted by this step's initiations starts its history from the next
        # step's average, not from its local strain.
        self._eq[~f.allowed] = 0.0

    def _nonlocal_inputs(self) -> tuple[np.ndarray, np.ndarray]:
        """The local equivalent strains and failed flags of every particle (the ranks gather them)."""
        return self._eq.copy(), self.field.damage >= 1.0

    def _initiate_all(self, new: np.ndarray) -> None:
        """The initiations of this evaluation (``rkfx.models.damage_ranks`` gathers them over ranks)."""
        if new.size:
            self._initiate(new)

    def _initiate(self, new: np.ndarray) -> None:
        """Fix n_L (major principal direction of C e, 4.22) and kappa_c (4.28) of the particles
        ``new``; mark their tracking candidates."""
        f = self.field
        initiate(self.model, new, self._effective[new], f.normal, f.chord, f.kappa_c)
        f.damaged[new] = True
        f.initiation_time[new] = f.clock[0]
        if self.track is not None and self.track.enabled:
            admit(*self.track.candidates(new, f.normal[new], f.parent[new]), f.allowed, f.parent)


def _subcell_terms(op) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ptr, eps_p A_C) of the MSCNI subcells of each damage point of ``op`` (a whole operator's
    ``stabilization`` or a rank's share), or no subcells; and the empty differences of no subcells."""
    s, none = getattr(op, "stabilization", None), np.empty((0, 3))
    if s is None:
        return np.zeros(op.num_nodes + 1, np.int64), np.empty(0), none
    return (s.ptr, s.weight, none) if hasattr(s, "ptr") else (op.ptr, op.weight, none)


@numba.njit(parallel=True, cache=True)
def _release(rows, before, damage, strain, effective, differences, ptr, weight, c, volume, psi_last, released):
    """released_L += (psi_L + psi_L,last) / 2 (D_L - D_L,before) over ``rows`` (the trapezoid in
    time, as the internal work), psi_L the undamaged energy of particle L, V_L e : C e / 2 plus its
    MSCNI terms' eps_p A_C dE : C dE / 2 (the energy that (1 - D_L) scales in the force), at the
    step's strain; ``psi_last`` holds psi_L of the last step and takes this one's."""
    for k in numba.prange(rows.shape[0]):
        i = rows[k]
        dd = damage[i] - before[k]
        psi = 0.5 * volume[i] * (strain[i, 0] * effective[i, 0] + strain[i, 1] * effective[i, 1]
                                 + strain[i, 2] * effective[i, 2])
        for q in range(ptr[i], ptr[i + 1]):
            for a in range(3):
                sa = c[a, 0] * differences[q, 0] + c[a, 1] * differences[q, 1] + c[a, 2] * differences[q, 2]
                psi += 0.5 * weight[q] * differences[q, a] * sa
        released[i] += 0.5 * (psi + psi_last[i]) * dd
        psi_last[i] = psi


class DamageDynamics(ExplicitDynamics):
    """M d'' = f_ext(t) - f_int(d) with the damage particle method's internal force: the
    explicit model of a damage run, whose history (``state()``) is its ``DamageField``.

    Args:
        op: Strain operator of the damage points.
        mass: Lumped mass per unknown, shape ``(2 n,)`` [kg].
        model, track: Damage points and tracking (``None``: every point may damage).
        dt: Time step [s] (the force's clock stamps initiation times with it).
        constraints, external_force: Essential conditions and f_ext(t) (``None``: no load).
    """

    def __init__(self, op: StrainOperator, mass: np.ndarray, model: DamageModel, track: Tracking | None, dt: float,
                 constraints: Sequence[Constraint] = (), external_force: Callable[[float], np.ndarray] | None = None):
        self.op, self.damage_model = op, model
        self.field = damage_field(model, track, dt)
        self.force = DamageForce(op, model, self.field, track, dt)
        super().__init__(mass, self.force, dt, external_force, constraints, self.field.arrays)


@dataclass
class Frames:
    """The fields of a run through time, for output (e.g. ParaView): ``write(t, **fields)`` is
    called at ``count`` evenly spaced history samples and at the end, with ``damage`` and
    ``crack_opening`` (w / w_c) per damage point and the coefficients ``displacement``, ``velocity``
    per node, shape ``(n, 2)`` (nodal values for finite elements, not for RK shape functions),
    whole on every rank. ``run_damage`` sets ``gather`` and ``gather_nodes``.
    A resumed run writes the frames of the piece it computes."""

    write: Callable[..., None]
    count: int = 20
    written: int = 0
    gather: Callable[[np.ndarray], np.ndarray] = np.copy
    gather_nodes: Callable[[np.ndarray], np.ndarray] = np.copy

    def last(self, r: "DamageRun") -> None:
        """The end state of ``r``, a finished run read back, if no frame was written."""
        if self.written == 0:
            n = len(r.displacement) // 2
            self.write(r.steps * r.dt, damage=r.damage, crack_opening=r.opening,
                       displacement=r.displacement.reshape(n, 2), velocity=r.velocity.reshape(n, 2))
            self.written += 1


class _Samples:
    """The sampled history of a damage run (the stepper's recorder): time, dissipated energy,
    damaged points and energies at every output, and the stepping time so far across the
    pieces of a resumed run; its arrays are checkpointed with the run."""

    def __init__(self, dynamics: DamageDynamics, steps: int, every: int,
                 total: Callable[[np.ndarray], np.ndarray] | None = None, frames: Frames | None = None,
                 progress: Callable[[int], None] | None = None):
        self.field, self.model = dynamics.field, dynamics.damage_model
        share = getattr(dynamics, "share", None)
        self.owned = None if share is None else np.asarray(share.owned, float)  # 1 on owned unknowns, 0 on ghosts
        self.progress = progress
        self.total = total  # sums a rank's (dissipated, damaged, stored) over the ranks
        self.frames = frames
        self.frame_every = 1 if frames is None else max(1, (steps // every + 1) // max(1, frames.count))
        self.frame_time = -np.inf  # the time of the last frame written
        self.frame_seconds = 0.0  # spent writing frames: not stepping time
        self.history = np.full((steps // every + 2, len(HISTORY)), np.nan)
        self.slot = np.zeros(1, np.int64)
        self.wall = np.zeros(1)
        self.base = None  # the earlier pieces' stepping time, read at this piece's first output
        self.t0 = time.perf_counter()  # the start of this piece

    def record(self, s: ExplicitState) -> None:
        if self.base is None:
            self.base = float(self.wall[0])
        self.wall[0] = self.base + time.perf_counter() - self.t0 - self.frame_seconds
        e = s.energy
        # The strain energy still stored, d . f_int(d) / 2: the force is linear in d at the
        # step's damage (max(1 - D, eta) of the cell and MSCNI terms alike).
        # (An elementwise product and sum, not a BLAS dot: the BLAS threads would spin beside
        # numba's after every sample.)
        d = s.d if self.owned is None else s.d * self.owned
        stored = 0.5 * float(np.multiply(d, s.f_int).sum())
        damage = np.array([self.field.dissipated(self.model), self.field.damaged.sum(), stored])
        if self.total is not None:
            damage = self.total(damage)
        self.history[self.slot[0]] = (s.time, damage[0], damage[1], e[0], e[1], e[2] + e[3], damage[2])
        if self.frames is not None and self.slot[0] % self.frame_every == 0:
            self.frame(s)
        self.slot[0] += 1
        if self.progress is not None:
            self.progress(s.step)

    def frame(self, s: ExplicitState) -> None:
        """Hand the fields at ``s`` to the frame writer (collective: the fields are gathered)."""
        t0 = time.perf_counter()
        f, whole, nodes = self.field, self.frames.gather, self.frames.gather_nodes
        opening = crack_opening(f.kappa, self.model.kappa0, f.kappa_c)
        self.frames.write(s.time, damage=whole(f.damage), crack_opening=whole(opening),
                          displacement=nodes(s.d).reshape(-1, 2), velocity=nodes(s.v).reshape(-1, 2))
        self.frame_time = s.time
        self.frames.written += 1
        self.frame_seconds += time.perf_counter() - t0

    def arrays(self) -> dict[str, np.ndarray]:
        return {"history": self.history, "slot": self.slot, "wall": self.wall}

    def restore(self, arrays) -> None:
        copy_into(self.arrays(), arrays, "run history")

    @property
    def elapsed(self) -> float:
        """Stepping time of the run so far, earlier pieces included [s]."""
        return (self.base or 0.0) + time.perf_counter() - self.t0 - self.frame_seconds


# --------------------------------------------------------------------------- runs


@dataclass
class DamageRun:
    """One explicit damage run.

    Attributes:
        label: Run label.
        history: Sampled (time [s], dissipated [J/m], damaged points, kinetic energy,
            internal work, external work, stored strain energy [J/m]), shape ``(k, 7)``
            (columns ``HISTORY``); the external work includes that of the prescribed motions
            (e.g. an impact velocity). ``released`` is what the internal work leaves after
            the stored energy: the energy the damage has taken out of the discrete solid.
        damage, kappa, normal, initiation_time: Final damage history per particle.
        opening: Final crack opening over the critical opening, w / w_c per particle
            (``rkfx.fracture.damage.crack_opening``: the fraction of its fracture energy spent).
        dissipation: Final dissipated energy per particle, V_L phi(kappa_L) [J/m].
        displacement, velocity: Final coefficients [m] and velocities [m/s], shape ``(2 n,)``.
        steps, dt: Time steps taken and their size [s].
        wall_time_s: Wall time of the time stepping [s] (summed over resumed pieces).
        energy_error: max |energy balance| / max energy of the run.
        resumed_from: Step the run resumed from, or ``None``.
    """

    label: str
    history: np.ndarray
    damage: np.ndarray
    kappa: np.ndarray
    normal: np.ndarray
    initiation_time: np.ndarray
    opening: np.ndarray
    dissipation: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    steps: int
    dt: float
    wall_time_s: float
    energy_error: float
    resumed_from: int | None = None

    def column(self, name: str) -> np.ndarray:
        return self.history[:, HISTORY.index(name)]

    @property
    def released(self) -> np.ndarray:
        """Internal work - stored strain energy at every sample [J/m]: the energy the damage
        released. With the local law it exceeds the law's ``dissipated`` = sum V_L phi(kappa_L),
        which counts only what Mazars' norm sees (docs/fracture.md); with the nonlocal law the
        two are the same energy summed two ways (psi dD per particle against the stepper's
        work), equal to the time integration's error (0.2 % on ``kalthoff --quick``)."""
        return self.column("internal") - self.column("stored")

    def save(self, path: Path) -> None:
        save_arrays(path.parent, dict(
            history=self.history, damage=self.damage, kappa=self.kappa, normal=self.normal,
            initiation_time=self.initiation_time, opening=self.opening, dissipation=self.dissipation,
            displacement=self.displacement, velocity=self.velocity, steps=self.steps, dt=self.dt,
            wall_time_s=self.wall_time_s, energy_error=self.energy_error, label=self.label), name=path.name)

    @classmethod
    def load(cls, path: Path) -> "DamageRun":
        z = read_arrays(path)
        if "dissipation" not in z or z["history"].shape[1] != len(HISTORY):
            raise InputError(f"{path} predates the per-particle crack outputs or the stored-energy history; "
                             "run again without --resume")
        return cls(str(z["label"]), z["history"], z["damage"], z["kappa"], z["normal"], z["initiation_time"],
                   z["opening"], z["dissipation"], z["displacement"], z["velocity"], int(z["steps"]),
                   float(z["dt"]), float(z["wall_time_s"]), float(z["energy_error"]))


def run_damage(label: str, op: StrainOperator, mass: np.ndarray, dt: float, model: DamageModel,
               track: Tracking | None, constraints: Sequence[Constraint], t_end: float,
               external_force: Callable[[float], np.ndarray] | None = None, samples: int = 200,
               checkpoint_every: int = 0, work_dir: Path | None = None, resume: Path | None = None,
               comm=None, x: np.ndarray | None = None, frames: Frames | None = None,
               progress: Callable[[int], None] | None = None) -> DamageRun:
    """Explicit dynamics with the damage of ``model`` to ``t_end`` (``samples`` history points),
    keeping finished work.

    Args:
        label: Run label (also the sub-directory of ``work_dir``/``resume``).
        op, mass, dt: Strain operator of the damage points (or the ``StrainRecipe`` of a
            ``SmearedStrain``, which each rank of a distributed run builds only its share of),
            lumped mass per unknown [kg] and time step [s].
        model, track: Damage points and tracking (``None``: every point may damage).
        constraints, external_force: As for ``DamageDynamics``.
        checkpoint_every: Checkpoint every so many steps (needs ``work_dir``).
        work_dir: Where finished results and checkpoints go.
        resume: Work directory of an interrupted invocation: a finished result there is
            returned as is, a checkpoint is continued.
        comm: An MPI communicator (mpi4py) or ``None``. With several ranks and the node
            positions ``x``, a ``SmearedStrain`` or ``MatrixStrain`` run is distributed
            (``rkfx.models.damage_ranks``: the serial result bit for bit, on every rank); other
            runs are serial: rank 0 runs them and writes the files, and every rank receives the
            result (or the error).
        x: Node (particle) positions, shape ``(n, 2)`` [m], which the ranks split by RCB.
        frames: Receives the fields through time (``Frames``); a finished run read back writes
            its end state.
        progress: Called with the step number at every history sample (e.g. a progress bar).
    """
    parallel = comm is not None and comm.size > 1
    if isinstance(op, StrainRecipe) and not (parallel and x is not None):
        op = op.build()  # one process builds the whole operator
    if parallel and (x is None or not isinstance(op, SmearedStrain | StrainRecipe | MatrixStrain)):
        return on_root(comm, lambda: run_damage(label, op, mass, dt, model, track, constraints, t_end,
                                                external_force, samples, checkpoint_every, work_dir, resume,
                                                frames=frames, progress=progress))
    if not t_end > 0:
        raise InputError(f"t_end = {t_end!r} must be positive (seconds)")
    if checkpoint_every and work_dir is None:
        raise InputError("checkpoint_every needs a work directory (the case's --out)")
    key = run_folder(label)
    finished = None if resume is None else Path(resume) / key / "result.npz"
    if finished is not None and finished.is_file():
        try:
            done = DamageRun.load(finished)
        except InputError as err:
            if not has_checkpoint(finished.parent):
                raise
            # The run goes on from its last checkpoint to the same result.
            log.warning("resume: %s; continuing %s from its checkpoint", str(err).split(";")[0], label)
        else:
            log.info("resume: %s read back finished (%s)", label, finished)
            if frames is not None:
                frames.last(done)
            return done
    steps = int(np.ceil(t_end / dt - 1e-9))
    every = max(1, steps // samples)
    start = None
    checkpoint_dir = None if work_dir is None else Path(work_dir) / key
    if resume is not None and has_checkpoint(Path(resume) / key):
        start = Path(resume) / key
    if parallel:
        from rkfx.models.damage_ranks import RankDamage  # noqa: PLC0415 - it builds on this module
        from rkfx.parallel.partition import rcb  # noqa: PLC0415

        dynamics = RankDamage(op, mass, model, track, dt, constraints, external_force, rcb(x, comm.size), comm)
        whole, whole_nodes, total = dynamics.gather, dynamics.gather_nodes, dynamics.share.sum
    else:
        dynamics = DamageDynamics(op, mass, model, track, dt, constraints, external_force)
        whole = whole_nodes = np.copy
        total = None
    if frames is not None:
        frames.gather, frames.gather_nodes = whole, whole_nodes
    kept = _Samples(dynamics, steps, every, total, frames, progress)
    res = CentralDifference(dt).run(dynamics, steps, output_every=every, recorder=kept,
                                    checkpoint_every=checkpoint_every, checkpoint_dir=checkpoint_dir, resume=start)
    elapsed = kept.elapsed
    history, slot, field, points = kept.history, kept.slot, dynamics.field, dynamics.damage_model
    if slot[0] == 0 or history[slot[0] - 1, 0] < steps * dt * (1 - 1e-12):
        kept.record(res.state)
    if frames is not None and kept.frame_time < res.state.time:
        kept.frame(res.state)
    run = DamageRun(label, history[:slot[0]].copy(), whole(field.damage), whole(field.kappa), whole(field.normal),
                    whole(field.initiation_time), whole(crack_opening(field.kappa, points.kappa0, field.kappa_c)),
                    whole(field.dissipation(points)), whole_nodes(res.state.d), whole_nodes(res.state.v), steps, dt,
                    elapsed, res.relative_energy_error(), res.resumed_from)
    if checkpoint_dir is not None:
        run.save(checkpoint_dir / "result.npz")
    return run
