"""Particle tracking (4.22) and crack normals."""
import numpy as np
import pytest

from rkfx.fracture.tracking import tracking
from rkfx.materials.elasticity import principal_direction
from rkfx.errors import InputError
from rkfx.geometry.particles import graded, structured


@pytest.fixture(scope="module")
def square():
    p = structured(1.0, 1.0, 11, 11)
    return (p,)


def test_candidates_lie_along_the_crack_within_the_tolerance(square):
    p, = square
    h = 0.1
    track = tracking(p.x, p.spacing, 0.3, radius=3.5)
    centre = int(np.argmin(np.linalg.norm(p.x - 0.5, axis=1)))
    cand, by = track.candidates(np.array([centre]), np.array([[0.0, 1.0]]))  # horizontal crack
    assert np.all(by == centre)
    d = p.x[cand] - p.x[centre]
    assert centre not in cand
    assert np.all(np.abs(d[:, 1]) / np.linalg.norm(d, axis=1) < 0.3)
    assert np.all(np.linalg.norm(d, axis=1) < 3.5 * h + 1e-12)
    # Along the row: the 3 nearest on either side; off the row: (3, 1) at 18.4 degrees is out.
    assert sorted(np.round(d[:, 0] / h).astype(int)) == [-3, -2, -1, 1, 2, 3]


def test_a_narrow_neighbourhood_follows_only_lattice_directions():
    """1.5 h: side and diagonal neighbours; a crack at 70 degrees (normal at -20) finds none
    within tol = 0.3, one along a grid line finds its two side neighbours."""
    p = structured(1.0, 1.0, 11, 11)
    track = tracking(p.x, p.spacing, 0.3, radius=1.5)
    centre = 60
    assert len(track.indices[track.indptr[centre]:track.indptr[centre + 1]]) == 8
    t = np.radians(-20.0)
    assert track.candidates(np.array([centre]), np.array([[np.cos(t), np.sin(t)]]))[0].size == 0
    assert sorted(track.candidates(np.array([centre]), np.array([[1.0, 0.0]]))[0]) == [49, 71]


def test_candidates_lie_ahead_of_the_parent():
    """A particle made a candidate by its left neighbour admits only the neighbours to its
    right (and level with it); without a parent, or with ``forward`` off, both sides."""
    p = structured(1.0, 1.0, 11, 11)
    centre, left = 60, 59
    parents = np.full(p.num_nodes, -1)
    parents[centre] = left
    horizontal = np.array([[0.0, 1.0]])
    for forward, expect in ((True, [1, 2, 3]), (False, [-3, -2, -1, 1, 2, 3])):
        track = tracking(p.x, p.spacing, 0.3, radius=3.5, forward=forward)
        cand, by = track.candidates(np.array([centre]), horizontal, parents[[centre]])
        assert sorted(np.round((p.x[cand, 0] - p.x[centre, 0]) / 0.1).astype(int)) == expect
    track = tracking(p.x, p.spacing, 0.3, radius=3.5)
    assert len(track.candidates(np.array([centre]), horizontal, np.array([-1]))[0]) == 6
    # Two initiating particles: each candidate records the first that admits it.
    cand, by = track.candidates(np.array([centre, 61]), np.array([[0.0, 1.0], [0.0, 1.0]]),
                                parents[[centre, 61]])
    assert by[cand == 62][0] == centre and by[cand == 60][0] == 61


def test_seeds_and_switch():
    p = structured(1.0, 1.0, 11, 11)
    track = tracking(p.x, p.spacing, 0.5, seeds=np.array([3, 7]), enabled=False)
    assert np.flatnonzero(track.seeds).tolist() == [3, 7] and not track.enabled


def test_bad_tracking_input(square):
    p, = square
    with pytest.raises(InputError, match="tol"):
        tracking(p.x, p.spacing, 0.0)
    with pytest.raises(InputError, match="radius"):
        tracking(p.x, p.spacing, 0.3, radius=0.5)
    with pytest.raises(InputError, match="seeds"):
        tracking(p.x, p.spacing, 0.3, seeds=np.zeros(3, bool))


def test_principal_direction():
    angles = np.array([0.0, 0.3, -1.0, np.pi / 2 - 0.01])
    s1, s2 = 5.0, -2.0
    c, s = np.cos(angles), np.sin(angles)
    stress = np.column_stack([s1 * c**2 + s2 * s**2, s1 * s**2 + s2 * c**2, (s1 - s2) * s * c])
    d = principal_direction(stress)
    assert np.allclose(np.abs(np.sum(d * np.column_stack([c, s]), axis=1)), 1.0)


def test_a_rank_keeps_the_neighbour_sets_that_reach_its_particles():
    """``near``: the neighbour sets of the particles with one of ``points`` among their
    neighbours, equal to the whole build's; the candidates among ``points`` of any initiations
    are the whole tracking's, with the same parents."""
    p = graded(np.linspace(0.0, 1.0, 23), np.linspace(0.0, 1.0, 19) ** 1.3)  # graded: radii differ
    whole = tracking(p.x, p.spacing, 0.4, radius=2.5)
    points = np.flatnonzero(p.x[:, 0] < 0.37)
    part = whole.near(points)
    reach = {i for i in range(p.num_nodes)
             if np.isin(whole.indices[whole.indptr[i]:whole.indptr[i + 1]], points).any()}
    assert reach - set(points.tolist()) and set(part.rows.tolist()) == reach | set(points.tolist())
    for i in range(p.num_nodes):
        mine = part.indices[part.indptr[i]:part.indptr[i + 1]]
        expect = whole.indices[whole.indptr[i]:whole.indptr[i + 1]] if i in part.rows else []
        assert sorted(mine) == sorted(expect), i
    rng = np.random.default_rng(3)
    nodes = np.sort(rng.choice(p.num_nodes, 40, replace=False))
    t = rng.uniform(0, np.pi, 40)
    normals, parents = np.column_stack([np.cos(t), np.sin(t)]), rng.integers(-1, p.num_nodes, 40)
    a, by_a = whole.candidates(nodes, normals, parents)
    b, by_b = part.candidates(nodes, normals, parents)
    keep = np.isin(a, points)
    assert keep.any() and np.array_equal(a[keep], b[np.isin(b, points)])
    assert np.array_equal(by_a[keep], by_b[np.isin(b, points)])
