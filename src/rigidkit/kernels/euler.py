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
``tol`` (``euler_from_quat`` only)
    Radians: at gimbal lock, how far the rotation may move to return the lock
    convention (angle written third 0) instead of the exact split of a rounding
    residue. 2 eps of the input dtype (see :func:`rigidkit.euler.euler_from_quat`).

The permuted quaternion ``p = (w, q[e1], q[e2], parity * q[m])`` reduces every
sequence to the cyclic one: for proper sequences the parity sign is absorbed by
``p`` alone, for Tait-Bryan ones also by the sign of ``t3``.
"""

from .._engine import kernel
from .so2 import angle_of


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
    params=("e1", "e2", "parity", "proper", "reverse", "scale", "tol"),
)
def euler_from_quat(e1, e2, parity, proper, reverse, scale, tol, w, x, y, z):
    """Euler angles of a quaternion, accurate everywhere, gimbal lock included.

    After Bernardes & Viollet (2022), "Quaternion to Euler angles conversion: A
    direct, general and computationally efficient method", PLoS ONE 17(11). With
    ``v = (q[e1], q[e2], parity * q[m])`` the rotation is split into two complex
    numbers ``z1 = |z1| e^{iS}``, ``z2 = |z2| e^{iD}``:

    * proper: ``z1 = w + i v1``, ``z2 = v2 + i v3``; ``t2 = 2 arg(|z1| + i |z2|)``,
      ``t1 = S + D = arg(z1 z2)``, ``t3 = S - D = arg(z1 conj(z2))``;
    * Tait-Bryan: ``q q_e2(pi/2)`` is the proper sequence ``e1 e2 e1`` with angles
      ``(t1, t2 + pi/2, -t3)``, whose ``z1 = (w - v2) + i (v1 - v3)`` and
      ``z2 = (w + v2) + i (v1 + v3)`` (up to the common factor ``1/sqrt(2)``);
      then ``t2 = arg(|z1| |z2| + 2 i (w v2 + v1 v3))`` (the sine without
      cancellation, so small ``t2`` keep their relative accuracy),
      ``t1 = arg(z1 z2)`` and ``t3 = parity * arg(z2 conj(z1))``.

    Every angle is an ``atan2`` (no ``acos``/``asin`` of a matrix entry; three
    calls, one per angle, most of the time of a numba loop) of quantities
    computed to a few ulp *relative*: the components
    of ``z1`` and ``z2`` are single components of ``q`` or, for Tait-Bryan, sums
    and differences that are exact (Sterbenz) exactly where they are small, i.e.
    near the lock. So all three angles are accurate to a few ulp for the
    quaternion given, at any distance from the lock.

    Gimbal lock. Near the lock one of ``z1``, ``z2`` (``z_s``, the other ``z_b``)
    is small, and the first and third angle are ill-conditioned with respect to
    the rotation (``arg z_s`` enters them with opposite signs). A float
    quaternion meant to be at the lock (from angles like ``(a, pi/2, b)``) has a
    ``z_s`` of rounding size whose argument is noise, and so would be its first
    and third angle. The lock convention puts the whole rotation into the angle
    written first and makes the one written third 0 (``t3`` for intrinsic, ``t1``
    for extrinsic sequences; then ``z_s`` is a multiple of ``z_b`` or of its
    conjugate). We return it whenever the nearest such decomposition is within
    ``tol`` (radians) of ``q`` and the middle angle is within ``8 tol`` of the lock
    (``|z_s|^2 <= 16 tol^2 (|z1|^2 + |z2|^2)``): a rotation whose third angle is
    merely 0 away from the lock (the identity of a Tait-Bryan sequence) keeps the
    exact split, whose derivatives are right, and rounding residues (a few eps)
    still take the lock convention. That nearest one replaces ``z_s`` by its
    projection on the ray it must lie on, which makes the angle ``t0`` between
    them (``t0`` = the angle written third). With ``W = X + iY`` the product whose
    argument is ``t0`` (``|W| = |z1| |z2|``) the projection is ``|z_s| cos t0 =
    X / |z_b|`` (0 if ``X < 0``), the distance ``|z_s| |sin t0| = |Y| / |z_b|``
    (``|z_s|`` if ``X < 0``), and the rotation moves by ``2 asin(distance /
    |q|)``, ``|q|^2 = (|z1|^2 + |z2|^2) / (2 if Tait-Bryan else 1)`` (the common
    factor cancels). So, squared and multiplied out (no division, and no
    underflow for a tiny ``z_s``, which always passes):
    ``Y^2 + min(X, 0)^2 <= (tol^2 / 4) (|z1|^2 + |z2|^2) |z_b|^2``. Then the
    angle written first is ``+-arg(z_b^2)`` and the middle angle is that of the
    projection. This covers the exact lock (``z_s = 0``) and a zero ``q`` (zero
    angles). The caller's ``tol`` is 2 eps of the input dtype (see
    :func:`rigidkit.euler.lock_tolerance`): a middle angle ``d`` from the lock has
    ``|z_s| / |q| = sin(d / 2)`` (Tait-Bryan: in the proper form), so the rotation
    moves by ``d |sin t0|`` or less; at ``d = 1e-12`` (beyond ``8 tol = 3.6e-15``)
    the exact split is kept.

    First and third angles are in (-pi, pi]; the middle in [0, pi] (proper) or
    [-pi/2, pi/2] (Tait-Bryan). The formulas are homogeneous of degree 0 in
    ``q``: ``q`` need not be unit, but should be of moderate scale (1e-70 to
    1e70), since the lock test multiplies four squares.
    """
    m = 3 - e1 - e2
    # Gather by static axis index. Selects, not a tuple index: numba cannot
    # vectorise a loop that indexes a tuple by a run-time int (72 -> 10.5 ns per
    # element with the vectorised atan2); on the other bindings the conditions are
    # Python bools, decided at once.
    v1 = where(e1 == 0, x, where(e1 == 1, y, z))
    v2 = where(e2 == 0, x, where(e2 == 1, y, z))
    v3 = parity * where(m == 0, x, where(m == 1, y, z))
    is_proper = proper == 1
    rev = reverse == 1
    a = where(is_proper, w, w - v2)
    b = where(is_proper, v1, v1 - v3)
    c = where(is_proper, v2, w + v2)
    d = where(is_proper, v3, v1 + v3)
    aa = a * a
    bb = b * b
    cc = c * c
    dd = d * d
    n1sq = aa + bb
    n2sq = cc + dd
    # z1 z2 (argument t1) and z1 conj(z2) with its sign made that of t3: proper
    # arg(z1 conj(z2)), Tait-Bryan parity * arg(z2 conj(z1)).
    ac = a * c
    bd = b * d
    ad = a * d
    bc = b * c
    sign3 = where(is_proper, 1, -parity)
    p_x = ac - bd
    p_y = ad + bc
    m_x = ac + bd
    m_y = sign3 * (bc - ad)
    # The products whose arguments are the angles written first (F) and third (T).
    f_x = where(rev, m_x, p_x)
    f_y = where(rev, m_y, p_y)
    t_x = where(rev, p_x, m_x)
    t_y = where(rev, p_y, m_y)
    # Lock test (docstring): the middle angle d is within 8 tol of the lock
    # (sin(d/2)^2 = |z_s|^2 / (|z1|^2 + |z2|^2) <= 16 tol^2), and the rotation
    # moves by at most tol when the angle written third is set to 0 and z_s
    # projected. Without the first test a third angle merely 0 would take the lock
    # branch, exact in value but with the lock's derivatives (third angle constant).
    small1 = n1sq < n2sq
    n_small = where(small1, n1sq, n2sq)
    n_big = where(small1, n2sq, n1sq)
    outside = minimum(t_x, 0.0)
    lock = (n_small <= (16.0 * tol * tol) * (n1sq + n2sq)) & (
        t_y * t_y + outside * outside <= (0.25 * tol * tol) * (n1sq + n2sq) * n_big
    )
    # At lock the angle written first is arg(z_b^2) (intrinsic), or for extrinsic
    # sequences arg(z1^2) (z2 small) or arg(conj(z2)^2) (z1 small), times sign3.
    g = where(rev, where(small1, -sign3, sign3), 1)
    sq_x = where(small1, cc - dd, aa - bb)
    sq_y = g * 2.0 * where(small1, c * d, a * b)
    first = angle_of(where(lock, sq_x, f_x), where(lock, sq_y, f_y))
    # The branch not taken is evaluated at a safe argument: at lock t = 0 (z_s = 0),
    # where atan2's derivative is 0/0, NaN in every gradient even through where().
    third = where(lock, 0.0, angle_of(where(lock, 1.0, t_x), where(lock, 0.0, t_y)))
    # Middle angle: the argument of a vector parallel to (|z1|, |z2|) (proper,
    # doubled), here times |z1|, or of (|z1| |z2|, 2 (w v2 + v1 v3)) (Tait-Bryan).
    # At lock |z_s| is replaced by the projection X / |z_b|: (|z1|, |z2|) |z_b|
    # becomes (|z1|^2, X) or (X, |z2|^2), and |z1| |z2| becomes X. One sqrt.
    proj = where(t_x > 0.0, t_x, 0.0)  # +0.0 also for t_x = -0.0
    n12 = sqrt(where(lock, 1.0, n1sq * n2sq))  # (not used at lock, where it can be 0)
    mid_c = where(is_proper, where(lock & small1, proj, n1sq), where(lock, proj, n12))
    mid_s = where(
        is_proper,
        where(lock, where(small1, n2sq, proj), n12),
        2.0 * (w * v2 + v1 * v3),
    )
    # mid_c >= +0: atan2 in [-pi/2, pi/2], no fold needed.
    mid = where(is_proper, 2.0, 1.0) * atan2(mid_s, mid_c)
    return (first * scale, mid * scale, third * scale)


@kernel(
    inputs=[(4,)],
    outputs=[(3,)],
    params=("e1", "e2", "parity", "proper", "reverse", "scale", "tol", "qmax"),
)
def euler_from_quat_checked(e1, e2, parity, proper, reverse, scale, tol, qmax, w, x, y, z):
    """:func:`euler_from_quat` with its input checked in the same pass.

    A row of moderate scale, ``|q|`` in ``[1 / qmax, qmax]`` (``qmax`` 1e70 for
    float64, 1e8 for float32: the lock test's fourth powers stay in range), gets
    the angles of :func:`euler_from_quat`, to the bit. Any other row (NaN, inf,
    zero, an extreme scale) gets a middle angle of ``8 scale``, outside every valid
    range (``[0, pi]``, ``[-pi/2, pi/2]``), and is computed as the zero quaternion,
    so that no operation meets an inf or a NaN (no floating-point warnings on any
    binding). The caller's scan of the middle angles for gimbal lock, which every
    call makes, then finds such rows too: validating costs no extra pass and no
    NumPy call on the common path.

    The scale is measured by ``m = (|w| + |x| + |y| + |z|) / 4``, which cannot
    overflow and propagates NaN (a maximum would drop it in Python's ``max``);
    ``|q| / 4 <= m <= |q| / 2``, so the rows passed are well inside the range and
    those within a factor 4 of its ends are flagged too (the caller's full check
    then takes them as they are).
    """
    m = 0.25 * (abs(w) + abs(x) + abs(y) + abs(z))
    ok = (m <= 0.25 * qmax) & (m >= 0.5 / qmax)  # False for NaN
    # A bad row is computed as the zero quaternion (zero angles, no inf or NaN met).
    # Its zero is ``w < w``, False: a zero of the inputs' own type, where a literal
    # 0.0 would make numba compute every float32 row in float64, no longer the bits
    # of euler_from_quat.
    zero = w < w
    first, mid, third = euler_from_quat(
        e1,
        e2,
        parity,
        proper,
        reverse,
        scale,
        tol,
        where(ok, w, zero),
        where(ok, x, zero),
        where(ok, y, zero),
        where(ok, z, zero),
    )
    return (first, where(ok, mid, 8.0 * scale), third)
