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
# # Lab 1 — RK shape functions and the reproducing conditions
#
# The reproducing kernel (RK) shape function of node $I$ is a kernel window corrected so that
# the approximation reproduces every monomial of the basis exactly:
#
# $$
# N_I(\mathbf{x}) = \mathbf{H}^T(\mathbf{0})\,\mathbf{M}^{-1}(\mathbf{x})\,
#   \mathbf{H}(\mathbf{x}-\mathbf{x}_I)\,\Phi_a(\mathbf{x}-\mathbf{x}_I),
# \qquad
# \mathbf{M}(\mathbf{x}) = \sum_I \mathbf{H}(\mathbf{x}-\mathbf{x}_I)\mathbf{H}^T(\mathbf{x}-\mathbf{x}_I)
#   \Phi_a(\mathbf{x}-\mathbf{x}_I)
# $$
#
# (eqs. (3.17)-(3.25) of the dissertation: the cubic B-spline kernel $\Phi_a$ is eq. (3.19),
# the moment matrix $\mathbf{M}$ eq. (3.24), the shape function eq. (3.25)). By construction
# the shape functions satisfy the reproducing conditions (eq. (3.22))
#
# $$
# \sum_I N_I(\mathbf{x})\, x_I^i y_I^j = x^i y^j, \qquad 0 \le i + j \le n,
# $$
#
# for a basis $\mathbf{H}$ of degree $n$. In this lab we build an RK approximation on an
# irregular node set with rkfx, evaluate $N_I$ and its gradients, check the reproducing
# conditions to round-off, and compare the linear ($n = 1$) with the quadratic ($n = 2$) basis.

# %%
import os
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rkfx.approximation.kernel import cubic_spline_values  # noqa: E402
from rkfx.approximation.shape_functions import evaluate, rk_approximation  # noqa: E402
from rkfx.geometry.particles import jittered  # noqa: E402

OUT = Path(os.environ.get("RKFX_LAB_OUT", Path.cwd() / "lab_output"))
OUT.mkdir(parents=True, exist_ok=True)
t_start = time.perf_counter()

# %% [markdown]
# ## The kernel
#
# rkfx uses the cubic B-spline of eq. (3.19) as a function of the normalised distance
# $s = |\mathbf{x} - \mathbf{x}_I| / a_I$; it is $C^2$, positive for $s < 1$ and zero beyond,
# so each node influences only the disc of radius $a_I$ (its *support*).

# %%
s = np.linspace(0.0, 1.2, 241)
phi = cubic_spline_values(s)
assert phi[0] == 2.0 / 3.0 and np.all(phi[s >= 1.0] == 0.0)
fig, ax = plt.subplots(figsize=(5, 3.2), layout="constrained")
ax.plot(s, phi)
ax.set_xlabel("s = |x - x_I| / a_I")
ax.set_ylabel("Phi(s)")
ax.set_title("cubic B-spline kernel, eq. (3.19)")
ax.grid(alpha=0.3)
fig.savefig(OUT / "01_kernel.png", dpi=120)
plt.close(fig)

# %% [markdown]
# ## An irregular node set
#
# Meshfree methods do not need a mesh, but rkfx keeps a triangulation of the nodes for the
# geometry and (in Lab 2) for the nodal integration cells. `jittered` moves the interior nodes
# of an 11 x 11 grid on the unit square at random, by up to 0.3 spacings, so that nothing is
# aligned by accident, and triangulates them (`from_points`: Delaunay inside a polygon whose
# sides it names).

# %%
n_side = 11
p = jittered(n_side, amplitude=0.3, seed=7)
print(f"{p.num_nodes} nodes, mean spacing {p.spacing.mean():.4f}")

# %% [markdown]
# ## Two approximations: linear and quadratic basis
#
# The support of node $I$ is $a_I = c\,h_I$. The moment matrix is invertible only when every
# point sees enough non-collinear nodes: 3 for the linear basis, 6 for the quadratic one, so
# the quadratic basis needs a larger support factor $c$ (1.5 and 2.5 are rkfx's usual choices).

# %%
rk1 = rk_approximation(p.x, p.spacing, support_factor=1.5, order=1)
rk2 = rk_approximation(p.x, p.spacing, support_factor=2.5, order=2)

# Evaluation points: a fine grid over the square (boundary included).
m = 81
gx = np.linspace(0.0, 1.0, m)
PX, PY = np.meshgrid(gx, gx)
pts = np.column_stack([PX.ravel(), PY.ravel()])

# Rows over the nodes: entries [N_I, N_I,x, N_I,y] at every point (direct gradients).
rows1 = evaluate(rk1, pts, gradients=True)
rows2 = evaluate(rk2, pts, gradients=True)
N1, N1x, N1y = (rows1.matrix(k) for k in range(3))
N2, N2x, N2y = (rows2.matrix(k) for k in range(3))
print("mean nodes per point: linear", np.diff(rows1.indptr).mean(), " quadratic", np.diff(rows2.indptr).mean())

# %% [markdown]
# ## The reproducing conditions, checked
#
# A sparse row matrix $\mathbf{N}$ (points x nodes) applied to nodal values of a monomial must
# give the monomial at the points. For the gradients the same holds with the derivative of the
# monomial: $\sum_I N_{I,x}(\mathbf{x}) = 0$ and $\sum_I N_{I,x}(\mathbf{x})\,x_I = 1$.

# %%
xI, yI = p.x[:, 0], p.x[:, 1]
px, py = pts[:, 0], pts[:, 1]
one = np.ones(p.num_nodes)

pu_error = np.abs(N1 @ one - 1.0)
lin_error = max(np.abs(N1 @ xI - px).max(), np.abs(N1 @ yI - py).max())
grad_pu = max(np.abs(N1x @ one).max(), np.abs(N1y @ one).max())
grad_lin = max(np.abs(N1x @ xI - 1.0).max(), np.abs(N1y @ yI - 1.0).max(),
               np.abs(N1x @ yI).max(), np.abs(N1y @ xI).max())
print(f"linear basis:  max |sum N_I - 1| = {pu_error.max():.2e}, max |sum N_I x_I - x| = {lin_error:.2e}")
print(f"               gradients: {grad_pu:.2e} (sum N_I,x = 0), {grad_lin:.2e} (sum N_I,x x_I = 1)")
assert pu_error.max() < 1e-12 and lin_error < 1e-12
assert grad_pu < 1e-10 and grad_lin < 1e-10

# %% [markdown]
# The linear basis does **not** reproduce $x^2$; the quadratic one does, and its gradients
# reproduce $\partial(x^2)/\partial x = 2x$ as well.

# %%
quad1 = np.abs(N1 @ xI**2 - px**2).max()
quad2 = max(np.abs(N2 @ xI**2 - px**2).max(), np.abs(N2 @ (xI * yI) - px * py).max(),
            np.abs(N2 @ yI**2 - py**2).max())
quad2_grad = max(np.abs(N2x @ xI**2 - 2 * px).max(), np.abs(N2y @ (xI * yI) - px).max())
pu2 = np.abs(N2 @ one - 1.0).max()
print(f"x^2 with the linear basis:    max error {quad1:.2e}")
print(f"quadratics, quadratic basis:  max error {quad2:.2e}, gradients {quad2_grad:.2e}, PU {pu2:.2e}")
assert quad1 > 1e-4          # a genuine approximation error, not round-off
assert quad2 < 1e-11 and quad2_grad < 1e-9 and pu2 < 1e-12

# %% [markdown]
# ## What a shape function looks like
#
# Take the node nearest the centre. Its RK shape function is a smooth bump over the support
# disc; unlike a finite-element hat it is not interpolating ($N_I(\mathbf{x}_J) \ne \delta_{IJ}$),
# and it may be slightly negative near the edge of the support, especially with the quadratic
# basis. The partition of unity holds everywhere regardless.

# %%
centre = int(np.argmin(np.linalg.norm(p.x - 0.5, axis=1)))
f1 = N1[:, centre].toarray().reshape(m, m)
f2 = N2[:, centre].toarray().reshape(m, m)
at_nodes = evaluate(rk1, p.x).matrix(0)
print(f"N_I(x_I) = {at_nodes[centre, centre]:.3f} (not 1: RK shape functions do not interpolate)")
assert at_nodes[centre, centre] < 0.99
assert f2.min() < f1.min() <= 1e-12  # quadratic basis: deeper negative lobes

fig, axes = plt.subplots(1, 3, figsize=(14, 4.2), layout="constrained")
for ax, f, title in ((axes[0], f1, "linear basis, c = 1.5"), (axes[1], f2, "quadratic basis, c = 2.5")):
    im = ax.pcolormesh(PX, PY, f, shading="auto", cmap="viridis")
    ax.triplot(p.x[:, 0], p.x[:, 1], p.triangles, color="w", lw=0.3, alpha=0.5)
    ax.plot(*p.x[centre], "r+", ms=10)
    ax.set_aspect("equal")
    ax.set_title(f"N_I near the centre, {title}")
    fig.colorbar(im, ax=ax, shrink=0.8)
im = axes[2].pcolormesh(PX, PY, np.log10(pu_error.reshape(m, m) + 1e-18), shading="auto", cmap="magma")
axes[2].set_aspect("equal")
axes[2].set_title("log10 |sum_I N_I - 1| (linear basis)")
fig.colorbar(im, ax=axes[2], shrink=0.8)
fig.savefig(OUT / "01_shape_functions.png", dpi=120)
plt.close(fig)

# %% [markdown]
# A cut along $y = y_I$ shows the two shape functions side by side, and what each basis makes
# of $u = x^2$ (the linear one is off by $O(h^2)$, the quadratic one exact).

# %%
row = np.argmin(np.abs(gx - p.x[centre, 1]))
cut = slice(row * m, (row + 1) * m)
fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), layout="constrained")
axes[0].plot(gx, f1[row], label="linear")
axes[0].plot(gx, f2[row], label="quadratic")
axes[0].axhline(0.0, color="k", lw=0.5)
axes[0].set_xlabel("x")
axes[0].set_title(f"N_I along y = {p.x[centre, 1]:.3f}")
axes[0].legend()
axes[1].semilogy(gx, np.abs(N1[cut] @ xI**2 - gx**2) + 1e-18, label="linear basis")
axes[1].semilogy(gx, np.abs(N2[cut] @ xI**2 - gx**2) + 1e-18, label="quadratic basis")
axes[1].set_xlabel("x")
axes[1].set_title("|sum N_I x_I^2 - x^2|")
axes[1].legend()
fig.savefig(OUT / "01_linear_vs_quadratic.png", dpi=120)
plt.close(fig)

elapsed = time.perf_counter() - t_start
print(f"figures in {OUT}; lab ran in {elapsed:.1f} s")

# %% [markdown]
# ## Exercises
#
# 1. Lower the support factor of the linear basis from 1.5 towards 1.0. At what value does
#    `evaluate` raise `SingularMomentMatrix`, and which point does the message name? Why does
#    the quadratic basis fail at a larger factor?
# 2. Measure the error of reproducing $u = \sin(\pi x)\sin(\pi y)$ (nodal coefficients equal to
#    nodal values) for `n_side` = 11, 21, 41 with both bases, and estimate the convergence
#    rate of the maximum error. Is it the rate you expect for a basis of degree $n$?
# 3. Check the gradient reproducing conditions for the quadratic basis:
#    $\sum_I N_{I,y}\, x_I y_I = x$ and $\sum_I N_{I,y}\, y_I^2 = 2y$.
# 4. Increase the jitter from $0.3h$ to $0.45h$. How do the number of neighbours per point and
#    the minimum of $N_I$ change? Do the reproducing conditions still hold to round-off?
