"""rigidkit: rigid-body kinematics in every representation, on every array backend.

Conventions (see README and docs/conventions.md): Hamilton quaternions, scalar
first ``(w, x, y, z)``; active rotations on column vectors, ``v_A = A_R_B @ v_B``;
Euler UPPER = intrinsic, lower = extrinsic; twists ``(v, omega)``; radians unless
``degrees=True``.
"""

from . import conversions, euler, quaternion, se2, se3, sim3, so2, so3
from .affine import Affine
from .errors import (
    EulerSequenceError,
    GimbalLockWarning,
    NonFiniteError,
    NotAffineError,
    NotARotationError,
    NotASimilarityError,
    PointAtInfinityError,
    RigidkitError,
    ShapeError,
    SingularMatrixError,
    ZeroNormError,
)
from .projective import Projective
from .quaternion import Quaternion
from .rotation import Rotation
from .rotation2d import Rotation2D
from .similarity import Similarity
from .transform import Transform
from .transform2d import Transform2D

__version__ = "0.1.0"

__all__ = [
    # groups and transforms
    "Rotation",
    "Transform",
    "Rotation2D",
    "Transform2D",
    "Similarity",
    "Affine",
    "Projective",
    "Quaternion",
    # functional layers
    "conversions",
    "euler",
    "quaternion",
    "so2",
    "se2",
    "so3",
    "se3",
    "sim3",
    "symbolic",
    # errors and warnings
    "RigidkitError",
    "NotARotationError",
    "NotASimilarityError",
    "NotAffineError",
    "SingularMatrixError",
    "PointAtInfinityError",
    "NonFiniteError",
    "ZeroNormError",
    "ShapeError",
    "EulerSequenceError",
    "GimbalLockWarning",
]


def __getattr__(name):
    # SymPy is heavy: import the symbolic module only when it is asked for.
    if name == "symbolic":
        import importlib

        return importlib.import_module(".symbolic", __name__)
    raise AttributeError(f"module 'rigidkit' has no attribute {name!r}")
