"""Kernels of geodesics on SO(3) and SE(3): powers, slerp, the shortest arc.

Built from formulas that exist once elsewhere, called here by name: the
quaternion product, quaternion <-> rotation vector, and the pose product,
inverse, log and exp of :mod:`.se3`. A power is ``exp(t log X)`` and the
geodesic from ``X0`` to ``X1`` is ``X0 (X0^-1 X1)^t``; the log takes the angle in
[0, pi] (the quaternion flipped to ``w >= 0``), so the geodesic is the shortest
one whatever the signs of the two quaternions.

Quaternions are Hamilton, scalar first; poses ``(w, x, y, z, tx, ty, tz)``;
twists ``(v, w)``.
"""

from .._engine import helper, kernel
from .coefficients import atan_ratio, norm3, sinc
from .quaternion import quat_hemisphere, quat_multiply
from .se3 import pose_compose, pose_from_twist, pose_inv, twist_from_pose
from .so3 import cos_of_norm
from .vector import cross3


@helper
def quat_power_entries(w, x, y, z, t):
    """``q^t = exp(t log q) = (cos(t phi), sin(t phi) v / |v|)``, ``phi`` in [0, pi/2].

    ``phi = atan2(|v|, w)`` is half the rotation angle once ``q`` is flipped to
    ``w >= 0`` (the shortest way round). The log and the exponential fused: the
    ratio ``phi / |v|`` (:func:`~.coefficients.atan_ratio`) and ``sin(t phi) / (t
    phi)`` (:func:`~.coefficients.sinc`) carry the small-angle series, so ``q`` at
    or near the identity (``|v| = 0``: ``q^t`` = identity) is exact and has finite
    gradients; ``norm3``'s derivative is 0 there, and
    :func:`~.rotvec.cos_of_norm` keeps the second one. Through the rotation vector
    (``quat_from_rotvec(t rotvec_from_quat(q))``, the same expression term by
    term) it took a second norm and a second series: 22.6 -> 21.3 ns per slerp.
    """
    w, x, y, z = quat_hemisphere(w, x, y, z)
    n = norm3(x, y, z)
    tk = t * atan_ratio(n, w)  # t phi / |v|
    tphi = tk * n
    s = tk * sinc(tphi)  # sin(t phi) / |v|
    # cos(t phi) from (t phi)^2 summed from v as well: through |v| alone autodiff
    # gives a Hessian of 0 at the identity, not -(t phi / |v|)^2 I (cos_of_norm).
    c = cos_of_norm(tk * tk * (x * x + y * y + z * z), tphi)
    return (c, s * x, s * y, s * z)


@kernel(inputs=[(4,), ()], outputs=[(4,)], vector_math=True)
def quat_power(w, x, y, z, t):
    """Power ``q^t`` of a unit quaternion: the rotation by ``t`` times its angle.

    The angle is in [0, pi] first (``q`` and ``-q`` give the same result), so
    ``q^0`` is the identity, ``q^1`` the rotation of ``q`` (with ``w >= 0``) and
    ``q^-1`` its inverse.
    """
    return quat_power_entries(w, x, y, z, t)


@helper
def quat_times_power(w0, x0, y0, z0, dw, dx, dy, dz, t):
    """``q0 d^t``: the slerp from ``q0`` along its relative rotation ``d = q0* q1``."""
    pw, px, py, pz = quat_power_entries(dw, dx, dy, dz, t)
    return quat_multiply(w0, x0, y0, z0, pw, px, py, pz)


@helper
def quat_slerp_entries(w0, x0, y0, z0, w1, x1, y1, z1, t):
    """``q0 (q0* q1)^t``, the shortest geodesic from ``q0`` (t = 0) to ``q1`` (t = 1)."""
    dw, dx, dy, dz = quat_multiply(w0, -x0, -y0, -z0, w1, x1, y1, z1)
    return quat_times_power(w0, x0, y0, z0, dw, dx, dy, dz, t)


@kernel(inputs=[(4,), (4,), ()], outputs=[(4,)], vector_math=True)
def quat_slerp(w0, x0, y0, z0, w1, x1, y1, z1, t):
    """Spherical linear interpolation ``q0 (q0* q1)^t`` of unit quaternions.

    Shortest path (the relative angle in [0, pi]); exactly ``q0`` at ``t = 0`` and
    the rotation of ``q1`` to a few ulp at ``t = 1``; extrapolates outside [0, 1].
    The small-angle series live in the rotation-vector helpers, so ``q0 = q1``
    and ``q0 = -q1`` are exact.
    """
    return quat_slerp_entries(w0, x0, y0, z0, w1, x1, y1, z1, t)


@kernel(inputs=[(16,), ()], outputs=[(7,)])
def pose_slerp_segment(w, x, y, z, px, py, pz, dx, dy, dz, phi, ux, uy, uz, t0, dt, t):
    """Decoupled interpolation at time ``t`` on a segment given by one row of 16.

    The row is ``(q0, p0, d, phi, u, t0, dt)``: the first sample's quaternion and
    position, the position step ``d = p1 - p0``, the relative rotation ``q0* q1 =
    (cos phi, sin phi u)`` as its half angle ``phi`` in [0, pi/2] (flipped to ``w
    >= 0``) and unit axis ``u`` (0 when ``phi = 0``), and the segment's start
    ``t0`` and length ``dt``. With ``a = (t - t0) / dt`` it returns the pose
    ``(q0 (cos(a phi), sin(a phi) u), p0 + a d)`` in the layout ``(w, x, y, z,
    tx, ty, tz)``: :func:`pose_slerp_decoupled` (whose power is
    :func:`quat_power_entries`) with the angle and axis taken once per pair of
    samples instead of at every time. One sine and one cosine a pose, no
    arctangent or square root, for many times on few segments (a time series
    resampled), from one row gathered per time. No small-angle series is needed:
    ``u = 0`` at ``phi = 0`` gives ``q0`` exactly. Not ``vector_math``: with rows
    of 16 and poses of 7 the loop does not vectorise, and the branch-free sine
    and cosine cost 24 ns an element in it, libm's 16.5.
    """
    a = (t - t0) / dt
    c = cos(a * phi)
    s = sin(a * phi)
    qw, qx, qy, qz = quat_multiply(w, x, y, z, c, s * ux, s * uy, s * uz)
    return (qw, qx, qy, qz, px + a * dx, py + a * dy, pz + a * dz)


@helper
def pose_power_entries(w, x, y, z, tx, ty, tz, t):
    """``T^t = exp(t log T)`` on SE(3): a fraction ``t`` of the screw motion."""
    vx, vy, vz, rx, ry, rz = twist_from_pose(w, x, y, z, tx, ty, tz)
    return pose_from_twist(t * vx, t * vy, t * vz, t * rx, t * ry, t * rz)


@kernel(inputs=[(7,), ()], outputs=[(7,)])
def pose_power(w, x, y, z, tx, ty, tz, t):
    """Power ``T^t = exp(t log T)`` of a pose (the screw motion scaled by ``t``)."""
    return pose_power_entries(w, x, y, z, tx, ty, tz, t)


@kernel(inputs=[(7,), (7,), ()], outputs=[(7,)])
def pose_slerp(w0, x0, y0, z0, a0, b0, c0, w1, x1, y1, z1, a1, b1, c1, t):
    """Screw interpolation ``T0 (T0^-1 T1)^t``: the SE(3) geodesic, constant twist."""
    iw, ix, iy, iz, ia, ib, ic = pose_inv(w0, x0, y0, z0, a0, b0, c0)
    d = pose_compose(iw, ix, iy, iz, ia, ib, ic, w1, x1, y1, z1, a1, b1, c1)
    pw, px, py, pz, pa, pb, pc = pose_power_entries(*d, t)
    return pose_compose(w0, x0, y0, z0, a0, b0, c0, pw, px, py, pz, pa, pb, pc)


@kernel(inputs=[(7,), (7,), ()], outputs=[(7,)], vector_math=True)
def pose_slerp_decoupled(w0, x0, y0, z0, a0, b0, c0, w1, x1, y1, z1, a1, b1, c1, t):
    """Rotation by slerp, translation linearly: ``(1 - t) t0 + t t1`` (exact at 0, 1)."""
    w, x, y, z = quat_slerp_entries(w0, x0, y0, z0, w1, x1, y1, z1, t)
    s = 1.0 - t
    return (w, x, y, z, s * a0 + t * a1, s * b0 + t * b1, s * c0 + t * c1)


@kernel(inputs=[(3,), (3,)], outputs=[(4,)], params=("tiny",))
def quat_from_two_vectors(tiny, ux, uy, uz, vx, vy, vz):
    """The shortest-arc rotation taking the direction of ``v`` to that of ``u``.

    ``q ~ (|u + v|^2 / 2, v x u)`` for unit ``u``, ``v``: the half-angle form of
    ``(1 + u.v, v x u)``, where ``1 + u.v = |u + v|^2 / 2`` is computed from the sum
    itself, so no digits cancel as ``v`` nears ``-u``. Where ``|u + v|^2 / 2 <
    tiny`` (the caller passes ``(64 eps)^2 / 2`` of the dtype: ``v = -u`` to
    rounding, where the rotation axis is undetermined and every half turn about
    an axis normal to ``v`` is a shortest arc) the axis is
    ``v x e_k``, ``e_k`` the coordinate axis least aligned with ``v``; the
    result still maps ``v`` to ``u`` within ``64 eps``. The inputs need not be
    unit, only nonzero.
    """
    nu = norm3(ux, uy, uz)
    nv = norm3(vx, vy, vz)
    ux = ux / nu
    uy = uy / nu
    uz = uz / nu
    vx = vx / nv
    vy = vy / nv
    vz = vz / nv
    sx = ux + vx
    sy = uy + vy
    sz = uz + vz
    h = 0.5 * (sx * sx + sy * sy + sz * sz)
    cx, cy, cz = cross3(vx, vy, vz, ux, uy, uz)
    ax = abs(vx)
    ay = abs(vy)
    az = abs(vz)
    use_x = (ax <= ay) & (ax <= az)
    use_y = ay <= az
    # v x e_x = (0, vz, -vy), v x e_y = (-vz, 0, vx), v x e_z = (vy, -vx, 0).
    px = where(use_x, 0.0, where(use_y, -vz, vy))
    py = where(use_x, vz, where(use_y, 0.0, -vx))
    pz = where(use_x, -vy, where(use_y, vx, 0.0))
    half_turn = h < tiny
    w = where(half_turn, 0.0, h)
    x = where(half_turn, px, cx)
    y = where(half_turn, py, cy)
    z = where(half_turn, pz, cz)
    n = norm3(x, y, z)
    n = sqrt(w * w + n * n)
    return (w / n, x / n, y / n, z / n)
