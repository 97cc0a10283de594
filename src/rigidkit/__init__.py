"""rigidkit: rigid-body kinematics in every representation, on every array backend.

Conventions (see README): Hamilton quaternions, scalar first ``(w, x, y, z)``;
active rotations on column vectors, ``v_A = A_R_B @ v_B``; Euler UPPER = intrinsic,
lower = extrinsic; twists ``(v, omega)``; radians unless ``degrees=True``.
"""

from . import conversions, so3
from .errors import (
    EulerSequenceError,
    GimbalLockWarning,
    NonFiniteError,
    NotARotationError,
    RigidkitError,
    ShapeError,
    ZeroNormError,
)
from .rotation import Rotation

__version__ = "0.1.0"

__all__ = [
    "Rotation",
    "conversions",
    "so3",
    "RigidkitError",
    "NotARotationError",
    "NonFiniteError",
    "ZeroNormError",
    "ShapeError",
    "EulerSequenceError",
    "GimbalLockWarning",
]
