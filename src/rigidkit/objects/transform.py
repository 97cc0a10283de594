"""``Transform``: a batch of rigid motions SE(3), stored as unit quaternion + translation.

Conventions: a transform ``A_T_B`` maps points of frame B to frame A,
``p_A = A_T_B @ p_B = R p_B + t``; ``A_T_C = A_T_B @ B_T_C`` applies ``B_T_C`` first.
Quaternions are Hamilton, scalar first; twists are ordered ``(v, w)`` as in Murray,
Li & Sastry 1994 (Sec. 2.3) and Barfoot 2017 (scipy's exponential coordinates are
``(w, v)``).
"""

from __future__ import annotations

import numpy as np

from .._engine.namespace import device_of, namespace_of
from .._validate import as_array, finite_array, scipy_kind, to_numpy
from ..functional import averaging as _avg
from ..functional import conversions as _conv
from ..functional import interpolation as _interp
from ..functional import screw as _screw
from ..functional import se3 as _se3
from ..kernels import pose_formats as _kpf
from ..kernels import se3 as _k
from ..kernels.kinematics import integration as _ki
from ._batch import BatchedArray, batch_shape, expect
from ._frozen import frozen
from .group import LieGroup, owned_method
from .registry import GroupSpec
from .rotation import Rotation

__all__ = ["Transform"]


class Transform(BatchedArray, LieGroup, family="space", rank=1):
    """A batch of rigid motions of any shape: ``p -> R p + t``.

    Stored as one array of shape ``(..., 7)``: a unit quaternion ``(w, x, y, z)``
    (Hamilton) and a translation ``(tx, ty, tz)``. The array namespace (NumPy,
    torch, ...) and dtype of the inputs are kept.

    Parameters
    ----------
    rotation : Rotation, optional
        Rotation part (identity when omitted).
    translation : array_like, shape (..., 3), optional
        Translation part (zero when omitted). The two batch shapes broadcast.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> A_R_B = rk.Rotation.from_rotvec([0.0, 0.0, np.pi / 2])
    >>> A_T_B = rk.Transform(rotation=A_R_B, translation=[1.0, 0.0, 0.0])
    >>> p_B = np.array([1.0, 0.0, 0.0])
    >>> np.round(A_T_B @ p_B, 12) + 0.0
    array([1., 1., 0.])
    >>> B_T_A = A_T_B.inv()
    >>> np.round(B_T_A @ (A_T_B @ p_B), 12) + 0.0
    array([1., 0., 0.])
    >>> np.round(rk.Transform.exp([0.0, 0.0, 1.0, 0.0, 0.0, np.pi]).as_matrix(), 12) + 0.0
    array([[-1.,  0.,  0.,  0.],
           [ 0., -1.,  0.,  0.],
           [ 0.,  0.,  1.,  1.],
           [ 0.,  0.,  0.,  1.]])
    """

    __slots__ = ("_pose", "_data")  # one array under two names (see _batch)
    _storage = "_pose"
    _trail = (7,)
    _repr_columns = "(qw, qx, qy, qz, tx, ty, tz)"
    _identity = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)  # (w, x, y, z, tx, ty, tz)
    _compose_kernel = _k.pose_compose
    _inverse_kernel = _k.pose_inv
    dof, matrix_size, point_dim = 6, 4, 3
    _spec = GroupSpec(
        algebra=_se3,
        tangent=(("translation", slice(0, 3)), ("rotation", slice(3, 6))),
        rate="twist",
        step=(_ki.se3_increment, _ki.se3_increment_rk4, _ki.se3_chain),
    )

    def __init__(self, rotation=None, translation=None):
        if rotation is not None and not isinstance(rotation, Rotation):
            if translation is None and scipy_kind(rotation) == "RigidTransform":
                self._pose = self._data = Transform._from_foreign(
                    "RigidTransform", rotation
                )._pose
                return
            rotation = expect(rotation, Rotation, "rotation")
        if translation is not None:
            translation = finite_array(translation, (3,), "translation")
        if rotation is None and translation is None:
            self._pose = self._data = self._filled(self._identity, ())
            return
        if rotation is None:
            quat = _constant_like(translation, [1.0, 0.0, 0.0, 0.0])
        else:
            quat = rotation._quat
        if translation is None:
            translation = _constant_like(quat, [0.0, 0.0, 0.0])
        self._pose = self._data = _k.pose_from_quat_translation(quat, translation)

    @classmethod
    def _from_foreign(cls, kind, obj):
        if kind == "RigidTransform":  # scipy's
            rotation = Rotation._from_foreign("Rotation", obj.rotation)
            return cls(rotation=rotation, translation=obj.translation)
        return None

    # -- construction ------------------------------------------------------------------
    @classmethod
    def from_matrix(cls, matrix, *, atol=None, orthonormalize=False):
        """From homogeneous matrices ``[[R, t], [0, 1]]``, shape (..., 4, 4), validated.

        Raises :class:`~rigidkit.NotARotationError` (naming the batch index) when the
        bottom row is not ``[0, 0, 0, 1]`` or the rotation block is not a rotation
        within ``atol``; ``orthonormalize=True`` replaces the rotation block by the
        nearest rotation (SVD) instead. See :func:`rigidkit.se3.pose_from_matrix`.

        >>> M = np.eye(4)
        >>> M[:3, 3] = [1.0, 2.0, 3.0]
        >>> Transform.from_matrix(M).translation
        array([1., 2., 3.])
        """
        return cls._wrap(
            _se3.pose_from_matrix(matrix, atol=atol, orthonormalize=orthonormalize)
        )

    @classmethod
    def exp(cls, xi):
        """``exp(hat(xi))`` of twists ``xi = (v, w)``, shape (..., 6).

        ``R = exp(hat(w))`` and ``t = J_l(w) v`` (a pure translation when ``w = 0``);
        ``w`` in radians. See :func:`rigidkit.se3.exp`.
        """
        return cls._wrap(_se3.pose_from_twist(xi))

    @classmethod
    def from_exp_coords(cls, exp_coords):
        """From scipy's exponential coordinates ``(w, v)``, shape (..., 6).

        scipy's ``RigidTransform.from_exp_coords`` puts the rotation first; our
        :meth:`exp` takes the twist ``(v, w)``: ``from_exp_coords(c)`` is
        ``exp(concat(c[3:], c[:3]))``. See :func:`rigidkit.se3.pose_from_exp_coords`.

        >>> T = Transform.from_exp_coords([0.0, 0.0, np.pi / 2, 1.0, 0.0, 0.0])
        >>> np.round(T.log(), 12) + 0.0  # (v, w)
        array([1.        , 0.        , 0.        , 0.        , 0.        ,
               1.57079633])

        See Also
        --------
        as_exp_coords, exp
        """
        return cls._wrap(_se3.pose_from_exp_coords(exp_coords))

    @classmethod
    def from_dual_quat(cls, dual_quat, *, scalar_first=True):
        """From unit dual quaternions ``(q_r, q_d)``, ``q_d = (0, t) q_r / 2``, (..., 8).

        ``scalar_first=True`` (ours): ``(rw, rx, ry, rz, dw, dx, dy, dz)``;
        ``False``: both parts scalar last, as scipy's ``RigidTransform`` (whose
        default that is). Non-unit input is normalised as scipy does (``q_r /
        |q_r|``; the component of ``q_d`` along ``q_r`` dropped); a zero ``q_r``
        raises :class:`~rigidkit.ZeroNormError`. See
        :func:`rigidkit.se3.pose_from_dual_quat`.

        >>> T = Transform.from_dual_quat([1.0, 0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.5])
        >>> T.translation
        array([1., 2., 3.])

        See Also
        --------
        as_dual_quat
        """
        return cls._wrap(_se3.pose_from_dual_quat(dual_quat, scalar_first=scalar_first))

    @classmethod
    def from_pq(cls, pq, *, scalar_first=True):
        """From pose vectors: translation then quaternion, shape (..., 7).

        ``scalar_first=True``: ``(x, y, z, qw, qx, qy, qz)`` (pytransform3d's
        ``pq``); ``False``: ``(x, y, z, qx, qy, qz, qw)`` (TUM trajectories, ROS
        ``Pose``). The quaternion is normalised. See :func:`rigidkit.se3.pose_from_pq`.

        >>> T = Transform.from_pq([1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0], scalar_first=False)
        >>> T.translation, T.rotation.as_quat()
        (array([1., 2., 3.]), array([1., 0., 0., 0.]))

        See Also
        --------
        as_pq
        """
        return cls._wrap(_se3.pose_from_pq(pq, scalar_first=scalar_first))

    @classmethod
    def random(cls, shape=(), rng=None, *, dtype=None, scale=1.0):
        """Random transforms: uniform (Haar) rotations, Gaussian translations.

        Translation components are independent normal with standard deviation
        ``scale``. ``rng`` is a :class:`numpy.random.Generator` or a seed.
        """
        shape = batch_shape(shape)
        rng = np.random.default_rng(rng)
        q = _conv.quat_normalize(rng.standard_normal(shape + (4,)))
        t = scale * rng.standard_normal(shape + (3,))
        pose = np.concatenate([q, t], axis=-1)
        return cls._wrap(pose.astype(dtype) if dtype is not None else pose)

    # -- representations ---------------------------------------------------------------
    def as_matrix(self, *, out=None):
        """Homogeneous matrices ``[[R, t], [0, 1]]`` (..., 4, 4), acting on ``[p; 1]``."""
        if out is None:  # a keyword doubles the cost of calling a kernel (~0.08 us)
            return _k.matrix_from_pose(self._pose)
        return _k.matrix_from_pose(self._pose, out=out)

    def log(self):
        """Twists ``(v, w)``, ``|w|`` in [0, pi], shape (..., 6); inverse of :meth:`exp`.

        ``w`` is the rotation vector and ``v = J_l(w)^-1 t``.
        """
        return _k.twist_from_pose(self._pose)

    def as_exp_coords(self):
        """scipy's exponential coordinates ``(w, v)``, ``|w|`` in [0, pi], (..., 6).

        :meth:`log` in scipy's order (rotation first): ``as_exp_coords()`` is
        ``concat(log()[3:], log()[:3])``. See :meth:`from_exp_coords`.

        >>> np.round(Transform(translation=[1.0, 2.0, 3.0]).as_exp_coords(), 12) + 0.0
        array([0., 0., 0., 1., 2., 3.])
        """
        return _kpf.exp_coords_from_pose(self._pose)

    def as_dual_quat(self, *, scalar_first=True):
        """Unit dual quaternions ``(q, (0, t) q / 2)``, shape (..., 8).

        The layout of :meth:`from_dual_quat` (``scalar_first=False``: scipy's
        default); ``q`` is the stored quaternion (``q`` and ``-q``, all 8 numbers
        negated, are the same motion).

        >>> Transform(translation=[2.0, 0.0, 0.0]).as_dual_quat()
        array([1., 0., 0., 0., 0., 1., 0., 0.])
        """
        kern = _kpf.dual_quat_from_pose if scalar_first else _kpf.dual_quat_xyzw_from_pose
        return kern(self._pose)

    def as_pq(self, *, scalar_first=True):
        """Pose vectors ``(x, y, z, qw, qx, qy, qz)``, shape (..., 7).

        ``scalar_first=False`` gives TUM/ROS ``(x, y, z, qx, qy, qz, qw)``; see
        :meth:`from_pq`.

        >>> Transform(translation=[1.0, 2.0, 3.0]).as_pq(scalar_first=False)
        array([1., 2., 3., 0., 0., 0., 1.])
        """
        kern = _kpf.pq_from_pose if scalar_first else _kpf.pq_xyzw_from_pose
        return kern(self._pose)

    def adjoint(self):
        """Adjoint ``[[R, hat(t) R], [0, R]]``, shape (..., 6, 6), for twists ``(v, w)``.

        ``T exp(xi) T^-1 = exp(Ad xi)``.
        """
        return _k.adjoint_from_pose(self._pose)

    @property
    def rotation(self) -> Rotation:
        """The rotation part ``R`` (a :class:`Rotation` of the same batch shape)."""
        return Rotation._wrap(self._pose[..., :4])

    @property
    def translation(self):
        """The translation part ``t``, shape (..., 3) (read-only for NumPy storage)."""
        return frozen(self._pose[..., 4:])

    # -- group operations --------------------------------------------------------------
    # ``T1 @ T2`` composes (``T2`` first), ``T @ p`` moves points and ``compose`` takes
    # an ``out=`` buffer of poses: Group, with _compose_kernel.
    # A Rotation on either side is the transform with zero translation (_include).
    @classmethod
    def _include(cls, x):
        return cls(rotation=x)

    def apply(self, points, *, inverse=False, out=None):
        """Move points: ``R p + t``, shape (..., 3) broadcasting with the batch shape.

        ``T @ p`` is this. The last axis is the point, so a (3, 3) array holds three
        points, its rows (not the columns of a matrix product: for those write
        ``(T.as_matrix() @ [[X], [1, 1, 1]])[:3]``). ``inverse=True`` applies the
        inverse motion, ``R^T (p - t)`` (``T.inv() @ p``, without forming it), as
        scipy's ``apply(..., inverse=True)``: ``p_B = A_T_B.apply(p_A, inverse=True)``.

        >>> A_T_B = Transform(translation=[1.0, 0.0, 0.0])
        >>> A_T_B.apply([0.0, 0.0, 0.0], inverse=True)
        array([-1.,  0.,  0.])
        """
        kern = _k.pose_apply_inverse if inverse else _k.pose_apply
        return kern(self._pose, as_array(points, (3,), "points"), out=out)

    def inv(self):
        """Inverse transforms ``[R^T, -R^T t]`` (closed form, no matrix inverse)."""
        return Transform._wrap(self._inverse_kernel(self._pose))

    def approx_equal(self, other, *, atol=1e-8):
        """Elementwise: rotation angle between them and translation distance <= ``atol``.

        ``atol`` is in radians for the rotation and in length units for the translation.
        """
        if not isinstance(other, Transform):
            other = expect(other, Transform, "other")
        angle, dist = pose_gap(self._pose, other._pose)
        return (angle <= atol) & (dist <= atol)

    def distance_to(self, other, *, rotation_weight=1.0, translation_weight=1.0):
        """Weighted distance ``sqrt(a theta^2 + b |t2 - t1|^2)`` to ``other``, (...).

        Of the relative motion ``self.inv() @ other`` (in the frame of ``self``):
        ``theta`` its rotation angle (radians, [0, pi]), ``|R1^T (t2 - t1)| = |t2 -
        t1|`` its translation length; ``a = rotation_weight``, ``b =
        translation_weight`` (non-negative). Symmetric and invariant to a change of
        the world frame. See :func:`rigidkit.se3.pose_distance`.

        >>> A = Transform(translation=[3.0, 4.0, 0.0])
        >>> float(A.distance_to(Transform()))
        5.0
        """
        other = expect(other, Transform, "other")
        return _k.pose_distance(
            _se3._weight(rotation_weight, "rotation_weight"),
            _se3._weight(translation_weight, "translation_weight"),
            self._pose,
            other._pose,
        )

    # -- powers and means (rigidkit.functional.interpolation / averaging) ---------------
    def __pow__(self, t):
        """``T ** t = exp(t log T)``: the screw motion scaled by ``t`` (scipy's).

        ``t`` (array_like, shape (...)) broadcasts with the batch; ``T ** -1`` is the
        inverse.
        """
        return Transform._wrap(_interp.pose_power_unchecked(self._pose, t))

    def mean(
        self, weights=None, *, method="chordal", axis=None, return_info=False, tol=None
    ):
        """Mean rigid motion along batch ``axis`` (default all), sign-independent.

        ``method="chordal"``: the chordal mean rotation and the weighted mean
        translation (the rigid motion nearest the mean 4x4 matrix);
        ``"geodesic"``: the SE(3) exponential barycenter, iterated until the norm of
        the mean twist ``(v, w)`` is below ``tol`` (1e-12; 1e-6 in float32).
        ``weights``, ``axis`` and ``return_info`` as :meth:`Rotation.mean`.

        >>> T = Transform.exp([[1.0, 0, 0, 0, 0, 0.1], [-1.0, 0, 0, 0, 0, -0.1]])
        >>> np.round(T.mean(method="geodesic").log(), 12) + 0.0
        array([0., 0., 0., 0., 0., 0.])
        """
        p, k = _avg.pose_mean_unchecked(
            self._pose, weights, method=method, axis=axis, tol=tol
        )
        return (
            (Transform._wrap(p), {"iterations": k}) if return_info else Transform._wrap(p)
        )

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        p = to_numpy(self._pose).tolist()
        q = ", ".join(f"{c:.6g}" for c in p[:4])
        t = ", ".join(f"{c:.6g}" for c in p[4:])
        return f"Transform(rotation=Rotation.from_quat([{q}]), translation=[{t}])"

    # -- screws (Chasles): see rigidkit.functional.screw ---------------------------------
    @classmethod
    def from_screw(cls, point, direction, pitch, angle):
        """The screw motion: turn by ``angle`` about an axis, slide ``pitch * angle`` on it.

        The axis passes through ``point`` along ``direction`` (any nonzero length;
        turning right-handed about it). ``pitch`` is length per radian; with
        ``pitch=inf`` the motion is a pure translation by ``angle`` (a length)
        along ``direction``. Equals ``Transform.exp(V)`` with ``V = (q x w + h w,
        w)``, ``w = angle * u``. Shapes (..., 3), (..., 3), (...), (...) broadcast.

        >>> T = Transform.from_screw([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.5, np.pi)
        >>> np.round(T @ np.array([0.0, 0.0, 0.0]), 12) + 0.0
        array([2.        , 0.        , 1.57079633])

        See Also
        --------
        as_screw : the inverse.
        """
        return cls.exp(_screw.twist_from_screw(point, direction, pitch, angle))

    def as_screw(self):
        """Screw parameters ``(point, direction, pitch, angle)`` of :meth:`log`.

        ``angle`` in [0, pi]; ``point`` is the axis point nearest the origin; a pure
        translation has ``pitch = inf``, ``angle`` its length and ``direction``
        its direction. See :func:`rigidkit.functional.screw.screw_from_twist`.

        >>> T = Transform.from_screw([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.5, 1.0)
        >>> q, u, h, angle = T.as_screw()
        >>> np.round(q, 12) + 0.0, u, float(np.round(h, 12)), float(np.round(angle, 12))
        (array([1., 0., 0.]), array([0., 0., 1.]), 0.5, 1.0)
        """
        return _screw.screw_from_twist(self.log())


# From a NumPy pose batch straight to its loop (``owned_method``): the method, the
# kernel's fast entry and its shape tests were ~0.45 us of a 0.9 us call at N = 10.
Transform.as_matrix = owned_method(
    Transform, _k.matrix_from_pose, Transform.as_matrix, array=True, out=True
)


def pose_gap(a, b):
    """Rotation angle (radians) and translation distance between poses ``a`` and ``b``.

    Reads ``(w, x, y, z, tx, ty, tz)`` from the first 7 components of the last axis
    (so also the rigid part of a similarity's ``(q, t, s)``); shapes broadcast.
    """
    angle = _conv.quat_angle_between_unchecked(a[..., :4], b[..., :4])
    xp = namespace_of(angle)
    d = a[..., 4:7] - b[..., 4:7]
    return angle, xp.sqrt(xp.sum(d * d, axis=-1))


def _constant_like(a, values):
    """``values`` as an array of the namespace, dtype and device of ``a``."""
    xp = namespace_of(a)
    return xp.asarray(values, dtype=a.dtype, device=device_of(a))
