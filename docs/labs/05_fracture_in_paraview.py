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
# # Lab 5 — A fracture run in ParaView
#
# Kalthoff's impact problem on a coarse particle grid, with the damage particle method of
# chapter 4 in explicit dynamics: the upper half of a pre-notched steel plate whose lower left
# edge is struck at $v_0 = 16.5$ m/s. A crack leaves the notch tip at a steep angle
# (about 70 degrees in the experiment). We write the particle fields through time with
# `rkfx.output.paraview.FieldSeries` — the particles as points and their nodal cells as
# quadrilaterals, each carrying displacement, velocity, damage $D$ and crack opening
# $w / w_c$ — then read the files back with pyvista and render the damage off-screen.
#
# The run uses the case module's public pieces (`rkfx.cases.kalthoff.setup`, which builds the
# plate, tracking and damage model; `model_conditions`, the impact and the roller) and drives
# the explicit model of `rkfx.models.damage_dynamics` with the central-difference stepper
# itself, so that a recorder can write a ParaView step at every output.

# %%
import os
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rkfx.approximation.shape_functions import evaluate  # noqa: E402
from rkfx.cases import kalthoff  # noqa: E402
from rkfx.fracture import damage as dm  # noqa: E402
from rkfx.models.damage_dynamics import DamageDynamics  # noqa: E402
from rkfx.output.paraview import FieldSeries, nodal_cells, pvd_times  # noqa: E402
from rkfx.solvers.central_difference import CentralDifference  # noqa: E402

OUT = Path(os.environ.get("RKFX_LAB_OUT", Path.cwd() / "lab_output"))
OUT.mkdir(parents=True, exist_ok=True)
VTK = OUT / "05_vtk"
t_start = time.perf_counter()

# %% [markdown]
# ## The model
#
# The case's parameters (steel, $E = 190$ GPa, $f_t = 0.95$ GPa, $G_F = 20$ kN/m) with about 40
# particles per side ($h \approx 2.6$ mm; the case's studies use 150-450). The pre-existing
# crack cuts the RK supports by the diffraction method, the cells are the grid's Voronoi
# rectangles, the damage is regularized by eq. (4.28) and grows by particle tracking
# (eq. (4.22)) from the four particles around the notch tip.

# %%
prm = {name: p.default for name, p in kalthoff.PARAMS.items()}
material = dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], "strain")
plate, track, model = kalthoff.setup(40, material, prm)
n = plate.p.num_nodes
t_end = 60e-6
steps = int(np.ceil(t_end / plate.dt - 1e-9))
print(f"{len(plate.xs)} x {len(plate.ys)} particles, h = {plate.h * 1e3:.2f} mm, dt = {plate.dt * 1e9:.0f} ns, "
      f"{steps} steps to {t_end * 1e6:.0f} us")

# %% [markdown]
# ## Writing the fields
#
# `FieldSeries(folder, name, points, cells=...)` writes one `.vtu` per call of `write(t, **fields)`
# and keeps the `.pvd` time index up to date. Scalars have shape `(n,)`, vectors `(n, 2)`.
# The recorder below is called by the stepper every `every` steps; it evaluates the
# displacement $u^h(\mathbf{x}_L) = \sum_I N_I(\mathbf{x}_L)\,\mathbf{d}_I$ at the particles (the
# coefficients $\mathbf{d}_I$ are not nodal values, Lab 1) and copies the damage history.
#
# The 265 steps take a second or two on one core. The compiled kernels use all cores by
# default; on a machine busy with other work a model this small runs faster on one thread
# (`NUMBA_NUM_THREADS=1` in the environment; `rkfx.parallel.threads` explains the contention).

# %%
N_at_particles = evaluate(plate.rk, plate.p.x).matrix(0)
series = FieldSeries(VTK, "kalthoff", plate.p.x, cells=nodal_cells(plate.domains))


class ParaViewRecorder:
    """Writes a ParaView step at every output of the stepper (a ``Recorder``)."""

    def __init__(self, dynamics: DamageDynamics):
        self.field = dynamics.field
        self.kept = 0

    def record(self, state) -> None:
        f = self.field
        series.write(state.time,
                     displacement=N_at_particles @ state.d.reshape(n, 2),
                     velocity=N_at_particles @ state.v.reshape(n, 2),
                     damage=f.damage,
                     opening=dm.crack_opening(f.kappa, model.kappa0, f.kappa_c))
        self.kept += 1

    def arrays(self):          # nothing to checkpoint: the files are the output
        return {}

    def restore(self, arrays):
        pass


dynamics = DamageDynamics(plate.op, plate.mass, model, track, plate.dt,
                          kalthoff.model_conditions(plate, prm["v0"]))
recorder = ParaViewRecorder(dynamics)
result = CentralDifference(plate.dt).run(dynamics, steps, output_every=steps // 6, recorder=recorder)
damage = dynamics.field.damage.copy()
opening = dm.crack_opening(dynamics.field.kappa, model.kappa0, dynamics.field.kappa_c)
print(f"{recorder.kept} ParaView steps in {VTK}; {int((opening >= 0.5).sum())} cracked particles, "
      f"energy balance error {result.relative_energy_error():.1e}")
assert recorder.kept >= 7 and np.isclose(pvd_times(series.pvd)[-1], steps * plate.dt)
assert result.relative_energy_error() < 1e-2

# %% [markdown]
# ## The crack, measured
#
# The crack angle from the +x axis: the major axis of the second moment of the cracked
# particles ($w / w_c \ge 0.5$) about the notch tip. No particle below the crack plane should
# crack (that would be spurious damage).

# %%
tip = np.array([kalthoff.A1, kalthoff.A2])
cracked = opening >= 0.5
rel = plate.p.x[cracked] - tip
eigval, eigvec = np.linalg.eigh(rel.T @ rel)
axis = eigvec[:, np.argmax(eigval)]
axis = axis if axis @ rel.sum(axis=0) > 0 else -axis
angle = float(np.degrees(np.arctan2(axis[1], axis[0])))
below = int(np.sum(cracked & (plate.p.x[:, 1] < kalthoff.A2 - 3 * plate.h)))
print(f"crack angle {angle:.1f} deg (experiment: about 70), cracked particles below the crack plane: {below}")
assert cracked.sum() >= 5
assert 45.0 < angle < 85.0 and below == 0

# %% [markdown]
# ## Reading the files back with pyvista
#
# pyvista reads the `.pvd` index like ParaView does: one dataset per time value. We check that
# the last step holds what we wrote, then render the damage on the nodal cells off-screen
# (`pyvista.OFF_SCREEN = True`; no display is needed).

# %%
import pyvista as pv  # noqa: E402

from rkfx.output.render import render  # noqa: E402

pv.OFF_SCREEN = True
reader = pv.get_reader(str(VTK / "kalthoff_cells.pvd"))
times = reader.time_values
reader.set_active_time_value(times[-1])
cells_mesh = reader.read()[0]
reader_p = pv.get_reader(str(series.pvd))
reader_p.set_active_time_value(times[-1])
points_mesh = reader_p.read()[0]
print(f"{len(times)} time values; particles: {points_mesh.n_points} points, cells: {cells_mesh.n_cells} quads")
assert points_mesh.n_points == n
np.testing.assert_allclose(points_mesh.point_data["damage"], damage)
assert abs(cells_mesh.area - kalthoff.SIDE**2) < 1e-9 * kalthoff.SIDE**2  # the cells tile the plate

# `rkfx.output.render` draws one field of a series off-screen (also from a shell:
# `python -m rkfx.output.render FILE.pvd --field damage`); the black line is the notch.
png = render(VTK / "kalthoff_cells.pvd", "damage", OUT / "05_kalthoff_damage.png", clim=(0.0, 1.0),
             title=f"Kalthoff, damage at t = {times[-1] * 1e6:.0f} us",
             segments=[((0.0, kalthoff.A2), (kalthoff.A1, kalthoff.A2))])
assert png.stat().st_size > 10_000

# %% [markdown]
# A matplotlib view of the same data, for comparison: the crack opening at the particles at
# each written time.

# %%
fig, axes = plt.subplots(1, 3, figsize=(13, 4.4), layout="constrained")
for ax, t in zip(axes, (times[len(times) // 3], times[2 * len(times) // 3], times[-1])):
    reader_p.set_active_time_value(t)
    w = reader_p.read()[0].point_data["opening"]
    sc = ax.scatter(plate.p.x[:, 0], plate.p.x[:, 1], c=w, s=6, cmap="inferno", vmin=0, vmax=1)
    ax.plot([0, kalthoff.A1], [kalthoff.A2, kalthoff.A2], "c-", lw=2)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"w / w_c at t = {t * 1e6:.0f} us")
fig.colorbar(sc, ax=axes, shrink=0.8)
fig.savefig(OUT / "05_opening_in_time.png", dpi=110)
plt.close(fig)

elapsed = time.perf_counter() - t_start
print(f"figures in {OUT}; lab ran in {elapsed:.1f} s")

# %% [markdown]
# ## Opening the files in ParaView
#
# The run wrote, in `RKFX_LAB_OUT/05_vtk/` (by default `lab_output/05_vtk/`):
#
# * `kalthoff_particles.pvd` — the particles as points with `displacement`, `velocity`,
#   `damage` and `opening` as point data;
# * `kalthoff_cells.pvd` — the nodal cells (four quadrilateral subcells each) with the same
#   fields as cell data: the picture of a particle method that looks like a continuum.
#
# In ParaView: *File → Open*, choose the `.pvd` file (not the `.vtu` files), *Apply*. Colour by
# `damage` or `opening`, and use the time controls of the toolbar to step through the run.
# For the deformed shape add *Filters → Warp By Vector* on `displacement` with a scale factor
# of about 100. From a shell, `paraview lab_output/05_vtk/kalthoff_cells.pvd` opens it directly.
# The cases write the same files with `--vtk` (e.g. `python -m rkfx.cases.terzaghi --quick --vtk`).

# %% [markdown]
# ## Exercises
#
# 1. Run to the case's full $t_{end} = 80\,\mu$s and with 60 particles per side. Does the
#    crack angle change, and how long does the run take? (The case module runs this study as
#    `python -m rkfx.cases.kalthoff --quick`.)
# 2. Switch tracking off (`kalthoff.setup(..., tracked=False)`) and look at the damage in
#    ParaView. Where does spurious damage appear, and why?
# 3. Add the effective stress $\mathbf{C}\tilde{\boldsymbol\varepsilon}$ to the written fields
#    as a Voigt tensor of shape `(n, 3)` (the smeared strain is `plate.op` applied to the
#    coefficients; see `rkfx.assembly.smeared_strain`), and plot its major principal stress in
#    ParaView with the *Tensor Glyph* or *Calculator* filters.
# 4. Replace the regularized model by an unregularized one with a constant $\kappa_c$
#    (`kalthoff.setup(..., regularized=False, kappa_c=...)`) and compare the dissipated energy
#    `dynamics.field.dissipated(model)` at 40 and 60 particles per side.
