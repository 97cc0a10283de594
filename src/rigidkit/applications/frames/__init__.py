"""Frames: a time-aware tree of coordinate frames and uncertain poses.

:class:`FrameGraph` holds named frames linked by static or time-stamped transforms
(tf2's buffer, without ROS), looked up along the path through the common ancestor
over whole arrays of stamps. :class:`UncertainTransform` is a pose with the
covariance of a perturbation on the group, propagated through compositions.
"""

from .graph import FrameGraph
from .tree import EdgeInfo
from .uncertain import UncertainTransform

__all__ = ["FrameGraph", "EdgeInfo", "UncertainTransform"]
