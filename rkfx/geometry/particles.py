"""Particles: nodes, their spacing, and the triangulation their nodal domains are cut from.

A ``Particles`` set is the discretisation every rkfx solver starts from. The triangulation's
vertices are the nodes; it carries the geometry (boundary edges tagged by name) and defines
the conforming nodal domains (``rkfx.geometry.nodal_domains``). Factories: ``structured`` and
``graded`` tensor grids, ``from_points`` for a cloud inside a polygon, and
``rkfx.geometry.gmsh_nodes.from_gmsh`` for gmsh geometry.
"""
from dataclasses import dataclass, field

import numba
import numpy as np
from scipy.spatial import Delaunay

from rkfx.errors import InputError, point_str


class NamedBoundary:
    """Boundary parts by name, for particle sets with ``boundary_names`` (name -> tag),
    ``boundary_tags`` and the node tuples of their boundary elements ``boundary_elements``
    (edges in 2-D, triangles in 3-D)."""

    boundary_names: dict[str, int]
    boundary_tags: np.ndarray

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
        return np.unique(self.boundary_elements[mask])


@dataclass(frozen=True)
class Particles(NamedBoundary):
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

    @property
    def boundary_elements(self) -> np.ndarray:
        return self.boundary_edges

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


def jittered(n: int, amplitude: float = 0.3, seed: int = 0) -> Particles:
    """An ``n`` x ``n`` grid on the unit square with every interior node moved at random by up to
    ``amplitude`` times the spacing in x and y (an irregular node set for patch tests and
    reproducing conditions); boundary names bottom, right, top, left."""
    if int(n) != n or n < 3:
        raise InputError(f"n = {n!r}: a jittered grid needs an integer >= 3 nodes per side")
    if not 0.0 <= amplitude < 0.5:
        raise InputError(f"amplitude = {amplitude!r}: use 0 <= amplitude < 0.5 spacings (nodes must not cross)")
    h = 1.0 / (int(n) - 1)
    g = np.linspace(0.0, 1.0, int(n))
    x = np.column_stack([np.tile(g, int(n)), np.repeat(g, int(n))])
    inside = (x > 1e-12).all(axis=1) & (x < 1 - 1e-12).all(axis=1)
    x[inside] += np.random.default_rng(seed).uniform(-amplitude * h, amplitude * h, size=(inside.sum(), 2))
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    return from_points(x, square, names={"bottom": [0], "right": [1], "top": [2], "left": [3]})


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


def cut_triangulation(p: Particles, polylines, gap: float | None = None, name: str = "crack",
                      exponent: float = 2.0):
    """Split a node set along pre-existing cracks, so no triangle straddles them.

    The cracks must run along triangulation edges (a structured grid split along a grid
    line, or a gmsh mesh with the crack lines embedded in the surface). Every node on a crack
    except a free tip is duplicated, one copy per side: the triangles around the node are
    grouped by the crack edges between them, each group gets its own copy, and each copy
    is moved off the crack line by ``gap`` towards its side. The result is a domain with a
    thin slit: its faces are boundary edges tagged ``name`` (traction-free unless loaded),
    the median-dual cells on either side do not overlap, and RK nodes are never on the crack
    (where the diffraction criterion could not tell the sides apart). A polyline end counts
    as a free tip unless it lies on the boundary; cracks may kink, and where they meet each
    wedge gets its own copy (the tip flags of ``cracks`` then need a look).

    Args:
        p: Particles with the crack lines among the triangulation edges.
        polylines: Vertices of each crack, shapes ``(m_k >= 2, 2)`` [m].
        gap: Distance of the face copies from the crack line [m]; default 1e-8 times the
            smallest nodal spacing on the cracks. The faces next to a tip are inclined by
            gap / h, which perturbs the solution by O(gap / h); round-off needs gap to stay well
            above 1e-16 |x|.
        name: Boundary part name of the crack faces.
        exponent: lambda of the diffraction distance of the returned cracks.

    Returns:
        ``(particles, cracks)``: the split set (new nodes appended; nodal spacing kept) and
        the ``rkfx.approximation.diffraction.Cracks`` to give ``rk_approximation``.

    Raises:
        InputError: A crack does not run along triangulation edges.
    """
    from rkfx.approximation.diffraction import cracks as make_cracks  # noqa: PLC0415

    x, tri, n = p.x, p.triangles, p.num_nodes
    scale = float(np.ptp(x, axis=0).max())
    tol = 1e-9 * scale
    lines = [np.asarray(v, dtype=np.float64).reshape(-1, 2) for v in polylines]
    on_boundary = _near_segments(np.array([v[[0, -1]] for v in lines]).reshape(-1, 2),
                                 x[p.boundary_edges].reshape(-1, 2, 2), tol).reshape(-1, 2)
    c = make_cracks(lines, [(not a, not b) for a, b in on_boundary], exponent)
    # Crack edges: triangulation edges whose ends and midpoint lie on a crack segment.
    e = p.edges
    on = _near_segments(x, c.segments, tol)
    cand = e[on[e[:, 0]] & on[e[:, 1]]]
    cand = cand[_near_segments(x[cand].mean(axis=1), c.segments, tol)]
    covered = np.linalg.norm(x[cand[:, 0]] - x[cand[:, 1]], axis=1).sum()
    length = np.linalg.norm(c.segments[:, 1] - c.segments[:, 0], axis=1).sum()
    if not abs(covered - length) <= 1e-6 * length:
        raise InputError(f"the cracks (total length {length:.6g}) run along only {covered:.6g} of "
                         "triangulation edges; put nodes on the crack lines (a grid line of a structured "
                         "grid, or gmsh.model.mesh.embed of the crack curves) and end cracks at nodes")
    cand = np.sort(cand, axis=1)
    crack_key = set(map(tuple, cand.tolist()))
    if gap is None:
        gap = 1e-8 * float(p.spacing[np.unique(cand)].min())
    # Triangles around each crack node, grouped across the non-crack edges at the node.
    new_tri = tri.copy()
    xn = x.copy()
    extra_x, extra_h = [], []
    normals = c.segments[:, 1] - c.segments[:, 0]
    normals = np.column_stack([-normals[:, 1], normals[:, 0]]) / np.linalg.norm(normals, axis=1)[:, None]
    ts_of = {v: [] for v in np.unique(cand).tolist()}
    for t, k in zip(*np.nonzero(np.isin(tri, list(ts_of)))):
        ts_of[int(tri[t, k])].append(int(t))
    for v, ts in ts_of.items():
        parent = {t: t for t in ts}

        def root(t):
            while parent[t] != t:
                t = parent[t]
            return t
        by_edge = {}
        for t in ts:
            for w in tri[t].tolist():
                if w != v and (min(v, w), max(v, w)) not in crack_key:
                    by_edge.setdefault(w, []).append(t)
        for group in by_edge.values():
            for t in group[1:]:
                parent[root(t)] = root(group[0])
        groups = {}
        for t in ts:
            groups.setdefault(root(t), []).append(t)
        if len(groups) < 2:
            continue  # a free tip: the crack ends inside the fan
        # Offset direction: the crack normal at v (mean over its segments), towards the group.
        nv = normals[_segment_distance(x[v][None], c.segments)[0] <= tol]
        nv = (nv * np.where(nv @ nv[0] < 0, -1.0, 1.0)[:, None]).mean(axis=0)
        nv /= np.linalg.norm(nv)
        for gi, group in enumerate(groups.values()):
            side = (x[tri[group]].mean(axis=1) - x[v]).mean(axis=0)
            s_n = side @ nv
            # Where cracks meet (more than two sides) each copy moves into its own wedge.
            off = np.sign(s_n) * nv if len(groups) == 2 and abs(s_n) > 1e-6 * np.linalg.norm(side) \
                else side / np.linalg.norm(side)
            if gi == 0:
                node = v
                xn[v] = x[v] + gap * off
            else:
                node = n + len(extra_x)
                extra_x.append(x[v] + gap * off)
                extra_h.append(p.spacing[v])
            for t in group:
                new_tri[t][tri[t] == v] = node
    xn = np.vstack([xn, np.array(extra_x).reshape(-1, 2)])
    # Tagged boundary edges of p, carried over through the triangle side that owns each, plus
    # the crack faces (both sides of every crack edge).
    side_keys = np.minimum(tri, np.roll(tri, -1, axis=1)) * n + np.maximum(tri, np.roll(tri, -1, axis=1))
    new_sides = np.stack([new_tri, np.roll(new_tri, -1, axis=1)], axis=-1)
    on_bnd = np.bincount(p.triangle_edges.ravel(), minlength=len(p.edges))[p.triangle_edges] == 1
    bkeys = _edge_keys(p.boundary_edges, n)
    order = np.argsort(bkeys)
    side_tag = np.zeros(tri.shape, np.int64)
    side_tag[on_bnd] = p.boundary_tags[order[np.searchsorted(bkeys[order], side_keys[on_bnd])]]
    tagged = {nm: new_sides[side_tag == t] for nm, t in p.boundary_names.items()}
    tagged[name] = new_sides[np.isin(side_keys, cand[:, 0] * n + cand[:, 1])]
    # A crack reaching the boundary is prolonged a little beyond it, so the face copies at its end
    # (a gap off the crack line, level with its end point) are still hidden from the other side.
    reach = 1e-6 * scale
    prolonged = []
    for v, ends in zip(lines, on_boundary):
        v = v.copy()
        for k, (i, j) in enumerate(((0, 1), (-1, -2))):
            if ends[k]:
                d = v[i] - v[j]
                v[i] = v[i] + reach * d / np.linalg.norm(d)
        prolonged.append(v)
    return particles(xn, new_tri, tagged, np.r_[p.spacing, extra_h]), make_cracks(
        prolonged, [(not a, not b) for a, b in on_boundary], exponent)


def _segment_distance(pts: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Distance of each point to each segment, shape ``(num_points, num_segments)``."""
    a = segments[None, :, 0]
    d = segments[None, :, 1] - a
    t = np.clip(np.sum((pts[:, None] - a) * d, axis=-1) / np.sum(d * d, axis=-1), 0.0, 1.0)
    return np.linalg.norm(pts[:, None] - a - t[..., None] * d, axis=-1)


def _near_segments(pts: np.ndarray, segments: np.ndarray, tol: float) -> np.ndarray:
    """Whether each point lies within ``tol`` of one of the segments, shape ``(num_points,)``."""
    out = np.zeros(len(pts), bool)
    for s in range(0, len(segments), 64):  # bounded memory for long boundaries
        out |= (_segment_distance(pts, segments[s:s + 64]) <= tol).any(axis=1)
    return out
