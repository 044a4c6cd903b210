"""Error norms of RK fields, integrated by Gauss quadrature on the background triangles."""
from collections.abc import Callable

import numpy as np

from rkfx.geometry.particles import Particles
from rkfx.integration.quadrature import _TRIANGLE_RULES
from rkfx.approximation.shape_functions import RKApproximation, evaluate


def gauss_points(p: Particles, degree: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(m, 2)`` and weights ``(m,)`` of a degree-``degree`` rule on every triangle."""
    bary, w = _TRIANGLE_RULES[degree]
    xt = p.x[p.triangles]
    e1, e2 = xt[:, 1] - xt[:, 0], xt[:, 2] - xt[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    return np.einsum("qk,tkd->tqd", bary, xt).reshape(-1, 2), np.outer(area, w).ravel()


def relative_errors(p: Particles, rk: RKApproximation, coefficients: np.ndarray,
                    exact: Callable[[np.ndarray], np.ndarray],
                    exact_gradient: Callable[[np.ndarray], np.ndarray] | None = None,
                    degree: int = 4) -> dict[str, float]:
    """Relative L2 error and, with ``exact_gradient``, relative H1-seminorm error.

    Args:
        coefficients: RK coefficients, shape ``(num_nodes,)`` or ``(num_nodes, k)``.
        exact: u(x) for x ``(m, 2)``, shape ``(m,)`` or ``(m, k)``.
        exact_gradient: grad u(x), shape ``(m, 2)`` or ``(m, k, 2)``.
    """
    pts, w = gauss_points(p, degree)
    rows = evaluate(rk, pts, gradients=exact_gradient is not None)
    c = coefficients.reshape(p.num_nodes, -1)
    uh = rows.matrix(0) @ c
    ue = np.asarray(exact(pts)).reshape(len(pts), -1)
    out = {"l2": float(np.sqrt(np.sum(w[:, None] * (uh - ue) ** 2) / np.sum(w[:, None] * ue**2)))}
    if exact_gradient is not None:
        gh = np.stack([rows.matrix(1) @ c, rows.matrix(2) @ c], axis=-1)
        ge = np.asarray(exact_gradient(pts)).reshape(gh.shape)
        out["h1"] = float(np.sqrt(np.sum(w[:, None, None] * (gh - ge) ** 2) / np.sum(w[:, None, None] * ge**2)))
    return out
