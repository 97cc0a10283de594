"""The container protocol shared by the object layer: a batch of elements in one array.

Every object class of rigidkit (``Rotation``, ``Transform``, ``Quaternion``,
``Affine``, ...) holds ONE array whose trailing axes are one element (a quaternion
``(4,)``, a pose ``(7,)``, a matrix ``(3, 4)``, ...) and whose leading axes are the
batch. :class:`BatchedArray` implements, once, what depends only on that layout:
``shape``, ``dtype``, ``single``, ``len``, indexing, iteration, ``reshape``,
``concatenate``, pickling, identity equality and the batch half of ``repr``.

It is deliberately only the container surface. ``@``, ``compose``, ``include`` and
``identity`` are defined once for every kind of transform in
:class:`rigidkit.objects.group.Group` (which reads the stored array through
``_data``); ``apply``, ``inv`` and ``as_matrix`` stay in each class, written against
its own attribute, so a single-element call pays nothing for the bases.
"""

from __future__ import annotations

import functools
import inspect

import numpy as np

from .._engine.namespace import _torch_namespace, device_of, namespace_of
from ..errors import ShapeError
from . import _pytree

__all__ = ["BatchedArray", "batch_shape"]


def batch_shape(shape) -> tuple:
    """A batch shape argument (an int or a sequence of ints) as a tuple."""
    return (shape,) if isinstance(shape, int) else tuple(shape)


def storage_slots(cls) -> tuple:
    """The slots that hold an instance's array: ``_data``, and its own name if any
    (``_quat``); each is written when an object is made (see :func:`_wrap_both`)."""
    return ("_data",) if cls._storage == "_data" else ("_data", cls._storage)


def place(data, *, like=None, xp=None, dtype=None, device=None):
    """A NumPy array ``data`` in the namespace, dtype and device asked for.

    ``like``: an array whose namespace, floating dtype and device are taken (each
    unless given); ``xp``: a namespace (``torch``, ``jax.numpy``, ``numpy``,
    ``array_api_strict``, ...); ``dtype``: a dtype of that namespace or its name
    (``"float32"``); ``device``: a device of that namespace.
    """
    if like is not None:
        if xp is None:
            xp = namespace_of(like)
        if dtype is None and "float" in str(getattr(like, "dtype", "")):
            dtype = like.dtype
        if device is None:
            device = device_of(like)
    if xp is None:
        xp = np
    if getattr(xp, "__name__", "") == "torch":
        xp = _torch_namespace()
    if isinstance(dtype, str):
        dtype = getattr(xp, dtype)
    if xp is np:
        return data if dtype is None else data.astype(dtype)
    return xp.asarray(data, dtype=dtype or xp.float64, device=device)


def _placing(make):
    """``identity`` / ``random`` taking ``like=``, ``xp=``, ``dtype=``, ``device=``."""

    @functools.wraps(make)
    def made(cls, *args, like=None, xp=None, dtype=None, device=None, **kwargs):
        if like is None and xp is None and device is None:
            return make(cls, *args, dtype=dtype, **kwargs)
        obj = make(cls, *args, **kwargs)  # NumPy float64, then placed
        return cls._wrap(place(obj._data, like=like, xp=xp, dtype=dtype, device=device))

    made.__doc__ = (made.__doc__ or "") + _PLACING_DOC
    sig = inspect.signature(make)
    extra = [
        inspect.Parameter(n, inspect.Parameter.KEYWORD_ONLY, default=None)
        for n in ("like", "xp", "dtype", "device")
        if n not in sig.parameters
    ]
    made.__signature__ = sig.replace(parameters=[*sig.parameters.values(), *extra])
    made._placed = True
    return classmethod(made)


_PLACING_DOC = """
        The result is made in any array namespace: ``like=`` an array (its
        namespace, floating dtype and device), or ``xp=`` a namespace (``torch``,
        ``jax.numpy``, ...), ``dtype=`` (a dtype or its name) and ``device=``; by
        default NumPy float64.
"""


def _wrap_both(storage: str):
    """``_wrap`` of a class that stores its array under its own name too.

    Two slots hold the one array, ``_data`` (read by the shared code) and the
    class's own name (``_quat``, read by its methods), each written directly: no
    property on the hot path, and ``torch.compile`` (whose tracer tells slot
    aliases apart) reads what was written under either name. ``object.__new__``
    bound once (no class here defines its own ``__new__``) pays for the
    ``setattr``: as fast as a generated ``obj._data = obj._quat = data``
    (~0.10 us a call, measured).
    """
    new = object.__new__

    def _wrap(cls, data):
        obj = new(cls)
        obj._data = data
        setattr(obj, storage, data)
        return obj

    return _wrap


class BatchedArray:
    """Mixin: a batch of elements stored in one array of shape ``batch + _trail``.

    A subclass sets ``_trail`` (the trailing shape of one element) and declares the
    slot that holds the array; when that slot is not called ``_data`` it names it in
    ``_storage`` (``Rotation`` keeps its quaternions in ``_quat``) and declares a
    ``_data`` slot too, and every constructor writes the array into both (the
    generated ``_wrap`` does), so the methods below and the class's own read it at
    plain attribute speed. A single element has batch shape ``()``.

    Subclasses implement :meth:`_repr_single`, the ``repr`` of one element.

    Examples
    --------
    >>> import rigidkit as rk
    >>> A_R_B = rk.Rotation.identity((2, 3))      # stored as quaternions (2, 3, 4)
    >>> A_R_B.shape, len(A_R_B), A_R_B[1].shape, A_R_B[1, 2].shape
    ((2, 3), 2, (3,), ())
    >>> A_R_B.reshape(6).shape, rk.Rotation.concatenate([A_R_B[0], A_R_B[1]]).shape
    ((6,), (6,))
    >>> A_R_B[0, 0]
    Rotation.from_quat([1, 0, 0, 0])
    """

    __slots__ = ()
    _trail: tuple
    _storage = "_data"

    def __init_subclass__(cls, **kwargs):
        # Before the bases' hooks: Group's registers the class, binding its _wrap.
        if cls._storage != "_data" and "_wrap" not in cls.__dict__:
            cls._wrap = classmethod(_wrap_both(cls._storage))
        super().__init_subclass__(**kwargs)
        cls._cut = -len(cls._trail)  # shape[:_cut] is the batch shape
        cls._whole = (slice(None),) * len(cls._trail)  # index of one whole element
        _pytree.register(cls)  # a JAX pytree and torch pytree node, lazily
        for name in ("identity", "random"):
            made = getattr(cls, name, None)
            if made is not None and not getattr(made, "_placed", False):
                setattr(cls, name, _placing(made.__func__))

    @classmethod
    def _wrap(cls, data):
        """An instance holding ``data`` (shape ``batch + _trail``), not validated."""
        obj = cls.__new__(cls)
        obj._data = data
        return obj

    @classmethod
    def _filled(cls, element, shape, dtype=None):
        """A NumPy array of batch ``shape``, each element a copy of ``element``.

        ``element`` has shape ``_trail`` (e.g. the identity); dtype default float64.
        """
        out = np.empty(batch_shape(shape) + cls._trail, dtype=dtype or np.float64)
        out[...] = element
        return out

    # -- the container protocol --------------------------------------------------------
    @property
    def shape(self) -> tuple:
        """Batch shape (``()`` for a single element)."""
        return tuple(self._data.shape[: self._cut])

    @property
    def dtype(self):
        """Floating dtype of the stored array."""
        return self._data.dtype

    @property
    def single(self) -> bool:
        """True for a single element (batch shape ``()``)."""
        return self._data.ndim == len(self._trail)

    def __len__(self):
        if self.single:
            raise TypeError(f"a single {type(self).__name__} has no len()")
        return self._data.shape[0]

    def __getitem__(self, index):
        if self.single:
            raise TypeError(f"a single {type(self).__name__} cannot be indexed")
        if not isinstance(index, tuple):
            index = (index,)
        # The trailing element axes are kept whole; an explicit ``...`` makes the
        # index complete, as the array API requires. (``is``, not ``in``: ``==`` on
        # an array index would compare elementwise.)
        for i in index:
            if i is Ellipsis:
                break
        else:
            index = index + (Ellipsis,)
        return self._wrap(self._data[index + self._whole])

    def __iter__(self):
        if self.single:
            raise TypeError(f"a single {type(self).__name__} is not iterable")
        for k in range(len(self)):
            yield self[k]

    def reshape(self, *shape):
        """The same elements with another batch shape."""
        if len(shape) == 1 and isinstance(shape[0], (tuple, list)):
            shape = tuple(shape[0])
        xp = namespace_of(self._data)
        return self._wrap(xp.reshape(self._data, tuple(shape) + self._trail))

    @classmethod
    def concatenate(cls, items):
        """Join 1-D batches (or single elements) along the first axis."""
        nd = len(cls._trail)
        arrays = [x._data if x._data.ndim > nd else x._data[None] for x in items]
        if not arrays:
            raise ShapeError(f"concatenate needs at least one {cls.__name__}")
        return cls._wrap(namespace_of(*arrays).concat(arrays, axis=0))

    def __repr__(self):
        if self.single:
            return self._repr_single()
        return f"{type(self).__name__}(shape={self.shape}, dtype={self.dtype})"

    def _repr_single(self) -> str:
        raise NotImplementedError

    def __reduce__(self):
        return (type(self)._wrap, (self._data,))

    def __eq__(self, other):  # identity of objects; use approx_equal to compare values
        return NotImplemented if not isinstance(other, type(self)) else self is other

    __hash__ = object.__hash__
