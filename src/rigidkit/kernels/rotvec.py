"""Kernels between unit quaternions and rotation vectors ``theta * axis``."""

from .._engine import kernel
from .coefficients import atan_ratio, sinc, versinc2  # noqa: F401  (bound by name)


@kernel(inputs=[(3,)], outputs=[(4,)])
def quat_from_rotvec(rx, ry, rz):
    """``q = (cos(theta/2), sin(theta/2)/theta * r)``, ``theta = |r|``.

    ``sinc`` keeps small angles exact; a vector so small that ``|r|^2`` underflows
    gives theta = 0 and q = (1, r/2), still right to the last bit.
    """
    theta = sqrt(rx * rx + ry * ry + rz * rz)
    half = 0.5 * theta
    s = 0.5 * sinc(half)
    return (cos(half), s * rx, s * ry, s * rz)


@kernel(inputs=[(4,)], outputs=[(3,)])
def rotvec_from_quat(w, x, y, z):
    """Rotation vector with angle in [0, pi] of a (not necessarily unit) quaternion.

    ``theta = 2 atan2(|v|, |w|)`` and ``r = theta / |v| * v`` after flipping ``q`` to
    ``w >= 0``; ``atan_ratio`` carries the small-angle series. Scale-invariant, so
    no normalisation is needed.
    """
    s = where(w < 0.0, -1.0, 1.0)
    w = s * w
    x = s * x
    y = s * y
    z = s * z
    n = sqrt(x * x + y * y + z * z)
    k = 2.0 * atan_ratio(n, w)
    return (k * x, k * y, k * z)


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def matrix_from_rotvec(rx, ry, rz):
    """Rodrigues: ``R = I + sinc(t) hat(r) + (1 - cos t)/t^2 hat(r)^2``, ``t = |r|``."""
    theta = sqrt(rx * rx + ry * ry + rz * rz)
    a = sinc(theta)
    b = versinc2(theta)
    xx = rx * rx
    yy = ry * ry
    zz = rz * rz
    xy = rx * ry
    xz = rx * rz
    yz = ry * rz
    return (
        1.0 - b * (yy + zz),
        b * xy - a * rz,
        b * xz + a * ry,
        b * xy + a * rz,
        1.0 - b * (xx + zz),
        b * yz - a * rx,
        b * xz - a * ry,
        b * yz + a * rx,
        1.0 - b * (xx + yy),
    )
