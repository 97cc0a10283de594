"""The primitive functions a kernel may call, bound once per backend.

A kernel is a plain Python function over scalar components whose free names are
the primitives listed in :data:`PRIMITIVES`, other helper kernels, and literals.
Each backend evaluates the same function object with its own globals:

* ``math``   : plain Python floats (one element) and, textually, numba loops
  (:data:`NUMBA_PRELUDE`; a loop that can be vectorised gets a branch-free
  ``atan2`` of its own, :data:`FAST_ATAN2`, within 0.66 ulp like libm's);
* ``xp``     : element-wise over arrays of any array-API namespace;
* ``sympy``  : symbolic expressions.

``where(cond, a, b)`` is the only branch a kernel may take on data; both ``a`` and
``b`` are always evaluated and must be finite for every input.
"""

from __future__ import annotations

import math

#: Names every binding provides. ``pi`` is a constant, the rest are functions.
PRIMITIVES = (
    "sqrt",
    "sin",
    "cos",
    "tan",
    "asin",
    "acos",
    "atan",
    "atan2",
    "exp",
    "log",
    "abs",
    "where",
    "maximum",
    "minimum",
    "copysign",
    "pi",
)


def _where_scalar(cond, a, b):
    return a if cond else b


def math_bindings() -> dict:
    """Primitives over Python floats (:data:`NUMBA_PRELUDE` mirrors them in numba)."""
    return {
        "sqrt": math.sqrt,
        "sin": math.sin,
        "cos": math.cos,
        "tan": math.tan,
        "asin": math.asin,
        "acos": math.acos,
        "atan": math.atan,
        "atan2": math.atan2,
        "exp": math.exp,
        "log": math.log,
        "abs": abs,
        "where": _where_scalar,
        "maximum": max,
        "minimum": min,
        "copysign": math.copysign,
        "pi": math.pi,
    }


#: Source text of the same primitives for a generated numba module (``math``'s
#: functions; see :func:`numba_prelude` for the module of a kernel).
NUMBA_PRELUDE = """\
import math
import numba
from math import sqrt, sin, cos, tan, asin, acos, atan, atan2, exp, log, copysign, pi


@numba.njit(inline="always", error_model="numpy")
def where(cond, a, b):
    return a if cond else b


@numba.njit(inline="always", error_model="numpy")
def maximum(a, b):
    return a if a >= b else b


@numba.njit(inline="always", error_model="numpy")
def minimum(a, b):
    return a if a <= b else b
"""


#: A branch-free ``atan2`` for numba loops, to follow :data:`NUMBA_PRELUDE` (it
#: replaces ``math.atan2`` there): within 0.66 ulp of the exact value (glibc's:
#: 0.79), finite inputs only. Vectorised it costs ~2.6 ns an element against libm's
#: ~20; in a loop that stays scalar it is slower than libm's (~170 instructions,
#: its selects become branches, values spilled around every other libm call; SE(3)
#: log 74 -> 105 ns an element), hence :func:`numba_prelude`.
FAST_ATAN2 = """

@numba.njit(inline="always", error_model="numpy")
def atan2(y, x):
    # numba's math.atan2 calls libm (~20 ns an element, never vectorised); this one
    # is conditional expressions (LLVM selects, blends once vectorised) and two
    # divisions, ~2.6 ns, within 0.66 ulp of the exact value (glibc's 0.79), a
    # degree-10 polynomial rather than libm's tables. Signed zeros as libm's:
    # atan2(+-0, -0) = +-pi, atan2(-0, x > 0) = -0; NaN in, NaN out. Finite
    # inputs only (an infinity gives NaN): kernels get validated, finite data.
    # The error-free steps below need IEEE order of operations: no fastmath.
    ax = abs(x)
    ay = abs(y)
    mx = ax if ax >= ay else ay
    mn = ay if ax >= ay else ax
    # The angle of (mx, mn), in [0, pi/4], is k pi/4 + atan(t) with |t| <=
    # tan(pi/8): t = mn/mx (k = 0) or (mn - mx)/(mn + mx) (k = 1), so that the
    # polynomial below needs only s = t^2 <= tan^2(pi/8).
    big = mn > 0.41421356237309503 * mx
    # Exact power-of-two scaling: above 1e289 by 2^-60, so that mn + mx and the
    # splits by 2^27 + 1 below cannot overflow; below 1e-241 by 2^200, so that the
    # products of the residual stay normal (a subnormal mx has few digits).
    sc = (
        8.673617379884035e-19
        if mx > 1e289
        else (1.6069380442589903e60 if mx < 1e-241 else 1.0)
    )
    mn2 = mn * sc
    mx2 = mx * sc
    num = mn2 - mx2 if big else mn2
    den = mn2 + mx2 if big else mx2
    # Their rounding errors (Fast2Sum, |mx2| >= |mn2|); none when k = 0.
    num_err = mn2 - (num + mx2) if big else 0.0
    den_err = mn2 - (den - mx2) if big else 0.0
    # mx == 0 (both zeros): t = 0/1 = 0, and the angle comes from the signs.
    den = den if mx != 0.0 else 1.0
    t = num / den
    # t_lo = (num + num_err)/(den + den_err) - t to first order: the rounding of
    # t, num and den, which would cost up to 1.5 ulp (t is as large as the result).
    # q + q_err = t den exactly (Dekker's product, Veltkamp splits by 2^27 + 1).
    c = 134217729.0 * t
    t_hi = c - (c - t)
    t_lo = t - t_hi
    c = 134217729.0 * den
    d_hi = c - (c - den)
    d_lo = den - d_hi
    q = t * den
    q_err = ((t_hi * d_hi - q) + t_hi * d_lo + t_lo * d_hi) + t_lo * d_lo
    res = ((num - q) - q_err) + (num_err - t * den_err)
    # Below 1e-290 (then t < 1e-49, and t alone is atan(t) correctly rounded) the
    # residual would be subnormal, too coarse to divide by den.
    t_lo = res / den if mn2 > 1e-290 else 0.0
    s = t * t
    # atan(t) = t + t^3 g(s), g(s) = (atan(sqrt s) - sqrt s) / (s sqrt s): degree
    # 10 in s, interpolating g at the 11 Chebyshev nodes of [0, tan^2(pi/8)]
    # (mpmath, 40 digits; relative error of p vs g 1.4e-16, g's term <= 6% of atan).
    p = -0.01917688711906226
    p = p * s + 0.03923165829558719
    p = p * s + -0.0508544973794026
    p = p * s + 0.0585814891280221
    p = p * s + -0.06664511447381948
    p = p * s + 0.07692183190826087
    p = p * s + -0.09090904578123903
    p = p * s + 0.11111111015256361
    p = p * s + -0.14285714284666542
    p = p * s + 0.1999999999999552
    p = p * s + -0.3333333333333333
    # Unfold: the angle of (|x|, |y|) is k pi/4 + sg atan(t) (|y| > |x|: pi/2 minus
    # it; x < 0, also x = -0.0: pi minus that), then y's sign.
    k = 1.0 if big else 0.0
    sg = 1.0
    k = 2.0 - k if ay > ax else k
    sg = -sg if ay > ax else sg
    neg = copysign(1.0, x) < 0.0
    k = 4.0 - k if neg else k
    sg = -sg if neg else sg
    # k pi/4 as hi + lo (to 4e-33; for k = 1, 2, 4 the rounded k pi/4 is exactly k
    # times the rounded pi/4, 3 pi/4 is its own pair). hi + st is split exactly
    # (Fast2Sum: hi = 0 or hi >= pi/4 > |st|), so the result is rounded once, and
    # at pi it is exactly math.pi, never above (the lo, 1.2e-16, is under half an
    # ulp). atan(t + t_lo) = atan(t) + t_lo / (1 + s), here t_lo (1 - s).
    hi = 2.356194490192345 if k == 3.0 else k * 0.7853981633974483
    lo = 9.184850993605148e-17 if k == 3.0 else k * 3.061616997868383e-17
    st = sg * t
    head = hi + st
    tail = (hi - head) + st
    tail = tail + (st * (s * p) + (lo + sg * t_lo * (1.0 - s)))
    return copysign(head + tail, y)
"""

#: Branch-free ``sin`` and ``cos`` for the batch loops of kernels declared with
#: ``vector_math=True`` (to follow :data:`FAST_ATAN2`): with them and the fast
#: ``atan2`` such a loop calls no libm function, so LLVM vectorises all of it. slerp:
#: 42 -> 17 ns an element at N = 1000, 95 -> 65 ns at N = 10. Within 0.78 ulp of
#: the exact value (glibc's: 0.56) for ``|x| <= 2^19``; beyond, NaN, and the loop
#: that got one reports it (:func:`.numba_backend._loop_source`, status 2) so that
#: the call is computed again by NumPy's libm.
FAST_SINCOS = """

@numba.njit(inline="always", error_model="numpy")
def _reduce_half_pi(x):
    # x = q pi/2 + (rh + rl), |rh + rl| <= pi/4, for |x| <= 2^19 (q < 2^19). pi/2 is
    # P1 + P2 + P3, P1 and P2 of 33 significant bits: q P1 and q P2 are exact, and
    # x - q P1 is exact too (Sterbenz: q P1 is within a factor 2 of x). The rest is
    # summed as a double-double (TwoSum, branch-free), so no digit of the remainder
    # is lost however close x comes to a multiple of pi/2 (the error left is q P3's
    # rounding and pi's beyond P3, < 2^19 * 2e-37 absolute).
    q = (x * 0.6366197723675814 + 6755399441055744.0) - 6755399441055744.0
    y = x - q * 1.5707963267341256
    w = q * 6.077100506303966e-11
    a = y - w
    bb = a - y
    e = (y - (a - bb)) - (w + bb)
    e = e - q * 2.0222662487959506e-21
    rh = a + e
    bb = rh - a
    rl = (a - (rh - bb)) + (e - bb)
    return q, rh, rl


@numba.njit(inline="always", error_model="numpy")
def _sin_pi4(rh, rl, s):
    # sin(r) = r + r^3 g(s), s = r^2, |r| <= pi/4; g of degree 5, interpolated at
    # the 6 Chebyshev nodes of [0, (pi/4)^2] (mpmath, 50 digits; relative error
    # 1.3e-16 of a term <= 8% of the result). The tail rl adds rl cos(r).
    p = 1.5918129294866608e-10
    p = p * s + -2.5051131845003624e-08
    p = p * s + 2.755731610255244e-06
    p = p * s + -0.00019841269836758574
    p = p * s + 0.008333333333330948
    p = p * s + -0.16666666666666666
    return rh + (rh * s * p + rl * (1.0 - 0.5 * s))


@numba.njit(inline="always", error_model="numpy")
def _cos_pi4(rh, rl, s):
    # cos(r) = 1 - s/2 + s^2 h(s), h of degree 5 (as g above; relative error 3e-17
    # of a term <= 1.6%). 1 - s/2 is summed with its own rounding error carried.
    p = -1.1382632425521717e-11
    p = p * s + 2.08761462684032e-09
    p = p * s + -2.7557317271729793e-07
    p = p * s + 2.480158729876569e-05
    p = p * s + -0.0013888888888887398
    p = p * s + 0.041666666666666664
    hz = 0.5 * s
    w = 1.0 - hz
    return w + (((1.0 - w) - hz) + (s * s * p - rh * rl))


@numba.njit(inline="always", error_model="numpy")
def sin(x):
    q, rh, rl = _reduce_half_pi(x)
    s = rh * rh
    m = q - 4.0 * math.floor(q * 0.25)  # the quadrant, 0 ... 3
    odd = m == 1.0 or m == 3.0
    v = _cos_pi4(rh, rl, s) if odd else _sin_pi4(rh, rl, s)
    v = -v if m >= 2.0 else v
    v = x if x == 0.0 else v  # sin(-0.0) = -0.0, as libm's (the sums above give +0)
    return v if abs(x) <= 524288.0 else math.nan


@numba.njit(inline="always", error_model="numpy")
def cos(x):
    q, rh, rl = _reduce_half_pi(x)
    s = rh * rh
    m = q - 4.0 * math.floor(q * 0.25)
    odd = m == 1.0 or m == 3.0
    v = _sin_pi4(rh, rl, s) if odd else _cos_pi4(rh, rl, s)
    v = -v if (m == 1.0 or m == 2.0) else v
    return v if abs(x) <= 524288.0 else math.nan
"""

#: ``math`` functions that numba calls in libm: a loop calling one is not vectorised.
LIBM_CALLS = frozenset({"sin", "cos", "tan", "asin", "acos", "atan", "exp", "log"})

#: The libm functions :data:`FAST_SINCOS` replaces.
VECTOR_MATH = frozenset({"sin", "cos"})


def _global_names(code) -> set:
    names = set(code.co_names)
    for c in code.co_consts:
        if hasattr(c, "co_code"):
            names |= _global_names(c)
    return names


def numba_prelude(functions, batch=True, vector_math=False) -> str:
    """The prelude of a generated module holding the Python ``functions``.

    :data:`NUMBA_PRELUDE`, plus :data:`FAST_ATAN2` if they call ``atan2`` and no
    other libm function (:data:`LIBM_CALLS`), in a batch loop (``batch``): only
    then can the loop be vectorised, where the fast ``atan2`` is 8x libm's; in a
    scalar loop, and in the one-element loop, libm's is faster. Names are read
    from the bytecode (no docstring or comment can match). Modules that do not
    call ``atan2`` keep the plain prelude (and their numba disk cache).

    ``vector_math`` (a kernel declared so): the batch loop also gets
    :data:`FAST_SINCOS`, and may call no other libm function.
    """
    names = set()
    for fn in functions:
        names |= _global_names(fn.__code__)
    libm = names & LIBM_CALLS
    if batch and vector_math:
        if libm - VECTOR_MATH:
            raise ValueError(
                f"vector_math kernels call only sin and cos of libm, not {sorted(libm)}"
            )
        return NUMBA_PRELUDE + FAST_ATAN2 + FAST_SINCOS
    if batch and "atan2" in names and not libm:
        return NUMBA_PRELUDE + FAST_ATAN2
    return NUMBA_PRELUDE


def xp_bindings(xp, dtype, device) -> dict:
    """Primitives element-wise over arrays of namespace ``xp``.

    Python scalars met by a primitive are lifted to ``dtype`` on ``device`` so that
    every primitive also accepts literals (``where(small, 1.0, x)``).
    """

    def lift(v):
        if isinstance(v, (int, float, bool)):
            return xp.asarray(v, dtype=dtype, device=device)
        return v

    def unary(f):
        return lambda x: f(lift(x))

    def binary(f):
        return lambda a, b: f(lift(a), lift(b))

    def where(cond, a, b):
        if isinstance(cond, bool):
            return a if cond else b
        a, b = lift(a), lift(b)
        try:
            return xp.where(cond, a, b)
        except TypeError:
            # A strict namespace (array-api-strict) refuses to promote a bool
            # operand with a float one. Kernels use a comparison that is always
            # False (``w < w``) as a zero of the inputs' own dtype: a literal 0.0
            # would make numba compute a float32 loop in float64.
            if a.dtype == xp.bool:
                a = xp.astype(a, b.dtype)
            if b.dtype == xp.bool:
                b = xp.astype(b, a.dtype)
            return xp.where(cond, a, b)

    return {
        "sqrt": unary(xp.sqrt),
        "sin": unary(xp.sin),
        "cos": unary(xp.cos),
        "tan": unary(xp.tan),
        "asin": unary(xp.asin),
        "acos": unary(xp.acos),
        "atan": unary(xp.atan),
        "atan2": binary(xp.atan2),
        "exp": unary(xp.exp),
        "log": unary(xp.log),
        "abs": unary(xp.abs),
        "where": where,
        "maximum": binary(xp.maximum),
        "minimum": binary(xp.minimum),
        "copysign": binary(xp.copysign),
        "pi": math.pi,
    }


def sympy_bindings() -> dict:
    """Primitives over SymPy expressions (``where`` becomes ``Piecewise``)."""
    import sympy as sp

    def as_number(v):
        # A comparison used as a typed zero or one (``w < w``, see xp_bindings).
        if v is True or v is sp.true:
            return sp.Integer(1)
        if v is False or v is sp.false:
            return sp.Integer(0)
        return v

    def where(cond, a, b):
        a, b = as_number(a), as_number(b)
        if cond is True or cond is sp.true:
            return a
        if cond is False or cond is sp.false:
            return b
        return sp.Piecewise((a, cond), (b, True))

    def copysign(a, b):
        return sp.Abs(a) * sp.Piecewise((-1, b < 0), (1, True))

    def atan2(y, x):
        # math.atan2 and NumPy give 0 at the origin; SymPy gives nan. Kernels rely on
        # the former in branches that where() later discards.
        if (
            y == 0
            and x == 0
            and getattr(x, "is_number", True)
            and getattr(y, "is_number", True)
        ):
            return sp.Integer(0)
        return sp.atan2(y, x)

    return {
        "sqrt": sp.sqrt,
        "sin": sp.sin,
        "cos": sp.cos,
        "tan": sp.tan,
        "asin": sp.asin,
        "acos": sp.acos,
        "atan": sp.atan,
        "atan2": atan2,
        "exp": sp.exp,
        "log": sp.log,
        "abs": sp.Abs,
        "where": where,
        "maximum": sp.Max,
        "minimum": sp.Min,
        "copysign": copysign,
        "pi": sp.pi,
    }
