"""Explicit u-p dynamics: Newmark with beta1 = 1/2, beta2 = 0 for u, the trapezoid with theta = 0
for p, lumped masses (eqs. 6.37-6.43).

The model (``ExplicitUPModel``) has a displacement field of time order 2 and a pressure field of
time order 1 (``rkfx.solvers.fields``), lumped masses M_u (inertia) and M_p (storage 1/Q), and
gives the two halves of its internal force apart, because the fluid half needs the new velocity:

    M_u a_{n+1}  = f_ext,u(t_{n+1}) - f_u(u_{n+1}, p_{n+1})                  (6.42)
    M_p p'_{n+1} = f_ext,p(t_{n+1}) - f_p(u'_{n+1}, p_{n+1})                 (6.43)

One step n -> n+1:

    u_{n+1}  = u_n + dt u'_n + dt^2/2 a_n                    (6.39, beta2 = 0)
    M_p p'_{n+1/2} = f_ext,p - f_p((u_{n+1} - u_n) / dt, p_n)
    p_{n+1}  = p_n + dt p'_{n+1/2}                           (6.41, theta = 0 in the diffusion)
    a_{n+1}  from (6.42);  u'_{n+1} = u'_n + dt/2 (a_n + a_{n+1})   (6.38, beta1 = 1/2)

The storage equation takes the skeleton's rate over the step, (u_{n+1} - u_n) / dt, rather than
u'_{n+1} or u'_n: with either end rate the pressure lags or leads the skeleton by O(dt) and the
undrained oscillation gains energy every step, so that without diffusion the literal reading of
(6.41)-(6.43) is unstable at any dt (measured on a one-node undrained system: growth at every
dt from 0.3 to 0.99 of 2 / omega). With the step's increment the undrained limit is the
central-difference scheme of the undrained skeleton, stable up to 2 / omega_max, and the
diffusion is forward Euler, stable up to 2 / lambda_max; together, see ``stable_steps``.

``rkfx.solvers.newmark.Newmark(beta=0, gamma=1/2, theta=0)`` takes the literal reading (the
storage rows see u'_{n+1}), and on the same one-node undrained system it grows at 0.1, 0.3 and
0.6 of 2 / omega (measured). This stepper stands apart until Newmark's explicit path can take
it, which needs more than another rate: a staggered predictor that updates p after u within the
step (Newmark's predictors both use the old rates, so p would lag u by a step).

Essential conditions (``rkfx.solvers.central_difference.Constraint`` rows over the whole vector,
e.g. collocation rows of u or p at boundary nodes) are imposed by M-orthogonal projection of the
new values and rates, as in ``CentralDifference``, each field in its own mass metric:
G u_{n+1} = g(t_{n+1}), G u'_{n+1} = g'(t_{n+1}), G p_{n+1} = g(t_{n+1}).

A model may also give ``pressure_stabilization(dt)``, a matrix S over the p unknowns (the fluid
pressure projection of 6.49, zero row sums), or ``None``: the storage is then M_p + S, solved
each step by conjugate gradients preconditioned by M_p, and the pressure conditions are imposed
in that metric. The stable-step estimates keep the lumped M_p, which only adds capacity, so
they stay on the safe side.

Stability needs dt below both the wave limit 2 / omega_max of M_u^-1 K_uu and the diffusion
limit 2 / lambda_max of M_p^-1 H (forward Euler on the pressure), and somewhat less where the
two are close. ``stable_steps`` estimates both by power iteration and the step allowed;
``ExplicitUPRun.limits`` reports them and which one governs.
"""
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from rkfx.errors import InputError
from rkfx.solvers.central_difference import Constraint, _Projection
from rkfx.solvers.checkpoint import RankFiles, has_checkpoint, save_arrays
from rkfx.solvers.fields import FieldLayout


@runtime_checkable
class ExplicitUPModel(Protocol):
    """What ``ExplicitUP`` needs of a model.

    Attributes:
        layout: Fields ``u`` (time order 2) then ``p`` (time order 1).
        essential: Essential conditions, rows over the whole vector.
    """

    layout: FieldLayout
    essential: Sequence[Constraint]

    def lumped_mass(self) -> np.ndarray:
        """M_u on the u unknowns [kg] and M_p on the p unknowns [m^3/Pa], shape ``(size,)``, positive."""

    def solid_force(self, u: np.ndarray, p: np.ndarray) -> np.ndarray:
        """f_u(u, p), the u block of the internal force [N], shape ``(size_u,)``."""

    def fluid_flux(self, v: np.ndarray, p: np.ndarray) -> np.ndarray:
        """f_p(u', p), the p block [m^3/s], shape ``(size_p,)``."""

    def external_force(self, t: float) -> np.ndarray | None:
        """f_ext(t) over the whole vector, or ``None``."""


@dataclass
class ExplicitUPRun:
    """A finished run: final state and the recorded samples.

    Attributes:
        x: Final [u, p], shape ``(size,)``.
        rate: Final [u', p'], shape ``(size,)``.
        times: Recorded times [s], shape ``(num_samples,)``.
        samples: What the recorder returned at each recorded time, stacked.
        steps: Steps taken.
        limits: ``{"wave": dt, "diffusion": dt}`` stable-step estimates [s] when computed.
        resumed_from: Step of the checkpoint the run continued from, or ``None``.
    """

    x: np.ndarray
    rate: np.ndarray
    times: np.ndarray
    samples: np.ndarray
    steps: int
    limits: dict = field(default_factory=dict)
    resumed_from: int | None = None


def _power_iteration(apply: Callable[[np.ndarray], np.ndarray], start: np.ndarray, iterations: int = 60,
                     dot: Callable[[np.ndarray, np.ndarray], float] | None = None) -> float:
    """Largest eigenvalue of a symmetric-positive operator (in its mass metric) by power iteration
    from ``start``; ``dot`` sums over the ranks' owned entries on MPI ranks."""
    w = start
    lam = 0.0
    for _ in range(iterations):
        z = apply(w)
        norm = np.linalg.norm(z) if dot is None else np.sqrt(dot(z, z))
        if norm == 0.0:
            return 0.0
        lam = float(w @ z / (w @ w)) if dot is None else dot(w, z) / dot(w, w)
        w = z / norm
    return lam


def _summed(share) -> Callable[[np.ndarray], np.ndarray]:
    """A rank's contributions over its local unknowns to the whole model's values there
    (``UnknownShare.assemble``, collective); serially the values themselves."""
    return (lambda v: v) if share is None else share.assemble


def stable_steps(model: ExplicitUPModel, safety: float = 1.0, seed: int = 0) -> dict[str, float]:
    """Stable-step estimates [s]: ``wave`` = 2 / omega_max of the undrained skeleton,
    ``diffusion`` = 2 / lambda_max of M_p^-1 H, each times ``safety``; ``governs`` names the
    smaller. ``coupled`` = 1 / (1/wave + 1/diffusion) is the step the stepper allows: where both
    limits are close the coupled scheme's limit falls below the smaller (to 0.62 of it on the
    one-node systems of ``tests/test_explicit_up.py``, where ``coupled`` is 0.50-0.91 of it).
    Power iteration approaches the largest eigenvalues from below, so the estimates can be a few
    percent long: run at a fraction of ``coupled`` (e.g. 0.9, as ``safety`` or on dt).

    A model split over MPI ranks (``share``, ``local``) starts from the serial run's vectors
    (seeded over the whole model's unknowns) and sums its products over the owned entries, so
    every rank gets the serial estimates to round-off. Collective then."""
    lay = model.layout
    su, sp_ = lay.block("u"), lay.block("p")
    share = getattr(model, "share", None)
    total = _summed(share)
    m = total(np.asarray(model.lumped_mass(), float))
    mu, mp = m[su], m[sp_]
    nu, npr = mu.size, mp.size
    zero_p, zero_u = np.zeros(npr), np.zeros(nu)
    if share is None:
        start_u, start_p = (np.random.default_rng(seed).standard_normal(k) for k in (nu, npr))
        dot_u = dot_p = None
    else:
        owned = np.zeros(lay.size, bool)
        owned[share.owned] = True
        index = np.asarray(model.local.index)
        whole_u = int(round(share.total(np.count_nonzero(owned[su]))))
        whole_p = int(round(share.total(np.count_nonzero(owned[sp_]))))
        start_u = np.random.default_rng(seed).standard_normal(whole_u)[index[su]]
        start_p = np.random.default_rng(seed).standard_normal(whole_p)[index[sp_] - whole_u]
        dot_u = lambda a, b: share.total(float(a[owned[su]] @ b[owned[su]]))  # noqa: E731
        dot_p = lambda a, b: share.total(float(a[owned[sp_]] @ b[owned[sp_]]))  # noqa: E731

    def block(values: np.ndarray, at: slice) -> np.ndarray:
        if share is None:
            return values
        whole = np.zeros(lay.size)
        whole[at] = values
        return total(whole)[at]

    # Undrained (the fast wave): no flow, so M_p p' = -C_pu u' gives p = -M_p^-1 f_p(u, 0) and the
    # skeleton sees K + C_up M_p^-1 C_pu.
    omega2 = _power_iteration(lambda w: block(model.solid_force(w, -block(model.fluid_flux(w, zero_p), sp_) / mp), su)
                              / mu, start_u, dot=dot_u)
    # The flux's response to p alone: f_p(0, p) = H p (+ the stabilization, which is part of it).
    lam = _power_iteration(lambda w: block(model.fluid_flux(zero_u, w), sp_) / mp, start_p, dot=dot_p)
    wave = safety * 2.0 / np.sqrt(omega2) if omega2 > 0 else np.inf
    diffusion = safety * 2.0 / lam if lam > 0 else np.inf
    return {"wave": wave, "diffusion": diffusion, "coupled": 1.0 / (1.0 / wave + 1.0 / diffusion),
            "governs": "wave" if wave <= diffusion else "diffusion"}


def _capacity_solver(S, mp: np.ndarray, summed_p: Callable[[np.ndarray], np.ndarray],
                     dot: Callable[[np.ndarray, np.ndarray], float], tol: float = 1e-10, max_iterations: int = 2000
                     ) -> Callable[[np.ndarray], np.ndarray]:
    """z = (M_p + S)^-1 b by conjugate gradients preconditioned by the lumped M_p (S: a model's
    pressure stabilization, on ranks its points' part, summed by ``summed_p``), to a relative
    residual ``tol`` in the M_p^-1 norm; refuses in one line when it does not converge."""
    def solve(b):
        z = b / mp
        r, s = b.copy(), z.copy()
        x = np.zeros_like(b)
        rz = dot(r, s)
        goal = tol * tol * rz
        for _ in range(max_iterations):
            if rz <= goal:
                return x
            q = mp * s + summed_p(S @ s)
            step = rz / dot(s, q)
            x += step * s
            r -= step * q
            z = r / mp
            rz, rz_old = dot(r, z), rz
            s = z + (rz / rz_old) * s
        raise InputError(f"the storage rows with the pressure projection did not converge in {max_iterations} "
                         "conjugate-gradient iterations: the projection's eps_f is far above 1/Q; run without fpp")
    return solve


def _by_field(constraints: Sequence[Constraint], su: slice, sp_: slice) -> tuple[list, list]:
    """The conditions on u and those on p, each with its rows restricted to its own block (the
    two masses differ by many orders of magnitude, so each field is projected in its own metric)."""
    on_u, on_p = [], []
    for c in constraints:
        g = c.G.tocsc()
        in_u, in_p = g[:, su].nnz, g[:, sp_].nnz
        if in_u and in_p:
            raise InputError("an essential condition couples u and p unknowns; give each field its own conditions")
        block, out = (su, on_u) if in_u else (sp_, on_p)
        out.append(Constraint(g[:, block].tocsr(), c.displacement, c.velocity))
    return on_u, on_p


def _project(proj, w: np.ndarray, target) -> None:
    if proj.G is not None:
        proj.project(w, target)


@dataclass
class ExplicitUP:
    """The stepper. ``dt`` [s] is the step; ``check_stability`` refuses a dt above the estimates.

    Attributes:
        dt: Step size [s].
        check_stability: Estimate the stable steps first and refuse a larger ``dt``.
    """

    dt: float
    check_stability: bool = True

    def __post_init__(self):
        if not (np.isfinite(self.dt) and self.dt > 0):
            raise InputError(f"dt = {self.dt!r}: the time step must be a positive number of seconds")

    def run(self, model: ExplicitUPModel, num_steps: int, *, record: Callable[[np.ndarray, np.ndarray, float], np.ndarray]
            | None = None, record_every: int = 1, x0: np.ndarray | None = None,
            progress: Callable[[int], None] | None = None, checkpoint_every: int = 0,
            checkpoint_dir=None, resume=None, comm=None) -> ExplicitUPRun:
        """Advance ``num_steps`` steps from rest (or ``x0``), recording ``record(x, rate, t)``
        at t = 0 and every ``record_every`` steps.

        ``checkpoint_every`` steps (and at the last) the state and the samples so far go to
        ``checkpoint_dir`` (written by rank 0 of ``comm``, or one file per rank for a model split
        over the ranks); ``resume``, a folder holding such a checkpoint of the same model and
        dt, continues from it to the same result as an uninterrupted run (the acceleration is a
        function of the state, so x and the rates are the whole state).

        A model split over MPI ranks (``share``: its masses, forces and fluxes are its points'
        contributions over its local unknowns) is stepped on the local vectors: every force is
        summed over the ranks (one neighbour exchange), so each local entry, owned or ghost,
        takes the whole model's update; the essential conditions' rows are whole on every rank
        (over its local unknowns), which projects alike; the new values and rates of the ghosts
        are then copied from their owners. ``record`` sees the local vectors (sum its owned
        terms over the ranks)."""
        if checkpoint_every and checkpoint_dir is None:
            raise InputError("checkpoint_every needs checkpoint_dir")
        lay = model.layout
        if lay.field("u").order != 2 or lay.field("p").order != 1:
            raise InputError("ExplicitUP needs a displacement field 'u' of time order 2 and a pressure 'p' of order 1")
        su, sp_ = lay.block("u"), lay.block("p")
        n = lay.size
        share = getattr(model, "share", None)
        total = _summed(share)
        files = RankFiles(share, comm)
        mass = np.asarray(model.lumped_mass(), float)
        mass = total(mass) if mass.shape == (n,) else mass
        bad = mass.shape != (n,) or not np.all(mass > 0)
        if share.max(float(bad)) if share is not None else bad:
            raise InputError("lumped_mass() must give a positive mass for each of the model's unknowns")
        limits = {}
        if self.check_stability:
            limits = stable_steps(model)
            bound = limits["coupled"]
            if self.dt > bound:
                raise InputError(f"dt = {self.dt:.4g} s exceeds the stable step {bound:.4g} s (wave limit "
                                 f"{limits['wave']:.4g} s, diffusion limit {limits['diffusion']:.4g} s, the "
                                 f"{limits['governs']} governs): take a smaller dt")
        on_u, on_p = _by_field(model.essential, su, sp_)
        proj_u = _Projection(on_u, mass[su])
        dt = self.dt
        stabilization = getattr(model, "pressure_stabilization", None)
        S = None if stabilization is None else stabilization(dt)
        capacity = None
        if S is not None:
            owned_p = slice(None) if share is None else np.isin(np.arange(n), share.owned)[sp_]

            def summed_p(v):
                if share is None:
                    return v
                whole = np.zeros(n)
                whole[sp_] = v
                return total(whole)[sp_]

            dot = (lambda a, b: float(a @ b)) if share is None else \
                (lambda a, b: share.total(float(a[owned_p] @ b[owned_p])))
            capacity = _capacity_solver(S, mass[sp_], summed_p, dot)
        # With the projection the storage is M_p + S, and the pressure conditions are imposed in
        # its metric, so that the rate stays the one of (M_p + S) p' = r on the free unknowns.
        proj_p = _Projection(on_p, mass[sp_], capacity)
        x = np.zeros(n) if x0 is None else np.array(x0, float)
        rate = np.zeros(n)
        acc = np.zeros(n)  # only the u block is used

        def f_ext(t):
            f = model.external_force(t)
            return np.zeros(n) if f is None else np.array(f, float)  # a copy: the step adds to it

        def acceleration(x, t):
            """a from (6.42) at the new u and p."""
            r = f_ext(t)
            r[su] -= model.solid_force(x[su], x[sp_])
            r[sp_] = 0.0
            a = np.zeros(n)
            a[su] = total(r)[su] / mass[su]
            return a

        def storage_rate(x_new, x, t):
            """p' over the step from (6.43): the coupling by the step's displacement increment
            (the rate at the half step), the diffusion at p_n (theta = 0)."""
            r = f_ext(t - 0.5 * dt)
            r[sp_] -= model.fluid_flux((x_new[su] - x[su]) / dt, x[sp_])
            r[su] = 0.0
            b = total(r)[sp_]
            return b / mass[sp_] if capacity is None else capacity(b)

        def from_owners(w):
            """w with its ghost entries copied from their owners (on ranks)."""
            return w if share is None else share.spread(np.ascontiguousarray(w))

        def constrain(w, block, proj, target):
            if proj.G is not None:
                part = w[block]  # a view: projected in place
                proj.project(part, target(part))

        times, samples = [], []
        first, resumed_from = 1, None
        if resume is not None and has_checkpoint(resume):  # per rank: refused on another number of ranks
            ck = files.load(resume)
            if ck["x"].shape != (n,) or float(ck["dt"]) != dt:
                raise InputError(f"the checkpoint in {str(resume)!r} has {ck['x'].size} unknowns and dt = "
                                 f"{float(ck['dt']):.6g} s, this run {n} and {dt:.6g} s: resume the same run, or "
                                 "delete the folder to start afresh")
            resumed_from = int(ck["step"])
            if resumed_from > num_steps:
                raise InputError(f"the checkpoint is at step {resumed_from}, beyond num_steps = {num_steps}")
            x, rate, first = ck["x"].copy(), ck["rate"].copy(), resumed_from + 1
            times, samples = list(ck["times"]), list(ck["samples"])
        elif record is not None:
            times.append(0.0)
            samples.append(np.asarray(record(x, rate, 0.0)))

        def save(step):
            save_arrays(files.folder(checkpoint_dir), {"x": x, "rate": rate, "step": np.int64(step),
                                                       "dt": np.float64(dt), "times": np.asarray(times, float),
                                                       "samples": np.asarray(samples)}, comm=files.writer)

        acc = acceleration(x, (first - 1) * dt)
        for step in range(first, num_steps + 1):
            t = step * dt
            x_new = x.copy()
            x_new[su] += dt * rate[su] + 0.5 * dt * dt * acc[su]
            constrain(x_new, su, proj_u, lambda part: proj_u.displacement_target(part, t))
            rate[sp_] = storage_rate(x_new, x, t)
            x_new[sp_] += dt * rate[sp_]
            constrain(x_new, sp_, proj_p, lambda part: proj_p.displacement_target(part, t))
            finite = np.all(np.isfinite(x_new))
            if not (share.least(int(finite)) if share is not None else finite):
                raise InputError(f"step {step} (t = {t:.4g} s): the solution is no longer finite; "
                                 "the step is unstable, take a smaller dt")
            x_new = from_owners(x_new)
            acc_new = acceleration(x_new, t)
            rate[su] += 0.5 * dt * (acc[su] + acc_new[su])
            constrain(rate, su, proj_u, lambda part: proj_u.velocity_target(t, dt))
            rate = from_owners(rate)
            acc, x = acc_new, x_new
            if record is not None and step % record_every == 0:
                times.append(t)
                samples.append(np.asarray(record(x, rate, t)))
            if progress is not None:
                progress(step)
            if checkpoint_every and (step % checkpoint_every == 0 or step == num_steps):
                save(step)
        return ExplicitUPRun(x, rate, np.array(times), np.array(samples), num_steps, limits, resumed_from)
