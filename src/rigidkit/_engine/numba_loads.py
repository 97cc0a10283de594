"""Loading compiled functions from numba's disk cache without numba's set-up.

numba's ``Dispatcher.compile`` refreshes the target context before it looks in
its disk cache. For a process's first function that installs every typing and
lowering registry and imports ``numba.np.arraymath``, whose BLAS probe imports
``scipy.linalg``: about a second of a fresh process (GIL held, on the engine's
background thread) before the first loop, against 10-60 ms for reading the loop
itself. A script's one-element calls use the slower Python-float path until
then. :func:`jit_signatures` reads a cached function directly.

While the thread loads, the process's switch interval is lowered
(:func:`switch_fast`): a caller busy in Python otherwise held the GIL for 5 ms
after each of the loader's ~2000 file reads and llvmlite calls, which made
0.17 s of loading take 0.5-2 s.

>>> import numpy as np
>>> import rigidkit as rk
>>> from rigidkit._engine import numba_backend
>>> R = rk.Rotation.random(4, rng=0)
>>> M = R.as_matrix()          # asks for the loop (compiled, or loaded)
>>> numba_backend.drain()
True
>>> bool(np.allclose(R.as_matrix(), M))
True
"""

from __future__ import annotations

import os
import sys

__all__ = ["SWITCH_INTERVAL", "jit_signatures", "switch_back", "switch_fast"]


def jit_signatures(fn, sigs, cache, **options):
    """``numba.njit(sigs, cache=cache, **options)(fn)``, its loads from the disk
    cache without numba's first-use set-up.

    numba refreshes its target context before it reads a function from its disk
    cache (``load_overload``): the first time in a process that installs every
    typing and lowering registry and imports ``numba.np.arraymath``, whose BLAS
    probe imports ``scipy.linalg`` (1.0-1.8 s of a fresh process, against 10-60 ms
    for the load itself). A cached machine-code function needs none of it, so
    each signature is read from the cache directly (:func:`_load_cached`); only
    one that is not there is compiled, by ``compile``, which refreshes the
    context itself. The dispatcher is then closed to compiles, as ``njit`` with
    signatures does. Only for code compiled without numba's runtime (``_nrt=False``,
    the kernels' loops): the runtime's symbols are linked in by that refresh, and a
    loaded function that calls them (a host loop that allocates) would abort.
    """
    import numba

    from . import compile_warnings

    disp = numba.njit(cache=cache, **options)(fn)
    from numba.core import typeinfer

    direct = cache and options.get("_nrt", True) is False
    with typeinfer.register_dispatcher(disp):
        for sig in sigs:
            if not (direct and _load_cached(disp, sig)):
                compile_warnings.before_compile()
                disp.compile(sig)
    disp.disable_compile()
    return disp


def _load_cached(disp, sig) -> bool:
    """Add ``sig``'s overload to ``disp`` from numba's disk cache, without the
    context refresh of ``Dispatcher.compile`` (see :func:`jit_signatures`); False
    when it is not cached, or numba's internals are not as expected (numba 0.68:
    then ``compile`` does it the usual way)."""
    try:
        from numba.core.compiler_lock import global_compiler_lock

        with global_compiler_lock:
            cres = disp._cache._load_overload(sig, disp.targetctx)
            if cres is None or cres.objectmode:
                return False
            disp._cache_hits[sig] += 1
            disp.targetctx.insert_user_function(
                cres.entry_point, cres.fndesc, [cres.library]
            )
            disp.add_overload(cres)
            return True
    except Exception:  # noqa: BLE001 - a numba whose internals differ: compile()
        return False


#: The interpreter's switch interval (s) while the engine's thread has work (see
#: switch_fast); ``RIGIDKIT_SWITCH_INTERVAL=0`` leaves the process's interval alone.
SWITCH_INTERVAL = float(os.environ.get("RIGIDKIT_SWITCH_INTERVAL") or 1e-3)
_SWITCH_SAVED = None  # (the caller's interval, ours as read back) while lowered


def switch_fast():
    """Lower the switch interval to ``SWITCH_INTERVAL`` while the thread has work.

    The GIL's convoy effect: each time this thread lets the GIL go (for a file
    read or stat of an import, ~1500 of them in numba's import, or a llvmlite
    call through ctypes, ~500 in a loop's load) a caller's thread that runs
    Python takes it, and this thread gets it back only when its wait of a
    switch interval (5 ms by default) runs out. With a caller spinning on
    one-element calls that made ~0.17 s of loading take 0.5-2 s (3-8x its CPU
    time); with 1 ms the two threads share the GIL about evenly. Process-wide,
    hence only while there is work, and restored by :func:`switch_back`.
    """
    global _SWITCH_SAVED
    before = sys.getswitchinterval()
    if _SWITCH_SAVED is None and 0 < SWITCH_INTERVAL < before:
        sys.setswitchinterval(SWITCH_INTERVAL)
        _SWITCH_SAVED = (before, sys.getswitchinterval())


def switch_back():
    """Restore the interval that :func:`switch_fast` lowered, unless the process
    has set one of its own meanwhile (which is then kept)."""
    global _SWITCH_SAVED
    if _SWITCH_SAVED is not None:
        before, ours = _SWITCH_SAVED
        _SWITCH_SAVED = None
        if sys.getswitchinterval() == ours:
            # Stored in whole microseconds, truncated: rounded, it stays as it was.
            sys.setswitchinterval(before + 5e-7)
