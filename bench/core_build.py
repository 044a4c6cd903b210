"""Benchmark: build the SCNI + MSCNI operators for 10^4 .. 10^6 nodes.

For each size, in a fresh process (so peak memory is that size's own):
  nodal domains (median-dual cells and subcells)                 -> ``domains``
  the rows every model integrates with (``rkfx.integration.quadrature.mscni_rules``): N at
  the smoothing points a block at a time, combined into the cell smoothed gradients (3.55)
  and, in the same pass, the subcell gradients grad~N(x_hat_C) of the MSCNI terms (3.56);
  N at the nodes; with ``--with-values`` also the value rows N(x_L) - N(x_hat_C) of the u-p
  storage and projection terms (3.58)                              -> ``operators``
The node set (a uniform grid and its triangulation) is input, not timed. Numba kernels are
compiled before timing. For reference, dolfinx assembles the P1 plane-strain stiffness on a
mesh with the same number of vertices (``fem_baselines.assembly_timing``).

Usage: python bench/core_build.py [--nodes 1e4 1e5 1e6] [--no-fem] [--with-values]
The last line printed reads ``<N> nodes: <seconds> s`` for the largest N.
"""
import argparse
import json
import resource
import subprocess
import sys
import time


def build(num_nodes: int, with_values: bool = False) -> dict:
    import numpy as np

    from rkfx.geometry.nodal_domains import nodal_domains
    from rkfx.geometry.particles import structured
    from rkfx.integration.quadrature import mscni_rules
    from rkfx.approximation.shape_functions import rk_approximation

    def once(n):
        side = int(round(np.sqrt(n)))
        p = structured(1.0, 1.0, side, side)
        rk = rk_approximation(p.x, p.spacing)
        t = {}
        t0 = time.perf_counter()
        d = nodal_domains(p)
        t["domains"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        nodal, rules, values = mscni_rules(p, rk, d, with_values=with_values)
        t["operators"] = time.perf_counter() - t0
        points = len(d.smoothing_points) + p.num_nodes + (len(d.subcell_area) if with_values else 0)
        rows = [nodal.gradients, nodal.values, rules[-1].gradients] + ([values.values] if with_values else [])
        nnz = sum(r.indices.size for r in rows)
        return p.num_nodes, points, nnz, t

    once(400)  # compile / load cached kernels
    nodes, points, nnz, t = once(num_nodes)
    return {"nodes": nodes, "points": points, "nnz": int(nnz), "stages": t, "total": sum(t.values()),
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def fem(num_nodes: int) -> dict:
    import dolfinx_solver  # noqa: F401

    from fem_baselines.assembly_timing import time_p1_assembly
    return time_p1_assembly(num_nodes)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nodes", nargs="+", type=float, default=[1e4, 1e5, 1e6])
    ap.add_argument("--no-fem", action="store_true", help="skip the dolfinx reference")
    ap.add_argument("--with-values", action="store_true", help="also the MSCNI value rows of the u-p models")
    ap.add_argument("--worker", choices=["rk", "fem"], help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        out = build(int(args.nodes[0]), args.with_values) if args.worker == "rk" else fem(int(args.nodes[0]))
        print(json.dumps(out))
        return
    rows = []
    for n in sorted(int(v) for v in args.nodes):
        def run(kind):
            r = subprocess.run([sys.executable, __file__, "--worker", kind, "--nodes", str(n)]
                               + ["--with-values"] * args.with_values,
                               capture_output=True, text=True)
            if r.returncode:
                sys.exit(f"benchmark worker ({kind}, {n} nodes) failed:\n{r.stderr[-2000:]}")
            return json.loads(r.stdout.strip().splitlines()[-1])
        rk = run("rk")
        fe = None if args.no_fem else run("fem")
        rows.append((rk, fe))
        stages = ", ".join(f"{k} {v:.2f}" for k, v in rk["stages"].items())
        print(f"  {rk['nodes']:>9,d} nodes: {stages}", flush=True)
    print()
    print(f"{'nodes':>10} {'eval points':>12} {'nnz':>12} {'wall [s]':>9} {'nodes/s':>10} {'peak [MB]':>10} "
          f"{'P1 asm [s]':>11} {'RK/P1':>6}")
    for rk, fe in rows:
        ref = f"{fe['assembly_s']:>11.2f} {rk['total'] / fe['assembly_s']:>6.1f}" if fe else f"{'-':>11} {'-':>6}"
        print(f"{rk['nodes']:>10,d} {rk['points']:>12,d} {rk['nnz']:>12,d} {rk['total']:>9.2f} "
              f"{rk['nodes'] / rk['total']:>10,.0f} {rk['peak_mb']:>10.0f} {ref}")
    if len(rows) > 1:
        (a, _), (b, _) = rows[0], rows[-1]
        slope = (b["total"] / a["total"]) / (b["nodes"] / a["nodes"])
        print(f"\ntime growth / node growth from {a['nodes']:,d} to {b['nodes']:,d} nodes: {slope:.2f} (1 = linear)")
    print(f"{rows[-1][0]['nodes']} nodes: {rows[-1][0]['total']:.2f} s")


if __name__ == "__main__":
    main()
