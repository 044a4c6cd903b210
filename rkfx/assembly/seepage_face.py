"""Seepage faces: boundary parts where water may leave the soil but not enter it.

On a seepage face the water pressure cannot exceed the atmosphere's and water can only flow
out: p <= 0, q.n >= 0 and p (q.n) = 0 -- a wet part at p = 0 that discharges, above it a dry
part without flow (the exit point of the phreatic surface on a downstream slope is not known
beforehand). The unilateral condition is held by a one-sided flux

    q.n = kappa <p>_+          (<p>_+ = max(p, 0)),

the penalty form of the complementarity: it adds int_face psi kappa <p>_+ ds to the storage
equation's residual and int psi kappa H(p) dp ds to its Jacobian, a semismooth term that Newton
handles like any other. Where water leaves, p = q.n / kappa > 0 is the penalty's error; with
kappa = c k / h it is h |grad p| / c, a small fraction of the pressure change over one spacing
for c ~ 1e3. Where the face is dry the term vanishes.

The face's points are the two Gauss points of each boundary segment between nodes
(``rkfx.integration.nodal_stabilized.boundary_rule``), with the RK rows N_I there.
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rkfx.approximation.semi_lagrangian import MovingRK, evaluate_moving
from rkfx.approximation.sparse_rows import SparseRows, gathered_rows
from rkfx.errors import InputError
from rkfx.integration.nodal_stabilized import boundary_rule


def check_penalty(kappa: float) -> None:
    """Raise InputError unless ``kappa`` is a positive outflow per unit pressure."""
    if not (np.isfinite(kappa) and kappa > 0):
        raise InputError(f"seepage face penalty = {kappa!r} must be a positive outflow per unit pressure "
                         "[m/(Pa s)], e.g. 1e3 k / h")


@dataclass(frozen=True)
class SeepageFace:
    """The points of a seepage face and its penalty.

    Attributes:
        values: Rows N_I at the points, over the model's nodes.
        weights: Length each point stands for, shape ``(num_points,)`` [m].
        points: Coordinates, shape ``(num_points, 2)`` [m].
        penalty: kappa, outflow per unit pressure [m/(Pa s)].
    """

    values: SparseRows
    weights: np.ndarray
    points: np.ndarray
    penalty: float

    def __post_init__(self):
        check_penalty(self.penalty)

    def localized(self, nodes: np.ndarray) -> "SeepageFace":
        """The same face over the local nodes ``nodes`` (as ``NodalIntegration.localized``)."""
        column = np.full(self.values.num_cols, -1, np.int64)
        column[np.asarray(nodes, np.int64)] = np.arange(len(nodes))
        if np.any(column[self.values.indices] < 0):
            raise InputError("seepage face: the local nodes do not cover the face's rows; add them to the touched nodes")
        rows = gathered_rows(self.values, np.arange(self.values.num_rows), column, len(nodes))
        return SeepageFace(rows, self.weights, self.points, self.penalty)

    def matrix(self) -> sp.csr_matrix:
        return self.values.matrix().tocsr()


def seepage_face(rk: MovingRK, segments: np.ndarray, penalty: float, nodes: np.ndarray | None = None) -> SeepageFace:
    """The seepage face along boundary ``segments`` (node pairs, the domain on their left) of the
    approximation ``rk``; with ``nodes`` (an MPI rank's own) only the points those nodes serve,
    so that every point is counted by one rank."""
    segments = np.asarray(segments, np.int64).reshape(-1, 2)
    if len(segments) == 0:
        raise InputError("seepage face: no boundary segments; pick the part's segments from the particles' boundary edges")
    b = boundary_rule(rk.x, segments)
    keep = np.arange(len(b.points)) if nodes is None else np.flatnonzero(np.isin(b.owner, nodes))
    weights = np.linalg.norm(b.normal_length[keep], axis=1)
    rows = evaluate_moving(rk, b.points[keep], b.owner[keep])
    return SeepageFace(rows, weights, b.points[keep], float(penalty))
