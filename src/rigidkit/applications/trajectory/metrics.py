"""Absolute and relative pose errors (APE, RPE) with evo's definitions.

The error of a pose is a rigid motion ``E``; a *relation* reduces it to a number
(Sturm et al. 2012, Sec. VI; evo's ``PoseRelation``):

- ``"translation"``: ``|t_E|``;
- ``"rotation_angle"``: the angle of ``R_E`` (radians, or degrees);
- ``"rotation_part"``: ``|R_E - I|_F = 2 sqrt(2) sin(theta / 2)``;
- ``"full"``: ``|E - I_4|_F = sqrt(8 sin^2(theta / 2) + |t_E|^2)``;
- ``"point_distance"``: the distance of the two positions (APE) or the
  difference of the distances that a pose pair spans in each (RPE).

The closed forms use ``|R - I|_F^2 = 2 (3 - tr R) = 8 sin^2(theta / 2)`` and the
unit quaternion's ``|q_vec| = sin(theta / 2)``: no matrix is formed, and the
rotation error keeps its relative precision for small angles.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._validate import to_numpy
from ...errors import ShapeError
from ...objects.registry import stored
from ...objects.transform import Transform
from .trajectory import Trajectory, check_pair

__all__ = ["RELATIONS", "UNITS", "MetricResult", "ape", "pair_indices", "rpe", "statistics"]

RELATIONS = ("translation", "rotation_angle", "rotation_part", "full", "point_distance")
UNITS = ("frames", "meters", "degrees", "radians")
_SQRT8 = np.sqrt(8.0)


def _sum_of_squares(x) -> float:
    """``x . x`` of a 1-D array: a BLAS dot up to 10,000 numbers (~1 us), einsum's
    single-threaded loop above, where OpenBLAS starts threads that make a dot of
    a million take 16 ms instead of 0.3 ms on a loaded machine."""
    return float(x @ x) if x.shape[0] <= 10_000 else float(np.einsum("i,i->", x, x))


def statistics(errors) -> dict:
    """``rmse, mean, median, std, min, max, sse`` of ``errors`` (last axis), floats.

    ``std`` is the population standard deviation (``ddof=0``), ``sse`` the sum of
    squares, as evo reports them.

    >>> bool(statistics(np.array([3.0, 4.0]))["rmse"] == np.sqrt(12.5))
    True
    """
    e = np.asarray(errors, dtype=np.float64)
    n = e.shape[-1]
    if n == 0:
        raise ShapeError("no errors to summarise (no pose or pair was compared)")
    if e.ndim == 1:
        # One pass per number: np.median, np.std and friends cost ~20 us each in
        # overhead at a few thousand errors, more than the metric. The sums of
        # squares: see _sum_of_squares.
        sse = _sum_of_squares(e)
        mean = float(e.sum()) / n
        half = n // 2
        # One kth: partitioning at two costs ~7x more; the lower middle is then
        # the largest of the lower part.
        part = np.partition(e, half)
        median = float(part[half]) if n % 2 else 0.5 * float(part[:half].max() + part[half])
        if sse == sse:  # no NaN: the partition orders every error around part[half]
            lo, hi = float(part[: half + 1].min()), float(part[half:].max())
        else:
            lo, hi = float(e.min()), float(e.max())
        # The deviations go in the partition's buffer (a million errors: 8 MB
        # less to allocate); two passes, as np.std, for the precision.
        d = np.subtract(e, mean, out=part)
        return {
            "rmse": float(np.sqrt(sse / n)),
            "mean": mean,
            "median": median,
            "std": float(np.sqrt(_sum_of_squares(d) / n)),
            "min": lo,
            "max": hi,
            "sse": sse,
        }
    sse = np.einsum("...i,...i->...", e, e)
    return {
        "rmse": np.sqrt(sse / n),
        "mean": e.mean(axis=-1),
        "median": np.median(e, axis=-1),
        "std": e.std(axis=-1),
        "min": e.min(axis=-1),
        "max": e.max(axis=-1),
        "sse": sse,
    }


@dataclass(frozen=True, eq=False)
class MetricResult:
    """The errors of :func:`ape` or :func:`rpe` and their statistics.

    Attributes
    ----------
    errors : ndarray, shape (..., M)
        One error per pose (APE) or pair (RPE).
    stamps : ndarray, shape (M,), or None
        The reference stamp of each pose (APE), of each pair's first pose (RPE).
    pairs : ndarray of int, shape (M, 2), or None
        RPE: the index pairs ``(i, j)`` compared; ``None`` for APE.
    stats : dict
        ``rmse, mean, median, std, min, max, sse`` (see :func:`statistics`).
    relation, unit : str
        What the numbers are: the relation, and ``"m"``, ``"rad"``, ``"deg"`` or
        ``"unit-less"``.
    """

    errors: np.ndarray
    stamps: np.ndarray | None
    pairs: np.ndarray | None
    stats: dict
    relation: str
    unit: str

    def __repr__(self):
        s = self.stats
        body = ", ".join(f"{k}={s[k]:.6g}" for k in ("rmse", "mean", "max"))
        kind = "RPE" if self.pairs is not None else "APE"
        return f"<{kind} {self.relation} [{self.unit}]: n={self.errors.shape[-1]}, {body}>"


def _check(relation, ref, est):
    if relation not in RELATIONS:
        raise ValueError(
            f"relation must be one of {', '.join(RELATIONS)}; got {relation!r}"
        )
    check_pair(("ref", ref), ("est", est), "compare")


def _on_numpy(traj):
    """``traj`` with its poses as NumPy float64 (off torch's graph and device):
    the metrics are evaluation, computed in NumPy on the host."""
    if isinstance(stored(traj.poses), np.ndarray):  # the stored array, not a copy
        return traj
    pq = np.asarray(to_numpy(traj.poses.as_pq()), dtype=np.float64)
    return Trajectory._trusted(traj.stamps, Transform.from_pq(pq))


def _unit(relation, degrees):
    if relation in ("translation", "point_distance"):
        return "m"
    if relation == "rotation_angle":
        return "deg" if degrees else "rad"
    return "unit-less"


def _distance(a, b, block=16384):
    """``|a - b|`` over the last axis (3).

    The positions are strided views into the poses (7 numbers a pose): in
    blocks of ``block`` rows, each block's differences land in one small buffer
    that stays in cache, so the poses are read once and only the result is
    written to memory (a million poses: 22 ms instead of 38 ms for whole-array
    passes, whose temporaries of 8-24 MB each go through memory).
    """
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.size <= 3 * block:
        return _distance_whole(a, b)
    lead = a.shape[:-1]
    a, b = a.reshape(-1, 3), b.reshape(-1, 3)  # views where the layout allows
    n = a.shape[0]
    out = np.empty(n, dtype=np.result_type(a, b))
    d = np.empty((min(block, n), 3), dtype=out.dtype)
    for k in range(0, n, block):
        m = min(block, n - k)
        dd, o = d[:m], out[k : k + m]
        np.subtract(a[k : k + m], b[k : k + m], out=dd)
        dd *= dd
        np.add(dd[:, 0], dd[:, 1], out=o)
        o += dd[:, 2]
    return np.sqrt(out, out=out).reshape(lead)


def _distance_whole(a, b):
    """``|a - b|`` over the last axis (3) in whole-array passes, one per column
    (NumPy's loops over an axis of 3 cost ~10x more): for a few thousand rows,
    which fit in cache, and for batches that broadcast."""
    out = a[..., 0] - b[..., 0]
    out *= out
    d = a[..., 1] - b[..., 1]
    d *= d
    out += d
    np.subtract(a[..., 2], b[..., 2], out=d)
    d *= d
    out += d
    return np.sqrt(out, out=out)


def _norm(v):
    """``|v|`` over the last axis (3)."""
    return np.sqrt(v[..., 0] ** 2 + v[..., 1] ** 2 + v[..., 2] ** 2)


def _reduce(R_E, t_E, relation, degrees):
    """The number of each error motion under ``relation``, from its rotation
    ``R_E`` (a Rotation) and the length of its translation ``t_E`` (an array, or
    None where the relation does not need it)."""
    if relation == "translation":
        return t_E
    q = np.asarray(R_E.as_quat())  # (w, x, y, z)
    sin_half = np.sqrt(q[..., 1] ** 2 + q[..., 2] ** 2 + q[..., 3] ** 2)
    if relation == "rotation_angle":
        angle = 2.0 * np.arctan2(sin_half, np.abs(q[..., 0]))
        return np.degrees(angle) if degrees else angle
    if relation == "rotation_part":
        return _SQRT8 * sin_half
    # full
    return np.sqrt(8.0 * sin_half**2 + t_E**2)


def ape(ref, est, relation="translation", degrees=False):
    """Absolute pose error of each pose: ``E_i = est_i^-1 ref_i`` under ``relation``.

    Parameters
    ----------
    ref, est : Trajectory
        Corresponding poses (associated and, usually, aligned); batches of shape
        ``(..., N)`` broadcast.
    relation : str
        One of :data:`RELATIONS` (see the module); ``"point_distance"`` is
        ``|p_ref_i - p_est_i|``.
    degrees : bool
        ``"rotation_angle"`` in degrees.

    Returns
    -------
    MetricResult
        ``errors`` of shape (..., N), ``stamps`` those of ``ref``.

    Notes
    -----
    Computed in NumPy: poses on torch or JAX are copied to NumPy float64 (off
    the autograd graph and the device) and the result holds NumPy arrays. An
    evaluation metric, like evo's; to differentiate a pose error, write it with
    the poses' own operations (``est.poses.inv() @ ref.poses``).

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> ref = rk.Trajectory([0.0, 1.0], rk.Transform(translation=[[0, 0, 0], [1.0, 0, 0]]))
    >>> est = rk.Trajectory([0.0, 1.0], rk.Transform(translation=[[0, 0, 0], [1, 0.5, 0]]))
    >>> r = rk.trajectory.ape(ref, est)
    >>> r.errors
    array([0. , 0.5])
    >>> round(r.stats["rmse"], 12)
    0.353553390593
    """
    _check(relation, ref, est)
    ref, est = _on_numpy(ref), _on_numpy(est)
    # E = est^-1 ref: R_E = R_est^T R_ref, and |t_E| = |R_est^T (p_ref - p_est)| =
    # |p_ref - p_est|, which is also the point distance: no pose product.
    t_E = None
    if relation in ("point_distance", "translation", "full"):
        t_E = _distance(np.asarray(ref.positions), np.asarray(est.positions))
    if relation in ("point_distance", "translation"):
        errors = t_E
    else:
        errors = _reduce(
            est.poses.rotation.inv() @ ref.poses.rotation, t_E, relation, degrees
        )
    return MetricResult(
        errors, ref.stamps, None, statistics(errors), relation, _unit(relation, degrees)
    )


def _angles_to_next(poses):
    """The rotation angle between consecutive poses, shape (N - 1,).

    ``2 acos|a.b|`` loses precision near 0; with ``s = sign(a.b)`` (1 at 0), the
    same angle is ``4 atan2(|a - s b|, |a + s b|)`` (the half-angle between the
    unit quaternions on the 3-sphere), accurate everywhere.
    """
    q = np.asarray(poses.rotation.as_quat())
    a, b = q[:-1], q[1:]
    s = np.where(np.einsum("ij,ij->i", a, b) < 0.0, -1.0, 1.0)[:, None]
    return 4.0 * np.arctan2(
        np.linalg.norm(a - s * b, axis=-1), np.linalg.norm(a + s * b, axis=-1)
    )


def _walk(cumulative, delta):
    """Indices chosen by walking: from each chosen index, the first later one whose
    accumulated amount reaches ``delta``; one searchsorted per chosen index."""
    chosen = [0]
    n = len(cumulative)
    i = 0
    while True:
        j = int(np.searchsorted(cumulative, cumulative[i] + delta, side="left"))
        # cumulative[i] + delta rounds: confirm with the difference itself.
        while j < n and cumulative[j] - cumulative[i] < delta:
            j += 1
        while j - 1 > i and cumulative[j - 1] - cumulative[i] >= delta:
            j -= 1
        if j >= n:
            return np.asarray(chosen, dtype=np.intp)
        chosen.append(j)
        i = j


def pair_indices(poses, delta, unit="frames", all_pairs=False, tolerance=0.1):
    """The index pairs ``(i, j)`` that :func:`rpe` compares, shape (M, 2).

    Chosen on ``poses`` (a Transform of shape (N,)) as evo chooses them:

    - ``"frames"``: ``(0, d), (d, 2d), ...`` (``d = delta``, an integer); with
      ``all_pairs``, every ``(i, i + d)``.
    - ``"meters"``: walking along the path from the last chosen index, the
      first index whose travelled distance from it reaches ``delta``, each chosen
      index paired with the next; with ``all_pairs``, for every ``i`` the later
      ``j`` whose travelled distance from ``i`` is closest to ``delta`` (the
      earlier of two), kept if it differs from ``delta`` by at most
      ``tolerance * delta``.
    - ``"degrees"``/``"radians"``: as ``"meters"`` with the rotation angles
      between consecutive poses accumulated; with ``all_pairs``, every pair
      ``i < j`` whose direct rotation angle differs from ``delta`` by at most
      ``tolerance * delta`` (an O(N^2) search, in blocks).
    """
    n = poses.shape[-1]
    if unit not in UNITS:
        raise ValueError(f"unit must be one of {', '.join(UNITS)}; got {unit!r}")
    if unit == "frames":
        d = int(delta)
        if d != delta or d < 1:
            raise ValueError(f"delta in frames must be a whole number >= 1, got {delta!r}")
        if all_pairs:
            i = np.arange(max(n - d, 0))
            return np.stack([i, i + d], axis=-1)
        ids = np.arange(0, n, d)
        return np.stack([ids[:-1], ids[1:]], axis=-1)
    delta = float(delta)
    if not delta > 0:
        raise ValueError(f"delta must be positive, got {delta!r}")
    if unit == "meters":
        p = np.asarray(poses.translation)
        steps = np.linalg.norm(np.diff(p, axis=0), axis=-1)
    else:
        if unit == "degrees":
            delta = np.radians(delta)
        if all_pairs:
            return _angle_pairs(poses, delta, tolerance * delta)
        steps = _angles_to_next(poses)
    cumulative = np.concatenate([[0.0], np.cumsum(steps)])
    if not all_pairs:
        ids = _walk(cumulative, delta) if n else np.zeros(0, dtype=np.intp)
        return np.stack([ids[:-1], ids[1:]], axis=-1)
    # For each i, the j > i with cumulative[j] - cumulative[i] closest to delta:
    # the two neighbours of the target value.
    i = np.arange(n)
    hi = np.minimum(np.searchsorted(cumulative, cumulative + delta, side="left"), n - 1)
    # The candidate below the target: the first index holding its value (a pose
    # repeated by association adds a step of zero; the earliest index wins ties).
    lo = np.searchsorted(cumulative, cumulative[np.maximum(hi - 1, 0)], side="left")
    lo = np.minimum(np.maximum(lo, i + 1), n - 1)
    hi = np.maximum(hi, lo)
    gap_lo = np.abs(cumulative[lo] - cumulative - delta)
    gap_hi = np.abs(cumulative[hi] - cumulative - delta)
    j = np.where(gap_hi < gap_lo, hi, lo)
    gap = np.minimum(gap_lo, gap_hi)
    keep = (i + 1 < n) & (gap <= tolerance * delta)
    return np.stack([i[keep], j[keep]], axis=-1)


def _angle_pairs(poses, delta, tol, block=1024):
    q = np.asarray(poses.rotation.as_quat())
    n = len(q)
    out_i, out_j = [], []
    for start in range(0, n, block):
        a = q[start : start + block]
        dot = np.abs(a @ q.T)
        angle = 2.0 * np.arccos(np.minimum(dot, 1.0))
        rows = np.arange(start, start + len(a))[:, None]
        ok = (np.abs(angle - delta) <= tol) & (np.arange(n)[None, :] > rows)
        ii, jj = np.nonzero(ok)
        out_i.append(ii + start)
        out_j.append(jj)
    if not out_i:
        return np.zeros((0, 2), dtype=np.intp)
    return np.stack([np.concatenate(out_i), np.concatenate(out_j)], axis=-1)


def rpe(
    ref,
    est,
    delta=1,
    unit="frames",
    relation="translation",
    all_pairs=False,
    tolerance=0.1,
    degrees=False,
    pairs_from="estimate",
):
    """Relative pose error of pose pairs: ``E_ij = (ref_i^-1 ref_j)^-1 (est_i^-1 est_j)``.

    Parameters
    ----------
    ref, est : Trajectory
        Corresponding poses (associated), equal length ``N``.
    delta : float
        The spacing of a pair, in ``unit``.
    unit : {"frames", "meters", "degrees", "radians"}
        How pairs are chosen: see :func:`pair_indices`.
    relation : str
        One of :data:`RELATIONS`; ``"point_distance"`` is ``| |p_j - p_i|_est -
        |p_j - p_i|_ref |``, the difference of the distances the pair spans.
    all_pairs : bool
        Every pair at spacing ``delta`` (overlapping), not consecutive ones.
    tolerance : float
        ``all_pairs`` with a metric unit: the largest relative difference of a
        pair's spacing from ``delta``.
    degrees : bool
        ``"rotation_angle"`` in degrees.
    pairs_from : {"estimate", "reference"}
        The trajectory whose path chooses the pairs (evo's default: the estimate).

    Returns
    -------
    MetricResult
        ``errors`` of shape (M,), ``pairs`` (M, 2), ``stamps`` the reference
        stamps of each pair's first pose.

    Notes
    -----
    Computed in NumPy, as :func:`ape`: poses on torch or JAX are copied to
    NumPy float64 (off the autograd graph) and the result holds NumPy arrays.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> x = np.arange(4.0)
    >>> ref = rk.Trajectory(x, rk.Transform(translation=np.c_[x, 0 * x, 0 * x]))
    >>> est = rk.Trajectory(x, rk.Transform(translation=np.c_[1.1 * x, 0 * x, 0 * x]))
    >>> r = rk.trajectory.rpe(ref, est, delta=1)
    >>> r.pairs.tolist(), np.round(r.errors, 12).tolist()
    ([[0, 1], [1, 2], [2, 3]], [0.1, 0.1, 0.1])
    """
    _check(relation, ref, est)
    ref, est = _on_numpy(ref), _on_numpy(est)
    if pairs_from not in ("estimate", "reference"):
        raise ValueError(
            f"pairs_from must be 'estimate' or 'reference', got {pairs_from!r}"
        )
    chooser = est if pairs_from == "estimate" else ref
    if len(chooser.shape) != 1:
        raise ShapeError("rpe takes one trajectory pair (poses of shape (N,)), not a batch")
    pairs = pair_indices(chooser.poses, delta, unit, all_pairs, tolerance)
    if len(pairs) == 0:
        raise ShapeError(
            f"no pose pair is {delta!r} {unit} apart in a trajectory of {len(ref)} poses"
        )
    i, j = pairs[:, 0], pairs[:, 1]
    pr, pe = np.asarray(ref.positions), np.asarray(est.positions)
    dr, de = pr[j] - pr[i], pe[j] - pe[i]  # the pairs' displacements, world axes
    if relation == "point_distance":
        errors = np.abs(_norm(de) - _norm(dr))
    else:
        # A = ref_i^-1 ref_j and B = est_i^-1 est_j; E = A^-1 B has R_E = R_A^T R_B
        # and |t_E| = |R_A^T (t_B - t_A)| = |t_B - t_A|, t_A = R_ref_i^T dr: rotations
        # and two rotated vectors, no pose product.
        Rr, Re = ref.poses.rotation, est.poses.rotation
        Rr_i, Re_i = Rr[i], Re[i]
        t_E = None
        if relation in ("translation", "full"):
            t_E = _distance(Re_i.apply(de, inverse=True), Rr_i.apply(dr, inverse=True))
        R_E = None
        if relation != "translation":
            R_E = (Rr_i.inv() @ Rr[j]).inv() @ (Re_i.inv() @ Re[j])
        errors = _reduce(R_E, t_E, relation, degrees)
    stamps = None if ref.stamps is None else ref.stamps[i]
    return MetricResult(
        errors, stamps, pairs, statistics(errors), relation, _unit(relation, degrees)
    )
