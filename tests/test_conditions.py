"""The boundary-condition vocabulary: values of every form evaluate to one shape."""
import numpy as np
import pytest

from rkfx.conditions import Displacement, Flux, Pressure, Traction, Velocity, split, values
from rkfx.errors import InputError

X = np.array([[0.0, 1.0], [2.0, 3.0], [4.0, 5.0]])
N = np.tile([0.0, 1.0], (3, 1))


@pytest.mark.parametrize("value, expected", [
    (0.5, [[0.5]] * 3),
    (lambda x, t: x[:, 1] * t, [[2.0], [6.0], [10.0]]),           # (m,) for one component
    (lambda x, t: x * t, [[2.0], [6.0], [10.0]]),                 # (m, gdim): the component is taken
])
def test_one_component(value, expected):
    assert np.array_equal(values(Displacement("top", value, (1,)), X, 2.0), np.array(expected))


def test_vectors_and_natural_conditions():
    assert np.array_equal(values(Traction("top", [0.0, -3.0]), X, 0.0, N), np.tile([0.0, -3.0], (3, 1)))
    tr = Traction("top", lambda x, t, n: -t * n)
    assert np.array_equal(values(tr, X, 2.0, N), -2.0 * N)
    assert np.array_equal(values(Flux("bottom", lambda x, t, n: x[:, 0] + n[:, 1]), X, 0.0, N), [[1.0], [3.0], [5.0]])
    assert np.array_equal(values(Pressure("right"), X), np.zeros((3, 1)))
    assert np.array_equal(values(Velocity("left", [1.0, 2.0]), X), np.tile([1.0, 2.0], (3, 1)))


def test_bad_conditions_name_the_culprit():
    with pytest.raises(InputError, match="components"):
        Displacement("top", 0.0, (0, 0))
    with pytest.raises(InputError, match="finite numbers"):
        Displacement("bottom", (None, 0.0))
    with pytest.raises(InputError, match="finite numbers"):
        Pressure("bottom", float("nan"))
    with pytest.raises(InputError, match="value has shape"):
        values(Displacement("top", lambda x, t: np.zeros(5), (0,)), X, 0.0)
    with pytest.raises(InputError, match="pass n"):
        values(Flux("top", lambda x, t, n: 0 * x[:, 0]), X, 0.0)
    with pytest.raises(InputError, match="not a boundary condition"):
        split([("top", 0.0)])
