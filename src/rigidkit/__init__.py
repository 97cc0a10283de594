"""rigidkit: rigid-body kinematics in every representation, on every array backend.

Conventions (see README): Hamilton quaternions, scalar first ``(w, x, y, z)``;
active rotations on column vectors, ``v_A = A_R_B @ v_B``; Euler UPPER = intrinsic,
lower = extrinsic; twists ``(v, omega)``; radians unless ``degrees=True``.
"""

from . import conversions, euler, quaternion, se2, se3, sim3, so2, so3
from .affine import Affine, NotAffineError
from .errors import (
    EulerSequenceError,
    GimbalLockWarning,
    NonFiniteError,
    NotARotationError,
    RigidkitError,
    ShapeError,
    ZeroNormError,
)
from .projective import PointAtInfinityError, Projective, SingularMatrixError
from .quaternion import Quaternion
from .rotation import Rotation
from .rotation2d import Rotation2D
from .similarity import NotASimilarityError, Similarity
from .transform import Transform
from .transform2d import Transform2D

__version__ = "0.1.0"

__all__ = [
    "Rotation",
    "Transform",
    "se3",
    "Rotation2D",
    "Transform2D",
    "so2",
    "se2",
    "quaternion",
    "sim3",
    "Quaternion",
    "Similarity",
    "Affine",
    "Projective",
    "NotASimilarityError",
    "NotAffineError",
    "SingularMatrixError",
    "PointAtInfinityError",
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
