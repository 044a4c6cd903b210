"""dolfinx meshes of gmsh models: the FEM baselines on the geometry the RKPM solvers read.

A gmsh model (e.g. one of ``rkfx.geometry.gmsh_solids``: ``sphere_octant``, ``box``,
``l_block``, meshed with linear tetrahedra) is read on one rank and distributed over the
communicator by :func:`dolfinx.io.gmsh.model_to_mesh`. The result is dolfinx's ``MeshData``:
the mesh, its cell and facet tags and the physical groups by name, so that
``fem_baselines.conditions.BoundaryParts`` resolves the parts by the names the builders give
(``x0``, ``surface``, ``left``, ``notch``, ...). Every FEM baseline that takes a mesh also takes
this ``MeshData`` (:func:`mesh_parts`).

Only rank 0 (``rank``) needs the model; the other ranks may pass ``None``. Errors found on that
rank (no mesh, no physical group of the solid) are raised on every rank, so no rank waits for a
broadcast that never comes.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import nullcontext
from typing import Any

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

from mpi4py import MPI

import dolfinx
import dolfinx.io.gmsh
import dolfinx.mesh

from rkfx.errors import InputError

__all__ = ["build_mesh", "mesh_from_gmsh", "mesh_parts"]


def _check_model(model: Any, gdim: int) -> str | None:
    """Why ``model`` cannot give a gdim-dimensional mesh, or None (read on the root rank only)."""
    if model is None:
        return "no gmsh model on the reading rank; pass gmsh.model there"
    if len(model.mesh.getNodes()[0]) == 0:
        return f"the gmsh model has no mesh; call gmsh.model.mesh.generate({gdim}) first"
    if not model.getPhysicalGroups(gdim):
        return (f"the gmsh model has no physical group of dimension {gdim} (the solid); add one with "
                f"gmsh.model.addPhysicalGroup({gdim}, ...)")
    types = {int(t) for _, e in model.getEntities(gdim) for t in model.mesh.getElements(gdim, e)[0]}
    if not types:
        return f"the gmsh model has no elements of dimension {gdim}; call gmsh.model.mesh.generate({gdim})"
    return None


def _raise_everywhere(comm: MPI.Comm, rank: int, error: Exception | None) -> None:
    """Raise ``error``, found on ``rank`` (None elsewhere), on every rank of ``comm``.

    The other ranks raise an ``InputError`` (a ``RuntimeError`` for anything else) with the
    same one-line message.
    """
    said = None if error is None else (isinstance(error, InputError), f"{error}")
    if comm.size > 1:
        said = comm.bcast(said, root=rank)
    if error is not None:
        raise error
    if said is not None:
        raise (InputError if said[0] else RuntimeError)(said[1])


def mesh_from_gmsh(model: Any = None, comm: MPI.Comm | None = None, gdim: int = 3,
                   rank: int = 0) -> dolfinx.io.gmsh.MeshData:
    """The distributed dolfinx mesh of a meshed gmsh model, with its tags and physical names.

    Collective on ``comm``.

    Args:
        model: ``gmsh.model`` already meshed in ``gdim`` dimensions, with a physical group of
            dimension ``gdim`` for the solid (its cells) and groups of dimension ``gdim - 1``
            naming boundary parts; needed on ``rank`` only. Default: ``gmsh.model`` there.
        comm: MPI communicator; defaults to ``MPI.COMM_WORLD``.
        gdim: Geometric dimension of the mesh: 3 for the solids of ``rkfx.geometry.gmsh_solids``
            (tetrahedra), 2 for plane models (triangles).
        rank: The rank that holds the model.

    Returns:
        dolfinx's ``MeshData``: ``mesh`` (cells of dimension gdim), ``cell_tags``,
        ``facet_tags`` (the boundary groups' tags on the local facets) and
        ``physical_groups`` (name -> (dim, tag), the same on every rank).

    Raises:
        rkfx.errors.InputError: On every rank, if the model has no mesh, no elements of
            dimension gdim or no physical group of that dimension.
    """
    comm = MPI.COMM_WORLD if comm is None else comm
    if gdim not in (2, 3):
        raise InputError(f"gdim = {gdim!r}: the FEM baselines take plane (2) or solid (3) gmsh models")
    error = None
    if comm.rank == rank:
        if model is None:
            import gmsh  # noqa: PLC0415  (only the reading rank needs gmsh)

            model = gmsh.model
        reason = _check_model(model, gdim)
        error = None if reason is None else InputError(reason)
    _raise_everywhere(comm, rank, error)
    return dolfinx.io.gmsh.model_to_mesh(model if comm.rank == rank else None, comm, rank, gdim=gdim)


def build_mesh(builder: Callable[..., Any], *args: Any, comm: MPI.Comm | None = None, gdim: int = 3,
               name: str = "rkfx_fem", **kwargs: Any) -> dolfinx.io.gmsh.MeshData:
    """Build a gmsh model on rank 0 with ``builder`` and distribute its mesh over ``comm``.

    The model is built in a scratch model (``rkfx.geometry.gmsh_nodes.scratch_model``), which is
    removed afterwards; the other ranks never touch gmsh.

    Args:
        builder: A builder of ``rkfx.geometry.gmsh_solids`` (``box``, ``sphere_octant``,
            ``l_block``) or any function ``builder(*args, model=gmsh.model, **kwargs)`` that adds
            and meshes a model with physical groups.
        *args, **kwargs: The builder's arguments (lengths and ``mesh_size`` [m]).
        comm: MPI communicator; defaults to ``MPI.COMM_WORLD``.
        gdim: Geometric dimension of the model (3 for the solids).
        name: The scratch model's name.

    Returns:
        As :func:`mesh_from_gmsh`.

    Raises:
        rkfx.errors.InputError: On every rank, if the builder refuses its arguments on rank 0
            (the message is the builder's; another error of the builder is a RuntimeError on
            the other ranks).

    Example:
        >>> from rkfx.geometry import gmsh_solids
        >>> data = build_mesh(gmsh_solids.sphere_octant, radius=1.0, mesh_size=0.2)
        >>> sorted(data.physical_groups)  # doctest: +SKIP
        ['solid', 'surface', 'x0', 'y0', 'z0']
    """
    comm = MPI.COMM_WORLD if comm is None else comm
    root = comm.rank == 0
    if root:
        from rkfx.geometry.gmsh_nodes import scratch_model  # noqa: PLC0415  (gmsh on rank 0 only)

        scratch = scratch_model(name)
    else:
        scratch = nullcontext(None)
    with scratch as model:
        error = None
        if root:
            try:
                builder(*args, model=model, **kwargs)
            except Exception as e:  # noqa: BLE001 - re-raised on every rank just below
                error = e
        _raise_everywhere(comm, 0, error)
        return mesh_from_gmsh(model, comm, gdim, rank=0)


def mesh_parts(geometry: Any) -> tuple[dolfinx.mesh.Mesh, Any, dict[str, Any]]:
    """``(mesh, facet_tags, physical_groups)`` of a bare mesh or of gmsh ``MeshData``.

    Args:
        geometry: A :class:`dolfinx.mesh.Mesh` (no tags: parts are sides of the bounding box or
            markers) or the ``MeshData`` of :func:`mesh_from_gmsh` / :func:`build_mesh`.
    """
    if isinstance(geometry, dolfinx.io.gmsh.MeshData):
        return geometry.mesh, geometry.facet_tags, dict(geometry.physical_groups)
    if isinstance(geometry, dolfinx.mesh.Mesh):
        return geometry, None, {}
    raise InputError(f"got {type(geometry).__name__} for the mesh; give a dolfinx Mesh or the MeshData of "
                     "fem_baselines.gmsh_mesh.mesh_from_gmsh")
