"""One IMU log split at keyframe stamps into windows of equal length, for
:func:`~rigidkit.applications.inertial.preintegrate` to take in one call."""

from __future__ import annotations

import numpy as np

from ..._validate import finite_array
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
        Increasing sample stamps (s).
    gyro, accel : array_like, shape (N, 3)
        Body rates (rad/s) and specific forces (m/s^2) in the body frame.
    keyframe_times : array_like, shape (K,)
        Increasing stamps within ``[times[0], ...]``.

    Returns
    -------
    gyro, accel : ndarray, shape (K - 1, M, 3)
    dt : ndarray, shape (K - 1, M)

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(10) * 0.1
    >>> g, a, dt = split_windows(t, np.zeros((10, 3)), np.zeros((10, 3)), [0.0, 0.25, 0.9])
    >>> g.shape, np.round(dt.sum(axis=-1), 12)
    ((2, 7, 3), array([0.25, 0.65]))
    """
    t = np.asarray(finite_array(times, (), "times"), dtype=np.float64)
    kf = np.asarray(finite_array(keyframe_times, (), "keyframe_times"), dtype=np.float64)
    gyro = np.asarray(finite_array(gyro, (3,), "gyro"))
    accel = np.asarray(finite_array(accel, (3,), "accel"))
    if t.ndim != 1 or len(t) != len(gyro) or len(t) != len(accel):
        raise DegenerateInputError("times, gyro and accel must have one row per sample")
    if len(kf) < 2 or np.any(np.diff(kf) <= 0) or np.any(np.diff(t) <= 0):
        raise DegenerateInputError(
            "times and keyframe_times must increase (2 keyframes or more)"
        )
    if kf[0] < t[0]:
        raise DegenerateInputError(f"keyframe {kf[0]} is before the first sample {t[0]}")
    ends = np.append(t[1:], max(kf[-1], t[-1]))
    first = np.searchsorted(t, kf[:-1], side="right") - 1
    last = np.searchsorted(t, kf[1:], side="left") - 1
    m = int((last - first).max()) + 1
    idx = np.minimum(first[:, None] + np.arange(m)[None, :], last[:, None])  # (K-1, M)
    lo = np.maximum(t[idx], kf[:-1, None])
    hi = np.minimum(ends[idx], kf[1:, None])
    dt = np.where(first[:, None] + np.arange(m)[None, :] <= last[:, None], hi - lo, 0.0)
    return gyro[idx], accel[idx], np.maximum(dt, 0.0)
