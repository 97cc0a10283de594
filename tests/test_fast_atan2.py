"""The numba loops' own ``atan2`` (``NUMBA_PRELUDE``) against mpmath at 40 digits.

Numba's ``math.atan2`` calls libm, ~20 ns an element and never vectorised, so a
generated loop that can be vectorised (no other libm call) uses a branch-free one,
``FAST_ATAN2`` (see ``rigidkit._engine.primitives.numba_prelude``). Here it runs
through the engine's real path, a kernel bound to numba, on:

* random pairs at scales 1e-300 ... 1e300, and with unrelated scales (tiny ratios);
* both sides, by a few ulp, of every threshold: ``|y|/|x| = tan(pi/8)`` (the two
  reductions), ``|y| = |x|``, the scalings of ``max(|x|, |y|)`` above 1e289 and below
  1e-241 (and 1e300, max double), the cut-off of the residual at 1e-290;
* subnormals, zeros and signed zeros, the axes and the diagonals of the four quadrants.

Error is ``|got - exact| / ulp(exact)`` (the ulp of the binade of the exact value).
Measured worst: 0.61 ulp on the cases here, 0.66 over 400,000 random pairs (half of
them with ``|y|/|x|`` just above tan(pi/8), where the error peaks); glibc's ``atan2``
measures 0.76 and 0.79 on the same. The bound asserted is 1 ulp. Zeros, axes and
diagonals (exact results 0, pi/4, ..., pi) and the sign of every result are those of
``math.atan2``. Only finite inputs are covered: the kernels get validated, finite
data, and this ``atan2`` gives NaN for an infinite one (libm: a multiple of pi/4).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np

from rigidkit._engine import kernel, numba_backend
from rigidkit._engine.primitives import FAST_ATAN2, NUMBA_PRELUDE, numba_prelude


@kernel(inputs=[(), ()], outputs=[()])
def _angle(y, x):
    return (atan2(y, x),)


def test_the_loops_here_and_only_vectorisable_ones_get_the_fast_atan2():
    """What the rest of this file measures is FAST_ATAN2, not libm's; a kernel that
    calls another libm function (its loop stays scalar) keeps libm's."""
    assert FAST_ATAN2 in numba_backend.module_source(_angle, (False, False))

    def with_sin(y, x):
        return atan2(y, x) * sin(x)

    def with_nested_exp(y, x):
        return (lambda v: exp(v))(atan2(y, x))

    def without_atan2(y, x):
        return sqrt(y * y + x * x)

    assert numba_prelude([_angle.fn]) == NUMBA_PRELUDE + FAST_ATAN2
    assert numba_prelude([_angle.fn], batch=False) == NUMBA_PRELUDE  # one element
    assert numba_prelude([_angle.fn, with_sin]) == NUMBA_PRELUDE
    assert numba_prelude([with_nested_exp]) == NUMBA_PRELUDE
    assert numba_prelude([without_atan2]) == NUMBA_PRELUDE


def _numba_atan2(y, x):
    y = np.ascontiguousarray(y, dtype=np.float64)
    x = np.ascontiguousarray(x, dtype=np.float64)
    return _angle(y, x, backend="numba")


def _ulp_errors(y, x, got):
    """``|got - atan2(y, x)| / ulp`` per element, the exact value from mpmath."""
    err = np.empty(len(got))
    with mpmath.workdps(40):
        for i, (yi, xi, gi) in enumerate(zip(y.tolist(), x.tolist(), got.tolist())):
            exact = mpmath.atan2(yi, xi)
            r = float(exact)
            ulp = math.ulp(r)
            power_of_two = abs(math.frexp(r)[0]) == 0.5 and abs(r) > 2.0**-1022
            if power_of_two and abs(mpmath.mpf(r)) > abs(exact):
                ulp /= 2  # rounded up onto a power of two: the binade below's ulp
            err[i] = float(abs(mpmath.mpf(gi) - exact)) / ulp
    return err


def _steps(v, k):
    """``v`` and its ``k`` floating-point neighbours on each side."""
    out = [v]
    lo = hi = v
    for _ in range(k):
        lo, hi = np.nextafter(lo, -np.inf), np.nextafter(hi, np.inf)
        out += [lo, hi]
    return out


def _below(v, k):
    """The ``k`` floating-point numbers below ``v``."""
    out = []
    for _ in range(k):
        v = np.nextafter(v, -np.inf)
        out.append(v)
    return out


def _quadrants(y, x):
    """Every sign combination of every pair, and the pairs swapped (|y| > |x|)."""
    y, x = np.asarray(y, dtype=np.float64), np.asarray(x, dtype=np.float64)
    ys, xs = np.concatenate([y, x]), np.concatenate([x, y])
    return (
        np.concatenate([ys, -ys, ys, -ys]),
        np.concatenate([xs, xs, -xs, -xs]),
    )


def _threshold_pairs():
    """(|y|, |x|) on both sides of every threshold, a few ulp each."""
    tan8 = float(mpmath.tan(mpmath.pi / 8))
    tiny = 2.0**-1074
    y, x = [], []
    for scale in (1.0, 3.7, 1e-200, 1e200, 1e-300, 1e300, 1e305, 1e-310, 1000 * tiny):
        for yi in _steps(tan8 * scale, 4) + _steps(scale, 4):
            y.append(yi)
            x.append(scale)
    for edge in (1e289, 1e-241, 1e300, 1.7976931348623157e308):
        mxs = _steps(edge, 3) if edge < 1e308 else [edge, *_below(edge, 3)]
        for mx in mxs:
            for ratio in (1.0, 0.99, 0.5, 0.42, 0.41, 0.3, 1e-10, 1e-60):
                y.append(mx * ratio)
                x.append(mx)
    # The residual's cut-off; below it (subnormal mn) the residual would be noise.
    for mn in [*_steps(1e-290, 3), 1e-300, 1e-305, 1e-310, 12345 * tiny]:
        for mx in (1e-290, 2e-290, 2.4e-290, 1e-250, 2e-241, 1e-241, 1.0, 1e250):
            y.append(mn)
            x.append(mx)
    return _quadrants(y, x)


def _random_pairs(rng):
    y, x = [], []
    for e in (-300, -150, -20, 0, 20, 150, 300):
        y.append(rng.standard_normal(400) * 10.0**e)
        x.append(rng.standard_normal(400) * 10.0**e)
    # Unrelated scales: tiny and huge ratios, results near 0 and pi/2 (and subnormal).
    y.append(rng.standard_normal(400) * 10.0 ** rng.uniform(-300, 300, 400))
    x.append(rng.standard_normal(400) * 10.0 ** rng.uniform(-300, 300, 400))
    # Ratios near 1 and tan(pi/8) at random scales (the two reductions meet there).
    base = rng.standard_normal(400) * 10.0 ** rng.uniform(-30, 30, 400)
    ratio = rng.choice([0.41421356237309503, 1.0], 400) * (
        1 + rng.uniform(-1e-3, 1e-3, 400)
    )
    y.append(base * ratio)
    x.append(base)
    # Subnormals: both, and one against a normal number.
    tiny = 2.0**-1074
    y.append(rng.integers(-(2**20), 2**20, 500) * tiny)
    x.append(rng.integers(-(2**20), 2**20, 500) * tiny)
    y.append(rng.integers(-(2**52), 2**52, 200) * tiny)
    x.append(rng.standard_normal(200) * 1e-300)
    y.append(rng.integers(-(2**52), 2**52, 200) * tiny)
    x.append(rng.standard_normal(200) * 10.0 ** rng.uniform(-240, 300, 200))
    y, x = np.concatenate(y), np.concatenate(x)
    return np.concatenate([y, x]), np.concatenate([x, y])


def _check_accuracy(y, x):
    got = _numba_atan2(y, x)
    err = _ulp_errors(y, x, got)
    i = int(np.argmax(err))
    assert err[i] < 1.0, f"atan2({y[i]!r}, {x[i]!r}) = {got[i]!r}: {err[i]:.3f} ulp"
    assert (np.abs(got) <= math.pi).all()
    libm = np.array([math.atan2(a, b) for a, b in zip(y.tolist(), x.tolist())])
    bad = np.signbit(got) != np.signbit(libm)
    assert not bad.any(), (y[bad][:5], x[bad][:5], got[bad][:5])


def test_random_pairs_within_an_ulp():
    y, x = _random_pairs(np.random.default_rng(20240611))
    _check_accuracy(y, x)


def test_both_sides_of_every_threshold_within_an_ulp():
    _check_accuracy(*_threshold_pairs())


def test_zeros_axes_and_diagonals_are_libms():
    """Exact results (0, pi/4, pi/2, 3 pi/4, pi, signed) are the rounded values,
    bit for bit, and signed zeros follow libm: atan2(+-0, -0) = +-pi."""
    vals = [0.0, 2.0**-1074, 1e-300, 1.0, 3.7, 1e300, 1.7976931348623157e308]
    y, x = [], []
    for a in vals:
        y += [0.0, a, a]
        x += [a, 0.0, a]
    y, x = _quadrants(y, x)
    got = _numba_atan2(y, x)
    want = np.array([math.atan2(a, b) for a, b in zip(y.tolist(), x.tolist())])
    assert np.array_equal(got, want)
    assert np.array_equal(np.signbit(got), np.signbit(want))
    assert np.array_equal(
        _numba_atan2([0.0, -0.0, 0.0, -0.0], [-0.0, -0.0, 0.0, 0.0]),
        [math.pi, -math.pi, 0.0, -0.0],
    )


def test_nan_in_nan_out():
    got = _numba_atan2(
        [np.nan, 1.0, np.nan, 0.0, -0.0], [1.0, np.nan, np.nan, np.nan, np.nan]
    )
    assert np.isnan(got).all()


def test_float32_loop_keeps_float32():
    """A float32 loop computes in float64 (the literals promote) and stores float32:
    the result is the float32 nearest the exact angle, or next to it."""
    rng = np.random.default_rng(5)
    y = rng.standard_normal(1000).astype(np.float32)
    x = rng.standard_normal(1000).astype(np.float32)
    got = _angle(y, x, backend="numba")
    assert got.dtype == np.float32
    with mpmath.workdps(40):
        exact = np.array(
            [float(mpmath.atan2(a, b)) for a, b in zip(y.tolist(), x.tolist())]
        )
    ulp32 = np.spacing(np.abs(exact).astype(np.float32))
    assert (np.abs(got.astype(np.float64) - exact) <= ulp32).all()
