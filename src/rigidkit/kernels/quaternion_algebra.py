"""Kernels of the general quaternion algebra ``H`` (not necessarily unit quaternions).

Components ``(w, x, y, z)`` = ``w + x i + y j + z k``, Hamilton (``i^2 = j^2 = k^2 =
ijk = -1``). The product, conjugate, normalisation and the rotation of a vector by
a unit quaternion are in :mod:`.quaternion`; this module adds what a non-unit
quaternion needs: inverse, exp, log and the 4x4 product matrices.
"""

from .._engine import kernel
from .coefficients import atan_ratio, norm3, sinc
from .so3 import cos_of_norm
from .vector import normalize4, scaled4


@kernel(inputs=[(4,)], outputs=[(4,), ()])
def quat_inverse(w, x, y, z):
    """``q^-1 = q* / |q|^2``, scaled by the largest component (no overflow); and ``m``.

    With ``m = max|q_i|`` and ``q = m p``: ``q^-1 = p* / (|p|^2 m)``, ``|p|^2`` in
    [1, 4]. The zero quaternion gives zeros and ``m = 0``, which callers reject.
    """
    w1, x1, y1, z1, m, r = scaled4(w, x, y, z)
    pos = m > 0.0
    k = 1.0 / (where(pos, r * r, 1.0) * where(pos, m, 1.0))
    return (k * w1, -k * x1, -k * y1, -k * z1, m)


@kernel(inputs=[(4,)], outputs=[(4,)])
def quat_exp(w, x, y, z):
    """``exp(w + v) = e^w (cos|v|, sin|v| v / |v|)`` = ``e^w (cos|v|, sinc(|v|) v)``.

    ``sinc`` carries the small-|v| series, so a tiny or zero vector part is exact;
    ``|v|`` is formed without overflow. Overflows (inf) once ``w`` > ~709.78
    (float64), like ``exp`` itself.
    """
    _, _, _, _, m, r = scaled4(x, y, z, 0.0)
    n = m * r
    e = exp(w)
    k = e * sinc(n)
    # cos|v| through the norm alone has no second derivative at v = 0; cos_of_norm
    # takes the series in |v|^2 there (one cosine, not the cosine and a sine).
    c = cos_of_norm(x * x + y * y + z * z, n)
    return (e * c, k * x, k * y, k * z)


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
    ux, uy, uz, _, nv = normalize4(x, y, z, 0.0)
    theta = atan2(nv, w)
    ux = where(nv > 0.0, ux, 1.0)
    # log|q| = log(M) + log(|q| / M), M = max |q_i|: |q| / M is in [1, 2].
    ws, xs, ys, zs, big, r = scaled4(w, x, y, z)
    pos = big > 0.0
    log_norm = log(where(pos, big, 1.0)) + log(where(pos, r, 1.0))
    # Near the positive real axis theta u is written (theta / |v|) v, with
    # atan_ratio's series (the same value): theta u alone has the derivative of
    # u = v / |v| at v = 0, namely 0, where d(theta u)/dv = I / w. On q / M
    # (theta u is scale-invariant), so 1 / w cannot overflow.
    ns = norm3(xs, ys, zs)
    near_real = ns < 0.02 * ws  # atan_ratio's series region (w > 0)
    k = atan_ratio(where(near_real, ns, 1.0), where(near_real, ws, 1.0))  # safe if unused
    return (
        log_norm,
        where(near_real, k * xs, theta * ux),
        where(near_real, k * ys, theta * uy),
        where(near_real, k * zs, theta * uz),
        big,
    )


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
