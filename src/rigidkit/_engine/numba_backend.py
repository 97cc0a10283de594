"""Generate, compile and cache the fused numba loop of a kernel.

For each kernel we write one small Python module: the primitive prelude, the
source of the kernel and of every helper it calls, and a loop over the batch that
reads the components of each input, calls the kernel, and writes each output
component. The module lives in a cache folder named after a hash of its text, so
numba's on-disk cache (``cache=True``) is valid across processes and is refreshed
whenever a kernel changes. The loop is compiled with ``nogil=True``; large batches
are split over threads (see :func:`run_loop`), so one compile serves the serial and
the parallel path.
"""

from __future__ import annotations

import os
import sys
import threading

from .primitives import NUMBA_PRELUDE

_AVAILABLE = None
_LOCK = threading.Lock()
_POOL = None

#: A batch at least this long is split over threads (thread hand-off costs ~20 us).
PARALLEL_MIN = int(os.environ.get("RIGIDKIT_PARALLEL_MIN", "200000"))


def available() -> bool:
    """True when numba can be imported and is not disabled by RIGIDKIT_DISABLE_NUMBA."""
    global _AVAILABLE
    if os.environ.get("RIGIDKIT_DISABLE_NUMBA", "") not in ("", "0"):
        return False
    if _AVAILABLE is None:
        try:
            import numba  # noqa: F401

            _AVAILABLE = True
        except Exception:  # pragma: no cover - depends on the machine
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


def _loop_source(kernel, bcast=()) -> str:
    """Loop over ``range(n)`` (a known non-negative index: LLVM vectorises it).

    Inputs flagged in ``bcast`` are a single row, read once before the loop.
    """
    nparams = len(kernel.params)
    args = ["n"] + [f"p{k}" for k in range(nparams)]
    pre = []
    call = [f"p{k}" for k in range(nparams)]
    for k, shape in enumerate(kernel.inputs):
        args.append(f"a{k}")
        w = _size(shape)
        if k < len(bcast) and bcast[k]:
            pre += [f"    b{k}_{c} = a{k}[{c}]" for c in range(w)]
            call += [f"b{k}_{c}" for c in range(w)]
        elif w <= FLAT_MAX:
            call += [f"a{k}[{w} * i + {c}]" for c in range(w)]
        else:
            call += [f"a{k}[i, {c}]" for c in range(w)]
    body = [f"        r = {kernel.name}({', '.join(call)})"]
    j = 0
    for k, shape in enumerate(kernel.outputs):
        args.append(f"o{k}")
        w = _size(shape)
        for c in range(w):
            target = f"o{k}[{w} * i + {c}]" if w <= FLAT_MAX else f"o{k}[i, {c}]"
            body.append(f"        {target} = r[{j}]")
            j += 1
    head = "@numba.njit(cache=CACHE, nogil=True, error_model='numpy')\n"
    head += f"def loop({', '.join(args)}):\n"
    return head + "\n".join(pre + ["    for i in range(n):"] + body) + "\n"


def _size(shape) -> int:
    n = 1
    for s in shape:
        n *= s
    return n


def _has_star_call(fn) -> bool:
    """True if ``fn`` calls something with ``*args`` (numba cannot inline that)."""
    import ast

    tree = ast.parse(function_source(fn))
    return any(
        isinstance(node, ast.Call) and any(isinstance(x, ast.Starred) for x in node.args)
        for node in ast.walk(tree)
    )


def module_source(kernel, bcast=()) -> str:
    parts = [NUMBA_PRELUDE]
    fns = [*kernel.dependencies(), kernel]
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
    parts.append("\n\n" + _loop_source(kernel, bcast))
    return "\n".join(parts)


def compile_loop(kernel, bcast=()):
    """Import (and so compile on first call) the generated module of ``kernel``."""
    import hashlib
    import importlib.util
    import tempfile

    import numba

    src = module_source(kernel, bcast)
    digest = hashlib.sha1((src + numba.__version__).encode()).hexdigest()[:16]
    modname = f"rigidkit_k_{kernel.name}_{digest}"
    folder = _cache_dir()
    with _LOCK:
        if modname in sys.modules:
            return sys.modules[modname].loop
        if folder is None:
            namespace = {"CACHE": False}
            exec(compile(src, f"<rigidkit kernel {kernel.name}>", "exec"), namespace)
            return namespace["loop"]
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
        return module.loop


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


def run_loop(loop, n, params, ins, outs):
    """Run ``loop(n, *params, *ins, *outs)``, split over threads if it pays.

    ``ins``/``outs`` are ``(array, width)``: ``width`` is the row width of a flat
    1-D array, 0 for a 2-D ``(n, width)`` array, None for a broadcast row. Each
    thread gets views of its rows, so every loop runs over ``range(its n)``.
    """

    def chunk(start, stop):
        args = list(params)
        for a, w in (*ins, *outs):
            if w is None:
                args.append(a)
            elif w:
                args.append(a[w * start : w * stop])
            else:
                args.append(a[start:stop])
        return args

    workers = 1 if n < PARALLEL_MIN else _workers()
    if workers < 2:
        loop(n, *chunk(0, n))
        return
    bounds = [n * k // workers for k in range(workers + 1)]
    futures = [
        _pool().submit(loop, bounds[k + 1] - bounds[k], *chunk(bounds[k], bounds[k + 1]))
        for k in range(1, workers)
    ]
    loop(bounds[1] - bounds[0], *chunk(bounds[0], bounds[1]))
    for f in futures:
        f.result()
