"""What the dynamic fracture cases share: the particle plate, the run with checkpoints, crack metrics.

A plate is a tensor grid of particles whose rectangular Voronoi cells (``rkfx.geometry.grid_cells``)
have faces along the pre-existing cracks, so no cell straddles a crack; the RK shape
functions see the cracks by diffraction (``rkfx.approximation.diffraction``). The damage particle method
(``rkfx.models.damage_dynamics``) runs as a ``DamageDynamics`` model on the central-difference
stepper (``rkfx.solvers.central_difference``).

``simulate`` runs a model on a plate through ``rkfx.models.damage_dynamics.run_damage``, which
keeps finished work (checkpoints, finished results read back on resume).

Cracks are read off the crack opening w / w_c = D kappa / kappa_c (``rkfx.fracture.damage.crack_opening``,
the fraction of a particle's fracture energy spent), not off D: with the regularized kappa_c
of a fine model D passes 0.9 at about ten times the threshold strain, where the stress has
softened by a few per cent only, so a D map shows a wide zone of onset around the cracks.
A particle counts as cracked from w / w_c >= ``CRACKED``; the crack particles reach 1, and few
lie in between (on the crack-branching model at h = 0.2 mm, 748 particles have w / w_c >= 0.5
and 686 of them >= 0.9, while 1,854 have D >= 0.9).
"""
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from rkfx.errors import InputError
from rkfx.fracture import damage as dm
from rkfx.fracture.nonlocal_average import band_factor, nonlocal_average
from rkfx.fracture.tracking import Tracking
from rkfx.approximation.diffraction import Cracks, cracks
from rkfx.assembly.lattice_stencil import template_particle
from rkfx.assembly.smeared_strain import SmearedStrain, StrainRecipe, lumped_mass, near_part, stable_time_step
from rkfx.models.damage_dynamics import DamageRun, Frames, run_damage
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.geometry.particles import Particles, graded
from rkfx.parallel.partition import rcb
from rkfx.approximation.shape_functions import RKApproximation, evaluate, rk_approximation
from rkfx.solvers.central_difference import Constraint
from rkfx.cases import _paraview, _preflight
from rkfx.cases._terminal import model_run, step_progress

CRACKED = 0.5  # w / w_c from which a particle counts as cracked (half its fracture energy spent)


@dataclass(frozen=True)
class Plate:
    """A particle plate on a tensor grid with pre-existing cracks along cell faces.

    Attributes:
        xs, ys: Grid coordinates [m].
        p: Particles (node j * nx + i at (xs[i], ys[j])).
        rk: RK approximation with the cracks.
        domains: Rectangular Voronoi cells; on MPI ranks only those of the particles near the
            rank's part (``whole_domains`` builds them all), with every area.
        op: Smeared strain operator B~ (4.31)-(4.33); on MPI ranks its recipe, from which each
            rank of ``simulate`` builds only the rows of its share.
        mass: Lumped mass per unknown [kg per unit thickness].
        dt: Time step [s].
        cracks: The pre-existing cracks.
    """

    xs: np.ndarray
    ys: np.ndarray
    p: Particles
    rk: RKApproximation
    domains: NodalDomains
    op: SmearedStrain | StrainRecipe
    mass: np.ndarray
    dt: float
    cracks: Cracks

    @property
    def h(self) -> float:
        """Largest grid spacing [m]."""
        return float(max(np.diff(self.xs).max(), np.diff(self.ys).max()))

    def whole_domains(self) -> NodalDomains:
        """The cells of every particle (those of ``domains`` if it has them all)."""
        if isinstance(self.op, SmearedStrain):
            return self.domains
        return grid_domains(self.xs, self.ys, list(self.cracks.segments))


def memory_need(methods: Sequence[str], rkpm: dict[str, Sequence], fem: dict[str, Sequence],
                particles: Callable[[float], float], verb: str = "lower") -> _preflight.Need:
    """The Need of a dynamic fracture case: its largest model among the study lists of the methods run.

    Args:
        methods: The methods to run.
        rkpm, fem: The study lists of each method by parameter name, e.g. ``{"nodes": [150, 250]}``.
        particles: Particles (or FEM vertices) of a model given one list entry.
        verb: How the entry must change to shrink the model (``lower`` a count, ``raise`` a spacing).
    """
    lists = {**(rkpm if "rkpm" in methods else {}), **(fem if "fem" in methods else {})}
    sizes = {name: max((particles(v) for v in vs), default=0.0) for name, vs in lists.items()}
    name = max(sizes, key=sizes.get, default=None)
    if name is None:
        return _preflight.need(0.0, 0, "", "")
    return _preflight.need(_preflight.DAMAGE_BYTES_PER_NODE, sizes[name],
                           f"{name}={','.join(f'{v:.6g}' for v in lists[name])}", f"{verb} {name}")


def check_nonlocal(radius: float, spacings: Sequence[float], E: float, ft: float, GF: float) -> None:
    """Raise InputError unless the nonlocal radius [m] spans 1.5-25 of the ``spacings`` [m] (a
    particle's average must reach its neighbours, and its row holds pi (R / h)^2 entries) and
    its band b is narrow enough that kappa_c = 2 G_F / (f_t b) exceeds kappa0."""
    if not (np.isfinite(radius) and radius > 0):
        raise InputError(f"nonlocal_radius = {radius!r} must be a positive length [m] (e.g. 2e-3)")
    coarse, fine = max(spacings), min(spacings)
    if radius < 1.5 * coarse:
        raise InputError(f"nonlocal_radius = {radius:g} m is below 1.5 spacings of h = {coarse:g} m; "
                         f"enlarge it or drop that spacing from nonlocal_h")
    if radius > 25 * fine:
        raise InputError(f"nonlocal_radius = {radius:g} m spans over 25 spacings of h = {fine:g} m (rows of "
                         f"{np.pi * (radius / fine) ** 2:,.0f} entries per particle); use a radius below {25 * fine:g} m")
    band_factor(E * GF / ft**2 / radius)  # raises if the band is too wide for G_F


def plate(xs: np.ndarray, ys: np.ndarray, slits: Sequence, tips: Sequence[tuple[bool, bool]],
          material: dm.DamageMaterial, rho: float, support_factor: float = 1.5, courant: float = 0.5,
          eps_p: float = 1.0, comm=None) -> Plate:
    """Particles, RK shape functions (linear basis, cubic B-spline kernel, support c h) with the
    cracks ``slits`` (free tips flagged by ``tips``), SCNI cells with the MSCNI terms of weight
    ``eps_p`` (0: plain SCNI), lumped mass and the CFL step. With an MPI ``comm`` of several
    ranks the operator is left as its recipe: each rank of ``simulate`` builds only the rows of
    its share, and the cells of only the particles those rows read."""
    p = graded(xs, ys)
    c = cracks([np.asarray(s, float) for s in slits], tips)
    rk = rk_approximation(p.x, p.spacing, support_factor, cracks=c)
    parallel = comm is not None and comm.size > 1
    nodes = None
    if parallel:  # the particles StrainRecipe.share will read: a cell's smoothing points lie within
        # half its diagonal of its particle
        reach = 0.5 * np.hypot(np.diff(xs).max(), np.diff(ys).max())
        nodes = near_part(p.x, rcb(p.x, comm.size), comm.rank, 1.001 * (rk.support.max() + reach))
        template = template_particle(p.x, rk)  # every rank snaps its rows to its rows (lattice_stencil)
        if template is not None:
            nodes = np.union1d(nodes, [template])
    domains = grid_domains(xs, ys, slits, nodes=nodes)
    recipe = StrainRecipe(p, rk, domains, eps_p)
    op = recipe if parallel else recipe.build()
    dt = stable_time_step(p.spacing, material.elastic, rho, courant)
    return Plate(np.asarray(xs, float), np.asarray(ys, float), p, rk, domains, op, lumped_mass(domains.area, rho),
                 dt, c)


def damage_model(pl: Plate, material: dm.DamageMaterial, regularized: bool = True,
                 kappa_c: float | None = None, nonlocal_radius: float = 0.0, comm=None) -> dm.DamageModel:
    """The damage particles of the plate: regularized (4.28) on the cells, or a constant kappa_c;
    with ``nonlocal_radius`` > 0 [m] regularized by the nonlocal equivalent strain over that radius
    instead (``rkfx.fracture.nonlocal_average``; with an MPI ``comm`` of several ranks, the rows
    of this rank's particles only, the part ``simulate`` will give it)."""
    geometry = dm.cell_geometry(pl.domains) if regularized else None
    model = dm.damage_model(material, pl.domains.area, geometry=geometry, kappa_c=kappa_c, regularized=regularized)
    if nonlocal_radius > 0 and regularized:
        factor = band_factor(material.E * material.GF / material.ft**2 / nonlocal_radius)
        mine = None if comm is None or comm.size == 1 else np.flatnonzero(rcb(pl.p.x, comm.size) == comm.rank)
        average = nonlocal_average(pl.p.x, model.volume, nonlocal_radius, factor, pl.cracks.segments, mine)
        model = replace(model, nonlocal_average=average)
    return model


def simulate(label: str, pl: Plate, model: dm.DamageModel, track: Tracking | None, constraints: Sequence[Constraint],
             t_end: float, external_force: Callable[[float], np.ndarray] | None = None, samples: int = 200,
             checkpoint_every: int = 0, work_dir: Path | None = None, resume: Path | None = None,
             comm=None, vtk: Path | None = None, frames: Frames | None = None) -> DamageRun:
    """The damage particle method on the plate to ``t_end`` (``rkfx.models.damage_dynamics.run_damage``;
    with an MPI ``comm`` of several ranks, distributed over them); with ``vtk`` a folder, the
    fields through time are written there for ParaView (``_paraview.damage_frames``); else
    ``frames`` receives them (e.g. for a study of the fields)."""
    if vtk is not None:
        frames = _paraview.damage_frames(vtk, label, pl.p.x, _paraview.nodal_cells(pl.whole_domains()),
                                         evaluate(pl.rk, pl.p.x).matrix(), comm)
    bar = step_progress(label, int(np.ceil(t_end / pl.dt - 1e-9)))
    try:
        return run_damage(label, pl.op, pl.mass, pl.dt, model, track, constraints, t_end, external_force, samples,
                          checkpoint_every, work_dir, resume, comm, x=pl.p.x, frames=frames, progress=bar)
    finally:
        bar.close()


def run_studies(results, studies: Sequence[tuple[str, Sequence, Callable]], summary: Callable,
                level: str = "n") -> None:
    """Append to ``results`` the runs ``one(level)`` of each ``(study, levels, one)`` and, after
    each study's runs, ``summary(study, runs)``; ``level`` names the levels on the terminal."""
    for study, levels, one in studies:
        runs = []
        for v in levels:
            with model_run(f"{study} {level}={v:g}"):
                runs.append(one(v))
        results.runs += runs
        if runs:
            results.runs.append(summary(study, runs))


# --------------------------------------------------------------------------- crack metrics


def crack_angle(x: np.ndarray, opening: np.ndarray, tip: np.ndarray, radius: float,
                threshold: float = CRACKED) -> float:
    """Angle [deg] from the +x axis of the line through ``tip`` fitted to the cracked points
    (w / w_c >= ``threshold``) within ``radius`` of the tip (the major axis of their second
    moment about the tip, pointing away from it); NaN with fewer than three such points."""
    d = x - np.asarray(tip, float)
    sel = (opening >= threshold) & (np.linalg.norm(d, axis=1) <= radius)
    if sel.sum() < 3:
        return float("nan")
    q = d[sel]
    w, v = np.linalg.eigh(q.T @ q)
    axis = v[:, np.argmax(w)]
    if axis @ q.sum(axis=0) < 0:
        axis = -axis
    return float(np.degrees(np.arctan2(axis[1], axis[0])))


def crack_share(r: DamageRun) -> float:
    """Fraction of the dissipated energy spent in the cracked particles (w / w_c >= ``CRACKED``);
    the rest is spent beside the cracks, in particles that initiated but barely opened."""
    total = float(np.sum(r.dissipation))
    return float(np.sum(r.dissipation[r.opening >= CRACKED])) / total if total > 0 else float("nan")


def count_branches(points: np.ndarray, opening: np.ndarray, columns: np.ndarray, width: float,
                   min_gap: float, threshold: float = CRACKED) -> np.ndarray:
    """Number of separate cracks crossing each column x in ``columns``: the cracked damage
    points (particles or element centroids, w / w_c >= ``threshold``) within ``width`` / 2 of
    the column, sorted by y, split where consecutive ones lie more than ``min_gap`` apart."""
    cracked = np.asarray(points, float)[np.asarray(opening) >= threshold]
    out = np.zeros(len(columns), int)
    for k, c in enumerate(columns):
        y = np.sort(cracked[np.abs(cracked[:, 0] - c) < 0.5 * width, 1])
        if y.size:
            out[k] = 1 + int(np.sum(np.diff(y) > min_gap))
    return out


def most_cracks(column_x: np.ndarray, counts: np.ndarray, length: float) -> int:
    """The most separate cracks side by side over ``length`` of x: the largest k such that
    consecutive columns spanning at least ``length`` [m] are each crossed by k or more cracks
    (``counts`` of ``count_branches`` at the sorted ``column_x``); 0 if no column is crossed.
    Short spurs and side cracks, crossed by a column or two, do not count."""
    x, c = np.asarray(column_x, float), np.asarray(counts, int)
    best = 0
    for k in range(1, int(c.max(initial=0)) + 1):
        edges = np.diff(np.r_[0, (c >= k).astype(int), 0])
        starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
        if np.any(x[ends] - x[starts] >= length - 1e-12):
            best = k
    return best


def run_series(r: DamageRun) -> dict:
    """The series every dynamic fracture run reports: the sampled history (time in µs) and the
    damaged particles (D > 0.01) as indices with their D and w / w_c, which ``damage_map`` draws."""
    hist = r.history
    damaged = np.flatnonzero(r.damage > 0.01)
    return {"time_us": 1e6 * hist[:, 0], "dissipated": hist[:, 1], "damaged": hist[:, 2], "kinetic": hist[:, 3],
            "internal": hist[:, 4], "external": hist[:, 5], "released": r.released, "damaged_index": damaged,
            "damaged_D": np.round(r.damage[damaged], 4), "damaged_w": np.round(r.opening[damaged], 4)}


# --------------------------------------------------------------------------- figures


def damage_map(ax, series: dict, nx: int, ny: int, lx: float, ly: float, key: str = "damaged_D"):
    """Damage D (``key="damaged_D"``) or crack opening w / w_c (``"damaged_w"``) on the grid's
    cells (pcolormesh) from ``run_series``; returns the mesh artist."""
    d = np.zeros(nx * ny)
    d[np.asarray(series["damaged_index"], int)] = series[key]
    xs, ys = np.linspace(0, lx, nx), np.linspace(0, ly, ny)
    xe = np.r_[xs[0], 0.5 * (xs[1:] + xs[:-1]), xs[-1]]
    ye = np.r_[ys[0], 0.5 * (ys[1:] + ys[:-1]), ys[-1]]
    return ax.pcolormesh(xe, ye, d.reshape(ny, nx), cmap="inferno_r", vmin=0, vmax=1, rasterized=True)


def label_map_axes(ax) -> None:
    """Axis labels of a map of the plate (coordinates in metres)."""
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def plot_dissipation(results, panels: Sequence[tuple[str, str]], path: Path, title: str,
                     label: Callable, order: Callable, scale: float = 1.0, unit: str = "J/m") -> Path | None:
    """Dissipation histories side by side, one panel per study present in ``results``: the
    law's dissipation (solid) and the energy released, internal work less stored (dashed).

    Args:
        panels: ``(study, panel title)`` pairs; studies without runs are skipped.
        label, order: Line label and sort key of a run.
        scale, unit: Energies are divided by ``scale`` and labelled in ``unit``.
    """
    from rkfx.cases._cli import pyplot, save  # noqa: PLC0415

    panels = [(s, t) for s, t in panels if any(r.info.get("study") == s for r in results.runs)]
    if not panels:
        return None
    plt = pyplot()
    fig, axes = plt.subplots(1, len(panels), figsize=(4.7 * len(panels), 3.9), squeeze=False, sharey=True,
                             layout="constrained")
    for ax, (study, head) in zip(axes[0], panels):
        runs = sorted((r for r in results.runs if r.info.get("study") == study), key=order)
        for k, r in enumerate(runs):
            color = plt.cm.viridis(k / max(1, len(runs) - 1) * 0.85)
            ax.plot(r.series["time_us"], np.asarray(r.series["dissipated"]) / scale, color=color, label=label(r))
            if "released" in r.series:  # the work the damage took, beside the law's sum
                ax.plot(r.series["time_us"], np.asarray(r.series["released"]) / scale, color=color, lw=0.8, ls="--")
        if any("released" in r.series for r in runs):
            ax.plot([], [], color="0.4", lw=0.8, ls="--", label="dashed: released (work - stored)")
        ax.set_title(head, fontsize=10)
        ax.set_xlabel("time [µs]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0][0].set_ylabel(f"dissipated energy [{unit}]")
    fig.suptitle(title, fontsize=11)
    return save(fig, path)
