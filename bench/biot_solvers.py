"""Benchmark: the u-p step solve at growing sizes, MUMPS against the Schur-complement field split.

Mandel's problem (E = 1e4 Pa, nu = 0, k = 1e-4, 20 m x 2 m quarter slab, SCNI+FPP), the
displacement conditions by Nitsche's method (``solve_biot(bc_method="nitsche")``), five backward
Euler steps of c dt / h^2 = 1 (one step size: one factorization or preconditioner set-up, five
solves). Each size and solver runs in a fresh process. Printed per run: the stepping time, the
Krylov iterations over the solves, the peak RSS, and the largest difference of the pressure
coefficients to MUMPS's (relative), when MUMPS ran at that size.

Usage: python bench/biot_solvers.py [--grids 201x21,401x41,801x81,1601x161] [--solvers mumps,fieldsplit]
The last line printed per run reads ``<nodes> nodes <solver>: steps <s> s, <its> iterations / <solves> solves, ...``.
"""
import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path


def run_one(nx: int, ny: int, solver: str, store: Path) -> dict:
    import resource  # noqa: PLC0415

    import dolfinx_solver  # noqa: F401, PLC0415  (before petsc4py)
    import numpy as np  # noqa: PLC0415

    from rkfx.conditions import Displacement, Pressure  # noqa: PLC0415
    from rkfx.errors import SolverError  # noqa: PLC0415
    from rkfx.geometry.particles import structured  # noqa: PLC0415
    from rkfx.memory import reuse_freed_memory  # noqa: PLC0415
    from rkfx.models.poroelasticity import PoroMaterial, solve_biot  # noqa: PLC0415
    from rkfx.warmup import warm_up  # noqa: PLC0415
    from verification.mandel import Mandel  # noqa: PLC0415

    reuse_freed_memory()
    warm_up()
    material = PoroMaterial(1.0e4, 0.0, 1.0e-4)
    exact = Mandel(material.E, material.nu, material.k, 20.0, 2.0, 40.0)
    times = (20.0 / (nx - 1)) ** 2 / exact.c * np.arange(6)
    bcs = [Displacement("left", components=(0,)), Displacement("bottom", components=(1,)),
           Displacement("top", lambda x, t: np.full(len(x), exact.plate_displacement(t)), (1,))]
    p = structured(20.0, 2.0, nx, ny)
    out = {"nodes": p.num_nodes, "solver": solver}
    try:
        sol = solve_biot(p, material, times, times[1:], bcs, [Pressure("right")], bc_method="nitsche", solver=solver)
    except SolverError as err:
        return out | {"failed": str(err).splitlines()[0][:200],
                      "peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20}
    ref = store / f"mumps_{nx}x{ny}.npy"
    if solver == "mumps":
        np.save(ref, sol.P)
    diff = float(np.abs(sol.P - np.load(ref)).max() / np.abs(np.load(ref)).max()) if ref.exists() else None
    return out | {"steps_s": sol.timings["steps"], "assemble_s": sol.timings["assemble"], **sol.linear,
                  "peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20, "diff_to_mumps": diff}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grids", default="201x21,401x41,801x81,1601x161")
    ap.add_argument("--solvers", default="mumps,fieldsplit")
    ap.add_argument("--one", help=argparse.SUPPRESS)
    ap.add_argument("--store", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        grid, solver = args.one.split(":")
        nx, ny = map(int, grid.split("x"))
        print(json.dumps(run_one(nx, ny, solver, Path(args.store))))
        return
    with tempfile.TemporaryDirectory() as store:
        for grid in args.grids.split(","):
            for solver in args.solvers.split(","):
                r = subprocess.run([sys.executable, __file__, "--one", f"{grid}:{solver}", "--store", store],
                                   capture_output=True, text=True)
                if r.returncode:
                    sys.exit(f"run {grid} {solver} failed:\n{r.stderr[-2000:]}")
                res = json.loads(r.stdout.strip().splitlines()[-1])
                if "failed" in res:
                    print(f"{res['nodes']:,} nodes {solver}: failed ({res['failed']}), peak RSS {res['peak_gb']:.2f} GB")
                    continue
                diff = "-" if res["diff_to_mumps"] is None else f"{res['diff_to_mumps']:.1e}"
                print(f"{res['nodes']:,} nodes {solver}: steps {res['steps_s']:.2f} s, {res['iterations']} iterations / "
                      f"{res['solves']} solves, peak RSS {res['peak_gb']:.2f} GB, difference to MUMPS {diff}",
                      flush=True)


if __name__ == "__main__":
    main()
