"""Benchmark: one semi-Lagrangian step at 10^4 .. 10^6 moving particles (issue target: <= 0.2 s at 10^5).

A step of ``rkfx.approximation.semi_lagrangian`` on a uniform grid of particles with supports
a = 2 h and a Verlet skin of h / 2, timed in three parts:

  ``search``   ``moved``: which nodes moved beyond skin / 2, and the search of their rows and of
               the rows near them (the Verlet lists)
  ``rows``     ``evaluate_moving(implicit=True)``: N_I and the implicit gradients (6.29) at
               the nodes from the candidate rows
  ``nsni``     all the NSNI rows (``nodal_integration(rule="nsni")``): N at the nodes, SNNI
               gradients from the 4 side midpoints of every square cell, the VC correction,
               and the derivatives of the implicit gradients for the stabilization

Three kinds of step: ``still`` (every node inside its skin: no search), ``some`` (the nodes in
a tenth of the domain moved 0.3 h beyond their reference) and ``all`` (every node moved past its
skin: every row searched, the worst step). Each is the best of ``--repeat`` runs. Numba kernels
are compiled before timing.

Usage: python bench/semi_lagrangian_step.py [--nodes 1e4 1e5 1e6] [--repeat 3]
The last line reads ``<N> particles: <seconds> s per worst step (search + rows)``.
"""
import argparse
import time

import numpy as np


def _best(f, repeat):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def step_times(num_nodes: int, repeat: int) -> dict:
    from rkfx.approximation.semi_lagrangian import evaluate_moving, moved, moving_rk
    from rkfx.geometry.particles import structured
    from rkfx.integration.nodal_stabilized import boundary_rule, nodal_cells, nodal_integration

    side = int(round(np.sqrt(num_nodes)))
    p = structured(1.0, 1.0, side, side)
    h = 1.0 / (side - 1)
    volume = np.full(p.num_nodes, h * h)
    cells = nodal_cells(p.x, volume)
    rk0 = moving_rk(p.x, 2.0 * h, skin=0.5 * h, reach=cells.reach)
    region = p.x[:, 0] < 0.1
    shifts = {"still": 0.1 * h * np.ones((p.num_nodes, 1)) * [1.0, 0.0],
              "some": 0.3 * h * region[:, None] * [1.0, 1.0],
              "all": 0.3 * h * np.ones((p.num_nodes, 1)) * [1.0, 1.0]}
    out = {"nodes": p.num_nodes}
    for kind, shift in shifts.items():
        x = p.x + shift
        t_search, rk = _best(lambda: moved(rk0, x), repeat)
        t_rows, rows = _best(lambda: evaluate_moving(rk, implicit=True), repeat)
        out[kind] = {"searched": rk.searched, "search": t_search, "rows": t_rows,
                     "neighbours": rows.indices.size / p.num_nodes}
    c = nodal_cells(rk.x, volume)
    b = boundary_rule(rk.x, p.boundary_edges)
    out["nsni"], _ = _best(lambda: nodal_integration(rk, c, b, "nsni"), repeat)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nodes", nargs="+", type=float, default=[1e4, 1e5, 1e6])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    from rkfx.memory import reuse_freed_memory  # noqa: PLC0415
    reuse_freed_memory()  # as a run would: each step's arrays reuse the last step's freed memory
    step_times(400, 1)  # compile / load the cached kernels
    results = [step_times(int(n), args.repeat) for n in sorted(args.nodes)]
    print(f"{'particles':>10} {'step':>6} {'rows searched':>14} {'search [s]':>11} {'rows [s]':>9} "
          f"{'total [s]':>10} {'neighbours':>11}")
    for r in results:
        for kind in ("still", "some", "all"):
            s = r[kind]
            print(f"{r['nodes']:>10,d} {kind:>6} {s['searched']:>14,d} {s['search']:>11.4f} {s['rows']:>9.4f} "
                  f"{s['search'] + s['rows']:>10.4f} {s['neighbours']:>11.2f}")
        print(f"{r['nodes']:>10,d} {'nsni':>6} {'':>14} {'':>11} {r['nsni']:>9.4f}   (all NSNI rows, after 'all')")
    if len(results) > 1:
        a, b = results[0], results[-1]
        ta, tb = (r["all"]["search"] + r["all"]["rows"] for r in (a, b))
        print(f"\nworst-step time growth / particle growth from {a['nodes']:,d} to {b['nodes']:,d}: "
              f"{(tb / ta) / (b['nodes'] / a['nodes']):.2f} (1 = linear)")
    last = results[-1]
    print(f"{last['nodes']} particles: {last['all']['search'] + last['all']['rows']:.3f} s per worst step (search + rows)")


if __name__ == "__main__":
    main()
