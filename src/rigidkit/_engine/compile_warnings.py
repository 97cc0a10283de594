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
touch none of that state at all (traced on numba 0.68). One case is left: a
module of another package that numba's first compile in a process imports, on
that thread, and that enters ``catch_warnings`` in its body: ``scipy._lib._util``
does once, through numba's BLAS probe, when ``scipy.linalg`` was not imported
before (a cold disk cache only).

>>> import warnings
>>> SHIM.catch_warnings is not warnings.catch_warnings   # a function of the thread
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

__all__ = ["SHIM", "compile_warnings", "isolate", "isolate_numba_modules"]

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


@contextlib.contextmanager
def _catch(record=False, **_ignored):
    log = []
    _LOCAL.stack.append(log)
    try:
        yield log if record else None
    finally:
        _LOCAL.stack.pop()


def _emit(message, category, filename, lineno):
    if isinstance(message, Warning):
        category = type(message)
    msg = _warnings.WarningMessage(message, category or UserWarning, filename, lineno)
    (_LOCAL.stack[-1] if _LOCAL.stack else _LOG).append(msg)


def catch_warnings(*args, **kwargs):
    if _isolated():
        return _catch(*args, **kwargs)
    return _warnings.catch_warnings(*args, **kwargs)


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


def isolate_numba_modules() -> int:
    """Give every imported numba module :data:`SHIM` as its ``warnings``; returns
    how many were changed (modules numba imports later are changed by the next
    call: the engine calls it before and after each compile)."""
    count = 0
    for name, module in list(sys.modules.items()):
        if (name == "numba" or name.startswith("numba.")) and getattr(
            module, "__dict__", {}
        ).get("warnings") is _warnings:
            module.warnings = SHIM
            count += 1
    return count
