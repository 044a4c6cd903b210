"""Distributed RKPM, serially: RCB partitions, ownership and ghosts, and the owned-row
assembly, whose parts summed give the whole system."""
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from conftest import l_shape, unit_square
from rkfx.approximation.shape_functions import rk_approximation
from rkfx.conditions import Displacement, Traction
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import structured
from rkfx.integration.quadrature import integration_rules, smoothed_gradients
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import elastic_terms, solve_plane_strain
from rkfx.parallel.ownership import nodal_integration_points, numbering, ownership
from rkfx.parallel.partition import rcb
from rkfx.parallel.rows import owned_block, owned_entries, renumbered
from verification.manufactured import SineField

MATERIAL = ElasticMaterial(1.0, 0.3)
FIELD = SineField(MATERIAL.lame_lambda, MATERIAL.shear_modulus)


@pytest.mark.parametrize("num_parts", [1, 2, 3, 5, 8])
def test_rcb_parts_are_balanced_and_connected(num_parts):
    p = l_shape(0.1)
    part = rcb(p.x, num_parts)
    counts = np.bincount(part, minlength=num_parts)
    assert counts.sum() == p.num_nodes and counts.min() > 0
    assert counts.max() - counts.min() <= num_parts  # each cut is off by at most one node
    edges = np.concatenate([p.triangles[:, [0, 1]], p.triangles[:, [1, 2]], p.triangles[:, [2, 0]]])
    for r in range(num_parts):
        inside = np.flatnonzero(part == r)
        keep = np.all(part[edges] == r, axis=1)
        graph = sp.coo_matrix((np.ones(keep.sum()), (edges[keep, 0], edges[keep, 1])),
                              shape=(p.num_nodes, p.num_nodes)).tocsr()[inside][:, inside]
        assert connected_components(graph, directed=False)[0] == 1


def test_rcb_is_deterministic_and_follows_weights():
    x = structured(2.0, 1.0, 41, 21).x
    assert np.array_equal(rcb(x, 3), rcb(x.copy(), 3))
    w = np.where(x[:, 0] < 1.0, 3.0, 1.0)  # the left half costs three times as much
    part = rcb(x, 2, w)
    loads = np.bincount(part, w)
    assert abs(loads[0] - loads[1]) <= w.max()
    assert (part[x[:, 0] < 0.5] == 0).all() and (part[x[:, 0] > 1.0] == 1).all()


@pytest.mark.parametrize("bad", [dict(num_parts=0), dict(num_parts=2.5), dict(num_parts=10**6),
                                 dict(num_parts=2, weights=-np.ones(4))])
def test_rcb_bad_input_names_the_culprit(bad):
    with pytest.raises(InputError, match="num_parts|weights"):
        rcb(np.random.default_rng(0).random((4, 2)), **bad)


def test_numbering_makes_each_part_contiguous():
    part = rcb(unit_square(0.1).x, 3)
    num = numbering(part, 3)
    assert np.array_equal(num.new_of_old[num.old_of_new], np.arange(len(part)))
    for r in range(3):
        assert (part[num.old_of_new[num.ranges[r]:num.ranges[r + 1]]] == r).all()


def test_ghosts_are_the_columns_of_the_owned_points():
    """The shape rows of a rank's cells couple its owned nodes to its ghosts and nothing else."""
    p = unit_square(0.08)
    rk = rk_approximation(p.x, p.spacing)
    d = nodal_domains(p)
    part = rcb(p.x, 3)
    for rank in range(3):
        own = ownership(part, 3, rank, rk, nodal_integration_points(d, p.x, np.flatnonzero(part == rank)))
        assert np.array_equal(np.sort(own.owned), np.flatnonzero(part == rank))
        assert own.end - own.start == own.num_owned and not np.isin(own.ghosts, own.owned).any()
        s = smoothed_gradients(p, rk, d, subcells=True, nodes=own.owned)
        cols = np.unique(np.concatenate([s.cell.indices, s.cell_minus_subcell.indices, s.node_values.indices]))
        assert np.array_equal(cols, np.union1d(own.owned, own.ghosts))


def test_selected_cells_are_the_rows_of_the_whole():
    p = l_shape(0.1)
    rk = rk_approximation(p.x, p.spacing)
    d = nodal_domains(p)
    nodes = np.flatnonzero(rcb(p.x, 3) == 1)
    whole = integration_rules("mscni", p, rk, d)
    part = integration_rules("mscni", p, rk, d, nodes=nodes)
    sub = np.flatnonzero(np.isin(d.subcell_node, nodes))
    for q, qp, rows in zip(whole, part, (nodes, sub)):
        assert np.array_equal(q.weights[rows], qp.weights)
        for k in range(2):
            assert abs(q.gradients.matrix(k)[rows] - qp.gradients.matrix(k)).max() < 1e-13
    with pytest.raises(InputError, match="gauss2"):
        integration_rules("gauss2", p, rk, d, nodes=nodes)


@pytest.mark.parametrize(("rule", "bc_method"), [("scni", "nitsche"), ("mscni", "nitsche"),
                                                 ("mscni", "transformation")])
def test_owned_rows_of_all_parts_sum_to_the_serial_system(rule, bc_method):
    p = l_shape(0.1)
    rk = rk_approximation(p.x, p.spacing)
    d = nodal_domains(p)
    terms = dict(material=MATERIAL, displacements=[Displacement("bottom", lambda x, t: FIELD.displacement(x))],
                 tractions=[Traction("right", lambda x, t, n: FIELD.traction(x, n))],
                 body_force=FIELD.body_force, rule=rule, bc_method=bc_method, nitsche_penalty=100.0)
    k, f, g, gv = elastic_terms(p, rk, d, **terms)
    part = rcb(p.x, 3)
    shares = [elastic_terms(p, rk, d, nodes=np.flatnonzero(part == r), **terms) for r in range(3)]
    assert abs(sum(s[0] for s in shares) - k).max() <= 1e-13 * abs(k).max()
    assert np.abs(sum(s[1] for s in shares) - f).max() <= 1e-13 * np.abs(f).max()
    # The collocation rows of the parts are those of the whole, in another order.
    gs, gw = sp.vstack([s[2] for s in shares]).toarray(), g.toarray()
    assert gs.shape == gw.shape
    assert np.abs(gs[np.lexsort(gs.T)] - gw[np.lexsort(gw.T)]).max() < 1e-15
    assert np.allclose(np.sort(np.concatenate([s[3] for s in shares])), np.sort(gv), rtol=0, atol=1e-15)


def test_owned_block_on_one_rank_is_the_row_range():
    a = sp.random(9, 9, density=0.4, random_state=0, format="csr")
    ranges = np.array([0, 9])
    assert abs(owned_block(a, ranges) - a).max() == 0
    v = np.arange(9.0)
    assert np.array_equal(owned_entries(v, ranges), v)


def test_one_rank_by_owned_rows_equals_the_whole_assembly():
    p = unit_square(0.1)
    bcs = [Displacement(s, lambda x, t: FIELD.displacement(x)) for s in p.boundary_names]
    for bc_method in ("nitsche", "transformation"):
        a = solve_plane_strain(p, MATERIAL, bcs, body_force=FIELD.body_force, bc_method=bc_method)
        b = solve_plane_strain(p, MATERIAL, bcs, body_force=FIELD.body_force, bc_method=bc_method,
                               distributed=True)
        assert np.abs(a.coefficients - b.coefficients).max() <= 1e-10 * np.abs(a.coefficients).max()
    with pytest.raises(InputError, match="distributed=True needs a nodal rule"):
        solve_plane_strain(p, MATERIAL, bcs, rule="gauss2", distributed=True)


def test_gamg_with_rigid_body_modes_gives_the_direct_solution():
    """CG + GAMG, given the nodes of its rows, aggregates node blocks with the rigid modes as near
    null space: the MUMPS coefficients to its tolerance, whole or by owned rows, in a few dozen
    iterations."""
    pytest.importorskip("petsc4py")
    from rkfx.linalg.petsc import LinearSolver  # noqa: PLC0415

    p = structured(1.0, 1.0, 31, 31)
    bcs = [Displacement(s, lambda x, t: FIELD.displacement(x)) for s in p.boundary_names]
    a = solve_plane_strain(p, MATERIAL, bcs, body_force=FIELD.body_force)
    for distributed in (False, True):
        b = solve_plane_strain(p, MATERIAL, bcs, body_force=FIELD.body_force, solver="cg-gamg",
                               distributed=distributed)
        assert np.abs(a.coefficients - b.coefficients).max() <= 1e-7 * np.abs(a.coefficients).max()
    k = sp.identity(6, format="csr")
    with pytest.raises(InputError, match="coordinates of 2 nodes for 6 rows"):
        LinearSolver(k, solver="cg-gamg", coordinates=np.zeros((2, 2)))


def _sorted_rows(m: sp.csr_matrix) -> bool:
    """Whether every row's columns ascend (read from the arrays, not scipy's flag)."""
    step = np.diff(m.indices.astype(np.int64))
    starts = m.indptr[1:-1]
    inside = np.ones(len(step), bool)
    inside[starts[(starts > 0) & (starts < len(m.indices))] - 1] = False
    return bool(np.all(step[inside] > 0))


@pytest.mark.parametrize(("size", "density", "swap"), [(7, 0.5, None), (400, 0.005, (10, 390))])
def test_renumbered_moves_rows_and_columns(size, density, swap):
    """Rows and columns go to their new places, each row's columns sorted: many rows left
    unsorted by the numbering (sorted by scipy) or a few (sorted in place)."""
    a = sp.random(size, size, density=density, random_state=2, format="csr")
    if swap is None:
        new = np.array([9, 2, 0, 5, 3, 8, 1])
    else:
        new = np.arange(size)
        new[list(swap)] = new[list(swap[::-1])]
    got = renumbered(a, new, size + 3)
    c = a.tocoo()
    expected = sp.csr_matrix((c.data, (new[c.row], new[c.col])), shape=(size + 3, size + 3))
    assert got.has_sorted_indices and _sorted_rows(got)
    assert abs(got - expected).max() == 0 and got.nnz == a.nnz


def test_sort_by_column_is_stable_and_takes_empty_rows():
    """Entries of the chosen rows ordered by column, equal columns in their order, values moved
    with them (one value or a row of values per entry); no rows or no entries are no work."""
    from rkfx.approximation.sparse_rows import sort_by_column

    indptr = np.array([0, 4, 4, 7])
    indices = np.array([5, 1, 5, 0, 9, 3, 3], np.int32)
    data = np.arange(7.0)
    pairs = np.column_stack([data, -data])
    sort_by_column(indptr, indices.copy(), pairs, rows=[2])
    assert np.array_equal(pairs[:4, 0], data[:4])  # row 0 untouched
    idx = indices.copy()
    sort_by_column(indptr, idx, data)
    assert np.array_equal(idx, [0, 1, 5, 5, 3, 3, 9]) and np.array_equal(data, [3, 1, 0, 2, 5, 6, 4])
    sort_by_column(np.zeros(1, np.int64), np.zeros(0, np.int32), np.zeros((0, 2)))
    sort_by_column(np.zeros(1, np.int64), np.zeros(0, np.int32), np.zeros(0))


def test_points_go_to_the_rank_owning_most_of_their_nodes():
    """``point_parts``: a point's owner holds most of its row nodes; a tie goes to the lowest rank."""
    import scipy.sparse as sp

    from rkfx.assembly.matrix_strain import point_parts

    nodes = [[0, 1, 2], [2, 3, 4], [1, 3, 5]]  # parts 0 0 1 | 1 1 2 | 0 1 2 (a three-way tie)
    part = np.array([0, 0, 1, 1, 2, 2])
    rows = [(3 * p + k, 2 * i + c) for p, ns in enumerate(nodes) for k in range(3) for i in ns for c in range(2)]
    r, c = np.array(rows).T
    B = sp.csr_matrix((np.ones(len(r)), (r, c)), shape=(9, 12))
    assert point_parts(B, part).tolist() == [0, 1, 0]


def test_touched_nodes_take_rows_and_columns_of_operators_and_columns_of_conditions():
    """Fields u (2 per node) then p (1 per node) on 5 nodes: a square operator's entry touches
    the nodes of its row and its column; a condition's row numbers are not unknowns."""
    from rkfx.parallel.unknowns import touched_nodes

    a = sp.csr_matrix(([1.0, 2.0], ([3, 11], [12, 0])), shape=(15, 15))  # u of node 1 - p of node 2; p 1 - u 0
    g = sp.csr_matrix(([1.0], ([4], [14])), shape=(6, 15))  # condition 4 on p of node 4
    assert touched_nodes((2, 1), 5, a, constraints=(g,)).tolist() == [0, 1, 2, 4]
    assert touched_nodes((2, 1), 5, g).tolist() == [2, 4]  # read as an operator, row 4 is u of node 2
