"""Particles from gmsh geometry: a ``.geo`` file or a model built with the gmsh Python API.

The 2-D mesh's vertices become the nodes and its triangles the background triangulation of
the nodal domains; 1-D physical groups name the boundary parts. In 3-D (``from_gmsh_3d``) the
tetrahedra's vertices become the nodes and 2-D physical groups name the boundary parts.
Import this module only where gmsh is installed (``pip install rkfx[geometry]``).
"""
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from rkfx.errors import InputError
from rkfx.geometry.particles import Particles, particles
from rkfx.geometry.particles3d import Particles3D, particles3d


@contextmanager
def scratch_model(name: str) -> Iterator:
    """A new gmsh model named ``name`` in the caller's gmsh session, or in one opened (and closed)
    here, with gmsh's terminal output off; the model is removed on exit. Yields ``gmsh.model``."""
    import gmsh  # noqa: PLC0415

    started = gmsh.isInitialized()
    if not started:
        gmsh.initialize(interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.model.add(name)
        try:
            yield gmsh.model
        finally:
            gmsh.model.remove()
    finally:
        if not started:
            gmsh.finalize()


def from_gmsh(model=None, comm=None) -> Particles:
    """Particles from the current 2-D mesh of a gmsh model.

    Args:
        model: ``gmsh.model`` (already meshed in 2-D); default the current model.
        comm: MPI communicator. The mesh is read on rank 0 and broadcast, so every rank holds
            the same node set.
    """
    x, tri, edges = _on_rank_zero(lambda: _read(model), comm)
    return particles(x, tri, edges)


def _on_rank_zero(read, comm):
    """``read()`` on rank 0 and its result broadcast to every rank; an ``InputError`` it raises
    is raised on every rank (the others would otherwise wait in the broadcast)."""
    rank = comm.rank if comm is not None else 0
    data = None
    if rank == 0:
        try:
            data = read()
        except InputError as error:
            data = error
    if comm is not None and comm.size > 1:
        data = comm.bcast(data, root=0)
    if isinstance(data, InputError):
        raise data
    return data


def _read(model):
    import gmsh  # noqa: PLC0415

    model = model or gmsh.model
    tags, coords, _ = model.mesh.getNodes()
    if len(tags) == 0:
        raise InputError("the gmsh model has no mesh; call gmsh.model.mesh.generate(2) first")
    index = np.full(int(tags.max()) + 1, -1, np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    x = coords.reshape(-1, 3)[:, :2]
    groups2 = model.getPhysicalGroups(2)
    surfaces = [e for _, g in groups2 for e in model.getEntitiesForPhysicalGroup(2, g)] if groups2 \
        else [e for _, e in model.getEntities(2)]
    tri = []
    for s in surfaces:
        types, _, nodes = model.mesh.getElements(2, s)
        for t, nd in zip(types, nodes):
            if t != 2:
                raise InputError(f"surface {s} has gmsh element type {t}; rkfx needs linear triangles "
                                 "(set Mesh.RecombineAll = 0 and Mesh.ElementOrder = 1)")
            tri.append(index[nd.astype(np.int64)].reshape(-1, 3))
    if not tri:
        raise InputError("the gmsh model has no 2-D elements; mesh a surface first")
    tri = np.concatenate(tri)
    edges = {}
    for dim, g in model.getPhysicalGroups(1):
        name = model.getPhysicalName(dim, g) or f"boundary_{g}"
        part = []
        for c in model.getEntitiesForPhysicalGroup(dim, g):
            for t, nd in zip(*model.mesh.getElements(1, c)[::2]):
                if t != 1:
                    raise InputError(f"curve {c} has gmsh element type {t}; use linear elements")
                part.append(index[nd.astype(np.int64)].reshape(-1, 2))
        edges[name] = np.concatenate(part) if part else np.empty((0, 2), np.int64)
    # Keep only nodes that belong to the surface mesh (gmsh may keep geometry points).
    used = np.unique(tri)
    renum = np.full(len(x), -1, np.int64)
    renum[used] = np.arange(len(used))
    return x[used], renum[tri], {k: renum[v] for k, v in edges.items()}


def from_gmsh_3d(model=None, comm=None) -> Particles3D:
    """Particles3D from the current 3-D mesh of a gmsh model (linear tetrahedra).

    The tetrahedra of the model's 3-D physical groups (of all its volumes if it has none) are
    the tetrahedralization; nodes in no tetrahedron are dropped and the rest renumbered in
    gmsh's order. Each 2-D physical group names a boundary part (its triangles must lie on the
    solid's boundary).

    Args:
        model: ``gmsh.model``, already meshed in 3-D; default the current model.
        comm: MPI communicator. The mesh is read on rank 0 and broadcast, so every rank holds
            the same node set.

    Raises:
        InputError: The model has no 3-D mesh, is meshed with other elements than linear
            tetrahedra (and triangles on the named faces), or fails ``particles3d``'s checks.
    """
    x, tets, faces = _on_rank_zero(lambda: _read_3d(model), comm)
    return particles3d(x, tets, faces)


def _read_3d(model):
    import gmsh  # noqa: PLC0415

    model = model or gmsh.model
    tags, coords, _ = model.mesh.getNodes()
    if len(tags) == 0:
        raise InputError("the gmsh model has no mesh; call gmsh.model.mesh.generate(3) first")
    index = np.full(int(tags.max()) + 1, -1, np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    x = coords.reshape(-1, 3)
    groups3 = model.getPhysicalGroups(3)
    volumes = sorted({e for _, g in groups3 for e in model.getEntitiesForPhysicalGroup(3, g)}) if groups3 \
        else [e for _, e in model.getEntities(3)]
    tets = []
    for v in volumes:
        for t, nd in zip(*model.mesh.getElements(3, v)[::2]):
            if t != 4:
                name = model.mesh.getElementProperties(t)[0]
                raise InputError(f"volume {v} has gmsh element type {t} ({name}); rkfx needs linear tetrahedra "
                                 "(set Mesh.ElementOrder = 1, Mesh.RecombineAll = 0 and no Mesh.SubdivisionAlgorithm "
                                 "before gmsh.model.mesh.generate(3))")
            tets.append(index[nd.astype(np.int64)].reshape(-1, 4))
    if not tets or sum(len(t) for t in tets) == 0:
        raise InputError("the gmsh model has no 3-D mesh (no tetrahedra); call gmsh.model.mesh.generate(3) first")
    tets = np.concatenate(tets)
    faces = {}
    for dim, g in model.getPhysicalGroups(2):
        name = model.getPhysicalName(dim, g) or f"boundary_{g}"
        part = []
        for s in model.getEntitiesForPhysicalGroup(dim, g):
            for t, nd in zip(*model.mesh.getElements(2, s)[::2]):
                if t != 2:
                    raise InputError(f"surface {s} of boundary {name!r} has gmsh element type {t}; rkfx needs "
                                     "linear triangles on the boundary (Mesh.ElementOrder = 1, Mesh.RecombineAll = 0)")
                part.append(index[nd.astype(np.int64)].reshape(-1, 3))
        faces[name] = np.concatenate(part) if part else np.empty((0, 3), np.int64)
    # Keep only the nodes of the tetrahedra (gmsh keeps geometry points and the nodes of
    # lower-dimensional entities outside the solid).
    used = np.unique(tets)
    renum = np.full(len(x), -1, np.int64)
    renum[used] = np.arange(len(used))
    for name, f in faces.items():
        if f.size and (renum[f] < 0).any():
            raise InputError(f"boundary {name!r} has triangles with nodes in no tetrahedron; "
                             "name only faces of the meshed solid")
    return x[used], renum[tets], {k: renum[v] for k, v in faces.items()}


def from_geo(path: str | Path, mesh_size: float | None = None, comm=None) -> Particles:
    """Particles from a gmsh ``.geo`` file, meshed in 2-D.

    Args:
        path: The ``.geo`` script.
        mesh_size: Optional global maximum mesh size [m].
        comm: MPI communicator. The file is read on rank 0 and the nodes broadcast.

    Raises:
        InputError: The file is missing, empty, binary, defines no surface, or gmsh reports an
            error while reading or meshing it; the message names the file and, where gmsh gives
            one, the line.
    """
    path = Path(path)
    _check_geo_text(path)
    return particles(*_on_rank_zero(lambda: _mesh_geo(path, mesh_size), comm))


def _check_geo_text(path: Path) -> None:
    """Refuse what gmsh would misread: a missing, empty or binary file."""
    if not path.is_file():
        raise InputError(f"geometry file {str(path)!r} not found")
    with path.open("rb") as f:
        head = f.read(8192)
    # Text never holds NUL or most C0 control bytes; gmsh would "read" such a file silently.
    if any(b < 32 and b not in b"\t\n\r\f\v" for b in head):
        raise InputError(f"{path}: not a .geo text file (it holds binary data); "
                         "pass a gmsh .geo script")
    if not head.strip():
        raise InputError(f"{path}: the file is empty, so it defines no surface; "
                         "write the geometry (points, curves, a Plane Surface) into it")


def _mesh_geo(path: Path, mesh_size: float | None):
    """Read and mesh ``path`` in a gmsh session (the caller's, or one opened here).

    gmsh's logger runs while the file is read; General.Terminal and General.AbortOnError come
    back as the caller had them.
    """
    import gmsh  # noqa: PLC0415

    started = gmsh.isInitialized()
    if not started:
        gmsh.initialize(interruptible=False)
    terminal = gmsh.option.getNumber("General.Terminal")
    abort = gmsh.option.getNumber("General.AbortOnError")
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.logger.start()
    try:
        gmsh.model.add(path.stem)
        try:
            # An exception thrown mid-parse leaves the rest of the file in gmsh's lexer, and
            # every later merge in the process fails on it; without the throw the parser reads
            # to the end and the errors are only logged.
            gmsh.option.setNumber("General.AbortOnError", 0)
            gmsh.merge(str(path))
        finally:
            gmsh.option.setNumber("General.AbortOnError", abort)
        _raise_logged_error(path, gmsh.logger.get(), "")
        if not gmsh.model.getEntities(2):
            raise InputError(f"{path}: the file defines no surface; add a Plane Surface to it")
        if mesh_size is not None:
            gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)
            gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
        try:
            gmsh.model.mesh.generate(2)
        except Exception:  # noqa: BLE001 - gmsh raises bare Exception; its log says why
            _raise_logged_error(path, gmsh.logger.get(), "gmsh cannot mesh it: ")
            raise
        return _read(gmsh.model)
    finally:
        gmsh.logger.stop()
        gmsh.model.remove()
        gmsh.option.setNumber("General.Terminal", terminal)
        if not started:
            gmsh.finalize()


_WHERE = re.compile(r"^'[^']*', line (\d+): ")


def _raise_logged_error(path: Path, log: list[str], what: str) -> None:
    """Raise the first error gmsh logged as one line naming ``path`` and the line, if any."""
    errors = [m.removeprefix("Error: ") for m in log if m.startswith("Error: ")]
    if not errors:
        return
    # gmsh often logs the cause without a line and then "'file', line N: Could not add ...".
    line = next((m.group(1) for e in errors if (m := _WHERE.match(e))), None)
    where = f"{path}:{line}" if line else f"{path}"
    cause = " ".join(_WHERE.sub("", errors[0]).split())
    raise InputError(f"{where}: {what}{cause}; fix the file and call from_geo again")
