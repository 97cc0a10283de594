"""The generated fast entry point of a kernel: its common calls in a few checks.

Every kernel call with NumPy arrays pays this function's checks before any work,
so for each kernel we write one, straight-line, with its shapes as constants (no
loops over the inputs, no lists, no ``math.prod``): on a 10-element batch the
bookkeeping would otherwise cost more than the arithmetic. It serves

* one element (every array exactly its trailing shape, batch ``()``): the
  compiled one-element loop once the kernel is hot there (its inputs of any
  strides), else the kernel over Python floats;
* a batch with one batch axis, every input either of that batch or a single row
  for the whole batch (``R0.apply(points)``), all float32 or all float64, below
  ``PARALLEL_MIN``, whose compiled loop is ready: the numba loop called
  directly, into a fresh array or a matching ``out=`` buffer. The loop itself
  checks that its inputs are C-contiguous, from the strides that travel with
  them (free in compiled code, ~0.05 us an input here), and returns 1, having
  touched nothing, when one is not: the call then takes the general path.

Anything else (other array namespaces, broadcasting between batch shapes, N-D
batches, conversions, a loop not yet loaded, a forced binding, bad shapes)
returns to :meth:`Kernel._call`, the general path, with the same arguments.

The loops called here are the compiled entry points of the loops (the tables
``E_*``, see :func:`entry_point`), not their numba dispatchers: a dispatcher
types every argument before it runs (~0.1 us of a 0.2 us call), and these checks
have established all it would: exact ``ndarray`` type, the dtype of the loop,
the number of dimensions and the trailing shape, and for an ``out=`` buffer
that it is C-contiguous and writable (``flags.carray``; a dispatcher refuses a
read-only one, the entry point would write into it). The inputs' C-contiguity,
the one thing left, the batch loop checks (above); the one-element loop's
inputs are typed of any layout. The general path keeps the
dispatchers, which check their arguments themselves.

The source for ``quat_apply`` (inputs ``(4,), (3,)``, output ``(3,)``) reads::

    def fast(self, a0, a1, out=None, backend=None):
        if backend is None and type(a0) is ndarray and type(a1) is ndarray:
            dt = a0.dtype
            s0 = a0.shape
            s1 = a1.shape
            if a1.dtype is dt:
                if s0 == (4,) and s1 == (3,):
                    ...  # one element
                elif len(s0) == 2 and s0[1] == 4 and len(s1) == 2 and ... \
and K.BINDING is None:
                    ...  # one branch per broadcast pattern
        return self._call(a0, a1, out=out, backend=backend)
"""

from __future__ import annotations

import math
import sys

import numpy as np

from . import numba_backend
from .loop_source import SINGLE

_INTS = (int, np.integer)


def entry_point(loop):
    """The compiled entry point of a numba dispatcher of one signature (else ``loop``).

    It unboxes its arguments as the signature says without checking them (an
    array of another dtype, rank or layout would be misread), so only callers
    that have checked them, as :func:`fast_source`'s code does, may call it.
    """
    try:
        (sig,) = loop.signatures
        return loop.overloads[sig].entry_point
    except (AttributeError, KeyError, TypeError, ValueError):
        return loop


def make_fast(kernel):
    """Compile :func:`fast_source` of ``kernel``: ``fast(self, *args, out, backend)``.

    Its namespace: NumPy's names, the kernel module (whose ``BINDING`` it reads at
    each call), the kernel over Python floats, and ``E_*``, the kernel's tables
    of ready entry points per broadcast pattern (filled as loops land).
    """
    env = {
        "ndarray": np.ndarray,
        "array": np.array,
        "empty": np.empty,
        "F64": np.dtype(np.float64),
        "F32": np.dtype(np.float32),
        "K": sys.modules[__package__ + ".kernel"],
        "PMIN": numba_backend.PARALLEL_MIN,
        "py": kernel.python,
        "INTS": _INTS,
        "single_out": single_out,
    }
    n = len(kernel.inputs)
    for j in [None, *range(n)]:
        if j is not None and n < 2:
            continue
        bcast = tuple(k == j for k in range(n))
        env["E" + _tag(bcast)] = kernel._entry.setdefault(bcast, {})
    env["E_single"] = kernel._entry.setdefault(SINGLE, {})
    src = fast_source(kernel)
    exec(compile(src, f"<rigidkit fast {kernel.name}>", "exec"), env)
    return env["fast"]


def single_out(kernel, res, out, dt):
    """Write one element's results ``res`` (a tuple of floats) into ``out=``
    (the fast entry's one-element call with ``out=``)."""
    outs = [out] if len(kernel.outputs) == 1 else list(out)
    k = 0
    for o, s in zip(outs, kernel.outputs):
        if type(o) is not np.ndarray or o.shape != s:
            raise ValueError(
                f"{kernel.name}: out= needs a NumPy array of shape {s}, got "
                f"{getattr(o, 'shape', type(o).__name__)}"
            )
        m = math.prod(s)
        if not s:
            o[()] = res[k]
        elif len(s) == 1:
            o[:] = res[k : k + m]
        else:  # .flat: a strided buffer's reshape(-1) would be a copy
            o.flat = res[k : k + m]
        k += m
    return kernel._finish(outs)


def _loop_key(params) -> str:
    """Source of the key of a ready-loop table: the dtype, and which params are ints."""
    if not params:
        return "dt"
    return "(dt, (" + "".join(f"isinstance({p}, INTS), " for p in params) + "))"


def _get_loop(table, params, indent) -> list[str]:
    """Lines that set ``loop`` from ready-loop table ``table`` (None: not ready).

    With static parameters the table's key (which ones are ints) costs one
    ``isinstance`` each, ~0.4 us for the seven of an Euler kernel. A memo
    ``M<table>`` keyed by the exact types (``tk``, formed once per call) finds
    a ready loop in one lookup; loops are never removed from a table, so a memo
    entry stays valid, and only hits are memoised (a loop may land any time).
    """
    pad = " " * indent
    if not params:
        return [f"{pad}loop = {table}.get(dt)"]
    memo = "M" + table
    return [
        f"{pad}loop = {memo}.get(tk)",
        f"{pad}if loop is None:",
        f"{pad}    loop = {table}.get({_loop_key(params)})",
        f"{pad}    if loop is not None:",
        f"{pad}        {memo}[tk] = loop",
    ]


def _run_loop(outs, args, shape_source, status) -> list[str]:
    """Lines that run ``loop`` into fresh outputs or a fitting ``out=``.

    ``shape_source(s)``: the source of the whole shape of an output of trailing
    shape ``s`` (a constant for one element, ``(n, *s)`` for a batch). An
    ``out=`` buffer must be writable too (``flags.carray``: C-contiguous,
    aligned and writable), as the entry point does not check it. ``status``:
    the loop returns 0 when it ran, 1 when an input was not C-contiguous (then
    these lines fall through, to the general path).
    """
    onames = [f"o{k}" for k in range(len(outs))]

    def run(call):
        if status:
            return [f"    if not {call}:", "    " + ret]
        return [f"    {call}", ret]

    ret = f"    return ({', '.join(onames)},)"
    if len(outs) == 1:
        ret = f"    return {onames[0]}"
    lines = ["if out is None:"]
    lines += [f"    {o} = empty({shape_source(s)}, dt)" for o, s in zip(onames, outs)]
    lines += run(f"loop({', '.join(args + onames)})")
    if len(outs) == 1:
        lines.append(
            "if type(out) is ndarray and out.dtype is dt and out.shape == "
            f"{shape_source(outs[0])} and out.flags.carray:"
        )
        ret = "    return out"
        lines += run(f"loop({', '.join(args)}, out)")
    return lines


def _run_single(outs, args) -> list[str]:
    """:func:`_run_loop` of the one-element loop: the output shapes are constants."""
    return _run_loop(outs, args, lambda s: repr(tuple(s)), status=False)


def fast_source(kernel) -> str:
    """Source of ``fast(self, *params, *arrays, out=None, backend=None)``.

    Every kernel has a one-element loop (table ``E_single``, 0-d inputs included).
    """
    nparams = len(kernel.params)
    params = [f"p{k}" for k in range(nparams)]
    names = [f"a{k}" for k in range(len(kernel.inputs))]
    ins = kernel.inputs
    outs = kernel.outputs
    signature = ", ".join(params + names + ["out=None", "backend=None"])
    general = f"self._call({', '.join(params + names)}, out=out, backend=backend)"
    L = []
    if params:  # the memos of _get_loop, one per ready-loop table
        tables = ["E_single", f"E{_tag(tuple(False for _ in ins))}"]
        if len(ins) > 1:
            tables += [
                f"E{_tag(tuple(k == j for k in range(len(ins))))}" for j in range(len(ins))
            ]
        L += [f"M{t} = {{}}" for t in tables]
    L.append(f"def fast(self, {signature}):")
    types_ok = " and ".join(f"type({a}) is ndarray" for a in names)
    L.append(f"    if backend is None and {types_ok}:")
    L.append(f"        dt = {names[0]}.dtype")
    if params:
        L.append(f"        tk = (dt, {', '.join(f'type({p})' for p in params)})")
    for k, a in enumerate(names):
        L.append(f"        s{k} = {a}.shape")
    same = " and ".join(f"{a}.dtype is dt" for a in names[1:]) or "True"
    L.append(f"        if {same}:")
    # -- one element -------------------------------------------------------------
    single = " and ".join(f"s{k} == {tuple(t)!r}" for k, t in enumerate(ins))
    L.append(f"            if {single}:")
    # The compiled one-element loop (once this kernel is hot at one element):
    # ~0.2 us of call, less than packing Python floats into a new array. A
    # loop in the table implies a float32 or float64 dtype.
    lkey = _loop_key(params)
    L += _get_loop("E_single", params, 16)
    L.append("                if loop is None:")
    L.append("                    if dt is not F64 and dt is not F32:")
    L.append(f"                        return {general}")
    L.append(f"                    self._single_seen({lkey})")
    L.append("                else:  # its inputs may have any strides")
    sargs = list(params) + names
    L += ["                    " + x for x in _run_single(outs, sargs)]
    call = list(params)
    for a, s in zip(names, ins):
        if len(s) == 0:
            call.append(f"{a}.item()")
        elif len(s) == 1:
            call.append(f"*{a}.tolist()")
        else:
            call.append(f"*{a}.ravel().tolist()")
    L.append(f"                r = py({', '.join(call)})")
    L.append("                if out is None:")
    L += ["                    " + line for line in _pack_single(outs)]
    L.append("                return single_out(self, r, out, dt)")
    # -- one batch axis: index tests on the shapes (a slice costs ~60 ns each) -------
    patterns = [(None, tuple(False for _ in ins))]
    if len(ins) > 1:
        for j in range(len(ins)):
            patterns.append((j, tuple(k == j for k in range(len(ins)))))
    for j, bcast in patterns:
        others = [k for k in range(len(ins)) if k != j]
        ref = others[0]
        conds = [] if j is None else [f"s{j} == {tuple(ins[j])!r}"]
        for k in others:
            t = ins[k]
            if k != ref and t == ins[ref]:  # one tuple test for a shape already known
                conds.append(f"s{k} == s{ref}")
                continue
            conds.append(f"len(s{k}) == {1 + len(t)}")
            conds += [f"s{k}[{1 + d}] == {size}" for d, size in enumerate(t)]
            if k != ref:
                conds.append(f"s{k}[0] == s{ref}[0]")
        L.append(f"            elif {' and '.join(conds)} and K.BINDING is None:")
        L += _get_loop(f"E{_tag(bcast)}", params, 16)
        # A broadcast row of one axis is passed as it is (others are raveled).
        # Contiguity is the loop's to check (status 1: back to the general path).
        L.append(f"                n = s{ref}[0]")
        L.append("                if loop is not None and n < PMIN:")
        args = list(params)
        for k, (a, t) in enumerate(zip(names, ins)):
            args.append(f"{a}.ravel()" if bcast[k] and len(t) != 1 else a)
        L += ["                    " + line for line in _run_batch(outs, args)]
    L.append(f"    return {general}")
    return "\n".join(L) + "\n"


def _tag(bcast) -> str:
    """Name suffix of the ready-loop table of a broadcast pattern."""
    return "_" + "".join("b" if b else "n" for b in bcast)


def _pack_single(outs) -> list[str]:
    """Lines that return the one-element result ``r`` as arrays of dtype ``dt``."""
    if len(outs) == 1:
        s = outs[0]
        if len(s) == 1:
            return ["return array(r, dt)"]
        return [f"return array(r, dt).reshape({s!r})"]
    lines = ["flat = array(r, dt)"]
    parts, start = [], 0
    for s in outs:
        m = math.prod(s)
        if not s:
            parts.append(f"flat[{start}]")  # a NumPy scalar: shape ()
        elif len(s) == 1:
            parts.append(f"flat[{start}:{start + m}]")
        else:
            parts.append(f"flat[{start}:{start + m}].reshape({s!r})")
        start += m
    lines.append(f"return ({', '.join(parts)},)")
    return lines


def _shape_n(shape) -> str:
    """Source of the tuple ``(n, *shape)``."""
    return "(" + ", ".join(["n", *map(str, shape)]) + ("," if not shape else "") + ")"


def _run_batch(outs, args) -> list[str]:
    """:func:`_run_loop` of the batch loop: outputs of shape ``(n, *trail)``."""
    return _run_loop(outs, args, _shape_n, status=True)
