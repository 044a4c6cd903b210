"""The halo counts of ``rkfx.parallel.ghost_counts`` (and so ``bench/ghosts.py``) against each rank's
own ownership: the same ghost nodes, and ghost points found by a direct search."""
import numpy as np
import pytest

from rkfx.approximation.neighbours import support_neighbours
from rkfx.approximation.shape_functions import rk_approximation
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.particles import structured
from rkfx.parallel.ghost_counts import count_halo, coupling, ghost_nodes, ghost_points
from rkfx.parallel.ownership import nodal_integration_points, ownership
from rkfx.parallel.partition import rcb

SIDE = 24


@pytest.fixture(scope="module")
def grid():
    lines = np.linspace(0.0, 1.0, SIDE)
    return structured(1.0, 1.0, SIDE, SIDE), grid_domains(lines, lines)


@pytest.mark.parametrize("factor", [1.5, 1.75])
@pytest.mark.parametrize("num_parts", [3, 8])
def test_halo_matches_ownership(grid, factor, num_parts):
    p, domains = grid
    rk = rk_approximation(p.x, p.spacing, factor)
    c = coupling(rk, domains, chunk=97)  # several chunks, cut mid-row
    part = rcb(p.x, num_parts)
    h = count_halo(c, part, num_parts)
    # Each particle's own evaluation points, searched in one call: a search per particle
    # would start the parallel kernels 576 times.
    evaluation = [nodal_integration_points(domains, p.x, [l]) for l in range(p.num_nodes)]
    ptr, idx = support_neighbours(rk.x, rk.support, np.concatenate(evaluation))
    ends = ptr[np.cumsum([len(q) for q in evaluation])]
    covering = np.split(idx, ends[:-1])
    subcells = np.bincount(domains.subcell_node, minlength=p.num_nodes)
    for r in range(num_parts):
        owned = np.flatnonzero(part == r)
        expected = ownership(part, num_parts, r, rk, nodal_integration_points(domains, p.x, owned)).ghosts
        np.testing.assert_array_equal(ghost_nodes(c, part, r), expected)
        points = [l for l in range(p.num_nodes) if part[l] != r and np.any(part[covering[l]] == r)]
        np.testing.assert_array_equal(ghost_points(c, part, r), points)
        neighbours = np.union1d(part[expected], part[points])
        assert (h.owned[r], h.ghost_nodes[r], h.ghost_points[r], h.ghost_subcells[r], h.neighbours[r]) == (
            len(owned), len(expected), len(points), subcells[points].sum(), len(neighbours))
        assert h.bytes[r] == 8 * (2 * len(expected) + 3 * subcells[points].sum())
