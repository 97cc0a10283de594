"""Kernels of inertial navigation: IMU steps on the Galilean group, and prediction.

An IMU sample is a body angular rate ``w`` (rad/s, gyroscope) and a specific force
``f = R^T (a - g)`` (m/s^2, accelerometer), both in the body frame. Over a step of
duration ``h`` the navigation state ``(R, v, p)`` obeys ``R' = R hat(w)``,
``v' = R f + g``, ``p' = v`` in a non-rotating navigation frame (``world``).

The part driven by the IMU alone is an element of the Galilean group SGal(3),
stored as 11 numbers ``(q, dv, dp, dt)``: a unit quaternion (Hamilton, scalar
first), a velocity and a position increment, and a duration, with the product
(Kelly 2023, "All about the Galilean group SGal(3)", Sec. 3)::

    (R1, v1, p1, t1) (R2, v2, p2, t2) = (R1 R2, v1 + R1 v2, p1 + v1 t2 + R1 p2, t1 + t2)

The preintegrated measurement of Forster et al. 2017 (``Delta R, Delta v, Delta p``,
eqs. 26-33) is the product of the steps of a window, and the state at its end is
``R_j = R_i dR``, ``v_j = v_i + g t + R_i dv``, ``p_j = p_i + v_i t + g t^2/2 + R_i dp``
(their eq. 44), :func:`nav_predict`. Steps:

* ``exact``, :func:`imu_step_exact`: the sample held over the step, the exponential
  of ``h (w, f, 0, 1)`` in sgal(3): ``(exp(h w), h J_l(h w) f, h^2 N(h w) f, h)`` with
  ``J_l = I + a W + b W^2`` (SO(3)'s left Jacobian) and
  ``N = int_0^1 u J_l(u theta) du = I/2 + b W + c W^2``, ``W = hat(h w)``,
  ``a = versinc2``, ``b = sin_defect3``, ``c = cos_defect4`` of ``|h w|``;
* ``forster``, :func:`imu_step_forster`: Forster's recursion (eqs. 26-33),
  ``(exp(h w), h f, h^2 f / 2, h)``;
* ``midpoint`` (VINS-Mono, Qin et al. 2018, Sec. IV-A): the mean rate of the two
  samples of a step and the mean of their specific forces rotated into the step's
  start frame, ``(E, h m, h^2 m / 2, h)``, ``E = exp(h (w0 + w1)/2)``,
  ``m = (f0 + E f1) / 2``;
* ``rk4``, :func:`imu_step_rk4`: Runge-Kutta-Munthe-Kaas of order 4 in sgal(3) for
  a smooth signal, from its values at the start, middle and end of the step.
"""

from ..._engine import helper, kernel
from ..coefficients import cos_defect4, norm3, sin_defect3, versinc2
from ..quaternion import quat_apply, quat_multiply
from ..so3 import (
    eye_hat_hat2_apply,
    half_angle_from_rotvec,
    quat_entries_from_rotvec,
)
from ..vector import cross3, hat_poly_apply, renormalize4


@helper
def galilean_entries(ox, oy, oz, fx, fy, fz, h):
    """The exact step ``(exp(h w), h J_l(h w) f, h^2 N(h w) f, h)`` as 11 scalars."""
    tx, ty, tz = h * ox, h * oy, h * oz
    qw, s, theta = half_angle_from_rotvec(tx, ty, tz)
    b = sin_defect3(theta)
    vx, vy, vz = eye_hat_hat2_apply(tx, ty, tz, 2.0 * s * s, b, fx, fy, fz)
    px, py, pz = hat_poly_apply(tx, ty, tz, 0.5, b, cos_defect4(theta), fx, fy, fz)
    hh = h * h
    return (
        qw,
        s * tx,
        s * ty,
        s * tz,
        h * vx,
        h * vy,
        h * vz,
        hh * px,
        hh * py,
        hh * pz,
        h,
    )


@kernel(inputs=[(3,), (3,), ()], outputs=[(11,)])
def imu_step_exact(ox, oy, oz, fx, fy, fz, h):
    """The step of a sample held over ``h``: ``exp(h (w, f, 0, 1))`` of sgal(3)."""
    return galilean_entries(ox, oy, oz, fx, fy, fz, h)


@kernel(inputs=[(3,), (3,), ()], outputs=[(11,)])
def imu_step_forster(ox, oy, oz, fx, fy, fz, h):
    """Forster et al. 2017, eqs. 26-33, one step: ``(exp(h w), h f, h^2 f / 2, h)``."""
    qw, qx, qy, qz = quat_entries_from_rotvec(h * ox, h * oy, h * oz)
    k = 0.5 * h * h
    return (qw, qx, qy, qz, h * fx, h * fy, h * fz, k * fx, k * fy, k * fz, h)


@helper
def vins_mean(ax, ay, az, fx, fy, fz, bx, by, bz, gx, gy, gz, h):
    """``(E, m)`` of VINS-Mono's midpoint step: ``E = exp(h (w0 + w1)/2)`` (its
    quaternion) and ``m = (f0 + E f1) / 2``, as 7 scalars."""
    qw, qx, qy, qz = quat_entries_from_rotvec(
        0.5 * h * (ax + bx), 0.5 * h * (ay + by), 0.5 * h * (az + bz)
    )
    ex, ey, ez = quat_apply(qw, qx, qy, qz, gx, gy, gz)
    return (qw, qx, qy, qz, 0.5 * (fx + ex), 0.5 * (fy + ey), 0.5 * (fz + ez))


@kernel(inputs=[(3,), (3,), (3,), (3,), ()], outputs=[(11,)])
def imu_step_midpoint(ax, ay, az, fx, fy, fz, bx, by, bz, gx, gy, gz, h):
    """VINS-Mono's step from samples ``(w0, f0)`` and ``(w1, f1)``: ``(E, h m,
    h^2 m / 2, h)`` (module doc)."""
    qw, qx, qy, qz, mx, my, mz = vins_mean(
        ax, ay, az, fx, fy, fz, bx, by, bz, gx, gy, gz, h
    )
    k = 0.5 * h * h
    return (qw, qx, qy, qz, h * mx, h * my, h * mz, k * mx, k * my, k * mz, h)


@helper
def sgal_bracket(a, b):
    """``[a, b]`` of sgal(3), tangents ``(w, nu, rho, tau)`` as 10-tuples::

    (w1 x w2, w1 x nu2 - w2 x nu1, w1 x rho2 - w2 x rho1 + tau2 nu1 - tau1 nu2, 0)
    """
    w = cross3(a[0], a[1], a[2], b[0], b[1], b[2])
    n1 = cross3(a[0], a[1], a[2], b[3], b[4], b[5])
    n2 = cross3(b[0], b[1], b[2], a[3], a[4], a[5])
    r1 = cross3(a[0], a[1], a[2], b[6], b[7], b[8])
    r2 = cross3(b[0], b[1], b[2], a[6], a[7], a[8])
    return (
        w[0], w[1], w[2],
        n1[0] - n2[0], n1[1] - n2[1], n1[2] - n2[2],
        r1[0] - r2[0] + b[9] * a[3] - a[9] * b[3],
        r1[1] - r2[1] + b[9] * a[4] - a[9] * b[4],
        r1[2] - r2[2] + b[9] * a[5] - a[9] * b[5],
        0.0,
    )  # fmt: skip


@helper
def sgal_dexp_inv_step(u, x, h):
    """``h (x + [u, x]/2 + [u, [u, x]]/12)``: the truncated ``dexp^-1_u(x)`` times h."""
    c = sgal_bracket(u, x)
    d = sgal_bracket(u, c)
    g = 1.0 / 12.0
    return (
        h * (x[0] + 0.5 * c[0] + g * d[0]), h * (x[1] + 0.5 * c[1] + g * d[1]),
        h * (x[2] + 0.5 * c[2] + g * d[2]), h * (x[3] + 0.5 * c[3] + g * d[3]),
        h * (x[4] + 0.5 * c[4] + g * d[4]), h * (x[5] + 0.5 * c[5] + g * d[5]),
        h * (x[6] + 0.5 * c[6] + g * d[6]), h * (x[7] + 0.5 * c[7] + g * d[7]),
        h * (x[8] + 0.5 * c[8] + g * d[8]), h * (x[9] + 0.5 * c[9] + g * d[9]),
    )  # fmt: skip


@helper
def scale10(k, u):
    """``k u`` of a 10-tuple."""
    return (
        k * u[0], k * u[1], k * u[2], k * u[3], k * u[4],
        k * u[5], k * u[6], k * u[7], k * u[8], k * u[9],
    )  # fmt: skip


@helper
def rk4_sum10(a, b, c, d):
    """``(a + 2 (b + c) + d) / 6`` of 10-tuples."""
    return (
        (a[0] + 2.0 * (b[0] + c[0]) + d[0]) / 6.0,
        (a[1] + 2.0 * (b[1] + c[1]) + d[1]) / 6.0,
        (a[2] + 2.0 * (b[2] + c[2]) + d[2]) / 6.0,
        (a[3] + 2.0 * (b[3] + c[3]) + d[3]) / 6.0,
        (a[4] + 2.0 * (b[4] + c[4]) + d[4]) / 6.0,
        (a[5] + 2.0 * (b[5] + c[5]) + d[5]) / 6.0,
        (a[6] + 2.0 * (b[6] + c[6]) + d[6]) / 6.0,
        (a[7] + 2.0 * (b[7] + c[7]) + d[7]) / 6.0,
        (a[8] + 2.0 * (b[8] + c[8]) + d[8]) / 6.0,
        (a[9] + 2.0 * (b[9] + c[9]) + d[9]) / 6.0,
    )


@helper
def sgal_exp_entries(u):
    """``exp`` of sgal(3) of ``(w, nu, rho, tau)``: ``(exp(w), J_l(w) nu, J_l(w) rho +
    tau N(w) nu, tau)`` as 11 scalars."""
    qw, s, theta = half_angle_from_rotvec(u[0], u[1], u[2])
    b = sin_defect3(theta)
    a = 2.0 * s * s
    vx, vy, vz = eye_hat_hat2_apply(u[0], u[1], u[2], a, b, u[3], u[4], u[5])
    rx, ry, rz = eye_hat_hat2_apply(u[0], u[1], u[2], a, b, u[6], u[7], u[8])
    c = cos_defect4(theta)
    nx, ny, nz = hat_poly_apply(u[0], u[1], u[2], 0.5, b, c, u[3], u[4], u[5])
    t = u[9]
    return (
        qw, s * u[0], s * u[1], s * u[2], vx, vy, vz,
        rx + t * nx, ry + t * ny, rz + t * nz, t,
    )  # fmt: skip


@kernel(inputs=[(6,), (6,), (6,), ()], outputs=[(11,)])
def imu_step_rk4(a0, a1, a2, a3, a4, a5, m0, m1, m2, m3, m4, m5, e0, e1, e2, e3, e4, e5, h):
    """RKMK4 step of ``D' = D (w, f, 0, 1)^`` from ``(w, f)`` at the start, middle and
    end of the step (body frame; Munthe-Kaas 1998, as
    :func:`..integration.se3_increment_rk4`). Constant input gives the exact step."""
    xa = (a0, a1, a2, a3, a4, a5, 0.0, 0.0, 0.0, 1.0)
    xm = (m0, m1, m2, m3, m4, m5, 0.0, 0.0, 0.0, 1.0)
    xe = (e0, e1, e2, e3, e4, e5, 0.0, 0.0, 0.0, 1.0)
    k1 = scale10(h, xa)
    k2 = sgal_dexp_inv_step(scale10(0.5, k1), xm, h)
    k3 = sgal_dexp_inv_step(scale10(0.5, k2), xm, h)
    k4 = sgal_dexp_inv_step(k3, xe, h)
    return sgal_exp_entries(rk4_sum10(k1, k2, k3, k4))


@kernel(inputs=[(11,), (11,)], outputs=[(11,)], params=("body",))
def sgal_chain(
    body,
    w1,
    x1,
    y1,
    z1,
    a1,
    b1,
    c1,
    d1,
    e1,
    f1,
    t1,
    w2,
    x2,
    y2,
    z2,
    a2,
    b2,
    c2,
    d2,
    e2,
    f2,
    t2,
):  # noqa: E501
    """``A B`` (body) or ``B A`` (world) in SGal(3), the quaternion renormalised: one
    link of the running product of steps (:func:`..integration.so3_chain`)."""
    s = body == 1
    aw, ax, ay, az = where(s, w1, w2), where(s, x1, x2), where(s, y1, y2), where(s, z1, z2)
    bw, bx, by, bz = where(s, w2, w1), where(s, x2, x1), where(s, y2, y1), where(s, z2, z1)
    va, vb, vc = where(s, a1, a2), where(s, b1, b2), where(s, c1, c2)
    ua, ub, uc = where(s, a2, a1), where(s, b2, b1), where(s, c2, c1)
    pa, pb, pc = where(s, d1, d2), where(s, e1, e2), where(s, f1, f2)
    ra, rb, rc = where(s, d2, d1), where(s, e2, e1), where(s, f2, f1)
    tb = where(s, t2, t1)
    q = quat_multiply(aw, ax, ay, az, bw, bx, by, bz)
    u = renormalize4(q[0], q[1], q[2], q[3])
    rv = quat_apply(aw, ax, ay, az, ua, ub, uc)
    rp = quat_apply(aw, ax, ay, az, ra, rb, rc)
    return (
        u[0], u[1], u[2], u[3],
        va + rv[0], vb + rv[1], vc + rv[2],
        pa + va * tb + rp[0], pb + vb * tb + rp[1], pc + vc * tb + rp[2],
        t1 + t2,
    )  # fmt: skip


@kernel(inputs=[(10,), (11,), (3,), (3,)], outputs=[(10,)])
def nav_predict(
    w, x, y, z, vx, vy, vz, px, py, pz,
    dw, dx, dy, dz, dvx, dvy, dvz, dpx, dpy, dpz, t,
    gx, gy, gz, ox, oy, oz,
):  # fmt: skip
    """The state ``t`` after ``(R, v, p)`` given the steps' product ``D``, gravity
    ``g`` and the navigation frame's rotation rate ``W`` (both in that frame).

    Integrated in the inertial frame that coincides with the navigation frame at the
    start (origin on the rotation axis): there ``R_I = R dR``, ``v_I = v + W x p +
    R dv + t J_l(t W) g`` and ``x_I = p + (v + W x p) t + R dp + t^2 N(t W) g``
    (gravity turns with the frame: ``int_0^t exp(s W) g ds``), then seen from the
    rotating frame: ``E = exp(-t W)``, ``R' = E R_I``, ``p' = E x_I``,
    ``v' = E v_I - W x p'``. With ``W = 0`` this is Forster's eq. 44.
    """
    ux, uy, uz = cross3(ox, oy, oz, px, py, pz)
    ix, iy, iz = vx + ux, vy + uy, vz + uz  # inertial velocity at the start
    qw, qx, qy, qz = quat_multiply(w, x, y, z, dw, dx, dy, dz)
    ax, ay, az = quat_apply(w, x, y, z, dvx, dvy, dvz)
    bx, by, bz = quat_apply(w, x, y, z, dpx, dpy, dpz)
    tx, ty, tz = t * ox, t * oy, t * oz
    theta = norm3(tx, ty, tz)
    cb = sin_defect3(theta)
    gvx, gvy, gvz = eye_hat_hat2_apply(tx, ty, tz, versinc2(theta), cb, gx, gy, gz)
    gpx, gpy, gpz = hat_poly_apply(tx, ty, tz, 0.5, cb, cos_defect4(theta), gx, gy, gz)
    tt = t * t
    vix, viy, viz = ix + ax + t * gvx, iy + ay + t * gvy, iz + az + t * gvz
    xix = px + ix * t + bx + tt * gpx
    xiy = py + iy * t + by + tt * gpy
    xiz = pz + iz * t + bz + tt * gpz
    ew, ex, ey, ez = quat_entries_from_rotvec(-tx, -ty, -tz)
    rw, rx, ry, rz = quat_multiply(ew, ex, ey, ez, qw, qx, qy, qz)
    nx, ny, nz = quat_apply(ew, ex, ey, ez, xix, xiy, xiz)
    mx, my, mz = quat_apply(ew, ex, ey, ez, vix, viy, viz)
    cx, cy, cz = cross3(ox, oy, oz, nx, ny, nz)
    u = renormalize4(rw, rx, ry, rz)
    return (u[0], u[1], u[2], u[3], mx - cx, my - cy, mz - cz, nx, ny, nz)


@kernel(inputs=[(10,), (11,), (3,)], outputs=[(10,)])
def nav_predict_flat(
    w, x, y, z, vx, vy, vz, px, py, pz,
    dw, dx, dy, dz, dvx, dvy, dvz, dpx, dpy, dpz, t,
    gx, gy, gz,
):  # fmt: skip
    """:func:`nav_predict` in a non-rotating frame (Forster et al. 2017, eq. 44):
    ``(R dR, v + g t + R dv, p + v t + g t^2/2 + R dp)``."""
    qw, qx, qy, qz = quat_multiply(w, x, y, z, dw, dx, dy, dz)
    u = renormalize4(qw, qx, qy, qz)
    ax, ay, az = quat_apply(w, x, y, z, dvx, dvy, dvz)
    bx, by, bz = quat_apply(w, x, y, z, dpx, dpy, dpz)
    k = 0.5 * t * t
    return (
        u[0], u[1], u[2], u[3],
        vx + gx * t + ax, vy + gy * t + ay, vz + gz * t + az,
        px + vx * t + gx * k + bx, py + vy * t + gy * k + by, pz + vz * t + gz * k + bz,
    )  # fmt: skip
