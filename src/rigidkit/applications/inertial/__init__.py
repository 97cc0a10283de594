"""Inertial navigation (``rk.inertial``): strapdown integration, IMU preintegration on
SE_2(3), and IMU simulation along trajectories.

Conventions, the same in every function: the navigation frame is ``frame="world"``
(gravity ``g``, a vector of any direction, and the velocity and position of the
states are in it; the orientation is ``R = world_R_body``); gyroscopes measure the
body's angular velocity (rad/s) and accelerometers its specific force
``f = R^T (a - g)`` (m/s^2), both in the body frame; sample ``k`` is held over step
``k``. States are :class:`~rigidkit.ExtendedPose` ``(R, v, p)``.

========================  ===========================================================
strapdown integration     ``integrate`` (``"exact"``, ``"midpoint"``, ``"rk4"``)
preintegration            ``preintegrate``, ``Preintegrated`` (``predict``,
                          ``corrected``, ``residual``), ``ImuNoise``, ``split_windows``,
                          GTSAM's layout: ``to_gtsam``, ``from_gtsam``
simulation                ``imu_from_trajectory``, ``simulate_imu`` (``ImuLog``),
                          ``states_from_trajectory``
========================  ===========================================================
"""

from .preintegration import *  # noqa: F403
from .preintegration import __all__ as _preintegration_names
from .simulation import *  # noqa: F403
from .simulation import __all__ as _simulation_names
from .strapdown import *  # noqa: F403
from .strapdown import __all__ as _strapdown_names
from .windows import *  # noqa: F403
from .windows import __all__ as _windows_names

__all__ = [*_strapdown_names, *_preintegration_names, *_windows_names, *_simulation_names]
