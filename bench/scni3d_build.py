"""Benchmark: build the 3-D SCNI + MSCNI operators for 10^4 .. 10^5 nodes and more.

For each size, in a fresh process (so peak memory is that size's own), on a uniform grid of
the unit cube:
  the nodal cells                                                        -> ``cells``
  the rows every 3-D model integrates with (``rkfx.integration.nodal_rules3d.mscni_rules_3d``):
  N at the nodes, the facet-smoothed gradients (3.55), the direct gradients at the subcell
  centroids, their cell means and the stabilization rows (3.56), and the value rows
  N(x_L) - N(x_hat_C) of the u-p storage and projection terms (3.58)    -> ``operators``
  optionally (``--stiffness``) the elastic stiffness from those rows     -> ``stiffness``
``--cells box`` takes the grid's box cells (the seed's 13-point rule: node, 6 face points,
6 subcell centroids); ``--cells median`` the median-dual cells of its Kuhn tetrahedra (~35
smoothing points and 14 subcells per node). The node set is input, not timed; numba kernels
are compiled before timing; support a = 1.5 h.

Usage: python bench/scni3d_build.py [--nodes 1e4 1e5] [--cells box|median] [--stiffness]
The last line printed reads ``<N> nodes: <seconds> s`` for the largest N.
"""
import argparse
import json
import resource
import subprocess
import sys
import time


def build(num_nodes: int, cells: str, with_stiffness: bool) -> dict:
    import numpy as np

    from rkfx.approximation.shape_functions import rk_approximation
    from rkfx.assembly.operators import stiffness
    from rkfx.geometry.nodal_cells3d import box_cells, median_dual_cells
    from rkfx.geometry.particles3d import box
    from rkfx.integration.nodal_rules3d import mscni_rules_3d
    from rkfx.materials.elasticity import ElasticMaterial
    from rkfx.memory import reuse_freed_memory

    reuse_freed_memory()  # as a run does (rkfx.memory)

    def once(n):
        side = int(np.ceil(n ** (1 / 3) - 1e-9))  # at least n nodes
        p = box(1.0, 1.0, 1.0, side, side, side)
        rk = rk_approximation(p.x, p.spacing, 1.5)
        t = {}
        t0 = time.perf_counter()
        c = box_cells(p) if cells == "box" else median_dual_cells(p)
        t["cells"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        nodal, rules, values = mscni_rules_3d(p, rk, c)
        t["operators"] = time.perf_counter() - t0
        nnz = nodal.values.indices.size + values.values.indices.size + sum(q.gradients.indices.size for q in rules[1:])
        nnz += nodal.gradients.indices.size
        k_nnz = 0
        if with_stiffness:
            t0 = time.perf_counter()
            k_nnz = stiffness(rules, ElasticMaterial(1.0, 0.3).D3()).nnz
            t["stiffness"] = time.perf_counter() - t0
        points = len(c.points) + p.num_nodes + len(c.subcell_volume)
        return p.num_nodes, points, nnz, k_nnz, t

    once(512)  # compile / load cached kernels
    nodes, points, nnz, k_nnz, t = once(num_nodes)
    return {"nodes": nodes, "points": points, "nnz": int(nnz), "k_nnz": int(k_nnz), "stages": t,
            "total": sum(v for k, v in t.items() if k != "stiffness"),
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nodes", nargs="+", type=float, default=[1e4, 1e5])
    ap.add_argument("--cells", choices=["box", "median"], default="box")
    ap.add_argument("--stiffness", action="store_true", help="also assemble the elastic stiffness")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        print(json.dumps(build(int(args.nodes[0]), args.cells, args.stiffness)))
        return
    rows = []
    for n in sorted(int(v) for v in args.nodes):
        r = subprocess.run([sys.executable, __file__, "--worker", "--nodes", str(n), "--cells", args.cells]
                           + ["--stiffness"] * args.stiffness, capture_output=True, text=True)
        if r.returncode:
            sys.exit(f"benchmark worker ({n} nodes) failed:\n{r.stderr[-2000:]}")
        rk = json.loads(r.stdout.strip().splitlines()[-1])
        rows.append(rk)
        stages = ", ".join(f"{k} {v:.2f}" for k, v in rk["stages"].items())
        print(f"  {rk['nodes']:>9,d} nodes ({args.cells} cells): {stages}", flush=True)
    print()
    print(f"{'nodes':>10} {'eval points':>12} {'row nnz':>12} {'K nnz':>12} {'build [s]':>10} {'nodes/s':>10} "
          f"{'peak [MB]':>10}")
    for rk in rows:
        print(f"{rk['nodes']:>10,d} {rk['points']:>12,d} {rk['nnz']:>12,d} {rk['k_nnz'] or '-':>12} "
              f"{rk['total']:>10.2f} {rk['nodes'] / rk['total']:>10,.0f} {rk['peak_mb']:>10.0f}")
    if len(rows) > 1:
        a, b = rows[0], rows[-1]
        slope = (b["total"] / a["total"]) / (b["nodes"] / a["nodes"])
        print(f"\ntime growth / node growth from {a['nodes']:,d} to {b['nodes']:,d} nodes: {slope:.2f} (1 = linear)")
    print(f"{rows[-1]['nodes']} nodes: {rows[-1]['total']:.2f} s")


if __name__ == "__main__":
    main()
