"""Generate, compile, cache and load the fused numba loop of a kernel.

For each kernel we write one small Python module: the primitive prelude, the
source of the kernel and of every helper it calls, and a loop over the batch that
reads the components of each input, calls the kernel, and writes each output
component. The module lives in a cache folder named after a hash of its text, so
numba's on-disk cache is valid across processes and is refreshed whenever a
kernel changes.

Each loop is compiled for one explicit signature (per dtype and broadcast
pattern; see :func:`signature`), so a dispatcher never compiles again: an
argument that does not match raises ``TypeError`` instead of compiling on the
caller's thread. Inputs are typed read-only, which writable arrays convert to.

Loops are compiled or loaded from the disk cache by one background thread
(:func:`request`), which also imports numba: a caller never waits for numba's
import or a compile, and is served by the vectorised NumPy path until its loop
is ready. :func:`wait` blocks for a loop (tests and ``backend="numba"``), and
``python -m rigidkit._engine.numba_backend`` compiles every shipped kernel (an
install step: afterwards a fresh process only loads from disk).

A batch loop is compiled with ``nogil=True``; large batches are split over threads
(see :func:`run_loop`), so one compile serves the serial and the parallel path.
Loops are compiled without NRT (see :func:`loop_options`).
"""

from __future__ import annotations

import os
import sys
import threading

from .primitives import numba_prelude

_AVAILABLE = None
_LOCK = threading.Lock()
_POOL = None

#: A batch at least this long is split over threads (thread hand-off costs ~20 us).
PARALLEL_MIN = int(os.environ.get("RIGIDKIT_PARALLEL_MIN", "200000"))


def available() -> bool:
    """True when numba is installed and not disabled by RIGIDKIT_DISABLE_NUMBA.

    Does not import numba (that takes ~0.5 s; the background thread does it).
    """
    global _AVAILABLE
    if os.environ.get("RIGIDKIT_DISABLE_NUMBA", "") not in ("", "0"):
        return False
    if _AVAILABLE is None:
        import importlib.util

        try:
            _AVAILABLE = importlib.util.find_spec("numba") is not None
        except (ImportError, ValueError):  # pragma: no cover - broken install
            _AVAILABLE = False
    return _AVAILABLE


def _cache_dir() -> str | None:
    base = os.environ.get("RIGIDKIT_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "rigidkit"
    )
    path = os.path.join(base, "numba")
    try:
        os.makedirs(path, exist_ok=True)
        probe = os.path.join(path, ".probe")
        with open(probe, "w"):
            pass
        return path
    except OSError:
        return None


def function_source(fn) -> str:
    """Source of ``fn`` without decorators, dedented."""
    import inspect  # these imports cost ~20 ms, paid only when a kernel is compiled
    import textwrap

    src = textwrap.dedent(inspect.getsource(fn))
    lines = src.splitlines()
    start = next(i for i, line in enumerate(lines) if line.lstrip().startswith("def "))
    return "\n".join(lines[start:]) + "\n"


#: Rows at most this wide are read and written through flat 1-D views with a
#: constant stride (``a[4 * i + c]``), which LLVM vectorises; wider rows (3x3
#: matrices) stay 2-D (``a[i, c]``): a stride-9 interleaved store vectorises badly.
FLAT_MAX = 4


#: Outputs wider than ``FLAT_MAX`` whose last axis is this long (4x4 and 3x4
#: matrices), in a loop that writes more numbers than it reads, are written a row
#: at a time, each row one vector store (:func:`.numba_stores.store_row`): numba
#: writes a component at a time, and LLVM does not merge those stores. Such a loop
#: waits on its stores: SE(3) ``Transform.as_matrix`` (7 in, 16 out), with the
#: cheaper off-diagonal of ``matrix_entries_from_quat``, 4.7 -> 4.3 us at N = 1e3,
#: 41 -> 38 us at 1e4 (scipy's copy: 3.5 and 32); the loops of ``quat_left_matrix``
#: and ``se3.hat`` -35%, ``sim3_matrix`` -10%. A loop that computes more than it
#: stores waits on its arithmetic, and building the vectors costs it shuffles:
#: ``projective_compose`` (32 in, 16 out) +5%, so it keeps scalar stores.
ROW_STORE = 4


#: The broadcast pattern of a kernel's one-element loop: every input and output of
#: exactly its trailing shape (no batch axis), one evaluation, no loop.
SINGLE = "single"


def _single_source(kernel) -> str:
    """One evaluation on arrays of exactly their trailing shapes (see ``SINGLE``).

    Inputs are read by their own indices (``A0[1, 2]``), not through a flat view:
    they may be strided (see :func:`signature`).
    """
    nparams = len(kernel.params)
    args = [f"p{k}" for k in range(nparams)]
    pre, call = [], [f"p{k}" for k in range(nparams)]
    for k, shape in enumerate(kernel.inputs):
        args.append(f"A{k}")
        for c in range(_size(shape)):
            index, rest = [], c
            for d in reversed(shape):
                index.insert(0, str(rest % d))
                rest //= d
            call.append(f"A{k}[{', '.join(index) or '()'}]")  # 0-d: A[()]
    body = [f"    r = {kernel.name}({', '.join(call)})"]
    j = 0
    for k, shape in enumerate(kernel.outputs):
        args.append(f"O{k}")
        pre.append(f"    o{k} = O{k}.reshape({_size(shape)})")
        for c in range(_size(shape)):
            body.append(f"    o{k}[{c}] = r[{j}]")
            j += 1
    return f"def loop({', '.join(args)}):\n" + "\n".join(pre + body) + "\n"


def _loop_source(kernel, bcast=()) -> str:
    """The loop over the batch, on arrays of their natural shape.

    Arguments: the static parameters, one C-contiguous array per input of shape
    ``(n, *input_shape)`` (a broadcast input, flagged in ``bcast``: its single row,
    flattened), then one per output of shape ``(n, *output_shape)``. Rows at most
    ``FLAT_MAX`` wide are read through flat views with a constant stride
    (``a[4 * i + c]``), which LLVM vectorises; the loop runs over ``range(n)``
    (a known non-negative index). A broadcast row is read once, before the loop.
    """
    nparams = len(kernel.params)
    args = [f"p{k}" for k in range(nparams)]
    pre = ["    n = O0.shape[0]"]
    strided = []
    call = [f"p{k}" for k in range(nparams)]
    for k, shape in enumerate(kernel.inputs):
        args.append(f"A{k}")
        w = _size(shape)
        if k < len(bcast) and bcast[k]:
            strided += _stride_tests(f"A{k}", (w,), batch=False)
            pre += [f"    b{k}_{c} = A{k}[{c}]" for c in range(w)]
            call += [f"b{k}_{c}" for c in range(w)]
            continue
        # Its length too: a generated function may pass a caller's array whose
        # length it has not tested (dispatch.owned_source's user arrays).
        strided += [f"A{k}.shape[0] != n", *_stride_tests(f"A{k}", shape)]
        if w <= FLAT_MAX:
            pre.append(f"    a{k} = A{k}.reshape(A{k}.size)")
            call += [f"a{k}[{w} * i + {c}]" for c in range(w)]
        else:
            pre.append(f"    a{k} = A{k}.reshape(n, {w})")
            call += [f"a{k}[i, {c}]" for c in range(w)]
    body = [f"        r = {kernel.name}({', '.join(call)})"]
    j = 0
    for k, shape in enumerate(kernel.outputs):
        args.append(f"O{k}")
        w = _size(shape)
        if _row_stores(kernel, shape):
            pre.append(f"    o{k} = O{k}.reshape(O{k}.size)")
            for c in range(0, w, ROW_STORE):
                row = ", ".join(f"r[{j + d}]" for d in range(ROW_STORE))
                body.append(f"        store_row(o{k}, {w} * i + {c}, ({row},))")
                j += ROW_STORE
            continue
        if w <= FLAT_MAX:
            pre.append(f"    o{k} = O{k}.reshape(O{k}.size)")
        else:
            pre.append(f"    o{k} = O{k}.reshape(n, {w})")
        for c in range(w):
            target = f"o{k}[{w} * i + {c}]" if w <= FLAT_MAX else f"o{k}[i, {c}]"
            body.append(f"        {target} = r[{j}]")
            j += 1
    done = "    return 0"
    if kernel.vector_math:
        # Status 2 if any input or result is not finite, a NaN of the fast sin and
        # cos among them (|x| > 2^19): one sum an element, which a NaN or an
        # infinity keeps non-finite (a sum that overflows only costs a recompute).
        # The or-reduction of a flag vectorises; an early exit would not.
        terms = call[nparams:] + [f"r[{k}]" for k in range(j)]
        body += [f"        v = {' + '.join(terms)}", "        bad |= v - v != 0.0"]
        pre.append("    bad = False")
        done = "    return 2 if bad else 0"
    if strided:  # not C-contiguous, or short: status 1, nothing read or written
        pre[1:1] = [
            "    if n > 0:",
            f"        if {' or '.join(strided)}:",
            "            return 1",
        ]
    head = f"def loop({', '.join(args)}):\n"
    lines = pre + ["    for i in range(n):"] + body + [done]
    return head + "\n".join(lines) + "\n"


def _stride_tests(name, shape, batch=True) -> list[str]:
    """Tests that input ``name``, typed C-contiguous, is not, for a batch of n > 0.

    The fast entry passes an input's array without asking NumPy whether it is
    C-contiguous (``flags.c_contiguous`` costs ~0.05 us an input), so the loop
    asks instead, for nothing: an array's own strides travel with it, whatever
    its type says. ``shape``: the shape after the batch axis, or with
    ``batch=False`` the whole shape (a broadcast row). As in NumPy, an axis of
    length 1 may have any stride, and so may the batch axis of a batch of one.
    """
    tests, step = [], 1
    first = 1 if batch else 0
    for axis in reversed(range(len(shape))):
        if shape[axis] != 1:
            tests.append(f"{name}.strides[{first + axis}] != {step} * {name}.itemsize")
        step *= shape[axis]
    if batch:
        tests.append(f"(n > 1 and {name}.strides[0] != {step} * {name}.itemsize)")
    return tests


def _row_stores(kernel, shape) -> bool:
    """True if a batch loop writes this output a row at a time (see ``ROW_STORE``)."""
    w = _size(shape)
    return (
        w > FLAT_MAX
        and len(shape) > 0
        and shape[-1] == ROW_STORE
        and w > sum(_size(s) for s in kernel.inputs)
    )


def _size(shape) -> int:
    n = 1
    for s in shape:
        n *= s
    return n


def _has_star_call(fn) -> bool:
    """True if ``fn`` calls something with ``*args`` (numba cannot inline that).

    Read from the bytecode (``CALL_FUNCTION_EX``), not by ``ast.parse``: this runs
    on the background thread, and on CPython 3.11 before 3.11.8 two threads that
    build ``ast`` objects at once can make either raise ``SystemError: AST
    constructor recursion depth mismatch`` (CPython gh-106905), in the user's
    thread as much as in ours.
    """
    import dis

    def star(code) -> bool:
        ops = {i.opname for i in dis.get_instructions(code)}
        return "CALL_FUNCTION_EX" in ops or any(
            star(c) for c in code.co_consts if hasattr(c, "co_code")
        )

    return star(fn.__code__)


def module_source(kernel, bcast=(), nogil=False) -> str:
    fns = [*kernel.dependencies(), kernel]
    # With the fast atan2 where it pays (batch loops that numba can vectorise).
    parts = [
        numba_prelude(
            [f.fn for f in fns], batch=bcast != SINGLE, vector_math=kernel.vector_math
        )
    ]
    nargs = len(kernel.params) + sum(_size(s) for s in kernel.inputs)
    # Inlined at numba-IR level, the kernel and its helpers fuse into the loop body
    # (LLVM alone does not inline across numba functions). Numba's inliner cannot
    # take calls with *args, nor very long argument lists (32: a 4x4 times a 4x4).
    inline = nargs < 32 and not any(_has_star_call(f.fn) for f in fns)
    deco = (
        "@numba.njit(inline='always', error_model='numpy')"
        if inline
        else ("@numba.njit(error_model='numpy')")
    )
    for f in fns:
        parts.append("\n\n" + deco + "\n" + function_source(f.fn))
    loop = _single_source(kernel) if bcast == SINGLE else _loop_source(kernel, bcast)
    if bcast != SINGLE and any(_row_stores(kernel, s) for s in kernel.outputs):
        from .numba_stores import VERSION

        # The version is part of the source, hence of the module's name and cache.
        parts.append(
            f"\n\nfrom rigidkit._engine.numba_stores import store_row  # v{VERSION}\n"
        )
    parts.append("\n\n" + loop)
    # numba's disk cache is keyed by the source, not by the options: a loop cached
    # with other options must not be taken for this one.
    parts.append(f"\n# compiled with {sorted(loop_options(nogil).items())!r}\n")
    return "\n".join(parts)


def _module(kernel, bcast, nogil=False):
    """Import the generated module of ``kernel`` for broadcast pattern ``bcast``."""
    src = module_source(kernel, bcast, nogil)
    return import_source(
        f"rigidkit_k_{kernel.name}", src, f"<rigidkit kernel {kernel.name}>"
    )


def import_source(prefix: str, src: str, label: str):
    """Import generated source ``src``: ``(module, cached)``.

    The module is named ``prefix`` and a hash of ``src`` and numba's version, and
    written once to the cache folder, since numba's disk cache needs the function
    in a real file (``cached`` False: no writable folder, the source is executed
    in memory and numba must not cache it). ``label`` names it in tracebacks then.
    """
    import hashlib
    import importlib.util
    import tempfile

    import numba

    digest = hashlib.sha1((src + numba.__version__).encode()).hexdigest()[:16]
    modname = f"{prefix}_{digest}"
    folder = _cache_dir()
    with _LOCK:
        if modname in sys.modules:
            return sys.modules[modname], folder is not None
        if folder is None:
            module = type(sys)(modname)
            exec(compile(src, label, "exec"), module.__dict__)
            sys.modules[modname] = module
            return module, False
        path = os.path.join(folder, modname + ".py")
        if not os.path.exists(path):
            fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
            with os.fdopen(fd, "w") as fh:
                fh.write(src)
            os.replace(tmp, path)
        spec = importlib.util.spec_from_file_location(modname, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        sys.modules[modname] = module
        return module, True


def signature(kernel, bcast, dtype, ints=()):
    """The one numba signature of a loop: its parameters, read-only inputs, outputs.

    Parameters are int64 where ``ints`` says so (a kernel may index a tuple with
    one), float64 otherwise. Inputs are ``(n, *shape)`` arrays (a broadcast one
    its flat row) of ``dtype``, typed read-only so that read-only and writable
    arrays both match; outputs are writable ``(n, *shape)`` arrays.
    """
    from numba import types

    dt = types.float32 if dtype.itemsize == 4 else types.float64
    args = [types.int64 if i else types.float64 for i in ints]
    if bcast == SINGLE:
        # Inputs of any layout (one element: strides cost nothing), so that the
        # fast entry need not check their contiguity (~0.05 us per input).
        args += [types.Array(dt, len(s), "A", readonly=True) for s in kernel.inputs]
        args += [types.Array(dt, len(s), "C") for s in kernel.outputs]
        return types.void(*args)
    # A batch loop returns 1 for an input that is not C-contiguous (its strides
    # are checked in the loop, see _stride_tests), else 0.
    for k, shape in enumerate(kernel.inputs):
        ndim = 1 if (k < len(bcast) and bcast[k]) else 1 + len(shape)
        args.append(types.Array(dt, ndim, "C", readonly=True))
    args += [types.Array(dt, 1 + len(shape), "C") for shape in kernel.outputs]
    return types.int64(*args)


def compile_loop(kernel, bcast, dtype, ints=(), nogil=False):
    """The compiled loop of ``kernel`` (from the disk cache when it is there).

    One dispatcher per dtype and broadcast pattern, compiled for its single
    :func:`signature` only, with further compiles disabled; ``nogil``: the
    variant that releases the GIL, for a batch split over threads.
    """
    import numba

    module, cache = _module(kernel, bcast, nogil)
    sig = signature(kernel, bcast, dtype, ints)
    return numba.njit([sig], cache=cache, **loop_options(nogil))(module.loop)


def loop_options(nogil=False) -> dict:
    """The options a loop is compiled with (also written into its module's source).

    A loop allocates nothing, so it needs no NRT (numba's reference counting):
    without it a call unboxes each array without allocating a meminfo for it,
    ~0.1 us less per call (SE(3) compose at one element 1.23 -> 1.04 us). Loops
    keep the GIL: releasing and taking it back costs ~35 ns a call (compose at
    N = 10: 0.20 vs 0.17 us for the loop's call), which only a batch split over
    threads (``nogil=True``, at least ``PARALLEL_MIN`` long, see
    :func:`run_loop`) gets back. That variant is compiled when such a batch
    first comes, in the background; until it is ready, batches run on one thread.
    """
    return {"nogil": nogil, "error_model": "numpy", "_nrt": False}


# -- the background loader ---------------------------------------------------------
_JOBS = None
_PENDING: dict = {}
_THREAD = None


class _Job:
    __slots__ = (
        "kernel",
        "bcast",
        "dtype",
        "ints",
        "nogil",
        "build",
        "done",
        "loop",
        "error",
    )

    def __init__(self, kernel, bcast, dtype, ints, build=None, nogil=False):
        self.kernel, self.bcast, self.dtype, self.ints = kernel, bcast, dtype, ints
        self.nogil = nogil
        self.build = build
        self.done = threading.Event()
        self.loop = None
        self.error = None


def request(kernel, bcast, dtype, ints=(), nogil=False) -> _Job:
    """Queue the loop of ``kernel`` for the background thread (once per key).

    When it is ready the thread calls ``kernel._loop_ready(bcast, dtype, ints,
    loop, nogil)``; ``nogil``: the variant for threads (see :func:`loop_options`).
    """
    key = (id(kernel), bcast, dtype.char, ints, nogil)
    job = _PENDING.get(key)
    if job is not None:
        return job
    return _submit(key, lambda: _Job(kernel, bcast, dtype, ints, nogil=nogil))


def request_build(key, build) -> _Job:
    """Queue ``build()``, a compile that is not a kernel's loop, for the background
    thread (once per ``key``); its result becomes ``job.loop`` when ``job.done``.

    For compiled code generated outside the engine (the integration scan of
    :mod:`rigidkit.applications.kinematics._scan`), under the same policy as the
    loops: numba is imported and the code compiled off the caller's thread, and
    :func:`drain` waits for it.
    """
    key = ("build", key)
    job = _PENDING.get(key)
    if job is not None:
        return job
    return _submit(key, lambda: _Job(None, None, None, None, build))


def _submit(key, make) -> _Job:
    global _JOBS, _THREAD
    with _LOCK:
        job = _PENDING.get(key)
        if job is None:
            job = _PENDING[key] = make()
            if _JOBS is None:
                import queue

                _JOBS = queue.SimpleQueue()
            _JOBS.put(job)
            if _THREAD is None:
                # A daemon: a process that ends does not wait for a compile (the
                # next one finds whatever was finished in the disk cache).
                _THREAD = threading.Thread(target=_work, name="rigidkit-numba", daemon=True)
                _THREAD.start()
    return job


def wait(kernel, bcast, dtype, ints=(), nogil=False):
    """The loop of ``kernel``, blocking until the background thread has it."""
    job = request(kernel, bcast, dtype, ints, nogil)
    job.done.wait()
    if job.error is not None:
        raise job.error
    return job.loop


def drain(timeout=None) -> bool:
    """Wait until every loop requested so far is ready (benchmarks and tests).

    Returns False if ``timeout`` (seconds) ran out first.
    """
    import time

    end = None if timeout is None else time.monotonic() + timeout
    for job in list(_PENDING.values()):
        left = None if end is None else max(0.0, end - time.monotonic())
        if not job.done.wait(left):
            return False
    return True


def _work():
    global _AVAILABLE
    try:
        import numba  # noqa: F401
    except Exception as exc:  # pragma: no cover - depends on the machine
        _AVAILABLE = False
        error = RuntimeError(f"numba could not be imported: {exc}")
    else:
        error = None
    while True:
        job = _JOBS.get()
        try:
            if error is not None:
                raise error
            if job.build is not None:
                job.loop = job.build()
            else:
                job.loop = compile_loop(
                    job.kernel, job.bcast, job.dtype, job.ints, job.nogil
                )
                job.kernel._loop_ready(job.bcast, job.dtype, job.ints, job.loop, job.nogil)
        except BaseException as exc:  # noqa: BLE001 - handed to whoever waits
            job.error = exc
        job.done.set()


def _pool():
    global _POOL
    if _POOL is None:
        from concurrent.futures import ThreadPoolExecutor

        _POOL = ThreadPoolExecutor(max_workers=max(1, _ncpu()))
    return _POOL


def _ncpu() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - non-Linux
        return os.cpu_count() or 1


def _workers() -> int:
    """Threads for a large batch: ``RIGIDKIT_NUM_THREADS``, else the idle cores.

    Splitting pays only when the other cores are free: on a machine whose 1-minute
    load already fills them, a second thread just competes for the same core.
    """
    env = os.environ.get("RIGIDKIT_NUM_THREADS")
    if env:
        return max(1, int(env))
    n = _ncpu()
    try:
        # The load includes the thread running this call; the rest is other work.
        others = max(0.0, os.getloadavg()[0] - 1.0)
    except OSError:  # pragma: no cover - no load average on this platform
        others = 0.0
    return max(1, min(n, int(n - others + 0.5)))


def workers(n) -> int:
    """How many threads a batch of ``n`` is split over (1 below ``PARALLEL_MIN``)."""
    return 1 if n < PARALLEL_MIN else _workers()


def run_loop(loop, n, params, ins, bcast, outs, workers=1):
    """Run ``loop(*params, *ins, *outs)``, split over ``workers`` threads; returns
    its status (see :func:`_ran`).

    ``ins``/``outs`` are ``(n, ...)`` arrays, except the inputs flagged in
    ``bcast`` (one row for the whole batch). Each thread gets views of its rows;
    with more than one, ``loop`` must be the variant that releases the GIL.
    """
    if workers < 2:
        return _ran(loop(*params, *ins, *outs))

    def chunk(start, stop):
        args = list(params)
        args += [a if b else a[start:stop] for a, b in zip(ins, bcast)]
        args += [o[start:stop] for o in outs]
        return args

    bounds = [n * k // workers for k in range(workers + 1)]
    futures = [
        _pool().submit(loop, *chunk(bounds[k], bounds[k + 1])) for k in range(1, workers)
    ]
    status = _ran(loop(*chunk(bounds[0], bounds[1])))
    for f in futures:
        status = max(status, _ran(f.result()))
    return status


def _ran(status):
    """A loop's status on arrays made C-contiguous, returned: 0, or 2 (a non-finite
    input or result of a ``vector_math`` loop: the caller computes the call again).
    1 would be our bug, not the caller's: outputs left unwritten must never pass
    for results."""
    if status == 1:
        raise RuntimeError("a compiled loop refused C-contiguous inputs (status 1)")
    return status


def precompile(kernels, dtypes=("float64", "float32"), verbose=False) -> int:
    """Compile (or load) the plain loop (no broadcast input) of each of ``kernels``.

    Kernels with static parameters are left out: their loops are typed by the
    parameters' values (see :func:`signature`), compiled when first called.
    Returns how many loops were compiled or loaded. Meant for install time:
    ``python -m rigidkit.applications.precompile`` passes every shipped kernel,
    and a later process's background thread only loads the loops from disk.
    """
    import time

    import numpy as np

    count = 0
    for kern in kernels:
        if kern.params:
            continue
        bcast = (False,) * len(kern.inputs)
        for name in dtypes:
            t0 = time.perf_counter()
            loop = compile_loop(kern, bcast, np.dtype(name))
            kern._loop_ready(bcast, np.dtype(name), (), loop)
            count += 1
            if verbose:
                dt = time.perf_counter() - t0
                print(f"{kern.fn.__module__}.{kern.name} {name}: {dt * 1e3:.0f} ms")
    return count
