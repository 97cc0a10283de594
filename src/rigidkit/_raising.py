"""When checks read values, and how they raise: the first offending batch index.

The switch :class:`set_validation`, :func:`concrete` (whether values can be read
now: not under ``jax.jit``, ``torch.compile`` or ``torch.func``, not a Dask array
before compute), the masks' questions :func:`any_true` and :func:`all_true`, and
:func:`raise_where` / :func:`raise_unless`, the one place an error about a batch
element is raised, with its batch index as ``err.index``. The checks themselves
are in :mod:`rigidkit._validate`, which re-exports all of these.

>>> import numpy as np
>>> from rigidkit.errors import NonFiniteError
>>> try:
...     raise_where(np.array([False, True]), NonFiniteError, "NaN {where}")
... except ValueError as err:
...     print(err, err.index)
NaN at batch index (1,) (1,)
"""

from __future__ import annotations

import numpy as np

from ._engine import dask_backend
from ._engine import namespace as _ns
from ._engine.namespace import is_torch, namespace_of

# -- when values can be checked: concreteness and the validation switch ---------------

#: Whether checks that read values run (shape checks always do); see
#: :class:`set_validation`. One module global: the hot path reads it in ~10 ns.
_ENABLED = True


class set_validation:
    """Turn the checks that read values on or off, for the process or a block.

    ``rk.set_validation(False)`` skips every check that needs the values of an
    array (finiteness, unit norms, orthonormality, ...; shapes are still checked),
    so no public op ever reads a device array back to the host: bad input then
    yields NaN or a wrong result instead of an error. Called plainly it sets the
    switch; as a context manager it restores the previous state on exit (like
    ``torch.set_grad_enabled``). The switch is process-wide, not per thread.

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> with rk.set_validation(False):
    ...     q = rk.conversions.quat_normalize(np.array([np.nan, 0.0, 0.0, 1.0]))
    >>> bool(np.isnan(q).any())
    True
    """

    def __init__(self, enabled: bool):
        global _ENABLED
        self.prev = _ENABLED
        _ENABLED = bool(enabled)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        global _ENABLED
        _ENABLED = self.prev


def validation_enabled() -> bool:
    """Whether checks that read values are on (see :class:`set_validation`)."""
    return _ENABLED


def concrete(x) -> bool:
    """Whether the values of ``x`` can be read now, without tracing or computing.

    False for a JAX tracer (under ``jax.jit``, ``vmap``, ``grad``...), a torch tensor
    while ``torch.compile`` traces or inside ``torch.func`` transforms (a wrapped
    tensor), and a Dask array (whose values exist only once computed; its checks
    are deferred to compute time instead, see :func:`checks_now`). True for NumPy
    arrays, Python numbers and other concrete arrays. NumPy input costs one type
    test; jax and torch are never imported here unless ``x`` is one of theirs.
    """
    t = type(x)
    if t is _NDARRAY:
        return not _ns.COMPILER._is_compiling_flag
    if t in _CONCRETE_TYPES:
        return True
    module = t.__module__
    if module.startswith("jax"):  # jax.Array is jaxlib's; tracers are jax._src's
        return not isinstance(x, _jax_tracer())
    if is_torch(x):
        import torch

        if torch.compiler.is_compiling():
            return False
        return not torch._C._functorch.is_functorch_wrapped_tensor(x)
    return not module.startswith("dask")


_CONCRETE_TYPES = frozenset(
    (np.ndarray, float, int, bool, np.bool_, np.float64, list, tuple)
)
_NDARRAY = np.ndarray
_JAX_TRACER = None


def _jax_tracer():
    global _JAX_TRACER
    if _JAX_TRACER is None:
        import jax  # already imported: x is a jax object

        _JAX_TRACER = jax.core.Tracer
    return _JAX_TRACER


def checks_now(x) -> bool:
    """Whether a check that reads ``x``'s values runs now (concrete, switch on)."""
    return _ENABLED and concrete(x)


def dynamo_traces() -> bool:
    """Whether TorchDynamo is tracing the caller (``torch.compile``).

    Then NumPy input is a graph value too, whose values and dtype cannot be read:
    the checks that read either skip it, as for any traced array (see
    :data:`rigidkit._engine.namespace.COMPILER`; hot paths read its flag
    themselves).
    """
    return _ns.COMPILER._is_compiling_flag


def _deferred(x) -> bool:
    """Whether a check of ``x`` is deferred to compute time (a Dask array, switch on)."""
    return _ENABLED and type(x) is not np.ndarray and dask_backend.is_dask(x)


# -- arrays, masks and batch indices ----------------------------------------------------


def to_numpy(a):
    """A NumPy view (or copy) of an array of any namespace, off the graph and the device.

    For checks and error messages, and for host-side bookkeeping that must not
    carry gradients (the step weights of the kinematics integrators).
    """
    if isinstance(a, np.ndarray):
        return a
    if hasattr(a, "detach"):  # torch: off the graph and the device first
        return a.detach().cpu().numpy()
    return np.asarray(a)


def batch_index(mask_batch) -> tuple:
    """Index of the first True in a boolean batch array (a NumPy view of it)."""
    idx = np.argwhere(np.asarray(to_numpy(mask_batch)))
    return tuple(int(i) for i in idx[0]) if idx.size else ()


def where_text(index: tuple) -> str:
    """``"at batch index (1, 2)"``, or ``"in the (single) input"`` for ``()``."""
    return f"at batch index {index}" if index else "in the (single) input"


def any_true(mask) -> bool:
    """Whether any entry of a boolean array (of any namespace, or a bool) is true.

    The question of every "is something wrong?" test: where the values cannot be
    read (see :func:`concrete`) or validation is off, nothing is found (False);
    for a Dask mask the answer is True ("maybe"), so that the error branch runs
    and its checks defer themselves to compute time.
    """
    if isinstance(mask, (np.ndarray, np.bool_)):
        return _ENABLED and bool(mask.any())
    if not checks_now(mask):
        return _deferred(mask)
    if getattr(mask, "ndim", 0) == 0:
        return bool(mask)
    return bool(namespace_of(mask).any(mask))


def all_true(mask) -> bool:
    """Whether every entry of a boolean array (of any namespace, or a bool) is true.

    The question of every "is all well?" test: True where the values cannot be
    read or validation is off, False ("maybe not") for a Dask mask (see
    :func:`any_true`).
    """
    if isinstance(mask, (np.ndarray, np.bool_)):
        return not _ENABLED or bool(mask.all())
    if not checks_now(mask):
        return not _deferred(mask)
    if getattr(mask, "ndim", 0) == 0:
        return bool(mask)
    return bool(namespace_of(mask).all(mask))


def raise_where(bad, error, message, *, value=None) -> None:
    """Raise ``error`` at the first True of the batch mask ``bad``; nothing if none.

    The one place an error about a batch element is raised, so every such error
    carries its batch index as ``err.index``. ``message`` is a format string: its
    field ``{where}`` becomes the index in words (``"axis is zero {where}"`` reads
    ``"axis is zero at batch index (1, 2)"``) and ``{value}`` the offending element
    of the array ``value`` (a float, or a list for an element with axes of its
    own). A callable ``message`` receives the index and returns the whole text.

    On a Dask mask the check runs per chunk at compute time (the error names the
    global batch index); where values cannot be read it is skipped.
    """
    if _deferred(bad):
        dask_backend.defer(_raise_where_numpy, (bad, value), (error, message), _relabel)
        return
    if not any_true(bad):
        return
    idx = batch_index(bad)
    if callable(message):
        raise error(message(idx), index=idx)
    found = None
    if value is not None:
        found = np.asarray(to_numpy(value))[idx]
        found = found.tolist() if found.ndim else float(found)
    raise error(message.format(where=where_text(idx), value=found), index=idx)


def _relabel(err, index):
    """``err`` (raised on a chunk) naming the batch ``index`` in the whole array."""
    text = str(err).replace(where_text(err.index), where_text(index), 1)
    return type(err)(text, index=index)


def _raise_where_numpy(bad, value, error, message):
    raise_where(bad, error, message, value=value)


def raise_unless(ok, error, message) -> None:
    """:func:`raise_where` at the first False of ``ok`` (a mask or a bool)."""
    if _deferred(ok):
        raise_where(~ok, error, message)
    elif not all_true(ok):
        raise_where(~np.asarray(to_numpy(ok)), error, message)
