"""rigidkit: rigid-body kinematics in every representation, on every array backend.

Conventions (see README and docs/conventions.md): Hamilton quaternions, scalar
first ``(w, x, y, z)``; active rotations on column vectors, ``v_A = A_R_B @ v_B``;
Euler UPPER = intrinsic, lower = extrinsic; twists ``(v, omega)``; radians unless
``degrees=True``.
"""

from ._validate import set_validation
from .errors import (  # noqa: F401  (exported below as listed in errors.__all__)
    ConnectivityError,
    ConvergenceWarning,
    DegenerateInputError,
    EdgeKindError,
    EulerSequenceError,
    ExtrapolationError,
    FrameKeywordError,
    GimbalLockError,
    GimbalLockWarning,
    LookupError,
    NonFiniteError,
    NotAffineError,
    NotARigidTransformError,
    NotARotationError,
    NotASimilarityError,
    OutOfRangeError,
    PointAtInfinityError,
    RigidkitError,
    ShapeError,
    SingularMatrixError,
    TimestampError,
    TrajectoryFileError,
    ZeroNormError,
)
from .errors import __all__ as _error_names
from .functional import conversions, se3, so3
from .objects.rotation import Rotation
from .objects.transform import Transform

# The rest loads on first use, which keeps ``import rigidkit`` fast (the issue's
# budget is 150 ms with NumPy; SymPy alone would take seconds). A module has one
# import path, that of its layer folder (``rigidkit.functional.so3``); ``rk.so3``
# is the attribute holding it, not a second path: ``import rigidkit.so3`` fails.
_LAZY = {
    "Rotation2D": ("objects.rotation2d", "Rotation2D"),
    "Transform2D": ("objects.transform2d", "Transform2D"),
    "Similarity": ("objects.similarity", "Similarity"),
    "ExtendedPose": ("objects.extended_pose", "ExtendedPose"),
    "Affine": ("objects.affine", "Affine"),
    "Projective": ("objects.projective", "Projective"),
    "Quaternion": ("objects.quaternion", "Quaternion"),
    "euler": ("functional.euler", None),
    "quaternion": ("functional.quaternion", None),
    "so2": ("functional.so2", None),
    "se2": ("functional.se2", None),
    "sim3": ("functional.sim3", None),
    "se23": ("functional.se23", None),
    "symbolic": ("applications.symbolic", None),
    "slerp": ("applications.interpolation", "slerp"),
    "Slerp": ("applications.interpolation", "Slerp"),
    "RotationSpline": ("applications.splines", "RotationSpline"),
    "BSplineSO3": ("applications.splines", "BSplineSO3"),
    "BSplineSE3": ("applications.splines", "BSplineSE3"),
    "align_vectors": ("applications.alignment", "align_vectors"),
    "align_points": ("applications.alignment", "align_points"),
    "kinematics": ("applications.kinematics", None),
    "inertial": ("applications.inertial", None),
    "jacobians": ("applications.jacobians", None),
    "cli": ("applications.cli", None),
    "geodesic_distance": ("objects.rotation", "geodesic_distance"),
    "chordal_distance": ("objects.rotation", "chordal_distance"),
    "quat_continuous": ("functional.sequences", "quat_continuous"),
    "unwrap_euler": ("functional.sequences", "unwrap_euler"),
    "Trajectory": ("applications.trajectory", "Trajectory"),
    "trajectory": ("applications.trajectory", None),
    "io": ("applications.io", None),
    "FrameGraph": ("applications.frames", "FrameGraph"),
    "UncertainTransform": ("applications.frames", "UncertainTransform"),
}

__version__ = "0.1.0"

__all__ = [
    # groups and transforms
    "Rotation",
    "Transform",
    "Rotation2D",
    "Transform2D",
    "Similarity",
    "ExtendedPose",
    "Affine",
    "Projective",
    "Quaternion",
    # interpolation, splines, alignment
    "slerp",
    "Slerp",
    "RotationSpline",
    "BSplineSO3",
    "BSplineSE3",
    "align_vectors",
    "align_points",
    # distances and sequences of rotations
    "geodesic_distance",
    "chordal_distance",
    "quat_continuous",
    "unwrap_euler",
    # trajectories and their files
    "Trajectory",
    "trajectory",
    "io",
    # frame graphs and uncertain poses
    "FrameGraph",
    "UncertainTransform",
    # functional layers
    "conversions",
    "euler",
    "quaternion",
    "so2",
    "se2",
    "so3",
    "se3",
    "sim3",
    "se23",
    "symbolic",
    "kinematics",
    "inertial",
    "jacobians",
    # the validation switch (docs/architecture.md, "Validation policy")
    "set_validation",
    # errors and warnings; rk.LookupError (also a builtin LookupError) is left out,
    # so that a star import does not shadow Python's own name
    *(name for name in _error_names if name != "LookupError"),
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
