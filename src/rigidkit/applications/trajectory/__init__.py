"""Trajectories: association, alignment and the standard error metrics.

``rk.Trajectory`` holds time-stamped poses; :func:`associate` pairs two
trajectories by time, :func:`align` moves an estimate onto a reference, and
:func:`ape`, :func:`rpe` and :func:`kitti_errors` compute the errors that SLAM
and odometry papers report, with evo's definitions (Sturm et al. 2012; Geiger
et al. 2012). Files are read and written by :mod:`rigidkit.io`.
"""

from .align import align
from .associate import associate
from .metrics import MetricResult, ape, rpe, statistics
from .trajectory import Trajectory

__all__ = ["MetricResult", "Trajectory", "align", "ape", "associate", "rpe", "statistics"]
