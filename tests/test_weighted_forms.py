"""WeightedForm: the fixed-pattern sum of A^T diag(w) B equals the sparse products."""
import numpy as np
import pytest
import scipy.sparse as sp

from rkfx.assembly.weighted_forms import WeightedForm, placed
from rkfx.errors import InputError


def test_equals_the_products():
    rng = np.random.default_rng(0)
    a1, b1 = sp.random(30, 12, 0.2, random_state=1, format="csr"), sp.random(30, 9, 0.3, random_state=2, format="csr")
    a2, b2 = sp.random(30, 12, 0.1, random_state=3, format="csr"), sp.random(30, 9, 0.2, random_state=4, format="csr")
    c = sp.random(12, 9, 0.1, random_state=5)
    form = WeightedForm([(a1, b1), (a2, b2)], (12, 9), constant=c)
    for _ in range(2):
        w1, w2 = rng.standard_normal(30), rng.standard_normal(30)
        want = a1.T @ sp.diags(w1) @ b1 + a2.T @ sp.diags(w2) @ b2 + c
        got = form([w1, w2])
        assert np.allclose(got.toarray(), want.toarray(), atol=1e-14)
        got.sort_indices()
        assert got.has_sorted_indices
    assert np.allclose(form([2.0, 0.0]).toarray(), (2 * a1.T @ b1 + c).toarray())


def test_placed_and_bad_shapes():
    a = sp.csr_matrix(np.array([[1.0, 2.0]]))
    assert np.array_equal(placed(a, 5, offset=1, stride=2).toarray(), [[0, 1, 0, 2, 0]])
    with pytest.raises(InputError, match="does not form"):
        WeightedForm([(sp.identity(3), sp.identity(4))], (3, 3))
    with pytest.raises(InputError, match="weight vectors"):
        WeightedForm([(sp.identity(3), sp.identity(3))], (3, 3))([1.0, 2.0])
