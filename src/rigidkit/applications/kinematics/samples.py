"""Velocities from sampled orientations and poses: finite differences on the group.

Between samples ``k`` and ``k + 1`` the increment is a logarithm: body
``log(R_k^T R_{k+1})``, world ``log(R_{k+1} R_k^T)`` (for poses ``log(T_k^-1
T_{k+1})`` and ``log(T_{k+1} T_k^-1)``); divided by the step it is the mean
velocity over the step, which equals the velocity at the step's middle to second
order (the bracket terms of the Magnus series are third order in the step). A
one-parameter motion's increment is the same vector whichever of its two ends
it is read at, so the differences combine directly:

* interior samples: the second-order central difference for non-uniform times,
  ``(h1 d+ + h2 d-) / (h1 + h2)`` with ``d- , d+`` the mean velocities of the
  steps before (``h1``) and after (``h2``);
* the two ends: second-order one-sided, ``((2 h1 + h2) d1 - h1 d2) / (h1 + h2)``
  from the first two steps (mirrored at the last sample); with only two samples,
  the mean velocity of the one step.

Constant-velocity motion (``R(t) = R_0 exp(omega t)``) is reproduced exactly (to
rounding) when every step turns by less than pi.
"""

from __future__ import annotations

import numpy as np

from ..._engine.namespace import device_of, is_numpy, namespace_of
from ..._validate import finite_array
from ...errors import DegenerateInputError, ShapeError
from ...functional import conversions as _conv
from ...functional import quaternion as _fq
from ...kernels import se3 as _se3
from ...objects.rotation import Rotation
from ...objects.transform import Transform
from ._common import body_flag, homogeneous_matrix, rotation_matrix

__all__ = ["angular_velocity_from_samples", "twist_from_samples"]


def _times(times, n, like, fn):
    t = finite_array(times, (), "times")
    if t.ndim == 0 or t.shape[-1] != n:
        raise ShapeError(
            f"{fn}: times must have shape (..., {n}), one per sample; got {t.shape}"
        )
    xp = namespace_of(like)
    if is_numpy(xp):
        t = np.asarray(t, dtype=np.result_type(t.dtype, like.dtype, np.float32))
    else:
        t = xp.asarray(t, dtype=like.dtype, device=device_of(like))
    h = t[..., 1:] - t[..., :-1]
    if not bool(namespace_of(h).all(h > 0)):
        raise DegenerateInputError(
            f"{fn}: times must increase strictly from sample to sample"
        )
    return h


def _combine(d, h, xp, second=None, before_last=None):
    """Velocities at the samples from the steps' means ``d`` (..., N-1, W), steps ``h``."""
    if d.shape[-2] == 1:
        return xp.concat([d, d], axis=-2)
    h = h[..., None]
    h1 = h[..., :-1, :]
    h2 = h[..., 1:, :]
    dm = d[..., :-1, :]
    dp = d[..., 1:, :]
    inner = (h1 * dp + h2 * dm) / (h1 + h2)
    a1, a2 = h[..., :1, :], h[..., 1:2, :]
    d2 = d[..., 1:2, :] if second is None else second
    first = ((2.0 * a1 + a2) * d[..., :1, :] - a1 * d2) / (a1 + a2)
    b1, b2 = h[..., -1:, :], h[..., -2:-1, :]
    dp = d[..., -2:-1, :] if before_last is None else before_last
    last = ((2.0 * b1 + b2) * d[..., -1:, :] - b1 * dp) / (b1 + b2)
    return xp.concat([first, inner, last], axis=-2)


def _check_count(n, fn):
    if n < 2:
        raise DegenerateInputError(
            f"{fn}: needs at least 2 samples along the time axis, got {n}"
        )


def angular_velocity_from_samples(rotations, times, *, frame=None):
    """Angular velocity at each sample of an orientation trajectory.

    Parameters
    ----------
    rotations : Rotation of shape (..., N), or array_like (..., N, 3, 3)
        Orientations ``W_R_B`` at the sample times (any batch of trajectories).
    times : array_like, shape (N,) or (..., N)
        Strictly increasing (non-uniform allowed).
    frame : {"world", "body"}

    Returns
    -------
    array, shape (..., N, 3)
        Radians per unit time; second-order accurate, exact for constant velocity.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> t = np.array([0.0, 0.1, 0.3, 0.4])
    >>> R = rk.Rotation.from_rotvec(np.outer(t, [0.0, 0.0, 2.0]))
    >>> np.round(angular_velocity_from_samples(R, t, frame="world"), 12) + 0.0
    array([[0., 0., 2.],
           [0., 0., 2.],
           [0., 0., 2.],
           [0., 0., 2.]])
    """
    fn = "angular_velocity_from_samples"
    body = body_flag(frame, fn)
    if isinstance(rotations, Rotation):
        q = rotations.as_quat()
    else:
        q = Rotation.from_matrix(rotation_matrix(rotations)).as_quat()
    if q.ndim < 2:
        raise ShapeError(
            f"{fn}: rotations need a time axis, shape (..., N); got a single one"
        )
    n = q.shape[-2]
    _check_count(n, fn)
    h = _times(times, n, q, fn)
    a, b = q[..., :-1, :], q[..., 1:, :]
    # body: q_k* q_{k+1}; world: q_{k+1} q_k*
    rel = (
        _fq.multiply(_conv.quat_conjugate(a), b)
        if body
        else _fq.multiply(b, _conv.quat_conjugate(a))
    )
    d = _conv.rotvec_from_quat(rel) / h[..., None]
    if not body or n < 3:
        return _combine(d, h, namespace_of(d))
    # A body increment is in the axes of its own step; the one-sided ends combine
    # two steps, so the second is turned into the axes of the end sample (then
    # omega_world = R omega_body holds at every sample, as in the world frame).
    second = _conv.quat_apply(rel[..., :1, :], d[..., 1:2, :])
    before_last = _conv.quat_apply(_conv.quat_conjugate(rel[..., -1:, :]), d[..., -2:-1, :])
    return _combine(d, h, namespace_of(d), second, before_last)


def twist_from_samples(transforms, times, *, frame=None):
    """Twist ``(v, omega)`` at each sample of a pose trajectory.

    Parameters
    ----------
    transforms : Transform of shape (..., N), or array_like (..., N, 4, 4)
        Poses ``W_T_B`` at the sample times.
    times : array_like, shape (N,) or (..., N)
        Strictly increasing.
    frame : {"world", "body"}
        World: ``hat(V) = T' T^-1``; body: ``T^-1 T'``.

    Returns
    -------
    array, shape (..., N, 6)

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> V = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.5])
    >>> t = np.linspace(0.0, 2.0, 5)
    >>> T = rk.Transform.exp(t[:, None] * V)
    >>> np.round(twist_from_samples(T, t, frame="body")[2], 12) + 0.0
    array([1. , 0. , 0. , 0. , 0. , 0.5])
    """
    fn = "twist_from_samples"
    body = body_flag(frame, fn)
    if isinstance(transforms, Transform):
        p = transforms._pose
    else:
        p = Transform.from_matrix(homogeneous_matrix(transforms))._pose
    if p.ndim < 2:
        raise ShapeError(
            f"{fn}: transforms need a time axis, shape (..., N); got a single one"
        )
    n = p.shape[-2]
    _check_count(n, fn)
    h = _times(times, n, p, fn)
    a, b = p[..., :-1, :], p[..., 1:, :]
    rel = (
        _se3.pose_compose(_se3.pose_inv(a), b)
        if body
        else _se3.pose_compose(b, _se3.pose_inv(a))
    )
    d = _se3.twist_from_pose(rel) / h[..., None]
    if not body or n < 3:
        return _combine(d, h, namespace_of(d))
    # As for rotations: the second step's twist in the axes of the end sample.
    second = _adjoint_apply(rel[..., :1, :], d[..., 1:2, :])
    before_last = _adjoint_apply(_se3.pose_inv(rel[..., -1:, :]), d[..., -2:-1, :])
    return _combine(d, h, namespace_of(d), second, before_last)


def _adjoint_apply(pose, twist):
    """``Ad_T V`` for poses (..., 7) and twists (..., 6)."""
    Ad = _se3.adjoint_from_pose(pose)
    return (Ad @ twist[..., None])[..., 0]
