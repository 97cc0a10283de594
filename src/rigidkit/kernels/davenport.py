"""Kernels between Davenport angles (three turns about given axes) and quaternions.

Davenport angles generalise Euler angles to any axes ``n1, n2, n3`` with ``n2``
orthogonal to ``n1`` and to ``n3`` (Shuster & Markley 2003); ``n1`` and ``n3``
may make any angle. Parameters, as for :mod:`.euler`:

``reverse``
    0 for an intrinsic sequence, ``R = R_n1(t1) R_n2(t2) R_n3(t3)`` (each turn
    about the axis moved by the turns before); 1 for an extrinsic one, ``R =
    R_n3(t3) R_n2(t2) R_n1(t1)`` (fixed world axes, ``n1`` first). The axes and
    angles are given in the order they are named, as in scipy.
``scale``
    Radians per input unit (``quat_from_davenport``) or output units per radian.
``tol`` (``davenport_from_quat`` only)
    The lock tolerance of :func:`.euler.euler_from_quat`.

The axes are unit vectors (the functional layer normalises and checks them).
"""

from .._engine import kernel
from .euler import euler_from_quat
from .quaternion import quat_multiply
from .vector import cross3, normalize4


@kernel(inputs=[(3,)], outputs=[(3,), ()])
def unit_axis(x, y, z):
    """Unit vector and norm of an axis, without overflow (zero gives zeros, 0)."""
    ux, uy, uz, _, n = normalize4(x, y, z, 0.0)
    return (ux, uy, uz, n)


@kernel(inputs=[(3,), (3,), (3,), (3,)], outputs=[(4,)], params=("reverse", "scale"))
def quat_from_davenport(reverse, scale, ax, ay, az, bx, by, bz, cx, cy, cz, t1, t2, t3):
    """Product of the three axis quaternions ``(cos(t/2), sin(t/2) n)`` in turn order.

    Intrinsic: ``q_n1(t1) q_n2(t2) q_n3(t3)``; extrinsic: ``q_n3(t3) q_n2(t2)
    q_n1(t1)``. A turn by 0 is the identity exactly, so fewer axes are padded
    with zero angles.
    """
    h = scale / 2
    c1 = cos(t1 * h)
    s1 = sin(t1 * h)
    c2 = cos(t2 * h)
    s2 = sin(t2 * h)
    c3 = cos(t3 * h)
    s3 = sin(t3 * h)
    rev = reverse == 1
    # Matrix-product order: (first factor, last factor).
    fw = where(rev, c3, c1)
    fx = where(rev, s3 * cx, s1 * ax)
    fy = where(rev, s3 * cy, s1 * ay)
    fz = where(rev, s3 * cz, s1 * az)
    lw = where(rev, c1, c3)
    lx = where(rev, s1 * ax, s3 * cx)
    ly = where(rev, s1 * ay, s3 * cy)
    lz = where(rev, s1 * az, s3 * cz)
    w, x, y, z = quat_multiply(fw, fx, fy, fz, c2, s2 * bx, s2 * by, s2 * bz)
    return quat_multiply(w, x, y, z, lw, lx, ly, lz)


@kernel(
    inputs=[(4,), (3,), (3,), (3,)],
    outputs=[(3,), (3,)],
    params=("reverse", "scale", "tol"),
)
def davenport_from_quat(
    reverse, scale, tol, w, x, y, z, ax, ay, az, bx, by, bz, cx, cy, cz
):
    """Davenport angles of a unit quaternion, by reduction to Euler ``XYX``.

    In product order let ``a`` be the first axis (``n1`` intrinsic, ``n3``
    extrinsic), ``p`` the last and ``b = n2``. Put ``c = a x b`` and ``lam =
    atan2(p . c, p . a)``, the angle from ``a`` to ``p`` about ``-b``: ``p =
    R_b(-lam) a``, so ``R_p(u) = R_b(-lam) R_a(u) R_b(lam)`` and

        ``R R_b(-lam) = R_a(u1) R_b(u2 - lam) R_a(u3)``,

    the proper Euler sequence ``a b a``, i.e. ``XYX`` in the frame ``[a, b, c]``.
    Its angles come from the accurate Euler kernel
    (:func:`rigidkit.kernels.euler.euler_from_quat`, lock handling included)
    applied to ``q q_b(-lam)`` with its vector part expressed in that frame. As
    scipy does, ``b`` is replaced by ``-b`` where ``lam > 0`` (then ``c`` and
    ``lam`` change sign, and the middle angle is negated back): the middle angle
    is in ``[lam, lam + pi]`` for ``lam <= 0`` and in ``[lam - pi, lam]`` for
    ``lam > 0``, an interval of length pi from ``lam`` that contains 0 (Euler
    sequences: ``[-pi/2, pi/2]`` Tait-Bryan, ``[0, pi]`` proper).

    Outputs: the angles in the order of the axes (times ``scale``), and the angles
    of the auxiliary ``XYX`` sequence (times ``scale``), whose middle one is the
    distance from the gimbal lock (0 or pi), for the caller's warning.
    """
    rev = reverse == 1
    px = where(rev, ax, cx)
    py = where(rev, ay, cy)
    pz = where(rev, az, cz)
    fx = where(rev, cx, ax)
    fy = where(rev, cy, ay)
    fz = where(rev, cz, az)
    kx, ky, kz = cross3(fx, fy, fz, bx, by, bz)
    # sin(lam) = p . c = (p -+ a) . c (a . c = 0), the sign chosen by cos(lam): then
    # p = a or p = -a exactly (Euler axes) give exactly 0, not a rounding residue of
    # random sign that would pick the middle angle's range at random. The zero is
    # made -0.0 (-((-y) + 0) keeps every other y), so p = -a gives lam = -pi (range
    # [-pi, 0], scipy's for such axes) and p = a gives lam = -0 (range [0, pi]).
    cos_lam = px * fx + py * fy + pz * fz
    sg = where(cos_lam < 0.0, 1.0, -1.0)
    sin_lam = (px + sg * fx) * kx + (py + sg * fy) * ky + (pz + sg * fz) * kz
    lam = atan2(-((-sin_lam) + 0.0), cos_lam)
    s = where(lam > 0.0, -1.0, 1.0)
    bx, by, bz = s * bx, s * by, s * bz
    kx, ky, kz = s * kx, s * ky, s * kz
    lam = s * lam  # <= 0
    h = -0.5 * lam
    sh = sin(h)
    qw, qx, qy, qz = quat_multiply(w, x, y, z, cos(h), sh * bx, sh * by, sh * bz)
    ex = qx * fx + qy * fy + qz * fz
    ey = qx * bx + qy * by + qz * bz
    ez = qx * kx + qy * ky + qz * kz
    e1, e2, e3 = euler_from_quat(0, 1, 1, 1, reverse, 1.0, tol, qw, ex, ey, ez)
    return (
        e1 * scale,
        s * (e2 + lam) * scale,
        e3 * scale,
        e1 * scale,
        e2 * scale,
        e3 * scale,
    )
