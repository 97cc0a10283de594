"""Input checks shared by the functional layer: shape, finiteness, norms.

Each raises a :class:`~rigidkit.errors.RigidkitError` subclass naming what was
wrong and the first offending batch index. The checks are one vectorised pass;
the index is looked up only once something is wrong.
"""

from __future__ import annotations

import math

import numpy as np

from ._engine.namespace import is_numpy, namespace_of
from .errors import NonFiniteError, ShapeError


def as_array(x, trail: tuple, what: str):
    """``x`` as an array of its own namespace (NumPy for lists), shape-checked."""
    if type(x) is not np.ndarray and is_numpy(namespace_of(x)):
        x = np.asarray(x)
    if isinstance(x, np.ndarray) and x.dtype.kind not in "fiu":
        raise ShapeError(f"{what}: expected real numbers, got dtype {x.dtype}")
    nt = len(trail)
    shape = tuple(x.shape)
    if len(shape) < nt or shape[len(shape) - nt :] != trail:
        want = "(..., " + ", ".join(map(str, trail)) + ")" if trail else "(...)"
        raise ShapeError(f"{what}: expected shape {want}, got {shape}")
    return x


def batch_index(mask_batch) -> tuple:
    """Index of the first True in a boolean batch array (a NumPy view of it)."""
    m = np.asarray(_to_numpy(mask_batch))
    idx = np.argwhere(m)
    return tuple(int(i) for i in idx[0]) if idx.size else ()


def _to_numpy(a):
    if isinstance(a, np.ndarray):
        return a
    if hasattr(a, "detach"):
        return a.detach().cpu().numpy()
    return np.asarray(a)


def where_text(index: tuple) -> str:
    return f"at batch index {index}" if index else "in the (single) input"


def check_finite(x, trail: tuple, what: str) -> None:
    """Raise :class:`NonFiniteError` if any component of ``x`` is NaN or infinite."""
    if isinstance(x, np.ndarray):
        if x.dtype.kind != "f":
            return
        if x.size <= 16:  # a ufunc call costs more than this loop for one element
            if all(map(math.isfinite, x.ravel().tolist())):
                return
        elif np.isfinite(x).all():
            return
        bad = ~np.isfinite(x)
    else:
        xp = namespace_of(x)
        fin = xp.isfinite(x)
        if bool(xp.all(fin)):
            return
        bad = ~_to_numpy(fin)
    if trail:
        bad = bad.reshape(bad.shape[: bad.ndim - len(trail)] + (-1,)).any(axis=-1)
    raise NonFiniteError(f"{what} contains NaN or infinity {where_text(batch_index(bad))}")


def finite_array(x, trail: tuple, what: str):
    """:func:`as_array` then :func:`check_finite`: the check of every user array."""
    x = as_array(x, trail, what)
    check_finite(x, trail, what)
    return x


def as_float(a):
    """Integer NumPy input becomes float64; other arrays are kept."""
    if isinstance(a, np.ndarray) and a.dtype.kind != "f":
        return a.astype(np.float64)
    return a


def any_true(mask) -> bool:
    """Whether any entry of a boolean array (of any namespace) is true."""
    if isinstance(mask, (np.ndarray, np.bool_)):
        return bool(mask.any())
    return bool(namespace_of(mask).any(mask))
