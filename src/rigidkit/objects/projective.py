"""``Projective``: invertible projective transforms of 3D space, and the ladder of kinds.

A projective transform is an invertible 4x4 matrix ``H`` acting on homogeneous
points: ``p -> (x, y, z) / w`` with ``(x, y, z, w) = H [p; 1]``. ``H`` and ``c H``
(``c != 0``) are the same transform.

The kinds of transform form a ladder, each included in the next::

    Rotation  ⊂  Transform  ⊂  Similarity  ⊂  Affine  ⊂  Projective
     SO(3)        SE(3)         Sim(3)       (A, t)     PGL(4)

``a @ b`` of two kinds on the ladder is computed in the more general of the two
(``Transform @ Affine`` is an ``Affine``, ``Similarity @ Projective`` a
``Projective``). That rule lives here, once: :func:`compose` ranks both operands,
includes each into the higher kind (``kind._include``) and composes there.
"""

from __future__ import annotations

import numpy as np

from .._engine.namespace import device_of, is_float32, namespace_of
from .._validate import (
    _to_numpy,
    any_true,
    as_array,
    as_float,
    batch_index,
    check_finite,
    where_text,
)
from ..errors import PointAtInfinityError, SingularMatrixError
from ..kernels import homogeneous as _k
from ._batch import BatchedArray, batch_shape

__all__ = [
    "Projective",
    "SingularMatrixError",
    "PointAtInfinityError",
    "compose",
]


# -- the ladder ----------------------------------------------------------------------


_LADDER: tuple = ()


def _ladder() -> tuple:
    """The kinds, from the least to the most general (imported late: no cycles)."""
    global _LADDER
    if not _LADDER:
        from .affine import Affine
        from .rotation import Rotation
        from .similarity import Similarity
        from .transform import Transform

        _LADDER = (Rotation, Transform, Similarity, Affine, Projective)
    return _LADDER


def _rank(x) -> int:
    """Position of ``x``'s kind on the ladder, or -1 when it is not a transform."""
    for r, kind in enumerate(_ladder()):
        if type(x) is kind:
            return r
    return -1


def compose(a, b):
    """``a @ b`` (``b`` applied first) in the more general kind of the two.

    >>> import rigidkit as rk
    >>> S = rk.Similarity(scale=2.0)
    >>> T = rk.Transform(translation=[1.0, 0.0, 0.0])
    >>> type(compose(T, S)).__name__, type(compose(S, rk.Projective.identity())).__name__
    ('Similarity', 'Projective')
    """
    ra, rb = _rank(a), _rank(b)
    if ra < 0 or rb < 0:
        raise TypeError(
            f"cannot compose {type(a).__name__} with {type(b).__name__}: both must be "
            "Rotation, Transform, Similarity, Affine or Projective"
        )
    kind = _ladder()[max(ra, rb)]
    return kind._include(a)._compose(kind._include(b))


def homogeneous_matrix(x):
    """The 4x4 homogeneous matrix of any kind on the ladder (``[[R, 0], [0, 1]]`` for a
    rotation)."""
    if _rank(x) == 0:
        R = x.as_matrix()
        xp = namespace_of(R)
        M = xp.zeros(tuple(R.shape[:-2]) + (4, 4), dtype=R.dtype, device=device_of(R))
        if isinstance(M, np.ndarray):
            M[..., :3, :3] = R
            M[..., 3, 3] = 1.0
            return M
        col = xp.zeros(tuple(R.shape[:-1]) + (1,), dtype=R.dtype, device=device_of(R))
        top = xp.concat([R, col], axis=-1)
        last = xp.asarray([0.0, 0.0, 0.0, 1.0], dtype=R.dtype, device=device_of(R))
        last = xp.broadcast_to(last, tuple(R.shape[:-2]) + (1, 4))
        return xp.concat([top, last], axis=-2)
    return x.as_matrix()


def _include_check(cls, x, what):
    r = _rank(x)
    if r < 0 or r > _ladder().index(cls):
        raise TypeError(f"{what} takes a transform of a kind included in {cls.__name__}")


class _LadderMember:
    """``@`` for the kinds defined here: composition through :func:`compose`, or points."""

    __slots__ = ()
    # NumPy's binary operators defer to us (ndarray @ X reaches __rmatmul__).
    __array_ufunc__ = None
    __rmatmul_rigidkit__ = True  # marks us for Transform (and Rotation) to defer to

    def __matmul__(self, other):
        if type(other) is type(self):  # the common case, without ranking
            return self._compose(other)
        if _rank(other) >= 0:
            return compose(self, other)
        return self.apply(other)

    def __rmatmul__(self, other):
        if _rank(other) >= 0:
            return compose(other, self)
        name = type(self).__name__
        raise TypeError(f"array @ {name} is not defined; transform points with X @ p")


# -- tolerances ------------------------------------------------------------------------


def singular_rtol(dtype) -> float:
    """Default Hadamard-ratio threshold below which a matrix counts as singular.

    The ratio ``|det A| / prod |row_i|`` is about ``1 / cond`` of ``A`` with
    normalised rows (see :mod:`rigidkit.kernels.homogeneous`); below 1e-12
    (float64) or 1e-5 (float32) an inverse keeps fewer than about 4 (resp. 2)
    correct digits, so we refuse it.
    """
    return 1e-5 if is_float32(dtype) else 1e-12


def infinity_rtol(dtype) -> float:
    """Default threshold of ``|w| / max|x, y, z, w|`` below which a point is at infinity.

    64 eps of the dtype: ``w`` is then within a few dozen roundings of zero, so
    its sign, and the side of infinity the point lies on, are noise.
    """
    return _INF_RTOL_32 if is_float32(dtype) else _INF_RTOL_64


_INF_RTOL_32 = 64.0 * float(np.finfo(np.float32).eps)
_INF_RTOL_64 = 64.0 * float(np.finfo(np.float64).eps)


def check_invertible(ratio, rtol, what):
    """Raise :class:`SingularMatrixError` where the Hadamard ``ratio`` is <= ``rtol``."""
    bad = ratio <= rtol
    if any_true(bad):
        idx = batch_index(bad)
        r = float(_to_numpy(ratio)[idx])
        raise SingularMatrixError(
            f"{what} {where_text(idx)} is singular: |det| / prod(|row|) = {r:.3g} "
            f"<= {rtol:g}"
        )


# -- the class -----------------------------------------------------------------------------


class Projective(BatchedArray, _LadderMember):
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

    def __init__(self, matrix, *, rtol=None):
        H = as_float(as_array(matrix, (4, 4), "projective matrix"))
        check_finite(H, (4, 4), "projective matrix")
        tol = singular_rtol(H.dtype) if rtol is None else rtol
        check_invertible(_k.projective_hadamard_ratio(H), tol, "projective matrix")
        self._data = H

    @classmethod
    def from_matrix(cls, matrix, *, rtol=None):
        """From 4x4 matrices, validated (finite, invertible); same as the constructor."""
        return cls(matrix, rtol=rtol)

    @classmethod
    def from_affine(cls, affine):
        """The inclusion: an :class:`~rigidkit.Affine` (or any kind below it) as ``H``."""
        _include_check(cls, affine, "Projective.from_affine")
        return cls._include(affine)

    @classmethod
    def _include(cls, x):
        return x if type(x) is cls else cls._wrap(homogeneous_matrix(x))

    @classmethod
    def identity(cls, shape=(), *, dtype=None):
        """Identity transforms of batch ``shape``."""
        return cls._wrap(cls._filled(np.eye(4), shape, dtype))

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
        """The matrices ``H``, shape (..., 4, 4) (as stored: not normalised)."""
        return self._data

    def as_projective(self):
        return self

    # -- operations ----------------------------------------------------------------------
    def _compose(self, other):
        return Projective._wrap(_k.projective_compose(self._data, other._data))

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
        if any_true(far):
            xp = namespace_of(far)
            if at_infinity == "raise":
                idx = batch_index(far)
                r = float(_to_numpy(ratio)[idx])
                raise PointAtInfinityError(
                    f"projective transform maps the point {where_text(idx)} to infinity: "
                    f"|w| / max(|x|, |y|, |z|, |w|) = {r:.3g} <= {tol:.3g}; "
                    'apply(..., at_infinity="nan") marks such points with NaN instead'
                )
            nan = xp.asarray(float("nan"), dtype=out.dtype, device=device_of(out))
            out = xp.where(far[..., None], nan, out)
        return out

    def apply_homogeneous(self, points):
        """``H [p; 1]``, shape (..., 4): the images before the homogeneous divide."""
        return _k.projective_apply_homogeneous(self._data, as_array(points, (3,), "points"))

    def approx_equal(self, other, *, atol=1e-12):
        """Elementwise: equal up to scale, ``max|H1 / |H1| -+ H2 / |H2|| <= atol``.

        Each matrix is divided by its Frobenius norm and the sign is chosen to match.
        """
        other = Projective._include(other)
        xp = namespace_of(self._data, other._data)
        a = self._data / xp.sqrt(xp.sum(self._data**2, axis=(-2, -1)))[..., None, None]
        b = other._data / xp.sqrt(xp.sum(other._data**2, axis=(-2, -1)))[..., None, None]
        shape = tuple(a.shape[:-2]) + (16,)
        same = xp.all(xp.reshape(xp.abs(a - b) <= atol, shape), axis=-1)
        flipped = xp.all(xp.reshape(xp.abs(a + b) <= atol, shape), axis=-1)
        return same | flipped

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        return f"Projective({_to_numpy(self._data).tolist()!r})"
