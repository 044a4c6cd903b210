"""Claims of the seed that a benchmark case checks, and their evaluation against results.json.

A case module lists its claims as ``CLAIMS = [Claim(...), ...]``. A claim names the run(s) it
is about (``run``: the method label, exact, or ``None`` for any; ``info``: values the run's
``info`` must have), the key measured there (in the run's ``errors``, else in its ``info``),
a comparison and its bound:

    Claim("Fig 3.5: SCNI+FPP first-step pressure within 5 % of the series away from the top",
          run="rkpm-scni+fpp", info={"study": "variants"}, key="first_step_max_dev_away",
          op="<=", bound=0.05)

``op`` is one of ``<=``, ``<``, ``>=``, ``>``, ``==`` or ``within`` (``bound`` a pair
``(low, high)``, both included). With ``over`` (a selector ``(run, info)`` of one other run) the
measured value is the ratio of the run's value to that run's value of ``over_key`` (default
``key``), for claims such as "NI's error is more than 3 times SCNI+FPP's". When the selector
matches several runs the claim must hold for every one of them. A claim with ``quick_only``
applies to the ``--quick`` sizes only, one with ``full_only`` to the default sizes only;
otherwise it is skipped and shown as such. A claim whose runs or key are missing, or whose
value is not a finite number, fails.
"""
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

OPS = ("<=", "<", ">=", ">", "==", "within")
PASS, FAIL, SKIP = "PASS", "FAILED", "SKIPPED"


@dataclass(frozen=True)
class Claim:
    """One checkable statement of the seed (see the module docstring)."""

    text: str
    key: str
    op: str
    bound: float | tuple[float, float]
    run: str | None = None
    info: Mapping[str, Any] = field(default_factory=dict)
    over: tuple[str | None, Mapping[str, Any]] | None = None
    over_key: str | None = None
    quick_only: bool = False
    full_only: bool = False

    def __post_init__(self):
        if self.op not in OPS:
            raise ValueError(f"claim {self.text!r}: op {self.op!r} is not one of {', '.join(OPS)}")
        if (self.op == "within") != isinstance(self.bound, (tuple, list)):
            raise ValueError(f"claim {self.text!r}: 'within' takes a pair (low, high), the others one number")
        if self.quick_only and self.full_only:
            raise ValueError(f"claim {self.text!r}: quick_only and full_only exclude each other")

    def bound_text(self) -> str:
        """The comparison as text, e.g. ``<= 0.05`` or ``in [60, 75]``."""
        if self.op == "within":
            return f"in [{_num(self.bound[0])}, {_num(self.bound[1])}]"
        return f"{self.op} {_num(self.bound)}"

    def selector_text(self) -> str:
        """Which runs the claim reads, e.g. ``rkpm-scni+fpp (study=variants)``."""
        text = _selector(self.run, self.info)
        if self.over is not None:
            text += f" / {_selector(*self.over)} [{self.over_key or self.key}]"
        return text


@dataclass(frozen=True)
class Outcome:
    """A claim's verdict: ``status`` PASS, FAILED or SKIPPED, the measured values and why."""

    claim: Claim
    status: str
    values: tuple[float | None, ...] = ()
    methods: tuple[str, ...] = ()
    note: str = ""

    @property
    def measured(self) -> str:
        """The measured value(s) as text."""
        if not self.values:
            return "-"
        return ", ".join("-" if v is None else _num(v) for v in self.values)


def _selector(run, info) -> str:
    text = run if run is not None else "any run"
    if info:
        text += " (" + ", ".join(f"{k}={v}" for k, v in info.items()) + ")"
    return text


def _num(v) -> str:
    if isinstance(v, bool) or v is None:
        return str(v)
    if isinstance(v, int):
        return str(v)
    v = float(v)
    if v != 0 and (abs(v) < 1e-3 or abs(v) >= 1e5):
        return f"{v:.3g}"
    return f"{v:.4g}"


def select(runs: Iterable[Mapping], run: str | None, info: Mapping[str, Any]) -> list[Mapping]:
    """The runs whose method is ``run`` (any if ``None``) and whose info has the ``info`` values."""
    out = []
    for r in runs:
        if run is not None and r.get("method") != run:
            continue
        have = r.get("info") or {}
        if all(k in have and _same(have[k], v) for k, v in info.items()):
            out.append(r)
    return out


def _same(a, b) -> bool:
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        return math.isclose(a, b, rel_tol=1e-9, abs_tol=0.0)
    return a == b


def holds(op: str, value: float, bound) -> bool:
    """``value op bound``."""
    if op == "within":
        return bound[0] <= value <= bound[1]
    return {"<=": value <= bound, "<": value < bound, ">=": value >= bound, ">": value > bound,
            "==": value == bound}[op]


def _finite(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


_MISSING = object()


def value_of(run: Mapping, key: str):
    """``run["errors"][key]``, else ``run["info"][key]`` (a missing key: a sentinel, never a number)."""
    for part in ("errors", "info"):
        values = run.get(part) or {}
        if key in values:
            return values[key]
    return _MISSING


def evaluate(claim: Claim, results: Mapping | None, quick: bool) -> Outcome:
    """The verdict of ``claim`` on one case's results (``None``: the case produced none)."""
    if (claim.quick_only and not quick) or (claim.full_only and quick):
        return Outcome(claim, SKIP, note="applies to the " + ("--quick" if claim.quick_only else "full") + " sizes")
    if results is None:
        return Outcome(claim, FAIL, note="no results")
    runs = results.get("runs") or []
    chosen = select(runs, claim.run, claim.info)
    if not chosen:
        return Outcome(claim, FAIL, note=f"no run matches {_selector(claim.run, claim.info)}")
    divisor = 1.0
    if claim.over is not None:
        others = select(runs, *claim.over)
        if len(others) != 1:
            return Outcome(claim, FAIL, note=f"{len(others)} runs match {_selector(*claim.over)} (need one)")
        divisor = value_of(others[0], claim.over_key or claim.key)
        if not _finite(divisor) or divisor == 0:
            what = "missing" if divisor is _MISSING else f"{divisor!r}"
            return Outcome(claim, FAIL, note=f"{claim.over_key or claim.key} of {_selector(*claim.over)} is {what}")
    values, bad = [], []
    for r in chosen:
        v = value_of(r, claim.key)
        if not _finite(v):
            values.append(None)
            bad.append(f"{r.get('method')}: {claim.key} " + ("missing" if v is _MISSING else f"is {v!r}"))
            continue
        v = v / divisor
        values.append(v)
        if not holds(claim.op, v, claim.bound):
            bad.append(f"{r.get('method')}: {_num(v)} not {claim.bound_text()}")
    methods = tuple(str(r.get("method")) for r in chosen)
    return Outcome(claim, FAIL if bad else PASS, tuple(values), methods, "; ".join(bad))


def evaluate_all(claims: Sequence[Claim], results: Mapping | None, quick: bool) -> list[Outcome]:
    """``evaluate`` for every claim, in order."""
    return [evaluate(c, results, quick) for c in claims]
