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

from . import conversions as _conv
from ._validate import as_array, check_finite
from .kernels import rotvec as _rv
from .kernels import so3 as _k

__all__ = ["hat", "vee", "exp", "log"]


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
        Rotation vectors, radians.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    w = as_array(w, (3,), "rotation vector")
    check_finite(w, (3,), "rotation vector")
    return _rv.matrix_from_rotvec(w)


def log(R, *, atol=None):
    """Rotation vector (angle in [0, pi]) of a rotation matrix, validated.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
    atol : float, optional
        Tolerance of the SO(3) check, see :func:`rigidkit.conversions.quat_from_matrix`.
    """
    return _rv.rotvec_from_quat(_conv.quat_from_matrix(R, atol=atol))
