"""Kernels between poses and unit dual quaternions ``q_r + eps q_d``.

A pose ``(w, x, y, z, tx, ty, tz)`` (unit quaternion ``q``, Hamilton, scalar first,
then the translation ``t``) is the unit dual quaternion with real part ``q_r = q``
and dual part ``q_d = (0, t) q / 2`` (Hamilton products), stored as 8 numbers
``(q_r, q_d)``, both scalar first (``_xyzw`` kernels: both scalar last, scipy's
default). The translation is read back as ``t = 2 vec(q_d q_r*)``.

A dual quaternion is unit when ``|q_r| = 1`` and ``q_r . q_d = 0``. Others are
normalised as scipy's ``RigidTransform.from_dual_quat`` does: both parts are
divided by ``|q_r|``, and the component of ``q_d`` along ``q_r`` is dropped. That
component is the scalar part of ``q_d q_r*`` (``scal(q_d q_r*) = q_d . q_r``), so
dropping it leaves ``t = 2 vec(q_d q_r*) / |q_r|^2`` as it is: only the vector part
is read.
"""

from .._engine import kernel
from .quaternion import quat_multiply
from .vector import normalize4


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
