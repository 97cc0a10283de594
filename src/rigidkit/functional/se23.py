"""The Lie group SE_2(3) of extended poses in functional form (arrays in, arrays out).

An extended pose is a navigation state ``(R, v, p)`` (Barrau & Bonnabel 2017): the
orientation of a body frame in the navigation frame (``world``), its velocity and
its position in that frame. Stored as arrays ``(w, x, y, z, vx, vy, vz, px, py, pz)``
(unit quaternion, Hamilton, scalar first); its matrix is the 5x5
``[[R, v, p], [0, 1, 0], [0, 0, 1]]``. Tangents are ordered ``(rho_v, rho_p, w)``,
``hat(xi) = [[hat(w), rho_v, rho_p], [0, 0, 0], [0, 0, 0]]``.

======================  ==========================================================
``exp(xi)``             ``expm(hat(xi)) = (exp(hat(w)), J_l(w) rho_v, J_l(w) rho_p)``
``log(M)``              ``(J_l(w)^-1 v, J_l(w)^-1 p, w)``, ``|w|`` in [0, pi]
``adjoint(M)``          ``[[R, 0, hat(v) R], [0, R, hat(p) R], [0, 0, R]]``
``ad(xi)``              ``[[hat(w), 0, hat(rho_v)], [0, hat(w), hat(rho_p)],
                        [0, 0, hat(w)]]``
``bracket(a, b)``       ``vee(hat(a) hat(b) - hat(b) hat(a))``
``left_jacobian(xi)``   ``exp(xi + d) ~ exp(J_l d) exp(xi)``; ``[[J, 0, Q_v], [0, J, Q_p],
                        [0, 0, J]]``, ``Q`` Barfoot's (2017, eq. 7.86)
``right_jacobian(xi)``  ``exp(xi + d) ~ exp(xi) exp(J_r d)``; ``J_r(xi) = J_l(-xi)``
======================  ==========================================================

>>> import numpy as np
>>> xi = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, np.pi / 2])
>>> np.round(exp(xi), 6) + 0.0
array([[ 0.     , -1.     ,  0.     ,  0.63662,  0.     ],
       [ 1.     ,  0.     ,  0.     ,  0.63662,  0.     ],
       [ 0.     ,  0.     ,  1.     ,  0.     ,  1.     ],
       [ 0.     ,  0.     ,  0.     ,  1.     ,  0.     ],
       [ 0.     ,  0.     ,  0.     ,  0.     ,  1.     ]])
>>> bool(np.allclose(log(exp(xi)), xi))
True
"""

from __future__ import annotations

from .._validate import as_array, check_bottom_row, finite_array
from ..errors import NotARigidTransformError, NotARotationError
from ..kernels import se23 as _k
from . import _lie
from . import conversions as _conv

__all__ = [
    *_lie.VOCABULARY,
    "extpose_from_matrix",
    "matrix_from_extpose",
    "extpose_from_tangent",
    "tangent_from_extpose",
    "extpose_from_parts",
]

# Rows and columns 3 and 4 swapped: its bottom row is the 4th row of the matrix,
# ``[0, 0, 0, 1, 0]`` read as ``[0, 0, 0, 0, 1]`` (one check for both rows).
_SWAP = [0, 1, 2, 4, 3]


def _tangent(xi):
    return finite_array(xi, (9,), "se_2(3) tangent")


def extpose_from_parts(quat, velocity, position):
    """Extended poses ``(q, v, p)``, (..., 10), from unit quaternions, velocities and
    positions (batch shapes broadcast; the quaternion is normalised)."""
    q = _conv.quat_normalize(quat, what="extended-pose quaternion")
    v = finite_array(velocity, (3,), "velocity")
    p = finite_array(position, (3,), "position")
    return _k.extpose_from_parts(q, v, p)


def _extpose(x):
    x = as_array(x, (10,), "extended pose")
    return extpose_from_parts(x[..., :4], x[..., 4:7], x[..., 7:])


def hat(xi):
    """``[[hat(w), rho_v, rho_p], [0, 0, 0], [0, 0, 0]]`` of tangents ``(rho_v, rho_p, w)``.

    (..., 9) -> (..., 5, 5); the inverse of :func:`vee`, a linear map.
    """
    return _k.hat(as_array(xi, (9,), "se_2(3) tangent"))


def vee(X):
    """Tangents ``(rho_v, rho_p, w)`` of se_2(3) matrices, (..., 5, 5) -> (..., 9).

    ``rho_v``, ``rho_p`` are the 4th and 5th columns, ``w`` the vector of the skew
    part of the 3x3 block; the inverse of :func:`hat`.
    """
    return _k.vee(as_array(X, (5, 5), "se_2(3) matrix"))


def extpose_from_tangent(xi):
    """Extended poses ``(q, v, p)`` of ``exp(hat(xi))``, tangents ``(rho_v, rho_p, w)``."""
    return _k.extpose_from_tangent(_tangent(xi))


def tangent_from_extpose(x):
    """Tangents ``(rho_v, rho_p, w)``, ``|w|`` in [0, pi], of extended poses (..., 10)."""
    return _k.tangent_from_extpose(_extpose(x))


def matrix_from_extpose(x):
    """The 5x5 matrices ``[[R, v, p], [0, 1, 0], [0, 0, 1]]`` of extended poses."""
    return _k.matrix_from_extpose(_extpose(x))


def exp(xi):
    """The 5x5 matrix ``expm(hat(xi))`` of tangents ``xi = (rho_v, rho_p, w)``.

    ``(R, J_l(w) rho_v, J_l(w) rho_p)`` with ``R = exp(hat(w))`` and ``J_l`` the SO(3)
    left Jacobian (the SE(3) exponential for each column).

    Parameters
    ----------
    xi : array_like, shape (..., 9)
        ``w`` in radians.

    Returns
    -------
    ndarray, shape (..., 5, 5)
    """
    return _k.matrix_from_extpose(_k.extpose_from_tangent(_tangent(xi)))


def extpose_from_matrix(M, *, atol=None, orthonormalize=False):
    """Extended poses ``(q, v, p)`` of 5x5 matrices ``[[R, v, p], [0, 1, 0], [0, 0, 1]]``.

    Parameters
    ----------
    M : array_like, shape (..., 5, 5)
    atol : float, optional
        Largest accepted deviation of the last two rows and of ``R`` from SO(3);
        default 1e-5 (float64) or 1e-4 (float32).
    orthonormalize : bool
        Replace the rotation block by the nearest rotation instead of raising.

    Raises
    ------
    NonFiniteError
        NaN or infinity anywhere.
    NotARigidTransformError
        The last two rows are not ``[0, 0, 0, 1, 0]``, ``[0, 0, 0, 0, 1]`` or the
        rotation block is not a rotation; the message names the first batch index.
    """
    M = finite_array(M, (5, 5), "extended-pose matrix")
    what = "an extended pose"
    check_bottom_row(M, atol, what, NotARigidTransformError, what="5x5 matrix")
    swapped = M[..., _SWAP, :][..., :, _SWAP]
    check_bottom_row(
        swapped, atol, what, NotARigidTransformError, what="5x5 matrix (4th row)"
    )
    try:
        q = _conv.quat_from_matrix(M[..., :3, :3], atol=atol, orthonormalize=orthonormalize)
    except NotARotationError as err:
        raise NotARigidTransformError(
            f"rotation block of the extended-pose {err}", index=err.index
        ) from None
    return _k.extpose_from_parts(q, M[..., :3, 3], M[..., :3, 4])


def log(M, *, atol=None):
    """Tangents ``(rho_v, rho_p, w)`` of 5x5 matrices, ``|w|`` in [0, pi].

    Validated like :func:`extpose_from_matrix` (tolerance ``atol``); the result has
    shape (..., 9).
    """
    return _k.tangent_from_extpose(extpose_from_matrix(M, atol=atol))


def adjoint(M, *, atol=None):
    """``[[R, 0, hat(v) R], [0, R, hat(p) R], [0, 0, R]]`` (9x9) of 5x5 matrices.

    ``M exp(xi) M^-1 = exp(Ad xi)``; ``M`` validated like :func:`extpose_from_matrix`.
    """
    return _k.adjoint_from_extpose(extpose_from_matrix(M, atol=atol))


def ad(xi):
    """Small adjoint, (..., 9) -> (..., 9, 9): ``ad(xi) @ u == bracket(xi, u)``."""
    return _k.ad(as_array(xi, (9,), "se_2(3) tangent"))


def bracket(xi1, xi2):
    """Lie bracket ``vee(hat(a) hat(b) - hat(b) hat(a))`` of tangents (..., 9).

    Equals ``(w1 x a2 + a1 x w2, w1 x b2 + b1 x w2, w1 x w2)`` for ``xi = (a, b, w)``.
    """
    return _k.bracket(
        as_array(xi1, (9,), "se_2(3) tangent"), as_array(xi2, (9,), "se_2(3) tangent")
    )


def left_jacobian(xi):
    """Left Jacobian of SE_2(3): ``exp(xi + d) ~ exp(J_l(xi) d) exp(xi)``.

    ``[[J_l(w), 0, Q(rho_v, w)], [0, J_l(w), Q(rho_p, w)], [0, 0, J_l(w)]]`` with
    Barfoot's ``Q`` (2017, eq. 7.86), for tangents (..., 9); result (..., 9, 9).
    """
    return _k.left_jacobian(_tangent(xi))


def left_jacobian_inverse(xi):
    """Inverse of :func:`left_jacobian`, finite for ``|w| < 2 pi``: (..., 9, 9)."""
    return _k.left_jacobian_inverse(_tangent(xi))


right_jacobian, right_jacobian_inverse = _lie.right_jacobians(
    __name__, "SE_2(3)", 9, "se_2(3) tangent", _k.left_jacobian, _k.left_jacobian_inverse
)
