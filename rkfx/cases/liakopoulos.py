"""Liakopoulos' drainage column: unsaturated u-p RKPM on NSNI beside the Taylor-Hood FEM
baseline (§6.4.2, Figs 6.7-6.9).

Problem. A column of sand W x L = 0.1 x 1 m, saturated, with water flowing down through it
at unit gradient (p = 0 everywhere: gravity alone drives the flow). At t = 0 the supply on
the top stops; the water drains through the base and the column desaturates from the top:

    top    (y = L)   traction-free, no flow
    bottom (y = 0)   u_y = 0, p = 0 (drains to the atmosphere)
    sides            u_x = 0, no flow

Equations (6.15)-(6.16) with zero air pressure (s = -p), Bishop's stress alpha S_w p, the
storage 1/Q of (6.7) and Darcy's law with k_rw (``rkfx.models.unsaturated_poroelasticity``);
the displacement is measured from the initial state, whose effective stress balances gravity.
Material (the seed's, after Khoei & Mohammadnejad 2011): E = 1.3 MPa, nu = 0.4, rho_s = 2000,
rho_w = 1000 kg/m^3, n = 0.2975, intrinsic permeability 4.5e-13 m^2, mu_w = 1e-3 Pa s,
K_s = 1e12 Pa, K_w = 2e9 Pa, g = 9.806 m/s^2. Retention: the seed's (6.80)-(6.81),
S_w = 1 - 0.10152 (s / gamma_w)^2.4279 and k_rw = 1 - 2.207 (1 - S_w) with gamma_w = 9806 N/m^3
(``--set retention=lewis-schrefler`` takes the form of Lewis & Schrefler 1998, gamma_w = 1e4
and exponent 1.0121 on k_rw; about 5 % apart in 1 - S_w). Heights are measured from the base.

Methods, on the same grid of ``ny`` nodes along the height (spacing h = L / (ny - 1), W / h + 1
across), both stepped by backward Euler with Newton (exact Jacobians) through ``rkfx.solvers``
on the same step times (first step ``first_step``, growing by 1.2 up to ``max_step``, hitting
every output time):

* RKPM: linear RK (a = 2 h), NSNI with the variationally consistent correction (or another
  rule of ``rkfx.integration.nodal_stabilized.RULES``), equal order u-p, collocated essential
  conditions;
* FEM: Taylor-Hood Q2-Q1 on the quadrilaterals of the same grid (``fem_baselines.unsaturated``).

An explicit step (eqs. 6.37-6.41) would be bounded by the undrained wave, h / c_fast with
c_fast ~ 2000 m/s here, i.e. some 5e8 steps for the two hours; the drainage is slow, so the
implicit steps are the practical choice. results.json reports that count.

Measures: the pressure profiles on the axis (at the heights of the grid rows) at 5, 10, 20, 30, 60 and 120 min (Fig 6.8), the
pressure histories at y = 0.625 and 0.975 m (Fig 6.9) and the settlement of the top. With
both methods: at every output time the largest difference of the RKPM profile from the FEM
one, relative to the FEM pressure range then; the settlement difference at the end. The
refinement study runs RKPM at ``refine_ny`` and compares each with the FEM run.

Under ``mpiexec`` both are distributed: the FEM on dolfinx's mesh partition, the RKPM model on
an RCB split of the particles (each rank integrates over its own nodes' cells and collocates at
its own boundary nodes; the samples are summed over the ranks; one checkpoint per rank).

Steady state (``steady``, on by default): both methods are also marched to the column's
drained rest (no flow: dp/dy = -S_w rho_w g) by pseudo-time continuation
(``rkfx.solvers.steady``), RKPM at ``ny`` and every ``refine_ny``, FEM at ``ny``, against the
exact quadrature of ``verification.drained_column``: the largest pressure error on the axis
relative to the top's suction, the settlement's relative error, RKPM's observed rates, and the
figure steady.png.

The seed compares with Liakopoulos' measurements and with other codes' FEM results; neither is
reproduced here, the comparison is RKPM against this FEM on the same equations.

Parameters and units (``--set NAME=VALUE``): E [Pa], nu [-], rho_s, rho_w [kg/m^3], porosity [-],
permeability [m^2], viscosity [Pa s], K_s, K_w [Pa], gravity [m/s^2], W, L [m], retention
(seed | lewis-schrefler), ny [count], refine_ny (list), rule, output_min (list) [min],
probes (list) [m], first_step, max_step [s], steady [bool].

    python -m rkfx.cases.liakopoulos [--quick] [--method rkpm|fem|both] [--set NAME=VALUE] [--out DIR]
        [--checkpoint-every N] [--resume DIR]
"""
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from rkfx.approximation.semi_lagrangian import evaluate_moving
from rkfx.assembly.weighted_forms import placed
from rkfx.cases import _cli, _preflight
from rkfx.cases._cli import Param, Results, Run
from rkfx.cases._confined_column import column_discretization
from rkfx.cases._nodal_up import owned, split_over_ranks, whole_unknowns
from rkfx.conditions import Displacement, Pressure
from rkfx.errors import InputError
from rkfx.integration.nodal_stabilized import RULES
from rkfx.materials.retention import Liakopoulos
from rkfx.models.explicit_poroelasticity import Constituents, collocation_rows
from rkfx.models.unsaturated_poroelasticity import UnsaturatedBiotModel, UnsaturatedSoil
from rkfx.report.claims import Claim
from rkfx.solvers.integrate import integrate, time_grid
from rkfx.solvers.model import Constraints
from rkfx.solvers.newmark import backward_euler
from rkfx.solvers.steady import steady_state
from verification.drained_column import drained_column

NAME = "liakopoulos"

RETENTION = {"seed": Liakopoulos(), "lewis-schrefler": Liakopoulos.lewis_schrefler()}

PARAMS = {
    "E": Param(1.3e6, "drained Young's modulus [Pa]"),
    "nu": Param(0.4, "drained Poisson's ratio [-]"),
    "rho_s": Param(2000.0, "grain density [kg/m^3]"),
    "rho_w": Param(1000.0, "water density [kg/m^3]"),
    "porosity": Param(0.2975, "porosity n [-]"),
    "permeability": Param(4.5e-13, "intrinsic permeability [m^2]"),
    "viscosity": Param(1.0e-3, "dynamic viscosity of water [Pa s]"),
    "K_s": Param(1.0e12, "grain bulk modulus [Pa]"),
    "K_w": Param(2.0e9, "water bulk modulus [Pa]"),
    "gravity": Param(9.806, "gravitational acceleration [m/s^2]"),
    "W": Param(0.1, "width of the column [m]"),
    "L": Param(1.0, "height of the column [m]"),
    "retention": Param("seed", "retention law: seed (6.80-6.81) or lewis-schrefler"),
    "ny": Param(41, "nodes along the height of the comparison [count]"),
    "refine_ny": Param([21, 81], "further RKPM resolutions, compared with the FEM run [count]", fingerprint=False),
    "rule": Param("nsni", "nodal integration rule of RKPM"),
    "output_min": Param([5.0, 10.0, 20.0, 30.0, 60.0, 120.0], "profile times [min]"),
    "probes": Param([0.625, 0.975], "heights of the pressure histories [m]"),
    "first_step": Param(1.0, "first time step [s]"),
    "max_step": Param(30.0, "largest time step [s]"),
    "steady": Param(True, "also march to the drained steady state and compare it with the exact one [bool]",
                    fingerprint=False),
}
QUICK = {"ny": 21, "refine_ny": [41], "output_min": [5.0, 10.0, 20.0, 30.0, 60.0]}


def _soil(E, nu, rho_s, rho_w, porosity, permeability, viscosity, K_s, K_w, gravity, retention) -> UnsaturatedSoil:
    medium = Constituents(E=E, nu=nu, rho_s=rho_s, rho_f=rho_w, porosity=porosity, k=permeability / viscosity,
                          K_s=K_s, K_f=K_w)
    return UnsaturatedSoil(medium, RETENTION[retention], gravity)


def check(*, E, nu, rho_s, rho_w, porosity, permeability, viscosity, K_s, K_w, gravity, W, L, retention, ny,
          refine_ny, rule, output_min, probes, first_step, max_step, steady=True, **_) -> None:
    """Raise InputError for a parameter outside its documented range (the CLI calls this before any work)."""
    if retention not in RETENTION:
        raise InputError(f"unknown retention {retention!r}; choose from {', '.join(RETENTION)}")
    for name, v in (("permeability", permeability), ("viscosity", viscosity), ("W", W), ("L", L),
                    ("first_step", first_step), ("max_step", max_step)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r} must be positive")
    _soil(E, nu, rho_s, rho_w, porosity, permeability, viscosity, K_s, K_w, gravity, retention)
    if rule not in RULES:
        raise InputError(f"unknown nodal rule {rule!r}; choose from {', '.join(RULES)}")
    for name, v in [("ny", ny)] + [("refine_ny", v) for v in refine_ny]:
        if int(v) != v or v < 6:
            raise InputError(f"{name} = {v!r}: need a whole number of at least 6 nodes along the height")
        if abs((v - 1) * W / L - round((v - 1) * W / L)) > 1e-9 or round((v - 1) * W / L) < 2:
            raise InputError(f"{name} = {v!r}: (ny - 1) W / L must be a whole number of at least 2 spacings across "
                             f"the column (W / L = {W / L:.4g}); e.g. ny = {int(round(L / W)) * 4 + 1}")
    if not output_min or min(output_min) <= 0:
        raise InputError(f"output_min = {output_min!r}: give positive output times in minutes")
    for y in probes:
        if not 0 <= y <= L:
            raise InputError(f"probe height {y!r} m lies outside the column [0, {L}]")
    if not isinstance(steady, (bool, np.bool_)):
        raise InputError(f"steady = {steady!r} must be true or false")


def memory_need(methods, *, ny, refine_ny, W, L, **_) -> _preflight.Need:
    """Peak memory of the largest grid."""
    n = max([ny] + list(refine_ny))
    nodes = n * (round((n - 1) * W / L) + 1)
    return _preflight.poro_need(methods, nodes, f"ny={n}", "lower ny or refine_ny")


def _grid(W, L, ny) -> tuple[int, int]:
    return int(round((ny - 1) * W / L)) + 1, int(ny)


def _points(W, L, probes, ny) -> np.ndarray:
    """Sample points: the axis profile at the heights of the ``ny`` grid rows (FEM's pressure
    vertices, where P1 carries no interpolation error of its own), then the probes, then the
    top of the axis."""
    ys = np.linspace(0.0, L, ny)
    y = np.r_[ys, probes, L]
    return np.column_stack([np.full(len(y), 0.5 * W), y])


class _Samples:
    """[p at the points..., u_y at the top] after every accepted step (checkpointed)."""

    def __init__(self, sample):
        self.sample, self.t, self.rows = sample, [], []

    def record(self, s) -> None:
        self.t.append(s.t)
        self.rows.append(self.sample(s.x))

    def arrays(self) -> dict[str, np.ndarray]:
        return {"t": np.array(self.t), "rows": np.array(self.rows)}

    def restore(self, arrays) -> None:
        self.t, self.rows = list(arrays["t"]), list(arrays["rows"])


def rkpm_column(soil, W, L, ny, rule, points, comm=None):
    """The RKPM model of the column (distributed on ``comm`` of several ranks) and the
    sampler of [p at ``points``..., u_y at the last one] of its state."""
    d = column_discretization(W, L, *_grid(W, L, ny), rule, comm=comm)
    n = d.particles.num_nodes
    size = 3 * n
    G = sp.vstack([collocation_rows(d.rk, owned(d, d.bottom), 1, n, 0, size),
                   collocation_rows(d.rk, owned(d, d.sides), 0, n, 0, size),
                   collocation_rows(d.rk, owned(d, d.bottom), None, n, 2 * n, size)]).tocsr()
    nearest = cKDTree(d.particles.x).query(points)[1]
    rows = evaluate_moving(d.rk, points, nearest).matrix().tocsr()
    # [p at the points..., u_y at the last one] over the whole vector
    rows = sp.vstack([placed(rows[:-1], size, 2 * n), placed(rows[-1:], size, 1, 2)]).tocsr()
    local, (G,), sample = split_over_ranks(d, comm, [G], rows)
    return UnsaturatedBiotModel(d.rule, soil, Constraints(G, np.zeros(G.shape[0])), local), sample


def _rkpm(soil, W, L, ny, rule, times, points, io):
    t0 = time.perf_counter()
    comm = _cli.comm()
    model, sample = rkpm_column(soil, W, L, ny, rule, points, comm)
    rec = _Samples(sample)
    st = backward_euler()
    out = integrate(st, model, times, start=st.start(model), recorder=rec, comm=comm,
                    progress=lambda it: _cli.progress(it, f"rkpm-{rule} ny={ny}", len(times) - 1), **io)
    return rec, time.perf_counter() - t0, {"unknowns": whole_unknowns(model), "newton_iterations": out.newton_iterations, "cuts": out.cuts,
                                           "steps": len(times) - 1}


def fem_column(soil, W, L, ny, points, comm=None):
    """The Taylor-Hood model of the column on the same grid and its sampler (as ``rkpm_column``)."""
    import dolfinx_solver  # noqa: F401, PLC0415

    from fem_baselines.poroelasticity import _Sampler, rectangle_mesh  # noqa: PLC0415
    from fem_baselines.unsaturated import FemUnsaturatedModel  # noqa: PLC0415

    nx, ny = _grid(W, L, ny)
    mesh = rectangle_mesh(np.linspace(0.0, W, nx), np.linspace(0.0, L, ny), "quadrilateral", comm=comm)
    bcs = [Displacement("bottom", components=(1,)), Displacement("left", components=(0,)),
           Displacement("right", components=(0,)), Pressure("bottom")]
    model = FemUnsaturatedModel(mesh, soil, bcs)
    sampler = _Sampler(mesh, points)

    def sample(x):
        model.assign(x, model.uh, model.ph)
        p, u = sampler(model.uh, model.ph)
        return np.r_[p[:-1], u[-1, 1]]

    return model, sample


def _fem(soil, W, L, ny, times, points, io):
    t0 = time.perf_counter()
    model, sample = fem_column(soil, W, L, ny, points, _cli.comm())
    rec = _Samples(sample)
    st = backward_euler()
    out = integrate(st, model, times, start=st.start(model), recorder=rec, comm=_cli.comm(),
                    progress=lambda it: _cli.progress(it, "fem-taylor-hood", len(times) - 1), **io)
    return rec, time.perf_counter() - t0, {"unknowns": model.layout.size, "newton_iterations": out.newton_iterations, "cuts": out.cuts,
                                           "steps": len(times) - 1}


def _series(rec: _Samples, times_s: np.ndarray, n_profile: int, n_probes: int) -> dict:
    t = np.r_[0.0, rec.t]
    rows = np.vstack([np.zeros(len(rec.rows[0])), np.array(rec.rows)])
    at = [int(np.argmin(np.abs(t - s))) for s in times_s]
    return {"t": t, "profiles": rows[at, :n_profile], "probes": rows[:, n_profile:n_profile + n_probes],
            "settlement": -rows[:, -1]}


def run(*, methods: Sequence[str] = ("rkpm", "fem"), E=1.3e6, nu=0.4, rho_s=2000.0, rho_w=1000.0, porosity=0.2975,
        permeability=4.5e-13, viscosity=1.0e-3, K_s=1.0e12, K_w=2.0e9, gravity=9.806, W=0.1, L=1.0,
        retention="seed", ny=41, refine_ny=(21, 81), rule="nsni", output_min=(5.0, 10.0, 20.0, 30.0, 60.0, 120.0),
        probes=(0.625, 0.975), first_step=1.0, max_step=30.0, steady=True, checkpoint_every=0, work_dir=None,
        resume=None) -> Results:
    """The comparison at ``ny`` and the RKPM refinement; see the module docstring."""
    prm = dict(E=E, nu=nu, rho_s=rho_s, rho_w=rho_w, porosity=porosity, permeability=permeability,
               viscosity=viscosity, K_s=K_s, K_w=K_w, gravity=gravity, W=W, L=L, retention=retention, ny=ny,
               refine_ny=list(refine_ny), rule=rule, output_min=list(output_min), probes=list(probes),
               first_step=first_step, max_step=max_step)
    check(**prm, steady=steady)
    soil = _soil(E, nu, rho_s, rho_w, porosity, permeability, viscosity, K_s, K_w, gravity, retention)
    mat = soil.medium.material
    c_fast = float(np.sqrt((mat.elastic.constrained_modulus + mat.alpha ** 2 / mat.S) / soil.medium.density))
    out_s = 60.0 * np.sort(np.asarray(output_min, float))
    times = time_grid(out_s, first_step, growth=1.2, max_step=max_step)
    points = _points(W, L, probes, ny)
    h = L / (ny - 1)
    results = Results(NAME, {**prm, "c_fast": c_fast, "explicit_step": h / c_fast,
                             "explicit_steps_needed": float(out_s[-1] * c_fast / h)})
    ck = _cli.Checkpoints(checkpoint_every, work_dir, resume)
    jobs = []
    if "fem" in methods:
        jobs.append(("fem-taylor-hood", "comparison", ny))
    if "rkpm" in methods:
        jobs.append((f"rkpm-{rule}", "comparison", ny))
        jobs += [(f"rkpm-{rule} ny={n}", "refinement", n) for n in refine_ny]
    for label, study, n in jobs:
        with _cli.model_run(label):
            if label.startswith("fem"):
                rec, wall, info = _fem(soil, W, L, n, times, points, ck.for_run(label))
            else:
                rec, wall, info = _rkpm(soil, W, L, n, rule, times, points, ck.for_run(label))
        results.runs.append(Run(label, wall, info.pop("unknowns"), series=_series(rec, out_s, ny, len(probes)),
                                info={"study": study, "ny": n, **info}))
    fem = next((r for r in results.runs if r.method == "fem-taylor-hood"), None)
    if fem is not None:
        f = fem.series
        for r in results.runs:
            if r is fem:
                continue
            s = r.series
            span = f["profiles"].max(axis=1) - f["profiles"].min(axis=1)
            diff = np.abs(s["profiles"] - f["profiles"]).max(axis=1) / span
            for minutes, d in zip(sorted(output_min), diff):
                r.errors[f"profile_{minutes:g}min"] = float(d)
            r.errors["profile_max"] = float(diff.max())
            r.errors["settlement_end"] = float(abs(s["settlement"][-1] - f["settlement"][-1]) / abs(f["settlement"][-1]))
            r.errors["probes_max"] = float(np.abs(s["probes"] - f["probes"]).max() / np.abs(f["probes"]).max())
    if steady:
        _steady_study(results, soil, methods, W, L, ny, refine_ny, rule, first_step)
    return results


def _steady_study(results: Results, soil: UnsaturatedSoil, methods, W, L, ny, refine_ny, rule, first_step) -> None:
    """The drained steady state (t -> infinity: no flow, dp/dy = -S_w rho_w g) by pseudo-time
    continuation (``rkfx.solvers.steady``) against its exact quadrature
    (``verification.drained_column``): RKPM at every resolution, FEM at ``ny``."""
    exact = drained_column(soil, L)
    jobs = [("fem-taylor-hood steady", ny)] if "fem" in methods else []
    if "rkpm" in methods:
        jobs += [(f"rkpm-{rule} steady ny={n}", n) for n in sorted({ny, *refine_ny})]
    for label, n in jobs:
        ys = np.linspace(0.0, L, n)
        points = np.vstack([np.column_stack([np.full(n, 0.5 * W), ys]), [[0.5 * W, L]]])
        t0 = time.perf_counter()
        with _cli.model_run(label):
            comm = _cli.comm()
            model, sample = (fem_column(soil, W, L, n, points, comm) if label.startswith("fem")
                             else rkpm_column(soil, W, L, n, rule, points, comm))
            done = steady_state(model, first_step, comm=comm)
        values = sample(done.state.x)
        p_exact = np.interp(ys, exact.y, exact.p)
        scale = abs(exact.p[-1])
        results.runs.append(Run(label, time.perf_counter() - t0, whole_unknowns(model),
                                series={"y": ys, "p": values[:-1], "p_exact": p_exact},
                                errors={"p_max": float(np.abs(values[:-1] - p_exact).max() / scale),
                                        "settlement": float(abs(values[-1] - exact.top_displacement)
                                                            / abs(exact.top_displacement))},
                                info={"study": "steady", "ny": n, "steps": done.run.steps,
                                      "newton_iterations": done.run.newton_iterations, "cuts": done.run.cuts,
                                      "pseudo_time": float(done.times[-1]), "top_suction": scale,
                                      "top_saturation": float(exact.saturation[-1]),
                                      "top_displacement": float(values[-1]),
                                      "top_displacement_exact": exact.top_displacement}))
    rk = sorted((r for r in results.runs if r.info["study"] == "steady" and r.method.startswith("rkpm")),
                key=lambda r: r.info["ny"])
    for coarse, fine in zip(rk, rk[1:]):
        ratio = (fine.info["ny"] - 1) / (coarse.info["ny"] - 1)
        for key in ("p_max", "settlement"):
            fine.errors[f"rate_{key}"] = float(np.log(coarse.errors[key] / fine.errors[key]) / np.log(ratio))


def plot(results: Results, out: Path) -> list[Path]:
    """Pressure profiles (Fig 6.8) beside RKPM's differences from FEM, the probe histories
    (Fig 6.9) and the settlement."""
    plt = _cli.pyplot()
    prm = results.params
    runs = [r for r in results.runs if r.info["study"] == "comparison"]
    if not runs:
        return []
    fig, axes = plt.subplots(2, 2, figsize=(13, 10), layout="constrained")
    (a_prof, a_diff), (a_hist, a_set) = axes
    ys = np.linspace(0.0, prm["L"], prm["ny"])
    minutes = sorted(prm["output_min"])
    shades = plt.cm.viridis(np.linspace(0.0, 0.85, len(minutes)))
    fem = next((r for r in runs if r.method.startswith("fem")), None)
    for r in runs:
        is_fem = r is fem
        style = dict(ls="--", lw=2.6, alpha=0.4) if is_fem else dict(ls="-", lw=1.1)
        s = r.series
        for i, m in enumerate(minutes):
            a_prof.plot(1e-3 * np.asarray(s["profiles"][i]), ys, color=shades[i], **style,
                        label=None if is_fem else f"{m:g} min")
        t = np.asarray(s["t"]) / 60.0
        for j, y in enumerate(prm["probes"]):
            a_hist.plot(t, 1e-3 * np.asarray(s["probes"])[:, j], color=f"C{j}", **style,
                        label=f"{r.method}, y = {y:g} m")
        a_set.plot(t, 1e3 * np.asarray(s["settlement"]), color="k" if is_fem else "C3", **style, label=r.method)
    transient = [r for r in results.runs if r.info["study"] != "steady"]
    compared = fem is not None and any(r is not fem for r in transient)
    if compared:
        ref = np.asarray(fem.series["profiles"])
        for r in transient:
            if r is fem:
                continue
            d = np.asarray(r.series["profiles"]) - ref
            refined = r.info["study"] == "refinement"
            for i, m in enumerate(minutes):
                a_diff.plot(d[i], ys, color=shades[i], ls=":" if refined else "-", lw=1.1,
                            label=(f"{m:g} min" if not refined else None))
            if refined:
                a_diff.plot([], [], color="0.4", ls=":", label=f"{r.method} (dotted)")
        rk = next((r for r in runs if r is not fem), None)
        if rk is not None:
            a_diff.set_title(f"RKPM - FEM ({fem.method}, {fem.info['ny']} nodes): at most "
                             f"{rk.errors['profile_max']:.2%} of the pressure range", fontsize=9)
        a_diff.axvline(0.0, color="k", lw=0.6)
        a_diff.set_xlabel("p_RKPM - p_FEM [Pa]")
        a_diff.set_ylabel("height y [m]")
        a_diff.legend(fontsize=8)
    else:  # one method only: nothing to difference
        a_diff.text(0.5, 0.5, "RKPM - FEM: both methods are needed\n(--method both)", ha="center", va="center",
                    fontsize=11, color="0.4", transform=a_diff.transAxes)
        a_diff.set_axis_off()
    a_prof.set_xlabel("water pressure p [kPa]")
    a_prof.set_ylabel("height y [m]")
    a_prof.set_title("profiles on the axis (thin RKPM, broad dashed FEM)", fontsize=9)
    a_prof.legend(fontsize=8, loc="lower left")
    a_hist.set_xlabel("t [min]")
    a_hist.set_ylabel("water pressure p [kPa]")
    a_hist.set_title("pressure histories at the probes (heights from the base)", fontsize=9)
    a_hist.legend(fontsize=8)
    a_set.set_xlabel("t [min]")
    a_set.set_ylabel("settlement of the top [mm]")
    a_set.legend(fontsize=8)
    for ax in (a_prof, a_hist, a_set) + ((a_diff,) if compared else ()):
        ax.grid(alpha=0.3)
    fig.suptitle(f"Liakopoulos drainage column, {prm['ny']} nodes along the height ({prm['retention']} retention)")
    figures = [_cli.save(fig, out / "drainage.png")]
    steady = [r for r in results.runs if r.info["study"] == "steady"]
    if steady:
        figures.append(_plot_steady(plt, steady, prm, out))
    return figures


def _plot_steady(plt, runs, prm, out: Path) -> Path:
    """The drained steady state: profiles against the exact one, and each run's error."""
    fig, (a_p, a_e) = plt.subplots(1, 2, figsize=(12, 6), layout="constrained")
    finest = max(runs, key=lambda r: r.info["ny"])
    a_p.plot(1e-3 * np.asarray(finest.series["p_exact"]), finest.series["y"], color="k", lw=3.0, alpha=0.3,
             label="exact (quadrature)")
    for i, r in enumerate(sorted(runs, key=lambda r: (r.method.startswith("rkpm"), r.info["ny"]))):
        y, p, pe = (np.asarray(r.series[k]) for k in ("y", "p", "p_exact"))
        fem = r.method.startswith("fem")
        style = dict(color="k", ls="--", lw=1.4) if fem else dict(color=f"C{i}", lw=1.1)
        a_p.plot(1e-3 * p, y, **style, label=f"{r.method}")
        a_e.plot((p - pe) / r.info["top_suction"], y, **style,
                 label=f"{r.method}: max {r.errors['p_max']:.1e}, settlement {r.errors['settlement']:.1e}")
    a_p.set_xlabel("water pressure p [kPa]")
    a_p.set_ylabel("height y [m]")
    a_p.set_title(f"no flow: dp/dy = -S_w rho_w g; top S_w = {finest.info['top_saturation']:.3f}", fontsize=9)
    a_e.axvline(0.0, color="k", lw=0.6)
    a_e.set_xlabel("(p - p_exact) / |p_exact(L)|")
    a_e.set_title("error on the axis, and relative error of the top's settlement", fontsize=9)
    for ax in (a_p, a_e):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Liakopoulos column drained to its steady state (pseudo-time continuation, backward Euler)")
    return _cli.save(fig, out / "steady.png")


CLAIMS = [
    Claim("Fig 6.8: the RKPM profile at 60 min lies within 5 % of the FEM baseline (of the pressure range)",
          run="rkpm-nsni", info={"study": "comparison"}, key="profile_60min", op="<", bound=0.05),
    Claim("Fig 6.8: the RKPM profile at 120 min lies within 5 % of the FEM baseline (of the pressure range)",
          run="rkpm-nsni", info={"study": "comparison"}, key="profile_120min", op="<", bound=0.05, full_only=True),
    Claim("RKPM settlement at the end within 5 % of the FEM baseline",
          run="rkpm-nsni", info={"study": "comparison"}, key="settlement_end", op="<", bound=0.05),
    Claim("Drained steady state: the RKPM profile at 41 rows within 1e-4 of the top suction of the exact one",
          run="rkpm-nsni steady ny=41", info={"study": "steady"}, key="p_max", op="<", bound=1e-4),
    Claim("Drained steady state: the RKPM profile converges at a rate above 1.5 from 21 to 41 rows",
          run="rkpm-nsni steady ny=41", info={"study": "steady"}, key="rate_p_max", op=">", bound=1.5),
]


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point (see the module docstring)."""
    return _cli.main(NAME, __doc__, PARAMS, run, plot, argv, QUICK, checkpoints=True)


if __name__ == "__main__":
    sys.exit(main())
