"""Command line of the benchmark report (see ``rkfx.report``)."""
import argparse
import datetime
import importlib
import importlib.metadata
import os
import platform
import pkgutil
import subprocess
import sys
import time
from pathlib import Path

from rkfx.report import html
from rkfx.report.claims import FAIL, Claim, Outcome, evaluate_all
from rkfx.report.run import run_case

ORDER = ("terzaghi", "mandel", "strip_load", "plate_with_hole", "sneddon", "cracked_bar", "kalthoff",
         "crack_branching", "injection")


def registry() -> list[str]:
    """The runnable cases (the public modules of ``rkfx.cases``), in the report's order."""
    import rkfx.cases  # noqa: PLC0415

    names = [m.name for m in pkgutil.iter_modules(rkfx.cases.__path__) if not m.name.startswith("_")]
    return [n for n in ORDER if n in names] + sorted(n for n in names if n not in ORDER)


def case_claims(name: str) -> tuple[list[Claim], str]:
    """The ``CLAIMS`` of ``rkfx.cases.<name>``, or ``[]`` and why there are none."""
    try:
        module = importlib.import_module(f"rkfx.cases.{name}")
    except Exception as err:  # noqa: BLE001  (a broken case is reported, not raised)
        return [], f"rkfx.cases.{name} does not import: {type(err).__name__}: {err}"
    claims = list(getattr(module, "CLAIMS", None) or [])
    return claims, "" if claims else f"rkfx.cases.{name} has no CLAIMS"


def _version(*dists: str) -> str:
    for d in dists:
        try:
            return importlib.metadata.version(d)
        except importlib.metadata.PackageNotFoundError:
            continue
    return "not installed"


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def _commit() -> str:
    try:
        root = Path(__file__).resolve().parents[2]
        out = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True, timeout=10)
        return out.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def machine(quick: bool, total: float, started: datetime.datetime) -> dict[str, str]:
    """The page header: machine, software versions, date, sizes and total wall time."""
    from rkfx import __version__  # noqa: PLC0415

    return {"date": started.isoformat(timespec="seconds"), "rkfx": f"{__version__} (commit {_commit()})",
            "sizes": "--quick" if quick else "default (full)", "total wall time": f"{total:.1f} s",
            "platform": platform.platform(), "CPU": f"{_cpu_model()}, {os.cpu_count()} logical cores",
            "python": sys.version.split()[0], "numpy": _version("numpy"), "scipy": _version("scipy"),
            "dolfinx": _version("fenics-dolfinx", "dolfinx-solver-real", "dolfinx-solver"),
            "gmsh": _version("gmsh")}


def parse(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="python -m rkfx.report", description=__doc__)
    p.add_argument("--quick", action="store_true", help="run every case with its --quick settings")
    p.add_argument("--out", type=Path, default=Path("results/report"), help="output folder (default results/report)")
    p.add_argument("--cases", default="", help="comma-separated cases to run (default: all)")
    p.add_argument("--timeout", type=float, default=None, help="seconds per case before it counts as failed")
    args = p.parse_args(argv)
    known = registry()
    args.names = [c.strip() for c in args.cases.split(",") if c.strip()] or known
    unknown = [c for c in args.names if c not in known]
    if unknown:
        p.error(f"unknown case(s) {', '.join(unknown)}; choose from {', '.join(known)}")
    return args


def main(argv=None) -> int:
    """Run the cases, check their claims, write ``OUT/index.html``; 0 if every claim holds."""
    args = parse(argv)
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    started = datetime.datetime.now().astimezone()
    t0 = time.perf_counter()
    cases, outcomes, ok = [], {}, True
    for name in args.names:
        case = run_case(name, out, args.quick, args.timeout)
        claims, why = case_claims(name)
        found = evaluate_all(claims, case.results, args.quick)
        if why:  # a case without claims cannot pass
            found.append(Outcome(Claim(why, key="-", op="==", bound=0.0), FAIL, note=why))
        cases.append(case)
        outcomes[name] = found
        status = html.status_of(found, case.failed)
        ok &= status != FAIL
        passed, checked = html.counts(found)
        failed = [str(i) for i, o in enumerate(found, 1) if o.status == FAIL]
        print(f"{name:<16} {status:<6} claims {passed}/{checked}  {case.wall_time_s:7.1f} s"
              + (f"  failed claims #{', #'.join(failed)}" if failed else "")
              + (f"  ({case.error}; see {case.folder / 'log.txt'})" if case.failed else ""), flush=True)
    total = time.perf_counter() - t0
    page = out / "index.html"
    page.write_text(html.page(cases, outcomes, machine(args.quick, total, started), out))
    print(f"total {total:.1f} s; {'all claims hold' if ok else 'SOME CLAIMS FAILED'}; report: {page}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
