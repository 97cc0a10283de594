"""The Lie group Sim(3) in functional form: the Lie vocabulary and its Jacobians.

Twists are ordered ``(v, omega, sigma)`` (7 components), ``sigma = log s``:
``hat(xi) = [[hat(omega) + sigma I, v], [0, 0]]``, extending the SE(3) order
``(v, omega)``. Group elements are homogeneous matrices ``[[s R, t], [0, 1]]``
(arrays in, arrays out); :class:`rigidkit.Similarity` is the object form. Closed
forms and their series are in :mod:`rigidkit.kernels.sim3`; the Jacobians are the
series of :func:`left_jacobian` (below).

>>> import numpy as np
>>> xi = np.array([0.1, -0.2, 0.3, 0.4, 0.5, -0.6, 0.7])
>>> bool(np.allclose(log(exp(xi)), xi))
True
>>> bool(np.array_equal(vee(hat(xi)), xi))
True
"""

from __future__ import annotations

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import device_of, namespace_of
from .._validate import (
    as_array,
    as_float,
    check_bottom_row,
    check_finite,
    default_atol,
    finite_array,
    raise_unless,
    raise_where,
    where_text,
    why_not_rotation,
)
from ..errors import NotASimilarityError
from ..kernels import matrix as _kmat
from ..kernels import sim3 as _k
from . import _lie

__all__ = [*_lie.VOCABULARY, "pose_from_matrix"]


def _twist(xi, what="sim(3) twist"):
    # Shape only: hat, ad and bracket are linear reshuffles, as in so3/se3; exp
    # and log check finiteness (through Similarity).
    return as_array(xi, (7,), what)


def hat(xi):
    """``[[hat(omega) + sigma I, v], [0, 0]]``: shape (..., 7) -> (..., 4, 4)."""
    return _k.sim3_hat(_twist(xi))


def vee(X):
    """Twist of a sim(3) matrix (its projection onto sim(3)): (..., 4, 4) -> (..., 7).

    ``omega`` from the skew part and ``sigma`` the mean of the diagonal of the 3x3
    block; ``vee(hat(xi)) == xi`` exactly.
    """
    return _k.sim3_vee(as_array(X, (4, 4), "sim(3) matrix"))


def exp(xi):
    """Homogeneous matrix ``expm(hat(xi)) = [[e^sigma R, V v], [0, 1]]``, shape (..., 4, 4).

    See :meth:`rigidkit.Similarity.exp` for the closed form.
    """
    xi = as_float(as_array(xi, (7,), "sim(3) twist"))
    check_finite(xi, (7,), "sim(3) twist")
    return _k.sim3_matrix(_k.sim3_exp(xi))


def log(M, *, atol=None):
    """Twist ``(v, omega, log s)``, ``|omega|`` in [0, pi], of ``[[s R, t], [0, 1]]``.

    Validated like :meth:`rigidkit.Similarity.from_matrix` (raises
    :class:`~rigidkit.NotASimilarityError` naming the batch index).
    """
    return _k.sim3_log(pose_from_matrix(M, atol=atol))


def adjoint(M, *, atol=None):
    """``Ad(M) = [[s R, hat(t) R, -t], [0, R, 0], [0, 0, 1]]`` (..., 7, 7) of
    ``[[s R, t], [0, 1]]``: ``M hat(xi) M^-1 = hat(Ad xi)``."""
    return _k.sim3_adjoint(pose_from_matrix(M, atol=atol))


def ad(xi):
    """Small adjoint ``[[hat(w) + sigma I, hat(v), -v], [0, hat(w), 0], [0, 0, 0]]``.

    ``ad(xi1) @ xi2 == bracket(xi1, xi2)``; ``adjoint(exp(xi)) == expm(ad(xi))``.
    """
    return _k.sim3_ad(_twist(xi))


def bracket(xi1, xi2):
    """Lie bracket ``vee(hat(xi1) hat(xi2) - hat(xi2) hat(xi1))``, shape (..., 7).

    ``= (w1 x v2 - w2 x v1 + s1 v2 - s2 v1, w1 x w2, 0)`` for ``xi = (v, w, s)``.
    """
    return _k.sim3_bracket(_twist(xi1), _twist(xi2))


# Terms of the series of J_l (the highest power of ad kept); see left_jacobian.
JACOBIAN_SERIES_TERMS = 32
_EYE7 = np.eye(7)


def _left_jacobian(xi):
    # Horner's rule: I + A/2 (I + A/3 (... (I + A/(N+1)))), N = JACOBIAN_SERIES_TERMS.
    A = _k.sim3_ad(xi)
    xp = namespace_of(A)
    eye = xp.asarray(_EYE7, dtype=A.dtype, device=device_of(A))
    S = eye
    for k in range(JACOBIAN_SERIES_TERMS, 0, -1):
        S = eye + xp.matmul(A, S) / (k + 1.0)
    return S


def _left_jacobian_inverse(xi):
    J = _left_jacobian(xi)
    if dask_backend.is_dask(J):  # Dask's LU takes one 2D matrix: one per element
        return dask_backend.map_batched(
            np.linalg.inv, [J], [2], outputs=[((7, 7), J.dtype)]
        )
    return namespace_of(J).linalg.inv(J)


def left_jacobian(xi):
    """Left Jacobian of Sim(3): ``exp(xi + d) ~ exp(J_l(xi) d) exp(xi)`` to first order.

    ``J_l(xi) = sum_k ad(xi)^k / (k+1)!`` (the closed form, with divided differences
    between ``sigma + i theta``, ``i theta`` and 0, is long and cancels near each
    coincidence). The series is summed by Horner's rule up to ``ad^N / (N+1)!``,
    ``N =`` :data:`JACOBIAN_SERIES_TERMS` ``= 32``, for float64 accuracy over the
    documented domain ``|omega| <= pi``, ``|sigma| <= 3`` (any ``v``):

    - ``ad(xi)`` is block triangular with diagonal blocks ``hat(omega) + sigma I``,
      ``hat(omega)`` and 0, normal matrices of norm ``rho = |sigma + i theta| <=
      4.34`` (``theta = |omega|``); the blocks holding ``v`` are linear in ``v``, so
      the relative error does not depend on ``|v|``;
    - the first omitted term is ``rho^33 / 34! < 4e-18`` (relative to ``|J_l|``,
      whose eigenvalues ``(e^z - 1) / z`` are at least 0.23 in modulus there); the
      largest term, ``rho^4 / 5! ~ 3``, bounds the rounding to ~1e-15;
    - measured against mpmath (40 digits) at the corners of the domain and at random
      points: at most 1.5e-15 of ``max |J_l|`` (``scipy.linalg.expm`` of
      ``[[ad, I], [0, 0]]`` errs by up to 6e-14 there).

    Outside the domain the series still converges (``phi(z) = (e^z - 1)/z`` is
    entire), with an error growing like ``rho^33 / 34!`` (1.6e-13 at ``rho = 6``).

    Parameters
    ----------
    xi : array_like, shape (..., 7)
        Twists ``(v, omega, sigma)``, finite.

    Returns
    -------
    ndarray, shape (..., 7, 7)
        ``J_l``, acting on twists ``(v, omega, sigma)``. Its ``(omega, omega)`` block
        is the SO(3) left Jacobian and its ``(v, v)`` block the matrix ``V`` of
        :func:`exp`.

    See Also
    --------
    right_jacobian, left_jacobian_inverse

    Examples
    --------
    >>> xi = np.array([0.1, -0.2, 0.3, 0.4, 0.5, -0.6, 0.7])
    >>> J = left_jacobian(xi)
    >>> bool(np.allclose(J[:3, :3] @ xi[:3], exp(xi)[:3, 3]))
    True
    """
    return _left_jacobian(finite_array(xi, (7,), "sim(3) twist"))


def left_jacobian_inverse(xi):
    """Inverse of :func:`left_jacobian`: ``log(exp(d) exp(xi)) ~ xi + J_l(xi)^-1 d``.

    The 7x7 linear system ``J_l X = I`` solved by LU (``linalg.inv`` of the input's
    namespace), on the series of :func:`left_jacobian` (its accuracy and domain).
    ``J_l`` is invertible unless ``e^z = 1`` for an eigenvalue ``z != 0`` of
    ``ad(xi)`` (``theta`` a nonzero multiple of 2 pi), so everywhere in the range of
    :func:`log`.

    Parameters
    ----------
    xi : array_like, shape (..., 7)
        Twists ``(v, omega, sigma)``, finite, as for :func:`left_jacobian`.

    Returns
    -------
    ndarray, shape (..., 7, 7)
        ``J_l^-1``, acting on twists ``(v, omega, sigma)``.

    See Also
    --------
    left_jacobian, right_jacobian_inverse

    Examples
    --------
    >>> xi = np.array([0.1, -0.2, 0.3, 0.4, 0.5, -0.6, 0.7])
    >>> bool(np.allclose(left_jacobian_inverse(xi) @ left_jacobian(xi), np.eye(7)))
    True
    """
    return _left_jacobian_inverse(finite_array(xi, (7,), "sim(3) twist"))


right_jacobian, right_jacobian_inverse = _lie.right_jacobians(
    __name__, "Sim(3)", 7, "sim(3) twist", _left_jacobian, _left_jacobian_inverse
)


def pose_from_matrix(matrix, *, atol=None):
    """Stored ``(w, x, y, z, tx, ty, tz, s)`` (..., 8) of ``[[s R, t], [0, 1]]``, checked.

    ``s`` is the root mean square of the singular values of the 3x3 block
    (``|A|_F / sqrt 3``) and ``R = A / s`` must be a rotation within ``atol``
    (default as :meth:`rigidkit.Rotation.from_matrix`). Raises
    :class:`~rigidkit.NonFiniteError` or :class:`~rigidkit.NotASimilarityError`
    naming the first bad batch index.
    """
    M = as_float(as_array(matrix, (4, 4), "homogeneous matrix"))
    check_finite(M, (4, 4), "homogeneous matrix")
    check_bottom_row(M, atol, "a similarity transform", NotASimilarityError)
    xp = namespace_of(M)
    A = M[..., :3, :3]
    s = xp.sqrt(xp.sum(A * A, axis=(-2, -1)) / 3.0)
    raise_where(
        s == 0.0,
        NotASimilarityError,
        "3x3 block of the homogeneous matrix {where} is zero; a similarity needs a "
        "positive scale",
    )
    R = A / s[..., None, None]
    q, err = _kmat.quat_from_matrix(R)
    tol = default_atol(M.dtype) if atol is None else atol

    def message(idx):
        return (
            f"3x3 block of the homogeneous matrix {where_text(idx)} is not a positive "
            f"scalar times a rotation: {why_not_rotation(R, idx)} (tolerance {tol:g})"
        )

    raise_unless(err <= tol, NotASimilarityError, message)
    return xp.concat([q, M[..., :3, 3], s[..., None]], axis=-1)
