"""The teaching labs of docs/labs/: each runs as a script and is a well-formed jupytext percent file."""
import ast
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
LABS = sorted((REPO / "docs" / "labs").glob("*.py"))
MARKER = re.compile(r"^# %%(?:\s+\[(\w+)\])?(?:\s.*)?$")


def cells(path: Path) -> list[tuple[str, list[str]]]:
    """The cells of a percent-format file as (kind, lines), after its optional YAML header."""
    lines = path.read_text().splitlines()
    if lines and lines[0] == "# ---":
        end = lines.index("# ---", 1)
        lines = lines[end + 1:]
    out: list[tuple[str, list[str]]] = []
    for line in lines:
        m = MARKER.match(line)
        if m:
            out.append((m.group(1) or "code", []))
        elif out:
            out[-1][1].append(line)
        else:
            assert not line.strip(), f"{path.name}: text before the first '# %%' cell: {line!r}"
    return out


def test_there_are_five_labs():
    assert [p.name[:3] for p in LABS] == ["01_", "02_", "03_", "04_", "05_"]


@pytest.mark.parametrize("lab", LABS, ids=lambda p: p.stem)
def test_lab_is_percent_format_and_ends_with_exercises(lab):
    compile(lab.read_text(), str(lab), "exec")
    ast.parse(lab.read_text())
    parts = cells(lab)
    kinds = [k for k, _ in parts]
    assert set(kinds) <= {"code", "markdown"}, kinds
    assert kinds.count("code") >= 3 and kinds.count("markdown") >= 3
    assert kinds[0] == "markdown" and parts[0][1][0].startswith("# # Lab "), "a lab opens with its title"
    for kind, body in parts:
        if kind == "markdown":  # markdown cells are comments only
            assert all(not line.strip() or line.startswith("#") for line in body), body
    kind, body = parts[-1]
    assert kind == "markdown"
    text = [line[2:] if line.startswith("# ") else line.lstrip("#") for line in body]
    text = [line for line in text if line.strip()]
    assert text[0] == "## Exercises", "the last cell is the Exercises section"
    items = [line for line in text if re.match(r"^\d+\. ", line)]
    assert 3 <= len(items) <= 4, items


@pytest.mark.parametrize("lab", LABS, ids=lambda p: p.stem)
def test_lab_runs_as_a_script(lab, tmp_path):
    env = dict(os.environ, RKFX_LAB_OUT=str(tmp_path), MPLBACKEND="Agg",
               PYTHONPATH=os.pathsep.join([str(REPO), *filter(None, [os.environ.get("PYTHONPATH")])]))
    # The labs' models are small: one thread avoids fighting over the cores of a busy machine.
    env.setdefault("NUMBA_NUM_THREADS", "1")
    proc = subprocess.run([sys.executable, str(lab)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    assert list(tmp_path.glob("*.png")), "a lab saves its figures to RKFX_LAB_OUT"
