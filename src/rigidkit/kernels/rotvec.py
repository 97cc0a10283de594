"""Kernels between unit quaternions and rotation vectors ``theta * axis``."""

from .._engine import helper, kernel
from .coefficients import atan_ratio, norm3, sinc  # noqa: F401  (bound by name)
from .matrix import matrix_entries_from_quat  # noqa: F401  (bound by name)


@helper
def quat_entries_from_rotvec(rx, ry, rz):
    """``(cos(theta/2), sin(theta/2)/theta * r)``, ``theta = |r|``, as four scalars.

    ``sinc`` keeps small angles exact; a vector so small that ``|r|^2`` underflows
    gives theta = 0 and q = (1, r/2), still right to the last bit. ``norm3`` keeps
    the gradient finite (``dq/dr = I/2``) at ``r = 0``, where ``d|r|/dr`` is 0/0.
    """
    theta = norm3(rx, ry, rz)
    half = 0.5 * theta
    s = 0.5 * sinc(half)
    return (cos(half), s * rx, s * ry, s * rz)


@kernel(inputs=[(3,)], outputs=[(4,)])
def quat_from_rotvec(rx, ry, rz):
    """``q = (cos(theta/2), sin(theta/2)/theta * r)``, ``theta = |r|``.

    See :func:`quat_entries_from_rotvec`.
    """
    return quat_entries_from_rotvec(rx, ry, rz)


@kernel(inputs=[(4,)], outputs=[(3,)])
def rotvec_from_quat(w, x, y, z):
    """Rotation vector with angle in [0, pi] of a (not necessarily unit) quaternion.

    ``theta = 2 atan2(|v|, |w|)`` and ``r = theta / |v| * v`` after flipping ``q`` to
    ``w >= 0``; ``atan_ratio`` carries the small-angle series. Scale-invariant, so
    no normalisation is needed, as long as ``|v|^2`` neither overflows nor
    underflows (``|q|`` within 1e-150 ... 1e150 in float64, 1e-18 ... 1e18 in
    float32); ``Rotation`` stores unit quaternions.
    """
    s = where(w < 0.0, -1.0, 1.0)
    w = s * w
    x = s * x
    y = s * y
    z = s * z
    n = norm3(x, y, z)  # a finite gradient at the identity
    k = 2.0 * atan_ratio(n, w)
    return (k * x, k * y, k * z)


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def matrix_from_rotvec(rx, ry, rz):
    """Rodrigues: ``R = I + sin(t)/t hat(r) + (1 - cos t)/t^2 hat(r)^2``, ``t = |r|``.

    Evaluated through the half-angle quaternion ``q = (cos(t/2), sin(t/2)/t r)``,
    which is the same formula (``sin t / t = 2 cos(t/2) sin(t/2)/t``, ``(1 - cos
    t)/t^2 = 2 (sin(t/2)/t)^2``) with every term at most 1: the textbook form sums
    ``1 - (1 - cos t)(1 - a_x^2)``, terms up to 2, and measured 1.2e-15 against
    mpmath at large angles; this one 8e-16 (from the rounding of ``|r|`` itself).
    """
    w, x, y, z = quat_entries_from_rotvec(rx, ry, rz)
    return matrix_entries_from_quat(w, x, y, z)
