"""scipy's ``spatial.transform`` classes computed by rigidkit: a one-line switch.

>>> from rigidkit.scipy import Rotation, RigidTransform, Slerp, RotationSpline
>>> Rotation.from_quat([0.0, 0.0, 0.0, 1.0]).as_matrix()[0]
array([1., 0., 0.])

The classes live in :mod:`rigidkit.applications.scipy_api`; see ``docs/scipy.md``.
"""

from .applications.scipy_api import RigidTransform, Rotation, RotationSpline, Slerp

__all__ = ["Rotation", "RigidTransform", "Slerp", "RotationSpline"]
