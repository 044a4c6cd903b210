"""A strain operator given by its matrix, whole or as one rank's share.

``MatrixStrain`` is the strain operator of ``rkfx.models.damage_dynamics`` for damage points
whose strains are rows of a matrix: e_L = B_L d (three Voigt rows per point, over the
interleaved nodal unknowns) and f_int = B^T (Sigma_L V_L). The cell strains of linear
triangles (``fem_baselines.crack_band_dynamics``) are one: damage points are the cells,
nodes the vertices.

On MPI ranks (``rkfx.models.damage_ranks``) each rank owns the nodes of its part and the
points most of whose row nodes it owns (ties: the lowest such rank), and keeps as ghosts the
nodes its points read (and any the caller adds) and the points that touch its nodes. One force
evaluation sends the loads Sigma_L V_L of the ghost points from their owners, forms the force
at the owned nodes from their rows of B^T, and sends the force at the ghost nodes from theirs
(``rkfx.parallel.halo``). The rows keep the serial entries in their serial order (renumbered,
never re-sorted), so every strain and force is the serial one bit for bit.
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rkfx.assembly.local_strain import LocalNodes, local_numbering
from rkfx.errors import InputError
from rkfx.parallel.halo import Halo, halo


@dataclass(frozen=True)
class MatrixStrain:
    """Strains B d and forces B^T (Sigma V) of ``m`` damage points over ``n`` nodes.

    Attributes:
        B: Rows 3 L .. 3 L + 2 are the Voigt strain rows of point L, shape ``(3 m, 2 n)``.
        BT: The transpose of ``B`` as CSR, shape ``(2 n, 3 m)``.
        volume: V_L of each point, shape ``(m,)`` [m^2 per unit thickness].
    """

    B: sp.csr_matrix
    BT: sp.csr_matrix
    volume: np.ndarray

    @property
    def num_nodes(self) -> int:
        """The number of damage points (the strain operators' name for it)."""
        return len(self.volume)

    def strain(self, d: np.ndarray) -> np.ndarray:
        return (self.B @ d).reshape(-1, 3)

    def force(self, stress: np.ndarray) -> np.ndarray:
        return self.BT @ (stress * self.volume[:, None]).ravel()


@dataclass(frozen=True)
class LocalMatrixStrain(LocalNodes):
    """A rank's share of a ``MatrixStrain`` (see the module docstring).

    Attributes:
        nodes: Global index of every local node: the owned ones first, ascending, then the
            ghosts by owner.
        owned_nodes: ``arange(num_owned)``.
        node_of: Local index of every global node (-1 if not local), shape ``(n,)``.
        points: Global index of every owned point, ascending.
        B: The owned points' rows over the local unknowns, shape ``(3 num_owned, 2 num_local)``.
        BT: The owned unknowns' rows over the local points' Voigt rows (owned points first).
        volume: V_L of every local point.
        row_halo, node_halo: The exchanges of the ghost points' loads and the ghost nodes' force.
    """

    nodes: np.ndarray
    owned_nodes: np.ndarray
    node_of: np.ndarray
    points: np.ndarray
    B: sp.csr_matrix
    BT: sp.csr_matrix
    volume: np.ndarray
    row_halo: Halo
    node_halo: Halo
    stabilization = None  # plain strains: ``DamageForce`` calls ``strain`` and ``force``

    @property
    def num_nodes(self) -> int:
        """The number of damage points of this rank (its owned points)."""
        return len(self.points)

    def strain(self, d: np.ndarray) -> np.ndarray:
        """Strains of the owned points, shape ``(num_owned, 3)``, for local d."""
        return (self.B @ d).reshape(-1, 3)

    def force(self, stress: np.ndarray) -> np.ndarray:
        """f_int on the local unknowns, shape ``(2 num_local,)`` [N], from the stresses of the
        owned points. Collective."""
        load = np.empty((len(self.volume), 3))
        np.multiply(stress, self.volume[:len(self.points), None], out=load[:len(self.points)])
        return self._exchanged(load, lambda out: np.copyto(out, self.BT @ load.ravel()))


def point_parts(B: sp.csr_matrix, part: np.ndarray) -> np.ndarray:
    """The owner of every point of ``B``: the rank owning most of its row entries' nodes (ties:
    the lowest of them), shape ``(m,)``."""
    size = int(part.max(initial=0)) + 1
    point = np.repeat(np.arange(B.shape[0]) // 3, np.diff(B.indptr))
    pair, votes = np.unique(point * size + part[B.indices // 2], return_counts=True)
    point, rank = pair // size, pair % size
    first = np.lexsort((rank, -votes, point))  # per point: most votes, then the lowest rank
    keep = first[np.r_[True, point[first][1:] != point[first][:-1]]]
    owner = np.zeros(B.shape[0] // 3, np.int64)
    owner[point[keep]] = rank[keep]
    return owner


def local_matrix_strain(op: MatrixStrain, part: np.ndarray, comm, extra_nodes=()) -> LocalMatrixStrain:
    """The share of ``comm.rank`` of ``op`` for the node parts ``part`` (collective)."""
    part = np.asarray(part, np.int64)
    n = op.B.shape[1] // 2
    if part.shape != (n,):
        raise InputError(f"node parts have shape {part.shape}; expected ({n},)")
    m, rank = op.num_nodes, comm.rank
    owner = point_parts(op.B, part)
    points = np.flatnonzero(owner == rank)
    mine = np.flatnonzero(part == rank)
    rows = (3 * points[:, None] + np.arange(3)).ravel()
    B = op.B[rows]
    read = np.zeros(n, bool)
    read[B.indices // 2] = True
    read[np.asarray(extra_nodes, np.int64)] = True
    nodes, node_of = local_numbering(mine, np.flatnonzero(read), part, n)
    dofs = (2 * mine[:, None] + np.arange(2)).ravel()
    BT = op.BT[dofs]
    touching = np.zeros(m, bool)
    touching[BT.indices // 3] = True
    local_points, point_of = local_numbering(points, np.flatnonzero(touching), owner, m)
    # Renumbered in place, never re-sorted: each row's sum keeps the serial order.
    B = sp.csr_matrix((B.data, 2 * node_of[B.indices // 2] + B.indices % 2, B.indptr), shape=(len(rows), 2 * len(nodes)))
    BT = sp.csr_matrix((BT.data, 3 * point_of[BT.indices // 3] + BT.indices % 3, BT.indptr),
                       shape=(len(dofs), 3 * len(local_points)))
    return LocalMatrixStrain(nodes, np.arange(len(mine)), node_of, points, B, BT,
                             np.ascontiguousarray(op.volume[local_points]),
                             halo(local_points, owner[local_points], comm), halo(nodes, part[nodes], comm))
