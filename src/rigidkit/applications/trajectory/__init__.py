"""Trajectories: association, alignment and the standard error metrics.

``rk.Trajectory`` holds time-stamped poses; :func:`associate` pairs two
trajectories by time, :func:`align` moves an estimate onto a reference, and
:func:`ape`, :func:`rpe` and :func:`kitti_errors` compute the errors that SLAM
and odometry papers report, with evo's definitions (Sturm et al. 2012; Geiger
et al. 2012). Files are read and written by :mod:`rigidkit.io`.
"""

from .align import align
from .associate import associate
from .kitti import KittiResult, kitti_errors
from .metrics import MetricResult, ape, rpe, statistics
from .pairs import pair_indices
from .plot import plot, plot_error_colored, plot_errors, save_report
from .trajectory import Trajectory

__all__ = [
    "KittiResult",
    "MetricResult",
    "Trajectory",
    "align",
    "ape",
    "associate",
    "kitti_errors",
    "pair_indices",
    "plot",
    "plot_error_colored",
    "plot_errors",
    "rpe",
    "save_report",
    "statistics",
]
