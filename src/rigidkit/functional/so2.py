"""The Lie group SO(2) in functional form (arrays in, arrays out).

A planar rotation by ``θ`` (radians, counter-clockwise) is the matrix
``exp(θ J) = [[cos θ, -sin θ], [sin θ, cos θ]]``, ``J = [[0, -1], [1, 0]]``, or
the unit complex number ``e^{iθ}``. Tangent vectors are 1-vectors ``(θ,)``, shape
(..., 1), like the ``(..., dof)`` tangent vectors of every other group, so that
``adjoint(R) @ tau`` and the Jacobians compose as matrices. SO(2) is commutative:
the adjoint and all Jacobians are ``[[1]]`` and the bracket is 0.

Every function is batched over leading axes and keeps the array namespace and
dtype of its input.

>>> import numpy as np
>>> R = exp(np.array([np.pi / 2]))
>>> np.round(R, 12) + 0.0
array([[ 0., -1.],
       [ 1.,  0.]])
>>> log(R)
array([1.57079633])
"""

from __future__ import annotations

from .._validate import as_array, check_rotation_2d, finite_array, raise_where
from ..errors import ZeroNormError
from ..kernels import so2 as _k
from . import _lie

__all__ = [*_lie.VOCABULARY, "complex_from_matrix", "complex_normalize"]


def _tangent(w, what="so(2) vector"):
    return finite_array(w, (1,), what)


def hat(w):
    """``hat(θ) = θ J = [[0, -θ], [θ, 0]]``: shape (..., 1) -> (..., 2, 2).

    >>> hat([2.0])
    array([[ 0., -2.],
           [ 2.,  0.]])
    """
    return _k.hat(as_array(w, (1,), "so(2) vector"))


def vee(W):
    """Inverse of :func:`hat` (skew part ``(W - W^T)/2``): (..., 2, 2) -> (..., 1)."""
    return _k.vee(as_array(W, (2, 2), "so(2) matrix"))


def exp(w):
    """Rotation matrices ``expm(hat(θ))``: shape (..., 1) radians -> (..., 2, 2).

    See Also
    --------
    log
    """
    return _k.matrix_from_angle(_tangent(w, "rotation angle"))


def log(R, *, atol=None):
    """Angle in (-pi, pi] of rotation matrices, validated: (..., 2, 2) -> (..., 1).

    Parameters
    ----------
    R : array_like, shape (..., 2, 2)
    atol : float, optional
        Tolerance of the SO(2) check, see :func:`complex_from_matrix`.

    See Also
    --------
    exp
    """
    return _k.angle_from_complex(complex_from_matrix(R, atol=atol))


def adjoint(R, *, atol=None):
    """``Ad(R) = [[1]]`` of rotation matrices (validated): (..., 2, 2) -> (..., 1, 1)."""
    return _k.adjoint_from_complex(complex_from_matrix(R, atol=atol))


def ad(w):
    """Small adjoint ``ad(θ) = [[0]]``: (..., 1) -> (..., 1, 1)."""
    return _k.ad(_tangent(w))


def bracket(u, w):
    """Lie bracket ``[u, w] = 0`` (so(2) is abelian): (..., 1) -> (..., 1)."""
    return _k.bracket(_tangent(u), _tangent(w))


def left_jacobian(w):
    """Left Jacobian ``[[1]]`` (``exp(θ + δ) = exp(δ) exp(θ)``): (..., 1) -> (..., 1, 1)."""
    return _k.jacobian(_tangent(w))


def left_jacobian_inverse(w):
    """Inverse of :func:`left_jacobian`: ``[[1]]``, shape (..., 1, 1)."""
    return _k.jacobian(_tangent(w))


right_jacobian, right_jacobian_inverse = _lie.right_jacobians(
    __name__, "SO(2)", 1, "so(2) vector", _k.jacobian, _k.jacobian
)


def complex_normalize(z, *, what="complex number"):
    """Unit ``(cos θ, sin θ)`` pairs of nonzero ``(re, im)`` pairs, shape (..., 2).

    Raises
    ------
    NonFiniteError, ZeroNormError
        For NaN/inf components or a zero pair, naming the batch index.
    """
    z = finite_array(z, (2,), what)
    unit, norm = _k.complex_normalize(z)
    raise_where(
        norm == 0.0, ZeroNormError, f"{what} is zero {{where}}; it names no rotation"
    )
    return unit


def complex_from_matrix(matrix, *, atol=None, orthonormalize=False):
    """Unit complex numbers ``(cos θ, sin θ)`` of 2x2 rotation matrices, validated.

    ``matrix`` (array_like, shape (..., 2, 2)) holds active rotations acting on
    column vectors; the result has shape (..., 2). ``atol`` is the largest accepted
    ``max(|R^T R - I|, |det R - 1|)`` (default
    :func:`rigidkit._validate.default_atol`: 1e-5 for float64, 1e-4 for float32).
    With ``orthonormalize=True`` the nearest rotation in Frobenius norm is taken
    instead of raising: ``(m00 + m11, m10 - m01)`` normalised.

    Raises
    ------
    NonFiniteError
        NaN or inf anywhere.
    NotARotationError
        A matrix is not a rotation within ``atol`` (a reflection, a scaling, a
        shear), or has no unique nearest rotation, naming the first such batch
        index and why.
    """
    m = finite_array(matrix, (2, 2), "rotation matrix")
    z, norm, err = _k.complex_from_matrix(m)
    check_rotation_2d(m, norm, err, atol=atol, orthonormalize=orthonormalize)
    return z
