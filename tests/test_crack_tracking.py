"""Particle tracking (4.22) and crack normals."""
import numpy as np
import pytest

from rkfx.crack_tracking import candidates, neighbour_graph, principal_direction
from rkfx.errors import InputError
from rkfx.particles import structured


def test_neighbours_of_an_interior_grid_node():
    p = structured(4.0, 4.0, 5, 5)
    g = neighbour_graph(p)
    centre = 12
    nbrs = set(g.indices[g.indptr[centre]:g.indptr[centre + 1]])
    # One diagonal direction of the triangulation: 4 axis neighbours and 2 diagonal ones.
    assert {7, 11, 13, 17} <= nbrs and len(nbrs) == 6


@pytest.mark.parametrize("tol, expected_count", [(0.3, 2), (0.8, 4)])
def test_candidates_lie_along_the_crack_segment(tol, expected_count):
    p = structured(4.0, 4.0, 5, 5)
    g = neighbour_graph(p)
    damaged = np.zeros(p.num_nodes, bool)
    damaged[12] = True
    normal = np.zeros((p.num_nodes, 2))
    normal[12] = (0.0, 1.0)  # horizontal crack segment
    allowed = candidates(p.x, g, damaged, normal, tol)
    new = np.flatnonzero(allowed & ~damaged)
    assert len(new) == expected_count
    assert {11, 13} <= set(new)  # left and right of the crack tip
    assert not allowed[7] and not allowed[17]  # across the crack: prevention zone


def test_tracking_off_allows_everything_and_seeds_are_allowed():
    p = structured(2.0, 2.0, 3, 3)
    g = neighbour_graph(p)
    none = np.zeros(p.num_nodes, bool)
    assert candidates(p.x, g, none, np.zeros((9, 2)), 0.3, tracking=False).all()
    seeds = none.copy()
    seeds[4] = True
    assert np.array_equal(candidates(p.x, g, none, np.zeros((9, 2)), 0.3, seeds=seeds), seeds)
    with pytest.raises(InputError, match="tol"):
        candidates(p.x, g, none, np.zeros((9, 2)), 0.0)


def test_principal_direction():
    angles = np.array([0.0, 0.3, -1.0, np.pi / 2 - 0.01])
    s1, s2 = 5.0, -2.0
    c, s = np.cos(angles), np.sin(angles)
    stress = np.column_stack([s1 * c**2 + s2 * s**2, s1 * s**2 + s2 * c**2, (s1 - s2) * s * c])
    d = principal_direction(stress)
    assert np.allclose(np.abs(np.sum(d * np.column_stack([c, s]), axis=1)), 1.0)
