"""One rank's share of the smeared strain operator: strains at its particles, forces on its nodes.

Explicit dynamics over MPI ranks (``rkfx.models.damage_ranks``) splits the particles over
the ranks (``rkfx.parallel.partition``). A rank owns its particles: the damage points there,
their rows of B~ (with the MSCNI subcell rows, ``rkfx.assembly.smeared_strain``) and the
unknowns of their nodes. Its *local nodes* are its own and its ghost nodes: the nodes in the
supports of its rows, and any the caller adds (the columns of the essential conditions).
Its *local rows* are its own and the ghost rows: rows of other ranks' particles that touch
one of its nodes.

One force evaluation, on local vectors (interleaved over the local nodes):

1. ``strains(d)``: the strains of the owned rows, from local coefficients only;
2. the caller turns them into stresses at its points (a damage law);
3. ``force(stress, ...)``: the loads of the owned rows (the stresses, or the subcell loads
   tau_C of ``Stabilization``), a halo exchange that brings those of the ghost rows, the
   transposed product for the owned nodes, and a halo exchange of the force at the ghost
   nodes (``rkfx.parallel.halo``).

Every sum runs over the same entries in the same order as the serial operator's, so the
strains and forces equal the serial ones bit for bit, and so does a whole explicit run on
any number of ranks. From a ``StrainRecipe`` a rank builds only the rows it reads: its
particles' rows, which become its local rows in place, and apart the rows of the other
particles that touch its nodes (``StrainRecipe.near``); the transposed entries of its nodes
are gathered from both in row order. No rank builds the whole operator or holds two copies
of its rows. On a uniform grid the rows of the share that are the template's run as lattice
stencils over the share's box (``rkfx.assembly.lattice_stencil.share_stencil``), as the
whole operator's do serially.
"""
from dataclasses import dataclass

import numba
import numpy as np

from rkfx.approximation.sparse_rows import SparseRows, gathered_rows, ranges
from rkfx.assembly.lattice_stencil import LatticeStencil, Snap, share_stencil
from rkfx.assembly.smeared_strain import (SmearedStrain, StrainRecipe, cell_average, damaged_subcell_stress,
                                          row_strains, subcell_load, transposed_force)
from rkfx.errors import InputError
from rkfx.parallel.halo import Halo, halo


@dataclass(frozen=True)
class LocalStabilization:
    """What a damage force reads of the local MSCNI terms.

    Attributes:
        owner: Owned point (index among the owned points) of each owned row, ``(num_owned_rows,)``.
    """

    owner: np.ndarray


class LocalNodes:
    """The local nodes of a rank's share of a strain operator: ``nodes`` (global index of every
    local node, the owned ones first), ``owned_nodes`` and ``node_of`` (local index of every
    global node, -1 if not local), the unknowns they carry, and the force's two exchanges over
    ``row_halo`` (loads of the ghost rows) and ``node_halo`` (force at the ghost nodes)."""

    def _exchanged(self, load: np.ndarray, transposed) -> np.ndarray:
        """The local force from the owned rows' ``load``: the ghost rows' loads brought in,
        ``transposed(out)`` writing the owned nodes' force, the ghost nodes' force brought in."""
        self.row_halo.exchange(load)
        f = np.empty(2 * self.num_local)
        transposed(f[:2 * len(self.owned_nodes)])
        self.node_halo.exchange(f.reshape(-1, 2))
        return f

    @property
    def num_local(self) -> int:
        return len(self.nodes)

    @property
    def dofs(self) -> np.ndarray:
        """Global interleaved unknowns of the local nodes, shape ``(2 num_local,)``."""
        return (2 * self.nodes[:, None] + np.arange(2)).ravel()

    def local_dofs(self, dofs: np.ndarray) -> np.ndarray:
        """Local index of global interleaved unknowns (-1 where not local)."""
        node = self.node_of[np.asarray(dofs) // 2]
        return np.where(node >= 0, 2 * node + np.asarray(dofs) % 2, -1)

    @property
    def owned_dofs(self) -> np.ndarray:
        """1.0 on the local unknowns of owned nodes, 0.0 on ghost copies, ``(2 num_local,)``."""
        w = np.zeros((self.num_local, 2))
        w[self.owned_nodes] = 1.0
        return w.ravel()


@dataclass(frozen=True)
class LocalSmearedStrain(LocalNodes):
    """A rank's share of a ``SmearedStrain`` (see the module docstring).

    Attributes:
        nodes: Global index of every local node, shape ``(num_local,)``: the owned nodes first,
            ascending, then the ghosts by owning rank.
        owned_nodes: Local index of every owned node, ``arange(num_owned)``.
        points: Global index of every owned point (= owned particle), ascending, ``(num_owned,)``.
        rows: The owned rows over the local nodes (the serial rows' entries in their order).
        ptr: Owned point k has the owned rows ``ptr[k]:ptr[k + 1]``.
        fraction, weight: A_C / A_L and eps_p A_C of each owned row (MSCNI), else ``None``.
        volume: V_L of each owned point [m^2].
        rows_t: For each owned node, its entries over the local rows (transposed, row order).
        row_weight: Weight of each local row in the transposed product (1, or V_L without MSCNI).
        owned_rows: Local index of each owned row among the local rows (the first ones).
        node_halo, row_halo: The exchanges of ghost nodes and ghost rows.
        stabilization: The MSCNI terms' owners, or ``None`` (plain SCNI).
        node_of: Local index of every global node (-1 if not local), shape ``(n,)``.
        stencil: The products as lattice stencils over the share's box of a uniform grid
            (``rkfx.assembly.lattice_stencil.share_stencil``), or ``None``.
    """

    nodes: np.ndarray
    owned_nodes: np.ndarray
    points: np.ndarray
    rows: SparseRows
    ptr: np.ndarray
    fraction: np.ndarray | None
    weight: np.ndarray | None
    volume: np.ndarray
    rows_t: SparseRows
    row_weight: np.ndarray
    owned_rows: np.ndarray
    node_halo: Halo
    row_halo: Halo
    stabilization: LocalStabilization | None
    node_of: np.ndarray
    stencil: LatticeStencil | None = None

    @property
    def num_nodes(self) -> int:
        """The number of damage points of this rank (its owned particles)."""
        return len(self.points)

    def strain(self, d: np.ndarray) -> np.ndarray:
        """Smeared strains at the owned points, shape ``(num_owned, 3)``, for local d."""
        if self.stabilization is not None:
            return self.strains(d)[0]
        return row_strains(self.rows, d)

    def strains(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The smeared strains ``(num_owned, 3)`` and the MSCNI differences per owned row."""
        if self.stabilization is None:
            raise InputError("this operator has no MSCNI terms; build it with smeared_strain(..., eps_p=1)")
        if self.stencil is not None:
            return self.stencil.strains(self.rows, self.ptr, self.fraction, np.ascontiguousarray(d, np.float64))
        sub = row_strains(self.rows, d)
        return cell_average(self.ptr, self.fraction, sub), sub

    def force(self, stress: np.ndarray, subcell_stress: np.ndarray | None = None) -> np.ndarray:
        """f_int on the local nodes, shape ``(2 num_local,)`` [N], from the stresses at the owned
        points (and the MSCNI subcell stresses of the owned rows). Collective."""
        stress = np.ascontiguousarray(stress, dtype=np.float64)
        load = np.empty((len(self.row_weight), 3))
        mine = load[:len(self.owned_rows)]  # the owned rows come first
        sub = np.empty((0, 3)) if subcell_stress is None else np.ascontiguousarray(subcell_stress, dtype=np.float64)
        if self.stencil is not None:
            return self._stencil_force(self.stencil.loads(self.ptr, self.fraction, self.weight, self.volume, stress,
                                                          sub, load), load)
        if self.stabilization is None:
            mine[...] = stress
        else:
            subcell_load(self.ptr, self.fraction, self.weight, self.volume, stress, sub, mine)
        return self._exchanged(load, lambda out: transposed_force(self.rows_t, load, self.row_weight, out=out))

    def _stencil_force(self, slot_major: np.ndarray, load: np.ndarray) -> np.ndarray:
        """The force of the stencil's loads (slot major, and as rows in ``load``)."""
        return self._exchanged(load, lambda out: self.stencil.transposed(slot_major, load, self.rows_t,
                                                                         self.row_weight, out))

    def damaged_force(self, stress: np.ndarray, differences: np.ndarray, c: np.ndarray,
                      damage: np.ndarray) -> np.ndarray:
        """``force`` with the damaged MSCNI subcell stresses of ``differences`` (as
        ``SmearedStrain.damaged_force``; damage per owned point). Collective."""
        if self.stencil is not None:
            load = np.empty((len(self.row_weight), 3))
            return self._stencil_force(self.stencil.damaged_loads(self.ptr, self.fraction, self.weight, self.volume,
                                                                  np.ascontiguousarray(stress, dtype=np.float64),
                                                                  differences, c, damage, load), load)
        damaged_subcell_stress(differences, c, self.stabilization.owner, damage, differences)
        return self.force(stress, differences)


def local_numbering(owned: np.ndarray, others: np.ndarray, owner: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Local order of global entries: ``owned`` first (ascending), then the ghosts ``others`` by
    owning rank and index (so each neighbour's ghosts are one contiguous block), and the local
    index of every global entry (-1 for the others), shape ``(size,)``."""
    ghosts = np.setdiff1d(others, owned)
    ghosts = ghosts[np.lexsort((ghosts, owner[ghosts]))]
    order = np.concatenate([owned, ghosts])
    local_of = np.full(size, -1, np.int64)
    local_of[order] = np.arange(len(order))
    return order, local_of


@numba.njit(cache=True)
def _renumber(index, new):
    """index[k] = new[index[k]], in place."""
    for k in range(len(index)):
        index[k] = new[index[k]]


@numba.njit(cache=True)
def _mark_columns(indptr, indices, rows, mark):
    for r in rows:
        for e in range(indptr[r], indptr[r + 1]):
            mark[indices[e]] = True


@numba.njit(cache=True)
def _copy_row(indptr, indices, data, r, column, fill, out_rows, out_data):
    for e in range(indptr[r], indptr[r + 1]):
        c = column[indices[e]]
        if c >= 0:
            out_rows[fill[c]] = r
            out_data[fill[c]] = data[e]
            fill[c] += 1


@numba.njit(cache=True)
def _copy_columns(indptr_a, indices_a, data_a, indptr_b, indices_b, data_b, column, fill, out_rows, out_data):
    """The entries of two sets of rows numbered alike (each row's entries in one set) in the
    columns with ``column`` >= 0, row by row, to ``out_*`` at the places ``fill`` of their columns."""
    for r in range(len(indptr_a) - 1):
        _copy_row(indptr_a, indices_a, data_a, r, column, fill, out_rows, out_data)
        _copy_row(indptr_b, indices_b, data_b, r, column, fill, out_rows, out_data)


def _renumbered_rows(rows: SparseRows, at: np.ndarray, column: np.ndarray, num_cols: int) -> SparseRows:
    """``gathered_rows`` of rows that hold entries in the rows ``at`` alone: their own arrays,
    the columns renumbered in place (``rows`` is spent)."""
    counts = np.diff(rows.indptr)[at]
    if counts.sum() != rows.indices.size:
        raise InputError("rows outside the owned ones hold entries; build the owned rows alone "
                         "(StrainRecipe.build(points=owned))")
    indptr = np.zeros(len(at) + 1, np.int64)
    np.cumsum(counts, out=indptr[1:])
    indices = rows.indices
    indices[:] = column.astype(np.int32)[indices]
    return SparseRows(indptr, indices, rows.data, num_cols)


def _owned_columns(sources: list[SparseRows], mine: np.ndarray, n: int):
    """The entries of the rows ``sources`` (one numbering of rows, each row's entries in one of
    them) in the columns ``mine`` (ascending), grouped by column, each column's in row order, as
    ``transpose_rows`` groups them: their rows, data and the count per column of ``mine``."""
    column = np.full(n, -1, np.int64)
    column[mine] = np.arange(len(mine))
    counts = sum(np.bincount(r.indices, minlength=n)[mine] for r in sources)
    fill = np.zeros(len(mine), np.int64)
    np.cumsum(counts[:-1], out=fill[1:])
    size = int(counts.sum())
    out_rows, out_data = np.empty(size, np.int32), np.empty((size, *sources[0].data.shape[1:]))
    a = sources[0]
    b = sources[1] if len(sources) > 1 else SparseRows(np.zeros_like(a.indptr), a.indices[:0], a.data[:0], a.num_cols)
    _copy_columns(a.indptr, a.indices, a.data, b.indptr, b.indices, b.data, column, fill, out_rows, out_data)
    return out_rows, out_data, counts


def _terms(op: SmearedStrain):
    """The rows a force sums over (MSCNI subcell rows, or the cell rows), their particles'
    row pointer, the particle of each row, and the MSCNI terms."""
    n = op.num_nodes
    s = op.stabilization
    if s is not None:
        return s.rows, s.ptr, s.owner, s
    return op.rows, np.arange(n + 1), np.arange(n), None


def local_smeared_strain(op: SmearedStrain | StrainRecipe, part: np.ndarray, comm, extra_nodes=()) -> LocalSmearedStrain:
    """The share of ``comm.rank`` of ``op`` for the particle parts ``part`` (collective).

    Local nodes and rows are numbered owned first, then the ghosts by owner; the entries of
    every row (and of every node's transposed row) keep their serial order, which is what
    fixes the order of the sums.

    Args:
        op: The whole operator (points = particles), one holding at least the rows this rank
            reads (``StrainRecipe.share``), or its recipe: then the rank builds the rows of its
            particles, which become its local rows in place, and apart the rows of the other
            particles that touch its nodes (``StrainRecipe.near``), so it never holds two copies.
        part: Rank of each particle, shape ``(n,)`` (e.g. ``rkfx.parallel.partition.rcb``).
        comm: The communicator (mpi4py).
        extra_nodes: Further nodes to keep as ghosts (e.g. every column of the constraints).
    """
    part = np.asarray(part, np.int64)
    n = op.num_nodes
    if part.shape != (n,):
        raise InputError(f"particle parts have shape {part.shape}; expected ({n},)")
    mine = np.flatnonzero(part == comm.rank)
    spent = isinstance(op, StrainRecipe)  # rows built here for this rank alone
    near_snap = None
    if spent:
        near = op.build(np.setdiff1d(op.near(part, comm.rank), mine))
        others, near_snap = _terms(near)[0], _snap(near)
        del near
        op = op.build(mine)
        sources = [_terms(op)[0], others]
        del others
    else:
        sources = None
    rows, ptr, row_point, s = _terms(op)
    snap, volume = _snap(op), op.volume
    del op  # a build of this rank's alone: its cell rows go (the force reads the subcell rows)
    counts = ptr[mine + 1] - ptr[mine]
    orows = ranges(ptr[mine], counts)
    touched = np.zeros(n, bool)
    _mark_columns(rows.indptr, rows.indices, orows, touched)
    touched[np.asarray(extra_nodes, np.int64)] = True
    nodes, node_of = local_numbering(mine, np.flatnonzero(touched), part, n)
    # The rows touching an owned node: the entries in owned columns, each node's in row order.
    trows, t_data, t_counts = _owned_columns(sources or [rows], mine, n)
    del sources
    local_rows = _renumbered_rows(rows, orows, node_of, len(nodes)) if spent else \
        gathered_rows(rows, orows, node_of, len(nodes))
    read = np.zeros(rows.num_rows, np.bool_)
    read[trows] = True
    lrows, row_of = local_numbering(orows, np.flatnonzero(read), part[row_point], rows.num_rows)
    del read
    t_indptr = np.zeros(len(mine) + 1, np.int64)
    np.cumsum(t_counts, out=t_indptr[1:])
    _renumber(trows, row_of)
    local_t = SparseRows(t_indptr, trows, t_data, len(lrows))
    row_weight = np.ones(len(lrows)) if s is not None else np.ascontiguousarray(volume[row_point[lrows]])
    point_ptr = np.zeros(len(mine) + 1, np.int64)
    np.cumsum(counts, out=point_ptr[1:])
    stab = None if s is None else LocalStabilization(np.repeat(np.arange(len(mine)), counts))
    row_halo = halo(_row_names(lrows, ptr, row_point, comm), part[row_point[lrows]], comm)
    stencil = None
    if snap is not None and len(mine):
        if near_snap is not None:
            snap = Snap(snap.template, snap.lattice, snap.matched | near_snap.matched)
        particle = row_point[lrows]
        stencil = share_stencil(snap, mine, local_rows, point_ptr, nodes, local_t, particle, lrows - ptr[particle],
                                np.concatenate([np.zeros(0, np.int64), *row_halo.send]))
    return LocalSmearedStrain(
        nodes, np.arange(len(mine)), mine, local_rows, point_ptr,
        None if s is None else np.ascontiguousarray(s.fraction[orows]),
        None if s is None else np.ascontiguousarray(s.weight[orows]),
        np.ascontiguousarray(volume[mine]), local_t, row_weight, np.arange(len(orows)),
        halo(nodes, part[nodes], comm), row_halo, stab, node_of, stencil)


def _snap(op: SmearedStrain) -> Snap | None:
    """The snapping of an MSCNI build's rows (``rkfx.assembly.lattice_stencil``), if any."""
    return None if op.stabilization is None else op.stabilization.snap


def _row_names(rows: np.ndarray, ptr: np.ndarray, row_point: np.ndarray, comm) -> np.ndarray:
    """Names of ``rows`` that every rank gives them alike: particle times the most rows of any
    particle, plus the row's place among its particle's (the row numbers themselves follow each
    rank's build of the nodal domains, ``grid_domains(nodes=...)``). Collective."""
    width = max(comm.allgather(int(np.diff(ptr).max(initial=1))))
    point = row_point[rows]
    return point * width + (rows - ptr[point])
