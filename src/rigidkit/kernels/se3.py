"""Kernels of SE(3): poses ``(w, x, y, z, tx, ty, tz)``, twists ``(v, w)``, Jacobians.

A pose is a unit quaternion (Hamilton, scalar first) followed by a translation:
the rigid motion ``p -> R p + t``. Here is everything SE(3) has as a group on
poses: compose, inverse, the action on points and its inverse, a distance, exp,
log, hat, vee, the adjoints, the bracket and the Jacobians (other layouts of a
pose are in :mod:`.pose_formats`). Twists are ordered ``(v, w)``, translation
first, as in Murray, Li & Sastry 1994 (Sec. 2.3) and Barfoot 2017 (Sec. 7.1):
``hat(V) = [[hat(w), v], [0, 0]]``, and ``exp(hat(V)) = [[R, J_l(w) v], [0, 1]]``
with ``R = exp(hat(w))`` and ``J_l`` the SO(3) left Jacobian (a pure translation
``v`` when ``w = 0``). Matrices are row-major, acting on column vectors ``[p; 1]``.

Jacobians follow the SO(3) convention (:mod:`.so3`):
``exp(x + d) ~ exp(J_l(x) d) exp(x)`` and ``J_r(x) = J_l(-x)``; the left Jacobian of
SE(3) is ``[[J_l(w), Q(v, w)], [0, J_l(w)]]`` with Barfoot's ``Q`` (Barfoot 2017,
eq. 7.86).
"""

from .._engine import helper, kernel
from .coefficients import (
    atan_ratio,
    cos_defect4,
    cot_defect2,
    norm3,
    sin_cos_defect5,
    sin_defect3,
)
from .matrix import matrix_from_quat
from .quaternion import (
    quat_angle,
    quat_apply,
    quat_compose,
    quat_hemisphere,
    quat_multiply,
)
from .so3 import (
    eye_hat_hat2_apply,
    half_angle_from_rotvec,
    rotvec_entries_from_quat,
    so3_left_jacobian_entries,
    so3_left_jacobian_inverse_entries,
)
from .vector import cross3, hat_matmul, mat33_mul


@helper
def se3_adjoint_entries(r0, r1, r2, r3, r4, r5, r6, r7, r8, tx, ty, tz):
    """Entries of ``Ad = [[R, hat(t) R], [0, R]]`` (6x6, row-major), twists ``(v, w)``."""
    c00, c01, c02, c10, c11, c12, c20, c21, c22 = hat_matmul(
        tx, ty, tz, r0, r1, r2, r3, r4, r5, r6, r7, r8
    )
    return (
        r0, r1, r2, c00, c01, c02,
        r3, r4, r5, c10, c11, c12,
        r6, r7, r8, c20, c21, c22,
        0.0, 0.0, 0.0, r0, r1, r2,
        0.0, 0.0, 0.0, r3, r4, r5,
        0.0, 0.0, 0.0, r6, r7, r8,
    )  # fmt: skip


@helper
def se3_q_entry(p, a, a_t, c, d, d_t, f, f_t, k1, k2, k3):
    """One entry of Barfoot's ``Q`` from the products named in :func:`se3_q_entries`."""
    return 0.5 * p + k1 * (a + a_t + c) + k2 * (d - d_t - 3.0 * c) + k3 * (f + f_t)


@helper
def se3_q_entries(vx, vy, vz, wx, wy, wz):
    """Entries of Barfoot's ``Q(v, w)``, the top-right block of the SE(3) ``J_l``.

    With ``W = hat(w)``, ``P = hat(v)``, ``t = |w|``::

        Q = P/2 + (t - sin t)/t^3 (WP + PW + WPW)
                + (t^2/2 + cos t - 1)/t^4 (WWP + PWW - 3 WPW)
                + (2t - 3 sin t + t cos t)/(2 t^5) (WPWW + WWPW)

    (Barfoot, State Estimation for Robotics, eq. 7.86). Since ``W`` and ``P`` are
    skew, ``PW = (WP)^T``, ``PWW = -(WWP)^T`` and ``WWPW = (WPWW)^T``, so four
    products suffice: ``A = WP``, ``C = AW``, ``D = WA``, ``F = CW``.
    """
    theta = norm3(wx, wy, wz)
    k1 = sin_defect3(theta)
    k2 = cos_defect4(theta)
    k3 = sin_cos_defect5(theta)
    w = (0.0, -wz, wy, wz, 0.0, -wx, -wy, wx, 0.0)
    p = (0.0, -vz, vy, vz, 0.0, -vx, -vy, vx, 0.0)
    a = mat33_mul(*w, *p)
    c = mat33_mul(*a, *w)
    d = mat33_mul(*w, *a)
    f = mat33_mul(*c, *w)
    return (
        se3_q_entry(p[0], a[0], a[0], c[0], d[0], d[0], f[0], f[0], k1, k2, k3),
        se3_q_entry(p[1], a[1], a[3], c[1], d[1], d[3], f[1], f[3], k1, k2, k3),
        se3_q_entry(p[2], a[2], a[6], c[2], d[2], d[6], f[2], f[6], k1, k2, k3),
        se3_q_entry(p[3], a[3], a[1], c[3], d[3], d[1], f[3], f[1], k1, k2, k3),
        se3_q_entry(p[4], a[4], a[4], c[4], d[4], d[4], f[4], f[4], k1, k2, k3),
        se3_q_entry(p[5], a[5], a[7], c[5], d[5], d[7], f[5], f[7], k1, k2, k3),
        se3_q_entry(p[6], a[6], a[2], c[6], d[6], d[2], f[6], f[2], k1, k2, k3),
        se3_q_entry(p[7], a[7], a[5], c[7], d[7], d[5], f[7], f[5], k1, k2, k3),
        se3_q_entry(p[8], a[8], a[8], c[8], d[8], d[8], f[8], f[8], k1, k2, k3),
    )


@helper
def se3_block_upper(j, q):
    """Entries of the 6x6 ``[[J, Q], [0, J]]`` from 9-tuples ``j`` and ``q``."""
    return (
        j[0], j[1], j[2], q[0], q[1], q[2],
        j[3], j[4], j[5], q[3], q[4], q[5],
        j[6], j[7], j[8], q[6], q[7], q[8],
        0.0, 0.0, 0.0, j[0], j[1], j[2],
        0.0, 0.0, 0.0, j[3], j[4], j[5],
        0.0, 0.0, 0.0, j[6], j[7], j[8],
    )  # fmt: skip


# -- poses -----------------------------------------------------------------------------


@helper
def se3_exp_pieces(wx, wy, wz):
    """Quaternion of ``exp(hat(w))`` and the coefficients ``(k1, k2)`` of
    ``J_l(w) = I + k1 hat(w) + k2 hat(w)^2``, as 6 scalars ``(qw, qx, qy, qz, k1, k2)``.

    ``k1 = (1 - cos t)/t^2`` is ``2 s^2`` with ``s = sin(t/2)/t`` already at hand for
    the quaternion (one sine fewer); ``k2 = (t - sin t)/t^3``; ``t = |w|``.
    """
    qw, s, theta = half_angle_from_rotvec(wx, wy, wz)
    return (qw, s * wx, s * wy, s * wz, 2.0 * s * s, sin_defect3(theta))


@helper
def se3_log_pieces(w, x, y, z):
    """Rotation vector ``r`` of ``q`` (``|r|`` in [0, pi]) and the coefficient ``c`` of
    ``J_l(r)^-1 = I - hat(r)/2 + c hat(r)^2``, as 4 scalars ``(rx, ry, rz, c)``.

    ``c = cot_defect2(t)``, ``t = |r|``, is finite up to ``t = pi``.
    """
    rx, ry, rz = rotvec_entries_from_quat(w, x, y, z)
    return (rx, ry, rz, cot_defect2(quat_angle(w, x, y, z)))


@kernel(inputs=[(4,), (3,)], outputs=[(7,)])
def pose_from_quat_translation(w, x, y, z, tx, ty, tz):
    """Pack a unit quaternion and a translation into a pose (broadcasting both)."""
    return (w, x, y, z, tx, ty, tz)


@kernel(inputs=[(7,), (7,)], outputs=[(7,)])
def pose_compose(w1, x1, y1, z1, tx1, ty1, tz1, w2, x2, y2, z2, tx2, ty2, tz2):
    """``T1 @ T2`` (``T2`` first): ``(q1 q2, t1 + R1 t2)``, ``q1 q2`` renormalised."""
    w, x, y, z = quat_compose(w1, x1, y1, z1, w2, x2, y2, z2)
    rx, ry, rz = quat_apply(w1, x1, y1, z1, tx2, ty2, tz2)
    return (w, x, y, z, tx1 + rx, ty1 + ry, tz1 + rz)


@kernel(inputs=[(7,), (3,)], outputs=[(3,)])
def pose_apply(w, x, y, z, tx, ty, tz, px, py, pz):
    """The rigid motion of points: ``R p + t``."""
    rx, ry, rz = quat_apply(w, x, y, z, px, py, pz)
    return (rx + tx, ry + ty, rz + tz)


@kernel(inputs=[(7,), (3,)], outputs=[(3,)])
def pose_apply_inverse(w, x, y, z, tx, ty, tz, px, py, pz):
    """The inverse motion of points, ``R^T (p - t)``, without forming the inverse."""
    return quat_apply(w, -x, -y, -z, px - tx, py - ty, pz - tz)


@kernel(
    inputs=[(7,), (7,)],
    outputs=[()],
    params=("rotation_weight", "translation_weight"),
)
def pose_distance(
    rotation_weight,
    translation_weight,
    w1, x1, y1, z1, tx1, ty1, tz1,
    w2, x2, y2, z2, tx2, ty2, tz2,
):  # fmt: skip
    """``sqrt(a theta^2 + b |t2 - t1|^2)`` of the relative pose ``T1^-1 T2``.

    ``theta`` (radians, [0, pi]) is the angle of ``R1^T R2`` (``atan2``-based, so
    exact near 0 and pi) and ``|t2 - t1|`` is the length of the translation
    ``R1^T (t2 - t1)`` of ``T1^-1 T2`` (a rotation keeps lengths); ``a``, ``b`` the
    (non-negative) weights. ``theta^2`` is taken as ``|2 v atan2(|v|, w) / |v||^2``
    (:func:`atan_ratio`), a smooth function of the quaternion ``(w, v)``: through
    ``theta`` itself autodiff would see ``d theta / dv = 0`` at ``v = 0`` (the norm's
    subgradient) and lose the rotation part of the Hessian where the rotations are
    equal and the translations not. The root is taken at a safe argument, so the
    gradient at ``T1 = T2`` is 0 (a subgradient), not NaN.
    """
    rw, rx, ry, rz = quat_multiply(w1, -x1, -y1, -z1, w2, x2, y2, z2)
    rw, rx, ry, rz = quat_hemisphere(rw, rx, ry, rz)
    k = 2.0 * atan_ratio(norm3(rx, ry, rz), rw)
    theta2 = k * k * (rx * rx + ry * ry + rz * rz)
    dx, dy, dz = tx2 - tx1, ty2 - ty1, tz2 - tz1
    s = rotation_weight * theta2 + translation_weight * (dx * dx + dy * dy + dz * dz)
    pos = s > 0.0
    return (where(pos, sqrt(where(pos, s, 1.0)), 0.0),)


@kernel(inputs=[(7,)], outputs=[(7,)])
def pose_inv(w, x, y, z, tx, ty, tz):
    """Inverse motion ``[R^T, -R^T t]``: ``(q*, -(q* t q))``."""
    rx, ry, rz = quat_apply(w, -x, -y, -z, tx, ty, tz)
    return (w, -x, -y, -z, -rx, -ry, -rz)


@kernel(inputs=[(7,)], outputs=[(4, 4)])
def matrix_from_pose(w, x, y, z, tx, ty, tz):
    """Homogeneous matrix ``[[R, t], [0, 1]]`` of a pose."""
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = matrix_from_quat(w, x, y, z)
    return (r0, r1, r2, tx, r3, r4, r5, ty, r6, r7, r8, tz, 0.0, 0.0, 0.0, 1.0)


@kernel(inputs=[(7,)], outputs=[(6, 6)])
def adjoint_from_pose(w, x, y, z, tx, ty, tz):
    """Adjoint ``[[R, hat(t) R], [0, R]]``: ``T exp(V) T^-1 = exp(Ad V)``, ``V = (v,w)``."""
    r = matrix_from_quat(w, x, y, z)
    return se3_adjoint_entries(*r, tx, ty, tz)


@kernel(inputs=[(6,)], outputs=[(7,)])
def pose_from_twist(vx, vy, vz, wx, wy, wz):
    """``exp`` of a twist ``(v, w)``: ``q = (cos(t/2), sinc(t/2) w / 2)``, ``t = J_l(w) v``.

    ``J_l(w) v = v + (1 - cos t)/t^2 w x v + (t - sin t)/t^3 w x (w x v)`` with
    ``t = |w|``; the coefficient helpers carry the small-angle series, and ``w = 0``
    gives the pure translation ``v``. This equals Murray, Li & Sastry's form (1994,
    Sec. 2.3, for a unit axis and an angle) written for ``w = theta * axis``:
    ``(I - R)(w x v)/t^2 + w w^T v / t^2``.
    """
    qw, qx, qy, qz, k1, k2 = se3_exp_pieces(wx, wy, wz)
    tx, ty, tz = eye_hat_hat2_apply(wx, wy, wz, k1, k2, vx, vy, vz)
    return (qw, qx, qy, qz, tx, ty, tz)


@kernel(inputs=[(7,)], outputs=[(6,)])
def twist_from_pose(w, x, y, z, tx, ty, tz):
    """``log`` of a pose: twist ``(v, w)`` with ``|w|`` in [0, pi].

    ``w`` is the rotation vector of ``q`` (sign flipped to ``w >= 0``, angle from
    ``atan2``, no cancellation near 0 or pi) and ``v = J_l(w)^-1 t``, where
    ``J_l^-1 = I - hat(w)/2 + cot_defect2(t) hat(w)^2`` is finite up to ``t = pi``.
    """
    rx, ry, rz, c = se3_log_pieces(w, x, y, z)
    vx, vy, vz = eye_hat_hat2_apply(rx, ry, rz, -0.5, c, tx, ty, tz)
    return (vx, vy, vz, rx, ry, rz)


# -- the Lie algebra se(3) -------------------------------------------------------------


@kernel(inputs=[(6,)], outputs=[(4, 4)])
def hat(vx, vy, vz, wx, wy, wz):
    """``hat(V) = [[hat(w), v], [0, 0]]`` for a twist ``V = (v, w)``."""
    return (0.0, -wz, wy, vx, wz, 0.0, -wx, vy, -wy, wx, 0.0, vz, 0.0, 0.0, 0.0, 0.0)


@kernel(inputs=[(4, 4)], outputs=[(6,)])
def vee(m00, m01, m02, m03, m10, m11, m12, m13, m20, m21, m22, m23, m30, m31, m32, m33):
    """Inverse of ``hat``: ``v`` from the last column, ``w`` from the skew part."""
    return (m03, m13, m23, 0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01))


@kernel(inputs=[(4, 4)], outputs=[(6, 6)])
def adjoint_from_matrix(
    m00, m01, m02, m03, m10, m11, m12, m13, m20, m21, m22, m23, m30, m31, m32, m33
):  # noqa: E501
    """Adjoint ``[[R, hat(t) R], [0, R]]`` of a homogeneous matrix ``[[R, t], [0, 1]]``."""
    return se3_adjoint_entries(m00, m01, m02, m10, m11, m12, m20, m21, m22, m03, m13, m23)


@kernel(inputs=[(6,)], outputs=[(6, 6)])
def ad(vx, vy, vz, wx, wy, wz):
    """Small adjoint ``ad_V = [[hat(w), hat(v)], [0, hat(w)]]``: ``ad_V U = [V, U]``."""
    return (
        0.0, -wz, wy, 0.0, -vz, vy,
        wz, 0.0, -wx, vz, 0.0, -vx,
        -wy, wx, 0.0, -vy, vx, 0.0,
        0.0, 0.0, 0.0, 0.0, -wz, wy,
        0.0, 0.0, 0.0, wz, 0.0, -wx,
        0.0, 0.0, 0.0, -wy, wx, 0.0,
    )  # fmt: skip


@kernel(inputs=[(6,), (6,)], outputs=[(6,)])
def bracket(vx1, vy1, vz1, wx1, wy1, wz1, vx2, vy2, vz2, wx2, wy2, wz2):
    """Lie bracket ``[V1, V2] = (w1 x v2 + v1 x w2, w1 x w2)`` (matrix commutator)."""
    ax, ay, az = cross3(wx1, wy1, wz1, vx2, vy2, vz2)
    bx, by, bz = cross3(vx1, vy1, vz1, wx2, wy2, wz2)
    cx, cy, cz = cross3(wx1, wy1, wz1, wx2, wy2, wz2)
    return (ax + bx, ay + by, az + bz, cx, cy, cz)


@kernel(inputs=[(6,)], outputs=[(6, 6)])
def left_jacobian(vx, vy, vz, wx, wy, wz):
    """Left Jacobian of SE(3) ``[[J_l(w), Q(v, w)], [0, J_l(w)]]``."""
    j = so3_left_jacobian_entries(wx, wy, wz)
    q = se3_q_entries(vx, vy, vz, wx, wy, wz)
    return se3_block_upper(j, q)


@kernel(inputs=[(6,)], outputs=[(6, 6)])
def left_jacobian_inverse(vx, vy, vz, wx, wy, wz):
    """``[[J^-1, -J^-1 Q J^-1], [0, J^-1]]``, ``J = J_l(w)`` (finite for ``|w| < 2 pi``)."""
    ji = so3_left_jacobian_inverse_entries(wx, wy, wz)
    q = se3_q_entries(vx, vy, vz, wx, wy, wz)
    m = mat33_mul(*ji, *mat33_mul(*q, *ji))
    return se3_block_upper(
        ji, (-m[0], -m[1], -m[2], -m[3], -m[4], -m[5], -m[6], -m[7], -m[8])
    )
