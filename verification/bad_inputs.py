"""Bad inputs to the cases and what each one does: the acceptance table of docs/reliability.md.

Every row runs a case's ``main(argv)`` in this process, in a fresh temporary working folder
(so the default ``results/<case>/`` lands there too), and records the exit code, the stderr
lines and whether any file or folder appeared or changed there. Rows that need a real
interpreter (a Python call that may start gmsh) run in a subprocess in the same way.

No row may start the work: the cases' warm-up is replaced by a tripwire, so a bad input that
slips past the checks shows up as "started work" instead of a long run. Rows marked ``work``
are refused at the start of the run itself (a garbled checkpoint is read when its run begins)
and keep the real warm-up.

    python -m verification.bad_inputs            # print the table
    python -m verification.bad_inputs --write    # regenerate docs/reliability.md
"""
import argparse
import contextlib
import importlib
import io
import logging
import os
import re
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from unittest import mock

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "reliability.md"

HEADER = """# Reliability: what bad input does

Every case refuses bad input before any work: one line on stderr naming the culprit and the
fix, exit code 2, and nothing written (no results folder, no moved files). The table below is
the record of every bad input tried, one row each: the command (run in an empty folder), its
exit code, the stderr line and whether anything was written. Memory refusals compare an
estimate of the run's peak memory with the memory the machine has available, shown here as
`<N>`. The table is generated, not edited: `python -m verification.bad_inputs --write`
regenerates it, and `tests/test_reliability_table.py` fails when a row misbehaves or this file
is out of date.
"""


@dataclass(frozen=True)
class Row:
    """One bad input.

    Attributes:
        what: What is wrong, in a few words.
        case: The case module under ``rkfx.cases`` whose ``main`` runs; ``""`` for a Python call.
        argv: The command-line arguments (relative paths: the row runs in its own empty folder).
        setup: Files the row needs, made in its folder before it runs (e.g. a file named as --out).
        code: For a Python call row, the call of a ``rkfx.geometry.gmsh_nodes`` function, run in a
            subprocess; its exit reads ``InputError`` when it raises one, else the exception's type.
        work: The refusal comes at the start of the run (keep the real warm-up).
        note: Why the row is not yet a one-line refusal, when it is not; such rows are shown,
            not asserted.
    """

    what: str
    case: str
    argv: tuple[str, ...] = ()
    setup: Callable[[Path], None] | None = None
    code: str = ""
    work: bool = False
    note: str = ""

    @property
    def command(self) -> str:
        if not self.case:
            return f"rkfx.geometry.gmsh_nodes.{self.code}"
        return " ".join([f"python -m rkfx.cases.{self.case}", *map(_quote, self.argv)])


@dataclass
class Outcome:
    """What a row did: exit code (or raised exception), stderr lines, files written."""

    exit: str
    lines: list[str] = field(default_factory=list)
    written: list[str] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def message(self) -> str:
        return self.lines[-1] if self.lines else ""


def _quote(arg: str) -> str:
    return '""' if arg == "" else (f"'{arg}'" if re.search(r"[\s;*()'\"]", arg) else arg)


def _file(name: str, text: str = "not a folder\n") -> Callable[[Path], None]:
    def make(tmp: Path) -> None:
        (tmp / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp / name).write_text(text)
    return make


def _folder(name: str) -> Callable[[Path], None]:
    return lambda tmp: (tmp / name).mkdir(parents=True)


def _bytes(name: str, data: bytes) -> Callable[[Path], None]:
    return lambda tmp: (tmp / name).write_bytes(data)


def _stored_run(case: str, run: str, quick: bool = False, checkpoint: bytes | None = None) -> Callable[[Path], None]:
    """An interrupted invocation of ``case`` in ``old-run`` with its default (or ``quick``)
    parameters: the fingerprint and one run's folder, holding ``checkpoint`` if given."""
    def make(tmp: Path) -> None:
        from rkfx.cases import _cli  # noqa: PLC0415

        module = importlib.import_module(f"rkfx.cases.{case}")
        params = _cli.parse_params(module.PARAMS, base=module.QUICK if quick else None)
        folder = tmp / "old-run" / "checkpoints" / run
        folder.mkdir(parents=True)
        if checkpoint is not None:
            (folder / "checkpoint.npz").write_bytes(checkpoint)
        _cli.write_fingerprint(folder.parent, _cli.fingerprint(case, module.PARAMS, params, "both"))
    return make


def _case_rows(case: str, sets: Sequence[tuple[str, str]], extra: Sequence[str] = ()) -> list[Row]:
    return [Row(what, case, (*extra, "--set", *item.split())) for what, item in sets]


BROKEN_GEO = "Point(1) = {0, 0, 0, 0.1};\nLine(1) = {1, 2;\nPlane Surface(1) = {;\n"
UNDEFINED_POINT_GEO = ("Point(1) = {0, 0, 0, 0.1};\nPoint(2) = {1, 0, 0, 0.1};\nPoint(3) = {1, 1, 0, 0.1};\n"
                       "Line(1) = {1, 2};\nLine(2) = {2, 3};\nLine(3) = {3, 7};\nCurve Loop(1) = {1, 2, 3};\n"
                       "Plane Surface(1) = {1};\n")

ROWS: list[Row] = [
    # --- the shared command line (mandel stands for every case) ---
    Row("unknown parameter", "mandel", ("--set", "nxx=41")),
    Row("--set without =", "mandel", ("--set", "nx")),
    Row("integer expected", "mandel", ("--set", "nx=forty")),
    Row("integer expected, got a float", "mandel", ("--set", "nx=41.5")),
    Row("number expected", "mandel", ("--set", "E=soft")),
    Row("non-finite number (nan)", "mandel", ("--set", "E=nan")),
    Row("non-finite number (inf)", "terzaghi", ("--set", "k=inf")),
    Row("true/false expected", "kalthoff", ("--set", "forward=maybe")),
    Row("empty list", "mandel", ("--set", "t_D=")),
    Row("list with a non-number", "mandel", ("--set", "t_D=0.1,soon")),
    Row("list with a non-finite number", "crack_branching", ("--set", "h=8e-4,inf")),
    Row("nonlocal radius under 1.5 spacings", "crack_branching", ("--set", "nonlocal_radius=5e-4")),
    Row("unknown --method", "mandel", ("--method", "bem")),
    Row("unknown option", "mandel", ("--fast",)),
    Row("--out is a file", "mandel", ("--out", "notes.txt"), setup=_file("notes.txt")),
    Row("--out under a file", "mandel", ("--out", "notes.txt/run1"), setup=_file("notes.txt")),
    Row("--out empty", "mandel", ("--out", "")),
    Row("--out in an unwritable folder", "mandel", ("--out", "/proc/sys/rkfx-results")),
    Row("--resume of a missing folder", "mandel", ("--resume", "old-run")),
    Row("--resume of a folder without checkpoints", "terzaghi", ("--resume", "old-run"), setup=_folder("old-run")),
    Row("negative --checkpoint-every", "mandel", ("--checkpoint-every", "-5")),
    Row("--checkpoint-every not a number", "kalthoff", ("--checkpoint-every", "often")),
    Row("--recompute without --resume", "kalthoff", ("--recompute",)),
    Row("--resume with other parameters", "kalthoff", ("--resume", "old-run", "--set", "v0=30"),
        setup=_stored_run("kalthoff", "rkpm-dpm_n150")),
    Row("--resume of runs without a fingerprint", "strip_load", ("--resume", "old-run"),
        setup=_folder("old-run/checkpoints/rkpm-ni")),
    Row("garbled checkpoint file", "mandel", ("--quick", "--method", "rkpm", "--resume", "old-run"),
        setup=_stored_run("mandel", "rkpm-scni+fpp-profiles", quick=True, checkpoint=b"garbage\n"), work=True),
    # --- memory: refused before any work ---
    Row("too big for memory", "mandel", ("--set", "nx=1000000000")),
    Row("too big for memory", "kalthoff", ("--set", "h=6.7e-4,1e-7")),
    Row("too big for memory", "crack_branching", ("--set", "h=1e-6")),
    Row("too big for memory", "cracked_bar", ("--set", "nodes=16,2000000000")),
    # --- documented ranges, case by case ---
    *_case_rows("mandel", [("Poisson's ratio 0.5", "nu=0.5"), ("negative modulus", "E=-1e4"),
                           ("zero mobility", "k=0"), ("Biot coefficient above 1", "alpha=1.5"),
                           ("negative storage", "S=-1e-3"), ("too few nodes", "nx=2"), ("zero slab width", "Lx=0"),
                           ("shrinking steps", "growth=0.5"), ("negative output time", "t_D=-0.1,0.5"),
                           ("unknown RKPM variant", "variants=scni+fpp,gauss"), ("unknown FEM element", "fem=p3p2"),
                           ("support too small", "support_factor=0.9"), ("no load", "F=0"),
                           ("first step too short for the exact solution", "dt_D=1e-12")]),
    *_case_rows("terzaghi", [("output time not a number", "t_out=soon"), ("output time after t_end", "t_out=5"),
                             ("too few nodes", "ny=2"), ("zero time step", "dt=0"), ("no load", "q=0"),
                             ("refinement with too few nodes", "refine_ny=21,2"), ("Poisson's ratio -1", "nu=-1"),
                             ("support too small", "support_factor=1")]),
    *_case_rows("strip_load", [("model too small for the strip", "extent=2"),
                               ("too many nodes for the grading", "nx=500"),
                               ("history point below the model", "depth_history=100"),
                               ("zero low mobility", "k_low=0"), ("no low-permeability steps", "steps_low=0"),
                               ("history ends before the profile", "t_D_end=0.01"),
                               ("unknown FEM element", "fem=taylor-hood,p1")]),
    *_case_rows("cracked_bar", [("odd node count", "nodes=15"), ("weak factor 1", "weak_factor=1"),
                                ("too few load steps", "steps=2"), ("path stops before failure", "u_end=0.9"),
                                ("unknown cells", "cells=hexagons"), ("strength above the modulus", "ft=3e6"),
                                ("bar too long for its fracture energy", "L=1e6"),
                                ("snapshot off the softening branch", "stress_at=1")]),
    *_case_rows("plate_with_hole", [("hole larger than the plate", "a=6"), ("mesh size too large", "h=10"),
                                    ("no levels", "levels=0"), ("unknown integration rule", "rules=mscni,gauss3"),
                                    ("unknown essential-BC method", "bc_method=penalty"),
                                    ("FEM degree not offered", "fem_degrees=4"),
                                    ("support too small", "support_factor=0.5"), ("Poisson's ratio 0.5", "nu=0.5"),
                                    ("no load", "T=0")]),
    *_case_rows("kalthoff", [("support too small for the crack", "support_factor=1.5"),
                             ("Courant number above 1", "courant=1.5"), ("too few particles", "h=0.01,6.7e-4"),
                             ("zero tracking radius", "radius=0"), ("negative stabilization", "eps_p=-1"),
                             ("Poisson's ratio above 0.5", "nu=0.6"), ("tracking tolerance above 1", "tol=1.5"),
                             ("too coarse for the fracture energy", "GF=1 h=6.7e-4")]),
    *_case_rows("crack_branching", [("unknown plane idealization", "plane=axisymmetric"),
                                    ("tracking tolerance above 1", "tol=2"), ("spacing too coarse", "h=0.01"),
                                    ("tracking radius below 1 spacing", "radius=0.5"), ("negative stabilization", "eps_p=-0.5"),
                                    ("Courant number 0", "courant=0"), ("zero density", "rho=0")]),
    *_case_rows("sneddon", [("even particle count along the crack", "crack_particles=10"),
                            ("spacing that does not divide the square", "c=0.35"),
                            ("unknown crack band", "bands=wide"), ("no residual stiffness", "residual=0"),
                            ("crack as wide as the square", "c=2"), ("no pressure", "p=0"),
                            ("tip size above the element size", "fem_tip=0.5")]),
    Row("too big for memory", "sneddon", ("--set", "crack_particles=9,9999")),
    *_case_rows("injection", [("spacing that does not divide the notch", "h=0.03"),
                              ("Biot coefficient below the porosity", "alpha=0.1"),
                              ("unknown Jacobian", "jacobian=exact"), ("falling notch pressure", "rate=-1"),
                              ("map time after the end", "t_out=5000"), ("porosity 1", "porosity=1"),
                              ("tracking tolerance above 1", "tol=2"),
                              ("unknown damage update", "damage_update=explicit"),
                              ("no residual stiffness", "residual=0"), ("negative injected rate", "injection_rate=-1")]),
    Row("FEM spacing that does not divide the notch", "injection", ("--method", "fem", "--set", "fem_h=0.03")),
    Row("too big for memory", "injection", ("--set", "h=1e-5")),
    *_case_rows("blanton", [("unknown test", "tests=CT-5"),
                            ("notch reaching the pre-fracture", "notch=0.05"),
                            ("pre-fracture outside the block", "offset=0.2"),
                            ("growth step above the pressure ramp", "dt=0.1"), ("zero friction", "mu=0"),
                            ("unknown damage update", "damage_update=explicit")], extra=("--method", "rkpm")),
    Row("negative contact penalty, FEM baseline", "blanton", ("--method", "fem", "--set", "penalty=-1")),
    Row("too big for memory", "blanton", ("--method", "rkpm", "--set", "h=1e-5")),
    *_case_rows("wave_column", [("unknown nodal rule", "rules=nsni,fem"), ("porosity 1", "porosity=1"),
                                ("grains softer than the skeleton", "K_s=1e8"), ("Courant number above 1", "courant=1.5"),
                                ("too few nodes along the height", "ny=3"), ("exclusion wider than the history", "exclude=1")]),
    Row("too big for memory", "wave_column", ("--set", "ny=99999999")),
    *_case_rows("liakopoulos", [("unknown retention law", "retention=vg"),
                                ("grid not whole across the column", "ny=20"),
                                ("probe above the column", "probes=1.5"), ("zero largest step", "max_step=0")]),
    Row("too big for memory", "liakopoulos", ("--set", "ny=99999991")),
    *_case_rows("levee", [("river above the crest", "water=1.5"), ("mesh too coarse for the slopes", "h=0.3"),
                          ("unknown nodal rule", "rule=gauss"), ("zero conductivity", "conductivity=0"),
                          ("residual saturation 1", "S_rw=1"), ("no steps of the plastic ramp", "ramp_steps=0"),
                          ("collapse path without plasticity", "collapse=true"),
                          ("zero largest settlement of the collapse path", "settlement_max=0")]),
    Row("too big for memory", "levee", ("--set", "h=1e-5")),
    *_case_rows("granular_collapse", [("aspect ratio zero", "aspects=0"), ("too few particles across", "across=3"),
                                      ("unknown nodal rule", "rules=gauss"), ("step beyond stability", "cfl=0.9")]),
    Row("too big for memory", "granular_collapse", ("--set", "across=99999")),
    Row("no FEM baseline", "granular_collapse", ("--method", "fem", "--quick")),
    *_case_rows("cryer", [("mesh coarser than the sphere", "mesh_size=0.9"), ("unknown RKPM variant", "variants=gauss2"),
                          ("negative radius", "radius=-1"), ("step growth below 1", "growth=0.5"),
                          ("no output time", "t_D=-0.1")]),
    Row("too big for memory", "cryer", ("--set", "mesh_size=0.01")),
    # --- geometry files ---
    Row("broken .geo file", "", code="from_geo('broken.geo')", setup=_file("broken.geo", BROKEN_GEO)),
    Row(".geo file with an undefined point", "", code="from_geo('undefined.geo')",
        setup=_file("undefined.geo", UNDEFINED_POINT_GEO)),
    Row("empty .geo file", "", code="from_geo('empty.geo')", setup=_file("empty.geo", "")),
    Row("binary file as .geo", "", code="from_geo('mesh.geo')", setup=_bytes("mesh.geo", bytes(range(256)))),
    Row("missing .geo file", "", code="from_geo('missing.geo')"),
]


class StartedWork(BaseException):
    """Raised by the tripwire in place of the warm-up: the row got past every check."""


def _snapshot(folder: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns) if p.is_file() else (-1, 0)
            for p in folder.rglob("*")}


def _clean(text: str, tmp: Path) -> str:
    """A stderr line without what differs between machines: the temporary folder and the free memory."""
    text = text.replace(str(tmp.resolve()), "<tmp>").replace(str(tmp), "<tmp>")
    return re.sub(r"has [0-9.]+ GB available", "has <N> GB available", text)


def _in_process(row: Row, tmp: Path) -> Outcome:
    from rkfx.cases import _cli  # noqa: PLC0415

    main = importlib.import_module(f"rkfx.cases.{row.case}").main
    err, out = io.StringIO(), io.StringIO()
    log = logging.getLogger("rkfx")
    handlers, level = list(log.handlers), log.level

    def tripwire():
        raise StartedWork

    here = os.getcwd()
    os.chdir(tmp)
    try:
        with contextlib.ExitStack() as stack:
            stack.enter_context(contextlib.redirect_stderr(err))
            stack.enter_context(contextlib.redirect_stdout(out))
            if not row.work:
                stack.enter_context(mock.patch.object(_cli, "warm_up", tripwire))
            try:
                code = str(main(list(row.argv)))
            except SystemExit as stop:
                code = str(stop.code if isinstance(stop.code, int) else 1)
            except StartedWork:
                code = "started work"
            except Exception as exc:  # noqa: BLE001 - a traceback is what the user would see
                print(f"{type(exc).__name__}: {exc}", file=err)
                code = "1 (traceback)"
    finally:
        os.chdir(here)
        log.handlers[:] = handlers  # a resume installs a stderr handler for its progress lines
        log.setLevel(level)
    return Outcome(code, [ln for ln in err.getvalue().splitlines() if ln.strip()])


# A Python call as a user would make it: an InputError is the one-line refusal, anything else a failure.
_CALL = """import sys
from rkfx.errors import InputError
from rkfx.geometry.gmsh_nodes import *
try:
    {code}
except InputError as err:
    print(f"InputError: {{err}}", file=sys.stderr)
    sys.exit(2)
except Exception as err:
    print(f"{{type(err).__name__}}: {{err}}", file=sys.stderr)
    sys.exit(1)
"""


def _subprocess(row: Row, tmp: Path) -> Outcome:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)}
    proc = subprocess.run([sys.executable, "-c", _CALL.format(code=row.code)], cwd=tmp, env=env,
                          capture_output=True, text=True, timeout=120)
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    raised = lines[-1].split(":", 1)[0] if proc.returncode in (1, 2) and lines else ""
    return Outcome(f"raises {raised}" if raised else str(proc.returncode), lines)


def run_row(row: Row) -> Outcome:
    """Run one row in a fresh temporary folder and record what it did."""
    with tempfile.TemporaryDirectory(prefix="rkfx-bad-input-") as name:
        tmp = Path(name)
        if row.setup is not None:
            row.setup(tmp)
        before = _snapshot(tmp)
        t0 = time.perf_counter()
        outcome = _in_process(row, tmp) if row.case else _subprocess(row, tmp)
        outcome.seconds = time.perf_counter() - t0
        after = _snapshot(tmp)
        outcome.written = sorted(k for k in after if before.get(k) != after[k]) + \
            sorted(f"{k} (removed)" for k in before if k not in after)
        outcome.lines = [_clean(ln, tmp) for ln in outcome.lines]
    return outcome


def refused(outcome: Outcome) -> bool:
    """The contract: exit code 2 (a Python call: an InputError), one stderr line, nothing written."""
    return outcome.exit in ("2", "raises InputError") and len(outcome.lines) == 1 and not outcome.written


def _cell(text: str) -> str:
    """Text for a Markdown table cell: pipes escaped, angle brackets not read as HTML."""
    return text.replace("|", "\\|").replace("<", "&lt;").replace(">", "&gt;").replace("\n", " ")


def table(rows: Sequence[Row] = ROWS, outcomes: Sequence[Outcome] | None = None) -> str:
    """docs/reliability.md: the header and one table row per bad input."""
    outcomes = [run_row(r) for r in rows] if outcomes is None else outcomes
    lines = [HEADER, "| # | bad input | command | exit | stderr | written |", "|---|---|---|---|---|---|"]
    for i, (row, out) in enumerate(zip(rows, outcomes), 1):
        stderr = out.message if len(out.lines) <= 1 else f"({len(out.lines)} lines) … {out.message}"
        if row.note:
            stderr += f" *({row.note})*"
        lines.append(f"| {i} | {_cell(row.what)} | `{_cell(row.command)}` | {out.exit} | {_cell(stderr)} | "
                     f"{_cell(', '.join(out.written)) if out.written else 'nothing'} |")
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """Print the table, or with ``--write`` regenerate docs/reliability.md."""
    parser = argparse.ArgumentParser(prog="python -m verification.bad_inputs", description=__doc__.split("\n\n")[0])
    parser.add_argument("--write", action="store_true", help=f"write {DOC.relative_to(ROOT)}")
    args = parser.parse_args(argv)
    text = table()
    if args.write:
        DOC.write_text(text)
        print(f"wrote {DOC}")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
