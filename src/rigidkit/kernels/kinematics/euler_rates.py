"""Kernels of Euler-angle kinematics: the rate matrix ``E``, its inverse and ``dE/dt``.

``omega = E(angles) @ d(angles)/dt`` with the angles and rates in the sequence's
own order, ``omega`` the angular velocity in the world frame (``vee(R' R^T)``) or the
body frame (``vee(R^T R')``). One kernel serves all 24 sequences, with the static
parameters of :mod:`rigidkit.kernels.euler` (``e1, e2, parity, proper, reverse``;
matrix-product order ``R = R_e1(t1) R_e2(t2) R_e3(t3)``) and ``body`` (0 world, 1
body).

Derivation. With ``a_k`` the unit axis of factor ``k`` and ``R_k`` the factor,
``R' R^T = t1' hat(a1) + t2' R_1 hat(a2) R_1^T + t3' R_1 R_2 hat(a3) (R_1 R_2)^T``,
so the columns of ``E`` (product order) are, in the world frame,
``c1 = a1, c2 = R_1 a2, c3 = R_1 R_2 a3``, and in the body frame
``b1 = (R_2 R_3)^T a1, b2 = R_3^T a2, b3 = a3``. In the permuted coordinates
``p = (v[e1], v[e2], v[m])`` (``m`` the third axis) every sequence is the cyclic
one, ``xyz`` or ``xyx``, with each angle multiplied by ``parity`` (a permutation
of odd parity reverses the sense of turning); since both ``omega`` and the axes
are permuted alike, the sign cancels in ``E`` itself (``P omega = E_xyz(parity t)
t'``). With ``S_k = parity sin t_k``, ``C_k = cos t_k`` the columns are:

=================  =====================  =====================
                   Tait-Bryan (xyz)       proper (xyx)
=================  =====================  =====================
world ``c1``       ``(1, 0, 0)``          ``(1, 0, 0)``
world ``c2``       ``(0, C1, S1)``        ``(0, C1, S1)``
world ``c3``       ``(S2, -S1 C2, C1 C2)`` ``(C2, S1 S2, -C1 S2)``
body ``b1``        ``(C2 C3, -C2 S3, S2)`` ``(C2, S2 S3, S2 C3)``
body ``b2``        ``(S3, C3, 0)``        ``(0, C3, -S3)``
body ``b3``        ``(0, 0, 1)``          ``(1, 0, 0)``
=================  =====================  =====================

``det E = C2`` (Tait-Bryan) or ``S2`` (proper) up to sign: ``E`` is singular at
gimbal lock, a middle angle of ``+-pi/2`` or ``0, pi``.

The derivative of a column is a cross product (each column is a fixed axis turned
by the factors before it): world ``c2' = t1' c1 x c2``, ``c3' = (t1' c1 + t2' c2)
x c3``; body ``b2' = -t3' b3 x b2``, ``b1' = -(t3' b3 + t2' b2) x b1``; in the
permuted coordinates the turning rates carry the parity too. ``E'`` is exact, no
finite difference.
"""

from ..._engine import helper, kernel
from ..vector import cross3  # noqa: F401  (bound by name)


@helper
def euler_product_order(reverse, a0, a1, a2):
    """``(t1, t2, t3)`` in matrix-product order from values in sequence order."""
    rev = reverse == 1
    return (where(rev, a2, a0), a1, where(rev, a0, a2))


@helper
def parity_sines_cosines(parity, t1, t2, t3):
    """``(S1, C1, S2, C2, S3, C3)``, ``S_k = parity sin t_k``, ``C_k = cos t_k``."""
    return (
        parity * sin(t1), cos(t1),
        parity * sin(t2), cos(t2),
        parity * sin(t3), cos(t3),
    )  # fmt: skip


@helper
def body_or_world(body, bod, world):
    """The 9 entries ``bod`` for ``body == 1``, else ``world``."""
    b = body == 1
    return (
        where(b, bod[0], world[0]),
        where(b, bod[1], world[1]),
        where(b, bod[2], world[2]),
        where(b, bod[3], world[3]),
        where(b, bod[4], world[4]),
        where(b, bod[5], world[5]),
        where(b, bod[6], world[6]),
        where(b, bod[7], world[7]),
        where(b, bod[8], world[8]),
    )


@helper
def euler_rate_columns(parity, proper, body, t1, t2, t3):
    """The 9 entries of ``E`` in permuted coordinates, column by column (product order).

    See the module docstring for the table.
    """
    s1, c1, s2, c2, s3, c3 = parity_sines_cosines(parity, t1, t2, t3)
    pr = proper == 1
    world = (
        1.0, 0.0, 0.0,
        0.0, c1, s1,
        where(pr, c2, s2), where(pr, s1 * s2, -s1 * c2), where(pr, -c1 * s2, c1 * c2),
    )  # fmt: skip
    bod = (
        where(pr, c2, c2 * c3), where(pr, s2 * s3, -c2 * s3), where(pr, s2 * c3, s2),
        where(pr, 0.0, s3), c3, where(pr, -s3, 0.0),
        where(pr, 1.0, 0.0), 0.0, where(pr, 0.0, 1.0),
    )  # fmt: skip
    return body_or_world(body, bod, world)


@helper
def euler_rate_column_derivatives(parity, proper, body, t1, t2, t3, r1, r2, r3):
    """``dE/dt`` in permuted coordinates (column by column, product order).

    ``r1, r2, r3`` are the angle rates in product order. Cross products of the
    columns (module docstring); the permuted frame turns by ``parity * r``.
    """
    c = euler_rate_columns(parity, proper, body, t1, t2, t3)
    u1 = parity * r1
    u2 = parity * r2
    u3 = parity * r3
    # world: c2' = u1 c1 x c2, c3' = (u1 c1 + u2 c2) x c3
    w2 = cross3(u1 * c[0], u1 * c[1], u1 * c[2], c[3], c[4], c[5])
    w3 = cross3(
        u1 * c[0] + u2 * c[3],
        u1 * c[1] + u2 * c[4],
        u1 * c[2] + u2 * c[5],
        c[6],
        c[7],
        c[8],
    )
    # body: b2' = -u3 b3 x b2, b1' = -(u3 b3 + u2 b2) x b1
    v2 = cross3(c[3], c[4], c[5], u3 * c[6], u3 * c[7], u3 * c[8])
    v1 = cross3(
        c[0],
        c[1],
        c[2],
        u3 * c[6] + u2 * c[3],
        u3 * c[7] + u2 * c[4],
        u3 * c[8] + u2 * c[5],
    )
    b = body == 1
    return (
        where(b, v1[0], 0.0),
        where(b, v1[1], 0.0),
        where(b, v1[2], 0.0),
        where(b, v2[0], w2[0]),
        where(b, v2[1], w2[1]),
        where(b, v2[2], w2[2]),
        where(b, 0.0, w3[0]),
        where(b, 0.0, w3[1]),
        where(b, 0.0, w3[2]),
    )


@helper
def euler_rate_inverse_rows(parity, proper, body, t1, t2, t3):
    """``E^-1`` in permuted coordinates (row by row, product order) and ``det``.

    Closed forms of the inverse of the columns' matrix (module docstring), with
    ``1 / D``, ``D = C2`` (Tait-Bryan) or ``S2`` (proper), evaluated at a safe
    denominator so the rows stay finite at the lock (the caller rejects it by the
    returned ``D``).
    """
    s1, c1, s2, c2, s3, c3 = parity_sines_cosines(parity, t1, t2, t3)
    pr = proper == 1
    d = where(pr, s2, c2)
    k = 1.0 / where(abs(d) > 0.0, d, 1.0)
    world = (
        1.0, where(pr, -c2 * s1 * k, s1 * s2 * k), where(pr, c2 * c1 * k, -c1 * s2 * k),
        0.0, c1, s1,
        0.0, where(pr, s1 * k, -s1 * k), where(pr, -c1 * k, c1 * k),
    )  # fmt: skip
    bod = (
        where(pr, 0.0, c3 * k), where(pr, s3 * k, -s3 * k), where(pr, c3 * k, 0.0),
        where(pr, 0.0, s3), c3, where(pr, -s3, 0.0),
        where(pr, 1.0, -s2 * c3 * k), where(pr, -c2 * s3 * k, s2 * s3 * k),
        where(pr, -c2 * c3 * k, 1.0),
    )  # fmt: skip
    return body_or_world(body, bod, world) + (d,)


@helper
def lock_sine(d):
    """``|D|``: the sine of the angle from the middle angle to the nearest lock.

    ``D = cos t2`` (Tait-Bryan) or ``sin t2`` (proper) up to sign, and the nearest
    zero of ``cos`` (``sin``) is ``asin(|D|)`` away, exactly; callers compare
    ``|D|`` with ``sin(tol)`` (monotonic, so the same test) and take the
    ``asin`` only to report a failure, not once per element.
    """
    return abs(d)


@helper
def permuted_to_world_3(e1, e2, p0, p1, p2):
    """Components on axes ``(x, y, z)`` of a vector given on ``(e1, e2, m)``."""
    return (
        where(e1 == 0, p0, where(e2 == 0, p1, p2)),
        where(e1 == 1, p0, where(e2 == 1, p1, p2)),
        where(e1 == 2, p0, where(e2 == 2, p1, p2)),
    )


@helper
def permuted_from_world_3(e1, e2, x, y, z):
    """Components on axes ``(e1, e2, m)`` of a vector given on ``(x, y, z)``."""
    w = (x, y, z)
    return (w[e1], w[e2], w[3 - e1 - e2])


@helper
def columns_times(c, u1, u2, u3):
    """``c[0:3] u1 + c[3:6] u2 + c[6:9] u3``: the matrix of columns ``c`` times ``u``."""
    return (
        c[0] * u1 + c[3] * u2 + c[6] * u3,
        c[1] * u1 + c[4] * u2 + c[7] * u3,
        c[2] * u1 + c[5] * u2 + c[8] * u3,
    )


@helper
def triples_in_sequence_order(e1, e2, reverse, v):
    """``v[0:3], v[3:6], v[6:9]`` (product order, permuted coordinates) in sequence order.

    Each triple on axes ``(x, y, z)``; the sequence's first angle is the
    product's last for extrinsic sequences.
    """
    rev = reverse == 1
    k0 = where(rev, 2, 0)
    k2 = where(rev, 0, 2)
    return (
        permuted_to_world_3(e1, e2, v[3 * k0], v[3 * k0 + 1], v[3 * k0 + 2]),
        permuted_to_world_3(e1, e2, v[3], v[4], v[5]),
        permuted_to_world_3(e1, e2, v[3 * k2], v[3 * k2 + 1], v[3 * k2 + 2]),
    )


@helper
def matrix_entries_from_columns(e1, e2, reverse, scale, c):
    """Row-major ``E`` on axes ``(x, y, z)`` and angles in sequence order.

    ``c`` holds the columns in permuted coordinates and product order
    (:func:`triples_in_sequence_order`).
    """
    col0, col1, col2 = triples_in_sequence_order(e1, e2, reverse, c)
    return (
        scale * col0[0], scale * col1[0], scale * col2[0],
        scale * col0[1], scale * col1[1], scale * col2[1],
        scale * col0[2], scale * col1[2], scale * col2[2],
    )  # fmt: skip


@helper
def dot3(ax, ay, az, bx, by, bz):
    """``a . b``."""
    return ax * bx + ay * by + az * bz


@helper
def rows_times_in_sequence_order(reverse, scale, r, p0, p1, p2):
    """``(r[0:3] . p, r[3:6] . p, r[6:9] . p) / scale`` in sequence order.

    ``r`` holds three rows in product order, ``p`` is in permuted coordinates.
    """
    inv = 1.0 / scale
    u1 = inv * dot3(r[0], r[1], r[2], p0, p1, p2)
    u2 = inv * dot3(r[3], r[4], r[5], p0, p1, p2)
    u3 = inv * dot3(r[6], r[7], r[8], p0, p1, p2)
    return euler_product_order(reverse, u1, u2, u3)


@helper
def rates_from_inverse_rows(reverse, scale, r, p0, p1, p2):
    """``E^-1 p`` in sequence order, and :func:`lock_sine`.

    ``r`` from :func:`euler_rate_inverse_rows`, ``p`` in permuted coordinates;
    divided by ``scale`` (rates in the angles' unit).
    """
    rates = rows_times_in_sequence_order(reverse, scale, r, p0, p1, p2)
    return rates + (lock_sine(r[9]),)


_PARAMS = ("e1", "e2", "parity", "proper", "reverse", "body", "scale")


@kernel(inputs=[(3,)], outputs=[(3, 3)], params=_PARAMS)
def rate_matrix_from_euler(e1, e2, parity, proper, reverse, body, scale, a0, a1, a2):
    """``E`` with ``omega = E @ rates``, row-major; see the module docstring.

    ``scale`` is radians per angle unit: the angles are multiplied by it, and so
    is ``E`` (rates in degrees per unit time give ``omega`` in radians).
    """
    t1, t2, t3 = euler_product_order(reverse, a0 * scale, a1 * scale, a2 * scale)
    c = euler_rate_columns(parity, proper, body, t1, t2, t3)
    return matrix_entries_from_columns(e1, e2, reverse, scale, c)


@kernel(inputs=[(3,), (3,)], outputs=[(3, 3)], params=_PARAMS)
def rate_matrix_derivative_from_euler(
    e1, e2, parity, proper, reverse, body, scale, a0, a1, a2, r0, r1, r2
):
    """``dE/dt`` for angles ``a`` changing at rates ``r`` (both in sequence order)."""
    t1, t2, t3 = euler_product_order(reverse, a0 * scale, a1 * scale, a2 * scale)
    u1, u2, u3 = euler_product_order(reverse, r0 * scale, r1 * scale, r2 * scale)
    c = euler_rate_column_derivatives(parity, proper, body, t1, t2, t3, u1, u2, u3)
    return matrix_entries_from_columns(e1, e2, reverse, scale, c)


@kernel(inputs=[(3,)], outputs=[(3, 3), ()], params=_PARAMS)
def rate_matrix_inverse_from_euler(
    e1, e2, parity, proper, reverse, body, scale, a0, a1, a2
):
    """``E^-1`` (row-major; rows in sequence order, columns x, y, z) and the lock distance.

    The second output is the sine of the angle from the middle angle to the
    nearest gimbal lock (:func:`lock_sine`); ``E^-1`` grows as its inverse, and
    callers reject it below their tolerance. Rows are divided by ``scale`` (rates
    in the angles' unit).
    """
    t1, t2, t3 = euler_product_order(reverse, a0 * scale, a1 * scale, a2 * scale)
    r = euler_rate_inverse_rows(parity, proper, body, t1, t2, t3)
    row0, row1, row2 = triples_in_sequence_order(e1, e2, reverse, r)
    inv = 1.0 / scale
    return (
        inv * row0[0], inv * row0[1], inv * row0[2],
        inv * row1[0], inv * row1[1], inv * row1[2],
        inv * row2[0], inv * row2[1], inv * row2[2],
        lock_sine(r[9]),
    )  # fmt: skip


@kernel(inputs=[(3,), (3,)], outputs=[(3,)], params=_PARAMS)
def omega_from_euler_rates(
    e1, e2, parity, proper, reverse, body, scale, a0, a1, a2, r0, r1, r2
):
    """``omega = E @ rates`` without forming ``E`` in memory."""
    t1, t2, t3 = euler_product_order(reverse, a0 * scale, a1 * scale, a2 * scale)
    u1, u2, u3 = euler_product_order(reverse, r0 * scale, r1 * scale, r2 * scale)
    c = euler_rate_columns(parity, proper, body, t1, t2, t3)
    p0, p1, p2 = columns_times(c, u1, u2, u3)
    return permuted_to_world_3(e1, e2, p0, p1, p2)


@kernel(inputs=[(3,), (3,)], outputs=[(3,), ()], params=_PARAMS)
def euler_rates_from_omega(
    e1, e2, parity, proper, reverse, body, scale, a0, a1, a2, wx, wy, wz
):
    """``rates = E^-1 @ omega`` (sequence order) and :func:`lock_sine`."""
    t1, t2, t3 = euler_product_order(reverse, a0 * scale, a1 * scale, a2 * scale)
    r = euler_rate_inverse_rows(parity, proper, body, t1, t2, t3)
    p0, p1, p2 = permuted_from_world_3(e1, e2, wx, wy, wz)
    return rates_from_inverse_rows(reverse, scale, r, p0, p1, p2)


@kernel(inputs=[(3,), (3,), (3,)], outputs=[(3,)], params=_PARAMS)
def alpha_from_euler_accelerations(
    e1, e2, parity, proper, reverse, body, scale, a0, a1, a2, r0, r1, r2, d0, d1, d2
):
    """Angular acceleration ``alpha = E @ accel + E' @ rates`` (``E'`` exact)."""
    t1, t2, t3 = euler_product_order(reverse, a0 * scale, a1 * scale, a2 * scale)
    u1, u2, u3 = euler_product_order(reverse, r0 * scale, r1 * scale, r2 * scale)
    g1, g2, g3 = euler_product_order(reverse, d0 * scale, d1 * scale, d2 * scale)
    c = euler_rate_columns(parity, proper, body, t1, t2, t3)
    dc = euler_rate_column_derivatives(parity, proper, body, t1, t2, t3, u1, u2, u3)
    p0 = c[0] * g1 + c[3] * g2 + c[6] * g3 + dc[0] * u1 + dc[3] * u2 + dc[6] * u3
    p1 = c[1] * g1 + c[4] * g2 + c[7] * g3 + dc[1] * u1 + dc[4] * u2 + dc[7] * u3
    p2 = c[2] * g1 + c[5] * g2 + c[8] * g3 + dc[2] * u1 + dc[5] * u2 + dc[8] * u3
    return permuted_to_world_3(e1, e2, p0, p1, p2)


@kernel(inputs=[(3,), (3,), (3,)], outputs=[(3,), ()], params=_PARAMS)
def euler_accelerations_from_alpha(
    e1, e2, parity, proper, reverse, body, scale, a0, a1, a2, r0, r1, r2, ax, ay, az
):
    """Euler second derivatives ``E^-1 (alpha - E' @ rates)`` and :func:`lock_sine`."""
    t1, t2, t3 = euler_product_order(reverse, a0 * scale, a1 * scale, a2 * scale)
    u1, u2, u3 = euler_product_order(reverse, r0 * scale, r1 * scale, r2 * scale)
    dc = euler_rate_column_derivatives(parity, proper, body, t1, t2, t3, u1, u2, u3)
    r = euler_rate_inverse_rows(parity, proper, body, t1, t2, t3)
    l0, l1, l2 = permuted_from_world_3(e1, e2, ax, ay, az)
    q0, q1, q2 = columns_times(dc, u1, u2, u3)
    return rates_from_inverse_rows(reverse, scale, r, l0 - q0, l1 - q1, l2 - q2)


@kernel(inputs=[(3,), (3,)], outputs=[(3,)], params=_PARAMS)
def euler_rates_projected(
    e1, e2, parity, proper, reverse, body, scale, a0, a1, a2, wx, wy, wz
):
    """``E^T @ omega / scale^2`` (sequence order; ``E = scale Q``): the rates of the
    sequences of one and two axes (the angles padded with zeros, see
    :func:`~rigidkit.functional.euler.parse_short_sequence`).

    The first one or two columns of ``E`` (the axes of the given turns, each moved
    by the turns before it or undone by those after it) are orthonormal times
    ``scale``: consecutive axes are perpendicular and a turn about one axis keeps
    its neighbour perpendicular to it. Their pseudo-inverse is therefore their
    transpose over ``scale^2``, and these entries of ``E^T omega / scale^2`` are
    the least-squares rates, exact where ``omega`` is in their span.
    """
    t1, t2, t3 = euler_product_order(reverse, a0 * scale, a1 * scale, a2 * scale)
    c = euler_rate_columns(parity, proper, body, t1, t2, t3)
    p0, p1, p2 = permuted_from_world_3(e1, e2, wx, wy, wz)
    # E^T / scale^2 = Q^T / scale, Q the unit columns
    return rows_times_in_sequence_order(reverse, scale, c, p0, p1, p2)


@kernel(inputs=[(3,)], outputs=[(3, 3)], params=_PARAMS)
def rate_matrix_transpose_from_euler(
    e1, e2, parity, proper, reverse, body, scale, a0, a1, a2
):
    """``E^T / scale^2`` (rows in sequence order, columns x, y, z): its first one or
    two rows are the pseudo-inverse of the rate matrix of a sequence of one or two
    axes (:func:`euler_rates_projected`)."""
    t1, t2, t3 = euler_product_order(reverse, a0 * scale, a1 * scale, a2 * scale)
    c = euler_rate_columns(parity, proper, body, t1, t2, t3)
    inv = 1.0 / scale
    e = matrix_entries_from_columns(e1, e2, reverse, inv, c)  # Q^T / scale
    return (e[0], e[3], e[6], e[1], e[4], e[7], e[2], e[5], e[8])
