"""Planar kinematics: SO(2) and SE(2) velocities and points moving in the plane.

A planar rotation ``R(t) = exp(theta(t) J)``, ``J = [[0, -1], [1, 0]]`` (a
constant rate makes a one-parameter group, ``F(t) F(s) = F(t + s)``, which is
``R = exp(omega J t)`` with ``omega J = R'(0)``), turns at ``omega`` with
``R' = omega J R = R omega J``: world and body angular velocity are one number
(shape (..., 1), like the so(2) tangent vectors). Planar twists are
``(vx, vy, omega)`` with ``T' = hat(V) T`` (world) or ``T hat(V)`` (body),
``V_world = Ad_T V_body``. Sampled rates integrate into trajectories as in 3D
(:func:`integrate_angular_velocity`, :func:`integrate_twist`), and sampled
trajectories give their velocities (:func:`angular_velocity_from_samples`,
:func:`twist_from_samples`).

>>> import numpy as np
>>> R = np.array([[0.0, -1.0], [1.0, 0.0]])          # theta = pi/2
>>> R_dot = 3.0 * np.array([[0.0, -1.0], [1.0, 0.0]]) @ R
>>> angular_velocity(R, R_dot, frame="world")
array([3.])
"""

from __future__ import annotations

from ...functional import se2 as _se2
from ...functional import so2 as _so2
from ...kernels.kinematics import planar as _k
from ...objects.rotation2d import Rotation2D
from ...objects.transform2d import Transform2D
from ._common import body_flag, vector
from .integration import integrate_from
from .samples import from_samples

__all__ = [
    "angular_velocity",
    "rotation_derivative",
    "twist_from_derivative",
    "transform_derivative",
    "twist_to_world",
    "twist_to_body",
    "point_velocity",
    "point_acceleration",
    "integrate_angular_velocity",
    "integrate_twist",
    "angular_velocity_from_samples",
    "twist_from_samples",
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


def angular_velocity(R, R_dot, *, frame):
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


def rotation_derivative(R, omega, *, frame):
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
    At the identity, ``R' = omega J``:

    >>> import numpy as np
    >>> rotation_derivative(np.eye(2), [2.0], frame="world") + 0.0
    array([[ 0., -2.],
           [ 2.,  0.]])
    """
    body_flag(frame, "planar.rotation_derivative")
    return _k.matrix_derivative_from_omega_2d(
        _rotation(R), vector(omega, (1,), "angular velocity")
    )


def twist_from_derivative(T, T_dot, *, frame):
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


def transform_derivative(T, twist, *, frame):
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


def twist_to_world(T, twist_body):
    """``V_world = Ad_T V_body = (R v + omega (ty, -tx), omega)``, planar twists.

    Parameters
    ----------
    T : Transform2D or array_like, shape (..., 3, 3)
        ``W_T_B``.
    twist_body : array_like, shape (..., 3)
        ``(vx, vy, omega)`` in the body frame.

    Returns
    -------
    array, shape (..., 3)

    See Also
    --------
    twist_to_body : the inverse.

    Examples
    --------
    Turning in place about the body origin, one unit along x: the world twist's
    ``v`` is the velocity of the world point at the origin.

    >>> import numpy as np
    >>> T = np.eye(3); T[0, 2] = 1.0
    >>> twist_to_world(T, [0.0, 0.0, 1.0])
    array([ 0., -1.,  1.])
    """
    return _k.twist_change_frame_2d(
        0, _transform(T), vector(twist_body, (3,), "body twist")
    )


def twist_to_body(T, twist_world):
    """``V_body = Ad_T^-1 V_world = (R^T (v - omega (ty, -tx)), omega)``.

    Parameters
    ----------
    T : Transform2D or array_like, shape (..., 3, 3)
    twist_world : array_like, shape (..., 3)

    Returns
    -------
    array, shape (..., 3)

    Examples
    --------
    >>> import numpy as np
    >>> T = np.eye(3); T[0, 2] = 1.0
    >>> twist_to_body(T, [0.0, -1.0, 1.0]) + 0.0
    array([0., 0., 1.])
    """
    return _k.twist_change_frame_2d(
        1, _transform(T), vector(twist_world, (3,), "world twist")
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
    Coriolis; for a point of the body (``v_rel = a_rel = 0``) it is
    ``[[-omega^2, -alpha], [alpha, -omega^2]] r`` with ``alpha = omega'``.

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


def integrate_angular_velocity(R0, omega, dt, *, frame, method="exact"):
    """Planar orientations of a body turning at the sampled rates ``omega``.

    SO(2) is commutative, so ``R_N = R_0 exp(J theta_N)`` with ``theta_N`` the
    integral of the rate: "exact" (zero-order hold) sums ``omega_k dt_k``,
    "midpoint" sums the midpoint rates (linear interpolation, 2nd order), and
    "rk4" applies Simpson's rule on the cubic through the nearest samples (RKMK4,
    whose brackets vanish in the plane: 4th order). Sampling and step times as in
    :func:`rigidkit.kinematics.integrate_angular_velocity`. The angles are
    summed by a pairwise scheme (rounding grows with ``log N``).

    Parameters
    ----------
    R0 : Rotation2D or array_like, shape (..., 2, 2)
        Initial orientation ``W_R_B``.
    omega : array_like, shape (..., N, 1)
        Angular velocity samples (rad per unit time, counter-clockwise), one
        1-vector per step like the so(2) tangent vectors; a 1-D log ``w`` of N
        samples is ``w[:, None]``. The batch shape broadcasts with ``R0``'s.
    dt : float or array_like, shape (N,) or (..., N)
        Step durations.
    frame : {"world", "body"}
        Required for uniformity with 3D (the two agree in the plane).
    method : {"exact", "midpoint", "rk4"}
        "midpoint" needs N >= 2 samples, "rk4" N >= 4.

    Returns
    -------
    Rotation2D of shape (..., N + 1), or matrices (..., N + 1, 2, 2) when ``R0``
    is an array. Element 0 is ``R0``.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> w = np.full((100, 1), np.pi / 2)                 # a quarter turn in 1 s
    >>> traj = integrate_angular_velocity(rk.Rotation2D.identity(), w, 0.01,
    ...                                   frame="body")
    >>> traj.shape, round(float(traj[-1].angle), 12)
    ((101,), 1.570796326795)
    """
    fn = "planar.integrate_angular_velocity"
    return integrate_from(R0, omega, dt, method, frame, fn, Rotation2D, _rotation)


def integrate_twist(T0, twist, dt, *, frame, method="exact"):
    """Planar poses of a body moving with the sampled twists ``(vx, vy, omega)``.

    Body frame (odometry: ``v`` the velocity of the body origin in its own axes):
    ``T' = T hat(V)``; world frame: ``T' = hat(V) T``. Each step is ``exp`` of
    se(2), chained in order; methods and sampling as in
    :func:`rigidkit.kinematics.integrate_twist` (zero-order hold, 2nd and 4th
    order, RKMK4 with the bracket of se(2)).

    Parameters
    ----------
    T0 : Transform2D or array_like, shape (..., 3, 3)
        Initial pose ``W_T_B``.
    twist : array_like, shape (..., N, 3)
    dt : float or array_like, shape (N,) or (..., N)
    frame : {"world", "body"}
    method : {"exact", "midpoint", "rk4"}

    Returns
    -------
    Transform2D of shape (..., N + 1), or matrices (..., N + 1, 3, 3) when ``T0``
    is an array.

    Examples
    --------
    A unicycle driving a half circle of radius 2: forward at 2, turning at 1 rad/s.

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> V = np.tile([2.0, 0.0, 1.0], (100, 1))
    >>> traj = integrate_twist(rk.Transform2D.identity(), V, np.pi / 100, frame="body")
    >>> np.round(traj[-1].translation, 12) + 0.0
    array([0., 4.])
    """
    fn = "planar.integrate_twist"
    return integrate_from(T0, twist, dt, method, frame, fn, Transform2D, _transform)


def angular_velocity_from_samples(rotations, times, *, frame):
    """Planar angular velocity at each sample of an orientation trajectory.

    The finite differences on the group of
    :func:`rigidkit.kinematics.angular_velocity_from_samples` (one algorithm for
    every group, :func:`.samples.velocity_from_samples`): second-order accurate,
    exact for a constant rate when every step turns by less than pi.

    Parameters
    ----------
    rotations : Rotation2D of shape (..., N), or array_like (..., N, 2, 2)
        Orientations ``W_R_B`` at the sample times.
    times : array_like, shape (N,) or (..., N)
        Strictly increasing (non-uniform allowed).
    frame : {"world", "body"}
        Required for uniformity with 3D (the two agree in the plane).

    Returns
    -------
    array, shape (..., N, 1)
        Radians per unit time, counter-clockwise.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> t = np.array([0.0, 0.1, 0.3, 0.4])
    >>> R = rk.Rotation2D.from_angle(2.0 * t)
    >>> np.round(angular_velocity_from_samples(R, t, frame="world")[:, 0], 12)
    array([2., 2., 2., 2.])
    """
    fn = "planar.angular_velocity_from_samples"
    return from_samples(rotations, times, frame, fn, Rotation2D, _rotation, "rotations")


def twist_from_samples(transforms, times, *, frame):
    """Planar twist ``(vx, vy, omega)`` at each sample of a pose trajectory.

    The finite differences on the group of
    :func:`rigidkit.kinematics.twist_from_samples`.

    Parameters
    ----------
    transforms : Transform2D of shape (..., N), or array_like (..., N, 3, 3)
        Poses ``W_T_B`` at the sample times.
    times : array_like, shape (N,) or (..., N)
        Strictly increasing (non-uniform allowed).
    frame : {"world", "body"}
        World: ``hat(V) = T' T^-1``; body: ``T^-1 T'``.

    Returns
    -------
    array, shape (..., N, 3)
        ``(vx, vy, omega)`` in the axes of ``frame``, per unit time.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> V = np.array([2.0, 0.0, 1.0])              # forward at 2, turning at 1 rad/s
    >>> t = np.linspace(0.0, 2.0, 5)
    >>> T = rk.Transform2D.exp(t[:, None] * V)
    >>> np.round(twist_from_samples(T, t, frame="body")[2], 12) + 0.0
    array([2., 0., 1.])
    """
    fn = "planar.twist_from_samples"
    return from_samples(transforms, times, frame, fn, Transform2D, _transform, "transforms")
