"""Kernels between unit quaternions and rotation vectors ``theta * axis``.

The two helpers here are the exponential and logarithm of SO(3) on quaternions,
written once: the SE(3) and Sim(3) kernels call them for their rotation part.
"""

from .._engine import helper, kernel
from .coefficients import atan_ratio, norm3, sinc
from .matrix import matrix_entries_from_quat
from .quaternion import quat_hemisphere


@helper(numerical=True)
def cos_of_norm(n2, n):
    """``cos(n)`` of a norm ``n = |r|``, given ``n2 = |r|^2`` summed from ``r`` too.

    Autodiff of ``cos`` through the norm (:func:`~.coefficients.norm3`, whose
    derivatives at ``r = 0`` are all 0) gives a Hessian of 0 at ``r = 0`` instead of
    ``-I``: ``|r|`` has no second derivative there. Below ``n2 < 9e-4`` (``n <
    0.03``, the threshold of ``sinc``) the value is the series in ``n2``, a
    polynomial in ``r`` whose derivatives of every order are exact: ``1 - n2/2 +
    n2^2/24 - n2^3/720``, the omitted ``n^8/8!`` < 2e-17 there. Above, the plain
    cosine, accurate to an ulp. The series is a few multiplications beside the
    cosine, where ``1 - n2 versinc2(n)`` (the first fix) cost a second sine: 16.5
    -> 24.7 ns per element in ``from_rotvec``.
    """
    series = 1.0 - 0.5 * n2 * (1.0 - n2 / 12.0 * (1.0 - n2 / 30.0))
    return where(n2 < 9e-4, series, cos(n))


@helper
def half_angle_from_rotvec(rx, ry, rz):
    """``(cos(theta/2), sin(theta/2)/theta, theta)``, ``theta = |r|``: the exponential
    of SO(3) on quaternions is ``q = (c, s r)``.

    ``sinc`` keeps small angles exact; a vector so small that ``|r|^2`` underflows
    gives theta = 0 and q = (1, r/2), still right to the last bit. ``norm3`` keeps
    the gradient finite (``dq/dr = I/2``) at ``r = 0``, where ``d|r|/dr`` is 0/0.

    ``c = cos(theta/2)`` is :func:`cos_of_norm` of ``|r|^2 / 4``: through ``theta``
    alone autodiff gets no second derivative at ``r = 0`` (``|r|`` has none;
    ``norm3`` says 0), and the Hessian of ``c`` there came out 0 instead of
    ``-I/4``. ``2 s^2`` is ``(1 - cos theta)/theta^2`` (``versinc2``, the same
    expression), which the SE(3) exponential takes from here.
    """
    t2 = rx * rx + ry * ry + rz * rz
    theta = norm3(rx, ry, rz)
    half = 0.5 * theta
    return (cos_of_norm(0.25 * t2, half), 0.5 * sinc(half), theta)


@helper
def quat_angle_from_rotvec(rx, ry, rz):
    """``(cos(theta/2), sin(theta/2)/theta * r)`` and ``theta = |r|``, as five scalars.

    See :func:`half_angle_from_rotvec`.
    """
    w, s, theta = half_angle_from_rotvec(rx, ry, rz)
    return (w, s * rx, s * ry, s * rz, theta)


@helper
def quat_entries_from_rotvec(rx, ry, rz):
    """``q = (cos(theta/2), sin(theta/2)/theta * r)``: :func:`quat_angle_from_rotvec`."""
    w, x, y, z, _ = quat_angle_from_rotvec(rx, ry, rz)
    return (w, x, y, z)


@helper
def rotvec_entries_from_quat(w, x, y, z):
    """Rotation vector ``r`` of ``q`` with angle in [0, pi], as three scalars.

    ``theta = 2 atan2(|v|, |w|)`` and ``r = theta / |v| * v`` after flipping ``q`` to
    ``w >= 0``; ``atan_ratio`` carries the small-angle series. Scale-invariant, so
    no normalisation is needed, as long as ``|v|^2`` neither overflows nor
    underflows (``|q|`` within 1e-150 ... 1e150 in float64, 1e-18 ... 1e18 in
    float32); ``Rotation`` stores unit quaternions. The angle itself is
    :func:`~rigidkit.kernels.quaternion.quat_angle`, whose flip and norm are the
    same expressions as here (one evaluation once inlined).
    """
    w, x, y, z = quat_hemisphere(w, x, y, z)
    n = norm3(x, y, z)  # a finite gradient at the identity
    k = 2.0 * atan_ratio(n, w)
    return (k * x, k * y, k * z)


@kernel(inputs=[(3,)], outputs=[(4,)])
def quat_from_rotvec(rx, ry, rz):
    """``q = (cos(theta/2), sin(theta/2)/theta * r)``, ``theta = |r|``.

    See :func:`half_angle_from_rotvec`.
    """
    return quat_entries_from_rotvec(rx, ry, rz)


@kernel(inputs=[(4,)], outputs=[(3,)])
def rotvec_from_quat(w, x, y, z):
    """Rotation vector with angle in [0, pi] of a (not necessarily unit) quaternion.

    See :func:`rotvec_entries_from_quat`.
    """
    return rotvec_entries_from_quat(w, x, y, z)


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
