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
# # Lab 3 — The inf-sup problem and fluid pressure projection (Terzaghi)
#
# rkfx solves Biot's equations (3.1)-(3.10) with the *same* RK shape functions for the
# displacement and the pore pressure (equal order, eq. (3.26)). That is convenient but, in the
# undrained limit (small permeability or small time step), the discrete pair violates the
# inf-sup (LBB) condition: the pressure develops spurious oscillations, exactly like equal-order
# $P_1$-$P_1$ finite elements of incompressible flow.
#
# The cure used here is the **fluid pressure projection** (FPP): a term
# $\int \varepsilon_f\,(\psi - \Pi\psi)(\dot p - \Pi\dot p)\,d\Omega$ added to the mass balance,
# eq. (3.49), where $\Pi$ projects onto cell-wise constants. It penalises only the part of the
# pressure that a constant per cell cannot represent — the oscillation — and it fades out as the
# problem becomes drained, through the parameter of eqs. (3.53)-(3.54):
#
# $$
# \varepsilon_f = \frac{\langle 1 - 3r\rangle\,(1 + \tanh(2 - 12 r))}{M'},\qquad
# r = \frac{c_v\,\Delta t}{h^2}.
# $$
#
# We compare the four integration variants of `rkfx.models.poroelasticity` on Terzaghi's
# consolidation column after the first time step, when the layer is still undrained except for
# a thin boundary layer at the drained top.

# %%
import os
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rkfx.conditions import Displacement, Pressure, Traction  # noqa: E402
from rkfx.geometry.particles import structured  # noqa: E402
from rkfx.models.poroelasticity import VARIANTS, PoroMaterial, fpp_parameter, solve_biot  # noqa: E402
from rkfx.solvers.integrate import time_grid  # noqa: E402
from verification.terzaghi import Terzaghi  # noqa: E402

OUT = Path(os.environ.get("RKFX_LAB_OUT", Path.cwd() / "lab_output"))
OUT.mkdir(parents=True, exist_ok=True)
t_start = time.perf_counter()

# %% [markdown]
# ## The problem
#
# A column $W \times H = 3 \times 10$ m, fixed and impermeable at the bottom, rollers on the
# sides, loaded suddenly by $q = 1$ kPa on its drained top ($p = 0$). Soft soil, $E = 1$ kPa,
# $\nu = 0$, mobility $k = 10^{-9}$ m$^2$/(Pa s), incompressible constituents ($S = 0$,
# $\alpha = 1$). At $t = 0^+$ the fluid carries the whole load, $p = p_0 = q$; the exact
# solution is the classical series of `verification.terzaghi`.

# %%
E, nu, k, alpha, S = 1.0e3, 0.0, 1.0e-9, 1.0, 0.0
W, H, q = 3.0, 10.0, 1.0e3
nx, ny = 7, 21
material = PoroMaterial(E, nu, k, alpha, S)
exact = Terzaghi(E, nu, k, H, q, alpha, S)
p0 = exact.p0
h = H / (ny - 1)
dt = 1.0
r = material.consolidation_coefficient * dt / h**2
print(f"p0 = {p0:.1f} Pa, c_v = {exact.c_v:.2e} m^2/s, r = c_v dt / h^2 = {r:.1e}")

particles = structured(W, H, nx, ny)
displacements = [Displacement("bottom"), Displacement("left", components=(0,)),
                 Displacement("right", components=(0,))]
pressures = [Pressure("top")]   # drained top, p = 0
tractions = [Traction("top", lambda x, t, n: np.tile([0.0, -q], (len(x), 1)))]

# %% [markdown]
# $r = 4 \times 10^{-6}$: one time step lets the pressure diffuse over a layer of thickness
# $\sqrt{c_v \Delta t} = 1$ mm, far below the node spacing $h = 0.5$ m. The exact profile is
# $p = p_0$ everywhere except at the very top.
#
# ## One step with each variant
#
# | variant    | integration | stabilization |
# |------------|-------------|---------------|
# | `ni`       | DNI         | none          |
# | `scni`     | SCNI + MSCNI subcells (3.56) | none |
# | `ni+fpp`   | DNI         | FPP (3.49)-(3.52) |
# | `scni+fpp` | SCNI + MSCNI subcells | FPP on the same cells (3.60) |

# %%
z = np.linspace(0.0, H, 201)
axis = np.column_stack([np.full_like(z, 0.5 * W), z])
p_exact = exact.pressure(z, dt)
away = z < H - 2.0 * h      # away from the drained boundary layer
profiles, deviation, overshoot = {}, {}, {}
for variant in VARIANTS:
    sol = solve_biot(particles, material, np.array([0.0, dt]), [dt], displacements=displacements,
                     pressures=pressures, tractions=tractions, variant=variant)
    profiles[variant] = sol.pressure(axis)[0]
    deviation[variant] = float(np.abs(profiles[variant] - p_exact)[away].max() / p0)
    overshoot[variant] = float(profiles[variant].max() / p0 - 1.0)
    print(f"{variant:9s}: max |p - p_exact| / p0 below the top layer = {deviation[variant]:.3f}, "
          f"overshoot max p / p0 - 1 = {overshoot[variant]:+.3f}")

# Unstabilized equal order oscillates; FPP removes the oscillation.
assert deviation["ni"] > 0.5 and deviation["scni"] > 0.5
assert deviation["scni+fpp"] < 0.05 and deviation["ni+fpp"] < 0.2

# %%
fig, axes = plt.subplots(1, 2, figsize=(11, 5.5), layout="constrained")
for ax, zoom in zip(axes, (False, True)):
    ax.plot(p_exact / p0, z / H, color="k", lw=3, alpha=0.35, label="exact")
    for variant, style in zip(VARIANTS, ("C3-", "C1--", "C2-.", "C0-")):
        ax.plot(profiles[variant] / p0, z / H, style, lw=1.3, label=variant)
    ax.set_xlabel("p / p0")
    ax.set_ylabel("z / H (drained top at 1)")
    ax.grid(alpha=0.3)
    if zoom:
        ax.set_ylim(0.7, 1.0)
        ax.set_title("near the drained top")
    else:
        ax.set_title(f"after the first step, dt = {dt:g} s")
axes[0].legend(fontsize=8)
fig.savefig(OUT / "03_first_step.png", dpi=120)
plt.close(fig)

# %% [markdown]
# ## The FPP parameter fades out when the flow is resolved
#
# $\varepsilon_f$ is largest in the undrained limit $r \to 0$ and vanishes for $r \ge 1/3$:
# once the time step lets the pressure diffuse over a node spacing, the equal-order pair is
# stable and no stabilization is added.

# %%
dts = np.logspace(-2, 8, 201)
eps = fpp_parameter(material, dts, h) * material.oedometric_storage_modulus
rs = material.consolidation_coefficient * dts / h**2
assert abs(eps[0] - (1.0 + np.tanh(2.0))) < 1e-6 and np.all(eps[rs >= 1 / 3] == 0.0)
fig, ax = plt.subplots(figsize=(5.5, 3.5), layout="constrained")
ax.semilogx(rs, eps)
ax.axvline(1 / 3, color="k", ls=":", lw=1)
ax.set_xlabel("r = c_v dt / h^2")
ax.set_ylabel("eps_f M'")
ax.set_title("FPP parameter, eqs. (3.53)-(3.54)")
ax.grid(alpha=0.3)
fig.savefig(OUT / "03_fpp_parameter.png", dpi=120)
plt.close(fig)

# %% [markdown]
# ## Consolidation over time
#
# With SCNI + FPP, march on to the consolidation times $T = c_v t / H^2 = 0.01, 0.05, 0.2$
# with growing steps (`time_grid`: the step grows by 1.5 every 10 steps, so each factorization
# is reused) and compare with the series.

# %%
t_out = np.array([0.01, 0.05, 0.2]) * H**2 / exact.c_v
times = np.r_[0.0, dt + time_grid(t_out - dt, 1.5 * dt, 1.5, hold=10)]
times[np.searchsorted(times, t_out - 1e-9 * t_out)] = t_out
sol = solve_biot(particles, material, times, t_out, displacements=displacements, pressures=pressures,
                 tractions=tractions, variant="scni+fpp")
p_later = sol.pressure(axis)
l2 = []
fig, ax = plt.subplots(figsize=(6, 5), layout="constrained")
for i, t in enumerate(t_out):
    pe = exact.pressure(z, t)
    l2.append(float(np.linalg.norm(p_later[i] - pe) / np.linalg.norm(pe)))
    ax.plot(pe / p0, z / H, color=f"C{i}", lw=3, alpha=0.35)
    ax.plot(p_later[i, ::10] / p0, z[::10] / H, "o", mfc="none", color=f"C{i}",
            label=f"T = {exact.dimensionless_time(t):.2f} (L2 error {l2[-1]:.1%})")
ax.set_xlabel("p / p0")
ax.set_ylabel("z / H")
ax.set_title(f"SCNI + FPP, {sol.steps} steps: lines exact, markers rkfx")
ax.legend(fontsize=8)
ax.grid(alpha=0.3)
fig.savefig(OUT / "03_consolidation.png", dpi=120)
plt.close(fig)
print("relative L2 errors at T = 0.01, 0.05, 0.2:", ", ".join(f"{e:.3f}" for e in l2))
assert max(l2) < 0.05

elapsed = time.perf_counter() - t_start
print(f"figures in {OUT}; lab ran in {elapsed:.1f} s")

# %% [markdown]
# ## Exercises
#
# 1. Increase the first time step from 1 s to $10^4$, $10^5$ and $10^6$ s and rerun the four
#    variants. At which $r$ do `ni` and `scni` stop oscillating? Compare with the point where
#    $\varepsilon_f$ vanishes.
# 2. Refine the column (`ny` = 21, 41, 81 with `nx` scaled accordingly) and plot the
#    first-step `scni+fpp` profile near the top. Does the boundary layer get resolved, and
#    how does the L2 error behave?
# 3. Make the constituents compressible (`S` = 1e-4 1/Pa). How do $p_0$, $c_v$ and the
#    oscillation of the unstabilized variants change? Explain with the storage term of
#    eq. (3.2).
# 4. Plot the vertical displacement of the top, `sol.displacement(...)`, against time for the
#    consolidation run and compare with `Terzaghi.settlement(t)` of `verification.terzaghi`.
