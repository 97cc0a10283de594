"""The container protocol (rigidkit.objects._batch.BatchedArray), once for every class.

Reference: NumPy indexing, reshaping and concatenation of the elements' matrices
(or, for Quaternion, of its 4 components), which the classes must commute with.
"""

import pickle

import numpy as np
import pytest

import rigidkit as rk
from conftest import GROUP_KINDS


def _make(name, shape, rng):
    if name == "Quaternion":
        return rk.Quaternion(rng.standard_normal(shape + (4,)))
    return getattr(rk, name).random(shape, rng)


def _values(x):
    return np.asarray(x) if isinstance(x, rk.Quaternion) else x.as_matrix()


# Every kind of the registry of groups (conftest.GROUP_KINDS), and Quaternion.
CLASSES = [cls.__name__ for cls in GROUP_KINDS] + ["Quaternion"]


@pytest.mark.parametrize("name", CLASSES)
def test_container_protocol_commutes_with_numpy(name):
    rng = np.random.default_rng(5)
    X = _make(name, (2, 3), rng)
    ref = _values(X)
    nt = ref.ndim - 2  # trailing axes of one element's values
    assert X.shape == (2, 3) and len(X) == 2 and not X.single
    np.testing.assert_array_equal(_values(X[1]), ref[1])
    np.testing.assert_array_equal(_values(X[1, 2]), ref[1, 2])
    np.testing.assert_array_equal(_values(X[:, ::2]), ref[:, ::2])
    np.testing.assert_array_equal(
        _values(X[..., 0]), ref[(Ellipsis, 0) + (slice(None),) * nt]
    )
    items = list(X)
    assert len(items) == 2
    np.testing.assert_array_equal(_values(items[0]), ref[0])
    Y = X.reshape(6)
    assert Y.shape == (6,)
    np.testing.assert_array_equal(_values(Y), ref.reshape((6,) + ref.shape[2:]))
    C = type(X).concatenate([X[0], X[1]])
    np.testing.assert_array_equal(_values(C), np.concatenate([ref[0], ref[1]]))
    P = pickle.loads(pickle.dumps(X))
    assert type(P) is type(X)
    np.testing.assert_array_equal(_values(P), ref)
    one = X[0, 0]
    assert one.shape == () and one.single
    with pytest.raises(TypeError):
        len(one)
    with pytest.raises(TypeError):
        one[0]
    assert isinstance(repr(one), str) and isinstance(repr(X), str)


@pytest.mark.parametrize("name", CLASSES)
def test_empty_batch(name):
    X = _make(name, (0,), np.random.default_rng(1))
    assert X.shape == (0,) and len(X) == 0 and list(X) == []
