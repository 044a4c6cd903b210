"""Steady unsaturated seepage through a rectangular dam: the exact discharge.

A rectangle 0 <= x <= L, 0 <= y <= T of soil whose vertical faces hold the water of two
reservoirs, p = gamma_w (H_1 - y) on x = 0 and p = gamma_w (H_2 - y) on x = L over the whole
height (hydrostatic below each water level, the same gradient as suction above it), with no flow
through the base and the crest. At steady state Darcy's flux q = -k k_rw(p) (grad p - S_w rho_w g)
of ``rkfx.models.unsaturated_poroelasticity`` is free of divergence, and with gravity along -y
its horizontal part is q_x = -k k_rw(p) dp/dx = -k d Phi(p)/dx, with Kirchhoff's potential

    Phi(p) = int_0^p k_rw(-p') dp'     (= p while saturated).

The discharge Q = int_0^T q_x dy is the same through every vertical section (no flow through
base and crest), so integrating it over x gives, whatever the pressure field inside,

    Q = (k / L) [ int_0^T Phi(gamma_w (H_1 - y)) dy - int_0^T Phi(gamma_w (H_2 - y)) dy ].

Saturated (k_rw = 1) this is Dupuit's k gamma_w (H_1^2 - H_2^2) / (2 L) plus the suction zones'
share; with the retention law's k_rw it is exact for the nonlinear two-dimensional problem
(the pressure field itself is not one-dimensional). A discrete solution's discharge is measured
as its mean over the domain, Q_h = (1/L) int q_x^h dA (``flux_integral`` of the models).

``dam_discharge`` evaluates Q by adaptive quadrature (scipy ``quad``, nested) for any retention
law; ``tests/test_steady_seepage.py`` checks it against the closed form of k_rw = 1 and runs
RKPM and FEM against it. ``python -m verification.rectangular_dam`` prints the convergence table
of ``docs/large_deformation.md``.

The soil is the sand of the levee of §6.4.3 (E = 1e7 Pa, nu = 0.3, rho_s = 2700, rho_w = 1000,
n = 0.46, K_s = 1e22, K_w = 1e9 Pa, van Genuchten S_rw = 0.0842, n = 2, beta = 0.7 1/m); its
printed permeability "5.0e-4 m^2" is read as a hydraulic conductivity of 5e-4 m/s (a clean sand),
i.e. a mobility k = 5e-4 / gamma_w m^2/(Pa s).
"""
import argparse
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.integrate import quad

from rkfx.assembly.weighted_forms import placed
from rkfx.models.explicit_poroelasticity import collocation_rows
from rkfx.models.unsaturated_poroelasticity import UnsaturatedBiotModel, UnsaturatedSoil
from rkfx.solvers.model import Constraints

def levee_sand(gravity: float = 9.806) -> UnsaturatedSoil:
    """The sand of §6.4.3 with van Genuchten's retention (6.82-6.83), as ``rkfx.cases.levee`` has it."""
    from rkfx.cases.levee import sand  # noqa: PLC0415

    return sand(gravity=gravity)


@dataclass(frozen=True)
class Dam:
    """A rectangular dam and its two water levels [m]. With ``seepage``, the downstream face
    above the tailwater is a seepage face (``rkfx.assembly.seepage_face``) instead of held at
    the suction of the tailwater's level; the discharge is then no longer known exactly."""

    length: float = 2.0
    height: float = 1.0
    head_up: float = 0.9
    head_down: float = 0.2
    seepage: bool = False

    def on_face(self, x: np.ndarray, down: bool, wet: bool | None = None) -> np.ndarray:
        """Which points ``x`` lie on the upstream (x = 0) or downstream (x = L) face; with
        ``wet`` only those below (True) or above (False) the face's water level (both
        include the level itself)."""
        tol = 1e-9 * self.length
        on = x[:, 0] > self.length - tol if down else x[:, 0] < tol
        if wet is None:
            return on
        level = self.head_down if down else self.head_up
        return on & (x[:, 1] <= level + tol if wet else x[:, 1] >= level - tol)


def seepage_penalty(soil: UnsaturatedSoil, h: float) -> float:
    """kappa = 1e3 k / h: the face's pressure where it discharges is h |grad p| / 1e3."""
    return 1e3 * soil.medium.k / h


def kirchhoff(law, p: float) -> float:
    """Phi(p) = int_0^p k_rw(-p') dp' [Pa] of a retention law (k_rw of the suction s = -p)."""
    if p >= 0.0:
        return p
    kr = lambda s: float(law.relative_permeability(np.array([s]))[0])  # noqa: E731
    return -quad(kr, 0.0, -p, epsabs=0.0, epsrel=1e-12, limit=200)[0]


def dam_discharge(soil: UnsaturatedSoil, dam: Dam) -> float:
    """The exact discharge Q through the dam per unit thickness [m^2/s] (module docstring)."""
    gamma_w = soil.medium.rho_f * soil.gravity
    law = soil.retention

    def face(head: float) -> float:
        # int_0^T Phi(gamma (H - y)) dy = (1/gamma) int_{gamma (H - T)}^{gamma H} Phi(p) dp
        lo, hi = gamma_w * (head - dam.height), gamma_w * head
        breaks = [0.0] if lo < 0.0 < hi else None
        return quad(lambda p: kirchhoff(law, p), lo, hi, points=breaks, epsabs=0.0, epsrel=1e-11, limit=200)[0] / gamma_w

    return soil.medium.k * (face(dam.head_up) - face(dam.head_down)) / dam.length


def heads(dam: Dam, gamma_w: float):
    """The pressure of each face, ``(up(x), down(x))`` with x of shape ``(m, 2)`` [Pa]."""
    return (lambda x: gamma_w * (dam.head_up - x[:, 1]), lambda x: gamma_w * (dam.head_down - x[:, 1]))


def rkpm_dam(soil: UnsaturatedSoil, dam: Dam, ny: int, comm=None, rule: str = "nsni") -> UnsaturatedBiotModel:
    """The RKPM model of the dam on a grid of ``ny`` rows (spacing T / (ny - 1), a = 2 h): the
    base fixed, the faces' pressures by collocation at their nodes (below the tailwater only,
    with the seepage face above it, when ``dam.seepage``). On a communicator of several ranks
    the nodes are split by RCB and each rank holds its own nodes' rows, conditions and face
    points (``model.share``)."""
    from rkfx.assembly.seepage_face import seepage_face  # noqa: PLC0415
    from rkfx.cases._confined_column import column_discretization  # noqa: PLC0415
    from rkfx.cases._nodal_up import owned, rank_unknowns  # noqa: PLC0415

    nx = int(round((ny - 1) * dam.length / dam.height)) + 1
    d = column_discretization(dam.length, dam.height, nx, ny, rule, comm=comm)
    x, n = d.particles.x, d.particles.num_nodes
    size = 3 * n
    base = owned(d, d.bottom)
    up = owned(d, np.flatnonzero(dam.on_face(x, down=False)))
    down = np.flatnonzero(dam.on_face(x, down=True, wet=True if dam.seepage else None))
    down = owned(d, down[:0] if dam.seepage and dam.head_down <= 0.0 else down)  # no tailwater: the whole face seeps
    p_up, p_down = heads(dam, soil.medium.rho_f * soil.gravity)
    G = sp.vstack([collocation_rows(d.rk, base, 0, n, 0, size), collocation_rows(d.rk, base, 1, n, 0, size),
                   collocation_rows(d.rk, up, None, n, 2 * n, size),
                   collocation_rows(d.rk, down, None, n, 2 * n, size)]).tocsr()
    g = np.r_[np.zeros(2 * len(base)), p_up(x[up]), p_down(x[down])]
    face = None
    if dam.seepage:
        edges = d.particles.boundary_edges
        dry = dam.on_face(x, down=True, wet=False)
        face = seepage_face(d.rk, edges[dry[edges].all(axis=1)], seepage_penalty(soil, dam.height / (ny - 1)),
                            nodes=d.own)
    local = None
    if d.own is not None:
        touched = G if face is None else sp.vstack([G, placed(face.matrix(), size, 2 * n)])
        local = rank_unknowns(d, touched, comm)
        G = G[:, local.index].tocsr()
    return UnsaturatedBiotModel(d.rule, soil, Constraints(G, g), local, seepage=face)


def fem_dam(soil: UnsaturatedSoil, dam: Dam, ny: int, comm=None):
    """The Taylor-Hood model of the dam on the same grid (quadrilaterals), as ``rkpm_dam``."""
    import dolfinx_solver  # noqa: F401, PLC0415

    from fem_baselines.poroelasticity import rectangle_mesh  # noqa: PLC0415
    from fem_baselines.unsaturated import FemUnsaturatedModel  # noqa: PLC0415
    from rkfx.conditions import Displacement, Pressure  # noqa: PLC0415

    nx = int(round((ny - 1) * dam.length / dam.height)) + 1
    mesh = rectangle_mesh(np.linspace(0.0, dam.length, nx), np.linspace(0.0, dam.height, ny), "quadrilateral",
                          comm=comm)
    p_up, p_down = heads(dam, soil.medium.rho_f * soil.gravity)
    if not dam.seepage:
        return FemUnsaturatedModel(mesh, soil, [Displacement("bottom"), Pressure("left", lambda x, t: p_up(x)),
                                                Pressure("right", lambda x, t: p_down(x))])
    below = lambda x: dam.on_face(x, down=True, wet=True)  # noqa: E731
    face = (lambda x: dam.on_face(x, down=True, wet=False), seepage_penalty(soil, dam.height / (ny - 1)))
    conditions = [Displacement("bottom"), Pressure("left", lambda x, t: p_up(x))]
    if dam.head_down > 0.0:
        conditions.append(Pressure(below, lambda x, t: p_down(x)))
    return FemUnsaturatedModel(mesh, soil, conditions, seepage=face)


def discharge(model, dam: Dam, first_step: float = 0.01, comm=None) -> tuple[float, object]:
    """Q_h of ``model`` at its steady state (``rkfx.solvers.steady``) and the march."""
    from rkfx.solvers.steady import steady_state  # noqa: PLC0415

    done = steady_state(model, first_step, comm=comm)
    return float(model.flux_integral(done.state.x)[0] / dam.length), done


def wet_height(model, dam: Dam, x: np.ndarray, num: int = 401) -> float:
    """The highest point of the downstream seepage face where water leaves (p > 0) [m] (serial)."""
    if hasattr(model, "seepage_pressures"):
        y, p = model.seepage.points[:, 1], model.seepage_pressures(x)
    else:
        from fem_baselines.poroelasticity import _Sampler  # noqa: PLC0415
        y = np.linspace(0.0, dam.height, num)
        model.assign(x, model.uh, model.ph)
        p = _Sampler(model.Q.mesh, np.column_stack([np.full(num, dam.length), y]))(model.uh, model.ph)[0]
    return float(y[p > 0.0].max(initial=0.0))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, nargs="+", default=[6, 11, 21, 41])
    ap.add_argument("--methods", nargs="+", default=["rkpm", "fem"])
    args = ap.parse_args()
    soil, dam = levee_sand(), Dam()
    exact = dam_discharge(soil, dam)
    gamma_w = soil.medium.rho_f * soil.gravity
    dupuit = soil.medium.k * gamma_w * (dam.head_up ** 2 - dam.head_down ** 2) / (2.0 * dam.length)
    print(f"exact Q = {exact:.10e} m^2/s (Dupuit's saturated share {dupuit:.6e})")
    print("| method | rows | unknowns | Q_h [m^2/s] | error | rate | steps | Newton | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for method in args.methods:
        previous = None
        for ny in args.rows:
            t0 = time.perf_counter()
            model = rkpm_dam(soil, dam, ny) if method == "rkpm" else fem_dam(soil, dam, ny)
            q, done = discharge(model, dam)
            err = abs(q - exact) / exact
            rate = "" if previous is None else f"{np.log(previous[1] / err) / np.log((ny - 1) / (previous[0] - 1)):.2f}"
            print(f"| {method} | {ny} | {model.layout.size} | {q:.8e} | {err:.2e} | {rate} | {done.run.steps} | "
                  f"{done.run.newton_iterations} | {time.perf_counter() - t0:.1f} |", flush=True)
            previous = (ny, err)
    seeping = Dam(head_down=0.0, seepage=True)
    print(f"\nno tailwater, the downstream face a seepage face (Q with the face held at suction: "
          f"{dam_discharge(soil, Dam(head_down=0.0)):.6e})")
    print("| method | rows | Q_h [m^2/s] | face outflow / Q_h | wet to y [m] | steps | Newton |")
    print("|---|---|---|---|---|---|---|")
    for method in args.methods:
        for ny in args.rows:
            model = rkpm_dam(soil, seeping, ny) if method == "rkpm" else fem_dam(soil, seeping, ny)
            q, done = discharge(model, seeping)
            x = done.state.x
            print(f"| {method} | {ny} | {q:.8e} | {model.seepage_outflow(x) / q:.5f} | {wet_height(model, seeping, x):.4f} | "
                  f"{done.run.steps} | {done.run.newton_iterations} |", flush=True)


if __name__ == "__main__":
    main()
