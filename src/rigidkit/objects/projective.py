"""``Projective``: invertible projective transforms of 3D space.

A projective transform is an invertible 4x4 matrix ``H`` acting on homogeneous
points: ``p -> (x, y, z) / w`` with ``(x, y, z, w) = H [p; 1]``. ``H`` and ``c H``
(``c != 0``) are the same transform. It is the most general kind on the ladder of
:mod:`rigidkit.objects.ladder`: every other kind of the space composes with it into
a ``Projective``.
"""

from __future__ import annotations

import functools

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import device_of, namespace_of
from .._validate import (
    _relabel,
    any_true,
    as_array,
    as_float,
    check_finite,
    check_invertible,
    infinity_rtol,
    raise_where,
    singular_rtol,
    to_numpy,
    validation_enabled,
)
from ..errors import PointAtInfinityError, SingularMatrixError
from ..kernels import homogeneous as _k
from ._batch import BatchedArray, batch_shape
from ._frozen import frozen, owned
from .group import Group
from .ladder import homogeneous_matrix

__all__ = ["Projective", "SingularMatrixError", "PointAtInfinityError"]


# -- the class -----------------------------------------------------------------------------


class Projective(BatchedArray, Group, family="space", rank=4):
    """A batch of invertible projective transforms of 3D space, one 4x4 matrix each.

    ``p -> (x, y, z) / w`` with ``(x, y, z, w) = H [p; 1]``; ``H`` and ``c H`` act the
    same. ``H1 @ H2`` applies ``H2`` first (matrix-product order). Points mapped to
    infinity (``w`` = 0 within a tolerance) are reported, never divided by zero: see
    :meth:`apply`.

    Parameters
    ----------
    matrix : array_like, shape (..., 4, 4)
        Finite, invertible: a matrix whose Hadamard ratio ``|det H| / prod |row_i|``
        is <= ``rtol`` raises :class:`SingularMatrixError` naming the batch index.
    rtol : float, optional
        Default :func:`singular_rtol` (1e-12 for float64, 1e-5 for float32).

    Examples
    --------
    >>> H = np.eye(4)
    >>> H[3, 2] = 1.0          # w' = z + 1: a perspective division by (z + 1)
    >>> P = Projective(H)
    >>> P @ np.array([2.0, 4.0, 1.0])
    array([1. , 2. , 0.5])
    >>> P @ np.array([2.0, 4.0, -1.0])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    rigidkit.errors.PointAtInfinityError: projective transform maps the point ...
    >>> P.apply(np.array([[2.0, 4.0, 1.0], [2.0, 4.0, -1.0]]), at_infinity="nan")
    array([[1. , 2. , 0.5],
           [nan, nan, nan]])
    """

    __slots__ = ("_data",)
    _trail = (4, 4)
    _repr_columns = "H"
    _identity = np.eye(4)
    _compose_kernel = _k.projective_compose

    def __init__(self, matrix, *, rtol=None):
        H = as_float(as_array(matrix, (4, 4), "projective matrix"))
        tol = singular_rtol(H.dtype) if rtol is None else rtol
        if dask_backend.is_dask(H):  # checked per chunk at compute time
            self._data = _checked_per_chunk(H, functools.partial(_check_matrix, rtol=tol))
            return
        _check_matrix(H, tol)
        self._data = owned(H, matrix)  # not the caller's array: objects are immutable

    @classmethod
    def from_matrix(cls, matrix, *, rtol=None):
        """From 4x4 matrices, validated (finite, invertible); same as the constructor."""
        return cls(matrix, rtol=rtol)

    @classmethod
    def from_affine(cls, affine):
        """The inclusion: an :class:`~rigidkit.Affine` (or any kind below it) as ``H``."""
        return cls.include(affine)

    @classmethod
    def _include(cls, x):
        return cls._wrap(homogeneous_matrix(x))

    @classmethod
    def random(cls, shape=(), rng=None, *, dtype=None):
        """Random transforms: the identity plus standard normal entries / 4.

        Invertible with probability 1; ``rng`` is a Generator or a seed.
        """
        rng = np.random.default_rng(rng)
        H = np.eye(4) + 0.25 * rng.standard_normal(batch_shape(shape) + (4, 4))
        return cls(H.astype(dtype) if dtype is not None else H)

    # -- representations ---------------------------------------------------------------
    def as_matrix(self):
        """The matrices ``H``, shape (..., 4, 4) (as stored: not normalised; read-only
        for NumPy storage)."""
        return frozen(self._data)

    def as_projective(self):
        return self

    # -- operations ----------------------------------------------------------------------
    def inv(self, *, rtol=None):
        """Inverse transforms ``H^-1`` (adjugate; raises if ``H`` became singular)."""
        inv, ratio = _k.projective_inverse(self._data)
        tol = singular_rtol(self._data.dtype) if rtol is None else rtol
        check_invertible(ratio, tol, "projective matrix")
        return Projective._wrap(inv)

    def apply(self, points, *, at_infinity="raise", rtol=None):
        """Map points, shape (..., 3): ``(x, y, z) / w`` for ``H [p; 1]``.

        A point whose image has ``|w| <= rtol max(|x|, |y|, |z|, |w|)`` is at infinity
        (default ``rtol`` from :func:`infinity_rtol`: 64 eps).

        Parameters
        ----------
        at_infinity : {"raise", "nan"}
            ``"raise"``: :class:`PointAtInfinityError` naming the first such batch
            index. ``"nan"``: those points come back as NaN (all three components),
            the others as usual. Use :meth:`apply_homogeneous` for the 4-vectors.
        """
        if at_infinity not in ("raise", "nan"):
            raise ValueError(f"at_infinity must be 'raise' or 'nan', got {at_infinity!r}")
        p = as_array(points, (3,), "points")
        out, ratio = _k.projective_apply(self._data, p)
        tol = infinity_rtol(out.dtype) if rtol is None else rtol
        far = ratio <= tol
        if not any_true(far):
            return out
        if at_infinity == "raise":
            raise_where(
                far,
                PointAtInfinityError,
                "projective transform maps the point {where} to infinity: |w| / "
                f"max(|x|, |y|, |z|, |w|) = {{value:.3g}} <= {tol:.3g}; "
                'apply(..., at_infinity="nan") marks such points with NaN instead',
                value=ratio,
            )
        xp = namespace_of(far)
        nan = xp.asarray(float("nan"), dtype=out.dtype, device=device_of(out))
        return xp.where(far[..., None], nan, out)

    def apply_homogeneous(self, points):
        """``H [p; 1]``, shape (..., 4): the images before the homogeneous divide."""
        return _k.projective_apply_homogeneous(self._data, as_array(points, (3,), "points"))

    def approx_equal(self, other, *, atol=1e-12):
        """Elementwise: equal up to scale, ``max|H1 / |H1| -+ H2 / |H2|| <= atol``.

        Each matrix is divided by its Frobenius norm and the sign is chosen to match.
        """
        other = Projective.include(other)
        xp = namespace_of(self._data, other._data)
        a = self._data / xp.sqrt(xp.sum(self._data**2, axis=(-2, -1)))[..., None, None]
        b = other._data / xp.sqrt(xp.sum(other._data**2, axis=(-2, -1)))[..., None, None]
        shape = tuple(a.shape[:-2]) + (16,)
        same = xp.all(xp.reshape(xp.abs(a - b) <= atol, shape), axis=-1)
        flipped = xp.all(xp.reshape(xp.abs(a + b) <= atol, shape), axis=-1)
        return same | flipped

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        return f"Projective({to_numpy(self._data).tolist()!r})"


def _check_matrix(H, rtol):
    """The constructor's checks of ``H`` (..., 4, 4): finite, invertible."""
    check_finite(H, (4, 4), "projective matrix")
    check_invertible(_k.projective_hadamard_ratio(H), rtol, "projective matrix")


def _passed(check, block):
    check(block)
    return block


def _checked_per_chunk(x, check):
    """The Dask array ``x`` (..., m, n), each chunk passed through the NumPy ``check``
    at compute time (errors name the global batch index). Nothing is computed now;
    the checks travel with ``x`` itself (a check deferred on a value derived from
    ``x``, such as a Hadamard ratio, would go with that value only)."""
    if not validation_enabled():
        return x
    return dask_backend.map_batched(
        functools.partial(_passed, check),
        [x],
        [2],
        _relabel,
        outputs=[(tuple(x.shape[-2:]), x.dtype)],
    )
