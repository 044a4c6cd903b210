"""Particles: nodes, their spacing, and the triangulation their nodal domains are cut from.

A ``Particles`` set is the discretisation every rkfx solver starts from. The triangulation's
vertices are the nodes; it carries the geometry (boundary edges tagged by name) and defines
the conforming nodal domains (``rkfx.nodal_domains``). Factories: ``structured`` and
``graded`` tensor grids, ``from_points`` for a cloud inside a polygon, and
``rkfx.gmsh_nodes.from_gmsh`` for gmsh geometry.
"""
from dataclasses import dataclass, field

import numba
import numpy as np
from scipy.spatial import Delaunay

from .errors import InputError, point_str


@dataclass(frozen=True)
class Particles:
    """Nodes with spacing, a conforming triangulation and named boundary parts.

    Attributes:
        x: Node coordinates, shape ``(num_nodes, 2)`` [m].
        spacing: Nodal spacing h_I, shape ``(num_nodes,)`` [m].
        triangles: Counter-clockwise vertex triples, shape ``(num_triangles, 3)``.
        boundary_edges: Boundary edges (i, j), oriented with the domain on the left,
            shape ``(num_boundary_edges, 2)``.
        boundary_tags: Tag of each boundary edge, shape ``(num_boundary_edges,)``; 0 = untagged.
        boundary_names: Name -> tag.
        edges: Unique triangulation edges (i < j), shape ``(num_edges, 2)``.
        triangle_edges: Edge index of side k = (v_k, v_k+1) of each triangle, shape ``(num_triangles, 3)``.
    """

    x: np.ndarray
    spacing: np.ndarray
    triangles: np.ndarray
    boundary_edges: np.ndarray
    boundary_tags: np.ndarray
    boundary_names: dict[str, int] = field(default_factory=dict)
    edges: np.ndarray | None = None
    triangle_edges: np.ndarray | None = None

    @property
    def num_nodes(self) -> int:
        return len(self.x)

    def tag(self, name: str) -> int:
        """Tag of a named boundary part."""
        if name not in self.boundary_names:
            raise InputError(f"unknown boundary {name!r}; this geometry names {sorted(self.boundary_names)}")
        return self.boundary_names[name]

    def boundary_nodes(self, *names: str) -> np.ndarray:
        """Sorted indices of the nodes on the named boundary parts (all parts if none named)."""
        if names:
            mask = np.isin(self.boundary_tags, [self.tag(n) for n in names])
        else:
            mask = np.ones(len(self.boundary_tags), bool)
        return np.unique(self.boundary_edges[mask])

    def area(self) -> float:
        """Area of the triangulated domain [m^2]."""
        return float(_triangle_areas(self.x, self.triangles).sum())


def _triangle_areas(x, tri):
    e1 = x[tri[:, 1]] - x[tri[:, 0]]
    e2 = x[tri[:, 2]] - x[tri[:, 0]]
    return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])


@numba.njit(cache=True)
def unique_edges(tri: np.ndarray, n: int):
    """Unique edges of a triangulation in O(N).

    Returns ``(edges, triangle_edges, count)``: edges (i < j) ordered by i, shape ``(e, 2)``; the
    edge of side (v_k, v_k+1) of each triangle, shape ``(t, 3)``; triangles per edge, shape ``(e,)``.
    """
    nt = tri.shape[0]
    deg = np.zeros(n + 1, np.int64)
    for t in range(nt):
        for k in range(3):
            a, b = tri[t, k], tri[t, (k + 1) % 3]
            deg[min(a, b) + 1] += 1
    for i in range(n):
        deg[i + 1] += deg[i]
    # Candidate partners of each low node (with repeats), then de-duplicated in place.
    partner = np.empty(deg[n], np.int64)
    fill = deg[:-1].copy()
    for t in range(nt):
        for k in range(3):
            a, b = tri[t, k], tri[t, (k + 1) % 3]
            lo = min(a, b)
            partner[fill[lo]] = max(a, b)
            fill[lo] += 1
    start = np.zeros(n + 1, np.int64)
    for i in range(n):
        m = deg[i]
        for q in range(deg[i], deg[i + 1]):
            dup = False
            for r in range(deg[i], m):
                if partner[r] == partner[q]:
                    dup = True
                    break
            if not dup:
                partner[m] = partner[q]
                m += 1
        start[i + 1] = start[i] + (m - deg[i])
    edges = np.empty((start[n], 2), np.int64)
    for i in range(n):
        for q in range(start[i + 1] - start[i]):
            edges[start[i] + q, 0] = i
            edges[start[i] + q, 1] = partner[deg[i] + q]
    triangle_edges = np.empty((nt, 3), np.int64)
    count = np.zeros(start[n], np.int64)
    for t in range(nt):
        for k in range(3):
            a, b = tri[t, k], tri[t, (k + 1) % 3]
            lo, hi = min(a, b), max(a, b)
            for e in range(start[lo], start[lo + 1]):
                if edges[e, 1] == hi:
                    triangle_edges[t, k] = e
                    count[e] += 1
                    break
    return edges, triangle_edges, count


def _edge_keys(edges, n):
    e = np.sort(edges, axis=1).astype(np.int64)
    return e[:, 0] * n + e[:, 1]


def particles(x: np.ndarray, triangles: np.ndarray, tagged_edges: dict[str, np.ndarray] | None = None,
              spacing: np.ndarray | None = None) -> Particles:
    """Validated ``Particles`` from nodes and a triangulation.

    Args:
        x: Node coordinates, shape ``(num_nodes, 2)`` [m].
        triangles: Vertex triples, shape ``(num_triangles, 3)``; any orientation.
        tagged_edges: Boundary part name -> its edges, shape ``(k, 2)`` (node pairs, any order).
        spacing: Nodal spacing h_I, shape ``(num_nodes,)``; default: mean length of the
            triangulation edges at the node.

    Raises:
        InputError: Non-finite or duplicate nodes, degenerate triangles, nodes in no triangle,
            or tagged edges that are not on the boundary.
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    tri = np.ascontiguousarray(triangles, dtype=np.int64)
    n = len(x)
    if x.ndim != 2 or x.shape[1] != 2 or n < 3:
        raise InputError(f"nodes must have shape (num_nodes >= 3, 2), got {x.shape}")
    bad = np.flatnonzero(~np.isfinite(x).all(axis=1))
    if bad.size:
        raise InputError(f"node {bad[0]} has non-finite coordinates {point_str(x[bad[0]])}; remove or fix it")
    used = np.zeros(n, bool)
    used[tri.ravel()] = True
    if not used.all():
        i = int(np.flatnonzero(~used)[0])
        raise InputError(f"node {i} at {point_str(x[i])} belongs to no triangle (outside the geometry or "
                         "a duplicate); remove it or mesh the domain with it")
    area = _triangle_areas(x, tri)
    tri[area < 0] = tri[area < 0][:, [0, 2, 1]]
    area = np.abs(area)
    scale = np.ptp(x, axis=0).max()
    tiny = np.flatnonzero(area <= 1e-13 * scale**2)
    if tiny.size:
        t = tri[tiny[0]]
        raise InputError(f"degenerate triangle {tiny[0]} with nodes {t.tolist()} at {x[t].tolist()}; "
                         "duplicate or collinear nodes — remove duplicates or re-mesh")
    # Boundary edges: those of one triangle, kept in the triangle's counter-clockwise sense.
    edges, tri_edges, counts = unique_edges(tri, n)
    if counts.max() > 2:
        e = edges[np.argmax(counts)]
        raise InputError(f"edge ({e[0]}, {e[1]}) is shared by {counts.max()} triangles; the "
                         "triangulation overlaps itself — re-mesh")
    t_b, k_b = np.nonzero(counts[tri_edges] == 1)
    bedges = np.column_stack([tri[t_b, k_b], tri[t_b, (k_b + 1) % 3]])
    bkeys = _edge_keys(bedges, n)
    tags = np.zeros(len(bedges), np.int64)
    names = {}
    for t, (name, part) in enumerate((tagged_edges or {}).items(), start=1):
        names[name] = t
        ek = _edge_keys(np.asarray(part, dtype=np.int64).reshape(-1, 2), n)
        hit = np.isin(ek, bkeys)
        if not hit.all():
            e = np.asarray(part).reshape(-1, 2)[np.flatnonzero(~hit)[0]]
            raise InputError(f"edge {e.tolist()} of boundary {name!r} is not on the domain boundary")
        tags[np.isin(bkeys, ek)] = t
    if spacing is None:
        spacing = _mean_edge_length(x, edges, n)
    spacing = np.ascontiguousarray(np.broadcast_to(np.asarray(spacing, float), (n,)))
    return Particles(x, spacing, tri, bedges, tags, names, edges, tri_edges)


def _mean_edge_length(x, edges, n):
    i, j = edges[:, 0], edges[:, 1]
    length = np.linalg.norm(x[i] - x[j], axis=1)
    total = np.bincount(i, length, n) + np.bincount(j, length, n)
    count = np.bincount(i, minlength=n) + np.bincount(j, minlength=n)
    return total / count


def graded(xs: np.ndarray, ys: np.ndarray) -> Particles:
    """Tensor-product grid on the coordinate lines ``xs`` x ``ys`` (strictly increasing).

    Boundary parts are named ``left``, ``right``, ``bottom`` and ``top``; the nodal spacing is
    the larger of the adjacent intervals in x and in y. Every quad is split along the same
    diagonal, so interior median-dual cells of a uniform grid all have area h_x h_y.
    """
    xs = np.asarray(xs, float)
    ys = np.asarray(ys, float)
    for name, c in (("xs", xs), ("ys", ys)):
        if c.ndim != 1 or len(c) < 2 or not np.all(np.diff(c) > 0):
            raise InputError(f"{name} must be a strictly increasing 1-D array of >= 2 coordinates")
    nx, ny = len(xs), len(ys)
    X, Y = np.meshgrid(xs, ys)
    x = np.column_stack([X.ravel(), Y.ravel()])
    node = np.arange(nx * ny).reshape(ny, nx)
    a, b = node[:-1, :-1], node[:-1, 1:]
    c, d = node[1:, 1:], node[1:, :-1]
    tri = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    def side(ids):
        return np.column_stack([ids[:-1], ids[1:]])
    edges = {"bottom": side(node[0]), "right": side(node[:, -1]),
             "top": side(node[-1]), "left": side(node[:, 0])}
    def local(c):
        d = np.diff(c)
        return np.maximum(np.r_[d, d[-1]], np.r_[d[0], d])
    spacing = np.maximum.outer(local(ys), local(xs)).ravel()
    return particles(x, tri, edges, spacing)


def structured(lx: float, ly: float, nx: int, ny: int, origin: tuple[float, float] = (0.0, 0.0)) -> Particles:
    """Uniform ``nx`` x ``ny`` grid of nodes on the rectangle [0, lx] x [0, ly] + origin."""
    for name, v in (("nx", nx), ("ny", ny)):
        if int(v) != v or v < 2:
            raise InputError(f"{name} = {v!r}: a grid needs an integer >= 2 nodes per direction")
    for name, v in (("lx", lx), ("ly", ly)):
        if not v > 0:
            raise InputError(f"{name} = {v!r}: the rectangle's side lengths must be positive")
    return graded(origin[0] + np.linspace(0.0, lx, int(nx)), origin[1] + np.linspace(0.0, ly, int(ny)))


def geometric_spacing(length: float, n: int, ratio: float) -> np.ndarray:
    """``n`` coordinates on [0, length] whose intervals grow by ``ratio`` from 0 towards ``length``."""
    if not ratio > 0:
        raise InputError(f"ratio = {ratio!r} must be positive (1 gives uniform spacing)")
    steps = ratio ** np.arange(n - 1)
    return np.r_[0.0, np.cumsum(steps)] * (length / steps.sum())


def from_points(x: np.ndarray, polygon: np.ndarray, names: dict[str, list[int]] | None = None) -> Particles:
    """Particles from a node cloud inside a simple polygon (convex or not).

    The polygon's vertices must be among the nodes; the cloud is Delaunay-triangulated and the
    triangles outside the polygon discarded.

    Args:
        x: Node coordinates, shape ``(num_nodes, 2)`` [m].
        polygon: Counter-clockwise polygon vertices, shape ``(k, 2)`` [m].
        names: Boundary part name -> indices of the polygon sides (side i runs from vertex i
            to vertex i + 1) it consists of.

    Raises:
        InputError: A node lies outside the polygon.
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    poly = np.asarray(polygon, float)
    scale = np.ptp(poly, axis=0).max()
    inside = _in_polygon(x, poly, 1e-9 * scale)
    if not inside.all():
        i = int(np.flatnonzero(~inside)[0])
        raise InputError(f"node {i} at {point_str(x[i])} lies outside the geometry; remove it or enlarge the polygon")
    tri = Delaunay(x).simplices
    keep = _in_polygon(x[tri].mean(axis=1), poly, -1.0)
    tri = tri[keep]
    # Tag boundary edges by the polygon side they lie on.
    edges = {}
    if names:
        bnd = particles(x, tri)
        e = bnd.boundary_edges
        mid = x[e].mean(axis=1)
        for name, sides in names.items():
            sel = np.zeros(len(e), bool)
            for s in sides:
                p, q = poly[s], poly[(s + 1) % len(poly)]
                t = q - p
                dist = np.abs((mid - p) @ np.array([-t[1], t[0]])) / np.linalg.norm(t)
                along = (mid - p) @ t / (t @ t)
                sel |= (dist < 1e-9 * scale) & (along > 0) & (along < 1)
            edges[name] = e[sel]
    return particles(x, tri, edges)


def _in_polygon(pts: np.ndarray, poly: np.ndarray, tol: float) -> np.ndarray:
    """Even-odd point-in-polygon test; points within ``tol`` of a side count as inside."""
    inside = np.zeros(len(pts), bool)
    near = np.zeros(len(pts), bool)
    for p, q in zip(poly, np.roll(poly, -1, axis=0)):
        crosses = (p[1] > pts[:, 1]) != (q[1] > pts[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = p[0] + (pts[:, 1] - p[1]) * (q[0] - p[0]) / (q[1] - p[1])
        inside ^= crosses & (pts[:, 0] < xc)
        if tol > 0:
            t = q - p
            s = np.clip((pts - p) @ t / (t @ t), 0.0, 1.0)
            near |= np.linalg.norm(pts - (p + s[:, None] * t), axis=1) <= tol
    return inside | near
