"""``Affine``: invertible affine transforms of 3D space, ``p -> A p + t``.

The homogeneous matrix is ``[[A, t], [0, 1]]`` with ``A`` any invertible 3x3 matrix
(rotations, scalings, shears, reflections). It sits between
:class:`~rigidkit.Similarity` and :class:`~rigidkit.Projective` on the ladder of
kinds (see :mod:`rigidkit.objects.ladder`): composing with a lower kind gives an
``Affine``, with a ``Projective`` a ``Projective``.
"""

from __future__ import annotations

import functools

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import device_of, namespace_of
from .._validate import (
    as_array,
    as_float,
    check_bottom_row,
    check_finite,
    check_invertible,
    singular_rtol,
    to_numpy,
)
from ..errors import NotAffineError
from ..kernels import homogeneous as _k
from ._batch import BatchedArray, batch_shape
from ._frozen import frozen
from .group import Group
from .ladder import homogeneous_matrix
from .projective import Projective, _checked_per_chunk

__all__ = ["Affine", "NotAffineError"]


class Affine(BatchedArray, Group, family="space", rank=3):
    """A batch of invertible affine transforms ``p -> A p + t``.

    Stored as one array of shape (..., 3, 4), ``[A | t]``. ``X1 @ X2`` applies ``X2``
    first: ``[A1 A2 | A1 t2 + t1]``; ``X @ p`` maps points (..., 3).

    Parameters
    ----------
    matrix : array_like, shape (..., 3, 3), optional
        The linear part ``A`` (identity when omitted); finite and invertible: a
        Hadamard ratio ``|det A| / prod |row_i|`` <= ``rtol`` raises
        :class:`~rigidkit.SingularMatrixError` naming the batch index.
    translation : array_like, shape (..., 3), optional
        ``t`` (zero when omitted). Batch shapes broadcast.
    rtol : float, optional
        Default 1e-12 (float64) or 1e-5 (float32), see
        :func:`rigidkit._validate.singular_rtol`.

    Examples
    --------
    >>> X = Affine(matrix=[[2.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ...            translation=[0.0, 0.0, 5.0])
    >>> X @ np.array([1.0, 1.0, 1.0])
    array([3., 1., 6.])
    >>> X.inv() @ (X @ np.array([1.0, 1.0, 1.0]))
    array([1., 1., 1.])
    """

    __slots__ = ("_data",)
    _trail = (3, 4)
    _repr_columns = "[A | t]"
    _identity = np.eye(3, 4)  # [I | 0]
    _compose_kernel = _k.affine_compose

    def __init__(self, matrix=None, translation=None, *, rtol=None):
        A = (
            None
            if matrix is None
            else as_float(as_array(matrix, (3, 3), "affine matrix A"))
        )
        t = (
            None
            if translation is None
            else as_float(as_array(translation, (3,), "translation"))
        )
        if A is None and t is None:
            A = np.eye(3)
        lazy = dask_backend.any_dask(A, t)  # checked per chunk at compute time, below
        if A is not None and not lazy:
            check_finite(A, (3, 3), "affine matrix A")
        if t is not None and not lazy:
            check_finite(t, (3,), "translation")
        ref = A if A is not None else t
        xp = namespace_of(ref)
        dt = ref.dtype if A is None or t is None else _result_dtype(xp, A, t)
        dev = device_of(ref)
        if A is None:
            A = xp.asarray(np.eye(3), dtype=dt, device=dev)
        if t is None:
            t = xp.zeros((3,), dtype=dt, device=dev)
        A, t = _cast(xp, A, dt), _cast(xp, t, dt)
        batch = tuple(np.broadcast_shapes(tuple(A.shape[:-2]), tuple(t.shape[:-1])))
        data = xp.concat(
            [
                xp.broadcast_to(A, batch + (3, 3)),
                xp.broadcast_to(t[..., None], batch + (3, 1)),
            ],
            axis=-1,
        )
        tol = singular_rtol(data.dtype) if rtol is None else rtol
        if lazy:
            data = _checked_per_chunk(data, functools.partial(_check_data, rtol=tol))
        else:
            check_invertible(_k.affine_hadamard_ratio(data), tol, "affine matrix A")
        self._data = data

    @classmethod
    def from_matrix(cls, matrix, *, atol=None, rtol=None):
        """From homogeneous matrices ``[[A, t], [0, 1]]``, shape (..., 4, 4), validated.

        Raises
        ------
        NonFiniteError
            NaN or infinity anywhere.
        NotAffineError
            The bottom row differs from ``[0, 0, 0, 1]`` by more than ``atol``
            (default 1e-5 for float64, 1e-4 for float32), naming the batch index.
        SingularMatrixError
            ``A`` is singular (see the class docs), naming the batch index.
        """
        M = as_float(as_array(matrix, (4, 4), "homogeneous matrix"))
        if dask_backend.is_dask(M):
            M = _checked_per_chunk(M, functools.partial(_check_homogeneous, atol=atol))
        else:
            _check_homogeneous(M, atol)
        return cls(matrix=M[..., :3, :3], translation=M[..., :3, 3], rtol=rtol)

    @classmethod
    def from_similarity(cls, similarity):
        """The inclusion: a :class:`~rigidkit.Similarity` (or a ``Transform`` or
        ``Rotation``) as the affine map ``[[s R, t], [0, 1]]``."""
        return cls.include(similarity)

    @classmethod
    def _include(cls, x):
        return cls._wrap(homogeneous_matrix(x)[..., :3, :])

    @classmethod
    def random(cls, shape=(), rng=None, *, dtype=None):
        """Random transforms: ``A`` = identity + standard normal / 2, ``t`` standard normal.

        Invertible with probability 1; ``rng`` is a Generator or a seed.
        """
        shape = batch_shape(shape)
        rng = np.random.default_rng(rng)
        A = np.eye(3) + 0.5 * rng.standard_normal(shape + (3, 3))
        t = rng.standard_normal(shape + (3,))
        if dtype is not None:
            A, t = A.astype(dtype), t.astype(dtype)
        return cls(matrix=A, translation=t)

    # -- representations ------------------------------------------------------------
    @property
    def matrix(self):
        """The linear part ``A``, shape (..., 3, 3) (read-only for NumPy storage)."""
        return frozen(self._data[..., :3])

    @property
    def translation(self):
        """The translation ``t``, shape (..., 3) (read-only for NumPy storage)."""
        return frozen(self._data[..., 3])

    def as_matrix(self):
        """Homogeneous matrices ``[[A, t], [0, 1]]``, shape (..., 4, 4)."""
        xp = namespace_of(self._data)
        last = xp.asarray(
            [0.0, 0.0, 0.0, 1.0], dtype=self._data.dtype, device=device_of(self._data)
        )
        last = xp.broadcast_to(last, self.shape + (1, 4))
        return xp.concat([self._data, last], axis=-2)

    def as_projective(self):
        """The same transforms as :class:`~rigidkit.Projective`."""
        return Projective.include(self)

    # -- operations --------------------------------------------------------------------
    def apply(self, points):
        """``A p + t`` for points of shape (..., 3), broadcasting with the batch shape."""
        return _k.affine_apply(self._data, as_array(points, (3,), "points"))

    def inv(self, *, rtol=None):
        """Inverse transforms ``[A^-1 | -A^-1 t]``.

        Raises :class:`~rigidkit.SingularMatrixError` if ``A`` became singular to
        working precision (a product of ill-conditioned factors can).
        """
        inv, ratio = _k.affine_inverse(self._data)
        tol = singular_rtol(self._data.dtype) if rtol is None else rtol
        check_invertible(ratio, tol, "affine matrix A")
        return Affine._wrap(inv)

    def approx_equal(self, other, *, atol=1e-12):
        """Elementwise ``max |[A1 | t1] - [A2 | t2]| <= atol``, shape (...)."""
        other = Affine.include(other)
        xp = namespace_of(self._data, other._data)
        close = xp.abs(self._data - other._data) <= atol
        return xp.all(xp.reshape(close, self.shape + (12,)), axis=-1)

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        d = to_numpy(self._data).tolist()
        A = [row[:3] for row in d]
        t = [row[3] for row in d]
        return f"Affine(matrix={A!r}, translation={t!r})"


def _check_data(data, rtol):
    """The constructor's checks of ``[A | t]`` (..., 3, 4)."""
    check_finite(data[..., :3], (3, 3), "affine matrix A")
    check_finite(data[..., 3], (3,), "translation")
    check_invertible(_k.affine_hadamard_ratio(data), rtol, "affine matrix A")


def _check_homogeneous(M, atol):
    """:meth:`Affine.from_matrix`'s checks of ``[[A, t], [0, 1]]`` (..., 4, 4)."""
    check_finite(M, (4, 4), "homogeneous matrix")
    check_bottom_row(M, atol, "an affine transform", NotAffineError)


def _cast(xp, a, dtype):
    """``a`` with ``dtype``, in its own namespace: Dask arrays stay lazy (``asarray``
    of one would compute it), torch tensors keep their graph."""
    if a.dtype == dtype:
        return a
    if hasattr(a, "astype"):  # NumPy, JAX, Dask
        return a.astype(dtype)
    return xp.asarray(a, dtype=dtype)


def _result_dtype(xp, a, b):
    if isinstance(a, np.ndarray) and isinstance(b, np.ndarray):
        return np.result_type(a, b)
    return a.dtype if a.dtype == b.dtype else xp.float64
