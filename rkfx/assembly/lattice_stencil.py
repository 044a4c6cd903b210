"""Lattice stencils: the subcell products of an explicit step on a uniform particle grid
without index arrays or per-row values.

On a uniform grid numbered row by row (``rkfx.geometry.particles.structured``: particle
j nx + i), every particle far from the boundary and the cracks has the same subcell rows
grad~N_I(x_hat_C) up to round-off, shifted by its index: one template row per subcell slot
(4 quadrants of about 13 entries). The products of ``rkfx.assembly.smeared_strain`` over
such rows become stencils over runs of consecutive particles in a grid row: each template
entry adds a shifted contiguous slice of the coefficients (strains) or of the subcell loads
(force) to the run, a loop that vectorizes, where the sparse product gathers one entry at a
time and reads 20 bytes per entry (index and two values). The cell averages, the damaged
subcell stresses and the subcell loads are formed in the same passes. Rows near the
boundary, the cracks and the slits stay sparse rows.

Exactness. The rows' entries are ordered by column (``sort_rows``) and the rows that match
the template to ``TEMPLATE_RTOL`` become the template (``snap_to_template``: a change of the
size of the round-off the rows carry). The stencils then add the same numbers in the same
order as the sparse products over these rows: strains in each row's entry order, forces in
the row order of each node's transposed row, no fused multiply-adds. Stencil and sparse
products agree bit for bit.

On MPI ranks each rank's share (``rkfx.assembly.local_strain``) has its rows snapped to the
same template and runs the same stencils over the box of grid positions its rows and their
nodes span (``share_stencil``): its local coefficients are scattered into the box, and the
subcell loads of the ghost rows, received from their owners, are placed there before the
force stencils run. A distributed run is therefore still the serial run bit for bit.

The template is the rows of one particle every rank can build: the lowest-numbered
particle farther than its support plus two cell diagonals from the boundary and from every
crack (``template_particle``).
"""
from dataclasses import dataclass

import numba
import numpy as np

from rkfx.approximation.shape_functions import RKApproximation
from rkfx.approximation.sparse_rows import SparseRows, ranges, sort_by_column
from rkfx.assembly.row_products import (damaged_stress, node_force, particle_average, particle_load, particle_stress,
                                        row_strain)

# Rows within this relative distance of the template (max |row - template| / max |template|)
# become the template; interior rows of a uniform grid differ by a few 1e-16.
TEMPLATE_RTOL = 1e-12
# Grid coordinates within this fraction of the spacing of a uniform grid count as on it.
GRID_RTOL = 1e-9


@dataclass(frozen=True)
class Lattice:
    """A uniform ``nx`` x ``ny`` particle grid numbered row by row (particle j nx + i)."""

    nx: int
    ny: int

    def ij(self, index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        index = np.asarray(index)
        return index % self.nx, index // self.nx

    def offsets(self, shift: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(di, dj) of index shifts ``dj nx + di`` with |di| < nx / 2."""
        shift = np.asarray(shift, np.int64)
        dj = np.floor_divide(shift + self.nx // 2, self.nx)
        return shift - dj * self.nx, dj


def lattice_of(x: np.ndarray) -> Lattice | None:
    """The uniform grid of the particles ``x`` (shape ``(n, 2)``) if they are one, numbered
    row by row; else ``None``."""
    x = np.asarray(x, float)
    n = len(x)
    if n < 4:
        return None
    nx = int(np.argmax(x[:, 1] != x[0, 1])) if np.any(x[:, 1] != x[0, 1]) else n
    if nx < 2 or n % nx:
        return None
    ny = n // nx
    gx = x[:, 0].reshape(ny, nx)
    gy = x[:, 1].reshape(ny, nx)
    hx = (gx[0, -1] - gx[0, 0]) / (nx - 1)
    hy = (gy[-1, 0] - gy[0, 0]) / max(ny - 1, 1)
    if ny < 2 or not (hx > 0 and hy > 0):
        return None
    on_x = np.abs(gx - (gx[0, 0] + hx * np.arange(nx))[None, :]).max() <= GRID_RTOL * hx
    on_y = np.abs(gy - (gy[0, 0] + hy * np.arange(ny))[:, None]).max() <= GRID_RTOL * hy
    return Lattice(nx, ny) if on_x and on_y else None


def template_particle(x: np.ndarray, rk: RKApproximation) -> int | None:
    """The particle whose subcell rows are the template: the lowest-numbered one farther than
    its support plus two cell diagonals (which bound its smoothing points' distance) from the
    grid's edge and from every crack; ``None`` if ``x`` is no uniform grid or none is."""
    lat = lattice_of(x)
    if lat is None:
        return None
    x = np.asarray(x, float)
    lo, hi = x.min(axis=0), x.max(axis=0)
    h = (hi - lo) / (np.array([lat.nx, lat.ny]) - 1)
    margin = rk.support.max() + 2.0 * np.hypot(*h)
    inside = np.all((x - lo >= margin) & (hi - x >= margin), axis=1)
    if rk.cracks is not None:
        for a, b in rk.cracks.segments:
            inside &= _distance_to_segment(x, a, b) >= margin
    found = np.flatnonzero(inside)
    return int(found[0]) if found.size else None


def _distance_to_segment(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    t = np.clip((x - a) @ ab / max(ab @ ab, 1e-300), 0.0, 1.0)
    return np.linalg.norm(x - (a + t[:, None] * ab), axis=1)


@dataclass(frozen=True)
class Template:
    """The subcell rows of the template particle, relative to it: slot s has the entries
    ``ptr[s]:ptr[s+1]``, each an index shift and a gradient."""

    ptr: np.ndarray
    shift: np.ndarray
    grad: np.ndarray

    @property
    def slots(self) -> int:
        return len(self.ptr) - 1


@dataclass(frozen=True)
class Snap:
    """What snapping a build's rows found: the ``template`` (index shifts on the ``lattice``) and
    which particles have its rows (``matched``, shape ``(n,)``; only built rows can match)."""

    template: Template
    lattice: Lattice
    matched: np.ndarray


def sort_rows(rows: SparseRows) -> None:
    """Order the entries of every row by column, in place (so that equal rows of shifted
    particles list their entries in the same order)."""
    sort_by_column(rows.indptr, rows.indices, rows.data)


def template_rows(rows: SparseRows, ptr: np.ndarray, particle: int) -> Template:
    """The rows ``ptr[particle]:ptr[particle+1]`` of ``rows`` as a ``Template``."""
    r0, r1 = ptr[particle], ptr[particle + 1]
    q0, q1 = rows.indptr[r0], rows.indptr[r1]
    return Template(np.ascontiguousarray(rows.indptr[r0:r1 + 1] - q0),
                    np.ascontiguousarray(rows.indices[q0:q1].astype(np.int64) - particle),
                    np.ascontiguousarray(rows.data[q0:q1]))


@numba.njit(parallel=True, cache=True)
def _snap(indptr, indices, data, ptr, tptr, shift, grad, tol, fits, matched):
    for ell in numba.prange(len(ptr) - 1):
        if not fits[ell] or ptr[ell + 1] - ptr[ell] != len(tptr) - 1:
            continue
        same = True
        for s in range(len(tptr) - 1):
            r = ptr[ell] + s
            if indptr[r + 1] - indptr[r] != tptr[s + 1] - tptr[s]:
                same = False
                break
            for e in range(tptr[s + 1] - tptr[s]):
                q = indptr[r] + e
                t = tptr[s] + e
                if indices[q] - ell != shift[t] or abs(data[q, 0] - grad[t, 0]) > tol \
                        or abs(data[q, 1] - grad[t, 1]) > tol:
                    same = False
                    break
            if not same:
                break
        if same:
            for s in range(len(tptr) - 1):
                r = ptr[ell] + s
                for e in range(tptr[s + 1] - tptr[s]):
                    data[indptr[r] + e, 0] = grad[tptr[s] + e, 0]
                    data[indptr[r] + e, 1] = grad[tptr[s] + e, 1]
            matched[ell] = True


def snap_to_template(rows: SparseRows, ptr: np.ndarray, template: Template, lattice: Lattice) -> np.ndarray:
    """Replace, in place, the subcell rows of every particle that match the template (same
    slots, same index shifts, gradients within ``TEMPLATE_RTOL``) by the template; returns
    which particles matched, shape ``(n,)`` bool. Particles whose shifted template would leave
    the grid never match (no wrap-around from one grid row to the next)."""
    n = len(ptr) - 1
    di, dj = lattice.offsets(template.shift)
    i, j = lattice.ij(np.arange(n))
    fits = (i + di.min() >= 0) & (i + di.max() < lattice.nx) & (j + dj.min() >= 0) & (j + dj.max() < lattice.ny)
    matched = np.zeros(n, np.bool_)
    tol = TEMPLATE_RTOL * max(np.abs(template.grad).max(), 1e-300)
    _snap(rows.indptr, rows.indices, rows.data, ptr, template.ptr, template.shift, template.grad, tol, fits, matched)
    return matched


def _runs(flags: np.ndarray, nx: int) -> tuple[np.ndarray, np.ndarray]:
    """Start and length of the runs of consecutive True ``flags`` within each grid row."""
    f = np.asarray(flags, np.int8).reshape(-1, nx)
    edge = np.diff(np.pad(f, ((0, 0), (1, 1))), axis=1)
    row, start = np.nonzero(edge == 1)
    _, stop = np.nonzero(edge == -1)
    return np.ascontiguousarray(row * nx + start, np.int64), np.ascontiguousarray(stop - start, np.int64)


@dataclass(frozen=True)
class LatticeStencil:
    """The products of an MSCNI operator (``rkfx.assembly.smeared_strain.Stabilization``) with
    the template rows as stencils, fused with the cell averages and the subcell loads; bit for
    bit the sparse products over the same rows.

    The stencils run over *positions* of a grid numbered row by row: the whole lattice for the
    whole operator (position = particle = node), or the box of a rank's share
    (``share_stencil``), into which the local coefficients are scattered and the subcell loads
    of the ghost rows placed; runs start at a position and write from a point (strains, loads)
    or a node (force) of the operator's own numbering.

    Attributes:
        template: The rows every matched particle has (``Template``), entries by column, index
            shifts over the positions.
        strain_start, strain_point, strain_length: Runs of consecutive matched particles in a
            grid row: first position, first point, length.
        sparse_particles: The other points, and ``sparse_rows`` their subcell rows.
        force_shift, force_slot, force_grad: The template's entries in the order in which a
            node's transposed row meets them (shift descending, slot ascending).
        force_start, force_node, force_length: Runs of nodes whose transposed rows are the
            template's alone: first position, first node, length.
        sparse_nodes: The other nodes (their sparse transposed product), and
            ``load_particles`` the points whose rows are read as rows (by the sparse nodes, or
            by other ranks).
        positions: The number of positions.
        node_position: Position of each node of the coefficients (-1: outside the box), or
            ``None`` (position = node).
        ghost_rows, ghost_slot, ghost_position: The ghost rows of matched particles, their
            slots and their particles' positions (a share's only).
    """

    template: Template
    strain_start: np.ndarray
    strain_point: np.ndarray
    strain_length: np.ndarray
    sparse_particles: np.ndarray
    sparse_rows: np.ndarray
    force_shift: np.ndarray
    force_slot: np.ndarray
    force_grad: np.ndarray
    force_start: np.ndarray
    force_node: np.ndarray
    force_length: np.ndarray
    sparse_nodes: np.ndarray
    load_particles: np.ndarray
    positions: int
    node_position: np.ndarray | None = None
    ghost_rows: np.ndarray | None = None
    ghost_slot: np.ndarray | None = None
    ghost_position: np.ndarray | None = None

    @property
    def coverage(self) -> tuple[float, float]:
        """The fractions of subcell rows and of nodes the stencils evaluate."""
        rows = self.template.slots * self.strain_length.sum()
        return rows / (rows + len(self.sparse_rows)), self.force_length.sum() / (
            self.force_length.sum() + len(self.sparse_nodes))

    def strains(self, rows: SparseRows, ptr: np.ndarray, fraction: np.ndarray,
                d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The cell strains ``(n, 3)`` and the subcell differences ``(num_rows, 3)`` of
        ``rows`` (the snapped rows this stencil was built from), as ``cell_average`` of the
        sparse product gives them."""
        n = len(ptr) - 1
        cell = np.empty((n, 3))
        sub = np.empty((rows.num_rows, 3))
        if self.node_position is None:
            ux, uy = np.ascontiguousarray(d[0::2]), np.ascontiguousarray(d[1::2])
        else:
            ux, uy = np.empty(self.positions), np.empty(self.positions)  # read at the nodes' positions only
            _scatter(d, self.node_position, ux, uy)
        t = self.template
        _stencil_strains(ux, uy, ptr, fraction, self.strain_start, self.strain_point, self.strain_length, t.ptr,
                         t.shift, t.grad, cell, sub)
        _sparse_strains(rows.indptr, rows.indices, rows.data, d, ptr, fraction, self.sparse_rows,
                        self.sparse_particles, cell, sub)
        return cell, sub

    def loads(self, ptr: np.ndarray, fraction: np.ndarray, weight: np.ndarray, volume: np.ndarray,
              stress: np.ndarray, sub_stress: np.ndarray, load: np.ndarray) -> np.ndarray:
        """The subcell loads of ``subcell_load`` (``sub_stress`` empty: none): slot major by
        position for the runs (returned), and as rows into ``load`` for ``load_particles``."""
        with_sub = sub_stress.shape[0] > 0
        slot_major = np.empty((self.template.slots, 3, self.positions))
        _stencil_loads(ptr, fraction, weight, volume, stress, sub_stress, with_sub, self.strain_start,
                       self.strain_point, self.strain_length, slot_major)
        _particle_loads(ptr, fraction, weight, volume, stress, sub_stress, with_sub, self.load_particles, load)
        return slot_major

    def damaged_loads(self, ptr: np.ndarray, fraction: np.ndarray, weight: np.ndarray, volume: np.ndarray,
                      stress: np.ndarray, differences: np.ndarray, c: np.ndarray, damage: np.ndarray,
                      load: np.ndarray) -> np.ndarray:
        """``loads`` with the subcell stresses (1 - D_L) C ``differences``, formed as the loads
        are (``rkfx.assembly.smeared_strain.damaged_subcell_stress``: the same numbers);
        ``differences`` is overwritten."""
        slot_major = np.empty((self.template.slots, 3, self.positions))
        _stencil_damaged_loads(ptr, fraction, weight, volume, stress, differences, c, damage, self.strain_start,
                               self.strain_point, self.strain_length, slot_major)
        _particle_damaged_loads(ptr, fraction, weight, volume, stress, differences, c, damage, self.load_particles,
                                load)
        return slot_major

    def transposed(self, slot_major: np.ndarray, load: np.ndarray, rows_t: SparseRows, unit: np.ndarray,
                   out: np.ndarray) -> np.ndarray:
        """The interleaved force of the loads into ``out``: by stencil from ``slot_major`` (the
        ghost rows' loads placed there first), over the sparse nodes' transposed rows from
        ``load``, in subcell order."""
        if self.ghost_rows is not None and len(self.ghost_rows):
            slot_major[self.ghost_slot, :, self.ghost_position] = load[self.ghost_rows]
        _stencil_force(slot_major, self.force_start, self.force_node, self.force_length, self.force_shift,
                       self.force_slot, self.force_grad, out)
        _nodes_force(rows_t.indptr, rows_t.indices, rows_t.data, load, unit, self.sparse_nodes, out)
        return out

    def force(self, rows_t: SparseRows, ptr: np.ndarray, fraction: np.ndarray, weight: np.ndarray,
              volume: np.ndarray, stress: np.ndarray, sub_stress: np.ndarray, unit: np.ndarray) -> np.ndarray:
        """The interleaved force of the nodal stresses and the subcell stresses (``sub_stress``
        empty: none) through the subcell loads, as ``subcell_load`` and the sparse transposed
        product over ``rows_t`` (row weights ``unit``, ones) give it, shape ``(2 n,)``."""
        load = np.empty((len(fraction), 3))
        slot_major = self.loads(ptr, fraction, weight, volume, stress, sub_stress, load)
        return self.transposed(slot_major, load, rows_t, unit, np.empty(2 * (len(ptr) - 1)))

    def damaged_force(self, rows_t: SparseRows, ptr: np.ndarray, fraction: np.ndarray, weight: np.ndarray,
                      volume: np.ndarray, stress: np.ndarray, differences: np.ndarray, c: np.ndarray,
                      damage: np.ndarray, unit: np.ndarray) -> np.ndarray:
        """``force`` with the subcell stresses of ``damaged_loads``; ``differences`` is overwritten."""
        load = np.empty((len(fraction), 3))
        slot_major = self.damaged_loads(ptr, fraction, weight, volume, stress, differences, c, damage, load)
        return self.transposed(slot_major, load, rows_t, unit, np.empty(2 * (len(ptr) - 1)))


def lattice_stencil(rows: SparseRows, ptr: np.ndarray, matched: np.ndarray, template: Template,
                    lattice: Lattice) -> LatticeStencil:
    """The stencils of the snapped ``rows`` (grouped by particle, ``ptr``) whose particles
    ``matched`` have the ``template`` rows. A node's force is a stencil where every row that
    reads the node is a matched particle's and there are as many as the template has entries."""
    n = len(ptr) - 1
    s_start, s_length = _runs(matched, lattice.nx)
    row_particle = np.repeat(np.arange(n), np.diff(ptr))
    sparse_rows = np.flatnonzero(~matched[row_particle]).astype(np.int64)
    counts = np.bincount(rows.indices, minlength=n)
    foreign = np.bincount(rows.indices[_entries(rows.indptr, sparse_rows)], minlength=n)
    alone = (counts == len(template.shift)) & (foreign == 0)
    f_start, f_length = _runs(alone, lattice.nx)
    sparse_nodes = np.flatnonzero(~alone).astype(np.int64)
    # The particles whose rows read a sparse node (their loads in subcell order).
    touched = np.zeros(n, np.bool_)
    touched[sparse_nodes] = True
    reads = np.zeros(rows.num_rows, np.bool_)
    _rows_reading(rows.indptr, rows.indices, touched, reads)
    load_particles = np.unique(row_particle[reads]).astype(np.int64)
    return _stencil(template, template.shift, s_start, s_start, s_length, np.flatnonzero(~matched), sparse_rows,
                    f_start, f_start, f_length, sparse_nodes, load_particles, n)


def share_stencil(snap: Snap, points: np.ndarray, rows: SparseRows, ptr: np.ndarray, nodes: np.ndarray,
                  rows_t: SparseRows, row_particle: np.ndarray, row_slot: np.ndarray,
                  sent_rows: np.ndarray) -> LatticeStencil:
    """The stencils of a rank's share of a snapped operator (``rkfx.assembly.local_strain``),
    over the box of grid positions its rows and their nodes span.

    Args:
        snap: The share's snapping (template, lattice, matched particles, global numbering).
        points: Global index of the owned points (particles), ascending; their ``rows`` (over
            the local nodes) by ``ptr``.
        nodes: Global index of the local nodes, the owned ones (= ``points``) first; those
            outside the box of the rows and their nodes (constraint columns) are left out.
        rows_t: Each owned node's entries over the local rows (owned rows first).
        row_particle, row_slot: Particle (global) and slot of each local row.
        sent_rows: The owned rows other ranks read (their loads are needed as rows).
    """
    lat, template = snap.lattice, snap.template
    owned = len(points)
    gi, gj = lat.ij(np.concatenate([nodes[np.unique(rows.indices)], row_particle]))
    i0, j0 = gi.min(), gj.min()
    nxb, nyb = gi.max() - i0 + 1, gj.max() - j0 + 1
    box = Lattice(int(nxb), int(nyb))

    def position(index):
        i, j = lat.ij(index)
        return (j - j0) * nxb + (i - i0)

    di, dj = lat.offsets(template.shift)
    shift = dj * nxb + di
    matched_row = snap.matched[row_particle]
    mine = snap.matched[points]
    at = position(points)
    flags = np.zeros(box.nx * box.ny, np.bool_)
    flags[at[mine]] = True
    s_start, s_length = _runs(flags, box.nx)
    point_at = np.full(len(flags), -1, np.int64)
    point_at[at] = np.arange(owned)
    owned_rows = ptr[-1]
    sparse_rows = np.flatnonzero(~matched_row[:owned_rows]).astype(np.int64)
    counts = np.diff(rows_t.indptr)
    foreign = np.bincount(np.repeat(np.arange(len(counts)), counts), weights=~matched_row[rows_t.indices],
                          minlength=len(counts))
    alone = (counts == len(template.shift)) & (foreign == 0)
    flags[:] = False
    flags[at[alone]] = True
    f_start, f_length = _runs(flags, box.nx)
    sparse_nodes = np.flatnonzero(~alone).astype(np.int64)
    read = rows_t.indices[_entries(rows_t.indptr, sparse_nodes)]
    read = np.concatenate([read[read < owned_rows], np.asarray(sent_rows, np.int64)])
    load_particles = np.unique(np.searchsorted(ptr, read, side="right") - 1).astype(np.int64)
    ghosts = np.flatnonzero(matched_row[owned_rows:]) + owned_rows
    position_of = np.where(_in_box(lat.ij(nodes), i0, j0, nxb, nyb), position(nodes), -1)
    return _stencil(template, shift, s_start, point_at[s_start], s_length, np.flatnonzero(~mine), sparse_rows,
                    f_start, point_at[f_start], f_length, sparse_nodes, load_particles, box.nx * box.ny,
                    node_position=position_of.astype(np.int64), ghost_rows=ghosts.astype(np.int64),
                    ghost_slot=np.asarray(row_slot[ghosts], np.int64),
                    ghost_position=position(row_particle[ghosts]).astype(np.int64))


def _in_box(ij, i0, j0, nx, ny) -> np.ndarray:
    i, j = ij
    return (i >= i0) & (i < i0 + nx) & (j >= j0) & (j < j0 + ny)


def _stencil(template: Template, shift: np.ndarray, s_start, s_point, s_length, sparse_particles, sparse_rows,
             f_start, f_node, f_length, sparse_nodes, load_particles, positions: int, **box) -> LatticeStencil:
    """A ``LatticeStencil`` of the ``template`` with index ``shift`` over the positions."""
    slot = np.repeat(np.arange(template.slots), np.diff(template.ptr))
    order = np.lexsort((slot, -shift))
    i64 = lambda a: np.ascontiguousarray(a, np.int64)  # noqa: E731
    return LatticeStencil(Template(template.ptr, i64(shift), template.grad), i64(s_start), i64(s_point),
                          i64(s_length), i64(sparse_particles), i64(sparse_rows), i64(shift[order]), i64(slot[order]),
                          np.ascontiguousarray(template.grad[order]), i64(f_start), i64(f_node), i64(f_length),
                          i64(sparse_nodes), i64(load_particles), int(positions), **box)


@numba.njit(parallel=True, cache=True)
def _rows_reading(indptr, indices, nodes, out):
    """out[row] = whether the row has an entry in a column flagged by ``nodes``."""
    for row in numba.prange(len(indptr) - 1):
        for q in range(indptr[row], indptr[row + 1]):
            if nodes[indices[q]]:
                out[row] = True
                break


def _entries(indptr: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """The entry positions of ``rows``."""
    return ranges(indptr[rows], indptr[rows + 1] - indptr[rows])


# --------------------------------------------------------------------------- kernels
# No fastmath: the stencils must round as the sparse products do (the same sums in the same
# order, no fused multiply-adds); the loops over a run still vectorize, its particles being
# independent. Four entries per pass over a run keep the sums in registers between them.


@numba.njit(cache=True, boundscheck=False)
def _add_strain(a0, a1, a2, ux, uy, gx, gy, m):
    for x in range(m):
        u = ux[x]
        v = uy[x]
        a0[x] += gx * u
        a1[x] += gy * v
        a2[x] += gy * u + gx * v


@numba.njit(cache=True, boundscheck=False)
def _add_strain4(a0, a1, a2, u0, v0, u1, v1, u2, v2, u3, v3, g, t, m):
    gx0, gy0, gx1, gy1 = g[t, 0], g[t, 1], g[t + 1, 0], g[t + 1, 1]
    gx2, gy2, gx3, gy3 = g[t + 2, 0], g[t + 2, 1], g[t + 3, 0], g[t + 3, 1]
    for x in range(m):
        b0 = a0[x]
        b1 = a1[x]
        b2 = a2[x]
        b0 += gx0 * u0[x]
        b1 += gy0 * v0[x]
        b2 += gy0 * u0[x] + gx0 * v0[x]
        b0 += gx1 * u1[x]
        b1 += gy1 * v1[x]
        b2 += gy1 * u1[x] + gx1 * v1[x]
        b0 += gx2 * u2[x]
        b1 += gy2 * v2[x]
        b2 += gy2 * u2[x] + gx2 * v2[x]
        b0 += gx3 * u3[x]
        b1 += gy3 * v3[x]
        b2 += gy3 * u3[x] + gx3 * v3[x]
        a0[x] = b0
        a1[x] = b1
        a2[x] = b2


@numba.njit(parallel=True, cache=True)
def _stencil_strains(ux, uy, ptr, fraction, start, point, length, tptr, shift, grad, cell, sub):
    """Subcell strains of the runs by the template, then their cell averages and differences."""
    slots = len(tptr) - 1
    for r in numba.prange(len(start)):
        first = start[r]
        m = length[r]
        acc = np.empty((slots, 3, m))
        for s in range(slots):
            a0, a1, a2 = acc[s, 0], acc[s, 1], acc[s, 2]
            a0[:] = 0.0
            a1[:] = 0.0
            a2[:] = 0.0
            t = tptr[s]
            while t + 4 <= tptr[s + 1]:
                o0, o1, o2, o3 = first + shift[t], first + shift[t + 1], first + shift[t + 2], first + shift[t + 3]
                _add_strain4(a0, a1, a2, ux[o0:o0 + m], uy[o0:o0 + m], ux[o1:o1 + m], uy[o1:o1 + m],
                             ux[o2:o2 + m], uy[o2:o2 + m], ux[o3:o3 + m], uy[o3:o3 + m], grad, t, m)
                t += 4
            while t < tptr[s + 1]:
                o = first + shift[t]
                _add_strain(a0, a1, a2, ux[o:o + m], uy[o:o + m], grad[t, 0], grad[t, 1], m)
                t += 1
        for x in range(m):  # particle_average, from the accumulators
            ell = point[r] + x
            p0 = ptr[ell]
            c0 = 0.0
            c1 = 0.0
            c2 = 0.0
            for s in range(slots):
                f = fraction[p0 + s]
                c0 += f * acc[s, 0, x]
                c1 += f * acc[s, 1, x]
                c2 += f * acc[s, 2, x]
            cell[ell, 0] = c0
            cell[ell, 1] = c1
            cell[ell, 2] = c2
            for s in range(slots):
                sub[p0 + s, 0] = c0 - acc[s, 0, x]
                sub[p0 + s, 1] = c1 - acc[s, 1, x]
                sub[p0 + s, 2] = c2 - acc[s, 2, x]


@numba.njit(parallel=True, cache=True)
def _sparse_strains(indptr, indices, grad, d, ptr, fraction, rows, particles, cell, sub):
    for k in numba.prange(len(rows)):
        row_strain(indptr, indices, grad, d, rows[k], sub)
    for k in numba.prange(len(particles)):
        particle_average(ptr, fraction, sub, particles[k], cell)


@numba.njit(parallel=True, cache=True)
def _stencil_loads(ptr, fraction, weight, volume, stress, sub_stress, with_sub, start, point, length, out):
    """particle_load of the runs' particles into out[s, :, position] (slot major)."""
    for r in numba.prange(len(start)):
        for x in range(length[r]):
            ell = point[r] + x
            at = start[r] + x
            t0, t1, t2 = particle_stress(ptr, weight, volume, stress, sub_stress, with_sub, ell)
            for s in range(out.shape[0]):
                c = ptr[ell] + s
                f = fraction[c]
                out[s, 0, at] = f * t0
                out[s, 1, at] = f * t1
                out[s, 2, at] = f * t2
                if with_sub:
                    out[s, 0, at] -= weight[c] * sub_stress[c, 0]
                    out[s, 1, at] -= weight[c] * sub_stress[c, 1]
                    out[s, 2, at] -= weight[c] * sub_stress[c, 2]


@numba.njit(parallel=True, cache=True)
def _stencil_damaged_loads(ptr, fraction, weight, volume, stress, diff, c, damage, start, point, length, out):
    """_stencil_loads with the subcell stresses (1 - D_L) C diff formed on the way."""
    slots = out.shape[0]
    for r in numba.prange(len(start)):
        sub = np.empty((slots, 3))
        for x in range(length[r]):
            ell = point[r] + x
            at = start[r] + x
            scale = 1.0 - damage[ell]
            p0 = ptr[ell]
            for s in range(slots):
                e0, e1, e2 = diff[p0 + s, 0], diff[p0 + s, 1], diff[p0 + s, 2]
                for j in range(3):
                    sub[s, j] = damaged_stress(c, scale, e0, e1, e2, j)
            t0 = volume[ell] * stress[ell, 0]
            t1 = volume[ell] * stress[ell, 1]
            t2 = volume[ell] * stress[ell, 2]
            for s in range(slots):
                w = weight[p0 + s]
                t0 += w * sub[s, 0]
                t1 += w * sub[s, 1]
                t2 += w * sub[s, 2]
            for s in range(slots):
                f = fraction[p0 + s]
                w = weight[p0 + s]
                out[s, 0, at] = f * t0 - w * sub[s, 0]
                out[s, 1, at] = f * t1 - w * sub[s, 1]
                out[s, 2, at] = f * t2 - w * sub[s, 2]


@numba.njit(parallel=True, cache=True)
def _particle_damaged_loads(ptr, fraction, weight, volume, stress, diff, c, damage, particles, out):
    """_particle_loads with the subcell stresses formed first (in place of ``diff``)."""
    for k in numba.prange(len(particles)):
        ell = particles[k]
        scale = 1.0 - damage[ell]
        for q in range(ptr[ell], ptr[ell + 1]):
            e0, e1, e2 = diff[q, 0], diff[q, 1], diff[q, 2]
            for j in range(3):
                diff[q, j] = damaged_stress(c, scale, e0, e1, e2, j)
        particle_load(ptr, fraction, weight, volume, stress, diff, True, ell, out)


@numba.njit(parallel=True, cache=True)
def _particle_loads(ptr, fraction, weight, volume, stress, sub_stress, with_sub, particles, out):
    for k in numba.prange(len(particles)):
        particle_load(ptr, fraction, weight, volume, stress, sub_stress, with_sub, particles[k], out)


@numba.njit(cache=True, boundscheck=False)
def _add_force(fx, fy, t0, t1, t2, gx, gy, m):
    for x in range(m):
        fx[x] += gx * t0[x] + gy * t2[x]
        fy[x] += gy * t1[x] + gx * t2[x]


@numba.njit(parallel=True, cache=True)
def _stencil_force(slot_major, start, node, length, shift, slot, grad, out):
    for r in numba.prange(len(start)):
        first = start[r]
        m = length[r]
        fx = np.empty(m)
        fy = np.empty(m)
        fx[:] = 0.0
        fy[:] = 0.0
        for t in range(len(shift)):
            o = first - shift[t]
            s = slot[t]
            _add_force(fx, fy, slot_major[s, 0, o:o + m], slot_major[s, 1, o:o + m], slot_major[s, 2, o:o + m],
                       grad[t, 0], grad[t, 1], m)
        for x in range(m):
            out[2 * (node[r] + x)] = fx[x]
            out[2 * (node[r] + x) + 1] = fy[x]


@numba.njit(cache=True)
def _scatter(d, position, ux, uy):
    """ux, uy at the positions of the nodes of interleaved d (nodes at -1 left out)."""
    for k in range(len(position)):
        at = position[k]
        if at >= 0:
            ux[at] = d[2 * k]
            uy[at] = d[2 * k + 1]


@numba.njit(parallel=True, cache=True)
def _nodes_force(indptr, indices, grad, load, unit, nodes, out):
    for k in numba.prange(len(nodes)):
        node_force(indptr, indices, grad, load, unit, nodes[k], out)
