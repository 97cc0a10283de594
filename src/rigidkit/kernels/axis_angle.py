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
    The vector part is scaled by its largest component before squaring, so the
    axis of a tiny rotation (``|v|^2`` below the smallest float: 1e-160 rad in
    float64, 1e-19 in float32) is still found instead of falling back to +x.
    """
    s = where(w < 0.0, -1.0, 1.0)
    w = s * w
    x = s * x
    y = s * y
    z = s * z
    m = maximum(maximum(abs(x), abs(y)), abs(z))
    zero = m <= 0.0  # m >= 0; not ==, which compares structure on SymPy expressions
    safe = where(zero, 1.0, m)
    x = x / safe
    y = y / safe
    z = z / safe
    n = sqrt(x * x + y * y + z * z)  # in [1, sqrt(3)] unless zero
    safe_n = where(zero, 1.0, n)
    return (
        where(zero, 1.0, x / safe_n),
        where(zero, 0.0, y / safe_n),
        where(zero, 0.0, z / safe_n),
        2.0 * atan2(n * m, w),
    )
