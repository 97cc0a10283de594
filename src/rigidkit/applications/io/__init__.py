"""File formats: the one home of rigidkit's readers and writers.

:func:`read_trajectory` and :func:`write_trajectory` handle pose trajectories in
the TUM RGB-D, KITTI odometry, EuRoC (ASL) and headed-CSV formats.
:func:`read_tf` and :func:`read_poses` read ROS recordings (bags and MCAP files,
the optional extra ``ros``).
"""

from .ros import read_poses, read_tf
from .trajectory_files import FORMATS, read_trajectory, write_trajectory

__all__ = ["FORMATS", "read_trajectory", "write_trajectory", "read_tf", "read_poses"]
