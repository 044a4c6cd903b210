"""The figure of docs/large_deformation.md: python docs/figures/large_deformation.py [--out PATH]

(a) A jittered node set after a shear of 1 and a quarter turn, rebuilt by the semi-Lagrangian
    approximation: one node's support and the neighbours it covers now, coloured by the error of
    the rebuilt shape functions on a linear field. (b) The energy ratios of every deformation
    mode of the free stiffness against Gauss-4 (13 x 13 nodes, a = 1.5 h): DNI and SNNI have
    modes below 10% of their energy, NSNI none. (c) The base pressure of the confined column of
    section 6.4.1 (3 x 241 nodes) with NSNI and DNI, against twice the undrained jump.
"""
import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import scipy.linalg as sl  # noqa: E402

from rkfx.approximation.semi_lagrangian import evaluate_moving, moved, moving_rk  # noqa: E402
from rkfx.approximation.shape_functions import RKApproximation  # noqa: E402
from rkfx.assembly import nodal_forms, operators  # noqa: E402
from rkfx.cases._confined_column import confined_column  # noqa: E402
from rkfx.geometry.nodal_domains import nodal_domains  # noqa: E402
from rkfx.geometry.particles import jittered, structured  # noqa: E402
from rkfx.integration.nodal_stabilized import boundary_rule, nodal_cells, nodal_integration  # noqa: E402
from rkfx.integration.quadrature import integration_rules  # noqa: E402
from rkfx.materials.elasticity import ElasticMaterial  # noqa: E402
from rkfx.solvers.explicit_up import ExplicitUP, stable_steps  # noqa: E402

HERE = Path(__file__).parent


def _moved_nodes(ax):
    p = jittered(21, 0.25, seed=4)
    X, h = p.x, float(p.spacing.mean())
    a = 2.0 * p.spacing
    rk = moving_rk(X, a, skin=0.4 * h)
    for t in np.linspace(0.0, 1.0, 81)[1:]:
        c, s = np.cos(t * np.pi / 2), np.sin(t * np.pi / 2)
        rk = moved(rk, ((X + np.c_[t * X[:, 1], 0 * X[:, 1]]) - 0.5) @ np.array([[c, s], [-s, c]]) + 0.5)
    x = rk.x
    rows = evaluate_moving(rk, implicit=True)
    f = 0.7 - 2.0 * x[:, 0] + 3.0 * x[:, 1]
    err = np.maximum(np.abs((rows @ f)[:, 0] - f), 1e-16)  # 1e-16: exact to round-off
    sc = ax.scatter(x[:, 0], x[:, 1], c=np.log10(err), s=9, cmap="viridis")
    i = int(np.argmin(np.sum((x - x.mean(0)) ** 2, axis=1)))
    m = rows.matrix(0)
    near = m[i].indices
    ax.scatter(x[near, 0], x[near, 1], facecolors="none", edgecolors="crimson", s=22, lw=0.9,
               label=f"{len(near)} nodes covering node {i} now")
    ax.add_patch(plt.Circle(x[i], a[i], fill=False, color="black", lw=1.6, label="its support a = 2h"))
    ax.set_aspect("equal")
    ax.set_title("(a) after shear 1 + quarter turn: rebuilt rows", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    plt.colorbar(sc, ax=ax, label="log10 |error| on a linear field", shrink=0.8)


def _energy_ratios(ax):
    p = structured(1.0, 1.0, 13, 13)
    dmat = ElasticMaterial(1.0, 0.3).D()
    d = nodal_domains(p)
    k_ref = operators.stiffness(integration_rules("gauss4", p, RKApproximation(p.x, 1.5 * p.spacing), d), dmat).toarray()
    q = np.linalg.eigh(k_ref)[1][:, 3:]
    cells = nodal_cells(p.x, d.area)
    rk = moving_rk(p.x, 1.5 * p.spacing, skin=0.5 / 12, reach=cells.reach)
    bnd = boundary_rule(p.x, p.boundary_edges)
    for rule, style in (("dni", "C0-"), ("snni", "C1--"), ("nsni", "C2-")):
        k = nodal_forms.stiffness(nodal_integration(rk, cells, bnd, rule), dmat).toarray()
        k = 0.5 * (k + k.T)
        r = np.sort(sl.eigh(q.T @ k @ q, q.T @ k_ref @ q, eigvals_only=True))
        ax.semilogy(np.arange(1, len(r) + 1), r, style, lw=1.2,
                    label=f"{rule}: {int(np.sum(r < 0.1))} modes below 0.1")
    ax.axhline(0.1, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("deformation mode (sorted)")
    ax.set_ylabel("energy seen by the rule / Gauss-4")
    ax.set_title("(b) spurious modes, 13 x 13 nodes, a = 1.5 h", fontsize=9)
    ax.legend(fontsize=7)


def _column(ax):
    for rule, style in (("nsni", "C2-"), ("dni", "C0-")):
        model, i_top, i_bot, _ = confined_column(241, rule)
        n = model.layout.field("p").nodes
        dt = 0.9 * stable_steps(model)["coupled"]
        steps = int(np.ceil(0.03 / dt))
        run = ExplicitUP(0.03 / steps).run(model, steps, record=lambda x, r, t: [x[2 * n + i_bot]])
        ax.plot(1e3 * run.times, run.samples[:, 0], style, lw=1.0, label=rule)
    mat = model.medium.material
    m_u = mat.elastic.constrained_modulus + mat.alpha ** 2 / mat.S
    ax.axhline(2 * mat.alpha / mat.S * 3000.0 / m_u, color="grey", lw=0.8, ls=":", label="2 alpha Q q / M_u")
    ax.set_xlabel("t [ms]")
    ax.set_ylabel("base pressure [Pa]")
    ax.set_title("(c) confined column, 3 x 241 nodes", fontsize=9)
    ax.legend(fontsize=7)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(HERE / "large_deformation.png"))
    args = ap.parse_args(argv)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4))
    _moved_nodes(axes[0])
    _energy_ratios(axes[1])
    _column(axes[2])
    fig.tight_layout()
    fig.savefig(args.out, dpi=130)
    print(args.out)


if __name__ == "__main__":
    main()
