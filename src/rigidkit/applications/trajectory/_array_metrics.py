"""APE and RPE in the poses' own array namespace (torch, JAX, Dask...): differentiable.

The NumPy path of :mod:`.metrics` is tuned for speed on the host; this one
computes the same numbers with the operations of the poses' namespace, so that
torch's autograd and ``jax.grad`` give the gradient of an error, or of a
statistic of the errors, with respect to the poses, and ``jax.jit`` can trace
it. Only the choice of the RPE pairs in a metric unit (metres, degrees) needs
the poses' values: it is made on a detached NumPy copy, and the pairs, integer
indices, are constants of the computation (as they are of evo's).

Square roots are taken safely (``sqrt(where(x > 0, x, 1))`` where ``x > 0``,
else 0): an error of exactly zero, a norm's kink, gets the subgradient 0 rather
than NaN.
"""

from __future__ import annotations

import numpy as np

from ..._engine.dask_backend import is_dask
from ..._engine.namespace import is_torch
from ...errors import ShapeError

__all__ = ["ape_errors", "rpe_errors", "statistics"]

_DEG = 180.0 / np.pi


def _sqrt(xp, x):
    """``sqrt(x)`` with the subgradient 0 at ``x = 0``."""
    pos = x > 0.0
    return xp.where(pos, xp.sqrt(xp.where(pos, x, xp.ones_like(x))), xp.zeros_like(x))


def _norm(xp, v):
    """``|v|`` over the last axis (3)."""
    return _sqrt(xp, v[..., 0] ** 2 + v[..., 1] ** 2 + v[..., 2] ** 2)


def _sort(x):
    """``x`` sorted along its last axis (torch and the array API name it apart;
    Dask, which has no sort, per block after joining the last axis into one chunk,
    lazily)."""
    if is_torch(x):
        return x.sort(dim=-1).values
    if is_dask(x):
        return x.rechunk({x.ndim - 1: -1}).map_blocks(np.sort, axis=-1, dtype=x.dtype)
    return x.__array_namespace__().sort(x, axis=-1)


def statistics(xp, errors) -> dict:
    """``rmse, mean, median, std, min, max, sse`` over the last axis, as arrays of
    ``errors``' namespace (0-d for one trajectory): differentiable, and equal to
    :func:`rigidkit.trajectory.statistics` (``std`` with ``ddof=0``, the median
    the mean of the two middle errors of an even count)."""
    n = errors.shape[-1]
    if n == 0:
        raise ShapeError("no errors to summarise (no pose or pair was compared)")
    s = _sort(errors)
    sse = xp.sum(errors * errors, axis=-1)
    mean = xp.sum(errors, axis=-1) / n
    d = errors - mean[..., None]
    return {
        "rmse": _sqrt(xp, sse / n),
        "mean": mean,
        "median": 0.5 * (s[..., (n - 1) // 2] + s[..., n // 2]),
        "std": _sqrt(xp, xp.sum(d * d, axis=-1) / n),
        "min": s[..., 0],
        "max": s[..., -1],
        "sse": sse,
    }


def _reduce(xp, R_E, t_E, relation, degrees):
    """The number of each error motion (see :func:`.metrics._reduce`)."""
    if relation == "translation":
        return t_E
    q = R_E.as_quat()  # (w, x, y, z)
    sin_half = _norm(xp, q[..., 1:])
    if relation == "rotation_angle":
        angle = 2.0 * xp.atan2(sin_half, xp.abs(q[..., 0]))
        return angle * _DEG if degrees else angle
    if relation == "rotation_part":
        return np.sqrt(8.0) * sin_half
    return _sqrt(xp, 8.0 * sin_half**2 + t_E**2)  # full


def ape_errors(xp, ref, est, relation, degrees):
    """The APE of each pose (:func:`rigidkit.trajectory.ape`), in ``xp``."""
    t_E = None
    if relation in ("point_distance", "translation", "full"):
        t_E = _norm(xp, ref.positions - est.positions)
    if relation in ("point_distance", "translation"):
        return t_E
    R_E = est.poses.rotation.inv() @ ref.poses.rotation
    return _reduce(xp, R_E, t_E, relation, degrees)


def rpe_errors(xp, ref, est, i, j, relation, degrees):
    """The RPE of each pair ``(i[k], j[k])`` (:func:`rigidkit.trajectory.rpe`), in
    ``xp``; ``i``, ``j`` NumPy integer arrays."""
    pr, pe = ref.positions, est.positions
    dr, de = pr[..., j, :] - pr[..., i, :], pe[..., j, :] - pe[..., i, :]
    if relation == "point_distance":
        return xp.abs(_norm(xp, de) - _norm(xp, dr))
    Rr, Re = ref.poses.rotation, est.poses.rotation
    Rr_i, Re_i = Rr[..., i], Re[..., i]
    t_E = None
    if relation in ("translation", "full"):
        t_E = _norm(xp, Re_i.apply(de, inverse=True) - Rr_i.apply(dr, inverse=True))
    R_E = None
    if relation != "translation":
        R_E = (Rr_i.inv() @ Rr[..., j]).inv() @ (Re_i.inv() @ Re[..., j])
    return _reduce(xp, R_E, t_E, relation, degrees)
