"""Kernels of SE(2): poses ``(c, s, tx, ty)`` and twists ``(vx, vy, ω)``.

A pose is the rotation ``c + i s`` (unit complex) and the translation ``t``; its
matrix is ``[[c, -s, tx], [s, c, ty], [0, 0, 1]]`` and it maps ``p`` to
``R p + t``. Twists are ordered ``(v, ω)`` as in 3D, with
``hat(ξ) = [[0, -ω, vx], [ω, 0, vy], [0, 0, 0]]``.

With ``J = [[0, -1], [1, 0]]``, ``exp(ξ) = (R(ω), V(ω) v)`` where
``V(θ) = sinc(θ) I + (1 - cos θ)/θ J``; ``V`` and its inverse are written with
the named coefficients of :mod:`.coefficients`, so no formula here has a
threshold of its own.
"""

from .._engine import helper, kernel
from .coefficients import sin_defect3, sinc, versinc2
from .so2 import (
    angle_between,
    angle_of,
    complex_apply,
    complex_from_block,
    complex_multiply,
)


@helper
def se2_v_coeffs(w):
    """``(a, b)`` of ``V(ω) = [[a, -b], [b, a]]``: ``a = sinc(ω)``, ``b = ω versinc2(ω)``.

    ``a = sin ω / ω`` and ``b = (1 - cos ω)/ω``, both exact through ω = 0.
    """
    return (sinc(w), w * versinc2(w))


@helper
def se2_v_inverse_coeffs(w):
    """``(α, h)`` of ``V(ω)^-1 = [[α, h], [-h, α]]``: ``h = ω/2``, ``α = cos h / sinc h``.

    ``V = a I + b J`` and ``J^2 = -I`` give ``V^-1 = (a I - b J)/(a^2 + b^2)``;
    with half-angle identities this is ``V^-1 = α I - (ω/2) J``,
    ``α = (ω/2) cot(ω/2)``. For |ω| <= pi, sinc(ω/2) >= 2/pi, so the only special
    case is sinc's own (at 0); near pi, α -> 0 with an absolute error of an ulp.
    At ω = ±2 pi, ``V`` is singular and α overflows, as it should.
    """
    h = 0.5 * w
    return (cos(h) / sinc(h), h)


@helper
def se2_q(vx, vy, w):
    """``q = (e vx + d vy, e vy - d vx)``, ``d = (1 - cos ω)/ω^2``, ``e = (ω - sin ω)/ω^2``.

    The derivative of ``t = V(ω) v`` along ω, the last column of the SE(2) ``J_l``.
    """
    d = versinc2(w)
    e = w * sin_defect3(w)
    return (e * vx + d * vy, e * vy - d * vx)


@kernel(inputs=[(3,)], outputs=[(4,)])
def pose_from_twist(vx, vy, w):
    """``exp``: ``R = (cos ω, sin ω)``, ``t = V(ω) v``, ``V = [[a, -b], [b, a]]``.

    See :func:`se2_v_coeffs`; ω = 0 gives the pure translation ``t = v``.
    """
    a, b = se2_v_coeffs(w)
    return (cos(w), sin(w), a * vx - b * vy, b * vx + a * vy)


@kernel(inputs=[(4,)], outputs=[(3,)])
def twist_from_pose(c, s, tx, ty):
    """``log``: ``ω = angle(c + i s)`` in (-pi, pi], ``v = V(ω)^-1 t``.

    See :func:`se2_v_inverse_coeffs`. The input need not be exactly unit.
    """
    w = angle_of(c, s)
    alpha, h = se2_v_inverse_coeffs(w)
    return (alpha * tx + h * ty, alpha * ty - h * tx, w)


@kernel(inputs=[(4,)], outputs=[(3, 3)])
def matrix_from_pose(c, s, tx, ty):
    """Homogeneous matrix ``[[c, -s, tx], [s, c, ty], [0, 0, 1]]``."""
    return (c, -s, tx, s, c, ty, 0.0, 0.0, 1.0)


@kernel(inputs=[(3, 3)], outputs=[(4,), (), (), ()])
def pose_from_matrix(m00, m01, m02, m10, m11, m12, m20, m21, m22):
    """Pose of a 3x3 homogeneous matrix, the block norm, block defect, bottom defect.

    The rotation is the nearest rotation to the upper-left block (see
    ``complex_from_block``); the block defect is ``max(|B^T B - I|, |det B - 1|)``;
    the bottom defect is ``max(|m20|, |m21|, |m22 - 1|)``.
    """
    c, s, n, err = complex_from_block(m00, m01, m10, m11)
    bottom = maximum(maximum(abs(m20), abs(m21)), abs(m22 - 1.0))
    return (c, s, m02, m12, n, err, bottom)


@kernel(inputs=[(4,), (4,)], outputs=[(4,)])
def pose_multiply(c1, s1, x1, y1, c2, s2, x2, y2):
    """Composition ``T1 T2`` (``T2`` first): ``(R1 R2, R1 t2 + t1)``."""
    c, s = complex_multiply(c1, s1, c2, s2)
    x, y = complex_apply(c1, s1, x2, y2)
    return (c, s, x + x1, y + y1)


@kernel(inputs=[(4,)], outputs=[(4,)])
def pose_inverse(c, s, tx, ty):
    """Inverse ``(R^T, -R^T t)``."""
    return (c, -s, -(c * tx + s * ty), s * tx - c * ty)


@kernel(inputs=[(4,), (2,)], outputs=[(2,)])
def pose_apply(c, s, tx, ty, x, y):
    """Map the point ``p``: ``R p + t``."""
    rx, ry = complex_apply(c, s, x, y)
    return (rx + tx, ry + ty)


@kernel(inputs=[(4,), (4,)], outputs=[(), ()])
def pose_distance(c1, s1, x1, y1, c2, s2, x2, y2):
    """Rotation angle between the poses (in [0, pi]) and translation distance."""
    (angle,) = angle_between(c1, s1, c2, s2)
    dx = x2 - x1
    dy = y2 - y1
    return (angle, sqrt(dx * dx + dy * dy))


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def hat(vx, vy, w):
    """``hat(ξ) = [[0, -ω, vx], [ω, 0, vy], [0, 0, 0]]`` for ``ξ = (vx, vy, ω)``."""
    return (0.0, -w, vx, w, 0.0, vy, 0.0, 0.0, 0.0)


@kernel(inputs=[(3, 3)], outputs=[(3,)])
def vee(m00, m01, m02, m10, m11, m12, m20, m21, m22):
    """Inverse of ``hat``: ``(m02, m12, (m10 - m01) / 2)``."""
    return (m02, m12, 0.5 * (m10 - m01))


@kernel(inputs=[(4,)], outputs=[(3, 3)])
def adjoint_from_pose(c, s, tx, ty):
    """``Ad = [[R, (ty, -tx)^T], [0, 0, 1]]`` for twists ordered ``(v, ω)``.

    From ``T hat(ξ) T^-1 = [[ω J, R v - ω J t], [0, 0]]`` and
    ``-J t = (ty, -tx)``.
    """
    return (c, -s, ty, s, c, -tx, 0.0, 0.0, 1.0)


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def ad(vx, vy, w):
    """Small adjoint ``ad(ξ) = [[ω J, -J v], [0, 0]]``, ``ad(ξ1) ξ2 = [ξ1, ξ2]``."""
    return (0.0, -w, vy, w, 0.0, -vx, 0.0, 0.0, 0.0)


@kernel(inputs=[(3,), (3,)], outputs=[(3,)])
def bracket(vx1, vy1, w1, vx2, vy2, w2):
    """Lie bracket ``vee(hat(ξ1) hat(ξ2) - hat(ξ2) hat(ξ1)) = (ω1 J v2 - ω2 J v1, 0)``."""
    return (w2 * vy1 - w1 * vy2, w1 * vx2 - w2 * vx1, 0.0)


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def left_jacobian(vx, vy, w):
    """Left Jacobian: ``exp(ξ + δ) ≈ exp(J_l(ξ) δ) exp(ξ)``.

    ``J_l = [[V, q], [0, 1]]`` with ``V = [[a, -b], [b, a]]`` as in ``exp`` and
    ``q = (e vx + d vy, e vy - d vx)``, ``d = (1 - cos ω)/ω^2``,
    ``e = (ω - sin ω)/ω^2``: the derivative of ``t = V(ω) v`` along ω, moved to the
    left. The right Jacobian is ``J_l(-ξ)``.
    """
    a, b = se2_v_coeffs(w)
    qx, qy = se2_q(vx, vy, w)
    return (a, -b, qx, b, a, qy, 0.0, 0.0, 1.0)


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def left_jacobian_inverse(vx, vy, w):
    """Inverse of the left Jacobian: ``[[V^-1, -V^-1 q], [0, 1]]`` (see ``left_jacobian``).

    ``V^-1`` from :func:`se2_v_inverse_coeffs`, ``q`` from :func:`se2_q`. Defined for
    |ω| < 2 pi.
    """
    alpha, h = se2_v_inverse_coeffs(w)
    qx, qy = se2_q(vx, vy, w)
    return (
        alpha,
        h,
        -(alpha * qx + h * qy),
        -h,
        alpha,
        h * qx - alpha * qy,
        0.0,
        0.0,
        1.0,
    )
