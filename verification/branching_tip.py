"""The crack tip of the crack-branching run at each spacing: how fast it runs and the stress around it
(issue: chapter 4 at the finest resolutions).

Dynamic branching theory reads the branching off the tip: below about 0.6 of the shear wave
speed the hoop stress sigma_tt around a running tip peaks straight ahead (theta = 0); faster,
its peak moves off the axis (Yoffe's solution), and a tip that still gets more energy than one
crack can spend splits. This study runs the regularized case at spacings h with frames of the
fields, and per frame (``FRAMES`` through the run) finds:

* the tips: the cracked particle (w / w_c >= 0.5) farthest in x, and the farthest of those more
  than ``BRANCH_OFFSET`` above and below the crack plane (the branch tips); their x [mm] and the speed of the farthest one between frames [m/s],
  against the Rayleigh speed c_R;
* the stress around the farthest tip while the crack is still single: the stress
  (1 - D) C eps of the uncracked particles in the annuli ``ANNULI`` around the tip, sigma_tt by
  angle theta from the crack's line (|theta| <= 75 degrees), its peak angle and the ratio of its
  mean over 45-75 degrees to its mean within 15 degrees of the axis (> 1: the peak is off the
  axis), and the share of those particles already damaged (D >= ``DAMAGED``);
* sigma_yy straight ahead of the tip at ``AHEAD`` (the process zone's load), and D there.

    python -m verification.branching_tip [--h 8e-4,4e-4,2e-4] [--out results/branching_tip]

Writes ``OUT/tip.json`` (every frame) and prints a markdown table per spacing, averaged over the
frames with the single tip at x = ``WINDOW``, then the tips through time; ``OUT/tips.png`` shows the
cracked particles of each run coloured by when they cracked.
"""
import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from rkfx.cases import _dynamic_fracture as dyn
from rkfx.cases import crack_branching as cb
from rkfx.fracture import damage as dm
from rkfx.models.damage_dynamics import Frames
from verification.branching_sensitivity import print_header, spacings

FRAMES = 40
DAMAGED = 0.05  # damage from which a particle counts as damaged
ANNULI = ((1e-3, 2e-3), (2e-3, 4e-3))  # radii around the tip [m]
AHEAD = (1e-3, 2e-3, 4e-3)  # distances straight ahead of the tip [m]
BRANCH_OFFSET = 2e-3  # distance off the crack plane y = a2 from which a cracked particle is on a branch [m]
WINDOW = (0.045, 0.065)  # tip x over which the single-tip frames are averaged [m]
BINS = np.radians(np.arange(-75.0, 76.0, 15.0))  # angle bins of sigma_tt (the crack faces lie at 180)


def rayleigh_speed(E: float, nu: float, rho: float) -> float:
    """c_R ~ c_s (0.862 + 1.14 nu) / (1 + nu) [m/s] (Viktorov's fit)."""
    return float(np.sqrt(E / (2 * (1 + nu) * rho)) * (0.862 + 1.14 * nu) / (1 + nu))


def tips(x: np.ndarray, opening: np.ndarray) -> tuple[np.ndarray | None, float | None, float | None]:
    """(farthest tip, x of the upper tip, x of the lower tip) of the cracked particles beyond the
    notch; the upper and lower tips are those more than ``BRANCH_OFFSET`` off the crack plane."""
    cracked = (opening >= dyn.CRACKED) & (x[:, 0] > cb.A1)
    if not cracked.any():
        return None, None, None
    pts = x[cracked]
    far = pts[np.argmax(pts[:, 0])]
    side = [pts[sel, 0].max() if sel.any() else None
            for sel in (pts[:, 1] > cb.A2 + BRANCH_OFFSET, pts[:, 1] < cb.A2 - BRANCH_OFFSET)]
    return far, *side


def hoop_profile(x: np.ndarray, stress: np.ndarray, uncracked: np.ndarray, damage: np.ndarray, tip: np.ndarray,
                 radii: tuple[float, float]) -> dict:
    """sigma_tt [Pa] of the uncracked particles at radii ``radii`` around ``tip``, by angle from +x."""
    d = x - tip
    r = np.hypot(d[:, 0], d[:, 1])
    th_all = np.arctan2(d[:, 1], d[:, 0])
    sel = uncracked & (r >= radii[0]) & (r < radii[1]) & (np.abs(th_all) <= BINS[-1] + 1e-12)
    th = th_all[sel]
    s, c = np.sin(th), np.cos(th)
    sxx, syy, sxy = stress[sel].T
    hoop = sxx * s * s + syy * c * c - 2 * sxy * s * c
    which = np.digitize(th, BINS) - 1
    means = [float(hoop[which == k].mean()) if np.any(which == k) else np.nan for k in range(len(BINS) - 1)]
    on = np.abs(th) < np.radians(15)
    off = (np.abs(th) >= np.radians(45)) & (np.abs(th) <= np.radians(75))
    centres = np.degrees(0.5 * (BINS[1:] + BINS[:-1]))
    peak = float(centres[int(np.nanargmax(means))]) if np.isfinite(means).any() else None
    ratio = float(hoop[off].mean() / hoop[on].mean()) if on.any() and off.any() and hoop[on].mean() > 0 else None
    return {"bins_deg": centres.tolist(), "hoop": means, "peak_deg": peak, "off_over_on": ratio,
            "particles": int(sel.sum()), "damaged_share": float(np.mean(damage[sel] >= DAMAGED)) if sel.any() else None}


def measure(h: float, overrides: dict | None = None) -> dict:
    """One regularized run at spacing ``h`` [m]; the tip and its stress at every frame."""
    prm = {k: p.default for k, p in cb.PARAMS.items()} | (overrides or {})
    material = dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], prm["plane"])
    t0 = time.perf_counter()
    pl, track, model, f = cb.setup(h, material, prm)
    kept = []

    def write(t, damage, crack_opening, displacement, velocity):
        kept.append((t, damage.copy(), crack_opening.copy(), displacement.ravel().copy()))

    r = dyn.simulate("tip", pl, model, track, [], prm["t_end"], external_force=lambda t: f,
                     frames=Frames(write, FRAMES))
    x, c = pl.p.x, material.elasticity()
    rows = []
    cracked_at = np.full(len(x), np.nan)  # the first frame time at which each particle counts as cracked
    for t, damage, opening, d in kept:
        cracked_at[np.isnan(cracked_at) & (opening >= dyn.CRACKED)] = 1e6 * t
        far, upper, lower = tips(x, opening)
        row = {"t_us": 1e6 * t, "tip_mm": None if far is None else (1e3 * far).tolist(),
               "upper_mm": None if upper is None else 1e3 * upper, "lower_mm": None if lower is None else 1e3 * lower}
        if far is not None:
            stress = (1.0 - damage)[:, None] * (pl.op.strain(d) @ c.T)
            row["annuli"] = [hoop_profile(x, stress, opening < dyn.CRACKED, damage, far, a) for a in ANNULI]
            ahead = [int(np.argmin(np.hypot(x[:, 0] - far[0] - s, x[:, 1] - far[1]))) for s in AHEAD]
            row["sigma_yy_ahead"] = [float(stress[k, 1]) for k in ahead]
            row["damage_ahead"] = [float(damage[k]) for k in ahead]
        rows.append(row)
    for a, b in zip(rows, rows[1:]):
        if a["tip_mm"] is not None and b["tip_mm"] is not None:
            b["speed"] = 1e3 * (b["tip_mm"][0] - a["tip_mm"][0]) / (b["t_us"] - a["t_us"])  # mm/us = 1e3 m/s
    branches, split, _ = cb.branch_metrics(r.opening, pl.xs, pl.ys)
    return {"h": h, "particles": pl.p.num_nodes, "c_R": rayleigh_speed(prm["E"], prm["nu"], prm["rho"]),
            "branches": branches, "split_mm": 1e3 * split if np.isfinite(split) else None, "frames": rows,
            "wall_s": time.perf_counter() - t0, "x": x, "cracked_at": cracked_at}


def plot(runs: list[dict], path: Path) -> None:
    """The cracked particles of each run beyond x = 45 mm, coloured by when they cracked."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    fig, axes = plt.subplots(len(runs), 1, figsize=(5.6, 2.4 * len(runs) + 0.5), squeeze=False, sharex=True,
                             layout="constrained")
    for ax, m in zip(axes[:, 0], runs):
        sel = np.isfinite(m["cracked_at"]) & (m["x"][:, 0] > 0.045)
        art = ax.scatter(1e3 * m["x"][sel, 0], 1e3 * m["x"][sel, 1], c=m["cracked_at"][sel], s=max(0.3, 2.5e3 * m["h"]),
                         cmap="viridis", vmin=15, vmax=80, marker="s", linewidths=0)
        ax.set(xlim=(45, 100), ylim=(0, 40), aspect="equal", ylabel="y [mm]", title=f"h = {1e3 * m['h']:.1f} mm")
    axes[-1, 0].set_xlabel("x [mm]")
    fig.suptitle(f"Cracked particles (w/w_c >= {dyn.CRACKED}) by the time they cracked", fontsize=10)
    fig.colorbar(art, ax=axes[:, 0].tolist(), label="cracked at [us]", shrink=0.6)
    fig.savefig(path, dpi=150)
    plt.close(fig)


def summary(m: dict) -> dict:
    """The single-tip frames in ``WINDOW``: mean speed / c_R, mean hoop ratio and peak angles per
    annulus, mean sigma_yy ahead / f_t; the tips' x at the end and their speed after the split."""
    split = m["split_mm"] if m["split_mm"] is not None else np.inf
    single = [f for f in m["frames"] if f["tip_mm"] is not None and "speed" in f
              and 1e3 * WINDOW[0] <= f["tip_mm"][0] <= min(1e3 * WINDOW[1], split)]
    after = [f for f in m["frames"] if f["tip_mm"] is not None and "speed" in f and f["tip_mm"][0] > split]

    def mean(vals):
        vals = [v for v in vals if v is not None]
        return float(np.mean(vals)) if vals else None

    ft = cb.PARAMS["ft"].default
    end = m["frames"][-1]
    return {"h_mm": 1e3 * m["h"], "frames": len(single), "speed_over_cR": mean([f["speed"] / m["c_R"] for f in single]),
            "after_split_over_cR": mean([f["speed"] / m["c_R"] for f in after]),
            "ratio": [mean([f["annuli"][k]["off_over_on"] for f in single]) for k in range(len(ANNULI))],
            "peak_deg": [mean([None if f["annuli"][k]["peak_deg"] is None else abs(f["annuli"][k]["peak_deg"])
                               for f in single]) for k in range(len(ANNULI))],
            "damaged_share": [mean([f["annuli"][k]["damaged_share"] for f in single]) for k in range(len(ANNULI))],
            "ahead_over_ft": [mean([f["sigma_yy_ahead"][k] for f in single]) for k in range(len(AHEAD))],
            "damage_ahead": [mean([f["damage_ahead"][k] for f in single]) for k in range(len(AHEAD))],
            "end_upper_mm": end["upper_mm"], "end_lower_mm": end["lower_mm"], "ft": ft,
            "branches": m["branches"], "split_mm": m["split_mm"], "wall_s": m["wall_s"]}


def _fmt(v, spec=".2f"):
    return "-" if v is None else format(v, spec)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", default="8e-4,4e-4,2e-4", help="spacings [m], comma-separated")
    ap.add_argument("--out", type=Path, default=Path("results/branching_tip"))
    args = ap.parse_args(argv)
    hs = spacings(args.h, "branching_tip")
    if hs is None:
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    runs = []
    print_header([
        "h [mm]", "frames", "v / c_R single", "v / c_R after split", "hoop 45-75 / 0-15 deg at 1-2, 2-4 mm",
        "mean peak angle at 1-2, 2-4 mm [deg]", "damaged at 1-2, 2-4 mm", "sigma_yy / f_t at 1, 2, 4 mm",
        "D at 1, 2, 4 mm", "tips at the end [mm]", "split [mm]", "branches", "wall [s]"])
    for h in hs:
        m = measure(h)
        runs.append(m)
        (args.out / "tip.json").write_text(json.dumps([{k: v for k, v in r.items() if k not in ("x", "cracked_at")}
                                                       for r in runs]) + "\n")
        plot(runs, args.out / "tips.png")
        s = summary(m)
        print(f"| {s['h_mm']:.1f} | {s['frames']} | {_fmt(s['speed_over_cR'])} | {_fmt(s['after_split_over_cR'])} | "
              f"{' / '.join(_fmt(v) for v in s['ratio'])} | {' / '.join(_fmt(v, '.0f') for v in s['peak_deg'])} | "
              f"{' / '.join(_fmt(v) for v in s['damaged_share'])} | "
              f"{' / '.join(_fmt(None if v is None else v / s['ft']) for v in s['ahead_over_ft'])} | "
              f"{' / '.join(_fmt(v) for v in s['damage_ahead'])} | "
              f"{_fmt(s['end_upper_mm'], '.1f')} / {_fmt(s['end_lower_mm'], '.1f')} | {_fmt(s['split_mm'], '.1f')} | "
              f"{s['branches']} | {s['wall_s']:.0f} |", flush=True)
    print("\nTips through time, x [mm] of the farthest / upper / lower (branch) tip:\n")
    for m in runs:
        print(f"- h = {1e3 * m['h']:.1f} mm: " + tip_history(m))
    return 0


def tip_history(m: dict, every: int = 4) -> str:
    """``t us: far/upper/lower`` of every ``every``-th frame with a tip, and of the last."""
    with_tip = [f for f in m["frames"] if f["tip_mm"] is not None]
    picked = with_tip[::every] + ([with_tip[-1]] if with_tip and (len(with_tip) - 1) % every else [])
    return ", ".join(f"{f['t_us']:.0f} us: {f['tip_mm'][0]:.1f}/{_fmt(f['upper_mm'], '.1f')}/{_fmt(f['lower_mm'], '.1f')}"
                     for f in picked)


if __name__ == "__main__":
    sys.exit(main())
