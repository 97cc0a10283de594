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
from .._validate import concrete, foreign_object, scipy_kind, to_numpy
from ..errors import ShapeError
from . import _pytree

__all__ = ["BatchedArray", "batch_shape"]


def batch_shape(shape) -> tuple:
    """A batch shape argument (an int or a sequence of ints) as a tuple."""
    return (shape,) if isinstance(shape, int) else tuple(shape)


# What to call instead of passing an array where an object is expected, by the
# object's class and the array's trailing shape (None: any shape).
_INSTEAD = {
    "Rotation": {
        (4,): "rk.Rotation.from_quat(q) for (w, x, y, z), or "
        "rk.Rotation.from_quat(q, scalar_first=False) for (x, y, z, w) as ROS, scipy "
        "and Eigen store it",
        (3, 3): "rk.Rotation.from_matrix(M)",
        (3,): "rk.Rotation.from_rotvec(v), or rk.Rotation.from_euler(seq, angles)",
        None: "rk.Rotation.from_quat(q, scalar_first=...), .from_matrix(M), "
        ".from_rotvec(v) or .from_euler(seq, angles)",
    },
    "Transform": {
        (4, 4): "rk.Transform.from_matrix(M)",
        (7,): "rk.Transform.from_pq(pq) for (x, y, z, qw, qx, qy, qz), or "
        "rk.Transform.from_pq(pq, scalar_first=False) for (x, y, z, qx, qy, qz, qw)",
        None: "rk.Transform.from_matrix(M), rk.Transform.from_pq(pq), or "
        "rk.Transform(rotation=rk.Rotation..., translation=t)",
    },
    "Rotation2D": {None: "rk.Rotation2D.from_angle(theta) or .from_matrix(M)"},
}


def instead(kind: str, x) -> str:
    """``"; call ... instead"`` for an array ``x`` given where a ``kind`` is expected."""
    table = _INSTEAD.get(kind)
    if table is None:
        return ""
    shape = tuple(getattr(x, "shape", np.shape(x)) if _is_arraylike(x) else ())
    if kind == "Rotation":  # a pose given as a Transform's rotation= (its first)
        if shape[-2:] == (4, 4):
            return f"; for 4x4 matrices, call {_INSTEAD['Transform'][(4, 4)]}"
        if shape[-1:] == (7,):
            return f"; for poses, call {_INSTEAD['Transform'][(7,)]}"
    trails = sorted((k for k in table if k is not None), key=len, reverse=True)
    for trail in trails:  # (4, 4) before (4,)
        if shape[len(shape) - len(trail) :] == trail:
            return f"; for an array of shape {shape}, call {table[trail]}"
    return f"; call {table[None]}"


def _is_arraylike(x) -> bool:
    if hasattr(x, "shape"):
        return True
    try:
        np.shape(x)
    except ValueError:  # ragged
        return False
    return isinstance(x, (list, tuple))


def expect(x, cls, what: str):
    """``x`` as an instance of ``cls``: itself, or converted from scipy's ``Rotation``
    or ``RigidTransform`` (or an object with ``as_rigidkit()``); anything else is a
    ``TypeError`` saying which constructor to call instead.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> try:
    ...     expect(np.eye(4), rk.Rotation, "rotation")
    ... except TypeError as err:
    ...     print(err)  # doctest: +NORMALIZE_WHITESPACE
    rotation must be a rigidkit.Rotation, got ndarray; for 4x4 matrices, call
    rk.Transform.from_matrix(M)
    """
    if isinstance(x, cls):
        return x
    made = foreign_object(x)
    if made is not None:
        kind, obj = made
        if isinstance(obj, cls):
            return obj
        converted = cls._from_foreign(kind, obj)
        if converted is not None:
            return converted
    got = type(x).__name__
    if made is not None:
        got = f"a {'scipy ' if scipy_kind(x) else ''}{made[0]}"
    raise TypeError(
        f"{what} must be a rigidkit.{cls.__name__}, got {got}{instead(cls.__name__, x)}"
    )


def storage_slots(cls) -> tuple:
    """The slots that hold an instance's array: ``_data``, and its own name if any
    (``_quat``); each is written when an object is made (see :func:`_wrap_both`)."""
    return ("_data",) if cls._storage == "_data" else ("_data", cls._storage)


def place(data, *, like=None, xp=None, dtype=None, device=None):
    """A NumPy array ``data`` in the namespace, dtype and device asked for.

    ``like``: an array whose namespace, floating dtype and device are taken (each
    unless given); ``xp``: a namespace (``torch``, ``jax.numpy``, ``numpy``,
    ``array_api_strict``, ...); ``dtype``: a dtype of that namespace or its name
    (``"float32"``), by default the namespace's default floating dtype
    (:func:`default_float`); ``device``: a device of that namespace.
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
    if dtype is None:
        dtype = default_float(xp)
    return xp.asarray(data, dtype=dtype, device=device)


def default_float(xp):
    """The default floating dtype of the namespace ``xp``: ``float32`` for JAX
    without ``jax_enable_x64`` and for torch unless ``torch.set_default_dtype``
    says otherwise, ``float64`` for NumPy."""
    return xp.asarray(0.0).dtype


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
        default NumPy float64, and in another namespace its default floating
        dtype (JAX: float32 unless ``jax_enable_x64`` is on; torch:
        ``torch.get_default_dtype()``).
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


def compiled_operator(cls, func, args, kwargs):
    """An operator between an object of ``cls`` and a tensor as TorchDynamo calls it.

    TorchDynamo (torch 2.13) does not call an object's operator method when the
    other operand is a tensor: it makes the operator torch's (``matmul``,
    ``__rpow__``, ``mul``, ``__rtruediv__``...) and, since an object is no graph
    value, fails ("Missing as_proxy() implementation") unless an operand defines
    ``__torch_function__``, which it then calls. While compiling, this finds the
    object's own method for ``func`` and calls it with the tensor (``X @ p``,
    ``X ** t``, ``s * q``, ``q / s``); anything else, and every call outside
    compilation, is ``NotImplemented``, so eager operators are unchanged.
    """
    if kwargs or len(args) != 2:
        return NotImplemented
    import torch  # (torch called this; namespace.COMPILER is bound only once a
    # tensor has met the engine, and an object made from NumPy may meet one here)

    if not torch.compiler.is_compiling():
        return NotImplemented
    ours = [isinstance(a, cls) for a in args]
    if ours[0] == ours[1]:
        return NotImplemented
    name = _OPERATOR_METHODS.get((getattr(func, "__name__", None), ours[1]))
    if name is None:
        return NotImplemented
    obj, tensor = (args[1], args[0]) if ours[1] else args
    return getattr(obj, name)(tensor)


# (name of the torch function, object second) -> the object's method of equal value,
# as TorchDynamo (torch 2.13) calls them: X @ p and p @ X as matmul(p, X), s * X as
# mul(s, X), X ** t as t.__rpow__(X), X / s as s.__rdiv__(X) (torch's __rtruediv__);
# X * s it hands to X.__mul__ itself. Each is held by a test (test_torch_matmul.py).
_OPERATOR_METHODS = {
    ("matmul", True): "__matmul__",
    ("mul", True): "__rmul__",
    ("__rpow__", True): "__pow__",
    ("__rdiv__", True): "__truediv__",
}


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
    def _from_foreign(cls, kind: str, obj):
        """An instance from scipy's object ``obj`` of class ``kind``, or None where
        this class has no such conversion (see :func:`expect`)."""
        return None

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

    #: The components of one stored element, named in the ``repr`` of a batch.
    _repr_columns = "values"

    def __repr__(self):
        if self.single:
            return self._repr_single()
        head = f"{type(self).__name__}(shape={self.shape}, dtype={self.dtype}"
        if not concrete(self._data):  # traced or lazy: no values to show
            return head + ")"
        values = np.array2string(
            np.asarray(to_numpy(self._data)),
            precision=6,
            suppress_small=True,
            separator=", ",
            threshold=200,  # a few rows first and last, as NumPy summarises
            edgeitems=3,
            prefix=" ",
        )
        return f"{head}, {self._repr_columns}=\n {values})"

    def _repr_single(self) -> str:
        raise NotImplementedError

    def __reduce__(self):
        return (type(self)._wrap, (self._data,))

    def __eq__(self, other):  # identity of objects; use approx_equal to compare values
        return NotImplemented if not isinstance(other, type(self)) else self is other

    __hash__ = object.__hash__
