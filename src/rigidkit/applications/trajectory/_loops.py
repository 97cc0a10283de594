"""The compiled loop of the "nearest" association (numba, built in the background).

Both stamp arrays are sorted, so one merge-like pass pairs them in ``O(N + M)``:
``np.searchsorted`` does a binary search per stamp (``O(M log N)``, 40 ms for a
million stamps into a million, mostly cache misses and mispredicted branches),
and the NumPy choice of the nearer neighbour then makes six more passes.
"""

from __future__ import annotations

from ..._engine import compile_host_loop, in_background, numba_available

__all__ = ["nearest_loop"]

_JOB = None


def _nearest(long, short, max_diff, out_short, out_long):
    """Pair each ``short[s]`` with the nearest ``long`` stamp (the earlier of two
    equally near), kept within ``max_diff``; write the kept pairs and return
    ``(count, repeats)``, ``repeats`` the number of kept pairs whose ``long``
    index equals the one before (the same rule as the NumPy path of
    :func:`rigidkit.trajectory.nearest_pairs`, index for index)."""
    n = long.shape[0]
    m = short.shape[0]
    j = 0
    k = 0
    repeats = 0
    for s in range(m):
        q = short[s]
        while j < n and long[j] < q:  # j = np.searchsorted(long, q)
            j += 1
        near = 0
        if n > 1:
            hi = min(max(j, 1), n - 1)
            lo = hi - 1
            near = lo if abs(long[lo] - q) <= abs(long[hi] - q) else hi
        if abs(long[near] - q) <= max_diff:
            if k > 0 and out_long[k - 1] == near:
                repeats += 1
            out_short[k] = s
            out_long[k] = near
            k += 1
    return k, repeats


def _build():
    """The compiled loop (on the engine's background thread)."""
    return compile_host_loop(
        _nearest,
        ("r1", "r1", "float", "w1:int64", "w1:int64"),
        dtypes=("float64",),
        returns=("int", "int"),
    )


def nearest_loop():
    """The compiled loop when it is ready, else None (asking starts its build;
    None for good without numba)."""
    global _JOB
    if _JOB is None and numba_available():
        _JOB = in_background("rigidkit.trajectory nearest pairs", _build)
    if _JOB is None or not _JOB.done.is_set() or _JOB.error is not None:
        return None
    return _JOB.loop
