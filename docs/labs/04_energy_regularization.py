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
# # Lab 4 — Energy regularization on the cracked bar
#
# A softening material law is ill-posed without a length scale: the damage localizes in the
# smallest band the discretization allows, so the energy spent to break a specimen goes to
# zero as the discretization is refined. rkfx's damage particle method (chapter 4) fixes the
# energy instead. Each SCNI particle $L$ softens by the linear law (4.2) between the threshold
# $\kappa_0 = f_t / E$ and a critical strain $\kappa_c$, and $\kappa_c$ is chosen per particle so
# that breaking it dissipates the fracture energy over its share of the crack,
# eq. (4.28):
#
# $$
# \kappa_c = \frac{G_F}{f_t}\,\frac{A_L}{V_L},
# $$
#
# with $V_L$ the particle's cell area and $A_L$ the chord of the cell along the crack through
# $\mathbf{x}_L$. The reference is the cohesive crack with the linear law (4.7): the bar's tip
# displacement at failure is $u_T^{max} = w_c = 2 G_F / f_t$ and the energy to break it
# $G_F A$, eqs. (4.7)-(4.9).
#
# In this lab we pull the bar at three resolutions with and without regularization and
# compare the force-displacement curves and the dissipated energy.

# %%
import os
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rkfx.cases.cracked_bar import load_path, load_targets, weak_points  # noqa: E402
from rkfx.fracture import damage as dm  # noqa: E402
from rkfx.models.damage_bar import elastic_limit, strip  # noqa: E402
from verification.cohesive_bar import CohesiveBar  # noqa: E402

OUT = Path(os.environ.get("RKFX_LAB_OUT", Path.cwd() / "lab_output"))
OUT.mkdir(parents=True, exist_ok=True)
t_start = time.perf_counter()

# %% [markdown]
# ## The bar
#
# Length $L = 100$, cross-section $A = 10$, $E = 2\times 10^6$, $f_t = 200$, $G_F = 1.885$,
# $\nu = 0$ (dimensionless units). `rkfx.models.damage_bar.strip` discretizes it as a 2-D strip
# of two rows of $n$ nodes with SCNI on the grid's Voronoi cells. The particles whose cells
# touch $x = L/2$ are weakened to $0.999\,\kappa_0$ so that the crack forms there.

# %%
L, A = 100.0, 10.0
material = dm.DamageMaterial(E=2.0e6, nu=0.0, ft=200.0, GF=1.885, plane="stress")
wc = material.critical_opening
bar = CohesiveBar(L, A, material.E, material.GF, material.ft)
print(f"kappa0 = {material.kappa0:.1e}, w_c = 2 G_F / f_t = {wc:.4e}, G_F A = {material.GF * A:.3f}")
resolutions = (16, 32, 64)

# %% [markdown]
# The unregularized model uses one constant $\kappa_c$ for every resolution: the value (4.28)
# gives the weak particles of the 16-node model (chord $A_L$ across the bar, crack normal
# $\mathbf{e}_x$). The two models are therefore identical at $n = 16$ and differ only under
# refinement.

# %%
s16 = strip(L, A, 16)
weak16 = np.flatnonzero(weak_points(s16, L))
chord16 = dm.chord_lengths(s16.geometry, weak16, np.tile([1.0, 0.0], (len(weak16), 1)))
kappa_c_const = float(dm.critical_strain(material, chord16, s16.volume[weak16]).mean())
print(f"constant kappa_c = {kappa_c_const:.4e} (= {kappa_c_const / material.kappa0:.1f} kappa0)")


# %% [markdown]
# ## Load paths
#
# Displacement control: an elastic step to 98% of the elastic limit, one just past it (only the
# weak particles start to damage, so the path takes the localized branch), then 30 equal
# steps to $1.02\,w_c$. Where no path is continuous in $u_T$ (a snap-back), `load_path`
# switches to dissipation control by itself.

# %%
def targets(u_peak: float, steps: int = 30) -> np.ndarray:
    return load_targets(u_peak, wc, steps, 1.02)  # the case's schedule


paths = {}
for regularized in (True, False):
    for n in resolutions:
        s = strip(L, A, n)
        model = dm.damage_model(material, s.volume, np.where(weak_points(s, L), 0.999, 1.0),
                                geometry=s.geometry, kappa_c=kappa_c_const, regularized=regularized)
        path = load_path(s, model, targets(elastic_limit(s, model)))
        paths[regularized, n] = (s, path)
        u_max = dm.failure_displacement(path.u, path.force)
        print(f"{'regularized' if regularized else 'constant kc':12s} n = {n:3d}: "
              f"dissipated / G_F A = {path.dissipated[-1] / (material.GF * A):.4f}, "
              f"u_T^max / w_c = {u_max / wc:.4f}, damaged particles {int(path.state.damaged.sum())}")

# %% [markdown]
# ## Mesh objectivity, checked
#
# With regularization every resolution breaks at $u_T^{max} \approx w_c$ and spends
# $0.999\,G_F A$ (the peak is $0.999 f_t A$ because of the weakening). With the constant
# $\kappa_c$ the band narrows with $h$ and the energy halves with each refinement.

# %%
GF_A = material.GF * A
reg = np.array([paths[True, n][1].dissipated[-1] for n in resolutions]) / GF_A
unreg = np.array([paths[False, n][1].dissipated[-1] for n in resolutions]) / GF_A
assert np.all(np.abs(reg / 0.999 - 1.0) < 5e-3), reg
assert all(abs(dm.failure_displacement(paths[True, n][1].u, paths[True, n][1].force) / wc - 1) < 5e-3
           for n in resolutions)
assert np.isclose(unreg[0], reg[0], rtol=1e-6)          # the same model at n = 16
assert np.all(unreg[:-1] > 1.5 * unreg[1:]), unreg      # energy lost under refinement
# Every model is broken at the end, F = 0.
assert all(abs(path.force[-1]) < 1e-6 * material.ft * A for _, path in paths.values())

# %%
fig, axes = plt.subplots(1, 3, figsize=(15, 4.3), layout="constrained")
u_ref = np.linspace(0.0, 1.05 * wc, 400)
for ax, regularized, title in ((axes[0], False, "constant kappa_c"), (axes[1], True, "regularized, eq. (4.28)")):
    ax.plot(u_ref / wc, bar.force(u_ref) / (material.ft * A), color="k", lw=3, alpha=0.3, label="cohesive crack")
    for n, shade in zip(resolutions, (0.45, 0.7, 0.95)):
        _, path = paths[regularized, n]
        ax.plot(path.u / wc, path.force / (material.ft * A), color=plt.cm.Blues(shade), label=f"n = {n}")
    ax.set_xlabel("u_T / w_c")
    ax.set_ylabel("F / (f_t A)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
axes[2].plot(resolutions, reg, "o-", label="regularized")
axes[2].plot(resolutions, unreg, "s--", label="constant kappa_c")
axes[2].axhline(0.999, color="k", lw=0.8, ls=":")
axes[2].set_xscale("log", base=2)
axes[2].set_xticks(resolutions, [str(n) for n in resolutions])
axes[2].set_xlabel("nodes along the bar")
axes[2].set_ylabel("dissipated energy / (G_F A)")
axes[2].set_title("energy to break the bar")
axes[2].legend()
axes[2].grid(alpha=0.3)
fig.savefig(OUT / "04_regularization.png", dpi=120)
plt.close(fig)

# %% [markdown]
# ## Where the energy goes
#
# The damage profile at the end of the regularized runs: in each model only the two particle
# columns beside $x = L/2$ (the weak section) break, so the damaged band narrows as $h$ shrinks,
# and $\kappa_c$ of (4.28) grows as $1/h$ ($V_L / A_L = h$ here) to keep the energy per crack
# area fixed.

# %%
fig, ax = plt.subplots(figsize=(6.5, 3.6), layout="constrained")
for n, shade in zip(resolutions, (0.45, 0.7, 0.95)):
    s, path = paths[True, n]
    bottom = s.points[:, 1] < 0.5 * s.H
    ax.step(s.points[bottom, 0], path.state.damage[bottom], where="mid", color=plt.cm.Reds(shade), label=f"n = {n}")
    kc = path.state.kappa_c[path.state.damaged]
    assert np.allclose(kc, kc[0])  # the band particles share one kappa_c
ax.set_xlim(0.35 * L, 0.65 * L)
ax.set_xlabel("x")
ax.set_ylabel("damage D")
ax.set_title("regularized models at the end of loading")
ax.legend(fontsize=8)
fig.savefig(OUT / "04_damage_profile.png", dpi=120)
plt.close(fig)
kc_by_n = [np.nanmax(paths[True, n][1].state.kappa_c) for n in resolutions]
print("regularized kappa_c of the band by n:", ", ".join(f"{v:.3e}" for v in kc_by_n))
# kappa_c h is the same at every resolution: (G_F / f_t) A_L / V_L with V_L / A_L = h.
kc_h = np.array(kc_by_n) * L / (np.array(resolutions) - 1)
assert np.allclose(kc_h, kc_h[0], rtol=1e-3), kc_h

elapsed = time.perf_counter() - t_start
print(f"figures in {OUT}; lab ran in {elapsed:.1f} s")

# %% [markdown]
# ## Exercises
#
# 1. Add $n = 128$ to `resolutions`. Predict the dissipated energy of the constant-$\kappa_c$
#    model before you run it. Where does its force-displacement curve turn back (snap back)?
# 2. Use `strip(L, A, n, cells="median-dual")` for the regularized model. The energy is still
#    $G_F A$ but $u_T^{max}$ overshoots $w_c$: plot the damage of the four band particles over
#    the load path and explain why they do not fail together.
# 3. Halve and double $G_F$. Check that the regularized models still dissipate $G_F A$ and
#    break at $w_c = 2G_F/f_t$. What happens when $G_F$ is so small that (4.28) gives
#    $\kappa_c < \kappa_0$ on the coarse model (`verification.cohesive_bar` tells you)?
# 4. Plot the crack opening `path.cod` (eq. (4.13)) against $u_T$ together with
#    `bar.opening(u)` of the cohesive reference, for the regularized and the unregularized
#    models.
