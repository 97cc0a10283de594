"""Kernels of moving bodies: twists, the derivatives of poses, points of a body.

Conventions: homogeneous matrices ``T = [[R, p], [0, 1]]``, row-major; twists
``(v, w)`` with ``hat(V) = [[hat(w), v], [0, 0]]``. A twist is in the world frame
(``T' = hat(V) T``, the spatial velocity) or the body frame (``T' = T hat(V)``);
the static parameter ``body`` is 0 or 1 (Murray, Li & Sastry 1994, Sec. 2.4.2).
The rotation parts are those of :mod:`.rotation`.
"""

from ..._engine import helper, kernel
from ..vector import cross3
from .rotation import hat_sq_apply, left_or_right_apply, omega_from_matrix_rate

# -- homogeneous transforms and twists ----------------------------------------------------


@helper
def derivative_of_homogeneous(body, r, k, ux, uy, uz, px, py, pz):
    """Row-major ``[[k, t], [0, 0]]`` with ``t = R u`` (body) or ``p + u`` (world).

    The common form of ``T'`` and ``T''`` in either frame: ``k`` is their rotation
    block, ``r`` the rotation ``R`` of ``T``, both row-major.
    """
    b = body == 1
    tx = where(b, r[0] * ux + r[1] * uy + r[2] * uz, px + ux)
    ty = where(b, r[3] * ux + r[4] * uy + r[5] * uz, py + uy)
    tz = where(b, r[6] * ux + r[7] * uy + r[8] * uz, pz + uz)
    return (
        k[0], k[1], k[2], tx,
        k[3], k[4], k[5], ty,
        k[6], k[7], k[8], tz,
        0.0, 0.0, 0.0, 0.0,
    )  # fmt: skip


@kernel(inputs=[(4, 4), (4, 4)], outputs=[(6,)], params=("body",))
def twist_from_matrix_derivative(
    body,
    m00, m01, m02, m03, m10, m11, m12, m13, m20, m21, m22, m23, m30, m31, m32, m33,
    d00, d01, d02, d03, d10, d11, d12, d13, d20, d21, d22, d23, d30, d31, d32, d33,
):  # fmt: skip
    """Twist ``(v, w)``: ``hat(V) = T' T^-1`` (world) or ``T^-1 T'`` (body).

    World: ``w = vee(R' R^T)``, ``v = p' - w x p``; body: ``w = vee(R^T R')``, ``v
    = R^T p'`` (the spatial and body velocities of Murray, Li & Sastry 1994, Sec.
    2.4.2).
    """
    wx, wy, wz = omega_from_matrix_rate(
        body, m00, m01, m02, m10, m11, m12, m20, m21, m22,
        d00, d01, d02, d10, d11, d12, d20, d21, d22,
    )  # fmt: skip
    cx, cy, cz = cross3(wx, wy, wz, m03, m13, m23)
    b = body == 1
    vx = where(b, m00 * d03 + m10 * d13 + m20 * d23, d03 - cx)
    vy = where(b, m01 * d03 + m11 * d13 + m21 * d23, d13 - cy)
    vz = where(b, m02 * d03 + m12 * d13 + m22 * d23, d23 - cz)
    return (vx, vy, vz, wx, wy, wz)


@kernel(inputs=[(4, 4), (6,), (6,)], outputs=[(4, 4)], params=("body",))
def matrix_second_derivative_from_twist(
    body,
    m00, m01, m02, m03, m10, m11, m12, m13, m20, m21, m22, m23, m30, m31, m32, m33,
    vx, vy, vz, wx, wy, wz, dvx, dvy, dvz, ax, ay, az,
):  # fmt: skip
    """``T'' = (hat(V') + hat(V)^2) T`` (world) or ``T (hat(V') + hat(V)^2)`` (body).

    ``hat(V') + hat(V)^2 = [[hat(a) + hat(w)^2, v' + w x v], [0, 0]]`` with
    ``V' = (v', a)``: differentiating ``T' = hat(V) T`` gives ``T'' = hat(V') T +
    hat(V) T' = (hat(V') + hat(V)^2) T`` (body alike, on the right). With
    ``V = 0`` and ``V' = 0`` except ``v = V`` this is also ``T'``: see
    :func:`matrix_derivative_from_twist`.
    """
    r = (m00, m01, m02, m10, m11, m12, m20, m21, m22)
    k = left_or_right_apply(body, wx, wy, wz, ax, ay, az, r)
    cx, cy, cz = cross3(wx, wy, wz, vx, vy, vz)
    ux = dvx + cx
    uy = dvy + cy
    uz = dvz + cz
    # translation column: world (hat(a) + hat(w)^2) p + u, body R u
    px, py, pz = hat_sq_apply(wx, wy, wz, ax, ay, az, m03, m13, m23)
    return derivative_of_homogeneous(body, r, k, ux, uy, uz, px, py, pz)


@kernel(inputs=[(4, 4), (6,)], outputs=[(4, 4)], params=("body",))
def matrix_derivative_from_twist(
    body,
    m00, m01, m02, m03, m10, m11, m12, m13, m20, m21, m22, m23, m30, m31, m32, m33,
    vx, vy, vz, wx, wy, wz,
):  # fmt: skip
    """``T' = hat(V) T`` (world) or ``T hat(V)`` (body), ``V = (v, w)``.

    World: ``[[hat(w) R, w x p + v], [0, 0]]``; body: ``[[R hat(w), R v], [0, 0]]``.
    """
    r = (m00, m01, m02, m10, m11, m12, m20, m21, m22)
    k = left_or_right_apply(body, 0.0, 0.0, 0.0, wx, wy, wz, r)
    cx, cy, cz = cross3(wx, wy, wz, m03, m13, m23)
    return derivative_of_homogeneous(body, r, k, vx, vy, vz, cx, cy, cz)


@kernel(inputs=[(6,), (6,)], outputs=[(4, 4)])
def acceleration_matrix_from_twists(vx, vy, vz, wx, wy, wz, dvx, dvy, dvz, ax, ay, az):
    """``hat(V') + hat(V)^2 = [[hat(a) + hat(w)^2, v' + w x v], [0, 0]]``.

    Acting on ``[q; 1]`` (a point, not the direction ``[q; 0]``) it gives the
    acceleration of a point moving with the body: ``T'' T^-1 [q; 1]`` in the world
    frame (see :func:`matrix_second_derivative_from_twist`).
    """
    cx, cy, cz = cross3(wx, wy, wz, vx, vy, vz)
    xx = wx * wx
    yy = wy * wy
    zz = wz * wz
    return (
        -(yy + zz), wx * wy - az, wx * wz + ay, dvx + cx,
        wx * wy + az, -(xx + zz), wy * wz - ax, dvy + cy,
        wx * wz - ay, wy * wz + ax, -(xx + yy), dvz + cz,
        0.0, 0.0, 0.0, 0.0,
    )  # fmt: skip


@kernel(inputs=[(4, 4), (6,)], outputs=[(6,)], params=("inverse",))
def twist_change_frame(
    inverse,
    m00, m01, m02, m03, m10, m11, m12, m13, m20, m21, m22, m23, m30, m31, m32, m33,
    vx, vy, vz, wx, wy, wz,
):  # fmt: skip
    """``Ad_T V`` (``inverse = 0``: body to world) or ``Ad_T^-1 V`` (world to body).

    ``Ad_T (v, w) = (R v + p x R w, R w)``; ``Ad_T^-1 (v, w) = (R^T (v - p x w),
    R^T w)``. No 6x6 matrix is formed.
    """
    inv = inverse == 1
    # body to world: first rotate, then add p x w'; world to body: the reverse
    cx, cy, cz = cross3(m03, m13, m23, wx, wy, wz)
    ux = where(inv, vx - cx, vx)
    uy = where(inv, vy - cy, vy)
    uz = where(inv, vz - cz, vz)
    rvx = where(inv, m00 * ux + m10 * uy + m20 * uz, m00 * ux + m01 * uy + m02 * uz)
    rvy = where(inv, m01 * ux + m11 * uy + m21 * uz, m10 * ux + m11 * uy + m12 * uz)
    rvz = where(inv, m02 * ux + m12 * uy + m22 * uz, m20 * ux + m21 * uy + m22 * uz)
    rwx = where(inv, m00 * wx + m10 * wy + m20 * wz, m00 * wx + m01 * wy + m02 * wz)
    rwy = where(inv, m01 * wx + m11 * wy + m21 * wz, m10 * wx + m11 * wy + m12 * wz)
    rwz = where(inv, m02 * wx + m12 * wy + m22 * wz, m20 * wx + m21 * wy + m22 * wz)
    ex, ey, ez = cross3(m03, m13, m23, rwx, rwy, rwz)
    return (
        where(inv, rvx, rvx + ex),
        where(inv, rvy, rvy + ey),
        where(inv, rvz, rvz + ez),
        rwx,
        rwy,
        rwz,
    )


# -- points of a rigid body ---------------------------------------------------------------


@kernel(inputs=[(3,), (3,), (3,)], outputs=[(3,)])
def point_velocity(wx, wy, wz, rx, ry, rz, ux, uy, uz):
    """``v = v_O + w x r`` of a point at ``r`` from a body point ``O`` moving at ``v_O``."""
    cx, cy, cz = cross3(wx, wy, wz, rx, ry, rz)
    return (ux + cx, uy + cy, uz + cz)


@kernel(inputs=[(3,), (3,), (3,), (3,), (3,), (3,)], outputs=[(3,)])
def point_acceleration(
    wx, wy, wz, ax, ay, az, rx, ry, rz, aox, aoy, aoz, vrx, vry, vrz, arx, ary, arz
):
    """``a = a_O + a x r + w x (w x r) + 2 w x v_rel + a_rel``.

    Tangential ``a x r``, centripetal ``w x (w x r)``, Coriolis ``2 w x v_rel``; the
    point moves relative to the body at ``v_rel`` with acceleration ``a_rel``.
    """
    tx, ty, tz = hat_sq_apply(wx, wy, wz, ax, ay, az, rx, ry, rz)
    cx, cy, cz = cross3(wx, wy, wz, vrx, vry, vrz)
    return (
        aox + tx + 2.0 * cx + arx,
        aoy + ty + 2.0 * cy + ary,
        aoz + tz + 2.0 * cz + arz,
    )
