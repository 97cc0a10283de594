"""rigidkit: rigid-body kinematics in every representation, on every array backend.

Conventions (see README and docs/conventions.md): Hamilton quaternions, scalar
first ``(w, x, y, z)``; active rotations on column vectors, ``v_A = A_R_B @ v_B``;
Euler UPPER = intrinsic, lower = extrinsic; twists ``(v, omega)``; radians unless
``degrees=True``.
"""

from . import conversions, se3, so3
from .errors import (
    EulerSequenceError,
    GimbalLockWarning,
    NonFiniteError,
    NotAffineError,
    NotARigidTransformError,
    NotARotationError,
    NotASimilarityError,
    PointAtInfinityError,
    RigidkitError,
    ShapeError,
    SingularMatrixError,
    ZeroNormError,
)
from .rotation import Rotation
from .transform import Transform

# The rest loads on first use, which keeps ``import rigidkit`` fast (the issue's
# budget is 150 ms with NumPy; SymPy alone would take seconds).
_LAZY = {
    "Rotation2D": ("rotation2d", "Rotation2D"),
    "Transform2D": ("transform2d", "Transform2D"),
    "Similarity": ("similarity", "Similarity"),
    "Affine": ("affine", "Affine"),
    "Projective": ("projective", "Projective"),
    "Quaternion": ("quaternion", "Quaternion"),
    "euler": ("euler", None),
    "quaternion": ("quaternion", None),
    "so2": ("so2", None),
    "se2": ("se2", None),
    "sim3": ("sim3", None),
    "symbolic": ("symbolic", None),
}

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
    "NotARigidTransformError",
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
    if name not in _LAZY:
        raise AttributeError(f"module 'rigidkit' has no attribute {name!r}")
    import importlib

    module_name, attr = _LAZY[name]
    module = importlib.import_module(f".{module_name}", __name__)
    value = module if attr is None else getattr(module, attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
