"""Benchmark: time to accuracy in elasticity, RKPM (SCNI, MSCNI; support 1.5 h, 2 h) against P1 and P2.

Two problems with exact solutions, both solved on the same nodes by every method:
- Kirsch's plate with a hole (``rkfx.cases.plate_with_hole``: quarter plate L = 5, a = 1,
  E = 1e3, nu = 0.3, gmsh mesh refined at the hole, h = 0.5 / 2^l);
- Timoshenko's cantilever (``verification.timoshenko_beam``, plane strain; structured grids
  of nodes, the FEM on the same vertices with every rectangle split along one diagonal).
RKPM: Nitsche's method, ``solver="auto"`` (MUMPS up to 10k unknowns, CG + GAMG above). FEM:
dolfinx Lagrange P1 / P2 with MUMPS. Errors: relative L2 of u and relative H1 seminorm of u
(the energy-norm error up to the material's constants). Wall time: the whole solve from the
nodes or the gmsh model (RK set-up or mesh conversion, assembly, solve), after a warm-up run.

For every RKPM run the FEM wall time at the same error is interpolated log-log between the
FEM runs of each degree; the ratio RKPM / FEM at matched error is printed (< 1: RKPM is faster;
outside the range of the FEM runs a bound, see ``ratio``). The beam's table also gives the CG
iterations of the RKPM solves ("LU": solved directly).

Usage: python bench/elastic_time_to_accuracy.py [--plate-levels 4] [--beam-grids 33x9,65x17,129x33,257x65]
"""
import argparse
import time

import numpy as np

import dolfinx_solver  # noqa: F401  (MPI before petsc4py)
import ufl
from fem_baselines import elasticity as fem
from fem_baselines.poroelasticity import rectangle_mesh
from rkfx.cases import plate_with_hole
from rkfx.integration.norms import relative_errors
from rkfx.models.elastostatics import solve_plane_strain
from rkfx.memory import reuse_freed_memory
from rkfx.warmup import warm_up
from verification.timoshenko_beam import TimoshenkoBeam

RKPM = [("scni", 1.5), ("mscni", 1.5), ("scni", 2.0), ("mscni", 2.0)]
DEGREES = (1, 2)


def plate_runs(levels: int) -> list[dict]:
    """Every method on every level of the plate with a hole."""
    runs = []
    for support in (1.5, 2.0):
        res = plate_with_hole.run(methods=("rkpm",), rules=("scni", "mscni"), support_factor=support,
                                  bc_method="nitsche", levels=levels)
        runs += [dict(method=f"RKPM {r.method[5:].upper()} {support:g}h", nodes=r.info["nodes"], dofs=r.n_dofs,
                      wall=r.wall_time_s, l2=r.errors["l2"], h1=r.errors["h1"]) for r in res.runs]
    res = plate_with_hole.run(methods=("fem",), fem_degrees=DEGREES, levels=levels)
    runs += [dict(method=f"FEM P{r.method[5:]}", nodes=r.info["nodes"], dofs=r.n_dofs, wall=r.wall_time_s,
                  l2=r.errors["l2"], h1=r.errors["h1"]) for r in res.runs]
    return runs


def beam_runs(grids: list[tuple[int, int]]) -> list[dict]:
    """Every method on every grid of the cantilever (plane strain)."""
    beam = TimoshenkoBeam(plane="strain")
    runs = []
    for nx, ny in grids:
        p = beam.nodes(nx, ny)
        for rule, support in RKPM:
            t0 = time.perf_counter()
            sol = solve_plane_strain(p, beam.material(), beam.conditions(), rule=rule, support_factor=support)
            wall = time.perf_counter() - t0
            err = relative_errors(p, sol.rk, sol.coefficients, beam.displacement, beam.gradient)
            it = sol.linear["iterations"] if sol.linear["solver"] == "cg-gamg" else "LU"
            runs.append(dict(method=f"RKPM {rule.upper()} {support:g}h", nodes=p.num_nodes, dofs=sol.n_dofs,
                             wall=wall, it=it, **err))
        for degree in DEGREES:
            t0 = time.perf_counter()
            mesh = rectangle_mesh(np.linspace(0, beam.L, nx), np.linspace(-beam.D / 2, beam.D / 2, ny))
            res = fem.solve_plane_strain(mesh, beam.E, beam.nu, beam.conditions(), degree=degree)
            wall = time.perf_counter() - t0
            e = fem.errors(res, lambda X: ufl.as_vector(beam.displacement_xy(X[0], X[1])))
            runs.append(dict(method=f"FEM P{degree}", nodes=p.num_nodes, dofs=res.n_dofs, wall=wall,
                             l2=e["l2"], h1=e["h1"]))
    return runs


def ratio(runs: list[dict], run: dict, norm: str, degree: int) -> str:
    """``run``'s wall time over FEM P<degree>'s at the same error in ``norm``, the latter
    interpolated log-log between its runs. Outside their range a bound: ">= r" where ``run``
    is less accurate than the coarsest FEM run (whose wall time bounds FEM's at that error
    from above), "<= r" where it is more accurate than the finest."""
    fe = sorted((r for r in runs if r["method"] == f"FEM P{degree}"), key=lambda r: -r[norm])
    e, w = np.log([r[norm] for r in fe]), np.log([r["wall"] for r in fe])
    x = np.log(run[norm])
    if x > e[0]:
        return f">= {run['wall'] / np.exp(w[0]):.2g}"
    if x < e[-1]:
        return f"<= {run['wall'] / np.exp(w[-1]):.2g}"
    return f"{run['wall'] / np.exp(np.interp(x, e[::-1], w[::-1])):.2f}"


def table(title: str, runs: list[dict]) -> None:
    """The runs and, for the RKPM ones, the wall-time ratios to P1 and P2 at matched error."""
    print(f"\n### {title}\n")
    print("| method | nodes | dofs | CG it. | rel. L2(u) | rel. H1(u) | wall [s] | / P1 at L2; H1 | / P2 at L2; H1 |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in runs:
        cells = ["", ""]
        if r["method"].startswith("RKPM"):
            cells = ["; ".join(ratio(runs, r, n, d) for n in ("l2", "h1")) for d in DEGREES]
        print(f"| {r['method']} | {r['nodes']:,} | {r['dofs']:,} | {r.get('it', '')} | {r['l2']:.2e} | "
              f"{r['h1']:.2e} | {r['wall']:.2f} | {cells[0]} | {cells[1]} |", flush=True)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plate-levels", type=int, default=4, help="levels of the plate with a hole (0: skip)")
    ap.add_argument("--beam-grids", default="33x9,65x17,129x33,257x65", help="nx x ny grids of the beam ('': skip)")
    args = ap.parse_args(argv)
    reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
    warm_up()
    beam_runs([(9, 3)])  # compile the kernels and forms before timing
    if args.plate_levels:
        runs = plate_runs(args.plate_levels)
        table("Plate with a hole (Kirsch)", sorted(runs, key=lambda r: (r["method"], r["nodes"])))
    grids = [tuple(map(int, g.split("x"))) for g in args.beam_grids.split(",") if g]
    if grids:
        runs = beam_runs(grids)
        table("Timoshenko cantilever (plane strain)", sorted(runs, key=lambda r: (r["method"], r["nodes"])))


if __name__ == "__main__":
    main()
