"""Linear-algebra helpers shared by the kernels: scaled norms, cross products, 3x3 products.

Each formula here is written once and called by the kernels of every group
(:mod:`.quaternion`, :mod:`.axis_angle`, :mod:`.so2`, :mod:`.homogeneous`, the
SO(3), SE(3) and Sim(3) kernels); the engine inlines it into each, so sharing
costs nothing at run time. Matrices are row-major tuples of entries.
"""

from .._engine import helper


@helper
def scaled4(a, b, c, d):
    """``(as, bs, cs, ds, m, r)``: the vector is ``m (as, bs, cs, ds)``, of norm ``m r``.

    ``m`` is the largest ``|component|``, so the scaled components are in
    [-1, 1] and ``r = |(as, bs, cs, ds)|`` in [1, 2]: no square under- or
    overflows for any finite input, from 1e-308 to 1e308 (the plain sum of
    squares overflows above 1e154 and underflows below 1e-154). The zero vector
    gives six zeros. Shorter vectors pass zeros for the missing components
    (``scaled4(x, y, z, 0.0)``: exact, the zeros add nothing).

    The root is taken at a safe argument, so autodiff gets a finite (zero)
    gradient at the zero vector instead of NaN.
    """
    m = maximum(maximum(abs(a), abs(b)), maximum(abs(c), abs(d)))
    pos = m > 0.0
    safe = where(pos, m, 1.0)
    a = a / safe
    b = b / safe
    c = c / safe
    d = d / safe
    r = where(pos, sqrt(where(pos, a * a + b * b + c * c + d * d, 1.0)), 0.0)
    return (a, b, c, d, m, r)


@helper
def normalize4(a, b, c, d):
    """Unit vector and norm ``(a, b, c, d) / n, n`` (see :func:`scaled4`); zero stays zero.

    The division is by ``m`` and then ``r`` (never by the product ``m r``, which
    loses bits when ``m`` is subnormal), so each component is within an ulp or
    two of the exact unit vector. The zero vector gives zeros and ``n = 0``,
    which callers reject (or map to their convention).
    """
    a, b, c, d, m, r = scaled4(a, b, c, d)
    safe = where(m > 0.0, r, 1.0)
    return (a / safe, b / safe, c / safe, d / safe, m * r)


@helper
def renormalize4(a, b, c, d):
    """``(a, b, c, d) (3 - n^2) / 2``, ``n^2 = a^2 + b^2 + c^2 + d^2``: unit again.

    One Newton step of ``1 / sqrt(n^2)`` from 1, for a vector that is unit up to
    rounding (a product of unit quaternions or complex numbers): with ``n^2 = 1 +
    d`` the result has ``n^2 = 1 - 3 d^2 / 4 + d^3 / 4``, so a deviation of a few
    ulp leaves one of rounding size and does not grow along a chain of products
    (unrenormalised, ``q = q q`` doubles it at every step: 1e-4 after 40). Costs
    8 multiplications and 4 additions, no division or root; inlined in the numba
    loop the compose kernels stay memory bound. Shorter vectors pass zeros.
    """
    k = 1.5 - 0.5 * (a * a + b * b + c * c + d * d)
    return (a * k, b * k, c * k, d * k)


@helper
def cross3(ax, ay, az, bx, by, bz):
    """Cross product ``a x b`` (= ``hat(a) @ b``)."""
    return (ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx)


@helper
def hat_poly_apply(wx, wy, wz, a, b, c, vx, vy, vz):
    """``(a I + b hat(w) + c hat(w)^2) v = a v + b w x v + c w x (w x v)``.

    Every series in ``w`` that rotation formulas need (``R``, ``J_l``, ``J_l^-1``,
    the ``V`` of Sim(3)) is of this form; no matrix is formed. A coefficient
    ``a = 1.0`` costs nothing in the numba loop (``1.0 * v`` folds to ``v``).
    """
    cx, cy, cz = cross3(wx, wy, wz, vx, vy, vz)
    dx, dy, dz = cross3(wx, wy, wz, cx, cy, cz)
    return (a * vx + b * cx + c * dx, a * vy + b * cy + c * dy, a * vz + b * cz + c * dz)


@helper
def hat_matmul(tx, ty, tz, m00, m01, m02, m10, m11, m12, m20, m21, m22):
    """Entries of ``hat(t) M``: column ``j`` is ``t x`` (column ``j`` of ``M``)."""
    c00, c10, c20 = cross3(tx, ty, tz, m00, m10, m20)
    c01, c11, c21 = cross3(tx, ty, tz, m01, m11, m21)
    c02, c12, c22 = cross3(tx, ty, tz, m02, m12, m22)
    return (c00, c01, c02, c10, c11, c12, c20, c21, c22)


@helper
def mat33_mul(a0, a1, a2, a3, a4, a5, a6, a7, a8, b0, b1, b2, b3, b4, b5, b6, b7, b8):
    """Entries of the 3x3 product ``A @ B`` (row-major in and out)."""
    return (
        a0 * b0 + a1 * b3 + a2 * b6,
        a0 * b1 + a1 * b4 + a2 * b7,
        a0 * b2 + a1 * b5 + a2 * b8,
        a3 * b0 + a4 * b3 + a5 * b6,
        a3 * b1 + a4 * b4 + a5 * b7,
        a3 * b2 + a4 * b5 + a5 * b8,
        a6 * b0 + a7 * b3 + a8 * b6,
        a6 * b1 + a7 * b4 + a8 * b7,
        a6 * b2 + a7 * b5 + a8 * b8,
    )


@helper
def det3(a00, a01, a02, a10, a11, a12, a20, a21, a22):
    """Determinant of a 3x3 matrix (cofactor expansion along the first row)."""
    return (
        a00 * (a11 * a22 - a12 * a21)
        - a01 * (a10 * a22 - a12 * a20)
        + a02 * (a10 * a21 - a11 * a20)
    )
