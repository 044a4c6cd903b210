"""How the crack-branching run at fine spacings responds to the method's parameters (issue: chapter 4
at the finest resolutions). Measures, per spacing h and variant of one parameter (or the
crack-band finite elements of size h on the same plate, variant ``crack-band FEM``, their cells
measured as the particles are), what the figure shows and where the energy goes:

* branches: the case's count on x = 80-95 mm; side by side: ``most_cracks``;
* x_two [mm]: the largest grid column crossed by two or more separate cracks (how far the
  branches run as a pair), first split x [mm];
* mid-plane [mm]: the x extent of the cracked particles within 2 h of the crack plane y = a2
  beyond the first split (a central crack);
* crack / onset [J/m]: the dissipation in the cracked particles (w / w_c >= 0.5) and in the
  rest (particles that initiated but barely opened);
* onset by distance [J/m]: the onset energy of the particles within 1 mm, 1-3 mm and beyond
  3 mm of the nearest cracked particle (fixed lengths, so that a zone of physical width keeps
  its band under refinement and one of a few spacings moves towards the first);
* flank: the uncracked particles within 1 mm of a crack, their number per cracked particle,
  their median opening w / w_c and median history kappa / kappa0;
* kappa_c / kappa0: the regularized critical strain (4.28) over the threshold, median over the
  particles that initiated.

    python -m verification.branching_sensitivity [--h 4e-4,2e-4] [--out results/branching_sensitivity]

Writes ``OUT/sensitivity.json`` and prints a markdown table (rows as they finish, so a stopped
study keeps what it measured).
"""
import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import NamedTuple

import numpy as np
from scipy.spatial import cKDTree

from rkfx.cases import _dynamic_fracture as dyn
from rkfx.cases import crack_branching as cb
from rkfx.errors import InputError
from rkfx.fracture import damage as dm

ONSET_BANDS = ((0.0, 1e-3), (1e-3, 3e-3), (3e-3, np.inf))  # distance to the nearest cracked particle [m]
VARIANTS = {  # name: the parameters that differ from the case's defaults
    "defaults": {},
    "eps_p=0": {"eps_p": 0.0},
    "eps_p=2": {"eps_p": 2.0},
    "tol=0.3": {"tol": 0.3},
    "tol=0.7": {"tol": 0.7},
    "courant=0.25": {"courant": 0.25},
    "symmetric candidates": {"forward": False},
    "residual=1e-3": {"residual": 1e-3},
    "residual=1e-2": {"residual": 1e-2},
    "nonlocal R=1mm": {"nonlocal_radius": 1e-3},
    "nonlocal R=2mm": {"nonlocal_radius": 2e-3},
    "nonlocal R=2mm eps_p=0": {"nonlocal_radius": 2e-3, "eps_p": 0.0},
    "nonlocal R=2mm eps_p=0.25": {"nonlocal_radius": 2e-3, "eps_p": 0.25},
    "nonlocal R=2.5mm": {"nonlocal_radius": 2.5e-3},
    "nonlocal R=3mm": {"nonlocal_radius": 3e-3},
    "nonlocal R=2mm untracked": {"nonlocal_radius": 2e-3, "tracked": False},
    "nonlocal R=2mm eps_p=0 untracked": {"nonlocal_radius": 2e-3, "eps_p": 0.0, "tracked": False},
    "crack-band FEM": {"fem": True},
}


class _Fracture(NamedTuple):
    """What one run leaves for the measurements: its damage points (particles or cells), their
    final opening w / w_c, dissipation and history kappa / kappa0, the crack count of every
    column x > a1 with the branch metrics, and the median kappa_c / kappa0 of the points that
    initiated (``None`` where the law has no such ratio to report)."""

    h: float
    points: np.ndarray
    opening: np.ndarray
    dissipation: np.ndarray
    kappa_ratio: np.ndarray
    dissipated: float
    columns: np.ndarray
    counts: np.ndarray
    branches: int
    split: float
    critical_ratio: float | None
    steps: int


def measure(h: float, overrides: dict) -> dict:
    """One regularized run of the case at spacing ``h`` [m] with ``overrides`` (case parameters,
    ``residual``: the residual stiffness of the damage model, ``nonlocal_radius`` [m],
    ``tracked``: ``False`` lets every particle damage, and ``fem``: the crack-band finite
    elements of size h instead of the particles); its measurements."""
    overrides = dict(overrides)
    t0 = time.perf_counter()
    run = _crack_band(h, overrides) if overrides.pop("fem", False) else _particles(h, overrides)
    return _metrics(run) | {"h": h, "steps": run.steps, "wall_s": time.perf_counter() - t0}


def _material(prm: dict) -> dm.DamageMaterial:
    return dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], prm["plane"])


def _particles(h: float, overrides: dict) -> _Fracture:
    """The damage particle method's run (the case's ``rkpm-dpm``, or its nonlocal study)."""
    residual = overrides.pop("residual", 0.0)
    radius = overrides.pop("nonlocal_radius", None)
    tracked = overrides.pop("tracked", True)
    prm = {k: p.default for k, p in cb.PARAMS.items()} | overrides
    material = _material(prm)
    pl, track, model, f = cb.setup(h, material, prm, nonlocal_radius=radius or 0.0)
    model = replace(model, residual=residual)
    track = track if tracked else replace(track, enabled=False)
    r = dyn.simulate("study", pl, model, track, [], prm["t_end"], external_force=lambda t: f)
    branches, split, counts = cb.branch_metrics(r.opening, pl.xs, pl.ys)
    started = np.flatnonzero(r.kappa > model.kappa0)  # the particles that initiated
    chords = dm.chord_lengths(model.geometry, started, r.normal[started])
    ratio = dm.critical_strain(material, chords, model.volume[started]) / model.kappa0[started]
    if model.nonlocal_average is not None:  # the band's kappa_c (rkfx.fracture.nonlocal_average)
        kc = 2.0 * material.GF / (material.ft * model.nonlocal_average.band_width)
        ratio = kc / model.kappa0[started]
    return _Fracture(pl.h, pl.p.x, r.opening, r.dissipation, r.kappa / model.kappa0, float(r.history[-1, 1]),
                     pl.xs[pl.xs > cb.A1], counts, branches, split, float(np.median(ratio)) if ratio.size else None,
                     r.steps)


def _crack_band(h: float, overrides: dict) -> _Fracture:
    """The crack-band finite elements of size ``h`` on the same plate (the case's ``fem``: gmsh
    triangles, no tracking), their cells measured as the particles are."""
    import dolfinx_solver  # noqa: F401, PLC0415 (before dolfinx)

    from fem_baselines.crack_band_dynamics import branching_crack_band  # noqa: PLC0415

    prm = {k: p.default for k, p in cb.PARAMS.items()} | overrides
    res = branching_crack_band(h, prm["t_end"], E=prm["E"], nu=prm["nu"], rho=prm["rho"], ft=prm["ft"], GF=prm["GF"],
                               sigma=prm["sigma"], plane=prm["plane"], width=cb.LX, height=cb.LY, a1=cb.A1, a2=cb.A2,
                               courant=prm["courant"], label="study")
    r = res.run
    columns, counts = cb.cell_branch_counts(res.centroids, r.opening, h)  # as the case counts them
    kappa0 = prm["ft"] / prm["E"]
    return _Fracture(h, res.centroids, r.opening, r.dissipation, r.kappa / kappa0, float(r.history[-1, 1]),
                     columns, counts, *cb._branches(counts, columns), None, r.steps)


def _metrics(run: _Fracture) -> dict:
    """The measurements of the module docstring, from one run."""
    two = run.columns[run.counts >= 2]
    cracked = run.opening >= dyn.CRACKED
    x, split = run.points, run.split
    mid = cracked & (np.abs(x[:, 1] - cb.A2) < 2 * run.h) & (x[:, 0] > (split if np.isfinite(split) else cb.A1))
    crack = float(run.dissipation[cracked].sum())
    # Where the onset energy sits: distance of each uncracked point to the nearest cracked one.
    rest = np.flatnonzero(~cracked & (run.dissipation > 0))
    far = cKDTree(x[cracked]).query(x[rest])[0] if cracked.any() and rest.size else np.zeros(rest.size)
    bands = [float(run.dissipation[rest][(far >= lo) & (far < hi)].sum()) for lo, hi in ONSET_BANDS]
    flank = rest[far < ONSET_BANDS[0][1]]  # the uncracked points beside the cracks
    return {"h": run.h, "particles": len(x), "branches": run.branches,
            "side_by_side": cb._most_cracks(run.counts, run.columns),
            "x_two_mm": 1e3 * float(two.max()) if two.size else None,
            "split_mm": 1e3 * split if np.isfinite(split) else None,
            "mid_plane_mm": 1e3 * float(np.ptp(x[mid, 0])) if mid.sum() > 1 else 0.0,
            "dissipated": run.dissipated, "crack": crack, "onset": run.dissipated - crack,
            "kappa_c_over_kappa0": run.critical_ratio,
            "onset_by_distance": bands, "flank_per_cracked": flank.size / max(1, int(cracked.sum())),
            "flank_opening": float(np.median(run.opening[flank])) if flank.size else None,
            "flank_kappa_over_kappa0": float(np.median(run.kappa_ratio[flank])) if flank.size else None}


ROW = ("| {h:.1f} | {variant} | {branches} | {side_by_side} | {split} | {x_two} | {mid_plane_mm:.1f} | "
       "{dissipated:.3f} | {crack:.3f} | {onset:.3f} | {share:.0%} | {bands} | {ratio} | "
       "{wall_s:.0f} |")


def print_header(columns: list[str]) -> None:
    """The head of a markdown table of ``columns`` (the study's rows follow as they finish)."""
    print("| " + " | ".join(columns) + " |")
    print("|" + "---|" * len(columns))


def spacings(text: str, prog: str) -> list[float] | None:
    """The spacings [m] of a ``--h`` list, or ``None`` after a one-line error naming it."""
    try:
        hs = [float(v) for v in text.split(",") if v]
    except ValueError:
        hs = []
    if not hs or not all(np.isfinite(h) and h > 0 for h in hs):
        print(f"{prog}: --h {text!r} is not a comma-separated list of positive spacings in m (e.g. 8e-4,4e-4)",
              file=sys.stderr)
        return None
    return hs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", default="4e-4,2e-4", help="spacings [m], comma-separated")
    ap.add_argument("--variants", default=",".join(VARIANTS), help="which variants, comma-separated")
    ap.add_argument("--out", type=Path, default=Path("results/branching_sensitivity"))
    args = ap.parse_args(argv)
    hs = spacings(args.h, "branching_sensitivity")
    if hs is None:
        return 2
    names = [v for v in args.variants.split(",") if v]
    unknown = [v for v in names if v not in VARIANTS]
    if unknown:
        print(f"branching_sensitivity: unknown variant {unknown[0]!r}; choose from {', '.join(VARIANTS)}",
              file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    print_header([
        "h [mm]", "variant", "branches", "side by side", "split x [mm]", "pair to x [mm]", "mid-plane [mm]",
        "dissipated [J/m]", "crack", "onset", "onset share", "onset < 1 / 1-3 / > 3 mm from a crack",
        "kappa_c/kappa0", "wall [s]"])
    for h in hs:
        for name in names:
            try:
                m = measure(h, VARIANTS[name]) | {"variant": name}
            except InputError as err:  # e.g. a nonlocal radius under 1.5 spacings of this h
                print(f"| {1e3 * h:.1f} | {name} | refused: {err} |", flush=True)
                continue
            rows.append(m)
            (args.out / "sensitivity.json").write_text(json.dumps(rows, indent=1) + "\n")
            print(ROW.format(**{**m, "h": 1e3 * h, "split": "-" if m["split_mm"] is None else f"{m['split_mm']:.1f}",
                                "x_two": "-" if m["x_two_mm"] is None else f"{m['x_two_mm']:.1f}",
                                "share": m["onset"] / m["dissipated"],
                                "ratio": "-" if m["kappa_c_over_kappa0"] is None else f"{m['kappa_c_over_kappa0']:.1f}",
                                "bands": " / ".join(f"{v:.3f}" for v in m["onset_by_distance"])}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
