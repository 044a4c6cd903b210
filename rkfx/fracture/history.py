"""Trial and committed history of a damage model for the implicit steppers.

A model that evaluates damage (``rkfx.fracture.damage``) from its committed state in every
residual keeps the trial state of the last evaluation in ``trial.state`` and, with particle
tracking, the admissions of the step's iterates in ``_trial_tracking`` (``(allowed, parent)``).
``DamageHistory`` gives such a model the ``commit``, ``state`` and ``restore`` of the stepper
protocol (``rkfx.solvers.model``): the RKPM hydraulic-fracture model and its crack-band FEM
baseline share it. The model holds ``committed`` (a ``DamageState``), ``points`` (its
``DamageModel``), ``allowed`` (or ``None`` without tracking), ``parent``, ``iterations`` (Newton
iterations of every accepted step), ``_count`` (those of the step under way) and ``track`` (a
``rkfx.fracture.tracking.Tracking``, or ``None``).
"""
from dataclasses import fields

import numpy as np

from rkfx.fracture import damage as dm


class DamageHistory:
    """``commit``, ``state`` and ``restore`` of a damage model, and its trial damage with the
    admission of tracking candidates (see the module docstring)."""

    MAX_TRACKING_ROUNDS = 1000  # admissions within one residual (each admits at least one point)

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

    def _admit(self, new: np.ndarray, normal: np.ndarray, allowed: np.ndarray, parent: np.ndarray) -> bool:
        """Allow, in place, the tracking candidates (4.22) of the points ``new`` that initiated
        with ``normal``; whether any was not allowed before."""
        if self.track is None or new.size == 0:
            return False
        cand, by = self.track.candidates(new, normal[new], parent)
        fresh = ~allowed[cand]
        allowed[cand] = True
        parent[cand[fresh]] = by[fresh]
        return bool(fresh.any())

    def commit(self) -> None:
        """The last residual's trial damage (and the step's admissions) become the committed ones."""
        self.committed = self.trial.state
        if self._trial_tracking is not None:
            self.allowed, self.parent = self._trial_tracking
        self._trial_tracking = None
        dm.check_regularization(self.points, self.committed)
        self.iterations.append(self._count)
        self._count = 0

    def state(self) -> dict[str, np.ndarray]:
        """The committed damage state, the admissions and the Newton iterations, for checkpoints."""
        out = {f.name: getattr(self.committed, f.name) for f in fields(dm.DamageState)} | {
            "iterations": np.array(self.iterations, np.int64), "parent": self.parent}
        if self.allowed is not None:
            out["allowed"] = self.allowed
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
