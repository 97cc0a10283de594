"""Host loops: compiled code that is not a kernel's loop, under the engine's policy.

Two kinds of algorithm of the layers above need a compiled loop of their own:

* a sequential scan (the running products of ``rk.kinematics``' integration):
  :func:`compile_scan` generates it from a ``chain`` kernel (the text of
  :func:`.loop_source.scan_source`) and compiles it; :func:`compile_fold`
  likewise a fold that keeps only the last state and sums (IMU preintegration:
  a window's product, bias Jacobians and covariance in one pass);
* a plain Python function written in numba's subset (the Gram pass and 4x4
  Jacobi solve of the chordal mean, in ``functional/averaging.py``):
  :func:`compile_host_loop` compiles it for the signatures it declares.

Both are compiled like the kernels' loops, with explicit signatures (a call
never compiles again; an argument that does not match raises ``TypeError``),
cached on disk, and only ever on the engine's one background thread: a caller
asks :func:`.numba_backend.in_background` for a build that calls one of these,
keeps serving its calls another way until the job is done, and never imports
numba itself. :func:`run_split` (from :mod:`.numba_backend`) splits a call over
the idle cores.

An argument is declared by a short code: ``"rN"`` a read-only C-contiguous
N-dimensional array of the loop's dtype (writable arrays match it too), ``"wN"``
a writable one, ``"rN:uint8"`` / ``"wN:int64"`` of another NumPy dtype,
``"bool"``, ``"int"`` (int64) or ``"float"`` (of the loop's dtype).
"""

from __future__ import annotations

from . import compile_warnings
from .loop_source import fold_source, scan_source
from .numba_backend import idle_workers, import_source, run_split

__all__ = ["compile_fold", "compile_host_loop", "compile_scan", "idle_workers", "run_split"]


def _types(args, dtype):
    """numba types of the argument codes ``args`` (see the module doc) for ``dtype``."""
    import numba
    import numpy as np
    from numba import types

    dt = types.float32 if dtype.itemsize == 4 else types.float64
    scalars = {"bool": types.boolean, "int": types.int64, "float": dt}
    out = []
    for code in args:
        if code in scalars:
            out.append(scalars[code])
        elif code[:1] in ("r", "w") and code[1:].partition(":")[0].isdigit():
            ndim, _, other = code[1:].partition(":")
            of = numba.from_dtype(np.dtype(other)) if other else dt
            out.append(types.Array(of, int(ndim), "C", readonly=code[0] == "r"))
        else:
            raise ValueError(f"unknown argument code {code!r}")
    return out


def compile_host_loop(fn, args, dtypes=("float64", "float32"), *, returns=(), nogil=False):
    """``fn`` compiled by numba for ``args`` (argument codes) in each of ``dtypes``.

    ``fn`` is written in numba's subset of Python and NumPy and returns nothing
    (it writes its outputs), or a tuple of the scalar codes ``returns``
    (``("int", "int")``); numba caches it next to its module. One
    dispatcher serves every dtype (chosen by its arguments' types). ``nogil``:
    it releases the GIL, for a call split over threads (:func:`run_split`).
    Called from a build of :func:`.numba_backend.in_background`, never on a
    caller's thread.
    """
    import numba
    import numpy as np
    from numba import types

    sigs = []
    for d in dtypes:
        res = types.void
        if returns:
            res = types.Tuple(_types(returns, np.dtype(d)))
        sigs.append(res(*_types(args, np.dtype(d))))
    compile_warnings.before_compile()  # numba may compile: its imports isolated
    return numba.njit(sigs, cache=True, nogil=nogil, error_model="numpy")(fn)


def compile_scan(chain, dtype):
    """The compiled ``scan(body, x0, inc, out)`` of a ``chain`` kernel for ``dtype``.

    ``out[b, 0] = x0[b]`` and ``out[b, k + 1] = chain(body, out[b, k], inc[b,
    k])``: ``body`` an int, ``x0`` (n, W) and ``inc`` (n, N, W) C-contiguous,
    ``out`` (n, N + 1, W), W the width of the chain's output. Generated from the
    chain's own source (:func:`.loop_source.scan_source`), cached on disk next to
    the kernels' loops, and releasing the GIL (trajectories split over threads
    with :func:`run_split`). Called from a build of
    :func:`.numba_backend.in_background`.
    """
    import numba
    from numba import types

    width = chain.outputs[0][0]
    module, cache = import_source(
        f"rigidkit_scan_{chain.name}",
        scan_source(chain, width),
        f"<rigidkit scan {chain.name}>",
    )
    sig = types.void(types.int64, *_types(("r2", "r3", "w3"), dtype))
    compile_warnings.before_compile()  # numba may compile: its imports isolated
    return numba.njit([sig], cache=cache, nogil=True, error_model="numpy")(module.scan)


def compile_fold(step, carried, summed, inputs, dtype):
    """The compiled ``fold(x0, in0, ..., out)`` of a ``step`` helper for ``dtype``.

    ``x0`` (n, carried + summed), each ``in_j`` (n, N, inputs[j]) and ``out`` (n,
    carried + summed), C-contiguous: the running state and sums of
    :func:`.loop_source.fold_source`, cached on disk next to the kernels' loops,
    releasing the GIL (windows split over threads with :func:`run_split`).
    Called from a build of :func:`.numba_backend.in_background`.
    """
    import numba
    from numba import types

    module, cache = import_source(
        f"rigidkit_fold_{step.name}",
        fold_source(step, carried, summed, tuple(inputs)),
        f"<rigidkit fold {step.name}>",
    )
    codes = ("r2",) + ("r3",) * len(inputs) + ("w2",)
    sig = types.void(*_types(codes, dtype))
    compile_warnings.before_compile()  # numba may compile: its imports isolated
    return numba.njit([sig], cache=cache, nogil=True, error_model="numpy")(module.fold)
