"""Effective band width of the integral nonlocal damage model with linear softening, in 1-D.

The model (Pijaudier-Cabot & Bazant 1987): the damage history is driven by the nonlocal
average of the local equivalent strain. A bar x in [-L/2, L/2] of N elements of size h (N odd,
the central element at x = 0, L ~ 12 R) carries the strain eps_i per element and

    epsbar_i = sum_j w_ij h <eps_j>+ / sum_j w_ij h,   w_ij = (1 - s^2/R^2)^(5/2), s = |x_i - x_j| < R,

(the 5/2 power is the 2-D bell (1 - r^2/R^2)^2 integrated along a straight band; sums over the
elements that exist), kappa_i = max(kappa_i, epsbar_i), D_i = D(kappa_i) of
``rkfx.fracture.damage.damage`` (linear softening, kappa0 = f_t / E, stress zero at kappa_c) and
sigma = E (1 - D_i) eps_i uniform along the bar. The central element has kappa0 * 0.999.

Loading: Newton's method on (eps_i, sigma) with q = eps_centre - eps_end prescribed (it grows
monotonically through the snap-back: the centre stretches, the elastic ends unload), steps cut
so that D moves by at most 0.02 and sigma by at most 1% f_t, until sigma = 0 (centre at
kappa_c). The 0.999 weakening, smeared by the average, hardly favours the centre: at the peak
the whole bar sits at kappa0 and both a localized band and diffuse softening of the whole bar
satisfy the equations. The loading set is therefore grown from the centre one ring at a time,
only where epsbar would pass max(kappa_old, kappa0), and shrunk where epsbar falls: the
narrowest consistent band, the stable path (a Newton step that lets every element load follows
the diffuse branch and damages the whole bar).

Energies per unit cross-section [J/m^2]:
  W     external work int sigma dU, U = sum_i h eps_i (trapezoid). G = W at sigma = 0.
  Y dD  the dissipation of the model, sum_i h int E eps_i^2 / 2 dD_i (trapezoid in the steps);
        "balance" is (W - elastic - Y dD) / W, the solver's check.
  phi   sum_i h dissipation_density(kappa_i). It assumes eps_i = kappa_i while damage grows
        (true for the local model): here eps far exceeds epsbar at the centre and falls below
        it on the flanks, so phi misses a quarter to a third of W ("phi err" = (phi - W) / W).
b_eff = G / (f_t kappa_c / 2). "damaged" is the width with D > 0 at failure (mostly the slight
damage taken at the peak), "failed" the width with D = 1. At failure the whole opening sits in
the central element (U -> kappa_c * int w ds = 0.98 kappa_c R as h -> 0): the strain localizes
into one element; "G after 1-elem" is the part of Y dD dissipated after the centre took 90% of
the inelastic opening for good. "phi x10 / W": phi after pulling the centre on to 10x its
failure strain at zero stress (the others at eps = 0); the average keeps rising in the
neighbours, D = 1 spreads to ~2 R and phi grows although no work is done.

    python -m verification.nonlocal_band [--ratios 2,3,4,6,10,15,20,30,50] [--h-over-R 0.1,0.05]
                                         [--out results/nonlocal_band]

Writes OUT/band.json (one record per run) and prints the table. Measured (E = 3.2e10 Pa,
f_t = 2.72e6 Pa, R = 1 mm, L = 12 R; b_eff/R is the same to 1e-14 with L = 20 R or other E, f_t, R):

| kappa_c/kappa0 | b_eff/R h/R=1/10 | 1/20 | 1/40 | damaged/R | phi err | G after 1-elem (1/10, 1/20, 1/40) |
|---|---|---|---|---|---|---|
|  2 | 1.2278 | 1.2281 | - | 1.55 | -44% | 1.9%, 0.7%, - |
|  3 | 1.3203 | 1.3207 | - | 2.05 | -37% | 1.5%, 0.5%, - |
|  4 | 1.3776 | 1.3779 | 1.3780 | 2.5 | -34% | 1.2%, 0.6%, 0.2% |
|  6 | 1.4493 | 1.4497 | 1.4498 | 3.3 | -31% | 0.8%, 0.4%, 0.2% |
| 10 | 1.5278 | 1.5281 | 1.5282 | 4.4 | -29% | 0.9%, 0.4%, 0.2% |
| 15 | 1.5816 | 1.5820 | 1.5821 | 5.5 | -27% | 0.7%, 0.4%, 0.1% |
| 20 | 1.6158 | 1.6161 | 1.6162 | 6.4 | -26% | 0.8%, 0.4%, 0.2% |
| 30 | 1.6586 | 1.6590 | 1.6591 | 8.0 | -26% | 0.8%, 0.3%, 0.1% |
| 50 | - | 1.7049 | - | 10.4 | -25% | -, 0.3%, - |

The 1/20 column is ``rkfx.fracture.nonlocal_average``'s table of b / R (``band_factor``). Coarse
elements change it little: at h/R = 0.4 / 0.25 / 0.1, 1.2881 / 1.3147 / 1.3203 (kappa_c/kappa0 = 3)
and 1.4985 / 1.5239 / 1.5278 (10).

balance |W - elastic - Y dD| / W < 3.5e-4 in every run; 230-300 steps.
"""
import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from rkfx.fracture.damage import damage, damage_slope, dissipation_density

E, FT, R = 3.2e10, 2.72e6, 1.0e-3
KAPPA0 = FT / E
WEAK = 0.999
L_OVER_R = 12.0


def weights(x: np.ndarray, radius: float) -> np.ndarray:
    """Row-normalised averaging matrix A (epsbar = A @ <eps>+) of the (1 - s^2/R^2)^(5/2) weight."""
    s = np.abs(x[:, None] - x[None, :]) / radius
    w = np.where(s < 1.0, np.clip(1.0 - s * s, 0.0, None) ** 2.5, 0.0)
    return w / w.sum(axis=1, keepdims=True)


def run(ratio: float, h_over_r: float, max_steps: int = 200_000) -> dict:
    """Pull the bar to sigma = 0 at kappa_c / kappa0 = ``ratio`` and element size h = h_over_r R."""
    t0 = time.perf_counter()
    h = h_over_r * R
    half = int(np.ceil(0.5 * L_OVER_R / h_over_r))
    n = 2 * half + 1
    c = half
    x = (np.arange(n) - half) * h
    A = weights(x, R)
    k0 = np.full(n, KAPPA0)
    k0[c] *= WEAK
    kc = np.full(n, ratio * KAPPA0)

    ctrl = np.zeros(n + 1)
    ctrl[c], ctrl[0] = 1.0, -1.0              # control q = eps_c - eps_end, grows through the snap-back

    def newton(e, sv, kold, M, q):
        """Equilibrium at control q with the loading set M fixed (kappa = epsbar on M, kappa_old off it)."""
        for _ in range(40):
            ebar = A @ np.maximum(e, 0.0)
            k = np.where(M, ebar, kold)
            Dn = damage(k, k0, kc)
            r = np.append((1.0 - Dn) * e - sv, e[c] - e[0] - q)
            norm = np.max(np.abs(r))
            if norm < 1e-12 * KAPPA0:
                return e, sv, ebar, k, Dn
            J = -(e * damage_slope(k, k0, kc) * M)[:, None] * A * (e > 0.0)[None, :]
            J[np.arange(n), np.arange(n)] += 1.0 - Dn
            try:
                dz = np.linalg.solve(np.vstack([np.column_stack([J, -np.ones(n)]), ctrl]), -r)
            except np.linalg.LinAlgError:
                return None
            for _ls in range(30):             # backtrack until the residual falls
                et, st = e + dz[:-1], sv + dz[-1]
                kt = np.where(M, A @ np.maximum(et, 0.0), kold)
                if np.max(np.abs(np.append((1.0 - damage(kt, k0, kc)) * et - st, et[c] - et[0] - q))) < norm:
                    break
                dz *= 0.5
            e, sv = et, st
        return None

    dist = np.abs(np.arange(n) - c)

    def step(eps, s, kold, M, q):
        """Equilibrium at q with a consistent loading set M: elements leave M where epsbar falls below
        their history, and join it (nearest to the centre first, one ring at a time) where epsbar would
        pass max(kappa_old, kappa0). The narrowest band that is consistent: the stable, localized path
        (a band growing all at once picks the diffuse branch, where the whole bar softens)."""
        M = M.copy()
        for _ in range(4 * n):
            out = newton(eps.copy(), s, kold, M, q)
            if out is None:
                return None
            e, sv, ebar, k, Dn = out
            drop = M & (ebar < kold)
            grow = ~M & (ebar > np.maximum(kold, k0))
            if grow.any():
                grow &= dist == dist[grow].min()
            if not (drop.any() or grow.any()):
                return e, sv, np.maximum(kold, ebar), Dn, M
            M = (M & ~drop) | grow
        return None

    # elastic up to the onset at the weakened centre: uniform strain k0[c]
    eps = np.full(n, k0[c] * (1.0 + 1e-12))   # epsbar_c just past k0[c] despite rounding in A
    kold = A @ eps
    s = eps[0]                                # sigma / E
    D = damage(kold, k0, kc)
    M = np.zeros(n, bool)
    M[c] = True
    W = 0.5 * E * s * h * eps.sum()           # external work so far (linear, exact); falls in snap-backs
    Yd = 0.0
    q, dq = 0.0, 1e-3 * KAPPA0
    steps, cuts = 0, 0
    peak, w_single = s, 0.0
    while steps < max_steps:
        out = step(eps, s, kold, M, q + dq)
        ok = out is not None
        if ok:
            e, sv, k, Dn, Mn = out
            ok = np.max(Dn - D) <= 0.02 and abs(sv - s) <= 0.01 * KAPPA0 and sv >= -1e-9 * KAPPA0
        if not ok:
            dq *= 0.5
            cuts += 1
            if dq < 1e-12 * KAPPA0:
                return {"ratio": ratio, "h_over_R": h_over_r, "converged": False, "steps": steps,
                        "eps_c_over_kappa0": float(eps[c] / KAPPA0), "sigma_over_ft": float(s * E / FT)}
            continue
        M = Mn
        sv = max(sv, 0.0)
        W += 0.5 * E * (s + sv) * h * (e.sum() - eps.sum())
        Yd += 0.25 * E * h * np.sum((eps ** 2 + e ** 2) * (Dn - D))
        eps, s, D, kold = e, sv, Dn, k
        steps += 1
        peak = max(peak, s)
        if eps[c] - s <= 0.9 * np.sum(eps - s):
            w_single = Yd                     # the last state before the centre takes 90% of the opening
        q += dq
        dq = min(2.0 * dq, max(0.05 * q, 1e-3 * KAPPA0))
        if D[c] >= 1.0:
            break
    elastic = 0.5 * E * h * np.sum((1.0 - D) * eps ** 2)
    phi = h * np.sum(dissipation_density(kold, k0, kc, E))
    g_full = 0.5 * FT * ratio * KAPPA0
    damaged = D > 0.0
    U = h * eps.sum()
    # pull on at sigma = 0: only the central element stretches (single-element localization)
    late = np.zeros(n)
    late[c] = 10.0 * eps[c]
    k_late = np.maximum(kold, A @ late)
    phi_late = h * np.sum(dissipation_density(k_late, k0, kc, E))
    return {
        "ratio": ratio, "h_over_R": h_over_r, "converged": bool(D[c] >= 1.0), "n": n, "L_over_R": n * h / R,
        "G": W, "b_eff_over_R": W / g_full / R,
        "damaged_over_R": float(h * damaged.sum() / R),
        "failed_over_R": float(h * (D >= 1.0).sum() / R),
        "balance": (W - elastic - Yd) / W, "phi_err": (phi - W) / W, "phi_over_R": phi / g_full / R,
        "peak_over_ft": peak * E / FT, "share": float(h * eps[c] / U),
        "U_over_kappa_c_R": U / (ratio * KAPPA0 * R),
        "after_single": 1.0 - w_single / Yd,
        "half_damaged_over_R": float(h * (D >= 0.5).sum() / R),
        "phi_late_over_W": phi_late / W, "failed_late_over_R": float(h * (k_late >= kc).sum() / R),
        "ends_damaged": bool(damaged[0] or damaged[-1]), "steps": steps, "cuts": cuts,
        "wall_s": time.perf_counter() - t0,
        "kappa_over_kappa0": [float(v) for v in kold[damaged] / KAPPA0],
    }


def numbers(text: str, flag: str, lo: float, hi: float) -> list[float] | None:
    """A comma-separated list of floats in [lo, hi], or None after a one-line error."""
    try:
        v = [float(t) for t in text.split(",") if t.strip()]
    except ValueError:
        v = []
    if not v or not all(lo <= a <= hi for a in v):
        print(f"nonlocal_band: {flag} {text!r} must be a comma-separated list of numbers in [{lo:g}, {hi:g}]",
              file=sys.stderr)
        return None
    return v


HEAD = ("| kappa_c/kappa0 | h/R | b_eff/R | damaged/R (D>0) | failed/R (D=1) | peak/f_t | balance W-(psi+YdD) "
        "| phi err | G after 1-elem | phi x10 / W | steps |\n|" + "---|" * 11)


def row(m: dict) -> str:
    if not m["converged"]:
        return (f"| {m['ratio']:g} | {m['h_over_R']:g} | not converged at eps_c = {m['eps_c_over_kappa0']:.3g} "
                f"kappa0, sigma = {m['sigma_over_ft']:.3g} f_t |" + " |" * 7 + f" {m['steps']} |")
    return (f"| {m['ratio']:g} | {m['h_over_R']:g} | {m['b_eff_over_R']:.4f} | {m['damaged_over_R']:.2f} | "
            f"{m['failed_over_R']:.2f} | {m['peak_over_ft']:.5f} | {m['balance']:+.1e} | {m['phi_err']:+.1%} | "
            f"{m['after_single']:.1%} | {m['phi_late_over_W']:.3f} | {m['steps']} |"
            + (" damage reached the ends: raise L_OVER_R" if m["ends_damaged"] else ""))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m verification.nonlocal_band", description=__doc__.splitlines()[0])
    ap.add_argument("--ratios", default="2,3,4,6,10,15,20,30,50",
                    help="kappa_c / kappa0 values in [1.5, 1000], comma-separated")
    ap.add_argument("--h-over-R", default="0.1,0.05", help="element sizes h / R in [0.01, 0.5], comma-separated")
    ap.add_argument("--out", type=Path, default=Path("results/nonlocal_band"))
    args = ap.parse_args(argv)
    ratios = numbers(args.ratios, "--ratios", 1.5, 1000.0)
    hs = numbers(args.h_over_R, "--h-over-R", 0.01, 0.5)
    if ratios is None or hs is None:
        return 2
    try:
        args.out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        print(f"nonlocal_band: --out {str(args.out)!r}: {err.strerror}", file=sys.stderr)
        return 2
    print(HEAD, flush=True)
    rows = []
    for ratio in ratios:
        for hr in hs:
            m = run(ratio, hr)
            rows.append(m)
            (args.out / "band.json").write_text(json.dumps(rows, indent=1) + "\n")
            print(row(m), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
