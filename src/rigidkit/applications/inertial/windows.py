"""One IMU log split at keyframe stamps into windows of equal length, for
:func:`~rigidkit.applications.inertial.preintegrate` to take in one call."""

from __future__ import annotations

import numpy as np

from ..._engine.dask_backend import is_dask
from ..._engine.namespace import device_of, is_torch, namespace_of
from ..._validate import as_float, finite_array, to_numpy
from ...errors import DegenerateInputError

__all__ = ["split_windows"]


def split_windows(times, gyro, accel, keyframe_times):
    """Windows between consecutive keyframes, padded with zero-duration steps.

    Sample ``k`` is held from ``times[k]`` to ``times[k + 1]`` (the last one to the
    last keyframe); a keyframe between two stamps splits that step between the two
    windows. Shorter windows are padded with copies of their last sample of
    duration 0, which change no preintegrated quantity.

    Parameters
    ----------
    times : array_like, shape (N,)
        Increasing sample stamps (s). They and ``keyframe_times`` decide the
        windows' count and length, so they are read as host numbers (not traced).
    gyro, accel : array_like, shape (N, 3)
        Body rates (rad/s) and specific forces (m/s^2) in the body frame.
    keyframe_times : array_like, shape (K,)
        Increasing stamps within ``[times[0], ...]``.

    Returns
    -------
    gyro, accel : array, shape (K - 1, M, 3)
        Rows of ``gyro`` and ``accel``, in their namespace (JAX, torch with its
        gradients, Dask lazily).
    dt : array, shape (K - 1, M)
        In the namespace, float dtype and device of ``gyro``.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(10) * 0.1
    >>> g, a, dt = split_windows(t, np.zeros((10, 3)), np.zeros((10, 3)), [0.0, 0.25, 0.9])
    >>> g.shape, np.round(dt.sum(axis=-1), 12)
    ((2, 7, 3), array([0.25, 0.65]))
    """
    t = _host(finite_array(times, (), "times"), "times")
    kf = _host(finite_array(keyframe_times, (), "keyframe_times"), "keyframe_times")
    gyro = as_float(finite_array(gyro, (3,), "gyro"))
    accel = as_float(finite_array(accel, (3,), "accel"))
    if t.ndim != 1 or len(t) != gyro.shape[0] or len(t) != accel.shape[0]:
        raise DegenerateInputError("times, gyro and accel must have one row per sample")
    if gyro.ndim != 2 or accel.ndim != 2:
        raise DegenerateInputError("gyro and accel must have shape (N, 3)")
    if len(kf) < 2 or np.any(np.diff(kf) <= 0) or np.any(np.diff(t) <= 0):
        raise DegenerateInputError(
            "times and keyframe_times must increase (2 keyframes or more)"
        )
    if kf[0] < t[0]:
        raise DegenerateInputError(f"keyframe {kf[0]} is before the first sample {t[0]}")
    # The windows' indices and durations come from the stamps alone (host numbers);
    # the samples are only gathered, so gyro and accel keep their namespace (traced,
    # differentiated, lazy).
    ends = np.append(t[1:], max(kf[-1], t[-1]))
    first = np.searchsorted(t, kf[:-1], side="right") - 1
    last = np.searchsorted(t, kf[1:], side="left") - 1
    m = int((last - first).max()) + 1
    idx = np.minimum(first[:, None] + np.arange(m)[None, :], last[:, None])  # (K-1, M)
    lo = np.maximum(t[idx], kf[:-1, None])
    hi = np.minimum(ends[idx], kf[1:, None])
    dt = np.where(first[:, None] + np.arange(m)[None, :] <= last[:, None], hi - lo, 0.0)
    dt = np.maximum(dt, 0.0)
    return _gather(gyro, idx), _gather(accel, idx), _like(dt, gyro)


def _host(x, what):
    """Stamps as float64 NumPy: they fix the windows' count and length (the output's
    shape), so they are read on the host; traced stamps cannot be."""
    if type(x) is np.ndarray:
        return x.astype(np.float64, copy=False)
    try:
        return np.asarray(to_numpy(x), dtype=np.float64)
    except Exception as err:  # a JAX tracer, say: the windows' shape needs the values
        raise DegenerateInputError(
            f"split_windows: {what} must be concrete (host) numbers: they decide the "
            "windows' shape, which a traced array cannot"
        ) from err


def _gather(x, idx):
    """``x[idx]`` (rows of ``x`` (N, 3) at ``idx`` (K, M)) in ``x``'s namespace."""
    flat = idx.reshape(-1)
    if is_torch(x):
        flat = namespace_of(x).asarray(flat, device=device_of(x))
    return x[flat].reshape(idx.shape + (3,))


def _like(a, like):
    """The NumPy array ``a`` in the namespace, float dtype and device of ``like``."""
    if type(like) is np.ndarray:
        return a.astype(like.dtype, copy=False)
    if is_dask(like):
        import dask.array as da

        return da.from_array(a.astype(like.dtype, copy=False))
    xp = namespace_of(like)
    return xp.asarray(a, dtype=like.dtype, device=device_of(like))
