"""Pairing the poses of two trajectories by their time stamps."""

from __future__ import annotations

import numpy as np

from ...errors import TimestampError
from ._loops import nearest_loop
from .trajectory import Trajectory, host_stamps

__all__ = ["associate", "nearest_pairs"]


def nearest_pairs(ref_stamps, est_stamps, max_diff):
    """Indices ``(i_ref, i_est)`` of the stamp pairs of the "nearest" rule.

    Every stamp of the trajectory with fewer stamps (``ref`` on a tie) is paired
    with the nearest stamp of the other, the earlier one of two equally near, and
    the pair is kept when they differ by at most ``max_diff`` (the rule of the
    TUM RGB-D benchmark's ``associate.py``, Sturm et al. 2012, as evo applies it).
    A stamp of the longer trajectory may be paired twice. Both index arrays
    are non-decreasing.

    >>> nearest_pairs(np.array([0.0, 1.0, 2.0]), np.array([0.004, 1.1, 2.0, 3.0]), 0.01)
    (array([0, 2]), array([0, 2]))
    """
    i_ref, i_est, _ = _pairs(ref_stamps, est_stamps, max_diff)
    return i_ref, i_est


def _pairs(ref_stamps, est_stamps, max_diff):
    """:func:`nearest_pairs` and whether both index arrays are known to be
    strictly increasing (no pose of the longer trajectory used twice)."""
    short_is_ref = len(ref_stamps) <= len(est_stamps)
    short, long = (ref_stamps, est_stamps) if short_is_ref else (est_stamps, ref_stamps)
    if len(short) == 0 or len(long) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty, True
    loop = nearest_loop()
    if loop is not None:
        i_short = np.empty(len(short), dtype=np.int64)
        i_long = np.empty(len(short), dtype=np.int64)
        k, repeats = loop(
            np.ascontiguousarray(long, dtype=np.float64),
            np.ascontiguousarray(short, dtype=np.float64),
            float(max_diff),
            i_short,
            i_long,
        )
        i_short, i_long, strict = i_short[:k], i_long[:k], repeats == 0
    else:
        i_short, i_long = _nearest_numpy(short, long, max_diff)
        strict = False  # not known: checked where it matters
    return (i_short, i_long, strict) if short_is_ref else (i_long, i_short, strict)


def _nearest_numpy(short, long, max_diff):
    """The "nearest" rule with NumPy (until the compiled loop is ready, or
    without numba): a binary search per stamp of ``short``."""
    hi = np.clip(np.searchsorted(long, short), 1, len(long) - 1) if len(long) > 1 else None
    if hi is None:
        near = np.zeros(len(short), dtype=np.intp)
    else:
        lo = hi - 1
        # The earlier of two equally near stamps, as a first-minimum search gives.
        near = np.where(np.abs(long[lo] - short) <= np.abs(long[hi] - short), lo, hi)
    keep = np.abs(long[near] - short) <= max_diff
    return np.flatnonzero(keep), near[keep]


def _take(traj, idx, strict=False):
    """The poses at the non-decreasing indices ``idx``; a view where they are a
    run of consecutive indices (a million poses are 56 MB to copy). ``strict``:
    ``idx`` is known to be strictly increasing, so spanning ``len(idx)`` indices
    makes it consecutive."""
    a, b = int(idx[0]), int(idx[-1]) + 1
    if b - a == len(idx) and (strict or len(idx) < 2 or bool((np.diff(idx) == 1).all())):
        idx = slice(a, b)
    return Trajectory._trusted(traj.stamps[idx], traj.poses[..., idx])


def _range(t) -> str:
    return f"[{float(t[0])!r}, {float(t[-1])!r}]" if len(t) else "[] (no poses)"


def associate(ref, est, max_diff=0.01, offset=0.0, method="nearest", max_gap=None):
    """The two trajectories reduced to the poses that match in time, in order.

    Parameters
    ----------
    ref, est : Trajectory
        With stamps (seconds).
    max_diff : float
        ``"nearest"``: the largest stamp difference of a pair, in seconds.
    offset : float
        Added to ``est``'s stamps before matching (a known clock offset); the
        returned ``est`` keeps its own stamps.
    method : {"nearest", "interpolate"}
        ``"nearest"``: every stamp of the shorter trajectory is paired with the
        nearest stamp of the longer one when they differ by at most
        ``max_diff`` (see :func:`nearest_pairs`; evo's and TUM's rule: a pose of
        the longer one may then be used twice, and its stamp repeats).
        ``"interpolate"``: ``ref`` is interpolated (SE(3) slerp,
        :meth:`Trajectory.at`) at every stamp of ``est`` inside ``ref``'s range
        whose two bracketing reference stamps are at most ``max_gap`` apart.
    max_gap : float, optional
        ``"interpolate"``: the widest reference interval to interpolate across
        (no limit when omitted).

    Returns
    -------
    (Trajectory, Trajectory)
        ``ref`` and ``est`` with one pose per pair, pair ``k`` at index ``k``.

    Raises
    ------
    TimestampError
        A trajectory without stamps, or no pair at all (naming both time ranges).

    Notes
    -----
    The pairs depend on the stamps' values, which are NumPy (never traced); the
    poses are only gathered by the pairs' indices (``"interpolate"``: slerped),
    in their own namespace. So poses on torch keep their graph, and under
    ``jax.jit`` association works on traced poses with the stamps as constants
    (a change of the stamps is a new trace).

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> ref = rk.Trajectory([0.0, 1.0, 2.0], rk.Transform.random(3, rng=0))
    >>> est = rk.Trajectory([0.995, 2.5], rk.Transform.random(2, rng=1))
    >>> r, e = rk.trajectory.associate(ref, est)
    >>> r.stamps, e.stamps
    (array([1.]), array([0.995]))
    """
    for name, traj in (("ref", ref), ("est", est)):
        if not isinstance(traj, Trajectory):
            raise TypeError(f"{name} must be a Trajectory, got {type(traj).__name__}")
        if traj.stamps is None:
            raise TimestampError(f"{name} has no stamps to associate by")
    t_ref, t_est = host_stamps(ref.stamps), host_stamps(est.stamps)
    # Without an offset, no copy of the stamps (8 MB for a million poses).
    t_est = t_est + float(offset) if float(offset) != 0.0 else t_est
    if method == "nearest":
        i_ref, i_est, strict = _pairs(t_ref, t_est, float(max_diff))
        if len(i_ref):
            return _take(ref, i_ref, strict), _take(est, i_est, strict)
    elif method == "interpolate":
        keep = (t_est >= t_ref[0]) & (t_est <= t_ref[-1]) if len(t_ref) else t_est < 0
        if max_gap is not None and len(t_ref) > 1:
            hi = np.clip(np.searchsorted(t_ref, t_est), 1, len(t_ref) - 1)
            exact = (
                t_ref[np.minimum(np.searchsorted(t_ref, t_est), len(t_ref) - 1)] == t_est
            )
            keep &= exact | (t_ref[hi] - t_ref[hi - 1] <= float(max_gap))
        i_est = np.flatnonzero(keep)
        if len(i_est) and len(t_ref) > 1:
            r = ref.at(t_est[i_est])
            return (
                Trajectory._trusted(r.stamps, r.poses),
                Trajectory._trusted(est.stamps[i_est], est.poses[..., i_est]),
            )
    else:
        raise ValueError(f"method must be 'nearest' or 'interpolate', got {method!r}")
    raise TimestampError(
        f"no pose of est matches one of ref: ref spans {_range(t_ref)} s, est "
        f"(offset {float(offset)!r} s added) {_range(t_est)} s, max_diff "
        f"{float(max_diff)!r} s; check the clocks (offset=) or max_diff"
    )
