"""Run setup code when an optional library (jax, torch) is imported, never importing it.

``import rigidkit`` must not import jax or torch, yet some setup has to exist
before their tracers first meet rigidkit: the object classes must be JAX pytrees
and torch pytree nodes before ``jax.jit(f)(R)`` flattens a ``Rotation``, and the
torch namespace adapter must be built outside ``torch.compile``, which cannot
trace its construction. :func:`when_imported` runs a function now if the library
is already imported, else right after its top-level module has executed (a
finder on ``sys.meta_path`` wraps the module's loader; it steps aside for every
other import).

>>> from rigidkit._engine.post_import import when_imported
>>> seen = []
>>> when_imported("json", lambda: seen.append("json"))   # already imported: now
>>> seen
['json']
"""

from __future__ import annotations

import sys
import threading
import warnings

_HOOKS: dict[str, list] = {}
_LOCK = threading.RLock()


def when_imported(name: str, fn) -> None:
    """Call ``fn()`` once the top-level module ``name`` is imported (now if it is)."""
    with _LOCK:
        if name in sys.modules and name not in _HOOKS:
            _run(name, [fn])
            return
        _HOOKS.setdefault(name, []).append(fn)
        if _Finder not in sys.meta_path:
            sys.meta_path.insert(0, _Finder)


def _run(name, hooks):
    for fn in hooks:
        try:
            fn()
        except Exception as err:  # a failed setup must not break the user's import
            warnings.warn(
                f"rigidkit: setup for {name} failed ({type(err).__name__}: {err}); "
                f"its arrays still work, without that integration",
                RuntimeWarning,
                stacklevel=3,
            )


class _Finder:
    """Finds nothing itself: wraps the loader of a watched module found by the others."""

    _busy = threading.local()

    @classmethod
    def find_spec(cls, fullname, path=None, target=None):
        if fullname not in _HOOKS or getattr(cls._busy, "on", False):
            return None
        cls._busy.on = True
        try:
            for finder in sys.meta_path:
                if finder is cls or not hasattr(finder, "find_spec"):
                    continue
                spec = finder.find_spec(fullname, path, target)
                if spec is not None:
                    break
            else:
                return None
        finally:
            cls._busy.on = False
        loader = spec.loader
        if loader is None or not hasattr(loader, "exec_module"):
            return spec
        exec_module = loader.exec_module

        def exec_then_hooks(module):
            exec_module(module)
            with _LOCK:
                hooks = _HOOKS.pop(fullname, [])
            _run(fullname, hooks)

        loader.exec_module = exec_then_hooks
        return spec
