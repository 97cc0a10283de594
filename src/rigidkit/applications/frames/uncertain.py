"""``UncertainTransform``: a pose with the covariance of a perturbation on SE(3).

Convention, stated once here and in every docstring below: the covariance ``cov``
(6x6, ``(v, omega)`` order, the tangent order of :class:`~rigidkit.Transform`)
is that of the perturbation ``xi ~ N(0, cov)`` in

- ``side="right"``: ``T = mean @ exp(xi)`` (a body-frame perturbation: GTSAM's
  and manif's choice, Sola et al. 2018, eq. 25), or
- ``side="left"``: ``T = exp(xi) @ mean`` (Barfoot 2017, Sec. 7.3.1).

The two are related by the adjoint: ``xi_left = Ad(mean) xi_right``, so
``cov_left = Ad(mean) cov_right Ad(mean)^T``. Operations propagate to first order
with the group Jacobians of :mod:`rigidkit.jacobians` (``cov' = J cov J^T``,
Sola et al. 2018, eq. 55), or with the fourth-order compound formula of Barfoot &
Furgale 2014 (``order=4``, for :meth:`UncertainTransform.compose`).
"""

from __future__ import annotations

import numpy as np

from ..._engine.namespace import device_of, is_numpy, namespace_of
from ...errors import ShapeError
from ...objects import registry
from ...objects._batch import expect
from ...objects.transform import Transform
from .. import jacobians as _jac

__all__ = ["UncertainTransform", "path_covariance"]

_SIDES = ("right", "left")


def _mT(A):
    return A.mT if hasattr(A, "mT") else np.swapaxes(A, -1, -2)


def _sandwich(J, S):
    """``J @ S @ J^T`` over a batch."""
    return J @ S @ _mT(J)


class UncertainTransform:
    """A rigid motion ``mean`` with the 6x6 covariance ``cov`` of a perturbation.

    ``side="right"``: ``T = mean @ exp(xi)``; ``side="left"``: ``T = exp(xi) @
    mean``; ``xi = (v, omega) ~ N(0, cov)`` in both. The inverse's covariance is
    ``Ad(mean) cov Ad(mean)^T`` on the right side (exact, not an approximation:
    ``(mean exp(xi))^-1 = mean^-1 exp(-Ad(mean) xi)``), which published code has
    got wrong by forgetting the adjoint (colmap/colmap#3155).

    Parameters
    ----------
    mean : Transform, shape (...)
    cov : array_like, shape (..., 6, 6)
        Symmetric positive semi-definite; ``(v, omega)`` order.
    side : {"right", "left"}

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> A_T_B = rk.UncertainTransform(rk.Transform(translation=[1.0, 0, 0]),
    ...                               np.diag([0.01, 0.01, 0.01, 0.0, 0.0, 0.04]))
    >>> B_T_C = rk.UncertainTransform(rk.Transform(translation=[2.0, 0, 0]),
    ...                               np.zeros((6, 6)))
    >>> A_T_C = A_T_B @ B_T_C                 # first order, right side
    >>> A_T_C.mean.translation
    array([3., 0., 0.])
    >>> round(float(A_T_C.cov[1, 1]), 6)      # 0.01 + 2^2 * 0.04: the yaw swings y
    0.17
    """

    __slots__ = ("_mean", "_cov", "_side")

    def __init__(self, mean, cov, side="right"):
        if not isinstance(mean, Transform):
            mean = expect(mean, Transform, "mean")  # says which constructor to call
        if side not in _SIDES:
            raise ValueError(f"side must be 'right' or 'left', got {side!r}")
        if isinstance(cov, np.ndarray) or not hasattr(cov, "shape"):
            cov = np.asarray(cov, dtype=np.result_type(float, np.asarray(mean.translation)))
        if tuple(cov.shape[-2:]) != (6, 6):
            raise ShapeError(f"cov: expected shape (..., 6, 6), got {tuple(cov.shape)}")
        self._mean, self._cov, self._side = mean, cov, side

    @property
    def mean(self) -> Transform:
        """The mean pose, a :class:`~rigidkit.Transform`."""
        return self._mean

    @property
    def cov(self):
        """Covariance of ``xi = (v, omega)``, shape (..., 6, 6), on :attr:`side`."""
        return self._cov

    @property
    def side(self) -> str:
        """``"right"`` (``mean @ exp(xi)``) or ``"left"`` (``exp(xi) @ mean``)."""
        return self._side

    @property
    def shape(self):
        return self._mean.shape

    def __repr__(self):
        return (
            f"UncertainTransform(shape={self.shape}, side={self._side!r}, "
            f"mean={self._mean!r})"
        )

    def to_side(self, side):
        """The same distribution with the perturbation on ``side``.

        Left from right: ``cov_L = Ad(mean) cov_R Ad(mean)^T``; right from left
        with ``Ad(mean)^-1``.

        >>> import numpy as np
        >>> import rigidkit as rk
        >>> X = rk.UncertainTransform(rk.Transform.exp([0.0, 0, 0, 0, 0, 1.0]),
        ...                           np.diag([1.0, 0, 0, 0, 0, 0]))
        >>> np.round(np.diag(X.to_side("left").cov)[:2], 6)   # x velocity turned by 1 rad
        array([0.291927, 0.708073])
        """
        if side not in _SIDES:
            raise ValueError(f"side must be 'right' or 'left', got {side!r}")
        if side == self._side:
            return self
        Ad = self._mean.adjoint() if side == "left" else self._mean.inv().adjoint()
        return UncertainTransform(self._mean, _sandwich(Ad, self._cov), side)

    def inv(self):
        """``mean^-1`` with ``cov' = J cov J^T``, ``J = -Ad(mean)`` (right) or
        ``-Ad(mean)^-1`` (left): exact, the inverse of a perturbed pose being a
        perturbed inverse.

        >>> import numpy as np
        >>> import rigidkit as rk
        >>> A_T_B = rk.UncertainTransform(rk.Transform(translation=[2.0, 0, 0]),
        ...                               np.diag([0.0, 0, 0, 0, 0, 0.01]))   # yaw only
        >>> np.round(np.diag(A_T_B.inv().cov), 6)    # B_T_A: the yaw swings A's origin
        array([0.  , 0.04, 0.  , 0.  , 0.  , 0.01])
        """
        M, J = _jac.inv(self._mean, side=self._side)
        return UncertainTransform(M, _sandwich(J, self._cov), self._side)

    def compose(self, other, *, joint_cov=None, order=1):
        """``self @ other`` (``other`` applied first) with its covariance.

        Parameters
        ----------
        other : UncertainTransform
            Converted to ``self.side`` if needed.
        joint_cov : array_like, shape (..., 12, 12), optional
            The joint covariance of ``(xi_self, xi_other)`` for correlated poses
            (both on ``self.side``); its diagonal blocks replace the two
            covariances. None: independent.
        order : {1, 4}
            1: ``cov = J_1 cov_1 J_1^T + J_2 cov_2 J_2^T`` (+ cross terms), with
            the right Jacobians ``(Ad(other)^-1, I)`` or the left ``(I,
            Ad(self))`` (Sola et al. 2018, eqs. 170-171). 4: the fourth-order
            compound of Barfoot & Furgale 2014 (eqs. 55-57; Barfoot 2017, Sec.
            7.3.3), independent poses only, closer at large covariance.

        Returns
        -------
        UncertainTransform
            On ``self.side``.

        Examples
        --------
        >>> import numpy as np
        >>> import rigidkit as rk
        >>> X = rk.UncertainTransform(rk.Transform(), np.diag([0.0, 0, 0, 0, 0, 0.09]))
        >>> Y = rk.UncertainTransform(rk.Transform(translation=[1.0, 0, 0]),
        ...                           np.diag([0.09, 0, 0, 0, 0, 0]))
        >>> np.round(np.diag(X.compose(Y).cov)[:2], 5)      # x of Y, y from X's yaw
        array([0.09, 0.09])
        >>> np.round(np.diag(X.compose(Y, order=4).cov)[:2], 5)   # Y's x turned by yaw
        array([0.08865, 0.09202])
        """
        if not isinstance(other, UncertainTransform):
            raise TypeError(
                f"compose takes an UncertainTransform, got {type(other).__name__}"
            )
        other = other.to_side(self._side)
        if order == 4:
            if joint_cov is not None:
                raise ValueError("order=4 is for independent poses (joint_cov=None)")
            return _compose4(self, other)
        if order != 1:
            raise ValueError(f"order must be 1 or 4, got {order!r}")
        Z, J1, J2 = _jac.compose(self._mean, other._mean, side=self._side)
        if joint_cov is None:
            cov = _sandwich(J1, self._cov) + _sandwich(J2, other._cov)
        else:
            J = np.concatenate(np.broadcast_arrays(J1, J2), axis=-1)
            cov = _sandwich(J, np.asarray(joint_cov))
        return UncertainTransform(Z, cov, self._side)

    def __matmul__(self, other):
        if isinstance(other, UncertainTransform):
            return self.compose(other)
        return NotImplemented

    def between(self, other):
        """``self^-1 @ other`` (``other`` seen from ``self``) for independent poses,
        first order with :func:`rigidkit.jacobians.between` on ``self.side``.

        >>> import numpy as np
        >>> import rigidkit as rk
        >>> W_T_A = rk.UncertainTransform(rk.Transform(), 0.01 * np.eye(6))
        >>> W_T_B = rk.UncertainTransform(rk.Transform(translation=[1.0, 0, 0]),
        ...                               0.01 * np.eye(6))
        >>> A_T_B = W_T_A.between(W_T_B)
        >>> np.round(np.diag(A_T_B.cov), 6)      # both add, plus A's rotation times 1 m
        array([0.02, 0.03, 0.03, 0.02, 0.02, 0.02])
        """
        other = other.to_side(self._side)
        Z, J1, J2 = _jac.between(self._mean, other._mean, side=self._side)
        cov = _sandwich(J1, self._cov) + _sandwich(J2, other._cov)
        return UncertainTransform(Z, cov, self._side)

    def transform_point(self, point, point_cov=None):
        """``mean @ p`` and its 3x3 covariance, to first order.

        ``cov_p' = J_T cov J_T^T + R cov_p R^T`` with ``J_T`` the Jacobian of the
        action for a perturbation on ``self.side`` (``R [I, -hat(p)]`` right,
        ``[I, -hat(mean p)]`` left; :func:`rigidkit.jacobians.apply`).

        Returns
        -------
        point : ndarray, shape (..., 3)
        cov : ndarray, shape (..., 3, 3)

        Examples
        --------
        >>> import numpy as np
        >>> import rigidkit as rk
        >>> W_T_C = rk.UncertainTransform(rk.Transform(), np.diag([0.0, 0, 0, 0, 0, 1e-4]))
        >>> p_W, cov = W_T_C.transform_point([2.0, 0.0, 0.0])
        >>> np.round(np.diag(cov), 8)             # a yaw of 0.01 rad moves it 2 cm in y
        array([0.    , 0.0004, 0.    ])
        """
        y, J_T, J_p = _jac.apply(self._mean, point, side=self._side)
        cov = J_T @ self._cov @ _mT(J_T)
        if point_cov is not None:
            cov = cov + _sandwich(J_p, np.asarray(point_cov))
        return y, cov


def _ad_op(S):
    """Barfoot's ``<<S>>`` of a 6x6 matrix,
    ``[[<<S_ww>>, <<S_vw + S_vw^T>>], [0, <<S_ww>>]]``, with ``<<M>> = -tr(M) I + M``
    for 3x3 blocks (Barfoot & Furgale 2014, eq. 56)."""
    ww = _op3(S[..., 3:, 3:])
    vw = _op3(S[..., :3, 3:] + _mT(S[..., :3, 3:]))
    return _blocks([[ww, vw], [0.0 * ww, ww]])


def _op3(M):
    tr = (M[..., 0, 0] + M[..., 1, 1] + M[..., 2, 2])[..., None, None]
    return M - tr * _eye3(M)


def _eye3(like):
    """The 3x3 identity in the namespace, dtype and device of ``like``."""
    xp = namespace_of(like)
    if is_numpy(xp):
        return np.eye(3, dtype=like.dtype)
    return xp.asarray(np.eye(3), dtype=like.dtype, device=device_of(like))


def _blocks(rows):
    """A block matrix from rows of blocks (NumPy, torch and JAX alike)."""
    xp = namespace_of(rows[0][0])
    return xp.concat([xp.concat(r, axis=-1) for r in rows], axis=-2)


def _pair(M, N):
    """``<M, N> = <<M>> <<N>> + <<N M>>`` (Barfoot & Furgale 2014, eq. 57)."""
    return _op3(M) @ _op3(N) + _op3(N @ M)


def _compose4(X, Y):
    """Fourth-order compound of two independent poses (Barfoot & Furgale 2014).

    Worked on the left side, ``T_i = exp(xi_i) mean_i``: with ``S_2' = Ad(mean_1)
    S_2 Ad(mean_1)^T``, ``S = S_1 + S_2' + (A_1 S_2' + S_2' A_1^T + A_2' S_1 +
    S_1 A_2'^T) / 12 + B / 4``, ``A = <<S>>`` and ``B`` of the 3x3 blocks
    (``rho`` = v, ``phi`` = omega). Written with matrix products and block
    concatenation only, so it runs (and differentiates) on torch and JAX too.
    """
    side = X.side
    Xl, Yl = X.to_side("left"), Y.to_side("left")
    M1 = Xl.mean
    S1 = Xl.cov
    S2 = _sandwich(M1.adjoint(), Yl.cov)
    xp = namespace_of(S1, S2)
    batch = tuple(np.broadcast_shapes(tuple(S1.shape[:-2]), tuple(S2.shape[:-2])))
    S1 = xp.broadcast_to(S1, batch + (6, 6))
    S2 = xp.broadcast_to(S2, batch + (6, 6))
    A1, A2 = _ad_op(S1), _ad_op(S2)
    rr1, rp1, pp1 = S1[..., :3, :3], S1[..., :3, 3:], S1[..., 3:, 3:]
    rr2, rp2, pp2 = S2[..., :3, :3], S2[..., :3, 3:], S2[..., 3:, 3:]
    b_rr = _pair(pp1, rr2) + _pair(_mT(rp1), rp2) + _pair(rp1, _mT(rp2)) + _pair(rr1, pp2)
    b_rp = _pair(pp1, _mT(rp2)) + _pair(_mT(rp1), pp2)
    B = _blocks([[b_rr, b_rp], [_mT(b_rp), _pair(pp1, pp2)]])
    S = S1 + S2 + (A1 @ S2 + S2 @ _mT(A1) + A2 @ S1 + S1 @ _mT(A2)) / 12.0 + B / 4.0
    return UncertainTransform(M1 @ Yl.mean, S, "left").to_side(side)


def path_covariance(up_s, up_t, q, shape, interpolation, extrapolate):
    """``target_T_source`` with its covariance (right side, first order) along a path.

    Each edge is an :class:`UncertainTransform` of its pose and covariance (zero
    where the edge has none); chains compose from the top down and the target's
    chain is inverted, as in :func:`~rigidkit.applications.frames.lookup.compose_path`.
    The covariance stays in the poses' namespace (torch autograd, JAX tracing).
    """
    from .lookup import chain, shaped

    def zeros(E):
        stored = registry.stored(E)
        xp = namespace_of(stored)
        return xp.zeros(E.shape + (6, 6), dtype=stored.dtype, device=device_of(stored))

    def uncertain(up):
        _, parts = chain(up, q, interpolation, extrapolate, want_cov=True)
        out = None
        for E, cov in parts:
            U = UncertainTransform(E, zeros(E) if cov is None else cov)
            out = U if out is None else out.compose(U)
        return out

    A_s, A_t = uncertain(up_s), uncertain(up_t)
    if A_t is None:
        U = A_s if A_s is not None else UncertainTransform(Transform(), np.zeros((6, 6)))
    elif A_s is None:
        U = A_t.inv()
    else:
        U = A_t.between(A_s)
    mean = shaped(U.mean, shape)
    cov = U.cov
    xp = namespace_of(cov)
    if U.mean.single:
        cov = xp.broadcast_to(cov, mean.shape + (6, 6))
        cov = cov.copy() if is_numpy(cov) else xp.asarray(cov, copy=True)
    else:
        cov = xp.reshape(cov, mean.shape + (6, 6))
    return UncertainTransform(mean, cov, "right")
