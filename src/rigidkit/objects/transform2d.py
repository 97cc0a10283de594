"""``Transform2D``: a batch of planar rigid motions (SE(2)).

Conventions: ``A_T_B`` maps points of frame B to frame A, ``p_A = R p_B + t``, as
the matrix ``[[R, t], [0, 0, 1]]`` acting on ``[p; 1]``; ``T1 @ T2`` applies ``T2``
first. Twists are ordered ``(v, ω) = (vx, vy, ω)`` as in 3D. Stored as
``(cos θ, sin θ, tx, ty)``, shape (..., 4).
"""

from __future__ import annotations

import numpy as np

from .._engine.namespace import float_dtype_of, namespace_of
from .._validate import as_array, finite_array, to_numpy
from ..functional import se2 as _se2
from ..kernels import se2 as _k
from ..kernels.kinematics import planar as _kp
from ._batch import BatchedArray, batch_shape, expect
from ._frozen import frozen
from .group import LieGroup
from .registry import GroupSpec
from .rotation2d import Rotation2D

__all__ = ["Transform2D"]


class Transform2D(BatchedArray, LieGroup, family="plane", rank=1):
    """A batch of planar rigid motions ``p -> R p + t`` of any batch shape.

    Parameters
    ----------
    rotation : Rotation2D, optional
        The rotation ``R`` (the identity when omitted).
    translation : array_like, shape (..., 2), optional
        The translation ``t``, finite (zero when omitted). The batch shapes of
        ``rotation`` and ``translation`` broadcast.

    Notes
    -----
    ``A_T_C = A_T_B @ B_T_C`` applies ``B_T_C`` first; ``A_T_B @ p_B`` gives
    ``p_A``. Tangent vectors are twists ``(vx, vy, ω)``, shape (..., 3), with
    ``hat(ξ) = [[0, -ω, vx], [ω, 0, vy], [0, 0, 0]]``. The array namespace and
    dtype of the inputs are kept.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> A_T_B = rk.Transform2D(
    ...     rotation=rk.Rotation2D.from_angle(90.0, degrees=True), translation=[1.0, 2.0]
    ... )
    >>> np.round(A_T_B @ np.array([1.0, 0.0]), 12) + 0.0
    array([1., 3.])
    >>> np.round((A_T_B @ A_T_B.inv()).as_matrix(), 12) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """

    __slots__ = ("_data",)
    _trail = (4,)
    _repr_columns = "(cos, sin, tx, ty)"
    _identity = (1.0, 0.0, 0.0, 0.0)  # (cos 0, sin 0, tx, ty)
    _compose_kernel = _k.pose_multiply
    _inverse_kernel = _k.pose_inverse
    dof, matrix_size, point_dim = 3, 3, 2
    _spec = GroupSpec(
        algebra=_se2,
        tangent=(("translation", slice(0, 2)), ("rotation", slice(2, 3))),
        rate="planar twist",
        step=(_kp.se2_increment, _kp.se2_increment_rk4, _kp.se2_chain),
    )

    def __init__(self, rotation=None, translation=None):
        if rotation is not None and not isinstance(rotation, Rotation2D):
            rotation = expect(rotation, Rotation2D, "rotation")
        if translation is None:
            cs = Rotation2D.identity()._data if rotation is None else rotation._data
            self._data = namespace_of(cs).concat([cs, cs * 0.0], axis=-1)
            return
        t = finite_array(translation, (2,), "translation")
        xp = namespace_of(t)
        if rotation is None:
            zero = t[..., :1] * 0.0
            cs = xp.concat([zero + 1.0, zero], axis=-1)
        else:
            cs = rotation._data
            xp = namespace_of(cs, t)
        dtype = float_dtype_of(xp, cs, t)
        cs = xp.asarray(cs, dtype=dtype)
        t = xp.asarray(t, dtype=dtype)
        batch = tuple(np.broadcast_shapes(tuple(cs.shape[:-1]), tuple(t.shape[:-1])))
        self._data = xp.concat(
            [xp.broadcast_to(cs, batch + (2,)), xp.broadcast_to(t, batch + (2,))],
            axis=-1,
        )

    # -- construction -------------------------------------------------------
    @classmethod
    def from_matrix(cls, matrix, *, atol=None, orthonormalize=False):
        """From homogeneous matrices ``[[R, t], [0, 0, 1]]``, shape (..., 3, 3), validated.

        Raises :class:`~rigidkit.NotARotationError` (naming the batch index) when the
        bottom row is not ``[0, 0, 1]`` or ``R`` is not a rotation within ``atol``;
        ``orthonormalize=True`` replaces ``R`` by its nearest rotation. See
        :func:`rigidkit.se2.pose_from_matrix`.
        """
        return cls._wrap(
            _se2.pose_from_matrix(matrix, atol=atol, orthonormalize=orthonormalize)
        )

    @classmethod
    def exp(cls, tau):
        """``expm(hat(ξ))`` for twists ``ξ = (vx, vy, ω)``, shape (..., 3).

        ``R = exp(ω J)``, ``t = V(ω) v`` (see :func:`rigidkit.se2.exp`).
        """
        xi = finite_array(tau, (3,), "se(2) twist")
        return cls._wrap(_k.pose_from_twist(xi))

    @classmethod
    def random(cls, shape=(), rng=None, *, dtype=None):
        """Random motions: Haar rotations and standard normal translations.

        ``rng`` is a :class:`numpy.random.Generator` or a seed.
        """
        rng = np.random.default_rng(rng)
        shape = batch_shape(shape)
        rot = Rotation2D.random(shape, rng)
        pose = np.concatenate([rot._data, rng.standard_normal(shape + (2,))], axis=-1)
        return cls._wrap(pose.astype(dtype) if dtype is not None else pose)

    # -- parts and representations ---------------------------------------------
    @property
    def translation(self):
        """The translation part ``t``, shape (..., 2) (read-only for NumPy storage)."""
        return frozen(self._data[..., 2:])

    @property
    def rotation(self) -> Rotation2D:
        """The rotation part, a :class:`Rotation2D` of the same batch shape."""
        return Rotation2D._wrap(self._data[..., :2])

    def as_matrix(self, *, out=None):
        """Homogeneous matrices ``[[c, -s, tx], [s, c, ty], [0, 0, 1]]``, (..., 3, 3)."""
        return _k.matrix_from_pose(self._data, out=out)

    def log(self):
        """Twists ``(vx, vy, ω)``, ω in (-pi, pi], shape (..., 3); see :meth:`exp`."""
        return _k.twist_from_pose(self._data)

    def adjoint(self):
        """``Ad = [[R, (ty, -tx)^T], [0, 0, 1]]``, shape (..., 3, 3), for ``(v, ω)``.

        ``T exp(ξ) T^-1 = exp(Ad ξ)``.
        """
        return _k.adjoint_from_pose(self._data)

    # -- group operations ----------------------------------------------------------
    # ``T1 @ T2`` composes (``T2`` first; either may be a Rotation2D) and ``T @ p``
    # maps points: Group.__matmul__.
    @classmethod
    def _include(cls, x):
        return cls(rotation=x)

    def apply(self, points, *, out=None):
        """Map points ``R p + t``, shape (..., 2) broadcasting with the batch shape."""
        p = as_array(points, (2,), "points")
        return _k.pose_apply(self._data, p, out=out)

    def inv(self):
        """Inverse motions ``(R^T, -R^T t)``."""
        return Transform2D._wrap(self._inverse_kernel(self._data))

    def approx_equal(self, other, *, atol=1e-8):
        """Elementwise: rotation angle between them and translation distance <= ``atol``."""
        angle, dist = _k.pose_distance(self._data, other._data)
        return (angle <= atol) & (dist <= atol)

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        t = ", ".join(f"{v:.6g}" for v in to_numpy(self.translation).tolist())
        return f"Transform2D(rotation={self.rotation!r}, translation=[{t}])"
