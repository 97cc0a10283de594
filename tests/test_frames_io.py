"""rk.io.read_tf and rk.io.read_poses on ROS 1 bags, ROS 2 bags (sqlite3 and MCAP) and
MCAP files that the tests write with rosbags' writers."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as R

import rigidkit as rk

rosbags = pytest.importorskip("rosbags")
from rosbags.typesys import Stores, get_typestore  # noqa: E402

# Stamps near today's epoch: their nanoseconds must survive the float64 seconds
# to float64's spacing there (2.4e-7 s).
T0_SEC = 1_764_000_000


class Messages:
    """Builds ROS messages of one type store (ROS 1 headers have a ``seq``)."""

    def __init__(self, store):
        self.ts = get_typestore(store)
        self.ros1 = store == Stores.ROS1_NOETIC
        if "tf2_msgs/msg/TFMessage" not in self.ts.types:  # not in rosbags' Noetic store
            from rosbags.typesys import get_types_from_msg

            self.ts.register(
                get_types_from_msg(
                    "geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"
                )
            )
        self.T = self.ts.types

    def header(self, sec, nanosec, frame):
        stamp = self.T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
        if self.ros1:
            return self.T["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame)
        return self.T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    def pose(self, pq):
        g = self.T
        return g["geometry_msgs/msg/Pose"](
            position=g["geometry_msgs/msg/Point"](x=pq[0], y=pq[1], z=pq[2]),
            orientation=g["geometry_msgs/msg/Quaternion"](
                w=pq[3], x=pq[4], y=pq[5], z=pq[6]
            ),
        )

    def transform_stamped(self, sec, nsec, parent, child, pq):
        g = self.T
        tf = g["geometry_msgs/msg/Transform"](
            translation=g["geometry_msgs/msg/Vector3"](x=pq[0], y=pq[1], z=pq[2]),
            rotation=g["geometry_msgs/msg/Quaternion"](w=pq[3], x=pq[4], y=pq[5], z=pq[6]),
        )
        return g["geometry_msgs/msg/TransformStamped"](
            header=self.header(sec, nsec, parent), child_frame_id=child, transform=tf
        )

    def serialize(self, msg):
        if self.ros1:
            return self.ts.serialize_ros1(msg, msg.__msgtype__)
        return self.ts.serialize_cdr(msg, msg.__msgtype__)


def writer(kind, path):
    """(writer context, Messages) for 'ros1', 'sqlite3' or 'mcap'."""
    if kind == "ros1":
        from rosbags.rosbag1 import Writer

        return Writer(path / "rec.bag"), Messages(Stores.ROS1_NOETIC)
    from rosbags.rosbag2 import StoragePlugin, Writer

    plugin = StoragePlugin.SQLITE3 if kind == "sqlite3" else StoragePlugin.MCAP
    return Writer(path / "rec", version=9, storage_plugin=plugin), Messages(
        Stores.ROS2_HUMBLE
    )


def bag_path(kind, path, as_file):
    if kind == "ros1":
        return path / "rec.bag"
    if as_file:  # the storage file alone: a plain .mcap or .db3
        (found,) = (path / "rec").glob("*.mcap" if kind == "mcap" else "*.db3")
        return found
    return path / "rec"


def random_pq(n, rng):
    q = R.random(n, rng=rng).as_quat(scalar_first=True)
    return np.concatenate([rng.normal(size=(n, 3)), q], axis=1)


RECORDINGS = [("ros1", False), ("sqlite3", False), ("mcap", False), ("mcap", True)]


@pytest.mark.parametrize("kind, as_file", RECORDINGS)
def test_read_tf_round_trip(tmp_path, kind, as_file):
    rng = np.random.default_rng(2)
    n = 30
    nsec = np.sort(rng.integers(0, 3_000_000_000, n))  # out of arrival order below
    odom = random_pq(n, rng)
    base = random_pq(n, rng)
    cam = random_pq(2, rng)
    w, m = writer(kind, tmp_path)
    msgtype = "tf2_msgs/msg/TFMessage"
    with w:
        tf = w.add_connection("/tf", msgtype, typestore=m.ts)
        static = w.add_connection("/tf_static", msgtype, typestore=m.ts)
        other = w.add_connection("/tf_other", msgtype, typestore=m.ts)
        TF = m.T[msgtype]
        for k, j in enumerate(rng.permutation(n)):  # stamps arrive out of order
            sec, ns = T0_SEC + int(nsec[j] // 10**9), int(nsec[j] % 10**9)
            msg = TF(
                transforms=[
                    m.transform_stamped(
                        sec, ns, "/map" if kind == "ros1" else "map", "odom", odom[j]
                    ),
                    m.transform_stamped(sec, ns, "odom", "base", base[j]),
                ]
            )
            w.write(tf, 10**9 * T0_SEC + k, m.serialize(msg))
        for k in range(2):  # a static transform republished: the last one wins
            msg = TF(transforms=[m.transform_stamped(T0_SEC, 0, "base", "camera", cam[k])])
            w.write(static, 10**9 * T0_SEC + n + k, m.serialize(msg))
        msg = TF(transforms=[m.transform_stamped(T0_SEC, 0, "map", "ghost", cam[0])])
        w.write(other, 10**9 * T0_SEC + n + 5, m.serialize(msg))
    g = rk.io.read_tf(bag_path(kind, tmp_path, as_file))
    assert set(g.frames) == {"map", "odom", "base", "camera"}  # /tf_other not read
    info = {e.child: e for e in g.edges}
    assert info["camera"].kind == "static" and info["odom"].count == n
    stamps = T0_SEC + nsec // 10**9 + (nsec % 10**9) * 1e-9
    assert info["odom"].range == (stamps[0], stamps[-1])
    want = rk.Transform.from_pq(odom)
    np.testing.assert_allclose(
        g.get("map", "odom", at=stamps).as_matrix(), want.as_matrix(), atol=1e-15
    )
    np.testing.assert_allclose(
        g.get("base", "camera").as_matrix(),
        rk.Transform.from_pq(cam[1]).as_matrix(),
        atol=1e-15,
    )
    g2 = rk.io.read_tf(bag_path(kind, tmp_path, as_file), topics=("/tf",), max_samples=5)
    assert "camera" not in g2.frames and g2.edges[0].count == 5


@pytest.mark.parametrize("kind", ["ros1", "sqlite3", "mcap"])
def test_read_poses(tmp_path, kind):
    rng = np.random.default_rng(4)
    n = 12
    pq = random_pq(n, rng)
    nsec = np.arange(n) * 50_000_000 + 123
    cov = rng.normal(size=(n, 36))
    w, m = writer(kind, tmp_path)
    g = m.T
    with w:
        conns = {
            name: w.add_connection(f"/{name}", t, typestore=m.ts)
            for name, t in [
                ("pose", "geometry_msgs/msg/PoseStamped"),
                ("pwc", "geometry_msgs/msg/PoseWithCovarianceStamped"),
                ("odom", "nav_msgs/msg/Odometry"),
                ("tfs", "geometry_msgs/msg/TransformStamped"),
                ("path", "nav_msgs/msg/Path"),
                ("tf", "tf2_msgs/msg/TFMessage"),
            ]
        }
        order = np.r_[1, 0, 2:n]  # the first two arrive swapped
        for k in order:
            sec, ns = T0_SEC + int(nsec[k] // 10**9), int(nsec[k] % 10**9)
            h = m.header(sec, ns, "map")
            pose = m.pose(pq[k])
            pwc = g["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=cov[k])
            twist = g["geometry_msgs/msg/TwistWithCovariance"](
                twist=g["geometry_msgs/msg/Twist"](
                    linear=g["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                    angular=g["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                ),
                covariance=np.zeros(36),
            )
            msgs = {
                "pose": g["geometry_msgs/msg/PoseStamped"](header=h, pose=pose),
                "pwc": g["geometry_msgs/msg/PoseWithCovarianceStamped"](header=h, pose=pwc),
                "odom": g["nav_msgs/msg/Odometry"](
                    header=h, child_frame_id="base", pose=pwc, twist=twist
                ),
                "tfs": m.transform_stamped(sec, ns, "map", "base", pq[k]),
            }
            for name, msg in msgs.items():
                w.write(conns[name], int(10**9 * T0_SEC + nsec[k]), m.serialize(msg))
        path = g["nav_msgs/msg/Path"](
            header=m.header(T0_SEC, 0, "map"),
            poses=[
                g["geometry_msgs/msg/PoseStamped"](
                    header=m.header(T0_SEC + int(s // 10**9), int(s % 10**9), "map"),
                    pose=m.pose(p),
                )
                for s, p in zip(nsec, pq)
            ],
        )
        w.write(conns["path"], 10**9 * (T0_SEC + 5), m.serialize(path))
    src = bag_path(kind, tmp_path, False)
    stamps = T0_SEC + nsec * 1e-9
    for name in ("pose", "pwc", "odom", "tfs", "path"):
        traj = rk.io.read_poses(src, f"/{name}")
        np.testing.assert_array_equal(traj.stamps, stamps)
        np.testing.assert_allclose(traj.poses.as_pq(), pq, atol=1e-15)
    for name in ("pwc", "odom"):
        traj, C = rk.io.read_poses(src, f"/{name}", with_covariance=True)
        np.testing.assert_array_equal(C, cov.reshape(n, 6, 6))
    with pytest.raises(rk.TrajectoryFileError, match="no topic '/nope'.*/pose"):
        rk.io.read_poses(src, "/nope")
    with pytest.raises(rk.TrajectoryFileError, match="TFMessage"):
        rk.io.read_poses(src, "/tf")
    with pytest.raises(rk.TrajectoryFileError, match="no covariance"):
        rk.io.read_poses(src, "/pose", with_covariance=True)


def test_missing_rosbags_names_the_extra(monkeypatch, tmp_path):
    import sys

    monkeypatch.setitem(sys.modules, "rosbags.highlevel", None)
    with pytest.raises(ImportError, match=r"rigidkit\[ros\]"):
        rk.io.read_tf(tmp_path / "x.bag")


@pytest.mark.parametrize("kind", ["ros1", "mcap"])
def test_read_tf_broken_tree_and_ros1_tf_message(tmp_path, kind):
    """A frame with two parents is an error naming the recording and both parents;
    ROS 1's older tf/tfMessage is read like tf2's message."""
    rng = np.random.default_rng(9)
    w, m = writer(kind, tmp_path)
    msgtype = "tf2_msgs/msg/TFMessage"
    if kind == "ros1":
        from rosbags.typesys import get_types_from_msg

        m.ts.register(
            get_types_from_msg(
                "geometry_msgs/TransformStamped[] transforms", "tf/msg/tfMessage"
            )
        )
        msgtype = "tf/msg/tfMessage"
    with w:
        tf = w.add_connection("/tf", msgtype, typestore=m.ts)
        TF = m.T[msgtype]
        for k, parent in enumerate(["map", "odom"]):
            msg = TF(
                transforms=[
                    m.transform_stamped(T0_SEC + k, 0, parent, "base", random_pq(1, rng)[0])
                ]
            )
            w.write(tf, 10**9 * (T0_SEC + k), m.serialize(msg))
    src = bag_path(kind, tmp_path, kind == "mcap")
    with pytest.raises(rk.ConnectivityError, match=r"rec.*'base'.*'map'.*'odom'"):
        rk.io.read_tf(src)
