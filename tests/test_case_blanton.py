"""Blanton's tests (seed 5.3.3): the case's set-up, its classification of a stage, its input checks."""
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from rkfx.cases import blanton as case
from rkfx.errors import InputError


def _params(**over):
    return {k: v.default for k, v in case.PARAMS.items()} | case.QUICK | over


@pytest.mark.parametrize("bad, match", [
    (dict(tests=["CT-5"]), r"CT-5"),
    (dict(notch=0.045), r"notch = 0.045: the notch must end at least 2 h short"),
    (dict(offset=0.2), r"offset = 0.2: the pre-fracture must cross"),
    (dict(dt=0.02), r"dt = 0.02 must not exceed t_ramp"),
    (dict(h=[0.03]), r"h = 0.03 must be positive and at most half the notch"),
    (dict(jacobian="exact"), r"jacobian"),
    (dict(margin=0.2), r"margin = 0.2 must lie in"),
    (dict(mu=0.0), r"mu = 0.0"),
])
def test_bad_input_is_refused_in_one_line(bad, match):
    with pytest.raises(InputError, match=match) as err:
        case.check(**_params(**bad))
    assert "\n" not in str(err.value)


def test_the_tests_of_table_5_1():
    assert [(t.name, t.theta, t.sigma_H / 1e6, t.sigma_h / 1e6, t.pressure / 1e6, t.observed) for t in case.TESTS.values()] \
        == [("CT-4", 60, 12, 10, 17, "arrest"), ("CT-7", 30, 19, 10, 17, "arrest"), ("CT-8", 60, 20, 5, 15, "cross"),
            ("CT-9", 30, 20, 5, 15, "arrest")]


def test_step_times_apply_the_confinement_drained_and_then_step_the_growth():
    t = case._step_times(100.0, 200.0, 0.01, 2e-4, 0.04)
    assert t[0] == 0.0 and t[1] == 10.0 and 100.0 in t and 200.0 in t  # first step >> drainage time (~4 s)
    assert np.diff(t[t <= 200.0]).max() <= 20.0 + 1e-12
    grow = t[t > 200.0]
    np.testing.assert_allclose(np.diff(np.r_[200.0, grow]), 2e-4, rtol=1e-6)
    assert np.isclose(grow[-1], 200.05)


def test_load_histories():
    pb = case._History([1.0, 2.0], [0.0, 10.0])
    assert pb(-1.0) == 0.0 and pb(1.5) == 5.0 and pb(7.0) == 10.0


def _block(x, h=0.01):
    """A pre-fracture along the y axis, the borehole on its left (x < 0), the HF's line y = 0."""
    x = np.asarray(x, float)
    return SimpleNamespace(x=x, distance=x[:, 0], borehole_side=-1.0, h=h, intersection=np.zeros(2))


def test_classification_of_a_test():
    h = 0.01
    hf = [(-0.05, 0.0), (-0.035, 0.0), (-0.02, 0.0), (-0.005, 0.0)]     # the HF up to the pre-fracture
    beyond = [(0.005, 0.0), (0.02, 0.0), (0.035, 0.0), (0.05, 0.0)]    # its continuation on the far side
    elsewhere = [(0.03, 0.10), (0.045, 0.10), (0.06, 0.10)]            # far-side damage away from the HF
    b = _block(hf + beyond + elsewhere, h)
    mask = lambda n_hf, n_beyond, n_else: np.array([i < n_hf for i in range(4)] + [i < n_beyond for i in range(4)]  # noqa: E731
                                                    + [i < n_else for i in range(3)])
    assert case.classify(b, mask(4, 0, 0), 0.0) == ("arrest", 0.0)
    assert case.classify(b, mask(4, 0, 0), 0.05)[0] == "open"           # > 4 h of the pre-fracture opened
    assert case.classify(b, mask(4, 0, 0), 0.03)[0] == "arrest"
    assert case.classify(b, mask(4, 2, 0), 0.0) == ("arrest", 0.02)     # 2 h beyond: not yet a crossing
    mode, depth = case.classify(b, mask(4, 4, 0), 0.05)
    assert mode == "cross" and np.isclose(depth, 0.05)
    # cracks beyond the pre-fracture that do not start at the intersection are no crossing
    assert case.classify(b, mask(4, 0, 3), 0.05) == ("open", 0.0)
    assert case.classify(b, mask(4, 1, 3), 0.0) == ("arrest", 0.005)
    assert case.classify(b, mask(1, 0, 0), 0.0)[0] == "not reached"
    assert case.classify(b, mask(0, 0, 3), 0.0)[0] == "not reached"


def test_the_fem_block_is_the_particles_cut_along_the_pre_fracture():
    """The crack-band FEM's block: the RKPM case's cut particles as vertices, the pre-fracture's
    faces paired node to node, the notch a band of elements, the confinement as tractions; the
    drained confinement of CT-8 (no slip) leaves the far field at (-sigma_H, -sigma_h)."""
    from mpi4py import MPI

    from rkfx.solvers.integrate import integrate
    from rkfx.solvers.newmark import damped

    prm = _params()
    rock = case._rock(**{k: prm[k] for k in case.ROCK_FIELDS})
    test = case.TESTS["CT-8"]
    geo = case.Block(0.005, side=prm["side"], offset=prm["offset"], theta=test.theta, notch=prm["notch"],
                     support_factor=prm["support_factor"])
    confine = (case._History([0.0, 100.0], [0.0, test.sigma_H]), case._History([0.0, 100.0], [0.0, test.sigma_h]))
    borehole = case.Pressure(case.Region(geo.in_notch, "borehole"), 0.0)
    fem = case._Fem(geo, rock, {"borehole": borehole, "confinement": confine},
                    case.FrictionalContact(k_N=rock.E / 0.005, k_T=rock.E / 0.005, mu=0.7), (0.3, 3.5), "symmetric",
                    "impl-ex", MPI.COMM_SELF)
    m = fem.model
    assert m.u_nodes.shape == (geo.p.num_nodes, 2) and m.m == len(geo.p.triangles)
    length = np.linalg.norm(geo.segment[1] - geo.segment[0])
    assert np.isclose(m.fracture.interface.weights.sum(), length, rtol=1e-9)
    band = m.centroids[m.precracked]
    assert 32 <= m.precracked.sum() <= 80 and np.abs(band[:, 1]).max() < 1.25 * 0.005
    assert len(fem._borehole) == np.count_nonzero(geo.notch_mask)
    f = m.loads(100.0)[:m.n_u].reshape(-1, 2).sum(axis=0)
    np.testing.assert_allclose(f, [-test.sigma_H * prm["side"], -test.sigma_h * prm["side"]], rtol=1e-9)
    integrate(damped(0.6, 0.6), m, case._step_times(100.0, 200.0, 0.01, 5e-4, 5e-4)[:12])
    assert (m.fracture.status() == case.STICK).all()
    stress = m.strain @ rock.damage_material.elasticity().T
    far = (np.hypot(np.maximum(np.abs(m.centroids[:, 0]) - prm["notch"], 0), m.centroids[:, 1]) > 0.05) \
        & (np.abs(geo.sites(m.centroids).distance) > 0.02)
    np.testing.assert_allclose(np.median(stress[far], axis=0), [-test.sigma_H, -test.sigma_h, 0.0],
                               atol=0.02 * test.sigma_H)


def _run(test, **kw):
    return case.run(methods=("rkpm",), **_params(tests=[test]), **kw)


def test_ct8_crosses_the_pre_fracture(tmp_path):
    """CT-8 (60 deg, 20/5 MPa, 15 MPa): the HF runs through the intersection and beyond it
    (measured at h = 5 mm: through in 13.5 ms, 95 mm beyond, 73 Newton iterations, 46 s)."""
    res = _run("CT-8", vtk=tmp_path)
    (r,) = res.runs
    assert r.info["mode"] == "cross" and r.info["crossed"] == 1 == r.info["observed_crossed"]
    assert r.info["depth_beyond"] > 10 * r.info["h"] and r.series["stopped"] is None
    assert r.info["ended_by_margin"]  # through to the block's edge before t_grow ran out
    x, w = np.asarray(r.series["x"]), np.asarray(r.series["opening"])
    assert np.abs(x[w >= case.CRACKED, 1]).max() < 0.05  # the crack stays along sigma_H
    assert r.info["rp"] == "cross" and r.info["gw"] == "arrest"
    # --vtk: the fields at the pressurization, every 10 growth steps and at the end
    pvd = (tmp_path / "rkpm_CT-8_h0.005_particles.pvd").read_text()
    steps = int(round(r.info["growth_ms"] / 1e3 / case.PARAMS["dt"].default))
    assert pvd.count("<DataSet") == steps // case.VTK_EVERY + 1 + (steps % case.VTK_EVERY != 0)
    assert (tmp_path / "rkpm_CT-8_h0.005_cells.pvd").is_file()


@pytest.mark.slow
def test_ct4_is_arrested_by_the_pre_fracture():
    """CT-4 (60 deg, 12/10 MPa, 17 MPa): the HF meets the pre-fracture, which slips there, and
    stops (measured at h = 5 mm: the far wing reaches the block's edge after 113 ms, 148 s)."""
    (r,) = _run("CT-4").runs
    assert r.info["mode"] in ("arrest", "open") and r.info["crossed"] == 0 == r.info["observed_crossed"]
    assert r.info["depth_beyond"] == 0.0 and r.series["stopped"] is None
    assert max(r.series["slip"]) > 0  # the pre-fracture slips where the HF meets it


def test_fem_ct7_is_arrested_and_tabled_beside_its_cost():
    """The crack-band FEM baseline, CT-7 (30 deg, 19/10 MPa, 17 MPa), h = 5 mm: the HF grows
    along sigma_H to the pre-fracture and stops there (measured: 24.5 ms, 204 Newton
    iterations, 34 s); the time-to-accuracy row counts its match."""
    res = case.run(methods=("fem",), **_params(tests=["CT-7"]))
    (r,) = res.runs
    assert r.method == "fem-crack-band CT-7 h=0.005" and r.info["family"] == "fem"
    assert r.info["mode"] in ("arrest", "open") and r.info["crossed"] == 0 and r.series["stopped"] is None
    x, w = np.asarray(r.series["x"]), np.asarray(r.series["opening"])
    cracked = w >= case.CRACKED
    assert cracked.sum() > 20 and np.abs(x[cracked, 1]).max() < 0.03  # along sigma_H, on the borehole's side
    (row,) = res.params["time_to_accuracy"]
    assert row == {"method": "fem", "h": 0.005, "tests": 1, "matched": 1, "wall_s": r.wall_time_s,
                   "dofs": r.n_dofs, "newton": r.info["newton"]}
