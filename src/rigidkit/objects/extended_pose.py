"""``ExtendedPose``: the group SE_2(3) of navigation states ``(R, v, p)``.

Barrau & Bonnabel 2017 ("The invariant extended Kalman filter as a stable
observer"): the orientation ``R`` of a body frame in the navigation frame
(``world``), the body's velocity ``v`` and position ``p`` in that frame, as the 5x5
matrix ``[[R, v, p], [0, 1, 0], [0, 0, 1]]``. Products are matrix products. Tangents
are ordered ``(rho_v, rho_p, w)``: ``exp`` of a tangent is the matrix exponential of
``[[hat(w), rho_v, rho_p], [0, 0, 0], [0, 0, 0]]``. Quaternions are Hamilton, scalar
first.
"""

from __future__ import annotations

import numpy as np

from .._engine.namespace import namespace_of
from .._validate import as_array, finite_array, to_numpy
from ..functional import conversions as _conv
from ..functional import se23 as _fse23
from ..kernels import se23 as _k
from ._batch import BatchedArray, batch_shape, expect
from ._frozen import frozen
from .group import LieGroup, owned_method
from .registry import GroupSpec
from .rotation import Rotation
from .transform import Transform, _constant_like, pose_gap

__all__ = ["ExtendedPose"]


class ExtendedPose(BatchedArray, LieGroup, family="navigation", rank=0):
    """A batch of navigation states ``(R, v, p)``, the group SE_2(3).

    Stored as one array of shape ``(..., 10)``: a unit quaternion ``(w, x, y, z)``
    (the body's orientation in the navigation frame, ``world_R_body``), the
    velocity ``(vx, vy, vz)`` and the position ``(px, py, pz)``, both of the body
    in the navigation frame. The matrix is ``[[R, v, p], [0, 1, 0], [0, 0, 1]]``;
    ``X1 @ X2 = (R1 R2, v1 + R1 v2, p1 + R1 p2)``. ``X @ x`` moves points by the
    pose part, ``R x + p`` (the matrix on ``[x; 0; 1]``).

    Tangents are ordered ``(rho_v, rho_p, w)``, 9 components, ``w`` in radians:
    ``exp(xi) = expm([[hat(w), rho_v, rho_p], [0, 0, 0], [0, 0, 0]]) =
    (exp(hat(w)), J_l(w) rho_v, J_l(w) rho_p)`` with ``J_l`` the SO(3) left Jacobian.
    ``plus``, ``minus`` and the Jacobians (``rk.jacobians``) use this order.

    Parameters
    ----------
    rotation : Rotation, optional
        ``R`` (identity when omitted).
    velocity, position : array_like, shape (..., 3), optional
        ``v`` and ``p`` (zero when omitted). The batch shapes broadcast.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> X = rk.ExtendedPose(rotation=rk.Rotation.from_rotvec([0.0, 0.0, np.pi / 2]),
    ...                     velocity=[1.0, 0.0, 0.0], position=[0.0, 0.0, 2.0])
    >>> np.round(X @ np.array([1.0, 0.0, 0.0]), 12) + 0.0
    array([0., 1., 2.])
    >>> Y = X @ X
    >>> np.round(Y.velocity, 12) + 0.0, np.round(Y.position, 12) + 0.0
    (array([1., 1., 0.]), array([0., 0., 4.]))
    >>> bool(rk.ExtendedPose.exp(X.log()).approx_equal(X))
    True
    """

    __slots__ = ("_data",)
    _trail = (10,)
    _repr_columns = "(qw, qx, qy, qz, vx, vy, vz, px, py, pz)"
    _identity = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)  # (q, v, p)
    _compose_kernel = _k.extpose_compose
    _inverse_kernel = _k.extpose_inv
    dof, matrix_size, point_dim = 9, 5, 3
    _spec = GroupSpec(
        algebra=_fse23,
        tangent=(
            ("velocity", slice(0, 3)),
            ("translation", slice(3, 6)),
            ("rotation", slice(6, 9)),
        ),
        rate="extended twist",
    )

    def __init__(self, rotation=None, velocity=None, position=None):
        if rotation is not None and not isinstance(rotation, Rotation):
            rotation = expect(rotation, Rotation, "rotation")
        v = None if velocity is None else finite_array(velocity, (3,), "velocity")
        p = None if position is None else finite_array(position, (3,), "position")
        q = None if rotation is None else rotation.as_quat()
        like = next((a for a in (q, v, p) if a is not None), None)
        if like is None:
            self._data = self._filled(self._identity, ())
            return
        if q is None:
            q = _constant_like(like, [1.0, 0.0, 0.0, 0.0])
        if v is None:
            v = _constant_like(like, [0.0, 0.0, 0.0])
        if p is None:
            p = _constant_like(like, [0.0, 0.0, 0.0])
        self._data = _k.extpose_from_parts(q, v, p)

    # -- construction --------------------------------------------------------------------
    @classmethod
    def from_matrix(cls, matrix, *, atol=None, orthonormalize=False):
        """From 5x5 matrices ``[[R, v, p], [0, 1, 0], [0, 0, 1]]``, validated.

        See :func:`rigidkit.functional.se23.extpose_from_matrix`.

        >>> M = np.eye(5)
        >>> M[:3, 3], M[:3, 4] = [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]
        >>> ExtendedPose.from_matrix(M).position
        array([4., 5., 6.])
        """
        return cls._wrap(
            _fse23.extpose_from_matrix(matrix, atol=atol, orthonormalize=orthonormalize)
        )

    @classmethod
    def exp(cls, xi):
        """``exp(hat(xi))`` of tangents ``xi = (rho_v, rho_p, w)``, shape (..., 9).

        ``(exp(hat(w)), J_l(w) rho_v, J_l(w) rho_p)``; ``w`` in radians. See
        :func:`rigidkit.functional.se23.exp`.
        """
        return cls._wrap(_fse23.extpose_from_tangent(xi))

    @classmethod
    def random(cls, shape=(), rng=None, *, dtype=None, scale=1.0):
        """Random states: uniform (Haar) rotations, Gaussian velocities and positions.

        Velocity and position components are independent normal with standard
        deviation ``scale``. ``rng`` is a :class:`numpy.random.Generator` or a seed.
        """
        shape = batch_shape(shape)
        rng = np.random.default_rng(rng)
        q = _conv.quat_normalize(rng.standard_normal(shape + (4,)))
        vp = scale * rng.standard_normal(shape + (6,))
        data = np.concatenate([q, vp], axis=-1)
        return cls._wrap(data.astype(dtype) if dtype is not None else data)

    # -- parts and representations -------------------------------------------------------
    @property
    def rotation(self) -> Rotation:
        """The orientation ``R`` (``world_R_body``), a :class:`Rotation`."""
        return Rotation._wrap(self._data[..., :4])

    @property
    def velocity(self):
        """The velocity ``v`` in the navigation frame, (..., 3) (read-only for NumPy)."""
        return frozen(self._data[..., 4:7])

    @property
    def position(self):
        """The position ``p`` in the navigation frame, (..., 3) (read-only for NumPy)."""
        return frozen(self._data[..., 7:10])

    @property
    def pose(self) -> Transform:
        """The pose part ``(R, p)`` as a :class:`Transform` (``world_T_body``)."""
        return Transform(rotation=self.rotation, translation=self._data[..., 7:10])

    def as_matrix(self):
        """5x5 matrices ``[[R, v, p], [0, 1, 0], [0, 0, 1]]``, shape (..., 5, 5)."""
        return _k.matrix_from_extpose(self._data)

    def log(self):
        """Tangents ``(rho_v, rho_p, w)``, ``|w|`` in [0, pi], shape (..., 9).

        ``w`` is the rotation vector, ``rho_v = J_l(w)^-1 v``, ``rho_p = J_l(w)^-1 p``;
        the inverse of :meth:`exp`.
        """
        return _k.tangent_from_extpose(self._data)

    def adjoint(self):
        """``[[R, 0, hat(v) R], [0, R, hat(p) R], [0, 0, R]]``, shape (..., 9, 9).

        ``X exp(xi) X^-1 = exp(Ad xi)`` for tangents ``(rho_v, rho_p, w)``.
        """
        return _k.adjoint_from_extpose(self._data)

    # -- group operations ----------------------------------------------------------------
    def apply(self, points, *, inverse=False, out=None):
        """Move points by the pose part: ``R x + p``, shape (..., 3).

        ``inverse=True`` applies ``R^T (x - p)``. The velocity does not act on
        points (the 5x5 matrix on ``[x; 0; 1]``).
        """
        kern = _k.extpose_apply_inverse if inverse else _k.extpose_apply
        return kern(self._data, as_array(points, (3,), "points"), out=out)

    def inv(self):
        """Inverse states ``(R^T, -R^T v, -R^T p)`` (closed form)."""
        return ExtendedPose._wrap(self._inverse_kernel(self._data))

    def approx_equal(self, other, *, atol=1e-8):
        """Elementwise: rotation angle, position and velocity gaps all <= ``atol``."""
        if not isinstance(other, ExtendedPose):
            other = expect(other, ExtendedPose, "other")
        a, b = self._data, other._data
        angle, dv = pose_gap(a, b)  # the rotation, and the components 4:7 (velocity)
        d = a[..., 7:] - b[..., 7:]
        dp = namespace_of(d).sqrt(namespace_of(d).sum(d * d, axis=-1))
        return (angle <= atol) & (dv <= atol) & (dp <= atol)

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        d = to_numpy(self._data).tolist()
        q = ", ".join(f"{c:.6g}" for c in d[:4])
        v = ", ".join(f"{c:.6g}" for c in d[4:7])
        p = ", ".join(f"{c:.6g}" for c in d[7:])
        return (
            f"ExtendedPose(rotation=Rotation.from_quat([{q}]), velocity=[{v}], "
            f"position=[{p}])"
        )


ExtendedPose.as_matrix = owned_method(
    ExtendedPose, _k.matrix_from_extpose, ExtendedPose.as_matrix, array=True
)
