"""The classic singular coefficients of rotation formulas, with their series.

Each is finite and accurate to about one ulp on the whole real line. Below its
threshold a coefficient is its Taylor series, carried to the order at which the
first omitted term is below 1e-16 relative at the threshold, so float64 (and,
a fortiori, float32) gets a correctly rounded-ish value; above it, the closed form,
whose relative error there is a few ulp because no cancellation is left. The
closed form is evaluated at a safe argument so the unused branch stays finite.
"""

from .._engine import helper


@helper
def sinc(x):
    """``sin(x) / x``.

    Series to x^6 below |x| < 0.03: the omitted x^8/9! is < 2e-19 there.
    """
    x2 = x * x
    small = abs(x) < 0.03
    series = 1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0))
    safe = where(small, 1.0, x)
    return where(small, series, sin(safe) / safe)


@helper
def versinc2(x):
    """``(1 - cos(x)) / x**2``, computed as ``2 sin^2(x/2) / x^2`` (no cancellation).

    Series to x^6 below |x| < 0.03: the omitted x^8/10! is < 2e-20 there.
    """
    x2 = x * x
    small = abs(x) < 0.03
    series = 0.5 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0)))
    safe = where(small, 1.0, x)
    s = sin(0.5 * safe) / safe
    return where(small, series, 2.0 * s * s)


@helper
def sin_defect3(x):
    """``(x - sin(x)) / x**3``.

    The closed form cancels: its relative error is about 6 eps / x^2 (1.3e-15 at
    x = 1, 3e-16 at x = 2). Below |x| < 2 we use the series instead, carried to
    x^20 so that the first omitted term, 6 x^22 / 25!, is < 2e-18 relative at 2.
    Successive terms differ by the factor -x^2 / ((2k+4)(2k+5)).
    """
    x2 = x * x
    small = abs(x) < 2.0
    series = (
        1.0
        - x2
        / 20.0
        * (
            1.0
            - x2
            / 42.0
            * (
                1.0
                - x2
                / 72.0
                * (
                    1.0
                    - x2
                    / 110.0
                    * (
                        1.0
                        - x2
                        / 156.0
                        * (
                            1.0
                            - x2
                            / 210.0
                            * (
                                1.0
                                - x2
                                / 272.0
                                * (
                                    1.0
                                    - x2
                                    / 342.0
                                    * (1.0 - x2 / 420.0 * (1.0 - x2 / 506.0))
                                )
                            )
                        )
                    )
                )
            )
        )
    ) / 6.0
    safe = where(small, 2.0, x)
    return where(small, series, (safe - sin(safe)) / (safe * safe * safe))


@helper
def atan_ratio(n, w):
    """``atan2(n, w) / n`` for ``n >= 0`` (the angle over the sine, quaternion log).

    With t = n / w small (w > 0), atan(t)/t = 1 - t^2/3 + t^4/5 - ...; series to
    t^8 below t < 0.02 (omitted t^10/11 < 1e-18). Elsewhere atan2 is exact-ish and
    n >= 0.02 w is far from zero unless w is tiny too, which only happens for a
    zero quaternion (rejected before any kernel runs).
    """
    small = n < 0.02 * w
    safe_w = where(small, w, 1.0)
    t = n / safe_w
    t2 = t * t
    series = (1.0 - t2 * (1.0 / 3.0 - t2 * (0.2 - t2 * (1.0 / 7.0 - t2 / 9.0)))) / safe_w
    safe_n = where(small, 1.0, n)
    return where(small, series, atan2(safe_n, w) / safe_n)
