"""Time to accuracy: the wall times and unknowns of the RKPM and FEM runs of a case at the
same error, each method's runs forming a curve of error against cost."""
from collections.abc import Callable, Sequence

import numpy as np

from rkfx.cases._cli import Run


def matched(runs: Sequence[Run], key: str, select: Callable[[Run], bool] = lambda r: True) -> list[dict]:
    """For every selected run of either method (``rkpm...`` or ``fem...``) whose error
    ``errors[key]`` lies within the range of the other method's, the other's wall time and
    unknowns interpolated in log-log between its runs. Rows by decreasing error: ``error``,
    ``level_of`` (the method whose run gives the row), both methods' ``*_wall_s`` and
    ``*_dofs``, and ``wall_ratio`` (RKPM over FEM)."""
    def curve(prefix):
        rows = sorted((r.errors[key], r.wall_time_s, r.n_dofs) for r in runs
                      if select(r) and r.method.startswith(prefix) and r.errors.get(key, 0) > 0)
        return np.array(rows) if rows else np.zeros((0, 3))

    def at(c, err):  # the wall time and unknowns of curve c at error err
        le = np.log(c[:, 0])
        return tuple(float(np.exp(np.interp(np.log(err), le, np.log(c[:, j])))) for j in (1, 2))

    rk, fe = curve("rkpm"), curve("fem")
    out = []
    for mine, other, name in ((rk, fe, "rkpm"), (fe, rk, "fem")):
        for err, wall, dofs in mine:
            if len(other) < 2 or not other[0, 0] <= err <= other[-1, 0]:
                continue
            o_wall, o_dofs = at(other, err)
            row = {"error": float(err), "level_of": name}
            row.update({f"{name}_wall_s": float(wall), f"{name}_dofs": int(dofs)})
            o = "fem" if name == "rkpm" else "rkpm"
            row.update({f"{o}_wall_s": o_wall, f"{o}_dofs": int(round(o_dofs))})
            row["wall_ratio"] = row["rkpm_wall_s"] / row["fem_wall_s"]
            out.append(row)
    return sorted(out, key=lambda row: -row["error"])
