"""Benchmark: Timoshenko's cantilever solved by RKPM at growing sizes, direct and iterative.

L = 48, D = 12, E = 3e7, nu = 0.3, plane stress, P = 1000; MSCNI, Nitsche on the clamped face,
support 1.5 h (``verification.timoshenko_beam``). For every grid of nodes it prints the wall
times of the stages (RK set-up and assembly, linear solve), the solver's iterations and reason,
the peak RSS of the process after the solve, and the displacement error at the nodes (relative
L2 over the nodes and relative tip deflection). Each size runs in a fresh process (or set of
MPI ranks), so the peak RSS is that size's (summed over the ranks).

Usage:
    python bench/beam_scale.py                                   (257x65, 1025x257, cg-gamg)
    python bench/beam_scale.py --grids 2049x513 --solver cg-gamg  (1,051,137 nodes)
    python bench/beam_scale.py --grids 257x65,1025x257 --solver mumps
    python bench/beam_scale.py --grids 2049x513 --ranks 2          (owned rows on 2 MPI ranks)
Further PETSc options through PETSC_OPTIONS, e.g. "-rkfx_ksp_monitor".
The last line printed per size reads ``<nodes> nodes <solver>: assemble <s> s, solve <s> s, ...``.
"""
import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path


def run_one(nx: int, ny: int, solver: str, support: float) -> dict:
    """One size in this process: stage times, iterations, peak RSS and errors."""
    import dolfinx_solver  # noqa: F401, PLC0415  (before mpi4py / petsc4py)
    import numpy as np  # noqa: PLC0415
    from mpi4py import MPI  # noqa: PLC0415

    from rkfx.approximation.shape_functions import evaluate  # noqa: PLC0415
    from rkfx.models.elastostatics import solve_plane_strain  # noqa: PLC0415
    from rkfx.memory import reuse_freed_memory  # noqa: PLC0415
    from rkfx.warmup import warm_up  # noqa: PLC0415
    from verification.timoshenko_beam import TimoshenkoBeam  # noqa: PLC0415

    reuse_freed_memory()
    warm_up()
    beam = TimoshenkoBeam()
    p = beam.nodes(nx, ny)
    t0 = time.perf_counter()
    comm = MPI.COMM_WORLD
    sol = solve_plane_strain(p, beam.material(), beam.conditions(), rule="mscni", solver=solver,
                             support_factor=support, comm=comm)
    wall = time.perf_counter() - t0
    rss = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20)  # all ranks' sum
    uh = evaluate(sol.rk, p.x).matrix(0) @ sol.coefficients
    ue = beam.displacement(p.x)
    tip = np.flatnonzero((np.abs(p.x[:, 0] - beam.L) < 1e-9) & (np.abs(p.x[:, 1]) < 1e-9))
    return {"nodes": p.num_nodes, "grid": f"{nx}x{ny}", "ranks": comm.size, "solver": sol.linear["solver"],
            "dofs": sol.n_dofs,
            "assemble_s": sol.timings["assemble"], "solve_s": sol.timings["solve"], "wall_s": wall,
            "iterations": sol.linear["iterations"], "reason": sol.linear["reason"], "peak_rss_gb": rss,
            "nodal_l2": float(np.linalg.norm(uh - ue) / np.linalg.norm(ue)),
            "tip_error": float(uh[tip[0], 1] / beam.tip_deflection() - 1) if len(tip) else float("nan")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grids", default="257x65,1025x257", help="comma-separated nx x ny grids of nodes")
    ap.add_argument("--solver", default="cg-gamg", help="auto | mumps | cg-gamg | gmres-ilu")
    ap.add_argument("--support", type=float, default=1.5, help="support size a / h")
    ap.add_argument("--ranks", type=int, default=1, help="MPI ranks (mpiexec next to this Python; one thread each)")
    ap.add_argument("--one", help=argparse.SUPPRESS)  # internal: run one grid, print its JSON
    args = ap.parse_args()
    if args.one:
        nx, ny = map(int, args.one.split("x"))
        result = run_one(nx, ny, args.solver, args.support)
        from mpi4py import MPI  # noqa: PLC0415  (loaded in order by run_one)
        if MPI.COMM_WORLD.rank == 0:
            print(json.dumps(result))
        return
    launch = [sys.executable] if args.ranks == 1 else [
        str(Path(sys.executable).with_name("mpiexec")), "-n", str(args.ranks), "env", "NUMBA_NUM_THREADS=1",
        sys.executable]
    for grid in args.grids.split(","):
        out = subprocess.run(launch + [__file__, "--one", grid, "--solver", args.solver,
                              "--support", str(args.support)], capture_output=True, text=True)
        if out.returncode:
            print(f"{grid}: failed\n{out.stderr.strip().splitlines()[-1] if out.stderr.strip() else ''}")
            continue
        r = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"{r['nodes']:,} nodes, {r['ranks']} rank(s), {r['solver']}: assemble {r['assemble_s']:.2f} s, solve {r['solve_s']:.2f} s, "
              f"{r['iterations']} iterations ({r['reason']}), peak RSS {r['peak_rss_gb']:.2f} GB, "
              f"nodal L2 error {r['nodal_l2']:.2e}, tip deflection error {r['tip_error']:+.2e}", flush=True)


if __name__ == "__main__":
    main()
