"""rigidkit: rigid-body kinematics in every representation, on every array backend.

Conventions (see README and docs/conventions.md): Hamilton quaternions, scalar
first ``(w, x, y, z)``; active rotations on column vectors, ``v_A = A_R_B @ v_B``;
Euler UPPER = intrinsic, lower = extrinsic; twists ``(v, omega)``; radians unless
``degrees=True``.
"""

from ._validate import set_validation
from .errors import (  # noqa: F401  (exported below as listed in errors.__all__)
    ConvergenceWarning,
    DegenerateInputError,
    EulerSequenceError,
    FrameError,
    GimbalLockError,
    GimbalLockWarning,
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
# budget is 150 ms with NumPy; SymPy alone would take seconds).
_LAZY = {
    "Rotation2D": ("objects.rotation2d", "Rotation2D"),
    "Transform2D": ("objects.transform2d", "Transform2D"),
    "Similarity": ("objects.similarity", "Similarity"),
    "Affine": ("objects.affine", "Affine"),
    "Projective": ("objects.projective", "Projective"),
    "Quaternion": ("objects.quaternion", "Quaternion"),
    "euler": ("functional.euler", None),
    "quaternion": ("functional.quaternion", None),
    "so2": ("functional.so2", None),
    "se2": ("functional.se2", None),
    "sim3": ("functional.sim3", None),
    "symbolic": ("applications.symbolic", None),
    "slerp": ("applications.interpolation", "slerp"),
    "Slerp": ("applications.interpolation", "Slerp"),
    "RotationSpline": ("applications.splines", "RotationSpline"),
    "BSplineSO3": ("applications.splines", "BSplineSO3"),
    "BSplineSE3": ("applications.splines", "BSplineSE3"),
    "align_vectors": ("applications.alignment", "align_vectors"),
    "align_points": ("applications.alignment", "align_points"),
    "kinematics": ("applications.kinematics", None),
    "jacobians": ("applications.jacobians", None),
    "geodesic_distance": ("objects.rotation", "geodesic_distance"),
    "chordal_distance": ("objects.rotation", "chordal_distance"),
    "quat_continuous": ("functional.sequences", "quat_continuous"),
    "unwrap_euler": ("functional.sequences", "unwrap_euler"),
    "Trajectory": ("applications.trajectory", "Trajectory"),
    "trajectory": ("applications.trajectory", None),
    "io": ("applications.io", None),
}

# The public module paths predate the layered tree (docs/architecture.md):
# ``import rigidkit.so3`` keeps working and is the same module object as
# ``rigidkit.functional.so3``.
_MODULE_ALIASES = {
    **{
        name: f"functional.{name}"
        for name in (
            "conversions",
            "euler",
            "quaternion",
            "so3",
            "se3",
            "so2",
            "se2",
            "sim3",
        )
    },
    "symbolic": "applications.symbolic",
    "kinematics": "applications.kinematics",
    "jacobians": "applications.jacobians",
    "cli": "applications.cli",
}


class _AliasFinder:
    """Resolve ``rigidkit.<public name>`` to the module in its layer folder."""

    @staticmethod
    def find_spec(fullname, path=None, target=None):
        prefix, _, leaf = fullname.rpartition(".")
        if prefix != __name__ or leaf not in _MODULE_ALIASES:
            return None
        import importlib.util

        return importlib.util.spec_from_loader(fullname, _AliasFinder)

    @staticmethod
    def create_module(spec):
        import importlib

        leaf = spec.name.rpartition(".")[2]
        module = importlib.import_module(f"{__name__}.{_MODULE_ALIASES[leaf]}")
        _REAL_SPECS[module.__name__] = module.__spec__
        return module

    @staticmethod
    def exec_module(module):
        # The import system stamped the alias spec on the real module: undo that.
        module.__spec__ = _REAL_SPECS[module.__name__]


_REAL_SPECS = {}


import sys as _sys  # noqa: E402

_sys.meta_path.append(_AliasFinder)

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
    "kinematics",
    "jacobians",
    # the validation switch (docs/architecture.md, "Validation policy")
    "set_validation",
    # errors and warnings
    *_error_names,
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
