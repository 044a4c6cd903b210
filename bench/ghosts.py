"""Benchmark: the halo of the explicit step over P ranks, measured on RCB partitions, and its cost model.

For square grids of particles (support factors 1.75, the fracture cases', and 1.5) and rank
counts P, the particles are split by ``rkfx.parallel.partition.rcb`` and every rank's halo is
counted from one global list of nodal-integration entries (``rkfx.parallel.ghost_counts``): owned
particles, ghost nodes (2 doubles of internal force each), ghost points (3 doubles per MSCNI
subcell row each), neighbour ranks (2 messages per step each) and bytes per step. Printed: max
and mean over ranks; the fit of the surface-to-volume law ghosts = c sqrt(n / P); the
projection to P ranks of ``--project-ranks`` at n = 1e6, 1e7, 1e8; and, given the step cost
per particle and the interconnect, the model

    T_step(P) = t_particle n / P + 2 k(P) alpha + bytes(P) / beta

and the particles per rank below which the exchange costs more than the step.

``--pingpong`` instead measures alpha (one-way time of an 8-byte message) and beta (bandwidth
of 4 MB messages) between 2 ranks:

    mpiexec -n 2 python bench/ghosts.py --pingpong

Usage: python bench/ghosts.py [--sides 100 316 1000] [--ranks 2 4 8 16 32 64]
       [--more-ranks 128 256 1000] [--t-particle 2.5e-7] [--alpha 1e-6] [--beta 5e9] [--json out.json]
The last line printed reads ``<n> particles, P = <P>: <ghost nodes> ghost nodes (max), <bytes> bytes per step (max)``.
"""
import argparse
import json
import math
import resource
import time

import numpy as np

ASSUMED = {"alpha": 1.5e-6, "beta": 10e9}  # an InfiniBand-class interconnect (assumption, not measured)
PROJECTED_N = (1e6, 1e7, 1e8)
FIT_MIN_RANKS, FIT_MIN_PER_RANK = 16, 1000  # the rows the law is fitted to
MIN_PER_RANK = 50  # --more-ranks are measured on the grids with at least this many particles per rank


def measure(side: int, factors, ranks, more_ranks) -> list[dict]:
    """Halo rows of a ``side`` x ``side`` grid on the unit square for each factor and rank count."""
    from rkfx.approximation.shape_functions import rk_approximation
    from rkfx.geometry.grid_cells import grid_domains
    from rkfx.geometry.particles import structured
    from rkfx.parallel.ghost_counts import count_halo, coupling
    from rkfx.parallel.partition import rcb

    lines = np.linspace(0.0, 1.0, side)
    p = structured(1.0, 1.0, side, side)
    domains = grid_domains(lines, lines)
    n = p.num_nodes
    counts = sorted(set(ranks) | {num for num in more_ranks if n / num >= MIN_PER_RANK})
    parts = {num: rcb(p.x, num) for num in counts}
    rows = []
    for factor in factors:
        t0 = time.perf_counter()
        c = coupling(rk_approximation(p.x, p.spacing, factor), domains)
        t_coupling = time.perf_counter() - t0
        for num in counts:
            t0 = time.perf_counter()
            h = count_halo(c, parts[num], num)
            row = {"n": n, "factor": factor, "P": num, "coupling_s": t_coupling, "halo_s": time.perf_counter() - t0}
            for name in ("owned", "ghost_nodes", "ghost_points", "ghost_subcells", "neighbours", "bytes"):
                v = getattr(h, name)
                row[name] = {"max": int(v.max()), "mean": float(v.mean())}
            rows.append(row)
    return rows


def fit(rows: list[dict], quantity: str, stat: str) -> tuple[float, float]:
    """Least-squares c of ``quantity[stat] = c sqrt(n / P)`` and the largest relative misfit."""
    s = np.array([math.sqrt(r["n"] / r["P"]) for r in rows])
    g = np.array([r[quantity][stat] for r in rows], float)
    c = float(s @ g / (s @ s))
    return c, float(np.max(np.abs(c * s - g) / g))


def crossover(t_particle: float, k: int, alpha: float, bytes_coef: float, beta: float) -> float:
    """Particles per rank m at which t_particle m = 2 k alpha + bytes_coef sqrt(m) / beta."""
    a, b = 2 * k * alpha, bytes_coef / beta
    root = (b + math.sqrt(b * b + 4 * t_particle * a)) / (2 * t_particle)
    return root * root


def model(rows_by_factor: dict, args) -> dict:
    """Fits, projections and the crossover of each support factor."""
    out = {}
    for factor, rows in rows_by_factor.items():
        # The slowest rank is an interior part from 16 ranks on; the corners of the halo add
        # a constant that matters below ~1,000 particles per rank.
        big = [r for r in rows if r["P"] >= FIT_MIN_RANKS and r["n"] / r["P"] >= FIT_MIN_PER_RANK]
        fits = {q: fit(big, q, "max") for q in ("ghost_nodes", "ghost_points", "bytes")}
        fits_mean = {q: fit(big, q, "mean") for q in ("ghost_nodes", "bytes")}
        k = max(r["neighbours"]["max"] for r in rows)
        c_bytes = fits["bytes"][0]
        projected = []
        for n in PROJECTED_N:
            m = n / args.project_ranks
            entry = {"n": n, "P": args.project_ranks, "per_rank": m,
                     "ghost_nodes": fits["ghost_nodes"][0] * math.sqrt(m), "bytes": c_bytes * math.sqrt(m),
                     "neighbours": k}
            for label, net in (("measured", {"alpha": args.alpha, "beta": args.beta}), ("assumed", ASSUMED)):
                if args.t_particle and net["alpha"] and net["beta"]:
                    entry[label] = {"compute_s": args.t_particle * m, "latency_s": 2 * k * net["alpha"],
                                    "bandwidth_s": entry["bytes"] / net["beta"]}
            projected.append(entry)
        cross = {}
        for label, net in (("measured", {"alpha": args.alpha, "beta": args.beta}), ("assumed", ASSUMED)):
            if args.t_particle and net["alpha"] and net["beta"]:
                cross[label] = crossover(args.t_particle, k, net["alpha"], c_bytes, net["beta"])
        out[str(factor)] = {"fit_max": fits, "fit_mean": fits_mean, "neighbours_max": k,
                            "projection": projected, "crossover_particles_per_rank": cross}
    return out


def print_rows(rows: list[dict]) -> None:
    print(f"{'n':>9} {'c':>5} {'P':>5} {'owned max':>10} {'ghost nodes':>16} {'ghost points':>16} "
          f"{'subcell rows':>16} {'neighbours':>11} {'bytes/step':>18}")
    print(f"{'':>32} {'max':>7} {'mean':>8} {'max':>7} {'mean':>8} {'max':>7} {'mean':>8} {'max':>4} "
          f"{'mean':>6} {'max':>8} {'mean':>9}")
    for r in rows:
        cells = " ".join(f"{r[q]['max']:>{w}d} {r[q]['mean']:>{w + 1}.1f}"
                         for q, w in (("ghost_nodes", 7), ("ghost_points", 7), ("ghost_subcells", 7),
                                      ("neighbours", 4), ("bytes", 8)))
        print(f"{r['n']:>9,d} {r['factor']:>5} {r['P']:>5} {r['owned']['max']:>10,d} {cells}")


def print_model(results: dict, args) -> None:
    for factor, m in results.items():
        f = m["fit_max"]
        print(f"\nsupport factor {factor}: ghosts = c sqrt(n / P) fitted to P >= {FIT_MIN_RANKS}, n / P >= "
              f"{FIT_MIN_PER_RANK} (largest misfit): "
              f"ghost nodes max c = {f['ghost_nodes'][0]:.2f} ({100 * f['ghost_nodes'][1]:.0f}%), mean c = "
              f"{m['fit_mean']['ghost_nodes'][0]:.2f}; ghost points max c = {f['ghost_points'][0]:.2f}; bytes max "
              f"c = {f['bytes'][0]:.0f} ({100 * f['bytes'][1]:.0f}%); neighbours k <= {m['neighbours_max']}")
        for e in m["projection"]:
            line = (f"  n = {e['n']:.0e}, P = {e['P']}: {e['per_rank']:,.0f} per rank, ghost nodes "
                    f"{e['ghost_nodes']:,.0f}, {e['bytes'] / 1e3:,.1f} kB per step")
            for label in ("measured", "assumed"):
                if label in e:
                    t = e[label]
                    line += (f"; {label}: compute {1e6 * t['compute_s']:,.1f} us, latency {1e6 * t['latency_s']:.1f} "
                             f"us, bandwidth {1e6 * t['bandwidth_s']:.2f} us")
            print(line)
        for label, mstar in m["crossover_particles_per_rank"].items():
            net = {"alpha": args.alpha, "beta": args.beta} if label == "measured" else ASSUMED
            print(f"  communication > computation below {mstar:,.0f} particles per rank ({label}: alpha = "
                  f"{1e6 * net['alpha']:.2f} us, beta = {net['beta'] / 1e9:.1f} GB/s, t_particle = "
                  f"{1e9 * args.t_particle:.0f} ns)")


def pingpong(json_path: str | None) -> None:
    """One-way time of messages between ranks 0 and 1 (run under mpiexec -n 2)."""
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    if comm.size != 2:
        raise SystemExit("--pingpong runs on exactly 2 ranks: mpiexec -n 2 python bench/ghosts.py --pingpong")
    other = 1 - comm.rank
    times = {}
    for size in (8, 64, 512, 4096, 32768, 262144, 1 << 22):
        buf = np.zeros(size, np.uint8)
        reps = max(20, min(20000, (1 << 26) // size))
        for timed in (False, True):  # warm up, then time
            comm.Barrier()
            t0 = time.perf_counter()
            for _ in range(reps if timed else 10):
                if comm.rank == 0:
                    comm.Send(buf, other)
                    comm.Recv(buf, other)
                else:
                    comm.Recv(buf, other)
                    comm.Send(buf, other)
        times[size] = (time.perf_counter() - t0) / (2 * reps)
    if comm.rank:
        return
    alpha = times[8]
    beta = (1 << 22) / (times[1 << 22] - alpha)
    for size, t in times.items():
        print(f"{size:>9,d} B: {1e6 * t:9.2f} us one way, {size / t / 1e9:6.2f} GB/s")
    print(f"alpha = {1e6 * alpha:.2f} us, beta = {beta / 1e9:.2f} GB/s")
    if json_path:
        with open(json_path, "w") as fh:
            json.dump({"one_way_s": {str(k): v for k, v in times.items()}, "alpha": alpha, "beta": beta}, fh, indent=1)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sides", nargs="+", type=int, default=[100, 316, 1000], help="particles per side")
    ap.add_argument("--factors", nargs="+", type=float, default=[1.75, 1.5], help="support factors")
    ap.add_argument("--ranks", nargs="+", type=int, default=[2, 4, 8, 16, 32, 64])
    ap.add_argument("--more-ranks", nargs="+", type=int, default=[128, 256, 1000],
                    help=f"further rank counts, on the grids with >= {MIN_PER_RANK} particles per rank")
    ap.add_argument("--project-ranks", type=int, default=1000)
    ap.add_argument("--t-particle", type=float, default=0.0, help="step cost per particle [s]")
    ap.add_argument("--alpha", type=float, default=0.0, help="measured latency per message [s]")
    ap.add_argument("--beta", type=float, default=0.0, help="measured bandwidth [bytes/s]")
    ap.add_argument("--pingpong", action="store_true", help="measure alpha and beta (mpiexec -n 2)")
    ap.add_argument("--json", help="write the rows and the model to this file")
    args = ap.parse_args(argv)
    if args.pingpong:
        pingpong(args.json)
        return
    rows = []
    for side in sorted(args.sides):
        t0 = time.perf_counter()
        rows += measure(side, args.factors, args.ranks, args.more_ranks)
        print(f"{side} x {side}: {time.perf_counter() - t0:.1f} s, peak RSS "
              f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB", flush=True)
    print_rows(rows)
    by_factor = {f: [r for r in rows if r["factor"] == f] for f in args.factors}
    results = model(by_factor, args)
    print_model(results, args)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"rows": rows, "model": results, "assumed": ASSUMED, "t_particle": args.t_particle,
                       "alpha": args.alpha, "beta": args.beta,
                       "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}, fh, indent=1)
    last = max(rows, key=lambda r: (r["n"], r["P"]))
    print(f"{last['n']} particles, P = {last['P']}: {last['ghost_nodes']['max']} ghost nodes (max), "
          f"{last['bytes']['max']} bytes per step (max)")


if __name__ == "__main__":
    main()
