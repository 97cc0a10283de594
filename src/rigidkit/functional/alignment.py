"""Rotations and rigid motions from corresponding vectors or points (Wahba, Kabsch,
Umeyama), arrays in and out, batched over leading axes.

``kabsch(a, b)`` minimises ``sum_i w_i |a_i - R b_i|^2`` over rotations (scipy's
``align_vectors`` order: ``R`` maps the ``b`` frame to the ``a`` frame); with the
weighted cross-covariance ``H = sum_i w_i a_i b_i^T = U S V^T`` (SVD) the minimiser
is ``R = U diag(1, 1, d) V^T``, ``d = det(U V^T)`` (the reflection fix). Where
``H`` has rank 1 (one pair, or all vectors parallel or antiparallel) the rotation
about the common direction is undetermined; we return the shortest arc from
``v_1`` to ``u_1``, which is then exact. ``umeyama(src, dst)`` centres the points
first (weighted centroids) and adds the translation and, optionally, the scale
``s = tr(diag(1, 1, d) S) / sum_i w_i |src_i - c_src|^2`` (Umeyama 1991).

Quaternions are Hamilton, scalar first; poses ``(w, x, y, z, tx, ty, tz)`` and
similarities ``(w, x, y, z, tx, ty, tz, s)``. Written against the array API
(``linalg.svd`` and ``linalg.det`` of the input's namespace); the degeneracy
checks read concrete values. Dask arrays stay lazy: each chunk of the batch is
solved on its own (the problem axes ``(N, 3)`` made whole, batch axes chunked), and
a degenerate problem raises at compute time naming the global batch index.

>>> import numpy as np
>>> b = np.eye(3)
>>> a = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # Rz(90) b
>>> q, rssd = kabsch(a, b)
>>> np.round(q, 12) + 0.0, bool(rssd < 1e-15)
(array([0.70710678, 0.        , 0.        , 0.70710678]), True)
"""

from __future__ import annotations

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import device_of, namespace_of
from .._validate import (
    _relabel,
    any_true,
    as_float,
    batch_index,
    finite_array,
    to_numpy,
    tolerances,
    where_text,
)
from ..errors import DegenerateInputError, ShapeError
from ..kernels import geodesic as _geo
from ..kernels import matrix as _kmat
from ..kernels import quaternion as _kq

__all__ = ["kabsch", "umeyama"]


def rank_rtol(dtype) -> float:
    """``sigma_2 / sigma_1`` below which a cross-covariance counts as rank 1: 64 eps.

    Then the second singular direction is rounding noise (its error is about
    ``eps sigma_1 / sigma_2``, radians), so the rotation about the first one is
    not determined by the data.
    """
    return tolerances(dtype).rank_rtol


def _half_turn_tiny(dtype) -> float:
    """``|u + v|^2 / 2`` below which unit ``u``, ``v`` count as antiparallel (64 eps)."""
    e = tolerances(dtype).rank_rtol
    return 0.5 * e * e


def _pairs(a, b, weights, what):
    a = as_float(finite_array(a, (3,), f"{what} a" if what == "vectors" else "src"))
    b = as_float(finite_array(b, (3,), f"{what} b" if what == "vectors" else "dst"))
    if a.ndim < 2 or b.ndim < 2:
        raise ShapeError(f"{what}: expected shape (..., N, 3), got {a.shape} and {b.shape}")
    xp = namespace_of(a, b)
    dtype = a.dtype if a.dtype == b.dtype else xp.float64
    a = xp.asarray(a, dtype=dtype)
    b = xp.asarray(b, dtype=dtype, device=device_of(a))
    shape = tuple(a.shape)
    if shape != tuple(b.shape):
        shape = np.broadcast_shapes(shape, tuple(b.shape))
        a = xp.broadcast_to(a, shape)
        b = xp.broadcast_to(b, shape)
    if shape[-2] == 0:
        raise DegenerateInputError(f"{what}: no pairs given (N = 0)")
    w = None
    if weights is not None:
        w = as_float(finite_array(weights, (), "weights"))
        w = xp.broadcast_to(xp.asarray(w, dtype=dtype, device=device_of(a)), shape[:-1])
        neg = w < 0.0
        if any_true(neg):
            idx = batch_index(neg)
            raise DegenerateInputError(f"weights are negative {where_text(idx)}", index=idx)
    return xp, a, b, w


def _lazy(fn, a, b, weights, **kw):
    """``fn`` over the chunks of Dask input: one independent problem per element."""
    import dask.array as da

    arrays = [a, b] if weights is None else [a, b, weights]
    arrays = [x if dask_backend.is_dask(x) else np.asarray(x) for x in arrays]
    if min(x.ndim for x in arrays[:2]) < 2:  # the NumPy path's shape error, now
        return fn(*(np.zeros(x.shape, x.dtype) for x in arrays), **kw)
    shape = np.broadcast_shapes(arrays[0].shape, arrays[1].shape)
    shapes = [shape, shape, shape[:-1]]
    arrays = [da.broadcast_to(x, s) for x, s in zip(arrays, shapes)]
    trails = [2, 2, 1][: len(arrays)]
    return dask_backend.map_batched(_Solve(fn, kw), arrays, trails, _relabel)


class _Solve:
    """``fn(*blocks, **kw)``, picklable for worker processes (a module-level class)."""

    def __init__(self, fn, kw):
        self.fn, self.kw = fn, kw

    def __call__(self, *blocks):
        return self.fn(*blocks, **self.kw)


def _zero_check(xp, total, what):
    bad = total <= 0.0
    if any_true(bad):
        idx = batch_index(bad)
        raise DegenerateInputError(f"{what} {where_text(idx)}", index=idx)


def _rotation(xp, h):
    """Quaternion of ``argmax tr(R^T H)`` and the rank-1 mask; h (..., 3, 3)."""
    u, s, vt = xp.linalg.svd(h)
    d = xp.linalg.det(u @ vt)
    ones = xp.ones_like(d)
    fix = xp.stack([ones, ones, d], axis=-1)
    r = (u * fix[..., None, :]) @ vt
    q, _ = _kmat.quat_from_matrix(r)
    rank1 = s[..., 1] <= rank_rtol(h.dtype) * s[..., 0]
    if any_true(rank1):
        arc = _geo.quat_from_two_vectors(
            _half_turn_tiny(h.dtype), u[..., :, 0], vt[..., 0, :]
        )
        q = xp.where(rank1[..., None], arc, q)
    return q, s, fix, rank1


def _rssd(xp, a, b, q, w):
    res = a - b @ _kmat.matrix_from_quat(q).mT
    sq = xp.sum(res * res, axis=-1)
    if w is not None:
        sq = sq * w
    return xp.sqrt(xp.sum(sq, axis=-1))


def kabsch(a, b, weights=None):
    """Rotation ``R`` minimising ``sum_i w_i |a_i - R b_i|^2`` (Wahba's problem).

    Parameters
    ----------
    a, b : array_like, shape (..., N, 3)
        Corresponding vectors in frames A and B (``a_i ~ A_R_B b_i``); batch shapes
        broadcast. Lengths matter (they weight the pairs), as in scipy.
    weights : array_like, shape (..., N), optional
        Non-negative weights of the pairs.

    Returns
    -------
    quat : array, shape (..., 4)
        ``A_R_B`` as a unit quaternion, scalar first.
    rssd : array, shape (...)
        ``sqrt(sum_i w_i |a_i - R b_i|^2)``, from the residuals themselves.

    Raises
    ------
    DegenerateInputError
        Negative weights, or ``H = 0`` (all pairs zero or of zero weight): no
        rotation is singled out.

    Notes
    -----
    Dask input stays lazy (chunked along the batch); a degenerate pair set
    raises at compute time, naming its global batch index.
    """
    if dask_backend.any_dask(a, b, weights):
        return _lazy(kabsch, a, b, weights)
    xp, a, b, w = _pairs(a, b, weights, "vectors")
    aw = a if w is None else a * w[..., None]
    h = aw.mT @ b  # sum_i w_i a_i b_i^T
    q, s, _, _ = _rotation(xp, h)
    _zero_check(xp, s[..., 0], "vectors: all pairs are zero or have zero weight")
    return q, _rssd(xp, a, b, q, w)


def umeyama(src, dst, weights=None, *, scale=False):
    """Rigid motion (or similarity) minimising ``sum_i w_i |dst_i - (s R src_i + t)|^2``.

    Parameters
    ----------
    src, dst : array_like, shape (..., N, 3)
        Corresponding points, ``dst_i ~ T @ src_i``; batch shapes broadcast.
    weights : array_like, shape (..., N), optional
        Non-negative weights of the points.
    scale : bool
        Also fit a uniform scale ``s > 0`` (Umeyama); otherwise ``s = 1`` (Kabsch).

    Returns
    -------
    array, shape (..., 7) or (..., 8) with ``scale=True``
        The pose ``(w, x, y, z, tx, ty, tz)``, or ``(..., s)`` appended.

    Raises
    ------
    DegenerateInputError
        Fewer than 3 points, weights that are negative or sum to zero, or points
        (of positive weight) that are coincident or collinear: the rotation about
        their line is then undetermined.

    Notes
    -----
    Dask input stays lazy (chunked along the batch); degenerate points raise
    at compute time, naming their global batch index.
    """
    if dask_backend.any_dask(src, dst, weights):
        return _lazy(umeyama, src, dst, weights, scale=scale)
    xp, x, y, w = _pairs(src, dst, weights, "points")
    n = x.shape[-2]
    if n < 3:
        raise DegenerateInputError(
            f"points: {n} given; a rigid motion needs at least 3 non-collinear points"
        )
    if w is None:
        cx = xp.sum(x, axis=-2) / n
        cy = xp.sum(y, axis=-2) / n
    else:
        total = xp.sum(w, axis=-1)
        _zero_check(xp, total, "weights sum to zero")
        cx = xp.sum(x * w[..., None], axis=-2) / total[..., None]
        cy = xp.sum(y * w[..., None], axis=-2) / total[..., None]
    x0 = x - cx[..., None, :]
    y0 = y - cy[..., None, :]
    yw = y0 if w is None else y0 * w[..., None]
    h = yw.mT @ x0  # sum_i w_i (dst_i - c_dst)(src_i - c_src)^T
    q, s, fix, rank1 = _rotation(xp, h)
    spread = s[..., 0] <= 0.0
    if any_true(rank1 | spread):
        idx = batch_index(rank1 | spread)
        kind = "coincident" if bool(to_numpy(spread)[idx]) else "collinear"
        raise DegenerateInputError(
            f"points are {kind} {where_text(idx)}: the rotation about their line is "
            "undetermined (need 3 non-collinear points of positive weight)",
            index=idx,
        )
    if scale:
        xx = xp.sum(x0 * x0, axis=-1)
        var = xp.sum(xx if w is None else xx * w, axis=-1)
        sc = xp.sum(s * fix, axis=-1) / var
        t = cy - sc[..., None] * _kq.quat_apply(q, cx)
        return xp.concat([q, t, sc[..., None]], axis=-1)
    t = cy - _kq.quat_apply(q, cx)
    return xp.concat([q, t], axis=-1)
