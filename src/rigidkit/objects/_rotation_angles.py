"""The angle parameterizations of :class:`~rigidkit.Rotation`, a base class of it.

Euler angles (three axes of ``xyz``, or one or two as in scipy), Davenport angles
(about any three axes, consecutive ones orthogonal), the continuous 6D
representation (Zhou et al. 2019) and modified Rodrigues parameters: each pair
``from_*`` / ``as_*`` converts through the stored unit quaternions, by the
functions of :mod:`rigidkit.functional`. Rotation lists this class first among
its bases, so these methods resolve as if written in it.
"""

from __future__ import annotations

import numpy as np  # noqa: F401  (the doctests' namespace)

from ..functional import conversions as _conv
from ..functional import davenport as _dav
from ..functional import euler
from ..functional import rot6d as _r6

__all__ = ["RotationAngles"]


class RotationAngles:
    """``from_*`` / ``as_*`` of Euler and Davenport angles, 6D and MRP (see module)."""

    __slots__ = ()

    @classmethod
    def from_mrp(cls, mrp):
        """From modified Rodrigues parameters ``axis * tan(angle / 4)``, shape (..., 3)."""
        return cls._wrap(_conv.quat_from_mrp(mrp))

    @classmethod
    def from_euler(cls, seq, angles, *, degrees=False):
        """From Euler angles, shape (..., n) for a sequence of ``n`` letters.

        ``seq``: three letters of ``xyz``, or one or two as in scipy (``"z"``,
        ``"zy"``; with one letter a scalar angle is accepted); UPPERCASE =
        intrinsic (body axes), lowercase = extrinsic (world axes). ``"ZYX"`` is
        yaw-pitch-roll. :meth:`as_euler` takes three letters (as scipy's).

        >>> from rigidkit import Rotation
        >>> R = Rotation.from_euler("ZYX", [90.0, 0.0, 0.0], degrees=True)
        >>> np.round(R.as_rotvec(), 12) + 0.0
        array([0.        , 0.        , 1.57079633])
        >>> bool(R.approx_equal(Rotation.from_euler("z", 90.0, degrees=True)))
        True
        """
        return cls._wrap(euler.quat_from_euler(seq, angles, degrees=degrees))

    @classmethod
    def from_davenport(cls, axes, order, angles, *, degrees=False):
        """From Davenport angles: turns about 1 to 3 given axes (scipy's semantics).

        ``order="intrinsic"`` (``"i"``, body axes): ``R = R_n1(t1) R_n2(t2)
        R_n3(t3)``; ``"extrinsic"`` (``"e"``, world axes): ``R = R_n3(t3) R_n2(t2)
        R_n1(t1)``. ``axes`` (3,) or (..., n, 3), any nonzero length, consecutive
        ones orthogonal (``n1`` and ``n3`` may make any angle); ``angles`` (..., n),
        a scalar for one axis. See
        :func:`rigidkit.functional.davenport.quat_from_davenport`.

        >>> from rigidkit import Rotation
        >>> ez, ey, ex = [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]
        >>> angles = [30.0, 20.0, 10.0]
        >>> R = Rotation.from_davenport([ez, ey, ex], "intrinsic", angles, degrees=True)
        >>> bool(R.approx_equal(Rotation.from_euler("ZYX", angles, degrees=True)))
        True
        """
        return cls._wrap(_dav.quat_from_davenport(axes, order, angles, degrees=degrees))

    def as_davenport(self, axes, order, *, degrees=False):
        """Davenport angles about three axes (..., 3, 3), shape (..., 3).

        Conventions and ranges as :meth:`from_davenport` and
        :func:`rigidkit.functional.davenport.davenport_from_quat` (scipy's): the
        middle angle lies in an interval of length pi that starts at the angle
        between the first and last axis; at gimbal lock a
        :class:`~rigidkit.GimbalLockWarning` and the third angle 0.

        >>> from rigidkit import Rotation
        >>> axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 1.0]]
        >>> R = Rotation.from_davenport(axes, "e", [0.4, -0.3, 0.2])
        >>> np.round(R.as_davenport(axes, "e"), 12) + 0.0
        array([ 0.4, -0.3,  0.2])
        """
        return _dav.davenport_from_quat_unchecked(axes, order, self._quat, degrees=degrees)

    @classmethod
    def from_6d(cls, rot6d):
        """From the continuous 6D representation (Zhou et al. 2019), shape (..., 6).

        The first two COLUMNS ``a1, a2`` of the matrix, ``(R00, R10, R20, R01, R11,
        R21)``, any scale: ``R = [b1 b2 b1 x b2]`` by Gram-Schmidt. (pytorch3d's
        ``rotation_6d`` holds the first two rows: that is ``R.inv().as_6d()``.)
        Zero or parallel vectors raise :class:`~rigidkit.DegenerateInputError`.
        See :mod:`rigidkit.functional.rot6d`.

        >>> from rigidkit import Rotation
        >>> R = Rotation.from_6d([2.0, 0.0, 0.0, 1.0, 3.0, 0.0])
        >>> np.round(R.as_quat(), 12) + 0.0
        array([1., 0., 0., 0.])
        """
        return cls._wrap(_r6.quat_from_rot6d(rot6d))

    def as_6d(self):
        """The 6D representation: the first two matrix columns, shape (..., 6).

        ``(R00, R10, R20, R01, R11, R21)`` (Zhou et al. 2019); see :meth:`from_6d`.

        >>> from rigidkit import Rotation
        >>> np.round(Rotation.from_rotvec([0.0, 0.0, np.pi / 2]).as_6d(), 12) + 0.0
        array([ 0.,  1.,  0., -1.,  0.,  0.])
        """
        return _r6.rot6d_from_quat(self._quat)

    def as_mrp(self):
        """Modified Rodrigues parameters ``axis * tan(angle / 4)``, norm <= 1."""
        return _conv.mrp_from_quat_unchecked(self._quat)

    def as_euler(self, seq, *, degrees=False):
        """Euler angles for ``seq`` (UPPER intrinsic, lower extrinsic), shape (..., 3).

        First and third angles in (-pi, pi]; the second in [0, pi] for proper
        sequences (``ZXZ``) and [-pi/2, pi/2] for Tait-Bryan ones (``ZYX``). At gimbal
        lock a :class:`~rigidkit.GimbalLockWarning` is emitted and the third angle
        is 0, also at a lock missed by rounding only (angles like ``(30, 90, 10)``
        degrees: see :func:`rigidkit.euler.euler_from_quat`); the angles always
        rebuild the rotation.
        """
        return euler.euler_from_quat_unchecked(seq, self._quat, degrees=degrees)
