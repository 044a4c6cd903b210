"""What a case prints on the terminal: the summary tables, progress through time steps, and a
line per finished model with the warnings it raised.

* ``summary_table(results)``: the parameters wrapped, then one table per study, no line wider
  than ``WIDTH`` columns (columns that do not fit continue in a second table).
* ``progress(steps, desc, total)``: a bar counting the steps with an ETA when stderr is a
  terminal (on rank 0), the bare iterable otherwise; ``step_progress(desc, total)`` is the same
  bar for a stepper that reports its step number.
* ``model_run(label)``: around one model's run. Its warnings go to stderr as one line each,
  naming the model, and when it ends a line says so with its wall time (also when stderr is not
  a terminal, where no bar is shown).
"""
import math
import sys
import textwrap
import time
import warnings
from collections.abc import Iterable, Sequence
from contextlib import contextmanager

import numpy as np

WIDTH = 100  # columns of the terminal output


def _rank() -> int:
    from rkfx.cases._cli import comm  # noqa: PLC0415  (the CLI owns the communicator)

    c = comm()
    return c.rank if c is not None else 0


def _fmt_value(v, digits: int | None = 6):
    """A parameter value as ``--set`` takes it: lists comma-separated, floats to ``digits``
    significant digits (``None``: all)."""
    if isinstance(v, (list, tuple)):
        return ",".join(_fmt_value(x, digits) for x in v) if v else "[]"
    return f"{v:.{digits}g}" if isinstance(v, float) and digits is not None else str(v)


def summary_table(results, width: int = WIDTH) -> str:
    """Plain-text tables no wider than ``width`` columns: the parameters (wrapped), then one
    table per study (``info["study"]``) with the info scalars, dofs, wall time and errors of its
    runs; columns that do not fit go to a continuation table, which repeats the method. A
    summary run (``info["study"] == "summary"``) gets a table of its own titled with what it
    aggregates (``info["of"]``, ``info["over"]``)."""
    tables = {k: v for k, v in results.params.items() if _is_records(v)}
    title = f"{results.case}: " + ", ".join(f"{k}={_fmt_value(v)}" for k, v in results.params.items()
                                            if k not in tables)
    out = [textwrap.fill(title, width, subsequent_indent="    ", break_on_hyphens=False)]
    for heading, runs in _studies(results.runs):
        out += ["", textwrap.fill(heading, width, subsequent_indent="    "), *_table(runs, width)]
    for name, records in tables.items():  # e.g. a time-to-accuracy table
        out += ["", f"{name}:", *_columns(list(dict.fromkeys(k for r in records for k in r)),
                                          [[_cell(r.get(k)) for k in dict.fromkeys(k for r in records for k in r)]
                                           for r in records], width)]
    return "\n".join(out)


def _is_records(v) -> bool:
    """A parameter that is a table: a non-empty list of dicts."""
    return isinstance(v, list) and bool(v) and all(isinstance(r, dict) for r in v)


def _studies(runs: Sequence) -> list[tuple[str, list]]:
    """(heading, runs) per study in order of appearance; each summary run apart."""
    groups: dict[str, list[Run]] = {}
    headings = {}
    for k, r in enumerate(runs):
        study = r.info.get("study")
        if study == "summary":
            key = f"summary {k}"
            of, over = r.info.get("of", r.method), r.info.get("over")
            headings[key] = f"summary of {of}" + (f" over {over}" if over else "") + ":"
        else:
            key = "runs" if study is None else f"study {study}"
            headings.setdefault(key, f"{key}:")
        groups.setdefault(key, []).append(r)
    return [(headings[k], v) for k, v in groups.items()]


def _table(runs: Sequence, width: int) -> list[str]:
    def keys(attr):
        seen = {}
        for r in runs:
            for k, v in getattr(r, attr).items():
                if np.ndim(v) == 0 and not (attr == "info" and k in ("study", "of", "over")):
                    seen.setdefault(k, None)
        return list(seen)

    info, errs = keys("info"), keys("errors")
    head = ["method", *info, "dofs", "wall [s]", *errs]
    rows = [[r.method, *(_cell(r.info.get(k)) for k in info), str(r.n_dofs), f"{r.wall_time_s:.2f}",
             *(_cell(r.errors.get(k)) for k in errs)] for r in runs]
    return _columns(head, rows, width)


def _columns(head: list[str], rows: list[list[str]], width: int) -> list[str]:
    """Rows of cells under ``head``, columns that do not fit in ``width`` continued in further
    tables that repeat the first column."""
    widths = [max(len(c) for c in col) for col in zip(head, *rows)]
    chunks, current, used = [], [0], widths[0]
    for i in range(1, len(head)):
        if used + 2 + widths[i] > width and len(current) > 1:
            chunks.append(current)
            current, used = [0], widths[0]
        current.append(i)
        used += 2 + widths[i]
    chunks.append(current)
    lines = []
    for n, cols in enumerate(chunks):
        def fmt(row):
            return "  ".join(row[i].rjust(widths[i]) if i else row[i].ljust(widths[i]) for i in cols)
        lines += ([] if n == 0 else [""]) + [fmt(head), "  ".join("-" * widths[i] for i in cols), *map(fmt, rows)]
    return lines


def _cell(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, (bool, np.bool_, str)):
        return str(v)
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    v = float(v)
    return "-" if not math.isfinite(v) else f"{v:.3g}"


def _bar(desc: str, total: int | None):
    """A tqdm bar on stderr when it is a terminal (rank 0), else ``None``."""
    if not sys.stderr.isatty() or _rank() != 0:
        return None
    try:
        from tqdm import tqdm  # noqa: PLC0415
    except ImportError:
        return None
    return tqdm(desc=desc, total=total, leave=False, unit="step")


def progress(iterable: Iterable, desc: str = "", total: int | None = None) -> Iterable:
    """The steps of ``iterable`` counted on a bar with an ETA when stderr is a terminal; the
    bare iterable otherwise."""
    bar = _bar(desc, total)
    if bar is None:
        return iterable

    def counted():
        try:
            for item in iterable:
                yield item
                bar.update()
        finally:
            bar.close()

    return counted()


class step_progress:  # noqa: N801  (used like a function)
    """``step_progress(desc, total)(step)``: moves a bar to ``step`` of ``total`` (no-op
    without a terminal); ``close()`` removes it."""

    def __init__(self, desc: str, total: int):
        self.bar = _bar(desc, total)

    def __call__(self, step: int, total: int | None = None) -> None:
        if self.bar is not None:
            self.bar.update(max(0, int(step) - self.bar.n))

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


@contextmanager
def model_run(label: str):
    """One model's run: its warnings are printed after it as ``warning [label]: ...`` (each once),
    and a line ``done [label] in T s`` when it ends without an error."""
    t0 = time.perf_counter()
    ok = False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            yield
            ok = True
        finally:
            if _rank() == 0:
                for text in dict.fromkeys(f"{w.message}" for w in caught):
                    print(f"warning [{label}]: {text}", file=sys.stderr)
                if ok:
                    print(f"done [{label}] in {time.perf_counter() - t0:.2f} s", file=sys.stderr)
