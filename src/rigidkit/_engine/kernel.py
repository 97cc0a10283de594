"""Kernels: write a formula once, evaluate it on every backend.

A kernel is a plain Python function of scalar components that returns a tuple of
scalar components. It may call the primitives of :mod:`.primitives` and other
functions registered with :func:`helper`. :func:`kernel` declares the trailing
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

* NumPy, one element: the function itself over Python floats (lowest latency);
* NumPy, more than ``NUMBA_MIN`` elements (or a loop already compiled in this
  process): the fused numba loop, split over cores for large batches;
* otherwise, any array namespace: element-wise evaluation with ``xp`` functions.
"""

from __future__ import annotations

import builtins
import math
import os
import types

import numpy as np

from . import numba_backend
from .namespace import device_of, float_dtype_of, is_numpy, namespace_of
from .primitives import PRIMITIVES, math_bindings, sympy_bindings, xp_bindings

#: Below this many elements a NumPy call never waits for a JIT compile.
NUMBA_MIN = int(os.environ.get("RIGIDKIT_NUMBA_MIN", "1000"))

_HELPERS: dict[str, Helper] = {}
_F64 = np.dtype(np.float64)
_F32 = np.dtype(np.float32)


def _free_names(fn) -> set[str]:
    names = set(fn.__code__.co_names)
    for const in fn.__code__.co_consts:
        if isinstance(const, types.CodeType):
            names |= set(const.co_names)
    return names


def _rebind(fn, bindings: dict):
    """A copy of ``fn`` whose globals are ``bindings`` (primitives + helpers)."""
    return types.FunctionType(fn.__code__, bindings, fn.__name__, fn.__defaults__)


class _Rebindable:
    """Shared machinery of helpers and kernels: dependency walk and rebinding."""

    def __init__(self, fn):
        self.fn = fn
        self.name = fn.__name__
        self.__doc__ = fn.__doc__
        self.__wrapped__ = fn
        for name in _free_names(fn):
            if name not in PRIMITIVES and name not in _HELPERS and not _is_builtin(name):
                raise NameError(
                    f"kernel {self.name} uses {name!r}, which is neither a primitive "
                    f"nor a registered helper"
                )

    def dependencies(self) -> list[Helper]:
        """Helpers called by this function, transitively, callees first."""
        order: list[Helper] = []
        seen: set[str] = set()

        def visit(fn):
            for name in sorted(_free_names(fn)):
                if name in _HELPERS and name not in seen:
                    seen.add(name)
                    visit(_HELPERS[name].fn)
                    order.append(_HELPERS[name])

        visit(self.fn)
        return order

    def bound(self, primitives: dict, *, scalar=False):
        """This function with ``primitives`` and rebound helpers as its globals.

        ``scalar=True`` (Python floats) first rewrites ``where(c, a, b)`` into
        ``a if c else b`` (see :func:`_scalar_version`): several times faster,
        and only the branch taken is evaluated.
        """
        make = _scalar_version if scalar else _rebind
        env = dict(primitives)
        env["__builtins__"] = builtins
        for dep in self.dependencies():
            env[dep.name] = make(dep.fn, env)
        return make(self.fn, env)


def _single_source(kernel) -> str:
    """Source of a kernel's one-element path: unpack, call on floats, pack.

    Written out per kernel (no loops over inputs) because on one element the
    bookkeeping costs as much as the arithmetic. It returns None unless every
    array is a float32/float64 NumPy array of exactly its trailing shape (batch
    shape ``()``), all of one dtype; the caller then takes the general path.
    """
    np_ = len(kernel.params)
    params = [f"p{k}" for k in range(np_)]
    names = [f"a{k}" for k in range(len(kernel.inputs))]
    lines = [f"def single({', '.join(params + names)}):"]
    checks = [f"type({a}) is not ndarray" for a in names]
    checks += [f"{a}.shape != {tuple(s)!r}" for a, s in zip(names, kernel.inputs)]
    lines.append(f"    if {' or '.join(checks)}:")
    lines.append("        return None")
    lines.append(f"    dt = {names[0]}.dtype")
    same = "".join(f" or {a}.dtype is not dt" for a in names[1:])
    lines.append(f"    if (dt is not F64 and dt is not F32){same}:")
    lines.append("        return None")
    call = list(params)
    for a, s in zip(names, kernel.inputs):
        if len(s) == 0:
            call.append(f"{a}.item()")
        elif len(s) == 1:
            call.append(f"*{a}.tolist()")
        else:
            call.append(f"*{a}.ravel().tolist()")
    lines.append(f"    r = py({', '.join(call)})")
    lines.append("    flat = array(r, dt)")
    if len(kernel.outputs) == 1:
        s = kernel.outputs[0]
        lines.append(
            "    return flat" if len(s) == 1 else f"    return flat.reshape({s!r})"
        )
    else:
        parts, start = [], 0
        for s in kernel.outputs:
            m = math.prod(s)
            if not s:
                parts.append(f"flat[{start}]")  # a NumPy scalar: shape ()
            elif len(s) == 1:
                parts.append(f"flat[{start}:{start + m}]")
            else:
                parts.append(f"flat[{start}:{start + m}].reshape({s!r})")
            start += m
        lines.append(f"    return ({', '.join(parts)},)")
    return "\n".join(lines) + "\n"


def _inline_branches():
    """A transformer: ``where(c, a, b)`` -> ``(a if c else b)``; max/min likewise."""
    import ast

    class InlineBranches(ast.NodeTransformer):
        """``where(c, a, b)`` -> ``(a if c else b)``; ``maximum``/``minimum`` likewise."""

        def visit_Call(self, node):
            self.generic_visit(node)
            if isinstance(node.func, ast.Name) and not node.keywords:
                name, args = node.func.id, node.args
                if name == "where" and len(args) == 3:
                    return ast.IfExp(test=args[0], body=args[1], orelse=args[2])
                if name in ("maximum", "minimum") and len(args) == 2:
                    op = ast.GtE() if name == "maximum" else ast.LtE()
                    a, b = args
                    if isinstance(a, ast.Name) and isinstance(b, ast.Name):
                        test = ast.Compare(left=a, ops=[op], comparators=[b])
                        return ast.IfExp(test=test, body=a, orelse=b)
            return node

    return InlineBranches()


def _scalar_version(fn, env: dict):
    """``fn`` compiled with branches inlined for Python floats (falls back to ``fn``)."""
    import ast  # only when a kernel is first evaluated on Python floats

    try:
        from .numba_backend import function_source

        tree = ast.parse(function_source(fn))
    except (OSError, TypeError):  # no source (defined interactively): plain rebind
        return _rebind(fn, env)
    tree = ast.fix_missing_locations(_inline_branches().visit(tree))
    namespace = dict(env)
    exec(compile(tree, f"<rigidkit scalar {fn.__name__}>", "exec"), namespace)
    return namespace[fn.__name__]


def _is_builtin(name: str) -> bool:
    return hasattr(builtins, name)


class Helper(_Rebindable):
    """A scalar function shared by kernels (a coefficient with its series, say)."""

    def __init__(self, fn):
        super().__init__(fn)
        self._py = None

    def __call__(self, *args):
        if self._py is None:
            self._py = self.bound(math_bindings(), scalar=True)
        return self._py(*args)


def helper(fn) -> Helper:
    """Register ``fn`` as a helper that kernels may call by name."""
    h = Helper(fn)
    _HELPERS[h.name] = h
    return h


class Kernel(_Rebindable):
    """A scalar formula bound to numba loops, array namespaces, floats and SymPy."""

    def __init__(self, fn, inputs, outputs, params=()):
        super().__init__(fn)
        self.inputs = [tuple(s) for s in inputs]
        self.outputs = [tuple(s) for s in outputs]
        self.params = tuple(params)
        self._py = None
        self._sym = None
        self._loop = None
        self._warm: set = set()
        self._xp_cache: dict = {}
        # One output: its shape, () when it is a flat vector (no reshape needed).
        self._single = None
        self._nargs = len(self.params) + len(self.inputs)

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
        """
        if backend is None and len(args) == self._nargs:
            if self._single is None:
                self._single = self._make_single()
            single = self._single(*args)
            if single is not None:
                return single if out is None else self._write_out(single, out)
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
            arrays = [np.asarray(a) for a in arrays]
        batch = self._batch_shape(xp, arrays)
        if xp is np and backend != "xp":
            return self._call_numpy(params, arrays, batch, out, backend)
        return self._call_xp(xp, params, arrays, batch)

    def _make_single(self):
        """Generate this kernel's one-element fast path (see :func:`_single_source`)."""
        env = {
            "ndarray": np.ndarray,
            "array": np.array,
            "F64": _F64,
            "F32": _F32,
            "py": self.python,
        }
        exec(compile(_single_source(self), f"<rigidkit single {self.name}>", "exec"), env)
        return env["single"]

    def _batch_shape(self, xp, arrays):
        shapes = []
        for k, (a, trail) in enumerate(zip(arrays, self.inputs)):
            shape = tuple(a.shape)
            nt = len(trail)
            if shape[len(shape) - nt :] != trail or len(shape) < nt:
                from ..errors import ShapeError

                want = "(..., " + ", ".join(map(str, trail)) + ")" if trail else "(...)"
                raise ShapeError(
                    f"{self.name}: argument {k} has shape {shape}, expected {want}"
                )
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
        n = math.prod(batch)
        if n == 0:
            return self._finish(self._outputs(batch, dtype, out))
        if backend is None:
            if n == 1:
                backend = "python"
            elif (n > NUMBA_MIN or dtype in self._warm) and numba_backend.available():
                backend = "numba"
            else:
                res = self._call_xp(np, params, arrays, batch)
                return res if out is None else self._write_out(res, out)
        if backend == "python":
            return self._call_python(params, arrays, batch, dtype, out)
        if backend == "numba":
            return self._call_numba(params, arrays, batch, dtype, out, n)
        if backend == "xp":  # pragma: no cover - handled by caller
            return self._call_xp(np, params, arrays, batch)
        raise ValueError(f"unknown backend {backend!r}")

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
        flat_max = numba_backend.FLAT_MAX
        ins = []
        bcast = []
        for a, trail in zip(arrays, self.inputs):
            m = math.prod(trail)
            size = a.size // m if m else 0
            if size == 1 and n != 1:  # one row for the whole batch: read it once
                ins.append((np.ascontiguousarray(a, dtype=dtype).reshape(m), None))
                bcast.append(True)
                continue
            if size != n:
                a = np.broadcast_to(a, batch + trail)
            flat = np.ascontiguousarray(a, dtype=dtype)
            ins.append(
                (flat.reshape(n * m), m) if m <= flat_max else (flat.reshape(n, m), 0)
            )
            bcast.append(False)
        key = tuple(bcast)
        if self._loop is None:
            self._loop = {}
        loop = self._loop.get(key)
        if loop is None:
            loop = self._loop[key] = numba_backend.compile_loop(self, key)
        oargs = []
        for o, s in zip(outs, self.outputs):
            m = math.prod(s)
            oargs.append((o.reshape(n * m), m) if m <= flat_max else (o.reshape(n, m), 0))
        if n:
            numba_backend.run_loop(loop, n, list(params), ins, oargs)
            self._warm.add(dtype)
        return self._finish(outs)

    # -- any array namespace --------------------------------------------------
    def _call_xp(self, xp, params, arrays, batch):
        dtype = float_dtype_of(xp, *arrays)
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
        key = (getattr(xp, "__name__", id(xp)), str(dtype), str(device))
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


def kernel(inputs, outputs, params=()):
    """Declare a kernel: trailing shapes of its array inputs and outputs.

    Parameters
    ----------
    inputs, outputs : sequence of tuple
        Trailing shape of each array argument / result, e.g. ``[(4,), (3,)]``.
    params : sequence of str
        Names of leading static arguments (Python numbers, same for the batch).
    """

    def wrap(fn):
        return Kernel(fn, inputs, outputs, params)

    return wrap
