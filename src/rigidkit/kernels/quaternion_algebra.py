"""Kernels of the general quaternion algebra ``H`` (not necessarily unit quaternions).

Components ``(w, x, y, z)`` = ``w + x i + y j + z k``, Hamilton (``i^2 = j^2 = k^2 =
ijk = -1``). The product, conjugate, normalisation and the rotation of a vector by
a unit quaternion are in :mod:`.quaternion`; this module adds what a non-unit
quaternion needs: inverse, exp, log and the 4x4 product matrices.
"""

from .._engine import helper, kernel
from .coefficients import sinc  # noqa: F401  (bound by name)


@helper
def scaled_norm3(x, y, z):
    """``(m, r)`` with ``|(x, y, z)| = m r``: ``m`` the largest ``|component|``.

    ``r`` is in ``[1, sqrt(3)]`` unless the vector is zero (then ``m = r = 0``), so
    no square under- or overflows for any finite input; ``(x, y, z) / (m r)`` is
    the unit direction to an ulp.
    """
    m = maximum(maximum(abs(x), abs(y)), abs(z))
    pos = m > 0.0
    safe = where(pos, m, 1.0)
    xs = x / safe
    ys = y / safe
    zs = z / safe
    # the root at a safe argument: a finite (zero) gradient at the origin, not NaN
    return (m, where(pos, sqrt(where(pos, xs * xs + ys * ys + zs * zs, 1.0)), 0.0))


@kernel(inputs=[(4,)], outputs=[(4,), ()])
def quat_inverse(w, x, y, z):
    """``q^-1 = q* / |q|^2``, scaled by the largest component (no overflow); and ``m``.

    With ``m = max|q_i|`` and ``q = m p``: ``q^-1 = p* / (|p|^2 m)``, ``|p|^2`` in
    [1, 4]. The zero quaternion gives zeros and ``m = 0``, which callers reject.
    """
    m = maximum(maximum(abs(w), abs(x)), maximum(abs(y), abs(z)))
    safe = where(m > 0.0, m, 1.0)
    w1 = w / safe
    x1 = x / safe
    y1 = y / safe
    z1 = z / safe
    n2 = w1 * w1 + x1 * x1 + y1 * y1 + z1 * z1
    k = 1.0 / (where(m > 0.0, n2, 1.0) * safe)
    return (k * w1, -k * x1, -k * y1, -k * z1, m)


@kernel(inputs=[(4,)], outputs=[(4,)])
def quat_exp(w, x, y, z):
    """``exp(w + v) = e^w (cos|v|, sin|v| v / |v|)`` = ``e^w (cos|v|, sinc(|v|) v)``.

    ``sinc`` carries the small-|v| series, so a tiny or zero vector part is exact;
    ``|v|`` is formed without overflow. Overflows (inf) once ``w`` > ~709.78
    (float64), like ``exp`` itself.
    """
    m, r = scaled_norm3(x, y, z)
    n = m * r
    e = exp(w)
    k = e * sinc(n)
    return (e * cos(n), k * x, k * y, k * z)


@kernel(inputs=[(4,)], outputs=[(4,), ()])
def quat_log(w, x, y, z):
    """Principal logarithm ``(log|q|, theta u)``, ``theta = atan2(|v|, w)`` in [0, pi].

    ``u = v / |v|`` is the unit direction of the vector part. No threshold is
    needed: ``atan2`` is accurate to an ulp for every ratio and ``theta u`` has no
    cancellation (unlike ``acos(w / |q|)``), small ``|v|`` included. Both norms
    are scaled by the largest component, so any finite nonzero ``q`` works.

    On the negative real axis (``v = 0``, ``w < 0``) the logarithm is ``log|w| + pi
    u`` for every unit ``u``; we return ``u = +i`` (``(log|w|, pi, 0, 0)``), the
    axis rigidkit also gives the identity rotation. Positive reals get ``(log w, 0,
    0, 0)``. The zero quaternion has no logarithm: the second output, ``max|q_i|``,
    is 0 for it, and callers reject it.
    """
    mv, rv = scaled_norm3(x, y, z)
    has_v = mv > 0.0
    theta = atan2(mv * rv, w)
    # u = (v / mv) / rv: neither factor under- or overflows.
    d1 = where(has_v, mv, 1.0)
    d2 = where(has_v, rv, 1.0)
    ux = where(has_v, x / d1 / d2, 1.0)
    uy = y / d1 / d2
    uz = z / d1 / d2
    # log|q| = log(M) + log(|q| / M), M = max |q_i|: |q| / M is in [1, 2].
    big = maximum(abs(w), mv)
    safe_big = where(big > 0.0, big, 1.0)
    ws = w / safe_big
    ns = mv / safe_big * rv
    rq = sqrt(ws * ws + ns * ns)
    log_norm = log(safe_big) + log(where(big > 0.0, rq, 1.0))
    return (log_norm, theta * ux, theta * uy, theta * uz, big)


@kernel(inputs=[(4,)], outputs=[(4, 4)])
def quat_left_matrix(w, x, y, z):
    """``q+`` with ``q p = q+ p`` (as 4-vectors): ``[[w, -v^T], [v, w I + hat(v)]]``."""
    return (
        w, -x, -y, -z,
        x, w, -z, y,
        y, z, w, -x,
        z, -y, x, w,
    )  # fmt: skip


@kernel(inputs=[(4,)], outputs=[(4, 4)])
def quat_right_matrix(w, x, y, z):
    """``q(+)`` with ``p q = q(+) p`` (as 4-vectors): ``[[w, -v^T], [v, w I - hat(v)]]``."""
    return (
        w, -x, -y, -z,
        x, w, z, -y,
        y, -z, w, x,
        z, y, -x, w,
    )  # fmt: skip
