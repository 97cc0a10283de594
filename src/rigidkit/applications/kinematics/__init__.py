"""Kinematics of moving frames: angular velocity, Euler rates, quaternion rates,
integration, twists, accelerations (``rk.kinematics``).

Every velocity names its frame: ``frame="world"`` (components in the fixed axes:
``R' = hat(omega) R``, ``T' = hat(V) T``) or ``frame="body"`` (in the moving axes:
``R' = R hat(omega)``, ``T' = T hat(V)``); the keyword is required, and
``omega_world = R omega_body``, ``V_world = Ad_T V_body``. Rotations are active,
``v_W = W_R_B @ v_B``; quaternions Hamilton ``(w, x, y, z)``; twists ``(v, omega)``;
radians unless ``degrees=True``. Functions take :class:`~rigidkit.Rotation` /
:class:`~rigidkit.Transform` objects or arrays (rotation matrices (..., 3, 3),
quaternions (..., 4) where the name says quaternion, homogeneous (..., 4, 4)),
batched over leading axes, on NumPy, torch and JAX alike.

========================  ===========================================================
rotation derivatives      ``angular_velocity``, ``rotation_derivative``,
                          ``angular_acceleration``, ``rotation_second_derivative``
Euler angles (24 seqs)    ``euler_rate_matrix`` (``omega = E rates``), ``euler_rates``,
                          ``angular_velocity_from_euler_rates``, ...
quaternions               ``quaternion_derivative``, ``quaternion_second_derivative``,
                          ``angular_velocity_from_quaternion_derivative``
integration               ``integrate_angular_velocity``, ``integrate_twist``
twists and points         ``twist_from_derivative``, ``transform_derivative``,
                          ``twist_to_world``, ``point_velocity``, ``point_acceleration``,
                          ``screw_from_twist``, ...
from data                 ``angular_velocity_from_samples``, ``twist_from_samples``
the plane                 :mod:`.planar` (SO(2), SE(2))
========================  ===========================================================

>>> import numpy as np
>>> import rigidkit as rk
>>> angles, rates = [0.3, 0.2, 0.1], [0.0, 0.0, 1.0]          # ZYX: roll rate only
>>> K = rk.kinematics
>>> w_B = K.angular_velocity_from_euler_rates("ZYX", angles, rates, frame="body")
>>> w_W = K.angular_velocity_from_euler_rates("ZYX", angles, rates, frame="world")
>>> w_B                                                         # about the body x-axis
array([1., 0., 0.])
>>> R = rk.Rotation.from_euler("ZYX", angles)
>>> bool(np.allclose(R @ w_B, w_W))
True
"""

from . import planar

# Each module lists its public names once, in its ``__all__``; the package exports
# them all (a star import takes exactly a module's ``__all__``).
from .euler_rates import *  # noqa: F403
from .euler_rates import __all__ as _euler_rates_names
from .integration import *  # noqa: F403
from .integration import __all__ as _integration_names
from .rotation import *  # noqa: F403
from .rotation import __all__ as _rotation_names
from .samples import *  # noqa: F403
from .samples import __all__ as _samples_names
from .twist import *  # noqa: F403
from .twist import __all__ as _twist_names

__all__ = [
    *_rotation_names,
    *_euler_rates_names,
    *_integration_names,
    *_twist_names,
    *_samples_names,
    "planar",
]
