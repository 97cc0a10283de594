"""Kernels between unit quaternions and (unit axis, angle) pairs."""

from .._engine import kernel


@kernel(inputs=[(3,), ()], outputs=[(4,)])
def quat_from_axis_angle(ax, ay, az, angle):
    """``q = (cos(angle/2), sin(angle/2) * axis / |axis|)``; the axis is normalised.

    The axis is scaled by its largest component before squaring so any finite
    nonzero axis normalises without overflow or underflow.
    """
    m = maximum(maximum(abs(ax), abs(ay)), abs(az))
    m = where(m > 0.0, m, 1.0)
    ax = ax / m
    ay = ay / m
    az = az / m
    n = sqrt(ax * ax + ay * ay + az * az)
    s = sin(0.5 * angle) / n
    return (cos(0.5 * angle), s * ax, s * ay, s * az)


@kernel(inputs=[(4,)], outputs=[(3,), ()])
def axis_angle_from_quat(w, x, y, z):
    """Unit axis and angle in [0, pi]; the axis is +x for the identity.

    The quaternion is flipped to ``w >= 0`` first, so the angle never exceeds pi.
    """
    s = where(w < 0.0, -1.0, 1.0)
    w = s * w
    x = s * x
    y = s * y
    z = s * z
    n = sqrt(x * x + y * y + z * z)
    zero = n == 0.0
    safe = where(zero, 1.0, n)
    return (
        where(zero, 1.0, x / safe),
        where(zero, 0.0, y / safe),
        where(zero, 0.0, z / safe),
        2.0 * atan2(n, w),
    )
