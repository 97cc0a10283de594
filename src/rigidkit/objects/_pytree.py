"""The object classes as JAX pytrees and torch pytree nodes, registered lazily.

Each class holds one array (:class:`~rigidkit.objects._batch.BatchedArray`), its
only leaf: ``jax.jit``, ``jax.vmap``, ``jax.grad`` and ``torch.func`` then take and
return ``Rotation``, ``Transform``, ... as they do arrays. Registration happens at
class creation if jax (resp. torch) is already imported, else when rigidkit first
meets one of its arrays (:func:`rigidkit._engine.post_import.when_imported`):
``import rigidkit`` imports neither.

>>> import rigidkit as rk
>>> from rigidkit.objects import _pytree
>>> _pytree.flatten(rk.Rotation.identity())[0][0].tolist()
[1.0, 0.0, 0.0, 0.0]
"""

from __future__ import annotations

from .._engine.post_import import when_imported

__all__ = ["register", "flatten"]

_CLASSES: list[type] = []
_DONE = {"jax": set(), "torch": set()}


def flatten(obj):
    """``([stored array], None)``: the one leaf of an object, and no static data."""
    return [obj._data], None


def _unflatten(cls):
    def unflatten(children, _context=None):
        return cls._wrap(children[0])

    return unflatten


def _register_jax():
    from jax import tree_util

    for cls in _CLASSES:
        if cls not in _DONE["jax"]:
            _DONE["jax"].add(cls)
            un = _unflatten(cls)
            tree_util.register_pytree_node(
                cls, lambda obj: ((obj._data,), None), lambda aux, ch, un=un: un(ch)
            )


def _register_torch():
    from torch.utils import _pytree

    for cls in _CLASSES:
        if cls not in _DONE["torch"]:
            _DONE["torch"].add(cls)
            _pytree.register_pytree_node(
                cls,
                flatten,
                _unflatten(cls),
                serialized_type_name=f"{cls.__module__}.{cls.__qualname__}",
            )


def register(cls) -> None:
    """Make ``cls`` a pytree of JAX and torch, now or once each is imported."""
    _CLASSES.append(cls)
    when_imported("jax", _register_jax)
    when_imported("torch", _register_torch)
