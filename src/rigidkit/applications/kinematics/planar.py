"""Planar kinematics: SO(2) and SE(2) velocities and points moving in the plane.

A planar rotation ``R(t) = exp(theta(t) J)``, ``J = [[0, -1], [1, 0]]`` (the
notes' ``e^{J omega t}``: the additive property ``F(t) F(s) = F(t + s)`` makes
``R = exp(omega J t)`` with ``omega J = R'(0)``), turns at ``omega`` with
``R' = omega J R = R omega J``: world and body angular velocity are one number
(shape (..., 1), like the so(2) tangent vectors). Planar twists are
``(vx, vy, omega)`` with ``T' = hat(V) T`` (world) or ``T hat(V)`` (body).

>>> import numpy as np
>>> R = np.array([[0.0, -1.0], [1.0, 0.0]])          # theta = pi/2
>>> R_dot = 3.0 * np.array([[0.0, -1.0], [1.0, 0.0]]) @ R
>>> angular_velocity(R, R_dot, frame="world")
array([3.])
"""

from __future__ import annotations

from ...functional import se2 as _se2
from ...functional import so2 as _so2
from ...kernels import kinematics_planar as _k
from ._common import body_flag, vector

__all__ = [
    "angular_velocity",
    "rotation_derivative",
    "twist_from_derivative",
    "transform_derivative",
    "point_velocity",
    "point_acceleration",
]


def _rotation(R):
    if hasattr(R, "as_matrix") and hasattr(R, "as_complex"):  # a Rotation2D
        return R.as_matrix()
    m = vector(R, (2, 2), "2D rotation matrix")
    _so2.log(m)  # raises NotARotationError with the batch index
    return m


def _transform(T):
    if hasattr(T, "as_matrix") and hasattr(T, "translation"):  # a Transform2D
        return T.as_matrix()
    m = vector(T, (3, 3), "2D homogeneous matrix")
    _se2.pose_from_matrix(m)
    return m


def angular_velocity(R, R_dot, *, frame=None):
    """``omega`` with ``R' = omega J R``; the same in the world and body frame.

    Parameters
    ----------
    R : Rotation2D or array_like, shape (..., 2, 2)
    R_dot : array_like, shape (..., 2, 2)
    frame : {"world", "body"}
        Required for uniformity with 3D (the two agree in the plane).

    Returns
    -------
    array, shape (..., 1)
    """
    body_flag(frame, "planar.angular_velocity")
    return _k.omega_from_matrix_derivative_2d(_rotation(R), vector(R_dot, (2, 2), "R_dot"))


def rotation_derivative(R, omega, *, frame=None):
    """``R' = omega J R`` (= ``R omega J``).

    Parameters
    ----------
    R : Rotation2D or array_like, shape (..., 2, 2)
    omega : array_like, shape (..., 1)
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., 2, 2)

    Examples
    --------
    The notes' ``R'(0) = omega J``:

    >>> import numpy as np
    >>> rotation_derivative(np.eye(2), [2.0], frame="world") + 0.0
    array([[ 0., -2.],
           [ 2.,  0.]])
    """
    body_flag(frame, "planar.rotation_derivative")
    return _k.matrix_derivative_from_omega_2d(
        _rotation(R), vector(omega, (1,), "angular velocity")
    )


def twist_from_derivative(T, T_dot, *, frame=None):
    """Planar twist ``(vx, vy, omega)``: ``hat(V) = T' T^-1`` (world) or ``T^-1 T'``.

    Parameters
    ----------
    T : Transform2D or array_like, shape (..., 3, 3)
    T_dot : array_like, shape (..., 3, 3)
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., 3)
    """
    body = body_flag(frame, "planar.twist_from_derivative")
    return _k.twist_from_matrix_derivative_2d(
        body, _transform(T), vector(T_dot, (3, 3), "T_dot")
    )


def transform_derivative(T, twist, *, frame=None):
    """``T' = hat(V) T`` (world) or ``T hat(V)`` (body), planar twists ``(vx, vy, omega)``.

    Parameters
    ----------
    T : Transform2D or array_like, shape (..., 3, 3)
    twist : array_like, shape (..., 3)
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., 3, 3)
    """
    body = body_flag(frame, "planar.transform_derivative")
    return _k.matrix_derivative_from_twist_2d(
        body, _transform(T), vector(twist, (3,), "planar twist")
    )


def point_velocity(omega, r, v_origin=(0.0, 0.0)):
    """``v = v_O + omega J r`` of the point at ``r`` from a body point ``O``.

    Parameters
    ----------
    omega : array_like, shape (..., 1)
    r, v_origin : array_like, shape (..., 2)

    Returns
    -------
    array, shape (..., 2)

    Examples
    --------
    >>> point_velocity([2.0], [1.0, 0.0])
    array([0., 2.])
    """
    w = vector(omega, (1,), "angular velocity")
    return _k.point_velocity_2d(w, vector(r, (2,), "r"), vector(v_origin, (2,), "v_origin"))


def point_acceleration(
    omega, alpha, r, a_origin=(0.0, 0.0), v_rel=(0.0, 0.0), a_rel=(0.0, 0.0)
):
    """``a = a_O + (alpha J - omega^2 I) r + 2 omega J v_rel + a_rel``.

    ``alpha J r`` tangential, ``-omega^2 r`` centripetal, ``2 omega J v_rel``
    Coriolis; for a point of the body this is the notes' planar
    ``[[-omega^2, -alpha], [alpha, -omega^2]] r`` (000 D.3, with ``alpha`` for the
    derivative they write ``omega'``).

    Parameters
    ----------
    omega, alpha : array_like, shape (..., 1)
    r, a_origin, v_rel, a_rel : array_like, shape (..., 2)

    Returns
    -------
    array, shape (..., 2)

    Examples
    --------
    >>> point_acceleration([2.0], [1.0], [1.0, 0.0])
    array([-4.,  1.])
    """
    w = vector(omega, (1,), "angular velocity")
    return _k.point_acceleration_2d(
        w,
        vector(alpha, (1,), "angular acceleration"),
        vector(r, (2,), "r"),
        vector(a_origin, (2,), "a_origin"),
        vector(v_rel, (2,), "v_rel"),
        vector(a_rel, (2,), "a_rel"),
    )
