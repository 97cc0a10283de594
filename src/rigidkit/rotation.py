"""``Rotation``: a batch of 3D rotations, stored as unit quaternions.

Conventions: Hamilton quaternions, scalar first ``(w, x, y, z)`` unless
``scalar_first=False``; rotations are active and act on column vectors,
``v_A = A_R_B @ v_B``; ``R1 @ R2`` applies ``R2`` first. Angles are radians unless
``degrees=True``.
"""

from __future__ import annotations

import math

import numpy as np

from . import conversions as _conv
from ._engine.namespace import is_numpy, namespace_of
from ._validate import as_array
from .errors import ShapeError
from .group import LieGroup

__all__ = ["Rotation"]


def _numpy_or(x):
    return np.asarray(x) if is_numpy(namespace_of(x)) else x


class Rotation(LieGroup):
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

    __slots__ = ("_quat",)
    dof = 3
    matrix_size = 3
    point_dim = 3
    __array_priority__ = 1000  # so ndarray @ Rotation defers to us (and fails clearly)

    def __init__(self, quat, *, _normalized=False):
        if not _normalized:
            quat = _conv.quat_normalize(quat)
        self._quat = quat

    # -- construction -------------------------------------------------------
    @classmethod
    def _wrap(cls, quat):
        obj = cls.__new__(cls)
        obj._quat = quat
        return obj

    @classmethod
    def from_quat(cls, quat, *, scalar_first=True):
        """From quaternions, shape (..., 4); normalised (any finite nonzero scale).

        ``scalar_first=True``: ``(w, x, y, z)`` (ours); ``False``: ``(x, y, z, w)``
        as in scipy, ROS and Eigen's storage order.

        >>> Rotation.from_quat([0.0, 0.0, 0.0, 2.0], scalar_first=False).as_quat()
        array([1., 0., 0., 0.])
        """
        q = as_array(quat, (4,), "quaternion")
        if not scalar_first:
            q = _conv.quat_wxyz_from_xyzw(q)
        return cls._wrap(_conv.quat_normalize(q))

    @classmethod
    def from_matrix(cls, matrix, *, atol=None, orthonormalize=False):
        """From rotation matrices, shape (..., 3, 3), validated.

        Raises :class:`~rigidkit.NotARotationError` (naming the batch index) when a
        matrix is not a rotation within ``atol``; ``orthonormalize=True`` projects
        onto the nearest rotation (SVD) instead.
        See :func:`rigidkit.conversions.quat_from_matrix`.
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
    def from_mrp(cls, mrp):
        """From modified Rodrigues parameters ``axis * tan(angle / 4)``, shape (..., 3)."""
        return cls._wrap(_conv.quat_from_mrp(mrp))

    @classmethod
    def from_euler(cls, seq, angles, *, degrees=False):
        """From Euler angles, shape (..., 3).

        ``seq``: three letters of ``xyz``; UPPERCASE = intrinsic (body axes),
        lowercase = extrinsic (world axes). ``"ZYX"`` is yaw-pitch-roll.

        >>> R = Rotation.from_euler("ZYX", [90.0, 0.0, 0.0], degrees=True)
        >>> np.round(R.as_rotvec(), 12) + 0.0
        array([0.        , 0.        , 1.57079633])
        """
        from . import euler

        return cls._wrap(euler.quat_from_euler(seq, angles, degrees=degrees))

    @classmethod
    def identity(cls, shape=(), *, dtype=None):
        """Identity rotations of batch ``shape`` (``()`` for one)."""
        shape = (shape,) if isinstance(shape, int) else tuple(shape)
        q = np.zeros(shape + (4,), dtype=dtype or np.float64)
        q[..., 0] = 1.0
        return cls._wrap(q)

    @classmethod
    def random(cls, shape=(), rng=None, *, dtype=None):
        """Uniformly distributed (Haar) rotations, from a normalised 4D Gaussian.

        ``rng`` is a :class:`numpy.random.Generator` or a seed.
        """
        shape = (shape,) if isinstance(shape, int) else tuple(shape)
        rng = np.random.default_rng(rng)
        q = rng.standard_normal(shape + (4,))
        q = _conv.quat_normalize(q)
        return cls._wrap(q.astype(dtype) if dtype is not None else q)

    @classmethod
    def concatenate(cls, rotations):
        """Join 1-D batches (or single rotations) along the first axis."""
        quats = [r._quat if r._quat.ndim > 1 else r._quat[None] for r in rotations]
        if not quats:
            raise ShapeError("concatenate needs at least one Rotation")
        xp = namespace_of(*quats)
        return cls._wrap(xp.concat(quats, axis=0))

    # -- representations ------------------------------------------------------
    def as_quat(self, *, scalar_first=True, canonical=False):
        """Unit quaternions, shape (..., 4); ``canonical=True`` gives ``w >= 0``."""
        q = _conv.quat_canonical(self._quat) if canonical else self._quat
        return q if scalar_first else _conv.quat_xyzw_from_wxyz(q)

    def as_matrix(self, *, out=None):
        """Rotation matrices, shape (..., 3, 3), ``v_A = A_R_B @ v_B``."""
        return _conv.matrix_from_quat(self._quat, out=out)

    def as_rotvec(self, *, degrees=False):
        """Rotation vectors ``angle * axis``, angle in [0, pi], shape (..., 3)."""
        r = _conv.rotvec_from_quat(self._quat)
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
        axis, angle = _conv.axis_angle_from_quat(self._quat)
        return axis, (angle * (180.0 / math.pi) if degrees else angle)

    def as_mrp(self):
        """Modified Rodrigues parameters ``axis * tan(angle / 4)``, norm <= 1."""
        return _conv.mrp_from_quat(self._quat)

    def as_euler(self, seq, *, degrees=False):
        """Euler angles for ``seq`` (UPPER intrinsic, lower extrinsic), shape (..., 3).

        First and third angles in (-pi, pi]; the second in [0, pi] for proper
        sequences (``ZXZ``) and [-pi/2, pi/2] for Tait-Bryan ones (``ZYX``). At gimbal
        lock a :class:`~rigidkit.GimbalLockWarning` is emitted and the third angle
        is 0, also at a lock missed by rounding only (angles like ``(30, 90, 10)``
        degrees: see :func:`rigidkit.euler.euler_from_quat`); the angles always
        rebuild the rotation.
        """
        from . import euler

        return euler.euler_from_quat(seq, self._quat, degrees=degrees)

    @property
    def angle(self):
        """Rotation angle in [0, pi], shape (...)."""
        return self.as_axis_angle()[1]

    @property
    def axis(self):
        """Unit rotation axis, shape (..., 3) (``+x`` for the identity)."""
        return self.as_axis_angle()[0]

    # -- group operations ----------------------------------------------------------
    def __matmul__(self, other):
        """``R1 @ R2`` composes (``R2`` first); ``R @ v`` rotates vectors (..., 3)."""
        if isinstance(other, Rotation):
            return Rotation._wrap(_conv.quat_multiply(self._quat, other._quat))
        if isinstance(other, LieGroup) or hasattr(other, "__rmatmul_rigidkit__"):
            return NotImplemented  # e.g. Rotation @ Affine: the more general kind decides
        return self.apply(other)

    def __rmatmul__(self, other):
        raise TypeError(
            "array @ Rotation is not defined; rotate vectors with R @ v or R.apply(v)"
        )

    def apply(self, vectors, *, out=None):
        """Rotate vectors, shape (..., 3) broadcasting with the rotation's shape."""
        v = as_array(vectors, (3,), "vectors")
        return _conv.quat_apply(self._quat, v, out=out)

    def inv(self):
        """Inverse rotations (conjugate quaternions)."""
        return Rotation._wrap(_conv.quat_conjugate(self._quat))

    def approx_equal(self, other, *, atol=1e-8):
        """Elementwise: the angle between the rotations is at most ``atol`` (radians).

        ``q`` and ``-q`` are the same rotation and compare equal.
        """
        return _conv.quat_angle_between(self._quat, other._quat) <= atol

    def magnitude(self):
        """Rotation angle in [0, pi] (same as :attr:`angle`)."""
        return self.angle

    # -- container protocol ---------------------------------------------------------
    @property
    def shape(self) -> tuple:
        """Batch shape (``()`` for a single rotation)."""
        return tuple(self._quat.shape[:-1])

    @property
    def dtype(self):
        return self._quat.dtype

    @property
    def single(self) -> bool:
        return self._quat.ndim == 1

    def __len__(self):
        if self.single:
            raise TypeError("a single Rotation has no len()")
        return self._quat.shape[0]

    def __getitem__(self, index):
        if self.single:
            raise TypeError("a single Rotation cannot be indexed")
        if not isinstance(index, tuple):
            index = (index,)
        return Rotation._wrap(self._quat[index + (slice(None),)])

    def __iter__(self):
        if self.single:
            raise TypeError("a single Rotation is not iterable")
        for k in range(len(self)):
            yield self[k]

    def reshape(self, *shape):
        """The same rotations with another batch shape."""
        if len(shape) == 1 and isinstance(shape[0], (tuple, list)):
            shape = tuple(shape[0])
        xp = namespace_of(self._quat)
        return Rotation._wrap(xp.reshape(self._quat, tuple(shape) + (4,)))

    def __repr__(self):
        q = self._quat
        if self.single:
            vals = ", ".join(f"{float(c):.6g}" for c in _numpy_or(_to_np(q)))
            return f"Rotation.from_quat([{vals}])"
        return f"Rotation(shape={self.shape}, dtype={q.dtype})"

    def __reduce__(self):
        return (Rotation._wrap, (self._quat,))

    def __eq__(self, other):  # identity of objects; use approx_equal for rotations
        return NotImplemented if not isinstance(other, Rotation) else self is other

    __hash__ = object.__hash__


def _to_np(q):
    return q.detach().cpu().numpy() if hasattr(q, "detach") else np.asarray(q)
