"""Steady states by pseudo-time continuation: backward Euler on steps that grow geometrically.

A model of ``rkfx.solvers`` whose rate terms vanish at rest (storage, Darcy flow, consolidation)
settles, as t -> infinity, into the state that solves its residual alone, r(x) = 0 with its
conditions: a steady seepage under gravity with the stresses in equilibrium with it, the initial
state of a slope or a levee before anything moves. Solving r(x) = 0 directly by Newton from a
far-off guess is fragile where the retention and relative permeability laws are steep; marching
the transient with backward Euler (unconditionally stable, L-stable) on steps dt_k = dt_0 g^k
follows a path of physical states and reaches the steady one in O(log(t_settle / dt_0)) steps,
each a Newton solve of the same model (``rkfx.solvers.integrate``, with its step cutting).

The march stops after the first step whose change is below ``rtol`` of the state in every field
(max norms over all ranks: ghost entries do not count twice in a maximum), or refuses in one
line after ``max_steps``.
"""
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError
from rkfx.solvers.integrate import Integration, integrate
from rkfx.solvers.model import Model
from rkfx.solvers.newmark import StepState, backward_euler


@dataclass
class SteadyState:
    """The end of a march.

    Attributes:
        state: The steady state (its rates are those of the last step, ~0).
        run: How the march went (steps, Newton iterations, cuts, wall time).
        times: Pseudo-times of the steps taken [s], the last one included.
        change: The largest relative change of a field over each step taken.
    """

    state: StepState
    run: Integration
    times: np.ndarray
    change: np.ndarray


def steady_state(model: Model, first_step: float, *, growth: float = 2.0, rtol: float = 1e-9,
                 max_steps: int = 80, comm=None, start: StepState | None = None,
                 progress: Callable | None = None, **options) -> SteadyState:
    """March ``model`` by backward Euler to its steady state (see the module docstring).

    Args:
        model: The model, from its initial state (``start``, default the stepper's start).
        first_step: dt_0 [s], small against the fastest process that should be followed.
        growth: g > 1, the ratio of consecutive steps.
        rtol: Stop when max|x_{k+1} - x_k| <= rtol max|x_{k+1}| in every field.
        max_steps: Refuse if the change is still above ``rtol`` after this many steps.
        comm: The communicator of a distributed model.
        options: Passed to ``integrate`` (solver, max_cuts, checkpoints).
    """
    if not (np.isfinite(first_step) and first_step > 0):
        raise InputError(f"first_step = {first_step!r} must be a positive pseudo-time step [s]")
    if not (np.isfinite(growth) and growth > 1.0):
        raise InputError(f"growth = {growth!r} must exceed 1 (the steps must grow to reach the steady state)")
    if not (np.isfinite(rtol) and 0.0 < rtol < 1.0):
        raise InputError(f"rtol = {rtol!r} must lie in (0, 1)")
    if int(max_steps) != max_steps or max_steps < 1:
        raise InputError(f"max_steps = {max_steps!r} must be a positive whole number")
    stepper = backward_euler()
    start = stepper.start(model) if start is None else start
    times = np.r_[0.0, first_step * np.cumsum(growth ** np.arange(max_steps))]
    blocks = [model.layout.block(f.name) for f in model.layout.fields]
    largest = (lambda v: v) if comm is None or comm.size == 1 else (lambda v: max(comm.allgather(v)))
    previous = start.x.copy()
    change: list[float] = []

    def settled(state: StepState) -> bool:
        nonlocal previous
        worst = 0.0
        for b in blocks:
            step = largest(float(np.max(np.abs(state.x[b] - previous[b]), initial=0.0)))
            size = largest(float(np.max(np.abs(state.x[b]), initial=0.0)))
            worst = max(worst, step / size if size > 0 else 0.0)
        previous = state.x.copy()
        change.append(worst)
        return worst <= rtol

    run = integrate(stepper, model, times, start=start, comm=comm, until=settled, progress=progress, **options)
    if not run.ended_early and not (change and change[-1] <= rtol):
        raise InputError(f"no steady state after {max_steps} steps to t = {times[-1]:.4g} s: the last step still "
                         f"changed a field by {change[-1]:.3g} of its size (rtol {rtol:g}); raise max_steps or growth")
    return SteadyState(run.state, run, times[1:run.steps + 1], np.asarray(change))

