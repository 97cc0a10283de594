"""Which array namespace an input belongs to, and a thin adapter for PyTorch.

NumPy arrays (and lists, tuples, Python numbers) map to ``numpy``; objects that
implement ``__array_namespace__`` (JAX, CuPy, array-api-strict, NumPy) map to that
namespace; ``torch.Tensor`` maps to a small adapter, since torch does not yet
expose the array-API names we use. Nothing here imports torch or jax unless the
input already is one of their arrays.
"""

from __future__ import annotations

import numpy as np

from . import post_import

_TORCH_NS = None


def _torch_namespace():
    """The torch adapter (made by :mod:`.torch_setup` at its first import)."""
    if _TORCH_NS is None:
        # An import statement, which TorchDynamo executes for real: the first
        # tensor may come inside torch.compile (see torch_setup).
        from .torch_setup import NAMESPACE

        return NAMESPACE
    return _TORCH_NS


def _set_torch_namespace():
    global _TORCH_NS, COMPILER
    from .torch_setup import NAMESPACE

    _TORCH_NS = NAMESPACE
    import torch.compiler

    has_flag = isinstance(getattr(torch.compiler, "_is_compiling_flag", None), bool)
    COMPILER = torch.compiler if has_flag else _Compiler()


class _NoCompiler:
    """Stands for ``torch.compiler`` until torch is in use: nothing is compiling."""

    _is_compiling_flag = False


class _Compiler:
    """``torch.compiler`` where it has no ``_is_compiling_flag`` (not torch 2.13)."""

    @property
    def _is_compiling_flag(self):
        import torch

        return torch.compiler.is_compiling()


#: ``torch.compiler`` once torch is in use, else a stand-in: its
#: ``_is_compiling_flag`` is true for the whole of a ``torch.compile`` session, so
#: it reads the same eagerly and to TorchDynamo. TorchDynamo traces NumPy code too:
#: a NumPy array made or captured in a compiled function is a graph value, whose
#: values cannot be read and whose ``dtype`` torch 2.13 cannot trace; code that
#: reads either asks this first (two attribute reads, ~20 ns; a call of
#: ``torch.compiler.is_compiling`` costs ~0.1 us, ``sys.modules`` is unsafe there).
COMPILER = _NoCompiler


post_import.when_imported("torch", _set_torch_namespace)


def is_torch(x) -> bool:
    return type(x).__module__.startswith("torch") and hasattr(x, "requires_grad")


def namespace_of(*arrays):
    """The array namespace shared by ``arrays`` (``numpy`` when none is special)."""
    found = None
    for a in arrays:
        if a is None or isinstance(a, (np.ndarray, np.generic, list, tuple, int, float)):
            continue
        if is_torch(a):
            ns = _torch_namespace()
        elif hasattr(a, "__array_namespace__"):
            ns = a.__array_namespace__()
            if post_import.PENDING:  # jax's setup, say, once jax's arrays come
                post_import.settle()
        else:
            continue
        if found is None:
            found = ns
        elif ns is not found and getattr(ns, "__name__", None) != getattr(
            found, "__name__", None
        ):
            raise TypeError(
                f"inputs mix array namespaces {found.__name__} and {ns.__name__}"
            )
    return np if found is None else found


def is_numpy(xp) -> bool:
    return xp is np or getattr(xp, "__name__", "") in ("numpy", "numpy.array_api")


def device_of(x):
    """The device to make arrays on that meet ``x``: None for NumPy and JAX.

    JAX places its arrays itself (a traced array's ``device`` is not a device, and
    ``asarray(tracer, device=...)`` fails under ``jax.jacfwd``), so new JAX arrays
    are never pinned; torch and CuPy arrays name theirs.
    """
    if isinstance(x, np.ndarray) or type(x).__module__.startswith("jax"):
        return None
    return getattr(x, "device", None)


def is_half(dtype) -> bool:
    """True for float16 and bfloat16 of any namespace (kept, but computed in float32)."""
    return dtype is _NP_F16 or "float16" in str(dtype)


def float_dtype_of(xp, *arrays):
    """The floating dtype of a result: that of the inputs, float64 for ints."""
    if is_numpy(xp):
        dts = [np.asarray(a).dtype for a in arrays]
        if dts and (dts[0] is _NP_F64 or dts[0] is _NP_F32):
            if all(d is dts[0] for d in dts):  # the common case, without result_type
                return dts[0]
        dt = np.result_type(*dts) if dts else np.dtype(np.float64)
        if not np.issubdtype(dt, np.floating) or dt.itemsize > 8:
            return np.dtype(np.float64)
        return dt
    if COMPILER._is_compiling_flag:  # a traced ndarray's dtype cannot be read
        arrays = [a for a in arrays if type(a) is not np.ndarray]
    dts = [a.dtype for a in arrays if hasattr(a, "dtype")]
    f64 = xp.float64
    f32 = xp.float32
    if dts and all(d == f32 for d in dts):
        return f32
    if dts and all(d == dts[0] for d in dts) and is_half(dts[0]):
        return dts[0]
    return f64


_NP_F64 = np.dtype(np.float64)
_NP_F32 = np.dtype(np.float32)
_NP_F16 = np.dtype(np.float16)


def is_float32(dtype) -> bool:
    """True for a 32-bit float dtype of any namespace (NumPy, torch, array-api).

    Identity tests first: ``str(dtype)`` costs ~1 us, a lot on one element.
    """
    if dtype is _NP_F64:
        return False
    if dtype is _NP_F32 or dtype is np.float32:
        return True
    return "float32" in str(dtype)
