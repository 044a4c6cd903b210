"""Dynamic crack branching by the damage particle method (seed 4.3.3, Fig 4.17-4.19).

Problem (Fig 4.17). A pre-notched plate [0, 0.1] x [0, 0.04] m with an edge crack along
y = a2 = 0.02 m from the left edge to x = a1 = 0.05 m. A uniform tensile traction
sigma = 1 MPa acts on the top (+y) and bottom (-y) edges from t = 0 (a step, then held). The
loads are self-equilibrated, so there are no displacement conditions: the explicit dynamics
carries the free body. Soda-lime glass: E = 3.2e10 Pa, nu = 0.2, rho = 2450 kg/m^3,
f_t = 2.72e6 Pa, G_F = 3 N/m, plane strain (``plane=stress`` for the thin-plate reading). The
crack runs from the tip to the right and splits into two major branches that reach the right
edge.

Model. As ``rkfx.cases.kalthoff``: a tensor grid of nx x ny particles whose rectangular
Voronoi cells (``rkfx.geometry.grid_cells``) have faces on the crack (nx and ny even, so x = a1 and
y = a2 are midlines between particle columns and rows and the crack tip is a cell corner);
the grid sizes are the even numbers whose spacing is nearest to each requested ``h``. RK shape
functions with the crack by diffraction (linear basis, cubic B-spline kernel, support 1.75 h:
the crack mouth at the free edge x = 0 needs more than 1.5 h, see ``kalthoff``), SCNI
smeared strains with the MSCNI stabilization (weight ``eps_p``; ``rkfx.models.damage_dynamics``
explains why dynamics needs it: with plain SCNI the 0.4 mm model grows a central crack
between the two branches and striped damage), the damage law (4.2) with Mazars' equivalent strain, the regularization
kappa_c = (G_F / f_t) A_L / V_L (4.28) and particle tracking (4.22) with tol = 0.5; the
particles within 0.75 h of the crack tip are the seeds. The traction load is the RK boundary
integral f_I = sum over the top and bottom half-segments of N_I(midpoint) t length
(``rkfx.assembly.boundary.traction_load``, SCNI's one-point rule). Central differences
(``rkfx.solvers.central_difference``) with the lumped mass and dt = 0.5 h / c_d
(``rkfx.assembly.smeared_strain``) to ``t_end`` = 80 microseconds.

Studies (``h`` lists nominal spacings [m]):

* ``rkpm-dpm``: the damage particle method at every ``h`` (Fig 4.18, 4.19b);
* ``rkpm-dpm-unregularized``: a constant kappa_c = G_F / (f_t h_0), h_0 the spacing of the
  coarsest model, at ``unregularized_h`` (Fig 4.19a).

* ``rkpm-dpm-nonlocal``: the damage history driven by the nonlocal equivalent strain over the
  radius ``nonlocal_radius`` (``rkfx.fracture.nonlocal_average``: kappa_c of a band of physical
  width, failed particles and the notch cut the averages), at ``nonlocal_h``;

* ``fem-crack-band``: linear triangles with a crack band and the same damage law, lumped mass,
  central differences and consistent edge tractions (``fem_baselines.crack_band_dynamics``),
  at element sizes ``fem_h``; no tracking.

Metrics per run: ``branches``, the number of major branches (``count_branches`` across every
grid column in x = 0.08-0.095 m; the most frequent nonzero count, ties to the larger),
``branch_x`` [m], the smallest x > a1 where a column is crossed by two or more separate
cracks (where the crack first splits; NaN if it never does), ``most_cracks``, the most separate
cracks that run side by side over at least 5 mm of x anywhere beyond a1 (``_dynamic_fracture.most_cracks``:
arrested branches and a central crack count, short spurs do not), ``tip_x`` [m], the largest x
of the cracked particles (crack opening w / w_c >= 0.5, ``_dynamic_fracture``),
``dissipated_end`` [J/m] with its history and the share spent in the cracked particles
(``dissipated_in_cracks``), ``released_end`` [J/m] (the internal work less the strain energy
still stored: what the damage took out of the discrete solid; with the local law more than
``dissipated_end``, the law's sum V_L phi(kappa_L), docs/fracture.md), and ``energy_error``
(max |energy balance| / max energy). A summary run per study maps h to branches and final dissipation
and gives ``dissipation_change_fine``, |W_d(finest) - W_d(second finest)| / W_d(finest).

Parameters (``--set NAME=VALUE``, SI units): E, nu, rho, ft, GF, sigma, plane, t_end, tol, h,
unregularized_h, fem_h, support_factor, courant, radius, forward, eps_p, nonlocal_h, nonlocal_radius. Long runs:
``--checkpoint-every N`` writes each model's state every N steps to OUT/checkpoints/, and
``--resume DIR`` continues an interrupted invocation (finished models are read back). A resume
with other parameters is refused in one line (``--recompute`` computes the runs again). Under
``mpiexec`` the RKPM and the crack-band FEM models are distributed over the ranks
(``rkfx.models.damage_ranks``: the serial damage bit for bit).

    python -m rkfx.cases.crack_branching [--quick] [--method rkpm|fem|both] [--set NAME=VALUE] [--out DIR] [--vtk]

With ``--vtk`` every model writes 21 frames (20 evenly spaced and the end) to OUT/vtk/: damage,
crack opening w / w_c, displacement and velocity at the particles and on their cells
(``<run>_particles.pvd``, ``<run>_cells.pvd``), and per element and vertex of the crack-band
meshes (``fem-crack-band_<size>.pvd``); about 0.5 MB per frame per 3,600 particles.
"""
import sys
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rkfx.fracture import damage as dm
from rkfx.assembly.boundary import boundary_quadrature, traction_load
from rkfx.conditions import Traction
from rkfx.fracture.tracking import check_tracking, tracking
from rkfx.assembly.smeared_strain import check_eps_p
from rkfx.errors import InputError
from rkfx.models.damage_dynamics import DamageRun
from rkfx.cases import _cli, _paraview, _preflight
from rkfx.cases import _dynamic_fracture as dyn
from rkfx.cases._cli import Param, Results, Run
from rkfx.report.claims import Claim

NAME = "crack_branching"
LX, LY, A1, A2 = 0.1, 0.04, 0.05, 0.02
BRANCH_WINDOW = (0.08, 0.095)  # columns where the branches are counted [m]
SIDE_BY_SIDE = 5e-3  # x extent over which cracks must run side by side to count in most_cracks [m]

PARAMS = {
    "E": Param(3.2e10, "Young's modulus [Pa]"),
    "nu": Param(0.2, "Poisson's ratio [-]"),
    "rho": Param(2450.0, "density [kg/m^3]"),
    "ft": Param(2.72e6, "tensile strength f_t [Pa]"),
    "GF": Param(3.0, "fracture energy G_F [N/m]"),
    "sigma": Param(1.0e6, "traction on the top and bottom edges, a step at t = 0 [Pa]"),
    "plane": Param("strain", "2-D idealization: strain or stress"),
    "t_end": Param(80e-6, "end time [s]"),
    "tol": Param(0.5, "particle tracking tolerance of (4.22) [-], in (0, 1]"),
    "h": Param([8e-4, 4e-4, 2e-4], "nominal nodal spacings of the regularized models [m]"),
    "unregularized_h": Param([8e-4, 4e-4, 2e-4], "nominal nodal spacings of the constant-kappa_c models [m]"),
    "fem_h": Param([8e-4, 4e-4, 2e-4], "element sizes of the crack-band finite element baseline [m]",
                   fingerprint=False),
    "support_factor": Param(1.75, "RK support radius / nodal spacing [-] (>= 1.6: see rkfx.cases.kalthoff)"),
    "courant": Param(0.5, "dt = courant * h / c_d [-], in (0, 1]"),
    "radius": Param(3.5, "tracking neighbourhood radius / nodal spacing [-], >= 1"),
    "forward": Param(True, "tracking: candidates only ahead of their particle (false: (4.22) both ways)"),
    "eps_p": Param(1.0, "weight of the MSCNI stabilization [-], >= 0 (0: plain SCNI)"),
    "nonlocal_h": Param([8e-4, 4e-4, 2e-4], "nominal nodal spacings of the nonlocal models [m]"),
    "nonlocal_radius": Param(2e-3, "radius R of the nonlocal equivalent strain [m], >= 1.5 spacings"),
}
QUICK = {"h": [1.6e-3, 8e-4], "unregularized_h": [1.6e-3, 8e-4], "fem_h": [1.6e-3, 8e-4], "nonlocal_h": [8e-4]}


def _even(length: float, h: float) -> int:
    """The even number of grid points over ``length`` whose spacing is nearest to ``h``."""
    m = length / h + 1.0
    lo = max(2, 2 * int(np.floor(m / 2)))
    return min((lo, lo + 2), key=lambda n: abs(length / (n - 1) - h))


def grid(h: float) -> tuple[np.ndarray, np.ndarray]:
    """Grid lines with spacing about ``h`` whose cell faces hold the crack: nx and ny even
    (x = a1 a column midline, y = a2 a row midline)."""
    return np.linspace(0.0, LX, _even(LX, h)), np.linspace(0.0, LY, _even(LY, h))


def _check(E, nu, rho, ft, GF, sigma, plane, t_end, tol, hs, support_factor, courant, radius, eps_p=1.0,
           nonlocal_hs=(), nonlocal_radius=2e-3):
    for name, v in (("rho", rho), ("sigma", sigma), ("t_end", t_end)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r} must be positive")
    if nonlocal_hs:
        dyn.check_nonlocal(nonlocal_radius, nonlocal_hs, E, ft, GF)
    material = dm.DamageMaterial(E, nu, ft, GF, plane)
    check_tracking(tol, radius)
    if not support_factor >= 1.6:
        raise InputError(f"support_factor = {support_factor!r}: use >= 1.6 (the crack mouth at x = 0 needs it)")
    if not 0 < courant <= 1.0:
        raise InputError(f"courant = {courant!r} must lie in (0, 1]")
    check_eps_p(eps_p)
    for h in hs:
        if not (np.isfinite(h) and 0 < h <= LY / 20):
            raise InputError(f"h = {h!r} m: use 0 < h <= {LY / 20:g} m (at least 20 spacings across the plate)")
        if not h >= 5e-5:
            raise InputError(f"h = {h!r} m is finer than 5e-5 m (over 1.6 million particles); refused")
    if hs:
        h0 = max(hs)
        if not material.critical_opening / 2 / h0 > material.kappa0:
            raise InputError(f"h = {h0:g} m is too coarse for G_F: kappa_c = G_F / (f_t h) <= kappa0; use "
                             f"h < E G_F / f_t^2 = {E * GF / ft**2:.3g} m")
    return material


def check(*, E, nu, rho, ft, GF, sigma, plane, t_end, tol, h, unregularized_h, fem_h, support_factor, courant,
          radius, eps_p, nonlocal_h, nonlocal_radius, **_) -> None:
    """Raise InputError for a parameter outside its documented range (the CLI calls this before any work)."""
    every = [float(v) for v in [*h, *unregularized_h, *fem_h, *nonlocal_h]]
    _check(E, nu, rho, ft, GF, sigma, plane, t_end, tol, every, support_factor, courant, radius, eps_p,
           [float(v) for v in nonlocal_h], nonlocal_radius)


def memory_need(methods, *, h, unregularized_h, fem_h, nonlocal_h, **_) -> _preflight.Need:
    """Peak memory of the finest model, (LX / h) (LY / h) particles (see ``rkfx.cases._preflight``)."""
    return dyn.memory_need(methods, {"h": h, "unregularized_h": unregularized_h, "nonlocal_h": nonlocal_h},
                           {"fem_h": fem_h},
                           lambda v: (LX / v + 1) * (LY / v + 1) if v > 0 else 0.0, "raise")


def traction_force(pl: dyn.Plate, sigma: float) -> np.ndarray:
    """f_I = int N_I sigma n dGamma over the top and bottom edges (SCNI's midpoint rule), shape (2 n,)."""
    bq = boundary_quadrature(pl.p, pl.domains, pl.rk)
    pull = lambda x, t, n: sigma * n  # noqa: E731 - t = sigma n: +y on top, -y on bottom
    return traction_load(pl.p, bq, [Traction("top", pull), Traction("bottom", pull)])


def setup(h: float, material: dm.DamageMaterial, prm: dict, regularized: bool = True, kappa_c: float | None = None,
          comm=None, nonlocal_radius: float = 0.0) -> tuple[dyn.Plate, object, dm.DamageModel, np.ndarray]:
    """The plate of spacing ``h``, its tracking (seeded by the four particles around the tip),
    damage model (nonlocal over ``nonlocal_radius`` [m] if > 0) and edge force, for the
    parameters ``prm`` (``PARAMS`` names)."""
    xs, ys = grid(h)
    pl = dyn.plate(xs, ys, [((0.0, A2), (A1, A2))], [(False, True)], material, prm["rho"], prm["support_factor"],
                   prm["courant"], prm["eps_p"], comm)
    seeds = np.linalg.norm(pl.p.x - np.array([A1, A2]), axis=1) < 0.75 * pl.h
    track = tracking(pl.p.x, pl.p.spacing, prm["tol"], seeds, prm["radius"], forward=prm["forward"])
    return (pl, track, dyn.damage_model(pl, material, regularized, kappa_c, nonlocal_radius, comm),
            traction_force(pl, prm["sigma"]))


def _rkpm(label, study, h, material, prm, regularized=True, kappa_c=None, nonlocal_radius=0.0, **io) -> Run:
    pl, track, model, f = setup(h, material, prm, regularized, kappa_c, io.get("comm"), nonlocal_radius)
    r = dyn.simulate(label, pl, model, track, [], prm["t_end"], external_force=lambda t: f, **io)
    return _run_record(r, study, h, pl, 2 * pl.p.num_nodes)


def branch_metrics(opening: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> tuple[int, float, np.ndarray]:
    """(branches, branch_x, counts) of a particle grid (``_branches``), with the crack count of
    every grid column x > a1."""
    columns = xs[xs > A1]
    points = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)  # particle order: x fastest
    dx, dy = np.diff(xs).min(), np.diff(ys).min()
    # Runs of cracked particles more than three rows apart are separate cracks.
    counts = dyn.count_branches(points, opening, columns, dx, 3.5 * dy)
    return (*_branches(counts, columns), counts)


def cell_branch_counts(centroids: np.ndarray, opening: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """(columns, counts) of the crack-band cells of size ``h``: columns x every h beyond a1 and
    the crack count of each (runs of cracked cells more than three sizes apart are separate)."""
    columns = np.arange(A1 + 0.5 * h, LX, h)
    return columns, dyn.count_branches(centroids, opening, columns, h, 3.0 * h)


def _most_cracks(counts: np.ndarray, column_x: np.ndarray) -> int:
    return dyn.most_cracks(column_x, counts, SIDE_BY_SIDE)


def _branches(counts: np.ndarray, column_x: np.ndarray) -> tuple[int, float]:
    """(branches, branch_x): the most frequent nonzero number of cracks across the columns in
    ``BRANCH_WINDOW`` (0 if none) and the smallest column x crossed by two or more (NaN if none)."""
    window = (column_x >= BRANCH_WINDOW[0] - 1e-12) & (column_x <= BRANCH_WINDOW[1] + 1e-12)
    nonzero = [int(c) for c in counts[window] if c > 0]
    # Mode; a tie goes to the larger count.
    branches = max(Counter(nonzero).items(), key=lambda kv: (kv[1], kv[0]))[0] if nonzero else 0
    split = np.flatnonzero(counts >= 2)
    return branches, float(column_x[split[0]]) if split.size else float("nan")


def _run_record(r: DamageRun, study, h, pl: dyn.Plate, dofs) -> Run:
    x = pl.p.x
    branches, branch_x, counts = branch_metrics(r.opening, pl.xs, pl.ys)
    cracked = r.opening >= dyn.CRACKED
    tip_x = float(x[cracked, 0].max()) if cracked.any() else float("nan")
    hist = r.history
    # Crack tip history: the largest x of the particles (finally cracked) initiated by each sample time.
    t_init = np.where(cracked, r.initiation_time, np.inf)
    tip_hist = np.array([x[s, 0].max() if (s := t_init <= t + 0.5 * r.dt).any() else np.nan for t in hist[:, 0]])
    series = {**dyn.run_series(r), "tip_x": tip_hist, "column_x": pl.xs[pl.xs > A1], "column_bands": counts}
    info = {"study": study, "h_nominal": h, "nx": len(pl.xs), "ny": len(pl.ys), "h": pl.h, "steps": r.steps,
            "dt": r.dt}
    most = _most_cracks(counts, pl.xs[pl.xs > A1])
    return Run(r.label, r.wall_time_s, dofs, series, _errors(r, branches, branch_x, most, tip_x), info)


def _errors(r: DamageRun, branches: int, branch_x: float, most: int, tip_x: float) -> dict:
    return {"branches": branches, "branch_x": branch_x, "most_cracks": most, "tip_x": tip_x,
            "dissipated_end": float(r.history[-1, 1]), "released_end": float(r.released[-1]),
            "dissipated_in_cracks": dyn.crack_share(r),
            "energy_error": r.energy_error}


def _fem(h: float, prm: dict, io: dict) -> Run:
    import dolfinx_solver  # noqa: F401, PLC0415

    from fem_baselines.crack_band_dynamics import branching_crack_band  # noqa: PLC0415

    io = dict(io)
    label = f"fem-crack-band h={h:g}"
    res = branching_crack_band(h, prm["t_end"], E=prm["E"], nu=prm["nu"], rho=prm["rho"], ft=prm["ft"], GF=prm["GF"],
                               sigma=prm["sigma"], plane=prm["plane"], width=LX, height=LY, a1=A1, a2=A2,
                               courant=prm["courant"], label=label,
                               frames=_paraview.crack_band_frames(io.pop("vtk"), label, io.get("comm")), **io)
    r = res.run
    columns, counts = cell_branch_counts(res.centroids, r.opening, h)
    cracked = r.opening >= dyn.CRACKED
    tip_x = float(res.centroids[cracked, 0].max()) if cracked.any() else float("nan")
    series = dyn.run_series(r)
    # The damaged cells' vertices (not the whole mesh): what the figures draw.
    series["damaged_cells"] = np.round(res.x[res.triangles[np.asarray(series["damaged_index"], int)]], 7)
    series.update(column_x=columns, column_bands=counts)
    info = {"study": "fem", "h_nominal": h, "h": h, "cells": res.num_cells, "steps": r.steps, "dt": r.dt}
    return Run(r.label, r.wall_time_s, 2 * res.num_nodes, series,
               _errors(r, *_branches(counts, columns), _most_cracks(counts, columns), tip_x), info)


def _summary(study: str, runs: Sequence[Run]) -> Run:
    runs = sorted(runs, key=lambda r: -r.info["h"])  # coarse to fine
    key = lambda r: f"{r.info['h_nominal']:g}"  # noqa: E731
    diss = [r.errors["dissipated_end"] for r in runs]
    change = abs(diss[-1] - diss[-2]) / diss[-1] if len(runs) >= 2 and diss[-1] > 0 else float("nan")
    return Run(study, float(sum(r.wall_time_s for r in runs)), max(r.n_dofs for r in runs),
               series={"branches": {key(r): r.errors["branches"] for r in runs},
                       "most_cracks": {key(r): r.errors["most_cracks"] for r in runs},
                       "dissipated_end": {key(r): d for r, d in zip(runs, diss)},
                       "wall_time_s": {key(r): r.wall_time_s for r in runs},
                       "dissipation_history": {key(r): {"time_us": r.series["time_us"],
                                                        "dissipated": r.series["dissipated"]} for r in runs}},
               errors={"dissipation_change_fine": change,
                       "dissipation_spread": float(max(diss) / min(diss) - 1) if min(diss) > 0 else float("inf")},
               info={"study": "summary", "of": study,
                     "over": "h=" + ",".join(key(r) for r in runs) + " (wall: their sum)"})


def run(*, methods: Sequence[str] = ("rkpm",), E=3.2e10, nu=0.2, rho=2450.0, ft=2.72e6, GF=3.0, sigma=1.0e6,
        plane="strain", t_end=80e-6, tol=0.5, h=(8e-4, 4e-4, 2e-4), unregularized_h=(8e-4, 4e-4, 2e-4),
        fem_h=(8e-4, 4e-4, 2e-4), support_factor=1.75, courant=0.5, radius=3.5, forward=True, eps_p=1.0,
        nonlocal_h=(8e-4, 4e-4, 2e-4), nonlocal_radius=2e-3, checkpoint_every=0, work_dir=None, resume=None,
        vtk=None) -> Results:
    """The damage particle method, regularized and with a constant kappa_c, at each spacing,
    and the crack-band finite elements at each element size; ``vtk``: a folder for every run's
    fields through time (``--vtk``)."""
    hs, unreg, fems = [float(v) for v in h], [float(v) for v in unregularized_h], [float(v) for v in fem_h]
    nonloc = [float(v) for v in nonlocal_h]
    material = _check(E, nu, rho, ft, GF, sigma, plane, t_end, tol, hs + unreg + fems + nonloc, support_factor,
                      courant, radius, eps_p, nonloc, nonlocal_radius)
    prm = dict(E=E, nu=nu, rho=rho, ft=ft, GF=GF, sigma=sigma, plane=plane, t_end=t_end, tol=tol, h=hs,
               unregularized_h=unreg, fem_h=fems, support_factor=support_factor, courant=courant, radius=radius,
               forward=forward, eps_p=eps_p, nonlocal_h=nonloc, nonlocal_radius=nonlocal_radius)
    io = {"checkpoint_every": checkpoint_every, "work_dir": work_dir, "resume": resume, "comm": _cli.comm(), "vtk": vtk}
    xs, ys = grid(max(hs + unreg) if hs + unreg else 8e-4)
    h0 = float(max(np.diff(xs).max(), np.diff(ys).max()))
    kappa_c = GF / (ft * h0)
    results = Results(NAME, {**prm, "kappa0": material.kappa0, "kappa_c_unregularized": kappa_c})
    studies = []
    if "rkpm" in methods:
        studies += [(study, levels, lambda v, study=study, kw=kw: _rkpm(f"{study} h={v:g}", study, v, material, prm,
                                                                        **kw, **io))
                    for study, levels, kw in (("rkpm-dpm", hs, {}), ("rkpm-dpm-unregularized", unreg,
                                                                       {"regularized": False, "kappa_c": kappa_c}),
                                              ("rkpm-dpm-nonlocal", nonloc, {"nonlocal_radius": nonlocal_radius}))]
    if "fem" in methods:
        studies.append(("fem-crack-band", fems, lambda v: _fem(v, prm, io)))
    dyn.run_studies(results, studies, _summary, level="h")
    return results


# --------------------------------------------------------------------------- figures


def _damage_map(ax, r: Run, key: str = "damaged_D"):
    if "cells" in r.info:  # crack-band FEM: the damaged triangles
        from matplotlib.collections import PolyCollection  # noqa: PLC0415

        m = PolyCollection(np.asarray(r.series["damaged_cells"], float).reshape(-1, 3, 2),
                           array=np.asarray(r.series[key], float), cmap="inferno_r", clim=(0, 1),
                           edgecolors="face", linewidths=0.1, rasterized=True)
        ax.set_facecolor(m.cmap(0.0))
        ax.add_collection(m)
    else:
        m = dyn.damage_map(ax, r.series, r.info["nx"], r.info["ny"], LX, LY, key)
    ax.plot([0, A1], [A2, A2], color="tab:blue", lw=2)
    for xb in BRANCH_WINDOW:
        ax.axvline(xb, color="tab:green", lw=0.8, ls=":")
    bx = r.errors.get("branch_x")
    if bx is not None and np.isfinite(bx):
        ax.axvline(bx, color="tab:cyan", lw=0.8, ls="--")
    ax.set_xlim(0, LX)
    ax.set_ylim(0, LY)
    ax.set_aspect("equal")
    ax.set_xticks([0, 0.025, 0.05, 0.075, 0.1])
    ax.set_yticks([0, 0.02, 0.04])
    dyn.label_map_axes(ax)
    return m


def _title(r: Run) -> str:
    e = r.errors
    bx = e["branch_x"]
    split = f", splits at x = {1e3 * bx:.0f} mm" if bx is not None and np.isfinite(bx) else ""
    size = f"{r.info['cells']:,} cells" if "cells" in r.info else f"{r.info['nx']} x {r.info['ny']} particles"
    window = f"x = {1e3 * BRANCH_WINDOW[0]:.0f}-{1e3 * BRANCH_WINDOW[1]:.0f} mm"
    return (f"h = {1e3 * r.info['h']:.3f} mm ({size}), dissipated {e['dissipated_end']:.3f} J/m\n"
            f"{e['branches']} crack(s) across {window}, {e['most_cracks']} side by side over "
            f"{1e3 * SIDE_BY_SIDE:.0f} mm{split}")


def plot(results: Results, out: Path) -> list[Path]:
    plt = _cli.pyplot()
    out = Path(out)
    files = []
    t_us = 1e6 * results.params["t_end"]
    for study, fname, head, key in (
            ("rkpm-dpm", "cracks", "damage particle method (regularized)", "damaged_w"),
            ("rkpm-dpm", "damage", "damage particle method (regularized)", "damaged_D"),
            ("rkpm-dpm-unregularized", "damage_unregularized", "constant $\\kappa_c$", "damaged_D"),
            ("rkpm-dpm-nonlocal", "cracks_nonlocal",
             f"nonlocal damage particle method (R = {1e3 * results.params['nonlocal_radius']:g} mm)", "damaged_w"),
            ("fem", "cracks_fem", "crack-band finite elements (no tracking)", "damaged_w")):
        runs = sorted((r for r in results.runs if r.info.get("study") == study), key=lambda r: -r.info["h"])
        if not runs:
            continue
        what = ("crack opening", "crack opening $w / w_c$") if key == "damaged_w" else ("damage", "damage D")
        fig, axes = plt.subplots(len(runs), 1, figsize=(7.6, 2.9 * len(runs) + 0.8), squeeze=False,
                                 layout="constrained")
        for ax, r in zip(axes[:, 0], runs):
            m = _damage_map(ax, r, key)
            ax.set_title(_title(r), fontsize=8.5)
        fig.colorbar(m, ax=list(axes[:, 0]), label=what[1], shrink=0.9 if len(runs) > 1 else 0.7)
        fig.suptitle(f"crack branching, {head}: {what[0]} at t = {t_us:.0f} µs\n(green: columns where branches are "
                     "counted; cyan: first split)", fontsize=10)
        files.append(_cli.save(fig, out / f"{fname}.png"))
    path = dyn.plot_dissipation(
        results, (("rkpm-dpm-unregularized", "(a) unregularized: constant $\\kappa_c$"),
                  ("rkpm-dpm", "(b) damage particle method, regularized (4.28)"),
                  ("rkpm-dpm-nonlocal", "(c) nonlocal equivalent strain"), ("fem", "(d) crack-band FEM")),
        out / "dissipation.png", "crack branching: global fracture energy dissipation",
        label=lambda r: f"h = {1e3 * r.info['h']:.3f} mm", order=lambda r: -r.info["h"])
    if path:
        files.append(path)
    return files


_DPM = {"study": "rkpm-dpm"}
CLAIMS = [
    Claim("Fig 4.18(a): at h = 0.8 mm the crack branches into two major branches",
          info={"study": "rkpm-dpm", "h_nominal": 8e-4}, key="branches", op="==", bound=2),
    Claim("Fig 4.18(a): the branches split ahead of the initial tip (x = 50 mm) and before x = 80 mm",
          info={"study": "rkpm-dpm", "h_nominal": 8e-4}, key="branch_x", op="within", bound=(0.05, 0.08)),
    Claim("Fig 4.18: the crack runs from the tip to the right, past x = 80 mm, at every refinement",
          info=_DPM, key="tip_x", op=">", bound=0.08, quick_only=True),
    Claim("Fig 4.19: the regularized dissipation changes < 0.5x as much as the unregularized one on refinement",
          run="rkpm-dpm", info={"study": "summary"}, key="dissipation_change_fine", op="<", bound=0.5,
          over=("rkpm-dpm-unregularized", {"study": "summary"})),
    Claim("Fig 4.19(b): the regularized dissipation converges, change over the last halving of h < 10 %",
          run="rkpm-dpm", info={"study": "summary"}, key="dissipation_change_fine", op="<", bound=0.10,
          full_only=True),
    Claim("Fig 4.19(a): without regularization the dissipation falls on refinement (h = 0.8 mm < 0.8x h = 1.6 mm)",
          info={"study": "rkpm-dpm-unregularized", "h_nominal": 8e-4}, key="dissipated_end", op="<", bound=0.8,
          over=(None, {"study": "rkpm-dpm-unregularized", "h_nominal": 1.6e-3}), quick_only=True),
    Claim("Fig 4.19(a): without regularization the dissipation falls on refinement (h = 0.4 mm < 0.8x h = 0.8 mm)",
          info={"study": "rkpm-dpm-unregularized", "h_nominal": 4e-4}, key="dissipated_end", op="<", bound=0.8,
          over=(None, {"study": "rkpm-dpm-unregularized", "h_nominal": 8e-4}), full_only=True),
    Claim("Nonlocal equivalent strain (R = 2 mm): two major branches at every spacing, the finest included",
          info={"study": "rkpm-dpm-nonlocal"}, key="branches", op="==", bound=2),
    Claim("Sec 4.3: explicit central differences keep the energy balance of the damage particle method within 0.1 %",
          info=_DPM, key="energy_error", op="<", bound=1e-3),
    Claim("Sec 4.3.3: the crack-band FEM baseline beside it keeps its energy balance within 0.1 %",
          info={"study": "fem"}, key="energy_error", op="<", bound=1e-3),
]


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point (see the module docstring)."""
    return _cli.main(NAME, __doc__, PARAMS, run, plot, argv, QUICK, checkpoints=True)


if __name__ == "__main__":
    sys.exit(main())
