"""Kirsch's plate with a hole: RKPM and FEM against the exact plane-strain solution.

Problem. An infinite plate with a traction-free circular hole of radius ``a`` under remote
uniaxial tension ``T`` along x, in plane strain. By symmetry one quarter is modelled, the
square [0, L] x [0, L] minus the quarter disk r < a:

    left   (x = 0)   symmetry roller   u_x = 0
    bottom (y = 0)   symmetry roller   u_y = 0
    right  (x = L)   exact Kirsch traction  sigma_exact n
    top    (y = L)   exact Kirsch traction  sigma_exact n
    hole   (r = a)   traction free

so that the finite plate reproduces the infinite-plate solution exactly
(``verification.kirsch``; stress concentration sigma_xx(0, a) = 3 T).

Discretisation. One gmsh mesh per level, built with the gmsh Python API
(``cases/geometry/plate_with_hole.geo`` is the same geometry as a .geo file): size h at the
outer corners, h/3 on the hole, h halved at each level. RKPM uses the mesh's vertices as
particles and its triangles as the background of the nodal domains (``rkfx.geometry.gmsh_nodes``);
the FEM baseline (dolfinx P1 / P2, ``fem_baselines.elasticity``) solves on the same triangles.

Reported per method and level: relative L2 error of u and relative H1-seminorm error of u
(RKPM: ``rkfx.integration.norms``, degree-4 Gauss rule on the triangles, direct gradient of u^h; FEM:
``fem_baselines.elasticity.errors``), both over the meshed (polygonal) domain; convergence
rates between levels; sigma_xx at (0, a) from the gradient of u^h (FEM: the stress of the
corner cell, taken 1 % of the hole's mesh size inside along (1, 1)) and its error relative to
the exact 3T. Figures: sigma_xx along x = 0, error against h, and the nodal displacement
error on the finest mesh.

Parameters and units (``--set NAME=VALUE``): E [Pa], nu [-], T [Pa], a [m], L [m], h [m],
levels, rules (RKPM integration rules), support_factor [-], bc_method, fem_degrees.

    python -m rkfx.cases.plate_with_hole [--quick] [--method rkpm|fem|both] [--set NAME=VALUE] [--out DIR] [--vtk]

With ``--vtk`` every run writes its field at t = 0 to OUT/vtk/<run>-level<l>: RKPM displacement,
strain and stress at the particles and on their median-dual cells, FEM displacement.
"""
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from verification.kirsch import Kirsch

from rkfx.assembly.boundary import BC_METHODS
from rkfx.conditions import Displacement, Traction
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_plane_strain
from rkfx.errors import InputError
from rkfx.integration.norms import relative_errors
from rkfx.integration.quadrature import RULES
from rkfx.cases import _cli, _paraview, _preflight
from rkfx.cases._cli import Param, Results, Run
from rkfx.report.claims import Claim

NAME = "plate_with_hole"
HOLE_REFINEMENT = 3.0  # mesh size on the hole = h / HOLE_REFINEMENT
NUM_PROFILE = 300      # points of the sigma_xx profile along x = 0
PLATE_NODES_PER_AREA = 2.5  # gmsh vertices per h^2 of the quarter plate (measured 2.4-2.6, finer on the hole)

PARAMS = {
    "E": Param(1.0e3, "Young's modulus [Pa]"),
    "nu": Param(0.3, "Poisson's ratio [-], in (-1, 0.5)"),
    "T": Param(1.0, "remote tension sigma_xx [Pa]"),
    "a": Param(1.0, "hole radius [m]"),
    "L": Param(5.0, "side of the quarter plate [0, L]^2 [m]"),
    "h": Param(0.5, "mesh size at the outer corners on the coarsest level (h/3 on the hole) [m]"),
    "levels": Param(4, "number of meshes [count], h halved each time, >= 1"),
    "rules": Param(["mscni"], "RKPM domain integration rules: mscni, scni, dni, gauss1, gauss2, gauss4"),
    "support_factor": Param(1.5, "RK support radius / nodal spacing [-], > 1"),
    "bc_method": Param("nitsche", "RKPM essential conditions: nitsche or transformation"),
    "fem_degrees": Param([1, 2], "FEM Lagrange degrees [-]: 1, 2 or 3"),
}
QUICK = {"h": 0.5, "levels": 1}


def _validate(a, L, h, levels, T, rules, bc_method, fem_degrees):
    if not a > 0:
        raise InputError(f"a = {a!r}: the hole radius must be positive")
    if not L > a:
        raise InputError(f"a = {a!r}, L = {L!r}: the hole radius a must be smaller than the plate side L; "
                         "lower a or raise L")
    if not 0 < h <= L - a:
        raise InputError(f"h = {h!r}: the mesh size must lie in (0, L - a] = (0, {L - a:g}]")
    if levels < 1:
        raise InputError(f"levels = {levels!r} must be >= 1")
    if T == 0:
        raise InputError("T = 0 gives the zero solution; relative errors need T != 0")
    for r in rules:
        if r not in RULES:
            raise InputError(f"rules: unknown rule {r!r}; choose from {', '.join(RULES)}")
    if bc_method not in BC_METHODS:
        raise InputError(f"bc_method = {bc_method!r}; choose one of {', '.join(BC_METHODS)}")
    for d in fem_degrees:
        if d not in (1, 2, 3):
            raise InputError(f"fem_degrees: degree {d!r} not offered; use 1, 2 or 3")


def check(*, E, nu, T, a, L, h, levels, rules, support_factor, bc_method, fem_degrees, **_) -> None:
    """Raise InputError for a parameter outside its documented range (the CLI calls this before any work)."""
    ElasticMaterial(E, nu)
    _validate(a, L, h, levels, T, list(rules), bc_method, [int(d) for d in fem_degrees])
    _preflight.support_factor_ok(support_factor)


def memory_need(methods, *, a, L, h, levels, fem_degrees, **_) -> _preflight.Need:
    """Peak memory of the finest level (see ``rkfx.cases._preflight``)."""
    finest = h / 2.0 ** (min(levels, 200) - 1)
    nodes = PLATE_NODES_PER_AREA * (L**2 - np.pi * a**2 / 4) / finest**2
    per = max([_preflight.ELASTIC_RKPM_BYTES_PER_NODE if "rkpm" in methods else 0.0,
               _preflight.ELASTIC_FEM_BYTES_PER_NODE * max(fem_degrees, default=1) ** 2 if "fem" in methods else 0.0])
    return _preflight.need(per, nodes, f"h={h:g}, levels={levels}", "raise h or lower levels")


def mesh_plate(a: float, L: float, h: float):
    """Mesh the quarter plate in the current gmsh session (rank 0 only); returns ``gmsh.model``.

    The same geometry and physical names as ``cases/geometry/plate_with_hole.geo``.
    """
    import gmsh  # noqa: PLC0415

    model = gmsh.model
    model.add(f"{NAME}_{h:g}")
    geo = model.geo
    hc = h / HOLE_REFINEMENT
    c = geo.addPoint(0, 0, 0, h)
    p = [geo.addPoint(a, 0, 0, hc), geo.addPoint(L, 0, 0, h), geo.addPoint(L, L, 0, h),
         geo.addPoint(0, L, 0, h), geo.addPoint(0, a, 0, hc)]
    curves = {"bottom": geo.addLine(p[0], p[1]), "right": geo.addLine(p[1], p[2]),
              "top": geo.addLine(p[2], p[3]), "left": geo.addLine(p[3], p[4]),
              "hole": geo.addCircleArc(p[4], c, p[0])}
    loop = geo.addCurveLoop(list(curves.values()))
    surface = geo.addPlaneSurface([loop])
    geo.synchronize()
    for name, tag in curves.items():
        model.addPhysicalGroup(1, [tag], name=name)
    model.addPhysicalGroup(2, [surface], name="domain")
    model.mesh.generate(2)
    return model


def _stress_xx(grad: np.ndarray, m: ElasticMaterial) -> np.ndarray:
    """sigma_xx [Pa] from displacement gradients (k, 2, 2) by the law of ``m``."""
    d = m.D()
    return d[0, 0] * grad[:, 0, 0] + d[0, 1] * grad[:, 1, 1]


def _fem_sigma_xx(result, m: ElasticMaterial, points: np.ndarray) -> np.ndarray:
    """sigma_xx [Pa] of a FEM solution at points (k, 2): the stress interpolated into DG(p-1)."""
    import dataclasses  # noqa: PLC0415

    import dolfinx.fem  # noqa: PLC0415
    import ufl  # noqa: PLC0415

    from fem_baselines.elasticity import stress_law  # noqa: PLC0415

    sig = stress_law(result.mesh, m)(result.u)
    space = dolfinx.fem.functionspace(result.mesh, ("DG", result.degree - 1, (2,)))
    s = dolfinx.fem.Function(space)
    s.interpolate(dolfinx.fem.Expression(ufl.as_vector([sig[0, 0], sig[1, 1]]),
                                         space.element.interpolation_points))
    s.x.scatter_forward()  # ghost cells may answer the point evaluation
    # fem_baselines offers point evaluation of the displacement only; evaluate the 2-component
    # stress field through the same (MPI-collective) code by swapping the function.
    return dataclasses.replace(result, u=s).evaluate(points)[:, 0]


def run(*, methods: Sequence[str] = ("rkpm", "fem"), E: float = 1.0e3, nu: float = 0.3, T: float = 1.0,
        a: float = 1.0, L: float = 5.0, h: float = 0.5, levels: int = 4, rules: Sequence[str] = ("mscni",),
        support_factor: float = 1.5, bc_method: str = "transformation", fem_degrees: Sequence[int] = (1, 2),
        comm=None, vtk=None) -> Results:
    """Solve the quarter plate on ``levels`` meshes with every requested method.

    Args:
        methods: ``"rkpm"`` and/or ``"fem"``.
        E, nu: Elastic constants [Pa], [-].
        T: Remote tension [Pa].
        a, L: Hole radius and plate side [m].
        h: Mesh size at the outer corners of the coarsest mesh [m]; level l uses h / 2^l.
        levels: Number of meshes.
        rules: RKPM integration rules.
        support_factor, bc_method: RKPM support a_I = c h_I and essential-BC method.
        fem_degrees: FEM Lagrange degrees.
        comm: MPI communicator (default COMM_WORLD).
        vtk: A folder for the ParaView files of every run (``<label>-level<l>``), or ``None``.

    Returns:
        One ``Run`` per method and level, labelled ``rkpm-<rule>`` / ``fem-p<degree>``, with
        ``info`` {level, h, nodes}, ``errors`` {l2, h1, sxx_hole, sxx_hole_err, rate_l2,
        rate_h1} and ``series`` {y_axis, sxx_axis} (+ node_x, node_y, node_error on the finest
        level: |u^h - u| / max|u| at the nodes).

    Raises:
        InputError: Invalid parameters.
    """
    material = ElasticMaterial(E, nu)
    rules, fem_degrees = list(rules), [int(d) for d in fem_degrees]
    _validate(a, L, h, levels, T, rules, bc_method, fem_degrees)
    exact = Kirsch(E, nu, a, T)
    params = dict(E=E, nu=nu, T=T, a=a, L=L, h=h, levels=levels, rules=rules, support_factor=support_factor,
                  bc_method=bc_method, fem_degrees=fem_degrees)
    results = Results(NAME, params)
    labels = ([f"rkpm-{r}" for r in rules] if "rkpm" in methods else []) + \
             ([f"fem-p{d}" for d in fem_degrees] if "fem" in methods else [])
    if not labels:
        raise InputError("nothing to run: choose --method rkpm|fem|both and non-empty rules/fem_degrees")

    if comm is None:
        try:
            import dolfinx_solver  # noqa: F401, PLC0415  (loads MPI before mpi4py)
            from mpi4py import MPI  # noqa: PLC0415
            comm = MPI.COMM_WORLD
        except ImportError:  # serial, scipy solves
            pass
    rank = comm.rank if comm is not None else 0

    import gmsh  # noqa: PLC0415

    from rkfx.geometry.gmsh_nodes import from_gmsh  # noqa: PLC0415
    if "fem" in methods:
        import ufl  # noqa: PLC0415

        from fem_baselines import elasticity as fem  # noqa: PLC0415
    started = gmsh.isInitialized()
    if not started:
        gmsh.initialize(interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)

    y_axis = a + (L - a) * np.linspace(0.0, 1.0, NUM_PROFILE) ** 2  # clustered at the hole
    axis = np.column_stack([np.zeros_like(y_axis), y_axis])
    # Symmetry rollers and the exact traction on the outer sides, for RKPM and FEM alike.
    bcs = [Displacement("left", 0.0, (0,)), Displacement("bottom", 0.0, (1,)),
           *(Traction(side, lambda x, t, n: exact.traction(x, n)) for side in ("right", "top"))]
    try:
        for lev in range(levels):
            hl = h / 2**lev
            if rank == 0:
                mesh_plate(a, L, hl)
            p = from_gmsh(gmsh.model, comm)
            u_nodes = exact.displacement(p.x)
            for label in labels:
                with _cli.model_run(f"{label} level {lev}"):
                    if label.startswith("rkpm"):
                        t0 = time.perf_counter()
                        sol = solve_plane_strain(p, material, bcs, rule=label[5:], bc_method=bc_method,
                                                 support_factor=support_factor, comm=comm)
                        wall, n_dofs = time.perf_counter() - t0, sol.n_dofs
                        errors = relative_errors(p, sol.rk, sol.coefficients, exact.displacement,
                                                 exact.displacement_gradient)
                        points = axis
                        sxx_axis = _stress_xx(sol.gradient(points), material)
                        u_h = sol.displacement(p.x)
                        if vtk is not None:
                            _paraview.write_elastic(vtk, f"{label}-level{lev}", p, sol, material, comm)
                    else:
                        res = fem.solve_plane_strain(gmsh.model, E, nu, bcs, degree=int(label[5:]), comm=comm)
                        wall, n_dofs = res.wall_time_s, res.n_dofs
                        e = fem.errors(res, lambda X: ufl.as_vector(exact.displacement_xy(X[0], X[1], ufl.sqrt)))
                        errors = {"l2": e["l2"], "h1": e["h1"]}
                        # FEM stresses jump across cells: move the profile into the domain by 1 % of
                        # the hole's mesh size (well beyond dolfinx's ~1e-5 collision tolerance), so one
                        # cell holds each point whatever the partition; the hole value is then that of
                        # the corner cell in the direction (1, 1), compared with the exact value there.
                        delta = 0.01 * hl / HOLE_REFINEMENT
                        points = axis + [delta, 0.0]
                        points[0, 1] += delta
                        sxx_axis = _fem_sigma_xx(res, material, points)
                        u_h = res.evaluate(p.x)
                        series = _paraview.fem_series(vtk, f"{label}-level{lev}", res.mesh)
                        if series is not None:
                            with series:
                                series.write(0.0, displacement=res.u)
                    errors["sxx_hole"] = float(sxx_axis[0])
                    errors["sxx_hole_err"] = abs(sxx_axis[0] - exact.stress(points[:1])[0, 0]) / abs(3 * T)
                    series = {"y_axis": y_axis, "sxx_axis": sxx_axis}
                    if lev == levels - 1:
                        series.update(node_x=p.x[:, 0], node_y=p.x[:, 1],
                                      node_error=np.linalg.norm(u_h - u_nodes, axis=1) / np.abs(u_nodes).max())
                    results.runs.append(Run(label, float(wall), int(n_dofs), series, errors,
                                            {"level": lev, "h": hl, "nodes": p.num_nodes}))
            if rank == 0:
                gmsh.model.remove()
    finally:
        if not started:
            gmsh.finalize()
    _add_rates(results.runs)
    return results


def _add_rates(runs: list[Run]):
    """rate_l2, rate_h1 = log(e_prev / e) / log(h_prev / h) for consecutive levels of a method."""
    prev = {}
    for r in runs:
        q = prev.get(r.method)
        if q is not None:
            for k in ("l2", "h1"):
                r.errors[f"rate_{k}"] = math.log(q.errors[k] / r.errors[k]) / math.log(q.info["h"] / r.info["h"])
        prev[r.method] = r


def plot(results: Results, out: Path) -> list[Path]:
    """Figures (PNG in ``out``): sigma_xx along x = 0, convergence, nodal error field."""
    import matplotlib.ticker  # noqa: PLC0415
    from matplotlib.colors import LogNorm  # noqa: PLC0415
    from matplotlib.tri import Triangulation  # noqa: PLC0415

    plt = _cli.pyplot()

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    prm = results.params
    a, L, T = prm["a"], prm["L"], prm["T"]
    exact = Kirsch(prm["E"], prm["nu"], a, T)
    methods = list(dict.fromkeys(r.method for r in results.runs))
    finest = {m: [r for r in results.runs if r.method == m][-1] for m in methods}
    styles = {m: dict(color=f"C{i}", marker="osD^vx"[i % 6]) for i, m in enumerate(methods)}
    files = []

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), layout="constrained")
    y = a + (L - a) * np.linspace(0.0, 1.0, 600) ** 2
    zoom = (a, a + 0.6 * a)
    for ax, xlim in zip(axes, ((a, L), zoom)):
        ax.plot(y, exact.stress(np.column_stack([0 * y, y]))[:, 0], "k-", lw=3, alpha=0.3, label="exact (Kirsch)")
        for m in methods:
            r = finest[m]
            ax.plot(r.series["y_axis"], r.series["sxx_axis"], color=styles[m]["color"], lw=1.1,
                    label=f"{m} ({r.n_dofs} dofs)")
        ax.axhline(3 * T, color="0.6", ls=":", lw=1)
        ax.set(xlabel="y [m] along x = 0", ylabel=r"$\sigma_{xx}$ [Pa]", xlim=xlim)
        ax.grid(alpha=0.3)
    axes[0].set_title("whole symmetry line")
    axes[1].set_title(f"near the hole (exact 3T = {3 * T:g} Pa at y = a)")
    axes[1].legend(frameon=False, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.suptitle(rf"$\sigma_{{xx}}$ along x = 0, finest mesh (h = {finest[methods[0]].info['h']:g} m)")
    files.append(_cli.save(fig, out / "sigma_xx_axis.png"))

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.4), sharex=True, layout="constrained")
    hs = np.array(sorted({r.info["h"] for r in results.runs}))
    for ax, key, title in zip(axes, ("l2", "h1"), ("relative $L^2$ error of u", "relative $H^1$-seminorm error of u")):
        for m in methods:
            rs = [r for r in results.runs if r.method == m]
            rates = [rs[-1].errors.get(f"rate_{k}") for k in ("l2", "h1")]
            label = m + (f" (rates {rates[0]:.2f} / {rates[1]:.2f})" if rates[0] is not None else "")
            ax.loglog([r.info["h"] for r in rs], [r.errors[key] for r in rs], ls="-", ms=6, label=label,
                      **styles[m])
        if len(hs) > 1:  # reference slope through half the median error at the coarsest h
            slope = 2 if key == "l2" else 1
            e0 = np.median([r.errors[key] for r in results.runs if r.info["h"] == hs[-1]])
            ax.loglog(hs, 0.5 * e0 * (hs / hs[-1]) ** slope, "k--", lw=0.8, label=f"slope {slope}")
        ax.set(xlabel="mesh size h [m] (outer corners; h/3 on the hole)", ylabel="relative error [-]", title=title)
        ax.set_xticks(hs, labels=[f"{v:g}" for v in hs])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.grid(alpha=0.3, which="both")
    # One legend for both panels (methods with their finest-level rates); slope hints in place.
    if len(hs) > 1:
        axes[0].legend(handles=axes[0].lines[-1:], frameon=False, fontsize=8, loc="lower right")
    axes[1].legend(frameon=False, fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0),
                   title="rates L2 / H1 (finest pair)" if len(hs) > 1 else None, title_fontsize=8)
    fig.suptitle("Plate with a hole: convergence against the Kirsch solution")
    files.append(_cli.save(fig, out / "convergence.png"))

    n = len(methods)
    ncol = min(n, 3)
    nrow = math.ceil(n / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.6 * ncol + 1.2, 3.6 * nrow + 0.4), squeeze=False,
                             layout="constrained")
    errs = np.concatenate([finest[m].series["node_error"] for m in methods])
    lo = max(np.percentile(errs, 1), errs.max() * 1e-4, 1e-16)
    norm = LogNorm(vmin=lo, vmax=max(errs.max(), lo * 10))
    for ax, m in zip(axes.flat, methods):
        s = finest[m].series
        tri = Triangulation(s["node_x"], s["node_y"])
        xc, yc = s["node_x"][tri.triangles].mean(1), s["node_y"][tri.triangles].mean(1)
        tri.set_mask(np.hypot(xc, yc) < a)  # Delaunay fills the hole: drop those triangles
        pc = ax.tripcolor(tri, np.maximum(s["node_error"], lo), norm=norm, shading="gouraud", cmap="viridis")
        ax.set(aspect="equal", xlabel="x [m]", ylabel="y [m]", title=m)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    fig.colorbar(pc, ax=axes.ravel().tolist(), label=r"$|u^h - u| \,/\, \max|u|$ at the nodes [-]")
    fig.suptitle(f"Nodal displacement error, finest mesh ({finest[methods[0]].info['nodes']} nodes)")
    files.append(_cli.save(fig, out / "error_field.png"))
    return files


# No seed figure: Kirsch's plate checks the SCNI / MSCNI elasticity of Sec 3.3.2 (3.56)-(3.59) on gmsh geometry.
CLAIMS = [
    Claim("Sec 3.3.2 (3.56)-(3.59): MSCNI displacement within 0.15 % (relative L2) of Kirsch's, h = 0.5 m",
          run="rkpm-mscni", info={"level": 0}, key="l2", op="<", bound=1.5e-3),
    Claim("Sec 3.3.2: MSCNI H1-seminorm error below 3.5 % on the coarsest mesh",
          run="rkpm-mscni", info={"level": 0}, key="h1", op="<", bound=3.5e-2),
    Claim("Kirsch: MSCNI stress concentration sigma_xx(0, a) = 3T within 10 %",
          run="rkpm-mscni", key="sxx_hole_err", op="<", bound=0.1),
    Claim("FEM P2 baseline on the same mesh: L2 error < 0.2 %",
          run="fem-p2", info={"level": 0}, key="l2", op="<", bound=2e-3),
    Claim("FEM P1 baseline on the same mesh: L2 error < 1.2 %",
          run="fem-p1", info={"level": 0}, key="l2", op="<", bound=1.2e-2),
    Claim("MSCNI is more accurate than P1 on the same nodes (L2 error ratio < 0.5)",
          run="rkpm-mscni", info={"level": 0}, key="l2", op="<", bound=0.5, over=("fem-p1", {"level": 0})),
    Claim("Sec 3.3.2: MSCNI converges, L2 rate > 1.8 from h = 0.5 to 0.25 m",
          run="rkpm-mscni", info={"level": 1}, key="rate_l2", op=">", bound=1.8, full_only=True),
]


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point (see the module docstring)."""
    return _cli.main(NAME, __doc__, PARAMS, run, plot, argv, QUICK)


if __name__ == "__main__":
    sys.exit(main())
