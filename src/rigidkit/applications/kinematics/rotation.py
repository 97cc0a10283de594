"""Angular velocity and acceleration of a turning frame, from matrices and quaternions.

Conventions: ``R = A_R_B`` maps body (``B``) coordinates to world (``A``)
coordinates, ``v_A = A_R_B @ v_B``. The world angular velocity has
``R' = hat(omega_A) R``, the body one ``R' = R hat(omega_B)``, and
``omega_A = R omega_B``. For the inverse, ``B_R_A = R^T``: ``(B_R_A)' =
-B_R_A hat(omega_A) = -hat(omega_B) B_R_A`` (the spatial and body angular
velocities of Murray, Li & Sastry 1994, Sec. 2.4.1, and their forms for the
inverse; pass ``R.inv()`` and negate, or use them as written). Quaternions are
Hamilton, scalar first: ``q' = q (0, omega_B) / 2 = (0, omega_A) q / 2``;
``scalar_first=False`` reads and writes every quaternion array of a call (``q``,
``q'``, ``q''``) as ``(x, y, z, w)``, the order of scipy, ROS and Eigen.
"""

from __future__ import annotations

from ...functional import conversions as _conv
from ...kernels.kinematics import rotation as _k
from ...objects.rotation import Rotation
from ._common import body_flag, quaternion, rotation_matrix, vector

__all__ = [
    "angular_velocity",
    "rotation_derivative",
    "angular_acceleration",
    "rotation_second_derivative",
    "quaternion_derivative",
    "quaternion_second_derivative",
    "angular_velocity_from_quaternion_derivative",
]


def angular_velocity(R, R_dot, *, frame):
    """Angular velocity of a turning frame from its rotation matrix and derivative.

    World: ``hat(omega) = R' R^T``; body: ``hat(omega) = R^T R'``
    (``omega_world = R omega_body``).

    Parameters
    ----------
    R : Rotation or array_like, shape (..., 3, 3)
        ``A_R_B``, validated as a rotation.
    R_dot : array_like, shape (..., 3, 3)
        ``dR/dt``. Only its component tangent to SO(3) at ``R`` is used (``vee``
        of the skew part).
    frame : {"world", "body"}
        Required.

    Returns
    -------
    array, shape (..., 3)
        Radians per unit time.

    See Also
    --------
    rotation_derivative : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> R = np.eye(3)
    >>> R_dot = np.array([[0.0, -2.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    >>> angular_velocity(R, R_dot, frame="world")
    array([0., 0., 2.])
    """
    body = body_flag(frame, "angular_velocity")
    m = rotation_matrix(R)
    return _k.omega_from_matrix_derivative(body, m, vector(R_dot, (3, 3), "R_dot"))


def rotation_derivative(R, omega, *, frame):
    """``dR/dt``: ``hat(omega) R`` (world) or ``R hat(omega)`` (body).

    Parameters
    ----------
    R : Rotation or array_like, shape (..., 3, 3)
    omega : array_like, shape (..., 3)
        Angular velocity in ``frame``, radians per unit time.
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., 3, 3)

    See Also
    --------
    angular_velocity : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> rotation_derivative(np.eye(3), [0.0, 0.0, 1.0], frame="body")
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  0.]])
    """
    body = body_flag(frame, "rotation_derivative")
    m = rotation_matrix(R)
    return _k.matrix_derivative_from_omega(body, m, vector(omega, (3,), "angular velocity"))


def angular_acceleration(R, R_dot, R_ddot, *, frame):
    """Angular acceleration ``d omega/dt`` from ``R``, ``R'`` and ``R''``.

    ``hat(alpha) = R'' R^T + R' R'^T`` (world) and ``R' R'^T = -hat(omega)^2`` is
    symmetric, so ``alpha = vee(R'' R^T)``; body: ``alpha = vee(R^T R'')``. Both
    are the derivative of the angular velocity in its own frame, and
    ``alpha_world = R alpha_body``.

    Parameters
    ----------
    R : Rotation or array_like, shape (..., 3, 3)
    R_dot, R_ddot : array_like, shape (..., 3, 3)
        First and second time derivatives (``R_dot`` is checked; it enters only
        through a symmetric term).
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., 3)
        Radians per unit time squared.

    See Also
    --------
    rotation_second_derivative : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> W = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    >>> angular_acceleration(np.eye(3), W, 3.0 * W + W @ W, frame="world")
    array([0., 0., 3.])
    """
    body = body_flag(frame, "angular_acceleration")
    m = rotation_matrix(R)
    vector(R_dot, (3, 3), "R_dot")
    return _k.alpha_from_matrix_second_derivative(body, m, vector(R_ddot, (3, 3), "R_ddot"))


def rotation_second_derivative(R, omega, alpha, *, frame):
    """``R'' = (hat(alpha) + hat(omega)^2) R`` (world) or ``R (hat(alpha) + hat(omega)^2)``.

    The matrix form of the rotational acceleration: differentiate
    ``R' = hat(omega) R`` once more (docs/errata.md E3 lists a form that drops the
    derivative of ``hat(omega)``).

    Parameters
    ----------
    R : Rotation or array_like, shape (..., 3, 3)
    omega, alpha : array_like, shape (..., 3)
        Angular velocity and acceleration in ``frame``.
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., 3, 3)

    Examples
    --------
    >>> import numpy as np
    >>> w, a = [0, 0, 2.0], [0, 0, 0]
    >>> R_ddot = rotation_second_derivative(np.eye(3), w, a, frame="world")
    >>> np.round(R_ddot, 12)
    array([[-4.,  0.,  0.],
           [ 0., -4.,  0.],
           [ 0.,  0.,  0.]])
    """
    body = body_flag(frame, "rotation_second_derivative")
    m = rotation_matrix(R)
    w = vector(omega, (3,), "angular velocity")
    return _k.matrix_second_derivative(
        body, m, w, vector(alpha, (3,), "angular acceleration")
    )


def _quat_in(q, scalar_first, what="quaternion"):
    """Quaternions ``(w, x, y, z)`` from ``q`` given in the order of ``scalar_first``.

    A :class:`~rigidkit.Rotation` carries its own order and is read as it is.
    """
    qq = quaternion(q, what)
    if scalar_first or isinstance(q, Rotation):
        return qq
    return _conv.quat_wxyz_from_xyzw(qq)


def _quat_out(q, scalar_first):
    """A quaternion array ``(w, x, y, z)`` in the order of ``scalar_first``."""
    return q if scalar_first else _conv.quat_xyzw_from_wxyz(q)


def quaternion_derivative(q, omega, *, frame, scalar_first=True):
    """``q' = q (0, omega) / 2`` (body) or ``(0, omega) q / 2`` (world), Hamilton.

    Parameters
    ----------
    q : Rotation or array_like, shape (..., 4)
        Quaternions ``(w, x, y, z)`` (any scale: ``q'`` scales with ``q``).
    omega : array_like, shape (..., 3)
        Angular velocity in ``frame``, radians per unit time.
    frame : {"world", "body"}
    scalar_first : bool, default True
        ``False``: ``q`` (an array) and the result are ``(x, y, z, w)``, as
        scipy's ``as_quat()``.

    Returns
    -------
    array, shape (..., 4)
        ``q'``, in the order of ``scalar_first``.

    See Also
    --------
    angular_velocity_from_quaternion_derivative : the inverse.

    Examples
    --------
    >>> quaternion_derivative([1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 2.0], frame="body")
    array([0., 0., 0., 1.])
    >>> quaternion_derivative([0, 0, 0, 1.0], [0, 0, 2.0], frame="body", scalar_first=False)
    array([0., 0., 1., 0.])
    """
    body = body_flag(frame, "quaternion_derivative")
    w = vector(omega, (3,), "angular velocity")
    return _quat_out(_k.quat_derivative(body, _quat_in(q, scalar_first), w), scalar_first)


def quaternion_second_derivative(q, omega, alpha, *, frame, scalar_first=True):
    """``q'' = q (-|omega|^2/4, alpha/2)`` (body) or ``(-|omega|^2/4, alpha/2) q`` (world).

    Parameters
    ----------
    q : Rotation or array_like, shape (..., 4)
        Quaternions ``(w, x, y, z)``, or ``(x, y, z, w)`` if ``scalar_first=False``.
    omega, alpha : array_like, shape (..., 3)
        Angular velocity and acceleration in ``frame``.
    frame : {"world", "body"}
    scalar_first : bool, default True
        ``False``: ``q`` (an array) and the result are ``(x, y, z, w)``.

    Returns
    -------
    array, shape (..., 4)
        ``q''``, in the order of ``scalar_first``.

    Examples
    --------
    >>> quaternion_second_derivative([1.0, 0, 0, 0], [0, 0, 2.0], [0, 0, 0], frame="world")
    array([-1.,  0.,  0.,  0.])
    """
    body = body_flag(frame, "quaternion_second_derivative")
    w = vector(omega, (3,), "angular velocity")
    a = vector(alpha, (3,), "angular acceleration")
    qdd = _k.quat_second_derivative(body, _quat_in(q, scalar_first), w, a)
    return _quat_out(qdd, scalar_first)


def angular_velocity_from_quaternion_derivative(q, q_dot, *, frame, scalar_first=True):
    """``omega = 2 vec(q* q') / |q|^2`` (body) or ``2 vec(q' q*) / |q|^2`` (world).

    Any scale of ``q`` (a changing norm only affects the scalar part).

    Parameters
    ----------
    q : Rotation or array_like, shape (..., 4)
        Nonzero quaternions ``(w, x, y, z)``.
    q_dot : array_like, shape (..., 4)
    frame : {"world", "body"}
    scalar_first : bool, default True
        ``False``: the arrays ``q`` and ``q_dot`` are ``(x, y, z, w)``, as scipy's
        ``as_quat()`` (``q_dot`` is always an array, so it follows this order even
        when ``q`` is a :class:`~rigidkit.Rotation`).

    Returns
    -------
    array, shape (..., 3)

    Raises
    ------
    ZeroNormError
        For a zero ``q``, naming the batch index.

    Examples
    --------
    >>> q, q_dot = [2.0, 0, 0, 0], [0, 0, 0, 2.0]
    >>> angular_velocity_from_quaternion_derivative(q, q_dot, frame="body")
    array([0., 0., 2.])
    """
    body = body_flag(frame, "angular_velocity_from_quaternion_derivative")
    qq = _quat_in(q, scalar_first)
    _conv.quat_normalize(qq)  # rejects a zero quaternion, with its batch index
    qd = vector(q_dot, (4,), "q_dot")
    if not scalar_first:
        qd = _conv.quat_wxyz_from_xyzw(qd)
    return _k.omega_from_quat_derivative(body, qq, qd)
