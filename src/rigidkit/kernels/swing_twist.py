"""Kernel of the swing-twist decomposition of a rotation about an axis."""

from .._engine import kernel
from .quaternion import quat_multiply
from .vector import normalize4, renormalize4


@kernel(inputs=[(4,), (3,)], outputs=[(4,), (4,)])
def swing_twist(w, x, y, z, nx, ny, nz):
    """``(swing, twist)`` with ``q = swing twist``, twist about the unit axis ``n``.

    The twist is the projection of ``q`` onto the rotations about ``n``: ``(w, (v .
    n) n)``, normalised (scaled, :func:`~rigidkit.kernels.vector.normalize4`), and
    the swing is ``q twist*``, whose vector part is orthogonal to ``n``: a turn
    about an axis orthogonal to ``n``. Both are flipped together to make the
    twist's ``w >= 0`` (``(-s)(-t) = s t``), so the twist angle is in [-pi, pi]
    about ``+n``.

    Where ``w = v . n = 0`` (the swing is a half turn, whatever the twist: then
    every split is valid) the projection is 0 and the twist is the identity,
    the swing ``q`` itself. Near there the twist is ill-conditioned (both
    components of the projection are small), but ``swing twist = q`` holds to
    rounding at any distance.
    """
    d = x * nx + y * ny + z * nz
    tw, tx, ty, tz, t = normalize4(w, d * nx, d * ny, d * nz)
    ok = t > 0.0
    tw = where(ok, tw, 1.0)
    s = where(tw < 0.0, -1.0, 1.0)
    tw = s * tw
    tx = s * tx
    ty = s * ty
    tz = s * tz
    sw, sx, sy, sz = quat_multiply(w, x, y, z, tw, -tx, -ty, -tz)
    sw, sx, sy, sz = renormalize4(sw, sx, sy, sz)
    return (sw, sx, sy, sz, tw, tx, ty, tz)
