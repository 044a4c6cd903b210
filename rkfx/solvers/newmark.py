"""Newmark for second-order fields with the generalized trapezoid for first-order ones.

For the model M x'' + C x' + r(x, t) = 0, G x = g(t) (``rkfx.solvers.model``), a step
n -> n+1 of size dt predicts, per unknown of a field of time order

* 2:  x~ = x_n + dt v_n + dt^2 (1/2 - beta) a_n,  v~ = v_n + dt (1 - gamma) a_n,
      a_{n+1} = (x_{n+1} - x~) / (beta dt^2),     v_{n+1} = v~ + gamma dt a_{n+1}
      (eqs. 5.18-5.20 with the seed's beta_1 = gamma and beta_2 = beta);
* 1:  x~ = x_n + dt (1 - theta) v_n,               v_{n+1} = (x_{n+1} - x~) / (theta dt)
      (eqs. 5.21-5.22);
* 0:  x_{n+1} free, no rates.

and solves M a_{n+1} + C v_{n+1} + r(x_{n+1}, t_{n+1}) = G^T mu with G x_{n+1} = g(t_{n+1})
by Newton on the corrector w = x_{n+1} - x~. The Jacobian is M/(beta dt^2) + C gamma/(beta dt)
+ K on second-order columns and C/(theta dt) + K on first-order ones.

A model whose capacity depends on its state (unsaturated storage 1/Q(p), the coupling
alpha S_w(p) div u') adds the term c(x, v) through ``rate_force(x, v)``, with its derivatives
``rate_tangents()`` = (dc/dx, dc/dv) at the last point; they enter the Jacobian as
dc/dx diag(dx) + dc/dv diag(dv). Such a model is not ``linear``, and its rate fields must be
implicit.

With beta = 0 or theta = 0 a field is explicit (eqs. 6.37-6.41, beta_2 = 0 and theta = 0):
x_{n+1} = x~ is known, and the unknown w is a_{n+1} (resp. v_{n+1}), so the step is one
linear solve with M + gamma dt C (resp. C), lumped or not. Essential conditions on an
explicit field are met by projecting x~ onto G x = g(t_{n+1}) (weighted by the lumped mass
or capacity) and imposing G v_{n+1} = g'(t_{n+1}).

Orders of accuracy (asserted in ``tests/test_steppers.py``): 2 for the trapezoidal rule
(beta = 1/4, gamma = 1/2), central differences (beta = 0, gamma = 1/2) and Crank-Nicolson
(theta = 1/2); 1 for backward Euler (theta = 1).
"""
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from rkfx.errors import InputError
from rkfx.linalg.linear_solver import Factorizations, linear_solver
from rkfx.parallel.unknowns import row_system
from rkfx.solvers.model import Constraints, Model, equation_weights, step_key
from rkfx.solvers.newton import NewtonOptions, NewtonResult, newton


@dataclass
class StepState:
    """The state at a step boundary.

    Attributes:
        step, t: Step index and time [s].
        x, v, a: Unknowns and their first and second time derivatives, shape ``(size,)``
            (v and a are zero where a field's order does not carry them).
        multipliers: Constraint forces G^T mu of the last step, shape ``(k,)``.
    """

    step: int
    t: float
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    multipliers: np.ndarray

    def arrays(self) -> dict[str, np.ndarray]:
        return {"step": np.int64(self.step), "t": np.float64(self.t), "x": self.x, "v": self.v, "a": self.a,
                "multipliers": self.multipliers}

    @classmethod
    def from_arrays(cls, z) -> "StepState":
        return cls(int(z["step"]), float(z["t"]), z["x"].copy(), z["v"].copy(), z["a"].copy(),
                   z["multipliers"].copy())


@dataclass(frozen=True)
class Coefficients:
    """How the state of step n+1 follows from the corrector w, per unknown.

    x = x~ + dx w, v = v~ + dv w, a = da w.

    Attributes:
        dt: Step size [s].
        dx, dv, da: Shape ``(size,)`` each.
        explicit: Unknowns whose x_{n+1} is the predictor (dx = 0).
    """

    dt: float
    dx: np.ndarray
    dv: np.ndarray
    da: np.ndarray

    @property
    def explicit(self) -> np.ndarray:
        return self.dx == 0.0


GUESSES = ("predictor", "previous")


@dataclass(frozen=True)
class Newmark:
    """The Newmark/trapezoid family (see the module docstring).

    Attributes:
        beta, gamma: Newmark parameters of second-order fields (the seed's beta_2, beta_1);
            beta = 0 is explicit (central differences with gamma = 1/2).
        theta: Trapezoid parameter of first-order fields; 1 backward Euler, 1/2
            Crank-Nicolson, 0 explicit.
        newton: Newton's settings.
        rtol, atol: Newton converges when ||F||_inf <= atol + rtol max(||F_0||_inf, s) on
            the equations, s the largest of ||r||, ||M a||, ||C v|| at the iterate, after at
            least ``min_iterations``.
        ctol: ... and ||G x - g||_inf <= ctol (1 + ||g||_inf) on the constraints.
        min_iterations: Newton iterations before the test is taken (1: never accept the
            predictor untried).
        guess: Where Newton starts: ``predictor`` (x~, the Newmark predictor) or ``previous``
            (x_n, the last step's unknowns; explicit fields keep their predictor). The step's
            solution is the same; the start is not. With steps far above a model's stiff
            periods (a loading that is quasi-static on the elastic time scale) the trapezoidal
            rule damps nothing, its velocities and accelerations alternate from step to step,
            and x~ = x_n + dt v_n + dt^2 a_n / 4 lands ever farther from x_(n+1) (a damage model
            then iterates through strains far past its thresholds); x_n does not.
    """

    beta: float = 0.25
    gamma: float = 0.5
    theta: float = 0.5
    newton: NewtonOptions = field(default_factory=NewtonOptions)
    rtol: float = 1e-10
    atol: float = 0.0
    ctol: float = 1e-10
    min_iterations: int = 1
    guess: str = "predictor"

    def __post_init__(self):
        if self.guess not in GUESSES:
            raise InputError(f"Newton's start guess = {self.guess!r}; choose one of {', '.join(GUESSES)}")
        if not 0.0 <= self.beta <= 0.5:
            raise InputError(f"Newmark beta = {self.beta!r} must lie in [0, 1/2] (1/4: trapezoidal rule)")
        if not 0.5 <= self.gamma <= 1.0:
            raise InputError(f"Newmark gamma = {self.gamma!r} must lie in [1/2, 1] (1/2: second order)")
        if not 0.0 <= self.theta <= 1.0:
            raise InputError(f"theta = {self.theta!r} must lie in [0, 1] (1: backward Euler, 1/2: Crank-Nicolson)")

    # ------------------------------------------------------------------ set-up

    def coefficients(self, orders: np.ndarray, dt: float) -> Coefficients:
        """dx, dv, da of every unknown for a step of size dt."""
        o2, o1, o0 = orders == 2, orders == 1, orders == 0
        dx, dv, da = np.zeros(len(orders)), np.zeros(len(orders)), np.zeros(len(orders))
        if self.beta > 0:
            dx[o2], dv[o2], da[o2] = 1.0, self.gamma / (self.beta * dt), 1.0 / (self.beta * dt * dt)
        else:
            dv[o2], da[o2] = self.gamma * dt, 1.0
        if self.theta > 0:
            dx[o1], dv[o1] = 1.0, 1.0 / (self.theta * dt)
        else:
            dv[o1] = 1.0
        dx[o0] = 1.0
        return Coefficients(dt, dx, dv, da)

    def predict(self, orders: np.ndarray, s: StepState, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Predictors x~ and v~ of the step from ``s``."""
        o2, o1 = orders == 2, orders == 1
        x, v = s.x.copy(), np.zeros_like(s.v)
        x[o2] += dt * s.v[o2] + dt * dt * (0.5 - self.beta) * s.a[o2]
        v[o2] = s.v[o2] + dt * (1.0 - self.gamma) * s.a[o2]
        x[o1] += dt * (1.0 - self.theta) * s.v[o1]
        return x, v

    def start(self, model: Model, x0: np.ndarray | None = None, v0: np.ndarray | None = None,
              a0: np.ndarray | None = None, t0: float = 0.0, comm=None) -> StepState:
        """The state at t0. Rates default to zero, except that a0 of second-order fields
        follows from M a0 = -(C v0 + r(x0, t0)) when the model has a mass (solved on comm)."""
        n = model.layout.size
        x = np.zeros(n) if x0 is None else np.array(x0, float).reshape(n)
        v = np.zeros(n) if v0 is None else np.array(v0, float).reshape(n)
        orders = model.layout.orders
        if a0 is not None:
            a = np.array(a0, float).reshape(n)
        else:
            a = np.zeros(n)
            m = model.mass()
            o2 = np.flatnonzero(orders == 2)
            share = getattr(model, "share", None)
            if m is not None and (o2.size if share is None else share.total(o2.size)):
                rhs = -model.residual(x, t0)
                c = model.capacity(1.0)
                if c is not None:
                    rhs -= c @ v
                mm = sp.csr_matrix(m)[o2][:, o2]
                diagonal = mm.nnz == mm.shape[0] and np.all(mm.diagonal() != 0)
                if share is not None:  # contributions: a diagonal mass is summed entry by entry
                    if share.least(diagonal) == 0:
                        raise InputError("the initial acceleration of a model distributed over MPI ranks needs a "
                                         "lumped (diagonal) mass; lump it, or pass a0")
                    rhs, diag = share.assemble(rhs), share.assemble(sp.csr_matrix(m).diagonal())
                    a[o2] = rhs[o2] / diag[o2]
                elif diagonal:
                    a[o2] = rhs[o2] / mm.diagonal()
                else:
                    ls = linear_solver(mm, comm)
                    a[o2] = ls.solve(rhs[o2])
                    ls.destroy()
        k = model.constraints(t0).count
        return StepState(0, float(t0), x, v, a, np.zeros(k))

    # ------------------------------------------------------------------ one step

    def advance(self, model: Model, s: StepState, dt: float, solves: Factorizations) \
            -> tuple[StepState | None, NewtonResult]:
        """Step ``s`` by dt; ``(None, result)`` when Newton fails (the caller cuts dt).

        Trial history is evaluated in the model; the caller commits it once it accepts the
        step (``rkfx.solvers.integrate``).
        """
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"time step dt = {dt!r} must be positive")
        orders = model.layout.orders
        t1 = s.t + dt
        start = getattr(model, "start_step", None)
        if start is not None:  # optional: a model whose update depends on the step (rkfx.solvers.model)
            start(s.t, dt)
        x_t, v_t = self.predict(orders, s, dt)
        con = model.constraints(t1)
        key = ("newmark-plan", id(model))
        plan = solves.memo.get(key)
        if plan is None:
            plan = solves.memo[key] = _Plan(self, model, dt, con.G)
        co = self.coefficients(orders, dt)
        system = _NewmarkSystem(self, model, plan, co, x_t, v_t, con, t1, s.t)
        w0 = np.zeros(len(x_t))
        if self.guess == "previous":  # x = x~ + dx w: start at x_n where w moves x (dx = 1)
            moved = co.dx == 1.0
            w0[moved] = s.x[moved] - x_t[moved]
        z0 = np.r_[w0, s.multipliers if len(s.multipliers) == con.count else np.zeros(con.count)]
        res = newton(system, z0, solves, self.newton)
        if not res.converged:
            return None, res
        x, v, a = system.state(res.z)
        return StepState(s.step + 1, t1, x, v, a, res.z[len(x_t):]), res


class _Plan:
    """What the steps of one run share: the constraint rows (fixed in time), which of them
    act on explicit unknowns, and the projection weights."""

    def __init__(self, stepper: "Newmark", model: Model, dt: float, G: sp.spmatrix):
        co = stepper.coefficients(model.layout.orders, dt)
        self.G = sp.csr_matrix(G)
        self.GT = self.G.T.tocsr()
        self.explicit = explicit = co.explicit  # the same for every dt
        self.linear = bool(model.linear or explicit.all())
        # Rows of G on explicit unknowns constrain the rate; the others the value.
        self.on_explicit = (abs(self.G) @ explicit.astype(float)) > 0
        on_implicit = (abs(self.G) @ (~explicit).astype(float)) > 0
        if np.any(self.on_explicit & on_implicit):
            raise InputError("an essential condition couples explicit and implicit unknowns; "
                             "constrain each field on its own rows")
        self.any_explicit = bool(self.on_explicit.any())
        self.share = share = getattr(model, "share", None)
        if explicit.any() and hasattr(model, "rate_force"):
            raise InputError("a model with a state-dependent capacity (rate_force) needs implicit rate fields; "
                             "take theta > 0 and beta > 0")
        if share is not None and share.total(self.any_explicit):
            raise InputError("explicit fields (beta = 0 or theta = 0) of a model distributed over MPI ranks are not "
                             "supported; run it on one rank, or take an implicit stepper")
        self.projection = None
        if self.any_explicit:
            weight = _lumped(model.mass(), model.capacity(dt), model.layout.orders, explicit)
            self.projection = _Projection(self.G[self.on_explicit], weight)

    def scaled_rows(self, co: Coefficients) -> sp.csr_matrix:
        """G diag(dx) on value rows, G diag(dv) on rate rows."""
        if not self.any_explicit:
            return self.G  # dx = 1 on every implicit unknown
        return (self.G @ sp.diags(np.where(self.explicit, co.dv, co.dx))).tocsr()


def _lumped(M, C, orders: np.ndarray, explicit: np.ndarray) -> np.ndarray:
    """Diagonal weights of the projection of explicit predictors: lumped mass or capacity."""
    d = np.ones(len(orders))
    for mat, order in ((M, 2), (C, 1)):
        if mat is not None:
            diag = sp.csr_matrix(mat).diagonal()
            sel = explicit & (orders == order) & (diag > 0)
            d[sel] = diag[sel]
    return d


class _NewmarkSystem:
    """F(w, mu) = [W (M a + C v + r(x, t) - G^T mu), c(w)] of one step."""

    def __init__(self, stepper: "Newmark", model: Model, plan: _Plan, co: Coefficients, x_t, v_t,
                 con: Constraints, t1: float, t0: float):
        self.stepper, self.model, self.plan, self.co, self.t1 = stepper, model, plan, co, t1
        self.n = len(x_t)
        # On MPI ranks (``rkfx.parallel.unknowns``): the model's vectors and matrices are this
        # rank's contributions over its local unknowns, the constraint rows its own.
        self.share = plan.share
        self.M, self.C = model.mass(), model.capacity(co.dt)
        self.G, self.Gw = plan.G, plan.scaled_rows(co)
        self.W = equation_weights(model, co)
        self.cw = _constraint_weights(self.G, self.Gw, self.W)
        self.rated = hasattr(model, "rate_force")
        self.linear = plan.linear
        on_explicit = plan.on_explicit
        if on_explicit.any():
            x_t = plan.projection.project(x_t, con.g[on_explicit])
            # dg/dt at t1: the model's, or the difference over the step.
            rate = con.rate if con.rate is not None else (con.g - model.constraints(t0).g) / (t1 - t0)
        self.x_t, self.v_t = x_t, v_t
        self.c0 = self.G @ x_t - con.g
        if on_explicit.any():
            self.c0[on_explicit] = (self.G @ v_t)[on_explicit] - np.asarray(rate, float)[on_explicit]
        self.gscale = 1.0 + self.norm(con.g)
        self.r0 = None

    def norm(self, r: np.ndarray) -> float:
        """max |r| over all entries (and ranks)."""
        local = float(np.abs(r).max()) if r.size else 0.0
        return local if self.share is None else self.share.max(local)

    def state(self, z):
        w = z[:self.n]
        co = self.co
        return self.x_t + co.dx * w, self.v_t + co.dv * w, co.da * w

    def residual(self, z):
        x, v, a = self.state(z)
        terms = [self.model.residual(x, self.t1)]
        terms += [mat @ rate for mat, rate in ((self.M, a), (self.C, v)) if mat is not None]
        if self.rated:
            terms.append(self.model.rate_force(x, v))
        mu = z[self.n:]
        if self.share is not None:
            # The whole model's terms at every local entry (one exchange for all of them).
            terms.append(self.plan.GT @ mu)
            terms = list(self.share.assemble(np.stack(terms, axis=1)).T)
            r = sum(terms[1:-1], terms[0]) - terms[-1]
            terms = terms[:-1]
        else:
            r = sum(terms[1:], terms[0])
            if mu.size:
                r = r - self.plan.GT @ mu
        self.scale = max(self.norm(t) for t in terms)
        if self.W is not None:
            r = self.W * r
        c = self.c0 + self.Gw @ z[:self.n]
        return np.r_[r, c if self.cw is None else self.cw * c]

    def jacobian(self, z):
        co = self.co
        x, _, _ = self.state(z)
        j = None
        d_x, d_v = self.model.rate_tangents() if self.rated else (None, None)
        for mat, scale in ((self.model.tangent(x, self.t1) if (co.dx != 0).any() else None, co.dx),
                           (self.M, co.da), (self.C, co.dv), (d_x, co.dx), (d_v, co.dv)):
            if mat is None or not scale.any():
                continue
            term = _scale_columns(sp.csr_matrix(mat), scale)
            j = term if j is None else j + term
        gt = -self.plan.GT
        if self.W is not None:
            j, gt = _scale_rows(j, self.W), _scale_rows(gt, self.W)
        k = self.G.shape[0]
        if k == 0:
            j = j.tocsr()
        else:  # all blocks CSR: scipy stacks them without converting to COO
            gw = self.Gw if self.cw is None else _scale_rows(self.Gw, self.cw)
            j = sp.bmat([[sp.csr_matrix(j), sp.csr_matrix(gt)], [sp.csr_matrix(gw), sp.csr_matrix((k, k))]],
                        format="csr")
        return j if self.share is None else row_system(j, self.share, k, self.share.comm)

    def jacobian_key(self):
        return ("newmark", step_key(self.co.dt)) if self.model.linear else None

    def converged(self, z, r, iteration):
        st = self.stepper
        eq, con = r[:self.n], r[self.n:] if self.cw is None else r[self.n:] / self.cw
        if self.r0 is None:  # the start: the predictor's residual
            self.r0 = self.norm(eq)
        if iteration < st.min_iterations:
            return False
        # Relative to the start and to the size of the terms at this iterate, so that
        # round-off in large cancelling forces does not stall a converged solve.
        ok_eq = self.norm(eq) <= st.atol + st.rtol * max(self.r0, self.scale)
        ok_con = self.norm(con) <= st.ctol * self.gscale
        return bool(ok_eq and ok_con)


def _constraint_weights(G: sp.csr_matrix, Gw: sp.csr_matrix, W: np.ndarray | None) -> np.ndarray | None:
    """Weights s_k of the constraint rows that make the step Jacobian symmetric when the model
    weights its equations for that (``W``): s_k Gw_kj = -W_j G_kj over row k, so that the
    constraint rows are the transpose of the -W G^T columns. A row whose entries ask for
    different s_k keeps 1 (that Jacobian is not symmetric). ``None`` without ``W``."""
    k = G.shape[0]
    if W is None or k == 0:
        return None
    g, gw = sp.csr_matrix(G), sp.csr_matrix(Gw)
    s = np.ones(k)
    if not (np.array_equal(g.indptr, gw.indptr) and np.array_equal(g.indices, gw.indices)):
        return s
    nonzero = gw.data != 0
    ratio = np.where(nonzero, -W[g.indices] * g.data / np.where(nonzero, gw.data, 1.0), np.nan)
    filled = np.flatnonzero(np.diff(g.indptr) > 0)
    if filled.size == 0:
        return s
    starts = g.indptr[filled]
    lo = np.fmin.reduceat(ratio, starts)
    hi = np.fmax.reduceat(ratio, starts)
    uniform = np.isfinite(lo) & (hi - lo <= 1e-12 * np.abs(hi)) & (lo != 0)
    s[filled[uniform]] = lo[uniform]
    return s


def _scale_columns(a: sp.csr_matrix, scale: np.ndarray) -> sp.csr_matrix:
    """a diag(scale), as a copy (a scalar multiple when the scale is uniform)."""
    if np.all(scale == scale[0]):
        return a * scale[0] if scale[0] != 1.0 else a
    return a @ sp.diags(scale)


def _scale_rows(a: sp.spmatrix, scale: np.ndarray) -> sp.csr_matrix:
    """diag(scale) a, as a copy."""
    a = sp.csr_matrix(a, copy=True)
    a.data *= np.repeat(scale, np.diff(a.indptr))
    return a


class _Projection:
    """x + W^-1 G^T lambda with G (x + ...) = g: the weighted projection onto the constraints,
    G W^-1 G^T factorized once (a small system, on every rank)."""

    def __init__(self, G: sp.csr_matrix, weight: np.ndarray):
        self.G = G
        self.winv_gt = (sp.diags(1.0 / weight) @ G.T).tocsr()
        self.solver = linear_solver(G @ self.winv_gt, solver="serial")

    def project(self, x: np.ndarray, g: np.ndarray) -> np.ndarray:
        return x + self.winv_gt @ np.atleast_1d(self.solver.solve(g - self.G @ x))


def theta_method(theta: float, **options) -> Newmark:
    """The theta-method for first-order models: 1 backward Euler, 1/2 Crank-Nicolson."""
    return Newmark(theta=theta, **options)


def backward_euler(**options) -> Newmark:
    return theta_method(1.0, **options)


def crank_nicolson(**options) -> Newmark:
    return theta_method(0.5, **options)


def trapezoidal(**options) -> Newmark:
    """Newmark beta = 1/4, gamma = 1/2 with theta = 1/2: the seed's choice (5.18-5.22)."""
    return Newmark(beta=0.25, gamma=0.5, theta=0.5, **options)


GAMMA_MAX = 2.0**0.5 - 0.5  # beta = (gamma + 1/2)^2 / 4 reaches 1/2


def damped(gamma: float = 0.6, theta: float = 0.6, **options) -> Newmark:
    """The Newmark family with numerical damping: gamma > 1/2 with beta = (gamma + 1/2)^2 / 4 for
    second-order fields (the high frequencies damped, unconditionally stable), theta > 1/2 for
    first-order ones; first order in time. For loadings that are quasi-static on the elastic
    time scale, taken with steps far above the stiff periods: the trapezoidal rule keeps those
    modes' oscillation undamped from step to step, this does not."""
    if not 0.5 < gamma <= GAMMA_MAX:
        raise InputError(f"gamma = {gamma!r} must lie in (1/2, {GAMMA_MAX:.3f}] (0.6: mild damping; above, beta "
                         "exceeds 1/2); 1/2 is the trapezoidal rule")
    if not 0.5 < theta <= 1.0:
        raise InputError(f"theta = {theta!r} must lie in (1/2, 1] (0.6: mild damping); 1/2 is Crank-Nicolson")
    return Newmark(beta=(gamma + 0.5) ** 2 / 4.0, gamma=gamma, theta=theta, **options)


def explicit(**options) -> Newmark:
    """beta = 0, gamma = 1/2, theta = 0: the explicit u-p scheme of eqs. (6.37)-(6.41)."""
    return Newmark(beta=0.0, gamma=0.5, theta=0.0, **options)
