"""Kernels of SO(3): its Lie vocabulary on unit quaternions and rotation vectors.

Everything SO(3) has as a Lie group is here, as for the other groups
(:mod:`.so2`, :mod:`.se2`, :mod:`.se3`, :mod:`.sim3`): ``hat`` and ``vee``; the
exponential and logarithm, between rotation vectors ``r = theta * axis`` (radians)
and unit quaternions (Hamilton, scalar first; the rotation vector's conversions
are these two maps); the left Jacobian, its inverse and the Lie bracket; and the
rates of a rotation-vector curve (its Jacobian applied, and that product's
derivative). The exp and log helpers are written once: the SE(3), Sim(3) and
geodesic kernels call them for their rotation part.

Jacobians (Solà, Deray & Atchuthan 2018, "A micro Lie theory for state estimation
in robotics", eqs. 143-146): the left Jacobian ``J_l(w)`` satisfies ``exp(w + d) ~
exp(J_l(w) d) exp(w)`` to first order in ``d``; the right Jacobian is ``J_r(w) =
J_l(-w)``, with ``exp(w + d) ~ exp(w) exp(J_r(w) d)``. With ``W = hat(w)`` and
``theta = |w|``::

    J_l    = I + (1 - cos t)/t^2 W + (t - sin t)/t^3 W^2      (versinc2, sin_defect3)
    J_l^-1 = I - W/2 + (1 - (t/2) cot(t/2))/t^2 W^2             (cot_defect2)

Every special case (small angles) lives in the coefficient helpers of
:mod:`.coefficients`. The Jacobian helpers are shared with the SE(3) kernels (the
translation of the exp of a twist is ``J_l(w) v``).

Rates of a rotation-vector curve: for ``R(t) = R0 exp(hat(r(t)))`` the body angular
velocity (``R^T dR/dt = hat(omega)``) is ``omega = J_r(r) r'`` with ``J_r(r) = I -
a hat(r) + b hat(r)^2``, ``a = (1 - cos t)/t^2`` (versinc2), ``b = (t - sin t)/t^3``
(sin_defect3), ``t = |r|``. Its derivative is::

    omega' = J_r(r) r'' + (dJ_r/dt) r'
           = J_r(r) r'' + (r.r') (k1 r x r' + k2 r x (r x r')) + b r' x (r x r')

with ``k1 = -(da/dt)/t = (2 (1 - cos t) - t sin t)/t^4`` and
``k2 = (db/dt)/t = (3 sin t - 2t - t cos t)/t^5`` (the angle's rate is
``(r.r')/t``). These are the formulas of scipy's ``RotationSpline``; the
coefficients come from the shared helpers, without thresholds of their own.
"""

from .._engine import helper, kernel
from .coefficients import (
    atan_ratio,
    cot_defect2,
    norm3,
    sin_cos_defect5,
    sin_defect3,
    sinc,
    versinc2,
)
from .matrix import matrix_entries_from_quat
from .quaternion import quat_hemisphere
from .vector import cross3, hat_poly_apply

# -- the Lie algebra so(3) -------------------------------------------------------------


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def hat(wx, wy, wz):
    """Skew matrix ``hat(w)`` with ``hat(w) @ v == cross(w, v)``."""
    return (0.0, -wz, wy, wz, 0.0, -wx, -wy, wx, 0.0)


@kernel(inputs=[(3, 3)], outputs=[(3,)])
def vee(m00, m01, m02, m10, m11, m12, m20, m21, m22):
    """Inverse of ``hat``, from the skew-symmetric part ``(W - W^T) / 2``."""
    return (0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01))


# -- exp and log: rotation vectors and unit quaternions --------------------------------


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


@helper(numerical=True)
def half_norm(rx, ry, rz, t2):
    """``|r| / 2`` from ``t2 = |r|^2``, for any finite ``r``.

    Above ``|r| > 1e18`` (float32's ``|r|^2`` overflows from 1e19, float64's from
    1e154) the squared norm is taken of ``r`` scaled by a power of two and the root
    scaled back, so ``|r| / 2`` stays finite up to float64's largest components,
    and the exponential of a rotation vector of ``1e300`` rad is a unit
    quaternion: the cosine and sine of the half angle reduce it exactly modulo
    ``2 pi`` (glibc's, NumPy's, torch's and XLA's do, to the last bit). Below, it
    is ``0.5 sqrt(t2)`` as before, the root at a safe argument (as
    :func:`~.coefficients.norm3`) so that the gradient is finite at ``r = 0``. One
    root either way; the numba loop of ``quat_from_rotvec`` takes 5-8% longer for
    it (1e6 rotation vectors, interleaved runs).
    """
    # |r| > 1e18 (t2 inf once it overflows) and |r| > 1e150 (float64 only: in
    # float32 1e-300 is 0, and 0 * t2 is 0 or, for an infinite t2, NaN: not > 1).
    big = t2 > 1e36
    huge = t2 * 1e-300 > 1.0
    # Exact scalings by powers of two, no division: 2^-66 for float32's range, and
    # 2^-594 beyond 1e150. No constant beyond float32's range: in float32 the
    # float64 ones become 0 and are never selected (NumPy warns on casting an
    # overflowing Python float, not an underflowing one).
    k = where(big, 1.3552527156068805e-20, 1.0) * where(huge, 1.1380524797363597e-159, 1.0)
    ux = rx * k
    uy = ry * k
    uz = rz * k
    s = where(big, ux * ux + uy * uy + uz * uz, t2)
    pos = s > 0.0
    c = where(huge, 7.378697629483821e19, 1.0)  # 2^66, and 2^528 = c^8
    c2 = c * c
    c4 = c2 * c2
    back = where(big, 3.6893488147419103e19, 0.5) * (c4 * c4)
    return back * where(pos, sqrt(where(pos, s, 1.0)), 0.0)


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
    half = half_norm(rx, ry, rz, t2)
    return (cos_of_norm(0.25 * t2, half), 0.5 * sinc(half), 2.0 * half)


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


# -- Jacobians and the bracket ---------------------------------------------------------


@helper
def eye_hat_hat2(wx, wy, wz, a, b):
    """Entries (row-major) of ``I + a hat(w) + b hat(w)^2``.

    Uses ``hat(w)^2 = w w^T - |w|^2 I``, so the diagonal is ``1 - b (|w|^2 - w_i^2)``.
    """
    xx = wx * wx
    yy = wy * wy
    zz = wz * wz
    bxy = b * wx * wy
    bxz = b * wx * wz
    byz = b * wy * wz
    return (
        1.0 - b * (yy + zz),
        bxy - a * wz,
        bxz + a * wy,
        bxy + a * wz,
        1.0 - b * (xx + zz),
        byz - a * wx,
        bxz - a * wy,
        byz + a * wx,
        1.0 - b * (xx + yy),
    )


@helper
def eye_hat_hat2_apply(wx, wy, wz, a, b, vx, vy, vz):
    """``(I + a hat(w) + b hat(w)^2) v = v + a w x v + b w x (w x v)``."""
    return hat_poly_apply(wx, wy, wz, 1.0, a, b, vx, vy, vz)


@helper
def so3_left_jacobian_entries(wx, wy, wz):
    """Entries of ``J_l(w) = I + versinc2(t) W + sin_defect3(t) W^2``, ``t = |w|``."""
    theta = norm3(wx, wy, wz)
    return eye_hat_hat2(wx, wy, wz, versinc2(theta), sin_defect3(theta))


@helper
def so3_left_jacobian_inverse_entries(wx, wy, wz):
    """Entries of ``J_l(w)^-1 = I - W/2 + cot_defect2(t) W^2`` (singular at t = 2 pi)."""
    theta = norm3(wx, wy, wz)
    return eye_hat_hat2(wx, wy, wz, -0.5, cot_defect2(theta))


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def left_jacobian(wx, wy, wz):
    """Left Jacobian ``J_l(w)`` of SO(3): ``exp(w + d) ~ exp(J_l d) exp(w)``."""
    return so3_left_jacobian_entries(wx, wy, wz)


@kernel(inputs=[(3,)], outputs=[(3, 3)])
def left_jacobian_inverse(wx, wy, wz):
    """Inverse of the left Jacobian of SO(3), finite for ``|w| < 2 pi``."""
    return so3_left_jacobian_inverse_entries(wx, wy, wz)


@kernel(inputs=[(3,), (3,)], outputs=[(3,)])
def bracket(ux, uy, uz, vx, vy, vz):
    """Lie bracket of so(3): ``[hat(u), hat(v)] = hat(u x v)``."""
    return cross3(ux, uy, uz, vx, vy, vz)


# -- rates of a rotation-vector curve --------------------------------------------------


@helper
def versinc2_rate(x):
    """``(2 (1 - cos x) - x sin x) / x**4`` (1/12 at 0), minus ``d versinc2/dx`` over x.

    With ``y = x/2`` the numerator is ``4 sin(y) (sin y - y cos y)``, and
    ``sin y - y cos y = y^3 (versinc2(y) - sin_defect3(y))`` (see ``cot_defect2``),
    so the coefficient is ``cot_defect2(x) sinc(y)^2``: products of accurate
    factors, no cancellation, the series in those helpers.
    """
    s = sinc(0.5 * x)
    return cot_defect2(x) * s * s


@kernel(inputs=[(3,), (3,)], outputs=[(3,)])
def body_rate_from_rotvec_rate(rx, ry, rz, dx, dy, dz):
    """Body angular velocity ``J_r(r) r'`` of ``R0 exp(hat(r(t)))``, radians per time."""
    theta = norm3(rx, ry, rz)
    return eye_hat_hat2_apply(rx, ry, rz, -versinc2(theta), sin_defect3(theta), dx, dy, dz)


@kernel(inputs=[(3,), (3,), (3,)], outputs=[(3,)])
def body_acceleration_from_rotvec_rates(rx, ry, rz, dx, dy, dz, ax, ay, az):
    """Body angular acceleration ``J_r(r) r'' + (dJ_r/dt) r'`` (see the module doc)."""
    theta = norm3(rx, ry, rz)
    b = sin_defect3(theta)
    jx, jy, jz = eye_hat_hat2_apply(rx, ry, rz, -versinc2(theta), b, ax, ay, az)
    p = rx * dx + ry * dy + rz * dz
    cx, cy, cz = cross3(rx, ry, rz, dx, dy, dz)
    ccx, ccy, ccz = cross3(rx, ry, rz, cx, cy, cz)
    dcx, dcy, dcz = cross3(dx, dy, dz, cx, cy, cz)
    k1 = p * versinc2_rate(theta)
    k2 = -2.0 * p * sin_cos_defect5(theta)
    return (
        jx + k1 * cx + k2 * ccx + b * dcx,
        jy + k1 * cy + k2 * ccy + b * dcy,
        jz + k1 * cz + k2 * ccz + b * dcz,
    )
