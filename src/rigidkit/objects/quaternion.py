"""General quaternions as objects: :class:`Quaternion` holds one array of shape (..., 4).

The algebra itself (Hamilton product, conjugate, inverse ``q* / |q|^2``, exp, log) is
the functional module :mod:`rigidkit.functional.quaternion`; this class gives it
operators, one meaning each: ``+`` and ``-`` add, ``*`` is the Hamilton product (or,
with a real scalar, scalar multiplication), ``/`` divides by a real scalar only.
``@`` is not defined: in rigidkit ``@`` means composing transforms or acting on
points, and a general quaternion is neither; rotate points with
:meth:`Quaternion.rotate` or ``q.to_rotation() @ p``.

>>> import numpy as np
>>> i = Quaternion([0.0, 1.0, 0.0, 0.0])
>>> j = Quaternion([0.0, 0.0, 1.0, 0.0])
>>> i * j                                  # ij = k
Quaternion([0.0, 0.0, 0.0, 1.0])
>>> np.asarray(i * i)                      # i^2 = -1
array([-1.,  0.,  0.,  0.])
"""

from __future__ import annotations

import numpy as np

from .._engine.dask_backend import is_dask
from .._engine.namespace import is_numpy, namespace_of
from .._validate import as_array, check_finite, to_numpy
from ..functional import quaternion as _fq
from ._batch import BatchedArray, compiled_operator
from ._frozen import frozen, owned
from .rotation import Rotation


class Quaternion(BatchedArray):
    """A batch of general quaternions ``w + x i + y j + z k``, shape (..., 4).

    Hamilton convention (``ij = k``), scalar first. Operators: ``q1 + q2``,
    ``q1 - q2``, ``-q``, ``q1 * q2`` (Hamilton product), ``s * q`` and ``q * s``
    (scalar multiplication by real numbers or arrays of the batch shape), ``q / s``
    (real ``s`` only). A non-quaternion operand of ``*`` is always a real scalar
    per batch element, so wrap 4-vectors as ``Quaternion(a)`` to multiply by them.
    ``@`` is not defined (module docs). ``np.asarray(q)`` gives the components.

    Parameters
    ----------
    components : array_like, shape (..., 4)
        ``(w, x, y, z)``; finite. Integer input becomes float64; the array
        namespace (NumPy, torch, ...) and float dtype are kept.

    Examples
    --------
    >>> q = Quaternion([1.0, 2.0, 3.0, 4.0])
    >>> np.round(np.asarray(q * q.inv()), 12) + 0.0
    array([1., 0., 0., 0.])
    >>> q.conjugate() * q                      # |q|^2 = 30
    Quaternion([30.0, 0.0, 0.0, 0.0])
    >>> (2 * q).w
    array(2.)
    """

    __slots__ = ("_q", "_data")  # one array under two names (see _batch)
    _storage = "_q"
    _trail = (4,)
    _repr_columns = "(w, x, y, z)"
    # NumPy's binary operators defer to ours (ndarray * Quaternion -> __rmul__).
    __array_ufunc__ = None

    @classmethod
    def __torch_function__(cls, func, types, args=(), kwargs=None):
        """``s * q``, ``q * s`` and ``q / s`` with a tensor ``s`` inside ``torch.compile``
        (:func:`~rigidkit.objects._batch.compiled_operator`); nothing anywhere else."""
        return compiled_operator(Quaternion, func, args, kwargs)

    def __init__(self, components):
        q = _fq._quat(components, "quaternion components")
        check_finite(q, (4,), "quaternion components")
        # Not the caller's array: objects are immutable.
        self._q = self._data = owned(q, components)

    @classmethod
    def from_parts(cls, scalar, vector):
        """From the scalar part (shape (...)) and the vector part (shape (..., 3)).

        >>> Quaternion.from_parts(0.0, [1.0, 2.0, 3.0])   # a pure quaternion
        Quaternion([0.0, 1.0, 2.0, 3.0])
        """
        v = as_array(vector, (3,), "vector part")
        xp = namespace_of(v, scalar)
        if is_numpy(xp):  # NumPy or Dask (kept lazy: asarray of one computes it)
            s = scalar
            if not isinstance(s, (int, float)) and not is_dask(s):
                s = np.asarray(s)
            dt = np.result_type(v.dtype, s if isinstance(s, (int, float)) else s.dtype)
            dt = dt if dt.kind == "f" else np.dtype(np.float64)
            v = _cast(v, dt)
            s = np.asarray(s, dtype=dt) if isinstance(s, (int, float)) else _cast(s, dt)
        else:
            s = xp.asarray(scalar, dtype=v.dtype)
        batch = tuple(np.broadcast_shapes(tuple(s.shape), tuple(v.shape[:-1])))
        parts = [
            xp.broadcast_to(s[..., None], batch + (1,)),
            xp.broadcast_to(v, batch + (3,)),
        ]
        return cls(xp.concat(parts, axis=-1))

    @classmethod
    def from_rotation(cls, rotation):
        """The unit quaternions of a :class:`~rigidkit.Rotation` (either sign)."""
        return cls._wrap(rotation.as_quat())

    def to_rotation(self):
        """The :class:`~rigidkit.Rotation` of ``q / |q|``.

        Raises
        ------
        ZeroNormError
            For a zero quaternion, naming its batch index.
        """
        return Rotation.from_quat(self._q)

    # -- components ---------------------------------------------------------------
    @property
    def w(self):
        """Scalar (real) part, shape (...)."""
        return frozen(self._q[..., 0])

    @property
    def x(self):
        """Coefficient of ``i``, shape (...)."""
        return frozen(self._q[..., 1])

    @property
    def y(self):
        """Coefficient of ``j``, shape (...)."""
        return frozen(self._q[..., 2])

    @property
    def z(self):
        """Coefficient of ``k``, shape (...)."""
        return frozen(self._q[..., 3])

    scalar = w

    @property
    def vector(self):
        """Vector (imaginary) part ``(x, y, z)``, shape (..., 3)."""
        return frozen(self._q[..., 1:])

    def __array__(self, dtype=None, copy=None):
        a = to_numpy(self._q)
        if dtype is not None:
            a = a.astype(dtype, copy=False)
        return a.copy() if copy else frozen(a)

    # -- algebra ------------------------------------------------------------------
    def __add__(self, other):
        if not isinstance(other, Quaternion):
            return NotImplemented
        return Quaternion._wrap(self._q + other._q)

    def __sub__(self, other):
        if not isinstance(other, Quaternion):
            return NotImplemented
        return Quaternion._wrap(self._q - other._q)

    def __neg__(self):
        return Quaternion._wrap(-self._q)

    def __pos__(self):
        return self

    def __mul__(self, other):
        if isinstance(other, Quaternion):
            return Quaternion._wrap(_fq.multiply(self._q, other._q))
        s = self._scalar(other)
        return NotImplemented if s is None else Quaternion._wrap(self._q * s)

    def __rmul__(self, other):
        s = self._scalar(other)
        return NotImplemented if s is None else Quaternion._wrap(s * self._q)

    def __truediv__(self, other):
        if isinstance(other, Quaternion):
            raise TypeError(
                "quaternion / quaternion is ambiguous (the product does not commute); "
                "write q1 * q2.inv() or q2.inv() * q1"
            )
        s = self._scalar(other)
        return NotImplemented if s is None else Quaternion._wrap(self._q / s)

    def __matmul__(self, other):
        raise TypeError(
            "@ is not defined for Quaternion: use * for the Hamilton product, "
            "q.rotate(p) or q.to_rotation() @ p to rotate points"
        )

    __rmatmul__ = __matmul__

    def _scalar(self, s):
        """A real scalar (or batch of them) as an array that broadcasts against ``_q``."""
        if isinstance(s, bool):
            return None
        if isinstance(s, (int, float)):
            return s
        if isinstance(s, np.generic) and s.dtype.kind in "fiu":
            return s
        if isinstance(s, complex) or getattr(getattr(s, "dtype", None), "kind", "") == "c":
            raise TypeError("a quaternion's scalar factor must be real")
        if not hasattr(s, "shape") and not isinstance(s, (list, tuple)):
            return None
        xp = namespace_of(self._q, s)
        if is_numpy(xp):
            if not is_dask(s):  # (np.asarray of a Dask array would compute it)
                s = np.asarray(s)
            if s.dtype.kind not in "fiu":
                return None
        else:
            s = xp.asarray(s)
        return s[..., None]

    def conjugate(self):
        """``q* = (w, -v)``."""
        return Quaternion._wrap(_fq.conjugate(self._q))

    def norm(self):
        """``|q|``, shape (...)."""
        return _fq.norm(self._q)

    def inv(self):
        """``q^-1 = q* / |q|^2`` (raises :class:`~rigidkit.ZeroNormError` for 0)."""
        return Quaternion._wrap(_fq.inv(self._q))

    def exp(self):
        """``exp(q)``; see :func:`rigidkit.functional.quaternion.exp`."""
        return Quaternion._wrap(_fq.exp(self._q))

    def log(self):
        """Principal ``log(q)``; see :func:`rigidkit.functional.quaternion.log`."""
        return Quaternion._wrap(_fq.log(self._q))

    def left_matrix(self):
        """``q+`` (..., 4, 4) with ``(q * p) == q.left_matrix() @ p`` as 4-vectors."""
        return _fq.left_matrix(self._q)

    def right_matrix(self):
        """``q(+)`` (..., 4, 4) with ``(p * q) == q.right_matrix() @ p`` as 4-vectors."""
        return _fq.right_matrix(self._q)

    def rotate(self, points):
        """``q p q^-1`` for points ``p`` (..., 3), any nonzero ``q``."""
        return _fq.rotate(self._q, points)

    def approx_equal(self, other, *, atol=1e-12, rtol=0.0):
        """``|q_i - o_i| <= atol + rtol |o_i|`` for all four components; shape (...).

        Componentwise (``q`` and ``-q`` differ here, unlike for rotations).
        """
        xp = namespace_of(self._q, other._q)
        close = xp.abs(self._q - other._q) <= atol + rtol * xp.abs(other._q)
        return xp.all(close, axis=-1)

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        vals = ", ".join(repr(c) for c in to_numpy(self._q).tolist())
        return f"Quaternion([{vals}])"


def _cast(a, dtype):
    """A NumPy or Dask array with ``dtype`` (Dask's ``astype`` stays lazy)."""
    return a if a.dtype == dtype else a.astype(dtype)
