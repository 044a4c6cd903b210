# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Lab 2 — Nodal integration and the linear patch test
#
# A Galerkin meshfree method still has to integrate the weak form. Evaluating everything at
# the nodes, with the node's cell area $A_L$ as weight, is the cheapest choice:
#
# * **DNI** (direct nodal integration): $\int \mathbf{B}^T\mathbf{D}\mathbf{B}\,d\Omega \approx
#   \sum_L \mathbf{B}^T(\mathbf{x}_L)\mathbf{D}\mathbf{B}(\mathbf{x}_L) A_L$ with the direct
#   gradients of $N_I$;
# * **SCNI** (stabilized conforming nodal integration): the gradient at $\mathbf{x}_L$ is
#   replaced by its average over the nodal cell $\Omega_L$, computed by the divergence theorem
#   as a boundary integral, eq. (3.55):
#   $\tilde N_{I,i}(\mathbf{x}_L) = \frac{1}{A_L}\int_{\partial\Omega_L} N_I\, n_i\, d\Gamma$;
# * **MSCNI** (modified SCNI): SCNI plus a stabilization on the subcells of each cell,
#   eq. (3.56), which penalises the zero-energy modes that nodal integration leaves.
#
# The *linear patch test* asks whether a method reproduces a linear displacement field exactly.
# The RK shape functions reproduce linear fields (Lab 1), so any failure is the integration's
# fault. SCNI passes because its smoothed gradients satisfy the *integration constraint*
# $\sum_L \tilde{\nabla} N_I(\mathbf{x}_L) A_L = \int_{\partial\Omega} N_I\,\mathbf{n}\,d\Gamma$
# (eq. (3.55) summed over the cells); DNI does not satisfy it and fails.

# %%
import os
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

from rkfx.approximation.shape_functions import evaluate, rk_approximation  # noqa: E402
from rkfx.assembly.boundary import boundary_quadrature  # noqa: E402
from rkfx.conditions import Displacement, Traction  # noqa: E402
from rkfx.geometry.nodal_domains import nodal_domains  # noqa: E402
from rkfx.geometry.particles import jittered  # noqa: E402
from rkfx.integration.quadrature import integration_rules  # noqa: E402
from rkfx.materials.elasticity import ElasticMaterial  # noqa: E402
from rkfx.models.elastostatics import solve_plane_strain  # noqa: E402
from rkfx.output.paraview import nodal_cells  # noqa: E402
from verification.manufactured import LinearField  # noqa: E402

OUT = Path(os.environ.get("RKFX_LAB_OUT", Path.cwd() / "lab_output"))
OUT.mkdir(parents=True, exist_ok=True)
t_start = time.perf_counter()

# %% [markdown]
# ## Nodes and their cells
#
# An irregular node set on the unit square (a jittered 9 x 9 grid). rkfx's nodal cells are the
# median-dual cells of the node triangulation: each triangle is cut into three quadrilateral
# subcells (node, edge midpoint, centroid, edge midpoint), and the cell of node $L$ is the union
# of its subcells. They tile the domain exactly.

# %%
n_side = 9
p = jittered(n_side, amplitude=0.3, seed=3)
domains = nodal_domains(p)
print(f"{p.num_nodes} nodes; the cells cover an area of {domains.area.sum():.15f}")
assert abs(domains.area.sum() - 1.0) < 1e-13

cells = nodal_cells(p)
fig, ax = plt.subplots(figsize=(5.5, 5.5), layout="constrained")
colors = plt.cm.tab20(cells.node % 20)
ax.add_collection(PolyCollection(cells.vertices, facecolors=colors, edgecolors="none", alpha=0.6))
ax.triplot(p.x[:, 0], p.x[:, 1], p.triangles, color="k", lw=0.3)
ax.plot(p.x[:, 0], p.x[:, 1], "k.", ms=4)
ax.set_aspect("equal")
ax.set_title("median-dual nodal cells (one colour per node)")
fig.savefig(OUT / "02_nodal_cells.png", dpi=120)
plt.close(fig)

# %% [markdown]
# ## The integration constraint
#
# `integration_rules(name, p, rk, domains)` returns the quadratures of a rule as sparse rows:
# points, weights and gradient rows. We sum $\nabla N_I\,w$ over the points of each rule and
# compare with the boundary integral of $N_I\,\mathbf{n}$ (one Gauss point per boundary
# half-segment, the same midpoint rule SCNI uses on the cell sides).

# %%
rk = rk_approximation(p.x, p.spacing, support_factor=1.5)
bq = boundary_quadrature(p, domains, rk, points_per_segment=1)
boundary_integral = bq.rows.matrix(0).T @ (bq.weights[:, None] * bq.normals)   # (nodes, 2)


def constraint_error(rule: str) -> float:
    q = integration_rules(rule, p, rk, domains)[0]       # MSCNI's first quadrature is SCNI
    domain_sum = np.stack([q.gradients.matrix(k).T @ q.weights for k in range(2)], axis=1)
    return float(np.abs(domain_sum - boundary_integral).max())


ic = {rule: constraint_error(rule) for rule in ("dni", "scni")}
for rule, err in ic.items():
    print(f"{rule:5s}: max_I |sum_L grad N_I(x_L) A_L - int N_I n dGamma| = {err:.2e}")
assert ic["scni"] < 1e-13 and ic["dni"] > 1e-4

# %% [markdown]
# ## The patch test
#
# Impose an arbitrary linear field $\mathbf{u} = \mathbf{c} + \mathbf{G}\mathbf{x}$
# (`verification.manufactured.LinearField`): its displacement on the bottom and left sides
# (Nitsche's method) and its exact traction on the top and right. With no body force, the exact
# solution of plane-strain elasticity is the linear field itself. `solve_plane_strain` takes
# the integration rule by name.

# %%
material = ElasticMaterial(E=2.0, nu=0.3)
field = LinearField(G=np.array([[1e-3, 2e-3], [-1.5e-3, 3e-3]]), c=np.array([1e-3, -2e-3]),
                    lam=material.lame_lambda, mu=material.shear_modulus)
conditions = [Displacement(side, lambda x, t: field.displacement(x)) for side in ("bottom", "left")]
conditions += [Traction(side, lambda x, t, n: field.traction(x, n)) for side in ("top", "right")]

# Check points: a fine grid over the square.
m = 61
gx = np.linspace(0.0, 1.0, m)
PX, PY = np.meshgrid(gx, gx)
pts = np.column_stack([PX.ravel(), PY.ravel()])
u_exact = field.displacement(pts)

errors, error_maps = {}, {}
for rule in ("dni", "gauss2", "scni", "mscni"):
    sol = solve_plane_strain(p, material, conditions, rule=rule, bc_method="nitsche")
    diff = np.linalg.norm(sol.displacement(pts) - u_exact, axis=1)
    errors[rule] = float(diff.max() / np.linalg.norm(u_exact, axis=1).max())
    error_maps[rule] = diff.reshape(m, m)
    print(f"{rule:6s}: max |u^h - u| / max |u| = {errors[rule]:.2e}")

assert errors["scni"] < 1e-10 and errors["mscni"] < 1e-10   # pass to round-off
assert errors["dni"] > 1e-5 and errors["gauss2"] > 1e-5     # fail: not integration-consistent

# %% [markdown]
# Note that Gauss quadrature on the background triangles fails too: the RK shape functions are
# rational functions whose supports do not follow the triangles, so no practical Gauss rule
# integrates them exactly, and the integration constraint is violated by a small amount.

# %%
fig, axes = plt.subplots(1, 3, figsize=(14, 4.3), layout="constrained")
names = list(errors)
axes[0].bar(names, [errors[r] for r in names], color=["C3", "C1", "C0", "C2"])
axes[0].set_yscale("log")
axes[0].axhline(1e-10, color="k", ls=":", lw=1)
axes[0].set_ylabel("max |u^h - u| / max |u|")
axes[0].set_title("linear patch test")
for ax, rule in zip(axes[1:], ("dni", "scni")):
    im = ax.pcolormesh(PX, PY, np.log10(error_maps[rule] + 1e-20), shading="auto", cmap="magma")
    ax.plot(p.x[:, 0], p.x[:, 1], "w.", ms=2)
    ax.set_aspect("equal")
    ax.set_title(f"log10 |u^h - u|, {rule.upper()}")
    fig.colorbar(im, ax=ax, shrink=0.8)
fig.savefig(OUT / "02_patch_test.png", dpi=120)
plt.close(fig)

# %% [markdown]
# ## Why MSCNI as well?
#
# SCNI samples each cell once. Its stiffness can have near-zero-energy modes that oscillate
# from node to node; MSCNI adds the subcell terms of eq. (3.56) with weight $\varepsilon_p$,
# which vanish for linear fields (the patch test is still passed, as above) but penalise those
# oscillations. The extra quadrature appears as a second entry of `integration_rules("mscni", ...)`:
# its rows are the differences $\tilde\nabla N_I(\mathbf{x}_L) - \tilde\nabla N_I(\hat{\mathbf{x}}_C)$
# between the cell and subcell smoothed gradients, so they annihilate any linear field.

# %%
scni_q, stab_q = integration_rules("mscni", p, rk, domains)
print(f"MSCNI: {len(scni_q.weights)} SCNI points + {len(stab_q.weights)} subcell terms")
for k in range(2):
    linear = stab_q.gradients.matrix(k) @ (p.x @ np.array([0.7, -0.4]))
    assert np.abs(linear).max() < 1e-12
assert abs(stab_q.weights.sum() - 1.0) < 1e-12   # eps_p = 1: the subcells tile the domain

elapsed = time.perf_counter() - t_start
print(f"figures in {OUT}; lab ran in {elapsed:.1f} s")

# %% [markdown]
# ## Exercises
#
# 1. Repeat the patch test with `bc_method="transformation"` (collocation of the prescribed
#    displacement at the boundary nodes) and MSCNI. Is the error still at round-off? Explain
#    with the fact that RK shape functions do not interpolate (Lab 1).
# 2. Replace the linear field by `verification.manufactured.SineField` (pass its `body_force`
#    to `solve_plane_strain` and prescribe its displacement on all four sides). Compute the
#    error for `n_side` = 9, 17, 33 with DNI, SCNI and MSCNI and plot error against h.
#    Which rules converge, and at what rate?
# 3. Assemble the stiffness matrix yourself with `rkfx.assembly.operators.stiffness` for DNI
#    and SCNI and count its eigenvalues near zero (beyond the three rigid modes). What do the
#    extra eigenvectors look like?
# 4. Repeat the integration-constraint check with `gauss4` instead of `gauss2`. Does a higher
#    Gauss order reduce the violation, and by how much?
