"""What every kinematics function shares: the frame keyword and reading its inputs."""

from __future__ import annotations

from ..._validate import finite_array
from ...errors import FrameKeywordError
from ...functional import conversions as _conv
from ...functional import se3 as _se3
from ...objects.rotation import Rotation
from ...objects.transform import Transform

_FRAMES = (
    "'world' (the velocity in the fixed axes: R' = hat(omega) R, T' = hat(V) T) or "
    "'body' (in the moving axes: R' = R hat(omega), T' = T hat(V))"
)


def body_flag(frame, fn: str) -> int:
    """1 for ``frame="body"``, 0 for ``"world"``; :class:`FrameKeywordError` otherwise.

    A velocity without its frame is ambiguous (``omega_world = R omega_body``), so
    the keyword has no default.
    """
    if frame == "world":
        return 0
    if frame == "body":
        return 1
    if frame is None:
        raise FrameKeywordError(f"{fn}: the keyword frame= is required: {_FRAMES}")
    raise FrameKeywordError(f"{fn}: frame must be {_FRAMES}; got {frame!r}")


def _matrix(x, cls, trail, what, check):
    """The matrix of a ``cls`` object, or ``x`` as a finite array checked by ``check``.

    ``check`` raises with the batch index where a matrix is outside the group
    (the conversions do); the matrix itself is used as given.
    """
    if isinstance(x, cls):
        return x.as_matrix()
    m = finite_array(x, trail, what)
    check(m)
    return m


def rotation_matrix(R, what: str = "rotation matrix"):
    """Rotation matrices (..., 3, 3) of a :class:`Rotation` or an array, validated."""
    return _matrix(R, Rotation, (3, 3), what, _conv.quat_from_matrix)


def homogeneous_matrix(T, what: str = "homogeneous matrix"):
    """Homogeneous matrices (..., 4, 4) of a :class:`Transform` or an array, validated."""
    return _matrix(T, Transform, (4, 4), what, _se3.pose_from_matrix)


def quaternion(q, what: str = "quaternion"):
    """Quaternions (..., 4) ``(w, x, y, z)`` of a :class:`Rotation` or an array."""
    if isinstance(q, Rotation):
        return q.as_quat()
    return finite_array(q, (4,), what)


def vector(x, trail, what: str):
    """A finite array of trailing shape ``trail``."""
    return finite_array(x, trail, what)
