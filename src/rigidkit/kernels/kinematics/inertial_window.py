"""Kernels of one-pass IMU preintegration: a window's product, bias Jacobians and
covariance, updated one sample at a time (the step of a compiled fold).

:func:`.inertial_jacobians.preintegration_sensitivity` writes each step's share of
the bias Jacobians and covariance as ``M_k = Phi(N, k+1) diag(I, R_k, R_k) S_k``,
which needs the window's end ``D_N``. In SGal(3) that transport factors as
``M_k = L(D_N) g_k`` (Forster et al. 2017, Appendix B, written in the window's
first frame), with a 9x9 ``L`` of the end alone and a 9x6 ``g_k`` of the step
alone::

    L = [[R_N^T, 0, 0], [-hat(v_N), I, 0], [-hat(p_N), t_N I, I]]
    g_k = [[A, 0], [R_k S^v_w + hat(v) A, R_k S^v_f],
           [R_k (S^p_w - t S^v_w) + hat(p - t v) A, R_k (S^p_f - t S^v_f)]]

with ``A = R_{k+1} S^phi_w``, ``(R_{k+1}, v, p, t) = D_{k+1}`` and ``S`` the step's
Jacobian in ``(w, f)`` (rows ``(phi, v, p)``, columns ``(w, f)``; its rotation rows
have no ``f`` column). Expanding ``L g_k`` gives the rows of
``sensitivity_entries`` term by term (``t_N - t`` and ``p_N - p - v (t_N - t)``
split into the parts of the end and of the step). So one pass over the samples
sums ``G = sum g_k`` and ``P = sum g_k diag(qg I, qa I) g_k^T`` (``qg``, ``qa``
the step's discrete noise variances ``sigma^2 / h``) beside the running product,
and the window's bias Jacobian is ``-L G``, its covariance ``L P L^T``.

The state of the fold is one tuple of :data:`WINDOW_STATE` numbers: ``D`` (11,
``(q, dv, dp, dt)``), ``G`` (54, row-major 9x6), ``P`` (45, the upper triangle
row by row) and the white-noise densities squared ``(sigma_g^2, sigma_a^2)``.
"""

from ..._engine import helper
from ..coefficients import sin_cos_defect5_from_sincos, sin_defect3_from_sin, versinc2
from ..matrix import matrix_from_quat
from ..so3 import eye_hat_hat2, eye_hat_hat2_apply, half_angle_from_rotvec
from ..vector import hat_matmul, hat_poly_apply, mat33_mul
from .inertial import imu_step_forster, imu_step_midpoint, sgal_chain
from .inertial_jacobians import (
    add_diag9,
    coefficient_series_jacobian,
    imu_step_jacobian_forster,
    imu_step_jacobian_midpoint,
    scale9,
    step_jacobian_rows,
)

#: Width of a fold's state: ``D`` (11), ``G`` (54), ``P`` (45), two noise variances.
WINDOW_STATE = 112


@helper
def window_mm(a, b):
    """``A B`` of 3x3 matrices given as 9-tuples (row-major)."""
    return mat33_mul(
        a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8],
        b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7], b[8],
    )  # fmt: skip


@helper
def window_update(s, st, jac, qg, qa):
    """The product ``D_{k+1}`` (11) after ``D_k = s`` (11) and step ``st`` (11), and
    the step's terms of ``G`` (54) and ``P`` (45) (module doc), from the step's
    Jacobian ``jac`` (54, 9x6 row-major, :mod:`.inertial_jacobians`) and the
    discrete noise variances ``qg``, ``qa`` of its inputs."""
    d = sgal_chain(
        1,
        s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], s[8], s[9], s[10],
        st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7], st[8], st[9], st[10],
    )  # fmt: skip
    rk = matrix_from_quat(s[0], s[1], s[2], s[3])
    ra = matrix_from_quat(d[0], d[1], d[2], d[3])
    # The step's 3x3 blocks: rotation rows in w; velocity and position rows in w, f.
    phw = (jac[0], jac[1], jac[2], jac[6], jac[7], jac[8], jac[12], jac[13], jac[14])
    svw = (jac[18], jac[19], jac[20], jac[24], jac[25], jac[26], jac[30], jac[31], jac[32])
    svf = (jac[21], jac[22], jac[23], jac[27], jac[28], jac[29], jac[33], jac[34], jac[35])
    spw = (jac[36], jac[37], jac[38], jac[42], jac[43], jac[44], jac[48], jac[49], jac[50])
    spf = (jac[39], jac[40], jac[41], jac[45], jac[46], jac[47], jac[51], jac[52], jac[53])
    a = window_mm(ra, phw)
    t = d[10]
    vw = window_mm(rk, svw)
    vf = window_mm(rk, svf)
    pw = window_mm(rk, spw)
    pf = window_mm(rk, spf)
    hv = hat_matmul(d[4], d[5], d[6], a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8])
    hp = hat_matmul(
        d[7] - t * d[4], d[8] - t * d[5], d[9] - t * d[6],
        a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8],
    )  # fmt: skip
    bw = (
        vw[0] + hv[0], vw[1] + hv[1], vw[2] + hv[2], vw[3] + hv[3], vw[4] + hv[4],
        vw[5] + hv[5], vw[6] + hv[6], vw[7] + hv[7], vw[8] + hv[8],
    )  # fmt: skip
    bf = vf
    cw = (
        pw[0] - t * vw[0] + hp[0], pw[1] - t * vw[1] + hp[1], pw[2] - t * vw[2] + hp[2],
        pw[3] - t * vw[3] + hp[3], pw[4] - t * vw[4] + hp[4], pw[5] - t * vw[5] + hp[5],
        pw[6] - t * vw[6] + hp[6], pw[7] - t * vw[7] + hp[7], pw[8] - t * vw[8] + hp[8],
    )  # fmt: skip
    cf = (
        pf[0] - t * vf[0], pf[1] - t * vf[1], pf[2] - t * vf[2],
        pf[3] - t * vf[3], pf[4] - t * vf[4], pf[5] - t * vf[5],
        pf[6] - t * vf[6], pf[7] - t * vf[7], pf[8] - t * vf[8],
    )  # fmt: skip
    return (
        d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7], d[8], d[9], d[10],
        a[0],
        a[1],
        a[2],
        0.0,
        0.0,
        0.0,
        a[3],
        a[4],
        a[5],
        0.0,
        0.0,
        0.0,
        a[6],
        a[7],
        a[8],
        0.0,
        0.0,
        0.0,
        bw[0],
        bw[1],
        bw[2],
        bf[0],
        bf[1],
        bf[2],
        bw[3],
        bw[4],
        bw[5],
        bf[3],
        bf[4],
        bf[5],
        bw[6],
        bw[7],
        bw[8],
        bf[6],
        bf[7],
        bf[8],
        cw[0],
        cw[1],
        cw[2],
        cf[0],
        cf[1],
        cf[2],
        cw[3],
        cw[4],
        cw[5],
        cf[3],
        cf[4],
        cf[5],
        cw[6],
        cw[7],
        cw[8],
        cf[6],
        cf[7],
        cf[8],
        qg * (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]),
        qg * (a[0] * a[3] + a[1] * a[4] + a[2] * a[5]),
        qg * (a[0] * a[6] + a[1] * a[7] + a[2] * a[8]),
        qg * (a[0] * bw[0] + a[1] * bw[1] + a[2] * bw[2]),
        qg * (a[0] * bw[3] + a[1] * bw[4] + a[2] * bw[5]),
        qg * (a[0] * bw[6] + a[1] * bw[7] + a[2] * bw[8]),
        qg * (a[0] * cw[0] + a[1] * cw[1] + a[2] * cw[2]),
        qg * (a[0] * cw[3] + a[1] * cw[4] + a[2] * cw[5]),
        qg * (a[0] * cw[6] + a[1] * cw[7] + a[2] * cw[8]),
        qg * (a[3] * a[3] + a[4] * a[4] + a[5] * a[5]),
        qg * (a[3] * a[6] + a[4] * a[7] + a[5] * a[8]),
        qg * (a[3] * bw[0] + a[4] * bw[1] + a[5] * bw[2]),
        qg * (a[3] * bw[3] + a[4] * bw[4] + a[5] * bw[5]),
        qg * (a[3] * bw[6] + a[4] * bw[7] + a[5] * bw[8]),
        qg * (a[3] * cw[0] + a[4] * cw[1] + a[5] * cw[2]),
        qg * (a[3] * cw[3] + a[4] * cw[4] + a[5] * cw[5]),
        qg * (a[3] * cw[6] + a[4] * cw[7] + a[5] * cw[8]),
        qg * (a[6] * a[6] + a[7] * a[7] + a[8] * a[8]),
        qg * (a[6] * bw[0] + a[7] * bw[1] + a[8] * bw[2]),
        qg * (a[6] * bw[3] + a[7] * bw[4] + a[8] * bw[5]),
        qg * (a[6] * bw[6] + a[7] * bw[7] + a[8] * bw[8]),
        qg * (a[6] * cw[0] + a[7] * cw[1] + a[8] * cw[2]),
        qg * (a[6] * cw[3] + a[7] * cw[4] + a[8] * cw[5]),
        qg * (a[6] * cw[6] + a[7] * cw[7] + a[8] * cw[8]),
        qg * (bw[0] * bw[0] + bw[1] * bw[1] + bw[2] * bw[2])
        + qa * (bf[0] * bf[0] + bf[1] * bf[1] + bf[2] * bf[2]),
        qg * (bw[0] * bw[3] + bw[1] * bw[4] + bw[2] * bw[5])
        + qa * (bf[0] * bf[3] + bf[1] * bf[4] + bf[2] * bf[5]),
        qg * (bw[0] * bw[6] + bw[1] * bw[7] + bw[2] * bw[8])
        + qa * (bf[0] * bf[6] + bf[1] * bf[7] + bf[2] * bf[8]),
        qg * (bw[0] * cw[0] + bw[1] * cw[1] + bw[2] * cw[2])
        + qa * (bf[0] * cf[0] + bf[1] * cf[1] + bf[2] * cf[2]),
        qg * (bw[0] * cw[3] + bw[1] * cw[4] + bw[2] * cw[5])
        + qa * (bf[0] * cf[3] + bf[1] * cf[4] + bf[2] * cf[5]),
        qg * (bw[0] * cw[6] + bw[1] * cw[7] + bw[2] * cw[8])
        + qa * (bf[0] * cf[6] + bf[1] * cf[7] + bf[2] * cf[8]),
        qg * (bw[3] * bw[3] + bw[4] * bw[4] + bw[5] * bw[5])
        + qa * (bf[3] * bf[3] + bf[4] * bf[4] + bf[5] * bf[5]),
        qg * (bw[3] * bw[6] + bw[4] * bw[7] + bw[5] * bw[8])
        + qa * (bf[3] * bf[6] + bf[4] * bf[7] + bf[5] * bf[8]),
        qg * (bw[3] * cw[0] + bw[4] * cw[1] + bw[5] * cw[2])
        + qa * (bf[3] * cf[0] + bf[4] * cf[1] + bf[5] * cf[2]),
        qg * (bw[3] * cw[3] + bw[4] * cw[4] + bw[5] * cw[5])
        + qa * (bf[3] * cf[3] + bf[4] * cf[4] + bf[5] * cf[5]),
        qg * (bw[3] * cw[6] + bw[4] * cw[7] + bw[5] * cw[8])
        + qa * (bf[3] * cf[6] + bf[4] * cf[7] + bf[5] * cf[8]),
        qg * (bw[6] * bw[6] + bw[7] * bw[7] + bw[8] * bw[8])
        + qa * (bf[6] * bf[6] + bf[7] * bf[7] + bf[8] * bf[8]),
        qg * (bw[6] * cw[0] + bw[7] * cw[1] + bw[8] * cw[2])
        + qa * (bf[6] * cf[0] + bf[7] * cf[1] + bf[8] * cf[2]),
        qg * (bw[6] * cw[3] + bw[7] * cw[4] + bw[8] * cw[5])
        + qa * (bf[6] * cf[3] + bf[7] * cf[4] + bf[8] * cf[5]),
        qg * (bw[6] * cw[6] + bw[7] * cw[7] + bw[8] * cw[8])
        + qa * (bf[6] * cf[6] + bf[7] * cf[7] + bf[8] * cf[8]),
        qg * (cw[0] * cw[0] + cw[1] * cw[1] + cw[2] * cw[2])
        + qa * (cf[0] * cf[0] + cf[1] * cf[1] + cf[2] * cf[2]),
        qg * (cw[0] * cw[3] + cw[1] * cw[4] + cw[2] * cw[5])
        + qa * (cf[0] * cf[3] + cf[1] * cf[4] + cf[2] * cf[5]),
        qg * (cw[0] * cw[6] + cw[1] * cw[7] + cw[2] * cw[8])
        + qa * (cf[0] * cf[6] + cf[1] * cf[7] + cf[2] * cf[8]),
        qg * (cw[3] * cw[3] + cw[4] * cw[4] + cw[5] * cw[5])
        + qa * (cf[3] * cf[3] + cf[4] * cf[4] + cf[5] * cf[5]),
        qg * (cw[3] * cw[6] + cw[4] * cw[7] + cw[5] * cw[8])
        + qa * (cf[3] * cf[6] + cf[4] * cf[7] + cf[5] * cf[8]),
        qg * (cw[6] * cw[6] + cw[7] * cw[7] + cw[8] * cw[8])
        + qa * (cf[6] * cf[6] + cf[7] * cf[7] + cf[8] * cf[8]),
    )  # fmt: skip


@helper
def exact_step_jacobian(wx, wy, wz, fx, fy, fz, h):
    """:func:`.inertial.imu_step_exact` (11) and
    :func:`.inertial_jacobians.imu_step_jacobian_exact` (54) of one sample, their
    coefficients computed once from the sine and cosine of the half angle.

    The two kernels call ``sin_defect3``, ``cos_defect4``, ``sin_cos_defect5`` and
    the rates of ``versinc2`` and ``cos_defect4`` of ``t = |h w|`` and of
    ``y = t/2`` on their own, each with its own sine: in the fold that was most of
    the exact step's cost (exact 1.97x forster's fold, 1.44x with this, measured
    interleaved). Here, with ``q = (C, s h w)`` the half-angle quaternion
    (``C = cos y``, ``s = sin(y)/t``, so ``sin y = s t`` and ``sinc(y) = 2 s``),
    ``sin t = 2 sin(y) C`` and ``cos t = C^2 - sin(y)^2``, the identities their
    docstrings state give every coefficient from the same factors:
    ``versinc2(t) = 2 s^2``, ``cos_defect4(t) = s3(y) (1 + 2 s) / 8``,
    ``versinc2_rate(t) = (versinc2(y) - s3(y)) s / 2`` (``cot_defect2(t)
    sinc(y)^2``) and ``cos_defect4_rate(t) = -(2 sin_cos_defect5(y) (1 + 2 s) +
    s3(y) (versinc2(y) - s3(y))) / 32``, ``s3 = sin_defect3``; the series below
    their thresholds are those helpers' own. ``J_r(t) = I - a W + b W^2`` shares
    ``a``, ``b`` with ``J_l``.
    """
    tx, ty, tz = h * wx, h * wy, h * wz
    qw, s, theta = half_angle_from_rotvec(tx, ty, tz)
    sin_y = s * theta
    sin_t = 2.0 * sin_y * qw
    cos_t = qw * qw - sin_y * sin_y
    y = 0.5 * theta
    a = 2.0 * s * s
    b = sin_defect3_from_sin(theta, sin_t)
    by = sin_defect3_from_sin(y, sin_y)
    one_sinc = 1.0 + 2.0 * s
    c = by * one_sinc * 0.125
    vy = versinc2(y)
    ra = -(vy - by) * s * 0.5
    rb = -2.0 * sin_cos_defect5_from_sincos(theta, sin_t, cos_t)
    rc = -(2.0 * sin_cos_defect5_from_sincos(y, sin_y, qw) * one_sinc + by * (vy - by)) * (
        1.0 / 32.0
    )
    hh = h * h
    vx, vy_, vz = eye_hat_hat2_apply(tx, ty, tz, a, b, fx, fy, fz)
    px, py, pz = hat_poly_apply(tx, ty, tz, 0.5, b, c, fx, fy, fz)
    st = (qw, s * tx, s * ty, s * tz, h * vx, h * vy_, h * vz, hh * px, hh * py, hh * pz, h)
    jac = step_jacobian_rows(
        scale9(h, eye_hat_hat2(tx, ty, tz, -a, b)),
        scale9(hh, coefficient_series_jacobian(tx, ty, tz, a, b, ra, rb, fx, fy, fz)),
        scale9(h, eye_hat_hat2(tx, ty, tz, a, b)),
        scale9(hh * h, coefficient_series_jacobian(tx, ty, tz, b, c, rb, rc, fx, fy, fz)),
        scale9(hh, add_diag9(eye_hat_hat2(tx, ty, tz, b, c), -0.5)),
    )
    return st, jac


@helper
def preintegration_step_exact(
    d0, d1, d2, d3, d4, d5, d6, d7, d8, d9, d10, wx, wy, wz, fx, fy, fz, h, qg, qa
):
    """One sample held over ``h`` (``"exact"``): :func:`window_update` of
    :func:`.inertial.imu_step_exact` and its Jacobian (:func:`exact_step_jacobian`)."""
    st, jac = exact_step_jacobian(wx, wy, wz, fx, fy, fz, h)
    s = (d0, d1, d2, d3, d4, d5, d6, d7, d8, d9, d10)
    return window_update(s, st, jac, qg, qa)


@helper
def preintegration_step_forster(
    d0, d1, d2, d3, d4, d5, d6, d7, d8, d9, d10, wx, wy, wz, fx, fy, fz, h, qg, qa
):
    """Forster's step (``"forster"``): :func:`window_update` of
    :func:`.inertial.imu_step_forster` and its Jacobian."""
    st = imu_step_forster(wx, wy, wz, fx, fy, fz, h)
    jac = imu_step_jacobian_forster(wx, wy, wz, fx, fy, fz, h)
    s = (d0, d1, d2, d3, d4, d5, d6, d7, d8, d9, d10)
    return window_update(s, st, jac, qg, qa)


@helper
def preintegration_step_midpoint(
    d0, d1, d2, d3, d4, d5, d6, d7, d8, d9, d10,
    ax, ay, az, fx, fy, fz, bx, by, bz, gx, gy, gz, h, qg, qa,
):  # fmt: skip
    """VINS-Mono's step (``"midpoint"``) from the samples ``(w0, f0)`` and ``(w1,
    f1)``: :func:`window_update` of :func:`.inertial.imu_step_midpoint` and its
    Jacobian."""
    st = imu_step_midpoint(ax, ay, az, fx, fy, fz, bx, by, bz, gx, gy, gz, h)
    jac = imu_step_jacobian_midpoint(ax, ay, az, fx, fy, fz, bx, by, bz, gx, gy, gz, h)
    s = (d0, d1, d2, d3, d4, d5, d6, d7, d8, d9, d10)
    return window_update(s, st, jac, qg, qa)
