"""Kernels of poses in other software's layouts: dual quaternions, pq, exp coords.

Poses are ``(w, x, y, z, tx, ty, tz)``: a unit quaternion (Hamilton, scalar first)
and a translation, the motion ``p -> R p + t``; our twists are ``(v, w)``. The
group operations on poses (compose, inverse, act, exp, log, distance) are SE(3)'s,
in :mod:`.se3`; this module holds only the conversions to other layouts.

====================  ==================================================================
dual quaternion       ``q_r + eps q_d`` stored as ``(q_r, q_d)``, 8 numbers, both scalar
                      first (``_xyzw`` kernels: both scalar last, scipy's default)
exponential coords    scipy's ``RigidTransform``: ``(w, v)``, rotation first; the same
                      numbers as our twist ``(v, w)`` in the other order
pq                    pytransform3d's pose vector ``(tx, ty, tz, qw, qx, qy, qz)``;
                      ``_xyzw``: TUM/ROS ``(tx, ty, tz, qx, qy, qz, qw)``
xyzw quaternion       scipy's and ROS's scalar-last ``(x, y, z, w)``, read (normalised)
                      and written in one pass each
====================  ==================================================================

Dual quaternions: a pose is the unit dual quaternion with real part ``q_r = q``
and dual part ``q_d = (0, t) q / 2`` (Hamilton products). The translation is read
back as ``t = 2 vec(q_d q_r*)``. A dual quaternion is unit when ``|q_r| = 1`` and
``q_r . q_d = 0``. Others are normalised as scipy's
``RigidTransform.from_dual_quat`` does: both parts are divided by ``|q_r|``, and
the component of ``q_d`` along ``q_r`` is dropped. That component is the scalar
part of ``q_d q_r*`` (``scal(q_d q_r*) = q_d . q_r``), so dropping it leaves ``t =
2 vec(q_d q_r*) / |q_r|^2`` as it is: only the vector part is read.
"""

from .._engine import kernel
from .quaternion import quat_multiply, quat_normalize
from .se3 import pose_from_twist, twist_from_pose
from .vector import normalize4

# -- dual quaternions ------------------------------------------------------------------


@kernel(inputs=[(7,)], outputs=[(8,)])
def dual_quat_from_pose(w, x, y, z, tx, ty, tz):
    """Unit dual quaternion ``(q, (0, t) q / 2)`` of a pose, both parts scalar first."""
    dw, dx, dy, dz = quat_multiply(0.0, 0.5 * tx, 0.5 * ty, 0.5 * tz, w, x, y, z)
    return (w, x, y, z, dw, dx, dy, dz)


@kernel(inputs=[(7,)], outputs=[(8,)])
def dual_quat_xyzw_from_pose(w, x, y, z, tx, ty, tz):
    """As :func:`dual_quat_from_pose`, both parts scalar last (scipy's default)."""
    rw, rx, ry, rz, dw, dx, dy, dz = dual_quat_from_pose(w, x, y, z, tx, ty, tz)
    return (rx, ry, rz, rw, dx, dy, dz, dw)


@kernel(inputs=[(8,)], outputs=[(7,), ()])
def pose_from_dual_quat(rw, rx, ry, rz, dw, dx, dy, dz):
    """Pose of a dual quaternion (scalar first), normalised; and a validity number.

    ``q = q_r / |q_r|`` and ``t = 2 vec(q_d q_r*) / |q_r|^2`` (the module docstring
    says why this is scipy's normalisation). The second output is ``|q_r|`` plus
    ``0 * q_d``: positive and finite exactly when ``q_r`` is nonzero and every
    component finite (``0 * inf`` and ``0 * nan`` are NaN), so one comparison on it
    validates the input. A zero ``q_r`` gives a zero pose, which callers reject.
    """
    w, x, y, z, n = normalize4(rw, rx, ry, rz)
    safe = 2.0 / where(n > 0.0, n, 1.0)
    # q_d / |q_r| times the unit q*: the vector part of q_d q_r* / |q_r|^2.
    _, tx, ty, tz = quat_multiply(dw, dx, dy, dz, w, -x, -y, -z)
    check = n + 0.0 * dw + 0.0 * dx + 0.0 * dy + 0.0 * dz
    return (w, x, y, z, safe * tx, safe * ty, safe * tz, check)


@kernel(inputs=[(8,)], outputs=[(7,), ()])
def pose_from_dual_quat_xyzw(rx, ry, rz, rw, dx, dy, dz, dw):
    """As :func:`pose_from_dual_quat`, both parts scalar last (scipy's default)."""
    return pose_from_dual_quat(rw, rx, ry, rz, dw, dx, dy, dz)


# -- exponential coordinates and pq -----------------------------------------------------


@kernel(inputs=[(6,)], outputs=[(7,)])
def pose_from_exp_coords(wx, wy, wz, vx, vy, vz):
    """``exp`` of scipy's exponential coordinates ``(w, v)``: our twist ``(v, w)``."""
    return pose_from_twist(vx, vy, vz, wx, wy, wz)


@kernel(inputs=[(7,)], outputs=[(6,)])
def exp_coords_from_pose(w, x, y, z, tx, ty, tz):
    """``log`` of a pose as scipy's exponential coordinates ``(w, v)``, ``|w| <= pi``."""
    vx, vy, vz, wx, wy, wz = twist_from_pose(w, x, y, z, tx, ty, tz)
    return (wx, wy, wz, vx, vy, vz)


@kernel(inputs=[(7,)], outputs=[(7,), ()])
def pose_from_pq(tx, ty, tz, qw, qx, qy, qz):
    """Pose of ``(tx, ty, tz, qw, qx, qy, qz)``, the quaternion normalised; a check.

    The check is ``|q| + 0 t``: positive and finite exactly when ``q`` is nonzero and
    every component finite (as in :func:`pose_from_dual_quat`).
    """
    w, x, y, z, n = quat_normalize(qw, qx, qy, qz)
    return (w, x, y, z, tx, ty, tz, n + 0.0 * tx + 0.0 * ty + 0.0 * tz)


@kernel(inputs=[(7,)], outputs=[(7,), ()])
def pose_from_pq_xyzw(tx, ty, tz, qx, qy, qz, qw):
    """As :func:`pose_from_pq` from TUM/ROS ``(tx, ty, tz, qx, qy, qz, qw)``."""
    return pose_from_pq(tx, ty, tz, qw, qx, qy, qz)


@kernel(inputs=[(7,)], outputs=[(7,)])
def pq_from_pose(w, x, y, z, tx, ty, tz):
    """``(tx, ty, tz, qw, qx, qy, qz)`` of a pose."""
    return (tx, ty, tz, w, x, y, z)


@kernel(inputs=[(7,)], outputs=[(7,)])
def pq_xyzw_from_pose(w, x, y, z, tx, ty, tz):
    """TUM/ROS ``(tx, ty, tz, qx, qy, qz, qw)`` of a pose."""
    return (tx, ty, tz, x, y, z, w)


@kernel(inputs=[(4,)], outputs=[(4,), ()])
def quat_from_xyzw(qx, qy, qz, qw):
    """Unit ``(w, x, y, z)`` of a scalar-last ``(x, y, z, w)`` (scipy, ROS), and the
    norm of the input (0 or not finite: no rotation), in one pass."""
    return quat_normalize(qw, qx, qy, qz)


@kernel(inputs=[(4,)], outputs=[(4,)])
def xyzw_from_quat(w, x, y, z):
    """Scalar-last ``(x, y, z, w)`` (scipy, ROS) of a quaternion ``(w, x, y, z)``."""
    return (x, y, z, w)
