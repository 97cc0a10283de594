"""Kernels of poses in other software's layouts, the inverse action and a distance.

Poses are ``(w, x, y, z, tx, ty, tz)``: a unit quaternion (Hamilton, scalar first)
and a translation, the motion ``p -> R p + t``; our twists are ``(v, w)``.

====================  ==================================================================
exponential coords    scipy's ``RigidTransform``: ``(w, v)``, rotation first; the same
                      numbers as our twist ``(v, w)`` in the other order
pq                    pytransform3d's pose vector ``(tx, ty, tz, qw, qx, qy, qz)``;
                      ``_xyzw``: TUM/ROS ``(tx, ty, tz, qx, qy, qz, qw)``
====================  ==================================================================
"""

from .._engine import kernel
from .coefficients import atan_ratio, norm3
from .quaternion import quat_apply, quat_hemisphere, quat_multiply, quat_normalize
from .se3 import pose_from_twist, twist_from_pose


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
    every component finite (as in :func:`.dual_quaternion.pose_from_dual_quat`).
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


@kernel(inputs=[(7,), (3,)], outputs=[(3,)])
def pose_apply_inverse(w, x, y, z, tx, ty, tz, px, py, pz):
    """The inverse motion of points, ``R^T (p - t)``, without forming the inverse."""
    return quat_apply(w, -x, -y, -z, px - tx, py - ty, pz - tz)


@kernel(
    inputs=[(7,), (7,)],
    outputs=[()],
    params=("rotation_weight", "translation_weight"),
)
def pose_distance(
    rotation_weight,
    translation_weight,
    w1, x1, y1, z1, tx1, ty1, tz1,
    w2, x2, y2, z2, tx2, ty2, tz2,
):  # fmt: skip
    """``sqrt(a theta^2 + b |t2 - t1|^2)`` of the relative pose ``T1^-1 T2``.

    ``theta`` (radians, [0, pi]) is the angle of ``R1^T R2`` (``atan2``-based, so
    exact near 0 and pi) and ``|t2 - t1|`` is the length of the translation
    ``R1^T (t2 - t1)`` of ``T1^-1 T2`` (a rotation keeps lengths); ``a``, ``b`` the
    (non-negative) weights. ``theta^2`` is taken as ``|2 v atan2(|v|, w) / |v||^2``
    (:func:`atan_ratio`), a smooth function of the quaternion ``(w, v)``: through
    ``theta`` itself autodiff would see ``d theta / dv = 0`` at ``v = 0`` (the norm's
    subgradient) and lose the rotation part of the Hessian where the rotations are
    equal and the translations not. The root is taken at a safe argument, so the
    gradient at ``T1 = T2`` is 0 (a subgradient), not NaN.
    """
    rw, rx, ry, rz = quat_multiply(w1, -x1, -y1, -z1, w2, x2, y2, z2)
    rw, rx, ry, rz = quat_hemisphere(rw, rx, ry, rz)
    k = 2.0 * atan_ratio(norm3(rx, ry, rz), rw)
    theta2 = k * k * (rx * rx + ry * ry + rz * rz)
    dx, dy, dz = tx2 - tx1, ty2 - ty1, tz2 - tz1
    s = rotation_weight * theta2 + translation_weight * (dx * dx + dy * dy + dz * dz)
    pos = s > 0.0
    return (where(pos, sqrt(where(pos, s, 1.0)), 0.0),)
