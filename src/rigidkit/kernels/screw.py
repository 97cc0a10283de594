"""Kernels of screws: the axis, pitch and magnitude of a twist, and back.

Chasles (Murray, Li & Sastry 1994, Sec. 2.3.3): every twist ``V = (v, w)`` with
``w != 0`` is a turn about an axis (through ``q``, direction ``u = w / |w|``) at
rate ``|w|``, combined with a slide along it at ``h |w|``: ``v = -w x q + h w``.
Then ``h = w . v / |w|^2`` (the pitch, length per radian) and the axis point
nearest the origin is ``q = w x v / |w|^2``.
A twist with ``w = 0`` is a pure translation: pitch infinite, direction
``v / |v|``, magnitude ``|v|``, axis through the origin. The zero twist gets the
direction ``+x`` (as the identity's rotation axis) and magnitude 0.
"""

from .._engine import kernel
from .coefficients import norm3
from .vector import cross3


@kernel(inputs=[(6,)], outputs=[(3,), (3,), (), (), ()])
def screw_from_twist(vx, vy, vz, wx, wy, wz):
    """``(q, u, h, m, rotates)`` of a twist; see the module docstring.

    ``rotates`` is 1.0 for ``w != 0`` and 0.0 for a pure translation (whose pitch,
    infinite, the caller writes; here it is 0). Exact zero test: a tiny ``w`` is a
    genuine screw with a far axis, correctly computed (``q`` grows as ``1/|w|``).
    """
    nw = norm3(wx, wy, wz)
    nv = norm3(vx, vy, vz)
    rot = nw > 0.0
    moves = nv > 0.0
    kw = 1.0 / where(rot, nw, 1.0)
    kv = 1.0 / where(moves, nv, 1.0)
    k2 = kw * kw
    cx, cy, cz = cross3(wx, wy, wz, vx, vy, vz)
    h = (wx * vx + wy * vy + wz * vz) * k2
    ux = where(rot, wx * kw, where(moves, vx * kv, 1.0))
    uy = where(rot, wy * kw, vy * kv)
    uz = where(rot, wz * kw, vz * kv)
    return (
        where(rot, cx * k2, 0.0),
        where(rot, cy * k2, 0.0),
        where(rot, cz * k2, 0.0),
        ux,
        uy,
        uz,
        where(rot, h, 0.0),
        where(rot, nw, nv),
        where(rot, 1.0, 0.0),
    )


@kernel(inputs=[(3,), (3,), (), (), ()], outputs=[(6,)])
def twist_from_screw(qx, qy, qz, ux, uy, uz, h, m, rotates):
    """Twist ``(v, w)`` of a screw: ``w = m u``, ``v = q x w + h w`` (``u`` normalised).

    With ``rotates = 0`` (infinite pitch) a pure translation ``v = m u``. ``u`` must
    be nonzero (callers check); ``h`` is not read then, so it may be infinite only
    if the caller replaced it (the pure-translation flag carries that case).
    """
    n = norm3(ux, uy, uz)
    k = m / where(n > 0.0, n, 1.0)
    ex = k * ux
    ey = k * uy
    ez = k * uz
    rot = rotates > 0.5
    cx, cy, cz = cross3(qx, qy, qz, ex, ey, ez)
    return (
        where(rot, cx + h * ex, ex),
        where(rot, cy + h * ey, ey),
        where(rot, cz + h * ez, ez),
        where(rot, ex, 0.0),
        where(rot, ey, 0.0),
        where(rot, ez, 0.0),
    )
