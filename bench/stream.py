"""Benchmark: the machine's memory bandwidth, STREAM-style, with the threads the explicit step uses.

Four compiled kernels (numba, in parallel over ``NUMBA_NUM_THREADS``) on float64 arrays far
larger than the caches (``--mib`` each): read (a sum), copy (b = a), scale (b = s a) and triad
(a = b + s c). Bandwidth counts the bytes the kernel must move (read 8, copy and scale 16,
triad 24 bytes per element), best of ``--reps``. This is the bound the explicit step's
products are held against (``bench/kalthoff_speed.py`` reports their bytes per step).

Usage: python bench/stream.py [--mib 512] [--reps 10]
The last line reads ``stream: <GB/s> GB/s (triad), <GB/s> GB/s (read)``.
"""
import argparse
import time

import numba
import numpy as np


@numba.njit(parallel=True, fastmath=True, cache=True)
def _read(a):  # fastmath: a vectorized sum, else the reduction's latency bounds it, not memory
    s = 0.0
    for i in numba.prange(len(a)):
        s += a[i]
    return s


@numba.njit(parallel=True, cache=True)
def _copy(a, b):
    for i in numba.prange(len(a)):
        b[i] = a[i]


@numba.njit(parallel=True, cache=True)
def _scale(a, b, s):
    for i in numba.prange(len(a)):
        b[i] = s * a[i]


@numba.njit(parallel=True, cache=True)
def _triad(a, b, c, s):
    for i in numba.prange(len(a)):
        a[i] = b[i] + s * c[i]


def bandwidth(mib: int = 512, reps: int = 10) -> dict[str, float]:
    """Best bandwidth of each kernel [GB/s] over ``reps`` runs on arrays of ``mib`` MiB."""
    n = mib * 2**20 // 8
    a, b, c = np.ones(n), np.full(n, 2.0), np.full(n, 0.5)
    kernels = {
        "read": (lambda: _read(a), 8),
        "copy": (lambda: _copy(a, b), 16),
        "scale": (lambda: _scale(a, b, 3.0), 16),
        "triad": (lambda: _triad(a, b, c, 3.0), 24),
    }
    out = {}
    for name, (run, bytes_per) in kernels.items():
        run()  # compile, touch the pages
        best = np.inf
        for _ in range(reps):
            t = time.perf_counter()
            run()
            best = min(best, time.perf_counter() - t)
        out[name] = bytes_per * n / best / 1e9
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mib", type=int, default=512, help="size of each array [MiB]")
    ap.add_argument("--reps", type=int, default=10, help="runs per kernel (the best counts)")
    args = ap.parse_args(argv)
    bw = bandwidth(args.mib, args.reps)
    print(f"threads {numba.get_num_threads()}, arrays {args.mib} MiB")
    for name, gbs in bw.items():
        print(f"  {name:5s} {gbs:6.1f} GB/s")
    print(f"stream: {bw['triad']:.1f} GB/s (triad), {bw['read']:.1f} GB/s (read)")


if __name__ == "__main__":
    main()
