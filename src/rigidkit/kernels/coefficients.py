"""The classic singular coefficients of rotation formulas, with their series.

Each is finite and accurate to about one ulp on the whole real line. Below its
threshold a coefficient is its Taylor series, carried to the order at which the
first omitted term is below 1e-16 relative at the threshold, so float64 (and,
a fortiori, float32) gets a correctly rounded-ish value; above it, the closed form,
whose relative error there is a few ulp because no cancellation is left. The
closed form is evaluated at a safe argument so the unused branch stays finite.

Each is a ``numerical`` helper (see :func:`rigidkit._engine.helper`): its
branches are one function, so :mod:`rigidkit.symbolic` writes it in closed form.
"""

from .._engine import helper


@helper(numerical=True)
def sinc(x):
    """``sin(x) / x``.

    Series to x^6 below |x| < 0.03: the omitted x^8/9! is < 2e-19 there.
    """
    x2 = x * x
    small = abs(x) < 0.03
    series = 1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0) * (1.0 - x2 * (1.0 / 42.0)))
    safe = where(small, 1.0, x)
    # sin(x), not sin(safe): the same value wherever it is used, finite with a
    # finite derivative where it is not, and the same argument as a cos(x) beside
    # it, so a loop's sine and cosine share one reduction (quat_power_entries).
    return where(small, series, sin(x) / safe)


@helper(numerical=True)
def versinc2(x):
    """``(1 - cos(x)) / x**2``, computed as ``2 sin^2(x/2) / x^2`` (no cancellation).

    Series to x^6 below |x| < 0.03: the omitted x^8/10! is < 2e-20 there.
    """
    x2 = x * x
    small = abs(x) < 0.03
    series = 0.5 * (
        1.0 - x2 * (1.0 / 12.0) * (1.0 - x2 * (1.0 / 30.0) * (1.0 - x2 * (1.0 / 56.0)))
    )
    safe = where(small, 1.0, x)
    s = sin(0.5 * safe) / safe
    return where(small, series, 2.0 * s * s)


@helper(numerical=True)
def sin_defect3_from_sin(x, sin_x):
    """``(x - sin(x)) / x**3`` given ``sin_x = sin(x)`` (a kernel that has the sine
    already, e.g. from the half angle, passes it: no second sine).

    The closed form cancels: its relative error is about 6 eps / x^2 (1.3e-15 at
    x = 1, 3e-16 at x = 2). Below |x| < 2 we use the series instead, carried to
    x^20 so that the first omitted term, 6 x^22 / 25!, is < 2e-18 relative at 2.
    Successive terms differ by the factor -x^2 / ((2k+4)(2k+5)).
    """
    x2 = x * x
    small = abs(x) < 2.0
    # Nested from the inside, each factor a product by the rounded reciprocal
    # (a division is ~4x a product's throughput and the chain sits in every SO(3)
    # Jacobian and IMU step; the rounding of 1/k moves the result by < 1 ulp).
    s = 1.0 - x2 * (1.0 / 506.0)
    s = 1.0 - x2 * (1.0 / 420.0) * s
    s = 1.0 - x2 * (1.0 / 342.0) * s
    s = 1.0 - x2 * (1.0 / 272.0) * s
    s = 1.0 - x2 * (1.0 / 210.0) * s
    s = 1.0 - x2 * (1.0 / 156.0) * s
    s = 1.0 - x2 * (1.0 / 110.0) * s
    s = 1.0 - x2 * (1.0 / 72.0) * s
    s = 1.0 - x2 * (1.0 / 42.0) * s
    s = 1.0 - x2 * (1.0 / 20.0) * s
    series = s * (1.0 / 6.0)
    # sin_x is the sine of x, not of safe: finite either way, used only where the
    # two agree.
    safe = where(small, 2.0, x)
    return where(small, series, (safe - sin_x) / (safe * safe * safe))


@helper(numerical=True)
def sin_defect3(x):
    """``(x - sin(x)) / x**3``: :func:`sin_defect3_from_sin` of ``(x, sin(x))``."""
    return sin_defect3_from_sin(x, sin(x))


@helper(numerical=True)
def atan_ratio(n, w):
    """``atan2(n, w) / n`` for ``n >= 0`` (the angle over the sine, quaternion log).

    With t = n / w small (w > 0), atan(t)/t = 1 - t^2/3 + t^4/5 - ...; series to
    t^8 below t < 0.02 (omitted t^10/11 < 1e-18). Elsewhere atan2 is exact-ish and
    n >= 0.02 w is far from zero unless w is tiny too, which only happens for a
    zero quaternion (rejected before any kernel runs).
    """
    small = n < 0.02 * w
    safe_w = where(small, w, 1.0)
    # t = 0 where unused: n itself may be large there (a non-unit quaternion), and
    # t^8 would overflow in the branch that where() discards.
    t = where(small, n / safe_w, 0.0)
    t2 = t * t
    series = (
        1.0 - t2 * (1.0 / 3.0 - t2 * (0.2 - t2 * (1.0 / 7.0 - t2 * (1.0 / 9.0))))
    ) / safe_w
    safe_n = where(small, 1.0, n)
    return where(small, series, atan2(safe_n, w) / safe_n)


@helper(numerical=True)
def cos_defect4(x):
    """``(cos(x) - 1 + x**2/2) / x**4`` (1/24 at 0), the third SE(3) Jacobian coefficient.

    No threshold of its own: with ``y = x/2``,
    ``cos x - 1 + x^2/2 = 2 (y - sin y)(y + sin y)``, so the coefficient is
    ``sin_defect3(y) (1 + sinc(y)) / 8``, a product of accurate factors with no
    cancellation (``1 + sinc >= 0.78``). Measured against mpmath: <= 2 ulp on
    [1e-12, 6.2].
    """
    y = 0.5 * x
    return sin_defect3(y) * (1.0 + sinc(y)) * 0.125


@helper(numerical=True)
def cot_defect2(x):
    """``(1 - (x/2) cot(x/2)) / x**2`` (1/12 at 0), the coefficient of SO(3) ``J^-1``.

    Equals ``(1 - x sin(x) / (2 (1 - cos x))) / x^2``; singular at ``x = 2 pi`` (as
    ``J^-1`` is), finite (``1/pi^2``) at ``x = pi``. No threshold of its own: with
    ``y = x/2``, ``1 - y cot y = (sin y - y cos y) / sin y`` and
    ``sin y - y cos y = y^3 (versinc2(y) - sin_defect3(y))``, a difference of at
    most 2:1 (1/2 - 1/6 at 0, 2/pi^2 - 1/pi^2 at pi), so no digits are lost: the
    coefficient is ``(versinc2(y) - sin_defect3(y)) / (4 sinc(y))``. The series
    (``1/12 + x^2/720 + x^4/30240 + ...``, coefficients ``|B_2k| / (2k)!``) lives
    in the two helpers' thresholds. Measured against mpmath: <= 3 ulp on
    [1e-12, 6.2].
    """
    y = 0.5 * x
    return (versinc2(y) - sin_defect3(y)) / (4.0 * sinc(y))


@helper(numerical=True)
def sin_cos_defect5_from_sincos(x, sin_x, cos_x):
    """``(2x - 3 sin(x) + x cos(x)) / (2 x**5)`` given ``sin_x``, ``cos_x`` of ``x``.

    The closed form cancels badly (relative error ~ 180 eps / x^4: 3 ulp at 2.5,
    1600 ulp at 0.5). Below |x| < 2.5 we use the series
    ``sum_{n>=2} (-1)^n (2n - 2) / (2 (2n + 1)!) x^(2n-4)``, carried to x^22 so the
    first omitted term is < 7e-19 relative at 2.5; successive terms differ by the
    factor ``-x^2 n / ((n - 1)(2n + 2)(2n + 3))``, nested below from the inside.
    Above 2.5 the closed form is within 3 ulp (measured against mpmath).
    """
    x2 = x * x
    small = abs(x) < 2.5
    s = 1.0 - x2 * (2.0 / 1287.0)  # n = 12 -> 13
    s = 1.0 - x2 * (11.0 / 6000.0) * s
    s = 1.0 - x2 * (5.0 / 2277.0) * s
    s = 1.0 - x2 * (3.0 / 1120.0) * s
    s = 1.0 - x2 * (4.0 / 1197.0) * s
    s = 1.0 - x2 * (7.0 / 1632.0) * s
    s = 1.0 - x2 * (1.0 / 175.0) * s
    s = 1.0 - x2 * (5.0 / 624.0) * s
    s = 1.0 - x2 * (2.0 / 165.0) * s
    s = 1.0 - x2 * (1.0 / 48.0) * s
    s = 1.0 - x2 * (1.0 / 21.0) * s  # n = 2 -> 3
    safe = where(small, 2.5, x)
    closed = (2.0 * safe - 3.0 * sin_x + safe * cos_x) / (
        2.0 * safe * safe * safe * safe * safe
    )
    return where(small, s * (1.0 / 120.0), closed)


@helper(numerical=True)
def sin_cos_defect5(x):
    """``(2x - 3 sin(x) + x cos(x)) / (2 x**5)`` (1/120 at 0), last coefficient of ``Q``:
    :func:`sin_cos_defect5_from_sincos` of ``(x, sin(x), cos(x))``."""
    return sin_cos_defect5_from_sincos(x, sin(x), cos(x))


@helper(numerical=True)
def exprel(x):
    """``(exp(x) - 1) / x`` (1 at 0), as ``scipy.special.exprel``.

    The closed form loses about ``eps e^x / |e^x - 1|`` relative (1.6 eps at
    x = 1, 10 eps at 0.1). Below |x| < 1 we use the series ``sum x^k / (k+1)!``
    nested as ``1 + x/2 (1 + x/3 (1 + ...))``, carried to x^18 so the first
    omitted term, x^19 / 20!, is < 7e-19 relative at |x| = 1 (exprel(-1) = 0.63).
    """
    small = abs(x) < 1.0
    s = 1.0 + x / 19.0
    for k in range(18, 1, -1):
        s = 1.0 + x / k * s
    safe = where(small, 1.0, x)
    return where(small, s, (exp(safe) - 1.0) / safe)


@helper(numerical=True)
def norm3(x, y, z):
    """``sqrt(x^2 + y^2 + z^2)`` whose gradient is 0, not NaN, at the origin.

    ``d sqrt(s)/ds`` is infinite at ``s = 0``, and autodiff multiplies it by
    ``ds/dx = 0``, giving NaN; evaluating the root at a safe argument keeps every
    gradient finite. Callers use the norm through even coefficients times the
    vector itself, so a zero derivative of the norm at 0 is the right one.
    """
    s = x * x + y * y + z * z
    pos = s > 0.0
    return where(pos, sqrt(where(pos, s, 1.0)), 0.0)
