"""rkfx.report: claim evaluation, a failing claim shown as FAILED with exit code 1, a crashing
case reported with its log, an end-to-end run of the fastest case, and CLAIMS in every case."""
import importlib
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from rkfx.report import __main__ as report
from rkfx.report import run as runner
from rkfx.report.claims import FAIL, PASS, SKIP, Claim, evaluate, evaluate_all

FAKE = {"case": "fake", "params": {},
        "runs": [{"method": "rkpm-a", "wall_time_s": 1.0, "n_dofs": 10, "series": {},
                  "errors": {"err": 0.01, "nan": None}, "info": {"study": "s", "n": 9, "q": 3.0}},
                 {"method": "rkpm-b", "wall_time_s": 2.0, "n_dofs": 40, "series": {},
                  "errors": {"err": 0.004}, "info": {"study": "s", "n": 19}},
                 {"method": "fem-p1", "wall_time_s": 0.5, "n_dofs": 12, "series": {},
                  "errors": {"err": 0.02}, "info": {"study": "fem"}}]}


def test_comparisons_and_selectors():
    ok = [Claim("a", key="err", op="<=", bound=0.01, run="rkpm-a"),
          Claim("b", key="err", op="<", bound=0.011, info={"study": "s"}),  # both rkpm runs
          Claim("c", key="err", op="within", bound=(0.001, 0.03)),  # every run
          Claim("d", key="err", op=">", bound=2.0, run="rkpm-a", over=("rkpm-b", {})),  # 0.01 / 0.004
          Claim("e", key="q", op="==", bound=3.0, run="rkpm-a"),  # from info
          Claim("f", key="err", op=">=", bound=0.004, info={"n": 19})]
    for c in ok:
        assert evaluate(c, FAKE, quick=True).status == PASS, c.text
    two = evaluate(ok[1], FAKE, quick=True)
    assert two.values == (0.01, 0.004) and two.methods == ("rkpm-a", "rkpm-b")
    assert evaluate(ok[3], FAKE, quick=True).values[0] == pytest.approx(2.5)


def test_failures_are_never_hidden():
    bad = {"too large": Claim("x", key="err", op="<", bound=0.005, info={"study": "s"}),  # rkpm-a fails
           "no run": Claim("x", key="err", op="<", bound=1, run="rkpm-z"),
           "no key": Claim("x", key="missing", op="<", bound=1, run="rkpm-a"),
           "not finite": Claim("x", key="nan", op="<", bound=1, run="rkpm-a"),
           "ambiguous over": Claim("x", key="err", op="<", bound=1, run="rkpm-a", over=(None, {"study": "s"}))}
    for why, c in bad.items():
        o = evaluate(c, FAKE, quick=True)
        assert o.status == FAIL and o.note, why
    assert "rkpm-a" in evaluate(bad["too large"], FAKE, quick=True).note
    assert evaluate(bad["no run"], None, quick=True).status == FAIL  # the case gave no results


def test_size_flags_skip():
    q = Claim("q", key="err", op="<", bound=1, run="rkpm-a", quick_only=True)
    f = Claim("f", key="err", op="<", bound=1, run="rkpm-a", full_only=True)
    assert [o.status for o in evaluate_all([q, f], FAKE, quick=True)] == [PASS, SKIP]
    assert [o.status for o in evaluate_all([q, f], FAKE, quick=False)] == [SKIP, PASS]


def test_bad_claims_are_refused():
    for kw in ({"op": "~"}, {"op": "within", "bound": 1.0}, {"op": "<", "bound": (0, 1)},
               {"op": "<", "quick_only": True, "full_only": True}):
        with pytest.raises(ValueError):
            Claim("x", key="err", **({"bound": 1.0} | kw))


def _fake_case(out: Path, name: str) -> runner.CaseRun:
    folder = out / name
    folder.mkdir(parents=True)
    (folder / "results.json").write_text(json.dumps(FAKE))
    (folder / "fig.png").write_bytes(b"\x89PNG\r\n\x1a\n")
    return runner.CaseRun(name, folder, 0.1, 0, FAKE, [folder / "fig.png"])


def test_failing_claim_renders_failed_and_exits_1(tmp_path, monkeypatch, capsys):
    claims = [Claim("Fig 0.1: holds", key="err", op="<=", bound=0.01, run="rkpm-a"),
              Claim("Fig 0.2: deliberately false", key="err", op="<", bound=1e-6, run="rkpm-b")]
    monkeypatch.setattr(report, "registry", lambda: ["fake"])
    monkeypatch.setattr(report, "run_case", lambda name, out, quick, timeout: _fake_case(out, name))
    monkeypatch.setattr(report, "case_claims", lambda name: (claims, ""))
    assert report.main(["--quick", "--out", str(tmp_path)]) == 1
    line = capsys.readouterr().out.splitlines()[0]
    assert line.split()[:4] == ["fake", "FAILED", "claims", "1/2"] and "#2" in line
    page = (tmp_path / "index.html").read_text()
    row = next(r for r in page.split("<tr>") if "deliberately false" in r)
    assert 'class="FAILED"' in row and "rkpm-b" in row
    assert 'class="PASS"' in next(r for r in page.split("<tr>") if "Fig 0.1: holds" in r)
    assert '<img src="fake/fig.png"' in page
    # RKPM and FEM runs, and error against wall time for the key they share.
    assert "fem-p1" in page and "Time to accuracy" in page
    # All claims true: exit code 0.
    monkeypatch.setattr(report, "case_claims", lambda name: (claims[:1], ""))
    assert report.main(["--quick", "--out", str(tmp_path / "again")]) == 0


def test_crashing_case_is_failed_with_its_log_and_the_report_completes(tmp_path, monkeypatch, capsys):
    real = runner.run_case
    monkeypatch.setattr(report, "registry", lambda: ["does_not_exist", "fake"])
    monkeypatch.setattr(report, "run_case", lambda name, out, quick, timeout: real(name, out, quick, timeout)
                        if name == "does_not_exist" else _fake_case(out, name))
    monkeypatch.setattr(report, "case_claims", lambda name: ([Claim("c", key="err", op="<", bound=1)], ""))
    assert report.main(["--out", str(tmp_path)]) == 1
    out = capsys.readouterr().out
    assert re.search(r"does_not_exist\s+FAILED", out) and re.search(r"fake\s+PASS", out)
    log = (tmp_path / "does_not_exist" / "log.txt").read_text()
    assert "No module named" in log
    page = (tmp_path / "index.html").read_text()
    assert "No module named" in page and "exit code 1" in page


def test_a_case_without_claims_fails(tmp_path, monkeypatch):
    monkeypatch.setattr(report, "registry", lambda: ["fake"])
    monkeypatch.setattr(report, "run_case", lambda name, out, quick, timeout: _fake_case(out, name))
    monkeypatch.setattr(report, "case_claims", lambda name: ([], "rkfx.cases.fake has no CLAIMS"))
    assert report.main(["--out", str(tmp_path)]) == 1
    assert "has no CLAIMS" in (tmp_path / "index.html").read_text()


def test_unknown_case_is_refused():
    with pytest.raises(SystemExit) as e:
        report.parse(["--cases", "nope"])
    assert e.value.code == 2


@pytest.mark.parametrize("name", report.registry())
def test_every_case_has_claims(name):
    claims = importlib.import_module(f"rkfx.cases.{name}").CLAIMS
    assert claims and all(isinstance(c, Claim) for c in claims)
    assert any(re.search(r"(Fig|Sec) \d|\(\d\.\d+\)", c.text) for c in claims), "cite the seed's figure or equation"
    assert any(not c.full_only for c in claims), "at least one claim checked at the --quick sizes"


def test_end_to_end_fastest_case(tmp_path):
    pytest.importorskip("gmsh")
    pytest.importorskip("dolfinx_solver")
    name = "plate_with_hole"
    out = tmp_path / "rep"
    proc = subprocess.run([sys.executable, "-m", "rkfx.report", "--quick", "--cases", name, "--out", str(out)],
                          capture_output=True, text=True, timeout=300, cwd=Path(__file__).resolve().parents[1])
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert proc.stdout.startswith(name)
    page = (out / "index.html").read_text()
    claims = importlib.import_module(f"rkfx.cases.{name}").CLAIMS
    import html  # noqa: PLC0415

    rows = [r for r in page.split("<tr>") if any(html.escape(c.text) in r for c in claims)]
    assert len(rows) == len(claims)
    figures = sorted((out / name).glob("*.png"))
    assert figures and all(f'<img src="{name}/{f.name}"' in page for f in figures)
    assert (out / name / "log.txt").read_text().startswith("$ ")
    for word in ("python", "numpy", "dolfinx", "rkfx", "total wall time"):
        assert word in page
