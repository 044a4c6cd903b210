"""Two-dimensional gmsh models with pre-existing fractures, meshed with linear triangles.

``fractured_square`` adds the square [-side/2, side/2]^2 with straight fractures embedded in its
surface, so the mesh has edges along every fracture and vertices at their ends;
``rkfx.geometry.gmsh_nodes.from_gmsh`` then gives the particles and
``rkfx.geometry.particles.cut_triangulation`` splits them along the fractures. The outer edges
are the 1-D physical groups ``bottom``, ``right``, ``top`` and ``left``; the fractures are not
boundary parts until they are cut. Import this module only where gmsh is installed; build
inside ``rkfx.geometry.gmsh_nodes.scratch_model`` to keep models apart.
"""
from collections.abc import Sequence

import numpy as np

from rkfx.errors import InputError

_SIDES = (("bottom", 1, 0), ("right", 0, 1), ("top", 1, 1), ("left", 0, 0))


def clip_to_square(point: Sequence[float], angle: float, side: float) -> np.ndarray:
    """The chord of the square [-side/2, side/2]^2 along the line through ``point`` at ``angle``
    [rad] to x, shape ``(2, 2)``, from its lower end (smaller parameter along (cos, sin)) to the
    upper one."""
    c = np.asarray(point, float)
    d = np.array([np.cos(angle), np.sin(angle)])
    half = side / 2.0
    if not (np.all(np.abs(c) < half)):
        raise InputError(f"fracture point {tuple(c)} lies outside the square of side {side:g}")
    ts = []
    for k in range(2):
        if abs(d[k]) > 1e-12:
            ts += [(-half - c[k]) / d[k], (half - c[k]) / d[k]]
    ts = np.array(ts)
    ends = c[None] + ts[:, None] * d[None]
    inside = np.all(np.abs(ends) <= half * (1 + 1e-12), axis=1)
    ts = np.sort(ts[inside])
    return np.clip(c[None] + ts[[0, -1], None] * d[None], -half, half)


def fractured_square(side: float, fractures: Sequence[np.ndarray], mesh_size: float, model=None):
    """Mesh the square [-side/2, side/2]^2 with the straight ``fractures`` (each ``(2, 2)``: its
    end points, inside the square or on its edges) embedded; element size ``mesh_size``
    everywhere. Returns the model."""
    import gmsh  # noqa: PLC0415

    if not (np.isfinite(side) and side > 0):
        raise InputError(f"side = {side!r} must be a positive length [m]")
    if not (np.isfinite(mesh_size) and 0 < mesh_size <= side / 2):
        raise InputError(f"mesh_size = {mesh_size!r} must be positive and at most half the side ({side / 2:g} m)")
    half = side / 2.0
    segs = [np.asarray(f, float).reshape(2, 2) for f in fractures]
    for s in segs:
        if np.any(np.abs(s) > half * (1 + 1e-12)) or np.linalg.norm(s[1] - s[0]) < mesh_size:
            raise InputError(f"fracture {s.tolist()} must lie in the square and be longer than mesh_size")
    model = model or gmsh.model
    occ = model.occ
    square = occ.addRectangle(-half, -half, 0.0, side, side)
    lines = [occ.addLine(occ.addPoint(*s[0], 0.0), occ.addPoint(*s[1], 0.0)) for s in segs]
    occ.fragment([(2, square)], [(1, line) for line in lines])
    occ.synchronize()
    surfaces = [tag for _, tag in model.getEntities(2)]
    groups: dict[str, list[int]] = {}
    tol = 1e-6 * side
    for _, curve in model.getEntities(1):
        b = np.asarray(model.getBoundingBox(1, curve)).reshape(2, 3)
        for name, axis, end in _SIDES:
            plane = (-half, half)[end]
            if abs(b[0, axis] - plane) <= tol and abs(b[1, axis] - plane) <= tol:
                groups.setdefault(name, []).append(curve)
                break
    for name, _, _ in _SIDES:
        model.setPhysicalName(1, model.addPhysicalGroup(1, groups[name]), name)
    model.setPhysicalName(2, model.addPhysicalGroup(2, surfaces), "solid")
    before = {k: gmsh.option.getNumber(k) for k in ("Mesh.MeshSizeFromPoints", "Mesh.MeshSizeMin",
                                                    "Mesh.MeshSizeMax", "Mesh.ElementOrder", "Mesh.RecombineAll")}
    try:
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0.0)
        gmsh.option.setNumber("Mesh.MeshSizeMin", mesh_size)
        gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)
        gmsh.option.setNumber("Mesh.ElementOrder", 1.0)
        gmsh.option.setNumber("Mesh.RecombineAll", 0.0)
        model.mesh.generate(2)
    finally:
        for k, v in before.items():
            gmsh.option.setNumber(k, v)
    return model
