"""Kernels of turning frames: angular velocity and acceleration, quaternion rates.

Conventions: rotation matrices are active, row-major, ``v_A = A_R_B @ v_B``;
quaternions Hamilton, scalar first. A velocity is in the world frame (``R' =
hat(w) R``, the spatial velocity) or the body frame (``R' = R hat(w)``); the static
parameter ``body`` is 0 or 1 (Murray, Li & Sastry 1994, Sec. 2.4.1). For a frame
``B`` turning in ``A``: ``A_R_B' = hat(w_A) A_R_B = A_R_B hat(w_B)`` and, for the
inverse ``B_R_A = A_R_B^T``, ``B_R_A' = -B_R_A hat(w_A) = -hat(w_B) B_R_A``. Twists
and points of a moving body are in :mod:`.twist`.
"""

from ..._engine import helper, kernel
from ..quaternion import quat_multiply
from ..vector import cross3


@helper
def skew_vee_of_product(
    a0, a1, a2, a3, a4, a5, a6, a7, a8, b0, b1, b2, b3, b4, b5, b6, b7, b8
):
    """``vee`` of the skew part of ``M = A @ B``: ``(M21 - M12, M02 - M20, M10 - M01) / 2``.

    Only the six off-diagonal entries are formed (18 products, not 27).
    """
    m01 = a0 * b1 + a1 * b4 + a2 * b7
    m02 = a0 * b2 + a1 * b5 + a2 * b8
    m10 = a3 * b0 + a4 * b3 + a5 * b6
    m12 = a3 * b2 + a4 * b5 + a5 * b8
    m20 = a6 * b0 + a7 * b3 + a8 * b6
    m21 = a6 * b1 + a7 * b4 + a8 * b7
    return (0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01))


@helper
def omega_from_matrix_rate(
    body, r0, r1, r2, r3, r4, r5, r6, r7, r8, d0, d1, d2, d3, d4, d5, d6, d7, d8
):
    """``vee(D R^T)`` (world) or ``vee(R^T D)`` (body); ``R``, ``D`` row-major."""
    b = body == 1
    # world: D @ R^T; body: R^T @ D
    return skew_vee_of_product(
        where(b, r0, d0), where(b, r3, d1), where(b, r6, d2),
        where(b, r1, d3), where(b, r4, d4), where(b, r7, d5),
        where(b, r2, d6), where(b, r5, d7), where(b, r8, d8),
        where(b, d0, r0), where(b, d1, r3), where(b, d2, r6),
        where(b, d3, r1), where(b, d4, r4), where(b, d5, r7),
        where(b, d6, r2), where(b, d7, r5), where(b, d8, r8),
    )  # fmt: skip


@helper
def hat_sq_apply(wx, wy, wz, ax, ay, az, vx, vy, vz):
    """``(hat(a) + hat(w)^2) v = a x v + w x (w x v)``."""
    cx, cy, cz = cross3(ax, ay, az, vx, vy, vz)
    ux, uy, uz = cross3(wx, wy, wz, vx, vy, vz)
    dx, dy, dz = cross3(wx, wy, wz, ux, uy, uz)
    return (cx + dx, cy + dy, cz + dz)


@helper
def left_or_right_apply(body, wx, wy, wz, ax, ay, az, r):
    """``(hat(a) + hat(w)^2) R`` (world) or ``R (hat(a) + hat(w)^2)`` (body), row-major.

    World: column ``j`` is ``(hat(a) + hat(w)^2) r_j``. Body: row ``i`` is
    ``r_i^T (hat(a) + hat(w)^2) = ((hat(a) + hat(w)^2)^T r_i)^T`` and the transpose
    of ``hat(a) + hat(w)^2`` is ``hat(-a) + hat(w)^2``.
    """
    b = body == 1
    s = where(b, -1.0, 1.0)
    # world columns, or body rows, are the images of these three vectors
    u0 = (where(b, r[0], r[0]), where(b, r[1], r[3]), where(b, r[2], r[6]))
    u1 = (where(b, r[3], r[1]), where(b, r[4], r[4]), where(b, r[5], r[7]))
    u2 = (where(b, r[6], r[2]), where(b, r[7], r[5]), where(b, r[8], r[8]))
    f0 = hat_sq_apply(wx, wy, wz, s * ax, s * ay, s * az, *u0)
    f1 = hat_sq_apply(wx, wy, wz, s * ax, s * ay, s * az, *u1)
    f2 = hat_sq_apply(wx, wy, wz, s * ax, s * ay, s * az, *u2)
    return (
        f0[0], where(b, f0[1], f1[0]), where(b, f0[2], f2[0]),
        where(b, f1[0], f0[1]), f1[1], where(b, f1[2], f2[1]),
        where(b, f2[0], f0[2]), where(b, f2[1], f1[2]), f2[2],
    )  # fmt: skip


# -- rotation matrices ----------------------------------------------------------------


@kernel(inputs=[(3, 3), (3, 3)], outputs=[(3,)], params=("body",))
def omega_from_matrix_derivative(
    body, r0, r1, r2, r3, r4, r5, r6, r7, r8, d0, d1, d2, d3, d4, d5, d6, d7, d8
):
    """Angular velocity ``vee(R' R^T)`` (world) or ``vee(R^T R')`` (body).

    ``vee`` of the skew part, so a derivative off the tangent space by rounding
    (or a not quite orthogonal ``R``) is projected onto it.
    """
    return omega_from_matrix_rate(
        body, r0, r1, r2, r3, r4, r5, r6, r7, r8, d0, d1, d2, d3, d4, d5, d6, d7, d8
    )


@kernel(inputs=[(3, 3), (3, 3)], outputs=[(3,)], params=("body",))
def alpha_from_matrix_second_derivative(
    body, r0, r1, r2, r3, r4, r5, r6, r7, r8, d0, d1, d2, d3, d4, d5, d6, d7, d8
):
    """Angular acceleration ``vee(R'' R^T)`` (world) or ``vee(R^T R'')`` (body).

    From ``hat(w) = R' R^T``: ``hat(w)' = R'' R^T + R' R'^T``, and ``R' R'^T =
    -hat(w)^2`` is symmetric, so it drops out of ``vee`` of the skew part (body
    alike, ``R'^T R' = -hat(w_B)^2``). ``d`` is ``R''``.
    """
    return omega_from_matrix_rate(
        body, r0, r1, r2, r3, r4, r5, r6, r7, r8, d0, d1, d2, d3, d4, d5, d6, d7, d8
    )


@kernel(inputs=[(3, 3), (3,)], outputs=[(3, 3)], params=("body",))
def matrix_derivative_from_omega(body, r0, r1, r2, r3, r4, r5, r6, r7, r8, wx, wy, wz):
    """``R' = hat(w) R`` (world) or ``R hat(w)`` (body), row-major."""
    return left_or_right_apply(
        body, 0.0, 0.0, 0.0, wx, wy, wz, (r0, r1, r2, r3, r4, r5, r6, r7, r8)
    )


@kernel(inputs=[(3, 3), (3,), (3,)], outputs=[(3, 3)], params=("body",))
def matrix_second_derivative(
    body, r0, r1, r2, r3, r4, r5, r6, r7, r8, wx, wy, wz, ax, ay, az
):
    """``R'' = (hat(a) + hat(w)^2) R`` (world) or ``R (hat(a) + hat(w)^2)`` (body).

    Differentiating ``R' = hat(w) R``: ``R'' = hat(w') R + hat(w) R' = (hat(a) +
    hat(w)^2) R`` with ``a = w'`` (body alike).
    """
    return left_or_right_apply(
        body, wx, wy, wz, ax, ay, az, (r0, r1, r2, r3, r4, r5, r6, r7, r8)
    )


# -- quaternions ------------------------------------------------------------------------


@helper
def quat_times_pure(body, w, x, y, z, s, vx, vy, vz):
    """``q (s, v)`` (body) or ``(s, v) q`` (world)."""
    b = body == 1
    return quat_multiply(
        where(b, w, s), where(b, x, vx), where(b, y, vy), where(b, z, vz),
        where(b, s, w), where(b, vx, x), where(b, vy, y), where(b, vz, z),
    )  # fmt: skip


@kernel(inputs=[(4,), (3,)], outputs=[(4,)], params=("body",))
def quat_derivative(body, w, x, y, z, wx, wy, wz):
    """``q' = q (0, w) / 2`` (body) or ``(0, w) q / 2`` (world), Hamilton."""
    return quat_times_pure(body, w, x, y, z, 0.0, 0.5 * wx, 0.5 * wy, 0.5 * wz)


@kernel(inputs=[(4,), (3,), (3,)], outputs=[(4,)], params=("body",))
def quat_second_derivative(body, w, x, y, z, wx, wy, wz, ax, ay, az):
    """``q'' = q (-|w|^2/4, a/2)`` (body) or ``(-|w|^2/4, a/2) q`` (world).

    Differentiating ``q' = q (0, w)/2``: ``q'' = q (0, w)(0, w)/4 + q (0, a)/2`` and
    ``(0, w)(0, w) = (-|w|^2, w x w) = (-|w|^2, 0)``.
    """
    s = -0.25 * (wx * wx + wy * wy + wz * wz)
    return quat_times_pure(body, w, x, y, z, s, 0.5 * ax, 0.5 * ay, 0.5 * az)


@kernel(inputs=[(4,), (4,)], outputs=[(3,)], params=("body",))
def omega_from_quat_derivative(body, w, x, y, z, dw, dx, dy, dz):
    """``w = 2 vec(q* q') / |q|^2`` (body) or ``2 vec(q' q*) / |q|^2`` (world).

    For ``q = s u`` (``u`` unit, ``s(t) > 0``) the scale's rate only enters the
    scalar part, so any scale of ``q`` gives the rotation's velocity. ``q`` and
    ``q'`` are divided by ``max |q_i|`` first (no overflow); a zero ``q`` gives
    zeros (callers reject it).
    """
    m = maximum(maximum(abs(w), abs(x)), maximum(abs(y), abs(z)))
    k = 1.0 / where(m > 0.0, m, 1.0)
    w = w * k
    x = x * k
    y = y * k
    z = z * k
    n2 = w * w + x * x + y * y + z * z
    g = 2.0 * k / where(m > 0.0, n2, 1.0)
    b = body == 1
    p = quat_multiply(
        where(b, w, dw), where(b, -x, dx), where(b, -y, dy), where(b, -z, dz),
        where(b, dw, w), where(b, dx, -x), where(b, dy, -y), where(b, dz, -z),
    )  # fmt: skip
    return (g * p[1], g * p[2], g * p[3])
