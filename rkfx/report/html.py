"""The report page: one plain HTML file (inline CSS, no scripts) beside the cases' folders.

Figures are referenced by their path relative to the page (``<case>/<figure>.png``), so the
output folder is self-contained and can be moved or archived whole.
"""
import html
import math
from collections.abc import Mapping, Sequence
from pathlib import Path

from rkfx.report.claims import FAIL, PASS, SKIP, Outcome

CSS = """
body { font-family: sans-serif; margin: 1.5em auto; max-width: 1200px; color: #222; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 2px solid #ccc; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em; font-size: 0.88em; }
th, td { border: 1px solid #bbb; padding: 3px 7px; text-align: left; vertical-align: top; }
th { background: #eee; } td.num { text-align: right; font-family: monospace; }
.PASS { background: #c8f0c8; color: #0a5a0a; font-weight: bold; }
.FAILED { background: #f8c4c4; color: #8a0000; font-weight: bold; }
.SKIPPED { background: #e4e4e4; color: #555; }
.wide { overflow-x: auto; } .note { color: #8a0000; font-size: 0.9em; }
pre { background: #f6f6f6; border: 1px solid #ddd; padding: 0.6em; overflow-x: auto; font-size: 0.82em; }
figure { display: inline-block; margin: 0.4em; vertical-align: top; }
figure img { max-width: 560px; border: 1px solid #ddd; } figcaption { font-size: 0.8em; color: #555; }
"""


def esc(x) -> str:
    """HTML-escaped text of anything."""
    return html.escape(str(x))


def num(v) -> str:
    """A scalar as compact text: 3 significant digits, '-' for None and non-finite values."""
    if v is None:
        return "-"
    if isinstance(v, bool) or isinstance(v, str):
        return str(v)
    if isinstance(v, int):
        return str(v)
    try:
        v = float(v)
    except (TypeError, ValueError):
        return str(v)
    return "-" if not math.isfinite(v) else f"{v:.3g}"


def table(head: Sequence[str] | None, rows: Sequence[Sequence],
          classes: Sequence[Sequence[str]] | None = None) -> str:
    """An HTML table (``head``: column titles, or ``None``); cells are escaped; ``classes`` gives
    each cell's CSS class."""
    out = ['<div class="wide"><table>']
    if head:
        out.append("<tr>" + "".join(f"<th>{esc(h)}</th>" for h in head) + "</tr>")
    for i, row in enumerate(rows):
        cells = []
        for j, c in enumerate(row):
            cls = classes[i][j] if classes else ""
            cells.append(f'<td class="{cls}">{esc(c)}</td>' if cls else f"<td>{esc(c)}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</table></div>")
    return "\n".join(out)


def scalar(v) -> bool:
    """Whether a results.json value is a table cell (a number, bool, string or None)."""
    return v is None or isinstance(v, (int, float, str, bool))


def claims_table(outcomes: Sequence[Outcome]) -> str:
    """The claim table: claim, runs, measured, bound, verdict (every claim, failed ones included)."""
    if not outcomes:
        return '<p class="note">This case has no claims.</p>'
    rows, classes = [], []
    for i, o in enumerate(outcomes, 1):
        verdict = o.status + (f" ({o.note})" if o.note else "")
        rows.append([i, o.claim.text, o.claim.selector_text(), o.claim.key, o.measured, o.claim.bound_text(), verdict])
        classes.append(["num", "", "", "", "num", "num", o.status])
    return table(["#", "claim (seed)", "run(s)", "errors key", "measured", "bound", "verdict"], rows, classes)


def runs_table(runs: Sequence[Mapping]) -> str:
    """RKPM and FEM runs side by side: method, dofs, wall time and every scalar error."""
    keys = list(dict.fromkeys(k for r in runs for k, v in (r.get("errors") or {}).items() if scalar(v)))
    rows, classes = [], []
    for r in runs:
        errs = r.get("errors") or {}
        rows.append([r.get("method"), num(r.get("n_dofs")), num(r.get("wall_time_s")),
                     *(num(errs.get(k)) for k in keys)])
        classes.append(["", "num", "num", *(["num"] * len(keys))])
    return table(["method", "dofs", "wall [s]", *keys], rows, classes)


ERROR_WORDS = ("err", "l2", "dev", "_vs_", "overshoot")  # keys that measure an error, not a result


def _family(method) -> str:
    return str(method).split("-")[0]


def time_to_accuracy(results: Mapping, claim_keys: Sequence[str]) -> str:
    """The case's own time-to-accuracy table (``params["time_to_accuracy"]``), else error against
    wall time per run for the error keys (``ERROR_WORDS`` in their names) that RKPM and FEM runs
    share, the claims' keys first, at most three."""
    params = results.get("params") or {}
    own = params.get("time_to_accuracy")
    if isinstance(own, list) and own and all(isinstance(r, Mapping) for r in own):
        head = list(dict.fromkeys(k for r in own for k in r))
        return "<h3>Time to accuracy</h3>\n" + table(
            head, [[num(r.get(k)) for k in head] for r in own], [["num"] * len(head) for _ in own])
    runs = [r for r in results.get("runs") or [] if _family(r.get("method")) in ("rkpm", "fem")
            and isinstance(r.get("wall_time_s"), (int, float))]
    shared = []
    for k in dict.fromkeys([*claim_keys, *(k for r in runs for k in (r.get("errors") or {}))]):
        fams = {_family(r["method"]) for r in runs if isinstance((r.get("errors") or {}).get(k), (int, float))}
        if fams == {"rkpm", "fem"} and any(w in k for w in ERROR_WORDS):
            shared.append(k)
    if not shared:
        return ""
    shared = [k for k in shared if k in claim_keys][:3] or shared[:1]
    parts = ["<h3>Time to accuracy (error against wall time, RKPM and FEM)</h3>"]
    for k in shared:
        rows = sorted(((r["method"], r.get("n_dofs"), r["wall_time_s"], r["errors"][k]) for r in runs
                       if isinstance((r.get("errors") or {}).get(k), (int, float))), key=lambda t: (abs(t[3]), t[2]))
        parts.append(f"<p>{esc(k)}, smallest first:</p>")
        parts.append(table(["method", "dofs", "wall [s]", k], [[m, num(d), num(w), num(e)] for m, d, w, e in rows],
                           [["", "num", "num", "num"]] * len(rows)))
    return "\n".join(parts)


def figures_html(figures: Sequence[Path], page_dir: Path) -> str:
    """``<img>`` of every figure, by its path relative to the page."""
    out = []
    for f in figures:
        rel = Path(f).resolve().relative_to(Path(page_dir).resolve()).as_posix()
        out.append(f'<figure><a href="{esc(rel)}"><img src="{esc(rel)}" alt="{esc(f.name)}"></a>'
                   f"<figcaption>{esc(f.name)}</figcaption></figure>")
    return "\n".join(out) if out else "<p>No figures.</p>"


def status_of(outcomes: Sequence[Outcome], failed: bool) -> str:
    """PASS when the case ran and no claim failed."""
    return FAIL if failed or any(o.status == FAIL for o in outcomes) else PASS


def counts(outcomes: Sequence[Outcome]) -> tuple[int, int]:
    """(passed, checked) claims; skipped ones are not counted."""
    checked = [o for o in outcomes if o.status != SKIP]
    return sum(o.status == PASS for o in checked), len(checked)


def case_section(case, outcomes: Sequence[Outcome], page_dir: Path) -> str:
    """One case: verdict, claims, figures, runs, time to accuracy (a failed case: its log tail)."""
    status = status_of(outcomes, case.failed)
    passed, checked = counts(outcomes)
    parts = [f'<h2 id="{esc(case.name)}">{esc(case.name)} <span class="{status}">{status}</span></h2>',
             f"<p>claims passed {passed}/{checked}; wall time {case.wall_time_s:.1f} s; folder "
             f'<a href="{esc(case.name)}/">{esc(case.name)}/</a> '
             f'(log: <a href="{esc(case.name)}/log.txt">log.txt</a>)</p>']
    if case.failed:
        parts.append(f'<p class="FAILED">FAILED: {esc(case.error)}</p>')
        parts.append(f"<pre>{esc(case.log_tail) or '(empty log)'}</pre>")
    parts.append("<h3>Claims</h3>")
    parts.append(claims_table(outcomes))
    if case.failed:
        return "\n".join(parts)
    parts.append("<h3>Figures</h3>")
    parts.append(figures_html(case.figures, page_dir))
    runs = case.results.get("runs") or []
    parts.append("<h3>Runs (RKPM and FEM)</h3>")
    parts.append(runs_table(runs) if runs else "<p>No runs.</p>")
    parts.append(time_to_accuracy(case.results, [o.claim.key for o in outcomes]))
    return "\n".join(p for p in parts if p)


def page(cases: Sequence, outcomes: Mapping[str, Sequence[Outcome]], header: Mapping[str, str],
         page_dir: Path) -> str:
    """The whole report page."""
    rows, classes = [], []
    for c in cases:
        oc = outcomes[c.name]
        status = status_of(oc, c.failed)
        passed, checked = counts(oc)
        rows.append([c.name, status, f"{passed}/{checked}", f"{c.wall_time_s:.1f}"])
        classes.append(["", status, "num", "num"])
    summary = table(["case", "verdict", "claims passed", "wall [s]"], rows, classes)
    links = " · ".join(f'<a href="#{esc(c.name)}">{esc(c.name)}</a>' for c in cases)
    head = table(None, [[k, v] for k, v in header.items()])
    body = [f"<h1>rkfx benchmark report</h1>", head, "<h2>Summary</h2>", summary, f"<p>{links}</p>",
            *(case_section(c, outcomes[c.name], page_dir) for c in cases)]
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>rkfx benchmark report</title><style>{CSS}</style></head>\n<body>\n"
            + "\n".join(body) + "\n</body></html>\n")
