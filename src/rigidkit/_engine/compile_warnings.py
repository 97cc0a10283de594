"""numba's use of :mod:`warnings` kept on the engine's compile thread.

numba's compiler enters ``warnings.catch_warnings()`` and sets filters
(``simplefilter``) around its passes: ``WarningsFixer.catch_warnings`` around
each typing constraint, ``compile_extra`` around its retry with rewrites. Before
Python 3.14 the filters, ``showwarning`` and the recording that
``catch_warnings(record=True)`` installs are one state for the whole process,
swapped on entry and put back on exit: a warning that the caller's thread
issues meanwhile is recorded by numba (and re-issued from the compile thread,
or dropped), or misses the caller's own ``catch_warnings(record=True)`` or
``pytest.warns``, and the caller's filters set meanwhile are undone on numba's
exit (CPython issue gh-91505; Python 3.14's context-aware warnings end it).

So every numba module's ``warnings`` (the module it imported) is replaced by
:data:`SHIM`, which is :mod:`warnings` itself on every thread but the engine's
compile thread (numba used by the caller behaves as before). On that thread it
keeps numba's warning state per thread: ``catch_warnings`` records into a list
of its own, the filter calls change nothing, and a warning issued there
(``warn``, ``warn_explicit``: numba's ``NumbaWarning``s about a generated loop)
goes to the innermost such recording, or else to :func:`compile_warnings`, never
to the process's filters and ``showwarning``. numba's import (run on that
thread) and its loads from the disk cache (:func:`.numba_loads.jit_signatures`)
touch none of that state at all (traced on numba 0.68). numba's first compile
in a process imports ``scipy.linalg`` (its BLAS probe), and ``scipy._lib._util``
enters ``catch_warnings`` in its body: :func:`before_compile` makes that import
first, on the compile thread, with :data:`SHIM` standing in for :mod:`warnings`
while the modules bind it (the only warning calls of that import, traced on
scipy 1.17 and 1.18).

>>> import warnings
>>> SHIM.catch_warnings is not warnings.catch_warnings   # its own, per thread
True
>>> with SHIM.catch_warnings(record=True) as log:        # on this thread: warnings'
...     SHIM.simplefilter("always")
...     SHIM.warn("seen by the caller's recording", UserWarning)
>>> [str(w.message) for w in log]
["seen by the caller's recording"]
"""

from __future__ import annotations

import contextlib
import sys
import threading
import types
import warnings as _warnings
from collections import deque

__all__ = [
    "SHIM",
    "before_compile",
    "compile_warnings",
    "isolate",
    "isolate_numba_modules",
]

_LOCAL = threading.local()
#: Warnings issued on the compile thread outside any recording of numba's (the
#: last 100): ``NumbaWarning``s about the engine's own generated code.
_LOG: deque = deque(maxlen=100)


def _isolated() -> bool:
    return getattr(_LOCAL, "stack", None) is not None


@contextlib.contextmanager
def isolate():
    """Within this block, on this thread, :data:`SHIM` keeps warnings to itself
    (the engine's compile thread runs inside it for good)."""
    before = getattr(_LOCAL, "stack", None)
    _LOCAL.stack = []
    try:
        yield
    finally:
        _LOCAL.stack = before


def compile_warnings() -> list:
    """The warnings (``warnings.WarningMessage``) that numba issued on the compile
    thread outside its own recordings, the last 100, oldest first."""
    return list(_LOG)


def _emit(message, category, filename, lineno):
    if isinstance(message, Warning):
        category = type(message)
    msg = _warnings.WarningMessage(message, category or UserWarning, filename, lineno)
    (_LOCAL.stack[-1] if _LOCAL.stack else _LOG).append(msg)


class catch_warnings(_warnings.catch_warnings):
    # A class, not a function: modules subclass it (numpy.testing does at import).
    # The thread that enters decides: isolated, a recording of its own.
    _rk_log = None

    def __enter__(self):
        if not _isolated():
            return super().__enter__()
        self._rk_log = []
        _LOCAL.stack.append(self._rk_log)
        return self._rk_log if self._record else None

    def __exit__(self, *exc_info):
        if self._rk_log is None:
            return super().__exit__(*exc_info)
        stack = _LOCAL.stack
        for i in range(len(stack) - 1, -1, -1):  # by identity (lists compare equal)
            if stack[i] is self._rk_log:
                del stack[i]
                break
        self._rk_log = None
        return None


def simplefilter(*args, **kwargs):
    if not _isolated():
        return _warnings.simplefilter(*args, **kwargs)


def filterwarnings(*args, **kwargs):
    if not _isolated():
        return _warnings.filterwarnings(*args, **kwargs)


def resetwarnings():
    if not _isolated():
        return _warnings.resetwarnings()


def warn(message, category=None, stacklevel=1, source=None, **kwargs):
    if not _isolated():
        return _warnings.warn(message, category, stacklevel + 1, source, **kwargs)
    frame = sys._getframe(1)
    _emit(message, category, frame.f_code.co_filename, frame.f_lineno)


def warn_explicit(message, category, filename, lineno, *args, **kwargs):
    if not _isolated():
        return _warnings.warn_explicit(message, category, filename, lineno, *args, **kwargs)
    _emit(message, category, filename, lineno)


class _Shim(types.ModuleType):
    """:mod:`warnings`, with the functions above in place of its own."""

    def __getattr__(self, name):
        return getattr(_warnings, name)


#: What numba's modules see as ``warnings`` (see the module's doc).
SHIM = _Shim("warnings", _warnings.__doc__)
_OWN = (catch_warnings, simplefilter, filterwarnings, resetwarnings, warn, warn_explicit)
for _fn in _OWN:
    _fn.__doc__ = getattr(_warnings, _fn.__name__).__doc__
    setattr(SHIM, _fn.__name__, _fn)


def loaded_modules() -> list:
    """``sys.modules``'s items, read safely while other threads import.

    ``list(sys.modules.items())`` walks the dict in steps between which Python
    code can run (a collection triggered by an allocation, a finaliser), and
    another thread's import then changes its size: ``RuntimeError: dictionary
    changed size during iteration`` on the compile thread (seen in a test run, it
    failed the job of every caller waiting on that loop). ``dict.copy`` copies the
    table in one call that runs no Python code; the retry is for any other way.
    """
    while True:
        try:
            return list(sys.modules.copy().items())
        except RuntimeError:  # pragma: no cover - the copy raced after all: again
            continue


def isolate_numba_modules() -> int:
    """Give every imported numba module :data:`SHIM` as its ``warnings``; returns
    how many were changed (modules numba imports later are changed by the next
    call: the engine calls it before and after each compile)."""
    count = 0
    for name, module in loaded_modules():
        if (name == "numba" or name.startswith("numba.")) and getattr(
            module, "__dict__", {}
        ).get("warnings") is _warnings:
            module.warnings = SHIM
            count += 1
    return count


#: Modules numba's first compile imports whose bodies use :mod:`warnings`.
_FIRST_COMPILE_IMPORTS = ("scipy.linalg.cython_blas", "scipy.__config__")
_PREPARED = False


def before_compile() -> None:
    """Called before numba compiles (not before a load from the disk cache).

    On the isolated compile thread, once per process: the modules that numba's
    first compile imports (:data:`_FIRST_COMPILE_IMPORTS`, where installed and
    not yet imported) are imported with ``sys.modules["warnings"]`` set to
    :data:`SHIM`, so their bodies' ``catch_warnings`` and filters stay on this
    thread and the modules keep :data:`SHIM` (which is :mod:`warnings` on every
    other thread). Elsewhere, or once done, nothing.
    """
    global _PREPARED
    if _PREPARED or not _isolated():
        return
    _PREPARED = True
    import importlib
    import importlib.util

    for name in _FIRST_COMPILE_IMPORTS:
        if name in sys.modules:
            continue
        try:
            if importlib.util.find_spec(name.split(".")[0]) is None:
                continue
        except (ImportError, ValueError):
            continue
        if sys.modules.get("warnings") is not _warnings:
            return
        sys.modules["warnings"] = SHIM
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001 - numba's own import reports it
            pass
        finally:
            sys.modules["warnings"] = _warnings
