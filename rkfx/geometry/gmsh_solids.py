"""Three-dimensional gmsh models of the 3-D benchmarks, meshed with linear tetrahedra.

Each builder adds its solid to a gmsh model (the current one by default), names the boundary
parts as 2-D physical groups and the solid as the 3-D group ``solid``, and meshes it in 3-D.
The same model then gives the RKPM particles (``rkfx.geometry.gmsh_nodes.from_gmsh_3d``) and
the dolfinx mesh of the FEM baseline (``dolfinx.io.gmsh.model_to_mesh(model, comm, 0, gdim=3)``),
so both methods run on the same geometry and vertices. Import this module only where gmsh is
installed; build inside ``rkfx.geometry.gmsh_nodes.scratch_model`` to keep models apart.

Boundary names:

* ``sphere_octant``: ``x0``, ``y0``, ``z0`` (the symmetry planes x = 0, y = 0, z = 0) and
  ``surface`` (the spherical surface r = radius);
* ``box``: ``left``/``right`` (x = 0 / lx), ``front``/``back`` (y = 0 / ly), ``bottom``/``top``
  (z = 0 / lz);
* ``l_block``: the six planes of the bounding box as for ``box`` and ``notch`` (the two faces of
  the re-entrant corner), a non-convex solid.
"""
import numpy as np

from rkfx.errors import InputError

_SIDES = (("left", 0, 0), ("right", 0, 1), ("front", 1, 0), ("back", 1, 1), ("bottom", 2, 0), ("top", 2, 1))


def _checked(mesh_size: float, **lengths: float) -> None:
    for name, v in lengths.items():
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r} must be a positive length [m]")
    if not (np.isfinite(mesh_size) and 0 < mesh_size <= max(lengths.values())):
        raise InputError(f"mesh_size = {mesh_size!r} must be positive and at most the solid's size "
                         f"({max(lengths.values()):g} m)")


# The options that set the element size here; they are gmsh-session wide, so ``_mesh`` puts
# back the caller's values (a later .geo file keeps its own point sizes).
_SIZE_OPTIONS = {"Mesh.MeshSizeFromPoints": 0.0, "Mesh.MeshSizeMin": None, "Mesh.MeshSizeMax": None,
                 "Mesh.ElementOrder": 1.0, "Mesh.RecombineAll": 0.0}


def _mesh(model, mesh_size: float) -> None:
    """Mesh the model's solid with linear tetrahedra whose size is ``mesh_size`` everywhere (the
    OCC points' own sizes are ignored, so halving ``mesh_size`` halves the spacing)."""
    import gmsh  # noqa: PLC0415

    model.occ.synchronize()
    before = {name: gmsh.option.getNumber(name) for name in _SIZE_OPTIONS}
    try:
        for name, value in _SIZE_OPTIONS.items():
            gmsh.option.setNumber(name, mesh_size if value is None else value)
        model.mesh.generate(3)
    finally:
        for name, value in before.items():
            gmsh.option.setNumber(name, value)


def _name_faces(model, bounds: np.ndarray, volume: int, other: str | None) -> None:
    """Name each face of ``volume`` by the side of the bounding box ``bounds`` (2, 3) it lies on;
    faces on none of them go to the group ``other``."""
    lo, hi = bounds
    tol = 1e-6 * float(np.max(hi - lo))  # OCC pads bounding boxes by ~1e-7
    groups: dict[str, list[int]] = {}
    for dim, face in model.getBoundary([(3, volume)], oriented=False):
        b = np.asarray(model.getBoundingBox(dim, face)).reshape(2, 3)
        for name, axis, end in _SIDES:
            plane = (lo, hi)[end][axis]
            if abs(b[0, axis] - plane) <= tol and abs(b[1, axis] - plane) <= tol:
                groups.setdefault(name, []).append(face)
                break
        else:
            if other is None:
                raise RuntimeError(f"face {face} lies on no side of the box")
            groups.setdefault(other, []).append(face)
    for name, faces in groups.items():
        model.setPhysicalName(2, model.addPhysicalGroup(2, faces), name)
    model.setPhysicalName(3, model.addPhysicalGroup(3, [volume]), "solid")


def sphere_octant(radius: float = 1.0, mesh_size: float = 0.1, model=None):
    """The octant x, y, z >= 0 of a sphere of ``radius`` [m] centred at the origin, meshed with
    tetrahedra of size ~ ``mesh_size`` [m]; boundary parts ``x0``, ``y0``, ``z0``, ``surface``.
    Returns the gmsh model."""
    import gmsh  # noqa: PLC0415

    _checked(mesh_size, radius=radius)
    model = model or gmsh.model
    ball = model.occ.addSphere(0.0, 0.0, 0.0, radius)
    corner = model.occ.addBox(0.0, 0.0, 0.0, 2.0 * radius, 2.0 * radius, 2.0 * radius)
    (solid,), _ = model.occ.intersect([(3, ball)], [(3, corner)])
    model.occ.synchronize()
    names = {}
    tol = 1e-6 * radius  # OCC pads bounding boxes by ~1e-7
    for dim, face in model.getBoundary([solid], oriented=False):
        b = np.asarray(model.getBoundingBox(dim, face)).reshape(2, 3)
        flat = [axis for axis in range(3) if abs(b[0, axis]) <= tol and abs(b[1, axis]) <= tol]
        names.setdefault("xyz"[flat[0]] + "0" if flat else "surface", []).append(face)
    for name, faces in names.items():
        model.setPhysicalName(2, model.addPhysicalGroup(2, faces), name)
    model.setPhysicalName(3, model.addPhysicalGroup(3, [solid[1]]), "solid")
    _mesh(model, mesh_size)
    return model


def box(lx: float = 1.0, ly: float = 1.0, lz: float = 1.0, mesh_size: float = 0.1, model=None):
    """The box [0, lx] x [0, ly] x [0, lz] [m] meshed with tetrahedra of size ~ ``mesh_size`` [m];
    boundary parts ``left``, ``right``, ``front``, ``back``, ``bottom``, ``top``. Returns the model."""
    import gmsh  # noqa: PLC0415

    _checked(mesh_size, lx=lx, ly=ly, lz=lz)
    model = model or gmsh.model
    vol = model.occ.addBox(0.0, 0.0, 0.0, lx, ly, lz)
    model.occ.synchronize()
    _name_faces(model, np.array([[0.0, 0.0, 0.0], [lx, ly, lz]]), vol, None)
    _mesh(model, mesh_size)
    return model


def l_block(size: float = 1.0, notch: float = 0.5, height: float = 1.0, mesh_size: float = 0.1, model=None):
    """A non-convex prism: the box [0, size]^2 x [0, height] without the corner column
    [size - notch, size]^2 x [0, height] [m], meshed with tetrahedra of size ~ ``mesh_size`` [m].
    Boundary parts: the bounding box's ``left``, ``right``, ``front``, ``back``, ``bottom``,
    ``top`` and ``notch`` (the two faces of the re-entrant edge). Returns the model."""
    import gmsh  # noqa: PLC0415

    _checked(mesh_size, size=size, height=height, notch=notch)
    if not notch < size:
        raise InputError(f"notch = {notch!r} must be smaller than size = {size!r}")
    model = model or gmsh.model
    whole = model.occ.addBox(0.0, 0.0, 0.0, size, size, height)
    corner = model.occ.addBox(size - notch, size - notch, 0.0, notch, notch, height)
    (solid,), _ = model.occ.cut([(3, whole)], [(3, corner)])
    model.occ.synchronize()
    _name_faces(model, np.array([[0.0, 0.0, 0.0], [size, size, height]]), solid[1], "notch")
    _mesh(model, mesh_size)
    return model
