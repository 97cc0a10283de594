"""The Lie group SE(2) of planar rigid motions in functional form (arrays in, out).

A motion is the homogeneous matrix ``T = [[R, t], [0, 1]]`` (``R`` in SO(2)) acting
on points ``p`` as ``R p + t``. Twists are ordered ``(v, ω) = (vx, vy, ω)`` as in
3D, with ``hat(ξ) = [[0, -ω, vx], [ω, 0, vy], [0, 0, 0]]``. Internally a pose is
``(cos θ, sin θ, tx, ty)``, shape (..., 4).

Jacobians: ``exp(ξ + δ) ≈ exp(J_l(ξ) δ) exp(ξ) ≈ exp(ξ) exp(J_r(ξ) δ)`` to first
order in ``δ``; ``J_r(ξ) = J_l(-ξ)`` and ``J_l(ξ) = Ad(exp ξ) J_r(ξ)``.

Every function is batched over leading axes and keeps the array namespace and
dtype of its input.

>>> import numpy as np
>>> xi = np.array([1.0, 0.0, np.pi / 2])    # (vx, vy, ω)
>>> np.round(exp(xi), 12) + 0.0
array([[ 0.        , -1.        ,  0.63661977],
       [ 1.        ,  0.        ,  0.63661977],
       [ 0.        ,  0.        ,  1.        ]])
>>> bool(np.allclose(log(exp(xi)), xi))
True
"""

from __future__ import annotations

from .._engine.namespace import namespace_of
from .._validate import as_array, check_bottom_row, check_rotation_2d, finite_array
from ..errors import NotARigidTransformError
from ..kernels import se2 as _k
from . import _lie
from .so2 import complex_normalize

__all__ = [*_lie.VOCABULARY, "pose_from_matrix", "matrix_from_pose"]


def _twist(xi, what="se(2) twist"):
    return finite_array(xi, (3,), what)


def hat(xi):
    """``hat(ξ) = [[0, -ω, vx], [ω, 0, vy], [0, 0, 0]]``: (..., 3) -> (..., 3, 3)."""
    return _k.hat(as_array(xi, (3,), "se(2) twist"))


def vee(X):
    """Inverse of :func:`hat`: ``(X[0, 2], X[1, 2], (X[1, 0] - X[0, 1]) / 2)``."""
    return _k.vee(as_array(X, (3, 3), "se(2) matrix"))


def exp(xi):
    """Homogeneous matrices ``expm(hat(ξ))`` of twists ``ξ = (vx, vy, ω)``.

    ``R = exp(ω J)``, ``t = V(ω) v`` with
    ``V(θ) = [[sin θ/θ, -(1 - cos θ)/θ], [(1 - cos θ)/θ, sin θ/θ]]`` (``V = I`` at
    ω = 0: a pure translation).

    Parameters
    ----------
    xi : array_like, shape (..., 3)
        Twists ``(v, ω)``: translation part (length units), angle (radians).

    Returns
    -------
    array, shape (..., 3, 3)

    See Also
    --------
    log
    """
    return _k.matrix_from_pose(_k.pose_from_twist(_twist(xi)))


def log(T, *, atol=None):
    """Twists ``(vx, vy, ω)``, ω in (-pi, pi], of homogeneous matrices (validated).

    ``v = V(ω)^-1 t`` with ``V^-1 = (ω/2) cot(ω/2) I - (ω/2) J``.

    Parameters
    ----------
    T : array_like, shape (..., 3, 3)
    atol : float, optional
        Tolerance of the check, see :func:`pose_from_matrix`.

    See Also
    --------
    exp
    """
    return _k.twist_from_pose(pose_from_matrix(T, atol=atol))


def adjoint(T, *, atol=None):
    """Adjoint ``[[R, (ty, -tx)^T], [0, 0, 1]]`` of homogeneous matrices (validated).

    For twists ``(v, ω)``: ``T hat(ξ) T^-1 = hat(Ad(T) ξ)``. (..., 3, 3) -> (..., 3, 3).
    """
    return _k.adjoint_from_pose(pose_from_matrix(T, atol=atol))


def ad(xi):
    """Small adjoint ``ad(ξ) = [[ω J, -J v], [0, 0]]``, ``ad(ξ1) ξ2 = [ξ1, ξ2]``."""
    return _k.ad(_twist(xi))


def bracket(xi1, xi2):
    """Lie bracket ``vee([hat ξ1, hat ξ2]) = (ω1 J v2 - ω2 J v1, 0)``: (..., 3)."""
    return _k.bracket(_twist(xi1), _twist(xi2))


def left_jacobian(xi):
    """Left Jacobian, ``exp(ξ + δ) ≈ exp(J_l(ξ) δ) exp(ξ)``: (..., 3) -> (..., 3, 3).

    ``J_l = [[V(ω), q], [0, 1]]`` with ``V`` as in :func:`exp` and
    ``q = ((ω - sin ω) vx + (1 - cos ω) vy, (ω - sin ω) vy - (1 - cos ω) vx) / ω^2``.

    >>> import numpy as np
    >>> left_jacobian(np.zeros(3)) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    return _k.left_jacobian(_twist(xi))


def left_jacobian_inverse(xi):
    """Inverse of :func:`left_jacobian` (closed form; defined for |ω| < 2 pi)."""
    return _k.left_jacobian_inverse(_twist(xi))


right_jacobian, right_jacobian_inverse = _lie.right_jacobians(
    __name__, "SE(2)", 3, "se(2) twist", _k.left_jacobian, _k.left_jacobian_inverse
)


def pose_from_matrix(matrix, *, atol=None, orthonormalize=False):
    """Poses ``(cos θ, sin θ, tx, ty)`` of 3x3 homogeneous matrices, validated.

    Parameters
    ----------
    matrix : array_like, shape (..., 3, 3)
        ``[[R, t], [0, 0, 1]]``, ``R`` acting on column vectors.
    atol : float, optional
        Tolerance of both checks: the rotation block's
        ``max(|R^T R - I|, |det R - 1|)`` and the bottom row's distance from
        ``[0, 0, 1]``; default 1e-5 (float64) or 1e-4 (float32).
    orthonormalize : bool
        Replace the rotation block by its nearest rotation instead of raising.
        A bad bottom row still raises: that matrix is not a rigid motion at all.

    Returns
    -------
    array, shape (..., 4)

    Raises
    ------
    NonFiniteError, NotARotationError
        Naming the first offending batch index.
    """
    m = finite_array(matrix, (3, 3), "SE(2) matrix")
    check_bottom_row(
        m, atol, "a rigid transform", NotARigidTransformError, what="SE(2) matrix"
    )
    pose, norm, err, _ = _k.pose_from_matrix(m)
    check_rotation_2d(
        m[..., :2, :2],
        norm,
        err,
        atol=atol,
        orthonormalize=orthonormalize,
        what="SE(2) matrix",
    )
    return pose


def matrix_from_pose(pose, *, out=None):
    """Homogeneous matrices ``[[c, -s, tx], [s, c, ty], [0, 0, 1]]`` of poses (..., 4).

    Poses are ``(cos θ, sin θ, tx, ty)``; the pair ``(cos θ, sin θ)`` is normalised
    first (any finite nonzero scale), as in :class:`rigidkit.Transform2D`.
    """
    p = as_array(pose, (4,), "SE(2) pose")
    cs = complex_normalize(p[..., :2], what="SE(2) pose (cos, sin)")
    t = finite_array(p[..., 2:], (2,), "SE(2) pose translation")
    return _k.matrix_from_pose(namespace_of(cs).concat([cs, t], axis=-1), out=out)
