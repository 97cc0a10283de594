"""Means of rotations and rigid motions, arrays in and out, reduced along batch axes.

Quaternions are Hamilton, scalar first ``(w, x, y, z)``; poses are
``(w, x, y, z, tx, ty, tz)``; twists ``(v, w)``. Every mean is independent of the
signs of the input quaternions (``q`` and ``-q`` are one rotation).

==============  ===========================================================
``chordal``     the rotation nearest the weighted mean of the rotation
                matrices (Frobenius): the eigenvector of the largest
                eigenvalue of ``M = sum w_i q_i q_i^T`` (Markley et al. 2007,
                scipy's ``Rotation.mean``); poses add the weighted mean
                translation (the Frobenius mean of the 4x4 matrices).
``geodesic``    the Karcher (Frechet) mean: ``mu <- mu exp(sum w_i log(mu^-1
                X_i) / sum w_i)`` from the chordal mean until the mean log is
                below ``tol``; for poses the SE(3) exponential barycenter (the
                same fixed point with SE(3) logs, Pennec and Arsigny 2012).
==============  ===========================================================

Written against the array API (namespace of the input; ``linalg.eigh`` of the
namespace); the Karcher loop tests convergence on concrete values, and where
they cannot be read (``jax.jit``, ``vmap``, ``grad``, ``torch.compile``,
``torch.func``) it runs ``max_iter`` steps, each mean frozen once converged.

Dask arrays stay lazy: the reduced axes are made whole (one chunk, rechunked) and
each chunk of the kept batch axes is averaged on its own (one ``map_blocks``-like
layer; with the default ``axis=None`` the whole batch is one chunk). The Karcher
loop then tests convergence per chunk (each chunk's mean log below ``tol``, as the
whole batch's is in NumPy), and the iteration count returned is a 0-d Dask array
(the most steps of any chunk). Bad input raises at compute time, naming the
global batch index.

>>> import numpy as np
>>> c, s = np.cos(0.1), np.sin(0.1)
>>> mean, steps = quat_mean([[c, 0.0, 0.0, s], [-c, 0.0, 0.0, s]])  # +-0.2 rad about z
>>> np.round(mean, 12) + 0.0
array([1., 0., 0., 0.])
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .._engine import compile_host_loop, dask_backend, in_background, numba_available
from .._engine.namespace import device_of, namespace_of
from .._validate import (
    _relabel,
    any_true,
    batch_index,
    finite_array,
    where_text,
)
from ..errors import DegenerateInputError, ShapeError
from ..kernels import quaternion as _kq
from ..kernels import se3 as _kse3
from ..kernels import so3 as _krv
from . import conversions as _conv
from ._chordal_loop import chordal_loop
from ._karcher import _average, karcher, lie_steps

__all__ = [
    "quat_mean",
    "quat_mean_unchecked",
    "pose_mean",
    "pose_mean_unchecked",
    "lie_steps",
    "lie_mean_unchecked",
    "reduce_axes",
]


def reduce_axes(axis, nbatch):
    """Batch axes to reduce, as a sorted tuple of non-negative ints (``None``: all).

    An axis that is not an integer, or outside the batch, is a
    :class:`~rigidkit.ShapeError` naming it.
    """
    if axis is None:
        return tuple(range(nbatch))
    axes = (axis,) if _is_int(axis) else axis
    if not isinstance(axes, (tuple, list)) or not all(_is_int(a) for a in axes):
        raise ShapeError(
            f"axis must be None, an int or a tuple of ints (batch axes), got {axis!r}"
        )
    out = []
    for a in axes:
        a = int(a)
        if not -nbatch <= a < nbatch:
            raise ShapeError(
                f"axis {a} is out of bounds for a batch of {nbatch} dimensions"
            )
        out.append(a % nbatch)
    return tuple(sorted(set(out)))


def _is_int(a):
    return isinstance(a, (int, np.integer)) and not isinstance(a, (bool, np.bool_))


def _check_weights_shape(shape, batch):
    """:class:`~rigidkit.ShapeError` unless weights of ``shape`` broadcast to ``batch``."""
    shape = tuple(shape)
    if len(shape) > len(batch) or any(
        s not in (1, b) for s, b in zip(shape[::-1], batch[::-1])
    ):
        raise ShapeError(
            f"weights: shape {shape} does not broadcast to the batch shape {tuple(batch)} "
            "(one weight per element, or a shape that broadcasts to it)"
        )


def _permute(xp, x, order):
    if hasattr(xp, "permute_dims"):
        return xp.permute_dims(x, order)
    return x.permute(*order)  # torch


def _grouped(xp, x, axes, trail):
    """``x`` (batch + trail) as (kept batch, K, trail): reduced axes merged into K."""
    nb = x.ndim - trail
    if len(axes) == nb:  # everything reduced (the default): no transpose
        shape = (math.prod(x.shape[:nb]),) + tuple(x.shape[nb:])
        return (x.reshape(shape) if isinstance(x, np.ndarray) else xp.reshape(x, shape)), ()
    keep = [a for a in range(nb) if a not in axes]
    order = tuple(keep) + tuple(axes) + tuple(range(nb, x.ndim))
    y = _permute(xp, x, order)
    kept = tuple(x.shape[a] for a in keep)
    k = math.prod([x.shape[a] for a in axes])  # a list: Dynamo traces no generator here
    return xp.reshape(y, kept + (k,) + tuple(x.shape[nb:])), kept


def _weights(xp, weights, batch, axes, like):
    """Weights broadcast to the batch, grouped (kept, K); validated; and their sums."""
    if weights is None:
        return None, None
    w = finite_array(weights, (), "weights")
    _check_weights_shape(w.shape, batch)
    w = xp.asarray(w, dtype=like.dtype, device=device_of(like))
    w = xp.broadcast_to(w, batch)
    neg = w < 0.0
    if any_true(neg):
        idx = batch_index(neg)
        raise DegenerateInputError(f"weights are negative {where_text(idx)}", index=idx)
    g, _ = _grouped(xp, w, axes, 0)
    total = xp.sum(g, axis=-1)
    zero = total <= 0.0
    if any_true(zero):
        idx = batch_index(zero)
        raise DegenerateInputError(
            f"weights sum to zero over the reduced axes {where_text(idx)} of the result; "
            "the mean is undefined",
            index=idx,
        )
    return g, total


def _chordal(xp, q, w):
    """Dominant eigenvector of ``sum_k w_k q_k q_k^T``; q (kept, K, 4), w (kept, K)."""
    if (
        isinstance(q, np.ndarray)
        and q.dtype in _NO_WEIGHTS  # the dtypes it is compiled for
        and q.shape[-2] >= GRAM_MIN
        and _gram_ready()
    ):
        return _chordal_compiled(q, w)
    m = q.mT @ (q if w is None else q * w[..., None])  # (kept, 4, 4)
    _, vecs = xp.linalg.eigh(m)
    return _kq.quat_canonical(vecs[..., :, -1])


#: Rotations per mean from which the NumPy path uses the compiled loop (once it is
#: compiled: the compile runs in the background, so no size waits for it).
GRAM_MIN = 2
_GRAM = None
_GRAM_JOB = None
#: The compiled loop's unweighted ``w`` argument, one per dtype it is compiled for.
_NO_WEIGHTS = {np.dtype(dt): np.empty((0, 0), dt) for dt in (np.float64, np.float32)}


def _gram_ready() -> bool:
    """Whether the compiled Gram loop is ready; the first ask starts its compile.

    The compile (or load from numba's cache) runs on the engine's background
    thread, as the kernels' loops do, so no call waits for it; until it is ready,
    BLAS serves.
    """
    global _GRAM_JOB
    if _GRAM is not None:
        return True
    if _GRAM_JOB is None and numba_available():
        _GRAM_JOB = in_background("chordal mean", _compile_gram)
    return False


def _compile_gram():
    global _GRAM
    # q (groups, K, 4) and w (groups, K) read, weighted, out (groups, 4) written.
    _GRAM = compile_host_loop(chordal_loop, ("r3", "r2", "bool", "w2"))
    return _GRAM


def _chordal_compiled(q, w):
    """The NumPy-side fast path of the chordal mean: one compiled pass and a 4x4 Jacobi.

    BLAS reads the (K, 4) operand twice and, for a product this skinny, runs near
    8 ns per rotation; this loop reads it once (about 1.5 ns), and its Jacobi solve
    saves ``numpy.linalg.eigh``'s ~10 us of call overhead.
    """
    q = np.ascontiguousarray(q)
    flat = q.reshape((-1,) + q.shape[-2:])
    if w is None:
        ww = np.empty((0, 0), q.dtype)
    else:
        ww = np.ascontiguousarray(w, dtype=q.dtype).reshape((flat.shape[0], -1))
    out = np.empty((flat.shape[0], 4), q.dtype)
    _GRAM(flat, ww, w is not None, out)
    return out.reshape(q.shape[:-2] + (4,))


def _check_count(q, what):
    if q.shape[-2] == 0:
        raise DegenerateInputError(f"the mean of zero {what} is undefined")


def _grouped_weighted(xp, x, weights, axis, what):
    """``x`` (..., c) grouped (kept, K, c) over the reduced axes; weights and sums."""
    axes = reduce_axes(axis, x.ndim - 1)
    g, _ = _grouped(xp, x, axes, 1)
    _check_count(g, what)
    w, total = _weights(xp, weights, tuple(x.shape[:-1]), axes, x)
    return g, w, total


_SO3_STEPS = lie_steps(
    _kq.quat_multiply, _kq.quat_conjugate, _krv.quat_from_rotvec, _krv.rotvec_from_quat
)
_SE3_STEPS = lie_steps(
    _kse3.pose_compose, _kse3.pose_inv, _kse3.pose_from_twist, _kse3.twist_from_pose
)


def lie_mean_unchecked(
    x, weights=None, *, steps, method="geodesic", axis=None, tol=None, max_iter=100
):
    """The Karcher mean of elements of any Lie group, stored ``(..., c)``, along batch axes.

    ``mu <- mu exp(sum w_i log(mu^-1 x_i) / sum w_i)`` from the first element of
    each averaged group until the norm of the mean log is below ``tol`` (1e-12, or
    1e-6 in float32): the weighted Frechet mean of the left-invariant metric,
    unique for data concentrated enough (Pennec and Arsigny 2012). ``steps`` is
    the group's ``(log_from, retract)`` (:func:`lie_steps`). Elements are assumed
    valid (not checked); the weights are validated as in :func:`quat_mean`.
    Returns ``(mean, iterations)``, ``mean`` of shape (kept batch..., c).
    """
    if method != "geodesic":
        raise ValueError(f"method must be 'geodesic' for this group, got {method!r}")
    if dask_backend.any_dask(x, weights):
        fn = functools.partial(lie_mean_unchecked, steps=steps)
        return _lazy_mean(fn, x, weights, axis, method, tol, max_iter)
    xp = namespace_of(x)
    g, w, total = _grouped_weighted(xp, x, weights, axis, "elements")
    return karcher(xp, g[..., 0, :], g, w, total, method, tol, max_iter, steps)


def quat_mean(quats, weights=None, *, method="chordal", axis=None, tol=None, max_iter=100):
    """Mean rotation of unit quaternions, along batch axes.

    Parameters
    ----------
    quats : array_like, shape (..., 4)
        Unit quaternions (normalised here), scalar first; signs are irrelevant.
    weights : array_like, shape (...), optional
        Non-negative weights, broadcasting with the batch shape; equal if omitted.
    method : {"chordal", "geodesic"}
        See the module table.
    axis : int or tuple of int, optional
        Batch axes to reduce (default: all); the others are kept.
    tol : float, optional
        Karcher tolerance on ``|mean log|`` (radians): 1e-12 (float64) or 1e-6
        (float32) by default.
    max_iter : int
        Karcher steps at most; a :class:`~rigidkit.ConvergenceWarning` if reached.

    Returns
    -------
    mean : array, shape (kept batch..., 4)
        Unit quaternion with ``w >= 0``.
    iterations : int
        Karcher steps taken (0 for ``"chordal"``).

    Raises
    ------
    DegenerateInputError
        Negative weights, weights that sum to zero, or nothing to average.
    """
    q = _conv.quat_normalize(quats, what="quaternions")
    return quat_mean_unchecked(
        q, weights, method=method, axis=axis, tol=tol, max_iter=max_iter
    )


def quat_mean_unchecked(
    q, weights=None, *, method="chordal", axis=None, tol=None, max_iter=100
):
    """:func:`quat_mean` of quaternions known to be unit and finite (not checked).

    The weights are still validated. :meth:`rigidkit.Rotation.mean` calls this.
    """
    if (
        type(q) is np.ndarray  # first: TorchDynamo cannot guard on a numba dispatcher
        and _GRAM is not None
        and weights is None
        and axis is None
        and method == "chordal"
    ):
        # The common call (one unweighted chordal mean of a NumPy batch) straight
        # to the compiled loop: the general path's grouping and checks cost ~3 us,
        # more than the loop itself below a thousand rotations.
        empty = _NO_WEIGHTS.get(q.dtype)
        n = q.size >> 2
        if empty is not None and n >= 2 and q.flags.c_contiguous:
            out = np.empty((1, 4), q.dtype)
            _GRAM(q.reshape(1, n, 4), empty, False, out)
            return out[0], 0
    if dask_backend.any_dask(q, weights):
        return _lazy_mean(quat_mean_unchecked, q, weights, axis, method, tol, max_iter)
    xp = namespace_of(q)
    g, w, total = _grouped_weighted(xp, q, weights, axis, "rotations")
    if g.shape[-2] == 1 and method in ("chordal", "geodesic"):
        return _kq.quat_canonical(g[..., 0, :]), 0  # the mean of one rotation
    mean, iterations = karcher(
        xp, _chordal(xp, g, w), g, w, total, method, tol, max_iter, _SO3_STEPS
    )
    return (_kq.quat_canonical(mean) if method == "geodesic" else mean), iterations


def pose_mean(poses, weights=None, *, method="chordal", axis=None, tol=None, max_iter=100):
    """Mean rigid motion of poses ``(w, x, y, z, tx, ty, tz)``, along batch axes.

    Parameters and returns as :func:`quat_mean`, with poses (..., 7) in and out;
    ``"chordal"`` is the chordal rotation mean with the weighted mean translation,
    ``"geodesic"`` the SE(3) exponential barycenter (see the module table), whose
    tolerance bounds the norm of the mean twist (radians and length units alike).
    """
    p = finite_array(poses, (7,), "poses")
    xp = namespace_of(p)
    q = _conv.quat_normalize(p[..., :4], what="pose quaternions")
    p = xp.concat([q, p[..., 4:]], axis=-1)
    return pose_mean_unchecked(
        p, weights, method=method, axis=axis, tol=tol, max_iter=max_iter
    )


def pose_mean_unchecked(
    p, weights=None, *, method="chordal", axis=None, tol=None, max_iter=100
):
    """:func:`pose_mean` of poses with unit quaternions, finite (not checked)."""
    if dask_backend.any_dask(p, weights):
        return _lazy_mean(pose_mean_unchecked, p, weights, axis, method, tol, max_iter)
    xp = namespace_of(p)
    g, w, total = _grouped_weighted(xp, p, weights, axis, "poses")
    t = _average(xp, g[..., 4:], w, total)
    mean = xp.concat([_chordal(xp, g[..., :4], w), t], axis=-1)
    mean, iterations = karcher(xp, mean, g, w, total, method, tol, max_iter, _SE3_STEPS)
    return xp.concat(
        [_kq.quat_canonical(mean[..., :4]), mean[..., 4:]], axis=-1
    ), iterations


def _lazy_mean(fn, x, weights, axis, method, tol, max_iter):
    """``fn`` on Dask input: kept batch axes chunked, reduced ones made whole."""
    import dask.array as da

    x = x if dask_backend.is_dask(x) else da.asarray(np.asarray(x))
    nbatch = x.ndim - 1
    axes = reduce_axes(axis, nbatch)
    keep = [a for a in range(nbatch) if a not in axes]
    order = tuple(keep) + axes
    arrays = [da.transpose(x, order + (nbatch,))]
    if weights is not None:
        w = weights if dask_backend.is_dask(weights) else np.asarray(weights)
        _check_weights_shape(w.shape, x.shape[:-1])
        arrays.append(da.transpose(da.broadcast_to(w, x.shape[:-1]), order))
    if method in ("chordal", "geodesic") and math.prod(x.shape[a] for a in axes) == 0:
        _check_count(np.zeros((0, 4)), "poses" if x.shape[-1] == 7 else "rotations")
    nk = len(keep)
    block = functools.partial(
        _mean_block, fn, dict(method=method, axis=tuple(range(nk, nbatch)), tol=tol,
                              max_iter=max_iter),
    )  # fmt: skip
    relabel = functools.partial(_relabel_transposed, order)
    mean, its = dask_backend.map_batched(
        block, arrays, [len(axes) + 1, len(axes)][: len(arrays)], relabel,
        outputs=[((x.shape[-1],), x.dtype), ((), np.int64)],
    )  # fmt: skip
    return mean, its.max()


def _mean_block(fn, kw, x, w=None):
    mean, iterations = fn(x, w, **kw)
    return mean, np.full(mean.shape[:-1], iterations, dtype=np.int64)


def _relabel_transposed(order, err, index):
    """A chunk's error naming ``index`` of the transposed batch, in the caller's axes."""
    if len(index) == len(order):  # a whole-batch index (negative weights)
        orig = [0] * len(order)
        for i, a in zip(index, order):
            orig[a] = i
        index = tuple(orig)
    return _relabel(err, index)
