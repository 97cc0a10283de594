"""Compile, cache and load the numba loops of kernels, on one background thread.

The loop of a kernel (per dtype and broadcast pattern) is generated as the text
of a small module (:mod:`.loop_source`), written to a cache folder under a name
that hashes its text, so numba's on-disk cache is valid across processes and is
refreshed whenever a kernel changes (:func:`import_source`).

Each loop is compiled for one explicit signature (see :func:`signature`), so a
dispatcher never compiles again: an argument that does not match raises
``TypeError`` instead of compiling on the caller's thread. Inputs are typed
read-only, which writable arrays convert to.

Every compile of the library runs on ONE background thread, ``rigidkit-numba``
(:func:`request` for a kernel's loop, :func:`in_background` for any other build:
the compiled host loops of :mod:`.host_loops`), which also imports numba: a
caller never waits for numba's import or a compile, and is served by the
vectorised NumPy path until its loop is ready. :func:`wait` blocks for a loop
(tests and ``backend="numba"``), :func:`drain` for every compile requested so
far, and ``python -m rigidkit.applications.precompile`` compiles every shipped
kernel (an install step: afterwards a fresh process only loads from disk).

Loops keep the GIL and are compiled without NRT (see
:func:`.loop_source.loop_options`); a batch of at least ``PARALLEL_MIN`` is
split over threads (:func:`run_loop`) by the variant compiled with
``nogil=True``, which is requested when the first such batch comes.
"""

from __future__ import annotations

import os
import sys
import threading

from .loop_source import SINGLE, loop_options, module_source
from .numba_loads import jit_signatures, switch_back, switch_fast

__all__ = [
    "PARALLEL_MIN",
    "SINGLE",
    "available",
    "cache_dir",
    "compile_loop",
    "drain",
    "idle_workers",
    "in_background",
    "jit_signatures",
    "module_source",
    "precompile",
    "request",
    "run_loop",
    "run_split",
    "wait",
    "workers",
]

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


def cache_dir() -> str | None:
    """The folder of the generated modules and numba's cache (None: not writable):
    ``$RIGIDKIT_CACHE_DIR/numba``, else ``~/.cache/rigidkit/numba``."""
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
    folder = cache_dir()
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
    module, cache = _module(kernel, bcast, nogil)
    sig = signature(kernel, bcast, dtype, ints)
    return jit_signatures(module.loop, [sig], cache, **loop_options(nogil))


# -- the background loader ---------------------------------------------------------
_JOBS = None
_PENDING: dict = {}
_THREAD = None


class _Job:
    """One compile of the background thread: ``done`` is set when ``loop`` (the
    result) or ``error`` is."""

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

    def result(self, timeout=None):
        """The compiled result, blocking until it is there (its error is raised)."""
        if not self.done.wait(timeout):
            raise TimeoutError(f"a rigidkit compile took more than {timeout} s")
        if self.error is not None:
            raise self.error
        return self.loop


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


def in_background(key, build) -> _Job:
    """Queue ``build()`` for the background thread, once per ``key``: a compile
    that is not a kernel's loop (a host loop of :mod:`.host_loops`).

    Its result becomes ``job.loop`` when ``job.done`` is set (``job.result()``
    waits for it). Under the same policy as the kernels' loops: numba is
    imported and the code compiled off the caller's thread, one compile at a
    time, and :func:`drain` waits for it.
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
    return request(kernel, bcast, dtype, ints, nogil).result()


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
    switch_fast()  # numba's import first, at the quicker GIL hand-over
    # numba's warning filters and recordings kept on this thread (see compile_warnings).
    from . import compile_warnings

    with compile_warnings.isolate():
        _serve(compile_warnings)


def _serve(compile_warnings):
    global _AVAILABLE
    # Before numba's first import: no colorama in its error messages (see _plain_errors).
    os.environ.setdefault("NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING", "1")
    try:
        import numba  # noqa: F401
    except Exception as exc:  # pragma: no cover - depends on the machine
        _AVAILABLE = False
        error = RuntimeError(f"numba could not be imported: {exc}")
    else:
        error = None
        _plain_errors()
    while True:
        job = _JOBS.get()
        switch_fast()  # (a no-op while it is lowered)
        try:
            if error is not None:
                raise error
            # numba's modules imported since the last job get the shim too.
            compile_warnings.isolate_numba_modules()
            if job.build is not None:
                job.loop = job.build()
            else:
                job.loop = compile_loop(
                    job.kernel, job.bcast, job.dtype, job.ints, job.nogil
                )
                job.kernel._loop_ready(job.bcast, job.dtype, job.ints, job.loop, job.nogil)
        except BaseException as exc:  # noqa: BLE001 - handed to whoever waits
            job.error = exc
        compile_warnings.isolate_numba_modules()  # and those it imported
        if _JOBS.empty():
            # Nothing left to load: the caller's interval again, before whoever
            # waits for this job (drain) resumes.
            switch_back()
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


def idle_workers() -> int:
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
    return 1 if n < PARALLEL_MIN else idle_workers()


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

    return max(_ran(s) for s in run_split(loop, n, workers, chunk))


def run_split(fn, n, workers, chunk) -> list:
    """``fn(*chunk(start, stop))`` for ``workers`` consecutive row ranges of ``n``.

    The first range runs on the caller's thread, the others on the engine's
    thread pool; returns the results in order. ``fn`` must release the GIL
    (compiled with ``nogil=True``) for the ranges to run at once.
    """
    bounds = [n * k // workers for k in range(workers + 1)]
    futures = [
        _pool().submit(fn, *chunk(bounds[k], bounds[k + 1])) for k in range(1, workers)
    ]
    first = fn(*chunk(bounds[0], bounds[1]))
    return [first, *(f.result() for f in futures)]


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


class _PlainErrors:
    """numba's colour scheme of error messages, without colours (its own NOP scheme)."""

    def code(self, msg):
        return msg

    errmsg = filename = indicate = highlight = reset = code


def _plain_errors():
    """Keep numba's compiles on our thread off the process's ``sys.stdout``/``stderr``.

    With colorama installed (evo, for one, brings it), numba formats the messages
    of the typing errors it meets and recovers from during a compile inside
    ``colorama.init()``/``deinit()``, which replace and restore ``sys.stdout`` and
    ``sys.stderr``: on our background thread that undoes a caller's redirection
    made meanwhile (``contextlib.redirect_stdout``, pytest's ``capsys``, a
    doctest), whose output then goes to the old stream. The environment variable
    set before numba's import turns the colours off; when numba was imported
    earlier (by the user), its scheme is replaced here.
    """
    from .compile_warnings import loaded_modules

    try:
        from numba.core import errors
    except Exception:  # pragma: no cover - numba's layout changed: nothing to undo
        return
    if type(errors._termcolor_inst).__name__ != "NOPColorScheme":
        errors._termcolor_inst = _PlainErrors()
    # Modules that numba imported meanwhile keep the scheme of their import time
    # (``_termcolor = errors.termcolor()`` in numba.core.types.functions, ir,
    # typing.typeof, compiler_machinery): the one that formats typing errors.
    for name, module in loaded_modules():
        if name.startswith("numba.") and type(
            getattr(module, "_termcolor", None)
        ).__name__ not in ("NoneType", "NOPColorScheme", "_PlainErrors"):
            module._termcolor = errors._termcolor_inst
