"""Kernels of planar moving frames: SO(2) and SE(2) velocities, points in the plane.

A planar rotation ``R(t) = exp(theta(t) J)``, ``J = [[0, -1], [1, 0]]``, has ``R' =
omega J R = R omega J``: SO(2) is commutative, so the world and body angular
velocities are the same number.
Planar twists are ``(vx, vy, omega)``, ``hat(V) = [[omega J, v], [0, 0]]``; world
``T' = hat(V) T`` (``v = p' - omega J p``), body ``T' = T hat(V)`` (``v = R^T p'``).
With ``J^2 = -I`` a body point accelerates at ``(alpha J - omega^2 I) r =
[[-omega^2, -alpha], [alpha, -omega^2]] r``, ``alpha = omega'`` (tangential plus
centripetal, the planar case of ``alpha x r + omega x (omega x r)``).

Integration steps (as in :mod:`.integration`, whose RKMK4 they
follow): SE(2) steps are poses ``exp(theta)`` chained in order; so(2) is abelian,
so every bracket vanishes, RKMK4 is Simpson's rule for ``theta = integral of
omega``, and the SO(2) steps are angles, summed.
"""

from ..._engine import helper, kernel
from ..se2 import bracket, pose_from_twist, pose_multiply


@kernel(inputs=[(2, 2), (2, 2)], outputs=[(1,)])
def omega_from_matrix_derivative_2d(r00, r01, r10, r11, d00, d01, d10, d11):
    """``omega = vee(R' R^T)`` (= ``vee(R^T R')``), from the skew part."""
    m10 = d10 * r00 + d11 * r01
    m01 = d00 * r10 + d01 * r11
    return (0.5 * (m10 - m01),)


@kernel(inputs=[(2, 2), (1,)], outputs=[(2, 2)])
def matrix_derivative_from_omega_2d(r00, r01, r10, r11, w):
    """``R' = omega J R``: rows ``(-omega r10, -omega r11), (omega r00, omega r01)``."""
    return (-w * r10, -w * r11, w * r00, w * r01)


@kernel(inputs=[(3, 3), (3, 3)], outputs=[(3,)], params=("body",))
def twist_from_matrix_derivative_2d(
    body, m00, m01, m02, m10, m11, m12, m20, m21, m22,
    d00, d01, d02, d10, d11, d12, d20, d21, d22,
):  # fmt: skip
    """Planar twist: ``omega`` of the rotation, ``v = p' - omega J p`` or ``R^T p'``."""
    w = 0.5 * ((d10 * m00 + d11 * m01) - (d00 * m10 + d01 * m11))
    b = body == 1
    vx = where(b, m00 * d02 + m10 * d12, d02 + w * m12)
    vy = where(b, m01 * d02 + m11 * d12, d12 - w * m02)
    return (vx, vy, w)


@kernel(inputs=[(3, 3), (3,)], outputs=[(3, 3)], params=("body",))
def matrix_derivative_from_twist_2d(
    body, m00, m01, m02, m10, m11, m12, m20, m21, m22, vx, vy, w
):
    """``T' = hat(V) T`` (world) or ``T hat(V)`` (body); ``omega J R = R omega J``."""
    b = body == 1
    tx = where(b, m00 * vx + m01 * vy, vx - w * m12)
    ty = where(b, m10 * vx + m11 * vy, vy + w * m02)
    return (-w * m10, -w * m11, tx, w * m00, w * m01, ty, 0.0, 0.0, 0.0)


@kernel(inputs=[(1,), (2,), (2,)], outputs=[(2,)])
def point_velocity_2d(w, rx, ry, ux, uy):
    """``v = v_O + omega J r``."""
    return (ux - w * ry, uy + w * rx)


@kernel(inputs=[(1,), (1,), (2,), (2,), (2,), (2,)], outputs=[(2,)])
def point_acceleration_2d(w, a, rx, ry, aox, aoy, vrx, vry, arx, ary):
    """``a = a_O + (alpha J - omega^2 I) r + 2 omega J v_rel + a_rel``."""
    w2 = w * w
    return (
        aox - a * ry - w2 * rx - 2.0 * w * vry + arx,
        aoy + a * rx - w2 * ry + 2.0 * w * vrx + ary,
    )


# -- integration steps (see integration.py) --------------------------------------------


@kernel(inputs=[(1,), ()], outputs=[(1,)])
def so2_increment(w, h):
    """The angle ``h w`` of a step of zero-order hold (or midpoint, given the
    midpoint rate)."""
    return (h * w,)


@kernel(inputs=[(1,), (1,), (1,), ()], outputs=[(1,)])
def so2_increment_rk4(a, m, e, h):
    """``h (a + 4 m + e) / 6``: RKMK4 in the abelian so(2) (every bracket is 0) is
    Simpson's rule, ``a``, ``m``, ``e`` the rate at the start, middle and end."""
    return (h * (a + 4.0 * m + e) / 6.0,)


@helper
def se2_dexp_inv(s, u0, u1, u2, a0, a1, a2):
    """``a + s/2 [u, a] + 1/12 [u, [u, a]]``, the truncated ``dexp^-1_u(a)`` of se(2)."""
    b = bracket(u0, u1, u2, a0, a1, a2)
    c = bracket(u0, u1, u2, b[0], b[1], b[2])
    k = 0.5 * s
    g = 1.0 / 12.0
    return (a0 + k * b[0] + g * c[0], a1 + k * b[1] + g * c[1], a2 + k * b[2] + g * c[2])


@kernel(inputs=[(3,), ()], outputs=[(4,)])
def se2_increment(vx, vy, w, h):
    """Pose ``(c, s, tx, ty)`` of ``exp(h V)``, ``V = (vx, vy, w)``: a step of
    zero-order hold (or midpoint)."""
    return pose_from_twist(h * vx, h * vy, h * w)


@kernel(inputs=[(3,), (3,), (3,), ()], outputs=[(4,)], params=("body",))
def se2_increment_rk4(body, a0, a1, a2, m0, m1, m2, e0, e1, e2, h):
    """Pose of ``exp(theta)``, ``theta`` the RKMK4 increment in se(2).

    As :func:`~rigidkit.kernels.kinematics.integration.se3_increment_rk4`, with the
    bracket of se(2).
    """
    s = where(body == 1, 1.0, -1.0)
    k1 = (h * a0, h * a1, h * a2)
    d2 = se2_dexp_inv(s, 0.5 * k1[0], 0.5 * k1[1], 0.5 * k1[2], m0, m1, m2)
    k2 = (h * d2[0], h * d2[1], h * d2[2])
    d3 = se2_dexp_inv(s, 0.5 * k2[0], 0.5 * k2[1], 0.5 * k2[2], m0, m1, m2)
    k3 = (h * d3[0], h * d3[1], h * d3[2])
    d4 = se2_dexp_inv(s, k3[0], k3[1], k3[2], e0, e1, e2)
    return pose_from_twist(
        (k1[0] + 2.0 * (k2[0] + k3[0]) + h * d4[0]) / 6.0,
        (k1[1] + 2.0 * (k2[1] + k3[1]) + h * d4[1]) / 6.0,
        (k1[2] + 2.0 * (k2[2] + k3[2]) + h * d4[2]) / 6.0,
    )


@kernel(inputs=[(4,), (4,)], outputs=[(4,)], params=("body",))
def se2_chain(body, c1, s1, x1, y1, c2, s2, x2, y2):
    """``A B`` (body) or ``B A`` (world) of planar poses (see
    :func:`~rigidkit.kernels.kinematics.integration.so3_chain`); the
    complex part is renormalised by :func:`~rigidkit.kernels.so2.complex_multiply`."""
    b = body == 1
    return pose_multiply(
        where(b, c1, c2), where(b, s1, s2), where(b, x1, x2), where(b, y1, y2),
        where(b, c2, c1), where(b, s2, s1), where(b, x2, x1), where(b, y2, y1),
    )  # fmt: skip


@kernel(inputs=[(3, 3), (3,)], outputs=[(3,)], params=("to_body",))
def twist_change_frame_2d(to_body, m00, m01, m02, m10, m11, m12, m20, m21, m22, vx, vy, w):
    """``Ad_T V = (R v + omega (ty, -tx), omega)``; its inverse with ``to_body=1``,
    ``(R^T (v - omega (ty, -tx)), omega)``."""
    b = to_body == 1
    # The offset of the adjoint's last column, added going to the world frame and
    # removed (before rotating back) going to the body frame.
    ux = where(b, vx - w * m12, vx)
    uy = where(b, vy + w * m02, vy)
    rx = where(b, m00 * ux + m10 * uy, m00 * ux + m01 * uy + w * m12)
    ry = where(b, m01 * ux + m11 * uy, m10 * ux + m11 * uy - w * m02)
    return (rx, ry, w)
