"""Array handling shared by the scipy drop-in classes: scipy's input promotion,
quaternion order and the copy-on-write of ``__setitem__``.

scipy promotes NumPy input (and lists) to float64, and keeps the floating dtype of
the other array libraries (torch, JAX, ...); results come back in the input's
namespace. scipy's quaternions are scalar last ``(x, y, z, w)``, rigidkit's scalar
first. These helpers do that, and nothing else: every computation is rigidkit's
own.
"""

from __future__ import annotations

import numpy as np

from ..._engine.namespace import is_numpy, namespace_of
from ...kernels import pose_formats as _kpf

__all__ = ["as_float", "canonical_sign", "is_np", "scalar", "set_rows", "wxyz", "xyzw"]

_F64 = np.dtype(np.float64)


def as_float(x):
    """``x`` as a floating array: NumPy float64 for NumPy input and lists (scipy's
    promotion), other namespaces kept (integers become their default float)."""
    if type(x) is np.ndarray:
        return x if x.dtype is _F64 or x.dtype == _F64 else x.astype(np.float64)
    if isinstance(x, (list, tuple, int, float, np.generic)):
        return np.asarray(x, dtype=np.float64)
    xp = namespace_of(x)
    if is_numpy(xp):
        return np.asarray(x, dtype=np.float64)
    if "float" not in str(x.dtype):
        return x * 1.0  # the library's default floating dtype
    return x


def is_np(x) -> bool:
    """Whether ``x`` is a NumPy array (scipy's "single" semantics apply)."""
    return type(x) is np.ndarray


def scalar(x):
    """A 0-d NumPy result as a NumPy scalar (``np.float64``), as scipy returns it."""
    if type(x) is np.ndarray and x.ndim == 0:
        return x[()]
    return x


def wxyz(q):
    """Scalar-last quaternions ``(x, y, z, w)`` reordered scalar first (a new array)."""
    if type(q) is np.ndarray:
        return np.concatenate([q[..., 3:], q[..., :3]], axis=-1)
    return _cat(q[..., 3:], q[..., :3])


_TO_XYZW = np.array([1, 2, 3, 0])
_xyzw_from_quat = _kpf.xyzw_from_quat


def xyzw(q):
    """Scalar-first quaternions ``(w, x, y, z)`` reordered scalar last (a new array)."""
    if type(q) is np.ndarray:
        return _xyzw_from_quat(q) if q.ndim > 1 else q.take(_TO_XYZW)
    return _cat(q[..., 1:], q[..., :1])


def _cat(a, b):
    return namespace_of(a).concat([a, b], axis=-1)


def canonical_sign(q):
    """``q`` or ``-q`` (scalar first): scipy's canonical sign (w > 0, ties broken by
    x, y, z)."""
    xp = namespace_of(q)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    flip = (w < 0) | ((w == 0) & ((x < 0) | ((x == 0) & ((y < 0) | ((y == 0) & (z < 0))))))
    return xp.where(flip[..., None], -q, q)


def set_rows(a, indexer, value):
    """A copy of ``a`` with ``a[indexer] = value`` (JAX: ``a.at[indexer].set``); the
    array ``a``, which an immutable rigidkit object may hold, is left alone."""
    if type(a) is np.ndarray:
        a = np.array(a)
    elif hasattr(a, "clone"):  # torch
        a = a.clone()
    elif hasattr(a, "at"):  # JAX
        return a.at[indexer].set(value)
    else:
        a = a.copy()
    a[indexer] = value
    return a
