"""Trial and committed history of a damage model for the implicit steppers.

A model that evaluates damage (``rkfx.fracture.damage``) from its committed state in every
residual keeps the trial state of the last evaluation in ``trial.state`` and, with particle
tracking, the admissions of the step's iterates in ``_trial_tracking`` (``(allowed, parent)``).
``DamageHistory`` gives such a model the ``commit``, ``state`` and ``restore`` of the stepper
protocol (``rkfx.solvers.model``): the RKPM hydraulic-fracture model and its crack-band FEM
baseline share it. The model holds ``committed`` (a ``DamageState``), ``points`` (its
``DamageModel``), ``residual_fraction`` (the least 1 - D), ``allowed`` (or ``None`` without
tracking), ``parent``, ``iterations`` (Newton iterations of every accepted step), ``_count``
(those of the step under way) and ``track`` (a ``rkfx.fracture.tracking.Tracking``, or
``None``). A model with a pre-existing fracture sets ``fracture`` (a
``rkfx.fracture.contact.FractureContact``, whose slip is history too): it is committed, saved and
restored with the damage.

Damage updates (``damage_update``, set by the model):

* ``"implicit"``: every residual evaluates the damage of its strains from the committed state
  (the seed's Newton on (5.34)-(5.36)); a softening particle's tangent turns negative and its
  loading/unloading switches between iterates.
* ``"impl-ex"``: the damage of a step is extrapolated from the two committed steps before it
  (Oliver, Huespe and Cante 2008, "An implicit/explicit integration scheme to increase
  computability of non-linear material and contact/friction problems", CMAME 197):
  kappa~ = kappa_n + (dt / dt_n) (kappa_n - max(kappa_(n-1), kappa0)) at the damaged points,
  D~ = D(kappa~), fixed over the step's iterates, so the step's solid response is the secant
  (1 - D~) C and Newton meets no softening or switching; once the step is accepted the
  implicit update of its converged strains is committed (and next extrapolated from). The
  error is first order in dt; the model's step size (``start_step``, called by the stepper)
  enters the extrapolation.
"""
from dataclasses import fields, replace

import numpy as np

from rkfx.errors import InputError
from rkfx.fracture import damage as dm
from rkfx.fracture.tracking import admit

DAMAGE_UPDATES = ("implicit", "impl-ex")


class DamageHistory:
    """``commit``, ``state`` and ``restore`` of a damage model, and its trial damage with the
    admission of tracking candidates (see the module docstring)."""

    MAX_TRACKING_ROUNDS = 1000  # admissions within one residual (each admits at least one point)
    damage_update = "implicit"
    fracture = None  # a FractureContact with its own trial/commit history, or None
    _dt = None                 # the step under way (start_step)
    _kappa_before = None       # impl-ex: kappa of the committed step before the last, and
    _dt_before = None          # the last committed step's size
    _last_strain = None        # impl-ex: the strains and options of the last residual
    _extrapolated = None       # impl-ex: (committed, dt, state) of the step under way

    def use_damage_update(self, name: str) -> None:
        """Choose ``"implicit"`` or ``"impl-ex"`` (module docstring)."""
        if name not in DAMAGE_UPDATES:
            raise InputError(f"damage_update = {name!r}; choose one of {', '.join(DAMAGE_UPDATES)}")
        self.damage_update = name

    def start_step(self, t: float, dt: float) -> None:
        """The stepper's next step (from t, of size dt): the impl-ex extrapolation's step."""
        self._dt = float(dt)

    def step_damage(self, eps: np.ndarray, **options) -> dm.DamageUpdate:
        """The damage of a residual's strains ``eps``: the implicit trial (``trial_damage``) or
        the step's impl-ex extrapolation with the secant stress and tangent (module docstring)."""
        if self.damage_update == "implicit":
            return self.trial_damage(eps, **options)
        self._last_strain = (eps, options)
        st = self._extrapolation()
        c = self.points.material.elasticity()
        frac = 1.0 - st.damage
        effective = eps @ c.T
        tangent = None
        if options.get("tangent", True):
            tangent = np.maximum(frac, options.get("tangent_floor", 0.0))[:, None, None] * c
        return dm.DamageUpdate(st, frac[:, None] * effective, tangent, 0.0)

    def _extrapolation(self) -> dm.DamageState:
        """The committed state with the impl-ex damage D~ of the step under way (its kappa stays
        the committed one: no point counts as loading within the step)."""
        c, dt = self.committed, self._dt
        if self._extrapolated is not None and self._extrapolated[0] is c and self._extrapolated[1] == dt:
            return self._extrapolated[2]
        d = c.damage
        if self._kappa_before is not None and self._dt_before and dt and c.damaged.any():
            k0 = self.points.kappa0
            grown = np.maximum(c.kappa - np.maximum(self._kappa_before, k0), 0.0)
            kappa = np.maximum(c.kappa + (dt / self._dt_before) * grown, k0)
            d = np.where(c.damaged, dm.damage(kappa, k0, np.where(c.damaged, c.kappa_c, np.inf)), c.damage)
            d = np.maximum(d, c.damage)
        st = replace(c, damage=d)
        self._extrapolated = (c, dt, st)
        return st

    def trial_damage(self, eps: np.ndarray, **options) -> dm.DamageUpdate:
        """The trial damage of the strains ``eps`` from the committed state
        (``rkfx.fracture.damage.update`` with ``options``). With tracking only allowed points may
        damage; the candidates (4.22) of the points initiating in the trial are admitted and the
        damage is evaluated again until none initiates. The admissions persist over a step's
        iterates until it is committed: a point strained past its threshold while not allowed
        would otherwise damage in one iterate and not in the next, and Newton would cycle."""
        if self.track is None:
            return dm.update(self.points, self.committed, eps, **options)
        if self._trial_tracking is None:
            self._trial_tracking = (self.allowed.copy(), self.parent.copy())
        allowed, parent = self._trial_tracking
        upd = dm.update(self.points, self.committed, eps, allowed=allowed, **options)
        done = self.committed.damaged.copy()
        for _ in range(self.MAX_TRACKING_ROUNDS):
            new = np.flatnonzero(upd.state.damaged & ~done)
            if new.size == 0 or not self._admit(new, upd.state.normal, allowed, parent):
                break
            done[new] = True
            upd = dm.update(self.points, self.committed, eps, allowed=allowed, **options)
        return upd

    def stiffness_fraction(self, damage: np.ndarray) -> np.ndarray:
        """1 - D kept at or above the model's ``residual_fraction``, per point."""
        return np.maximum(1.0 - damage, self.residual_fraction)

    def opening(self, state: dm.DamageState | None = None) -> np.ndarray:
        """w / w_c = D kappa / kappa_c of every point (``rkfx.fracture.damage.crack_opening``) of
        ``state`` (default the committed one), shape ``(m,)``."""
        st = self.committed if state is None else state
        return dm.crack_opening(st.kappa, self.points.kappa0, st.kappa_c)

    def _admit(self, new: np.ndarray, normal: np.ndarray, allowed: np.ndarray, parent: np.ndarray) -> bool:
        """Allow, in place, the tracking candidates (4.22) of the points ``new`` that initiated
        with ``normal``; whether any was not allowed before."""
        if self.track is None or new.size == 0:
            return False
        return admit(*self.track.candidates(new, normal[new], parent[new]), allowed, parent)

    def commit(self) -> None:
        """The last residual's trial damage (and the step's admissions) become the committed ones;
        under impl-ex, the implicit update of the step's converged strains."""
        if self.damage_update == "impl-ex" and self._last_strain is not None:
            eps, options = self._last_strain
            self.trial = self.trial_damage(eps, **options)
            self._kappa_before, self._dt_before = self.committed.kappa, self._dt
            self._last_strain = None
        self.committed = self.trial.state
        if self._trial_tracking is not None:
            self.allowed, self.parent = self._trial_tracking
        self._trial_tracking = None
        dm.check_regularization(self.points, self.committed)
        self.iterations.append(self._count)
        self._count = 0
        if self.fracture is not None:
            self.fracture.commit()

    def state(self) -> dict[str, np.ndarray]:
        """The committed damage state, the admissions and the Newton iterations, for checkpoints."""
        out = {f.name: getattr(self.committed, f.name) for f in fields(dm.DamageState)} | {
            "iterations": np.array(self.iterations, np.int64), "parent": self.parent}
        if self.allowed is not None:
            out["allowed"] = self.allowed
        if self.damage_update == "impl-ex" and self._kappa_before is not None:
            out["implex_kappa_before"] = self._kappa_before
            out["implex_dt_before"] = np.array([self._dt_before])
        if self.fracture is not None:
            out |= self.fracture.state()
        return out

    def restore(self, arrays) -> None:
        """The committed history from ``state()`` arrays."""
        self.committed = dm.DamageState(**{f.name: np.array(arrays[f.name]) for f in fields(dm.DamageState)})
        self.iterations = [int(i) for i in arrays["iterations"]]
        self.parent = np.array(arrays["parent"], np.int64)
        if self.allowed is not None:
            self.allowed = np.array(arrays["allowed"], bool)
        self._trial_tracking = None
        self._count = 0
        if "implex_kappa_before" in arrays:
            self._kappa_before = np.array(arrays["implex_kappa_before"])
            self._dt_before = float(np.asarray(arrays["implex_dt_before"])[0])
        if self.fracture is not None:
            self.fracture.restore(arrays)
        self._extrapolated = self._last_strain = None
