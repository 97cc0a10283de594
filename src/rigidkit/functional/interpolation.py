"""Geodesic interpolation and powers on SO(3) and SE(3), arrays in and out.

Quaternions are Hamilton, scalar first ``(w, x, y, z)``; poses are
``(w, x, y, z, tx, ty, tz)``. The geodesic from ``X0`` (at ``t = 0``) to ``X1``
(at ``t = 1``) is ``X0 (X0^-1 X1)^t`` with ``X^t = exp(t log X)`` and the log's
angle in [0, pi]: the shortest path, whatever the quaternion signs. Batch shapes
of the two ends and of ``t`` broadcast; the array namespace and dtype are kept.

>>> import numpy as np
>>> q0 = np.array([1.0, 0.0, 0.0, 0.0])
>>> q1 = np.array([0.0, 0.0, 0.0, 1.0])              # half turn about z
>>> np.round(quat_slerp(q0, q1, 0.5), 12)            # quarter turn about z
array([0.70710678, 0.        , 0.        , 0.70710678])
"""

from __future__ import annotations

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import device_of, is_numpy, is_torch, namespace_of
from .._validate import as_array, as_float, check_finite, finite_array
from ..kernels import geodesic as _k
from . import conversions as _conv

__all__ = [
    "quat_power",
    "quat_slerp",
    "pose_power",
    "pose_slerp",
    "quat_power_unchecked",
    "quat_slerp_unchecked",
    "pose_power_unchecked",
    "pose_slerp_unchecked",
    "segment_index",
    "segment_index_numpy",
    "uniform_segment",
    "take_rows",
    "meet",
]


def _unit_quat(q, what):
    return _conv.quat_normalize(as_float(as_array(q, (4,), what)), what=what)


def _pose(p, what):
    """A pose with its quaternion normalised (validated)."""
    p = as_float(finite_array(p, (7,), what))
    q = _conv.quat_normalize(p[..., :4], what=f"{what} quaternion")
    return namespace_of(p).concat([q, p[..., 4:]], axis=-1)


def _fraction(t, like):
    """``t`` checked finite, as an array (float64 for integers).

    A Python number is weak, as in NumPy: it takes the dtype, namespace and device
    of ``like`` (the ends), so float32 rotations stay float32 and the compiled loop
    of their dtype serves them (a float64 ``t`` made the result float64, through
    the general path: 40 us at N = 10 instead of 7).
    """
    if type(t) is np.ndarray and t.dtype.kind == "f":  # the common call, first
        # A float array is already what the kernels take: only the finiteness
        # check (the one of _validate, a Python sum for a few values), not
        # as_array's conversions.
        check_finite(t, (), _T_WHAT)
        return t
    if type(t) is float or type(t) is int:
        check_finite(t, (), _T_WHAT)
        if type(like) is np.ndarray:
            return np.array(t, like.dtype if like.dtype.kind == "f" else np.float64)
        return namespace_of(like).asarray(t, dtype=like.dtype, device=device_of(like))
    return as_float(finite_array(t, (), _T_WHAT))


_T_WHAT = "interpolation parameter t"


def quat_power(q, t):
    """``q^t = exp(t log q)``: the rotation about the same axis by ``t`` times the angle.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions (normalised here), scalar first.
    t : array_like, shape (...)
        Exponents; broadcasts with the batch shape of ``q``.

    Returns
    -------
    ndarray, shape (..., 4)
        Unit quaternions; ``q^0`` is the identity, ``q^-1`` the inverse.

    >>> import numpy as np
    >>> np.round(quat_power([0.0, 0.0, 0.0, 1.0], 0.5), 12)   # half of a half turn
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    u = _unit_quat(q, "quaternion")
    return _k.quat_power(u, _fraction(t, u))


def quat_slerp(q0, q1, t):
    """Spherical linear interpolation ``q0 (q0* q1)^t``, shortest path.

    Parameters
    ----------
    q0, q1 : array_like, shape (..., 4)
        End quaternions (normalised here), scalar first; ``q1`` and ``-q1`` give
        the same rotations.
    t : array_like, shape (...)
        Fractions: 0 gives ``q0`` exactly, 1 the rotation ``q1``; values outside
        [0, 1] extrapolate along the geodesic.

    Returns
    -------
    ndarray, shape (..., 4)
    """
    a = _unit_quat(q0, "quaternion q0")
    b = _unit_quat(q1, "quaternion q1")
    return _k.quat_slerp(a, b, _fraction(t, a))


def pose_power(pose, t):
    """``T^t = exp(t log T)`` of poses ``(w, x, y, z, tx, ty, tz)``: the screw scaled by t.

    Parameters
    ----------
    pose : array_like, shape (..., 7)
    t : array_like, shape (...)

    Returns
    -------
    ndarray, shape (..., 7)
    """
    p = _pose(pose, "pose")
    return _k.pose_power(p, _fraction(t, p))


def pose_slerp(pose0, pose1, t, *, decoupled=False):
    """Interpolate poses ``(w, x, y, z, tx, ty, tz)`` along the SE(3) geodesic.

    The default is the screw motion ``T0 (T0^-1 T1)^t`` (constant body twist);
    ``decoupled=True`` interpolates the rotation by slerp and the translation
    linearly, ``(1 - t) t0 + t t1`` (a straight line for the origin).

    Parameters
    ----------
    pose0, pose1 : array_like, shape (..., 7)
    t : array_like, shape (...)

    Returns
    -------
    ndarray, shape (..., 7)
    """
    a = _pose(pose0, "pose0")
    b = _pose(pose1, "pose1")
    return pose_slerp_unchecked(a, b, t, decoupled=decoupled)


# The ``*_unchecked`` variants take ends known to be unit quaternions / valid poses
# (the storage of Rotation and Transform) and check only ``t``.


def quat_power_unchecked(q, t):
    """:func:`quat_power` of a unit quaternion (not checked); ``t`` is checked."""
    return _k.quat_power(q, _fraction(t, q))


def quat_slerp_unchecked(q0, q1, t):
    """:func:`quat_slerp` of unit quaternions (not checked); ``t`` is checked."""
    return _k.quat_slerp(q0, q1, _fraction(t, q0))


def pose_power_unchecked(pose, t):
    """:func:`pose_power` of a valid pose (not checked); ``t`` is checked."""
    return _k.pose_power(pose, _fraction(t, pose))


def pose_slerp_unchecked(pose0, pose1, t, *, decoupled=False):
    """:func:`pose_slerp` of valid poses (not checked); ``t`` is checked."""
    kernel = _k.pose_slerp_decoupled if decoupled else _k.pose_slerp
    return kernel(pose0, pose1, _fraction(t, pose0))


def segment_index(knots, times):
    """Index ``i`` of the interval ``[knots[i], knots[i + 1]]`` holding each time.

    scipy's convention: intervals are closed on the right except that the first
    knot belongs to interval 0, so an interior knot ``knots[k]`` falls in interval
    ``k - 1`` (at its end). Times before the first knot get 0, after the last
    ``n - 2`` (the end intervals, continued). The lookup runs in the namespace of
    ``times`` (``searchsorted`` of NumPy, torch or JAX; per chunk on Dask), so it
    traces under ``jax.jit`` and ``torch.compile`` and stays lazy on Dask.

    Parameters
    ----------
    knots : ndarray, shape (n,)
        Strictly increasing (NumPy).
    times : array, shape (...)
        Any array namespace.

    Returns
    -------
    integer array of the namespace of ``times``, shape (...)

    >>> segment_index(np.array([0.0, 1.0, 2.0]), np.array([-1.0, 0.0, 1.0, 1.5, 3.0]))
    array([0, 0, 0, 1, 1])
    """
    top = len(knots) - 2
    if isinstance(times, (np.ndarray, np.generic, float, int)):
        idx = np.searchsorted(knots, times, side="left") - 1
        return np.clip(idx, 0, top)
    if is_torch(times):
        import torch

        k = torch.as_tensor(knots, dtype=times.dtype, device=times.device)
        idx = torch.searchsorted(k, times.contiguous(), side="left") - 1
        return torch.clamp(idx, 0, top)
    if dask_backend.is_dask(times):
        return times.map_blocks(segment_index_numpy, knots, dtype=np.intp)
    xp = namespace_of(times)
    k = xp.asarray(knots, dtype=times.dtype)
    return xp.clip(xp.searchsorted(k, times, side="left") - 1, 0, top)


def segment_index_numpy(times, knots):
    """:func:`segment_index` of a NumPy block (for Dask's ``map_blocks``)."""
    return segment_index(knots, np.asarray(times))


def uniform_segment(x, count):
    """Segment ``s = clip(floor(x), 0, count - 1)`` and ``u = x - s`` of uniform knots.

    ``x`` is the time in knot units; ``s`` is an integer array and ``u`` (in
    [0, 1) inside the range, beyond it outside) an array of ``x``'s dtype, both
    of the namespace of ``x`` (traces; lazy on Dask). The gradient of ``u`` with
    respect to ``x`` is 1.

    >>> s, u = uniform_segment(np.array([-0.5, 0.25, 1.0, 2.5]), 2)
    >>> s, u
    (array([0, 0, 1, 1]), array([-0.5 ,  0.25,  0.  ,  1.5 ]))
    """
    if is_torch(x):
        import torch

        s = torch.clamp(torch.floor(x), 0, count - 1)
        return s.to(torch.int64), x - s
    if isinstance(x, np.ndarray) or dask_backend.is_dask(x):
        s = np.clip(np.floor(x), 0, count - 1)
        return s.astype(np.intp), x - s
    xp = namespace_of(x)
    s = xp.clip(xp.floor(x), 0, count - 1)
    return s.astype(xp.int32 if count < 2**31 else xp.int64), x - s


def take_rows(x, idx):
    """``x[idx]`` along the first axis; ``idx`` an integer array of any namespace.

    NumPy ``x`` meets the namespace of ``idx`` first (a constant under ``jit``, a
    one-chunk Dask array for Dask indices, a tensor on the device of ``idx``). A
    0-d index goes through one of shape (1,): torch reads a 0-d index tensor as a
    Python int, a data-dependent one that ``torch.compile`` cannot make.
    """
    x = meet(x, idx)
    if getattr(idx, "ndim", None) == 0:
        return x[idx[None]][0]
    return x[idx]


def meet(x, like):
    """``x`` in the namespace (and device) of ``like`` if ``x`` is NumPy; else ``x``.

    The dtype of ``x`` is kept. Arrays of two special namespaces are returned as
    they are (the caller's kernels report the mix).
    """
    if not isinstance(x, np.ndarray) or isinstance(like, (np.ndarray, np.generic)):
        return x
    if dask_backend.is_dask(like):
        import dask.array as da

        return da.from_array(x, chunks=x.shape)
    if is_torch(like):
        import torch

        return torch.as_tensor(x, device=like.device)
    xp = namespace_of(like)
    if is_numpy(xp):
        return x
    return xp.asarray(x, device=device_of(like))
