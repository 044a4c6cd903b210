"""Quasi-static load stepping with step cutting and dissipation control through snap-backs.

A quasi-static model (``rkfx.solvers.model``, without mass or capacity) is driven by one load
factor lam: its essential conditions are G x = g(lam), ``constraints(lam)`` giving g and
``rate`` = dg/dlam (g = lam g^ for a prescribed tip displacement lam = u_T). A step solves

    r(x, lam) - G^T mu = 0,   G x - g(lam) = 0,   c(x, mu, lam) = 0

for z = (x, mu, lam) with the shared ``newton``; the control row c is

* displacement control: lam - lam_target = 0;
* dissipation control: (F_0 (lam - lam_0) - lam_0 (F - F_0)) / 2 - tau = 0, the energy
  dissipated in the step by the secant estimate (Gutierrez 2004; Verhoosel et al. 2009),
  with the reaction F = w . mu (``reaction_weights``; default the rate dg/dlam, the force
  work-conjugate to lam) and lam_0, F_0 the committed values.

``march`` reaches every load target exactly in sub-steps. A sub-step is cut by 4 when Newton
fails or the model's history grows by more than ``max_increment`` (e.g. damage), and grows
back by 2 after each success. A sub-step smaller than ``min_fraction`` of the target spacing
that still fails means that no equilibrium path is continuous in lam (a snap-back: the force
must drop while lam decreases); the path is then followed by steps of prescribed dissipation
tau (from ``energy_step``, cut by 4 on failure, grown by 2 up to ``energy_step`` after each
success; a step is also rejected unless 0 < dissipated <= ``max_dissipation`` tau, i.e. the
secant estimate met a far branch) until lam is past the stalled value again or the force has
vanished, and displacement control resumes.

What ``march`` calls on the model, besides ``residual``, ``tangent``, ``constraints``,
``commit``, ``state`` and ``restore`` (the residual evaluates trial history from the committed
state; ``commit()`` follows every accepted step). Optional, looked up by name:

    set_control(mode)      called before each Newton solve with ``"displacement"`` or
                           ``"dissipation"`` (a damage law may treat loading differently)
    history_increment()    the largest growth of the history variable in the trial of the
                           last ``residual`` call over the committed one (default 0: no cuts)
    dissipation()          energy dissipated by that trial since the last commit (needed
                           for dissipation control)
    force_scale            attribute: a typical nodal force; Newton converges at
                           ||r - G^T mu||_inf <= rtol force_scale (default 1)
    reaction_weights       attribute: w of F = w . mu, shape ``(k,)`` (default ``rate``)

Checkpoints (``checkpoint_every`` accepted steps, and at the end): the committed x, mu, lam,
the position in the march, the counters, ``model.state()`` and the recorder's arrays, written
atomically; ``resume=DIR`` continues bit for bit as the uninterrupted run would.
"""
import time as _time
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from rkfx.errors import InputError, SolverError
from rkfx.linalg.linear_solver import Factorizations
from rkfx.solvers.checkpoint import load_arrays, restore_run, prefixed, save_run
from rkfx.solvers.integrate import Recorder  # record(state) after every accepted step (a LoadState), arrays(), restore()
from rkfx.solvers.model import Model
from rkfx.solvers.newton import NewtonOptions, newton

DISPLACEMENT, DISSIPATION = "displacement", "dissipation"


@dataclass(frozen=True)
class QuasiStatic:
    """Settings of ``march`` (see the module docstring).

    Attributes:
        newton: Newton's settings (24 solves per step: a step converges by its 24th iterate).
        rtol: Equilibrium tolerance relative to the model's ``force_scale``.
        ctol: ||G x - g||_inf <= ctol ||g||_inf on the constraints.
        arc_tol: |c| <= arc_tol tau on the dissipation row.
        energy_step: First (and largest) dissipation step tau; 0 disables dissipation control.
        max_increment: Largest history growth per step (``history_increment``).
        min_fraction: Smallest displacement sub-step, as a fraction of the target spacing.
        max_dissipation: A dissipation step is rejected unless 0 < dissipated <= this x tau.
        max_arc_steps: Bound on the dissipation-controlled steps of a run.
    """

    newton: NewtonOptions = field(default_factory=lambda: NewtonOptions(max_iterations=24))
    rtol: float = 1e-10
    ctol: float = 1e-12
    arc_tol: float = 1e-9
    energy_step: float = 0.0
    max_increment: float = 0.1
    min_fraction: float = 1e-3
    max_dissipation: float = 3.0
    max_arc_steps: int = 10000

    def __post_init__(self):
        if int(self.max_arc_steps) != self.max_arc_steps or self.max_arc_steps < 1:
            raise InputError(f"max_arc_steps = {self.max_arc_steps!r} must be a positive integer")
        for name in ("rtol", "ctol", "arc_tol", "max_increment", "max_dissipation"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"QuasiStatic {name} = {v!r} must be positive and finite")
        if not (np.isfinite(self.energy_step) and self.energy_step >= 0):
            raise InputError(f"energy_step = {self.energy_step!r} must be >= 0 (0: no dissipation control)")
        if not 0 < self.min_fraction <= 1:
            raise InputError(f"min_fraction = {self.min_fraction!r} must lie in (0, 1] (e.g. 1e-3)")


@dataclass
class LoadState:
    """An accepted step, as handed to the recorder.

    Attributes:
        step: Accepted steps so far (displacement and dissipation controlled).
        lam: Load factor; force: reaction F = w . mu.
        x: Unknowns, shape ``(size,)``; mu: constraint multipliers, shape ``(k,)``.
        control: ``"displacement"`` or ``"dissipation"``: how the step was controlled.
    """

    step: int
    lam: float
    force: float
    x: np.ndarray
    mu: np.ndarray
    control: str


@dataclass
class _Cursor:
    """Where the march is (checkpointed): target k, sub-step du, energy step tau, and the
    stalled load of a dissipation-controlled stretch (NaN under displacement control)."""

    k: int = 0
    entered: bool = False
    lam: float = 0.0
    du: float = 0.0
    tau: float = 0.0
    f_max: float = 0.0
    stall: float = float("nan")
    steps: int = 0
    cuts: int = 0
    arc_steps: int = 0
    iterations: int = 0
    wall: float = 0.0


@dataclass
class Marched:
    """How a run went.

    Attributes:
        x, mu, lam, force: The last accepted state.
        steps: Accepted steps; cuts: step cuts (displacement and dissipation steps);
            arc_steps: dissipation-controlled steps; iterations: Newton iterations.
        factorizations: Matrices factorized here.
        resumed_from: Accepted steps of the checkpoint resumed from, or ``None``.
        wall_time_s: Wall time of the march, over all pieces of a resumed run [s].
    """

    x: np.ndarray
    mu: np.ndarray
    lam: float
    force: float
    steps: int
    cuts: int
    arc_steps: int
    iterations: int
    factorizations: int
    resumed_from: int | None
    wall_time_s: float


class ConstraintRows:
    """The constraint rows G of a step system over z = (x, mu, lam): G, G^T, and the step
    Jacobian [[K, -G^T, .], [G, 0, .], [., ., .]] bordered by one row and column (``bordered``).
    Shared with ``rkfx.solvers.path_following``."""

    def __init__(self, G: sp.csr_matrix):
        self.G, self.GT = G, G.T.tocsr()
        gc = G.tocoo()
        self.k, self.n = G.shape
        self._rows, self._cols, self._data = [gc.col, self.n + gc.row], [self.n + gc.row, gc.col], [-gc.data, gc.data]

    def bordered(self, K: sp.spmatrix, rows: list, cols: list, data: list) -> sp.csr_matrix:
        """The step Jacobian of the tangent ``K`` with the further entries (``rows``, ``cols``,
        ``data``: lists of arrays) in the border (row and column n + k), assembled from
        triplets (a block matrix of scipy costs more than the factorization of these small
        systems)."""
        kc = sp.coo_matrix(K)
        size = self.n + self.k + 1
        return sp.csr_matrix((np.concatenate([kc.data, *self._data, *data]),
                              (np.concatenate([kc.row, *self._rows, *rows]), np.concatenate([kc.col, *self._cols, *cols]))),
                             shape=(size, size))


class _ControlledSystem:
    """F(x, mu, lam) = [r(x, lam) - G^T mu, G x - g(lam), c] of one step (module docstring)."""

    linear = False

    def __init__(self, stepper: QuasiStatic, model: Model, rows: ConstraintRows, weights, tol: float,
                 target: float | None = None, tau: float | None = None, lam0: float = 0.0, f0: float = 0.0):
        self.stepper, self.model, self.G, self.GT, self.fixed = stepper, model, rows.G, rows.GT, rows
        self.n, self.k = rows.G.shape[1], rows.G.shape[0]
        self.weights, self.tol, self.target, self.tau, self.lam0, self.f0 = weights, tol, target, tau, lam0, f0

    def split(self, z):
        return z[:self.n], z[self.n:self.n + self.k], float(z[-1])

    def residual(self, z):
        x, mu, lam = self.split(z)
        con = self.model.constraints(lam)
        self.rate, self.gscale = con.rate, (np.abs(con.g).max() if con.count else 0.0)
        r = self.model.residual(x, lam) - self.GT @ mu
        if self.tau is None:
            c = lam - self.target
        else:
            c = 0.5 * (self.f0 * (lam - self.lam0) - self.lam0 * (self._weights() @ mu - self.f0)) - self.tau
        return np.r_[r, self.G @ x - con.g, c]

    def _weights(self):
        return self.rate if self.weights is None else self.weights

    def jacobian(self, z):
        """[[K, -G^T, 0], [G, 0, -rate], [0, c_mu, c_lam]]."""
        x, _, lam = self.split(z)
        n, k = self.n, self.k
        rows, cols, data = [n + np.arange(k)], [np.full(k, n + k)], [-np.asarray(self.rate, float)]
        if self.tau is None:  # lam - lam_target
            rows += [[n + k]]
            cols += [[n + k]]
            data += [[1.0]]
        else:  # (F0 (lam - lam0) - lam0 (w . mu - F0)) / 2
            rows += [np.full(k + 1, n + k)]
            cols += [n + np.arange(k + 1)]
            data += [np.r_[-0.5 * self.lam0 * np.asarray(self._weights(), float), 0.5 * self.f0]]
        return self.fixed.bordered(self.model.tangent(x, lam), rows, cols, data)

    def jacobian_key(self):
        return None

    def converged(self, z, r, iteration):
        if iteration < 1:
            return False
        n, k = self.n, self.k
        eq, con, c = r[:n], r[n:n + k], r[-1]
        st = self.stepper
        return bool(np.abs(eq).max() <= self.tol
                    and (k == 0 or np.abs(con).max() <= st.ctol * max(self.gscale, 1e-300))
                    and abs(c) <= st.arc_tol * (1.0 if self.tau is None else self.tau))


def march(model: Model, targets, stepper: QuasiStatic = QuasiStatic(), *, recorder: Recorder | None = None,
          solves: Factorizations | None = None, comm=None, solver: str = "mumps", checkpoint_every: int = 0,
          checkpoint_dir: str | Path | None = None, resume: str | Path | None = None) -> Marched:
    """Load stepping of a quasi-static ``model`` through the load factors ``targets``.

    Args:
        model: The model (module docstring: what it gives).
        targets: Increasing positive load factors, shape ``(K,)``; every one is reached exactly.
        stepper: Tolerances, cutting and dissipation control.
        recorder: Keeps the accepted steps; checkpointed with the state.
        solves: Factorizations to use (default: new ones on ``comm`` with ``solver``, freed at
            the end).
        checkpoint_every: Write a checkpoint every so many accepted steps (0: never), and one
            at the end.
        checkpoint_dir: Folder of the checkpoint.
        resume: A checkpoint folder of the same model and targets to continue from.

    Raises:
        SolverError: The smallest sub-step fails without dissipation control, or the
            dissipation-controlled path stalls; naming the load and Newton's reason.
        InputError: Bad targets, checkpoint settings or a checkpoint of another run.
    """
    targets = np.asarray(targets, float)
    if targets.ndim != 1 or targets.size == 0 or not np.all(np.isfinite(targets)):
        raise InputError("load targets must be a non-empty 1-D sequence of finite numbers")
    if targets[0] <= 0 or np.any(np.diff(targets) <= 0):
        raise InputError("load targets must be positive and strictly increasing (e.g. np.unique of them)")
    if int(checkpoint_every) != checkpoint_every or checkpoint_every < 0:
        raise InputError(f"checkpoint_every = {checkpoint_every!r} must be a non-negative integer (0: never)")
    if checkpoint_every and checkpoint_dir is None:
        raise InputError("checkpoint_every needs checkpoint_dir")
    if stepper.energy_step > 0 and not callable(getattr(model, "dissipation", None)):
        raise InputError(f"dissipation control (energy_step = {stepper.energy_step:g}) needs the model's "
                         "dissipation(); give the model one or set energy_step=0")
    con = model.constraints(0.0)
    if con.rate is None:
        raise InputError("quasi-static constraints need rate = dg/dlam (Constraints.rate)")
    G = sp.csr_matrix(con.G)
    n, k = model.layout.size, G.shape[0]
    constraint_rows = ConstraintRows(G)
    weights = getattr(model, "reaction_weights", None)
    if weights is not None:
        weights = np.asarray(weights, float)
        if weights.shape != (k,):
            raise InputError(f"reaction_weights has shape {weights.shape}; the model has {k} constraint rows")
    tol = stepper.rtol * float(getattr(model, "force_scale", 1.0))
    set_control = getattr(model, "set_control", None)
    increment = getattr(model, "history_increment", lambda: 0.0)
    spacing = np.diff(np.r_[0.0, targets])

    cur = _Cursor(du=float(spacing[0]), tau=float(stepper.energy_step))
    x, mu = np.zeros(n), np.zeros(k)
    resumed = None
    if resume is not None:
        ck = load_arrays(resume)
        if ck["x"].shape != (n,) or ck["mu"].shape != (k,):
            raise InputError(f"checkpoint in {str(resume)!r} has {ck['x'].size} unknowns and {ck['mu'].size} "
                             f"constraints; this model has {n} and {k}: resume with the same model")
        if not np.array_equal(ck["targets"], targets):
            raise InputError(f"checkpoint in {str(resume)!r} was made with other load targets; resume with "
                             "the same parameters")
        x, mu = ck["x"].copy(), ck["mu"].copy()
        cur = _Cursor(**{f.name: type(f.default)(ck["cursor__" + f.name]) for f in fields(_Cursor)})
        restore_run(ck, model, recorder)
        resumed = cur.steps

    own = solves is None
    solves = Factorizations(comm, solver) if own else solves
    made = solves.count
    t_wall = _time.perf_counter()
    wall0 = cur.wall

    def reaction(mu_, lam_):
        return float((model.constraints(lam_).rate if weights is None else weights) @ mu_)

    def checkpoint():
        cur.wall = wall0 + _time.perf_counter() - t_wall
        save_run(checkpoint_dir, {"x": x, "mu": mu, "targets": targets} | prefixed(asdict(cur), "cursor__"),
                 model, recorder, comm)

    def solve(mode, lam_start, **control):
        """Newton from the committed state; the converged (x, mu, lam) or the failed result."""
        if set_control is not None:
            set_control(mode)
        system = _ControlledSystem(stepper, model, constraint_rows, weights, tol, **control)
        res = newton(system, np.r_[x, mu, lam_start], solves, stepper.newton)
        cur.iterations += res.iterations
        return (system.split(res.z) if res.converged else None), res

    def accept(trial, mode):
        nonlocal x, mu
        model.commit()
        x, mu, cur.lam = trial
        cur.steps += 1
        force = reaction(mu, cur.lam)
        if recorder is not None:
            recorder.record(LoadState(cur.steps, cur.lam, force, x.copy(), mu.copy(), mode))
        if checkpoint_every and cur.steps % checkpoint_every == 0:
            checkpoint()
        return force

    try:
        while cur.k < len(targets):
            target, span = float(targets[cur.k]), float(spacing[cur.k])
            smallest = stepper.min_fraction * span
            if not cur.entered:
                cur.du = min(max(cur.du, smallest), target - cur.lam)
                cur.entered = True
            if np.isfinite(cur.stall):  # a dissipation-controlled stretch through a snap-back
                lam0 = cur.lam
                trial, res = solve(DISSIPATION, lam0, tau=cur.tau, lam0=lam0, f0=reaction(mu, lam0))
                if trial is None or not 0.0 < model.dissipation() <= stepper.max_dissipation * cur.tau \
                        or increment() > stepper.max_increment:
                    cur.tau /= 4.0
                    cur.cuts += 1
                    if cur.tau < 1e-6 * stepper.energy_step:
                        why = res.reason if trial is None else "each step met a far branch or grew the history too much"
                        raise SolverError(f"the dissipation-controlled path stalls at load {cur.lam:.6g} ({why}); "
                                          "use more steps or check the model's parameters")
                    continue
                cur.arc_steps += 1
                force = accept(trial, DISSIPATION)
                if cur.lam >= cur.stall or force <= 1e-6 * cur.f_max or cur.arc_steps >= stepper.max_arc_steps:
                    cur.stall, cur.du = float("nan"), smallest
                else:
                    cur.tau = min(2.0 * cur.tau, stepper.energy_step)
                continue
            if cur.lam >= target:  # reached (or passed by a dissipation-controlled stretch)
                cur.du = min(cur.du, span)
                cur.k += 1
                cur.entered = False
                continue
            lam0 = cur.lam
            un = target if lam0 + cur.du >= target * (1 - 1e-12) else lam0 + cur.du
            trial, res = solve(DISPLACEMENT, un, target=un)
            small = un - lam0 <= smallest * (1 + 1e-9)
            if trial is not None and (increment() <= stepper.max_increment or small):
                cur.f_max = max(cur.f_max, accept(trial, DISPLACEMENT))
                cur.du = 2.0 * (un - lam0)
                continue
            if not small:
                cur.du = max((un - lam0) / 4.0, smallest)
                cur.cuts += 1
                continue
            if not (stepper.energy_step > 0 and cur.tau > 0):
                raise SolverError(f"no equilibrium found at load {un:.6g} even with a sub-step of {un - lam0:.3g} "
                                  f"(Newton: {res.reason}; a snap-back?); use more steps, or dissipation control "
                                  "(energy_step > 0)")
            cur.stall = un
        if checkpoint_every:
            checkpoint()
    finally:
        made = solves.count - made
        if own:
            solves.destroy()
    return Marched(x, mu, cur.lam, reaction(mu, cur.lam), cur.steps, cur.cuts, cur.arc_steps, cur.iterations,
                   made, resumed, wall0 + _time.perf_counter() - t_wall)
