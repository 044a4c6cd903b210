"""Shared node sets: gmsh unstructured meshes of a square and of a non-convex L-shape."""
import functools

import numpy as np
import pytest

gmsh = pytest.importorskip("gmsh")

from rkfx.geometry.gmsh_nodes import from_gmsh  # noqa: E402
from rkfx.geometry.particles import Particles  # noqa: E402


def _mesh(points, names, h):
    """Mesh a polygon (CCW points) with gmsh; side i gets the name names[i]."""
    gmsh.initialize(interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.model.add("poly")
        occ = gmsh.model.geo
        pts = [occ.addPoint(x, y, 0.0, h) for x, y in points]
        lines = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
        loop = occ.addCurveLoop(lines)
        surf = occ.addPlaneSurface([loop])
        occ.synchronize()
        for name in dict.fromkeys(names):
            tag = gmsh.model.addPhysicalGroup(1, [l for l, n in zip(lines, names) if n == name])
            gmsh.model.setPhysicalName(1, tag, name)
        gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [surf]), "domain")
        gmsh.model.mesh.generate(2)
        return from_gmsh(gmsh.model)
    finally:
        gmsh.finalize()


@functools.cache
def unit_square(h: float) -> Particles:
    """Unstructured gmsh nodes on [0, 1]^2 with sides bottom/right/top/left."""
    return _mesh([(0, 0), (1, 0), (1, 1), (0, 1)], ["bottom", "right", "top", "left"], h)


@functools.cache
def l_shape(h: float) -> Particles:
    """Unstructured gmsh nodes on the L-shape [0,2]^2 minus (1,2]^2 (non-convex)."""
    return _mesh([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)],
                 ["bottom", "right", "inner", "inner", "top", "left"], h)


def random_points(p: Particles, m: int, seed: int = 0) -> np.ndarray:
    """m random points inside the triangulated domain, a third of them on or near the boundary."""
    rng = np.random.default_rng(seed)
    xt = p.x[p.triangles]
    e1, e2 = xt[:, 1] - xt[:, 0], xt[:, 2] - xt[:, 0]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    t = rng.choice(len(xt), size=m, p=area / area.sum())
    r = rng.random((m, 2))
    flip = r.sum(1) > 1
    r[flip] = 1 - r[flip]
    pts = xt[t, 0] + r[:, :1] * (xt[t, 1] - xt[t, 0]) + r[:, 1:] * (xt[t, 2] - xt[t, 0])
    e = p.boundary_edges[rng.integers(len(p.boundary_edges), size=m // 3)]
    s = rng.random((m // 3, 1))
    pts[: m // 3] = (1 - s) * p.x[e[:, 0]] + s * p.x[e[:, 1]]
    return pts
