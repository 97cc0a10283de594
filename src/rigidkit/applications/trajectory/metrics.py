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

from ..._engine import dask_backend
from ..._engine.namespace import is_numpy, namespace_of
from ..._validate import concrete, to_numpy
from ...errors import RigidkitError, ShapeError
from ...objects.registry import stored
from ...objects.transform import Transform
from . import _array_metrics
from .pairs import UNITS, pair_indices
from .trajectory import Trajectory, check_pair

__all__ = ["RELATIONS", "UNITS", "MetricResult", "ape", "pair_indices", "rpe", "statistics"]

RELATIONS = ("translation", "rotation_angle", "rotation_part", "full", "point_distance")
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

    A torch or JAX array gives arrays of its namespace instead (0-d for one
    series), differentiable, as ``ape`` and ``rpe`` report them on such poses; a
    Dask array gives lazy Dask arrays (nothing is computed by the call).

    >>> bool(statistics(np.array([3.0, 4.0]))["rmse"] == np.sqrt(12.5))
    True
    """
    if not isinstance(errors, (np.ndarray, np.generic)) and hasattr(errors, "shape"):
        # torch, JAX and Dask (NumPy's functions dispatch to its lazy ones)
        return _array_metrics.statistics(namespace_of(errors), errors)
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
    errors : array, shape (..., M)
        One error per pose (APE) or pair (RPE): NumPy float64 for NumPy poses,
        else an array of the poses' namespace (torch, JAX), on their graph.
    stamps : ndarray, shape (M,), or None
        The reference stamp of each pose (APE), of each pair's first pose (RPE).
    pairs : ndarray of int, shape (M, 2), or None
        RPE: the index pairs ``(i, j)`` compared; ``None`` for APE.
    stats : dict
        ``rmse, mean, median, std, min, max, sse`` (see :func:`statistics`):
        floats for one NumPy trajectory pair, else arrays (of the poses'
        namespace, differentiable, for torch and JAX poses).
    relation, unit : str
        What the numbers are: the relation, and ``"m"``, ``"rad"``, ``"deg"`` or
        ``"unit-less"``.
    """

    errors: object
    stamps: np.ndarray | None
    pairs: np.ndarray | None
    stats: dict
    relation: str
    unit: str

    def __repr__(self):
        s = self.stats
        body = ", ".join(
            f"{k}={float(to_numpy(s[k])):.6g}" for k in ("rmse", "mean", "max")
        )
        kind = "RPE" if self.pairs is not None else "APE"
        return f"<{kind} {self.relation} [{self.unit}]: n={self.errors.shape[-1]}, {body}>"


def _check(relation, ref, est):
    if relation not in RELATIONS:
        raise ValueError(
            f"relation must be one of {', '.join(RELATIONS)}; got {relation!r}"
        )
    check_pair(("ref", ref), ("est", est), "compare")


def _namespace(ref, est):
    """The poses' namespace where the metrics compute in it (torch, JAX, ...;
    NumPy's functions for Dask, which dispatch to its lazy ones); None for NumPy,
    computed by the NumPy path tuned for the host."""
    a, b = stored(ref.poses), stored(est.poses)
    if dask_backend.any_dask(a, b):
        return np
    xp = namespace_of(a, b)
    return None if is_numpy(xp) else xp


def _on_numpy(traj):
    """``traj`` with its poses as NumPy float64 (off torch's graph and device)."""
    if isinstance(stored(traj.poses), np.ndarray):  # the stored array, not a copy
        return traj
    pq = np.asarray(to_numpy(traj.poses.as_pq()), dtype=np.float64)
    return Trajectory._trusted(traj.stamps, Transform.from_pq(pq))


def _checked_pairs(pairs, n):
    """``pairs`` as NumPy indices of shape (M, 2), each in ``[0, n)``."""
    p = np.asarray(to_numpy(pairs))
    if p.ndim != 2 or p.shape[1] != 2 or p.dtype.kind not in "iu":
        raise ShapeError(f"pairs must be integers of shape (M, 2), got {p.dtype} {p.shape}")
    bad = (p < 0) | (p >= n)
    if bad.any():
        k = int(np.argmax(bad.any(axis=1)))
        raise ShapeError(
            f"pairs[{k}] = {p[k].tolist()} is not a pair of indices in [0, {n})",
            index=(k,),
        )
    return p


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
    Poses on torch or JAX are compared with their own namespace's operations:
    ``errors`` and ``stats`` are arrays of it, so torch's autograd and
    ``jax.grad`` differentiate them with respect to the poses, and the whole
    function can be traced by ``jax.jit`` (the stamps, NumPy, are constants). At
    an error of exactly zero the gradient of its norm is the subgradient 0.

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
    xp = _namespace(ref, est)
    if xp is not None:
        errors = _array_metrics.ape_errors(xp, ref, est, relation, degrees)
        stats = _array_metrics.statistics(xp, errors)
        return MetricResult(
            errors, ref.stamps, None, stats, relation, _unit(relation, degrees)
        )
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
    pairs=None,
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
    pairs : array_like of int, shape (M, 2), optional
        The index pairs ``(i, j)`` to compare, chosen beforehand (by
        :func:`pair_indices`, say): ``delta``, ``unit``, ``all_pairs``,
        ``tolerance`` and ``pairs_from`` are then not used. For gradients with
        ``jax.grad`` or ``jax.jit`` and pairs in a metric unit, which need the
        poses' values.

    Returns
    -------
    MetricResult
        ``errors`` of shape (M,), ``pairs`` (M, 2), ``stamps`` the reference
        stamps of each pair's first pose.

    Notes
    -----
    Poses on torch or JAX are compared in their own namespace, as by
    :func:`ape`: the errors and statistics are differentiable with respect to
    the poses. The pairs are integer indices, constants of the computation:
    ``unit="frames"`` chooses them from the length alone (so ``jax.jit`` traces
    the whole function), a metric unit from the poses' values (a detached NumPy
    copy: under ``jax.jit`` or ``jax.grad``, whose poses are traced, pass
    ``pairs=`` chosen outside).

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
    xp = _namespace(ref, est)
    if xp is None:
        ref, est = _on_numpy(ref), _on_numpy(est)
    if pairs_from not in ("estimate", "reference"):
        raise ValueError(
            f"pairs_from must be 'estimate' or 'reference', got {pairs_from!r}"
        )
    chooser = est if pairs_from == "estimate" else ref
    if len(chooser.shape) != 1:
        raise ShapeError("rpe takes one trajectory pair (poses of shape (N,)), not a batch")
    if pairs is not None:
        pairs = _checked_pairs(pairs, len(ref))
    else:
        if xp is not None and unit != "frames":  # chosen from values: on the host
            a = stored(chooser.poses)
            if not concrete(a) and not dask_backend.is_dask(a):  # Dask: computed
                raise RigidkitError(
                    f"rpe: pairs {delta!r} {unit} apart are chosen from the poses' "
                    "values, which are traced here (jax.jit, jax.grad, torch.compile); "
                    "choose them outside with rk.trajectory.pair_indices and pass pairs="
                )
            chooser = _on_numpy(chooser)
        pairs = pair_indices(chooser.poses, delta, unit, all_pairs, tolerance)
    if len(pairs) == 0:
        raise ShapeError(
            f"no pose pair is {delta!r} {unit} apart in a trajectory of {len(ref)} poses"
        )
    i, j = pairs[:, 0], pairs[:, 1]
    if xp is not None:
        errors = _array_metrics.rpe_errors(xp, ref, est, i, j, relation, degrees)
        stamps = None if ref.stamps is None else ref.stamps[i]
        stats = _array_metrics.statistics(xp, errors)
        return MetricResult(
            errors, stamps, pairs, stats, relation, _unit(relation, degrees)
        )
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
