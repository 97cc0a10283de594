"""Kernels on quaternions ``(w, x, y, z)``, Hamilton convention (``ij = k``)."""

from .._engine import helper, kernel
from .coefficients import norm3
from .vector import cross3, normalize4, renormalize4


@kernel(inputs=[(4,)], outputs=[(4,), ()])
def quat_normalize(w, x, y, z):
    """Unit quaternion and the input's norm, without overflow or underflow.

    Scaling by the largest component first keeps the squares in range for any
    finite input from 1e-308 to 1e308. A zero quaternion gives zero components and norm
    0, which callers reject.
    """
    return normalize4(w, x, y, z)


@helper
def quat_hemisphere(w, x, y, z):
    """``q`` or ``-q``, whichever has ``w >= 0``: the same rotation, angle in [0, pi].

    ``w = -0.0`` counts as ``w >= 0`` (no flip), as does ``w = 0`` (angle pi).
    """
    s = where(w < 0.0, -1.0, 1.0)
    return (s * w, s * x, s * y, s * z)


@helper
def quat_angle(w, x, y, z):
    """Rotation angle of ``q`` in [0, pi]: ``2 atan2(|v|, |w|)``, any scale of ``q``.

    ``atan2`` has no cancellation near 0 or pi (unlike ``2 acos(w)``); ``norm3``
    keeps the gradient finite at the identity.
    """
    w, x, y, z = quat_hemisphere(w, x, y, z)
    return 2.0 * atan2(norm3(x, y, z), w)


@kernel(inputs=[(4,), (4,)], outputs=[(4,)])
def quat_multiply(w1, x1, y1, z1, w2, x2, y2, z2):
    """Hamilton product ``q1 q2`` (as rotations: ``q2`` first, then ``q1``).

    Each vector component sums its two pairs of terms separately, ``(w1 v2 + v1 w2)
    + (v1 x v2)``: for ``q1 = q2*`` (or ``q2 = q1*``) each pair is a product minus
    the same product, exactly 0 in IEEE arithmetic, so ``q* q`` and ``q q*`` have a
    vector part of exactly 0 (summed left to right it keeps a rounding residue of
    ~1e-17). The numba loops are compiled without fast-math, so no FMA contraction
    breaks this.
    """
    return (
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        (w1 * x2 + x1 * w2) + (y1 * z2 - z1 * y2),
        (w1 * y2 + y1 * w2) + (z1 * x2 - x1 * z2),
        (w1 * z2 + z1 * w2) + (x1 * y2 - y1 * x2),
    )


@kernel(inputs=[(4,), (4,)], outputs=[(4,)])
def quat_compose(w1, x1, y1, z1, w2, x2, y2, z2):
    """Composition of rotations ``q1 q2`` (``q2`` first): the Hamilton product of
    unit quaternions, renormalised (:func:`~rigidkit.kernels.vector.renormalize4`)
    so that chains of compositions stay unit to a few ulp.

    :func:`quat_multiply` is the bare product, for the algebra of any quaternions.
    """
    w, x, y, z = quat_multiply(w1, x1, y1, z1, w2, x2, y2, z2)
    return renormalize4(w, x, y, z)


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
    cx, cy, cz = cross3(x, y, z, vx, vy, vz)
    tx = 2.0 * cx
    ty = 2.0 * cy
    tz = 2.0 * cz
    ux, uy, uz = cross3(x, y, z, tx, ty, tz)
    return (vx + w * tx + ux, vy + w * ty + uy, vz + w * tz + uz)


@kernel(inputs=[(4,), (4,)], outputs=[()])
def quat_angle_between(w1, x1, y1, z1, w2, x2, y2, z2):
    """Rotation angle of ``q1* q2`` in [0, pi], from ``atan2`` (no acos cancellation)."""
    w, x, y, z = quat_multiply(w1, -x1, -y1, -z1, w2, x2, y2, z2)
    return (quat_angle(w, x, y, z),)
