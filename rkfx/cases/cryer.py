"""Cryer's problem: 3-D RKPM u-p (SCNI + FPP) and dolfinx Taylor-Hood against the exact solution.

Problem. A poroelastic sphere of radius a, at rest, carries from t = 0+ a uniform compressive
normal traction sigma0 on its surface, which is drained (p = 0). The load is first carried by
the pore fluid, p = p0 = B sigma0 uniformly; as the surface drains, the outer shell stiffens
and squeezes the core, so the pressure at the centre rises above p0 (the Mandel-Cryer effect)
before it dissipates. Exact solution: ``verification.cryer`` (Cryer 1963, any Biot
parameters). One octant is modelled, r <= a with x, y, z >= 0 (gmsh, linear tetrahedra):

    x0, y0, z0   symmetry planes: u_x = 0, u_y = 0, u_z = 0 on x = 0, y = 0, z = 0; no flow
    surface      total traction -sigma0 n, drained p = 0

Methods on the same gmsh model: RKPM (``rkfx.models.poroelasticity`` on ``Particles3D``: the
median-dual cells of the tetrahedra, SCNI with the MSCNI subcells and fluid pressure
projection, eqs. 3.49-3.62 in 3-D; ``ni`` is direct nodal integration without projection) and
Taylor-Hood P2-P1 on the same tetrahedra (``fem_baselines.poroelasticity``), both stepped by
backward Euler on the same step times.

Default data: E = 1e4 Pa, nu = 0, k = 1e-4 m^2/(Pa s), alpha = 1, S = 0 (the parameters of the
seed's Mandel problem), a = 1 m, sigma0 = 1 Pa: c = 1 m^2/s, p0 = 1 Pa, time unit a^2/c = 1 s.
Time is reported as T = c t / a^2; the exact centre pressure peaks at 1.575 p0 at T = 0.063.

Studies, written to results.json and plotted:

* history — the centre pressure p(0, t) at every step and the pressure along the radius in the
  direction (1, 1, 1) at the output times ``t_D``, for ``variants`` and ``fem``. Steps start at
  ``dt_D`` and grow by ``growth`` every ``hold`` steps up to ``max_dt_D`` (so that a direct
  solver factorizes a few matrices). Errors: the largest centre-pressure error over the
  history relative to the exact peak (``history_max``), its relative L2 norm over the steps,
  the peak value and time, and the relative L2 error of each radial profile.
* early — ``early_steps`` steps of ``early_dt_D``, in which the surface layer is far thinner
  than the node spacing: the pressure along the radius after the first and the last step.
  Overshoot = max p^h - max p along the radius, in units of p0 (unstabilized equal-order
  pairs oscillate there, eq. 3.46).
* refinement — the history with ``scni+fpp`` on the mesh sizes ``rkpm_levels`` and Taylor-Hood
  on ``fem_levels``: error, unknowns and wall time per level, and the wall time of each method
  at the errors both reach (time to accuracy, interpolated in log-log).

Parameters and units (``--set NAME=VALUE``): E [Pa], nu [-], k [m^2/(Pa s)], alpha [-], S [1/Pa],
radius [m], load [Pa], mesh_size [m], dt_D [-], growth [-], hold [steps], max_dt_D [-],
t_D (list) [-], variants (list), early_variants (list), early_dt_D [-], early_steps, fem (list),
rkpm_levels (list) [m], fem_levels (list) [m], support_factor [-], bc_method (transformation |
nitsche), solver (auto | mumps | fieldsplit, which needs bc_method=nitsche; in 3-D auto is MUMPS).

    python -m rkfx.cases.cryer [--quick] [--method rkpm|fem|both] [--set NAME=VALUE] [--out DIR]
        [--checkpoint-every N] [--resume DIR] [--vtk]

With ``--vtk`` the history runs write displacement, pressure, strain and effective stress at the
times ``t_D`` to OUT/vtk/ (RKPM: the particles and their tetrahedra with the fields as point
data; FEM: dolfinx VTK files), e.g.
``python -m rkfx.output.render OUT/vtk/rkpm-scni+fpp_cells.pvd --field pressure --view iso-``.

With ``--checkpoint-every N`` every run writes its state every N steps to OUT/checkpoints/;
``--resume DIR`` continues an interrupted invocation.
"""
import sys
from collections.abc import Sequence
from contextlib import nullcontext
from pathlib import Path

import numpy as np

from verification.cryer import Cryer

from rkfx.cases import _cli, _paraview, _preflight, _up_solver
from rkfx.cases._accuracy import matched
from rkfx.cases._cli import Param, Results, Run
from rkfx.conditions import Displacement, Pressure, Traction
from rkfx.errors import InputError
from rkfx.geometry.gmsh_nodes import from_gmsh_3d, scratch_model
from rkfx.geometry.gmsh_solids import sphere_octant
from rkfx.models.poroelasticity import VARIANTS, PoroMaterial, solve_biot
from rkfx.report.claims import Claim
from rkfx.solvers.integrate import time_grid

NAME = "cryer"
FEM_ELEMENTS = ("taylor-hood",)
NUM_SAMPLES = 101  # points along the radius
DIRECTION = np.ones(3) / np.sqrt(3.0)  # the sampled radius, inside the octant
INNER = 0.99  # the radius is sampled up to INNER a: the faceted surface lies inside the sphere

PARAMS = {
    "E": Param(1.0e4, "drained Young's modulus [Pa]"),
    "nu": Param(0.0, "drained Poisson's ratio [-]"),
    "k": Param(1.0e-4, "mobility k_h / gamma_f [m^2/(Pa s)]"),
    "alpha": Param(1.0, "Biot coefficient [-]"),
    "S": Param(0.0, "storage coefficient 1/Q [1/Pa] (0: incompressible constituents)"),
    "radius": Param(1.0, "sphere radius a [m]"),
    "load": Param(1.0, "compressive surface traction sigma0 [Pa]"),
    "mesh_size": Param(0.05, "gmsh tetrahedron size of the history and early studies [m]"),
    "dt_D": Param(1.0e-3, "first time step c dt / a^2 [-]"),
    "growth": Param(2.0, "step growth factor every `hold` steps [-]"),
    "hold": Param(20, "steps per step size (one factorization each) [count]"),
    "max_dt_D": Param(5.0e-3, "largest time step c dt / a^2 [-]"),
    "t_D": Param([0.01, 0.05, 0.1, 0.3, 0.6], "output times c t / a^2 of the radial profiles [-]; the last ends "
                                              "the history"),
    "variants": Param(["scni+fpp", "ni"], "RKPM variants of the history study", fingerprint=False),
    "early_variants": Param(list(VARIANTS), "RKPM variants of the early-time study", fingerprint=False),
    "early_dt_D": Param(1.0e-3, "time step c dt / a^2 of the early-time study [-]"),
    "early_steps": Param(10, "steps of the early-time study [count]"),
    "fem": Param(list(FEM_ELEMENTS), "FEM elements: taylor-hood", fingerprint=False),
    "rkpm_levels": Param([0.1, 0.07, 0.05], "mesh sizes of the RKPM refinement (scni+fpp) [m]", fingerprint=False),
    "fem_levels": Param([0.2, 0.14, 0.1, 0.07], "mesh sizes of the Taylor-Hood refinement [m]", fingerprint=False),
    "support_factor": Param(1.5, "RK support radius / nodal spacing [-], > 1"),
    **_up_solver.PARAMS,
}
QUICK = {"mesh_size": 0.1, "t_D": [0.01, 0.05, 0.1, 0.3], "early_variants": ["ni", "scni+fpp"],
         "rkpm_levels": [0.15, 0.1], "fem_levels": [0.2, 0.14]}

# Nodes of a sphere octant meshed at size h: about 0.53 (a / h)^3 (gmsh, measured at h = 0.05 a).
NODES_PER_UNIT = 0.53
# Peak memory per node at 4,270 nodes (mesh_size 0.05, measured with the whole case's runs):
# RKPM 5.6 GB (two MUMPS factors of a matrix with ~950 entries per row), Taylor-Hood 4.7 GB; the
# fill of a 3-D factorization grows about as N^(4/3), hence the factor (N / 4270)^(1/3).
RKPM_BYTES_PER_NODE = 1.3e6
FEM_BYTES_PER_NODE = 1.1e6
MEASURED_NODES = 4270


def _nodes(radius: float, size: float) -> float:
    return NODES_PER_UNIT * (radius / size) ** 3


def _check(*, E, nu, k, alpha, S, radius, load, mesh_size, dt_D, growth, hold, max_dt_D, t_D, variants,
           early_variants, early_dt_D, early_steps, fem, rkpm_levels, fem_levels, support_factor,
           bc_method="transformation", solver="auto"):
    Cryer(E, nu, k, radius, load, alpha, S)  # the material and geometry, named in one line
    PoroMaterial(E, nu, k, alpha, S)
    for name, sizes in (("mesh_size", [mesh_size]), ("rkpm_levels", rkpm_levels), ("fem_levels", fem_levels)):
        for h in sizes:
            if not (np.isfinite(h) and 0 < h <= radius / 2):
                raise InputError(f"{name}: mesh size {h!r} must lie in (0, radius / 2 = {radius / 2:g}] m")
    for name, v in (("dt_D", dt_D), ("max_dt_D", max_dt_D), ("early_dt_D", early_dt_D)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r} must be positive")
    if not growth >= 1.0:
        raise InputError(f"growth = {growth!r} must be >= 1")
    if int(hold) != hold or hold < 1 or int(early_steps) != early_steps or early_steps < 1:
        raise InputError(f"hold = {hold!r} and early_steps = {early_steps!r} must be positive integers")
    if not t_D or min(t_D) <= 0:
        raise InputError(f"t_D = {t_D!r}: output times must be positive")
    _preflight.known(list(variants) + list(early_variants), VARIANTS, "RKPM variant")
    _preflight.known(fem, FEM_ELEMENTS, "FEM element")
    _preflight.support_factor_ok(support_factor)
    _up_solver.check(bc_method, solver)


def check(**params) -> None:
    """Raise InputError for a parameter outside its documented range (the CLI calls this before any work)."""
    _check(**params)


def memory_need(methods, *, radius, mesh_size, rkpm_levels, fem_levels, **_) -> _preflight.Need:
    """Peak memory of the largest run (see ``rkfx.cases._preflight``)."""
    def peak(per_node, nodes):
        return per_node * nodes * max(1.0, nodes / MEASURED_NODES) ** (1 / 3)

    rk = _nodes(radius, min([mesh_size, *rkpm_levels]))
    fe = _nodes(radius, min([mesh_size, *fem_levels]))
    need = max(peak(RKPM_BYTES_PER_NODE, rk) if "rkpm" in methods else 0.0,
               peak(FEM_BYTES_PER_NODE, fe) if "fem" in methods else 0.0)
    return _preflight.need(need, 1, f"mesh_size={min([mesh_size, *rkpm_levels, *fem_levels]):g}",
                           "raise mesh_size or the finest level")


def _conditions(load: float) -> list:
    """Symmetry rollers on the three cut planes, the drained, loaded spherical surface."""
    return [Displacement("x0", 0.0, (0,)), Displacement("y0", 0.0, (1,)), Displacement("z0", 0.0, (2,)),
            Pressure("surface", 0.0), Traction("surface", lambda x, t, n: -load * n)]


def _geometry(radius: float, size: float, fem: bool):
    """The particles of a gmsh sphere octant and, with ``fem``, the dolfinx mesh of the same model."""
    comm = _cli.comm()
    root = comm is None or comm.rank == 0
    with scratch_model("cryer") if root else nullcontext(None) as model:
        if root:
            sphere_octant(radius, size, model=model)
        particles = from_gmsh_3d(model, comm)
        mesh = None
        if fem:
            from fem_baselines.gmsh_mesh import mesh_from_gmsh  # noqa: PLC0415

            mesh = mesh_from_gmsh(model, comm)
    return particles, mesh


def _rkpm(p, material, bcs, times, variant, support_factor, samples, key, ck, up, vtk=None, vtk_times=None):
    """One RKPM run: pressures at ``samples`` at every step, wall time, unknowns; ``up``: the solver
    options (``bc_method``, ``solver``); with ``vtk`` a folder, its fields at ``vtk_times`` [s]."""
    kind = {Displacement: [], Pressure: [], Traction: []}
    for c in bcs:
        kind[type(c)].append(c)
    with _cli.model_run(key):
        sol = solve_biot(p, material, times, times[1:], kind[Displacement], kind[Pressure], kind[Traction],
                         variant=variant, support_factor=support_factor, comm=_cli.comm(),
                         progress=lambda it: _cli.progress(it, key, len(times) - 1), **ck.for_run(key), **up)
    if vtk is not None:
        _paraview.write_biot(vtk, key.removesuffix("-history"), p, sol, material.elastic, _cli.comm(), vtk_times)
    return sol.pressure(samples), sol.wall_time_s, sol.n_dofs


def _fem(mesh, material, bcs, times, element, samples, key, ck, vtk=None, vtk_times=None):
    from fem_baselines import poroelasticity as fb  # noqa: PLC0415

    series = _paraview.fem_series(vtk, key.removesuffix("-history"), mesh.mesh, vtk_times)
    with _cli.model_run(key):
        res = fb.solve_biot(mesh, material.E, material.nu, material.k, material.alpha, material.S, element, bcs,
                            times, samples, times[1:], comm=_cli.comm(), vtk=series,
                            progress=lambda it: _cli.progress(it, key, len(times) - 1), **ck.for_run(key))
    if series is not None:
        series.close()
    return res.p, res.wall_time_s, res.n_dofs


def _shown(key: str, vtk, times) -> tuple:
    """(folder, times) of the ParaView files of a history run; nothing for the other runs."""
    return (vtk, times) if vtk is not None and key.endswith("-history") else (None, None)


def _history_errors(run_: Run, exact: Cryer, T: np.ndarray, centre: np.ndarray, t_D) -> None:
    """The history's errors (see the module docstring) into ``run_.errors``."""
    pe = exact.centre_pressure(T * exact.time_scale)
    peak = pe.max()
    run_.errors["history_max"] = float(np.abs(centre - pe).max() / peak)
    run_.errors["history_l2"] = float(np.linalg.norm(centre - pe) / np.linalg.norm(pe))
    run_.errors["peak"] = float(centre.max() / exact.p0)
    run_.errors["peak_error"] = float((centre.max() - peak) / peak)
    run_.errors["peak_T"] = float(T[np.argmax(centre)])


def run(*, methods: Sequence[str] = ("rkpm", "fem"), E=1.0e4, nu=0.0, k=1.0e-4, alpha=1.0, S=0.0, radius=1.0,
        load=1.0, mesh_size=0.05, dt_D=1.0e-3, growth=2.0, hold=20, max_dt_D=5.0e-3, t_D=(0.01, 0.05, 0.1, 0.3, 0.6),
        variants=("scni+fpp", "ni"), early_variants=VARIANTS, early_dt_D=1.0e-3, early_steps=10,
        fem=FEM_ELEMENTS, rkpm_levels=(0.1, 0.07, 0.05), fem_levels=(0.2, 0.14, 0.1, 0.07), support_factor=1.5,
        bc_method="transformation", solver="auto", checkpoint_every=0, work_dir=None, resume=None,
        vtk=None) -> Results:
    """The three studies for every requested method; see the module docstring. ``vtk``: a folder for
    the ParaView files of the history runs at the times ``t_D`` (``--vtk``)."""
    _check(E=E, nu=nu, k=k, alpha=alpha, S=S, radius=radius, load=load, mesh_size=mesh_size, dt_D=dt_D,
           growth=growth, hold=hold, max_dt_D=max_dt_D, t_D=t_D, variants=variants, early_variants=early_variants,
           early_dt_D=early_dt_D, early_steps=early_steps, fem=fem, rkpm_levels=rkpm_levels, fem_levels=fem_levels,
           support_factor=support_factor, bc_method=bc_method, solver=solver)
    up = {"bc_method": bc_method, "solver": solver}
    material = PoroMaterial(E, nu, k, alpha, S)
    exact = Cryer(E, nu, k, radius, load, alpha, S)
    scale, p0 = exact.time_scale, exact.p0
    t_out = np.sort(np.asarray(t_D, float))
    times = time_grid(t_out * scale, dt_D * scale, growth, max_dt_D * scale, hold=int(hold))
    T = times[1:] / scale
    r = np.linspace(0.0, INNER * radius, NUM_SAMPLES)
    samples = np.vstack([np.zeros(3), r[:, None] * DIRECTION])  # the centre, then the radius
    keep = np.searchsorted(times[1:], t_out * scale)
    profiles_exact = np.array([exact.pressure(r, t) for t in t_out * scale])
    bcs = _conditions(load)
    ck = _cli.Checkpoints(checkpoint_every, work_dir, resume)
    params = dict(E=E, nu=nu, k=k, alpha=alpha, S=S, radius=radius, load=load, mesh_size=mesh_size, dt_D=dt_D,
                  growth=growth, hold=hold, max_dt_D=max_dt_D, t_D=list(t_D), variants=list(variants),
                  early_variants=list(early_variants), early_dt_D=early_dt_D, early_steps=early_steps, fem=list(fem),
                  rkpm_levels=list(rkpm_levels), fem_levels=list(fem_levels), support_factor=support_factor,
                  bc_method=bc_method, solver=solver,
                  c=exact.c, p0=p0, B=exact.B, time_scale=scale, steps=len(times) - 1,
                  peak_exact=exact.peak().ratio, peak_T_exact=exact.peak().T)
    results = Results(NAME, params)
    want_fem = "fem" in methods and bool(fem)
    p, mesh = _geometry(radius, mesh_size, want_fem)
    params.update(nodes=p.num_nodes)

    solvers = []
    if "rkpm" in methods:
        for v in dict.fromkeys(list(variants) + list(early_variants)):
            solvers.append((f"rkpm-{v}", v in variants, v in early_variants,
                            lambda tt, key, v=v: _rkpm(p, material, bcs, tt, v, support_factor, samples, key, ck,
                                                       up, *_shown(key, vtk, t_out * scale))))
    if want_fem:
        for e in fem:
            solvers.append((f"fem-{e}", True, True,
                            lambda tt, key, e=e: _fem(mesh, material, bcs, tt, e, samples, key, ck,
                                                      *_shown(key, vtk, t_out * scale))))
    done = {}  # (method, mesh size) -> the history's (pressures, wall, unknowns), reused by the refinement
    for label, history, early, solve in solvers:
        run_ = Run(label, 0.0, 0, series={"r": r},
                   info={"study": "history and early time", "nodes": p.num_nodes, "mesh_size": mesh_size})
        if history:
            ph, wall, dofs = done[label, mesh_size] = solve(times, f"{label}-history")
            run_.wall_time_s, run_.n_dofs = wall, dofs
            run_.series.update(T=T, centre=ph[:, 0] / p0, centre_exact=exact.centre_pressure(times[1:]) / p0,
                               t_D=list(t_out), profiles=ph[keep, 1:] / p0, profiles_exact=profiles_exact / p0)
            _history_errors(run_, exact, T, ph[:, 0], t_out)
            for td, ph_r, pe_r in zip(t_out, ph[keep, 1:], profiles_exact):
                run_.errors[f"l2_p_TD{td:g}"] = float(np.linalg.norm(ph_r - pe_r) / np.linalg.norm(pe_r))
        if early:
            tt = early_dt_D * scale * np.arange(int(early_steps) + 1)
            ph, wall, dofs = solve(tt, f"{label}-early")
            for tag, j in (("first", 0), ("last", len(tt) - 2)):
                pe = exact.pressure(r, tt[j + 1])
                run_.series[f"early_{tag}"] = ph[j, 1:] / p0
                run_.series[f"early_{tag}_exact"] = pe / p0
                run_.series[f"early_{tag}_T"] = float(tt[j + 1] / scale)
                run_.errors[f"early_{tag}_overshoot"] = float((ph[j, 1:].max() - pe.max()) / p0)
                run_.errors[f"early_{tag}_l2"] = float(np.linalg.norm(ph[j, 1:] - pe) / np.linalg.norm(pe))
            if not history:
                run_.wall_time_s, run_.n_dofs = wall, dofs
        results.runs.append(run_)
    _refinement(results, methods, material, exact, bcs, times, samples, rkpm_levels, fem_levels, fem, radius,
                support_factor, ck, done, up)
    return results


def _refinement(results, methods, material, exact, bcs, times, samples, rkpm_levels, fem_levels, fem, radius,
                support_factor, ck, done, up) -> None:
    """The refinement study: one history run per level and method (the history study's run where
    the level is its mesh size), and the time to accuracy."""
    T = times[1:] / exact.time_scale
    levels = []
    if "rkpm" in methods:
        levels += [("rkpm-scni+fpp", h) for h in rkpm_levels]
    if "fem" in methods and fem:
        levels += [(f"fem-{fem[0]}", h) for h in fem_levels]
    for label, h in levels:
        is_fem = label.startswith("fem")
        p, mesh = _geometry(radius, h, is_fem and (label, h) not in done)
        key = f"{label}-h{h:g}"
        if (label, h) in done:
            ph, wall, dofs = done[label, h]
        elif is_fem:
            ph, wall, dofs = _fem(mesh, material, bcs, times, fem[0], samples, key, ck)
        else:
            ph, wall, dofs = _rkpm(p, material, bcs, times, "scni+fpp", support_factor, samples, key, ck, up)
        run_ = Run(f"{label} h={h:g}", wall, dofs,
                   info={"study": "refinement", "nodes": p.num_nodes, "mesh_size": h, "refinement": True})
        _history_errors(run_, exact, T, ph[:, 0], [])
        results.runs.append(run_)
    table = matched(results.runs, "history_max", lambda r: r.info.get("refinement"))
    if table:
        results.params["time_to_accuracy"] = table


def plot(results: Results, out: Path) -> list[Path]:
    """The centre-pressure history with its errors, the radial profiles, the early-time layer and
    the refinement (error against unknowns and wall time)."""
    plt = _cli.pyplot()
    prm = results.params
    files = []
    hist = [r for r in results.runs if "centre" in r.series]
    if hist:
        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 4.8))
        r0 = hist[0]
        ax.semilogx(r0.series["T"], r0.series["centre_exact"], color="k", lw=2.4, alpha=0.45, label="exact (Cryer)")
        for r in hist:
            color, ls = _cli.method_style(r.method)
            ax.semilogx(r.series["T"], r.series["centre"], color=color, ls=ls, lw=1.2,
                        label=f"{r.method} (peak {r.errors['peak']:.3f})")
            ax2.semilogx(r.series["T"], np.asarray(r.series["centre"]) - np.asarray(r.series["centre_exact"]),
                         color=color, ls=ls, lw=1.2, label=f"{r.method}: max {r.errors['history_max']:.1%} of the peak")
        ax.axhline(1.0, color="0.6", lw=0.8, ls=":")
        ax.set_xlabel("T = c t / a$^2$ [-]")
        ax.set_ylabel("p(0, t) / p0 [-]")
        ax.set_title(f"centre pressure: Mandel-Cryer rise to {prm['peak_exact']:.3f} p0")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax2.axhline(0.0, color="0.6", lw=0.8)
        ax2.set_xlabel("T = c t / a$^2$ [-]")
        ax2.set_ylabel("(p$^h$ - p)(0, t) / p0 [-]")
        ax2.set_title("error of the centre pressure")
        ax2.legend(fontsize=8)
        ax2.grid(alpha=0.3, which="both")
        fig.suptitle(f"Cryer's sphere (octant), {prm['nodes']} nodes, mesh size {prm['mesh_size']:g} m, "
                     f"nu = {prm['nu']:g}, {prm['steps']} backward-Euler steps")
        fig.tight_layout()
        files.append(_cli.save(fig, out / "history.png"))

        fig, ax = plt.subplots(figsize=(7.5, 5))
        radius = np.asarray(r0.series["r"]) / prm["radius"]
        colors = plt.cm.viridis(np.linspace(0.0, 0.85, len(r0.series["t_D"])))
        markers = ["o", "s", "^", "v", "D"]
        for i, td in enumerate(r0.series["t_D"]):
            ax.plot(radius, np.asarray(r0.series["profiles_exact"][i]), color=colors[i], lw=2.2, alpha=0.5,
                    label=f"exact, T = {td:g}")
            for j, r in enumerate(hist):
                every = 6
                ax.plot(radius[j * 2 % every::every], np.asarray(r.series["profiles"][i])[j * 2 % every::every],
                        ls="none", marker=markers[j % len(markers)], ms=4, mfc="none", color=colors[i],
                        label=r.method if i == 0 else None)
        ax.set_xlabel("r / a along (1, 1, 1) [-]")
        ax.set_ylabel("p / p0 [-]")
        ax.set_title("pressure along the radius (lines exact, markers numerical)")
        ax.legend(fontsize=7, ncol=2)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        files.append(_cli.save(fig, out / "profiles.png"))
    early = [r for r in results.runs if "early_first" in r.series]
    if early:
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.6), sharey=True)
        radius = np.asarray(early[0].series["r"]) / prm["radius"]
        for ax, tag in zip(axes, ("first", "last")):
            ax.plot(radius, early[0].series[f"early_{tag}_exact"], color="k", lw=2.4, alpha=0.4, label="exact")
            for r in early:
                color, ls = _cli.method_style(r.method)
                ax.plot(radius, r.series[f"early_{tag}"], color=color, ls=ls, lw=1.2,
                        label=f"{r.method} ({r.errors[f'early_{tag}_overshoot']:+.0%})")
            ax.set_xlim(0.5, 1.0)
            ax.set_title(f"after the {tag} step, T = {early[0].series[f'early_{tag}_T']:.1e}")
            ax.set_xlabel("r / a along (1, 1, 1) [-] (drained surface at 1)")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, title="method (overshoot / p0)", title_fontsize=7)
        axes[0].set_ylabel("p / p0 [-]")
        fig.suptitle(f"Early time, steps of c $\\Delta$t / a$^2$ = {prm['early_dt_D']:g}: the drained layer is "
                     "thinner than the node spacing")
        fig.tight_layout()
        files.append(_cli.save(fig, out / "early_time.png"))
    levels = [r for r in results.runs if r.info.get("refinement")]
    if levels:
        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 4.6))
        for prefix, marker in (("rkpm", "o"), ("fem", "s")):
            rows = sorted((r.n_dofs, r.wall_time_s, r.errors["history_max"]) for r in levels
                          if r.method.startswith(prefix))
            if not rows:
                continue
            d, w, e = map(np.array, zip(*rows))
            color, _ = _cli.method_style([r.method for r in levels if r.method.startswith(prefix)][0])
            label = "RKPM SCNI+FPP" if prefix == "rkpm" else "Taylor-Hood P2-P1"
            ax.loglog(d, e, marker=marker, color=color, label=label)
            ax2.loglog(w, e, marker=marker, color=color, label=label)
        from matplotlib.ticker import NullFormatter  # noqa: PLC0415

        for a, xl in ((ax, "unknowns"), (ax2, "wall time [s]")):
            a.xaxis.set_minor_formatter(NullFormatter())  # minor labels collide on short decades
            a.set_xlabel(xl)
            a.set_ylabel("max centre-pressure error / exact peak [-]")
            a.grid(alpha=0.3, which="both")
            a.legend(fontsize=8)
        ax.set_title("error against unknowns")
        ax2.set_title("time to accuracy")
        fig.tight_layout()
        files.append(_cli.save(fig, out / "refinement.png"))
    return files


CLAIMS = [
    Claim("Sec 3.3.2 in 3-D, Cryer: the SCNI+FPP centre-pressure history lies within 3 % of the exact solution (largest "
          "error over the history, relative to the exact peak)", run="rkpm-scni+fpp", key="history_max", op="<=",
          bound=0.03),
    Claim("Sec 3.3.2 in 3-D, Cryer: SCNI+FPP reproduces the Mandel-Cryer peak within 3 %", run="rkpm-scni+fpp",
          key="peak_error", op="within", bound=(-0.03, 0.03)),
    Claim("Sec 3.3.2 in 3-D, Cryer: the SCNI+FPP centre pressure rises above 1.4 p0 (exact 1.575 p0 at nu = 0)",
          run="rkpm-scni+fpp", key="peak", op=">", bound=1.4),
    Claim("Sec 3.3.2 in 3-D, Cryer: Taylor-Hood's centre-pressure history lies within 3 % of the exact solution",
          run="fem-taylor-hood", key="history_max", op="<=", bound=0.03),
    Claim("(3.46) in 3-D, Cryer early time: NI (no projection) oscillates, overshoot > 20 % of p0 after the first step",
          run="rkpm-ni", key="early_first_overshoot", op=">", bound=0.20),
    Claim("(3.49)-(3.62) in 3-D, Cryer early time: SCNI+FPP does not, overshoot <= 10 % of p0 after the first step",
          run="rkpm-scni+fpp", key="early_first_overshoot", op="<=", bound=0.10),
]


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point (see the module docstring)."""
    return _cli.main(NAME, __doc__, PARAMS, run, plot, argv, QUICK, checkpoints=True)


if __name__ == "__main__":
    sys.exit(main())
