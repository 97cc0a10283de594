"""scipy's argument checks and error messages, shared by the drop-in classes.

Each raises the ``ValueError`` (or ``TypeError``) that ``scipy.spatial.transform``
raises for the same input, in its wording where scipy's tests match it; no
computation happens here.
"""

from __future__ import annotations

import math

import numpy as np

from ._arrays import as_float

__all__ = [
    "align_args",
    "broadcast",
    "check_trail",
    "davenport_order",
    "det3",
    "exponent",
    "generator",
    "shape_arg",
]


def check_trail(x, trail, what):
    """Raise unless the trailing axes of ``x`` are ``trail``."""
    shape = tuple(x.shape)
    if shape[len(shape) - len(trail) :] != trail or len(shape) < len(trail):
        text = ", ".join(str(t) for t in trail)
        raise ValueError(f"Expected `{what}` to have shape (..., {text}), got {shape}.")


def shape_arg(num, shape):
    """The batch shape named by scipy's ``num`` or ``shape`` (at most one given)."""
    if num is not None and shape is not None:
        raise ValueError("Only one of `num` or `shape` can be specified.")
    if shape is not None:
        if isinstance(shape, (int, np.integer)):
            return (int(shape),)
        if not isinstance(shape, tuple) or not all(
            isinstance(s, (int, np.integer)) for s in shape
        ):
            raise ValueError("`shape` must be an int or a tuple of ints.")
        return shape
    return () if num is None else (num,)


def generator(rng):
    """A NumPy generator from scipy's ``rng`` (a seed, a generator or None)."""
    if isinstance(rng, (np.random.RandomState, np.random.Generator)):
        return rng
    return np.random.default_rng(rng)


def det3(m):
    """Determinants of 3x3 matrices (..., 3, 3), by cofactors (any namespace)."""
    a, b, c = m[..., 0, :], m[..., 1, :], m[..., 2, :]
    return (
        a[..., 0] * (b[..., 1] * c[..., 2] - b[..., 2] * c[..., 1])
        - a[..., 1] * (b[..., 0] * c[..., 2] - b[..., 2] * c[..., 0])
        + a[..., 2] * (b[..., 0] * c[..., 1] - b[..., 1] * c[..., 0])
    )


def broadcast(sa, sb, what=None):
    """The broadcast of batch shapes ``sa`` and ``sb``, or scipy's ValueError naming
    ``what`` ("rotations", "transforms"; None: rotations against vectors)."""
    try:
        return np.broadcast_shapes(tuple(sa), tuple(sb))
    except ValueError:
        if what is None:
            raise ValueError(
                f"Cannot broadcast {tuple(sa)} rotations to {tuple(sb)} vectors "
                "(operands could not be broadcast together)."
            ) from None
        raise ValueError(
            f"Cannot broadcast {tuple(sa)} {what} in first to {tuple(sb)} {what} in "
            "second object."
        ) from None


def exponent(n):
    """A power's exponent as a float: a number or an array of one element (scipy's)."""
    if isinstance(n, (int, float)):
        return n
    size = getattr(n, "size", None)
    size = size() if callable(size) else size
    if isinstance(n, (list, tuple)) or (size is not None and size != 1):
        raise ValueError("Array exponent must be a scalar")
    return float(n if size is None or getattr(n, "ndim", 0) == 0 else n.reshape(()))


def davenport_order(order):
    """Raise unless ``order`` is one of scipy's Davenport orders."""
    if order not in ("e", "extrinsic", "i", "intrinsic"):
        raise ValueError(
            "order should be 'e'/'extrinsic' for extrinsic sequences or 'i'/"
            f"'intrinsic' for intrinsic sequences, got {order!r}"
        )


def align_args(a, b, weights, return_sensitivity):
    """scipy's checks of ``Rotation.align_vectors``' arguments: ``(a, b, weights)``
    as (N, 3), (N, 3) and None or (N,) arrays (one pair: an infinite weight)."""
    a_in, b_in = as_float(a), as_float(b)
    a2 = a_in[None] if a_in.ndim == 1 else a_in
    b2 = b_in[None] if b_in.ndim == 1 else b_in
    if a2.shape[-1] != 3:
        raise ValueError(
            f"Expected input `a` to have shape (3,) or (N, 3), got {tuple(a_in.shape)}"
        )
    if b2.shape[-1] != 3:
        raise ValueError(
            f"Expected input `b` to have shape (3,) or (N, 3), got {tuple(b_in.shape)}"
        )
    if a2.shape != b2.shape:
        raise ValueError(
            "Expected inputs `a` and `b` to have same shapes, got "
            f"{tuple(a_in.shape)} and {tuple(b_in.shape)} respectively."
        )
    if a2.ndim > 2:
        raise ValueError(
            "Expected inputs `a` and `b` to have shape (3,) or (N, 3), got "
            f"{tuple(a_in.shape)} and {tuple(b_in.shape)} respectively."
        )
    n = a2.shape[0]
    if weights is not None:
        w = as_float(weights)
        if w.ndim != 1:
            raise ValueError(
                f"Expected `weights` to be 1 dimensional, got shape {tuple(w.shape)}."
            )
        if n > 1 and w.shape[0] != n:
            raise ValueError(
                "Expected `weights` to have number of values equal to number of "
                f"input vectors, got {w.shape[0]} values and {n} vectors."
            )
        if bool((w < 0).any()):
            raise ValueError("`weights` may not contain negative values")
        n_inf = int((w == math.inf).sum())
        if n_inf > 1:
            raise ValueError("Only one infinite weight is allowed")
        if n_inf == 1 or n == 1:
            weights = w = (w * 0 + math.inf) if n == 1 else w
            _primary_nonzero(a2, b2, w)
    elif n == 1:
        _primary_nonzero(a2, b2, None)
    if return_sensitivity and (
        n == 1 or (weights is not None and bool((w == math.inf).any()))
    ):
        raise ValueError(
            "Cannot return sensitivity matrix with an infinite weight or one vector pair"
        )
    return a2, b2, weights


def _primary_nonzero(a, b, w):
    k = 0 if w is None else int(np.argmax(np.asarray(w) == math.inf))
    if not (bool((a[k] ** 2).sum() > 0) and bool((b[k] ** 2).sum() > 0)):
        raise ValueError("Cannot align zero length primary vectors")
