"""The damage particle method on MPI ranks: every rank steps its own particles.

The particles are split by recursive coordinate bisection (``rkfx.parallel.partition``).
Each rank owns the damage points at its particles and the unknowns of their nodes, and keeps
ghost copies of the nodes its strains read and of the constraint columns
(``rkfx.assembly.local_strain``). One step of ``rkfx.solvers.central_difference`` then runs
on the rank's local vectors as it would serially; per step the ranks exchange:

* the loads of the rows that couple to another rank's nodes, and the internal force at the
  ghost nodes (two neighbour-only halo exchanges, ``rkfx.parallel.halo``);
* when a particle initiates anywhere, the new crack particles with their normals and parents
  (one small all-gather), so that every rank marks among its own particles the tracking
  candidates (4.22) a serial run marks, with the same parents, also across the partition
  boundaries; each rank keeps only the neighbour sets that reach its particles
  (``Tracking.near``); how many initiated on each rank is one all-gather of a count per step
  (with tracking on);
* with the nonlocal equivalent strain (``rkfx.fracture.nonlocal_average``), the strains and
  failed flags of the particles within R of the rank's own (two neighbour-only halo exchanges
  over that wider ghost layer), which the averages of the rank's allowed particles read;
* the energies (one all-reduce per ``SETTLE_EVERY`` steps of
  ``rkfx.solvers.central_difference``) and the history samples.

The constraint rows are replicated (the columns of G are ghosts everywhere), so every rank
solves the same small projection. Every strain, force and damage update is the serial
one's, entry for entry in the same order, so a run on any number of ranks gives the serial
damage, crack paths and displacements bit for bit; only the summed energies and dissipation
may differ in the last digits (sums in another order). Checkpoints are one file per rank
(``rank<r>-of-<P>/``, resumable on the same number of ranks); finished results are gathered
and written once.
"""
from dataclasses import replace

import numpy as np

from rkfx.assembly.local_strain import LocalNodes, local_smeared_strain
from rkfx.assembly.matrix_strain import MatrixStrain, local_matrix_strain
from rkfx.errors import InputError
from rkfx.fracture.damage import DamageModel, initiate
from rkfx.fracture.nonlocal_average import NonlocalAverage
from rkfx.fracture.tracking import Tracking, admit
from rkfx.models.damage_dynamics import DamageDynamics, DamageForce, damage_field
from rkfx.parallel.halo import halo
from rkfx.solvers.central_difference import Constraint, ExplicitDynamics


class MpiShare:
    """``rkfx.solvers.central_difference.RankShare`` over an mpi4py communicator."""

    def __init__(self, comm, owned: np.ndarray):
        self.comm, self.owned = comm, owned
        self.rank, self.size = comm.rank, comm.size

    def sum(self, values: np.ndarray) -> np.ndarray:
        return _summed(self.comm, np.array(values, dtype=np.float64))

    def least(self, value: int) -> int:
        return int(min(self.comm.allgather(int(value))))


def _summed(comm, values: np.ndarray) -> np.ndarray:
    """``values`` (C-contiguous) summed over the ranks, in place; returns them."""
    from mpi4py import MPI  # noqa: PLC0415 - loaded already: the communicator is one

    comm.Allreduce(MPI.IN_PLACE, values, op=MPI.SUM)
    return values


def restricted(model: DamageModel, points: np.ndarray) -> DamageModel:
    """The data of ``points`` of ``model`` (the cell geometry stays whole: it is read by the
    global indices of initiating points)."""
    average = model.nonlocal_average
    return replace(model, volume=model.volume[points], kappa0=model.kappa0[points],
                   kappa_c=None if model.kappa_c is None else model.kappa_c[points],
                   nonlocal_average=None if average is None else average.restricted(points))


class RankDamageForce(DamageForce):
    """``DamageForce`` of one rank's points. Initiations are gathered over the ranks with their
    parents, and every rank marks the candidates among its own points of those initiations
    whose neighbour sets reach them (``Tracking.near``), so each point's admission and parent
    are the serial ones."""

    def __init__(self, op: LocalNodes, model: DamageModel, local_model: DamageModel, field,
                 track: Tracking | None, dt: float, comm, part: np.ndarray | None = None):
        tracked = track is not None and track.enabled
        if local_model.nonlocal_average is not None:
            local_model = replace(local_model, nonlocal_average=self._nonlocal_halo(
                local_model.nonlocal_average, np.asarray(op.points, np.int64), part, comm))
        super().__init__(op, local_model, field, track.near(op.points) if tracked else track, dt)
        self.whole, self.comm = model, comm
        self.tracked = tracked
        if tracked:
            field.allowed[:] = track.seeds[op.points]
        self._counts = np.zeros(comm.size, np.int64)
        self._one = np.zeros(1, np.int64)

    def _gathered(self, new: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The initiations of every rank in this evaluation, rank by rank (ids, normals,
        parents), or ``None`` if there are none: an all-gather of the counts, then one of
        (id, n_x, n_y, parent) quadruples as doubles (ids below 2^53 are exact). Collective."""
        self._one[0] = len(new)
        self.comm.Allgather(self._one, self._counts)
        total = int(self._counts.sum())
        if total == 0:
            return None
        f = self.field
        mine = np.empty((len(new), 4))
        mine[:, 0], mine[:, 1:3], mine[:, 3] = self.op.points[new], f.normal[new], f.parent[new]
        every = np.empty((total, 4))
        self.comm.Allgatherv(mine, [every, 4 * self._counts])
        return every[:, 0].astype(np.int64), np.ascontiguousarray(every[:, 1:3]), every[:, 3].astype(np.int64)

    def _nonlocal_halo(self, average: NonlocalAverage, points: np.ndarray, part: np.ndarray | None,
                       comm) -> NonlocalAverage:
        """``average`` (the rows of ``points``, columns the particles' global indices) on the
        numbering of the particles it reads: the rank's own ``points`` first, then the others
        by owning rank (``part``: the rank of every particle); sets up their halo (collective)."""
        if part is None:
            raise InputError("a distributed nonlocal damage model needs the rank of every particle (part)")
        others = np.setdiff1d(np.unique(average.indices), points)
        others = others[np.argsort(np.asarray(part)[others], kind="stable")]
        read = np.concatenate([points, others])
        self._average_halo = halo(read, np.asarray(part)[read], comm)
        self._values = np.zeros(len(read))
        self._failed = np.zeros(len(read), np.bool_)
        order = np.argsort(read, kind="stable")
        local = order[np.searchsorted(read[order], average.indices)].astype(np.int32)
        return NonlocalAverage(average.radius, average.band_factor, average.indptr, local, average.weights)

    def _nonlocal_inputs(self) -> tuple[np.ndarray, np.ndarray]:
        """The equivalent strains and failed flags of the particles the rank's averages read:
        its own, and the others' from their owners (collective over the neighbours: one halo
        exchange of the strains and one of the flags per step)."""
        n = len(self._eq)
        self._values[:n] = self._eq
        np.greater_equal(self.field.damage, 1.0, out=self._failed[:n])
        self._average_halo.exchange(self._values)
        self._average_halo.exchange(self._failed)
        return self._values, self._failed

    def _initiate_all(self, new: np.ndarray) -> None:
        f, points = self.field, self.op.points
        if new.size:
            initiate(self.whole, points[new], self._effective[new], f.normal, f.chord, f.kappa_c, at=new)
            f.damaged[new] = True
            f.initiation_time[new] = f.clock[0]
        if not self.tracked:
            return
        gathered = self._gathered(new)
        if gathered is None:
            return
        ids, normals, parents = gathered
        order = np.argsort(ids, kind="stable")  # ascending, as serially
        cand, by = self.track.candidates(ids[order], normals[order], parents[order])
        local = self.op.node_of[cand]  # points are the owned particles, the first local nodes
        mine = (local >= 0) & (local < len(points))
        admit(local[mine], by[mine], f.allowed, f.parent)


class RankDamage(DamageDynamics):
    """One rank's part of a ``DamageDynamics`` problem (the module docstring says how).

    Args:
        op, mass, model, track, dt, constraints, external_force: The whole problem, as for
            ``DamageDynamics`` (``op`` a ``SmearedStrain``, or its ``StrainRecipe``: then this
            rank builds only the rows it reads, ``local_smeared_strain``; or a
            ``rkfx.assembly.matrix_strain.MatrixStrain``, whose points need not be the nodes).
        part: Rank of each node (particle), shape ``(n,)``.
        comm: The communicator (mpi4py).
    """

    def __init__(self, op, mass, model: DamageModel, track: Tracking | None, dt: float, constraints, external_force,
                 part: np.ndarray, comm):
        columns = np.unique(np.concatenate([c.G.indices // 2 for c in constraints])) if constraints else []
        local = local_matrix_strain(op, part, comm, columns) if isinstance(op, MatrixStrain) else \
            local_smeared_strain(op, part, comm, extra_nodes=columns)
        points, dofs = local.points, local.dofs
        self.op, self.damage_model = local, restricted(model, points)
        self.field = damage_field(self.damage_model, None, dt)
        self.force = RankDamageForce(local, model, self.damage_model, self.field, track, dt, comm, part)
        self.damage_model = self.force.model  # its nonlocal rows numbered over the particles they read
        essential = [Constraint(_columns(c.G, local), c.displacement, c.velocity) for c in constraints]
        f_ext = None if external_force is None else (lambda t: np.asarray(external_force(t))[dofs])
        ExplicitDynamics.__init__(self, np.asarray(mass)[dofs], self.force, dt, f_ext, essential,
                                  self.field.arrays)
        self.share = MpiShare(comm, local.owned_dofs)
        self.comm, self.num_points, self.num_whole_nodes = comm, op.num_nodes, len(mass) // 2

    def gather(self, values: np.ndarray) -> np.ndarray:
        """The whole array of a per-point quantity from every rank's owned points (collective)."""
        return _gathered(self.comm, self.op.points, np.asarray(values), self.num_points)

    def gather_nodes(self, local: np.ndarray) -> np.ndarray:
        """The whole interleaved vector ``(2 n,)`` from the local vectors of every rank (collective)."""
        op = self.op
        owned = np.asarray(local).reshape(-1, 2)[op.owned_nodes]
        return _gathered(self.comm, op.nodes[op.owned_nodes], owned, self.num_whole_nodes).ravel()


def _gathered(comm, index: np.ndarray, values: np.ndarray, size: int) -> np.ndarray:
    """``values`` of the global entries ``index`` of every rank, as one array of ``size`` rows."""
    pieces = comm.allgather((index, values))
    out = np.empty((size, *values.shape[1:]), values.dtype)
    for at, v in pieces:
        out[at] = v
    return out


def _columns(g, local: LocalNodes):
    """``g`` on the local unknowns (every column of ``g`` is local), each row's entries kept in
    their order, so that G w sums as serially."""
    import scipy.sparse as sp  # noqa: PLC0415

    g = sp.csr_matrix(g)
    return sp.csr_matrix((g.data, local.local_dofs(g.indices), g.indptr), shape=(g.shape[0], 2 * local.num_local))
