"""The batch loops of ``vector_math`` kernels: their own ``sin`` and ``cos`` against
mpmath, and the recompute of every call they cannot serve.

``FAST_SINCOS`` (``rigidkit._engine.primitives``) replaces libm's ``sin`` and ``cos``
in the batch loops of kernels declared ``vector_math=True`` (slerp, powers), so that
LLVM vectorises those loops whole. Here it runs through the engine's real path, a
kernel bound to numba, on random arguments at every scale up to its limit 2^19, on
both sides (by a few ulp) of the multiples of pi/4 where the reduction and the
quadrant change, on tiny and signed-zero arguments, and float32. Error is
``|got - exact| / ulp(exact)``; measured worst 0.78 ulp (glibc: 0.56), bound 1 ulp.

Beyond 2^19, and for an infinite or NaN argument, it gives NaN; the loop reports any
non-finite input or result (status 2) and the call is computed again by NumPy, whose
libm results are asserted here bit for bit, through the fast entry, the general path
and ``out=``.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from rigidkit._engine import kernel, numba_backend
from rigidkit._engine.primitives import (
    FAST_ATAN2,
    FAST_SINCOS,
    NUMBA_PRELUDE,
    numba_prelude,
)

pytestmark = pytest.mark.skipif(not numba_backend.available(), reason="needs numba")

F64 = np.dtype(np.float64)
F32 = np.dtype(np.float32)


@kernel(inputs=[()], outputs=[(2,)], vector_math=True)
def _sincos(x):
    return (sin(x), cos(x))


def _loop(dtype=F64):
    return numba_backend.wait(_sincos, (False,), dtype)


def test_only_the_batch_loops_of_vector_math_kernels_get_it():
    assert FAST_SINCOS in numba_backend.module_source(_sincos, (False,))
    assert "return 2 if bad else 0" in numba_backend.module_source(_sincos, (False,))
    single = numba_backend.module_source(_sincos, numba_backend.SINGLE)
    assert FAST_SINCOS not in single  # one element: libm's, faster unvectorised

    def with_exp(x):
        return exp(sin(x))

    assert numba_prelude([_sincos.fn], vector_math=True) == (
        NUMBA_PRELUDE + FAST_ATAN2 + FAST_SINCOS
    )
    assert numba_prelude([_sincos.fn]) == NUMBA_PRELUDE
    with pytest.raises(ValueError, match="exp"):
        numba_prelude([with_exp], vector_math=True)


def _ulp_errors(x, got, fn):
    err = np.empty(len(x))
    with mpmath.workdps(40):
        for i, (xi, gi) in enumerate(zip(x.tolist(), got.tolist())):
            exact = fn(mpmath.mpf(xi))
            ulp = math.ulp(float(exact)) if exact != 0 else math.ulp(0.0)
            err[i] = float(abs(mpmath.mpf(gi) - exact)) / ulp
    return err


def _arguments(rng):
    quarter = math.pi / 4 * np.arange(-16, 17)
    k = np.unique(np.round(rng.uniform(-(2.0**19), 2.0**19, 200) / (math.pi / 2)))
    near = np.concatenate([quarter, k * (math.pi / 2)])
    steps = [near]
    for d in (1, 2, 5):  # a few ulp either side
        steps += [near + d * np.spacing(near), near - d * np.spacing(near)]
    return np.concatenate(
        steps
        + [
            rng.uniform(-4.0, 4.0, 2000),
            rng.uniform(-1e3, 1e3, 1000),
            rng.uniform(-(2.0**19), 2.0**19, 1000),
            10.0 ** rng.uniform(-300, 0, 500) * rng.choice([-1.0, 1.0], 500),
            [2.0**19, -(2.0**19), np.nextafter(2.0**19, 0.0), 1e-8, 5e-324],
        ]
    )


def test_fast_sin_and_cos_within_one_ulp(rng):
    x = _arguments(rng)
    got = np.empty((x.size, 2))
    assert _loop()(x, got) == 0  # all served by the fast loop
    assert _ulp_errors(x, got[:, 0], mpmath.sin).max() < 1.0
    assert _ulp_errors(x, got[:, 1], mpmath.cos).max() < 1.0


def test_signed_zeros_as_libm():
    got = np.empty((2, 2))
    _loop()(np.array([0.0, -0.0]), got)
    np.testing.assert_array_equal(got, [[0.0, 1.0], [-0.0, 1.0]])
    assert math.copysign(1.0, got[1, 0]) == -1.0


def test_float32_against_float64_libm(rng):
    x = rng.uniform(-1e4, 1e4, 3000).astype(np.float32)
    got = np.empty((x.size, 2), np.float32)
    assert _loop(F32)(x, got) == 0
    ref = np.stack([np.sin(x.astype(np.float64)), np.cos(x.astype(np.float64))], -1)
    assert np.abs(got - ref).max() <= np.finfo(np.float32).eps


@pytest.mark.parametrize("bad", ["above 2^19", -1e6, 1e30, np.inf, np.nan])
@pytest.mark.parametrize("dtype", [F64, F32])
def test_what_the_fast_loop_cannot_serve_is_computed_again(bad, dtype, rng):
    """NaN from the fast sin/cos (beyond 2^19), infinities and NaN: status 2, and
    every way of calling the kernel returns NumPy's libm result instead."""
    _loop(dtype)
    x = rng.uniform(-3.0, 3.0, 12).astype(dtype)
    if bad == "above 2^19":  # the next number of the dtype
        bad = np.nextafter(dtype.type(2.0**19), dtype.type(np.inf))
    x[7] = bad
    status = _loop(dtype)(x, np.empty((12, 2), dtype))
    assert status == 2
    with np.errstate(invalid="ignore"):
        ref = np.stack([np.sin(x), np.cos(x)], -1)
    np.testing.assert_array_equal(_sincos(x), ref)  # the fast entry
    out = np.empty((12, 2), dtype)
    assert _sincos(x, out=out) is out
    np.testing.assert_array_equal(out, ref)
    # A 2-D batch takes the general path; its loop reports the same.
    np.testing.assert_array_equal(_sincos(x.reshape(3, 4)), ref.reshape(3, 4, 2))
