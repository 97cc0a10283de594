"""Kernels: write a formula once, evaluate it on every backend.

A kernel is a plain Python function of scalar components that returns a tuple of
scalar components. It may call the primitives of :mod:`.primitives`, and the
:func:`helper` functions and other kernels that its module defines or imports
(resolved by name in that module, at definition). :func:`kernel` declares the trailing
shape of each array input and output, and turns the function into a
:class:`Kernel` that takes and returns arrays batched over leading axes
(broadcasting like NumPy):

>>> from rigidkit._engine import kernel
>>> @kernel(inputs=[(2,)], outputs=[()])
... def norm2(x, y):
...     return (sqrt(x * x + y * y),)
>>> float(norm2([3.0, 4.0]))
5.0

Dispatch, for ``a = kernel(arrays...)``:

* NumPy, one element: the function itself over Python floats, or, once the
  kernel is hot there (``SINGLE_HOT`` calls), its compiled one-element loop;
* NumPy, a batch whose compiled loop is ready: the fused numba loop, called
  from a generated entry point (:mod:`.dispatch`) whose checks cost ~0.25 us
  (a call at N = 10 is ~0.8 us in all), split over cores for large batches;
* NumPy, a batch whose loop is not ready yet: the loop is requested from the
  background thread (:func:`.numba_backend.request`, which imports numba and
  compiles or loads the loop from the disk cache) and this batch runs without
  it, element by element on Python floats (up to ``ROWS_MAX`` elements) or
  element-wise with NumPy functions. No call ever waits for numba or a compile;
* otherwise, any array namespace: element-wise evaluation with ``xp`` functions.
"""

from __future__ import annotations

import contextlib
import math
import os
import weakref

import numpy as np

from . import dask_backend, numba_backend
from .binding import Helper, _Rebindable, _refuse_redefinition, helper
from .namespace import (
    device_of,
    float_dtype_of,
    is_half,
    is_numpy,
    namespace_of,
)
from .post_import import when_imported
from .primitives import math_bindings, sympy_bindings, xp_bindings

__all__ = ["Helper", "Kernel", "helper", "kernel"]

#: A NumPy batch of more than this many elements whose compiled loop is not ready
#: waits for it (compiled or loaded by the background thread) instead of taking
#: the vectorised NumPy path meanwhile. None (the default): no batch ever waits.
NUMBA_MIN = (
    int(os.environ["RIGIDKIT_NUMBA_MIN"]) if os.environ.get("RIGIDKIT_NUMBA_MIN") else None
)

#: Force one NumPy binding for every batch of more than one element: ``"numba"``
#: (waits for the compiled loop), ``"xp"`` (element-wise NumPy), or None (automatic).
#: Tests set it to check one binding; the fast path steps aside when it is set.
BINDING = None

#: Whether a NumPy call whose loop is not ready asks the background thread for it
#: (True, the default). ``RIGIDKIT_BACKGROUND_COMPILE=0``: a loop is compiled only
#: where a caller waits for it (``backend="numba"``, ``RIGIDKIT_NUMBA_MIN``,
#: ``rigidkit precompile``), for processes that call many kernels a few times each
#: (the test suite), where each speculative compile (1-3 s of CPU) costs more than it saves.
BACKGROUND = os.environ.get("RIGIDKIT_BACKGROUND_COMPILE", "1") != "0"

#: A kernel called this many times on one element asks for a compiled one-element
#: loop (faster than Python floats there, mostly by not packing a new array).
SINGLE_HOT = 64

#: While a loop loads, batches up to this size run element by element on Python
#: floats (about 1 us each), faster there than the element-wise NumPy path.
ROWS_MAX = 16

_F32 = np.dtype(np.float32)
_F16 = np.dtype(np.float16)


class Kernel(_Rebindable):
    """A scalar formula bound to numba loops, array namespaces, floats and SymPy."""

    def __init__(self, fn, inputs, outputs, params=(), vector_math=False):
        super().__init__(fn)
        self.inputs = [tuple(s) for s in inputs]
        self.outputs = [tuple(s) for s in outputs]
        self.params = tuple(params)
        self.vector_math = vector_math
        self._py = None
        self._sym = None
        self._xp_cache: dict = {}
        # Compiled numba loops, ready to call: {broadcast pattern: {dtype: loop}}.
        # Filled by the background loader (numba_backend.request); read without a
        # lock by the fast path, so entries are only ever added.
        self._ready: dict = {}
        # The same loops' compiled entry points, for the fast path only (see
        # dispatch.entry_point): {broadcast pattern: {dtype: entry point}}.
        self._entry: dict = {}
        # The loops that release the GIL, for batches split over threads (loaded
        # only when such a batch comes, see loop_source.loop_options).
        self._threaded: dict = {}
        self._nsingle: dict = {}  # one-element calls counted per loop key
        _TORCH_KERNELS.add(self)
        if TORCH_BIND is not None:  # torch is set up: bound now (see torch_setup)
            TORCH_BIND(self)

    # -- scalar bindings -------------------------------------------------
    @property
    def python(self):
        """The kernel over Python floats: ``python(*params, *components)``."""
        if self._py is None:
            self._py = self.bound(math_bindings(), scalar=True)
        return self._py

    def sympy(self, *args):
        """The kernel over SymPy expressions: ``sympy(*params, *components)``."""
        if self._sym is None:
            self._sym = self.bound(sympy_bindings())
        return self._sym(*args)

    # -- array entry point -------------------------------------------------
    def __call__(self, *args, out=None, backend=None):
        """Evaluate over batched arrays.

        Parameters
        ----------
        *args
            The static parameters (Python numbers), then one array per input, of
            shape ``(..., *input_shape)``; batch shapes broadcast.
        out : array or tuple of arrays, optional
            NumPy buffers of shape ``(..., *output_shape)`` to write into.
        backend : {"numba", "xp", "python"}, optional
            Force a binding (tests use this to compare them).

        The first call generates this kernel's fast entry point
        (:func:`.dispatch.fast_source`) and makes it the ``__call__`` of a
        subclass of one instance, so later calls go straight to it: one Python
        frame between the caller and the numba loop.
        """
        first = args[len(self.params)] if len(args) > len(self.params) else None
        if type(first) is not np.ndarray and not isinstance(first, _PLAIN):
            # Not NumPy: no fast path needed yet (and torch.compile could not trace
            # its generation).
            return self._call(*args, out=out, backend=backend)
        fast = self._make_fast()
        self.__class__ = type(f"Kernel_{self.name}", (type(self),), {"__call__": fast})
        return fast(self, *args, out=out, backend=backend)

    def _make_fast(self):
        """Generate this kernel's fast entry point (see :mod:`.dispatch`)."""
        from .dispatch import make_fast

        return make_fast(self)

    def _single_seen(self, key):
        """Count one-element calls; the 64th asks for the compiled one-element loop.

        Only kernels called often one element at a time get it: it is one more
        compile (in the background) per kernel and dtype.
        """
        n = self._nsingle.get(key, 0)
        if n < SINGLE_HOT:
            self._nsingle[key] = n + 1
        elif n == SINGLE_HOT:
            self._nsingle[key] = n + 1
            if BACKGROUND and numba_backend.available():
                dtype, ints = key if self.params else (key, ())
                numba_backend.request(self, numba_backend.SINGLE, dtype, ints)

    def _call(self, *args, out=None, backend=None):
        """The general path: any namespace, broadcasting, conversions, forced bindings."""
        nparams = len(self.params)
        params = args[:nparams]
        arrays = args[nparams:]
        if len(arrays) != len(self.inputs):
            raise TypeError(
                f"{self.name} takes {len(self.inputs)} array arguments, got {len(arrays)}"
            )
        xp = namespace_of(*arrays)
        if is_numpy(xp) and xp is not np and backend != "xp":
            xp = np
        if xp is np:
            for a in arrays:
                if type(a) is not np.ndarray and dask_backend.is_dask(a):
                    return self._call_dask(params, arrays, out)
            arrays = [np.asarray(a) for a in arrays]
        batch = self._batch_shape(xp, arrays)
        if xp is np and backend != "xp":
            return self._call_numpy(params, arrays, batch, out, backend)
        return self._call_xp(xp, params, arrays, batch)

    def _call_dask(self, params, arrays, out):
        """Dask input: a lazy graph of this kernel over the chunks (see dask_backend)."""
        if out is not None:
            raise ValueError(f"{self.name}: out= takes NumPy arrays, not Dask arrays")
        arrays = [a if dask_backend.is_dask(a) else np.asarray(a) for a in arrays]
        self._batch_shape(np, arrays)  # shape errors now, not at compute time
        dtype = float_dtype_of(np, *[np.empty(0, dtype=a.dtype) for a in arrays])
        return dask_backend.call(self, params, arrays, dtype)

    def _loop_ready(self, bcast, dtype, ints, loop, nogil=False):
        """Called by the background loader when a compiled loop can be used.

        The table of a broadcast pattern is keyed by dtype, and for a kernel with
        parameters by ``(dtype, ints)`` (which parameters are integers, see
        :func:`_ints`): each combination is its own compiled signature.
        ``nogil``: the variant for batches split over threads, kept apart.
        """
        from .dispatch import entry_point

        key = (dtype, ints) if self.params else dtype
        if nogil:
            self._threaded.setdefault(bcast, {})[key] = loop
            return
        self._entry.setdefault(bcast, {})[key] = entry_point(loop)
        self._ready.setdefault(bcast, {})[key] = loop

    def _batch_shape(self, xp, arrays):
        shapes = []
        for k, (a, trail) in enumerate(zip(arrays, self.inputs)):
            shape = tuple(a.shape)
            nt = len(trail)
            if shape[len(shape) - nt :] != trail or len(shape) < nt:
                from ..errors import shape_error

                raise shape_error(f"{self.name}: argument {k}", shape, trail)
            shapes.append(shape[: len(shape) - nt])
        if all(s == shapes[0] for s in shapes):  # the common case; skips ~3 us
            return shapes[0] if shapes else ()
        try:
            return tuple(np.broadcast_shapes(*shapes))
        except ValueError:
            from ..errors import ShapeError

            raise ShapeError(
                f"{self.name}: batch shapes {shapes} do not broadcast"
            ) from None

    # -- numpy ---------------------------------------------------------------
    def _call_numpy(self, params, arrays, batch, out, backend):
        dtype = float_dtype_of(np, *arrays)
        if dtype is _F16:  # kept, computed in float32 (numba has no float16)
            res = self._call_numpy(
                params, [a.astype(_F32) for a in arrays], batch, None, backend
            )
            res = self._finish(
                [r.astype(_F16) for r in ([res] if len(self.outputs) == 1 else res)]
            )
            return res if out is None else self._write_out(res, out)
        n = math.prod(batch)
        if n == 0:
            return self._finish(self._outputs(batch, dtype, out))
        if backend is None:
            backend = BINDING if n > 1 else "python"
        if backend is None:
            bcast = self._pattern(arrays, n)
            ints = _ints(params)
            key = (dtype, ints) if params else dtype
            if self._ready.get(bcast, {}).get(key) is not None:
                backend = "numba"
            elif NUMBA_MIN is not None and n > NUMBA_MIN and numba_backend.available():
                backend = "numba"
            else:
                # Not ready: ask the background thread for the loop and serve this
                # batch without it (never wait for numba's import or a compile).
                if BACKGROUND and numba_backend.available():
                    numba_backend.request(self, bcast, dtype, ints)
                if n <= ROWS_MAX:
                    res = self._call_rows(params, arrays, batch, dtype, n)
                else:
                    # Standing in for the loop, which never warns: a kernel's
                    # overflow into a branch that `where` discards is not the
                    # caller's (slerp's sinc at t phi ~ 1e308).
                    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                        res = self._call_xp(np, params, arrays, batch)
                return res if out is None else self._write_out(res, out)
        if backend == "python":
            return self._call_python(params, arrays, batch, dtype, out)
        if backend == "numba":
            return self._call_numba(params, arrays, batch, dtype, out, n)
        if backend == "xp":
            res = self._call_xp(np, params, arrays, batch)
            return res if out is None else self._write_out(res, out)
        raise ValueError(f"unknown backend {backend!r}")

    def _pattern(self, arrays, n):
        """Which inputs are one row for the whole batch (read once by the loop)."""
        return tuple(n != 1 and a.size == math.prod(t) for a, t in zip(arrays, self.inputs))

    def _call_rows(self, params, arrays, batch, dtype, n):
        """A small batch element by element on Python floats (while a loop loads)."""
        rows = [
            np.broadcast_to(a, batch + t).reshape(n, math.prod(t)).tolist()
            for a, t in zip(arrays, self.inputs)
        ]
        py = self.python
        res = [py(*params, *[c for r in rows for c in r[i]]) for i in range(n)]
        flat = np.array(res, dtype=dtype).reshape(n, -1)
        if len(self.outputs) == 1:
            return flat.reshape(batch + self.outputs[0])
        outs, k = [], 0
        for s in self.outputs:
            m = math.prod(s)
            # A copy: results must be C-contiguous, as the loop's are.
            outs.append(np.ascontiguousarray(flat[:, k : k + m]).reshape(batch + s))
            k += m
        return self._finish(outs)

    def _outputs(self, batch, dtype, out):
        if out is None:
            return [np.empty(batch + s, dtype=dtype) for s in self.outputs]
        outs = [out] if isinstance(out, np.ndarray) else list(out)
        for o, s in zip(outs, self.outputs):
            if o.shape != batch + s or not o.flags.c_contiguous:
                raise ValueError(
                    f"{self.name}: out= needs a C-contiguous array of shape {batch + s}, "
                    f"got {o.shape}"
                )
        return outs

    def _write_out(self, res, out):
        """Copy results into the caller's ``out=`` buffers and return those."""
        res = [res] if len(self.outputs) == 1 else list(res)
        outs = self._outputs(
            tuple(np.shape(res[0]))[: np.ndim(res[0]) - len(self.outputs[0])], None, out
        )
        for o, r in zip(outs, res):
            o[...] = r
        return self._finish(outs)

    def _finish(self, outs):
        return outs[0] if len(outs) == 1 else tuple(outs)

    def _call_python(self, params, arrays, batch, dtype, out):
        comps = []
        for a in arrays:
            comps += a.ravel().tolist()
        res = self.python(*params, *comps)
        outs = self._outputs(batch, dtype, out)
        k = 0
        for o, s in zip(outs, self.outputs):
            m = math.prod(s)
            o.reshape(-1)[:] = res[k : k + m]
            k += m
        return self._finish(outs)

    def _call_numba(self, params, arrays, batch, dtype, out, n):
        outs = self._outputs(batch, dtype, out)
        bcast = self._pattern(arrays, n)
        ins = []
        for a, trail, row in zip(arrays, self.inputs, bcast):
            if row:
                ins.append(np.ascontiguousarray(a, dtype=dtype).reshape(-1))
                continue
            if a.shape != batch + trail:
                a = np.broadcast_to(a, batch + trail)
            ins.append(np.ascontiguousarray(a, dtype=dtype).reshape((n,) + trail))
        ints = _ints(params)
        loop = self._ready.get(bcast, {}).get((dtype, ints) if params else dtype)
        if loop is None:
            if not numba_backend.available():
                raise RuntimeError(f"{self.name}: numba is not available")
            loop = numba_backend.wait(self, bcast, dtype, ints)
        oargs = [o.reshape((n,) + s) for o, s in zip(outs, self.outputs)]
        workers = numba_backend.workers(n)
        if workers > 1:
            key = (dtype, ints) if params else dtype
            threaded = self._threaded.get(bcast, {}).get(key)
            if threaded is None:
                # Asked for now, for the next batch; this one runs on one thread.
                if BACKGROUND:
                    numba_backend.request(self, bcast, dtype, ints, nogil=True)
                workers = 1
            else:
                loop = threaded
        if numba_backend.run_loop(loop, n, list(params), ins, bcast, oargs, workers):
            # A vector_math loop met a non-finite input or result (a NaN of its
            # fast sine beyond 2^19 among them): computed again with NumPy's libm.
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                res = self._call_xp(np, params, arrays, batch)
            for o, r in zip(outs, [res] if len(self.outputs) == 1 else res):
                o[...] = r
        return self._finish(outs)

    # -- any array namespace --------------------------------------------------
    def _call_xp(self, xp, params, arrays, batch):
        dtype = float_dtype_of(xp, *arrays)
        if is_half(dtype):  # kept, computed in float32
            work = [xp.asarray(a, dtype=xp.float32) for a in arrays]
            res = self._call_xp(xp, params, work, batch)
            res = [res] if len(self.outputs) == 1 else res
            return self._finish([xp.asarray(r, dtype=dtype) for r in res])
        device = next((device_of(a) for a in arrays if device_of(a) is not None), None)
        arrays = [xp.asarray(a, dtype=dtype, device=device) for a in arrays]
        comps = []
        for a, trail in zip(arrays, self.inputs):
            if not trail:
                comps.append(a)
                continue
            flat = xp.reshape(
                a, tuple(a.shape[: a.ndim - len(trail)]) + (math.prod(trail),)
            )
            comps += [flat[..., c] for c in range(math.prod(trail))]
        name = getattr(xp, "__name__", id(xp))
        if name == "torch":
            device = None  # see torch_setup.bind
        key = (name, str(dtype), str(device))
        fn = self._xp_cache.get(key)
        if fn is None:
            fn = self._xp_cache[key] = self.bound(xp_bindings(xp, dtype, device))
        res = fn(*params, *comps)
        outs = []
        k = 0
        for s in self.outputs:
            m = math.prod(s)
            parts = [
                xp.broadcast_to(xp.asarray(c, dtype=dtype, device=device), batch)
                for c in res[k : k + m]
            ]
            k += m
            if not s:
                outs.append(parts[0])
            else:
                outs.append(xp.reshape(xp.stack(parts, axis=-1), batch + s))
        return self._finish(outs)


_INTS = (int, np.integer)
_PLAIN = (list, tuple, int, float, type(None))

#: Every kernel, bound to torch when torch is set up (:func:`.torch_setup.bind`,
#: then ``TORCH_BIND``, which binds the kernels made later at their creation).
_TORCH_KERNELS: weakref.WeakSet = weakref.WeakSet()
TORCH_BIND = None


def _bind_all_torch():
    global TORCH_BIND
    from .torch_setup import bind

    TORCH_BIND = bind
    for k in list(_TORCH_KERNELS):
        bind(k)


when_imported("torch", _bind_all_torch)


@contextlib.contextmanager
def waiting_for_loops():
    """Within this block every NumPy batch waits for its compiled loop.

    For the install step (:mod:`rigidkit.applications.precompile`), which runs
    the common calls once so that the variants they use are compiled into the
    disk cache; outside it no batch ever waits (``NUMBA_MIN``).
    """
    global NUMBA_MIN
    before, NUMBA_MIN = NUMBA_MIN, 0
    try:
        yield
    finally:
        NUMBA_MIN = before


def _ints(params) -> tuple:
    """Which static parameters are integers (int64 in a loop; floats are float64)."""
    return tuple(isinstance(p, _INTS) for p in params)


def kernel(inputs, outputs, params=(), vector_math=False):
    """Declare a kernel: trailing shapes of its array inputs and outputs.

    Parameters
    ----------
    inputs, outputs : sequence of tuple
        Trailing shape of each array argument / result, e.g. ``[(4,), (3,)]``.
    params : sequence of str
        Names of leading static arguments (Python numbers, same for the batch).
    vector_math : bool
        Its batch loops use the engine's own branch-free ``sin``, ``cos`` and
        ``atan2`` (:data:`.primitives.FAST_SINCOS`), so that LLVM vectorises them
        whole; the kernel may call no other libm function. Such a loop reports a
        non-finite input or result (status 2), and that call is computed again by
        NumPy: the fast ``sin`` and ``cos`` give NaN beyond ``|x| = 2^19``. For
        kernels whose cost is their sines and cosines, measured before choosing.
    """

    def wrap(fn):
        _refuse_redefinition(fn)
        return Kernel(fn, inputs, outputs, params, vector_math)

    return wrap
