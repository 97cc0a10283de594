"""Velocities from sampled orientations and poses: finite differences on the group.

One algorithm for every Lie group (:func:`velocity_from_samples`, used by the
functions of SO(3) and SE(3) here and of SO(2) and SE(2) in :mod:`.planar`).
Between samples ``k`` and ``k + 1`` the increment is a logarithm: body
``log(X_k^-1 X_{k+1})``, world ``log(X_{k+1} X_k^-1)`` (``R^T`` for ``R^-1`` of a
rotation); divided by the step it is the mean
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

from ..._engine.namespace import device_of, is_numpy, is_torch, namespace_of
from ..._validate import finite_array, raise_unless
from ...errors import DegenerateInputError, ShapeError
from ...objects.registry import stored
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
    if isinstance(t, np.ndarray) and is_numpy(xp):
        t = np.asarray(t, dtype=np.result_type(t.dtype, like.dtype, np.float32))
    elif is_numpy(xp):  # NumPy samples, times of another namespace: kept there
        t = _floating(t, like)
    else:
        t = xp.asarray(t, dtype=like.dtype, device=device_of(like))
    h = t[..., 1:] - t[..., :-1]
    # Read only where values can be read (skipped under tracing and with
    # set_validation(False); at compute time on Dask).
    raise_unless(
        h > 0,
        DegenerateInputError,
        f"{fn}: times must increase strictly from sample to sample; the step "
        "{where} is not positive",
    )
    return h


def _floating(t, like):
    """Times ``t`` (JAX, torch, Dask) as floats of at least the precision of ``like``."""
    if is_torch(t):
        import torch

        f64 = t.dtype == torch.float64 or like.dtype == np.float64
        return t.to(torch.float64 if f64 else torch.float32)
    kind = np.result_type(np.dtype(t.dtype), like.dtype, np.float32)
    return t if t.dtype == kind else t.astype(kind)


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


def velocity_from_samples(X, times, body, fn, what):
    """The velocity (a tangent per unit time) at each sample of ``X``, any Lie group.

    Parameters
    ----------
    X : LieGroup of shape (..., N)
        The samples (any registered Lie group, :mod:`rigidkit.objects.registry`).
    times : array_like, shape (N,) or (..., N)
        Strictly increasing.
    body : int
        1 for body velocities (``X^-1 X'``), 0 for world ones (``X' X^-1``).
    fn, what : str
        The public function's name and what ``X`` holds, for the messages.

    Returns
    -------
    array, shape (..., N, dof)
    """
    if X.single:
        raise ShapeError(f"{fn}: {what} need a time axis, shape (..., N); got a single one")
    n = X.shape[-1]
    _check_count(n, fn)
    h = _times(times, n, stored(X), fn)
    a, b = X[..., :-1], X[..., 1:]
    # compose, not @: TorchDynamo cannot trace @ on objects
    rel = a.inv().compose(b) if body else b.compose(a.inv())
    d = rel.log() / h[..., None]
    if not body or n < 3:
        return _combine(d, h, namespace_of(d))
    # A body increment is in the axes of its own step; the one-sided ends combine
    # two steps, so the second is turned into the axes of the end sample (then
    # V_world = Ad_X V_body holds at every sample, as in the world frame).
    second = _adjoint_apply(rel[..., :1], d[..., 1:2, :])
    before_last = _adjoint_apply(rel[..., -1:].inv(), d[..., -2:-1, :])
    return _combine(d, h, namespace_of(d), second, before_last)


def from_samples(X, times, frame, fn, group, read, what):
    """:func:`velocity_from_samples` of objects of class ``group`` or of matrices.

    ``read`` validates matrices (``X`` not a ``group``) for ``group.from_matrix``.
    """
    body = body_flag(frame, fn)
    if not isinstance(X, group):
        X = group.from_matrix(read(X))
    return velocity_from_samples(X, times, body, fn, what)


def _adjoint_apply(X, tau):
    """``Ad_X tau`` for group elements (...) and tangents (..., dof)."""
    return (X.adjoint() @ tau[..., None])[..., 0]


def angular_velocity_from_samples(rotations, times, *, frame):
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
    return from_samples(rotations, times, frame, fn, Rotation, rotation_matrix, "rotations")


def twist_from_samples(transforms, times, *, frame):
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
    return from_samples(
        transforms, times, frame, fn, Transform, homogeneous_matrix, "transforms"
    )
