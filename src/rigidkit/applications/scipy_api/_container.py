"""The container protocol shared by the drop-in ``Rotation`` and ``RigidTransform``.

scipy's classes are sequences of their batch's first axis: ``len``, indexing,
item assignment and iteration, each a ``TypeError`` for a single element, and a
``repr`` that rebuilds the object from its matrices. A wrapper holds one rigidkit
object whose array (``_data``) has the batch axes first and one element axis
last; the subclass names that array, how to wrap an array and how to store one.
"""

from __future__ import annotations

import numpy as np

from ._arrays import set_rows

__all__ = ["Batch"]


class Batch:
    """Base of the drop-in classes: the container protocol over ``_data``.

    A subclass sets ``_NAME`` (scipy's class name), ``_NOUN`` (for the messages),
    ``_NO_LEN`` (scipy's message for ``len`` of a single element) and ``_KIND``
    (the class that item assignment accepts), and defines the property ``_data``,
    the static method ``_from_data(array)`` (a new wrapper) and ``_store(array)``.
    """

    __slots__ = ()
    _NAME = _NOUN = _NO_LEN = ""
    _KIND: type = object

    @property
    def single(self):
        """Whether this holds one element (batch shape ``()``)."""
        return self._data.ndim == 1

    @property
    def shape(self):
        """The batch shape."""
        return tuple(self._data.shape[:-1])

    def __len__(self):
        a = self._data
        if a.ndim == 1:
            raise TypeError(self._NO_LEN)
        return a.shape[0]

    def __bool__(self):
        return True

    def __getitem__(self, indexer):
        a = self._data
        if a.ndim == 1:
            raise TypeError(f"Single {self._NOUN} is not subscriptable.")
        if isinstance(indexer, list):
            indexer = np.asarray(indexer, dtype=np.intp if not indexer else None)
        if isinstance(indexer, tuple):  # the element axis stays whole
            whole = (slice(None),)
            if not any(i is Ellipsis for i in indexer):
                whole = (Ellipsis, slice(None))
            return self._from_data(a[indexer + whole])
        return self._from_data(a[indexer])

    def __setitem__(self, indexer, value):
        a = self._data
        if a.ndim == 1:
            raise TypeError(f"Single {self._NOUN} is not subscriptable.")
        if not isinstance(value, self._KIND):
            raise TypeError(f"value must be a {self._NAME} object")
        self._store(set_rows(a, indexer, value._data))

    def __iter__(self):
        if self._data.ndim == 1:
            raise TypeError(f"Single {self._NOUN} is not iterable.")
        for k in range(len(self)):
            yield self[k]

    def __repr__(self):
        # scipy's: the matrices' repr indented under ``Name.from_matrix(``.
        head = f"{self._NAME}.from_matrix("
        m = f"{self.as_matrix()!r}".splitlines()
        pad = " " * len(head)
        return head + "\n".join([m[0]] + [pad + line for line in m[1:]]) + ")"
