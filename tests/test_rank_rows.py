"""A rank of an explicit run builds only the operator rows it reads: those rows equal the whole
build's entry for entry, and every row that touches one of its nodes is among them."""
import numpy as np
import pytest

from rkfx.assembly.smeared_strain import StrainRecipe, smeared_strain
from rkfx.cases import kalthoff
from rkfx.fracture import damage as dm
from rkfx.parallel.partition import rcb


@pytest.fixture(scope="module")
def plate():
    prm = {k: v.default for k, v in kalthoff.PARAMS.items()}
    material = dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], "strain")
    pl, _, _ = kalthoff.setup(30, material, prm)  # a slit with a free tip: supports cut by diffraction
    return pl


@pytest.mark.parametrize("eps_p", [1.0, 0.0])
@pytest.mark.parametrize("size", [2, 3])
def test_share_rows_are_the_whole_rows_and_cover_the_part(plate, eps_p, size):
    whole = smeared_strain(plate.p, plate.rk, plate.domains, eps_p)
    recipe = StrainRecipe(plate.p, plate.rk, plate.domains, eps_p)
    part = rcb(plate.p.x, size)
    for rank in range(size):
        share = recipe.share(part, rank)
        rows_w = whole.stabilization.rows if eps_p else whole.rows
        rows_s = share.stabilization.rows if eps_p else share.rows
        assert rows_s.indptr.shape == rows_w.indptr.shape
        built = np.flatnonzero(np.diff(rows_s.indptr))
        for r in built:
            a = slice(rows_w.indptr[r], rows_w.indptr[r + 1])
            b = slice(rows_s.indptr[r], rows_s.indptr[r + 1])
            assert np.array_equal(rows_w.indices[a], rows_s.indices[b]) and np.array_equal(rows_w.data[a], rows_s.data[b])
        row_of = np.repeat(np.arange(rows_w.num_rows), np.diff(rows_w.indptr))
        needed = np.unique(row_of[part[rows_w.indices] == rank])
        assert np.isin(needed, built).all()
        assert len(built) < rows_w.num_rows  # a share, not the whole
