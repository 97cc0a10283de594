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

import math

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import device_of, namespace_of
from .._validate import (
    _relabel,
    any_true,
    as_array,
    as_float,
    batch_index,
    check_finite,
    finite_array,
    to_numpy,
    tolerances,
    where_text,
)
from ..errors import DegenerateInputError, ShapeError
from ..kernels import geodesic as _geo
from ..kernels import matrix as _kmat
from ..kernels import quaternion as _kq
from ..kernels import so3 as _kso3

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


def _pairs(a, b, weights, what, *, allow_inf=False):
    a = as_float(finite_array(a, (3,), f"{what} a" if what == "vectors" else "src"))
    b = as_float(finite_array(b, (3,), f"{what} b" if what == "vectors" else "dst"))
    if a.ndim < 2 or b.ndim < 2:
        raise ShapeError(f"{what}: expected shape (..., N, 3), got {a.shape} and {b.shape}")
    xp = namespace_of(a, b)
    dtype = a.dtype if a.dtype == b.dtype else xp.float64
    a = xp.asarray(a, dtype=dtype)
    b = xp.asarray(b, dtype=dtype, device=device_of(a))
    w = None
    if weights is not None:
        w = as_array(weights, (), "weights")
        if allow_inf:
            check_finite(xp.where(w == math.inf, 0.0, as_float(w)), (), "weights")
        else:
            check_finite(w, (), "weights")
    shape = _shapes(what, a.shape, b.shape, None if w is None else w.shape)
    if tuple(a.shape) != shape:
        a = xp.broadcast_to(a, shape)
    if tuple(b.shape) != shape:
        b = xp.broadcast_to(b, shape)
    if shape[-2] == 0:
        raise DegenerateInputError(f"{what}: no pairs given (N = 0)")
    if w is not None:
        w = xp.asarray(as_float(w), dtype=dtype, device=device_of(a))
        if tuple(w.shape) != shape[:-1]:
            w = xp.broadcast_to(w, shape[:-1])
        neg = w < 0.0
        if any_true(neg):
            idx = batch_index(neg)
            raise DegenerateInputError(f"weights are negative {where_text(idx)}", index=idx)
    return xp, a, b, w


def _shapes(what, a_shape, b_shape, w_shape):
    """The broadcast shape ``(..., N, 3)`` of a problem set, checked.

    Only batch axes broadcast: the numbers of pairs ``N`` must be equal, and
    ``weights`` must end in ``N``; a ShapeError names both counts.
    """
    names = ("a", "b") if what == "vectors" else ("src", "dst")
    n = a_shape[-2]
    if n != b_shape[-2]:
        raise ShapeError(
            f"{what}: {n} in {names[0]} (shape {tuple(a_shape)}) but {b_shape[-2]} in "
            f"{names[1]} (shape {tuple(b_shape)}); the numbers of {what} must be equal"
        )
    batch = _broadcast(what, names, a_shape[:-2], b_shape[:-2])
    if w_shape is not None:
        if len(w_shape) < 1 or w_shape[-1] != n:
            raise ShapeError(
                f"weights: shape {tuple(w_shape)} for {n} {what}; expected (..., {n}), "
                "one weight per pair"
            )
        batch = _broadcast("weights", ("weights", what), w_shape[:-1], batch)
    return batch + (n, 3)


def _broadcast(what, names, s1, s2):
    """The broadcast of two batch shapes, or a ShapeError naming both."""
    try:
        return tuple(np.broadcast_shapes(tuple(s1), tuple(s2)))
    except ValueError:
        raise ShapeError(
            f"{what}: the batch shapes {tuple(s1)} of {names[0]} and {tuple(s2)} of "
            f"{names[1]} do not broadcast"
        ) from None


def _lazy(fn, a, b, weights, **kw):
    """``fn`` over the chunks of Dask input: one independent problem per element."""
    import dask.array as da

    arrays = [a, b] if weights is None else [a, b, weights]
    arrays = [x if dask_backend.is_dask(x) else np.asarray(x) for x in arrays]
    if min(x.ndim for x in arrays[:2]) < 2:  # the NumPy path's shape error, now
        return fn(*(np.zeros(x.shape, x.dtype) for x in arrays), **kw)
    w_shape = None if weights is None else arrays[2].shape
    what = "vectors" if fn is kabsch else "points"
    shape = _shapes(what, arrays[0].shape, arrays[1].shape, w_shape)
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


def kabsch(a, b, weights=None, *, return_sensitivity=False):
    """Rotation ``R`` minimising ``sum_i w_i |a_i - R b_i|^2`` (Wahba's problem).

    Parameters
    ----------
    a, b : array_like, shape (..., N, 3)
        Corresponding vectors in frames A and B (``a_i ~ A_R_B b_i``); batch shapes
        broadcast, the numbers of pairs ``N`` must be equal. Lengths matter (they
        weight the pairs), as in scipy.
    weights : array_like, shape (..., N), optional
        Non-negative weights of the pairs; batch axes broadcast. One weight per
        problem may be ``inf``: that pair is aligned exactly (the shortest arc
        from ``b_k`` to ``a_k``) and the others fix the turn about ``a_k`` by
        minimising their weighted residuals, as scipy's ``align_vectors``.
    return_sensitivity : bool
        Also return the sensitivity matrix of Markley (1993).

    Returns
    -------
    quat : array, shape (..., 4)
        ``A_R_B`` as a unit quaternion, scalar first.
    rssd : array, shape (...)
        ``sqrt(sum_i w_i |a_i - R b_i|^2)``, from the residuals themselves (an
        infinitely weighted pair, aligned exactly, counts 0).
    sensitivity : array, shape (..., 3, 3)
        With ``return_sensitivity=True``: ``mean(w) / zeta (kappa I + H H^T)``,
        ``H = sum_i w_i a_i b_i^T`` with singular values ``s`` (the last one
        negated when ``det(U V^T) < 0``), ``kappa = s1 s2 + s2 s3 + s3 s1`` and
        ``zeta = (s1 + s2)(s2 + s3)(s3 + s1)``: times the variance of the
        vectors' angular errors it is the covariance of the small rotation
        vector error of ``R`` (Markley 1993, "Attitude determination using
        vector observations: a fast optimal matrix algorithm", J. Astronaut.
        Sci. 41(2), 261-280; scipy's ``return_sensitivity``). Infinite where
        ``H`` has rank 1 (the rotation about its line is undetermined).

    Raises
    ------
    ShapeError
        Different numbers of pairs in ``a`` and ``b``, or ``weights`` not of
        shape ``(..., N)``.
    DegenerateInputError
        Negative weights, more than one infinite weight in a problem, a zero
        vector in an infinitely weighted pair, a sensitivity asked for with an
        infinite weight, or ``H = 0`` (all pairs zero or of zero weight): no
        rotation is singled out.

    Notes
    -----
    Dask input stays lazy (chunked along the batch); a degenerate pair set
    raises at compute time, naming its global batch index.

    Examples
    --------
    >>> a = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    >>> b = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])     # b_1 is off: Rx(-90) a_1
    >>> q, rssd = kabsch(a, b, [np.inf, 1.0])                 # a_0 = R b_0 exactly
    >>> np.round(q, 12) + 0.0, bool(rssd < 1e-15)
    (array([ 0.70710678, -0.70710678,  0.        ,  0.        ]), True)
    """
    if dask_backend.any_dask(a, b, weights):
        return _lazy(kabsch, a, b, weights, return_sensitivity=return_sensitivity)
    xp, a, b, w = _pairs(a, b, weights, "vectors", allow_inf=True)
    is_inf = None
    if w is not None:
        inf = w == math.inf
        if any_true(inf):
            is_inf = inf
            many = xp.sum(xp.where(inf, xp.ones_like(w), xp.zeros_like(w)), axis=-1) > 1
            if any_true(many):
                idx = batch_index(many)
                raise DegenerateInputError(
                    f"weights: more than one infinite weight {where_text(idx)}; only "
                    "one pair can be aligned exactly",
                    index=idx,
                )
            if return_sensitivity:
                raise DegenerateInputError(
                    "weights: no sensitivity matrix with an infinite weight (the "
                    "rotation is then not a least-squares estimate)"
                )
            w = xp.where(inf, xp.zeros_like(w), w)
    aw = a if w is None else a * w[..., None]
    h = aw.mT @ b  # sum_i w_i a_i b_i^T
    q, s, fix, _ = _rotation(xp, h)
    total = s[..., 0]
    if is_inf is not None:
        has_inf = xp.any(is_inf, axis=-1)
        total = xp.where(has_inf, xp.ones_like(total), total)
    _zero_check(xp, total, "vectors: all pairs are zero or have zero weight")
    if is_inf is not None:
        q = xp.where(has_inf[..., None], _exact_pair(xp, a, b, w, is_inf, has_inf), q)
    rssd = _rssd(xp, a, b, q, w)
    if not return_sensitivity:
        return q, rssd
    sf = s * fix
    s0, s1, s2 = sf[..., 0], sf[..., 1], sf[..., 2]
    zeta = (s0 + s1) * (s1 + s2) * (s2 + s0)
    kappa = s0 * s1 + s1 * s2 + s2 * s0
    mean_w = xp.ones_like(s0) if w is None else xp.mean(w, axis=-1)
    eye = xp.asarray(np.eye(3), dtype=h.dtype, device=device_of(h))
    hh = h @ h.mT
    with np.errstate(divide="ignore", invalid="ignore"):
        sens = (mean_w / zeta)[..., None, None] * (kappa[..., None, None] * eye + hh)
    return q, rssd, sens


def _cross(u, v):
    """``u x v`` over the last axis (any namespace)."""
    xp = namespace_of(u)
    u0, u1, u2 = u[..., 0], u[..., 1], u[..., 2]
    v0, v1, v2 = v[..., 0], v[..., 1], v[..., 2]
    return xp.stack([u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0], axis=-1)


def _exact_pair(xp, a, b, w, is_inf, has_inf):
    """The rotation taking the infinitely weighted ``b_k`` onto ``a_k`` exactly.

    The shortest arc ``Q`` from ``b_k`` to ``a_k``, then the turn ``phi`` about
    ``u = a_k / |a_k|`` that best aligns the other pairs: with ``c_i = Q b_i``,
    ``phi = atan2(sum_i w_i (c_i x a_i).u, sum_i w_i (c_i.a_i - (c_i.u)(a_i.u)))``
    (the 2-D alignment of their projections onto the plane normal to ``u``),
    ``R = exp(phi u) Q``. ``w`` holds 0 for the exact pair.
    """
    sel = is_inf[..., None]
    a_k = xp.sum(xp.where(sel, a, xp.zeros_like(a)), axis=-2)
    b_k = xp.sum(xp.where(sel, b, xp.zeros_like(b)), axis=-2)
    na = xp.sum(a_k * a_k, axis=-1)
    nb = xp.sum(b_k * b_k, axis=-1)
    zero = has_inf & ((na == 0.0) | (nb == 0.0))
    if any_true(zero):
        idx = batch_index(zero)
        raise DegenerateInputError(
            f"vectors: the infinitely weighted pair has a zero vector {where_text(idx)}",
            index=idx,
        )
    one = xp.ones_like(a_k)  # problems without an exact pair: any nonzero stand-in
    a_k = xp.where(has_inf[..., None], a_k, one)
    b_k = xp.where(has_inf[..., None], b_k, one)
    q_pri = _geo.quat_from_two_vectors(_half_turn_tiny(a.dtype), a_k, b_k)
    u = a_k / xp.sqrt(xp.sum(a_k * a_k, axis=-1))[..., None]
    c = _kq.quat_apply(q_pri[..., None, :], b)
    uu = u[..., None, :]
    sin_t = xp.sum(_cross(c, a) * uu, axis=-1)
    cos_t = xp.sum(c * a, axis=-1) - xp.sum(c * uu, axis=-1) * xp.sum(a * uu, axis=-1)
    phi = xp.atan2(xp.sum(w * sin_t, axis=-1), xp.sum(w * cos_t, axis=-1))
    q_sec = _kso3.quat_from_rotvec(phi[..., None] * u)
    return _kq.quat_multiply(q_sec, q_pri)


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
