"""The sequential part of integration: running products of group elements.

``out[0] = x0``, ``out[k + 1] = chain(out[k], inc[k])`` along the step axis, for a
``chain`` kernel of :mod:`rigidkit.kernels.kinematics_integration` (``so3_chain``,
``se3_chain``: associative, normalising). Two bindings of the same kernel:

* NumPy with numba: one compiled loop over trajectories and steps, generated from
  the kernel's own source (as the engine generates its loops) and cached on disk
  next to the engine's. numba is imported only here, on the first call that is
  large enough (``COMPILE_MIN`` steps in all); smaller calls never wait for it.
  Many trajectories are split over the idle cores (threads, ``nogil``).
* Any other array namespace (torch, JAX, NumPy without numba): a parallel prefix
  product (Hillis-Steele doubling), ``log2(N)`` rounds of the chain kernel over
  whole arrays; built from slicing and concatenation only, so it traces under
  ``jax.jit`` and gradients flow through it. Its rounding grows with ``log N``
  rather than ``N``.
"""

from __future__ import annotations

import hashlib
import os
import sys
import threading

import numpy as np

from ..._engine import numba_backend as _nb
from ..._engine.namespace import is_numpy, namespace_of
from ..._engine.primitives import NUMBA_PRELUDE

#: Fewer steps than this (over all trajectories) take the array path, no compile.
COMPILE_MIN = int(os.environ.get("RIGIDKIT_SCAN_COMPILE_MIN", "20000"))

_LOCK = threading.Lock()
_SCANS: dict = {}


def _scan_source(chain, width: int) -> str:
    fns = [*chain.dependencies(), chain]
    parts = [NUMBA_PRELUDE]
    for f in fns:
        parts.append(
            "\n\n@numba.njit(inline='always', error_model='numpy')\n"
            + _nb.function_source(f.fn)
        )
    w = range(width)
    state = ", ".join(f"s{c}" for c in w)
    lines = [
        "@numba.njit(cache=CACHE, nogil=True, error_model='numpy')",
        "def scan(body, x0, inc, out):",
        "    n, steps = inc.shape[0], inc.shape[1]",
        "    for b in range(n):",
        *[f"        s{c} = x0[b, {c}]" for c in w],
        *[f"        out[b, 0, {c}] = s{c}" for c in w],
        "        for k in range(steps):",
        f"            r = {chain.name}(body, {state}, "
        + ", ".join(f"inc[b, k, {c}]" for c in w)
        + ")",
        *[f"            s{c} = r[{c}]" for c in w],
        *[f"            out[b, k + 1, {c}] = s{c}" for c in w],
    ]
    parts.append("\n\n" + "\n".join(lines) + "\n")
    return "\n".join(parts)


def _compiled(chain, width: int):
    """The numba scan of ``chain`` (imported from, or written to, the disk cache)."""
    key = (chain.name, width)
    scan = _SCANS.get(key)
    if scan is not None:
        return scan
    import importlib.util
    import tempfile

    import numba

    src = _scan_source(chain, width)
    digest = hashlib.sha1((src + numba.__version__).encode()).hexdigest()[:16]
    modname = f"rigidkit_scan_{chain.name}_{digest}"
    folder = _nb._cache_dir()
    with _LOCK:
        if key in _SCANS:
            return _SCANS[key]
        if folder is None:
            namespace = {"CACHE": False}
            exec(compile(src, f"<rigidkit scan {chain.name}>", "exec"), namespace)
            scan = namespace["scan"]
        else:
            path = os.path.join(folder, modname + ".py")
            if not os.path.exists(path):
                fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
                with os.fdopen(fd, "w") as fh:
                    fh.write("CACHE = True\n" + src)
                os.replace(tmp, path)
            spec = importlib.util.spec_from_file_location(modname, path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            sys.modules[modname] = module
            scan = module.scan
        _SCANS[key] = scan
    return scan


def running_product(chain, body: int, x0, inc):
    """``(..., N + 1, W)`` running products of ``x0`` (..., W) and ``inc`` (..., N, W).

    The batch shapes of ``x0`` and ``inc`` broadcast; ``chain(body, a, b)`` is the
    link (``a b`` for body frames, ``b a`` for world frames).
    """
    xp = namespace_of(x0, inc)
    width = inc.shape[-1]
    steps = inc.shape[-2]
    batch = tuple(np.broadcast_shapes(tuple(x0.shape[:-1]), tuple(inc.shape[:-2])))
    n = int(np.prod(batch, dtype=np.int64))
    if (
        is_numpy(xp)
        and isinstance(inc, np.ndarray)
        and n * steps >= COMPILE_MIN
        and _nb.available()
    ):
        return _numba_product(chain, body, x0, inc, batch, n, steps, width)
    return _doubling_product(chain, body, x0, inc, batch, xp)


def _numba_product(chain, body, x0, inc, batch, n, steps, width):
    dtype = np.result_type(x0.dtype, inc.dtype)
    x0 = np.ascontiguousarray(np.broadcast_to(x0, batch + (width,)), dtype).reshape(
        n, width
    )
    inc = np.ascontiguousarray(np.broadcast_to(inc, batch + (steps, width)), dtype).reshape(
        n, steps, width
    )
    out = np.empty((n, steps + 1, width), dtype)
    scan = _compiled(chain, width)
    workers = min(n, _nb._workers()) if n > 1 and n * steps >= 2 * COMPILE_MIN else 1
    if workers < 2:
        scan(body, x0, inc, out)
    else:
        bounds = [n * k // workers for k in range(workers + 1)]
        futures = [
            _nb._pool().submit(scan, body, x0[a:b], inc[a:b], out[a:b])
            for a, b in zip(bounds[1:-1], bounds[2:])
        ]
        scan(body, x0[: bounds[1]], inc[: bounds[1]], out[: bounds[1]])
        for f in futures:
            f.result()
    return out.reshape(batch + (steps + 1, width))


def _doubling_product(chain, body, x0, inc, batch, xp):
    steps = inc.shape[-2]
    width = inc.shape[-1]
    if tuple(inc.shape[:-2]) != batch:
        inc = xp.broadcast_to(inc, batch + (steps, width))
    prefix = inc
    shift = 1
    while shift < steps:
        # prefix[k] <- prefix[k - shift] * prefix[k]: after the round, prefix[k]
        # is the product of inc[max(0, k - 2 shift + 1) ... k], in order.
        later = chain(body, prefix[..., : steps - shift, :], prefix[..., shift:, :])
        prefix = xp.concat([prefix[..., :shift, :], later], axis=-2)
        shift *= 2
    if tuple(x0.shape[:-1]) != batch:
        x0 = xp.broadcast_to(x0, batch + (width,))
    head = x0[..., None, :]
    if steps == 0:
        return head
    rest = chain(body, xp.broadcast_to(head, batch + (steps, width)), prefix)
    return xp.concat([head, rest], axis=-2)
