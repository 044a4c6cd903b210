"""Strip load on a consolidating half-space: RKPM and FEM against the exact solution (seed 3.4.3).

Problem. A surface pressure q over a strip of width 2b on a drained, saturated elastic
half-space (plane strain, incompressible constituents). Half the domain is modelled, x in
[0, Lx], depth in [0, Ly] with Lx = Ly = 25 b (coordinates y = -depth, surface at y = 0):

    surface (y = 0)     traction (0, -q) for x <= b, free beyond; drained p = 0
    bottom (y = -Ly)    u = 0, no flow
    left (x = 0)        symmetry: u_x = 0, no flow
    right (x = Lx)      u_x = 0, no flow

Exact solution: ``verification.strip_load`` (Fourier transform in x, closed-form inversion in
time) for the half-space; the finite model's boundaries are 25 b away. Time is reported as
the seed's T_D = E k t / ((1 + nu) b^2), with k = k_h / gamma_f the mobility.

Seed set-up (Fig 3.10-3.13): q = 10 kPa, b = 0.2 m, E = 1e4 kPa, nu = 0, k_h = 5e-8 m/s,
gamma_f = 9.8 kN/m^3, 31 x 31 non-uniform nodes, Delta t_D = 0.025 (Delta t = 19.6 s). The node
lines here: uniform over the loaded strip (5 intervals on [0, b]), then geometric to 25 b;
in depth geometric from b/5 at the surface.

Studies:

* drained — pressure along the axis x = 0 at ``t_D_profile`` (Fig 3.11) and the history at
  depth ``depth_history`` on the axis (Fig 3.12) against the exact solution.
* undrained — low permeability (k_h = 5e-13 m/s, ``k_low``) with an impermeable surface
  (Fig 3.13): pressure and displacement fields after ``steps_low`` steps, NI against SCNI+FPP;
  reported is the spread of p between neighbouring nodes (checkerboard measure).

Parameters and units (``--set NAME=VALUE``): E [Pa], nu [-], k [m^2/(Pa s)], k_low
[m^2/(Pa s)], q [Pa], b [m], extent [-] (Lx = Ly = extent b), nx, ny, dt_D [-],
t_D_profile [-], t_D_end [-], depth_history [m], steps_low, variants (list), low_variants
(list), fem (list), support_factor [-], bc_method (transformation | nitsche), solver (auto | mumps
| fieldsplit, which needs bc_method=nitsche).

    python -m rkfx.cases.strip_load [--quick] [--method rkpm|fem|both] [--set NAME=VALUE] [--out DIR]
        [--checkpoint-every N] [--resume DIR] [--vtk]

With ``--vtk`` every run writes displacement, pressure, strain and effective stress to OUT/vtk/
(RKPM: particles and nodal cells; FEM: dolfinx VTK files): the drained runs at t_D_profile and
t_D_end, the low-permeability runs (``<run>-low-k``) after their last step.

With ``--checkpoint-every N`` every run (RKPM and FEM) writes its state every N steps (and at its end) to
OUT/checkpoints/; ``--resume DIR`` continues a killed invocation from DIR/checkpoints/, finished
runs returning their results at once.
"""
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from verification.strip_load import StripLoad

from rkfx.conditions import Displacement, Pressure, Traction, split
from rkfx.errors import InputError
from rkfx.geometry.particles import graded
from rkfx.models.poroelasticity import VARIANTS, PoroMaterial, solve_biot
from rkfx.solvers.integrate import time_grid
from rkfx.cases import _cli, _paraview, _preflight, _up_solver
from rkfx.cases._cli import Param, Results, Run
from rkfx.report.claims import Claim

NAME = "strip_load"
FEM_ELEMENTS = ("taylor-hood", "q1q1", "q1q1-fpp")
STRIP_INTERVALS = 5  # node intervals across the loaded half-width b

PARAMS = {
    "E": Param(1.0e7, "drained Young's modulus [Pa]"),
    "nu": Param(0.0, "drained Poisson's ratio [-]"),
    "k": Param(5.0e-8 / 9.8e3, "mobility k_h / gamma_f [m^2/(Pa s)] (seed: 5e-8 m/s / 9.8 kN/m^3)"),
    "k_low": Param(5.0e-13 / 9.8e3, "mobility of the low-permeability study [m^2/(Pa s)]"),
    "q": Param(1.0e4, "strip pressure [Pa]"),
    "b": Param(0.2, "half-width of the strip [m]"),
    "extent": Param(25.0, "model width and depth in units of b [-]"),
    "nx": Param(31, "nodes along x [count]"),
    "ny": Param(31, "nodes along the depth [count]"),
    "dt_D": Param(0.025, "time step in T_D = E k t / ((1 + nu) b^2) [-]"),
    "t_D_profile": Param(0.1, "time of the pressure profile along the axis [-]"),
    "t_D_end": Param(2.0, "end of the pressure history [-]"),
    "depth_history": Param(0.2, "depth of the history point on the axis [m], in [0, extent b]"),
    "steps_low": Param(4, "time steps of the low-permeability study [count]"),
    "variants": Param(["scni+fpp", "ni"], "RKPM variants of the drained study", fingerprint=False),
    "low_variants": Param(["ni", "scni+fpp"], "RKPM variants of the low-permeability study", fingerprint=False),
    "fem": Param(["taylor-hood", "q1q1-fpp"], "FEM elements: taylor-hood, q1q1, q1q1-fpp", fingerprint=False),
    "support_factor": Param(1.5, "RK support radius / nodal spacing [-], > 1"),
    **_up_solver.PARAMS,
}
QUICK = {"nx": 21, "ny": 21, "t_D_end": 0.5, "fem": ["taylor-hood"]}


def _node_line_sizes(b: float, length: float, n: int, first: float, uniform_to: float = 0.0,
                     name: str = "nx") -> tuple[int, int, float]:
    """Uniform intervals, graded intervals and graded span of ``node_lines``; InputError if ``n`` does not fit."""
    m = int(round(uniform_to / first)) if uniform_to > 0 else 0
    rest = n - 1 - m
    if rest < 1:
        raise InputError(f"{name} = {n}: {n} nodes cannot resolve the strip: need more than {m + 1}")
    span = length - m * first
    if rest * first >= span:
        raise InputError(f"{name} = {n}: {n} nodes over {length:g} m are too many for a first spacing of "
                         f"{first:g} m (b / {STRIP_INTERVALS}); use fewer than {int(span / first) + m + 1}")
    return m, rest, span


def node_lines(b: float, length: float, n: int, first: float, uniform_to: float = 0.0) -> np.ndarray:
    """n coordinates on [0, length]: uniform (spacing ``first``) up to ``uniform_to``, then geometric."""
    m, rest, span = _node_line_sizes(b, length, n, first, uniform_to)
    ratio = brentq(lambda r: first * (r**rest - 1) / (r - 1) - span, 1.0 + 1e-9, 10.0)
    steps = first * ratio ** np.arange(rest)
    return np.r_[first * np.arange(m + 1), m * first + np.cumsum(steps)]


def _check(nx, ny, dt_D, t_D_profile, t_D_end, extent, b, q, steps_low, variants, low_variants, fem,
           support_factor=1.5, depth_history=0.0, bc_method="transformation", solver="auto"):
    for name, v in (("b", b), ("extent", extent), ("dt_D", dt_D), ("t_D_profile", t_D_profile)):
        if not v > 0:
            raise InputError(f"{name} = {v!r} must be positive")
    if extent < 4:
        raise InputError(f"extent = {extent!r}: the model must reach well beyond the strip (>= 4 b)")
    if not t_D_end >= t_D_profile:
        raise InputError(f"t_D_end = {t_D_end!r} must be >= t_D_profile = {t_D_profile!r}")
    if q == 0:
        raise InputError("q = 0: no load")
    if steps_low < 1:
        raise InputError(f"steps_low = {steps_low!r} must be >= 1")
    _preflight.known(list(variants) + list(low_variants), VARIANTS, "RKPM variant")
    _preflight.known(fem, FEM_ELEMENTS, "FEM element")
    if nx < STRIP_INTERVALS + 3 or ny < 4:
        raise InputError(f"nx = {nx}, ny = {ny}: need nx >= {STRIP_INTERVALS + 3} and ny >= 4")
    _preflight.support_factor_ok(support_factor)
    _up_solver.check(bc_method, solver)
    first = b / STRIP_INTERVALS
    _node_line_sizes(b, extent * b, nx, first, uniform_to=b, name="nx")
    _node_line_sizes(b, extent * b, ny, first, name="ny")
    if not 0 <= depth_history <= extent * b:
        raise InputError(f"depth_history = {depth_history!r} m: use a depth in [0, extent b] = "
                         f"[0, {extent * b:g}] m")


def check(*, E, nu, k, k_low, q, b, extent, nx, ny, dt_D, t_D_profile, t_D_end, depth_history, steps_low,
          variants, low_variants, fem, support_factor, bc_method="transformation", solver="auto", **_) -> None:
    """Raise InputError for a parameter outside its documented range (the CLI calls this before any work)."""
    _check(nx, ny, dt_D, t_D_profile, t_D_end, extent, b, q, steps_low, variants, low_variants, fem,
           support_factor, depth_history, bc_method, solver)
    PoroMaterial(E, nu, k)
    try:
        PoroMaterial(E, nu, k_low)
    except InputError:
        raise InputError(f"k_low = {k_low!r} must be positive [m^2/(Pa s)]") from None


def memory_need(methods, *, nx, ny, **_) -> _preflight.Need:
    """Peak memory of the largest run, nx ny nodes (see ``rkfx.cases._preflight``)."""
    return _preflight.poro_need(methods, nx * ny, f"nx={nx}, ny={ny}", "lower nx or ny")


def _solve(method, xs, ys, material, q, b, times, outputs, samples, drained, support_factor, io, vtk=None,
           vtk_name="", vtk_times=None, up=None):
    """Pressure (k, m) and displacement (k, m, 2) at the samples, wall time, unknowns; with ``vtk``
    a folder, the fields at ``vtk_times`` [s] are written there as ``vtk_name``; ``up``: the RKPM
    solver options (``bc_method``, ``solver``)."""
    # Fixed bottom, rollers on the sides, the surface drained or not: for RKPM and FEM alike.
    held = [Displacement("bottom"), Displacement("left", components=(0,)), Displacement("right", components=(0,))]
    held += [Pressure("top")] if drained else []
    if method.startswith("rkpm-"):
        p = graded(xs, ys)
        load = Traction("top", lambda x, t, n: np.column_stack([0 * x[:, 0], -q * (x[:, 0] <= b + 1e-12 * b)]))
        kinds = split(held)
        sol = solve_biot(p, material, times, outputs, displacements=kinds[Displacement], pressures=kinds[Pressure],
                         tractions=[load], variant=method[5:], support_factor=support_factor,
                         comm=_cli.comm(), progress=lambda it: _cli.progress(it, method, len(times) - 1), **io,
                         **(up or {}))
        if vtk is not None:
            _paraview.write_biot(vtk, vtk_name, p, sol, material.elastic, _cli.comm(), vtk_times)
        return sol.pressure(samples), sol.displacement(samples), sol.wall_time_s, sol.n_dofs
    import dolfinx_solver  # noqa: F401, PLC0415

    from fem_baselines import poroelasticity as fb  # noqa: PLC0415

    element = method[4:]
    mesh = fb.rectangle_mesh(xs, ys, "triangle" if element == "taylor-hood" else "quadrilateral")
    tol = 1e-9 * (xs[-1] - xs[0])
    # The load on the strip's facets only: RKPM's step in x, interpolated, would load the next facet too.
    strip = lambda x: (np.abs(x[:, 1] - ys[-1]) <= tol) & (x[:, 0] <= b + tol)  # noqa: E731
    bcs = held + [Traction(strip, (0.0, -q))]
    series = _paraview.fem_series(vtk, vtk_name, mesh, vtk_times)
    res = fb.solve_biot(mesh, material.E, material.nu, material.k, material.alpha, material.S, element, bcs,
                        times, samples, outputs, vtk=series,
                        progress=lambda it: _cli.progress(it, method, len(times) - 1), **io)
    if series is not None:
        series.close()
    return res.p, res.u, res.wall_time_s, res.n_dofs


def run(*, methods: Sequence[str] = ("rkpm", "fem"), E=1.0e7, nu=0.0, k=5.0e-8 / 9.8e3, k_low=5.0e-13 / 9.8e3,
        q=1.0e4, b=0.2, extent=25.0, nx=31, ny=31, dt_D=0.025, t_D_profile=0.1, t_D_end=2.0, depth_history=0.2,
        steps_low=4, variants=("scni+fpp", "ni"), low_variants=("ni", "scni+fpp"), fem=("taylor-hood", "q1q1-fpp"),
        support_factor=1.5, bc_method="transformation", solver="auto", checkpoint_every=0, work_dir=None, resume=None,
        vtk=None) -> Results:
    """Both studies for every requested method; see the module docstring. ``vtk``: a folder for the
    ParaView files (``--vtk``)."""
    ck = _cli.Checkpoints(checkpoint_every, work_dir, resume)
    _check(nx, ny, dt_D, t_D_profile, t_D_end, extent, b, q, steps_low, variants, low_variants, fem,
           support_factor, depth_history, bc_method, solver)
    up = {"bc_method": bc_method, "solver": solver}
    length = extent * b
    first = b / STRIP_INTERVALS
    xs = node_lines(b, length, nx, first, uniform_to=b)
    depths = node_lines(b, length, ny, first)
    ys = -depths[::-1]
    exact = StripLoad(E, nu, k, b, q)
    to_t = exact.time  # T_D -> t
    dt = to_t(dt_D)
    t_prof, t_end = to_t(t_D_profile), to_t(t_D_end)
    times = time_grid([t_prof, t_end], dt)
    depth = np.linspace(0.0, min(10 * b, length), 201)
    axis = np.column_stack([np.zeros_like(depth), -depth])
    hist = np.array([[0.0, -depth_history]])
    samples = np.vstack([axis, hist])
    p_axis_exact = exact.pressure(np.zeros_like(depth), depth, t_prof)
    t_hist = times[1:]
    p_hist_exact = exact.pressure(np.zeros_like(t_hist), np.full_like(t_hist, depth_history), t_hist)
    params = dict(E=E, nu=nu, k=k, k_low=k_low, q=q, b=b, extent=extent, nx=nx, ny=ny, dt_D=dt_D,
                  t_D_profile=t_D_profile, t_D_end=t_D_end, depth_history=depth_history, steps_low=steps_low,
                  variants=list(variants), low_variants=list(low_variants), fem=list(fem),
                  support_factor=support_factor, bc_method=bc_method, solver=solver, dt=dt, steps=len(times) - 1)
    results = Results(NAME, params)
    material = PoroMaterial(E, nu, k)
    drained = ([f"rkpm-{v}" for v in variants] if "rkpm" in methods else []) + \
              ([f"fem-{e}" for e in fem] if "fem" in methods else [])
    i_prof = int(np.searchsorted(t_hist, t_prof))
    for label in drained:
        with _cli.model_run(label):
            p_h, _, wall, dofs = _solve(label, xs, ys, material, q, b, times, t_hist, samples, True, support_factor,
                                        ck.for_run(label), vtk, label, [t_prof, t_end], up)
        prof, histp = p_h[i_prof, :-1], p_h[:, -1]
        results.runs.append(Run(
            label, wall, dofs,
            series={"depth": depth, "p_axis": prof, "p_axis_exact": p_axis_exact,
                    "t_D": t_hist / to_t(1.0), "p_history": histp, "p_history_exact": p_hist_exact},
            errors={"l2_p_axis": float(np.linalg.norm(prof - p_axis_exact) / np.linalg.norm(p_axis_exact)),
                    "max_err_history": float(np.abs(histp - p_hist_exact).max() / q)},
            info={"study": "drained", "nodes": nx * ny}))
    # Low permeability, impermeable surface: the undrained regime (Fig 3.13).
    low = PoroMaterial(E, nu, k_low)
    t_low = dt * np.arange(steps_low + 1)
    gx, gy = np.meshgrid(xs[xs <= 6 * b + 1e-12], ys[ys >= -6 * b - 1e-12])
    field_pts = np.column_stack([gx.ravel(), gy.ravel()])
    low_methods = [f"rkpm-{v}" for v in low_variants] if "rkpm" in methods else []
    for label in low_methods:
        with _cli.model_run(f"{label} (low k)"):
            p_h, u_h, wall, dofs = _solve(label, xs, ys, low, q, b, t_low, t_low[-1:], field_pts, False,
                                          support_factor, ck.for_run(f"{label}-low-permeability"), vtk,
                                          f"{label}-low-k", t_low[-1:], up)
        pf = p_h[0].reshape(gx.shape)
        # Checkerboard measure: mean |second difference| of p between neighbouring nodes, over q.
        jump = (np.abs(np.diff(pf, 2, axis=0)).mean() + np.abs(np.diff(pf, 2, axis=1)).mean()) / (2 * q)
        results.runs.append(Run(f"{label} (low k)", wall, dofs,
                                series={"x": field_pts[:, 0], "y": field_pts[:, 1], "p": p_h[0], "u": u_h[0]},
                                errors={"p_second_difference": float(jump)},
                                info={"study": "undrained", "nodes": nx * ny}))
    return results


def plot(results: Results, out: Path) -> list[Path]:
    """Axis profile and history (Figs 3.11-3.12); low-permeability fields (Fig 3.13)."""
    import matplotlib.ticker  # noqa: PLC0415

    plt = _cli.pyplot()

    prm = results.params
    q, b = prm["q"], prm["b"]
    files = []
    drained = [r for r in results.runs if r.info["study"] == "drained"]
    markers = ["o", "s", "^", "D", "v"]
    if drained:
        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5.2))
        r0 = drained[0]
        d = np.asarray(r0.series["depth"])
        ax.plot(np.asarray(r0.series["p_axis_exact"]) / q, d / b, color="k", lw=2.5, alpha=0.4, label="exact")
        for j, r in enumerate(drained):
            ax.plot(np.asarray(r.series["p_axis"])[::6] / q, d[::6] / b, ls="none", marker=markers[j % 5],
                    mfc="none", label=f"{r.method} (L2 {r.errors['l2_p_axis']:.1%})")
        ax.invert_yaxis()
        ax.set_xlabel("p / q [-]")
        ax.set_ylabel("depth / b [-]")
        ax.set_title(f"pressure on the axis x = 0 at T_D = {prm['t_D_profile']:g}")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        ax2.semilogx(r0.series["t_D"], np.asarray(r0.series["p_history_exact"]) / q, color="k", lw=2.5, alpha=0.4,
                     label="exact")
        exact = np.asarray(r0.series["p_history_exact"]) / q
        lo, hi = min(exact.min(), 0.0), exact.max()
        window = (lo - 0.3 * (hi - lo), hi + 0.3 * (hi - lo))  # an unstable run must not hide the others
        for j, r in enumerate(drained):
            ph = np.asarray(r.series["p_history"]) / q
            outside = bool(np.any((ph < window[0]) | (ph > window[1])))
            ax2.semilogx(r.series["t_D"], ph, marker=markers[j % 5], ms=3, mfc="none", lw=0.8,
                         label=r.method + (f" (leaves the plot: {ph.min():.3g} to {ph.max():.3g})" if outside else ""))
        ax2.set_ylim(*window)
        ax2.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax2.set_xlabel("T_D = E k t / ((1 + nu) b^2) [-]")
        ax2.set_ylabel("p / q [-]")
        ax2.set_title(f"history at x = 0, depth {prm['depth_history']:g} m")
        ax2.legend(fontsize=8)
        ax2.grid(alpha=0.3, which="both")
        fig.suptitle(f"Strip load on a consolidating half-space, {prm['nx']} x {prm['ny']} graded nodes")
        fig.tight_layout()
        files.append(_cli.save(fig, out / "drained.png"))
    low = [r for r in results.runs if r.info["study"] == "undrained"]
    if low:
        fig, axes = plt.subplots(3, len(low), figsize=(4.6 * len(low) + 1.5, 12), squeeze=False,
                                 layout="constrained")
        fields = (("p / q", lambda r: np.asarray(r.series["p"]) / q),
                  ("u_x [mm]", lambda r: 1e3 * np.asarray(r.series["u"])[:, 0]),
                  ("u_y [mm]", lambda r: 1e3 * np.asarray(r.series["u"])[:, 1]))
        for i, (name, get) in enumerate(fields):
            vals = [get(r) for r in low]
            lo, hi = min(v.min() for v in vals), max(v.max() for v in vals)
            for j, (r, v) in enumerate(zip(low, vals)):
                ax = axes[i, j]
                tc = ax.tricontourf(np.asarray(r.series["x"]) / b, np.asarray(r.series["y"]) / b, v,
                                    levels=np.linspace(lo, hi, 21), cmap="coolwarm" if i == 0 else "viridis")
                ax.set_aspect("equal")
                ax.set_title(f"{r.method}: {name}", fontsize=10)
                ax.set_xlabel("x / b")
                ax.set_ylabel("y / b")
            fig.colorbar(tc, ax=list(axes[i]), shrink=0.85, label=name)
        fig.suptitle(f"Low permeability, impermeable surface: fields after {prm['steps_low']} steps")
        files.append(_cli.save(fig, out / "undrained_fields.png", dpi=110))
    return files


CLAIMS = [
    Claim("Fig 3.11: SCNI+FPP pressure on the axis at T_D = 0.1 within 5 % (relative L2) of the exact solution",
          run="rkpm-scni+fpp", info={"study": "drained"}, key="l2_p_axis", op="<", bound=0.05),
    Claim("Fig 3.12: SCNI+FPP pressure history at 0.2 m depth within 2 % of q of the exact solution",
          run="rkpm-scni+fpp", info={"study": "drained"}, key="max_err_history", op="<", bound=0.02),
    Claim("Fig 3.11: FEM Taylor-Hood pressure on the axis within 5 % (relative L2) of the exact solution",
          run="fem-taylor-hood", info={"study": "drained"}, key="l2_p_axis", op="<", bound=0.05),
    Claim("Fig 3.12: NI is less accurate than SCNI+FPP: its history error is more than 3x larger",
          run="rkpm-ni", info={"study": "drained"}, key="max_err_history", op=">", bound=3.0,
          over=("rkpm-scni+fpp", {"study": "drained"})),
    Claim("Fig 3.13: low permeability, NI's pressure oscillates: its checkerboard measure > 4x that of SCNI+FPP",
          run="rkpm-ni (low k)", key="p_second_difference", op=">", bound=4.0, over=("rkpm-scni+fpp (low k)", {})),
]


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point (see the module docstring)."""
    return _cli.main(NAME, __doc__, PARAMS, run, plot, argv, QUICK, checkpoints=True)


if __name__ == "__main__":
    sys.exit(main())
