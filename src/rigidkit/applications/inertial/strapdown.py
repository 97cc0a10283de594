"""Strapdown integration: gyroscope and accelerometer samples into navigation states.

Conventions (every function of :mod:`rigidkit.applications.inertial`):

* the navigation frame is ``frame="world"``: gravity ``g`` (m/s^2, a vector of any
  direction, ``(0, 0, -9.81)`` for z up) and the states' velocity ``v`` and
  position ``p`` are in it; the orientation is ``R = world_R_body``;
* the gyroscope measures the body's angular velocity ``w`` (rad/s) and the
  accelerometer its specific force ``f = R^T (a - g)`` (m/s^2), both in the body
  frame; ``a = p''`` (a resting accelerometer reads ``-R^T g``, up for z up);
* sample ``k`` belongs to step ``k``, from ``t_k`` to ``t_k + dt_k``; ``N`` samples
  give ``N + 1`` states.

Steps are elements of the Galilean group SGal(3) (Kelly 2023), computed for all
samples at once; their running product (:mod:`rigidkit.applications.kinematics`'s
scan: a compiled loop on NumPy, a parallel prefix product on torch and JAX) is the
preintegrated measurement from the start, and the states follow in closed form,
gravity and the frame's rotation included (:func:`rigidkit.kernels.kinematics.
inertial.nav_predict`).
"""

from __future__ import annotations

import numpy as np

from ..._engine.dask_backend import is_dask
from ..._engine.namespace import device_of, is_numpy, namespace_of
from ..._validate import finite_array
from ...errors import ShapeError
from ...kernels.kinematics import inertial as _k
from ...objects import registry
from ...objects.extended_pose import ExtendedPose
from ..kinematics import _scan
from ..kinematics._stencils import rates_at_step_points
from ..kinematics.integration import _steps

__all__ = ["integrate", "GRAVITY"]

#: Standard gravity along -z (a z-up navigation frame), m/s^2.
GRAVITY = (0.0, 0.0, -9.81)

_METHODS = ("exact", "midpoint", "rk4")
#: The identity of SGal(3), ``(q, dv, dp, dt)``.
_IDENTITY = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def samples(gyro, accel, fn):
    """The gyro and accelerometer logs as float arrays (..., N, 3), checked."""
    out = []
    for x, what in ((gyro, "gyro"), (accel, "accel")):
        shape = tuple(x.shape) if hasattr(x, "shape") else np.shape(x)
        if len(shape) < 2 or shape[-1] != 3:
            raise ShapeError(f"{fn}: {what} must have shape (..., N, 3), got {shape}")
        x = finite_array(x, (3,), what)
        if isinstance(x, np.ndarray) and x.dtype.kind != "f":
            x = x.astype(np.float64)
        out.append(x)
    if out[0].shape[-2] != out[1].shape[-2]:
        raise ShapeError(
            f"{fn}: gyro has {out[0].shape[-2]} samples, accel {out[1].shape[-2]}"
        )
    return out


def vector_like(v, like, what):
    """A 3-vector (or batch of them) in the namespace, dtype and device of ``like``."""
    v = finite_array(v, (3,), what)
    if is_dask(v):
        return v.astype(like.dtype)
    xp = namespace_of(like)
    if is_numpy(xp):
        return np.asarray(v, dtype=like.dtype)
    return xp.asarray(v, dtype=like.dtype, device=device_of(like))


def _identity_row(like):
    xp = namespace_of(like)
    if is_numpy(xp):
        return np.asarray(_IDENTITY, dtype=like.dtype)
    return xp.asarray(_IDENTITY, dtype=like.dtype, device=device_of(like))


def steps_of(method, w, f, h, fn, dt=None):
    """The steps (..., N, 11) of a log, for a smooth signal (integrate's methods).

    ``dt``: the caller's step durations where they are host numbers (the stencil
    weights are computed on the host, so ``jax.jit`` of a log with a Python ``dt``
    traces), else ``h`` serves."""
    if method not in _METHODS:
        raise ValueError(f"{fn}: method must be one of {_METHODS}, got {method!r}")
    if method == "exact":
        return _k.imu_step_exact(w, f, h)
    xp = namespace_of(w, f)
    x = xp.concat([w, f], axis=-1)
    host = dt if isinstance(dt, (int, float, np.ndarray)) else h
    mid, end = rates_at_step_points(x, host, order=2 if method == "midpoint" else 4)
    if method == "midpoint":
        return _k.imu_step_exact(mid[..., :3], mid[..., 3:], h)
    return _k.imu_step_rk4(x, mid, end, h)


def running_steps(inc):
    """``D_k``, (..., N + 1, 11): the products of the first ``k`` steps."""
    x0 = _identity_row(inc)
    _scan.prepare(_k.sgal_chain, x0, inc, inc.shape[-2])
    return _scan.running_product(_k.sgal_chain, 1, x0, inc)


def integrate(state0, gyro, accel, dt, *, gravity=GRAVITY, earth_rate=None, method="rk4"):
    """Navigation states ``(R, v, p)`` of a body from its gyroscope and accelerometer.

    In the navigation frame (``frame="world"``; gravity and the states' ``v``, ``p``
    in it, ``R = world_R_body``) the body moves by ``R' = R hat(w)``,
    ``v' = R f + g``, ``p' = v`` for body rates ``w`` (rad/s) and specific forces
    ``f = R^T (a - g)`` (m/s^2). ``earth_rate`` is the navigation frame's own
    angular velocity ``W`` with respect to an inertial frame, in its axes (the
    Earth's 7.292115e-5 rad/s about its axis, expressed in a local ENU or NED
    frame): the gyroscope then measures the body's inertial rate, and the equations
    gain the transport term of the rotation, ``R' = R hat(w) - hat(W) R``, the
    Coriolis acceleration ``-2 W x v`` and the centrifugal acceleration
    ``-W x (W x p)`` (about the frame's origin, taken on the axis of ``W``; a local
    frame's ``g`` is then gravitation alone, the centrifugal term of its origin being
    in neither).

    Parameters
    ----------
    state0 : ExtendedPose
        The state at the first sample; its batch shape broadcasts with the logs'.
    gyro, accel : array_like, shape (..., N, 3)
        Body angular rates (rad/s) and specific forces (m/s^2), sample ``k`` at the
        start of step ``k``.
    dt : float or array_like, shape (N,) or (..., N)
        Step durations (s): uniform, or one per sample.
    gravity : array_like, shape (3,) or (..., 3)
        ``g`` in the navigation frame (m/s^2), any direction.
    earth_rate : array_like, shape (3,) or (..., 3), optional
        ``W`` (rad/s), the navigation frame's rotation; None: a non-rotating frame.
    method : {"exact", "midpoint", "rk4"}
        ``"exact"`` holds each sample over its step (the closed form on SGal(3),
        exact for piecewise-constant input, first order for a smooth one);
        ``"midpoint"`` (second order) and ``"rk4"`` (Runge-Kutta-Munthe-Kaas,
        fourth order) treat the samples as a smooth signal, interpolated between
        them (at least 2 and 4 samples). Gravity and ``W`` are integrated exactly
        by every method.

    Returns
    -------
    ExtendedPose, shape (..., N + 1)
        Element 0 is ``state0``.

    Examples
    --------
    A body at rest for one second (z up): the accelerometer reads ``+9.81`` up.

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> gyro, accel = np.zeros((100, 3)), np.tile([0.0, 0.0, 9.81], (100, 1))
    >>> X = rk.inertial.integrate(rk.ExtendedPose(), gyro, accel, 0.01)
    >>> X.shape, bool(np.abs(X[-1].position).max() < 1e-12)
    ((101,), True)
    >>> spin = np.tile([0.0, 0.0, 1.0], (100, 1))            # turning about z, 1 rad/s
    >>> X = rk.inertial.integrate(rk.ExtendedPose(), spin, accel, 0.01)
    >>> np.round(X[-1].rotation.as_rotvec(), 12) + 0.0
    array([0., 0., 1.])
    """
    fn = "integrate"
    if not isinstance(state0, ExtendedPose):
        raise TypeError(f"{fn}: state0 must be a rigidkit.ExtendedPose")
    w, f = samples(gyro, accel, fn)
    h = _steps(dt, w, fn)
    D = running_steps(steps_of(method, w, f, h, fn, dt))
    x0 = registry.stored(state0)
    return ExtendedPose._wrap(predict_states(_cast(x0, D), D, gravity, earth_rate))


def predict_states(x0, D, gravity, earth_rate):
    """States (..., 10) at the ends of the products ``D`` (..., 11) from ``x0``."""
    g = vector_like(gravity, D, "gravity")
    if earth_rate is None:
        return _k.nav_predict_flat(x0[..., None, :], D, g[..., None, :])
    omega = vector_like(earth_rate, D, "earth_rate")
    return _k.nav_predict(x0[..., None, :], D, g[..., None, :], omega[..., None, :])


def _cast(x, like):
    """``x`` in the namespace and dtype of ``like`` (a Dask array stays lazy)."""
    if is_dask(x):
        return x.astype(like.dtype)
    xp = namespace_of(like)
    if is_numpy(xp):
        return np.asarray(x, dtype=like.dtype)
    return xp.asarray(x, dtype=like.dtype, device=device_of(like))
