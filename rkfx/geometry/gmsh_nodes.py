"""Particles from gmsh geometry: a ``.geo`` file or a model built with the gmsh Python API.

The 2-D mesh's vertices become the nodes and its triangles the background triangulation of
the nodal domains; 1-D physical groups name the boundary parts. Import this module only
where gmsh is installed (``pip install rkfx[geometry]``).
"""
from pathlib import Path

import numpy as np

from rkfx.errors import InputError
from rkfx.geometry.particles import Particles, particles


def from_gmsh(model=None, comm=None) -> Particles:
    """Particles from the current 2-D mesh of a gmsh model.

    Args:
        model: ``gmsh.model`` (already meshed in 2-D); default the current model.
        comm: MPI communicator. The mesh is read on rank 0 and broadcast, so every rank holds
            the same node set.
    """
    rank = comm.rank if comm is not None else 0
    data = _read(model) if rank == 0 else None
    if comm is not None and comm.size > 1:
        data = comm.bcast(data, root=0)
    x, tri, edges = data
    return particles(x, tri, edges)


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


def from_geo(path: str | Path, mesh_size: float | None = None, comm=None) -> Particles:
    """Particles from a gmsh ``.geo`` file, meshed in 2-D (optionally with a global mesh size [m])."""
    import gmsh  # noqa: PLC0415

    path = Path(path)
    if not path.is_file():
        raise InputError(f"geometry file {str(path)!r} not found")
    rank = comm.rank if comm is not None else 0
    data = None
    if rank == 0:
        started = gmsh.isInitialized()
        if not started:
            gmsh.initialize(interruptible=False)
        gmsh.option.setNumber("General.Terminal", 0)
        try:
            gmsh.model.add(path.stem)
            gmsh.merge(str(path))
            if mesh_size is not None:
                gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)
                gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
            gmsh.model.mesh.generate(2)
            data = _read(gmsh.model)
            gmsh.model.remove()
        finally:
            if not started:
                gmsh.finalize()
    if comm is not None and comm.size > 1:
        data = comm.bcast(data, root=0)
    return particles(*data)
