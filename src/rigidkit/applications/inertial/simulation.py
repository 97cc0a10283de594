"""IMU readings of a body moving along a trajectory: ideal, and with noise and biases.

The trajectory gives the pose ``world_T_body(t) = (R, p)`` and its exact first and
second derivatives as body twists ``V = (v_b, w) = vee(T^-1 dT/dt)`` and ``dV/dt``
(``rk.BSplineSE3``, or any callable ``traj(t, order, frame="body")`` that does).
Then ``dp/dt = R v_b`` and ``d2p/dt2 = R (w x v_b + dv_b/dt)``, so the ideal readings
are the body rate ``w`` and the specific force ``f = R^T (a - g) = w x v_b + dv_b/dt
- R^T g``, in the navigation frame ``frame="world"`` with gravity ``g`` (m/s^2) any
vector. With the frame's own rotation ``W`` (``earth_rate``) the gyroscope reads
``w + R^T W`` and the accelerometer adds the Coriolis and centrifugal terms,
``R^T (2 W x dp/dt + W x (W x p))``, as :func:`~.strapdown.integrate` expects.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._engine.namespace import namespace_of
from ...objects.extended_pose import ExtendedPose
from ...objects.rotation import Rotation
from .preintegration import ImuNoise
from .strapdown import GRAVITY, vector_like

__all__ = ["imu_from_trajectory", "simulate_imu", "states_from_trajectory", "ImuLog"]


@dataclass(frozen=True)
class ImuLog:
    """Simulated IMU samples (:func:`simulate_imu`).

    Attributes
    ----------
    times : ndarray, shape (N,)
        Sample stamps (s), ``1 / rate_hz`` apart; sample ``k`` is held over
        ``[times[k], times[k] + dt]``.
    dt : float
    gyro, accel : ndarray, shape (..., N, 3)
        Measured body rates (rad/s) and specific forces (m/s^2).
    gyro_bias, accel_bias : ndarray, shape (..., N, 3)
        The biases in each sample (their random walks), the truth to estimate.
    """

    times: np.ndarray
    dt: float
    gyro: np.ndarray
    accel: np.ndarray
    gyro_bias: np.ndarray
    accel_bias: np.ndarray


def _pose_and_twists(trajectory, times):
    """The poses and body twists in the trajectory's namespace (traced, lazy, on the
    autograd graph: no conversion to NumPy)."""
    T = trajectory(times)
    V = trajectory(times, 1, frame="body")
    A = trajectory(times, 2, frame="body")
    return T, V, A


def _cross(a, b):
    """``a x b`` over the last axis, in the namespace of ``a`` and ``b``."""
    xp = namespace_of(a, b)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return xp.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def imu_from_trajectory(trajectory, times, *, gravity=GRAVITY, earth_rate=None):
    """Ideal gyroscope and accelerometer readings along ``trajectory`` at ``times``.

    Parameters
    ----------
    trajectory : BSplineSE3 or callable
        ``trajectory(t)`` a :class:`~rigidkit.Transform` ``world_T_body``, and
        ``trajectory(t, 1, frame="body")``, ``trajectory(t, 2, frame="body")`` its
        body twist ``(v_b, w)`` and that twist's derivative (exact).
    times : array_like, shape (...)
    gravity : array_like, shape (3,)
        ``g`` in the navigation frame (m/s^2).
    earth_rate : array_like, shape (3,), optional
        The navigation frame's rotation ``W`` (rad/s), in its axes.

    Returns
    -------
    gyro, accel : ndarray, shape (..., 3)
        ``w (+ R^T W)`` (rad/s) and ``f = R^T (a - g)`` (m/s^2) in the body frame.

    Examples
    --------
    A body turning about z at 0.2 rad/s while moving along x at 1 m/s:

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> ctrl = rk.Transform.exp(np.outer(np.arange(6.0), [1.0, 0, 0, 0, 0, 0.2]))
    >>> gyro, accel = rk.inertial.imu_from_trajectory(rk.BSplineSE3(ctrl), 1.0)
    >>> np.round(gyro, 12) + 0.0, np.round(accel, 12) + 0.0   # w, w x v - R^T g
    (array([0. , 0. , 0.2]), array([0.  , 0.2 , 9.81]))
    """
    T, V, A = _pose_and_twists(trajectory, times)
    w, vb = V[..., 3:], V[..., :3]
    R = T.rotation
    g = vector_like(gravity, V, "gravity")
    f = _cross(w, vb) + A[..., :3] - R.apply(g, inverse=True)
    if earth_rate is not None:
        W = vector_like(earth_rate, V, "earth_rate")
        p = T.translation
        v = R.apply(vb)
        extra = 2.0 * _cross(W, v) + _cross(W, _cross(W, p))
        f = f + R.apply(extra, inverse=True)
        w = w + R.apply(W, inverse=True)
    return w, f


def states_from_trajectory(trajectory, times):
    """The navigation states ``(R, v, p)`` along ``trajectory`` at ``times``
    (``v = R v_b``, in the navigation frame ``"world"``), an ExtendedPose (...).

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> ctrl = rk.Transform.exp(np.outer(np.arange(6.0), [1.0, 0, 0, 0, 0, 0.0]))
    >>> X = rk.inertial.states_from_trajectory(rk.BSplineSE3(ctrl), [0.0, 2.0])
    >>> np.round(X.velocity, 12) + 0.0, np.round(X.position[:, 0], 12) + 0.0
    (array([[1., 0., 0.],
           [1., 0., 0.]]), array([1., 3.]))
    """
    T = trajectory(times)
    V = trajectory(times, 1, frame="body")
    R = T.rotation
    return ExtendedPose(
        rotation=Rotation._wrap(R._quat),
        velocity=R.apply(V[..., :3]),
        position=T.translation,
    )


def simulate_imu(
    trajectory,
    rate_hz,
    *,
    noise=None,
    rng=None,
    shape=(),
    gravity=GRAVITY,
    earth_rate=None,
    gyro_bias=0.0,
    accel_bias=0.0,
):
    """Noisy IMU samples along ``trajectory`` at ``rate_hz``, with drifting biases.

    Sample ``k`` at ``t_k = t_min + k / rate_hz`` (over the trajectory's span) is the
    ideal reading (:func:`imu_from_trajectory`) plus the bias and white noise of
    standard deviation ``density * sqrt(rate_hz)`` (``noise``, :class:`ImuNoise`);
    the biases start at ``gyro_bias``, ``accel_bias`` and walk by
    ``random_walk / sqrt(rate_hz)`` per sample (a discretised Wiener process).

    Parameters
    ----------
    trajectory : BSplineSE3 or callable
        As :func:`imu_from_trajectory`, with attributes ``t_min`` and ``t_max``.
    rate_hz : float
    noise : ImuNoise, optional
        None: ideal samples (constant biases).
    rng : numpy.random.Generator or int, optional
        Seeded, so a simulation is reproducible.
    shape : tuple
        Batch of independent noise realisations: the arrays are ``shape + (N, 3)``.
    gravity, earth_rate
        As :func:`imu_from_trajectory`.
    gyro_bias, accel_bias : float or array_like, shape (3,) or shape + (3,)
        The initial biases.

    Returns
    -------
    ImuLog

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> ctrl = rk.Transform.exp(np.outer(np.arange(6.0), [1.0, 0, 0, 0, 0, 0.2]))
    >>> noise = rk.inertial.ImuNoise(1e-3, 1e-2, 1e-5, 1e-4)
    >>> log = rk.inertial.simulate_imu(rk.BSplineSE3(ctrl), 100.0, noise=noise, rng=0)
    >>> log.gyro.shape, log.dt
    ((300, 3), 0.01)
    """
    rng = np.random.default_rng(rng)
    noise = ImuNoise() if noise is None else noise
    h = 1.0 / float(rate_hz)
    n = int(np.floor((trajectory.t_max - trajectory.t_min) / h + 1e-9))
    times = trajectory.t_min + h * np.arange(n)
    w, f = imu_from_trajectory(trajectory, times, gravity=gravity, earth_rate=earth_rate)
    shape = tuple(np.atleast_1d(shape)) if shape != () else ()

    def walk(start, rw):
        b0 = np.broadcast_to(np.asarray(start, dtype=np.float64), shape + (3,))
        steps = rw * np.sqrt(h) * rng.standard_normal(shape + (n, 3))
        steps[..., 0, :] = 0.0
        return b0[..., None, :] + np.cumsum(steps, axis=-2)

    bg = walk(gyro_bias, noise.gyro_random_walk)
    ba = walk(accel_bias, noise.accel_random_walk)
    gyro = (
        w + bg + noise.gyro_noise_density / np.sqrt(h) * rng.standard_normal(shape + (n, 3))
    )
    accel = (
        f
        + ba
        + noise.accel_noise_density / np.sqrt(h) * rng.standard_normal(shape + (n, 3))
    )
    return ImuLog(times, h, gyro, accel, bg, ba)
