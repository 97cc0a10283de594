"""Array handling shared by the scipy drop-in classes: scipy's input promotion.

scipy promotes NumPy input (and lists) to float64, and keeps the floating dtype of
the other array libraries (torch, JAX, ...); results come back in the input's
namespace. These helpers do the same, and nothing else: every computation is
rigidkit's own.
"""

from __future__ import annotations

import numpy as np

from ..._engine.namespace import is_numpy, namespace_of

__all__ = ["as_float", "is_np", "scalar"]

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
