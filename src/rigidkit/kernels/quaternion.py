"""Kernels on quaternions ``(w, x, y, z)``, Hamilton convention (``ij = k``)."""

from .._engine import kernel


@kernel(inputs=[(4,)], outputs=[(4,), ()])
def quat_normalize(w, x, y, z):
    """Unit quaternion and the input's norm, without overflow or underflow.

    Scaling by the largest component first keeps the squares in range for any
    finite input from 1e-308 to 1e308. A zero quaternion gives zero components and norm
    0, which callers reject.
    """
    m = maximum(maximum(abs(w), abs(x)), maximum(abs(y), abs(z)))
    safe = where(m > 0.0, m, 1.0)
    w1 = w / safe
    x1 = x / safe
    y1 = y / safe
    z1 = z / safe
    n = sqrt(w1 * w1 + x1 * x1 + y1 * y1 + z1 * z1)
    safe_n = where(m > 0.0, n, 1.0)
    return (w1 / safe_n, x1 / safe_n, y1 / safe_n, z1 / safe_n, n * m)


@kernel(inputs=[(4,), (4,)], outputs=[(4,)])
def quat_multiply(w1, x1, y1, z1, w2, x2, y2, z2):
    """Hamilton product ``q1 q2`` (as rotations: ``q2`` first, then ``q1``)."""
    return (
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    )


@kernel(inputs=[(4,)], outputs=[(4,)])
def quat_conjugate(w, x, y, z):
    """Conjugate ``(w, -x, -y, -z)``: the inverse rotation of a unit quaternion."""
    return (w, -x, -y, -z)


@kernel(inputs=[(4,)], outputs=[(4,)])
def quat_canonical(w, x, y, z):
    """The sign of ``q`` with ``w >= 0`` (first nonzero of w, x, y, z positive).

    Written with ``<`` and ``>`` only: on SymPy expressions ``==`` and ``!=`` compare
    structure, not value.
    """
    s = where(
        w < 0.0,
        -1.0,
        where(
            w > 0.0,
            1.0,
            where(
                x < 0.0,
                -1.0,
                where(
                    x > 0.0,
                    1.0,
                    where(y < 0.0, -1.0, where(y > 0.0, 1.0, where(z < 0.0, -1.0, 1.0))),
                ),
            ),
        ),
    )
    return (s * w, s * x, s * y, s * z)


@kernel(inputs=[(4,), (3,)], outputs=[(3,)])
def quat_apply(w, x, y, z, vx, vy, vz):
    """Rotate ``v`` by unit ``q``: ``q v q*`` = ``v + w t + u x t``, ``t = 2 u x v``."""
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + y * tz - z * ty,
        vy + w * ty + z * tx - x * tz,
        vz + w * tz + x * ty - y * tx,
    )


@kernel(inputs=[(4,), (4,)], outputs=[()])
def quat_angle_between(w1, x1, y1, z1, w2, x2, y2, z2):
    """Rotation angle of ``q1* q2`` in [0, pi], from ``atan2`` (no acos cancellation)."""
    w = w1 * w2 + x1 * x2 + y1 * y2 + z1 * z2
    x = w1 * x2 - x1 * w2 - y1 * z2 + z1 * y2
    y = w1 * y2 + x1 * z2 - y1 * w2 - z1 * x2
    z = w1 * z2 - x1 * y2 + y1 * x2 - z1 * w2
    return (2.0 * atan2(sqrt(x * x + y * y + z * z), abs(w)),)
