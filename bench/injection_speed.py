"""Benchmark: the injection case (seed 5.3.2) at one resolution, with the time split.

Runs ``rkfx.cases.injection.solve`` at particle spacing ``--h`` to ``--t-end`` with the case's
defaults otherwise, and prints the wall time, the time steps (and cuts), the Newton iterations,
and the time spent in the model's residual and Jacobian assembly against the rest (linear
solves and the stepper), plus the peak RSS. The issue's target: h = 2.5e-3 m (160,801
particles) from 0 to 4000 s within 20 minutes.

Usage:
    python bench/injection_speed.py [--h 0.01] [--t-end 4000] [--jacobian full] [--damage-update impl-ex]
        [--injection-rate 2.75e-7 --residual 1e-4]
"""
import argparse
import resource
import time

import numpy as np

from rkfx.cases import injection as case
from rkfx.models import hydraulic_fracture as hf
from rkfx.memory import reuse_freed_memory
from rkfx.warmup import warm_up


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, default=0.01, help="particle spacing [m]")
    ap.add_argument("--t-end", type=float, default=4000.0, help="end time [s]")
    ap.add_argument("--dt", type=float, default=50.0, help="time step [s]")
    ap.add_argument("--jacobian", default="full", choices=hf.JACOBIANS)
    ap.add_argument("--damage-update", default="implicit", choices=case.DAMAGE_UPDATES)
    ap.add_argument("--injection-rate", type=float, default=0.0,
                    help="rate-driven: Q = this x t [m^2/s^2] into the notch (0: the notch pressure)")
    ap.add_argument("--residual", type=float, default=1e-6, help="stiffness fraction left in damaged particles")
    args = ap.parse_args()
    reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
    warm_up()
    spent = {"residual": 0.0, "tangent": 0.0, "capacity": 0.0}
    for name in spent:
        original = getattr(hf.HydraulicFractureModel, name)

        def timed(self, *a, _original=original, _name=name):
            t0 = time.perf_counter()
            try:
                return _original(self, *a)
            finally:
                spent[_name] += time.perf_counter() - t0

        setattr(hf.HydraulicFractureModel, name, timed)
    prm = {k: v.default for k, v in case.PARAMS.items()}
    rock = case._rock(**{k: prm[k] for k in ("E", "nu", "rho_s", "rho_w", "porosity", "k_h", "gamma_w", "K_w", "K_s",
                                             "GF", "ft", "viscosity", "alpha")})
    t0 = time.perf_counter()
    s = case.solve(args.h, L=prm["L"], c=prm["c"], rate=prm["rate"], t_end=args.t_end, dt=args.dt,
                   t_out=[args.t_end], tol=prm["tol"], radius=prm["radius"], jacobian=args.jacobian,
                   support_factor=prm["support_factor"], rock=rock, max_cuts=prm["max_cuts"],
                   damage_update=args.damage_update, injection_rate=args.injection_rate, residual=args.residual)
    wall = time.perf_counter() - t0
    assembly = sum(spent.values())
    rows = s["rec"].rows
    load = f"injected Q = {args.injection_rate:g} t m^2/s" if args.injection_rate > 0 else "notch pressure"
    print(f"h = {args.h:g} m: {s['nodes']:,} particles, {s['n_dofs']:,} unknowns, {args.jacobian} Jacobian, "
          f"{args.damage_update} damage, {load}, residual stiffness {args.residual:g}")
    print(f"reached t = {rows['t'][-1]:g} s of {args.t_end:g} s" + (f" (stopped: {s['stopped']})" if s["stopped"] else ""))
    print(f"steps {s['steps']}, cuts {s['cuts']}, Newton iterations {s['newton']}, "
          f"per step {np.mean(rows['iterations']):.2f} (max {int(max(rows['iterations']))})")
    print(f"assembly (residual {spent['residual']:.1f} s, Jacobian {spent['tangent']:.1f} s, capacity "
          f"{spent['capacity']:.1f} s): {assembly:.1f} s; linear solves and stepping: {wall - assembly:.1f} s")
    print(f"peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6:.2f} GB")
    print(f"wall {wall:.1f} s")


if __name__ == "__main__":
    main()
