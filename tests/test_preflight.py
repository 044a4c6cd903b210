"""Cases refuse, before any work, runs that cannot fit in memory and parameters outside their documented ranges."""
import importlib
import pkgutil

import pytest

import rkfx.cases
from rkfx.cases import _preflight
from rkfx.errors import InputError
from verification.bad_inputs import Row, refused, run_row

CASES = [m.name for m in pkgutil.iter_modules(rkfx.cases.__path__) if not m.name.startswith("_")]
MACHINE = 24e9  # the smallest machine the documented runs must fit on [bytes]


def _refusal(case, *argv):
    """The outcome of ``python -m rkfx.cases.<case> argv`` (in an empty folder, work replaced by a tripwire)."""
    out = run_row(Row("", case, tuple(argv)))
    assert refused(out), (out.exit, out.lines, out.written)
    return out.message


@pytest.mark.parametrize("case, item, culprit", [("mandel", "nx=1000000000", "nx=1000000000"),
                                                 ("kalthoff", "h=6.7e-4,1e-7", "h=0.00067,1e-07"),
                                                 ("crack_branching", "h=1e-6", "h=1e-06"),
                                                 ("terzaghi", "refine_ny=21,100000000", "refine_ny")])
def test_too_big_for_memory_is_refused_in_one_line(case, item, culprit):
    message = _refusal(case, "--set", item)
    assert f"{culprit}" in message and "needs about" in message and "GB available; " in message


@pytest.mark.parametrize("case", CASES)
def test_documented_and_quick_runs_fit_a_24_gb_machine(case):
    module = importlib.import_module(f"rkfx.cases.{case}")
    defaults = {k: v.default for k, v in module.PARAMS.items()}
    for params in (defaults, {**defaults, **getattr(module, "QUICK", {})}):
        for methods in (("rkpm",), ("fem",), ("rkpm", "fem")):
            need = module.memory_need(methods, **params)
            assert need.bytes < MACHINE / 2, (params, methods, need)
            _preflight.refuse_if_too_big(need, available=MACHINE)


def test_refusal_names_estimate_machine_and_fix():
    need = _preflight.Need(3e12, "nx=10", "lower nx")
    with pytest.raises(InputError, match=r"^nx=10 needs about 3e\+03 GB, this machine has 16.0 GB available; "
                                         r"lower nx$"):
        _preflight.refuse_if_too_big(need, available=16e9)
    with pytest.raises(InputError, match=r"needs about 6e\+03 GB \(2 ranks"):
        _preflight.refuse_if_too_big(need, ranks=2, available=16e9)
    _preflight.refuse_if_too_big(_preflight.Need(1e9, "nx=10", "lower nx"), available=16e9)


def test_available_memory_is_read():
    avail = _preflight.available_bytes()
    assert avail is None or avail > 1e8


@pytest.mark.parametrize("case, item, name", [
    ("mandel", "support_factor=0.9", "support_factor"), ("mandel", "dt_D=1e-12", "dt_D"),
    ("mandel", "nu=0.5", "nu"), ("mandel", "k=0", "k"),
    ("terzaghi", "t_out=soon", "t_out"), ("terzaghi", "support_factor=1", "support_factor"),
    ("terzaghi", "alpha=0", "alpha"),
    ("strip_load", "depth_history=100", "depth_history"), ("strip_load", "k_low=0", "k_low"),
    ("strip_load", "nx=500", "nx"), ("strip_load", "ny=1000", "ny"), ("strip_load", "support_factor=0", "support_factor"),
    ("strip_load", "S=-1", "S"),
    ("cracked_bar", "GF=0", "GF"), ("cracked_bar", "ft=3e6", "ft"),
    ("plate_with_hole", "support_factor=0.5", "support_factor"), ("plate_with_hole", "nu=0.5", "nu"),
    ("plate_with_hole", "E=0", "E"),
    ("kalthoff", "eps_p=-1", "eps_p"), ("kalthoff", "E=-1", "E"), ("kalthoff", "GF=0", "GF"),
    ("crack_branching", "radius=0.5", "radius"), ("kalthoff", "tol=1.5", "tol"), ("crack_branching", "eps_p=-0.5", "eps_p"),
    ("crack_branching", "plane=axisymmetric", "plane"), ("crack_branching", "nu=0.5", "nu"),
])
def test_documented_range_is_checked_before_any_work(case, item, name):
    assert name in _refusal(case, "--set", item)
