"""Kernels between Euler angles (all 24 sequences) and unit quaternions.

One kernel each way serves every sequence: the sequence enters as static integer
parameters, so one numba compile (per dtype) covers all 24.

Parameters of both kernels, in matrix-product order ``R = R_e1(t1) R_e2(t2) R_e3(t3)``:

``e1, e2``
    Axis indices (0 = x, 1 = y, 2 = z) of the first two factors. ``m = 3 - e1 - e2``
    is the remaining axis.
``parity``
    Levi-Civita symbol of ``(e1, e2, m)``: +1 for a cyclic order (xyz), -1 otherwise.
``proper``
    1 for proper Euler sequences (``e3 = e1``, like ZXZ), 0 for Tait-Bryan ones
    (``e3 = m``, like ZYX).
``reverse``
    1 when the angles are given in the reverse of product order. An intrinsic
    sequence ``"IJK"`` with angles ``(a, b, c)`` is ``R_I(a) R_J(b) R_K(c)``
    (reverse = 0); an extrinsic ``"ijk"`` is ``R_k(c) R_j(b) R_i(a)`` (reverse = 1).
``scale``
    Radians per input unit (``from_euler``) or output units per radian
    (``euler_from_quat``): 1, or the degree factor.

The permuted quaternion ``p = (w, q[e1], q[e2], parity * q[m])`` reduces every
sequence to the cyclic one: for proper sequences the parity sign is absorbed by
``p`` alone, for Tait-Bryan ones also by the sign of ``t3``.
"""

from .._engine import kernel
from .so2 import angle_of  # noqa: F401  (bound by name)


@kernel(
    inputs=[(3,)],
    outputs=[(4,)],
    params=("e1", "e2", "parity", "proper", "reverse", "scale"),
)
def quat_from_euler(e1, e2, parity, proper, reverse, scale, a0, a1, a2):
    """Unit quaternion ``q_e1(t1) q_e2(t2) q_e3(t3)``, the product of axis quaternions.

    With ``c_n = cos(t_n / 2)``, ``s_n = sin(t_n / 2)`` the product in closed form
    is (Hamilton, cyclic axes; an odd order flips ``s3`` for Tait-Bryan):

    * Tait-Bryan: ``p = (c1c2c3 - s1s2s3, s1c2c3 + c1s2s3, c1s2c3 - s1c2s3,
      c1c2s3 + s1s2c3)``;
    * proper: ``p = (c2 cos S, c2 sin S, s2 cos D, s2 sin D)`` with ``S = (t1 + t3)/2``,
      ``D = (t1 - t3)/2``, whose cosines and sines are formed from the half-angle
      ones (no extra trigonometry).

    No matrix is formed; each component is a few roundings from exact.
    """
    rev = reverse == 1
    h = scale / 2  # exact; and a SymPy Integer scale keeps SymPy expressions exact
    t1 = where(rev, a2, a0) * h
    t2 = a1 * h
    t3 = where(rev, a0, a2) * h
    c1 = cos(t1)
    s1 = sin(t1)
    c2 = cos(t2)
    s2 = sin(t2)
    c3 = cos(t3)
    s3 = sin(t3)
    # Tait-Bryan in the cyclic frame, with t3 -> parity * t3.
    s3p = parity * s3
    cc = c1 * c2
    ss = s1 * s2
    cs = c1 * s2
    sc = s1 * c2
    tb0 = cc * c3 - ss * s3p
    tb1 = sc * c3 + cs * s3p
    tb2 = cs * c3 - sc * s3p
    tb3 = cc * s3p + ss * c3
    # Proper: cos/sin of the half-sum S and half-difference D.
    cos_s = c1 * c3 - s1 * s3
    sin_s = s1 * c3 + c1 * s3
    cos_d = c1 * c3 + s1 * s3
    sin_d = s1 * c3 - c1 * s3
    is_proper = proper == 1
    p0 = where(is_proper, c2 * cos_s, tb0)
    p1 = where(is_proper, c2 * sin_s, tb1)
    p2 = where(is_proper, s2 * cos_d, tb2)
    p3 = parity * where(is_proper, s2 * sin_d, tb3)
    # Scatter (p1, p2, p3) onto the axes (e1, e2, m).
    return (
        p0,
        where(e1 == 0, p1, where(e2 == 0, p2, p3)),
        where(e1 == 1, p1, where(e2 == 1, p2, p3)),
        where(e1 == 2, p1, where(e2 == 2, p2, p3)),
    )


@kernel(
    inputs=[(4,)],
    outputs=[(3,)],
    params=("e1", "e2", "parity", "proper", "reverse", "scale"),
)
def euler_from_quat(e1, e2, parity, proper, reverse, scale, w, x, y, z):
    """Euler angles of a quaternion, accurate everywhere, gimbal lock included.

    After Bernardes & Viollet (2022), "Quaternion to Euler angles conversion: A
    direct, general and computationally efficient method", PLoS ONE 17(11). With
    ``v = (q[e1], q[e2], parity * q[m])`` the rotation is split into two complex
    numbers ``z1 = |z1| e^{iS}``, ``z2 = |z2| e^{iD}``:

    * proper: ``z1 = w + i v1``, ``z2 = v2 + i v3``; ``t2 = 2 atan2(|z2|, |z1|)``,
      ``t1 = S + D = arg(z1 z2)``, ``t3 = S - D = arg(z1 conj(z2))``;
    * Tait-Bryan: ``q q_e2(pi/2)`` is the proper sequence ``e1 e2 e1`` with angles
      ``(t1, t2 + pi/2, -t3)``, whose ``z1 = (w - v2) + i (v1 - v3)`` and
      ``z2 = (w + v2) + i (v1 + v3)`` (up to a common factor); then
      ``t2 = atan2(2 (w v2 + v1 v3), |z1| |z2|)`` (the sine without cancellation,
      so small ``t2`` keep their relative accuracy), ``t1 = arg(z1 z2)`` and
      ``t3 = parity * arg(z2 conj(z1))``.

    Every angle is an ``atan2`` (no ``acos``/``asin`` of a matrix entry) of
    quantities computed to a few ulp *relative*: the components of ``z1`` and
    ``z2`` are single components of ``q`` or, for Tait-Bryan, sums and differences
    that are exact (Sterbenz) exactly where they are small, i.e. near the lock.
    So all three angles are accurate to a few ulp for the quaternion given, at
    any distance from the lock. Near the lock the first and third angle are
    ill-conditioned with respect to the rotation (``arg`` of the tiny ``z1`` or
    ``z2`` enters them with opposite signs), but the rebuilt rotation is exact.
    At exact lock (``z1`` or ``z2`` zero) the split is undetermined: we then put
    the whole rotation into the angle written first and make the one written
    third 0 (``t3`` for intrinsic, ``t1`` for extrinsic sequences). There is no
    other threshold. First and third angles are in (-pi, pi];
    the middle in [0, pi] (proper) or [-pi/2, pi/2] (Tait-Bryan).

    The formulas are homogeneous of degree 0 in ``q``: ``q`` need not be unit (but
    should be of moderate scale, since it is squared).
    """
    m = 3 - e1 - e2
    # Gather by static axis index (a tuple index: numba, NumPy, torch, SymPy alike).
    v1 = (x, y, z)[e1]
    v2 = (x, y, z)[e2]
    v3 = parity * (x, y, z)[m]
    is_proper = proper == 1
    a = where(is_proper, w, w - v2)
    b = where(is_proper, v1, v1 - v3)
    c = where(is_proper, v2, w + v2)
    d = where(is_proper, v3, v1 + v3)
    # Scale z1 and z2 by their largest component: the products below then keep
    # their relative accuracy (and t1, t3 their shared error) however small a number
    # is, subnormal included, and |z| = m |z / m| cannot underflow.
    m1 = maximum(abs(a), abs(b))
    m2 = maximum(abs(c), abs(d))
    z1_zero = m1 <= 0.0
    z2_zero = m2 <= 0.0
    s1 = where(z1_zero, 1.0, m1)
    s2 = where(z2_zero, 1.0, m2)
    a = a / s1
    b = b / s1
    c = c / s2
    d = d / s2
    n1 = m1 * sqrt(a * a + b * b)
    n2 = m2 * sqrt(c * c + d * d)
    # Middle angle: proper 2 atan2(|z2|, |z1|); Tait-Bryan atan2(sin, cos). One atan2
    # call with selected arguments (a numba loop evaluates both sides of a where).
    mid = where(is_proper, 2.0, 1.0) * atan2(
        where(is_proper, n2, 2.0 * (w * v2 + v1 * v3)),
        where(is_proper, n1, n1 * n2),
    )
    # Exact lock: one number is zero, its argument undetermined. Replacing it by the
    # other number gives t3 = 0 (product order), by the other's conjugate t1 = 0;
    # either way the angle written third is 0.
    flip = where(reverse == 1, -1.0, 1.0)
    a1 = where(z1_zero, c, a)
    b1 = where(z1_zero, flip * d, b)
    c1 = where(z2_zero, a, c)
    d1 = where(z2_zero, flip * b, d)
    first = angle_of(a1 * c1 - b1 * d1, a1 * d1 + b1 * c1)
    # arg(z1 conj(z2)) for proper; parity * arg(z2 conj(z1)) for Tait-Bryan.
    sign3 = where(is_proper, 1, -parity)
    third = angle_of(a1 * c1 + b1 * d1, sign3 * (b1 * c1 - a1 * d1))
    rev = reverse == 1
    return (
        where(rev, third, first) * scale,
        mid * scale,
        where(rev, first, third) * scale,
    )
