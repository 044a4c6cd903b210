"""Error norms of RK fields, integrated by Gauss quadrature on the background triangles (or
tetrahedra in 3-D)."""
from collections.abc import Callable
from functools import cache

import numpy as np
from scipy.special import roots_jacobi

from rkfx.integration.quadrature import _TRIANGLE_RULES
from rkfx.approximation.shape_functions import RKApproximation, evaluate


@cache
def tetrahedron_rule(n: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Barycentric points ``(n^3, 4)`` and weights (sum 1) of the conical product rule on the
    tetrahedron, exact for polynomials of degree 2 n - 1: the collapsed map x = a,
    y = b (1 - a), z = c (1 - a)(1 - b) of the unit cube, Gauss-Jacobi in a (weight (1 - a)^2)
    and b (weight 1 - b), Gauss-Legendre in c (Stroud 1971)."""
    ta, wa = roots_jacobi(n, 2.0, 0.0)
    tb, wb = roots_jacobi(n, 1.0, 0.0)
    tc, wc = np.polynomial.legendre.leggauss(n)
    a, b, c = (0.5 * (t + 1.0) for t in (ta, tb, tc))
    wa, wb, wc = wa / 8.0, wb / 4.0, wc / 2.0  # the Jacobi weights on [-1, 1] mapped to [0, 1]
    A, B, C = np.meshgrid(a, b, c, indexing="ij")
    w = np.einsum("i,j,k->ijk", wa, wb, wc).ravel()
    x, y = A.ravel(), (B * (1.0 - A)).ravel()
    z = (C * (1.0 - A) * (1.0 - B)).ravel()
    return np.column_stack([1.0 - x - y - z, x, y, z]), w / w.sum()


def gauss_points(p, degree: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(m, 2)`` and weights ``(m,)`` of a degree-``degree`` rule on every triangle; for
    3-D particles points ``(m, 3)`` of a conical product rule of degree >= ``degree`` on every
    tetrahedron."""
    if p.x.shape[1] == 3:
        bary, w = tetrahedron_rule(max(2, (degree + 2) // 2))
        xt = p.x[p.tetrahedra]
        volume = np.abs(np.einsum("ti,ti->t", np.cross(xt[:, 1] - xt[:, 0], xt[:, 2] - xt[:, 0]),
                                  xt[:, 3] - xt[:, 0])) / 6.0
        return np.einsum("qk,tkd->tqd", bary, xt).reshape(-1, 3), np.outer(volume, w).ravel()
    bary, w = _TRIANGLE_RULES[degree]
    xt = p.x[p.triangles]
    e1, e2 = xt[:, 1] - xt[:, 0], xt[:, 2] - xt[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    return np.einsum("qk,tkd->tqd", bary, xt).reshape(-1, 2), np.outer(area, w).ravel()


def relative_errors(p, rk: RKApproximation, coefficients: np.ndarray,
                    exact: Callable[[np.ndarray], np.ndarray],
                    exact_gradient: Callable[[np.ndarray], np.ndarray] | None = None,
                    degree: int = 4) -> dict[str, float]:
    """Relative L2 error and, with ``exact_gradient``, relative H1-seminorm error.

    Args:
        coefficients: RK coefficients, shape ``(num_nodes,)`` or ``(num_nodes, k)``.
        exact: u(x) for x ``(m, g)`` (g = 2, or 3 for 3-D particles), shape ``(m,)`` or ``(m, k)``.
        exact_gradient: grad u(x), shape ``(m, g)`` or ``(m, k, g)``.
    """
    pts, w = gauss_points(p, degree)
    rows = evaluate(rk, pts, gradients=exact_gradient is not None)
    c = coefficients.reshape(p.num_nodes, -1)
    uh = rows.matrix(0) @ c
    ue = np.asarray(exact(pts)).reshape(len(pts), -1)
    out = {"l2": float(np.sqrt(np.sum(w[:, None] * (uh - ue) ** 2) / np.sum(w[:, None] * ue**2)))}
    if exact_gradient is not None:
        gh = np.stack([rows.matrix(1 + j) @ c for j in range(p.x.shape[1])], axis=-1)
        ge = np.asarray(exact_gradient(pts)).reshape(gh.shape)
        out["h1"] = float(np.sqrt(np.sum(w[:, None, None] * (gh - ge) ** 2) / np.sum(w[:, None, None] * ge**2)))
    return out
