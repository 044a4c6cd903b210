"""Path following past a limit load: the load factor an unknown, a displacement prescribed.

Load stepping (``integrate`` with a ``ramp``) finds no equilibrium beyond the largest load a
structure carries, so its last converged step only bounds that load from below, and where
Newton gives up depends on the step and the solver. Here the model's loads scale with its
time argument t (a load factor, e.g. ``ramp(t) = t``) and one linear measure of the
displacement, d(x) = a . x (the settlement of a point), is driven instead (indirect
displacement control, Batoz & Dhatt 1979). Each step solves

    r(x, t) - G^T mu = 0,   G x - g = 0,   a . x - d_k = 0

for z = (x, mu, t) with the shared ``newton``; its Jacobian borders the model's tangent with
the load's column dr/dt and the row a. Past the limit load d keeps growing while t levels off
(perfect plasticity: the collapse load) or falls (softening), so the path t(d) shows the limit
load itself rather than a failure of the solve.

The model gives ``residual``, ``tangent``, ``constraints`` (G x = g fixed; ``rate`` unused),
``commit``/``state``/``restore`` (trial history from the committed state), and
``load_derivative()``: dr/dt at the last ``residual`` call. Each target d_k is reached exactly
in sub-steps: a sub-step whose Newton fails is cut by 4 (down to ``min_fraction`` of the
target spacing, then the run stops with the path so far), and grows back by 2 after each
success. Checkpoints every ``checkpoint_every`` accepted steps and at the end; ``resume=DIR``
continues as the uninterrupted run would. Serial: the bordered system has one global row.
"""
import time as _time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from rkfx.errors import InputError
from rkfx.linalg.linear_solver import Factorizations
from rkfx.solvers.checkpoint import load_arrays, prefixed, restore_run, save_run
from rkfx.solvers.newton import NewtonOptions, newton
from rkfx.solvers.quasi_static import ConstraintRows


@dataclass(frozen=True)
class PathFollowing:
    """Settings of ``follow``.

    Attributes:
        newton: Newton's settings.
        rtol: Equilibrium: ||r - G^T mu||_inf <= rtol ||dr/dt||_inf (the full load's size).
        ctol: ||G x - g||_inf <= ctol (1 + ||g||_inf), as Newmark's, and
            |a . x - d| <= ctol max(|d|, |a| . |x|): relative to the terms' size.
        min_fraction: Smallest sub-step, as a fraction of the target spacing.
    """

    newton: NewtonOptions = field(default_factory=lambda: NewtonOptions(max_iterations=30))
    rtol: float = 1e-9
    ctol: float = 1e-10
    min_fraction: float = 1.0 / 256.0

    def __post_init__(self):
        for name in ("rtol", "ctol"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"PathFollowing {name} = {v!r} must be positive and finite")
        if not 0 < self.min_fraction <= 1:
            raise InputError(f"min_fraction = {self.min_fraction!r} must lie in (0, 1] (e.g. 1/256)")


@dataclass
class PathState:
    """An accepted step, as handed to the recorder: ``step`` accepted so far, the prescribed
    displacement ``d``, the load factor ``t`` found, the unknowns ``x``."""

    step: int
    d: float
    t: float
    x: np.ndarray


@dataclass
class _Cursor:
    """Where the path is (checkpointed)."""

    k: int = 0
    d: float = 0.0
    t: float = 0.0
    dd: float = 0.0
    steps: int = 0
    cuts: int = 0
    iterations: int = 0
    wall: float = 0.0
    ended: str = ""


@dataclass
class Followed:
    """How a run went.

    Attributes:
        x, t, d: The last accepted state (unknowns, load factor, displacement).
        path: (d, t) of every accepted step, the start (d0, t0) first, shape ``(steps + 1, 2)``.
        steps, cuts, iterations: Accepted steps, cut sub-steps, Newton iterations.
        ended: Why the path ended: ``"targets"`` (the last target reached), ``"load"`` (the
            load factor reached ``until_load``), ``"until"`` (``until`` held) or
            ``"no-equilibrium"`` (the smallest sub-step failed; ``message`` says where).
        message: Why an ``"no-equilibrium"`` path stopped, else ``""``.
        resumed_from: Accepted steps of the checkpoint resumed from, or ``None``.
        wall_time_s: Wall time over all pieces of a resumed run [s].
    """

    x: np.ndarray
    t: float
    d: float
    path: np.ndarray
    steps: int
    cuts: int
    iterations: int
    ended: str
    message: str
    resumed_from: int | None
    wall_time_s: float


class _Bordered:
    """F(x, mu, tau) = [r(x, t) - G^T mu, G x - g, c] of one step, t = sigma tau, the control row
    c = rho (a . x - d) (displacement) or K (tau - load / sigma) (a load step, with ``load``).
    sigma = K / max|dr/dt| and rho = K / max|a|, K the largest entry of the start's tangent,
    bring the border to the tangent's size, so that the direct solver's pivots on it are not
    taken for null ones."""

    linear = False

    def __init__(self, model, rows: ConstraintRows, g: np.ndarray, a: np.ndarray, *, d: float, stepper: PathFollowing,
                 scales: tuple[float, float, float], load: float | None = None):
        self.model, self.rows, self.g, self.a, self.d, self.st = model, rows, g, a, d, stepper
        self.G, self.GT = rows.G, rows.GT
        self.load = load
        self.kmax, self.sigma, self.rho = scales
        self.n, self.k = rows.n, rows.k
        self.gscale = float(np.abs(g).max()) if g.size else 0.0

    def split(self, z):
        """x, mu and the load factor t."""
        return z[:self.n], z[self.n:self.n + self.k], self.sigma * float(z[-1])

    def unknowns(self, x, mu, t):
        """z of x, mu and t."""
        return np.r_[x, mu, t / self.sigma]

    def residual(self, z):
        x, mu, t = self.split(z)
        r = self.model.residual(x, t) - self.GT @ mu
        self.rate = np.asarray(self.model.load_derivative(), float)
        c = self.rho * (self.a @ x - self.d) if self.load is None else self.kmax * (z[-1] - self.load / self.sigma)
        return np.r_[r, self.G @ x - self.g, c]

    def jacobian(self, z):
        x, _, t = self.split(z)
        n, k = self.n, self.k
        col = np.flatnonzero(self.rate)
        row = np.flatnonzero(self.a) if self.load is None else np.array([n + k])
        border = self.rho * self.a[row] if self.load is None else np.array([self.kmax])
        return self.rows.bordered(self.model.tangent(x, t), [col, np.full(len(row), n + k)],
                                  [np.full(len(col), n + k), row], [self.sigma * self.rate[col], border])

    def jacobian_key(self):
        return None

    def converged(self, z, r, iteration):
        if iteration < 1:
            return False
        n, k = self.n, self.k
        x, _, t = self.split(z)
        scale = max(float(np.abs(self.rate).max()), 1e-300)
        if self.load is None:
            miss, size = abs(r[-1]) / self.rho, max(abs(self.d), np.abs(self.a) @ np.abs(x))
        else:
            miss, size = abs(t - self.load), max(abs(self.load), abs(t))
        return bool(np.abs(r[:n]).max() <= self.st.rtol * scale
                    and (k == 0 or np.abs(r[n:n + k]).max() <= self.st.ctol * (1.0 + self.gscale))
                    and miss <= self.st.ctol * max(size, 1e-300))


def follow(model, control: np.ndarray, targets, x0: np.ndarray, t0: float = 0.0,
           stepper: PathFollowing = PathFollowing(), *, until_load: float | None = None,
           until: Callable[[PathState, np.ndarray], bool] | None = None, recorder=None, comm=None, solver: str = "mumps",
           checkpoint_every: int = 0, checkpoint_dir: str | Path | None = None,
           resume: str | Path | None = None) -> Followed:
    """Follow the equilibrium path of ``model`` with a . x driven through ``targets``.

    Args:
        model: The model (module docstring: what it gives); serial.
        control: a, shape ``(size,)``: the displacement measure d(x) = a . x.
        targets: The values of d to reach, strictly monotone away from d(x0), shape ``(K,)``.
        x0: The committed start (in equilibrium at t0 with the model's history).
        t0: Its load factor.
        stepper: Tolerances and cutting.
        until_load: End where the load factor reaches this value: the step that would pass it
            is replaced by a load step to it (a load-controlled step from the committed
            state), so the path ends on the equilibrium at exactly that load.
        until: A test ``until(state, path)`` of each accepted step, ``path`` the (d, t) so far
            (as ``Followed.path``); the path ends after the first step for which it holds (a
            limit load reached: the load factor levelled off).
        recorder: Keeps the accepted steps (``record(PathState)``, ``arrays()``, ``restore()``);
            checkpointed with the state.
        checkpoint_every: Write a checkpoint every so many accepted steps (0: never), and one
            at the end.
        checkpoint_dir: Folder of the checkpoint.
        resume: A checkpoint folder of the same model and targets to continue from.

    Raises:
        InputError: Bad control, targets or checkpoint settings, a model without
            ``load_derivative``, or a model split over several ranks.
    """
    if not callable(getattr(model, "load_derivative", None)):
        raise InputError(f"{type(model).__name__} has no load_derivative(): path following needs dr/dt of its loads")
    share = getattr(model, "share", None)
    if share is not None and share.size > 1:
        raise InputError("path following runs serially (its bordered row is global); run this stage on one rank")
    n = model.layout.size
    a = np.asarray(control, float)
    x = np.array(x0, float)
    if a.shape != (n,) or x.shape != (n,) or not np.all(np.isfinite(a)) or not np.any(a):
        raise InputError(f"control and x0 must be finite vectors of the model's {n} unknowns, control nonzero")
    targets = np.asarray(targets, float)
    d0 = float(a @ x)
    if targets.ndim != 1 or targets.size == 0 or not np.all(np.isfinite(targets)):
        raise InputError("targets must be a non-empty 1-D sequence of finite numbers")
    direction = np.sign(targets[0] - d0)
    if direction == 0 or np.any(direction * np.diff(np.r_[d0, targets]) <= 0):
        raise InputError(f"targets must move strictly one way from the start's d = {d0:.6g}")
    if int(checkpoint_every) != checkpoint_every or checkpoint_every < 0:
        raise InputError(f"checkpoint_every = {checkpoint_every!r} must be a non-negative integer (0: never)")
    if checkpoint_every and checkpoint_dir is None:
        raise InputError("checkpoint_every needs checkpoint_dir")
    con = model.constraints(t0)
    G, g = sp.csr_matrix(con.G), np.asarray(con.g, float)
    rows = ConstraintRows(G)
    spacing = np.abs(np.diff(np.r_[d0, targets]))
    cur = _Cursor(d=d0, t=float(t0), dd=float(spacing[0]))
    path = [(d0, float(t0))]
    mu = np.zeros(G.shape[0])
    model.residual(x, float(t0))  # a trial only: the sizes of the border at the start
    rate, kmax = np.abs(model.load_derivative()).max(), abs(sp.csr_matrix(model.tangent(x, float(t0)))).max()
    if not (np.isfinite(rate) and rate > 0 and np.isfinite(kmax) and kmax > 0):
        raise InputError(f"the model's loads do not change with t (max |dr/dt| = {rate:g}) or its tangent is zero: "
                         "give the model a load factor (ramp)")
    scales = (kmax, kmax / rate, kmax / np.abs(a).max())
    resumed = None
    if resume is not None:
        ck = load_arrays(resume)
        if ck["x"].shape != (n,) or not np.array_equal(ck["targets"], targets):
            raise InputError(f"checkpoint in {str(resume)!r} is of another model or other targets; resume with "
                             "the same parameters")
        x, mu = ck["x"].copy(), ck["mu"].copy()
        cur = _Cursor(**{f.name: type(f.default)(ck["cursor__" + f.name]) for f in fields(_Cursor)})
        path = [tuple(r) for r in ck["path"]]
        scales = tuple(float(v) for v in ck["scales"])
        restore_run(ck, model, recorder)
        resumed = cur.steps

    solves = Factorizations(comm, solver)
    t_wall, wall0 = _time.perf_counter(), cur.wall
    message = ""

    def checkpoint():
        cur.wall = wall0 + _time.perf_counter() - t_wall
        save_run(checkpoint_dir, {"x": x, "mu": mu, "targets": targets, "path": np.array(path), "scales": np.array(scales)}
                 | prefixed(asdict(cur), "cursor__"), model, recorder, comm)

    def solve(start, **row):
        system = _Bordered(model, rows, g, a, stepper=stepper, scales=scales, **row)
        res = newton(system, system.unknowns(*start), solves, stepper.newton)
        cur.iterations += res.iterations
        return system, res

    try:
        while not cur.ended:
            target, smallest = float(targets[cur.k]), stepper.min_fraction * float(spacing[cur.k])
            left = abs(target - cur.d)
            step = left if cur.dd >= left * (1 - 1e-12) else cur.dd
            d_new = target if step == left else cur.d + direction * step
            system, res = solve((x, mu, cur.t), d=d_new)
            passed = (res.converged and until_load is not None and cur.t != until_load
                      and (cur.t - until_load) * (system.split(res.z)[2] - until_load) <= 0)
            if passed:  # a load step to until_load, from the committed state
                x1, mu1, t1 = system.split(res.z)
                s = (until_load - cur.t) / (t1 - cur.t)
                system, res = solve((x + s * (x1 - x), mu + s * (mu1 - mu), until_load), d=0.0, load=until_load)
            if not res.converged:
                if step <= smallest * (1 + 1e-9):
                    message = f"no equilibrium found at d = {d_new:.6g} with a sub-step of {step:.3g} (Newton: {res.reason})"
                    cur.ended = "no-equilibrium"
                    break
                cur.dd = max(step / 4.0, smallest)
                cur.cuts += 1
                continue
            model.commit()
            x, mu, t = system.split(res.z)
            if passed:
                d_new = float(a @ x)
            cur.d, cur.t, cur.steps, cur.dd = d_new, t, cur.steps + 1, 2.0 * step
            path.append((d_new, t))
            if d_new == target:
                cur.k += 1
                cur.dd = min(cur.dd, float(spacing[min(cur.k, len(spacing) - 1)]))
            state = PathState(cur.steps, d_new, t, x.copy())
            if recorder is not None:
                recorder.record(state)
            cur.ended = ("load" if passed else "targets" if cur.k == len(targets)
                         else "until" if until is not None and until(state, np.array(path)) else "")
            if checkpoint_every and cur.steps % checkpoint_every == 0:
                checkpoint()
        if checkpoint_every:
            checkpoint()
    finally:
        solves.destroy()
    return Followed(x, cur.t, cur.d, np.array(path), cur.steps, cur.cuts, cur.iterations, cur.ended, message,
                    resumed, wall0 + _time.perf_counter() - t_wall)
