"""The Lie group SE(3) in functional form (arrays in, arrays out, batched).

Conventions: twists are ordered ``(v, w)``, ``V = [v; w]``, translation first as in
Murray, Li & Sastry 1994 (Sec. 2.3) and Barfoot 2017 (Sec. 7.1), with ``hat(V) =
[[hat(w), v], [0, 0]]`` (scipy's exponential coordinates are ``(w, v)``).
Homogeneous matrices ``[[R, t], [0, 1]]`` act on column vectors ``[p; 1]``; poses
are arrays ``(w, x, y, z, tx, ty, tz)`` (unit quaternion, Hamilton, scalar first,
then translation).

======================  ==========================================================
``exp(V)``              ``expm(hat(V)) = [[R, J_l(w) v], [0, 1]]``, ``R = exp(hat(w))``
``log(M)``              twist with ``|w|`` in [0, pi] and ``v = J_l(w)^-1 t``
``adjoint(M)``          ``Ad = [[R, hat(t) R], [0, R]]``: ``M exp(V) M^-1 = exp(Ad V)``
``ad(V)``               ``[[hat(w), hat(v)], [0, hat(w)]]``: ``ad(V) U = [V, U]``
``bracket(V, U)``       ``vee(hat(V) hat(U) - hat(U) hat(V))``
``left_jacobian(V)``    ``exp(V + d) ~ exp(J_l d) exp(V)``; ``[[J_l(w), Q], [0, J_l(w)]]``
``right_jacobian(V)``   ``exp(V + d) ~ exp(V) exp(J_r d)``; ``J_r(V) = J_l(-V)``
======================  ==========================================================

>>> import numpy as np
>>> V = np.array([1.0, 0.0, 0.0, 0.0, 0.0, np.pi / 2])  # (v, w): screw about z
>>> np.round(exp(V), 12) + 0.0
array([[ 0.        , -1.        ,  0.        ,  0.63661977],
       [ 1.        ,  0.        ,  0.        ,  0.63661977],
       [ 0.        ,  0.        ,  1.        ,  0.        ],
       [ 0.        ,  0.        ,  0.        ,  1.        ]])
>>> bool(np.allclose(log(exp(V)), V))
True
"""

from __future__ import annotations

import math

from .._validate import as_array, check_bottom_row, finite_array
from ..errors import NotARigidTransformError, NotARotationError, OutOfRangeError
from ..kernels import se3 as _k
from . import _lie
from . import conversions as _conv
from . import pose_formats as _formats

# The other layouts of a pose live in pose_formats; rk.se3 offers them too (its
# __all__, taken whole below).
from .pose_formats import *  # noqa: F403
from .pose_formats import _pose

__all__ = [
    *_lie.VOCABULARY,
    "pose_from_matrix",
    "matrix_from_pose",
    "pose_from_twist",
    "twist_from_pose",
    *_formats.__all__,
    "pose_distance",
    "pose_distance_unchecked",
]


def _twist(xi, what="twist"):
    return finite_array(xi, (6,), what)


def hat(xi):
    """``hat(V) = [[hat(w), v], [0, 0]]`` of twists ``V = (v, w)``: (..., 6) -> (..., 4, 4).

    The inverse of :func:`vee`; a linear map, so any real input is accepted.
    """
    return _k.hat(as_array(xi, (6,), "twist"))


def vee(X):
    """Twist ``(v, w)`` of se(3) matrices: (..., 4, 4) -> (..., 6).

    ``v`` is the last column and ``w`` the vector of the skew part of the 3x3 block
    (its projection onto so(3)); the inverse of :func:`hat`.
    """
    return _k.vee(as_array(X, (4, 4), "se(3) matrix"))


def pose_from_twist(xi):
    """Pose ``(w, x, y, z, tx, ty, tz)`` of ``exp(hat(xi))``, twists ``(v, w)`` (..., 6)."""
    return _k.pose_from_twist(_twist(xi))


def exp(xi):
    """Homogeneous matrix ``expm(hat(V))`` of twists ``V = (v, w)``.

    ``exp(hat(V)) = [[R, J_l(w) v], [0, 1]]`` with ``R = exp(hat(w))`` (Rodrigues)
    and ``J_l`` the SO(3) left Jacobian; for ``w = 0`` a pure translation by ``v``.
    For ``w != 0`` the translation is ``(I - R)(w x v)/|w|^2 + w w^T v / |w|^2``
    (Murray, Li & Sastry 1994, Sec. 2.3, with the angle folded into ``w``).

    Parameters
    ----------
    xi : array_like, shape (..., 6)
        Twists ``(v, w)``: ``w`` in radians, ``v`` in length units.

    Returns
    -------
    ndarray, shape (..., 4, 4)

    See Also
    --------
    log
    """
    return _k.matrix_from_pose(_k.pose_from_twist(_twist(xi)))


def log(M, *, atol=None):
    """Twist ``(v, w)`` of homogeneous matrices, with ``|w|`` in [0, pi].

    ``w`` is the rotation vector of ``R`` and ``v = J_l(w)^-1 t``.

    Parameters
    ----------
    M : array_like, shape (..., 4, 4)
        Validated like :func:`pose_from_matrix`.
    atol : float, optional
        Tolerance of the validation.

    Returns
    -------
    ndarray, shape (..., 6)
        Twists ``(v, w)``, translation first.

    See Also
    --------
    exp
    """
    return _k.twist_from_pose(pose_from_matrix(M, atol=atol))


def pose_from_matrix(M, *, atol=None, orthonormalize=False):
    """Pose ``(w, x, y, z, tx, ty, tz)`` of homogeneous matrices ``[[R, t], [0, 1]]``.

    Parameters
    ----------
    M : array_like, shape (..., 4, 4)
    atol : float, optional
        Largest accepted deviation of the bottom row from ``[0, 0, 0, 1]`` and of
        ``R`` from SO(3) (see :func:`rigidkit.conversions.quat_from_matrix`); default
        1e-5 (float64) or 1e-4 (float32).
    orthonormalize : bool
        Replace the rotation block by the nearest rotation instead of raising. The
        bottom row is still checked.

    Raises
    ------
    NonFiniteError
        NaN or infinity anywhere.
    NotARotationError
        The bottom row is not ``[0, 0, 0, 1]`` or the rotation block is not a
        rotation; the message names the first such batch index.
    """
    M = finite_array(M, (4, 4), "homogeneous matrix")
    check_bottom_row(M, atol, "a rigid transform", NotARigidTransformError)
    try:
        q = _conv.quat_from_matrix(M[..., :3, :3], atol=atol, orthonormalize=orthonormalize)
    except NotARotationError as err:
        raise NotARigidTransformError(
            f"rotation block of the homogeneous {err}", index=err.index
        ) from None
    return _k.pose_from_quat_translation(q, M[..., :3, 3])


def adjoint(M, *, atol=None):
    """Adjoint ``[[R, hat(t) R], [0, R]]`` (6x6) of homogeneous ``[[R, t], [0, 1]]``.

    For twists ``(v, w)``: ``M exp(V) M^-1 = exp(Ad V)`` and
    ``M hat(V) M^-1 = hat(Ad V)``. ``M`` is validated like
    :func:`pose_from_matrix` (with tolerance ``atol``).

    Parameters
    ----------
    M : array_like, shape (..., 4, 4)
    atol : float, optional

    Returns
    -------
    ndarray, shape (..., 6, 6)
    """
    return _k.adjoint_from_pose(pose_from_matrix(M, atol=atol))


def ad(xi):
    """Small adjoint ``ad(V) = [[hat(w), hat(v)], [0, hat(w)]]``: (..., 6) -> (..., 6, 6).

    For twists ``(v, w)``: ``ad(V) @ U == bracket(V, U)`` and
    ``adjoint(exp(V)) == expm(ad(V))``.
    """
    return _k.ad(as_array(xi, (6,), "twist"))


def bracket(xi1, xi2):
    """Lie bracket ``vee(hat(V1) hat(V2) - hat(V2) hat(V1))`` of twists ``(v, w)``.

    Equals ``(w1 x v2 + v1 x w2, w1 x w2)``.

    Parameters
    ----------
    xi1, xi2 : array_like, shape (..., 6)
        Twists ``(v, w)``; batch shapes broadcast.

    Returns
    -------
    ndarray, shape (..., 6)
    """
    return _k.bracket(as_array(xi1, (6,), "twist"), as_array(xi2, (6,), "twist"))


def left_jacobian(xi):
    """Left Jacobian of SE(3): ``exp(V + d) ~ exp(J_l(V) d) exp(V)`` to first order.

    ``J_l = [[J_l(w), Q(v, w)], [0, J_l(w)]]`` for twists ``V = (v, w)``, with the
    SO(3) left Jacobian ``J_l(w)`` and Barfoot's ``Q`` (small-angle series in its
    coefficient helpers). It is also ``sum_k ad(V)^k / (k+1)!`` and the matrix
    ``V`` of exp: ``exp(V) = [[R, J_l(w) v], [0, 1]]``.

    Parameters
    ----------
    xi : array_like, shape (..., 6)
        Twists ``(v, w)`` at which the exponential is linearised; finite.

    Returns
    -------
    ndarray, shape (..., 6, 6)
        ``J_l``, acting on twists ``(v, w)``.

    See Also
    --------
    right_jacobian, left_jacobian_inverse
    """
    return _k.left_jacobian(_twist(xi))


def left_jacobian_inverse(xi):
    """Inverse of :func:`left_jacobian`: ``log(exp(d) exp(V)) ~ V + J_l(V)^-1 d``.

    ``[[J^-1, -J^-1 Q J^-1], [0, J^-1]]`` with ``J = J_l(w)``, for twists
    ``(v, w)`` (..., 6) with ``|w| < 2 pi`` (where ``J_l`` is invertible); the
    result has shape (..., 6, 6).
    """
    return _k.left_jacobian_inverse(_twist(xi))


right_jacobian, right_jacobian_inverse = _lie.right_jacobians(
    __name__, "SE(3)", 6, "twist", _k.left_jacobian, _k.left_jacobian_inverse
)


def matrix_from_pose(pose, *, out=None):
    """Homogeneous matrices ``[[R, t], [0, 1]]`` of poses ``(w, x, y, z, tx, ty, tz)``.

    The quaternion is normalised first (any finite nonzero scale), as in
    :class:`rigidkit.Transform`.

    Parameters
    ----------
    pose : array_like, shape (..., 7)
    out : ndarray, shape (..., 4, 4), optional

    Returns
    -------
    ndarray, shape (..., 4, 4)

    See Also
    --------
    pose_from_matrix
    """
    return _k.matrix_from_pose(_pose(pose), out=out)


def twist_from_pose(pose):
    """Twists ``(v, w)``, ``|w|`` in [0, pi], of poses ``(w, x, y, z, tx, ty, tz)``.

    The quaternion is normalised first; the inverse of :func:`pose_from_twist`.

    Parameters
    ----------
    pose : array_like, shape (..., 7)

    Returns
    -------
    ndarray, shape (..., 6)
    """
    return _k.twist_from_pose(_pose(pose))


# -- a distance ------------------------------------------------------------------------


def _weight(value, name):
    value = float(value)
    if not value >= 0.0 or value == math.inf:
        raise OutOfRangeError(f"{name} must be finite and >= 0, got {value}")
    return value


def pose_distance(pose1, pose2, *, rotation_weight=1.0, translation_weight=1.0):
    """Weighted distance ``sqrt(a theta^2 + b |dt|^2)`` between poses.

    Of the relative pose ``T1^-1 T2`` (the motion from ``T1`` to ``T2`` in the
    frame of ``T1``): ``theta`` is its rotation angle (radians, [0, pi]), ``dt =
    R1^T (t2 - t1)`` its translation, so ``|dt| = |t2 - t1|``. It is symmetric
    and left-invariant, ``d(X T1, X T2) = d(T1, T2)`` (a change of the world
    frame), not right-invariant (a change of the body frame moves the
    translations). ``a = rotation_weight`` (per radian squared), ``b =
    translation_weight`` (per length squared) set how many length units one
    radian is worth; ``a = 0`` or ``b = 0`` gives the translation distance or the
    geodesic rotation angle alone.

    Parameters
    ----------
    pose1, pose2 : array_like, shape (..., 7)
        Poses ``(w, x, y, z, tx, ty, tz)`` (quaternions normalised first);
        batch shapes broadcast.
    rotation_weight, translation_weight : float
        Non-negative.

    Returns
    -------
    ndarray, shape (...)

    Examples
    --------
    >>> import numpy as np
    >>> c = np.sqrt(0.5)
    >>> a = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    >>> b = [c, 0.0, 0.0, c, 3.0, 4.0, 0.0]  # a quarter turn, moved by 5
    >>> float(np.round(pose_distance(a, b, rotation_weight=0.0), 12))
    5.0
    >>> bool(np.isclose(pose_distance(a, b), np.hypot(np.pi / 2, 5.0)))
    True
    """
    return pose_distance_unchecked(
        _pose(pose1),
        _pose(pose2),
        rotation_weight=rotation_weight,
        translation_weight=translation_weight,
    )


def pose_distance_unchecked(pose1, pose2, *, rotation_weight=1.0, translation_weight=1.0):
    """:func:`pose_distance` of unit-quaternion poses as they are (weights checked)."""
    return _k.pose_distance(
        _weight(rotation_weight, "rotation_weight"),
        _weight(translation_weight, "translation_weight"),
        pose1,
        pose2,
    )
