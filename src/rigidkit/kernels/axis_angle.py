"""Kernels between unit quaternions and (unit axis, angle) pairs."""

from .._engine import kernel
from .quaternion import quat_hemisphere
from .vector import normalize4


@kernel(inputs=[(3,), ()], outputs=[(4,)])
def quat_from_axis_angle(ax, ay, az, angle):
    """``q = (cos(angle/2), sin(angle/2) * axis / |axis|)``; the axis is normalised.

    The axis is normalised by :func:`~rigidkit.kernels.vector.normalize4` (scaled
    by its largest component), so any finite nonzero axis works without overflow
    or underflow.
    """
    ux, uy, uz, _, _ = normalize4(ax, ay, az, 0.0)
    s = sin(0.5 * angle)
    return (cos(0.5 * angle), s * ux, s * uy, s * uz)


@kernel(inputs=[(4,)], outputs=[(3,), ()])
def axis_angle_from_quat(w, x, y, z):
    """Unit axis and angle in [0, pi]; the axis is +x for the identity.

    The quaternion is flipped to ``w >= 0`` first, so the angle never exceeds pi.
    The vector part is normalised by its largest component first
    (:func:`~rigidkit.kernels.vector.normalize4`), so the axis of a tiny rotation
    (``|v|^2`` below the smallest float: 1e-160 rad in float64, 1e-19 in float32)
    is still found instead of falling back to +x.
    """
    w, x, y, z = quat_hemisphere(w, x, y, z)
    ux, uy, uz, _, n = normalize4(x, y, z, 0.0)
    # n >= 0; not ==, which compares structure on SymPy expressions
    return (where(n > 0.0, ux, 1.0), uy, uz, 2.0 * atan2(n, w))
