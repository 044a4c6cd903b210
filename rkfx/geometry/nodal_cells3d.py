"""Conforming 3-D nodal domains for SCNI: median-dual cells of a tetrahedralization, and grid boxes.

SCNI smooths the gradient of a shape function over the nodal domain Omega_L by the divergence
theorem (eq. 3.55, here in 3-D):

    grad~ N_I(x_L) = 1/V_L int_{Omega_L} grad N_I dV = 1/V_L int_{Gamma_L} N_I n dA
                   ~= 1/V_L sum_G N_I(x_G) S_G,

with the cell's boundary Gamma_L cut into planar facets G of outward area vector S_G = n_G A_G
and smoothing point x_G at the facet's area centroid. One point per planar facet integrates
linear functions exactly, so the sum is exact for linear N_I when the facets close the cell:
sum_G S_G = 0 and sum_G x_G (outer) S_G = V_L I. Cells that conform (each interior facet
shared by the two cells on either side, with opposite vectors and one common point) make
sum_L V_L grad~ N_I the boundary sum of N_I n A alone: the integration constraint of the
linear patch test.

The stabilization of eq. (3.56)-(3.60) needs subcells C of each cell with volumes V_C summing
to V_L and their centroids x_hat_C (the stabilization points).

* ``median_dual_cells``: in each tetrahedron T the region of vertex v,
  {lambda_v >= lambda_w for every other vertex w}, is a convex hexahedron with corners v, the
  three edge midpoints m_vw, the three centroids of the faces through v and the centroid g
  of T. Its faces away from v are, per edge (v, w), the quadrilateral (m_vw, c_f1, g, c_f2)
  in the plane lambda_v = lambda_w, shared with w's region; its faces through v lie on the
  faces of T and cancel against the neighbouring tetrahedron's, except on the boundary.
  Subcells: one per edge (v, w) at v, the pyramids with apex x_v over the quadrilaterals of
  that edge in the tetrahedra around it.
* ``box_cells``: the Voronoi boxes of a tensor grid, the seed's 13-point rule (node, 6 face
  points, 6 pyramid subcells).

Every quantity of a median-dual cell is an affine invariant of its tetrahedron, so each has a
fixed barycentric form (derived on the reference tetrahedron, where the swap c <-> d of the
two vertices off the edge is a symmetry):

* quadrilateral of edge (a, b): area centroid (13 (x_a + x_b) + 5 (x_c + x_d)) / 36, area
  vector (x_c + x_d - x_a - x_b) x (x_d - x_c) / 24, pointing from a to b when (a, b, c, d)
  is an even permutation of a positively oriented tetrahedron;
* pyramid with apex x_a over it: volume V_T / 12, centroid (25 x_a + 13 x_b + 5 (x_c + x_d)) / 48;
* boundary quadrilateral (v, m_vb, centroid, m_vc) of a boundary triangle (v, b, c): area A / 3,
  area centroid (22 x_v + 7 (x_b + x_c)) / 36.
"""
from dataclasses import dataclass

import numba
import numpy as np

from rkfx.errors import InputError
from rkfx.geometry.particles3d import BOX_SIDES, TET_EDGES, Particles3D, tetrahedron_volumes


@dataclass(frozen=True)
class BoundaryFacets:
    """The cells' facets on the solid's boundary, each owned by one node.

    Attributes:
        node: Owning node, shape ``(b,)``.
        point: Index of the facet's area centroid among ``NodalCells3D.points``, shape ``(b,)``.
        normal: Outward unit normal, shape ``(b, 3)``.
        area: Facet area, shape ``(b,)`` [m^2].
        tag: Boundary tag of the parent boundary face (``Particles3D.boundary_tags``), shape ``(b,)``.
    """

    node: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    area: np.ndarray
    tag: np.ndarray


@dataclass(frozen=True)
class NodalCells3D:
    """Nodal domains Omega_L, their planar facets and subcells: the data of SCNI in 3-D.

    Attributes:
        volume: V_L, shape ``(num_nodes,)`` [m^3].
        points: Smoothing points x_G, the area centroids of the cells' facets, shape ``(q, 3)`` [m];
            an interior facet shared by two cells appears once.
        facet_ptr: The facets of cell L are ``facet_ptr[L]:facet_ptr[L + 1]``, shape ``(num_nodes + 1,)``.
        facet_point: Smoothing point of each facet, index into ``points``, shape ``(F,)``.
        facet_vector: Outward area vector S_G = n_G A_G of each facet for its cell, shape
            ``(F, 3)`` [m^2]; a shared facet appears in both cells with opposite vectors.
            A boundary node's boundary facets are among its cell's facets.
        subcell_node: Node L of each subcell C, shape ``(c,)``; subcells are grouped by node
            in increasing node order.
        subcell_volume: V_C > 0, summing to V_L per node, shape ``(c,)`` [m^3].
        subcell_centroid: Stabilization point x_hat_C, shape ``(c, 3)`` [m].
        boundary: The facets on the solid's boundary.
    """

    volume: np.ndarray
    points: np.ndarray
    facet_ptr: np.ndarray
    facet_point: np.ndarray
    facet_vector: np.ndarray
    subcell_node: np.ndarray
    subcell_volume: np.ndarray
    subcell_centroid: np.ndarray
    boundary: BoundaryFacets

    @property
    def num_nodes(self) -> int:
        return len(self.volume)

    @property
    def facet_node(self) -> np.ndarray:
        """The cell of each facet, shape ``(F,)``."""
        return np.repeat(np.arange(self.num_nodes), np.diff(self.facet_ptr))

    @property
    def subcell_ptr(self) -> np.ndarray:
        """The subcells of node L are ``subcell_ptr[L]:subcell_ptr[L + 1]``, shape ``(num_nodes + 1,)``."""
        ptr = np.zeros(self.num_nodes + 1, np.int64)
        np.cumsum(np.bincount(self.subcell_node, minlength=self.num_nodes), out=ptr[1:])
        return ptr

    def smoothed_gradient(self, values: np.ndarray) -> np.ndarray:
        """Smoothed gradients (eq. 3.55) at the nodes of a field given at the smoothing points.

        Args:
            values: The field at ``points``, shape ``(q,)`` or ``(q, k)``.

        Returns:
            1/V_L sum_G values(x_G) S_G, shape ``(num_nodes, 3)`` or ``(num_nodes, k, 3)``.
        """
        v = np.asarray(values, float)
        flat = v.reshape(len(v), -1)[self.facet_point]  # (F, k)
        node = self.facet_node
        out = np.empty((self.num_nodes, flat.shape[1], 3))
        for j in range(flat.shape[1]):
            for d in range(3):
                out[:, j, d] = np.bincount(node, flat[:, j] * self.facet_vector[:, d], self.num_nodes)
        out /= self.volume[:, None, None]
        return out[:, 0] if v.ndim == 1 else out


@numba.njit(cache=True)
def _dual_quads(x, tet, edges, edge_of, vol, ns):
    """Per tetrahedron t and edge e = (a, b, c, d) of ``edges``: the area centroid and area
    vector (a -> b) of the edge's quadrilateral, shape ``(m, 6, 3)`` each; and the pyramids
    over it with apex x_a and x_b summed into subcells ``2 edge_of[t, e] + (a > b)`` and
    ``2 edge_of[t, e] + (b > a)``: their volumes, shape ``(ns,)``, and first moments,
    shape ``(ns, 3)``. Barycentric forms: see the module docstring."""
    m = tet.shape[0]
    points = np.empty((m, 6, 3))
    vector = np.empty((m, 6, 3))
    sub_volume = np.zeros(ns)
    sub_moment = np.zeros((ns, 3))
    u = np.empty(3)
    w = np.empty(3)
    for t in range(m):
        v12 = vol[t] / 12.0  # every pyramid over an edge quadrilateral is V_T / 12
        for e in range(6):
            a, b, c, d = tet[t, edges[e, 0]], tet[t, edges[e, 1]], tet[t, edges[e, 2]], tet[t, edges[e, 3]]
            sa = 2 * edge_of[t, e] + (a > b)
            sb = 2 * edge_of[t, e] + (b > a)
            sub_volume[sa] += v12
            sub_volume[sb] += v12
            for k in range(3):
                cd = x[c, k] + x[d, k]
                points[t, e, k] = (13.0 * (x[a, k] + x[b, k]) + 5.0 * cd) / 36.0
                sub_moment[sa, k] += v12 * (25.0 * x[a, k] + 13.0 * x[b, k] + 5.0 * cd) / 48.0
                sub_moment[sb, k] += v12 * (25.0 * x[b, k] + 13.0 * x[a, k] + 5.0 * cd) / 48.0
                u[k] = cd - x[a, k] - x[b, k]
                w[k] = x[d, k] - x[c, k]
            vector[t, e, 0] = (u[1] * w[2] - u[2] * w[1]) / 24.0
            vector[t, e, 1] = (u[2] * w[0] - u[0] * w[2]) / 24.0
            vector[t, e, 2] = (u[0] * w[1] - u[1] * w[0]) / 24.0
    return points, vector, sub_volume, sub_moment


@numba.njit(cache=True)
def _facet_lists(tet, edges, vector, bnode, bpoint, bvector, n):
    """The facets of every cell grouped by cell (a counting sort, O(F)): the pointer, points
    and vectors. Per cell, its quadrilaterals in tetrahedron then edge order, then its
    boundary facets. ``vector[t, e]`` points from vertex ``edges[e, 0]`` to ``edges[e, 1]``."""
    m = tet.shape[0]
    ptr = np.zeros(n + 1, np.int64)
    for t in range(m):
        for e in range(6):
            ptr[tet[t, edges[e, 0]] + 1] += 1
            ptr[tet[t, edges[e, 1]] + 1] += 1
    for f in range(len(bnode)):
        ptr[bnode[f] + 1] += 1
    for i in range(n):
        ptr[i + 1] += ptr[i]
    fill = ptr[:-1].copy()
    point = np.empty(ptr[n], np.int64)
    vec = np.empty((ptr[n], 3))
    for t in range(m):
        for e in range(6):
            a, b = tet[t, edges[e, 0]], tet[t, edges[e, 1]]
            ka, kb = fill[a], fill[b]
            fill[a] += 1
            fill[b] += 1
            point[ka] = 6 * t + e
            point[kb] = 6 * t + e
            for d in range(3):
                vec[ka, d] = vector[t, e, d]
                vec[kb, d] = -vector[t, e, d]
    for f in range(len(bnode)):
        k = fill[bnode[f]]
        fill[bnode[f]] += 1
        point[k] = bpoint[f]
        for d in range(3):
            vec[k, d] = bvector[f, d]
    return ptr, point, vec


def _selected(n: int, nodes: np.ndarray) -> np.ndarray:
    """Mask of ``nodes`` among ``n``."""
    mine = np.zeros(n, bool)
    mine[np.asarray(nodes, np.int64)] = True
    return mine


def _index(a: np.ndarray) -> np.ndarray:
    """Point indices as int32 where they fit (F is ~70 per node: 0.28 GB less at 10^6 nodes)."""
    return a.astype(np.int32) if a.size == 0 or a.max() < np.iinfo(np.int32).max else a


def _boundary_facets(p: Particles3D, first_point: int) -> tuple[BoundaryFacets, np.ndarray, np.ndarray]:
    """Each boundary triangle (v0, v1, v2) cut into its 3 vertex quadrilaterals (v, m_vb,
    centroid, m_vc), planar and in the triangle's plane; facet 3 f + j belongs to vertex j of
    face f and has point ``first_point + 3 f + j``. Also returns their points and area vectors."""
    x, f = p.x, p.boundary_faces
    x0, x1, x2 = x[f[:, 0]], x[f[:, 1]], x[f[:, 2]]
    third = np.cross(x1 - x0, x2 - x0) / 6.0  # a third of the outward area vector
    area = np.linalg.norm(third, axis=1)
    pts = np.stack([(22.0 * x0 + 7.0 * (x1 + x2)) / 36.0, (22.0 * x1 + 7.0 * (x2 + x0)) / 36.0,
                    (22.0 * x2 + 7.0 * (x0 + x1)) / 36.0], axis=1).reshape(-1, 3)
    k = len(f)
    facets = BoundaryFacets(node=f.reshape(-1), point=first_point + np.arange(3 * k),
                            normal=np.repeat(third / area[:, None], 3, axis=0), area=np.repeat(area, 3),
                            tag=np.repeat(p.boundary_tags, 3))
    return facets, pts, np.repeat(third, 3, axis=0)


def median_dual_cells(p: Particles3D, nodes: np.ndarray | None = None) -> NodalCells3D:
    """Median-dual nodal domains of a tetrahedralization, with one subcell per edge end.

    Smoothing points: 6 per tetrahedron (one per edge quadrilateral, point ``6 t + e`` for the
    edge ``TET_EDGES[e]`` of tetrahedron t), then 3 per boundary triangle. Subcells: for each
    edge (v, w) of the tetrahedralization, one at v and one at w, each the union of the
    pyramids with apex at its node over the edge's quadrilaterals; node v's subcells come in
    increasing order of w. Pyramids over boundary facets have no volume and are no subcells.
    Compiled loops over the tetrahedra: a 47^3 grid's cells (10^5 nodes) in about a second.

    ``nodes`` (indices, e.g. a rank's own nodes) builds only the tetrahedra around them (t then
    counts those, in their order): the cells, volumes and subcells of those nodes equal the
    whole build's value for value, in the same order; the other nodes' cells are partial or
    empty. Node indices stay global; the boundary facets are whole.
    """
    x, tet, n = p.x, p.tetrahedra, p.num_nodes
    if nodes is not None:
        tet = np.ascontiguousarray(tet[_selected(n, nodes)[tet].any(axis=1)])
    m = len(tet)
    vol = tetrahedron_volumes(x, tet)
    a, b = tet[:, TET_EDGES[:, 0]], tet[:, TET_EDGES[:, 1]]  # (m, 6)
    key = np.minimum(a, b) * n + np.maximum(a, b)
    edge_key, edge_of = np.unique(key.ravel(), return_inverse=True)
    edge_of = edge_of.reshape(m, 6)
    ns = 2 * len(edge_key)  # subcell 2 E + s: edge E at its low (s = 0) or high (s = 1) node
    points, vector, sub_volume, sub_moment = _dual_quads(x, tet, TET_EDGES, edge_of, vol, ns)
    boundary, bpoints, bvector = _boundary_facets(p, 6 * m)
    ptr, facet_point, facet_vector = _facet_lists(tet, TET_EDGES[:, :2].copy(), vector, boundary.node,
                                                  boundary.point, bvector, n)
    # Subcells grouped by node. Edges come sorted by (low, high) node, so a stable sort of the
    # interleaved (low, high) ends leaves each node's subcells in increasing order of the other node.
    sub_node = np.column_stack([edge_key // n, edge_key % n]).reshape(-1)
    order = np.argsort(sub_node, kind="stable")
    return NodalCells3D(
        volume=np.bincount(tet.reshape(-1), np.repeat(vol / 4.0, 4), n),
        points=np.concatenate([points.reshape(-1, 3), bpoints]),
        facet_ptr=ptr, facet_point=_index(facet_point), facet_vector=facet_vector,
        subcell_node=sub_node[order], subcell_volume=sub_volume[order],
        subcell_centroid=sub_moment[order] / sub_volume[order, None], boundary=boundary)


def box_cells(p: Particles3D, nodes: np.ndarray | None = None) -> NodalCells3D:
    """Voronoi boxes of a tensor grid (``p.grid``): the seed's 13-point rule.

    Node (i, j, k) owns the box between the mid-planes around it (half, quarter or eighth boxes
    on the boundary). Its 6 facets, in the order -x, +x, -y, +y, -z, +z, are the box's faces,
    each with one smoothing point at its centre; an interior face is shared with the one
    neighbour box across it. Subcells: the pyramids with apex at the node over the faces; a
    boundary node lies on its boundary faces, whose pyramids are empty and dropped, so interior
    nodes have 6 subcells, face nodes 5, edge nodes 4 and corner nodes 3. Boundary facets are
    tagged with the tags ``p`` gives the names ``left``, ``right``, ``front``, ``back``,
    ``bottom``, ``top`` (0 where it has no such name).

    Smoothing points: the faces normal to x, numbered ``p + (nx + 1) (j + ny k)`` for the face on
    plane p = 0..nx, then those normal to y (``i + nx (q + (ny + 1) k)``), then to z.

    ``nodes`` (indices, e.g. a rank's own nodes) builds only their cells, equal to the whole
    build's value for value; the other nodes' cells are empty (no facets or subcells, volume
    0). Node indices and the smoothing points' numbering stay global; the boundary facets are
    whole.

    Raises:
        InputError: ``p`` is no tensor grid, or its nodes are not the grid's (x fastest).
    """
    if p.grid is None:
        raise InputError("box_cells needs a tensor-grid node set (graded_box or box, p.grid set); "
                         "use median_dual_cells for this one")
    lines = [np.asarray(c, float) for c in p.grid]
    shape = tuple(len(c) for c in lines)  # (nx, ny, nz)
    z, y, xg = np.meshgrid(lines[2], lines[1], lines[0], indexing="ij")
    node_x = np.column_stack([xg.ravel(), y.ravel(), z.ravel()])
    scale = max(float(np.ptp(c)) for c in lines)
    if node_x.shape != p.x.shape or np.abs(node_x - p.x).max() > 1e-12 * scale:
        raise InputError("the nodes are not the tensor grid p.grid in x-fastest order; "
                         "build them with graded_box or use median_dual_cells")
    # Per axis: the planes bounding the boxes (ends and interval midpoints), the boxes' widths
    # and centres along that axis.
    planes = [np.r_[c[0], 0.5 * (c[1:] + c[:-1]), c[-1]] for c in lines]
    width = [np.diff(q) for q in planes]
    centre = [0.5 * (q[1:] + q[:-1]) for q in planes]
    n = p.num_nodes
    sel = np.arange(n) if nodes is None else np.flatnonzero(_selected(n, nodes))
    ijk = np.unravel_index(sel, shape[::-1])[::-1]  # (i, j, k) of every built node
    volume = np.zeros(n)
    volume[sel] = width[0][ijk[0]] * width[1][ijk[1]] * width[2][ijk[2]]
    points, first, count = [], [], 0
    for axis in range(3):
        # Faces normal to ``axis``: a grid of (planes along axis) x (boxes along the others).
        dims = [centre[d] if d != axis else planes[d] for d in range(3)]
        zz, yy, xx = np.meshgrid(dims[2], dims[1], dims[0], indexing="ij")
        points.append(np.column_stack([xx.ravel(), yy.ravel(), zz.ravel()]))
        first.append(count)
        count += xx.size
    points = np.concatenate(points)
    facet_point, facet_vector, sub_volume = _box_faces(ijk, shape, planes, width, lines, first)
    sub_centroid = node_x[sel, None, :] + 0.75 * (points[facet_point] - node_x[sel, None, :])
    keep = sub_volume > 0.0  # exactly 0 for a boundary node's faces on the boundary planes
    # Boundary facets: the faces on the end planes, one per boundary node and side.
    whole = np.unravel_index(np.arange(n), shape[::-1])[::-1] if nodes is not None else ijk
    bnode, bface, btag = [], [], []
    for name, axis, end in BOX_SIDES:
        on = np.flatnonzero(whole[axis] == (shape[axis] - 1 if end else 0))
        bnode.append(on)
        bface.append(np.full(len(on), 2 * axis + end))
        btag.append(np.full(len(on), p.boundary_names.get(name, 0), np.int64))
    bnode, bface = np.concatenate(bnode), np.concatenate(bface)
    b_point, b_vector, _ = _box_faces(tuple(c[bnode] for c in whole), shape, planes, width, lines, first)
    rows = np.arange(len(bnode))
    bvec = b_vector[rows, bface]
    barea = np.linalg.norm(bvec, axis=1)
    boundary = BoundaryFacets(node=bnode, point=b_point[rows, bface], normal=bvec / barea[:, None],
                              area=barea, tag=np.concatenate(btag))
    counts = np.zeros(n, np.int64)
    counts[sel] = 6
    return NodalCells3D(
        volume=volume, points=points, facet_ptr=np.r_[0, np.cumsum(counts)],
        facet_point=_index(facet_point.reshape(-1)), facet_vector=facet_vector.reshape(-1, 3),
        subcell_node=np.repeat(sel, 6)[keep.reshape(-1)], subcell_volume=sub_volume[keep],
        subcell_centroid=sub_centroid[keep], boundary=boundary)


def _box_faces(ijk, shape, planes, width, lines, first) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The 6 faces of the boxes of the grid nodes ``ijk`` (index arrays i, j, k of k nodes):
    smoothing point ``(k, 6)``, outward area vector ``(k, 6, 3)`` and the volume of the pyramid
    with apex at the node over each face ``(k, 6)``."""
    m = len(ijk[0])
    facet_point = np.empty((m, 6), np.int64)
    facet_vector = np.zeros((m, 6, 3))
    sub_volume = np.empty((m, 6))
    for axis in range(3):
        fshape = [s + (d == axis) for d, s in enumerate(shape)]
        others = [d for d in range(3) if d != axis]
        area = width[others[0]][ijk[others[0]]] * width[others[1]][ijk[others[1]]]
        for side in (0, 1):  # the face below (-) and above (+) the node along ``axis``
            f = 2 * axis + side
            idx = list(ijk)
            idx[axis] = ijk[axis] + side
            facet_point[:, f] = first[axis] + idx[0] + fshape[0] * (idx[1] + fshape[1] * idx[2])
            facet_vector[:, f, axis] = area if side else -area
            # Pyramid with apex at the node: a third of base area x height.
            sub_volume[:, f] = area * np.abs(planes[axis][idx[axis]] - lines[axis][ijk[axis]]) / 3.0
    return facet_point, facet_vector, sub_volume
