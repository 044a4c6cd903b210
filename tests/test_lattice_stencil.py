"""Lattice stencils (``rkfx.assembly.lattice_stencil``): on a uniform grid with a slit, the
stencil products are the sparse products over the same (snapped) rows bit for bit, for the
strains, the force with and without subcell stresses, and the damaged force; snapping moves
the rows by round-off only; a rank's share is snapped to the same template as the whole
operator; off a uniform grid nothing changes."""
import dataclasses

import numpy as np
import pytest

from rkfx.approximation.diffraction import cracks
from rkfx.approximation.shape_functions import rk_approximation
from rkfx.assembly.lattice_stencil import TEMPLATE_RTOL, lattice_of, template_particle
from rkfx.assembly.smeared_strain import row_strains, smeared_strain
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.particles import graded, jittered
from rkfx.materials.elasticity import ElasticMaterial

SLIT = ((0.0, 0.25), (0.5, 0.25))  # on a row midline of the 40 x 43 grid below


@pytest.fixture(scope="module")
def plate():
    xs, ys = np.linspace(0.0, 1.0, 40), np.linspace(0.0, 1.0, 43)
    p = graded(xs, ys)
    rk = rk_approximation(p.x, p.spacing, 2.0, cracks=cracks([np.array(SLIT)], [(False, True)]))
    domains = grid_domains(xs, ys, [SLIT])
    return p, rk, domains, smeared_strain(p, rk, domains, eps_p=1.0)


def sparse(op):
    """The same operator without its stencils (the sparse products over the same rows)."""
    return dataclasses.replace(op, stabilization=dataclasses.replace(op.stabilization, stencil=None))


def test_the_stencils_cover_the_interior(plate):
    p, rk, _, op = plate
    st = op.stabilization.stencil
    assert st is not None and st.template.slots == 4
    rows, nodes = st.coverage
    assert rows > 0.6 and nodes > 0.4  # the boundary layers and the slit's neighbourhood stay sparse
    c = template_particle(p.x, rk)
    assert np.any((st.strain_start <= c) & (c < st.strain_start + st.strain_length))  # it has its own rows
    assert len(st.sparse_rows) > 0 and len(st.sparse_nodes) > 0


def test_stencil_products_are_the_sparse_products_bit_for_bit(plate):
    p, _, _, op = plate
    plain = sparse(op)
    rng = np.random.default_rng(0)
    d = rng.standard_normal(2 * p.num_nodes)
    (e1, sub1), (e0, sub0) = op.strains(d), plain.strains(d)
    assert np.array_equal(e1, e0) and np.array_equal(sub1, sub0)
    stress = rng.standard_normal((p.num_nodes, 3))
    sub_stress = rng.standard_normal(sub0.shape)
    assert np.array_equal(op.force(stress), plain.force(stress))
    assert np.array_equal(op.force(stress, sub_stress), plain.force(stress, sub_stress))
    c = ElasticMaterial(2.0e11, 0.3).D()
    damage = rng.uniform(0.0, 1.0, p.num_nodes)
    assert np.array_equal(op.damaged_force(stress, sub1.copy(), c, damage),
                          plain.damaged_force(stress, sub0.copy(), c, damage))


def test_snapping_moves_the_rows_by_round_off_only(plate):
    p, rk, domains, op = plate
    raw = smeared_strain(p, rk, domains, eps_p=1.0, lattice=False)
    assert raw.stabilization.stencil is None
    d = np.random.default_rng(1).standard_normal(2 * p.num_nodes)
    a, b = row_strains(op.stabilization.rows, d), row_strains(raw.stabilization.rows, d)
    assert 0 < np.abs(a - b).max() <= 50 * TEMPLATE_RTOL * np.abs(b).max()


def test_a_share_is_snapped_to_the_whole_operators_template(plate):
    """Rows built for some particles only (a rank's share), the template particle not among
    them, equal the whole operator's rows entry for entry."""
    p, rk, domains, op = plate
    c = template_particle(p.x, rk)
    points = np.flatnonzero(p.x[:, 0] > 0.6)
    assert c not in points
    share = smeared_strain(p, rk, domains, eps_p=1.0, points=points).stabilization
    whole = op.stabilization
    assert share.stencil is None
    for ell in points[::37]:
        r0, r1 = whole.ptr[ell], whole.ptr[ell + 1]
        q0, q1 = whole.rows.indptr[r0], whole.rows.indptr[r1]
        s0, s1 = share.rows.indptr[r0], share.rows.indptr[r1]
        assert np.array_equal(share.rows.indices[s0:s1], whole.rows.indices[q0:q1])
        assert np.array_equal(share.rows.data[s0:s1], whole.rows.data[q0:q1])


def test_no_stencil_off_a_uniform_grid():
    p = jittered(12, 0.2)
    assert lattice_of(p.x) is None
    xs, ys = np.linspace(0.0, 1.0, 12) ** 1.3, np.linspace(0.0, 1.0, 12)
    q = graded(xs, ys)
    assert lattice_of(q.x) is None
    op = smeared_strain(q, rk_approximation(q.x, q.spacing, 2.0), grid_domains(xs, ys), eps_p=1.0)
    assert op.stabilization.stencil is None
    u = graded(np.linspace(0.0, 2.0, 9), np.linspace(0.0, 1.0, 5))
    assert lattice_of(u.x) == lattice_of(u.x) and lattice_of(u.x).nx == 9
