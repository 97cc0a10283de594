"""The primitive functions a kernel may call, bound once per backend.

A kernel is a plain Python function over scalar components whose free names are
the primitives listed in :data:`PRIMITIVES`, other helper kernels, and literals.
Each backend evaluates the same function object with its own globals:

* ``math``   : plain Python floats (one element) and, textually, numba loops;
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
    """Primitives over Python floats (also the text used inside numba loops)."""
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


#: Source text of the same primitives for a generated numba module.
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
        return xp.where(cond, lift(a), lift(b))

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

    def where(cond, a, b):
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
