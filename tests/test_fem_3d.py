"""The dolfinx baselines in 3-D, on the tetrahedra of the gmsh solids the RKPM solver reads.

Elasticity (``fem_baselines.elasticity.solve_elasticity_3d``): manufactured convergence of P1
and P2 on ``gmsh_solids.box`` and the non-convex ``l_block``, and the linear patch test with
tractions from the facet normals. Biot u-p (``fem_baselines.poroelasticity.solve_biot`` on a
tetrahedral mesh): a 3-D column against Terzaghi's solution and its undrained first step, the
sphere octant's undrained pressure (Skempton's B) and its Mandel-Cryer rise, and the same run
serially and on 2 ranks. Meshes come from ``fem_baselines.gmsh_mesh.build_mesh``, and boundary
parts are the builders' physical names.

Numbers measured on the development machine are quoted next to each bound (run with ``-s`` to
see them printed).
"""

from __future__ import annotations

import math
import shutil

import pytest

pytest.importorskip("dolfinx_solver")
gmsh = pytest.importorskip("gmsh")

import dolfinx_solver  # noqa: E402,F401  (must precede dolfinx / petsc4py)

import numpy as np  # noqa: E402
import ufl  # noqa: E402

from fem_baselines import poroelasticity as pe  # noqa: E402
from fem_baselines.conditions import SIDES_3D, BoundaryParts  # noqa: E402
from fem_baselines.elasticity import errors, solve_elasticity_3d  # noqa: E402
from fem_baselines.gmsh_mesh import build_mesh, mesh_from_gmsh, mesh_parts  # noqa: E402
from rkfx.conditions import Displacement, Pressure, Traction  # noqa: E402
from rkfx.errors import InputError  # noqa: E402
from rkfx.geometry import gmsh_solids  # noqa: E402
from rkfx.geometry.gmsh_nodes import scratch_model  # noqa: E402
from rkfx.materials.elasticity import ElasticMaterial  # noqa: E402
from test_mpi import MPIEXEC, _serial_and_parallel  # noqa: E402
from verification.terzaghi import Terzaghi  # noqa: E402

XYZ = (0, 1, 2)  # every component of a 3-D vector condition
BOX_SIDES = tuple(SIDES_3D)  # left, right, front, back, bottom, top

# --------------------------------------------------------------------------- manufactured field
# u_i = A_i prod_j f_ij(w x_j) with f_ij in {sin, cos}: smooth, not a polynomial, every
# component coupled to every coordinate. f = -div sigma(u) = -(mu lap u + (lam + mu) grad div u).
E_MMS, NU_MMS = 1.0, 0.3
W_MMS = np.pi / 2  # a quarter wave per unit length: the coarsest meshes are in the asymptotic range
KINDS = (("sin", "cos", "sin"), ("cos", "sin", "sin"), ("sin", "sin", "cos"))
AMPS = (0.01, -0.02, 0.015)


def _factor(kind: str, s, order: int, lib):
    """d^order/ds^order of sin(w s) or cos(w s), with numpy or UFL functions."""
    sin, cos = (np.sin, np.cos) if lib is np else (ufl.sin, ufl.cos)
    fn = (sin if kind == "sin" else cos) if order != 1 else (cos if kind == "sin" else sin)
    sign = -1.0 if (order == 2 or (order == 1 and kind == "cos")) else 1.0
    return sign * W_MMS**order * fn(W_MMS * s)


def _derivative(i: int, orders: tuple[int, int, int], x, lib=np):
    """d^|orders| u_i / dx^orders at x (3, npts) (numpy) or X (UFL)."""
    out = AMPS[i]
    for j in range(3):
        out = out * _factor(KINDS[i][j], x[j], orders[j], lib)
    return out


def u_mms(x: np.ndarray) -> np.ndarray:
    """Exact displacement, x (3, npts) -> (3, npts) [m]."""
    return np.array([_derivative(i, (0, 0, 0), x) for i in range(3)])


def grad_u_mms(x: np.ndarray) -> np.ndarray:
    """G[i, k] = du_i/dx_k, x (3, npts) -> (3, 3, npts)."""
    return np.array([[_derivative(i, tuple(int(j == k) for j in range(3)), x) for k in range(3)] for i in range(3)])


def f_mms(x: np.ndarray) -> np.ndarray:
    """Body force -div sigma(u_mms), x (3, npts) -> (3, npts) [N/m^3]."""
    mat = ElasticMaterial(E_MMS, NU_MMS)
    lam, mu = mat.lame_lambda, mat.shear_modulus

    def d2(i, k, m):  # d^2 u_i / dx_k dx_m
        o = [0, 0, 0]
        o[k] += 1
        o[m] += 1
        return _derivative(i, tuple(o), x)

    return np.array([-(mu * sum(d2(k, m, m) for m in range(3)) + (lam + mu) * sum(d2(i, k, i) for i in range(3)))
                     for k in range(3)])


def u_mms_ufl(X):
    return ufl.as_vector([_derivative(i, (0, 0, 0), X, ufl) for i in range(3)])


def _stress(G: np.ndarray, E: float, nu: float) -> np.ndarray:
    """3-D stress of displacement gradient(s) G (3, 3, ...)."""
    mat = ElasticMaterial(E, nu)
    eps = 0.5 * (G + np.swapaxes(G, 0, 1))
    tr = eps[0, 0] + eps[1, 1] + eps[2, 2]
    return mat.lame_lambda * tr * np.eye(3).reshape((3, 3) + (1,) * (G.ndim - 2)) + 2 * mat.shear_modulus * eps


def test_manufactured_body_force_matches_divergence_of_stress():
    """The body force equals -div sigma(u_mms) by central differences."""
    x = np.random.default_rng(0).uniform(0.05, 0.95, size=(3, 40))
    d = 1e-5
    div = np.zeros((3, x.shape[1]))
    for j in range(3):
        e = np.zeros((3, 1))
        e[j] = d
        plus, minus = _stress(grad_u_mms(x + e), E_MMS, NU_MMS), _stress(grad_u_mms(x - e), E_MMS, NU_MMS)
        div += (plus[:, j] - minus[:, j]) / (2 * d)
    np.testing.assert_allclose(f_mms(x), -div, atol=1e-8)


# Halving sizes; the unstructured meshes' resolution is measured by their cells,
# h = (|Omega| / N_cells)^(1/3), not by the nominal size.
MMS_SIZES = {1: (0.2, 0.1, 0.05), 2: (0.4, 0.2, 0.1)}
VOLUME = {"box": 1.0, "l_block": 0.75}
PARTS = {"box": BOX_SIDES, "l_block": (*BOX_SIDES, "notch")}


@pytest.fixture(scope="module")
def mms_study() -> dict:
    """{geometry: {degree: [(mesh size, h, errors, n_dofs, seconds)]}} on three meshes of each solid."""
    out = {}
    for geo in ("box", "l_block"):
        out[geo] = {1: [], 2: []}
        meshes = {}
        for degree, sizes in MMS_SIZES.items():
            for size in sizes:
                if size not in meshes:
                    meshes[size] = build_mesh(getattr(gmsh_solids, geo), mesh_size=size)
                data = meshes[size]
                h = (VOLUME[geo] / data.mesh.topology.index_map(3).size_global) ** (1 / 3)
                bcs = [Displacement(part, lambda x, t: u_mms(x.T).T, XYZ) for part in PARTS[geo]]
                res = solve_elasticity_3d(data, E_MMS, NU_MMS, bcs, degree=degree, body_force=f_mms)
                out[geo][degree].append((size, h, errors(res, u_mms_ufl), res.n_dofs, res.wall_time_s))
    return out


def _rates(rows: list, key: str) -> list[float]:
    return [math.log(a[2][key] / b[2][key]) / math.log(a[1] / b[1]) for a, b in zip(rows, rows[1:])]


def _report(degree: int, geo: str, rows: list) -> tuple[list[float], list[float]]:
    l2, energy = _rates(rows, "l2"), _rates(rows, "energy")
    print(f"\nP{degree} {geo}: L2 {[f'{r[2]['l2']:.2e}' for r in rows]} rates {np.round(l2, 2)}, energy "
          f"{[f'{r[2]['energy']:.2e}' for r in rows]} rates {np.round(energy, 2)}, dofs {[r[3] for r in rows]}, "
          f"{rows[-1][4]:.2f} s on the finest")
    return l2, energy


@pytest.mark.parametrize("geo", ["box", "l_block"])
def test_p1_convergence_rates(mms_study, geo):
    rows = mms_study[geo][1]
    l2, energy = _report(1, geo, rows)
    assert min(l2) >= 1.8  # measured 2.08, 2.09 (box); 2.13, 2.12 (l_block)
    assert min(energy) >= 0.9  # measured 1.00, 1.06; 1.14, 1.06
    assert rows[-1][2]["l2"] < 3e-3  # measured 1.8e-3, 1.7e-3


@pytest.mark.parametrize("geo", ["box", "l_block"])
def test_p2_convergence_rates(mms_study, geo):
    rows = mms_study[geo][2]
    l2, energy = _report(2, geo, rows)
    assert min(l2) >= 2.7  # measured 3.86, 3.03 (box); 3.80, 3.23 (l_block)
    assert min(energy) >= 1.8  # measured 2.28, 2.08; 2.30, 2.16
    assert rows[-1][2]["l2"] < 3e-4  # measured 1.4e-4, 1.4e-4
    p1 = {r[0]: r[2]["l2"] for r in mms_study[geo][1]}
    shared = [(p1[r[0]], r[2]["l2"]) for r in rows if r[0] in p1]
    assert len(shared) == 2 and all(e2 < 0.1 * e1 for e1, e2 in shared)  # on the same mesh: measured 0.02-0.04


def test_energy_error_with_an_explicit_gradient_is_the_same(mms_study):
    data = build_mesh(gmsh_solids.box, mesh_size=0.2)
    res = solve_elasticity_3d(data, E_MMS, NU_MMS, [Displacement(p, lambda x, t: u_mms(x.T).T, XYZ)
                                                    for p in BOX_SIDES], degree=1, body_force=f_mms)

    def grad(X):
        return ufl.as_matrix([[_derivative(i, tuple(int(j == k) for j in range(3)), X, ufl) for k in range(3)]
                              for i in range(3)])

    auto, explicit = errors(res, u_mms_ufl), errors(res, u_mms_ufl, grad)
    for key in ("h1", "energy"):
        assert explicit[key] == pytest.approx(auto[key], rel=1e-10)
    assert auto["energy"] == pytest.approx(mms_study["box"][1][0][2]["energy"], rel=1e-12)  # mesh size 0.2


# --------------------------------------------------------------------------- patch test
E_PATCH, NU_PATCH = 7.5, 0.25
A0 = np.array([0.01, -0.02, 0.005])
B_LIN = np.array([[0.02, 0.03, -0.01], [0.01, -0.015, 0.02], [-0.005, 0.01, 0.025]])  # du_i/dx_j
S_LIN = _stress(B_LIN, E_PATCH, NU_PATCH)  # the linear field's constant stress


def u_lin(x: np.ndarray, t: float = 0.0) -> np.ndarray:
    """The linear field as a condition's value: x (m, 3) -> (m, 3)."""
    return A0 + x @ B_LIN.T


@pytest.mark.parametrize("geo", ["box", "l_block"])
def test_patch_test_linear_field(geo):
    """P1 reproduces a linear field exactly: u on three faces, sigma n from the facet normals on
    the others, a roller with traction on one face. The two faces of the l_block's re-entrant
    edge take a condition each (markers): a part that turns a corner gives the points on the
    corner one facet's normal (``fem_baselines.conditions``)."""
    data = build_mesh(getattr(gmsh_solids, geo), mesh_size=0.25)
    s_n = lambda x, t, n: n @ S_LIN.T  # noqa: E731
    bcs = [Displacement("left", u_lin, XYZ), Displacement("front", u_lin, XYZ),
           Displacement("bottom", lambda x, t: u_lin(x)[:, 2], (2,)),
           Traction("bottom", lambda x, t, n: (n @ S_LIN.T)[:, :2], (0, 1)),
           Traction("right", s_n, XYZ), Traction("back", s_n, XYZ), Traction("top", s_n, XYZ)]
    if geo == "l_block":  # the faces x = 0.5 (y >= 0.5) and y = 0.5 (x >= 0.5)
        bcs += [Traction(lambda x: np.isclose(x[:, 0], 0.5) & (x[:, 1] > 0.5 - 1e-9), s_n, XYZ),
                Traction(lambda x: np.isclose(x[:, 1], 0.5) & (x[:, 0] > 0.5 - 1e-9), s_n, XYZ)]
    res = solve_elasticity_3d(data, E_PATCH, NU_PATCH, bcs, degree=1)
    xd = res.u.function_space.tabulate_dof_coordinates()
    error = np.abs(res.u.x.array.reshape(-1, 3) - u_lin(xd)).max()
    print(f"\npatch test {geo}: max nodal error {error:.1e} ({res.n_dofs} dofs)")
    assert error < 1e-10  # measured ~1e-15
    pts = np.array([[0.1, 0.2, 0.3], [0.45, 0.45, 0.9], [0.2, 0.9, 0.5]])
    np.testing.assert_allclose(res.evaluate(pts), u_lin(pts), atol=1e-10)
    assert np.all(np.isnan(res.evaluate(np.array([[0.9, 0.9, 0.5], [2.0, 0.0, 0.0]]))[1]))


# --------------------------------------------------------------------------- meshes and parts


def test_gmsh_parts_sides_and_normals():
    """The box's named faces are the sides of its bounding box, with the axis normals; the
    sphere's surface normals are radial to the facets' angle; the octant has no 'top' side."""
    box = build_mesh(gmsh_solids.box, 2.0, 1.0, 0.5, mesh_size=0.2)
    assert sorted(box.physical_groups) == sorted([*BOX_SIDES, "solid"])
    mesh, tags, groups = mesh_parts(box)
    named, bare = BoundaryParts(mesh, tags, groups), BoundaryParts(mesh)
    centre = np.array([1.0, 0.5, 0.25])
    for side, (axis, lower) in SIDES_3D.items():
        assert np.array_equal(named.facets(side), bare.facets(side)), side
        n = named.normals(side, centre[None] + 0.0)
        assert np.allclose(n[0], np.eye(3)[axis] * (-1.0 if lower else 1.0), rtol=0, atol=1e-12), side

    octant = build_mesh(gmsh_solids.sphere_octant, radius=1.0, mesh_size=0.2)
    parts = BoundaryParts(*mesh_parts(octant))
    x = np.random.default_rng(2).normal(size=(50, 3))
    x = np.abs(x) / np.linalg.norm(x, axis=1)[:, None]  # points on the sphere
    cosines = np.einsum("ij,ij->i", parts.normals("surface", x), x)
    assert cosines.min() > 0.97  # measured 0.997: facets of ~0.2 rad
    assert np.allclose(parts.normals("z0", x[:3]), [0.0, 0.0, -1.0])
    assert len(parts.cells("surface")) >= len(parts.facets("surface")) > 0
    with pytest.raises(InputError, match="'top' has no facets"):
        parts.facets("top")
    with pytest.raises(InputError, match=r"no boundary part 'side'.*'surface'.*'front'"):
        parts.facets("side")


# --------------------------------------------------------------------------- Terzaghi column
# A 1 x 1 x 10 m column of tetrahedra: fixed base, rollers on the four sides, load q and p = 0
# on top. nu > 0 and alpha < 1, so the 3-D solid's constrained modulus K + 4G/3 matters.
C_E, C_NU, C_K, C_ALPHA, C_Q, C_H, C_SIZE = 1e3, 0.25, 1e-9, 0.8, 1e3, 10.0, 0.5
C_Z = np.linspace(0.0, C_H, 21)
C_POINTS = np.column_stack([np.full(21, 0.5), np.full(21, 0.5), C_Z])
C_AWAY = C_Z <= C_H - 4 * C_SIZE  # outside the drained top's discrete boundary layer (one or two cells)


@pytest.fixture(scope="module")
def column():
    return build_mesh(gmsh_solids.box, 1.0, 1.0, C_H, mesh_size=C_SIZE)


def column_bcs() -> list:
    return [Displacement("bottom", 0.0, XYZ), Displacement("left", 0.0, (0,)), Displacement("right", 0.0, (0,)),
            Displacement("front", 0.0, (1,)), Displacement("back", 0.0, (1,)),
            Traction("top", (0.0, 0.0, -C_Q), XYZ), Pressure("top")]


@pytest.mark.parametrize("S", [0.0, 1e-3])
def test_terzaghi_column_taylor_hood(column, S):
    """50 steps to T_v = 0.1: the pressure along the axis and the settlement profile."""
    exact = Terzaghi(C_E, C_NU, C_K, C_H, C_Q, C_ALPHA, S)
    times = np.linspace(0.0, 0.1 * C_H**2 / exact.c_v, 51)
    res = pe.solve_biot(column, C_E, C_NU, C_K, C_ALPHA, S, "taylor-hood", column_bcs(), times, C_POINTS,
                        times[[10, 50]])
    errs = [np.abs(res.p[j] - exact.pressure(C_Z, t)).max() / exact.p0 for j, t in enumerate(res.output_times)]
    settle = np.abs(res.u[1, :, 2] - exact.displacement(C_Z, times[50])).max() / exact.settlement(times[50])
    lateral = np.abs(res.u[:, :, :2]).max() / np.abs(res.u[:, :, 2]).max()
    print(f"\nTerzaghi 3-D Taylor-Hood S={S:g}: max |p - p_ex| / p0 at T_v = 0.02, 0.1: {errs[0]:.4f}, {errs[1]:.4f}; "
          f"u_z {settle:.1e}; lateral/vertical {lateral:.1e} ({res.n_dofs} dofs, {res.wall_time_s:.2f} s)")
    assert errs[0] < 0.02 and errs[1] < 0.005  # measured 0.0097, 0.0021 (both S)
    assert settle < 0.01  # measured 2.0e-3 (S = 0), 3.3e-4
    assert lateral < 1e-3  # measured 4.8e-5, 7.7e-6 (rollers: one-dimensional up to the mesh)
    assert res.n_factorizations == 1


def test_terzaghi_column_undrained_first_step(column):
    """dt = 1 s (c dt / h^2 = 3e-6): the undrained oedometric response of compressible constituents.

    Undrained (alpha eps_v + S p = 0) under zero lateral strain, sigma_zz = K_v eps_zz - alpha p = -q
    with K_v = K + 4G/3, gives p0 = alpha M q / (K_v + alpha^2 M) = alpha M q / (K_u + 4G/3) with
    M = 1/S and K_u = K + alpha^2 M (= alpha q / (alpha^2 + S K_v): q / alpha when S = 0), and
    u_z(z, 0+) = -q z / (K_u + 4G/3).
    """
    S = 1e-3
    mat = ElasticMaterial(C_E, C_NU)
    M = 1.0 / S
    K_u, G = mat.bulk_modulus + C_ALPHA**2 * M, mat.shear_modulus
    p0 = C_ALPHA * M * C_Q / (K_u + 4 * G / 3)
    assert p0 == pytest.approx(Terzaghi(C_E, C_NU, C_K, C_H, C_Q, C_ALPHA, S).p0, rel=1e-12)
    res = pe.solve_biot(column, C_E, C_NU, C_K, C_ALPHA, S, "taylor-hood", column_bcs(), np.array([0.0, 1.0]),
                        C_POINTS, [1.0])
    p_err = np.abs(res.p[0] / p0 - 1.0)[C_AWAY].max()
    u0 = -C_Q * C_Z / (K_u + 4 * G / 3)
    u_err = np.abs(res.u[0, :, 2] - u0)[C_AWAY].max() / np.abs(u0).max()
    print(f"\nundrained column: p0 = {p0:.2f} Pa; max |p/p0 - 1| below z = H - 2 m {p_err:.1e}, u_z error {u_err:.1e}")
    assert p_err < 3e-3  # measured 7.0e-4
    assert u_err < 1e-4  # measured 2.2e-6


def test_equal_order_column_oscillates_and_fpp_stabilises(column):
    """The first step (nearly undrained, S = 0) with P1-P1 on tetrahedra: unstabilised it shows
    the spurious pressure mode; with FPP (h = cbrt(cell volume)) it is gone, as Taylor-Hood's."""
    times = np.array([0.0, 1.0])
    p0 = C_Q / C_ALPHA
    spread = {}
    for element in ("q1q1", "q1q1-fpp", "taylor-hood"):
        res = pe.solve_biot(column, C_E, C_NU, C_K, C_ALPHA, 0.0, element, column_bcs(), times, C_POINTS, [1.0])
        spread[element] = np.abs(res.p[0] / p0 - 1.0)[C_AWAY].max()
    print("\nfirst-step max |p/p0 - 1| below z = H - 2 m: " + ", ".join(f"{k} {v:.1e}" for k, v in spread.items()))
    assert spread["q1q1"] > 0.05  # measured 0.21
    assert spread["q1q1-fpp"] < 5e-3 and spread["taylor-hood"] < 5e-3  # measured 4.6e-4, 7.9e-4


# --------------------------------------------------------------------------- sphere octant
# Radius 1 m, symmetry rollers on x0, y0, z0, total traction -sigma0 n on the surface.
SP_E, SP_K, SP_SIGMA0 = 1e4, 1e-4, 1.0
SP_POINTS = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.3, 0.3, 0.3], [0.0, 0.4, 0.2]])


@pytest.fixture(scope="module")
def octant():
    return build_mesh(gmsh_solids.sphere_octant, radius=1.0, mesh_size=0.2)


def octant_bcs(drained: bool) -> list:
    bcs = [Displacement("x0", 0.0, (0,)), Displacement("y0", 0.0, (1,)), Displacement("z0", 0.0, (2,)),
           Traction("surface", lambda x, t, n: -SP_SIGMA0 * n, XYZ)]
    return bcs + [Pressure("surface")] if drained else bcs


def skempton_b(nu: float, alpha: float, S: float) -> float:
    """B = alpha M / (K + alpha^2 M) = alpha / (alpha^2 + S K), M = 1/S; 1/alpha when S = 0."""
    K = ElasticMaterial(SP_E, nu).bulk_modulus
    return alpha / (alpha**2 + S * K)


@pytest.mark.parametrize(("nu", "alpha", "S"), [(0.0, 1.0, 0.0), (0.2, 0.8, 0.0), (0.2, 0.8, 1e-4)])
def test_sphere_undrained_pressure_is_skempton_b(octant, nu, alpha, S):
    """Impermeable surface, one step: the uniform undrained state p = B sigma0 (mean total
    stress -sigma0, alpha eps_v + S p = 0), u = eps_v x / 3 with eps_v = -S p / alpha."""
    B = skempton_b(nu, alpha, S)
    times = np.array([0.0, 1.0])
    res = pe.solve_biot(octant, SP_E, nu, SP_K, alpha, S, "taylor-hood", octant_bcs(False), times, SP_POINTS, [1.0])
    p_err = np.abs(res.p[0] / (B * SP_SIGMA0) - 1.0).max()
    u_exact = -S * B * SP_SIGMA0 / (3 * alpha) * SP_POINTS
    u_err = np.abs(res.u[0] - u_exact).max() * SP_E / SP_SIGMA0
    print(f"\nundrained octant nu={nu} alpha={alpha} S={S:g}: B = {B:.4f}, max |p/(B sigma0) - 1| {p_err:.1e}, "
          f"|u - u_ex| E / sigma0 {u_err:.1e}")
    assert p_err < 2e-3  # measured <= 6.1e-4 (the faceted surface)
    assert u_err < 3e-3  # measured <= 1.1e-3


def test_sphere_mandel_cryer_effect(octant):
    """Drained surface, 30 steps from T = c t / R^2 = 1e-4 to 1: the centre pressure first rises
    above its undrained value (the Mandel-Cryer effect), then decays.

    The first step's centre value lies above B sigma0 by the drained layer of one P1 cell
    (:func:`test_sphere_first_step_tends_to_skempton_b`); the exact Cryer history is for
    ``verification/cryer.py``.
    """
    nu, alpha, S = 0.0, 1.0, 0.0
    mat = ElasticMaterial(SP_E, nu)
    c = SP_K * mat.constrained_modulus / (alpha**2 + S * mat.constrained_modulus)
    T = np.r_[0.0, np.geomspace(1e-4, 1.0, 30)]
    res = pe.solve_biot(octant, SP_E, nu, SP_K, alpha, S, "taylor-hood", octant_bcs(True), T / c, SP_POINTS[:1],
                        T[1:] / c)
    p = res.p[:, 0] / (skempton_b(nu, alpha, S) * SP_SIGMA0)
    peak = int(np.argmax(p))
    print(f"\nCryer octant ({res.n_dofs} dofs, {res.wall_time_s:.2f} s): p_c / (B sigma0) first {p[0]:.3f}, "
          f"peak {p[peak]:.3f} at T = {T[1 + peak]:.3g}, last {p[-1]:.3f}")
    assert 1.0 < p[0] < 1.2  # measured 1.129
    assert p[peak] > 1.3 * p[0]  # measured 1.574 = 1.39 x the first
    assert 0 < peak < len(p) - 1 and np.all(np.diff(p[: peak + 1]) > 0)  # rises until the peak (T = 0.057)
    assert np.all(np.diff(p[peak:]) < 0) and p[-1] < 0.15  # then decays: measured 0.079 at T = 1


def test_sphere_first_step_tends_to_skempton_b():
    """Drained surface, one step to T = 1e-4 (sqrt(c dt) = 0.01 R): the centre pressure exceeds
    B sigma0 because the discrete drained layer is a cell thick, not sqrt(c dt); the excess
    shrinks with the mesh size."""
    nu, alpha, S = 0.2, 0.8, 1e-4
    mat = ElasticMaterial(SP_E, nu)
    c = SP_K * mat.constrained_modulus / (alpha**2 + S * mat.constrained_modulus)
    times = np.array([0.0, 1e-4 / c])
    excess = []
    for size in (0.3, 0.2, 0.14):
        data = build_mesh(gmsh_solids.sphere_octant, radius=1.0, mesh_size=size)
        res = pe.solve_biot(data, SP_E, nu, SP_K, alpha, S, "taylor-hood", octant_bcs(True), times, SP_POINTS[:1],
                            times[1:])
        excess.append(res.p[0, 0] / (skempton_b(nu, alpha, S) * SP_SIGMA0) - 1.0)
    print(f"\nfirst-step centre pressure / (B sigma0) - 1 at mesh sizes 0.3, 0.2, 0.14: {np.round(excess, 4)}")
    assert 0 < excess[2] < excess[1] < excess[0] < 0.1  # measured 0.072, 0.052, 0.031


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
def test_sphere_serial_and_two_ranks_agree(tmp_path):
    """``tests/mpi/fem_sphere_3d.py``: the mesh built on rank 0 and split over 2 ranks, the
    tractions from the normals of all ranks' facets: the same samples as the serial run."""
    a, b = _serial_and_parallel(tmp_path, "fem_sphere_3d.py", 2)
    assert np.all(np.isfinite(a))
    assert np.abs(a - b).max() <= 1e-8 * np.abs(a).max()  # measured 5e-16


# --------------------------------------------------------------------------- bad input


def test_bad_input(octant):
    times = np.array([0.0, 1.0])
    args = (octant, SP_E, 0.2, SP_K, 1.0, 0.0, "taylor-hood", octant_bcs(True), times)
    with pytest.raises(ValueError, match=r"sample_points must have shape \(m, 3\)"):
        pe.solve_biot(*args, SP_POINTS[:, :2], [1.0])
    with pytest.raises(InputError, match=r"no boundary part 'middle'.*'x0'.*'front'"):
        pe.solve_biot(octant, SP_E, 0.2, SP_K, 1.0, 0.0, "taylor-hood", [Pressure("middle")], times, SP_POINTS, [1.0])
    with pytest.raises(InputError, match="components"):
        pe.solve_biot(*args[:7], [Displacement("x0", 0.0, (0, 3))], times, SP_POINTS, [1.0])
    with pytest.raises(ValueError, match="3D tetrahedral mesh"):
        solve_elasticity_3d(pe.rectangle_mesh([0.0, 1.0], [0.0, 1.0]), 1.0, 0.3, [Displacement("left")])
    with pytest.raises(ValueError, match=r"body_force gave shape \(2, 1\)"):
        solve_elasticity_3d(octant, 1.0, 0.3, [Displacement("x0", 0.0, XYZ)], body_force=lambda x: np.zeros((2, 1)))
    with pytest.raises(InputError, match="mesh_size"):
        build_mesh(gmsh_solids.box, mesh_size=-1.0)
    with pytest.raises(InputError, match="no mesh; call gmsh.model.mesh.generate"):
        with scratch_model("empty") as model:
            model.occ.addBox(0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
            model.occ.synchronize()
            mesh_from_gmsh(model)
    with pytest.raises(InputError, match="MeshData"):
        mesh_parts("box.msh")
