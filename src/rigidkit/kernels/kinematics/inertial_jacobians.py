"""Kernels of IMU preintegration's Jacobians: steps in their inputs, and windows.

The bias Jacobians and the covariance of a preintegrated window (Forster et al.
2017, Sec. V and Appendix B) are sums over its steps of ``Phi(N, k+1) diag(I, R_k,
R_k) S_k``: the Jacobian ``S_k`` of step ``k`` (of :mod:`.inertial`) in its gyro and
accelerometer inputs, carried to the window's end through the Galilean structure of
the product (:func:`preintegration_sensitivity`). Rows are ``(phi, v, p)``: the
rotation for a right perturbation ``dR exp(phi)``, velocity and position additive
in the window's first frame, as Forster's; columns ``(w, f)``.
"""

from ..._engine import helper, kernel
from ..coefficients import cos_defect4, norm3, sin_cos_defect5, sin_defect3, sinc, versinc2
from ..matrix import matrix_from_quat
from ..quaternion import quat_multiply
from ..so3 import eye_hat_hat2, so3_left_jacobian_entries, versinc2_rate
from ..vector import cross3, hat_matmul, mat33_mul
from .inertial import vins_mean


@helper
def cos_defect4_rate(x):
    """``(d cos_defect4 / dx) / x`` (-1/360 at 0), from accurate factors.

    ``cos_defect4(x) = s3(y) (1 + sinc(y)) / 8`` with ``y = x/2`` and
    ``s3 = sin_defect3``; with ``s3'(y)/y = -2 sin_cos_defect5(y)`` and
    ``sinc'(y)/y = -(versinc2(y) - s3(y))`` (see :func:`.so3.versinc2_rate`) this is
    ``-(2 sin_cos_defect5(y) (1 + sinc(y)) + s3(y) (versinc2(y) - s3(y))) / 32``:
    two terms of one sign, so nothing cancels and no threshold of its own is needed.
    """
    y = 0.5 * x
    s3 = sin_defect3(y)
    return -(2.0 * sin_cos_defect5(y) * (1.0 + sinc(y)) + s3 * (versinc2(y) - s3)) / 32.0


@helper
def coefficient_series_jacobian(tx, ty, tz, a, b, ra, rb, fx, fy, fz):
    """Entries of ``d/d theta [(c I + a W + b W^2) f]`` (3x3), ``W = hat(theta)``.

    ``ra = (da/dt)/t``, ``rb = (db/dt)/t`` with ``t = |theta|`` (the coefficients'
    rates over their argument, finite at 0)::

        -a hat(f) - b (hat(theta x f) + W hat(f)) + (theta x f) ra theta^T
                  + (theta x (theta x f)) rb theta^T
    """
    cx, cy, cz = cross3(tx, ty, tz, fx, fy, fz)
    dx, dy, dz = cross3(tx, ty, tz, cx, cy, cz)
    wf = mat33_mul(
        0.0, -tz, ty, tz, 0.0, -tx, -ty, tx, 0.0,
        0.0, -fz, fy, fz, 0.0, -fx, -fy, fx, 0.0,
    )  # fmt: skip
    hc = (0.0, -cz, cy, cz, 0.0, -cx, -cy, cx, 0.0)
    hf = (0.0, -fz, fy, fz, 0.0, -fx, -fy, fx, 0.0)
    ux, uy, uz = ra * cx + rb * dx, ra * cy + rb * dy, ra * cz + rb * dz
    return (
        -a * hf[0] - b * (hc[0] + wf[0]) + ux * tx,
        -a * hf[1] - b * (hc[1] + wf[1]) + ux * ty,
        -a * hf[2] - b * (hc[2] + wf[2]) + ux * tz,
        -a * hf[3] - b * (hc[3] + wf[3]) + uy * tx,
        -a * hf[4] - b * (hc[4] + wf[4]) + uy * ty,
        -a * hf[5] - b * (hc[5] + wf[5]) + uy * tz,
        -a * hf[6] - b * (hc[6] + wf[6]) + uz * tx,
        -a * hf[7] - b * (hc[7] + wf[7]) + uz * ty,
        -a * hf[8] - b * (hc[8] + wf[8]) + uz * tz,
    )


# -- step Jacobians: d(step) / d(w, f), rows (phi, v, p) of the step's own frame --------


@helper
def so3_right_jacobian_entries(tx, ty, tz):
    """``J_r(theta) = J_l(-theta)``: ``exp(theta + d) ~ exp(theta) exp(J_r d)``."""
    return so3_left_jacobian_entries(-tx, -ty, -tz)


@helper
def block_rows(a, b, c, d, e, f):
    """The 9x6 entries ``[[a, b], [c, d], [e, f]]`` from 3x3 tuples."""
    return (
        a[0], a[1], a[2], b[0], b[1], b[2],
        a[3], a[4], a[5], b[3], b[4], b[5],
        a[6], a[7], a[8], b[6], b[7], b[8],
        c[0], c[1], c[2], d[0], d[1], d[2],
        c[3], c[4], c[5], d[3], d[4], d[5],
        c[6], c[7], c[8], d[6], d[7], d[8],
        e[0], e[1], e[2], f[0], f[1], f[2],
        e[3], e[4], e[5], f[3], f[4], f[5],
        e[6], e[7], e[8], f[6], f[7], f[8],
    )  # fmt: skip


@helper
def step_jacobian_rows(jr, jv_w, jv_f, jp_w, jp_f):
    """The 9x6 entries ``[[J_r, 0], [dv/dw, dv/df], [dp/dw, dp/df]]`` from 3x3 tuples."""
    z = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    return block_rows(jr, z, jv_w, jv_f, jp_w, jp_f)


@helper
def sub9(a, b):
    """``a - b`` of 3x3 tuples."""
    return (
        a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3], a[4] - b[4],
        a[5] - b[5], a[6] - b[6], a[7] - b[7], a[8] - b[8],
    )  # fmt: skip


@helper
def axpy9(k, a, b):
    """``k a + b`` of 3x3 tuples."""
    return (
        k * a[0] + b[0], k * a[1] + b[1], k * a[2] + b[2], k * a[3] + b[3], k * a[4] + b[4],
        k * a[5] + b[5], k * a[6] + b[6], k * a[7] + b[7], k * a[8] + b[8],
    )  # fmt: skip


@helper
def scale9(k, u):
    """``k u`` of a 9-tuple (a 3x3 matrix)."""
    return (
        k * u[0],
        k * u[1],
        k * u[2],
        k * u[3],
        k * u[4],
        k * u[5],
        k * u[6],
        k * u[7],
        k * u[8],
    )


@helper
def mat33_product(a, b):
    """``A B`` of 3x3 matrices given as 9-tuples (row-major), without ``*`` calls
    (which a compiled fold cannot inline)."""
    return mat33_mul(
        a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8],
        b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7], b[8],
    )  # fmt: skip


@helper
def add_diag9(u, k):
    """``u + k I`` of a 9-tuple (a 3x3 matrix)."""
    return (u[0] + k, u[1], u[2], u[3], u[4] + k, u[5], u[6], u[7], u[8] + k)


@kernel(inputs=[(3,), (3,), ()], outputs=[(9, 6)])
def imu_step_jacobian_exact(ox, oy, oz, fx, fy, fz, h):
    """Jacobian of :func:`imu_step_exact` in ``(w, f)``: rotation rows for a right
    perturbation of ``exp(h w)``, velocity and position rows additive in the step's
    start frame. ``d(J_l(th) f)/d th`` and ``d(N(th) f)/d th`` from the coefficients'
    rates (:func:`coefficient_series_jacobian`), ``th = h w``."""
    tx, ty, tz = h * ox, h * oy, h * oz
    theta = norm3(tx, ty, tz)
    a = versinc2(theta)
    b = sin_defect3(theta)
    c = cos_defect4(theta)
    rb = -2.0 * sin_cos_defect5(theta)
    jr = so3_right_jacobian_entries(tx, ty, tz)
    dv = coefficient_series_jacobian(
        tx, ty, tz, a, b, -versinc2_rate(theta), rb, fx, fy, fz
    )
    dp = coefficient_series_jacobian(
        tx, ty, tz, b, c, rb, cos_defect4_rate(theta), fx, fy, fz
    )
    hh = h * h
    h3 = hh * h
    jl = eye_hat_hat2(tx, ty, tz, a, b)
    n = eye_hat_hat2(tx, ty, tz, b, c)  # I + b W + c W^2; N = that - I/2
    return step_jacobian_rows(
        scale9(h, jr),
        scale9(hh, dv),
        scale9(h, jl),
        scale9(h3, dp),
        scale9(hh, add_diag9(n, -0.5)),
    )


@kernel(inputs=[(3,), (3,), ()], outputs=[(9, 6)])
def imu_step_jacobian_forster(ox, oy, oz, fx, fy, fz, h):
    """Jacobian of :func:`imu_step_forster` in ``(w, f)`` (the step terms of
    Forster et al. 2017, eqs. 59 and Appendix B): ``[[h J_r, 0], [0, h I],
    [0, h^2/2 I]]``."""
    jr = so3_right_jacobian_entries(h * ox, h * oy, h * oz)
    z = (0.0,) * 9
    k = 0.5 * h * h
    return step_jacobian_rows(
        scale9(h, jr),
        z,
        (h, 0.0, 0.0, 0.0, h, 0.0, 0.0, 0.0, h),
        z,
        (k, 0.0, 0.0, 0.0, k, 0.0, 0.0, 0.0, k),
    )


@kernel(inputs=[(3,), (3,), (3,), (3,), ()], outputs=[(9, 6)])
def imu_step_jacobian_midpoint(ax, ay, az, fx, fy, fz, bx, by, bz, gx, gy, gz, h):
    """Jacobian of :func:`imu_step_midpoint` in a change ``(dw, df)`` of both samples
    (a bias): ``E`` turns by ``J_r(h wm) h dw``, ``m`` changes by ``(I + E) df / 2 -
    E hat(f1) J_r h dw / 2``."""
    mx, my, mz = 0.5 * h * (ax + bx), 0.5 * h * (ay + by), 0.5 * h * (az + bz)
    jr = so3_right_jacobian_entries(mx, my, mz)
    qw, qx, qy, qz, _, _, _ = vins_mean(ax, ay, az, fx, fy, fz, bx, by, bz, gx, gy, gz, h)
    e = eye_hat_hat2(qx, qy, qz, 2.0 * qw, 2.0)  # R of a unit quaternion
    hf = (0.0, -gz, gy, gz, 0.0, -gx, -gy, gx, 0.0)
    dm_w = mat33_product(mat33_product(e, hf), jr)
    dm_w = scale9(-0.5 * h, dm_w)
    dm_f = scale9(0.5, add_diag9(e, 1.0))
    k = 0.5 * h * h
    return step_jacobian_rows(
        scale9(h, jr),
        scale9(h, dm_w),
        scale9(h, dm_f),
        scale9(k, dm_w),
        scale9(k, dm_f),
    )


# -- preintegration: how each step's error reaches the window's end ----------------------


@helper
def weighted_gram45(m, qg, qa):
    """The 45 entries (upper triangle, row by row) of ``M diag(qg I, qa I) M^T`` for a
    9x6 ``M`` (a 54-tuple): one step's share of the preintegrated covariance."""
    return (
        qg * (m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
        + qa * (m[3] * m[3] + m[4] * m[4] + m[5] * m[5]),
        qg * (m[0] * m[6] + m[1] * m[7] + m[2] * m[8])
        + qa * (m[3] * m[9] + m[4] * m[10] + m[5] * m[11]),
        qg * (m[0] * m[12] + m[1] * m[13] + m[2] * m[14])
        + qa * (m[3] * m[15] + m[4] * m[16] + m[5] * m[17]),
        qg * (m[0] * m[18] + m[1] * m[19] + m[2] * m[20])
        + qa * (m[3] * m[21] + m[4] * m[22] + m[5] * m[23]),
        qg * (m[0] * m[24] + m[1] * m[25] + m[2] * m[26])
        + qa * (m[3] * m[27] + m[4] * m[28] + m[5] * m[29]),
        qg * (m[0] * m[30] + m[1] * m[31] + m[2] * m[32])
        + qa * (m[3] * m[33] + m[4] * m[34] + m[5] * m[35]),
        qg * (m[0] * m[36] + m[1] * m[37] + m[2] * m[38])
        + qa * (m[3] * m[39] + m[4] * m[40] + m[5] * m[41]),
        qg * (m[0] * m[42] + m[1] * m[43] + m[2] * m[44])
        + qa * (m[3] * m[45] + m[4] * m[46] + m[5] * m[47]),
        qg * (m[0] * m[48] + m[1] * m[49] + m[2] * m[50])
        + qa * (m[3] * m[51] + m[4] * m[52] + m[5] * m[53]),
        qg * (m[6] * m[6] + m[7] * m[7] + m[8] * m[8])
        + qa * (m[9] * m[9] + m[10] * m[10] + m[11] * m[11]),
        qg * (m[6] * m[12] + m[7] * m[13] + m[8] * m[14])
        + qa * (m[9] * m[15] + m[10] * m[16] + m[11] * m[17]),
        qg * (m[6] * m[18] + m[7] * m[19] + m[8] * m[20])
        + qa * (m[9] * m[21] + m[10] * m[22] + m[11] * m[23]),
        qg * (m[6] * m[24] + m[7] * m[25] + m[8] * m[26])
        + qa * (m[9] * m[27] + m[10] * m[28] + m[11] * m[29]),
        qg * (m[6] * m[30] + m[7] * m[31] + m[8] * m[32])
        + qa * (m[9] * m[33] + m[10] * m[34] + m[11] * m[35]),
        qg * (m[6] * m[36] + m[7] * m[37] + m[8] * m[38])
        + qa * (m[9] * m[39] + m[10] * m[40] + m[11] * m[41]),
        qg * (m[6] * m[42] + m[7] * m[43] + m[8] * m[44])
        + qa * (m[9] * m[45] + m[10] * m[46] + m[11] * m[47]),
        qg * (m[6] * m[48] + m[7] * m[49] + m[8] * m[50])
        + qa * (m[9] * m[51] + m[10] * m[52] + m[11] * m[53]),
        qg * (m[12] * m[12] + m[13] * m[13] + m[14] * m[14])
        + qa * (m[15] * m[15] + m[16] * m[16] + m[17] * m[17]),
        qg * (m[12] * m[18] + m[13] * m[19] + m[14] * m[20])
        + qa * (m[15] * m[21] + m[16] * m[22] + m[17] * m[23]),
        qg * (m[12] * m[24] + m[13] * m[25] + m[14] * m[26])
        + qa * (m[15] * m[27] + m[16] * m[28] + m[17] * m[29]),
        qg * (m[12] * m[30] + m[13] * m[31] + m[14] * m[32])
        + qa * (m[15] * m[33] + m[16] * m[34] + m[17] * m[35]),
        qg * (m[12] * m[36] + m[13] * m[37] + m[14] * m[38])
        + qa * (m[15] * m[39] + m[16] * m[40] + m[17] * m[41]),
        qg * (m[12] * m[42] + m[13] * m[43] + m[14] * m[44])
        + qa * (m[15] * m[45] + m[16] * m[46] + m[17] * m[47]),
        qg * (m[12] * m[48] + m[13] * m[49] + m[14] * m[50])
        + qa * (m[15] * m[51] + m[16] * m[52] + m[17] * m[53]),
        qg * (m[18] * m[18] + m[19] * m[19] + m[20] * m[20])
        + qa * (m[21] * m[21] + m[22] * m[22] + m[23] * m[23]),
        qg * (m[18] * m[24] + m[19] * m[25] + m[20] * m[26])
        + qa * (m[21] * m[27] + m[22] * m[28] + m[23] * m[29]),
        qg * (m[18] * m[30] + m[19] * m[31] + m[20] * m[32])
        + qa * (m[21] * m[33] + m[22] * m[34] + m[23] * m[35]),
        qg * (m[18] * m[36] + m[19] * m[37] + m[20] * m[38])
        + qa * (m[21] * m[39] + m[22] * m[40] + m[23] * m[41]),
        qg * (m[18] * m[42] + m[19] * m[43] + m[20] * m[44])
        + qa * (m[21] * m[45] + m[22] * m[46] + m[23] * m[47]),
        qg * (m[18] * m[48] + m[19] * m[49] + m[20] * m[50])
        + qa * (m[21] * m[51] + m[22] * m[52] + m[23] * m[53]),
        qg * (m[24] * m[24] + m[25] * m[25] + m[26] * m[26])
        + qa * (m[27] * m[27] + m[28] * m[28] + m[29] * m[29]),
        qg * (m[24] * m[30] + m[25] * m[31] + m[26] * m[32])
        + qa * (m[27] * m[33] + m[28] * m[34] + m[29] * m[35]),
        qg * (m[24] * m[36] + m[25] * m[37] + m[26] * m[38])
        + qa * (m[27] * m[39] + m[28] * m[40] + m[29] * m[41]),
        qg * (m[24] * m[42] + m[25] * m[43] + m[26] * m[44])
        + qa * (m[27] * m[45] + m[28] * m[46] + m[29] * m[47]),
        qg * (m[24] * m[48] + m[25] * m[49] + m[26] * m[50])
        + qa * (m[27] * m[51] + m[28] * m[52] + m[29] * m[53]),
        qg * (m[30] * m[30] + m[31] * m[31] + m[32] * m[32])
        + qa * (m[33] * m[33] + m[34] * m[34] + m[35] * m[35]),
        qg * (m[30] * m[36] + m[31] * m[37] + m[32] * m[38])
        + qa * (m[33] * m[39] + m[34] * m[40] + m[35] * m[41]),
        qg * (m[30] * m[42] + m[31] * m[43] + m[32] * m[44])
        + qa * (m[33] * m[45] + m[34] * m[46] + m[35] * m[47]),
        qg * (m[30] * m[48] + m[31] * m[49] + m[32] * m[50])
        + qa * (m[33] * m[51] + m[34] * m[52] + m[35] * m[53]),
        qg * (m[36] * m[36] + m[37] * m[37] + m[38] * m[38])
        + qa * (m[39] * m[39] + m[40] * m[40] + m[41] * m[41]),
        qg * (m[36] * m[42] + m[37] * m[43] + m[38] * m[44])
        + qa * (m[39] * m[45] + m[40] * m[46] + m[41] * m[47]),
        qg * (m[36] * m[48] + m[37] * m[49] + m[38] * m[50])
        + qa * (m[39] * m[51] + m[40] * m[52] + m[41] * m[53]),
        qg * (m[42] * m[42] + m[43] * m[43] + m[44] * m[44])
        + qa * (m[45] * m[45] + m[46] * m[46] + m[47] * m[47]),
        qg * (m[42] * m[48] + m[43] * m[49] + m[44] * m[50])
        + qa * (m[45] * m[51] + m[46] * m[52] + m[47] * m[53]),
        qg * (m[48] * m[48] + m[49] * m[49] + m[50] * m[50])
        + qa * (m[51] * m[51] + m[52] * m[52] + m[53] * m[53]),
    )  # fmt: skip


@helper
def sensitivity_entries(
    kw, kx, ky, kz, kva, kvb, kvc, kpa, kpb, kpc, kt,
    aw, ax, ay, az, ava, avb, avc, apa, apb, apc, at,
    nw, nx, ny, nz, nva, nvb, nvc, npa, npb, npc, nt,
    s,
):  # fmt: skip
    """How an error of step ``k`` reaches the end of its window: ``Phi(N, k+1)
    diag(I, R_k, R_k) S_k`` (9x6), rows ``(phi, v, p)`` of the window's product ``D_N``
    (rotation: right perturbation; velocity and position: additive in the window's
    first frame), columns ``(w, f)`` of the step's inputs.

    ``D_k``, ``D_{k+1}`` are the products of the first ``k`` and ``k + 1`` steps
    (``a``), ``S_k`` the step's own Jacobian (``imu_step_jacobian_*``). In SGal(3),
    ``D_N = D_{k+1} D_{k+1,N}`` gives, for a change ``(phi, v, p)`` of ``D_{k+1}``:
    ``R_N^T R_{k+1} phi``, ``v - hat(v_N - v_{k+1}) R_{k+1} phi`` and
    ``p + t v - hat(p_N - p_{k+1} - v_{k+1} t) R_{k+1} phi`` with ``t = t_N - t_{k+1}``;
    the step's ``(phi, v, p)`` enters ``D_{k+1}`` as ``(phi, R_k v, R_k p)``.
    """
    rk = matrix_from_quat(kw, kx, ky, kz)
    ra = matrix_from_quat(aw, ax, ay, az)
    qw, qx, qy, qz = quat_multiply(nw, -nx, -ny, -nz, aw, ax, ay, az)
    rn = matrix_from_quat(qw, qx, qy, qz)
    t = nt - at
    dva, dvb, dvc = nva - ava, nvb - avb, nvc - avc
    dpa, dpb, dpc = npa - apa - ava * t, npb - apb - avb * t, npc - apc - avc * t
    phw, phf = (
        (s[0], s[1], s[2], s[6], s[7], s[8], s[12], s[13], s[14]),
        (s[3], s[4], s[5], s[9], s[10], s[11], s[15], s[16], s[17]),
    )
    svw, svf = (
        (s[18], s[19], s[20], s[24], s[25], s[26], s[30], s[31], s[32]),
        (s[21], s[22], s[23], s[27], s[28], s[29], s[33], s[34], s[35]),
    )
    spw, spf = (
        (s[36], s[37], s[38], s[42], s[43], s[44], s[48], s[49], s[50]),
        (s[39], s[40], s[41], s[45], s[46], s[47], s[51], s[52], s[53]),
    )
    aw_ = mat33_mul(*ra, *phw)
    af_ = mat33_mul(*ra, *phf)
    kvw = mat33_mul(*rk, *svw)
    kvf = mat33_mul(*rk, *svf)
    kpw = mat33_mul(*rk, *spw)
    kpf = mat33_mul(*rk, *spf)
    hvw = hat_matmul(dva, dvb, dvc, *aw_)
    hvf = hat_matmul(dva, dvb, dvc, *af_)
    hpw = hat_matmul(dpa, dpb, dpc, *aw_)
    hpf = hat_matmul(dpa, dpb, dpc, *af_)
    return block_rows(
        mat33_mul(*rn, *phw),
        mat33_mul(*rn, *phf),
        sub9(kvw, hvw),
        sub9(kvf, hvf),
        sub9(axpy9(t, kvw, kpw), hpw),
        sub9(axpy9(t, kvf, kpf), hpf),
    )


@kernel(inputs=[(11,), (11,), (11,), (9, 6), (), ()], outputs=[(9, 6), (45,)])
def preintegration_sensitivity(
    kw, kx, ky, kz, kva, kvb, kvc, kpa, kpb, kpc, kt,
    aw, ax, ay, az, ava, avb, avc, apa, apb, apc, at,
    nw, nx, ny, nz, nva, nvb, nvc, npa, npb, npc, nt,
    s00, s01, s02, s03, s04, s05,
    s10, s11, s12, s13, s14, s15,
    s20, s21, s22, s23, s24, s25,
    s30, s31, s32, s33, s34, s35,
    s40, s41, s42, s43, s44, s45,
    s50, s51, s52, s53, s54, s55,
    s60, s61, s62, s63, s64, s65,
    s70, s71, s72, s73, s74, s75,
    s80, s81, s82, s83, s84, s85,
    qg, qa,
):  # fmt: skip
    """``M = Phi(N, k+1) diag(I, R_k, R_k) S_k`` (9x6, :func:`sensitivity_entries`) and
    the step's covariance share ``M diag(qg I, qa I) M^T`` (upper triangle, 45
    entries), ``qg``, ``qa`` the discrete noise variances of the step's gyro and
    accelerometer inputs (0 for no covariance)."""
    s = (
        s00, s01, s02, s03, s04, s05,
        s10, s11, s12, s13, s14, s15,
        s20, s21, s22, s23, s24, s25,
        s30, s31, s32, s33, s34, s35,
        s40, s41, s42, s43, s44, s45,
        s50, s51, s52, s53, s54, s55,
        s60, s61, s62, s63, s64, s65,
        s70, s71, s72, s73, s74, s75,
        s80, s81, s82, s83, s84, s85,
    )  # fmt: skip
    m = sensitivity_entries(
        kw, kx, ky, kz, kva, kvb, kvc, kpa, kpb, kpc, kt,
        aw, ax, ay, az, ava, avb, avc, apa, apb, apc, at,
        nw, nx, ny, nz, nva, nvb, nvc, npa, npb, npc, nt,
        s,
    )  # fmt: skip
    return m + weighted_gram45(m, qg, qa)
