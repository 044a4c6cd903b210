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

import numba
import numpy as np

from .particles import Particles


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
class NodalDomains:
    """Nodal domains Omega_L, their subcells and the data of their smoothed gradients.

    Attributes:
        area: A_L, shape ``(num_nodes,)`` [m^2].
        second_moment: Integrals of (x-x_L)^2, (x-x_L)(y-y_L), (y-y_L)^2 over Omega_L,
            shape ``(num_nodes, 3)`` [m^4].
        subcell_node: Node L of each subcell C, shape ``(num_subcells,)``.
        subcell_area: A_C, shape ``(num_subcells,)`` [m^2].
        subcell_centroid: x_hat_C, shape ``(num_subcells, 2)`` [m].
        smoothing_points: Midpoints of all cell and subcell boundary segments, shape ``(q, 2)`` [m].
        subcell_point: Smoothing point of each of the 4 subcell sides, shape ``(num_subcells, 4)``.
        subcell_normal_length: Outward normal x length of each side, shape ``(num_subcells, 4, 2)`` [m].
        cell_ptr: Per-node CSR pointer into the cell-boundary segment lists, shape ``(num_nodes + 1,)``.
        cell_point: Smoothing point of each cell-boundary segment, shape ``(k,)``.
        cell_normal_length: Outward normal x length of each, shape ``(k, 2)`` [m].
        boundary: The domain boundary split at edge midpoints.
    """

    area: np.ndarray
    second_moment: np.ndarray
    subcell_node: np.ndarray
    subcell_area: np.ndarray
    subcell_centroid: np.ndarray
    smoothing_points: np.ndarray
    subcell_point: np.ndarray
    subcell_normal_length: np.ndarray
    cell_ptr: np.ndarray
    cell_point: np.ndarray
    cell_normal_length: np.ndarray
    boundary: BoundarySegments


def _normal_length(p, q):
    """Outward normal x length of the counter-clockwise side p -> q (shape (..., 2))."""
    d = q - p
    return np.stack([d[..., 1], -d[..., 0]], axis=-1)


def _quad_moments(v):
    """Area, centroid and second moments about vertex 0 of CCW quads v, shape (s, 4, 2)."""
    r = v - v[:, :1]
    x0, y0 = r[..., 0], r[..., 1]
    x1, y1 = np.roll(x0, -1, axis=1), np.roll(y0, -1, axis=1)
    cross = x0 * y1 - x1 * y0
    area = 0.5 * cross.sum(axis=1)
    cx = ((x0 + x1) * cross).sum(axis=1) / (6.0 * area)
    cy = ((y0 + y1) * cross).sum(axis=1) / (6.0 * area)
    ixx = (cross * (x0 * x0 + x0 * x1 + x1 * x1)).sum(axis=1) / 12.0
    iyy = (cross * (y0 * y0 + y0 * y1 + y1 * y1)).sum(axis=1) / 12.0
    ixy = (cross * (x0 * y1 + 2 * x0 * y0 + 2 * x1 * y1 + x1 * y0)).sum(axis=1) / 24.0
    centroid = v[:, 0] + np.column_stack([cx, cy])
    return area, centroid, np.column_stack([ixx, ixy, iyy])


@numba.njit(cache=True)
def _cell_lists(n, tri, edge_of, is_boundary, seg_point, quarter_point, nl_sub):
    """Per-node cell-boundary segments: the two m-g sides of each subcell, plus boundary half-edges."""
    t_count = tri.shape[0]
    count = np.zeros(n + 1, np.int64)
    for t in range(t_count):
        for k in range(3):
            v = tri[t, k]
            count[v + 1] += 2 + is_boundary[edge_of[t, k]] + is_boundary[edge_of[t, (k + 2) % 3]]
    for i in range(n):
        count[i + 1] += count[i]
    ptr = count.copy()
    fill = count[:-1].copy()
    point = np.empty(ptr[-1], np.int64)
    nl = np.empty((ptr[-1], 2))
    for t in range(t_count):
        for k in range(3):
            v = tri[t, k]
            s = 3 * t + k
            for side in range(4):
                if side == 0 and not is_boundary[edge_of[t, k]]:
                    continue
                if side == 3 and not is_boundary[edge_of[t, (k + 2) % 3]]:
                    continue
                point[fill[v]] = quarter_point[s, side] if side in (0, 3) else seg_point[s, side]
                nl[fill[v], 0] = nl_sub[s, side, 0]
                nl[fill[v], 1] = nl_sub[s, side, 1]
                fill[v] += 1
    return ptr, point, nl


def nodal_domains(p: Particles) -> NodalDomains:
    """Median-dual nodal domains of a ``Particles`` set (vectorised over triangles)."""
    x, tri, n = p.x, p.triangles, p.num_nodes
    nt = len(tri)
    xt = x[tri]  # (t, 3, 2)
    g = xt.mean(axis=1)
    mid = 0.5 * (xt + np.roll(xt, -1, axis=1))  # mid[:, k] on edge (v_k, v_k+1)
    # Unique undirected edges; edge_of[t, k] is the edge (v_k, v_k+1).
    directed = np.stack([tri, np.roll(tri, -1, axis=1)], axis=-1).reshape(-1, 2)
    lo = directed.min(axis=1)
    hi = directed.max(axis=1)
    uniq, edge_of, counts = np.unique(lo * n + hi, return_inverse=True, return_counts=True)
    edge_of = edge_of.reshape(nt, 3)
    ne = len(uniq)
    is_boundary = (counts == 1).astype(np.int64)
    e_lo, e_hi = uniq // n, uniq % n
    # Smoothing points: 3 per triangle (midpoints of m_k -> g), then 2 per edge (quarter points).
    seg_mid = 0.5 * (mid + g[:, None, :])  # (t, 3, 2)
    quarter = np.concatenate([0.75 * x[e_lo] + 0.25 * x[e_hi], 0.25 * x[e_lo] + 0.75 * x[e_hi]])
    smoothing_points = np.concatenate([seg_mid.reshape(-1, 2), quarter])

    def quarter_index(node, edge):
        return 3 * nt + edge + ne * (node == e_hi[edge])

    # Subcell of vertex k of triangle t: (v_k, m_k, g, m_{k-1}); row 3 t + k.
    vk = xt
    mk = mid
    mkm = np.roll(mid, 1, axis=1)
    gg = np.broadcast_to(g[:, None, :], xt.shape)
    quads = np.stack([vk, mk, gg, mkm], axis=2).reshape(-1, 4, 2)
    area, centroid, moments = _quad_moments(quads)
    nl = _normal_length(quads, np.roll(quads, -1, axis=1))  # (s, 4, 2)
    tt = np.repeat(np.arange(nt), 3)
    kk = np.tile(np.arange(3), nt)
    node = tri.reshape(-1)
    e_k = edge_of[tt, kk]
    e_km = edge_of[tt, (kk + 2) % 3]
    seg_point = np.column_stack([np.zeros(len(tt), np.int64), 3 * tt + kk, 3 * tt + (kk + 2) % 3,
                                 np.zeros(len(tt), np.int64)])
    quarter_point = np.column_stack([quarter_index(node, e_k), np.zeros(len(tt), np.int64),
                                     np.zeros(len(tt), np.int64), quarter_index(node, e_km)])
    subcell_point = seg_point + quarter_point
    cell_ptr, cell_point, cell_nl = _cell_lists(n, tri, edge_of, is_boundary, seg_point, quarter_point, nl)
    # Boundary: each boundary edge (i -> j, domain on the left) split at its midpoint.
    be = p.boundary_edges
    bkey = be.min(axis=1) * n + be.max(axis=1)
    bedge = np.searchsorted(uniq, bkey)
    xm = 0.5 * (x[be[:, 0]] + x[be[:, 1]])
    ends = np.concatenate([np.stack([x[be[:, 0]], xm], 1), np.stack([xm, x[be[:, 1]]], 1)])
    bnode = np.concatenate([be[:, 0], be[:, 1]])
    bnl = _normal_length(ends[:, 0], ends[:, 1])
    blen = np.linalg.norm(bnl, axis=1)
    boundary = BoundarySegments(
        node=bnode, ends=ends, normal=bnl / blen[:, None], length=blen,
        tag=np.concatenate([p.boundary_tags, p.boundary_tags]),
        point=quarter_index(bnode, np.concatenate([bedge, bedge])))
    return NodalDomains(
        area=np.bincount(node, area, n),
        second_moment=np.column_stack([np.bincount(node, moments[:, c], n) for c in range(3)]),
        subcell_node=node, subcell_area=area, subcell_centroid=centroid,
        smoothing_points=smoothing_points, subcell_point=subcell_point,
        subcell_normal_length=nl, cell_ptr=cell_ptr, cell_point=cell_point,
        cell_normal_length=cell_nl, boundary=boundary)
