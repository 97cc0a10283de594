"""Kernels of the integration of angular velocity and twists: one step each.

For ``R' = R hat(w(t))`` (body) or ``R' = hat(w(t)) R`` (world) the step from
``t_k`` to ``t_k + h`` is ``R_{k+1} = R_k exp(theta_k)`` (body) or ``exp(theta_k)
R_k`` (world), and ``theta_k`` depends on the rate only, not on ``R_k``: the
increments of every step are computed at once (batched, fused), and only their
product is sequential (see :mod:`rigidkit.applications.kinematics.integration`).
The same holds for SE(3) and twists ``(v, w)``, and for the plane (the kernels
of SO(2) and SE(2) steps are in :mod:`.planar`).

``theta`` per method:

* zero-order hold (``"exact"``): ``theta = h w_k``, the exact motion for a rate
  held constant over the step;
* midpoint: ``theta = h w(t_k + h/2)``, second order for a smooth rate;
* RK4: the Runge-Kutta-Munthe-Kaas method of order 4 (Munthe-Kaas 1998), classical
  RK4 for the local coordinates ``theta(t)``, whose equation is
  ``theta' = dexp^-1_theta(w)`` with ``dexp^-1_u(a) ~ a + s/2 [u, a] + 1/12 [u, [u,
  a]]`` (``s = +1`` body, ``-1`` world; the terms kept are the ones order 4
  needs)::

      k1 = h w(t)
      k2 = h dexp^-1_{k1/2}(w(t + h/2))
      k3 = h dexp^-1_{k2/2}(w(t + h/2))
      k4 = h dexp^-1_{k3}(w(t + h))
      theta = (k1 + 2 k2 + 2 k3 + k4) / 6

Each step is an exponential, so the result is a rotation to rounding whatever the
step; a constant rate gives every method the exact ``exp(h w)`` (all brackets
vanish).
"""

from ..._engine import helper, kernel
from ..quaternion import quat_multiply
from ..se3 import bracket, pose_compose, pose_from_twist
from ..so3 import quat_entries_from_rotvec
from ..vector import hat_poly_apply, renormalize4


@helper
def so3_dexp_inv(s, ux, uy, uz, ax, ay, az):
    """``a + s/2 u x a + 1/12 u x (u x a)``, the truncated ``dexp^-1_u(a)`` of so(3)."""
    return hat_poly_apply(ux, uy, uz, 1.0, 0.5 * s, 1.0 / 12.0, ax, ay, az)


@helper
def se3_dexp_inv(s, u0, u1, u2, u3, u4, u5, a0, a1, a2, a3, a4, a5):
    """``a + s/2 [u, a] + 1/12 [u, [u, a]]``, the truncated ``dexp^-1_u(a)`` of se(3)."""
    b = bracket(u0, u1, u2, u3, u4, u5, a0, a1, a2, a3, a4, a5)
    c = bracket(u0, u1, u2, u3, u4, u5, b[0], b[1], b[2], b[3], b[4], b[5])
    k = 0.5 * s
    g = 1.0 / 12.0
    return (
        a0 + k * b[0] + g * c[0],
        a1 + k * b[1] + g * c[1],
        a2 + k * b[2] + g * c[2],
        a3 + k * b[3] + g * c[3],
        a4 + k * b[4] + g * c[4],
        a5 + k * b[5] + g * c[5],
    )


@kernel(inputs=[(3,), ()], outputs=[(4,)])
def so3_increment(wx, wy, wz, h):
    """Unit quaternion of ``exp(h w)``: a step of zero-order hold (or midpoint, given
    the midpoint rate)."""
    return quat_entries_from_rotvec(h * wx, h * wy, h * wz)


@kernel(inputs=[(3,), (3,), (3,), ()], outputs=[(4,)], params=("body",))
def so3_increment_rk4(body, ax, ay, az, mx, my, mz, ex, ey, ez, h):
    """Unit quaternion of ``exp(theta)``, ``theta`` the RKMK4 increment (module doc).

    ``a``, ``m``, ``e``: the rate at the start, middle and end of the step.
    """
    s = where(body == 1, 1.0, -1.0)
    k1x = h * ax
    k1y = h * ay
    k1z = h * az
    d2 = so3_dexp_inv(s, 0.5 * k1x, 0.5 * k1y, 0.5 * k1z, mx, my, mz)
    k2x = h * d2[0]
    k2y = h * d2[1]
    k2z = h * d2[2]
    d3 = so3_dexp_inv(s, 0.5 * k2x, 0.5 * k2y, 0.5 * k2z, mx, my, mz)
    k3x = h * d3[0]
    k3y = h * d3[1]
    k3z = h * d3[2]
    d4 = so3_dexp_inv(s, k3x, k3y, k3z, ex, ey, ez)
    tx = (k1x + 2.0 * (k2x + k3x) + h * d4[0]) / 6.0
    ty = (k1y + 2.0 * (k2y + k3y) + h * d4[1]) / 6.0
    tz = (k1z + 2.0 * (k2z + k3z) + h * d4[2]) / 6.0
    return quat_entries_from_rotvec(tx, ty, tz)


@kernel(inputs=[(6,), ()], outputs=[(7,)])
def se3_increment(vx, vy, vz, wx, wy, wz, h):
    """Pose of ``exp(h V)``, ``V = (v, w)``: a step of zero-order hold (or midpoint)."""
    return pose_from_twist(h * vx, h * vy, h * vz, h * wx, h * wy, h * wz)


@kernel(inputs=[(6,), (6,), (6,), ()], outputs=[(7,)], params=("body",))
def se3_increment_rk4(
    body,
    a0, a1, a2, a3, a4, a5,
    m0, m1, m2, m3, m4, m5,
    e0, e1, e2, e3, e4, e5,
    h,
):  # fmt: skip
    """Pose of ``exp(theta)``, ``theta`` the RKMK4 increment in se(3) (module doc)."""
    s = where(body == 1, 1.0, -1.0)
    k1 = (h * a0, h * a1, h * a2, h * a3, h * a4, h * a5)
    d2 = se3_dexp_inv(
        s, 0.5 * k1[0], 0.5 * k1[1], 0.5 * k1[2], 0.5 * k1[3], 0.5 * k1[4], 0.5 * k1[5],
        m0, m1, m2, m3, m4, m5,
    )  # fmt: skip
    k2 = (h * d2[0], h * d2[1], h * d2[2], h * d2[3], h * d2[4], h * d2[5])
    d3 = se3_dexp_inv(
        s, 0.5 * k2[0], 0.5 * k2[1], 0.5 * k2[2], 0.5 * k2[3], 0.5 * k2[4], 0.5 * k2[5],
        m0, m1, m2, m3, m4, m5,
    )  # fmt: skip
    k3 = (h * d3[0], h * d3[1], h * d3[2], h * d3[3], h * d3[4], h * d3[5])
    d4 = se3_dexp_inv(s, k3[0], k3[1], k3[2], k3[3], k3[4], k3[5], e0, e1, e2, e3, e4, e5)
    return pose_from_twist(
        (k1[0] + 2.0 * (k2[0] + k3[0]) + h * d4[0]) / 6.0,
        (k1[1] + 2.0 * (k2[1] + k3[1]) + h * d4[1]) / 6.0,
        (k1[2] + 2.0 * (k2[2] + k3[2]) + h * d4[2]) / 6.0,
        (k1[3] + 2.0 * (k2[3] + k3[3]) + h * d4[3]) / 6.0,
        (k1[4] + 2.0 * (k2[4] + k3[4]) + h * d4[4]) / 6.0,
        (k1[5] + 2.0 * (k2[5] + k3[5]) + h * d4[5]) / 6.0,
    )


@kernel(inputs=[(4,), (4,)], outputs=[(4,)], params=("body",))
def so3_chain(body, w1, x1, y1, z1, w2, x2, y2, z2):
    """``a b`` (body) or ``b a`` (world), normalised: one link of the product scan.

    ``a`` is the earlier factor (the orientation so far), ``b`` the later one (a
    step); the composition is associative, so the same link serves a sequential
    scan and a parallel prefix product. Both factors are unit quaternions (to
    rounding), so :func:`~rigidkit.kernels.vector.renormalize4` (one Newton step
    towards ``|q| = 1``) keeps them unit to rounding over any number of steps: the
    norm error does not accumulate (it would grow linearly without it).
    """
    b = body == 1
    p = quat_multiply(
        where(b, w1, w2), where(b, x1, x2), where(b, y1, y2), where(b, z1, z2),
        where(b, w2, w1), where(b, x2, x1), where(b, y2, y1), where(b, z2, z1),
    )  # fmt: skip
    return renormalize4(p[0], p[1], p[2], p[3])


@kernel(inputs=[(7,), (7,)], outputs=[(7,)], params=("body",))
def se3_chain(body, w1, x1, y1, z1, a1, b1, c1, w2, x2, y2, z2, a2, b2, c2):
    """``A B`` (body) or ``B A`` (world) of poses, the quaternion normalised (see
    :func:`so3_chain`)."""
    b = body == 1
    p = pose_compose(
        where(b, w1, w2), where(b, x1, x2), where(b, y1, y2), where(b, z1, z2),
        where(b, a1, a2), where(b, b1, b2), where(b, c1, c2),
        where(b, w2, w1), where(b, x2, x1), where(b, y2, y1), where(b, z2, z1),
        where(b, a2, a1), where(b, b2, b1), where(b, c2, c1),
    )  # fmt: skip
    u = renormalize4(p[0], p[1], p[2], p[3])
    return (u[0], u[1], u[2], u[3], p[4], p[5], p[6])
