"""Run setup for an optional library (jax, torch) once it is in use, never importing it.

``import rigidkit`` must not import jax or torch, yet some setup has to exist
before their tracers work on rigidkit's objects: the object classes must be JAX
pytrees and torch pytree nodes (``jax.jit(f)(R)`` flattens a ``Rotation``), and
the torch adapter and the kernels' torch bindings must be made outside
``torch.compile``, which cannot trace their making. :func:`when_imported` runs
a function now if the library is already imported, else when the engine first
meets one of its arrays (:func:`.namespace.namespace_of` calls :func:`settle`;
for torch, importing :mod:`.torch_setup` does it, even inside a compiled
function: its import runs the setup registered for torch, as TorchDynamo
executes an ``import`` for real). No import hook is installed: the library's
own import runs no rigidkit code.

So an object must meet rigidkit as that library's array before the library's
tracers see it: ``jax.jit(f)(R)`` with ``R`` made from JAX arrays (or made
after ``import jax`` preceded ``import rigidkit``) works; a NumPy-made ``R``
handed to ``jax.jit`` as the very first contact, in a process that imported
jax after rigidkit, is not a pytree yet.

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

__all__ = ["PENDING", "arrived", "settle", "when_imported"]

#: Setup waiting for its library: {top-level module name: [functions]}.
PENDING: dict[str, list] = {}
_ARRIVED: set[str] = set()
_LOCK = threading.RLock()


def when_imported(name: str, fn) -> None:
    """Call ``fn()`` once the library ``name`` is in use (now if it is imported).

    torch is in use once :mod:`.torch_setup` is imported (its last line calls
    :func:`arrived`), which the engine does at its own import if torch is
    imported, else at the first tensor it meets.
    """
    with _LOCK:
        if name in _ARRIVED:
            _run(name, [fn])
            return
        PENDING.setdefault(name, []).append(fn)
    if name != "torch" and name in sys.modules:
        arrived(name)


def settle() -> None:
    """Run the setup of every waiting library (but torch, see above) imported by now."""
    for name in [n for n in list(PENDING) if n != "torch" and n in sys.modules]:
        arrived(name)


def arrived(name: str) -> None:
    """``name`` is in use: run its waiting setup, and any registered later at once."""
    with _LOCK:
        _ARRIVED.add(name)
        hooks = PENDING.pop(name, [])
    _run(name, hooks)


def _run(name, hooks):
    for fn in hooks:
        try:
            fn()
        except Exception as err:  # a failed setup must not break the user's call
            warnings.warn(
                f"rigidkit: setup for {name} failed ({type(err).__name__}: {err}); "
                f"its arrays still work, without that integration",
                RuntimeWarning,
                stacklevel=3,
            )
