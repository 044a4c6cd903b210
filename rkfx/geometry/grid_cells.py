"""Rectangular nodal domains of a tensor grid: the Voronoi cells of ``rkfx.geometry.particles.graded`` nodes.

The cell of node (i, j) (node index j nx + i, the order of ``graded``) is the rectangle
[xm_i, xm_i+1] x [ym_j, ym_j+1] with xm = (xs_0, midpoints of the grid intervals, xs_nx-1) and
likewise ym, so cells of boundary nodes are half cells and corner cells quarter cells. Each
cell is cut through its node into (up to) four quadrant subcells, each a rectangle with
counter-clockwise vertices (x_L, a point on one cell side, the cell corner, a point on the
other cell side), the convention of the median-dual subcells (``rkfx.geometry.nodal_domains``);
quadrants of zero area (beyond the domain boundary) are dropped.

All cell and subcell sides lie on the *refined grid*: the lines through the nodes and the
midlines between them. Every side is one refined-grid segment with one smoothing point, its
midpoint, shared by the two cells (or subcells) on either side of it, so the divergence sums
of SCNI cancel exactly inside the domain.

Slits. Cell faces may be declared slits (pre-existing cracks lying on the midlines). A face
segment on a slit is not shared: each of the two cells gets its own smoothing point, moved off
the slit by 1e-9 times the grid interval across it towards its own node, so that an RK
approximation with the same crack (``rkfx.approximation.diffraction``, diffraction method) evaluates each cell's
side on that cell's side of the crack. The offset perturbs the smoothed gradients of the cells
along a slit by ~1e-9 relative to the field's gradient; no boundary segments are made on slits
(their faces are traction-free).
"""
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from rkfx.errors import InputError, point_str
from rkfx.geometry.nodal_domains import BoundarySegments, NodalDomains

SLIT_OFFSET = 1e-9  # slit smoothing points: distance off the slit / grid interval across it
_TOL = 1e-9  # coordinate matching tolerance / grid extent
# Boundary tags of ``rkfx.geometry.particles.graded`` (its parts are tagged in this order from 1).
TAGS = {"bottom": 1, "right": 2, "top": 3, "left": 4}
# Quadrants (sx, sy), counter-clockwise around the node.
_SX = np.array([1, -1, -1, 1])
_SY = np.array([1, 1, -1, -1])
# The quadrant across a quadrant's side through the node: horizontal side (flip sy), vertical (flip sx).
_ACROSS_H = np.array([3, 2, 1, 0])
_ACROSS_V = np.array([1, 0, 3, 2])


def _coordinates(name: str, c) -> np.ndarray:
    c = np.asarray(c, dtype=np.float64)
    if c.ndim != 1 or len(c) < 2 or not np.isfinite(c).all() or not np.all(np.diff(c) > 0):
        raise InputError(f"{name} must be a finite, strictly increasing 1-D array of >= 2 grid coordinates")
    return c


def _refined(c: np.ndarray) -> np.ndarray:
    """Node coordinates interleaved with the interval midpoints: c_0, m_1, c_1, ..., c_n-1."""
    r = np.empty(2 * len(c) - 1)
    r[0::2] = c
    r[1::2] = 0.5 * (c[1:] + c[:-1])
    return r


def grid_domains(xs: np.ndarray, ys: np.ndarray, slits: Sequence | None = (),
                 nodes: np.ndarray | None = None) -> NodalDomains:
    """Rectangular nodal domains of the grid ``xs`` x ``ys`` with quadrant subcells (vectorised).

    Args:
        xs, ys: Strictly increasing grid coordinates [m]; nodes in the order of
            ``rkfx.geometry.particles.graded(xs, ys)``.
        slits: Axis-aligned segments ((x0, y0), (x1, y1)) [m] on cell faces: on a midline
            between two grid rows (or columns), from and to grid or mid-grid coordinates.
        nodes: Node indices (e.g. a rank's particles and those near them) whose cells and
            subcells alone are built, equal entry for entry to the whole build's; areas,
            moments and the boundary stay whole, the other nodes get no cell segments, and the
            smoothing points are only those the built cells and the boundary use.

    Returns:
        ``NodalDomains`` with ``subcell_vertices`` filled; ``boundary`` tags as ``graded``'s
        (``TAGS``).

    Raises:
        InputError: Bad coordinates, or a slit not on cell faces.
    """
    xs, ys = _coordinates("xs", xs), _coordinates("ys", ys)
    slits = [] if slits is None else list(slits)
    nx, ny = len(xs), len(ys)
    n = nx * ny
    xb, yb = _refined(xs), _refined(ys)
    kx, ky = len(xb) - 1, len(yb) - 1  # refined intervals per line
    # Smoothing points: vertical segments V(l, b) on x = xb[l], y in [yb[b], yb[b+1]], then
    # horizontal segments H(l, a) on y = yb[l], x in [xb[a], xb[a+1]].
    num_v = len(xb) * ky
    total = num_v + len(yb) * kx
    xmid, ymid = 0.5 * (xb[1:] + xb[:-1]), 0.5 * (yb[1:] + yb[:-1])

    def coordinates(ids):  # of the smoothing points ids (< total)
        out = np.empty((len(ids), 2))
        v = ids < num_v
        out[v, 0], out[v, 1] = xb[ids[v] // ky], ymid[ids[v] % ky]
        h = ids[~v] - num_v
        out[~v, 0], out[~v, 1] = xmid[h % kx], yb[h // kx]
        return out

    def vseg(l, b):
        return l * ky + b

    def hseg(l, a):
        return num_v + l * kx + a

    # Quadrants (node, q), node-major; those of zero area are dropped.
    i = np.tile(np.arange(nx), ny)[:, None]
    j = np.repeat(np.arange(ny), nx)[:, None]
    sx, sy = _SX[None, :], _SY[None, :]
    keep = ((sx > 0) & (i < nx - 1) | (sx < 0) & (i > 0)) & ((sy > 0) & (j < ny - 1) | (sy < 0) & (j > 0))
    node, q = np.nonzero(keep)
    whole_area, whole_moments = _integrals(keep, i[:, 0], j[:, 0], xb, yb)
    if nodes is not None:
        mine = np.zeros(n, bool)
        mine[np.asarray(nodes, np.int64)] = True
        built = mine[node]
        node, q = node[built], q[built]
    i, j, sx, sy = i[node, 0], j[node, 0], _SX[q], _SY[q]
    lx0, ly0, lx1, ly1 = 2 * i, 2 * j, 2 * i + sx, 2 * j + sy
    ax, ay = np.minimum(lx0, lx1), np.minimum(ly0, ly1)  # refined intervals spanned
    xn, yn, xf, yf = xb[lx0], yb[ly0], xb[lx1], yb[ly1]
    # Sides: horizontal through the node, vertical far, horizontal far, vertical through the node.
    h_near, v_far, h_far, v_near = hseg(ly0, ax), vseg(lx1, ay), hseg(ly1, ax), vseg(lx0, ay)
    # Counter-clockwise: vertices node, (far x, node y), far corner, (node x, far y) with sides
    # h_near, v_far, h_far, v_near where sx sy > 0; the other quadrants take them in reverse.
    ccw = sx * sy > 0
    vx = (xn, np.where(ccw, xf, xn), xf, np.where(ccw, xn, xf))
    vy = (yn, np.where(ccw, yn, yf), yf, np.where(ccw, yf, yn))
    verts = np.empty((len(node), 4, 2))
    for k in range(4):
        verts[:, k, 0], verts[:, k, 1] = vx[k], vy[k]
    side_point = np.stack([np.where(ccw, h_near, v_near), np.where(ccw, v_far, h_far),
                           np.where(ccw, h_far, v_far), np.where(ccw, v_near, h_near)], axis=1)
    # The far sides are cell sides; a side through the node is one where the quadrant across
    # it is missing (on the domain boundary).
    h_open, v_open = ~keep[node, _ACROSS_H[q]], ~keep[node, _ACROSS_V[q]]
    outer = np.ones((len(node), 4), bool)
    outer[:, 0] = np.where(ccw, h_open, v_open)
    outer[:, 3] = np.where(ccw, v_open, h_open)
    slit_points, shift = np.zeros(0, np.int64), np.zeros((0, 2))
    if slits:
        side_point, slit_points, shift = _split_slits(slits, xs, ys, xb, yb, total, coordinates, side_point,
                                                      verts[:, 0], num_v)
    a, b = xf - xn, yf - yn
    boundary = _boundary(xb, yb, kx, ky, nx, vseg, hseg)
    # The smoothing points: every one, or (nodes given) those in use, in their order; the
    # points on slits moved off them to the low side, their copies (numbered from total) to the high.
    used = np.ones(total + len(slit_points), bool)
    if nodes is not None:
        used[:] = False
        used[side_point] = used[boundary.point] = True
        number = np.cumsum(used) - 1
        side_point, boundary = number[side_point], replace(boundary, point=number[boundary.point])
    points = _placed_points(np.flatnonzero(used), total, coordinates, slit_points, shift)
    return NodalDomains(
        area=whole_area, second_moment=whole_moments,
        subcell_node=node, subcell_area=np.abs(a * b),
        subcell_centroid=np.column_stack([xn + 0.5 * a, yn + 0.5 * b]),
        smoothing_points=points, subcell_point=side_point, subcell_outer=outer,
        boundary=boundary, subcell_vertices=verts)


def _placed_points(ids, total, coordinates, slit_points, shift):
    """The coordinates of the smoothing points ``ids`` (ascending): those below ``total`` at
    ``coordinates``, the ones on slits moved by ``-shift``, and copy k (id ``total`` + k) at
    slit point k moved by ``+shift``."""
    base = ids < total
    points = np.empty((len(ids), 2))
    points[base] = coordinates(ids[base])
    copy = np.full(total, -1, np.int64)
    copy[slit_points] = np.arange(len(slit_points))
    low = np.flatnonzero(base)[copy[ids[base]] >= 0]
    points[low] -= shift[copy[ids[low]]]
    high = ids[~base] - total
    points[~base] = coordinates(slit_points[high]) + shift[high]
    return points


def _integrals(keep, i, j, xb, yb):
    """Area and second moments (about the node) of every node's cell: the sums over its kept
    quadrants in their order, (a, b) = far corner - node."""
    n = len(i)
    area, moments = np.zeros(n), np.zeros((n, 3))
    for q in range(4):
        k = keep[:, q]
        a = np.where(k, xb[np.clip(2 * i + _SX[q], 0, len(xb) - 1)] - xb[2 * i], 0.0)
        b = np.where(k, yb[np.clip(2 * j + _SY[q], 0, len(yb) - 1)] - yb[2 * j], 0.0)
        quadrant = np.abs(a * b)
        area += quadrant
        moments[:, 0] += a * a * quadrant / 3
        moments[:, 1] += 0.25 * a * b * quadrant
        moments[:, 2] += b * b * quadrant / 3
    return area, moments


def _boundary(xb, yb, kx, ky, nx, vseg, hseg) -> BoundarySegments:
    """The domain boundary as the refined-grid segments on it, counter-clockwise, each owned
    by the node at its nearer end."""
    a, b = np.arange(kx), np.arange(ky)
    ny = (ky + 2) // 2
    top, right = len(yb) - 1, len(xb) - 1
    parts = [  # (tag, owner, start, end, point)
        (TAGS["bottom"], (a + 1) // 2, np.c_[xb[a], np.full(kx, yb[0])], np.c_[xb[a + 1], np.full(kx, yb[0])],
         hseg(0, a)),
        (TAGS["right"], ((b + 1) // 2) * nx + nx - 1, np.c_[np.full(ky, xb[-1]), yb[b]],
         np.c_[np.full(ky, xb[-1]), yb[b + 1]], vseg(right, b)),
        (TAGS["top"], (ny - 1) * nx + (a + 1) // 2, np.c_[xb[a + 1], np.full(kx, yb[-1])],
         np.c_[xb[a], np.full(kx, yb[-1])], hseg(top, a)),
        (TAGS["left"], ((b + 1) // 2) * nx, np.c_[np.full(ky, xb[0]), yb[b + 1]],
         np.c_[np.full(ky, xb[0]), yb[b]], vseg(0, b)),
    ]
    ends = np.concatenate([np.stack([s, e], axis=1) for _, _, s, e, _ in parts])
    d = ends[:, 1] - ends[:, 0]
    nl = np.column_stack([d[:, 1], -d[:, 0]])
    length = np.linalg.norm(nl, axis=1)
    return BoundarySegments(
        node=np.concatenate([o for _, o, _, _, _ in parts]).astype(np.int64), ends=ends,
        normal=nl / length[:, None], length=length,
        tag=np.concatenate([np.full(len(o), t, np.int64) for t, o, _, _, _ in parts]),
        point=np.concatenate([p for *_, p in parts]).astype(np.int64))


def _split_slits(slits, xs, ys, xb, yb, total, coordinates, side_point, node_xy, num_v):
    """Give each cell its own smoothing point on the face segments lying on ``slits``: the
    low-side cell keeps the point, to be moved down (or left); the high-side cell gets a copy
    (numbered ``total`` + k), to be moved up (or right), each by ``SLIT_OFFSET`` times the grid
    interval across the slit. Returns the sides' points, the points on slits and their shifts."""
    scale = max(np.ptp(xs), np.ptp(ys))
    tol = _TOL * scale
    kx, ky = len(xb) - 1, len(yb) - 1
    on_slit = np.zeros(total, bool)
    offset = np.zeros(total)
    for k, slit in enumerate(slits):
        s = np.asarray(slit, dtype=np.float64)
        where = f"slit {k} {point_str(s[0])}-{point_str(s[1])}" if s.shape == (2, 2) else f"slit {k}"
        if s.shape != (2, 2) or not np.isfinite(s).all():
            raise InputError(f"{where} must be two finite end points ((x0, y0), (x1, y1))")
        horizontal = abs(s[1, 1] - s[0, 1]) <= tol < abs(s[1, 0] - s[0, 0])
        vertical = abs(s[1, 0] - s[0, 0]) <= tol < abs(s[1, 1] - s[0, 1])
        if not (horizontal or vertical):
            raise InputError(f"{where} is not an axis-aligned segment of positive length; slits must run "
                             "along grid midlines (horizontal or vertical)")
        across, along, grid, axis = (yb, xb, ys, "y") if horizontal else (xb, yb, xs, "x")
        c = s[:, 1 if horizontal else 0].mean()
        mid = across[1:-1:2]  # interior midlines
        line = 2 * int(np.argmin(np.abs(mid - c))) + 1 if len(mid) else -1
        if line < 0 or abs(across[line] - c) > tol:
            raise InputError(f"{where} does not lie on a cell face: {axis} = {c:.6g} is not midway between "
                             f"two grid {'rows' if horizontal else 'columns'}; put slits on the lines halfway "
                             "between grid lines, or shift the grid")
        lo, hi = np.sort(s[:, 0 if horizontal else 1])
        a0, a1 = (int(np.argmin(np.abs(along - e))) for e in (lo, hi))
        if abs(along[a0] - lo) > tol or abs(along[a1] - hi) > tol or a1 <= a0:
            other = "x" if horizontal else "y"
            raise InputError(f"{where} does not end on a cell corner or side midpoint: its ends {other} = "
                             f"{lo:.6g}, {hi:.6g} must be grid coordinates or midpoints between them "
                             "(within the grid)")
        seg = np.arange(a0, a1)
        idx = num_v + line * kx + seg if horizontal else line * ky + seg
        on_slit[idx] = True
        offset[idx] = SLIT_OFFSET * (grid[(line + 1) // 2] - grid[(line - 1) // 2])
    slit_points = np.flatnonzero(on_slit)
    normal = np.where((slit_points < num_v)[:, None], [1.0, 0.0], [0.0, 1.0])
    shift = offset[slit_points, None] * normal
    copy = np.full(total, -1, np.int64)
    copy[slit_points] = total + np.arange(len(slit_points))
    # Sides on a slit whose node lies on the high side of it take the copy.
    sub, side = np.nonzero(on_slit[side_point])
    at = side_point[sub, side]
    axis = np.where(at < num_v, 0, 1)
    high = node_xy[sub, axis] > coordinates(at)[np.arange(len(at)), axis]
    side_point[sub[high], side[high]] = copy[at[high]]
    return side_point, slit_points, shift
