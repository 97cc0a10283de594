"""Poses in other software's layouts (functional layer: arrays in, arrays out).

A pose is an array ``(w, x, y, z, tx, ty, tz)``: a unit quaternion (Hamilton,
scalar first) and a translation, the motion ``p -> R p + t``. This module converts
poses to and from the layouts of other software; SE(3) itself (exp, log,
adjoints, Jacobians, matrices, distance) is :mod:`rigidkit.se3`, which also
offers every function here under the same name (``rk.se3.pose_from_dual_quat``).
The kernels are those of :mod:`rigidkit.kernels.pose_formats`.

=======================  ==============================================================
dual quaternion          ``(q_r, q_d)``, ``q_d = (0, t) q_r / 2``; ``scalar_first=False``:
                         both parts scalar last (scipy's default)
exponential coordinates  scipy's ``RigidTransform``: ``(w, v)``, rotation first
pq                       pytransform3d's ``(tx, ty, tz, qw, qx, qy, qz)``;
                         ``scalar_first=False``: TUM/ROS ``(tx, ty, tz, qx, qy, qz, qw)``
=======================  ==============================================================

>>> import numpy as np
>>> np.round(pq_from_pose([1.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0]), 12) + 0.0
array([1., 2., 3., 1., 0., 0., 0.])
"""

from __future__ import annotations

import math

import numpy as np

from .._validate import all_true, as_array, check_finite, finite_array, raise_unless
from ..errors import ZeroNormError
from ..kernels import pose_formats as _k
from ..kernels import se3 as _kse3
from . import conversions as _conv

__all__ = [
    "pose_from_exp_coords",
    "exp_coords_from_pose",
    "pose_from_dual_quat",
    "dual_quat_from_pose",
    "pose_from_pq",
    "pq_from_pose",
]


def _pose(pose):
    """A validated pose: the quaternion normalised, the translation finite."""
    p = as_array(pose, (7,), "pose")
    q = _conv.quat_normalize(p[..., :4], what="pose quaternion")
    t = finite_array(p[..., 4:], (3,), "pose translation")
    return _kse3.pose_from_quat_translation(q, t)


def pose_from_exp_coords(exp_coords):
    """Pose of scipy's exponential coordinates ``(w, v)``: ``exp`` of our twist ``(v, w)``.

    scipy's ``RigidTransform.from_exp_coords`` orders the twist rotation first,
    ``(rx, ry, rz, vx, vy, vz)``; rigidkit's twists are ``(v, w)``
    (:func:`rigidkit.se3.exp`).
    The numbers are the same: ``pose_from_exp_coords(c) == pose_from_twist(
    concat(c[3:], c[:3]))``.

    Parameters
    ----------
    exp_coords : array_like, shape (..., 6)
        ``(w, v)``: ``w`` a rotation vector (radians), ``v`` in length units.

    Returns
    -------
    ndarray, shape (..., 7)
        Poses ``(w, x, y, z, tx, ty, tz)``.

    See Also
    --------
    exp_coords_from_pose

    Examples
    --------
    >>> from rigidkit.functional.se3 import pose_from_twist
    >>> c = np.array([0.0, 0.0, np.pi / 2, 1.0, 0.0, 0.0])  # (w, v): screw about z
    >>> np.allclose(pose_from_exp_coords(c), pose_from_twist(np.r_[c[3:], c[:3]]))
    True
    """
    return _k.pose_from_exp_coords(
        finite_array(exp_coords, (6,), "exponential coordinates")
    )


def exp_coords_from_pose(pose):
    """scipy's exponential coordinates ``(w, v)`` of poses, ``|w|`` in [0, pi].

    The twist of :func:`rigidkit.se3.twist_from_pose` rotation first, as scipy's
    ``RigidTransform.as_exp_coords``; the quaternion is normalised first.

    Parameters
    ----------
    pose : array_like, shape (..., 7)
        ``(w, x, y, z, tx, ty, tz)``.

    Returns
    -------
    ndarray, shape (..., 6)
        ``(w, v)``, rotation first.

    See Also
    --------
    pose_from_exp_coords

    Examples
    --------
    >>> np.round(exp_coords_from_pose([1.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0]), 12) + 0.0
    array([0., 0., 0., 1., 2., 3.])
    """
    return _k.exp_coords_from_pose(_pose(pose))


def _checked(kern, x, trail, what, zero_message):
    """``kern(x)`` (a pose and a validity number) with its input validated from it.

    The kernel's second output is positive and finite exactly for valid input (see
    :func:`rigidkit.kernels.pose_formats.pose_from_dual_quat`), so valid input
    costs no separate pass; only after a failure is ``x`` searched for the cause.
    """
    x = as_array(x, trail, what)
    if type(x) is np.ndarray and x.ndim > 1:
        # The element-wise NumPy path warns about NaN it computes; the check below
        # reports it instead (no errstate elsewhere: torch.compile cannot trace it).
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            pose, check = kern(x)
    else:
        pose, check = kern(x)
    ok = (check > 0.0) & (check < math.inf)
    if not all_true(ok):
        check_finite(x, trail, what)
        raise_unless(ok, ZeroNormError, zero_message)
    return pose


def pose_from_dual_quat(dual_quat, *, scalar_first=True):
    """Poses of unit dual quaternions ``q_r + eps q_d``, ``q_d = (0, t) q_r / 2``.

    Stored as ``(q_r, q_d)``, 8 numbers (Hamilton products). The translation is
    ``t = 2 vec(q_d q_r*)``. Non-unit input is normalised as by scipy's
    ``RigidTransform.from_dual_quat``: both parts divided by ``|q_r|`` and the
    component of ``q_d`` along ``q_r`` dropped, i.e. ``q = q_r / |q_r|`` and ``t =
    2 vec(q_d q_r*) / |q_r|^2``. ``q`` and ``-q`` (all 8 numbers) are one motion.

    Parameters
    ----------
    dual_quat : array_like, shape (..., 8)
        ``(q_r, q_d)``, each of the two parts in the order of ``scalar_first``.
    scalar_first : bool
        True (ours): ``(rw, rx, ry, rz, dw, dx, dy, dz)``; False (scipy's
        default): ``(rx, ry, rz, rw, dx, dy, dz, dw)``.

    Returns
    -------
    ndarray, shape (..., 7)
        Poses ``(w, x, y, z, tx, ty, tz)``, ``w`` of the sign of ``rw``.

    Raises
    ------
    NonFiniteError
        NaN or infinity in a component.
    ZeroNormError
        A zero real part ``q_r`` (scipy maps it to the identity rotation; here it
        is an error naming the batch index).

    See Also
    --------
    dual_quat_from_pose

    Examples
    --------
    >>> # a quarter turn about z, then the translation (1, 0, 0)
    >>> c = np.sqrt(0.5)
    >>> dq = [c, 0.0, 0.0, c, 0.0, 0.5 * c, -0.5 * c, 0.0]  # q_d = (0, i/2)(c + c k)
    >>> np.round(pose_from_dual_quat(dq), 12) + 0.0
    array([0.70710678, 0.        , 0.        , 0.70710678, 1.        ,
           0.        , 0.        ])
    """
    kern = _k.pose_from_dual_quat if scalar_first else _k.pose_from_dual_quat_xyzw
    return _checked(
        kern,
        dual_quat,
        (8,),
        "dual quaternion",
        "dual quaternion has a zero real part {where}; it names no rigid motion",
    )


def dual_quat_from_pose(pose, *, scalar_first=True):
    """Unit dual quaternions ``(q, (0, t) q / 2)`` of poses, shape (..., 8).

    The layout of :func:`pose_from_dual_quat`. The quaternion is normalised first.

    Parameters
    ----------
    pose : array_like, shape (..., 7)
        ``(w, x, y, z, tx, ty, tz)``.
    scalar_first : bool
        True (ours): ``(rw, rx, ry, rz, dw, dx, dy, dz)``; False (scipy's
        default): both parts scalar last.

    Returns
    -------
    ndarray, shape (..., 8)

    See Also
    --------
    pose_from_dual_quat

    Examples
    --------
    >>> np.round(dual_quat_from_pose([1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0]), 12) + 0.0
    array([1., 0., 0., 0., 0., 1., 0., 0.])
    """
    kern = _k.dual_quat_from_pose if scalar_first else _k.dual_quat_xyzw_from_pose
    return kern(_pose(pose))


def pose_from_pq(pq, *, scalar_first=True):
    """Poses of pose vectors: translation, then quaternion (normalised).

    Hamilton quaternions; the motion is ``p -> R p + t``.

    Parameters
    ----------
    pq : array_like, shape (..., 7)
        The translation ``t``, then the quaternion in the order of ``scalar_first``.
    scalar_first : bool
        True: ``(tx, ty, tz, qw, qx, qy, qz)``, pytransform3d's ``pq``; False:
        ``(tx, ty, tz, qx, qy, qz, qw)``, the TUM trajectory and ROS ``Pose`` order.

    Returns
    -------
    ndarray, shape (..., 7)
        Poses ``(w, x, y, z, tx, ty, tz)``, the quaternion moved first.

    Raises
    ------
    NonFiniteError, ZeroNormError
        NaN or infinity anywhere, or a zero quaternion, naming the batch index.

    See Also
    --------
    pq_from_pose

    Examples
    --------
    >>> pose_from_pq([1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 2.0], scalar_first=False)
    array([1., 0., 0., 0., 1., 2., 3.])
    """
    kern = _k.pose_from_pq if scalar_first else _k.pose_from_pq_xyzw
    return _checked(
        kern, pq, (7,), "pose vector", "pose vector has a zero quaternion {where}"
    )


def pq_from_pose(pose, *, scalar_first=True):
    """Pose vectors ``(tx, ty, tz, qw, qx, qy, qz)`` of poses (the quaternion normalised).

    The inverse of :func:`pose_from_pq`.

    Parameters
    ----------
    pose : array_like, shape (..., 7)
        ``(w, x, y, z, tx, ty, tz)``.
    scalar_first : bool
        True: pytransform3d's ``pq`` (the order of the summary line); False:
        TUM/ROS ``(tx, ty, tz, qx, qy, qz, qw)``.

    Returns
    -------
    ndarray, shape (..., 7)

    Examples
    --------
    >>> pq_from_pose([1.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0], scalar_first=False)
    array([1., 2., 3., 0., 0., 0., 1.])
    """
    kern = _k.pq_from_pose if scalar_first else _k.pq_xyzw_from_pose
    return kern(_pose(pose))
