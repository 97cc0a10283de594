"""The Lie group Sim(3) in functional form: hat, vee, exp, log, adjoint, ad, bracket.

Twists are ordered ``(v, omega, sigma)`` (7 components), ``sigma = log s``:
``hat(xi) = [[hat(omega) + sigma I, v], [0, 0]]``, extending the SE(3) order
``(v, omega)``. Group elements are homogeneous matrices ``[[s R, t], [0, 1]]``
(arrays in, arrays out); :class:`rigidkit.Similarity` is the object form. Closed
forms and their series are in :mod:`rigidkit.kernels.sim3`.

>>> import numpy as np
>>> xi = np.array([0.1, -0.2, 0.3, 0.4, 0.5, -0.6, 0.7])
>>> bool(np.allclose(log(exp(xi)), xi))
True
>>> bool(np.array_equal(vee(hat(xi)), xi))
True
"""

from __future__ import annotations

from .._engine.namespace import namespace_of
from .._validate import (
    as_array,
    as_float,
    check_bottom_row,
    check_finite,
    default_atol,
    raise_unless,
    raise_where,
    where_text,
    why_not_rotation,
)
from ..errors import NotASimilarityError
from ..kernels import matrix as _kmat
from ..kernels import sim3 as _k
from . import _lie

# Sim(3) has no Jacobians here (yet): the vocabulary up to ``bracket``.
__all__ = [*_lie.VOCABULARY[:7], "pose_from_matrix"]


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
