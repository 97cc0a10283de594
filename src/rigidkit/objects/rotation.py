"""``Rotation``: a batch of 3D rotations, stored as unit quaternions.

Conventions: Hamilton quaternions, scalar first ``(w, x, y, z)`` unless
``scalar_first=False``; rotations are active and act on column vectors,
``v_A = A_R_B @ v_B``; ``R1 @ R2`` applies ``R2`` first. Angles are radians unless
``degrees=True``.
"""

from __future__ import annotations

import math

import numpy as np

from .._validate import as_array, to_numpy
from ..functional import averaging as _avg
from ..functional import conversions as _conv
from ..functional import distances as _dist
from ..functional import interpolation as _interp
from ..functional import quaternion as _quaternion
from ..functional import sequences as _seq
from ..functional import so3 as _so3
from ..functional import swing_twist as _st
from ..functional import symmetry as _sym
from ..kernels.kinematics import integration as _ki
from ._batch import BatchedArray, batch_shape, expect
from ._frozen import frozen
from ._rotation_angles import RotationAngles
from .group import LieGroup
from .registry import GroupSpec

__all__ = ["Rotation", "geodesic_distance", "chordal_distance"]


class Rotation(RotationAngles, BatchedArray, LieGroup, family="space", rank=0):
    """A batch of 3D rotations of any shape, one unit quaternion each.

    Conventions: Hamilton quaternions ``(w, x, y, z)``; active rotations on column
    vectors, ``v_A = A_R_B @ v_B``; ``A_R_C = A_R_B @ B_R_C`` applies ``B_R_C`` first.
    The array namespace (NumPy, torch, ...) and dtype of the input are kept.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> A_R_B = rk.Rotation.from_rotvec([0.0, 0.0, np.pi / 2])
    >>> v_B = np.array([1.0, 0.0, 0.0])
    >>> np.round(A_R_B @ v_B, 12) + 0.0
    array([0., 1., 0.])
    >>> A_R_B.shape
    ()
    """

    __slots__ = ("_quat", "_data")  # one array under two names (see _batch)
    _storage = "_quat"
    _trail = (4,)
    _repr_columns = "(w, x, y, z)"
    _identity = (1.0, 0.0, 0.0, 0.0)
    _compose_kernel = _conv.quat_compose
    _inverse_kernel = _quaternion.conjugate
    dof, matrix_size, point_dim = 3, 3, 3
    _spec = GroupSpec(
        algebra=_so3,
        tangent=(("rotation", slice(0, 3)),),
        rate="angular velocity",
        step=(_ki.so3_increment, _ki.so3_increment_rk4, _ki.so3_chain),
    )

    def __init__(self, quat, *, _normalized=False):
        if type(quat) is not np.ndarray and hasattr(quat, "as_matrix"):
            quat = expect(quat, Rotation, "Rotation(quat)")._quat  # scipy's: converted
        elif not _normalized:
            quat = _conv.quat_normalize(quat)
        self._quat = self._data = quat

    @classmethod
    def _from_foreign(cls, kind, obj):
        if kind == "Rotation":  # scipy's
            return cls._wrap(_conv.quat_normalize(obj.as_quat(scalar_first=True)))
        return None

    # -- construction -------------------------------------------------------
    @classmethod
    def from_quat(cls, quat, *, scalar_first=True):
        """From quaternions, shape (..., 4); normalised (any finite nonzero scale).

        ``scalar_first=True``: ``(w, x, y, z)`` (ours); ``False``: ``(x, y, z, w)``
        as in scipy, ROS and Eigen's storage order.

        >>> Rotation.from_quat([0.0, 0.0, 0.0, 2.0], scalar_first=False).as_quat()
        array([1., 0., 0., 0.])
        """
        if type(quat) is not np.ndarray and hasattr(quat, "as_matrix"):
            return expect(quat, cls, "quat")  # an object: no order to choose
        q = as_array(quat, (4,), "quaternion")
        if not scalar_first:
            q = _conv.quat_wxyz_from_xyzw(q)
        return cls._wrap(_conv.quat_normalize(q))

    @classmethod
    def from_matrix(cls, matrix, *, atol=None, orthonormalize=False):
        """From rotation matrices, shape (..., 3, 3), validated.

        ``atol`` is the largest accepted distance from SO(3), ``max(|R^T R - I|,
        |det R - 1|)``: by default 1e-5 for float64 (so matrices written to 6
        decimals, up to 2e-6 off, are accepted) and 1e-4 for float32. A matrix
        within it is projected onto the nearest rotation (to ``3/8 atol^2``); one
        farther (a scaling by 1 + 1e-5, a shear, a reflection) raises
        :class:`~rigidkit.NotARotationError` naming the batch index, and NaN or
        infinity :class:`~rigidkit.NonFiniteError`. ``orthonormalize=True``
        projects any finite matrix onto its nearest rotation (SVD) instead.
        See :func:`rigidkit.conversions.quat_from_matrix`.

        >>> M = np.round(Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix(), 6)
        >>> R = Rotation.from_matrix(M)                    # 6 decimals: accepted
        >>> bool(np.abs(R.as_matrix() - M).max() < 1e-6)
        True
        """
        return cls._wrap(
            _conv.quat_from_matrix(matrix, atol=atol, orthonormalize=orthonormalize)
        )

    @classmethod
    def from_rotvec(cls, rotvec, *, degrees=False):
        """From rotation vectors ``angle * axis``, shape (..., 3)."""
        if degrees:
            rotvec = as_array(rotvec, (3,), "rotation vector") * (math.pi / 180.0)
        return cls._wrap(_conv.quat_from_rotvec(rotvec))

    @classmethod
    def exp(cls, tau):
        """``exp(hat(tau))`` for rotation vectors ``tau`` (radians), shape (..., 3)."""
        return cls.from_rotvec(tau)

    @classmethod
    def from_axis_angle(cls, axis, angle, *, degrees=False):
        """From an axis (shape (..., 3), any nonzero length) and an angle (shape (...))."""
        t = as_array(angle, (), "angle")
        if degrees:
            t = t * (math.pi / 180.0)
        return cls._wrap(_conv.quat_from_axis_angle(axis, t))

    @classmethod
    def create_group(cls, group, axis="Z", *, dtype=None):
        """The elements of a finite rotation group, shape (n,) (scipy's ``create_group``).

        ``group``: ``"I"`` (icosahedral, 60), ``"O"`` (octahedral, 24), ``"T"``
        (tetrahedral, 12), ``"Dn"`` (dihedral, 2n) or ``"Cn"`` (cyclic, n) about
        ``axis`` (``"X"``, ``"Y"``, ``"Z"``). Built NumPy-side (float64 unless
        ``dtype``); see :func:`rigidkit.functional.symmetry.quat_group`.

        >>> len(Rotation.create_group("O")), Rotation.create_group("D2", "X").shape
        (24, (4,))
        """
        q = _sym.quat_group(group, axis, dtype=np.float64 if dtype is None else dtype)
        return cls._wrap(q)

    def reduce(self, left=None, right=None, *, return_indices=False):
        """``l @ self @ r`` of smallest angle, ``l`` in ``left``, ``r`` in ``right``.

        scipy's ``Rotation.reduce``: with ``left`` and ``right`` the symmetry groups
        (e.g. :meth:`create_group`) of two objects related by ``self``, the
        smallest rotation that aligns them. ``None`` is the identity alone. With
        ``return_indices=True`` returns ``(reduced, left_index, right_index)``,
        integer arrays of the batch shape (None for a group not given). Runs on
        the rotations' array namespace (a matrix product and an argmax); see
        :func:`rigidkit.functional.symmetry.quat_reduce`.

        >>> R = Rotation.from_rotvec([0.0, 0.0, 1.6])
        >>> reduced = R.reduce(right=Rotation.create_group("C4"))
        >>> float(np.round(reduced.angle, 12))            # 1.6 - pi/2
        0.029203673205
        """
        if left is None and right is None:
            return (self, None, None) if return_indices else self
        q, li, ri = _sym.quat_reduce(
            self._quat,
            None if left is None else left._quat,
            None if right is None else right._quat,
        )
        reduced = Rotation._wrap(q)
        if not return_indices:
            return reduced
        return reduced, (None if left is None else li), (None if right is None else ri)

    @classmethod
    def random(cls, shape=(), rng=None, *, dtype=None):
        """Uniformly distributed (Haar) rotations, from a normalised 4D Gaussian.

        ``rng`` is a :class:`numpy.random.Generator` or a seed.
        """
        rng = np.random.default_rng(rng)
        q = rng.standard_normal(batch_shape(shape) + (4,))
        q = _conv.quat_normalize(q)
        return cls._wrap(q.astype(dtype) if dtype is not None else q)

    # -- representations ------------------------------------------------------
    def as_quat(self, *, scalar_first=True, canonical=False):
        """Unit quaternions, shape (..., 4); ``canonical=True`` gives ``w >= 0``.

        A NumPy result of the stored quaternions is a read-only view (objects are
        immutable; ``.copy()`` it to edit), see :mod:`rigidkit.objects._frozen`.
        """
        if canonical:
            q = _conv.quat_canonical(self._quat)
        elif scalar_first:
            return frozen(self._quat)
        else:
            q = self._quat
        return q if scalar_first else _conv.quat_xyzw_from_wxyz(q)

    def as_matrix(self, *, out=None):
        """Rotation matrices, shape (..., 3, 3), ``v_A = A_R_B @ v_B``."""
        return _conv.matrix_from_quat_unchecked(self._quat, out=out)

    def as_rotvec(self, *, degrees=False):
        """Rotation vectors ``angle * axis``, angle in [0, pi], shape (..., 3)."""
        r = _conv.rotvec_from_quat_unchecked(self._quat)
        return r * (180.0 / math.pi) if degrees else r

    def log(self):
        """Rotation vectors (angle in [0, pi]), the inverse of :meth:`exp`."""
        return self.as_rotvec()

    def adjoint(self):
        """Adjoint of SO(3): the rotation matrix itself, ``R hat(w) R^T = hat(R w)``."""
        return self.as_matrix()

    def as_axis_angle(self, *, degrees=False):
        """``(axis, angle)``: unit axes (..., 3) and angles (...) in [0, pi].

        The identity has axis ``+x`` and angle 0.
        """
        axis, angle = _conv.axis_angle_from_quat_unchecked(self._quat)
        return axis, (angle * (180.0 / math.pi) if degrees else angle)

    @property
    def angle(self):
        """Rotation angle in [0, pi], shape (...)."""
        return self.as_axis_angle()[1]

    @property
    def axis(self):
        """Unit rotation axis, shape (..., 3) (``+x`` for the identity)."""
        return self.as_axis_angle()[0]

    # -- group operations ----------------------------------------------------------
    # ``R1 @ R2`` composes (``R2`` first), ``R @ v`` rotates vectors and ``compose``
    # takes an ``out=`` buffer: Group, with the Hamilton product as _compose_kernel.
    def apply(self, vectors, *, inverse=False, out=None):
        """Rotate vectors, shape (..., 3) broadcasting with the rotation's shape.

        ``R @ v`` is this. The last axis is the vector, so a (3, 3) array ``X`` is
        three vectors, its rows: ``R @ X == X @ R.as_matrix().T``. The matrix
        product, which rotates the columns, is spelled ``R.as_matrix() @ X``.
        ``inverse=True`` applies the inverse rotation, ``R^T v`` (``v_B = B_R_A
        v_A`` from ``A_R_B``), as scipy's ``apply(v, inverse=True)``; ``out`` is a
        NumPy buffer of shape (..., 3) for the result.

        >>> R = Rotation.from_rotvec([0.0, 0.0, np.pi / 2])
        >>> X = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) + 1.0
        >>> np.round(R @ X, 12) + 0.0                  # rows rotated
        array([[-1.,  2.,  1.],
               [-2.,  1.,  1.],
               [-1.,  1.,  2.]])
        >>> np.round(R.as_matrix() @ X, 12) + 0.0      # columns rotated
        array([[-1., -2., -1.],
               [ 2.,  1.,  1.],
               [ 1.,  1.,  2.]])
        """
        v = as_array(vectors, (3,), "vectors")
        q = _quaternion.conjugate(self._quat) if inverse else self._quat
        return _conv.quat_apply_unchecked(q, v, out=out)

    def inv(self):
        """Inverse rotations (conjugate quaternions)."""
        return Rotation._wrap(self._inverse_kernel(self._quat))

    def approx_equal(self, other, *, atol=1e-8):
        """Elementwise: the angle between the rotations is at most ``atol`` (radians).

        ``q`` and ``-q`` are the same rotation and compare equal.
        """
        if not isinstance(other, Rotation):
            other = expect(other, Rotation, "other")
        return _conv.quat_angle_between_unchecked(self._quat, other._quat) <= atol

    def angle_to(self, other):
        """Geodesic distance: the angle (radians, [0, pi]) of ``self.inv() @ other``.

        ``|log(R1^T R2)|``, the Riemannian distance on SO(3), shape of the
        broadcast batches; equal to scipy's ``(r1.inv() * r2).magnitude()``. See
        also :meth:`chordal_distance` and :func:`rigidkit.geodesic_distance`.

        >>> a = Rotation.from_rotvec([0.0, 0.0, 0.5])
        >>> float(np.round(a.angle_to(Rotation.from_rotvec([0.0, 0.0, -0.25])), 12))
        0.75
        """
        if not isinstance(other, Rotation):
            other = expect(other, Rotation, "other")
        return _conv.quat_angle_between_unchecked(self._quat, other._quat)

    def chordal_distance(self, other):
        """Chordal distance ``|R1 - R2|_F`` (Frobenius), ``2 sqrt(2) sin(theta/2)``.

        ``theta`` is :meth:`angle_to`; in [0, 2 sqrt(2)]. See
        :mod:`rigidkit.functional.distances`.

        >>> a = Rotation.identity()
        >>> float(np.round(a.chordal_distance(Rotation.from_rotvec([np.pi, 0, 0])), 12))
        2.828427124746
        """
        if not isinstance(other, Rotation):
            other = expect(other, Rotation, "other")
        return _dist.chordal_distance_unchecked(self._quat, other._quat)

    def swing_twist(self, axis):
        """``(swing, twist)`` Rotations with ``self = swing @ twist``, twist about ``axis``.

        ``twist`` (applied first) turns about ``axis`` (..., 3), by an angle in [-pi,
        pi]; ``swing`` about an axis orthogonal to it. Where the swing is a half
        turn every twist would do and the twist is the identity. For ``self =
        twist' @ swing'`` use ``s, t = self.inv().swing_twist(axis)``, ``twist' =
        t.inv()``, ``swing' = s.inv()``. See :mod:`rigidkit.functional.swing_twist`.

        >>> R = Rotation.from_euler("ZYX", [0.7, 0.2, 0.0])  # yaw, then pitch (body)
        >>> swing, twist = R.swing_twist([0.0, 1.0, 0.0])
        >>> float(np.round(twist.angle, 12)), bool((swing @ twist).approx_equal(R))
        (0.2, True)
        """
        swing, twist = _st.swing_twist(self._quat, axis)
        return Rotation._wrap(swing), Rotation._wrap(twist)

    def continuous(self, *, axis=-1):
        """The same rotations with quaternion signs continuous along batch ``axis``.

        Each quaternion is flipped to ``-q`` where needed so that neighbours have
        ``q_k . q_k+1 >= 0`` (the first keeps its sign): for plots and learning
        targets; the rotations are unchanged. ``axis`` is a batch axis (default
        the last). See :func:`rigidkit.quat_continuous`.
        """
        nb = len(self.shape)
        if nb == 0:  # one rotation: nothing to be continuous with
            return self
        if not -nb <= axis < nb:
            raise np.exceptions.AxisError(
                f"axis {axis} is out of bounds for a batch of {nb} dimensions"
            )
        q = _seq.quat_continuous(self._quat, axis=(axis % nb) - nb - 1)
        return Rotation._wrap(q)

    def magnitude(self):
        """Rotation angle in [0, pi] (same as :attr:`angle`)."""
        return self.angle

    # -- powers and means (rigidkit.functional.interpolation / averaging) ---------------
    def __pow__(self, t):
        """``R ** t = exp(t log R)``: ``t`` times the angle about the axis (scipy's).

        ``t`` (array_like, shape (...)) broadcasts with the batch; ``R ** 0`` is the
        identity and ``R ** -1`` the inverse.
        """
        return Rotation._wrap(_interp.quat_power_unchecked(self._quat, t))

    def mean(
        self, weights=None, *, method="chordal", axis=None, return_info=False, tol=None
    ):
        """Mean rotation along batch ``axis`` (default all), independent of ``q`` signs.

        ``method="chordal"`` (scipy's): the rotation nearest the weighted mean
        matrix; ``"geodesic"``: the Karcher mean, iterated until the norm of the mean
        log is below ``tol`` (1e-12 rad; 1e-6 in float32). ``weights`` (shape (...),
        >= 0) broadcast with the batch. ``return_info=True`` returns ``(mean, info)``,
        ``info = {"iterations": k}``. See :func:`rigidkit.functional.averaging.quat_mean`.

        >>> R = Rotation.from_rotvec([[0.0, 0.0, 0.1], [0.0, 0.0, -0.1]])
        >>> np.round(R.mean().as_rotvec(), 12) + 0.0
        array([0., 0., 0.])
        """
        q, k = _avg.quat_mean_unchecked(
            self._quat, weights, method=method, axis=axis, tol=tol
        )
        return (Rotation._wrap(q), {"iterations": k}) if return_info else Rotation._wrap(q)

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        vals = ", ".join(f"{c:.6g}" for c in to_numpy(self._quat).tolist())
        return f"Rotation.from_quat([{vals}])"


def geodesic_distance(a, b):
    """Geodesic distance between Rotations: the angle of ``a.inv() @ b``, [0, pi].

    Radians, shape of the broadcast batches; :meth:`Rotation.angle_to`.

    >>> import rigidkit as rk
    >>> a, b = rk.Rotation.identity(), rk.Rotation.from_rotvec([0.0, 0.3, 0.0])
    >>> float(np.round(rk.geodesic_distance(a, b), 12))
    0.3
    """
    return a.angle_to(b)


def chordal_distance(a, b):
    """Chordal distance between Rotations, ``|R_a - R_b|_F`` (Frobenius), [0, 2.83].

    ``2 sqrt(2) sin(theta / 2)`` of the geodesic angle; :meth:`Rotation.chordal_distance`.

    >>> import rigidkit as rk
    >>> a, b = rk.Rotation.identity(), rk.Rotation.from_rotvec([0.0, 0.3, 0.0])
    >>> float(np.round(rk.chordal_distance(a, b), 12))  # 2 sqrt(2) sin(0.15)
    0.42267486736
    """
    return a.chordal_distance(b)
