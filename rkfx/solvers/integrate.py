"""The time loop of the implicit steppers: step cutting, outputs, checkpoints and resume.

``integrate`` walks a grid of step times t_0 < t_1 < ... (``time_grid`` makes one that hits
every output time). Each interval is one step; when Newton fails on it the interval is cut
in halves, up to ``max_cuts`` times, and the step is retried from the committed state, so a
failed step never touches the model's history. Every finished grid step is committed, handed
to ``recorder.record(state)``, and every ``checkpoint_every`` grid steps the stepper state,
the model's committed history and the recorder's arrays are written atomically to
``checkpoint_dir``; ``resume=DIR`` continues from there and ends as an uninterrupted run would.
``until(state)`` ends the run early, after the first committed grid step for which it holds
(an event: a crack reaching a boundary); a checkpoint is written there, and resuming from it
ends at once.
A model distributed over MPI ranks (``rkfx.parallel.unknowns``) writes one checkpoint per
rank (``rank<r>-of-<P>/``), which resumes on the same number of ranks.
"""
import time as _time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from rkfx.errors import InputError
from rkfx.linalg.linear_solver import Factorizations
from rkfx.solvers.checkpoint import RankFiles, restore_run, prefixed, save_run, unprefixed
from rkfx.solvers.model import Model
from rkfx.solvers.newmark import Newmark, StepState


class Recorder(Protocol):
    """What a run keeps of its steps (outputs at chosen times, histories)."""

    def record(self, state: StepState) -> None:
        """Called after every committed grid step."""

    def arrays(self) -> Mapping[str, np.ndarray]:
        """What has been kept so far, for checkpoints."""

    def restore(self, arrays: Mapping[str, np.ndarray]) -> None:
        """Set what was kept from ``arrays()``."""


@dataclass
class Integration:
    """How a run went.

    Attributes:
        state: The final state.
        steps: Grid steps finished (including those before a resume).
        substeps: Steps solved here, cuts included.
        cuts: Intervals that had to be cut.
        newton_iterations: Linear solves of all Newton iterations here.
        factorizations: Matrices factorized here.
        resumed_from: Grid step of the checkpoint resumed from, or ``None``.
        wall_time_s: Wall time of the loop [s].
        ended_early: ``until`` held before the last step time.
    """

    state: StepState
    steps: int
    substeps: int
    cuts: int
    newton_iterations: int
    factorizations: int
    resumed_from: int | None
    wall_time_s: float
    ended_early: bool = False


def time_grid(output_times: Sequence[float], first_step: float, growth: float = 1.0,
              max_step: float = np.inf, hold: int = 1) -> np.ndarray:
    """Step times 0 = t_0 < t_1 < ... hitting every output time exactly.

    Steps start at ``first_step`` and grow by ``growth`` every ``hold`` steps (1 = uniform) up
    to ``max_step``; a step that would pass an output time is shortened to end on it. Holding
    the step for several steps lets a linear model reuse its factorization.
    """
    if int(hold) != hold or hold < 1:
        raise InputError(f"hold = {hold!r} must be a positive integer")
    out = np.sort(np.asarray(output_times, float))
    if not first_step > 0:
        raise InputError(f"first time step {first_step!r} must be positive")
    if not growth >= 1.0:
        raise InputError(f"step growth {growth!r} must be >= 1")
    if out.size == 0 or out[0] <= 0:
        raise InputError("output times must be positive")
    t, dt, grid = 0.0, first_step, [0.0]
    for target in out:
        while t < target * (1 - 1e-12):
            step = min(dt, max_step)
            if t + step > target * (1 - 1e-9) or target - (t + step) < 1e-3 * step:
                step = target - t
            t = target if abs(target - (t + step)) <= 1e-12 * target else t + step
            grid.append(t)
            if (len(grid) - 1) % hold == 0:
                dt = min(dt * growth, max_step)
    return np.array(grid)


def integrate(stepper: Newmark, model: Model, times: Sequence[float], *, start: StepState | None = None,
              recorder: Recorder | None = None, solves: Factorizations | None = None, comm=None,
              solver: str = "mumps", max_cuts: int = 4, checkpoint_every: int = 0,
              checkpoint_dir: str | Path | None = None, resume: str | Path | None = None,
              progress: Callable | None = None, until: Callable[[StepState], bool] | None = None) -> Integration:
    """Advance ``model`` through the step times ``times`` with ``stepper``.

    Args:
        stepper: A ``Newmark`` (theta-method, trapezoid, explicit, ...).
        model: The model (``rkfx.solvers.model.Model``).
        times: Step times, shape ``(N + 1,)``, strictly increasing, ``times[0]`` the start.
        start: Initial state (default ``stepper.start(model, t0=times[0])``).
        recorder: Keeps outputs; checkpointed with the state.
        solves: Factorizations to use (default: new ones on ``comm`` with ``solver``, freed
            at the end).
        max_cuts: Halvings of a failing interval before the run stops with an error.
        checkpoint_every: Write a checkpoint every so many grid steps and at the last one
            (0: never), so that resuming a finished run returns its result at once.
        checkpoint_dir: Folder of the checkpoint.
        resume: A checkpoint folder to continue from.
        progress: Optional wrapper of the step iterator (a progress bar).
        until: Optional test of each committed grid step; the run ends after the first that
            passes it.

    Raises:
        SolverError: A step failed at the smallest cut, naming the step, time, iteration and
            residual.
    """
    t_all = np.asarray(times, float)
    if t_all.ndim != 1 or len(t_all) < 1 or np.any(np.diff(t_all) <= 0):
        raise InputError("step times must be a strictly increasing 1-D sequence")
    if checkpoint_every and checkpoint_dir is None:
        raise InputError("checkpoint_every needs checkpoint_dir")
    if int(max_cuts) != max_cuts or max_cuts < 0:
        raise InputError(f"max_cuts = {max_cuts!r} must be a non-negative integer")
    own = solves is None
    solves = Factorizations(comm, solver) if own else solves
    made = solves.count
    resumed = None
    files = RankFiles(getattr(model, "share", None), comm)
    if resume is not None:
        ck = files.load(resume)
        s = StepState.from_arrays(unprefixed(ck, "state__"))
        if s.x.shape != (model.layout.size,):
            raise InputError(f"checkpoint in {str(resume)!r} has {s.x.size} unknowns; this model has "
                             f"{model.layout.size}")
        k = s.step
        if k >= len(t_all) or abs(t_all[k] - s.t) > 1e-12 * max(abs(s.t), 1.0):
            raise InputError(f"checkpoint in {str(resume)!r} is at t = {s.t:.6g} (step {k}), which is not step "
                             f"{k} of these step times; resume with the same times")
        restore_run(ck, model, recorder)
        resumed = k
    else:
        s = start if start is not None else stepper.start(model, t0=float(t_all[0]), comm=solves.comm)
        if abs(s.t - t_all[0]) > 1e-12 * max(abs(t_all[0]), 1.0):
            raise InputError(f"the start state is at t = {s.t:.6g}, the step times start at {t_all[0]:.6g}")
    substeps = cuts = iterations = 0
    t_wall = _time.perf_counter()
    ended = resumed is not None and until is not None and s.step < len(t_all) - 1 and bool(until(s))
    steps = range(s.step + 1, len(t_all) if not ended else s.step + 1)
    try:
        for k in (progress(steps) if progress else steps):
            target = float(t_all[k])
            dt = target - s.t
            depth = 0
            while s.t < target:
                last = target - s.t <= dt * (1 + 1e-9)
                h = target - s.t if last else dt
                new, res = stepper.advance(model, s, h, solves)
                iterations += res.iterations
                if new is None:
                    if depth >= max_cuts:
                        raise res.error(f"step {k} (t = {s.t + h:.6g} s, dt = {h:.3g} s after {depth} cuts)")
                    depth += 1
                    cuts += 1
                    dt = 0.5 * h
                    continue
                model.commit()
                substeps += 1
                if last:
                    new.t, new.step = target, k
                else:
                    new.step = s.step
                s = new
            if recorder is not None:
                recorder.record(s)
            ended = until is not None and k < len(t_all) - 1 and bool(until(s))
            if checkpoint_every and (k % checkpoint_every == 0 or k == len(t_all) - 1 or ended):
                save_run(files.folder(checkpoint_dir), prefixed(s.arrays(), "state__"), model, recorder, files.writer)
            if ended:
                break
    finally:
        made = solves.count - made
        if own:
            solves.destroy()
    return Integration(s, s.step, substeps, cuts, iterations, made, resumed, _time.perf_counter() - t_wall, ended)
