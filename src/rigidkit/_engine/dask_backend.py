"""Dask arrays: every kernel maps over the chunks, and checks wait for compute time.

A Dask array has no ``__array_namespace__``; reading it with ``np.asarray``
would compute the whole graph. Instead :func:`call` builds one
:func:`dask.array.blockwise` layer per kernel call: each chunk of the batch runs
the kernel's NumPy path (the compiled numba loop), and nothing is computed until
the user asks. Trailing (element) axes are made whole first; batch axes may be
chunked at will and broadcast like NumPy.

Validation (``rigidkit._validate``) cannot raise while the graph is built, so a
check of a Dask array is deferred (:func:`defer`): the same NumPy check runs on
each chunk at compute time, and its error names the GLOBAL batch index (the
chunk's offset added to the index within the chunk). The deferred check is then
made a dependency of the arrays the op returns:

* a check of values derived from a kernel's outputs (a norm, an orthonormality
  error) goes into those outputs (the most recent kernel call it depends on);
* a check of an op's input, made before the kernel call that consumes it, waits
  (per thread) for that call and goes into its outputs.

Attaching rewrites the output array in place (its graph and name), as Dask's own
``x[...] = v`` does; the outputs are fresh arrays of the op being built, so no
array the caller already holds changes. Checks on one output run in the order
they were made (each depends on the one before), so the first failing check of
an element decides the error, as in the eager path.

>>> import numpy as np, dask.array as da
>>> import rigidkit as rk
>>> q = da.from_array(np.array([[1.0, 0, 0, 0], [0, 0, 0, 0]]), chunks=(1, 4))
>>> unit = rk.conversions.quat_normalize(q)      # nothing computed yet
>>> try:
...     unit.compute()
... except rk.ZeroNormError as err:
...     print(err.index)
(1,)
"""

from __future__ import annotations

import importlib
import itertools
import math
import threading
import weakref

import numpy as np

from . import namespace as _namespace

_LETTERS = "abcdefghijklmnopqrstuvwxy"  # batch axes, then trailing ones; "z" is free


def is_dask(x) -> bool:
    """Whether ``x`` is a Dask collection (checked by module name: no import)."""
    if isinstance(x, (float, int, list, tuple)):  # TorchDynamo cannot read a builtin's
        return False  # __module__
    if _namespace.COMPILER._is_compiling_flag:  # nor a class's; and Dask never traces
        return False
    return type(x).__module__.startswith("dask")


# -- kernels over chunks -------------------------------------------------------------


def _kernel_ref(kernel):
    """What a worker process needs to find ``kernel``: its module and name if it is a
    module attribute (kernels are), else the object itself (thread schedulers)."""
    module = getattr(kernel.fn, "__module__", None)
    try:
        if getattr(importlib.import_module(module), kernel.name, None) is kernel:
            return (module, kernel.name)
    except (ImportError, TypeError, ValueError):
        pass
    return kernel


def _resolve(ref):
    if isinstance(ref, tuple):
        return getattr(importlib.import_module(ref[0]), ref[1])
    return ref


def _run_kernel(ref, params, outputs, nbatch, *blocks):
    """One chunk: the kernel's NumPy path, outputs packed along one trailing axis."""
    # Invalid input yields NaN here and is reported by the deferred checks, as the
    # eager path reports it from the kernel outputs: no NumPy warnings meanwhile.
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        res = _resolve(ref)(*params, *blocks)
    if len(outputs) == 1:
        return res
    batch = np.shape(res[0])[: np.ndim(res[0]) - len(outputs[0])]
    flat = [np.reshape(r, batch + (math.prod(s),)) for r, s in zip(res, outputs)]
    return np.concatenate(flat, axis=-1)


def call(kernel, params, arrays, dtype):
    """``kernel(*params, *arrays)`` on Dask (and NumPy) arrays, lazily, chunk by chunk.

    ``dtype`` is the result dtype (that of the NumPy path). Returns one Dask
    array per output (a tuple when there are several).
    """
    import dask.array as da

    nbs = [a.ndim - len(t) for a, t in zip(arrays, kernel.inputs)]
    nb = max(nbs)
    pairs, deps = [], set()
    used = nb
    for a, t, nbk in zip(arrays, kernel.inputs, nbs):
        trail = _LETTERS[used : used + len(t)]
        used += len(t)
        if is_dask(a):
            deps |= set(a.__dask_graph__().layers)
            if t:
                a = a.rechunk({a.ndim - 1 - k: -1 for k in range(len(t))})
        pairs += [a, _LETTERS[nb - nbk : nb] + trail]
    batch = _LETTERS[:nb]
    outs = kernel.outputs
    ref = _kernel_ref(kernel)
    if len(outs) == 1:
        trail = _LETTERS[used : used + len(outs[0])]
        new_axes = dict(zip(trail, outs[0]))
        combo = da.blockwise(
            _run_kernel, batch + trail, ref, None, params, None, outs, None, nb, None,
            *pairs, new_axes=new_axes, dtype=dtype, concatenate=True,
            meta=np.empty((0,) * (nb + len(outs[0])), dtype=dtype),
        )  # fmt: skip
        results = [combo]
    else:
        width = sum(math.prod(s) for s in outs)
        combo = da.blockwise(
            _run_kernel, batch + "z", ref, None, params, None, outs, None, nb, None,
            *pairs, new_axes={"z": width}, dtype=dtype, concatenate=True,
            meta=np.empty((0,) * (nb + 1), dtype=dtype),
        )  # fmt: skip
        results, k = [], 0
        for s in outs:
            m = math.prod(s)
            part = combo[..., k] if not s else combo[..., k : k + m]
            results.append(part if len(s) <= 1 else part.reshape(combo.shape[:-1] + s))
            k += m
    _register(results, [len(s) for s in outs], deps | {combo.name})
    return results[0] if len(results) == 1 else tuple(results)


# -- deferred checks -----------------------------------------------------------------


class _Group:
    """The outputs of one kernel call, the graph layers they depend on, their checks."""

    __slots__ = ("refs", "trails", "names", "deps", "last", "order")

    def __init__(self, outputs, trails, deps, order):
        self.refs = [weakref.ref(o) for o in outputs]
        self.trails = trails
        self.names = {o.name for o in outputs}
        self.deps = deps
        self.last = None  # the latest check attached, which the next one follows
        self.order = order


_COUNTER = itertools.count()
_LOCAL = threading.local()
_RECENT = 64  # groups and pending checks remembered per thread


def _state():
    if not hasattr(_LOCAL, "groups"):
        _LOCAL.groups = []
        _LOCAL.pending = []
    return _LOCAL


def _register(outputs, trails, deps):
    st = _state()
    group = _Group(outputs, trails, deps, next(_COUNTER))
    st.groups.append(group)
    del st.groups[:-_RECENT]
    # Checks of this call's inputs, made before it: they go into its outputs now.
    waiting = [p for p in st.pending if p[1] <= deps]
    for item in waiting:
        st.pending.remove(item)
        _attach(group, item[0])


def _check_block(check, args, relabel, ninputs, nbatch, *blocks):
    """One chunk of a deferred check; an error gets the global batch index."""
    from ..errors import RigidkitError

    arrays, offsets = blocks[:ninputs], blocks[ninputs : ninputs + nbatch]
    try:
        check(*arrays, *args)
    except RigidkitError as err:
        if not err.index:
            raise
        glob = tuple(int(off[i]) for off, i in zip(offsets, err.index))
        raise relabel(err, glob) from None
    return np.zeros((1,) * nbatch, dtype=bool)


def defer(check, arrays, args, relabel, trails=None):
    """Run ``check(*numpy_chunks, *args)`` per chunk of ``arrays`` at compute time.

    An error it raises is replaced by ``relabel(err, global_index)`` (the same
    error naming the index in the whole array; ``_validate`` words messages).

    ``arrays[0]`` is a Dask array whose batch shape the check indexes (a mask,
    or the checked array with ``trails[0]`` trailing axes); each other array (or
    ``None``) has the same batch axes and ``trails[k]`` trailing axes (default:
    all its axes beyond the batch). The check raises a
    :class:`~rigidkit.errors.RigidkitError` with an index within the chunk.
    """
    import dask.array as da

    trails = trails or (0,) * len(arrays)
    ref = arrays[0]
    nb = ref.ndim - trails[0]
    batch = _LETTERS[:nb]
    pairs, names, layers, used = [], set(), set(), nb
    for a, t in zip(arrays, trails):
        if a is None:
            pairs += [None, None]
            continue
        t = t if t else a.ndim - nb if a is not ref else 0
        trail = _LETTERS[used : used + t]
        used += t
        if is_dask(a):
            names.add(a.name)
            layers |= set(a.__dask_graph__().layers)
            if t:
                a = a.rechunk({a.ndim - 1 - k: -1 for k in range(t)})
        pairs += [a, batch[nb - (a.ndim - t) :] + trail]
    chunkss, offsets = _unify_with_offsets(pairs, batch)

    def build(prev):
        # ``prev``, the check attached before on the same outputs, is an input:
        # this one runs on a chunk only once that one has passed there.
        after = []
        if prev is not None:
            if prev.ndim == nb and prev.numblocks == tuple(len(chunkss[x]) for x in batch):
                after = [prev, batch]
            else:
                after = [prev.all(), ""]
        return da.blockwise(
            _check_block, batch, check, None, tuple(args), None, relabel, None,
            len(arrays), None,
            nb, None, *pairs, *offsets, *after, adjust_chunks=dict.fromkeys(batch, 1),
            dtype=bool, concatenate=True, meta=np.empty((0,) * nb, dtype=bool),
            align_arrays=False,
        )  # fmt: skip

    st = _state()
    for group in reversed(st.groups):
        # The newest kernel call the checked values come from, or that consumed them.
        if group.names & layers or (names and names <= group.deps):
            _attach(group, build)
            return
    st.pending.append((build, frozenset(names)))
    del st.pending[:-_RECENT]


def _first(x, *checks):
    return x


def _attach(group, build):
    """Make the check ``build(group.last)`` a dependency of every live output of
    ``group``, in place."""
    import dask.array as da

    chk = group.last = build(group.last)
    for ref, t in zip(group.refs, group.trails):
        out = ref()
        if out is None:
            continue
        nb = out.ndim - t
        ind = _LETTERS[: out.ndim]
        c = chk
        cind = ind[nb - c.ndim : nb] if c.ndim <= nb else None
        if cind is None or any(
            c.numblocks[i] not in (1, out.numblocks[nb - c.ndim + i]) for i in range(c.ndim)
        ):
            c, cind = c.all(), ""  # one check block for all
        new = da.blockwise(
            _first, ind, out, ind, c, cind, align_arrays=False, dtype=out.dtype,
            meta=out._meta,
        )  # fmt: skip
        out.dask = new.dask
        out._name = new.name
        group.names.add(new.name)


# -- host-side algorithms over chunks -------------------------------------------------


def _run_batched(fn, relabel, nin, nb, *blocks):
    """One chunk of :func:`map_batched`: ``fn`` on NumPy blocks, errors relabelled."""
    from ..errors import RigidkitError

    arrays, offsets = blocks[:nin], blocks[nin : nin + nb]
    try:
        res = fn(*arrays)
    except RigidkitError as err:
        if not err.index or relabel is None:
            raise
        glob = tuple(int(off[i]) for off, i in zip(offsets, err.index))
        raise relabel(err, glob + tuple(err.index[len(glob) :])) from None
    return res if isinstance(res, tuple) else (res,)


def _pick(block, k):
    return block[k]


def map_batched(fn, arrays, trails, relabel=None, outputs=None):
    """``fn(*numpy_blocks)`` per chunk of the batch: one independent problem per element.

    For host-side algorithms (an SVD, an eigen-solve, a search) that are not one
    kernel but solve each batch element on its own. ``arrays`` (Dask, NumPy or
    ``None``) have leading batch axes, aligned from the right as in NumPy
    broadcasting, and ``trails[k]`` trailing problem axes, which are made whole
    (one chunk); batch axes stay chunked. ``fn`` returns one array or a tuple,
    each with the block's batch shape followed by ``outputs[k] = (trailing shape,
    dtype)``. An error ``fn`` raises naming an index within the chunk is replaced
    by ``relabel(err, global_index)`` at compute time (trailing index entries,
    beyond the batch, are kept). Returns one Dask array per output (a tuple when
    there are several); nothing is computed.

    Without ``outputs``, ``fn`` first runs on empty NumPy arrays (a leading axis of
    length 0 added): that raises its static errors (shapes, counts) now, as the
    NumPy path would, and gives the outputs' trailing shapes and dtypes.
    """
    import dask.array as da

    nbs = [None if a is None else a.ndim - t for a, t in zip(arrays, trails)]
    nb = max(n for n in nbs if n is not None)
    if outputs is None:
        empty = [None if a is None else np.zeros((0,) + a.shape, a.dtype) for a in arrays]
        probe = fn(*empty)
        probe = probe if isinstance(probe, tuple) else (probe,)
        outputs = [(tuple(r.shape[1 + nb :]), r.dtype) for r in probe]
    batch = _LETTERS[:nb]
    pairs, used = [], nb
    for a, t, nbk in zip(arrays, trails, nbs):
        if a is None:
            pairs += [None, None]
            continue
        trail = _LETTERS[used : used + t]
        used += t
        if not is_dask(a):
            a = da.asarray(np.asarray(a))
        if t:
            a = a.rechunk({a.ndim - 1 - k: -1 for k in range(t)})
        pairs += [a, batch[nb - nbk :] + trail]
    chunkss, offsets = _unify_with_offsets(pairs, batch)
    combo = da.blockwise(
        _run_batched, batch, fn, None, relabel, None, len(arrays), None, nb, None,
        *pairs, *offsets, concatenate=True, dtype=object,
        meta=np.empty((0,) * nb, dtype=object), align_arrays=False,
    )  # fmt: skip
    results = []
    for k, (shape, dtype) in enumerate(outputs):
        trail = _LETTERS[used : used + len(shape)]
        results.append(
            da.blockwise(
                _pick,
                batch + trail,
                combo,
                batch,
                k,
                None,
                new_axes=dict(zip(trail, shape)),
                dtype=dtype,
                meta=np.empty((0,) * (nb + len(shape)), dtype=dtype),
            )  # fmt: skip
        )
    return results[0] if len(results) == 1 else tuple(results)


def any_dask(*xs) -> bool:
    """Whether any of ``xs`` is a Dask collection."""
    return any(type(x) is not np.ndarray and is_dask(x) for x in xs)


def _unify_with_offsets(pairs, batch):
    """Unify the chunks of ``pairs`` (array, index letters, ...) in place; return the
    chunks per letter and, per batch letter, the global index of each element as a
    blockwise argument, so that a check run per chunk names the global batch index."""
    import dask.array as da
    from dask.array.core import unify_chunks

    chunkss, unified = unify_chunks(*pairs)
    pairs[::2] = unified
    offsets = []
    for letter in batch:
        chunks = chunkss[letter]
        offsets += [da.arange(sum(chunks), chunks=(chunks,)), letter]
    return chunkss, offsets
