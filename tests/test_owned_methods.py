"""``a @ b`` and ``a.inv()`` go straight from the operator to the compiled loop.

The methods the engine writes (``_engine.owned_function``, declared by
``objects.group.owned_method``) skip the kernel's entry
for two NumPy batches of one kind, shape and dtype; every other case (strided
storage, N-D batches, mixed dtypes, one element against a batch) must reach the
general method and agree. Checked against the product and the inverse of the
homogeneous matrices by NumPy (``@``, ``np.linalg.inv``), for every kind that has
the methods, with the compiled loops ready.
"""

from __future__ import annotations

import numpy as np
import pytest

import rigidkit as rk
from conftest import GROUP_KINDS
from rigidkit._engine import numba_backend

pytestmark = pytest.mark.skipif(not numba_backend.available(), reason="needs numba")

KINDS = GROUP_KINDS


def _ready(cls, dtype):
    for kern in (cls._compose_kernel, cls._inverse_kernel):
        if kern is not None:  # kinds whose inv is more than one kernel have none
            numba_backend.wait(kern, (False,) * len(kern.inputs), np.dtype(dtype))


def _cases(cls, dtype):
    a = cls.random(12, rng=1, dtype=dtype)
    b = cls.random(12, rng=2, dtype=dtype)
    wide = cls.random(24, rng=3, dtype=dtype)
    return {
        "batch": (a, b),
        "strided storage": (wide[::2], b),  # a view: the loop refuses, the method doesn't
        "one element": (a[3], b[5]),
        "one against a batch": (a[3], b),
        "2-D batches": (a.reshape(3, 4), b.reshape(3, 4)),
        "empty": (a[:0], b[:0]),
    }


# float32 for two kinds only: the generated code is one for all (each kind and
# dtype is two more loops to compile in a fresh CI cache).
CASES = [(c, np.float64) for c in KINDS] + [(c, np.float32) for c in KINDS[:2]]


@pytest.mark.parametrize(
    "cls, dtype", CASES, ids=[f"{c.__name__}-{np.dtype(d).name}" for c, d in CASES]
)
def test_owned_compose_and_inverse(cls, dtype):
    _ready(cls, dtype)
    tol = 64 * np.finfo(dtype).eps
    for label, (a, b) in _cases(cls, dtype).items():
        ma, mb = a.as_matrix().astype(np.float64), b.as_matrix().astype(np.float64)
        for _ in range(2):  # the second call finds the loops the first one asked for
            ab, ai = a @ b, a.inv()
        assert type(ab) is cls and type(ai) is cls, label
        assert ab._data.dtype == dtype and ai._data.dtype == dtype, label
        assert ab.shape == np.broadcast_shapes(a.shape, b.shape), label
        assert ab._data.flags.c_contiguous and ab._data.flags.writeable, label
        assert not np.shares_memory(ab._data, a._data), label
        assert not np.shares_memory(ai._data, a._data), label
        np.testing.assert_allclose(ab.as_matrix(), ma @ mb, rtol=0, atol=tol, err_msg=label)
        np.testing.assert_allclose(
            ai.as_matrix(), np.linalg.inv(ma), rtol=0, atol=tol, err_msg=label
        )
    # Mixed dtypes leave the owned path and compose in the wider one.
    a, b = _cases(cls, np.float32)["batch"]
    assert (a @ _cases(cls, np.float64)["batch"][1])._data.dtype == np.float64


def test_owned_methods_keep_their_docs_and_errors():
    R = rk.Rotation.random(3, rng=0)
    assert rk.Rotation.inv.__doc__ and "conjugate" in rk.Rotation.inv.__doc__
    with pytest.raises(TypeError, match="not defined"):
        np.ones((3, 3)) @ R
    # Two kinds of one family still compose in the more general one.
    T = rk.Transform.random(3, rng=1)
    RT = R @ T
    assert type(RT) is rk.Transform
    np.testing.assert_allclose(
        RT.as_matrix()[:, :3, :],
        R.as_matrix() @ T.as_matrix()[:, :3, :],
        rtol=0,
        atol=1e-14,
    )
    # ``@`` with points is still ``apply``.
    v = np.array([1.0, 0.0, 0.0])
    np.testing.assert_allclose(R @ v, R.as_matrix() @ v, rtol=0, atol=1e-15)
