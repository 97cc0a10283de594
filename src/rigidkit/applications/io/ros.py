"""ROS recordings without ROS: transforms and poses from bags and MCAP files.

Reads ROS 1 bags (``.bag``), ROS 2 bags (a directory with ``metadata.yaml``, its
storage sqlite3 or MCAP) and single ``.db3`` or ``.mcap`` files through the
pure-Python `rosbags <https://gitlab.com/ternaris/rosbags>`_ library, the
optional extra ``ros`` (``pip install 'rigidkit[ros]'``), imported on first use.

Stamps are header stamps in seconds, ``sec + nanosec * 1e-9`` as a float64 (the
nanoseconds of a stamp near the year 2026 are kept to ~0.2 us, float64's spacing
at 1.7e9 s). Frame names lose a leading ``/`` (ROS 1's ``/base_link`` is
``base_link``), as tf2 does.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import TrajectoryFileError
from ...objects.transform import Transform

__all__ = ["read_tf", "read_poses"]

#: tf2's message, and tf's of ROS 1 bags before tf2 (the same fields)
_TF = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")
_POSE_TYPES = {
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
    "geometry_msgs/msg/TransformStamped",
    "nav_msgs/msg/Odometry",
    "nav_msgs/msg/Path",
}


def _reader(path):
    """An open-able ``AnyReader`` on ``path`` (a file, a bag directory, or a list of
    ROS 1 bags), with a clear error when the ``ros`` extra is missing."""
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError as err:
        raise ImportError(
            "reading ROS recordings needs the optional dependency 'rosbags': "
            "pip install 'rigidkit[ros]'"
        ) from err
    paths = [Path(p) for p in path] if isinstance(path, (list, tuple)) else [Path(path)]
    # Bags that embed no message definitions fall back to ROS 2 Humble's types.
    return AnyReader(paths, default_typestore=get_typestore(Stores.ROS2_HUMBLE))


def _frame(name):
    return name[1:] if name.startswith("/") else name


def _stamp(header):
    return header.stamp.sec + header.stamp.nanosec * 1e-9


def _pq(position, rotation):
    """``(tx, ty, tz, w, x, y, z)`` of a ROS translation/position and quaternion."""
    return (
        position.x,
        position.y,
        position.z,
        rotation.w,
        rotation.x,
        rotation.y,
        rotation.z,
    )


def read_tf(path, topics=("/tf", "/tf_static"), *, max_duration=None, max_samples=None):
    """The transforms of a ROS recording as a :class:`~rigidkit.FrameGraph`.

    Every ``tf2_msgs/TFMessage`` (or ROS 1 ``tf/tfMessage``) on ``topics`` is
    read: a transform on a topic whose name ends in ``_static`` (``/tf_static``)
    becomes a static edge (the last one published wins), any other a sample of a
    dynamic edge at its header stamp. Every sample is kept unless
    ``max_duration`` or ``max_samples`` is given (:class:`~rigidkit.FrameGraph`'s
    bounds).

    Parameters
    ----------
    path : str, Path, or list of them
        A ROS 1 ``.bag`` (or a list of them), a ROS 2 bag directory, or a
        ``.db3`` or ``.mcap`` file.
    topics : sequence of str
        The topics to read (``tf2_msgs/TFMessage`` only; others are ignored).
    max_duration, max_samples : optional
        Buffer bounds of the returned graph (None: keep everything).

    Returns
    -------
    FrameGraph
        Edges ``header.frame_id -> child_frame_id`` holding
        ``frame_id_T_child_frame_id``.

    Raises
    ------
    ImportError
        ``rosbags`` is not installed (the ``ros`` extra).
    ConnectivityError
        The recording gives a frame two parents (the message names the file and
        both parents).
    ValueError
        An edge both static (``/tf_static``) and dynamic.
    """
    from ..frames import FrameGraph  # a sibling application, loaded on use

    static = {}
    dynamic = {}
    with _reader(path) as reader:
        conns = [c for c in reader.connections if c.topic in topics and c.msgtype in _TF]
        for conn, _, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            is_static = conn.topic.endswith("_static")
            for tf in msg.transforms:
                edge = (_frame(tf.header.frame_id), _frame(tf.child_frame_id))
                pq = _pq(tf.transform.translation, tf.transform.rotation)
                if is_static:
                    static[edge] = pq
                else:
                    dynamic.setdefault(edge, ([], []))
                    dynamic[edge][0].append(_stamp(tf.header))
                    dynamic[edge][1].append(pq)
    graph = FrameGraph(max_duration=max_duration, max_samples=max_samples)
    try:
        for (parent, child), pq in static.items():
            graph.add(parent, child, np.array(pq))
        for (parent, child), (stamps, rows) in dynamic.items():
            graph.add(parent, child, np.array(rows), stamps=np.array(stamps))
    except ValueError as err:  # a tree the recording breaks: say which recording
        raise type(err)(f"{path}: {err}") from err
    return graph


def read_poses(path, topic, *, with_covariance=False):
    """The poses on one topic of a ROS recording as a :class:`~rigidkit.Trajectory`.

    ``geometry_msgs/PoseStamped``, ``PoseWithCovarianceStamped``,
    ``TransformStamped`` and ``nav_msgs/Odometry`` give one pose per message at
    its header stamp; ``nav_msgs/Path`` gives the poses of the last message on the
    topic (a path is republished whole), each at its own stamp. Poses are sorted
    by stamp; of several at one stamp the last received is kept.

    Parameters
    ----------
    path : str, Path, or list of them
        As for :func:`read_tf`.
    topic : str
    with_covariance : bool
        Also return the covariances of ``PoseWithCovarianceStamped`` and
        ``Odometry`` messages, shape (N, 6, 6), as the messages hold them: rows
        ``(x, y, z, rotation about X, Y, Z)``, i.e. ``(v, omega)`` order, not
        converted to a side (ROS leaves the convention to the publisher).

    Returns
    -------
    Trajectory, or (Trajectory, ndarray (N, 6, 6))
        Poses ``frame_id_T_child`` (``header.frame_id`` is the world frame).

    Raises
    ------
    ImportError
        ``rosbags`` is not installed (the ``ros`` extra).
    TrajectoryFileError
        No such topic, a message type not listed above, no covariance in the
        messages, or no messages.
    """
    from ..trajectory import Trajectory  # a sibling application, loaded on use

    stamps, rows, covs = [], [], []
    with _reader(path) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        if not conns:
            known = sorted({c.topic for c in reader.connections})
            raise TrajectoryFileError(
                f"{path}: no topic {topic!r}; topics: {', '.join(known)}", path=str(path)
            )
        kind = conns[0].msgtype
        if kind not in _POSE_TYPES:
            raise TrajectoryFileError(
                f"{path}: topic {topic!r} holds {kind}, not one of "
                f"{', '.join(sorted(_POSE_TYPES))}",
                path=str(path),
            )
        if with_covariance and kind not in (
            "geometry_msgs/msg/PoseWithCovarianceStamped",
            "nav_msgs/msg/Odometry",
        ):
            raise TrajectoryFileError(f"{path}: {kind} messages carry no covariance")
        for conn, _, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            if kind == "nav_msgs/msg/Path":
                stamps = [_stamp(p.header) for p in msg.poses]
                rows = [_pq(p.pose.position, p.pose.orientation) for p in msg.poses]
                continue
            stamps.append(_stamp(msg.header))
            if kind == "geometry_msgs/msg/TransformStamped":
                rows.append(_pq(msg.transform.translation, msg.transform.rotation))
                continue
            pose = msg.pose if kind == "geometry_msgs/msg/PoseStamped" else msg.pose.pose
            rows.append(_pq(pose.position, pose.orientation))
            if with_covariance:
                covs.append(np.asarray(msg.pose.covariance, dtype=np.float64).reshape(6, 6))
    if not rows:
        raise TrajectoryFileError(f"{path}: no poses on topic {topic!r}", path=str(path))
    t = np.array(stamps)
    # sorted by stamp; the last received of equal stamps wins (stable sort, then
    # keep the last of each run)
    order = np.argsort(t, kind="stable")
    keep = np.ones(len(order), dtype=bool)
    keep[:-1] = t[order][1:] != t[order][:-1]
    order = order[keep]
    traj = Trajectory(t[order], Transform.from_pq(np.array(rows)[order]))
    if with_covariance:
        return traj, np.stack(covs)[order]
    return traj
