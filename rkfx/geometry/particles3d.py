"""Particles in 3-D: nodes, their spacing, and the tetrahedralization their nodal domains are cut from.

The 3-D counterpart of ``rkfx.geometry.particles``. The tetrahedra's vertices are the nodes;
they carry the geometry (boundary triangles tagged by name) and define the conforming nodal
domains of SCNI (``rkfx.geometry.nodal_cells3d``). Factories: ``graded_box`` and ``box``
tensor grids, ``jittered_box`` (an irregular node set for patch tests), and
``rkfx.geometry.gmsh_nodes.from_gmsh_3d`` for gmsh solids.

Grid nodes are numbered x fastest, then y, then z: node (i, j, k) is ``i + nx (j + ny k)``.
"""
from dataclasses import dataclass, field

import numpy as np

from rkfx.errors import InputError, point_str
from rkfx.geometry.particles import NamedBoundary

# Outward faces of a positively oriented tetrahedron (0, 1, 2, 3), face k opposite vertex k:
# det[x1 - x0, x2 - x0, x3 - x0] > 0 puts x3 on the right-hand side of (0, 1, 2), so the
# outward face there is (0, 2, 1); the others follow by even permutations.
TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
# The 6 edges (a, b) of a tetrahedron, each completed to an even permutation (a, b, c, d).
TET_EDGES = np.array([[0, 1, 2, 3], [0, 2, 3, 1], [0, 3, 1, 2], [1, 2, 0, 3], [1, 3, 2, 0], [2, 3, 0, 1]])
# Boundary parts of a box, in tag order: (name, axis, 0 = min / 1 = max end).
BOX_SIDES = (("left", 0, 0), ("right", 0, 1), ("front", 1, 0), ("back", 1, 1), ("bottom", 2, 0), ("top", 2, 1))


@dataclass(frozen=True)
class Particles3D(NamedBoundary):
    """Nodes with spacing, a conforming tetrahedralization and named boundary parts.

    Attributes:
        x: Node coordinates, shape ``(num_nodes, 3)`` [m].
        spacing: Nodal spacing h_I, shape ``(num_nodes,)`` [m].
        tetrahedra: Vertex quadruples, positively oriented (det[x1 - x0, x2 - x0, x3 - x0] > 0),
            shape ``(num_tetrahedra, 4)``.
        boundary_faces: Boundary triangles, oriented so that their right-hand normal points out
            of the solid, shape ``(num_boundary_faces, 3)``.
        boundary_tags: Tag of each boundary face, shape ``(num_boundary_faces,)``; 0 = untagged.
        boundary_names: Name -> tag.
        grid: The coordinate lines ``(xs, ys, zs)`` [m] of a tensor-grid node set (nodes x
            fastest, then y, then z), else ``None``.
    """

    x: np.ndarray
    spacing: np.ndarray
    tetrahedra: np.ndarray
    boundary_faces: np.ndarray
    boundary_tags: np.ndarray
    boundary_names: dict[str, int] = field(default_factory=dict)
    grid: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def num_nodes(self) -> int:
        return len(self.x)

    @property
    def boundary_elements(self) -> np.ndarray:
        return self.boundary_faces

    def volume(self) -> float:
        """Volume of the tetrahedralized solid [m^3]."""
        return float(tetrahedron_volumes(self.x, self.tetrahedra).sum())


def tetrahedron_volumes(x: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Signed volumes det[x1 - x0, x2 - x0, x3 - x0] / 6, shape ``(num_tetrahedra,)`` [m^3]."""
    x0 = x[tets[:, 0]]
    return np.einsum("ij,ij->i", np.cross(x[tets[:, 1]] - x0, x[tets[:, 2]] - x0), x[tets[:, 3]] - x0) / 6.0


def _row_keys(rows: np.ndarray, n: int) -> np.ndarray:
    """One int64 key per row of sorted node indices (each < ``n``), equal for equal rows."""
    k = rows.shape[1]
    if float(n) ** k < 2.0**62:
        key = rows[:, 0].astype(np.int64)
        for c in range(1, k):
            key = key * n + rows[:, c]
        return key
    # Too many nodes for a positional key: rank the rows instead (O(N log N) as well).
    order = np.lexsort(rows.T[::-1])
    new = np.r_[True, np.any(rows[order[1:]] != rows[order[:-1]], axis=1)]
    key = np.empty(len(rows), np.int64)
    key[order] = np.cumsum(new) - 1
    return key


def _parity(rows: np.ndarray) -> np.ndarray:
    """Parity (0 even, 1 odd) of the permutation sorting each row of three distinct indices."""
    a, b, c = rows[:, 0], rows[:, 1], rows[:, 2]
    return ((a > b).astype(np.int8) + (a > c) + (b > c)) % 2


def particles3d(x: np.ndarray, tetrahedra: np.ndarray, tagged_faces: dict[str, np.ndarray] | None = None,
                spacing: np.ndarray | None = None,
                grid: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> Particles3D:
    """Validated ``Particles3D`` from nodes and a tetrahedralization.

    Args:
        x: Node coordinates, shape ``(num_nodes, 3)`` [m].
        tetrahedra: Vertex quadruples, shape ``(num_tetrahedra, 4)``; any orientation.
        tagged_faces: Boundary part name -> its triangles, shape ``(k, 3)`` (node triples, any
            order); parts are tagged 1, 2, ... in the dict's order.
        spacing: Nodal spacing h_I [m], shape ``(num_nodes,)`` or a scalar; default: mean length
            of the tetrahedralization's edges at the node.
        grid: Coordinate lines ``(xs, ys, zs)`` if the nodes are a tensor grid, x fastest.

    Raises:
        InputError: Non-finite nodes, vertex indices out of range, nodes in no tetrahedron,
            degenerate or overlapping tetrahedra, a face shared by more than two tetrahedra, or
            tagged faces that are not on the boundary.
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    tet = np.array(tetrahedra, dtype=np.int64, copy=True)
    if x.ndim != 2 or x.shape[1] != 3 or len(x) < 4:
        raise InputError(f"nodes must have shape (num_nodes >= 4, 3), got {x.shape}")
    n = len(x)
    if tet.ndim != 2 or tet.shape[1] != 4 or len(tet) == 0:
        raise InputError(f"tetrahedra must have shape (num_tetrahedra >= 1, 4), got {tet.shape}")
    bad = np.flatnonzero(~np.isfinite(x).all(axis=1))
    if bad.size:
        raise InputError(f"node {bad[0]} has non-finite coordinates {point_str(x[bad[0]])}; remove or fix it")
    out = np.flatnonzero(((tet < 0) | (tet >= n)).any(axis=1))
    if out.size:
        raise InputError(f"tetrahedron {out[0]} has vertices {tet[out[0]].tolist()} outside 0..{n - 1}; "
                         "index the nodes from 0")
    used = np.zeros(n, bool)
    used[tet.ravel()] = True
    if not used.all():
        i = int(np.flatnonzero(~used)[0])
        raise InputError(f"node {i} at {point_str(x[i])} belongs to no tetrahedron (outside the solid or "
                         "a duplicate); remove it or mesh the solid with it")
    vol = tetrahedron_volumes(x, tet)
    flip = vol < 0
    tet[flip] = tet[flip][:, [0, 1, 3, 2]]
    scale = np.ptp(x, axis=0).max()
    tiny = np.flatnonzero(np.abs(vol) <= 1e-13 * scale**3)
    if tiny.size:
        t = tet[tiny[0]]
        raise InputError(f"degenerate tetrahedron {tiny[0]} (volume {abs(vol[tiny[0]]):.3g} m^3) with nodes "
                         f"{t.tolist()} at {x[t].tolist()}; duplicate or coplanar nodes — remove them or re-mesh")
    bfaces = _boundary_faces(tet, n)
    bkeys = _row_keys(np.sort(bfaces, axis=1), n)
    tags = np.zeros(len(bfaces), np.int64)
    names = {}
    for t, (name, part) in enumerate((tagged_faces or {}).items(), start=1):
        names[name] = t
        part = np.asarray(part, dtype=np.int64).reshape(-1, 3)
        if part.size and (part.min() < 0 or part.max() >= n):
            raise InputError(f"boundary {name!r} names nodes outside 0..{n - 1}")
        fk = _row_keys(np.sort(part, axis=1), n)
        hit = np.isin(fk, bkeys)
        if not hit.all():
            f = part[np.flatnonzero(~hit)[0]]
            raise InputError(f"face {f.tolist()} of boundary {name!r} is not a boundary face of the "
                             "tetrahedralization (interior or no face at all); tag only faces of one tetrahedron")
        tags[np.isin(bkeys, fk)] = t
    if spacing is None:
        spacing = _mean_edge_length(x, tet)
    spacing = np.ascontiguousarray(np.broadcast_to(np.asarray(spacing, float), (n,)))
    if grid is not None:
        grid = tuple(np.asarray(c, float) for c in grid)
        if len(grid) != 3 or np.prod([len(c) for c in grid]) != n:
            raise InputError(f"grid must be 3 coordinate arrays whose sizes multiply to the {n} nodes")
    return Particles3D(x, spacing, tet, bfaces, tags, names, grid)


def _boundary_faces(tet: np.ndarray, n: int) -> np.ndarray:
    """Faces of exactly one tetrahedron, outward, in tetrahedron order (sorted face keys, O(N log N))."""
    faces = tet[:, TET_FACES].reshape(-1, 3)
    srt = np.sort(faces, axis=1)
    key = _row_keys(srt, n)
    order = np.argsort(key)
    ks = key[order]
    start = np.flatnonzero(np.r_[True, ks[1:] != ks[:-1]])
    count = np.diff(np.r_[start, len(ks)])
    if count.max() > 2:
        f = srt[order[start[np.argmax(count)]]]
        raise InputError(f"face {f.tolist()} is shared by {count.max()} tetrahedra; the tetrahedralization "
                         "overlaps itself — re-mesh")
    # Two tetrahedra sharing a face must lie on opposite sides of it: their outward copies of the
    # face run in opposite senses. Same sense = they overlap (e.g. a duplicated tetrahedron).
    pair = start[count == 2]
    f1, f2 = order[pair], order[pair + 1]
    parity = _parity(faces)
    same = np.flatnonzero(parity[f1] == parity[f2])
    if same.size:
        t1, t2 = f1[same[0]] // 4, f2[same[0]] // 4
        raise InputError(f"tetrahedra {t1} and {t2} lie on the same side of their common face "
                         f"{srt[f1[same[0]]].tolist()} (they overlap); remove the duplicate or re-mesh")
    return faces[np.sort(order[start[count == 1]])]


def _mean_edge_length(x: np.ndarray, tet: np.ndarray) -> np.ndarray:
    n = len(x)
    e = np.sort(tet[:, TET_EDGES[:, :2]].reshape(-1, 2), axis=1)
    e = np.unique(e[:, 0] * n + e[:, 1])
    i, j = e // n, e % n
    length = np.linalg.norm(x[i] - x[j], axis=1)
    total = np.bincount(i, length, n) + np.bincount(j, length, n)
    return total / (np.bincount(i, minlength=n) + np.bincount(j, minlength=n))


def _coordinates(name: str, c) -> np.ndarray:
    c = np.asarray(c, dtype=np.float64)
    if c.ndim != 1 or len(c) < 2 or not np.isfinite(c).all() or not np.all(np.diff(c) > 0):
        raise InputError(f"{name} must be a finite, strictly increasing 1-D array of >= 2 coordinates")
    return c


def _kuhn(nx: int, ny: int, nz: int) -> np.ndarray:
    """The 6 Kuhn (Freudenthal) tetrahedra of every grid hexahedron, positively oriented.

    Each hexahedron is cut along its main diagonal (0,0,0) -> (1,1,1): one tetrahedron per order
    in which the path along the cube's edges steps through the axes. Neighbouring hexahedra cut
    their common face along the same diagonal, so the tetrahedralization is conforming.
    """
    node = np.arange(nx * ny * nz).reshape(nz, ny, nx)
    base = node[:-1, :-1, :-1].ravel()
    step = np.array([1, nx, nx * ny])  # node index increment along x, y, z
    tets = []
    for perm, sign in (((0, 1, 2), 1), ((1, 2, 0), 1), ((2, 0, 1), 1),
                       ((0, 2, 1), -1), ((2, 1, 0), -1), ((1, 0, 2), -1)):
        # det[e_a, e_a + e_b, e_a + e_b + e_c] = sign of the permutation (a, b, c).
        v1 = step[perm[0]]
        v2 = v1 + step[perm[1]]
        v3 = step.sum()
        t = np.column_stack([base, base + v1, base + v2, base + v3])
        tets.append(t if sign > 0 else t[:, [0, 2, 1, 3]])
    return np.concatenate(tets)


def _box_faces(nx: int, ny: int, nz: int) -> dict[str, np.ndarray]:
    """The boundary triangles of the Kuhn tetrahedralization, by side (``BOX_SIDES``)."""
    node = np.arange(nx * ny * nz).reshape(nz, ny, nx)
    sides = {"left": node[:, :, 0], "right": node[:, :, -1], "front": node[:, 0, :],
             "back": node[:, -1, :], "bottom": node[0], "top": node[-1]}

    def split(ids):
        # The Kuhn cut of a grid face is its diagonal (low, low) -> (high, high).
        a, b, c, d = ids[:-1, :-1], ids[:-1, 1:], ids[1:, 1:], ids[1:, :-1]
        return np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])

    return {name: split(sides[name]) for name, _, _ in BOX_SIDES}


def _grid_nodes(xs, ys, zs) -> np.ndarray:
    z, y, x = np.meshgrid(zs, ys, xs, indexing="ij")
    return np.column_stack([x.ravel(), y.ravel(), z.ravel()])


def graded_box(xs: np.ndarray, ys: np.ndarray, zs: np.ndarray) -> Particles3D:
    """Tensor grid on the coordinate lines ``xs`` x ``ys`` x ``zs`` (strictly increasing) [m].

    Every hexahedron is split into 6 tetrahedra along the same main diagonal (Kuhn split), so
    the interior median-dual cells of a uniform grid all have volume h_x h_y h_z. Boundary parts:
    ``left``/``right`` (x min/max), ``front``/``back`` (y min/max), ``bottom``/``top`` (z
    min/max), tagged 1..6 in that order. The nodal spacing is the largest interval adjacent to
    the node in x, y and z; ``grid`` is ``(xs, ys, zs)``.
    """
    xs, ys, zs = _coordinates("xs", xs), _coordinates("ys", ys), _coordinates("zs", zs)
    nx, ny, nz = len(xs), len(ys), len(zs)

    def local(c):
        d = np.diff(c)
        return np.maximum(np.r_[d, d[-1]], np.r_[d[0], d])

    hx, hy, hz = local(xs), local(ys), local(zs)
    spacing = np.maximum(np.maximum(hz[:, None, None], hy[None, :, None]), hx[None, None, :]).ravel()
    return particles3d(_grid_nodes(xs, ys, zs), _kuhn(nx, ny, nz), _box_faces(nx, ny, nz), spacing,
                       grid=(xs, ys, zs))


def box(lx: float, ly: float, lz: float, nx: int, ny: int, nz: int,
        origin: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Particles3D:
    """Uniform ``nx`` x ``ny`` x ``nz`` grid of nodes on [0, lx] x [0, ly] x [0, lz] + origin [m]."""
    for name, v in (("nx", nx), ("ny", ny), ("nz", nz)):
        if int(v) != v or v < 2:
            raise InputError(f"{name} = {v!r}: a grid needs an integer >= 2 nodes per direction")
    for name, v in (("lx", lx), ("ly", ly), ("lz", lz)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r}: the box's side lengths must be positive")
    return graded_box(origin[0] + np.linspace(0.0, lx, int(nx)), origin[1] + np.linspace(0.0, ly, int(ny)),
                      origin[2] + np.linspace(0.0, lz, int(nz)))


def jittered_box(n: int, amplitude: float = 0.2, seed: int = 0) -> Particles3D:
    """An ``n``^3 grid on the unit cube with every interior node moved at random by up to
    ``amplitude`` times the spacing in each coordinate: an irregular node set for patch tests.

    Boundary nodes stay on the grid, so the boundary parts are those of ``graded_box``; the
    tetrahedra are the grid's Kuhn split. ``grid`` is ``None`` (the nodes left the grid lines).

    Kuhn tetrahedra are thin (a vertex lies 1/sqrt(2) spacings from the opposite face), so a
    jitter below 1/6 spacing never inverts one, while 0.3 inverts one in most draws from
    n = 10 on. 0.2 (the default) inverted none in 10 seeds up to n = 47.

    Raises:
        InputError: ``amplitude`` outside [0, 0.5), or a draw that would invert a tetrahedron
            (use a smaller amplitude or another seed).
    """
    if int(n) != n or n < 3:
        raise InputError(f"n = {n!r}: a jittered box needs an integer >= 3 nodes per side")
    if not 0.0 <= amplitude < 0.5:
        raise InputError(f"amplitude = {amplitude!r}: use 0 <= amplitude < 0.5 spacings (nodes must not cross)")
    n = int(n)
    h = 1.0 / (n - 1)
    g = np.linspace(0.0, 1.0, n)
    x = _grid_nodes(g, g, g)
    inside = (x > 0.5 * h).all(axis=1) & (x < 1.0 - 0.5 * h).all(axis=1)
    x[inside] += np.random.default_rng(seed).uniform(-amplitude * h, amplitude * h, size=(inside.sum(), 3))
    tet = _kuhn(n, n, n)
    # The Kuhn tetrahedra are built positively oriented; a jittered one that no longer is
    # would be flipped by ``particles3d`` and overlap its neighbours.
    vol = tetrahedron_volumes(x, tet)
    bad = np.flatnonzero(vol <= 0.0)
    if bad.size:
        raise InputError(f"amplitude = {amplitude!r} with seed = {seed!r} inverts tetrahedron {bad[0]} of the "
                         f"Kuhn split (nodes {tet[bad[0]].tolist()}); use amplitude < 1/6 (never inverts) "
                         "or another seed")
    return particles3d(x, tet, _box_faces(n, n, n))
