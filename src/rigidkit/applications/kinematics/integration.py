"""Integration of sampled angular velocity and twists into trajectories.

Sample ``k`` of the rate is its value at ``t_k = dt_0 + ... + dt_{k-1}``, the start
of step ``k``; ``N`` samples give ``N`` steps and ``N + 1`` orientations (the
first is the initial one). Methods (see :mod:`rigidkit.kernels.kinematics.integration`):

``"exact"``
    Zero-order hold: the rate is held over each step, ``R_{k+1} = R_k exp(w_k dt_k)``
    (body). Exact for piecewise-constant rates (what a gyroscope reporting mean
    rates per sample measures), first order for smooth ones.
``"midpoint"``
    The rate at the middle of the step, linearly interpolated between samples (or
    extrapolated from the last two): second order for a smooth rate.
``"rk4"``
    Runge-Kutta-Munthe-Kaas of order 4, the rates at the middle and end of the
    step from the cubic through the four nearest samples: fourth order.

Every step is an exponential and the running product is renormalised each step,
so the orientations are unit quaternions to rounding over any length, and a
constant rate gives ``exp(w t)`` with every method.

The increments of all steps are computed at once (they do not depend on the
orientation: batched kernels, fused numba loops on NumPy); only their running
product is sequential: a compiled numba loop on NumPy (3.6 M steps, an hour at
1 kHz, take well under a second), a parallel prefix product on torch, JAX,
NumPy without numba, and NumPy calls made before the compiled loop is ready
(it is compiled in the background, never waited for; see :mod:`._scan`).
The plane has its own versions in :mod:`.planar`.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from ..._engine import dask_backend
from ..._engine.namespace import device_of, is_numpy, namespace_of
from ..._validate import finite_array
from ...errors import ShapeError
from ...functional.interpolation import meet
from ...objects import registry
from ...objects.rotation import Rotation
from ...objects.transform import Transform
from . import _scan
from ._common import body_flag, homogeneous_matrix, rotation_matrix
from ._stencils import rates_at_step_points

__all__ = ["integrate_angular_velocity", "integrate_twist"]

_METHODS = ("exact", "midpoint", "rk4")


def _method(method, fn):
    if method not in _METHODS:
        raise ValueError(f"{fn}: method must be one of {_METHODS}, got {method!r}")
    return method


def _steps(dt, rate, fn):
    """Step durations, shape () or (..., N), of the namespace of the rates or ``dt``."""
    return _rates_and_steps(dt, rate, fn)[1]


def _rates_and_steps(dt, rate, fn):
    """Rates and step durations of one namespace, the steps of shape () or (..., N).

    The steps stay in the caller's namespace: NumPy rates meet JAX, torch or Dask
    steps (a traced ``dt`` under ``jax.jit`` stays traced, a Python float is a
    constant of the rates' namespace).
    """
    n = rate.shape[-2]
    h = finite_array(dt, (), "dt")
    if h.ndim and h.shape[-1] != n:
        raise ShapeError(
            f"{fn}: dt has {h.shape[-1]} step times on its last axis, the rates {n} "
            f"samples (one step per sample; pass a scalar for uniform steps)"
        )
    rate = meet(rate, h)
    xp = namespace_of(rate)
    if is_numpy(xp) and not dask_backend.is_dask(h):
        h = np.asarray(h, dtype=rate.dtype)
    elif is_numpy(xp):
        h = h.astype(rate.dtype)
    else:
        h = xp.asarray(h, dtype=rate.dtype, device=device_of(rate))
    return rate, h


def _increments(one, rk4, method, rate, h):
    """The per-step group elements, shape (..., N, W): ``one(rate, h)`` per step
    (zero-order hold, or midpoint given the midpoint rates), or ``rk4(start, mid,
    end, h)`` from the rates at three points of each step."""
    if method == "exact":
        return one(rate, h)
    mid, end = rates_at_step_points(rate, h, order=2 if method == "midpoint" else 4)
    if method == "midpoint":
        return one(mid, h)
    return rk4(rate, mid, end, h)


def integrate(X0, rate, dt, method, fn, body=0):
    """The trajectory, shape (..., N + 1), of the Lie group of ``X0`` from ``X0``.

    Shared by every group: the group's declaration (``GroupSpec.step`` and
    ``rate``, :mod:`rigidkit.objects.registry`) gives the step kernels and the
    rate's name. Validates the rates (``(..., N, dof)``), the steps and the
    method, makes the increments (:func:`_increments`) and chains them
    (:func:`._scan.running_product`). For a commutative group (no chain: SO(2))
    the increments are tangents, summed (:func:`._scan.running_sum`), and the
    trajectory is ``X0 exp(sum)``.
    """
    spec = registry.spec(type(X0))
    one, rk4, chain = spec.step
    if rk4.params:
        rk4 = partial(rk4, body)
    _method(method, fn)
    r = _samples(rate, spec.dof, spec.rate, fn)
    r, h = _rates_and_steps(dt, r, fn)
    x0 = _like(registry.stored(X0), r)
    if chain is None:
        tau = _scan.running_sum(_increments(one, rk4, method, r, h))
        return spec.wrap(x0[..., None, :]).compose(spec.cls.exp(tau))
    # Asked for before the increments are made: a cached scan loads meanwhile.
    _scan.prepare(chain, x0, r, r.shape[-2])
    x = _scan.running_product(chain, body, x0, _increments(one, rk4, method, r, h))
    return spec.wrap(x)


def integrate_from(X0, rate, dt, method, frame, fn, group, read):
    """:func:`integrate` from an object of class ``group`` or from its matrices.

    ``read`` validates matrices (``X0`` not a ``group``) for ``group.from_matrix``;
    the trajectory comes back as ``X0`` came: objects, or their matrices.
    """
    body = body_flag(frame, fn)
    as_object = isinstance(X0, group)
    start = X0 if as_object else group.from_matrix(read(X0))
    traj = integrate(start, rate, dt, method, fn, body)
    return traj if as_object else traj.as_matrix()


def _samples(rate, width, what, fn):
    shape = tuple(rate.shape) if hasattr(rate, "shape") else np.shape(rate)
    if len(shape) < 2 or shape[-1] != width:
        hint = "; a 1-D log w of N samples is w[:, None]" if width == 1 else ""
        raise ShapeError(
            f"{fn}: {what} must have shape (..., N, {width}), got {shape}{hint}"
        )
    r = finite_array(rate, (width,), what)
    if isinstance(r, np.ndarray) and r.dtype.kind != "f":
        r = r.astype(np.float64)
    return r


def integrate_angular_velocity(R0, omega, dt, *, frame, method="exact"):
    """Orientation trajectory of a body turning at the sampled rates ``omega``.

    Body frame (gyroscope rates): ``R' = R hat(omega)``; world frame:
    ``R' = hat(omega) R``. Sample ``k`` is the rate at the start of step ``k``.

    Parameters
    ----------
    R0 : Rotation or array_like, shape (..., 3, 3)
        Initial orientation ``W_R_B``.
    omega : array_like, shape (..., N, 3)
        Angular velocity samples, radians per unit time; the batch shape
        broadcasts with that of ``R0`` (many trajectories at once).
    dt : float or array_like, shape (N,) or (..., N)
        Step durations (uniform, or one per sample).
    frame : {"world", "body"}
        Required.
    method : {"exact", "midpoint", "rk4"}
        Zero-order hold, second or fourth order (module docstring). "midpoint"
        needs N >= 2 samples, "rk4" N >= 4.

    Returns
    -------
    Rotation of shape (..., N + 1), or matrices (..., N + 1, 3, 3) when ``R0`` is
    an array. Element 0 is ``R0``.

    Examples
    --------
    A gyroscope log at 200 Hz, one second about z at pi/2 rad/s:

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> omega = np.tile([0.0, 0.0, np.pi / 2], (200, 1))
    >>> R0 = rk.Rotation.identity()
    >>> traj = integrate_angular_velocity(R0, omega, 1 / 200, frame="body")
    >>> traj.shape
    (201,)
    >>> np.round(traj[-1].as_rotvec(), 12)
    array([0.        , 0.        , 1.57079633])
    """
    return integrate_from(
        R0,
        omega,
        dt,
        method,
        frame,
        "integrate_angular_velocity",
        Rotation,
        rotation_matrix,
    )


def integrate_twist(T0, twist, dt, *, frame, method="exact"):
    """Pose trajectory of a body moving with the sampled twists ``(v, omega)``.

    Body frame (dead reckoning from velocities measured on the vehicle, ``v`` the
    velocity of its origin in its own axes): ``T' = T hat(V)``; world frame:
    ``T' = hat(V) T``. Methods and sampling as in
    :func:`integrate_angular_velocity`; the steps are ``exp`` of se(3).

    Parameters
    ----------
    T0 : Transform or array_like, shape (..., 4, 4)
        Initial pose ``W_T_B``.
    twist : array_like, shape (..., N, 6)
        Twist samples ``(v, omega)``.
    dt : float or array_like, shape (N,) or (..., N)
    frame : {"world", "body"}
    method : {"exact", "midpoint", "rk4"}

    Returns
    -------
    Transform of shape (..., N + 1), or matrices (..., N + 1, 4, 4) when ``T0`` is
    an array.

    Examples
    --------
    Driving a quarter circle of radius 1: forward at 1, turning left at 1 rad/s.

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> V = np.tile([1.0, 0, 0, 0, 0, 1.0], (100, 1))
    >>> traj = integrate_twist(rk.Transform.identity(), V, np.pi / 200, frame="body")
    >>> np.round(traj[-1].translation, 12)
    array([1., 1., 0.])
    """
    return integrate_from(
        T0, twist, dt, method, frame, "integrate_twist", Transform, homogeneous_matrix
    )


def _like(x0, rate):
    """``x0`` in the namespace, dtype and device of the rates."""
    xp = namespace_of(rate)
    if dask_backend.is_dask(x0) or dask_backend.is_dask(rate):
        dtype = np.result_type(x0.dtype, rate.dtype)
        return x0.astype(dtype) if dask_backend.is_dask(x0) else np.asarray(x0, dtype)
    if is_numpy(xp):
        return np.asarray(x0, dtype=np.result_type(x0.dtype, rate.dtype))
    return xp.asarray(x0, dtype=rate.dtype, device=device_of(rate))
