"""Kernels of Sim(3), the similarity transforms ``x -> s R x + t``.

An element is stored as 8 components ``(w, x, y, z, tx, ty, tz, s)``: a unit
quaternion (Hamilton, scalar first), the translation and the scale ``s > 0``.
Tangent vectors (twists) are ``(v, omega, sigma)`` (7 components), ``sigma = log s``,
with ``hat(xi) = [[hat(omega) + sigma I, v], [0, 0]]``.

The exponential: ``hat(omega)`` and ``sigma I`` commute, so the 3x3 block is
``e^sigma R``, ``R = exp(hat(omega))``, and the translation is ``V v`` with

    V = int_0^1 e^(u sigma) R(u omega) du = a I + b hat(omega) + c hat(omega)^2,

    a = (e^sigma - 1) / sigma,
    b = int_0^1 e^(u sigma) sin(u theta) / theta du,
    c = int_0^1 e^(u sigma) (1 - cos(u theta)) / theta^2 du,   theta = |omega|.

With ``z = sigma + i theta`` and ``f(z) = (e^z - 1) / z``: ``a = f(sigma)``,
``b = Im f(z) / theta`` and ``c = (f(sigma) - Re f(z)) / theta^2``. On the axis of
``omega`` V multiplies by ``f(sigma)``; in the plane orthogonal to it, by the
complex number ``f(z)``. So ``V^-1 = alpha I + beta hat(omega) + gamma hat(omega)^2``
with ``alpha = 1 / a``, and ``1 / f(z)`` in the plane, which gives (see
:func:`sim3_log`) ``beta = -b / |f|^2``, ``gamma = (b^2 - c Re f) / (a |f|^2)``. For
``theta <= pi`` (the range of ``log``) ``f(z)`` is never 0, so V is invertible.
"""

from .._engine import helper, kernel
from .coefficients import exprel, sinc, versinc2
from .matrix import matrix_from_quat
from .quaternion import quat_angle, quat_apply, quat_compose
from .so3 import quat_angle_from_rotvec, rotvec_entries_from_quat
from .vector import cross3, hat_matmul, hat_poly_apply


@helper(numerical=True)
def sim3_v_coeffs(sigma, theta):
    """``(a, b, c)`` of ``V = a I + b hat(w) + c hat(w)^2`` (module docs), theta >= 0.

    Below ``|z| < 1.5`` (``z = sigma + i theta``) the closed forms cancel (their
    error grows like eps / |z|^2), so we expand ``sin`` and ``1 - cos`` under the
    integrals instead:

        b = sum_j (-theta^2)^j E_{2j+1}(sigma) / (2j+1)!,
        c = sum_j (-theta^2)^j E_{2j+2}(sigma) / (2j+2)!,
        E_k(sigma) = int_0^1 u^k e^(u sigma) du,

    summed by Horner's rule for j = 11 ... 0 (the first omitted term, 1.5^24 / 25!,
    is < 1e-17 relative at theta = 1.5). ``E_k`` comes from the downward recurrence
    ``E_k = (e^sigma - sigma E_{k+1}) / (k+1)`` (integration by parts), which damps
    any error by ``|sigma| / (k+1) <= 1.5 / (k+1)`` per step: started at
    ``E_28 ~ e^sigma / (29 + sigma)`` (relative error ~ sigma^2 / 28^2), it is
    exact to rounding by ``E_24``, the last one used. Each quantity refers to the
    previous one once, so the SymPy twin stays small.

    Above the threshold, the closed forms

        b = (sigma e^sigma sinc(theta) - (e^sigma cos(theta) - 1)) / |z|^2
        c = (sigma e^sigma versinc2(theta) + a - e^sigma sinc(theta)) / |z|^2

    lose at most about 5 ulp just above it, less further out. Measured against
    mpmath quadrature (1 ulp = 2^-52 relative): ``a`` (:func:`exprel`) 1 ulp, ``b``
    <= 3, ``c`` <= 5. The series branch runs on zeroed arguments outside its range,
    so both branches stay finite (and so do their gradients).
    """
    z2 = sigma * sigma + theta * theta
    small = z2 < 2.25
    ss = where(small, sigma, 0.0)
    tt = where(small, theta * theta, 0.0)
    e = exp(sigma)
    es = where(small, e, 1.0)  # = exp(ss)
    ek = es / (29.0 + ss)  # E_28
    for k in range(27, 24, -1):
        ek = (es - ss * ek) / (k + 1.0)  # E_27, E_26, E_25
    sb = 0.0
    sc = 0.0
    for j in range(11, -1, -1):
        ek = (es - ss * ek) / (2.0 * j + 3.0)  # E_{2j+2}
        sc = ek - tt * sc / ((2.0 * j + 3.0) * (2.0 * j + 4.0))
        ek = (es - ss * ek) / (2.0 * j + 2.0)  # E_{2j+1}
        sb = ek - tt * sb / ((2.0 * j + 2.0) * (2.0 * j + 3.0))
    a = exprel(sigma)
    safe = where(small, 1.0, z2)
    b = (sigma * e * sinc(theta) - (e * cos(theta) - 1.0)) / safe
    c = (sigma * e * versinc2(theta) + a - e * sinc(theta)) / safe
    return (a, where(small, sb, b), where(small, 0.5 * sc, c))


@kernel(inputs=[(7,)], outputs=[(8,)])
def sim3_exp(vx, vy, vz, wx, wy, wz, sigma):
    """Similarity ``expm(hat(xi))`` of a twist ``(v, omega, sigma)``: ``(q, V v, e^sigma)``.

    The rotation is ``q = (cos(theta/2), sinc(theta/2) omega / 2)`` (exact for small
    angles); ``V`` as in the module docs, applied as ``a v + b w x v + c w x (w x v)``.
    """
    qw, qx, qy, qz, theta = quat_angle_from_rotvec(wx, wy, wz)
    a, b, c = sim3_v_coeffs(sigma, theta)
    tx, ty, tz = hat_poly_apply(wx, wy, wz, a, b, c, vx, vy, vz)
    return (qw, qx, qy, qz, tx, ty, tz, exp(sigma))


@kernel(inputs=[(8,)], outputs=[(7,)])
def sim3_log(w, x, y, z, tx, ty, tz, s):
    """Twist ``(V^-1 t, omega, log s)`` with ``|omega|`` in [0, pi].

    ``omega`` is the rotation vector of ``q`` (``2 atan2(|u|, |w|) u / |u|``, sign
    flipped to ``w >= 0``, series from ``atan_ratio``). ``V^-1`` restricted to the
    plane orthogonal to ``omega`` is ``1 / f(z)``: writing ``f = Re f + i b theta``
    with ``Re f = a - c theta^2``, ``1 / f = conj(f) / |f|^2`` gives
    ``beta = -b / |f|^2`` and ``gamma = (1/a - Re(1/f)) / theta^2 = (b^2 - c Re f) /
    (a |f|^2)`` (no 1/theta left). All of ``b, c, Re f`` are divided by ``a`` first
    so ``|f|^2`` does not overflow for scales up to e^700.
    """
    wx, wy, wz = rotvec_entries_from_quat(w, x, y, z)
    theta = quat_angle(w, x, y, z)
    sigma = log(where(s > 0.0, s, 1.0))
    a, b, c = sim3_v_coeffs(sigma, theta)
    b1 = b / a
    c1 = c / a
    re1 = 1.0 - c1 * theta * theta
    im1 = b1 * theta
    f2 = re1 * re1 + im1 * im1
    alpha = 1.0 / a
    beta = -b1 / (a * f2)
    gamma = (b1 * b1 - c1 * re1) / (a * f2)
    vx, vy, vz = hat_poly_apply(wx, wy, wz, alpha, beta, gamma, tx, ty, tz)
    return (vx, vy, vz, wx, wy, wz, sigma)


@kernel(inputs=[(8,), (8,)], outputs=[(8,)])
def sim3_compose(w1, x1, y1, z1, tx1, ty1, tz1, s1, w2, x2, y2, z2, tx2, ty2, tz2, s2):
    """``S1 S2``: ``(q1 q2, s1 R1 t2 + t1, s1 s2)`` (``S2`` applied first).

    ``q1 q2`` is renormalised (:func:`~rigidkit.kernels.quaternion.quat_compose`).
    """
    w, x, y, z = quat_compose(w1, x1, y1, z1, w2, x2, y2, z2)
    rx, ry, rz = quat_apply(w1, x1, y1, z1, tx2, ty2, tz2)
    return (w, x, y, z, s1 * rx + tx1, s1 * ry + ty1, s1 * rz + tz1, s1 * s2)


@kernel(inputs=[(8,), (3,)], outputs=[(3,)])
def sim3_apply(w, x, y, z, tx, ty, tz, s, px, py, pz):
    """``s R p + t`` for a point ``p``."""
    rx, ry, rz = quat_apply(w, x, y, z, px, py, pz)
    return (s * rx + tx, s * ry + ty, s * rz + tz)


@kernel(inputs=[(8,)], outputs=[(8,)])
def sim3_inverse(w, x, y, z, tx, ty, tz, s):
    """``(q*, -R^T t / s, 1 / s)``: the inverse of ``p -> s R p + t``."""
    inv_s = 1.0 / s
    rx, ry, rz = quat_apply(w, -x, -y, -z, tx, ty, tz)
    return (w, -x, -y, -z, -inv_s * rx, -inv_s * ry, -inv_s * rz, inv_s)


@kernel(inputs=[(8,)], outputs=[(4, 4)])
def sim3_matrix(w, x, y, z, tx, ty, tz, s):
    """Homogeneous matrix ``[[s R, t], [0, 1]]``."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = matrix_from_quat(w, x, y, z)
    return (
        s * r00, s * r01, s * r02, tx,
        s * r10, s * r11, s * r12, ty,
        s * r20, s * r21, s * r22, tz,
        0.0, 0.0, 0.0, 1.0,
    )  # fmt: skip


@kernel(inputs=[(8,)], outputs=[(7, 7)])
def sim3_adjoint(w, x, y, z, tx, ty, tz, s):
    """``Ad`` with ``X hat(xi) X^-1 = hat(Ad xi)``, twists ``(v, omega, sigma)``:

    ``[[s R, hat(t) R, -t], [0, R, 0], [0, 0, 1]]``, from
    ``X hat(xi) X^-1 = [[hat(R w) + sigma I, s R v - (hat(R w) + sigma I) t], [0, 0]]``.
    """
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = matrix_from_quat(w, x, y, z)
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = hat_matmul(
        tx, ty, tz, r00, r01, r02, r10, r11, r12, r20, r21, r22
    )
    return (
        s * r00, s * r01, s * r02, m00, m01, m02, -tx,
        s * r10, s * r11, s * r12, m10, m11, m12, -ty,
        s * r20, s * r21, s * r22, m20, m21, m22, -tz,
        0.0, 0.0, 0.0, r00, r01, r02, 0.0,
        0.0, 0.0, 0.0, r10, r11, r12, 0.0,
        0.0, 0.0, 0.0, r20, r21, r22, 0.0,
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    )  # fmt: skip


@kernel(inputs=[(7,)], outputs=[(4, 4)])
def sim3_hat(vx, vy, vz, wx, wy, wz, sigma):
    """``[[hat(omega) + sigma I, v], [0, 0]]`` of a twist ``(v, omega, sigma)``."""
    return (
        sigma, -wz, wy, vx,
        wz, sigma, -wx, vy,
        -wy, wx, sigma, vz,
        0.0, 0.0, 0.0, 0.0,
    )  # fmt: skip


@kernel(inputs=[(4, 4)], outputs=[(7,)])
def sim3_vee(
    m00, m01, m02, m03, m10, m11, m12, m13, m20, m21, m22, m23, m30, m31, m32, m33
):
    """Inverse of ``sim3_hat``: the projection onto sim(3) (skew part, mean diagonal).

    ``sigma`` is the mean of the diagonal written as ``m00 + ((m11 - m00) + (m22 -
    m00)) / 3``, so that ``vee(hat(xi))`` returns ``sigma`` bit for bit (the plain
    ``(m00 + m11 + m22) / 3`` of three equal numbers is off by an ulp for 15% of
    them).
    """
    return (
        m03,
        m13,
        m23,
        0.5 * (m21 - m12),
        0.5 * (m02 - m20),
        0.5 * (m10 - m01),
        m00 + ((m11 - m00) + (m22 - m00)) / 3.0,
    )


@kernel(inputs=[(7,), (7,)], outputs=[(7,)])
def sim3_bracket(vx, vy, vz, wx, wy, wz, s, ux, uy, uz, px, py, pz, r):
    """``vee([hat(xi1), hat(xi2)])`` = ``(w1 x u + s1 u - p x v - r v, w1 x p, 0)``.

    For ``xi1 = (v, w, s)``, ``xi2 = (u, p, r)``: the ``sigma I`` parts commute, so
    the bracket has no scale component.
    """
    ax, ay, az = cross3(wx, wy, wz, ux, uy, uz)
    bx, by, bz = cross3(px, py, pz, vx, vy, vz)
    cx, cy, cz = cross3(wx, wy, wz, px, py, pz)
    return (
        ax + s * ux - bx - r * vx,
        ay + s * uy - by - r * vy,
        az + s * uz - bz - r * vz,
        cx,
        cy,
        cz,
        0.0,
    )


@kernel(inputs=[(7,)], outputs=[(7, 7)])
def sim3_ad(vx, vy, vz, wx, wy, wz, s):
    """Small adjoint ``ad(xi) = [[hat(w) + s I, hat(v), -v], [0, hat(w), 0], [0, 0, 0]]``.

    ``ad(xi1) @ xi2 == bracket(xi1, xi2)``.
    """
    return (
        s, -wz, wy, 0.0, -vz, vy, -vx,
        wz, s, -wx, vz, 0.0, -vx, -vy,
        -wy, wx, s, -vy, vx, 0.0, -vz,
        0.0, 0.0, 0.0, 0.0, -wz, wy, 0.0,
        0.0, 0.0, 0.0, wz, 0.0, -wx, 0.0,
        0.0, 0.0, 0.0, -wy, wx, 0.0, 0.0,
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    )  # fmt: skip
