"""scipy's ``spatial.transform`` API on rigidkit: ``from rigidkit.scipy import Rotation``.

``Rotation``, ``RigidTransform``, ``Slerp`` and ``RotationSpline`` with the
signatures, defaults and semantics of ``scipy.spatial.transform`` (quaternions
``(x, y, z, w)``, exponential coordinates and twists ``(omega, v)``, ``*``
composes), computed by rigidkit's own objects (``.as_rigidkit()``). See
``docs/scipy.md`` for how to switch and where rigidkit deliberately differs.
"""

from .rigid_transform import RigidTransform
from .rotation import Rotation
from .slerp import Slerp
from .spline import RotationSpline

__all__ = ["Rotation", "RigidTransform", "Slerp", "RotationSpline"]
