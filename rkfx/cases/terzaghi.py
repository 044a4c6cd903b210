"""Terzaghi's consolidation: RKPM u-p variants and dolfinx FEM against the exact series (seed 3.4.1).

Problem. A soil layer of height H under a load q applied suddenly at t = 0+ on its drained top;
the bottom is fixed and impermeable, the sides are rollers and impermeable, so the response is
one-dimensional. Modelled as a W x H column:

    top    (y = H)   total traction (0, -q), drained p = 0
    bottom (y = 0)   u = 0, no flow
    left, right      u_x = 0, no flow

The load is carried at first by the pore fluid (p = p0 = alpha q / (alpha^2 + S K_v)); the
pressure then diffuses out through the top with the consolidation coefficient
c_v = k K_v / (alpha^2 + S K_v). Exact solution: ``verification.terzaghi`` (Fourier series,
erfc series at early times).

Seed set-up (Fig 3.4-3.6): W = 3 m, H = 10 m, 7 x 21 nodes, Delta t = 1 s, E = 1 kPa, nu = 0,
k_h = 1e-5 m/s and gamma_f = 10 kN/m^3, so k = k_h / gamma_f = 1e-9 m^2/(Pa s); c_v = 1e-6 m^2/s,
so after the first step the layer is still undrained except for a thin boundary layer at the
top, the regime in which equal-order u-p approximations oscillate.

Studies:

* variants — pressure along the column axis at the output times (the first step and
  ``t_end``; more with ``t_out``), for every RKPM variant and FEM element. After the first
  step: deviation from the exact profile away from the drained layer (more than
  ``2 H / (ny - 1)`` below the top) and the overshoot max p / p0 - 1.
* refinement — the first-step profile near the drained top with ``refine_ny`` nodes along the
  height (seed: 21, 41, 81), for ``scni+fpp`` and Taylor-Hood; relative L2 error of p along
  the axis per level.

Parameters and units (``--set NAME=VALUE``): E [Pa], nu [-], k [m^2/(Pa s)], alpha [-],
S [1/Pa], W [m], H [m], q [Pa], nx, ny, dt [s], t_end [s], t_out (list [s]), growth [-],
variants (list), fem (list), refine_ny (list), support_factor [-], bc_method (transformation |
nitsche), solver (auto | mumps | fieldsplit, which needs bc_method=nitsche).

    python -m rkfx.cases.terzaghi [--quick] [--method rkpm|fem|both] [--set NAME=VALUE] [--out DIR]
        [--checkpoint-every N] [--resume DIR]

With ``--vtk`` the runs of the variants study write displacement, pressure, strain and effective
stress at the output times to OUT/vtk/ (RKPM: particles and nodal cells; FEM: dolfinx VTK files).

With ``--checkpoint-every N`` every run (RKPM and FEM) writes its state every N steps (and at its end) to
OUT/checkpoints/; ``--resume DIR`` continues a killed invocation from DIR/checkpoints/, finished
runs returning their results at once.
"""
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from verification.terzaghi import Terzaghi

from rkfx.conditions import Displacement, Pressure, Traction, split
from rkfx.errors import InputError
from rkfx.geometry.particles import structured
from rkfx.models.poroelasticity import VARIANTS, PoroMaterial, solve_biot
from rkfx.solvers.integrate import time_grid
from rkfx.cases import _cli, _paraview, _preflight, _up_solver
from rkfx.cases._cli import Param, Results, Run
from rkfx.report.claims import Claim

NAME = "terzaghi"
FEM_ELEMENTS = ("taylor-hood", "q1q1", "q1q1-fpp")
NUM_SAMPLES = 501
HOLD = 10

PARAMS = {
    "E": Param(1.0e3, "drained Young's modulus [Pa]"),
    "nu": Param(0.0, "drained Poisson's ratio [-]"),
    "k": Param(1.0e-9, "mobility k_h / gamma_f [m^2/(Pa s)]"),
    "alpha": Param(1.0, "Biot coefficient [-]"),
    "S": Param(0.0, "storage coefficient 1/Q [1/Pa] (0: incompressible constituents)"),
    "W": Param(3.0, "width of the column [m]"),
    "H": Param(10.0, "height of the layer [m]"),
    "q": Param(1.0e3, "load on the top [Pa]"),
    "nx": Param(7, "nodes across the width [count]"),
    "ny": Param(21, "nodes along the height [count]"),
    "dt": Param(1.0, "first time step [s]"),
    "t_end": Param(1.0, "last output time [s] (always an output)"),
    "t_out": Param([], "further output times [s]"),
    "growth": Param(1.5, "step growth factor every 10 steps after the first [-]"),
    "variants": Param(list(VARIANTS), "RKPM variants", fingerprint=False),
    "fem": Param(list(FEM_ELEMENTS), "FEM elements: taylor-hood, q1q1, q1q1-fpp", fingerprint=False),
    "refine_ny": Param([21, 41, 81], "nodes along the height of the refinement study [count]", fingerprint=False),
    "support_factor": Param(1.5, "RK support radius / nodal spacing [-], > 1"),
    **_up_solver.PARAMS,
}
QUICK = {"refine_ny": [21, 41], "fem": ["taylor-hood", "q1q1-fpp"]}


def _times(t_out) -> list[float]:
    """``t_out`` as numbers (an empty default list reads --set values as text)."""
    try:
        times = [float(t) for t in t_out]
    except (TypeError, ValueError):
        raise InputError(f"t_out = {list(t_out)!r}: give output times in seconds, e.g. t_out=10,100") from None
    if not all(np.isfinite(times)):
        raise InputError(f"t_out = {times!r}: output times must be finite")
    return times


def _check(W, H, q, nx, ny, dt, t_end, t_out, growth, variants, fem, refine_ny, support_factor=1.5,
           bc_method="transformation", solver="auto"):
    for name, v in (("W", W), ("H", H), ("dt", dt)):
        if not v > 0:
            raise InputError(f"{name} = {v!r} must be positive")
    if q == 0:
        raise InputError("q = 0: the layer carries no load")
    for name, v in [("nx", nx), ("ny", ny)] + [("refine_ny", v) for v in refine_ny]:
        if v < 3:
            raise InputError(f"{name} = {v}: need at least 3 nodes per direction")
    if not t_end >= dt:
        raise InputError(f"t_end = {t_end!r} must be >= dt = {dt!r} (the first step is always taken)")
    if any(not 0 < t <= t_end for t in t_out):
        raise InputError(f"t_out = {t_out!r}: output times must lie in (0, t_end]")
    if not growth >= 1:
        raise InputError(f"growth = {growth!r} must be >= 1")
    _preflight.known(variants, VARIANTS, "RKPM variant")
    _preflight.known(fem, FEM_ELEMENTS, "FEM element")
    _preflight.support_factor_ok(support_factor)
    _up_solver.check(bc_method, solver)


def check(*, E, nu, k, alpha, S, W, H, q, nx, ny, dt, t_end, t_out, growth, variants, fem, refine_ny,
          support_factor, bc_method="transformation", solver="auto", **_) -> None:
    """Raise InputError for a parameter outside its documented range (the CLI calls this before any work)."""
    _check(W, H, q, nx, ny, dt, t_end, _times(t_out), growth, variants, fem, refine_ny, support_factor, bc_method,
           solver)
    PoroMaterial(E, nu, k, alpha, S)


def _refined_nx(nx, ny, n):
    """Nodes across the width of the refinement model with ``n`` nodes along the height."""
    return max(3, int(round((nx - 1) * (n - 1) / (ny - 1))) + 1)


def memory_need(methods, *, nx, ny, refine_ny, **_) -> _preflight.Need:
    """Peak memory of the largest run: nx ny nodes, or a refinement model (see ``rkfx.cases._preflight``)."""
    nodes = max([nx * ny] + [_refined_nx(nx, ny, n) * n for n in refine_ny])
    return _preflight.poro_need(methods, nodes, f"nx={nx}, ny={ny}, refine_ny={','.join(map(str, refine_ny))}",
                                "lower nx, ny or refine_ny")


def _solve(method, W, H, nx, ny, material, q, times, outputs, samples, support_factor, io, vtk=None, up=None):
    """Pressure at the samples for each output time, wall time and unknowns; with ``vtk`` a
    folder, the fields at the output times are also written there for ParaView; ``up``: the RKPM
    solver options (``bc_method``, ``solver``)."""
    # Fixed bottom, rollers on the sides, the load q on the drained top: for RKPM and FEM alike.
    bcs = [Displacement("bottom"), Displacement("left", components=(0,)), Displacement("right", components=(0,)),
           Pressure("top"),
           Traction("top", lambda x, t, n: np.tile([0.0, -q], (len(x), 1)))]
    if method.startswith("rkpm-"):
        p = structured(W, H, nx, ny)
        kinds = split(bcs)
        sol = solve_biot(p, material, times, outputs, displacements=kinds[Displacement], pressures=kinds[Pressure],
                         tractions=kinds[Traction], variant=method[5:], support_factor=support_factor,
                         comm=_cli.comm(), progress=lambda it: _cli.progress(it, method, len(times) - 1), **io,
                         **(up or {}))
        if vtk is not None:
            _paraview.write_biot(vtk, method, p, sol, material.elastic, _cli.comm())
        return sol.pressure(samples), sol.wall_time_s, sol.n_dofs
    import dolfinx_solver  # noqa: F401, PLC0415

    from fem_baselines import poroelasticity as fb  # noqa: PLC0415

    element = method[4:]
    mesh = fb.rectangle_mesh(np.linspace(0, W, nx), np.linspace(0, H, ny),
                             "triangle" if element == "taylor-hood" else "quadrilateral")
    series = _paraview.fem_series(vtk, method, mesh)
    res = fb.solve_biot(mesh, material.E, material.nu, material.k, material.alpha, material.S, element, bcs,
                        times, samples, outputs, vtk=series,
                        progress=lambda it: _cli.progress(it, method, len(times) - 1), **io)
    if series is not None:
        series.close()
    return res.p, res.wall_time_s, res.n_dofs


def run(*, methods: Sequence[str] = ("rkpm", "fem"), E=1.0e3, nu=0.0, k=1.0e-9, alpha=1.0, S=0.0, W=3.0, H=10.0,
        q=1.0e3, nx=7, ny=21, dt=1.0, t_end=1.0, t_out=(), growth=1.5, variants=VARIANTS, fem=FEM_ELEMENTS,
        refine_ny=(21, 41, 81), support_factor=1.5, bc_method="transformation", solver="auto", checkpoint_every=0,
        work_dir=None, resume=None, vtk=None) -> Results:
    """Both studies for every requested method; see the module docstring. ``vtk``: a folder for
    the ParaView files of the variants study's runs (``--vtk``)."""
    t_out = _times(t_out)
    _check(W, H, q, nx, ny, dt, t_end, t_out, growth, variants, fem, refine_ny, support_factor, bc_method, solver)
    up = {"bc_method": bc_method, "solver": solver}
    material = PoroMaterial(E, nu, k, alpha, S)
    ck = _cli.Checkpoints(checkpoint_every, work_dir, resume)
    exact = Terzaghi(E, nu, k, H, q, alpha, S)
    p0 = exact.p0
    outputs = np.unique(np.r_[dt, np.asarray(t_out, float), t_end])
    times = np.array([0.0, dt])
    if t_end > dt:  # after the first step, steps grow towards the later outputs
        times = np.r_[0.0, dt + time_grid(outputs[outputs > dt] - dt, dt * growth, growth, hold=HOLD)]
        times[np.searchsorted(times, outputs - 1e-9 * outputs)] = outputs  # exact output times
    z = np.linspace(0.0, H, NUM_SAMPLES)
    samples = np.column_stack([np.full_like(z, 0.5 * W), z])
    p_exact = np.array([exact.pressure(z, t) for t in outputs])
    away = z < H - 2.0 * H / (ny - 1)
    labels = ([f"rkpm-{v}" for v in variants] if "rkpm" in methods else []) + \
             ([f"fem-{e}" for e in fem] if "fem" in methods else [])
    results = Results(NAME, dict(E=E, nu=nu, k=k, alpha=alpha, S=S, W=W, H=H, q=q, nx=nx, ny=ny, dt=dt, t_end=t_end,
                                 t_out=list(t_out), growth=growth, variants=list(variants), fem=list(fem),
                                 refine_ny=list(refine_ny), support_factor=support_factor, bc_method=bc_method,
                                 solver=solver, p0=p0, c_v=exact.c_v,
                                 steps=len(times) - 1))
    for label in labels:
        with _cli.model_run(label):
            p_h, wall, dofs = _solve(label, W, H, nx, ny, material, q, times, outputs, samples, support_factor,
                                     ck.for_run(label), vtk, up)
        first = p_h[0] / p0
        errors = {"first_step_max_dev_away": float(np.abs(first - p_exact[0] / p0)[away].max()),
                  "first_step_overshoot": float(first.max() - 1.0),
                  "first_step_l2": float(np.linalg.norm(p_h[0] - p_exact[0]) / np.linalg.norm(p_exact[0]))}
        for t, ph, pe in zip(outputs[1:], p_h[1:], p_exact[1:]):
            errors[f"l2_t{t:g}"] = float(np.linalg.norm(ph - pe) / np.linalg.norm(pe))
        results.runs.append(Run(label, wall, dofs, series={"z": z, "t": outputs, "p": p_h, "p_exact": p_exact},
                                errors=errors, info={"study": "variants", "nx": nx, "ny": ny}))
    # Refinement near the drained top after the first step (Fig 3.6).
    refine = [m for m in ("rkpm-scni+fpp", "fem-taylor-hood") if m.split("-")[0] in methods]
    for label in refine:
        for n in refine_ny:
            mx = _refined_nx(nx, ny, n)
            with _cli.model_run(f"{label} ny={n}"):
                p_h, wall, dofs = _solve(label, W, H, mx, n, material, q, np.array([0.0, dt]), [dt], samples,
                                         support_factor, ck.for_run(f"{label}-ny{n}"), up=up)
            results.runs.append(Run(f"{label} ny={n}", wall, dofs,
                                    series={"z": z, "t": [dt], "p": p_h, "p_exact": p_exact[:1]},
                                    errors={"first_step_l2": float(np.linalg.norm(p_h[0] - p_exact[0])
                                                                   / np.linalg.norm(p_exact[0]))},
                                    info={"study": "refinement", "nx": mx, "ny": n}))
    return results


def plot(results: Results, out: Path) -> list[Path]:
    """First-step profiles of every method (Fig 3.5), later profiles, and the refinement (Fig 3.6)."""
    plt = _cli.pyplot()

    prm = results.params
    H, p0 = prm["H"], prm["p0"]
    files = []
    runs = [r for r in results.runs if r.info["study"] == "variants"]
    if runs:
        fig, axes = plt.subplots(1, 2, figsize=(12, 6.2), layout="constrained")
        z = np.asarray(runs[0].series["z"]) / H
        for ax, zoom in zip(axes, (False, True)):
            ax.plot(np.asarray(runs[0].series["p_exact"][0]) / p0, z, color="k", lw=2.5, alpha=0.4, label="exact")
            for r in runs:
                color, ls = _cli.method_style(r.method)
                ax.plot(np.asarray(r.series["p"][0]) / p0, z, color=color, ls=ls, lw=1.3,
                        label=f"{r.method} (overshoot {r.errors['first_step_overshoot']:+.0%})")
            ax.set_xlabel("p / p0 [-]")
            ax.set_ylabel("height y / H [-] (drained top at 1)")
            ax.grid(alpha=0.3)
            if zoom:
                ax.set_ylim(0.7, 1.0)
                ax.set_title("near the drained top")
            else:
                ax.set_title(f"whole column, t = {prm['dt']:g} s (first step)")
        # Below the panels: the oscillating profiles fill the whole column.
        fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=4, fontsize=7)
        fig.suptitle(f"Terzaghi, {prm['nx']} x {prm['ny']} nodes: pressure after the first step "
                     f"(c_v dt / h^2 = {prm['c_v'] * prm['dt'] / (H / (prm['ny'] - 1)) ** 2:.1e})")
        files.append(_cli.save(fig, out / "first_step.png"))
        if len(runs[0].series["t"]) > 1:
            fig, ax = plt.subplots(figsize=(8.5, 5.5), layout="constrained")
            ts = runs[0].series["t"]
            colors = plt.cm.viridis(np.linspace(0, 0.85, len(ts)))
            best = [r for r in runs if r.method in ("rkpm-scni+fpp", "fem-taylor-hood")] or runs[:1]
            for i, t in enumerate(ts):
                ax.plot(np.asarray(runs[0].series["p_exact"][i]) / p0, z, color=colors[i], lw=2.5, alpha=0.4,
                        label=f"exact, t = {t:.3g} s")
                for j, r in enumerate(best):
                    ax.plot(np.asarray(r.series["p"][i])[::25] / p0, z[::25], ls="none", marker="os"[j % 2],
                            mfc="none", color=colors[i], label=r.method if i == 0 else None)
            ax.set_xlabel("p / p0 [-]")
            ax.set_ylabel("y / H [-]")
            ax.set_title("consolidation: lines exact, markers numerical")
            fig.legend(*ax.get_legend_handles_labels(), fontsize=7, loc="outside right upper")
            ax.grid(alpha=0.3)
            files.append(_cli.save(fig, out / "consolidation.png"))
    ref = [r for r in results.runs if r.info["study"] == "refinement"]
    if ref:
        fig, ax = plt.subplots(figsize=(7, 5.5))
        z = np.asarray(ref[0].series["z"]) / H
        ax.plot(np.asarray(ref[0].series["p_exact"][0]) / p0, z, color="k", lw=2.5, alpha=0.4, label="exact")
        for r in ref:
            base = r.method.split(" ")[0]
            shade = {21: 0.45, 41: 0.7, 81: 1.0}.get(r.info["ny"], 0.8)
            color = plt.cm.Blues(shade) if base.startswith("rkpm") else plt.cm.Greens(shade)
            ax.plot(np.asarray(r.series["p"][0]) / p0, z, color=color, ls="-" if base.startswith("rkpm") else ":",
                    label=f"{r.method} (L2 {r.errors['first_step_l2']:.2e})")
        ax.set_ylim(0.8, 1.0)
        ax.set_xlabel("p / p0 [-]")
        ax.set_ylabel("y / H [-] (drained top at 1)")
        ax.set_title(f"first-step pressure near the drained top, t = {prm['dt']:g} s")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        files.append(_cli.save(fig, out / "refinement.png"))
    return files


CLAIMS = [
    Claim("Fig 3.5: SCNI+FPP first-step pressure within 5 % of Terzaghi's solution away from the drained layer",
          run="rkpm-scni+fpp", info={"study": "variants"}, key="first_step_max_dev_away", op="<=", bound=0.05),
    Claim("Fig 3.5: NI alone gives severe pressure oscillations (deviation > 50 % of p0)",
          run="rkpm-ni", info={"study": "variants"}, key="first_step_max_dev_away", op=">", bound=0.5),
    Claim("Fig 3.5: SCNI alone gives severe pressure oscillations (deviation > 50 % of p0)",
          run="rkpm-scni", info={"study": "variants"}, key="first_step_max_dev_away", op=">", bound=0.5),
    Claim("Fig 3.5: FPP with NI only partly removes the oscillation: its deviation > 2x that of SCNI+FPP",
          run="rkpm-ni+fpp", info={"study": "variants"}, key="first_step_max_dev_away", op=">", bound=2.0,
          over=("rkpm-scni+fpp", {"study": "variants"})),
    Claim("Sec 3.4.1: SCNI+FPP overshoot near the drainage boundary is minor (< 10 % of p0)",
          run="rkpm-scni+fpp", info={"study": "variants"}, key="first_step_overshoot", op="<", bound=0.10),
    Claim("Sec 3.4.1: the overshoot also appears with stable finite elements (Taylor-Hood > 10 % of p0)",
          run="fem-taylor-hood", info={"study": "variants"}, key="first_step_overshoot", op=">", bound=0.10),
    Claim("Fig 3.6: refining 21 -> 41 nodes along the height lowers the first-step L2 error of SCNI+FPP",
          run="rkpm-scni+fpp ny=41", key="first_step_l2", op="<", bound=1.0, over=("rkpm-scni+fpp ny=21", {})),
    Claim("Fig 3.6: refining 41 -> 81 nodes along the height lowers the first-step L2 error of SCNI+FPP",
          run="rkpm-scni+fpp ny=81", key="first_step_l2", op="<", bound=1.0, over=("rkpm-scni+fpp ny=41", {}),
          full_only=True),
]


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point (see the module docstring)."""
    return _cli.main(NAME, __doc__, PARAMS, run, plot, argv, QUICK, checkpoints=True)


if __name__ == "__main__":
    sys.exit(main())
