"""The KITTI odometry protocol: drift over path segments of 100 to 800 m."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ShapeError
from .trajectory import Trajectory

__all__ = ["LENGTHS", "KittiResult", "kitti_errors"]

LENGTHS = (100, 200, 300, 400, 500, 600, 700, 800)


@dataclass(frozen=True, eq=False)
class KittiResult:
    """The errors of :func:`kitti_errors`.

    Attributes
    ----------
    translation_percent : float
        Mean translation error over all segments, in percent of the segment
        length (KITTI's "translational error").
    rotation_deg_per_100m : float
        Mean rotation error over all segments, degrees per 100 m.
    table : dict
        ``{length: (translation_percent, rotation_deg_per_100m, count)}`` for
        every length with at least one segment.
    first, last, length : ndarray
        Each segment's first and last frame and its nominal length (m).
    translation, rotation : ndarray
        Each segment's errors per metre: ``|t_E| / L`` and ``angle(R_E) / L``
        (radians per metre).
    """

    translation_percent: float
    rotation_deg_per_100m: float
    table: dict
    first: np.ndarray
    last: np.ndarray
    length: np.ndarray
    translation: np.ndarray
    rotation: np.ndarray

    def __repr__(self):
        return (
            f"<KITTI: {self.translation_percent:.4f} %, "
            f"{self.rotation_deg_per_100m:.4f} deg/100m over {len(self.first)} segments>"
        )


def kitti_errors(ref, est, lengths=LENGTHS, step=10):
    """KITTI odometry errors of ``est`` against the ground truth ``ref``.

    The rule of the KITTI odometry development kit (Geiger et al. 2012), in
    float64: with ``d_k`` the ground-truth path length up to frame ``k``, for
    every ``step``-th first frame ``i`` and each length ``L`` the segment ends at
    the first frame ``j`` with ``d_j > d_i + L`` (no segment if there is none).
    Its error motion is ``E = (est_i^-1 est_j)^-1 (ref_i^-1 ref_j)``; the
    translation error is ``|t_E| / L``, the rotation error ``angle(R_E) / L``.
    The results average over all segments (the devkit's printed numbers) and per
    length. The angle is ``2 atan2(|q_vec|, |q_w|)``, which keeps its precision
    for small angles where the devkit's ``acos((tr R - 1) / 2)`` rounds (the two
    agree to that rounding).

    Parameters
    ----------
    ref, est : Trajectory
        Corresponding poses (frame ``k`` of each), equal length.
    lengths : sequence of float
        Segment lengths in metres.
    step : int
        Spacing of the first frames (10 in the devkit: once a second at 10 Hz).

    Returns
    -------
    KittiResult

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> x = np.arange(0.0, 1000.0, 1.0)
    >>> gt = rk.Trajectory(None, rk.Transform(translation=np.c_[x, 0 * x, 0 * x]))
    >>> est = rk.Trajectory(None, rk.Transform(translation=np.c_[1.01 * x, 0 * x, 0 * x]))
    >>> r = rk.trajectory.kitti_errors(gt, est)
    >>> t, r, count = r.table[100]  # 1 % of the 101 m a "100 m" segment spans here
    >>> round(t, 12), r, count
    (1.01, 0.0, 90)
    """
    for name, traj in (("ref", ref), ("est", est)):
        if not isinstance(traj, Trajectory):
            raise TypeError(f"{name} must be a Trajectory, got {type(traj).__name__}")
    if len(ref) != len(est) or len(ref.shape) != 1 or len(est.shape) != 1:
        raise ShapeError(
            f"kitti_errors compares frame by frame: ref has shape {ref.shape}, est "
            f"{est.shape}; give two trajectories of equal length"
        )
    n = len(ref)
    p = np.asarray(ref.positions)
    dist = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=-1))])
    firsts = np.arange(0, n, int(step))
    seg_first, seg_last, seg_len = [], [], []
    for L in lengths:
        last = np.searchsorted(dist, dist[firsts] + float(L), side="right")
        ok = last < n
        seg_first.append(firsts[ok])
        seg_last.append(last[ok])
        seg_len.append(np.full(int(ok.sum()), float(L)))
    # The devkit's order: by first frame, then by length.
    first = np.concatenate(seg_first)
    last = np.concatenate(seg_last)
    length = np.concatenate(seg_len)
    order = np.lexsort(
        (np.repeat(np.arange(len(lengths)), [len(f) for f in seg_first]), first)
    )
    first, last, length = first[order], last[order], length[order]
    if len(first) == 0:
        raise ShapeError(
            f"no segment: the ground truth is {dist[-1]:.6g} m long, shorter than "
            f"the shortest length {float(min(lengths))!r} m"
        )
    R, P = ref.poses, est.poses
    E = (P[first].inv() @ P[last]).inv() @ (R[first].inv() @ R[last])
    pq = np.asarray(E.as_pq())
    t_err = np.linalg.norm(pq[:, :3], axis=-1) / length
    angle = 2.0 * np.arctan2(np.linalg.norm(pq[:, 4:], axis=-1), np.abs(pq[:, 3]))
    r_err = angle / length
    table = {}
    for L in lengths:
        sel = length == float(L)
        if sel.any():
            table[L] = (
                float(100.0 * t_err[sel].mean()),
                float(np.degrees(r_err[sel].mean()) * 100.0),
                int(sel.sum()),
            )
    return KittiResult(
        float(100.0 * t_err.mean()),
        float(np.degrees(r_err.mean()) * 100.0),
        table,
        first,
        last,
        length,
        t_err,
        r_err,
    )
