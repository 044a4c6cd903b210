"""Conforming nodal representative domains: the median-dual cells of the triangulation.

Each triangle (a, b, c) with centroid g and edge midpoints m_ab, m_bc, m_ca is cut into three
quadrilateral *subcells*, one per vertex: (a, m_ab, g, m_ca). A node's domain Omega_L is the
union of its subcells over the triangles around it. Why median-dual cells rather than
clipped Voronoi cells:

* they conform to any triangulated geometry, convex or not, with no clipping;
* every node is a vertex of each of its own subcells, boundary nodes included, so MSCNI
  subcells never degenerate at the boundary;
* cell boundaries are straight segments whose midpoints are shared by exactly two cells,
  so the divergence-theorem sums of SCNI (eq. 3.55) cancel exactly inside the domain.

Smoothed gradients need N at the midpoints of the cell-boundary segments: one point per
triangle edge half-segment (m -> g) and two "quarter points" per triangulation edge (the
midpoints of the half-edges a -> m_ab, used by subcells and, on the boundary, by cells).
"""
from dataclasses import dataclass
from functools import cached_property

import numba
import numpy as np

from rkfx.geometry.particles import Particles


@dataclass(frozen=True)
class BoundarySegments:
    """Halves of the boundary edges, each owned by the node at its end.

    Attributes:
        node: Owning node, shape ``(num_segments,)``.
        ends: Segment end points, shape ``(num_segments, 2, 2)`` [m], counter-clockwise.
        normal: Outward unit normal, shape ``(num_segments, 2)``.
        length: Shape ``(num_segments,)`` [m].
        tag: Boundary tag of the parent edge, shape ``(num_segments,)``.
        point: Index of the segment midpoint among the smoothing points, shape ``(num_segments,)``.
    """

    node: np.ndarray
    ends: np.ndarray
    normal: np.ndarray
    length: np.ndarray
    tag: np.ndarray
    point: np.ndarray

    @property
    def midpoint(self) -> np.ndarray:
        return self.ends.mean(axis=1)


@dataclass(frozen=True)
class Triangulation:
    """The triangles whose median-dual cells a ``NodalDomains`` holds: subcell 3 t + k is the
    corner of triangle t at its vertex k. The subcells' sides are computed from it where
    they are needed rather than stored (0.38 GB at 10^6 nodes).

    Attributes:
        x: Node coordinates, shape ``(num_nodes, 2)`` [m].
        triangles: Counter-clockwise vertex triples, shape ``(num_triangles, 3)``.
    """

    x: np.ndarray
    triangles: np.ndarray


@dataclass(frozen=True)
class NodalDomains:
    """Nodal domains Omega_L, their subcells and the data of their smoothed gradients.

    A cell's boundary is made of the sides of its subcells marked ``subcell_outer``; the
    segments of the cells and the sides' normals are formed on request (``cell_segments``,
    ``side_normal_length``), a block of nodes or subcells at a time.

    Attributes:
        area: A_L, shape ``(num_nodes,)`` [m^2].
        second_moment: Integrals of (x-x_L)^2, (x-x_L)(y-y_L), (y-y_L)^2 over Omega_L,
            shape ``(num_nodes, 3)`` [m^4].
        subcell_node: Node L of each subcell C, shape ``(num_subcells,)``.
        subcell_area: A_C, shape ``(num_subcells,)`` [m^2].
        subcell_centroid: x_hat_C, shape ``(num_subcells, 2)`` [m].
        smoothing_points: Midpoints of all cell and subcell boundary segments, shape ``(q, 2)`` [m].
        subcell_point: Smoothing point of each of the 4 subcell sides, shape ``(num_subcells, 4)``.
        subcell_outer: Whether each side lies on its cell's boundary, shape ``(num_subcells, 4)``.
        boundary: The domain boundary split at edge midpoints.
        subcell_vertices: Counter-clockwise vertices of each subcell, vertex 0 the node, shape
            ``(num_subcells, 4, 2)`` [m], or ``None`` (median-dual cells: see ``triangulation``
            and ``rkfx.fracture.damage.cell_geometry``).
        triangulation: The triangles of median-dual cells, or ``None`` (cells with
            ``subcell_vertices``).
    """

    area: np.ndarray
    second_moment: np.ndarray
    subcell_node: np.ndarray
    subcell_area: np.ndarray
    subcell_centroid: np.ndarray
    smoothing_points: np.ndarray
    subcell_point: np.ndarray
    subcell_outer: np.ndarray
    boundary: BoundarySegments
    subcell_vertices: np.ndarray | None = None
    triangulation: Triangulation | None = None

    def __post_init__(self):
        # Node and point indices are kept as int32 (a 10^6-node grid's cells: 0.14 GB less).
        for name in ("subcell_node", "subcell_point"):
            a = np.asarray(getattr(self, name))
            if a.dtype != np.int32 and (a.size == 0 or a.max() < np.iinfo(np.int32).max):
                object.__setattr__(self, name, a.astype(np.int32))
        if (self.subcell_vertices is None) == (self.triangulation is None):
            raise ValueError("NodalDomains needs exactly one of subcell_vertices and triangulation")

    def side_normal_length(self, sub: np.ndarray | None = None) -> np.ndarray:
        """Outward normal x length of the 4 sides of the subcells ``sub`` (default all),
        shape ``(len(sub), 4, 2)`` [m]."""
        sub = np.arange(len(self.subcell_area)) if sub is None else np.asarray(sub, np.int64)
        if self.triangulation is not None:
            return _median_dual_sides(self.triangulation.x, self.triangulation.triangles, sub)
        v = self.subcell_vertices[sub]
        out = np.empty(v.shape)
        w = np.roll(v, -1, axis=1)
        out[..., 0] = w[..., 1] - v[..., 1]
        out[..., 1] = v[..., 0] - w[..., 0]
        return out

    @cached_property
    def _subcells_by_node(self) -> tuple[np.ndarray, np.ndarray]:
        """Pointer per node into the subcells sorted by node (stably), and that order."""
        order = np.argsort(self.subcell_node, kind="stable").astype(np.int32)
        ptr = np.zeros(len(self.area) + 1, np.int64)
        np.cumsum(np.bincount(self.subcell_node, minlength=len(self.area)), out=ptr[1:])
        return ptr, order

    def segment_counts(self) -> np.ndarray:
        """The number of cell-boundary segments of each node, shape ``(num_nodes,)`` (0: no cell)."""
        return np.bincount(self.subcell_node, self.subcell_outer.sum(axis=1), len(self.area)).astype(np.int64)

    def cell_segments(self, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The cell-boundary segments of ``nodes``: their row pointer, shape ``(len(nodes) + 1,)``,
        smoothing points and outward normal x length, shape ``(k, 2)`` [m]; per node, its
        subcells' outer sides in subcell then side order."""
        ptr, order = self._subcells_by_node
        seg, sub, side = _segments(np.asarray(nodes, np.int64), ptr, order, self.subcell_outer)
        normal = self.side_normal_length(sub)[np.arange(len(sub)), side] if sub.size else np.zeros((0, 2))
        return seg, self.subcell_point[sub, side], normal


@numba.njit(cache=True)
def _segments(nodes, ptr, order, outer):
    """Per node of ``nodes``, the (subcell, side) pairs of its outer sides, with their pointer."""
    seg = np.zeros(len(nodes) + 1, np.int64)
    for i in range(len(nodes)):
        c = 0
        for s in order[ptr[nodes[i]]:ptr[nodes[i] + 1]]:
            for k in range(4):
                c += outer[s, k]
        seg[i + 1] = seg[i] + c
    sub = np.empty(seg[-1], np.int64)
    side = np.empty(seg[-1], np.int64)
    m = 0
    for i in range(len(nodes)):
        for s in order[ptr[nodes[i]]:ptr[nodes[i] + 1]]:
            for k in range(4):
                if outer[s, k]:
                    sub[m] = s
                    side[m] = k
                    m += 1
    return seg, sub, side


def _normal_length(p, q):
    """Outward normal x length of the counter-clockwise side p -> q (shape (..., 2))."""
    d = q - p
    return np.stack([d[..., 1], -d[..., 0]], axis=-1)


@numba.njit(inline="always")
def _corner(x, tri, t, k, qx, qy):
    """The vertices (v, m_k, g, m_k-1) of the subcell at corner k of triangle t, relative to its
    node v, into ``qx``, ``qy`` (counter-clockwise). The midpoints are formed as in the
    smoothing points, so that shared sides cancel exactly."""
    v, nxt, prv = tri[t, k], tri[t, (k + 1) % 3], tri[t, (k + 2) % 3]
    gx = (x[tri[t, 0], 0] + x[tri[t, 1], 0] + x[tri[t, 2], 0]) / 3.0
    gy = (x[tri[t, 0], 1] + x[tri[t, 1], 1] + x[tri[t, 2], 1]) / 3.0
    qx[0] = 0.0
    qy[0] = 0.0
    qx[1] = 0.5 * (x[v, 0] + x[nxt, 0]) - x[v, 0]
    qy[1] = 0.5 * (x[v, 1] + x[nxt, 1]) - x[v, 1]
    qx[2] = gx - x[v, 0]
    qy[2] = gy - x[v, 1]
    qx[3] = 0.5 * (x[prv, 0] + x[v, 0]) - x[v, 0]
    qy[3] = 0.5 * (x[prv, 1] + x[v, 1]) - x[v, 1]


@numba.njit(parallel=True, cache=True)
def _median_dual_sides(x, tri, sub):
    """Outward normal x length of the sides of the median-dual subcells ``sub`` (3 t + k)."""
    nl = np.empty((len(sub), 4, 2))
    for m in numba.prange(len(sub)):
        qx = np.empty(4)
        qy = np.empty(4)
        _corner(x, tri, sub[m] // 3, sub[m] % 3, qx, qy)
        for i in range(4):
            j = (i + 1) % 4
            nl[m, i, 0] = qy[j] - qy[i]
            nl[m, i, 1] = -(qx[j] - qx[i])
    return nl


@numba.njit(parallel=True, cache=True)
def _subcells(x, tri, tri_edges, edges, is_boundary):
    """Smoothing points and, per subcell (v, m_k, g, m_k-1), its area, centroid, second
    moments about v, and the smoothing point of each side and whether it is a cell side."""
    nt = tri.shape[0]
    ne = edges.shape[0]
    ns = 3 * nt
    points = np.empty((3 * nt + 2 * ne, 2))
    area = np.empty(ns)
    centroid = np.empty((ns, 2))
    moments = np.empty((ns, 3))
    side_point = np.empty((ns, 4), np.int64)
    outer = np.empty((ns, 4), np.bool_)
    for e in numba.prange(ne):
        i, j = edges[e, 0], edges[e, 1]
        for d in range(2):
            points[3 * nt + e, d] = 0.75 * x[i, d] + 0.25 * x[j, d]
            points[3 * nt + ne + e, d] = 0.25 * x[i, d] + 0.75 * x[j, d]
    for t in numba.prange(nt):
        qx = np.empty(4)
        qy = np.empty(4)
        gx = (x[tri[t, 0], 0] + x[tri[t, 1], 0] + x[tri[t, 2], 0]) / 3.0
        gy = (x[tri[t, 0], 1] + x[tri[t, 1], 1] + x[tri[t, 2], 1]) / 3.0
        for k in range(3):
            a, b = tri[t, k], tri[t, (k + 1) % 3]
            points[3 * t + k, 0] = 0.5 * (0.5 * (x[a, 0] + x[b, 0]) + gx)
            points[3 * t + k, 1] = 0.5 * (0.5 * (x[a, 1] + x[b, 1]) + gy)
        for k in range(3):
            s = 3 * t + k
            v = tri[t, k]
            e_k = tri_edges[t, k]
            e_p = tri_edges[t, (k + 2) % 3]
            _corner(x, tri, t, k, qx, qy)
            a2 = 0.0
            cx = 0.0
            cy = 0.0
            ixx = 0.0
            ixy = 0.0
            iyy = 0.0
            for i in range(4):
                j = (i + 1) % 4
                c = qx[i] * qy[j] - qx[j] * qy[i]
                a2 += c
                cx += (qx[i] + qx[j]) * c
                cy += (qy[i] + qy[j]) * c
                ixx += c * (qx[i] * qx[i] + qx[i] * qx[j] + qx[j] * qx[j])
                iyy += c * (qy[i] * qy[i] + qy[i] * qy[j] + qy[j] * qy[j])
                ixy += c * (qx[i] * qy[j] + 2 * qx[i] * qy[i] + 2 * qx[j] * qy[j] + qx[j] * qy[i])
            area[s] = 0.5 * a2
            centroid[s, 0] = x[v, 0] + cx / (3.0 * a2)
            centroid[s, 1] = x[v, 1] + cy / (3.0 * a2)
            moments[s, 0] = ixx / 12.0
            moments[s, 1] = ixy / 24.0
            moments[s, 2] = iyy / 12.0
            # Side midpoints: quarter point of edge k near v, the two m-g midpoints, quarter
            # point of edge k-1 near v. The m-g sides bound the cell; the half-edges through v
            # only on the domain boundary.
            side_point[s, 0] = 3 * nt + e_k + (ne if edges[e_k, 1] == v else 0)
            side_point[s, 1] = 3 * t + k
            side_point[s, 2] = 3 * t + (k + 2) % 3
            side_point[s, 3] = 3 * nt + e_p + (ne if edges[e_p, 1] == v else 0)
            outer[s, 0] = is_boundary[e_k]
            outer[s, 1] = True
            outer[s, 2] = True
            outer[s, 3] = is_boundary[e_p]
    return points, area, centroid, moments, side_point, outer


def nodal_domains(p: Particles, nodes: np.ndarray | None = None) -> NodalDomains:
    """Median-dual nodal domains of a ``Particles`` set (compiled loops over triangles).

    ``nodes`` (indices, e.g. a rank's own nodes) builds only the triangles around them: their
    cells, areas and moments are whole and equal to the whole build's, the subcells are those
    of those triangles (of their own and their neighbours' corners), and the other nodes' cells
    are partial or empty. Node indices stay global. The smoothing points are numbered for
    this build alone; the boundary is whole.
    """
    x, tri, n = p.x, p.triangles, p.num_nodes
    edges, edge_of = p.edges, p.triangle_edges
    ne = len(edges)
    is_boundary = np.bincount(edge_of.ravel(), minlength=ne) == 1
    if nodes is not None:
        mine = np.zeros(n, bool)
        mine[np.asarray(nodes, np.int64)] = True
        around = mine[tri].any(axis=1)
        tri, edge_of = np.ascontiguousarray(tri[around]), np.ascontiguousarray(edge_of[around])
    points, area, centroid, moments, side_point, outer = _subcells(x, tri, edge_of, edges, is_boundary)
    # Boundary: each boundary edge (i -> j, domain on the left) split at its midpoint; the
    # half-segment midpoints are the edge's quarter points.
    be = p.boundary_edges
    bedge = _edge_index(edges, be.min(axis=1), be.max(axis=1))
    xm = 0.5 * (x[be[:, 0]] + x[be[:, 1]])
    ends = np.concatenate([np.stack([x[be[:, 0]], xm], 1), np.stack([xm, x[be[:, 1]]], 1)])
    bnode = np.concatenate([be[:, 0], be[:, 1]])
    bnl = _normal_length(ends[:, 0], ends[:, 1])
    blen = np.linalg.norm(bnl, axis=1)
    both = np.concatenate([bedge, bedge])
    boundary = BoundarySegments(
        node=bnode, ends=ends, normal=bnl / blen[:, None], length=blen,
        tag=np.concatenate([p.boundary_tags, p.boundary_tags]),
        point=3 * len(tri) + both + ne * (bnode == edges[both, 1]))
    node = tri.reshape(-1)
    return NodalDomains(
        area=np.bincount(node, area, n),
        second_moment=np.column_stack([np.bincount(node, moments[:, c], n) for c in range(3)]),
        subcell_node=node, subcell_area=area, subcell_centroid=centroid,
        smoothing_points=points, subcell_point=side_point, subcell_outer=outer,
        boundary=boundary, triangulation=Triangulation(x, tri))


def _edge_index(edges: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Index of the edges (lo, hi) in ``edges``, which is sorted by low node."""
    idx = np.searchsorted(edges[:, 0], lo)
    for _ in range(64):  # a node has few edges: step to the matching high node
        miss = edges[idx, 1] != hi
        if not miss.any():
            return idx
        idx[miss] += 1
    raise AssertionError("boundary edge not found among the triangulation's edges")
