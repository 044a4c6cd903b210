"""Every runnable case has a test file and answers --help."""
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import rkfx.cases

CASES = [m.name for m in pkgutil.iter_modules(rkfx.cases.__path__) if not m.name.startswith("_")]


def test_there_are_cases():
    assert {"plate_with_hole", "mandel", "terzaghi"} <= set(CASES)


@pytest.mark.parametrize("name", CASES)
def test_case_has_a_test(name):
    assert (Path(__file__).parent / f"test_case_{name}.py").exists(), f"rkfx.cases.{name} has no test"


@pytest.mark.parametrize("name", CASES)
def test_case_cli_help(name):
    out = subprocess.run([sys.executable, "-m", f"rkfx.cases.{name}", "--help"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and "--quick" in out.stdout and "--set" in out.stdout
