"""The pose pairs of the relative pose error, chosen as evo chooses them.

By a number of frames, or by the distance travelled or the rotation turned
along a trajectory (Sturm et al. 2012, Sec. VI; evo's ``delta_unit`` and
``all_pairs``). The pairs depend on the poses' values only for a metric unit;
they are NumPy indices on the host.
"""

from __future__ import annotations

import numpy as np

__all__ = ["UNITS", "pair_indices"]

UNITS = ("frames", "meters", "degrees", "radians")


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
    """The ``(M, 2)`` index pairs ``(i, j)`` that :func:`rigidkit.trajectory.rpe` compares.

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

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> x = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 3.0])
    >>> poses = rk.Transform(translation=np.c_[x, 0 * x, 0 * x])
    >>> rk.trajectory.pair_indices(poses, 2).tolist()
    [[0, 2], [2, 4]]
    >>> rk.trajectory.pair_indices(poses, 1.0, unit="meters").tolist()
    [[0, 2], [2, 4], [4, 5]]
    >>> rk.trajectory.pair_indices(poses, 1.0, unit="meters", all_pairs=True).tolist()
    [[0, 2], [1, 3], [2, 4], [4, 5]]
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
