"""Kernels of SE_2(3): extended poses ``(R, v, p)``, tangents ``(rho_v, rho_p, w)``.

The group of navigation states of Barrau & Bonnabel 2017 ("The invariant extended
Kalman filter as a stable observer", Sec. 3): a rotation ``R``, a velocity ``v``
and a position ``p``, with the 5x5 matrix ``[[R, v, p], [0, 1, 0], [0, 0, 1]]``.
An element is stored as 10 components ``(w, x, y, z, vx, vy, vz, px, py, pz)``: a
unit quaternion (Hamilton, scalar first), then ``v``, then ``p``. Products are
matrix products: ``X1 X2 = (R1 R2, v1 + R1 v2, p1 + R1 p2)``.

Tangent vectors are ordered ``(rho_v, rho_p, w)`` (9 components):
``hat(xi) = [[hat(w), rho_v, rho_p], [0, 0, 0], [0, 0, 0]]``, and its matrix
exponential is ``(exp(hat(w)), J_l(w) rho_v, J_l(w) rho_p)`` with ``J_l`` the SO(3)
left Jacobian, as the translation of SE(3) (:mod:`.se3`): SE_2(3) is SE(3) with a
second translation column, so every formula here is the SE(3) one applied to each
column, built from the same helpers (the small-angle series live in
:mod:`.coefficients` and :mod:`.so3`). The left Jacobian is
``[[J, 0, Q(rho_v, w)], [0, J, Q(rho_p, w)], [0, 0, J]]`` with Barfoot's ``Q``
(Barfoot 2017, eq. 7.86), and the adjoint ``[[R, 0, hat(v) R], [0, R, hat(p) R],
[0, 0, R]]``. Jacobians follow the SO(3) convention: ``exp(x + d) ~ exp(J_l(x) d)
exp(x)``.

The group acts on points through its pose part, ``x -> R x + p`` (the matrix on
``[x; 0; 1]``).
"""

from .._engine import helper, kernel
from .matrix import matrix_from_quat
from .quaternion import quat_apply, quat_compose
from .se3 import se3_exp_pieces, se3_log_pieces, se3_q_entries
from .so3 import (
    eye_hat_hat2_apply,
    so3_left_jacobian_entries,
    so3_left_jacobian_inverse_entries,
)
from .vector import cross3, hat_matmul, mat33_mul


@helper
def se23_block_upper(j, a, b):
    """Entries of the 9x9 ``[[J, 0, A], [0, J, B], [0, 0, J]]`` from 9-tuples."""
    return (
        j[0], j[1], j[2], 0.0, 0.0, 0.0, a[0], a[1], a[2],
        j[3], j[4], j[5], 0.0, 0.0, 0.0, a[3], a[4], a[5],
        j[6], j[7], j[8], 0.0, 0.0, 0.0, a[6], a[7], a[8],
        0.0, 0.0, 0.0, j[0], j[1], j[2], b[0], b[1], b[2],
        0.0, 0.0, 0.0, j[3], j[4], j[5], b[3], b[4], b[5],
        0.0, 0.0, 0.0, j[6], j[7], j[8], b[6], b[7], b[8],
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, j[0], j[1], j[2],
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, j[3], j[4], j[5],
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, j[6], j[7], j[8],
    )  # fmt: skip


@helper
def se23_exp_entries(ax, ay, az, bx, by, bz, wx, wy, wz):
    """``(q, J_l(w) a, J_l(w) b)`` of the tangent ``(a, b, w)``, as 10 scalars."""
    qw, qx, qy, qz, k1, k2 = se3_exp_pieces(wx, wy, wz)
    vx, vy, vz = eye_hat_hat2_apply(wx, wy, wz, k1, k2, ax, ay, az)
    px, py, pz = eye_hat_hat2_apply(wx, wy, wz, k1, k2, bx, by, bz)
    return (qw, qx, qy, qz, vx, vy, vz, px, py, pz)


# -- extended poses ---------------------------------------------------------------------


@kernel(inputs=[(4,), (3,), (3,)], outputs=[(10,)])
def extpose_from_parts(w, x, y, z, vx, vy, vz, px, py, pz):
    """Pack a unit quaternion, a velocity and a position (broadcasting all three)."""
    return (w, x, y, z, vx, vy, vz, px, py, pz)


@kernel(inputs=[(10,), (10,)], outputs=[(10,)])
def extpose_compose(
    w1, x1, y1, z1, vx1, vy1, vz1, px1, py1, pz1,
    w2, x2, y2, z2, vx2, vy2, vz2, px2, py2, pz2,
):  # fmt: skip
    """``X1 @ X2`` (``X2`` first): ``(q1 q2, v1 + R1 v2, p1 + R1 p2)``."""
    w, x, y, z = quat_compose(w1, x1, y1, z1, w2, x2, y2, z2)
    ax, ay, az = quat_apply(w1, x1, y1, z1, vx2, vy2, vz2)
    bx, by, bz = quat_apply(w1, x1, y1, z1, px2, py2, pz2)
    return (w, x, y, z, vx1 + ax, vy1 + ay, vz1 + az, px1 + bx, py1 + by, pz1 + bz)


@kernel(inputs=[(10,)], outputs=[(10,)])
def extpose_inv(w, x, y, z, vx, vy, vz, px, py, pz):
    """Inverse ``(R^T, -R^T v, -R^T p)``: the matrix inverse in closed form."""
    ax, ay, az = quat_apply(w, -x, -y, -z, vx, vy, vz)
    bx, by, bz = quat_apply(w, -x, -y, -z, px, py, pz)
    return (w, -x, -y, -z, -ax, -ay, -az, -bx, -by, -bz)


@kernel(inputs=[(10,), (3,)], outputs=[(3,)])
def extpose_apply(w, x, y, z, vx, vy, vz, px, py, pz, ux, uy, uz):
    """The action on points, ``R u + p`` (the 5x5 matrix on ``[u; 0; 1]``)."""
    rx, ry, rz = quat_apply(w, x, y, z, ux, uy, uz)
    return (rx + px, ry + py, rz + pz)


@kernel(inputs=[(10,), (3,)], outputs=[(3,)])
def extpose_apply_inverse(w, x, y, z, vx, vy, vz, px, py, pz, ux, uy, uz):
    """The inverse action ``R^T (u - p)``, without forming the inverse."""
    return quat_apply(w, -x, -y, -z, ux - px, uy - py, uz - pz)


@kernel(inputs=[(10,)], outputs=[(5, 5)])
def matrix_from_extpose(w, x, y, z, vx, vy, vz, px, py, pz):
    """The 5x5 matrix ``[[R, v, p], [0, 1, 0], [0, 0, 1]]`` (row-major)."""
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = matrix_from_quat(w, x, y, z)
    return (
        r0, r1, r2, vx, px,
        r3, r4, r5, vy, py,
        r6, r7, r8, vz, pz,
        0.0, 0.0, 0.0, 1.0, 0.0,
        0.0, 0.0, 0.0, 0.0, 1.0,
    )  # fmt: skip


@kernel(inputs=[(10,)], outputs=[(9, 9)])
def adjoint_from_extpose(w, x, y, z, vx, vy, vz, px, py, pz):
    """``Ad = [[R, 0, hat(v) R], [0, R, hat(p) R], [0, 0, R]]``: ``X exp(xi) X^-1 =
    exp(Ad xi)`` for tangents ``(rho_v, rho_p, w)``."""
    r = matrix_from_quat(w, x, y, z)
    a = hat_matmul(vx, vy, vz, *r)
    b = hat_matmul(px, py, pz, *r)
    return se23_block_upper(r, a, b)


@kernel(inputs=[(9,)], outputs=[(10,)])
def extpose_from_tangent(ax, ay, az, bx, by, bz, wx, wy, wz):
    """``exp`` of a tangent ``(rho_v, rho_p, w)``: ``(exp(w), J_l(w) rho_v, J_l(w) rho_p)``.

    As the SE(3) exponential (:func:`.se3.pose_from_twist`) for each column: ``w = 0``
    gives ``(I, rho_v, rho_p)``, the coefficient helpers carry the small-angle series.
    """
    return se23_exp_entries(ax, ay, az, bx, by, bz, wx, wy, wz)


@kernel(inputs=[(10,)], outputs=[(9,)])
def tangent_from_extpose(w, x, y, z, vx, vy, vz, px, py, pz):
    """``log``: ``(J_l(w)^-1 v, J_l(w)^-1 p, w)`` with ``|w|`` in [0, pi].

    ``w`` is the rotation vector of ``q`` (``atan2``-based); ``J_l^-1 = I - hat(w)/2 +
    cot_defect2(t) hat(w)^2`` is finite up to ``t = pi`` (as :func:`.se3.twist_from_pose`).
    """
    rx, ry, rz, c = se3_log_pieces(w, x, y, z)
    ax, ay, az = eye_hat_hat2_apply(rx, ry, rz, -0.5, c, vx, vy, vz)
    bx, by, bz = eye_hat_hat2_apply(rx, ry, rz, -0.5, c, px, py, pz)
    return (ax, ay, az, bx, by, bz, rx, ry, rz)


# -- the Lie algebra se_2(3) ------------------------------------------------------------


@kernel(inputs=[(9,)], outputs=[(5, 5)])
def hat(ax, ay, az, bx, by, bz, wx, wy, wz):
    """``hat(xi) = [[hat(w), rho_v, rho_p], [0, 0, 0], [0, 0, 0]]``."""
    return (
        0.0, -wz, wy, ax, bx,
        wz, 0.0, -wx, ay, by,
        -wy, wx, 0.0, az, bz,
        0.0, 0.0, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0, 0.0, 0.0,
    )  # fmt: skip


@kernel(inputs=[(5, 5)], outputs=[(9,)])
def vee(
    m00, m01, m02, m03, m04,
    m10, m11, m12, m13, m14,
    m20, m21, m22, m23, m24,
    m30, m31, m32, m33, m34,
    m40, m41, m42, m43, m44,
):  # fmt: skip
    """Inverse of ``hat``: ``rho_v``, ``rho_p`` from the columns 4 and 5, ``w`` from the
    skew part of the 3x3 block."""
    return (
        m03, m13, m23, m04, m14, m24,
        0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01),
    )  # fmt: skip


@kernel(inputs=[(9,)], outputs=[(9, 9)])
def ad(ax, ay, az, bx, by, bz, wx, wy, wz):
    """Small adjoint ``[[hat(w), 0, hat(rho_v)], [0, hat(w), hat(rho_p)], [0, 0, hat(w)]]``:
    ``ad(xi) u = [xi, u]``."""
    w = (0.0, -wz, wy, wz, 0.0, -wx, -wy, wx, 0.0)
    a = (0.0, -az, ay, az, 0.0, -ax, -ay, ax, 0.0)
    b = (0.0, -bz, by, bz, 0.0, -bx, -by, bx, 0.0)
    return se23_block_upper(w, a, b)


@kernel(inputs=[(9,), (9,)], outputs=[(9,)])
def bracket(
    ax1, ay1, az1, bx1, by1, bz1, wx1, wy1, wz1, ax2, ay2, az2, bx2, by2, bz2, wx2, wy2, wz2
):  # noqa: E501
    """Lie bracket: ``(w1 x a2 + a1 x w2, w1 x b2 + b1 x w2, w1 x w2)``."""
    c = cross3(wx1, wy1, wz1, ax2, ay2, az2)
    d = cross3(ax1, ay1, az1, wx2, wy2, wz2)
    e = cross3(wx1, wy1, wz1, bx2, by2, bz2)
    f = cross3(bx1, by1, bz1, wx2, wy2, wz2)
    g = cross3(wx1, wy1, wz1, wx2, wy2, wz2)
    return (
        c[0] + d[0], c[1] + d[1], c[2] + d[2],
        e[0] + f[0], e[1] + f[1], e[2] + f[2],
        g[0], g[1], g[2],
    )  # fmt: skip


@kernel(inputs=[(9,)], outputs=[(9, 9)])
def left_jacobian(ax, ay, az, bx, by, bz, wx, wy, wz):
    """``[[J_l(w), 0, Q(rho_v, w)], [0, J_l(w), Q(rho_p, w)], [0, 0, J_l(w)]]``."""
    j = so3_left_jacobian_entries(wx, wy, wz)
    qa = se3_q_entries(ax, ay, az, wx, wy, wz)
    qb = se3_q_entries(bx, by, bz, wx, wy, wz)
    return se23_block_upper(j, qa, qb)


@kernel(inputs=[(9,)], outputs=[(9, 9)])
def left_jacobian_inverse(ax, ay, az, bx, by, bz, wx, wy, wz):
    """``[[J^-1, 0, -J^-1 Q_v J^-1], [0, J^-1, -J^-1 Q_p J^-1], [0, 0, J^-1]]``,
    ``J = J_l(w)`` (finite for ``|w| < 2 pi``)."""
    ji = so3_left_jacobian_inverse_entries(wx, wy, wz)
    qa = se3_q_entries(ax, ay, az, wx, wy, wz)
    qb = se3_q_entries(bx, by, bz, wx, wy, wz)
    ma = mat33_mul(*ji, *mat33_mul(*qa, *ji))
    mb = mat33_mul(*ji, *mat33_mul(*qb, *ji))
    return se23_block_upper(
        ji,
        (-ma[0], -ma[1], -ma[2], -ma[3], -ma[4], -ma[5], -ma[6], -ma[7], -ma[8]),
        (-mb[0], -mb[1], -mb[2], -mb[3], -mb[4], -mb[5], -mb[6], -mb[7], -mb[8]),
    )
