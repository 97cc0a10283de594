"""The sequential part of integration: running products of group elements.

``out[0] = x0``, ``out[k + 1] = chain(out[k], inc[k])`` along the step axis, for a
``chain`` kernel (``so3_chain``, ``se3_chain`` of
:mod:`rigidkit.kernels.kinematics.integration`, ``se2_chain`` of
:mod:`rigidkit.kernels.kinematics.planar`: associative, normalising). Two
bindings of the same kernel:

* NumPy with numba: one compiled loop over trajectories and steps, which the
  engine generates from the kernel's own source (:func:`rigidkit._engine.compile_scan`),
  compiled for one signature per dtype and cached on disk next to the kernels'
  loops. Like those loops it is compiled (or loaded from the cache) by the
  engine's background thread (:func:`rigidkit._engine.in_background`), never on
  the caller's: a call
  made before it is ready runs the prefix product below, by chunks of
  ``CHUNK`` elements, and hands the rest to the scan if it lands meanwhile
  (3.6 M steps: 2.6 s for the first call of a fresh process with an empty cache,
  where compiling on the caller's thread took 5.3 s). It is asked for by calls
  of at least ``COMPILE_MIN`` steps in all, before their increments are computed
  (:func:`prepare`), so that a cached scan is usually loaded by the time they are
  needed. Many trajectories are split over the idle cores (threads, ``nogil``).
* Any other array namespace (torch, JAX, NumPy without numba or before the scan is
  ready): a work-efficient parallel prefix product (Ladner-Fischer / Blelloch):
  the pairs ``x[2i] x[2i+1]`` are multiplied, their prefix products found
  recursively, and the even entries completed with one more product: about
  ``2 N`` chain evaluations over whole arrays in ``log2(N)`` rounds (the earlier
  Hillis-Steele doubling took ``N log2(N)``: 10.6 s against 1.2 s at 3.6 M steps
  on element-wise NumPy). Built from slicing, stacking and concatenation only, so
  it traces under ``jax.jit`` (on JAX arrays it runs as one jitted program) and
  gradients flow through it. Its rounding grows with ``log N`` rather than ``N``.
"""

from __future__ import annotations

import math
import os
from functools import partial

import numpy as np

from ..._engine import (
    compile_scan,
    dask_backend,
    idle_workers,
    in_background,
    is_numpy,
    is_torch,
    namespace_of,
    numba_available,
    run_split,
)

#: Calls of fewer steps than this (over all trajectories) never ask for the
#: compiled scan: the prefix product serves them in well under a millisecond more.
COMPILE_MIN = int(os.environ.get("RIGIDKIT_SCAN_COMPILE_MIN", "20000"))

#: The compiled scans that are ready, by (chain name, width, dtype char).
_SCANS: dict = {}


def _build(chain, width: int, dtype):
    """Compile (or load from the disk cache) the scan of ``chain`` for ``dtype``.

    Runs on the engine's background thread (:func:`rigidkit._engine.compile_scan`
    generates and compiles it); the scan is served from ``_SCANS`` once there.
    """
    scan = compile_scan(chain, dtype)
    _SCANS[(chain.name, width, dtype.char)] = scan
    return scan


def _request(chain, width: int, dtype):
    return in_background(
        ("scan", chain.name, width, dtype.char), lambda: _build(chain, width, dtype)
    )


def prepare(chain, x0, rate, steps: int) -> None:
    """Ask for the compiled scan of a coming call (before its increments are made).

    A no-op off NumPy, without numba, or below ``COMPILE_MIN`` steps in all.
    """
    if not (isinstance(rate, np.ndarray) and numba_available()):
        return
    batch = np.broadcast_shapes(tuple(x0.shape[:-1]), tuple(rate.shape[:-2]))
    if int(np.prod(batch, dtype=np.int64)) * steps < COMPILE_MIN:
        return
    dtype = np.result_type(x0.dtype, rate.dtype)
    if dtype.kind == "f" and dtype.itemsize in (4, 8):
        _request(chain, _width(chain), dtype)


def _width(chain) -> int:
    return chain.outputs[0][0]


def wait(chain, dtype) -> None:
    """Block until the compiled scan of ``chain`` for ``dtype`` is ready (tests)."""
    _request(chain, _width(chain), np.dtype(dtype)).result()


def running_product(chain, body: int, x0, inc):
    """``(..., N + 1, W)`` running products of ``x0`` (..., W) and ``inc`` (..., N, W).

    The batch shapes of ``x0`` and ``inc`` broadcast; ``chain(body, a, b)`` is the
    link (``a b`` for body frames, ``b a`` for world frames). The compiled scan
    runs when it is ready (never waited for); otherwise the prefix product, by
    chunks on NumPy, so that a scan that becomes ready during a long call serves
    the rest of it.
    """
    if dask_backend.any_dask(x0, inc):
        return _dask_product(chain, body, x0, inc)
    xp = namespace_of(x0, inc)
    width = inc.shape[-1]
    steps = inc.shape[-2]
    # plain Python on the shapes: nothing NumPy runs in a call torch.compile traces
    batch = _broadcast(tuple(x0.shape[:-1]), tuple(inc.shape[:-2]))
    n = math.prod(batch)
    if is_numpy(xp) and isinstance(inc, np.ndarray) and n * steps >= COMPILE_MIN:
        dtype = np.result_type(x0.dtype, inc.dtype)
        key = (chain.name, width, dtype.char)
        scan = _SCANS.get(key)
        if scan is not None:
            return _numba_product(scan, body, x0, inc, batch, n, steps, width, dtype)
        prepare(chain, x0, inc, steps)
        return _chunked_product(chain, body, key, x0, inc, batch, n, steps, dtype)
    if not is_torch(inc) and (
        type(inc).__module__.startswith("jax") or type(x0).__module__.startswith("jax")
    ):
        return _jax_prefix()(chain, int(body), x0, inc, batch)
    return _prefix_product(chain, body, x0, inc, batch, xp)


def _dask_product(chain, body, x0, inc):
    """:func:`running_product` of Dask arrays, lazily: each chunk of the batch is
    one NumPy call (the compiled scan or the prefix product) with the step axis
    whole (the scan runs along it); the batch axes stay chunked as given."""
    import dask.array as da

    width = inc.shape[-1]
    steps = inc.shape[-2]
    batch = _broadcast(tuple(x0.shape[:-1]), tuple(inc.shape[:-2]))
    x0 = da.broadcast_to(da.asarray(x0), batch + (width,))
    inc = da.broadcast_to(da.asarray(inc), batch + (steps, width))
    dtype = np.result_type(x0.dtype, inc.dtype)
    return dask_backend.map_batched(
        partial(running_product, chain, body),
        [x0, inc],
        [1, 2],
        outputs=[((steps + 1, width), dtype)],
    )


def _dask_sum(inc):
    """:func:`running_sum` of a Dask array: per chunk of the batch, the step axis
    whole."""
    shape = (inc.shape[-2] + 1, inc.shape[-1])
    return dask_backend.map_batched(running_sum, [inc], [2], outputs=[(shape, inc.dtype)])


def _broadcast(a: tuple, b: tuple) -> tuple:
    """``np.broadcast_shapes(a, b)`` in plain Python (the shapes broadcast)."""
    n = max(len(a), len(b))
    a = (1,) * (n - len(a)) + a
    b = (1,) * (n - len(b)) + b
    return tuple(y if x == 1 else x for x, y in zip(a, b))


_JAX_PREFIX = None


def _jax_prefix():
    """The prefix product as one ``jax.jit`` program (cached per chain and shapes).

    Eager JAX compiles every operation for every new shape, and each level of the
    prefix scheme has new shapes: 200 steps took ~8 s eagerly, ~1 s as one program
    (later calls of the same shapes: none). Under an outer ``jit``, ``vmap`` or
    ``grad`` this is an ordinary nested ``jit``.
    """
    global _JAX_PREFIX
    if _JAX_PREFIX is None:
        import jax

        def run(chain, body, x0, inc, batch):
            return _prefix_product(chain, body, x0, inc, batch, namespace_of(x0, inc))

        _JAX_PREFIX = jax.jit(run, static_argnums=(0, 1, 4))
    return _JAX_PREFIX


#: Elements (trajectories x steps) per chunk of a prefix product that waits for
#: the compiled scan: ~0.1 s each, so a scan that lands mid-call takes over soon.
CHUNK = 1 << 18


def _chunked_product(chain, body, key, x0, inc, batch, n, steps, dtype):
    """The NumPy prefix product chunk by chunk along the steps, each chunk starting
    from the last state, switching to the compiled scan as soon as it is ready."""
    width = inc.shape[-1]
    out = np.empty(batch + (steps + 1, width), dtype)
    out[..., 0, :] = x0
    state = out[..., 0, :]
    m = max(1, CHUNK // max(n, 1))
    k = 0
    while k < steps:
        scan = _SCANS.get(key)
        if scan is not None:
            rest = inc[..., k:, :]
            out[..., k:, :] = _numba_product(
                scan, body, state, rest, batch, n, steps - k, width, dtype
            )
            break
        part = _prefix_product(chain, body, state, inc[..., k : k + m, :], batch, np)
        out[..., k + 1 : k + m + 1, :] = part[..., 1:, :]
        k = min(k + m, steps)
        state = out[..., k, :]
    return out


def _numba_product(scan, body, x0, inc, batch, n, steps, width, dtype):
    x0 = np.ascontiguousarray(np.broadcast_to(x0, batch + (width,)), dtype).reshape(
        n, width
    )
    inc = np.ascontiguousarray(np.broadcast_to(inc, batch + (steps, width)), dtype).reshape(
        n, steps, width
    )
    out = np.empty((n, steps + 1, width), dtype)
    workers = min(n, idle_workers()) if n > 1 and n * steps >= 2 * COMPILE_MIN else 1
    if workers < 2:
        scan(body, x0, inc, out)
    else:
        run_split(scan, n, workers, lambda a, b: (body, x0[a:b], inc[a:b], out[a:b]))
    return out.reshape(batch + (steps + 1, width))


def _prefix_product(chain, body, x0, inc, batch, xp):
    width = inc.shape[-1]
    if tuple(x0.shape[:-1]) != batch:
        x0 = xp.broadcast_to(x0, batch + (width,))
    if tuple(inc.shape[:-2]) != batch:
        inc = xp.broadcast_to(inc, batch + tuple(inc.shape[-2:]))
    # x0 is the earliest factor: the running products are the prefixes of [x0, inc].
    seq = xp.concat([x0[..., None, :], inc], axis=-2)
    # On NumPy the chain runs element-wise (backend="xp"): its own compiled loops
    # would be background compiles for a path the compiled scan replaces.
    kw = {"backend": "xp"} if is_numpy(xp) else {}
    return _prefixes(lambda a, b: chain(body, a, b, **kw), seq, xp)


def running_sum(inc):
    """``(..., N + 1, W)``: 0, ``inc[0]``, ``inc[0] + inc[1]``, ...: the running
    product of an abelian group written additively (SO(2) angles), by the same
    prefix scheme (rounding grows with ``log N``, where ``cumsum``'s grows with
    ``N``)."""
    if dask_backend.any_dask(inc):
        return _dask_sum(inc)
    xp = namespace_of(inc)
    seq = xp.concat([0.0 * inc[..., :1, :], inc], axis=-2)
    return _prefixes(lambda a, b: a + b, seq, xp)


def _prefixes(link, x, xp):
    """Inclusive prefix products of ``x`` (..., n, W) along axis -2, in order."""
    n = x.shape[-2]
    if n == 1:
        return x
    m = n // 2
    pairs = link(x[..., 0 : 2 * m : 2, :], x[..., 1 : 2 * m : 2, :])
    odd = _prefixes(link, pairs, xp)  # odd[i]: the product of x[0 .. 2i + 1]
    # The even entries: x[0], then odd[i - 1] x[2i].
    even = xp.concat(
        [x[..., :1, :], link(odd[..., : (n - 1) // 2, :], x[..., 2::2, :])], axis=-2
    )
    lead = tuple(x.shape[:-2])
    width = x.shape[-1]
    both = xp.reshape(xp.stack([even[..., :m, :], odd], axis=-2), lead + (2 * m, width))
    return both if n == 2 * m else xp.concat([both, even[..., m:, :]], axis=-2)
