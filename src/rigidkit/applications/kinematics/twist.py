"""Twists and rigid-body velocities: ``T' = hat(V) T`` (world) or ``T hat(V)`` (body).

Conventions: ``T = W_T_B = [[R, p], [0, 1]]`` maps body points to world points;
twists are ``V = (v, omega)`` with ``hat(V) = [[hat(omega), v], [0, 0]]`` (scipy
orders them ``(omega, v)``). The world twist (``hat(V) = T' T^-1``, the spatial
velocity of Murray, Li & Sastry 1994, Sec. 2.4.2) has ``v = p' - omega x p``, the
velocity of the world point passing through the origin; the body twist
(``T^-1 T'``, their body velocity) has ``v = R^T p'``, the velocity of the body
origin in body axes. ``V_world = Ad_T V_body``.

A point ``q`` of the body (world coordinates) moves at ``hat(V) [q; 1]`` and
accelerates at ``(hat(V') + hat(V)^2) [q; 1]`` (world twists: differentiate
``[q'; 0] = hat(V) [q; 1]`` once more).
"""

from __future__ import annotations

from ...functional import screw as _screw
from ...kernels.kinematics import twist as _k
from ._common import body_flag, homogeneous_matrix, vector

__all__ = [
    "twist_from_derivative",
    "transform_derivative",
    "transform_second_derivative",
    "spatial_acceleration_matrix",
    "twist_to_world",
    "twist_to_body",
    "point_velocity",
    "point_acceleration",
    "screw_from_twist",
    "twist_from_screw",
]

screw_from_twist = _screw.screw_from_twist
twist_from_screw = _screw.twist_from_screw


def twist_from_derivative(T, T_dot, *, frame):
    """Twist ``(v, omega)`` of a moving frame: ``hat(V) = T' T^-1`` or ``T^-1 T'``.

    World: ``omega = vee(R' R^T)``, ``v = p' - omega x p`` (the spatial velocity of
    Murray, Li & Sastry 1994, Sec. 2.4.2); body:
    ``omega = vee(R^T R')``, ``v = R^T p'``.

    Parameters
    ----------
    T : Transform or array_like, shape (..., 4, 4)
        ``W_T_B``, validated.
    T_dot : array_like, shape (..., 4, 4)
        ``dT/dt`` (its bottom row is not read).
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., 6)

    See Also
    --------
    transform_derivative : the inverse.

    Examples
    --------
    A frame at ``p = (1, 0, 0)`` turning about the world z-axis at 1 rad/s:

    >>> import numpy as np
    >>> T = np.eye(4); T[0, 3] = 1.0
    >>> T_dot = np.zeros((4, 4)); T_dot[0, 1] = -1.0; T_dot[1, 0] = 1.0; T_dot[1, 3] = 1.0
    >>> twist_from_derivative(T, T_dot, frame="world")
    array([0., 0., 0., 0., 0., 1.])
    >>> twist_from_derivative(T, T_dot, frame="body")
    array([0., 1., 0., 0., 0., 1.])
    """
    body = body_flag(frame, "twist_from_derivative")
    m = homogeneous_matrix(T)
    return _k.twist_from_matrix_derivative(body, m, vector(T_dot, (4, 4), "T_dot"))


def transform_derivative(T, twist, *, frame):
    """``dT/dt = hat(V) T`` (world) or ``T hat(V)`` (body).

    Parameters
    ----------
    T : Transform or array_like, shape (..., 4, 4)
    twist : array_like, shape (..., 6)
        ``(v, omega)`` in ``frame``.
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., 4, 4)

    See Also
    --------
    twist_from_derivative : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> transform_derivative(np.eye(4), [1.0, 0, 0, 0, 0, 0], frame="body")[:3, 3]
    array([1., 0., 0.])
    """
    body = body_flag(frame, "transform_derivative")
    m = homogeneous_matrix(T)
    return _k.matrix_derivative_from_twist(body, m, vector(twist, (6,), "twist"))


def transform_second_derivative(T, twist, twist_dot, *, frame):
    """``T'' = (hat(V') + hat(V)^2) T`` (world) or ``T (hat(V') + hat(V)^2)`` (body).

    Parameters
    ----------
    T : Transform or array_like, shape (..., 4, 4)
    twist, twist_dot : array_like, shape (..., 6)
        The twist ``(v, omega)`` in ``frame`` and its time derivative.
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., 4, 4)

    Examples
    --------
    >>> import numpy as np
    >>> T = np.eye(4); T[0, 3] = 2.0
    >>> V = [0, 0, 0, 0, 0, 1.0]
    >>> transform_second_derivative(T, V, np.zeros(6), frame="world")[:3, 3]
    array([-2.,  0.,  0.])
    """
    body = body_flag(frame, "transform_second_derivative")
    m = homogeneous_matrix(T)
    V = vector(twist, (6,), "twist")
    return _k.matrix_second_derivative_from_twist(
        body, m, V, vector(twist_dot, (6,), "twist_dot")
    )


def spatial_acceleration_matrix(twist, twist_dot, *, frame):
    """``hat(V') + hat(V)^2 = [[hat(alpha) + hat(omega)^2, v' + omega x v], [0, 0]]``.

    For world twists, ``q'' = M [q; 1]`` is the acceleration of the body point at
    world position ``q`` (``M = T'' T^-1``); for body twists ``M = T^-1 T''`` acts
    on body coordinates and gives the acceleration in body axes. Differentiating
    ``[q'; 0] = hat(V) [q; 1]`` gives ``[q''; 0] = hat(V') [q; 1] + hat(V) [q'; 0] =
    (hat(V') + hat(V)^2) [q; 1]``: the derivative of the twist, acting on the point
    ``[q; 1]``.

    Parameters
    ----------
    twist, twist_dot : array_like, shape (..., 6)
        ``(v, omega)`` and its derivative ``(v', alpha)`` in ``frame``.
    frame : {"world", "body"}
        Required (the formula is the same; the frame says what it acts on).

    Returns
    -------
    array, shape (..., 4, 4)

    Examples
    --------
    Uniform rotation about z at 2 rad/s: a point at (1, 0, 0) accelerates at
    ``-4`` towards the axis.

    >>> import numpy as np
    >>> M = spatial_acceleration_matrix([0, 0, 0, 0, 0, 2.0], np.zeros(6), frame="world")
    >>> M @ np.array([1.0, 0.0, 0.0, 1.0])
    array([-4.,  0.,  0.,  0.])
    """
    body_flag(frame, "spatial_acceleration_matrix")
    V = vector(twist, (6,), "twist")
    return _k.acceleration_matrix_from_twists(V, vector(twist_dot, (6,), "twist_dot"))


def twist_to_world(T, twist_body):
    """``V_world = Ad_T V_body = (R v + p x R omega, R omega)``.

    Parameters
    ----------
    T : Transform or array_like, shape (..., 4, 4)
        ``W_T_B``.
    twist_body : array_like, shape (..., 6)

    Returns
    -------
    array, shape (..., 6)

    See Also
    --------
    twist_to_body : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> T = np.eye(4); T[0, 3] = 1.0
    >>> twist_to_world(T, [0.0, 1.0, 0.0, 0.0, 0.0, 1.0])
    array([0., 0., 0., 0., 0., 1.])
    """
    m = homogeneous_matrix(T)
    return _k.twist_change_frame(0, m, vector(twist_body, (6,), "body twist"))


def twist_to_body(T, twist_world):
    """``V_body = Ad_T^-1 V_world = (R^T (v - p x omega), R^T omega)``.

    Parameters
    ----------
    T : Transform or array_like, shape (..., 4, 4)
    twist_world : array_like, shape (..., 6)

    Returns
    -------
    array, shape (..., 6)

    Examples
    --------
    >>> import numpy as np
    >>> T = np.eye(4); T[0, 3] = 1.0
    >>> twist_to_body(T, [0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    array([0., 1., 0., 0., 0., 1.])
    """
    m = homogeneous_matrix(T)
    return _k.twist_change_frame(1, m, vector(twist_world, (6,), "world twist"))


def point_velocity(omega, r, v_origin=0.0):
    """Velocity ``v_O + omega x r`` of the body point at ``r`` from a body point ``O``.

    All vectors in one frame (world, or body axes for body velocities).

    Parameters
    ----------
    omega : array_like, shape (..., 3)
        Angular velocity, radians per unit time.
    r : array_like, shape (..., 3)
        Position of the point relative to ``O``.
    v_origin : array_like, shape (..., 3), optional
        Velocity of ``O`` (default 0: ``O`` on the axis).

    Returns
    -------
    array, shape (..., 3)

    Examples
    --------
    >>> point_velocity([0.0, 0.0, 2.0], [1.0, 0.0, 0.0])
    array([0., 2., 0.])
    """
    w = vector(omega, (3,), "angular velocity")
    return _k.point_velocity(w, vector(r, (3,), "r"), _zero3(v_origin, w, "v_origin"))


def point_acceleration(omega, alpha, r, a_origin=0.0, v_rel=0.0, a_rel=0.0):
    """Acceleration of a point at ``r`` from a body point ``O``, in one frame.

    ``a = a_O + alpha x r + omega x (omega x r) + 2 omega x v_rel + a_rel``: the
    tangential (``alpha x r``), centripetal (``omega x (omega x r)``, towards the
    axis) and Coriolis (``2 omega x v_rel``) terms, for a point moving relative
    to the body at ``v_rel`` with acceleration ``a_rel`` (both zero for a point of
    the body).

    Parameters
    ----------
    omega, alpha : array_like, shape (..., 3)
        Angular velocity and acceleration.
    r : array_like, shape (..., 3)
    a_origin, v_rel, a_rel : array_like, shape (..., 3), optional
        Default 0.

    Returns
    -------
    array, shape (..., 3)

    Examples
    --------
    >>> point_acceleration([0, 0, 2.0], [0, 0, 0], [1.0, 0, 0], v_rel=[1.0, 0, 0])
    array([-4.,  4.,  0.])
    """
    w = vector(omega, (3,), "angular velocity")
    return _k.point_acceleration(
        w,
        vector(alpha, (3,), "angular acceleration"),
        vector(r, (3,), "r"),
        _zero3(a_origin, w, "a_origin"),
        _zero3(v_rel, w, "v_rel"),
        _zero3(a_rel, w, "a_rel"),
    )


def _zero3(x, like, what):
    """An optional vector: the scalar 0 default becomes a zero 3-vector like ``like``."""
    if isinstance(x, (int, float)) and x == 0:
        from ..._engine.namespace import device_of, namespace_of

        xp = namespace_of(like)
        return xp.zeros((3,), dtype=like.dtype, device=device_of(like))
    return vector(x, (3,), what)
