"""Wave propagation in a saturated poroelastic column: explicit RKPM u-p on NSNI and DNI, the
Taylor-Hood FEM baseline, against the exact solution (§6.4.1, Figs 6.4-6.6).

Problem. A soil layer of height L, infinite in x, under a step load q on its drained top from
t = 0; modelled as a laterally confined column three nodes wide (rollers on both sides):

    top    (y = L)   total traction (0, -q), drained p = 0
    bottom (y = 0)   u_y = 0, no flow
    sides            u_x = 0, no flow

The load starts a fast (undrained) compressional wave, speed c = sqrt(M_u / rho) ~ 1690 m/s,
that rings between the loaded top and the fixed base while the fluid drains slowly through the
top (c_v = 1.18 m^2/s). Behind the first front the pore pressure is alpha Q q / M_u = 2865 Pa,
twice that at the base after the reflection; the drained settlement would be q L / M.

Methods.
* RKPM: linear RK (a = 2 h), nodal integration by NSNI (naturally stabilized, with the
  variationally consistent correction; eqs. 6.52-6.79) or DNI (direct nodal integration, the
  comparison of Fig 6.5), lumped masses, and the explicit u-p step (beta1 = 1/2, beta2 = 0,
  theta = 0, eqs. 6.37-6.49) of ``rkfx.solvers.explicit_up`` at ``courant`` times the step it
  allows; which of the wave and diffusion limits governs is reported.
* FEM: Taylor-Hood (P2-P1) triangles on the same column (``ny`` vertices along the height),
  consistent mass, Newmark's trapezoid for u with the trapezoid theta = 1/2 for p, dt =
  ``fem_courant`` h / c (``fem_baselines.poroelasticity.solve_biot`` with ``density``).

Reference: ``verification.wave_column`` (the u-p column in the Laplace domain, inverted by a
Fourier series with Lanczos factors; its checks are listed there). The seed plots the FEM
results of Soares (2014) as its reference; here the exact solution is.

Measures: the top displacement u_y(L, t) and the base pressure p(0, t), each as a relative L2
error over the history from 0 to ``t_end``, leaving out ``exclude`` seconds either side of
every fast-front arrival at that point (where any discrete solution, and the inversion,
rings). Studies:

* rules — NSNI and DNI at ``ny`` nodes along the height (Fig 6.5), and Taylor-Hood;
* refinement — NSNI at ``refine_ny`` nodes (Fig 6.6): errors and observed rates.

With ``fpp=true`` the RKPM storage rows carry the fluid pressure projection of (6.49) on the
pressure rates (``rkfx.models.explicit_poroelasticity``); off by default: on this column it
smears the fronts (docs/large_deformation.md).

Parameters and units (``--set NAME=VALUE``): E [Pa], nu [-], rho_s, rho_f [kg/m^3], porosity [-],
k [m^4/(N s)], K_s, K_f [Pa], L [m], q [Pa], ny [count], refine_ny (list), rules (list),
t_end [s], courant [-], fem_courant [-], exclude [s], samples [count], fpp [bool].

    python -m rkfx.cases.wave_column [--quick] [--method rkpm|fem|both] [--set NAME=VALUE] [--out DIR]
        [--checkpoint-every N] [--resume DIR]

With ``--checkpoint-every N`` every run writes its state every N steps (and at its end) to
OUT/checkpoints/; ``--resume DIR`` continues a killed invocation from DIR/checkpoints/.
"""
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from verification.wave_column import WaveColumn

from rkfx.cases import _cli, _preflight
from rkfx.cases._cli import Param, Results, Run
from rkfx.cases._confined_column import confined_column
from rkfx.conditions import Displacement, Pressure, Traction
from rkfx.errors import InputError
from rkfx.integration.nodal_stabilized import RULES
from rkfx.models.explicit_poroelasticity import Constituents
from rkfx.report.claims import Claim
from rkfx.solvers.explicit_up import ExplicitUP, stable_steps

NAME = "wave_column"

PARAMS = {
    "E": Param(254423076.9, "drained Young's modulus [Pa]"),
    "nu": Param(0.298, "drained Poisson's ratio [-]"),
    "rho_s": Param(2700.0, "grain density [kg/m^3]"),
    "rho_f": Param(1000.0, "fluid density [kg/m^3]"),
    "porosity": Param(0.48, "porosity n [-]"),
    "k": Param(3.55e-9, "mobility [m^4/(N s)]"),
    "K_s": Param(1.1e10, "grain bulk modulus [Pa]"),
    "K_f": Param(3.3e9, "fluid bulk modulus [Pa]"),
    "L": Param(10.0, "height of the layer [m]"),
    "q": Param(3000.0, "step load on the top [Pa]"),
    "ny": Param(241, "nodes along the height of the rules study [count]"),
    "refine_ny": Param([61, 121, 241, 481], "nodes along the height of the NSNI refinement [count]",
                       fingerprint=False),
    "rules": Param(["nsni", "dni"], "nodal rules of the rules study", fingerprint=False),
    "t_end": Param(0.05, "end of the history [s]"),
    "courant": Param(0.9, "RKPM step / the step the explicit scheme allows [-], in (0, 1]"),
    "fem_courant": Param(0.5, "FEM step / (h / c_fast) [-]"),
    "exclude": Param(1.0e-3, "time left out either side of a front's arrival [s]"),
    "samples": Param(2000, "recorded samples per history, at most [count]"),
    "fpp": Param(False, "RKPM storage rows stabilized by the fluid pressure projection (6.49) [bool]"),
}
QUICK = {"ny": 121, "refine_ny": [61, 121]}


def _medium(E, nu, rho_s, rho_f, porosity, k, K_s, K_f) -> Constituents:
    return Constituents(E=E, nu=nu, rho_s=rho_s, rho_f=rho_f, porosity=porosity, k=k, K_s=K_s, K_f=K_f)


def _exact(medium: Constituents, L: float, q: float) -> WaveColumn:
    mat = medium.material
    return WaveColumn(mat.elastic.constrained_modulus, mat.alpha, mat.S, medium.k, medium.density, L, q)


def check(*, E, nu, rho_s, rho_f, porosity, k, K_s, K_f, L, q, ny, refine_ny, rules, t_end, courant, fem_courant,
          exclude, samples, fpp=False, **_) -> None:
    """Raise InputError for a parameter outside its documented range (the CLI calls this before any work)."""
    _medium(E, nu, rho_s, rho_f, porosity, k, K_s, K_f)
    for name, v in (("L", L), ("t_end", t_end), ("fem_courant", fem_courant)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r} must be positive")
    if not (np.isfinite(q) and q != 0):
        raise InputError(f"q = {q!r}: the column carries no load; give a nonzero load in Pa")
    for name, v in [("ny", ny)] + [("refine_ny", v) for v in refine_ny]:
        if int(v) != v or v < 5:
            raise InputError(f"{name} = {v!r}: need a whole number of at least 5 nodes along the height")
    for r in rules:
        if r not in RULES:
            raise InputError(f"unknown nodal rule {r!r}; choose from {', '.join(RULES)}")
    if not 0 < courant <= 1:
        raise InputError(f"courant = {courant!r} must lie in (0, 1] (a fraction of the stable step)")
    if not 0 <= exclude < t_end / 4:
        raise InputError(f"exclude = {exclude!r} s must lie in [0, t_end / 4)")
    if int(samples) != samples or samples < 10:
        raise InputError(f"samples = {samples!r}: record at least 10 samples")
    if not isinstance(fpp, (bool, np.bool_)):
        raise InputError(f"fpp = {fpp!r} must be true or false")


def memory_need(methods, *, ny, refine_ny, **_) -> _preflight.Need:
    """Peak memory of the largest column (three nodes across)."""
    nodes = 3 * max([ny] + list(refine_ny))
    return _preflight.poro_need(methods, nodes, f"ny={ny}, refine_ny={','.join(map(str, refine_ny))}",
                                "lower ny or refine_ny")


def _errors(exact: WaveColumn, t: np.ndarray, u: np.ndarray, p: np.ndarray, exclude: float, L: float) \
        -> tuple[dict, np.ndarray, np.ndarray]:
    """Relative L2 errors of the top displacement and the base pressure away from the fronts,
    and the exact histories."""
    u_exact, p_exact = exact.histories([L, 0.0], t)
    errors = {}
    for key, y, h, e in (("u_top", L, u, u_exact[:, 0]), ("p_base", 0.0, p, p_exact[:, 1])):
        arrivals = exact.arrivals(y, float(t[-1]))
        keep = np.all(np.abs(t[:, None] - arrivals[None, :]) > exclude, axis=1)
        errors[f"{key}_l2"] = float(np.linalg.norm(h[keep] - e[keep]) / np.linalg.norm(e[keep]))
    return errors, u_exact[:, 0], p_exact[:, 1]


def _rkpm(medium, L, q, ny, rule, t_end, courant, samples, io, fpp=False):
    """The RKPM history: times, u_y(L), p(0), and what the run measured."""
    t0 = time.perf_counter()
    comm = _cli.comm()
    model, _, _, observe = confined_column(ny, rule, medium, L, q, comm=comm, fpp=fpp)
    limits = stable_steps(model)
    steps = int(np.ceil(t_end / (courant * limits["coupled"])))
    dt = t_end / steps
    bar = _cli.step_progress(f"rkpm-{rule} ny={ny}", steps)
    try:
        run = ExplicitUP(dt, check_stability=False).run(model, steps, record=lambda x, r, t: observe(x),
                                                        record_every=max(1, steps // samples), progress=bar,
                                                        comm=comm, **io)
    finally:
        bar.close()
    info = {"dt": dt, "steps": steps, "wave_limit": limits["wave"], "diffusion_limit": limits["diffusion"],
            "governs": limits["governs"],
            "unknowns": model.layout.size if model.share is None else int(model.share.total(model.share.num_owned))}
    return run.times, run.samples[:, 0], run.samples[:, 1], time.perf_counter() - t0, info


def _fem(medium, L, q, ny, t_end, fem_courant, c_fast, samples, io):
    """The Taylor-Hood history on ny vertices along the height, two elements across."""
    import dolfinx_solver  # noqa: F401, PLC0415

    from fem_baselines import poroelasticity as fb  # noqa: PLC0415

    h = L / (ny - 1)
    mesh = fb.rectangle_mesh(np.linspace(0.0, 2 * h, 3), np.linspace(0.0, L, ny), "triangle", comm=_cli.comm())
    steps = int(np.ceil(t_end / (fem_courant * h / c_fast)))
    times = np.linspace(0.0, t_end, steps + 1)
    out = times[::max(1, steps // samples)]
    bcs = [Displacement("bottom", components=(1,)), Displacement("left", components=(0,)),
           Displacement("right", components=(0,)), Pressure("top"),
           Traction("top", lambda x, t, n: np.tile([0.0, -q], (len(x), 1)))]
    mat = medium.material
    res = fb.solve_biot(mesh, mat.elastic.E, mat.elastic.nu, mat.k, mat.alpha, mat.S, "taylor-hood", bcs, times,
                        np.array([[h, L], [h, 0.0]]), out, density=medium.density,
                        progress=lambda it: _cli.progress(it, "fem-taylor-hood", steps), **io)
    return out, res.u[:, 0, 1], res.p[:, 1], res.wall_time_s, {"dt": t_end / steps, "steps": steps,
                                                                "unknowns": res.n_dofs}


def run(*, methods: Sequence[str] = ("rkpm", "fem"), E=254423076.9, nu=0.298, rho_s=2700.0, rho_f=1000.0,
        porosity=0.48, k=3.55e-9, K_s=1.1e10, K_f=3.3e9, L=10.0, q=3000.0, ny=241, refine_ny=(61, 121, 241, 481),
        rules=("nsni", "dni"), t_end=0.05, courant=0.9, fem_courant=0.5, exclude=1.0e-3, samples=2000, fpp=False,
        checkpoint_every=0, work_dir=None, resume=None) -> Results:
    """Both studies for every requested method; see the module docstring."""
    check(E=E, nu=nu, rho_s=rho_s, rho_f=rho_f, porosity=porosity, k=k, K_s=K_s, K_f=K_f, L=L, q=q, ny=ny,
          refine_ny=refine_ny, rules=rules, t_end=t_end, courant=courant, fem_courant=fem_courant, exclude=exclude,
          samples=samples, fpp=fpp)
    medium = _medium(E, nu, rho_s, rho_f, porosity, k, K_s, K_f)
    exact = _exact(medium, L, q)
    ck = _cli.Checkpoints(checkpoint_every, work_dir, resume)
    results = Results(NAME, dict(E=E, nu=nu, rho_s=rho_s, rho_f=rho_f, porosity=porosity, k=k, K_s=K_s, K_f=K_f, L=L,
                                 q=q, ny=ny, refine_ny=list(refine_ny), rules=list(rules), t_end=t_end,
                                 courant=courant, fem_courant=fem_courant, exclude=exclude, fpp=fpp,
                                 fast_speed=exact.fast_speed, undrained_pressure=exact.undrained_pressure,
                                 drained_settlement=exact.drained_settlement, c_v=exact.c_v))

    def record(label, study, n, t, u, p, wall, info):
        errors, u_exact, p_exact = _errors(exact, t, u, p, exclude, L)
        results.runs.append(Run(label, wall, info.pop("unknowns"),
                                series={"t": t, "u_top": u, "p_base": p, "u_exact": u_exact, "p_exact": p_exact},
                                errors=errors, info={"study": study, "ny": n, **info}))

    jobs = []
    if "rkpm" in methods:
        jobs += [(f"rkpm-{r}", "rules", ny, r) for r in rules]
        jobs += [(f"rkpm-nsni ny={n}", "refinement", n, "nsni") for n in refine_ny]
    if "fem" in methods:
        jobs.append(("fem-taylor-hood", "rules", ny, None))
    for label, study, n, rule in jobs:
        with _cli.model_run(label):
            if rule is None:
                out = _fem(medium, L, q, n, t_end, fem_courant, exact.fast_speed, samples, ck.for_run(label))
            else:
                out = _rkpm(medium, L, q, n, rule, t_end, courant, samples, ck.for_run(label), fpp)
        record(label, study, n, *out)
    refined = sorted((r for r in results.runs if r.info["study"] == "refinement"), key=lambda r: r.info["ny"])
    for coarse, fine in zip(refined, refined[1:]):
        ratio = (fine.info["ny"] - 1) / (coarse.info["ny"] - 1)
        for key in ("u_top_l2", "p_base_l2"):
            fine.errors[f"rate_{key}"] = float(np.log(coarse.errors[key] / fine.errors[key]) / np.log(ratio))
    return results


def plot(results: Results, out: Path) -> list[Path]:
    """The histories of the rules study (Fig 6.5) and of the refinement (Fig 6.6), each beside its
    difference from the exact solution."""
    plt = _cli.pyplot()
    prm = results.params
    exact = _exact(_medium(*(prm[k] for k in ("E", "nu", "rho_s", "rho_f", "porosity", "k", "K_s", "K_f"))),
                   prm["L"], prm["q"])
    files = []
    for study, name in (("rules", "histories.png"), ("refinement", "refinement.png")):
        runs = [r for r in results.runs if r.info["study"] == study]
        if not runs:
            continue
        fig, axes = plt.subplots(2, 2, figsize=(13, 8), sharex=True, layout="constrained")
        ref = max(runs, key=lambda r: len(r.series["t"])).series
        t_ref = 1e3 * np.asarray(ref["t"])
        axes[0, 0].plot(t_ref, 1e6 * np.asarray(ref["u_exact"]), color="k", lw=2.6, alpha=0.3, label="exact")
        axes[1, 0].plot(t_ref, np.asarray(ref["p_exact"]), color="k", lw=2.6, alpha=0.3, label="exact")
        shades = plt.cm.viridis(np.linspace(0.0, 0.8, len(runs)))
        for i, r in enumerate(runs):
            t = 1e3 * np.asarray(r.series["t"])
            if study == "rules":
                color, ls = {"rkpm-nsni": ("C2", "-"), "rkpm-dni": ("C3", "-"),
                             "fem-taylor-hood": ("C0", "--")}.get(r.method, _cli.method_style(r.method))
                label = r.method
            else:
                color, ls, label = shades[i], "-", f"NSNI, {r.info['ny']} nodes"
            e, sr = r.errors, r.series
            for row, (key, scale, err) in enumerate((("u_top", 1e6, "u_top_l2"), ("p_base", 1.0, "p_base_l2"))):
                h, x = scale * np.asarray(sr[key]), scale * np.asarray(sr[key.split("_")[0] + "_exact"])
                axes[row, 0].plot(t, h, color=color, ls=ls, lw=1.0, label=f"{label} (L2 {e[err]:.2%})")
                axes[row, 1].plot(t, h - x, color=color, ls=ls, lw=0.9, label=label)
        for row in range(2):
            for arrival in 1e3 * exact.arrivals(prm["L"] * (1 - row), prm["t_end"]):
                axes[row, 1].axvspan(arrival - 1e3 * prm["exclude"], arrival + 1e3 * prm["exclude"], color="0.9",
                                     lw=0)
        axes[0, 0].set_ylabel("top displacement u_y(L) [um]")
        axes[1, 0].set_ylabel("base pressure p(0) [Pa]")
        axes[0, 1].set_ylabel("u_y(L) - exact [um]")
        axes[1, 1].set_ylabel("p(0) - exact [Pa]")
        axes[1, 0].axhline(2 * prm["undrained_pressure"], color="grey", lw=0.7, ls=":")
        for ax in axes[1]:
            ax.set_xlabel("t [ms]")
        for ax in axes.ravel():
            ax.grid(alpha=0.3)
        low, high = axes[0, 0].get_ylim()
        axes[0, 0].set_ylim(low, high + 0.35 * (high - low))  # room for the legend above the curves
        axes[0, 0].legend(fontsize=7, loc="upper right", ncol=2)
        axes[1, 0].legend(fontsize=7, loc="center right")
        axes[0, 1].set_title("grey bands: +-exclude around the fronts (left out of the L2 errors)", fontsize=8)
        what = f"{prm['ny']} nodes along the height" if study == "rules" else "NSNI under refinement"
        fpp = ", RKPM with the pressure projection (fpp)" if prm.get("fpp") else ""
        fig.suptitle(f"Saturated column under a step load, {what} (fast wave {prm['fast_speed']:.0f} m/s){fpp}")
        files.append(_cli.save(fig, out / name))
    return files


CLAIMS = [
    Claim("Fig 6.5: NSNI top displacement within 5 % (L2 over the history) of the exact solution",
          run="rkpm-nsni", info={"study": "rules"}, key="u_top_l2", op="<", bound=0.05),
    Claim("Fig 6.5: NSNI base pressure within 5 % (L2 over the history) of the exact solution",
          run="rkpm-nsni", info={"study": "rules"}, key="p_base_l2", op="<", bound=0.05),
    Claim("Fig 6.5: DNI's base pressure is visibly worse than NSNI's at 241 nodes (error ratio > 3)",
          run="rkpm-dni", info={"study": "rules"}, key="p_base_l2", op=">", bound=3.0,
          over=("rkpm-nsni", {"study": "rules"}), full_only=True),
    Claim("Fig 6.5: DNI's top displacement is worse than NSNI's (error ratio > 2)",
          run="rkpm-dni", info={"study": "rules"}, key="u_top_l2", op=">", bound=2.0,
          over=("rkpm-nsni", {"study": "rules"})),
    Claim("Taylor-Hood with the trapezoid: base pressure within 5 % of the exact solution",
          run="fem-taylor-hood", key="p_base_l2", op="<", bound=0.05),
    Claim("Fig 6.6: NSNI converges, top-displacement rate > 1 from 61 to 121 nodes",
          run="rkpm-nsni ny=121", key="rate_u_top_l2", op=">", bound=1.0),
    Claim("Fig 6.6: NSNI converges, base-pressure rate > 1 from 61 to 121 nodes",
          run="rkpm-nsni ny=121", key="rate_p_base_l2", op=">", bound=1.0),
    Claim("Fig 6.6: NSNI keeps converging, base-pressure rate > 1.5 from 241 to 481 nodes",
          run="rkpm-nsni ny=481", key="rate_p_base_l2", op=">", bound=1.5, full_only=True),
]


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point (see the module docstring)."""
    return _cli.main(NAME, __doc__, PARAMS, run, plot, argv, QUICK, checkpoints=True)


if __name__ == "__main__":
    sys.exit(main())
