"""Mandel's problem: RKPM u-p variants and dolfinx FEM against the exact solution (seed 3.4.2).

Problem. A poroelastic slab 2Lx x 2Ly squeezed by rigid, frictionless, impermeable plates that
carry a total force 2F per unit thickness; the lateral sides x = +-Lx are drained and free.
One quarter is modelled, [0, Lx] x [0, Ly]:

    left   (x = 0)    symmetry: u_x = 0, no flow
    bottom (y = 0)    symmetry: u_y = 0, no flow
    top    (y = Ly)   rigid plate: u_y = exact plate displacement (uniform), no flow
    right  (x = Lx)   drained (p = 0), traction free

Loading at t = 0+ gives a uniform undrained pressure p0+; near the centre the pressure then
first rises above p0+ (the Mandel-Cryer effect) before it dissipates. Exact solution:
Abousleiman et al. (1996), ``verification.mandel``, for any nu, alpha and storage S.

Seed set-up (Fig 3.7-3.9): Lx = 20, Ly = 2, 101 x 11 nodes, E = 1e4, nu = 0, k = 1e-4,
incompressible constituents (alpha = 1, S = 0), F = 2 Lx: consolidation coefficient c = 1 and
p0+ = 1. Time is reported as T_D = c t / Lx^2 and steps as Delta t_D = c Delta t / h^2 with
h = Lx / (nx - 1).

Two studies, both written to results.json and plotted:

* profiles — p along y = 0 at the output times ``t_D``; steps start at ``dt_D`` and grow by
  ``growth`` every 10 steps (each output time is hit exactly). Relative L2 error of p along
  y = 0 per output time, and p(0, t) against time for the Mandel-Cryer effect.
* early — the seed's Fig 3.8: 20 steps of Delta t_D = 0.01 and 0.1, and 2 of 1.0, for every
  RKPM variant and FEM element. Overshoot = max p^h - max p (both over y = 0) in units of p0+.

Methods: RKPM variants ``ni``, ``scni``, ``ni+fpp``, ``scni+fpp`` (``rkfx.models.poroelasticity``;
"scni" is SCNI with the MSCNI subcells, eps_p = 1); FEM ``taylor-hood`` (P2-P1 triangles on
the same vertices), ``q1q1`` and ``q1q1-fpp`` (bilinear quadrilaterals on the same vertices,
unstabilized and with the pressure projection) from ``fem_baselines.poroelasticity``.

Parameters and units (``--set NAME=VALUE``): E [Pa], nu [-], k [m^2/(Pa s)], alpha [-],
S [1/Pa], Lx [m], Ly [m], F [N/m], nx, ny, dt_D [-], growth [-], t_D (list), variants (list),
early_variants (list), fem (list), support_factor [-], bc_method (transformation | nitsche),
solver (auto | mumps | fieldsplit: GMRES with a Schur split, for large grids, with bc_method=nitsche).

    python -m rkfx.cases.mandel [--quick] [--method rkpm|fem|both] [--set NAME=VALUE] [--out DIR]
        [--checkpoint-every N] [--resume DIR] [--vtk]

With ``--vtk`` the runs of the profiles study write displacement, pressure, strain and effective
stress at the times ``t_D`` to OUT/vtk/ (RKPM: particles and nodal cells; FEM: dolfinx VTK files).

With ``--checkpoint-every N`` every run (RKPM and FEM) writes its state every N steps (and at its end) to
OUT/checkpoints/; ``--resume DIR`` continues a killed invocation from DIR/checkpoints/, finished
runs returning their results at once.
"""
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from verification.mandel import Mandel

from rkfx.conditions import Displacement, Pressure, split
from rkfx.errors import InputError
from rkfx.geometry.particles import structured
from rkfx.models.poroelasticity import VARIANTS, PoroMaterial, solve_biot
from rkfx.solvers.integrate import time_grid
from rkfx.cases import _cli, _paraview, _preflight, _up_solver
from rkfx.cases._cli import Param, Results, Run
from rkfx.report.claims import Claim

NAME = "mandel"
FEM_ELEMENTS = ("taylor-hood", "q1q1", "q1q1-fpp")
EARLY = ((0.01, 20), (0.1, 20), (1.0, 2))  # (Delta t_D, steps) of the seed's Fig 3.8
HOLD = 10  # steps per growth stage: the factorization is reused within a stage
NUM_SAMPLES = 401  # points along y = 0

PARAMS = {
    "E": Param(1.0e4, "drained Young's modulus [Pa]"),
    "nu": Param(0.0, "drained Poisson's ratio [-]"),
    "k": Param(1.0e-4, "mobility k_h / gamma_f [m^2/(Pa s)]"),
    "alpha": Param(1.0, "Biot coefficient [-]"),
    "S": Param(0.0, "storage coefficient 1/Q [1/Pa] (0: incompressible constituents)"),
    "Lx": Param(20.0, "half-width of the slab [m]"),
    "Ly": Param(2.0, "half-height of the slab [m]"),
    "F": Param(40.0, "force on the quarter model's top plate per unit thickness [N/m] (seed: 2 Lx)"),
    "nx": Param(101, "nodes along x [count]"),
    "ny": Param(11, "nodes along y [count]"),
    "dt_D": Param(0.01, "first time step c dt / h^2 of the profiles study [-]"),
    "growth": Param(1.6, "step growth factor every 10 steps in the profiles study [-]"),
    "t_D": Param([0.01, 0.1, 0.5, 1.0], "output times c t / Lx^2 [-]"),
    "variants": Param(["scni+fpp", "ni"], "RKPM variants of the profiles study", fingerprint=False),
    "early_variants": Param(list(VARIANTS), "RKPM variants of the early-time study", fingerprint=False),
    "fem": Param(list(FEM_ELEMENTS), "FEM elements: taylor-hood, q1q1, q1q1-fpp", fingerprint=False),
    "support_factor": Param(1.5, "RK support radius / nodal spacing [-], > 1"),
    **_up_solver.PARAMS,
}
QUICK = {"nx": 41, "ny": 5, "t_D": [0.01, 0.1], "early_variants": ["ni", "scni+fpp"],
         "fem": ["taylor-hood", "q1q1-fpp"]}


def _check(nx, ny, dt_D, growth, t_D, variants, early_variants, fem, Lx, Ly, F, support_factor=1.5,
           bc_method="transformation", solver="auto"):
    for name, v in (("nx", nx), ("ny", ny)):
        if v < 3:
            raise InputError(f"{name} = {v}: need at least 3 nodes per direction")
    for name, v in (("Lx", Lx), ("Ly", Ly), ("dt_D", dt_D)):
        if not v > 0:
            raise InputError(f"{name} = {v!r} must be positive")
    if not growth >= 1.0:
        raise InputError(f"growth = {growth!r} must be >= 1")
    if not t_D or min(t_D) <= 0:
        raise InputError(f"t_D = {t_D!r}: output times must be positive")
    _preflight.known(list(variants) + list(early_variants), VARIANTS, "RKPM variant")
    _preflight.known(fem, FEM_ELEMENTS, "FEM element")
    if F == 0:
        raise InputError("F = 0: the problem has no load")
    _preflight.support_factor_ok(support_factor)
    _up_solver.check(bc_method, solver)


def check(*, E, nu, k, alpha, S, Lx, Ly, F, nx, ny, dt_D, growth, t_D, variants, early_variants, fem,
          support_factor, bc_method="transformation", solver="auto", **_) -> None:
    """Raise InputError for a parameter outside its documented range (the CLI calls this before any work)."""
    _check(nx, ny, dt_D, growth, t_D, variants, early_variants, fem, Lx, Ly, F, support_factor, bc_method, solver)
    PoroMaterial(E, nu, k, alpha, S)
    exact = Mandel(E, nu, k, Lx, Ly, F, alpha, S)
    first = dt_D * (Lx / (nx - 1)) ** 2 / exact.c  # the first step is the earliest time evaluated
    try:
        exact.n_roots(np.array([first, min(t_D) * Lx**2 / exact.c]))
    except ValueError as err:  # the exact series cannot reach so early a time
        raise InputError(f"dt_D = {dt_D!r}, nx = {nx}: the first step is too short for the exact solution ({err}); "
                         "raise dt_D or t_D, or lower nx") from None


def memory_need(methods, *, nx, ny, **_) -> _preflight.Need:
    """Peak memory of the largest run, nx ny nodes (see ``rkfx.cases._preflight``)."""
    return _preflight.poro_need(methods, nx * ny, f"nx={nx}, ny={ny}", "lower nx or ny")


def _conditions(exact):
    """The quarter model's boundary conditions, the same for RKPM and FEM: symmetry rollers left and
    bottom, the rigid plate's displacement on top, drained right side."""
    return [Displacement("left", components=(0,)), Displacement("bottom", components=(1,)),
            Displacement("top", lambda x, t: np.full(len(x), exact.plate_displacement(t)), (1,)),
            Pressure("right")]


def _rkpm(p, material, bcs, times, outputs, variant, support_factor, desc, io, vtk=None, vtk_times=None,
          bc_method="transformation", solver="auto"):
    """One RKPM run; with ``vtk`` a folder, its fields at ``vtk_times`` [s] are written there."""
    kinds = split(bcs)
    sol = solve_biot(p, material, times, outputs, kinds[Displacement], kinds[Pressure], variant=variant,
                     support_factor=support_factor, comm=_cli.comm(), bc_method=bc_method, solver=solver,
                     progress=lambda it: _cli.progress(it, desc, len(times) - 1), **io)
    if vtk is not None:
        _paraview.write_biot(vtk, f"rkpm-{variant}", p, sol, material.elastic, _cli.comm(), vtk_times)
    return sol, sol.pressure, sol.wall_time_s, sol.n_dofs


def _fem(xs, ys, material, bcs, times, outputs, element, samples, io, vtk=None, vtk_times=None):
    import dolfinx_solver  # noqa: F401, PLC0415

    from fem_baselines import poroelasticity as fb  # noqa: PLC0415

    mesh = fb.rectangle_mesh(xs, ys, "triangle" if element == "taylor-hood" else "quadrilateral")
    series = _paraview.fem_series(vtk, f"fem-{element}", mesh, vtk_times)
    res = fb.solve_biot(mesh, material.E, material.nu, material.k, material.alpha, material.S, element, bcs,
                        times, samples, outputs, vtk=series,
                        progress=lambda it: _cli.progress(it, f"fem-{element}", len(times) - 1), **io)
    if series is not None:
        series.close()
    return res.p, res.wall_time_s, res.n_dofs


def run(*, methods: Sequence[str] = ("rkpm", "fem"), E=1.0e4, nu=0.0, k=1.0e-4, alpha=1.0, S=0.0, Lx=20.0,
        Ly=2.0, F=40.0, nx=101, ny=11, dt_D=0.01, growth=1.6, t_D=(0.01, 0.1, 0.5, 1.0),
        variants=("scni+fpp", "ni"), early_variants=VARIANTS, fem=FEM_ELEMENTS, support_factor=1.5,
        bc_method="transformation", solver="auto", checkpoint_every=0, work_dir=None, resume=None,
        vtk=None) -> Results:
    """Both studies for every requested method; see the module docstring. ``vtk``: a folder for the
    ParaView files of the profiles study's runs at the times ``t_D`` (``--vtk``)."""
    _check(nx, ny, dt_D, growth, t_D, variants, early_variants, fem, Lx, Ly, F, support_factor, bc_method, solver)
    material = PoroMaterial(E, nu, k, alpha, S)
    exact = Mandel(E, nu, k, Lx, Ly, F, alpha, S)
    c, p0 = exact.c, exact.p0
    h = Lx / (nx - 1)
    xs, ys = np.linspace(0.0, Lx, nx), np.linspace(0.0, Ly, ny)
    particles = structured(Lx, Ly, nx, ny)
    x = np.linspace(0.0, Lx, NUM_SAMPLES)
    samples = np.column_stack([x, np.zeros_like(x)])
    t_out = np.sort(np.asarray(t_D, float)) * Lx**2 / c
    times = time_grid(t_out, dt_D * h**2 / c, growth, hold=HOLD)
    p_exact = np.array([exact.pressure(x, t) for t in t_out])
    history_exact = exact.pressure(np.zeros(len(times) - 1), times[1:])
    params = dict(E=E, nu=nu, k=k, alpha=alpha, S=S, Lx=Lx, Ly=Ly, F=F, nx=nx, ny=ny, dt_D=dt_D, growth=growth,
                  t_D=list(t_D), variants=list(variants), early_variants=list(early_variants), fem=list(fem),
                  support_factor=support_factor, bc_method=bc_method, solver=solver, c=c, p0=p0, h=h,
                  steps=len(times) - 1)
    results = Results(NAME, params)
    ck = _cli.Checkpoints(checkpoint_every, work_dir, resume)
    bcs = _conditions(exact)
    solvers = []
    if "rkpm" in methods:
        for v in dict.fromkeys(list(variants) + list(early_variants)):
            solvers.append((f"rkpm-{v}", v in variants, v in early_variants,
                            lambda tt, out, key, shown=None, v=v: _rkpm(particles, material, bcs, tt, out, v,
                                                                        support_factor, f"rkpm {v}", ck.for_run(key),
                                                                        shown, t_out, bc_method, solver)))
    if "fem" in methods:
        for e in fem:
            def fem_solve(tt, out, key, shown=None, e=e):
                pp, wall, dofs = _fem(xs, ys, material, bcs, tt, out, e, samples, ck.for_run(key), shown, t_out)
                return None, (lambda pts, pp=pp: pp), wall, dofs
            solvers.append((f"fem-{e}", True, True, fem_solve))
    for label, profiles, early, solve in solvers:
        run_ = Run(label, 0.0, 0, series={"x": x}, info={"nodes": nx * ny})
        if profiles:
            with _cli.model_run(f"{label} profiles"):
                _, sample, wall, dofs = solve(times, times[1:], f"{label}-profiles", vtk)
            p_all = sample(samples)
            keep = np.searchsorted(times[1:], t_out)
            p_h = p_all[keep]
            run_.wall_time_s, run_.n_dofs = wall, dofs
            run_.series.update(t_D=list(t_D), p=p_h, p_exact=p_exact,
                               history_t_D=times[1:] * c / Lx**2, history_p=p_all[:, 0], history_exact=history_exact)
            for td, ph, pe in zip(sorted(t_D), p_h, p_exact):
                run_.errors[f"l2_p_TD{td:g}"] = float(np.linalg.norm(ph - pe) / np.linalg.norm(pe))
            run_.errors["cryer_peak"] = float(p_all[:, 0].max() / p0)
        if early:
            for dtd, nsteps in EARLY:
                tt = dtd * h**2 / c * np.arange(nsteps + 1)
                with _cli.model_run(f"{label} early dt_D={dtd:g}"):
                    _, sample, wall, dofs = solve(tt, tt[-1:], f"{label}-early-dtD{dtd:g}")
                ph = sample(samples)[0]
                pe = exact.pressure(x, tt[-1])
                tag = f"early_dtD{dtd:g}"
                run_.series[tag] = ph
                run_.series[tag + "_exact"] = pe
                run_.series[tag + "_t_D"] = float(tt[-1] * c / Lx**2)
                run_.errors[tag + "_overshoot"] = float((ph.max() - pe.max()) / p0)
                run_.errors[tag + "_l2"] = float(np.linalg.norm(ph - pe) / np.linalg.norm(pe))
                if not profiles:
                    run_.wall_time_s += wall
                    run_.n_dofs = dofs
        results.runs.append(run_)
    return results


def plot(results: Results, out: Path) -> list[Path]:
    """Profiles with the Mandel-Cryer history, and the early-time comparison (Fig 3.8)."""
    plt = _cli.pyplot()

    prm = results.params
    Lx, p0 = prm["Lx"], prm["p0"]
    files = []
    prof = [r for r in results.runs if "p" in r.series]
    if prof:
        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 5), gridspec_kw={"width_ratios": [1.4, 1]})
        times = prof[0].series["t_D"]
        colors = plt.cm.viridis(np.linspace(0.0, 0.85, len(times)))
        x = np.asarray(prof[0].series["x"]) / Lx
        markers = ["o", "s", "^", "v", "D", "x"]
        for i, td in enumerate(sorted(times)):
            ax.plot(x, np.asarray(prof[0].series["p_exact"][i]) / p0, color=colors[i], lw=2.2, alpha=0.5,
                    label=f"exact, $T_D$ = {td:g}")
            for j, r in enumerate(prof):
                every = max(1, len(x) // 25)
                ax.plot(x[j * 3 % every::every], np.asarray(r.series["p"][i])[j * 3 % every::every] / p0,
                        ls="none", marker=markers[j % len(markers)], ms=4, mfc="none", color=colors[i],
                        label=r.method if i == 0 else None)
        ax.set_xlabel("x / Lx [-]")
        ax.set_ylabel("p / p0+ [-]")
        ax.set_title("pressure along y = 0 (lines exact, markers numerical)")
        ax.axhline(1.0, color="0.6", lw=0.8, ls=":")
        ax.legend(fontsize=7, ncol=2)
        ax.grid(alpha=0.3)
        r0 = prof[0]
        ax2.semilogx(r0.series["history_t_D"], np.asarray(r0.series["history_exact"]) / p0, color="k", lw=2.2,
                     alpha=0.5, label="exact")
        for j, r in enumerate(prof):
            ax2.semilogx(r.series["history_t_D"], np.asarray(r.series["history_p"]) / p0,
                         marker=markers[j % len(markers)], ms=3, mfc="none", lw=0.8, label=r.method)
        ax2.axhline(1.0, color="0.6", lw=0.8, ls=":")
        ax2.set_xlabel("$T_D = c t / L_x^2$ [-]")
        ax2.set_ylabel("p(0, 0, t) / p0+ [-]")
        ax2.set_title("centre pressure: Mandel-Cryer rise above p0+")
        ax2.legend(fontsize=8)
        ax2.grid(alpha=0.3, which="both")
        fig.suptitle(f"Mandel's problem, {prm['nx']} x {prm['ny']} nodes, nu = {prm['nu']:g}, "
                     f"c = {prm['c']:.3g}, p0+ = {p0:.3g}")
        fig.tight_layout()
        files.append(_cli.save(fig, out / "profiles.png"))
    early = [r for r in results.runs if "early_dtD0.01" in r.series]
    if early:
        fig, axes = plt.subplots(1, len(EARLY), figsize=(5 * len(EARLY), 4.6), sharey=True)
        x = np.asarray(early[0].series["x"]) / Lx
        for ax, (dtd, nsteps) in zip(np.atleast_1d(axes), EARLY):
            tag = f"early_dtD{dtd:g}"
            ax.plot(x, np.asarray(early[0].series[tag + "_exact"]) / p0, color="k", lw=2.5, alpha=0.4,
                    label="exact")
            for r in early:
                color, ls = _cli.method_style(r.method)
                ax.plot(x, np.asarray(r.series[tag]) / p0, color=color, ls=ls, lw=1.2,
                        label=f"{r.method} ({r.errors[tag + '_overshoot']:+.0%})")
            ax.set_xlim(0.8, 1.0)
            ax.set_title(f"$\\Delta t_D$ = {dtd:g}, {nsteps} steps: $T_D$ = {early[0].series[tag + '_t_D']:.1e}")
            ax.set_xlabel("x / Lx [-] (drained side at 1)")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, title="method (overshoot / p0+)", title_fontsize=7)
        np.atleast_1d(axes)[0].set_ylabel("p / p0+ along y = 0 [-]")
        fig.suptitle("Early-time pressure near the drained side: spurious oscillation without stabilization")
        fig.tight_layout()
        files.append(_cli.save(fig, out / "early_time.png"))
    return files


CLAIMS = [
    *(Claim(f"Fig 3.9: {m} pressure along y = 0 within 3 % (relative L2) of the exact solution at T_D = {t:g}",
            run=m, key=f"l2_p_TD{t:g}", op="<=", bound=0.03, full_only=t > 0.1)
      for m in ("rkpm-scni+fpp", "fem-taylor-hood") for t in (0.01, 0.1, 0.5)),
    Claim("Fig 3.9: Mandel-Cryer effect, the centre pressure of SCNI+FPP rises above 1.1 p0+",
          run="rkpm-scni+fpp", key="cryer_peak", op=">", bound=1.1),
    Claim("Fig 3.8 (top): SCNI+FPP stable at early time, overshoot <= 5 % of p0+ with 20 steps of dt_D = 0.01",
          run="rkpm-scni+fpp", key="early_dtD0.01_overshoot", op="<=", bound=0.05),
    Claim("Fig 3.8 (top): NI oscillates at early time, overshoot > 20 % of p0+ with 20 steps of dt_D = 0.01",
          run="rkpm-ni", key="early_dtD0.01_overshoot", op=">", bound=0.20),
    Claim("Fig 3.8 (top): NI oscillates even when FPP is applied, overshoot > 1 % of p0+ at dt_D = 0.01",
          run="rkpm-ni+fpp", key="early_dtD0.01_overshoot", op=">", bound=0.01, full_only=True),
]


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point (see the module docstring)."""
    return _cli.main(NAME, __doc__, PARAMS, run, plot, argv, QUICK, checkpoints=True)


if __name__ == "__main__":
    sys.exit(main())
