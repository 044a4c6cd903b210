"""Run one benchmark case in its own process and read back what it wrote.

``run_case(name, out, quick)`` calls ``sys.executable -m rkfx.cases.<name> [--quick] --out
OUT/<name>`` with the output (stdout and stderr, interleaved) kept in ``OUT/<name>/log.txt``.
A case that fails (non-zero exit, timeout, no or unreadable results.json) is reported as such
with the tail of its log; it never stops the report.
"""
import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

LOG = "log.txt"
TAIL_LINES = 40


@dataclass
class CaseRun:
    """What one case's process left: its results (``None`` if it failed), figures and log."""

    name: str
    folder: Path
    wall_time_s: float
    returncode: int | None
    results: dict | None = None
    figures: list[Path] = field(default_factory=list)
    error: str = ""
    log_tail: str = ""

    @property
    def failed(self) -> bool:
        """True when the case crashed or wrote no readable results."""
        return self.results is None


def tail(path: Path, lines: int = TAIL_LINES) -> str:
    """The last ``lines`` lines of a text file ('' if it cannot be read)."""
    try:
        text = Path(path).read_text(errors="replace")
    except OSError:
        return ""
    return "\n".join(text.splitlines()[-lines:])


def read_results(folder: Path) -> tuple[dict | None, str]:
    """``folder/results.json`` as data, or ``None`` and the reason."""
    path = Path(folder) / "results.json"
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        return None, f"{path.name} was not written"
    except (OSError, ValueError) as err:
        return None, f"{path.name} is unreadable ({type(err).__name__}: {err})"
    if not isinstance(data, dict) or not isinstance(data.get("runs"), list):
        return None, f"{path.name} has no list of runs"
    return data, ""


def figures(folder: Path) -> list[Path]:
    """The PNG figures a case wrote into its folder (not those set aside in previous/)."""
    return sorted(Path(folder).glob("*.png"))


def set_aside(folder: Path) -> None:
    """Move an earlier results.json and figures in ``folder`` to ``folder/previous/``, so that a
    case that dies before writing leaves nothing that could be taken for its own."""
    stale = [f for f in [Path(folder) / "results.json", *figures(folder)] if f.is_file()]
    if stale:
        previous = Path(folder) / "previous"
        previous.mkdir(exist_ok=True)
        for f in stale:
            f.replace(previous / f.name)


def run_case(name: str, out: Path, quick: bool = True, timeout: float | None = None,
             extra: list[str] | None = None) -> CaseRun:
    """Run ``rkfx.cases.<name>`` into ``out/<name>``; see the module docstring."""
    folder = Path(out) / name
    folder.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-m", f"rkfx.cases.{name}", *(["--quick"] if quick else []), "--out", str(folder),
           *(extra or [])]
    set_aside(folder)
    # The case imports the same rkfx as this process, whatever the working directory.
    root = str(Path(__file__).resolve().parents[2])
    env = dict(os.environ, PYTHONUNBUFFERED="1",
               PYTHONPATH=os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH", "")) if p))
    start = time.perf_counter()
    code, error = None, ""
    with open(folder / LOG, "w") as log:
        log.write("$ " + " ".join(cmd) + "\n")
        log.flush()
        try:
            code = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env,
                                  timeout=timeout).returncode
        except subprocess.TimeoutExpired:
            error = f"timed out after {timeout:g} s"
        except OSError as err:
            error = f"could not start: {err}"
    wall = time.perf_counter() - start
    results = None
    if not error and code != 0:
        error = f"exit code {code}"
    if not error:
        results, error = read_results(folder)
    return CaseRun(name, folder, wall, code, results, figures(folder) if results is not None else [], error,
                   tail(folder / LOG) if error else "")
