"""Collapse of a dry Drucker-Prager column on moving particles: how far each nodal rule gets.

The set-up of Bui et al. (2008): a column 0.2 m long and 0.1 m high against a smooth wall at
x = 0, released at t = 0 onto a floor with Coulomb friction; E = 0.84 MPa, nu = 0.3,
rho = 2650 kg/m^3, phi = 19.8 deg, c = 0, psi = 0; geostatic start with K0 = 1 - sin(phi).
``rkfx.models.lagrangian_plasticity`` on a grid of ``nx`` particles across, a = 2 h,
central differences at ``cfl`` h / c (the column of ``rkfx.cases.granular_collapse``, which
runs it against the published run-outs);
``--support`` sets a in spacings (2 by default). Prints the state every tenth of the run and a last line
with the run-out, the height at the wall, how long the run went and why it stopped.

    python bench/column_collapse.py [--nx 21] [--rule nsni] [--t-end 0.7] [--viscosity 0] [--eta 0]
        [--cfl 0.3] [--support 2] [--floor-friction 0.36] [--width 0.2] [--height 0.1]
"""
import argparse
import time

import numpy as np

from rkfx.cases.granular_collapse import column, detached, front, wall_height
from rkfx.errors import InputError
from rkfx.materials.drucker_prager import DruckerPrager
from rkfx.solvers.central_difference import CentralDifference


class _Printer:
    def __init__(self, model, t0, width, h):
        self.model, self.t0, self.width, self.h = model, t0, width, h

    def record(self, s):
        m, w = self.model, self.width
        print(f"t={s.time:.3f} s  front={w * (1 + front(m, w)):.4f} m  height at wall={wall_height(m, self.h):.4f} m  "
              f"kinetic={s.energies()['kinetic']:.3e} J  max eps_p={m.plastic_strain.max():.2f}  "
              f"wall time={time.perf_counter() - self.t0:.1f} s", flush=True)

    def arrays(self):
        return {}

    def restore(self, arrays):
        pass


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nx", type=int, default=21)
    ap.add_argument("--rule", default="nsni")
    ap.add_argument("--t-end", type=float, default=0.7)
    ap.add_argument("--viscosity", type=float, default=0.0, help="beta of the artificial viscosity beta rho c h")
    ap.add_argument("--eta", type=float, default=0.0, help="a fixed viscosity [Pa s], the same at every spacing")
    ap.add_argument("--cfl", type=float, default=0.3)
    ap.add_argument("--support", type=float, default=2.0, help="support radius a_I in particle spacings")
    ap.add_argument("--floor-friction", type=float, default=float(np.tan(np.radians(19.8))))
    ap.add_argument("--width", type=float, default=0.2, help="column width L [m] (nx particles across it)")
    ap.add_argument("--height", type=float, default=0.1, help="column height H [m] (aspect ratio a = H / L)")
    args = ap.parse_args()
    width, height = args.width, args.height
    soil = DruckerPrager(E=0.84e6, nu=0.3, phi=19.8, c=0.0, psi=0.0)
    model, dt, p, h = column(width, height, args.nx, None, soil, 2650.0, 9.81, rule=args.rule,
                             floor_friction=args.floor_friction, cfl=args.cfl, support=args.support,
                             viscosity=args.viscosity, eta=args.eta)
    steps = int(np.ceil(args.t_end / dt))
    print(f"{len(p.x)} particles, h = {h:.4g} m, dt = {dt:.3g} s, {steps} steps, rule {args.rule}, "
          f"a = {args.support} h, viscosity {args.viscosity}, eta {args.eta} Pa s", flush=True)
    t0 = time.perf_counter()
    why = "ran to t_end"
    try:
        CentralDifference(dt).run(model, steps, output_every=max(1, steps // 10), recorder=_Printer(model, t0, width, h))
    except InputError as e:
        why = f"stopped: {e}"
    wall = time.perf_counter() - t0
    done = model.neighbour_rebuilds["steps"]
    runout = front(model, width)
    print(f"run-out {width * (1 + runout):.4f} m (dL/L = {runout:.3f}; {detached(model)} particles thrown ahead), "
          f"height at the wall {wall_height(model, h):.4f} m, t = {done * dt:.3f} s after {done} "
          f"steps, {1e3 * wall / max(done, 1):.1f} ms/step; {model.neighbour_rebuilds}; {why}")


if __name__ == "__main__":
    main()
