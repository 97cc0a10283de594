"""The Lie group SO(3) in functional form: hat, vee, exp, log (arrays in and out).

Rotation vectors ``w = theta * axis`` (radians) live in the tangent space; ``hat(w)``
is the skew matrix with ``hat(w) @ v == cross(w, v)``; ``exp(w)`` is the rotation
matrix ``expm(hat(w))`` (Rodrigues) and ``log`` its inverse with angle in [0, pi].

>>> import numpy as np
>>> w = np.array([0.1, -0.2, 0.3])
>>> bool(np.allclose(log(exp(w)), w))
True
"""

from __future__ import annotations

from .._validate import as_array, finite_array
from ..kernels import so3 as _k
from . import _lie
from . import conversions as _conv

__all__ = list(_lie.VOCABULARY)

# Jacobian conventions, for rotation vectors w and small d:
#   left:  exp(w + d) ~ exp(J_l(w) d) exp(w)     right: exp(w + d) ~ exp(w) exp(J_r(w) d)
#   J_r(w) = J_l(-w) = J_l(w)^T.


def _rotvec(w):
    return finite_array(w, (3,), "rotation vector")


def hat(w):
    """Skew-symmetric matrix of ``w``: shape (..., 3) -> (..., 3, 3)."""
    return _k.hat(as_array(w, (3,), "so(3) vector"))


def vee(W):
    """Vector of a skew matrix (its skew-symmetric part): (..., 3, 3) -> (..., 3)."""
    return _k.vee(as_array(W, (3, 3), "so(3) matrix"))


def exp(w):
    """Rotation matrix ``expm(hat(w))`` of a rotation vector (Rodrigues' formula).

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Rotation vectors ``angle * axis``, radians; any angle (not only [0, pi]).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Rotation matrices acting on column vectors.
    """
    return _k.matrix_from_rotvec(_rotvec(w))


def log(R, *, atol=None):
    """Rotation vector (angle in [0, pi]) of a rotation matrix, validated.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
    atol : float, optional
        Tolerance of the SO(3) check, see :func:`rigidkit.conversions.quat_from_matrix`.
    """
    return _k.rotvec_from_quat(_conv.quat_from_matrix(R, atol=atol))


def adjoint(R, *, atol=None):
    """Adjoint of SO(3), the rotation matrix itself: ``R hat(w) R^T = hat(R w)``.

    ``R`` is validated (see :func:`rigidkit.conversions.quat_from_matrix`) and the
    result is a new array, the rotation matrix rebuilt from its quaternion.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
    atol : float, optional
        Tolerance of the SO(3) check.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    return _conv.matrix_from_quat_unchecked(_conv.quat_from_matrix(R, atol=atol))


def ad(w):
    """Small adjoint of so(3), ``hat(w)``: (..., 3) -> (..., 3, 3).

    ``ad(u) @ v == bracket(u, v) == u x v``.
    """
    return hat(w)


def bracket(u, v):
    """Lie bracket of so(3): ``vee(hat(u) hat(v) - hat(v) hat(u)) = u x v``.

    Parameters
    ----------
    u, v : array_like, shape (..., 3)
        Batch shapes broadcast.

    Returns
    -------
    ndarray, shape (..., 3)

    >>> bracket([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    array([0., 0., 1.])
    """
    u = as_array(u, (3,), "so(3) vector")
    return _k.bracket(u, as_array(v, (3,), "so(3) vector"))


def left_jacobian(w):
    """Left Jacobian of SO(3): ``exp(w + d) ~ exp(J_l(w) d) exp(w)`` to first order.

    ``J_l = I + (1 - cos t)/t^2 hat(w) + (t - sin t)/t^3 hat(w)^2`` with ``t = |w|``
    (small-angle series in the coefficient helpers); also ``sum_k hat(w)^k/(k+1)!``.

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Rotation vectors, radians.

    Returns
    -------
    ndarray, shape (..., 3, 3)

    See Also
    --------
    right_jacobian, left_jacobian_inverse

    >>> import numpy as np
    >>> np.round(left_jacobian([0.0, 0.0, np.pi / 2]), 6) + 0.0  # 2/pi = 0.63662
    array([[ 0.63662, -0.63662,  0.     ],
           [ 0.63662,  0.63662,  0.     ],
           [ 0.     ,  0.     ,  1.     ]])
    """
    return _k.left_jacobian(_rotvec(w))


def left_jacobian_inverse(w):
    """Inverse of :func:`left_jacobian`: ``log(exp(d) exp(w)) ~ w + J_l(w)^-1 d``.

    ``J_l^-1 = I - hat(w)/2 + (1 - (t/2) cot(t/2))/t^2 hat(w)^2`` for rotation
    vectors ``w`` (..., 3), finite for ``t = |w| < 2 pi``; shape (..., 3, 3).
    """
    return _k.left_jacobian_inverse(_rotvec(w))


right_jacobian, right_jacobian_inverse = _lie.right_jacobians(
    __name__, "SO(3)", 3, "rotation vector", _k.left_jacobian, _k.left_jacobian_inverse
)
