"""Partition the particles over ranks by recursive coordinate bisection (RCB).

Why RCB: RK shape functions have compact supports of a few spacings, so the nodes a rank
must know besides its own (its ghosts) are those within one support of its evaluation points.
RCB cuts the node cloud by straight lines (planes in 3-D) into compact, nearly square parts, so that ghost
layer stays a thin band along the cuts, of a width of one support. It costs a few sorts
(O(n log n log P)), is deterministic, so every rank computes the same partition from the
same coordinates with no communication, and needs no graph partitioner (no extra dependency).
"""
import numpy as np

from rkfx.errors import InputError


def rcb(x: np.ndarray, num_parts: int, weights: np.ndarray | None = None) -> np.ndarray:
    """The part of each node, recursive coordinate bisection into ``num_parts`` parts.

    Each step splits a set of nodes meant for k parts into sets for floor(k/2) and
    ceil(k/2) parts, cutting across the longer side of their bounding box at the weighted
    quantile floor(k/2)/k (the weighted median when k is even), so any count of parts works.
    Ties in the cut coordinate are broken by the other coordinates (x before y before z) and
    then by node index, so the result depends only on ``x`` and ``weights``.

    Args:
        x: Node coordinates, shape ``(num_nodes, 2)`` or ``(num_nodes, 3)`` [m].
        num_parts: Number of parts, 1 <= num_parts <= num_nodes.
        weights: Non-negative work per node, shape ``(num_nodes,)`` (default: all 1).

    Returns:
        Part of each node, shape ``(num_nodes,)`` int64, parts numbered 0..num_parts-1 along
        the cuts (lower coordinates first); every part has at least one node.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] not in (2, 3):
        raise InputError(f"rcb takes node coordinates of shape (num_nodes, 2) or (num_nodes, 3), not {x.shape}")
    n = len(x)
    if int(num_parts) != num_parts or not 1 <= num_parts <= n:
        raise InputError(f"num_parts = {num_parts!r} must be an integer from 1 to the {n} nodes")
    num_parts = int(num_parts)
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=np.float64)
    if w.shape != (n,) or not np.all(np.isfinite(w)) or np.any(w < 0) or not w.sum() > 0:
        raise InputError(f"rcb weights must be finite, non-negative, not all zero, of shape ({n},); "
                         f"got shape {w.shape}")
    part = np.empty(n, np.int64)
    stack = [(np.arange(n), 0, num_parts)]
    while stack:
        idx, first, k = stack.pop()
        if k == 1:
            part[idx] = first
            continue
        k_lo = k // 2
        xs = x[idx]
        extent = xs.max(axis=0) - xs.min(axis=0)
        axis = int(np.argmax(extent))  # the first of equally long sides
        others = [xs[:, a] for a in range(x.shape[1] - 1, -1, -1) if a != axis]
        order = idx[np.lexsort((idx, *others, xs[:, axis]))]
        cum = np.cumsum(w[order])
        target = cum[-1] * k_lo / k
        j = int(np.searchsorted(cum, target))  # cum[j - 1] < target <= cum[j]
        # Nodes in the lower set: j or j + 1, whichever weight is nearer the target.
        m = j if j > 0 and target - cum[j - 1] <= cum[min(j, len(cum) - 1)] - target else j + 1
        m = min(max(m, k_lo), len(order) - (k - k_lo))
        stack.append((order[m:], first + k_lo, k - k_lo))
        stack.append((order[:m], first, k_lo))
    return part
