"""The command-line interface every case shares: parameters, results file, summary table.

    python -m rkfx.cases.<name> [--quick] [--method rkpm|fem|both] [--set NAME=VALUE ...] [--out DIR]

A case declares its parameters as ``{name: Param(default, doc)}``; ``--set`` values are
coerced to the default's type (float, int, str, bool; comma-separated lists for list
defaults). ``--quick`` first applies the case's coarse settings, then ``--set`` overrides.
Bad parameters and the case's own input errors (``rkfx.errors.InputError``) end the program
with a one-line message on stderr and exit code 2, never a traceback.

Results go to ``DIR/results.json`` (default ``results/<name>/``) with the schema

    {"case": str, "params": {...},
     "runs": [{"method": str, "wall_time_s": float, "n_dofs": int,
               "series": {...}, "errors": {...}, "info": {...}}]}

(numpy arrays become lists; non-finite floats become null).

``--vtk`` also writes each run's fields through time for ParaView into ``DIR/vtk/``: RKPM
particles and nodal cells as ``<run>_particles.pvd`` / ``<run>_cells.pvd`` (``rkfx.output.paraview``),
FEM functions as ``<run>.pvd`` (``fem_baselines.paraview``); the case's ``run`` receives the folder
as ``vtk``.

Cases with checkpoints keep their runs' files in ``DIR/checkpoints/<run>/`` with the
fingerprint of the invocation (``fingerprint.json``: case, rkfx version, method, parameters).
``--resume DIR`` refuses, in one line naming the differing values, to read back runs computed
with other parameters, unless ``--recompute`` asks to compute them again.
"""
import argparse
import inspect
import json
import logging
import math
import os
import shutil
import sys
import textwrap
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from rkfx.cases._preflight import before_work
# The cases call these as _cli.progress, _cli.model_run, ...
from rkfx.cases._terminal import _fmt_value, model_run, progress, step_progress, summary_table  # noqa: F401
from rkfx.errors import InputError, SolverError
from rkfx.parallel.threads import share_cores
from rkfx.solvers.checkpoint import has_checkpoint, run_folder
from rkfx.memory import reuse_freed_memory
from rkfx.warmup import warm_up

VTK_FOLDER = "vtk"  # OUT/vtk: the ParaView files of --vtk
METHODS = {"rkpm": ("rkpm",), "fem": ("fem",), "both": ("rkpm", "fem")}


@dataclass(frozen=True)
class Alias:
    """An older name of a parameter that held the value in other terms: ``--set NAME=TEXT`` reads
    TEXT as the type of ``example`` and gives the parameter ``convert(value)``.

    Example: Kalthoff's ``nodes=150`` (particles along x) is ``h=[0.1 / 149]`` (spacing [m])."""

    name: str
    example: Any
    convert: Callable[[Any], Any]
    doc: str


@dataclass(frozen=True)
class Param:
    """A documented case parameter: its default (which fixes its type) and a one-line doc.

    ``fingerprint=False`` marks a value that only chooses which runs exist (a list of levels or
    variants, each run stored under its own label): a resume may change it and keeps the
    stored runs. Every other value is part of the fingerprint of the stored runs. A parameter
    added to a case defaults to the case's behaviour before it: runs stored before it existed
    resume as computed with its default.
    ``aliases``: older names that ``--set`` still takes for this parameter: a name (same value
    and unit) or an ``Alias`` (a value in other terms, converted); results and fingerprints
    use the parameter's own name, and a resume translates stored aliases the same way.
    """

    default: Any
    doc: str
    fingerprint: bool = True
    aliases: tuple[str | Alias, ...] = ()


@dataclass
class Run:
    """One solve of a case by one method.

    Attributes:
        method: Method label, e.g. ``rkpm-mscni`` or ``fem-p2``.
        wall_time_s: Wall time of the solve [s].
        n_dofs: Number of unknowns.
        series: Named arrays (curves, fields) for plots.
        errors: Named scalar errors (and rates) against the exact solution.
        info: Named scalars that identify the run (mesh size, level, ...).
    """

    method: str
    wall_time_s: float
    n_dofs: int
    series: dict[str, Any] = field(default_factory=dict)
    errors: dict[str, float] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)


@dataclass
class Results:
    """What a case's ``run`` returns: its name, the parameters used and the runs."""

    case: str
    params: dict[str, Any]
    runs: list[Run] = field(default_factory=list)


class ParameterError(InputError):
    """A ``--set`` override names no parameter or cannot be read as the parameter's type."""


def coerce(name: str, text: str, default: Any) -> Any:
    """``text`` read as the type of ``default`` (lists: comma-separated, typed by their first item;
    ``none``: the empty list, e.g. to skip a study)."""
    if isinstance(default, (list, tuple)):
        kind = default[0] if default else ""
        if text.strip().lower() == "none":
            return []
        items = [t.strip() for t in text.split(",") if t.strip()]
        if not items:
            raise ParameterError(f"{name}: expected a comma-separated list (or none), got {text!r}")
        return [coerce(name, t, kind) for t in items]
    if isinstance(default, bool):
        low = text.strip().lower()
        if low in ("1", "true", "yes", "on"):
            return True
        if low in ("0", "false", "no", "off"):
            return False
        raise ParameterError(f"{name}: expected true or false, got {text!r}")
    if isinstance(default, int):
        try:
            return int(text)
        except ValueError:
            raise ParameterError(f"{name}: expected an integer, got {text!r}") from None
    if isinstance(default, float):
        try:
            value = float(text)
        except ValueError:
            raise ParameterError(f"{name}: expected a number, got {text!r}") from None
        if not math.isfinite(value):
            raise ParameterError(f"{name}: expected a finite number, got {text!r}")
        return value
    return text


def parse_params(specs: Mapping[str, Param], overrides: Sequence[str] = (),
                 base: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Defaults of ``specs``, then ``base`` (e.g. quick settings), then ``NAME=VALUE`` overrides."""
    params = {k: v.default for k, v in specs.items()}
    params.update(base or {})
    valid = ", ".join(specs)
    names = alias_names(specs)
    for item in overrides:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep:
            raise ParameterError(f"--set {item!r}: expected NAME=VALUE; valid names: {valid}")
        if name not in specs and name not in names:
            raise ParameterError(f"unknown parameter {name!r}; valid names: {valid}")
        if name in names:
            target, alias = names[name]
            value = coerce(target, text, specs[target].default) if alias is None else \
                alias.convert(coerce(name, text, alias.example))
            if _rank() == 0:
                print(f"note: --set {name} is an alias of {target}" +
                      ("" if alias is None else f" ({alias.doc}): {target}={_fmt_value(value)}"), file=sys.stderr)
            params[target] = value
            continue
        params[name] = coerce(name, text, specs[name].default)
    return params


def alias_names(specs: Mapping[str, Param]) -> dict[str, tuple[str, Alias | None]]:
    """``{alias: (parameter name, Alias or None)}`` of the parameters' ``aliases``."""
    return {(a.name if isinstance(a, Alias) else a): (k, a if isinstance(a, Alias) else None)
            for k, v in specs.items() for a in v.aliases}


def canonical(params: Mapping[str, Any], specs: Mapping[str, Param]) -> dict[str, Any]:
    """``params`` with alias names replaced by their parameters (values converted)."""
    names, out = alias_names(specs), {}
    for k, v in params.items():
        if k in names and names[k][0] not in params:
            target, alias = names[k]
            out[target] = v if alias is None else alias.convert(v)
        else:
            out[k] = v
    return out


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage dump), exit code 2."""

    def error(self, message):
        _fail(self.prog, f"{message} (see --help)")


def _fail(prog: str, message: str):
    if _rank() == 0:
        print(f"{prog}: error: {' '.join(str(message).split())}", file=sys.stderr)
    raise SystemExit(2)


def comm():
    """MPI.COMM_WORLD when this process runs under MPI (mpi4py loaded, or launched by mpiexec
    with more than one rank), else ``None``. Under mpiexec MPI is loaded here, through
    ``dolfinx_solver`` (which must come before mpi4py)."""
    mpi = sys.modules.get("mpi4py.MPI")
    if mpi is None and max(int(os.environ.get(k, "1") or 1) for k in _MPI_SIZE_VARS) > 1:
        import dolfinx_solver  # noqa: F401, PLC0415
        from mpi4py import MPI as mpi  # noqa: N812, PLC0415
    return mpi.COMM_WORLD if mpi is not None else None


_MPI_SIZE_VARS = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE")  # set by MPICH and Open MPI launchers


def _rank() -> int:
    c = comm()
    return c.rank if c is not None else 0


def build_parser(name: str, doc: str | None, specs: Mapping[str, Param],
                 quick: Mapping[str, Any] | None = None, checkpoints: bool = False) -> argparse.ArgumentParser:
    """The shared parser; ``--help`` lists the parameters with defaults and docs. Long
    explicit cases (``checkpoints``) also take ``--checkpoint-every N`` and ``--resume DIR``."""
    lines = ["parameters (--set NAME=VALUE):"]
    width = max(len(k) for k in specs) if specs else 0
    for k, v in specs.items():
        default = _fmt_value(v.default)
        also = "; alias " + ", ".join(a if isinstance(a, str) else f"{a.name}: {a.doc}" for a in v.aliases) \
            if v.aliases else ""
        lines.append(f"  {k:<{width}}  {v.doc} (default {default}{also})")
    if quick:
        lines.append("--quick sets " + ", ".join(f"{k}={_fmt_value(v)}" for k, v in quick.items()))
    summary = (doc or "").strip().split("\n\n")[0]
    parser = _Parser(prog=f"python -m rkfx.cases.{name}", description=summary, epilog="\n".join(lines),
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="coarse settings for a fast check")
    parser.add_argument("--method", choices=list(METHODS), default="both", help="methods to run (default both)")
    parser.add_argument("--set", dest="overrides", action="extend", nargs="+", default=[], metavar="NAME=VALUE",
                        help="override parameters (--set a=1 b=2 or --set a=1 --set b=2)")
    parser.add_argument("--out", type=Path, default=None,
                        help=f"output directory (default results/{name}/, or DIR with --resume DIR)")
    parser.add_argument("--vtk", action="store_true",
                        help="also write the fields through time for ParaView into OUT/vtk/ (off by default)")
    if checkpoints:
        parser.add_argument("--checkpoint-every", type=int, default=0, metavar="N",
                            help="write a checkpoint every N time steps (into OUT/checkpoints/)")
        parser.add_argument("--resume", type=Path, default=None, metavar="DIR",
                            help="continue a killed run from the output directory DIR: finished models are "
                                 "read back, the interrupted one continues from its last checkpoint")
        parser.add_argument("--recompute", action="store_true",
                            help="with --resume: when DIR's runs were computed with other parameters or another "
                                 "rkfx, compute them again (DIR's checkpoints move to DIR/previous/)")
    return parser


@dataclass(frozen=True)
class Checkpoints:
    """Where a case's runs keep checkpoints (``--checkpoint-every``, ``--resume``).

    Attributes:
        every: Checkpoint every so many steps (0: never).
        work_dir: ``OUT/checkpoints``; each run writes into a folder named after its key.
        resume: ``DIR/checkpoints`` of an interrupted invocation, or ``None``.
    """

    every: int = 0
    work_dir: Path | None = None
    resume: Path | None = None

    def for_run(self, key: str) -> dict:
        """``checkpoint_every``, ``checkpoint_dir`` and ``resume`` for the solver of one run: a run
        that had a checkpoint (finished or not) continues from it, the others start afresh."""
        folder = run_folder(key)
        ck_dir = None if not self.every or self.work_dir is None else Path(self.work_dir) / folder
        old = None if self.resume is None else Path(self.resume) / folder
        return {"checkpoint_every": self.every, "checkpoint_dir": ck_dir,
                "resume": old if has_checkpoint(old) else None}


def main(name: str, doc: str | None, specs: Mapping[str, Param], run: Callable[..., Results],
         plot: Callable[[Results, Path], Sequence[Path]] | None = None, argv: Sequence[str] | None = None,
         quick: Mapping[str, Any] | None = None, checkpoints: bool = False) -> int:
    """Parse ``argv``, call ``run(methods=..., **params)``, write results.json, plot, print the table.

    With ``checkpoints`` the case's ``run`` also receives ``checkpoint_every``, ``work_dir``
    (``OUT/checkpoints``) and ``resume`` (``DIR/checkpoints`` or ``None``).

    Returns:
        0 on success. Bad parameters and ``InputError`` raise ``SystemExit(2)`` after a one-line
        message on stderr.
    """
    parser = build_parser(name, doc, specs, quick, checkpoints)
    args = parser.parse_args(argv)
    if args.out is None:  # a resumed run completes the folder it resumes
        args.out = getattr(args, "resume", None) or Path("results") / name
    try:
        params = parse_params(specs, args.overrides, quick if args.quick else None)
        before_work(run, params, METHODS[args.method], comm())  # ranges and memory, before any work
        extra = {}
        if checkpoints:
            if args.checkpoint_every < 0:
                raise ParameterError(f"--checkpoint-every {args.checkpoint_every}: use a positive step count (0: none)")
            if args.resume is not None and not (args.resume / "checkpoints").is_dir():
                raise ParameterError(f"--resume {args.resume}: no checkpoints/ folder there; give the --out "
                                     "directory of the interrupted run")
            if args.recompute and args.resume is None:
                raise ParameterError("--recompute: give --resume DIR, the folder whose runs to compute again")
            extra = {"checkpoint_every": args.checkpoint_every, "work_dir": Path(args.out) / "checkpoints",
                     "resume": None if args.resume is None else args.resume / "checkpoints"}
        if args.vtk:
            if "vtk" not in inspect.signature(run).parameters:
                raise ParameterError(f"--vtk: the {name} case writes no ParaView files yet; drop --vtk")
            extra["vtk"] = Path(args.out) / VTK_FOLDER
        check_out(args.out, raw=argv if argv is not None else sys.argv[1:])
        _report_resumes(args.resume if checkpoints else None)
        stamp = fingerprint(name, specs, params, args.method) if checkpoints else None
        if checkpoints and args.resume is not None and not check_resume(args.resume, stamp, args.recompute, specs):
            extra["resume"] = None  # --recompute: every stored run differs
            if _same(args.resume, args.out) and _rank() == 0:
                set_aside_checkpoints(args.out)
        if _rank() == 0:
            set_aside_previous(args.out)
        stamped = write_fingerprint(Path(args.out) / "checkpoints", stamp) if checkpoints and _rank() == 0 else []
        world = comm()
        if world is not None and world.size > 1:
            share_cores(world)  # ranks x threads <= cores
        reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
        warm_up()  # wall times below measure the methods, not the JIT compiler
        try:
            results = run(methods=METHODS[args.method], **params, **extra)
        except (InputError, SolverError):
            _unstamp(stamped)
            raise
    except (InputError, SolverError) as err:
        _fail(parser.prog, err)
    if _rank() != 0:
        return 0
    path = write_results(results, args.out)
    figures = list(plot(results, args.out)) if plot is not None else []
    print(summary_table(results))
    print(f"\nresults: {path}")
    for f in figures:
        print(f"figure:  {f}")
    if args.vtk:
        for f in sorted((Path(args.out) / VTK_FOLDER).glob("*.pvd")):
            print(f"paraview: {f}")
    return 0


def jsonable(obj: Any) -> Any:
    """Plain JSON data: arrays to lists, numpy scalars to Python, non-finite floats to None."""
    if isinstance(obj, Mapping):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


class _Stderr(logging.StreamHandler):
    """A log handler on whatever ``sys.stderr`` is when a record comes (it may be replaced)."""

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, _):
        pass


def _report_resumes(resume: Path | None) -> None:
    """With ``--resume``, say on stderr (rank 0) which runs are read back and where each continues."""
    log = logging.getLogger("rkfx")
    if resume is None or _rank() != 0 or any(getattr(h, "rkfx_resume", False) for h in log.handlers):
        return
    handler = _Stderr()
    handler.setFormatter(logging.Formatter("%(message)s"))
    handler.rkfx_resume = True
    log.addHandler(handler)
    log.setLevel(logging.INFO)


FINGERPRINT = "fingerprint.json"  # in OUT/checkpoints: what the stored runs were computed with


def fingerprint(case: str, specs: Mapping[str, Param], params: Mapping[str, Any], method: str) -> dict:
    """What the runs stored under ``OUT/checkpoints`` are computed with: the case, the rkfx
    version, the ``--method`` and every parameter that is part of the fingerprint (``Param``)."""
    from rkfx import __version__  # noqa: PLC0415

    return jsonable({"case": case, "rkfx": __version__, "method": method,
                     "params": {k: params[k] for k, v in specs.items() if v.fingerprint}})


def differences(stored: Mapping[str, Any], now: Mapping[str, Any]) -> list[str]:
    """``name = stored (now new)`` for each fingerprint entry that differs; the method is left
    out, as each method's runs have their own folders."""
    out = [f"{k} {stored.get(k)} (now {now[k]})" for k in ("case", "rkfx") if stored.get(k) != now[k]]
    old, new = stored.get("params", {}), now["params"]
    for k in dict.fromkeys([*new, *old]):
        if k not in old or k not in new or old[k] != new[k]:
            out.append(f"{k} = {_fmt_value(old.get(k, 'unset'), None)} (now {_fmt_value(new.get(k, 'unset'), None)})")
    return out


def check_resume(resume: Path, stamp: Mapping[str, Any], recompute: bool,
                 specs: Mapping[str, Param] | None = None) -> bool:
    """Whether the runs stored in ``resume/checkpoints`` were computed with ``stamp``; if not,
    ``False`` with ``recompute``, else a one-line error naming the differing parameters."""
    folder = Path(resume) / "checkpoints"
    path = folder / FINGERPRINT
    why, fix = None, "add --recompute to compute them again"
    if path.is_file():
        try:
            stored = json.loads(path.read_text())
            if specs is not None:  # runs stored under a parameter's older name, or before it existed
                stored["params"] = _predating(canonical(stored.get("params", {}), specs), specs)
            diff = differences(stored, stamp)
        except (ValueError, AttributeError):
            diff = [f"{path} is unreadable"]
        if diff:
            why, fix = f"its runs were computed with {'; '.join(diff)}", "resume with the same --set values, or " + fix
    elif folder.is_dir() and any(d.is_dir() for d in folder.iterdir()):
        why = (f"{folder} has no {FINGERPRINT} (written by an older rkfx), so its runs cannot be checked against "
               "these parameters")
    if why is None:
        return True
    if recompute:
        logging.getLogger("rkfx").info("resume: %s: %s; computing every run again", resume, why)
        return False
    raise ParameterError(f"--resume {resume}: {why}; {fix}")


def _predating(params: Mapping[str, Any], specs: Mapping[str, Param]) -> dict[str, Any]:
    """``params`` with every fingerprinted parameter they lack at its default: a parameter added to
    a case defaults to the case's behaviour before it, so runs stored before it existed were
    computed as with its default."""
    missing = {k: v.default for k, v in specs.items() if v.fingerprint and k not in params}
    return {**params, **jsonable(missing)}


def write_fingerprint(folder: Path, stamp: Mapping[str, Any]) -> list[Path]:
    """Write ``folder/fingerprint.json`` unless it holds ``stamp`` already (up to the method);
    returns what was created here (for ``_unstamp``)."""
    folder = Path(folder)
    try:
        if not differences(json.loads((folder / FINGERPRINT).read_text()), stamp):
            return []
    except (OSError, ValueError, AttributeError):
        pass
    made = []
    missing = folder
    while not missing.exists():
        made.insert(0, missing)
        missing = missing.parent
    path = folder / FINGERPRINT
    if not path.exists():
        made.append(path)
    folder.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(stamp, indent=1) + "\n")
    tmp.replace(path)
    return made


def _unstamp(made: Sequence[Path]) -> None:
    """Remove the fingerprint and folder ``write_fingerprint`` created when the run stored nothing
    beside them (it stopped on bad input), so that bad input leaves nothing behind."""
    for path in reversed(made):
        if path.is_file():
            if any(f != path for f in path.parent.iterdir()):
                return
            path.unlink()
        elif path.is_dir() and not any(path.iterdir()):
            path.rmdir()


def _same(a: Path, b: Path) -> bool:
    return Path(a).resolve() == Path(b).resolve()


def set_aside_checkpoints(out: Path) -> Path | None:
    """Move ``out/checkpoints`` to ``out/previous/checkpoints`` (replacing an older one there):
    runs to be computed again must not be read back by a later resume, nor be lost."""
    folder = Path(out) / "checkpoints"
    if not folder.is_dir():
        return None
    target = Path(out) / "previous" / "checkpoints"
    if target.is_dir():
        shutil.rmtree(target)
    target.parent.mkdir(exist_ok=True)
    folder.replace(target)
    return target


def set_aside_previous(out: Path) -> list[Path]:
    """Move the results.json, figures and ParaView folder of an earlier run in ``out`` to
    ``out/previous/``, so that a run that fails leaves no outputs that could be taken for its
    own; returns what moved."""
    out = Path(out)
    stale = [f for f in [out / "results.json", *sorted(out.glob("*.png"))] if f.is_file()] if out.is_dir() else []
    stale += [d for d in [out / VTK_FOLDER] if d.is_dir()]
    if not stale:
        return []
    previous = out / "previous"
    if previous.is_dir():
        for f in previous.iterdir():
            if f.is_file():
                f.unlink()
        shutil.rmtree(previous / VTK_FOLDER, ignore_errors=True)
    previous.mkdir(exist_ok=True)
    for f in stale:
        f.replace(previous / f.name)
    return [previous / f.name for f in stale]


def check_out(out: Path, raw: Sequence[str] = ()) -> None:
    """Refuse an output folder that cannot take the results, before anything runs.

    ``raw``: the command line, to tell an empty ``--out ""`` (which Path reads as ".") apart.
    """
    raw = list(raw)
    given = [raw[i + 1] for i, a in enumerate(raw[:-1]) if a == "--out"] + \
        [a.split("=", 1)[1] for a in raw if a.startswith("--out=")]
    if any(not g.strip() for g in given):
        raise ParameterError('--out "": give an output folder (default results/<case>/)')
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out {out}: is a file, not a folder; choose another output folder")
    # The nearest existing folder must take new entries; nothing is created before the run.
    base = out.absolute()
    while not base.exists():
        base = base.parent
    if not base.is_dir():
        raise ParameterError(f"--out {out}: {base} is a file, not a folder; choose another output folder")
    if not os.access(base, os.W_OK | os.X_OK):
        raise ParameterError(f"--out {out}: {base} is not writable; choose a writable output folder")


def write_results(results: Results, out: Path) -> Path:
    """Write ``out/results.json`` (creating ``out``); returns its path."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    data = {"case": results.case, "params": results.params,
            "runs": [{"method": r.method, "wall_time_s": r.wall_time_s, "n_dofs": r.n_dofs,
                      "series": r.series, "errors": r.errors, "info": r.info} for r in results.runs]}
    path = out / "results.json"
    path.write_text(json.dumps(jsonable(data), indent=1, allow_nan=False) + "\n")
    return path


# Line style of each method, shared by the figures of all cases: (colour, linestyle).
METHOD_STYLES = {"ni": ("tab:red", "-"), "scni": ("tab:orange", "-"), "ni+fpp": ("tab:purple", "--"),
                 "scni+fpp": ("tab:blue", "-"), "taylor-hood": ("tab:green", ":"), "q1q1": ("tab:brown", ":"),
                 "q1q1-fpp": ("tab:cyan", "-.")}


def method_style(method: str) -> tuple[str, str]:
    """Colour and linestyle of a run label such as ``rkpm-scni+fpp`` or ``fem-taylor-hood ny=41``."""
    key = method.split(" ")[0].split("-", 1)[-1]
    return METHOD_STYLES.get(key, ("0.3", "-"))


def pyplot():
    """``matplotlib.pyplot`` on the non-interactive Agg backend (figures are files, no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, path: Path, dpi: int = 130) -> Path:
    """Write a figure and close it."""
    fig.savefig(path, dpi=dpi)
    fig.clf()
    import matplotlib.pyplot as plt

    plt.close(fig)
    return path
