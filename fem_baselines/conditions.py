"""The boundary conditions of ``rkfx.conditions`` on dolfinx meshes: what the FEM baselines share.

A condition's part (:data:`Part`) is resolved to local facets by :class:`BoundaryParts`: the name
of a gmsh physical group (when the mesh came from gmsh with facet tags, e.g. by
``fem_baselines.gmsh_mesh.mesh_from_gmsh``), a side of the mesh's bounding box (located by
coordinates: ``"left"``, ``"right"``, ``"bottom"``, ``"top"`` in 2-D (:data:`SIDES`);
``"left"``/``"right"`` (x), ``"front"``/``"back"`` (y), ``"bottom"``/``"top"`` (z) in 3-D
(:data:`SIDES_3D`, the names of ``rkfx.geometry.gmsh_solids.box``)), an int facet tag, or a
marker ``marker(x) -> bool (m,)`` with x of shape ``(m, gdim)`` (dolfinx's ``X`` of shape
``(3, m)`` is passed as ``X[:gdim].T``; a facet belongs to the part when the marker holds at all
its vertices). Facets are edges of triangles or quadrilaterals in 2-D and triangles of tetrahedra
in 3-D.

Values are evaluated by ``rkfx.conditions.values`` at dolfinx's interpolation points and
returned in dolfinx's layout (:func:`at_points`); tractions and fluxes given as ``value(x, t, n)``
get n, the outward unit normal of the part's facet nearest to each point (by facet midpoint,
the centroid of a triangle in 3-D: in 2-D exact for the Lagrange points on the facets up to
degree 3; on a flat part in 3-D every facet has the part's normal, and on a curved one -- the
``surface`` of a sphere -- a point on a facet's edge may take the normal of the facet next to
it, a difference of the order of the facets' angle). The data is continuous: at a vertex where
one part turns a corner it takes one facet's normal, so give each side of a corner its own
condition. Data of a part is interpolated on the cells next to its facets only
(:meth:`BoundaryParts.interpolate`): those carry every dof that a ``ds`` integral or a Dirichlet
condition on the part reads.

Unknown parts, parts without facets, bad markers and conditions of the wrong kind raise a
one-line ``rkfx.errors.InputError`` naming the part and the fix. Resolving a part is collective
on the mesh communicator (it checks that some rank has facets of it).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import numpy as np
from mpi4py import MPI
from scipy.spatial import cKDTree

import dolfinx
import dolfinx.fem
import dolfinx.mesh

from rkfx.conditions import NATURAL, Condition, Region, split, values
from rkfx.errors import InputError

__all__ = ["SIDES", "SIDES_3D", "BoundaryParts", "Part", "at_points", "check_kinds", "sides"]

#: A boundary part: a physical-group name or a side of the bounding box (str), a facet tag
#: (int), or a marker ``marker(x) -> bool (m,)`` with x of shape (m, gdim).
Part = str | int | Callable[[np.ndarray], np.ndarray]

#: The sides of a 2-D mesh's bounding box that name parts without facet tags: (axis, lower side?).
SIDES = {"left": (0, True), "right": (0, False), "bottom": (1, True), "top": (1, False)}

#: The sides of a 3-D mesh's bounding box, named as ``rkfx.geometry.gmsh_solids.box`` names the
#: faces of a box (z is up): (axis, lower side?).
SIDES_3D = {"left": (0, True), "right": (0, False), "front": (1, True), "back": (1, False),
            "bottom": (2, True), "top": (2, False)}


def sides(gdim: int) -> dict[str, tuple[int, bool]]:
    """The bounding-box sides that name parts on a mesh of geometric dimension ``gdim``."""
    return SIDES_3D if gdim == 3 else SIDES


def _describe(part: Any) -> str:
    """The part as an error message names it."""
    if callable(part):
        return f"marker {getattr(part, '__qualname__', repr(part))}"
    if isinstance(part, (int, np.integer)) and not isinstance(part, bool):
        return f"facet tag {int(part)}"
    return repr(part)


def check_kinds(conditions: Sequence[Condition], allowed: tuple[type, ...], solver: str,
                gdim: int = 2) -> dict[type, list]:
    """The conditions grouped by kind (``rkfx.conditions.split``).

    Kinds ``solver`` cannot take, and vector components beyond ``gdim``, raise.
    """
    kinds = split(conditions)
    names = ", ".join(k.__name__ for k in allowed)
    for kind, found in kinds.items():
        if found and kind not in allowed:
            raise InputError(f"{solver} takes no {kind.__name__} conditions (on {_describe(found[0].boundary)}); "
                             f"give {names} from rkfx.conditions")
        for c in found:
            if max(c.prescribed(gdim)) >= gdim:
                raise InputError(f"{kind.__name__} on {_describe(c.boundary)}: components {c.components} on a "
                                 f"{gdim}D mesh; use components below {gdim}")
    return kinds


def at_points(condition: Condition, X: np.ndarray, t: float, gdim: int, n: np.ndarray | None = None,
              shape: tuple[int, ...] = ()) -> np.ndarray:
    """A condition's value at dolfinx points in dolfinx's layout.

    Args:
        condition: A condition of ``rkfx.conditions``.
        X: Points from dolfinx, shape (3, npts) [m].
        t: Time [s].
        gdim: Geometric dimension (the rows of X that are coordinates).
        n: Outward unit normals, shape (npts, gdim), for tractions and fluxes given as functions.
        shape: ``()`` for a scalar field, ``(k,)`` for a vector field of k components (the
            unlisted components are 0).

    Returns:
        Shape (npts,) for a scalar field, (k, npts) for a vector field.
    """
    npts = X.shape[1]
    components = list(condition.prescribed(gdim))
    v = values(condition, X[:gdim].T, t, n) if npts else np.zeros((0, len(components)))
    if not shape:
        return np.ascontiguousarray(v[:, 0])
    out = np.zeros((shape[0], npts))
    out[components] = v.T
    return out


def _outward_normals(mesh: dolfinx.mesh.Mesh, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Midpoints and outward unit normals, both (nf, gdim), of exterior facets of a 2D or 3D mesh.

    A 2-D facet is a segment (normal: the tangent turned by 90 degrees), a 3-D facet a triangle
    (normal: the cross product of two edges; its midpoint is the centroid). Either normal is
    turned away from the centre of the facet's one cell.
    """
    fdim, x, gdim = mesh.topology.dim - 1, mesh.geometry.x, mesh.geometry.dim
    corners = dolfinx.mesh.entities_to_geometry(mesh, fdim, facets)[:, :gdim]  # the facets' vertices come first
    if gdim == 2:
        a, b = x[corners[:, 0], :2], x[corners[:, 1], :2]
        mid, tangent = 0.5 * (a + b), b - a
        normal = np.column_stack([tangent[:, 1], -tangent[:, 0]]) / np.linalg.norm(tangent, axis=1)[:, None]
    else:
        # The corners in lexicographic order of their coordinates, not the local numbering: a facet
        # shared by two ranks then gets bit-identical midpoint and normal on both.
        p = x[corners]  # (nf, 3, 3)
        order = np.lexsort((p[:, :, 2], p[:, :, 1], p[:, :, 0]), axis=1)
        a, b, c = (np.take_along_axis(p, order[:, i, None, None], axis=1)[:, 0] for i in range(3))
        mid, normal = (a + b + c) / 3.0, np.cross(b - a, c - a)
        normal /= np.maximum(np.linalg.norm(normal, axis=1), np.finfo(float).tiny)[:, None]
    f2c = mesh.topology.connectivity(fdim, mesh.topology.dim)
    cells = np.asarray(f2c.array)[np.asarray(f2c.offsets)[facets]]  # the one cell of an exterior facet
    centre = x[dolfinx.mesh.entities_to_geometry(mesh, mesh.topology.dim, cells), :gdim].mean(axis=1)
    normal[np.einsum("ij,ij->i", normal, mid - centre) < 0] *= -1.0
    return mid, normal


class BoundaryParts:
    """The boundary parts of one dolfinx mesh, resolved to local facets once each.

    Args:
        mesh: A dolfinx mesh.
        facet_tags: Facet MeshTags (from gmsh), or None.
        physical_groups: Physical-group name -> (dim, tag) (from gmsh); names found here come
            before the sides of the bounding box.
    """

    def __init__(self, mesh: dolfinx.mesh.Mesh, facet_tags: Any = None,
                 physical_groups: Mapping[str, Any] | None = None):
        self.mesh, self.facet_tags = mesh, facet_tags
        self.physical_groups = dict(physical_groups or {})
        self.fdim, self.gdim = mesh.topology.dim - 1, mesh.geometry.dim
        mesh.topology.create_connectivity(self.fdim, mesh.topology.dim)
        self._facets: dict[Any, np.ndarray] = {}
        self._normals: dict[Any, tuple[cKDTree, np.ndarray]] = {}
        self._box: tuple[np.ndarray, np.ndarray] | None = None

    # ------------------------------------------------------------------ facets

    def facets(self, part: Part) -> np.ndarray:
        """Sorted local indices (int32) of the part's facets. Collective on first use of a part."""
        key = (type(part).__name__, part) if not callable(part) else part
        if key not in self._facets:
            found = np.unique(np.asarray(self._locate(part), dtype=np.int32))
            if self.mesh.comm.allreduce(found.size, op=MPI.SUM) == 0:
                raise InputError(f"boundary part {_describe(part)} has no facets on the mesh's boundary; "
                                 "check its name or marker")
            self._facets[key] = found
        return self._facets[key]

    def _locate(self, part: Part) -> np.ndarray:
        mesh, fdim = self.mesh, self.fdim
        if callable(part):
            return dolfinx.mesh.locate_entities_boundary(mesh, fdim, self._marker(part))
        if isinstance(part, str):
            if part in self.physical_groups:
                dim, tag = self.physical_groups[part]
                if dim != fdim:
                    raise InputError(f"boundary part {part!r} is a physical group of dimension {dim}; name one "
                                     f"of dimension {fdim} (facets)")
                return self._tagged(part, tag)
            if part in sides(self.gdim):
                return dolfinx.mesh.locate_entities_boundary(mesh, fdim, self._side(part))
            groups = sorted(n for n, (d, _) in self.physical_groups.items() if d == fdim)
            raise InputError(f"no boundary part {part!r}: name a physical group {groups}, a side of the bounding "
                             f"box {list(sides(self.gdim))}, or give a marker x -> bool with x of shape "
                             f"(m, {self.gdim})")
        if isinstance(part, (int, np.integer)) and not isinstance(part, bool):
            return self._tagged(part, int(part))
        if isinstance(part, Region):
            raise InputError(f"region {part.name!r} lies inside the domain; the FEM baselines prescribe values on "
                             "boundary facets only: give a boundary part (name, tag or marker)")
        raise InputError(f"boundary part {part!r}: give a name (str), a facet tag (int) or a marker x -> bool "
                         f"with x of shape (m, {self.gdim})")

    def _tagged(self, part: Part, tag: int) -> np.ndarray:
        if self.facet_tags is None:
            raise InputError(f"boundary part {_describe(part)} needs facet tags and the mesh has none; "
                             "mesh with gmsh physical groups or give a marker")
        return self.facet_tags.find(int(tag))

    def _marker(self, marker: Callable) -> Callable[[np.ndarray], np.ndarray]:
        """The rkfx marker ``marker(x (m, gdim))`` as dolfinx calls markers: ``m(X (3, m))``."""
        gdim = self.gdim

        def on(X):
            inside = np.asarray(marker(X[:gdim].T))
            if inside.shape != (X.shape[1],):
                raise InputError(f"{_describe(marker)} returned shape {inside.shape} for {X.shape[1]} points; return "
                                 f"a bool array (m,) for x of shape (m, {gdim})")
            return inside.astype(bool, copy=False)

        return on

    def _side(self, side: str) -> Callable[[np.ndarray], np.ndarray]:
        """Marker (dolfinx's layout) of a side of the mesh's bounding box, within 1e-10 of its size."""
        if self._box is None:
            x = self.mesh.geometry.x[:, : self.gdim]
            lo = np.full(self.gdim, np.inf) if x.size == 0 else x.min(axis=0)
            hi = np.full(self.gdim, -np.inf) if x.size == 0 else x.max(axis=0)
            self.mesh.comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
            self.mesh.comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
            self._box = lo, hi
        lo, hi = self._box
        tol = 1e-10 * float(np.max(hi - lo))
        axis, lower = sides(self.gdim)[side]
        value = lo[axis] if lower else hi[axis]
        return lambda X: np.abs(X[axis] - value) <= tol

    def cells(self, part: Part) -> np.ndarray:
        """Sorted local cells (int32) next to the part's facets."""
        f2c = self.mesh.topology.connectivity(self.fdim, self.mesh.topology.dim)
        offsets, links = np.asarray(f2c.offsets), np.asarray(f2c.array)
        f = self.facets(part)
        return np.unique(np.concatenate([links[offsets[f]], links[offsets[f + 1] - 1]])).astype(np.int32)

    def tags(self, parts: Iterable[Part], what: str) -> dolfinx.mesh.MeshTags:
        """Facet MeshTags giving part i the tag i + 1; overlapping parts raise."""
        parts = list(parts)
        found = [self.facets(p) for p in parts]
        facets = np.concatenate([np.zeros(0, np.int32)] + found)
        tag = np.concatenate([np.zeros(0, np.int32)] + [np.full(f.size, i + 1, np.int32) for i, f in enumerate(found)])
        order = np.argsort(facets, kind="stable")
        facets, tag = facets[order], tag[order]
        shared = np.flatnonzero(np.diff(facets) == 0)
        if shared.size:
            a, b = parts[tag[shared[0]] - 1], parts[tag[shared[0] + 1] - 1]
            raise InputError(f"{what} parts {_describe(a)} and {_describe(b)} share facets; give each facet one {what}")
        return dolfinx.mesh.meshtags(self.mesh, self.fdim, facets, tag)

    # ------------------------------------------------------------------ data

    def normals(self, part: Part, x: np.ndarray) -> np.ndarray:
        """Outward unit normal of the part's facet (by midpoint) nearest to each point x (m, gdim).

        Collective on first use of a part when the mesh is distributed: every rank then looks
        among the facets of all ranks, so that a point gets the same normal however the mesh is
        split (on a curved part the nearest local facet would depend on the partition).
        """
        tree, normal = self._normal_table(part)
        if tree is None:
            return np.full((len(x), self.gdim), np.nan)
        return normal[tree.query(x)[1]]

    def _normal_table(self, part: Part) -> tuple[cKDTree | None, np.ndarray]:
        """The part's facet midpoints (as a k-d tree) and outward normals, built once per part."""
        if self.gdim != self.mesh.topology.dim or self.gdim not in (2, 3):
            raise InputError(f"boundary part {_describe(part)}: normals need a 2D or 3D mesh of cells of its own "
                             "dimension; give a constant value")
        key = (type(part).__name__, part) if not callable(part) else part
        if key not in self._normals:
            mid, normal = _outward_normals(self.mesh, self.facets(part))
            comm = self.mesh.comm
            if comm.size > 1:  # all ranks' facets, each once (shared ones computed bit-identically), sorted
                table = np.concatenate(comm.allgather(np.column_stack([mid, normal])))
                table = np.unique(table, axis=0)
                mid, normal = table[:, : self.gdim], table[:, self.gdim:]
            self._normals[key] = (cKDTree(mid) if len(mid) else None, normal)
        return self._normals[key]

    def interpolate(self, fn: dolfinx.fem.Function, condition: Condition, t: float) -> None:
        """fn = the condition's value at t on the cells next to its part (the other dofs are left alone).

        Tractions and fluxes given as ``value(x, t, n)`` get the outward normals of
        :meth:`normals`; a scalar fn takes the first prescribed component. Collective on the
        mesh communicator.
        """
        shape = tuple(fn.function_space.value_shape)
        part, gdim = condition.boundary, self.gdim
        want_n = isinstance(condition, NATURAL) and callable(condition.value)
        if want_n:
            self._normal_table(part)  # collective: before dolfinx calls data() on the ranks that have points

        def data(X):
            n = self.normals(part, X[:gdim].T) if want_n and X.shape[1] else None
            return at_points(condition, X, t, gdim, n, shape)

        fn.interpolate(data, cells0=self.cells(part))
