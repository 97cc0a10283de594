"""Kernels of planar moving frames: SO(2) and SE(2) velocities, points in the plane.

A planar rotation ``R(t) = exp(theta(t) J)``, ``J = [[0, -1], [1, 0]]`` (the
notes' ``e^{J omega t}``), has ``R' = omega J R = R omega J``: SO(2) is
commutative, so the world and body angular velocities are the same number.
Planar twists are ``(vx, vy, omega)``, ``hat(V) = [[omega J, v], [0, 0]]``; world
``T' = hat(V) T`` (``v = p' - omega J p``), body ``T' = T hat(V)`` (``v = R^T p'``).
With ``J^2 = -I`` a body point accelerates at ``(alpha J - omega^2 I) r``, the
notes' ``[[-omega^2, -alpha], [alpha, -omega^2]]`` (000 D.3, with ``alpha`` for
their ``omega'``).
"""

from .._engine import kernel


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
