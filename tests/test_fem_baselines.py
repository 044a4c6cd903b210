"""dolfinx plane-strain FEM baseline: manufactured convergence, patch tests, timing."""

from __future__ import annotations

import contextlib
import math

import pytest

pytest.importorskip("dolfinx_solver")
gmsh = pytest.importorskip("gmsh")

import dolfinx_solver  # noqa: E402,F401  (must precede dolfinx / petsc4py)

import numpy as np  # noqa: E402
import ufl  # noqa: E402
from mpi4py import MPI  # noqa: E402

from fem_baselines.assembly_timing import time_p1_assembly  # noqa: E402
from fem_baselines.elasticity import (  # noqa: E402
    errors,
    solve_plane_strain,
)
from fem_baselines.conditions import BoundaryParts  # noqa: E402
from rkfx.conditions import Displacement, Pressure, Traction  # noqa: E402
from rkfx.errors import InputError  # noqa: E402
from rkfx.materials.elasticity import ElasticMaterial  # noqa: E402

E_MMS, NU_MMS = 1.0, 0.3
SIDES = ("left", "right", "bottom", "top")


@contextlib.contextmanager
def unit_square_model(h: float):
    """gmsh model of [0,1]^2 meshed with triangles of size ~h.

    Physical groups: 2D "domain", 1D "left", "right", "bottom", "top".
    Yields ``gmsh.model``; finalizes gmsh on exit.
    """
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        if MPI.COMM_WORLD.rank == 0:
            gmsh.model.add("unit_square")
            surf = gmsh.model.occ.addRectangle(0.0, 0.0, 0.0, 1.0, 1.0)
            gmsh.model.occ.synchronize()
            sides = {}
            for dim, tag in gmsh.model.getBoundary([(2, surf)], oriented=False):
                cx, cy, _ = gmsh.model.occ.getCenterOfMass(dim, abs(tag))
                if abs(cy) < 1e-12:
                    sides["bottom"] = abs(tag)
                elif abs(cy - 1.0) < 1e-12:
                    sides["top"] = abs(tag)
                elif abs(cx) < 1e-12:
                    sides["left"] = abs(tag)
                else:
                    sides["right"] = abs(tag)
            assert sorted(sides) == sorted(SIDES)
            gmsh.model.addPhysicalGroup(2, [surf], name="domain")
            for name in SIDES:
                gmsh.model.addPhysicalGroup(1, [sides[name]], name=name)
            gmsh.option.setNumber("Mesh.MeshSizeMin", h)
            gmsh.option.setNumber("Mesh.MeshSizeMax", h)
            gmsh.model.mesh.generate(2)
        yield gmsh.model
    finally:
        gmsh.finalize()


# --- manufactured solution --------------------------------------------------
# u = (0.1 sin(pi x) cos(pi y), 0.05 x^2 y), plane strain, E = 1, nu = 0.3.
# f = -div sigma = -(mu lap u + (lam + mu) grad div u):
#   lap u   = (-0.2 pi^2 sin(pi x) cos(pi y), 0.1 y)
#   div u   = 0.1 pi cos(pi x) cos(pi y) + 0.05 x^2
#   grad div u = (-0.1 pi^2 sin(pi x) cos(pi y) + 0.1 x, -0.1 pi^2 cos(pi x) sin(pi y))


def u_mms(x: np.ndarray) -> np.ndarray:
    """Exact displacement, x (2, npts) -> (2, npts)."""
    return np.array(
        [0.1 * np.sin(np.pi * x[0]) * np.cos(np.pi * x[1]), 0.05 * x[0] ** 2 * x[1]]
    )


def grad_u_mms(x: np.ndarray) -> np.ndarray:
    """Exact gradient G[i, j] = du_i/dx_j, x (2, npts) -> (2, 2, npts)."""
    p = np.pi
    return np.array(
        [
            [0.1 * p * np.cos(p * x[0]) * np.cos(p * x[1]), -0.1 * p * np.sin(p * x[0]) * np.sin(p * x[1])],
            [0.1 * x[0] * x[1], 0.05 * x[0] ** 2],
        ]
    )


def f_mms(x: np.ndarray) -> np.ndarray:
    """Body force -div sigma(u_mms), x (2, npts) -> (2, npts)."""
    lam, mu = ElasticMaterial(E_MMS, NU_MMS).lame
    p2 = np.pi**2
    sc = np.sin(np.pi * x[0]) * np.cos(np.pi * x[1])
    cs = np.cos(np.pi * x[0]) * np.sin(np.pi * x[1])
    return np.array(
        [
            0.2 * p2 * mu * sc + (lam + mu) * (0.1 * p2 * sc - 0.1 * x[0]),
            -0.1 * mu * x[1] + (lam + mu) * 0.1 * p2 * cs,
        ]
    )


def u_mms_ufl(X):
    return ufl.as_vector(
        (0.1 * ufl.sin(ufl.pi * X[0]) * ufl.cos(ufl.pi * X[1]), 0.05 * X[0] ** 2 * X[1])
    )


def _stress(G: np.ndarray, E: float, nu: float) -> np.ndarray:
    """Plane-strain stress from displacement gradient(s) G (2, 2, ...)."""
    lam, mu = ElasticMaterial(E, nu).lame
    eps = 0.5 * (G + np.swapaxes(G, 0, 1))
    tr = eps[0, 0] + eps[1, 1]
    return lam * tr * np.eye(2).reshape((2, 2) + (1,) * (G.ndim - 2)) + 2.0 * mu * eps


def test_manufactured_body_force_matches_divergence_of_stress():
    """The hand-derived f equals -div sigma(u_mms) (central differences)."""
    rng = np.random.default_rng(0)
    x = rng.uniform(0.05, 0.95, size=(2, 50))
    d = 1e-5
    div = np.zeros((2, x.shape[1]))
    for j in range(2):
        e = np.zeros((2, 1))
        e[j] = d
        s_plus = _stress(grad_u_mms(x + e), E_MMS, NU_MMS)
        s_minus = _stress(grad_u_mms(x - e), E_MMS, NU_MMS)
        div += (s_plus[:, j] - s_minus[:, j]) / (2 * d)
    np.testing.assert_allclose(f_mms(x), -div, atol=1e-7)


MESH_SIZES = (1 / 8, 1 / 16, 1 / 32)


@pytest.fixture(scope="module")
def mms_study():
    """Errors of P1 and P2 on the three meshes, plus the finest P1 result."""
    out = {1: [], 2: []}
    finest = None
    for h in MESH_SIZES:
        with unit_square_model(h) as model:
            md_results = {}
            for degree in (1, 2):
                md_results[degree] = solve_plane_strain(
                    model,
                    E_MMS,
                    NU_MMS,
                    [Displacement(side, lambda x, t: u_mms(x.T).T) for side in SIDES],
                    body_force=f_mms,
                    degree=degree,
                )
        for degree, res in md_results.items():
            out[degree].append(errors(res, u_mms_ufl))
        finest = md_results[1]
    return out, finest


def _rates(errs: list[float]) -> list[float]:
    return [
        math.log(errs[i] / errs[i + 1]) / math.log(MESH_SIZES[i] / MESH_SIZES[i + 1])
        for i in range(len(errs) - 1)
    ]


def test_p1_convergence_rates(mms_study):
    out, _ = mms_study
    l2 = [e["l2"] for e in out[1]]
    h1 = [e["h1"] for e in out[1]]
    assert min(_rates(l2)) >= 1.8, (l2, _rates(l2))
    assert min(_rates(h1)) >= 0.9, (h1, _rates(h1))
    assert l2[-1] < 2e-3 and h1[-1] < 5e-2


def test_p2_convergence_rates(mms_study):
    out, _ = mms_study
    l2 = [e["l2"] for e in out[2]]
    h1 = [e["h1"] for e in out[2]]
    assert min(_rates(l2)) >= 2.8, (l2, _rates(l2))
    assert min(_rates(h1)) >= 1.8, (h1, _rates(h1))
    # P2 beats P1 on every mesh.
    assert all(e2["l2"] < e1["l2"] for e1, e2 in zip(out[1], out[2]))


def test_explicit_gradient_gives_same_errors(mms_study):
    _, res = mms_study
    G = lambda X: ufl.as_matrix(  # noqa: E731
        [
            [0.1 * ufl.pi * ufl.cos(ufl.pi * X[0]) * ufl.cos(ufl.pi * X[1]),
             -0.1 * ufl.pi * ufl.sin(ufl.pi * X[0]) * ufl.sin(ufl.pi * X[1])],
            [0.1 * X[0] * X[1], 0.05 * X[0] ** 2],
        ]
    )
    e_auto = errors(res, u_mms_ufl)
    e_expl = errors(res, u_mms_ufl, G)
    assert e_expl["h1"] == pytest.approx(e_auto["h1"], rel=1e-10)
    assert e_expl["l2"] == pytest.approx(e_auto["l2"], rel=1e-12)


def test_result_metadata_and_evaluate(mms_study):
    _, res = mms_study
    assert res.n_dofs == 2 * res.mesh.topology.index_map(0).size_global
    assert res.wall_time_s > 0.0
    assert set(res.timings) == {"mesh", "setup", "solve"}
    pts = np.array([[0.3, 0.7], [0.5, 0.5], [1.0, 1.0], [0.0, 0.25], [1.5, 0.5], [-0.1, -0.1]])
    vals = res.evaluate(pts)
    assert vals.shape == (6, 2)
    np.testing.assert_allclose(vals[:4], u_mms(pts[:4].T).T, atol=5e-4)
    # Nodal interpolation on the boundary is exact up to Dirichlet data.
    np.testing.assert_allclose(vals[2:4], u_mms(pts[2:4].T).T, atol=1e-12)
    assert np.all(np.isnan(vals[4:]))


# --- patch tests ---------------------------------------------------------------
E_PATCH, NU_PATCH = 7.5, 0.25
A0 = np.array([0.01, -0.02])
B = np.array([[0.02, 0.03], [0.01, -0.015]])  # du_i/dx_j
S = _stress(B, E_PATCH, NU_PATCH)  # constant stress of the linear field


def u_lin(x: np.ndarray) -> np.ndarray:
    return A0[:, None] + B @ x


def u_lin_bc(x: np.ndarray, t: float) -> np.ndarray:
    """u_lin as a condition's value: x (m, 2) -> (m, 2)."""
    return u_lin(x.T).T


def _traction(normal):
    t = S @ np.asarray(normal, dtype=float)
    return lambda x, time, n: np.tile(t, (len(x), 1))


def s_n(x: np.ndarray, t: float, n: np.ndarray) -> np.ndarray:
    """The patch's traction sigma n on any side, from the facet normals."""
    return n @ S.T


def _max_nodal_error(res) -> float:
    V = res.u.function_space
    xd = V.tabulate_dof_coordinates()[:, :2]
    uh = res.u.x.array.reshape(-1, 2)
    return float(np.abs(uh - u_lin(xd.T).T).max())


def test_patch_test_linear_field_with_tractions():
    with unit_square_model(0.2) as model:
        res = solve_plane_strain(
            model,
            E_PATCH,
            NU_PATCH,
            [Displacement("left", u_lin_bc), Displacement("bottom", u_lin_bc),
             Traction("right", _traction((1.0, 0.0))), Traction("top", _traction((0.0, 1.0)))],
            degree=1,
        )
    assert _max_nodal_error(res) < 1e-10
    rng = np.random.default_rng(1)
    pts = rng.uniform(0.0, 1.0, size=(20, 2))
    np.testing.assert_allclose(res.evaluate(pts), u_lin(pts.T).T, atol=1e-10)


def test_patch_test_rollers_and_constant_data():
    """Rollers on left/bottom, tractions on all four sides."""
    with unit_square_model(0.25) as model:
        res = solve_plane_strain(
            model,
            E_PATCH,
            NU_PATCH,
            [
                Displacement("left", lambda x, t: u_lin(x.T)[0], (0,)),
                Displacement("bottom", u_lin_bc, (1,)),  # every component given, the listed one taken
                Traction("right", S @ np.array([1.0, 0.0])),  # a constant vector
                Traction("top", _traction((0.0, 1.0))),
                Traction("left", s_n),  # from the outward normals
                Traction("bottom", s_n),
            ],
        )
    assert _max_nodal_error(res) < 1e-10



def test_bare_mesh_with_marker_boundaries():
    """A dolfinx mesh with geometric markers instead of physical names."""
    import dolfinx.mesh

    msh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 5, 7)
    res = solve_plane_strain(
        msh,
        E_PATCH,
        NU_PATCH,
        [
            Displacement(lambda x: np.isclose(x[:, 0], 0.0), u_lin_bc),
            Displacement("bottom", u_lin_bc),  # a side of the bounding box
            Traction(lambda x: np.isclose(x[:, 0], 1.0), _traction((1.0, 0.0))),
            Traction(lambda x: np.isclose(x[:, 1], 1.0), s_n),
        ],
    )
    assert _max_nodal_error(res) < 1e-10


def test_physical_groups_and_facet_tags_name_the_same_parts():
    with unit_square_model(0.25) as model:
        sides = ("left", "bottom", "right", "top")
        by_name = solve_plane_strain(model, E_PATCH, NU_PATCH, [Displacement(sides[0], u_lin_bc),
                                                                Displacement(sides[1], u_lin_bc),
                                                                Traction(sides[2], s_n), Traction(sides[3], s_n)])
        tag = [by_name.physical_groups[name].tag for name in sides]
        by_tag = solve_plane_strain(model, E_PATCH, NU_PATCH, [Displacement(tag[0], u_lin_bc),
                                                               Displacement(tag[1], u_lin_bc),
                                                               Traction(tag[2], s_n), Traction(tag[3], s_n)])
    assert np.array_equal(by_name.u.x.array, by_tag.u.x.array)
    assert _max_nodal_error(by_name) < 1e-10


def test_outward_normals_on_a_hole():
    """The facets of a circular hole: outward (into the hole) normals of unit length, from the
    nearest facet, and the cells next to the part."""
    from rkfx.cases.plate_with_hole import mesh_plate

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        if MPI.COMM_WORLD.rank == 0:
            mesh_plate(1.0, 4.0, 0.5)
        res = solve_plane_strain(gmsh.model, E_PATCH, NU_PATCH, [Displacement("left", 0.0, (0,)),
                                                                 Displacement("bottom", 0.0, (1,))])
    finally:
        gmsh.finalize()
    parts = BoundaryParts(res.mesh, res.facet_tags, res.physical_groups)
    x = res.mesh.geometry.x[:, :2]
    r = np.linalg.norm(x, axis=1)
    on_hole = x[np.abs(r - 1.0) < 1e-9]
    if len(parts.facets("hole")):
        n = parts.normals("hole", on_hole * 1.001)
        assert np.allclose(np.linalg.norm(n, axis=1), 1.0)
        assert np.all(np.einsum("ij,ij->i", n, -on_hole) > 0.99)  # facets of ~0.17 rad: cos > 0.996
        assert len(parts.cells("hole")) >= len(parts.facets("hole"))
    top = parts.normals("top", np.array([[2.0, 4.0]]))
    assert top.shape == (1, 2)
    if len(parts.facets("top")):
        assert np.array_equal(top, [[0.0, 1.0]])


def test_bad_conditions_raise():
    with unit_square_model(0.5) as model:
        with pytest.raises(InputError, match="no boundary part 'nowhere'.*physical group"):
            solve_plane_strain(model, 1.0, 0.3, [Displacement("nowhere", u_lin_bc)])
        with pytest.raises(InputError, match="takes no Pressure"):
            solve_plane_strain(model, 1.0, 0.3, [Displacement("left"), Pressure("right")])
        with pytest.raises(InputError, match="share facets"):
            solve_plane_strain(model, 1.0, 0.3, [Displacement("left"), Traction("top", 1.0),
                                                 Traction(lambda x: x[:, 1] > 0.5, 2.0)])
        with pytest.raises(InputError, match="facet tag 999"):
            solve_plane_strain(model, 1.0, 0.3, [Displacement(999)])


# --- assembly timing -----------------------------------------------------------


def test_time_p1_assembly_small():
    r = time_p1_assembly(2000)
    assert {"vertices", "dofs", "assembly_s", "nnz"} <= set(r)
    assert abs(r["vertices"] - 2000) <= 0.05 * 2000
    assert r["dofs"] == 2 * r["vertices"]
    # P1 vector on a structured triangle mesh: <= 7 neighbours x 4 entries per vertex.
    assert r["dofs"] < r["nnz"] <= 28 * r["vertices"]
    assert 0.0 < r["assembly_s"] < 5.0
    assert r["form_s"] >= 0.0
