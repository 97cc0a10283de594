"""rk.FrameGraph: structure, lookups against explicit compositions with scipy, errors,
time travel, velocities and thread safety."""

import pickle
import threading

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as R
from scipy.spatial.transform import Slerp as ScipySlerp

import rigidkit as rk
from rigidkit._engine import drain


def matrices(pq):
    """4x4 matrices of rows (tx, ty, tz, qx, qy, qz, qw)? No: of (p, q scalar first)."""
    pq = np.asarray(pq).reshape(-1, 7)
    M = np.tile(np.eye(4), (len(pq), 1, 1))
    M[:, :3, :3] = R.from_quat(pq[:, 3:], scalar_first=True).as_matrix()
    M[:, :3, 3] = pq[:, :3]
    return M


def random_pq(n, rng, scale=1.0):
    q = R.random(n, rng=rng).as_quat(scalar_first=True)
    return np.concatenate([rng.normal(scale=scale, size=(n, 3)), q], axis=1)


def decoupled_reference(stamps, pq, times):
    """tf2's rule with scipy: linear translation, scipy's Slerp for the rotation."""
    M = np.tile(np.eye(4), (len(times), 1, 1))
    rot = ScipySlerp(stamps, R.from_quat(pq[:, 3:], scalar_first=True))(times)
    M[:, :3, :3] = rot.as_matrix()
    for k in range(3):
        M[:, k, 3] = np.interp(times, stamps, pq[:, k])
    return M


def screw_reference(stamps, pq, times):
    """The SE(3) geodesic between neighbours with scipy's RigidTransform exp and log."""
    from scipy.spatial.transform import RigidTransform

    T = RigidTransform.from_matrix(matrices(pq))
    i = np.clip(np.searchsorted(stamps, times, side="right") - 1, 0, len(stamps) - 2)
    a = (times - stamps[i]) / (stamps[i + 1] - stamps[i])
    step = (T[i].inv() * T[i + 1]).as_exp_coords()
    return (T[i] * RigidTransform.from_exp_coords(a[:, None] * step)).as_matrix()


@pytest.fixture
def robot():
    """map -> odom (dynamic) -> base (dynamic) -> arm -> camera (static), map -> tag."""
    rng = np.random.default_rng(7)
    t = np.sort(rng.uniform(0.0, 5.0, 40))
    data = {
        ("map", "odom"): (t, random_pq(40, rng)),
        ("odom", "base"): (t[::2] + 0.01, random_pq(20, rng)),
        ("base", "arm"): (None, random_pq(1, rng)),
        ("arm", "camera"): (None, random_pq(1, rng)),
        ("map", "tag"): (None, random_pq(1, rng)),
    }
    g = rk.FrameGraph(max_duration=None)
    for (p, c), (s, pq) in data.items():
        g.add(p, c, rk.Transform.from_pq(pq if s is not None else pq[0]), stamps=s)
    return g, data


def explicit(data, times, rule=decoupled_reference):
    """tag_T_camera = (map_T_tag)^-1 map_T_odom odom_T_base base_T_arm arm_T_camera."""
    M = {}
    for (p, c), (s, pq) in data.items():
        M[p, c] = matrices(pq)[0] if s is None else rule(s, pq, times)
    return np.linalg.inv(M["map", "tag"]) @ (
        M["map", "odom"] @ M["odom", "base"] @ M["base", "arm"] @ M["arm", "camera"]
    )


# -- structure --------------------------------------------------------------------------
def test_structure(robot):
    g, _ = robot
    assert set(g.frames) == {"map", "odom", "base", "arm", "camera", "tag"}
    assert g.parent("camera") == "arm" and g.parent("map") is None
    assert g.children("map") == ["odom", "tag"]
    assert g.path("camera", "tag") == ["camera", "arm", "base", "odom", "map", "tag"]
    # through the common ancestor only: base is the top of camera -> odom
    assert g.path("camera", "odom") == ["camera", "arm", "base", "odom"]
    assert g.path("odom", "camera") == ["odom", "base", "arm", "camera"]
    info = {e.child: e for e in g.edges}
    assert info["odom"].kind == "dynamic" and info["odom"].count == 40
    assert info["camera"].kind == "static" and info["camera"].range is None
    g.remove("tag")
    assert "tag" not in g.frames
    with pytest.raises(rk.LookupError, match="'tag'"):
        g.get("map", "tag")


def test_second_parent_and_cycle_rejected(robot):
    g, _ = robot
    with pytest.raises(rk.ConnectivityError, match="'arm'.*'base'.*'map'"):
        g.add("map", "arm", rk.Transform())
    with pytest.raises(
        rk.ConnectivityError, match="cycle map -> odom -> base -> arm -> camera -> map"
    ):
        g.add("camera", "map", rk.Transform())
    with pytest.raises(rk.ConnectivityError, match="itself"):
        g.add("a", "a", rk.Transform())
    with pytest.raises(ValueError, match="update_static"):
        g.add("base", "arm", rk.Transform())
    before = g.get("odom", "camera", at=2.0)  # caches the path's composed static run
    new = rk.Transform(translation=[0.0, 0.0, 9.0])
    g.update_static("base", "arm", new)
    assert np.array_equal(g.get("base", "arm").translation, [0.0, 0.0, 9.0])
    after = g.get("odom", "camera", at=2.0)
    want = g.get("odom", "base", at=2.0) @ new @ g.get("arm", "camera")
    np.testing.assert_allclose(after.as_matrix(), want.as_matrix(), atol=1e-14)
    assert not np.allclose(after.as_matrix(), before.as_matrix())


# -- lookups ----------------------------------------------------------------------------
@pytest.mark.parametrize("interpolation", ["decoupled", "screw"])
def test_get_matches_explicit_composition(robot, interpolation):
    g, data = robot
    times = np.random.default_rng(1).uniform(0.5, 4.5, 200)
    rule = decoupled_reference if interpolation == "decoupled" else screw_reference
    want = explicit(data, times, rule)
    got = g.get("tag", "camera", at=times, interpolation=interpolation)
    assert got.shape == (200,)
    np.testing.assert_allclose(got.as_matrix(), want, atol=1e-10)
    # the reverse lookup is the inverse, and a single time equals the batch's row
    back = g.get("camera", "tag", at=times, interpolation=interpolation)
    np.testing.assert_allclose(back.as_matrix(), np.linalg.inv(want), atol=1e-10)
    one = g.get("tag", "camera", at=float(times[3]), interpolation=interpolation)
    assert one.shape == ()
    np.testing.assert_allclose(one.as_matrix(), want[3], atol=1e-10)
    grid = g.get("tag", "camera", at=times.reshape(20, 10), interpolation=interpolation)
    assert grid.shape == (20, 10)
    # few times on many samples take a slerp per time, many take each segment's log
    # once: the same geodesics
    # single lookups in and out of each edge's last segment, in time order and not
    for k in list(np.argsort(times)[::3]) + list(range(0, 200, 7)):
        one = g.get("tag", "camera", at=float(times[k]), interpolation=interpolation)
        np.testing.assert_allclose(one.as_matrix(), want[k], atol=1e-10)
    few = g.get("tag", "camera", at=times[:5], interpolation=interpolation)
    np.testing.assert_allclose(few.as_matrix(), want[:5], atol=1e-10)
    np.testing.assert_allclose(few.as_matrix(), got[:5].as_matrix(), atol=1e-14)


@pytest.mark.parametrize("decoupled", [True, False])
def test_interpolation_is_rk_slerp(decoupled):
    """Between two samples an edge is rk.slerp of them (decoupled=True: tf2's rule)."""
    rng = np.random.default_rng(8)
    T = rk.Transform.from_pq(random_pq(2, rng))
    g = rk.FrameGraph()
    g.add("a", "b", T, stamps=[1.0, 3.0])
    a = np.array([0.0, 0.1, 0.5, 0.77, 1.0])
    want = rk.slerp(T[0], T[1], a, decoupled=decoupled).as_matrix()
    how = "decoupled" if decoupled else "screw"
    got = g.get("a", "b", at=1.0 + 2.0 * a, interpolation=how).as_matrix()
    np.testing.assert_allclose(got, want, atol=1e-14)
    for k in range(len(a)):
        one = g.get("a", "b", at=float(1.0 + 2.0 * a[k]), interpolation=how).as_matrix()
        np.testing.assert_allclose(one, want[k], atol=1e-14)


def test_decoupled_segment_kernel_is_slerp():
    """The kernel of the batched decoupled lookup, ``(q0 (cos(a phi), sin(a phi)
    u), p0 + a d)`` at ``a = (t - t0) / dt`` from a segment's row (its relative
    rotation's half angle and axis, taken once per segment by ``_segments``),
    against ``quat_slerp`` and
    ``pose_slerp_decoupled`` of the two ends, including opposite quaternions,
    coincident ends and ends 1e-9 rad apart, in float64 and float32."""
    from rigidkit.applications.frames.buffer import _segments
    from rigidkit.kernels.geodesic import pose_slerp_decoupled, pose_slerp_segment

    rng = np.random.default_rng(21)
    n = 3000
    q0 = np.asarray(rk.Rotation.random(n, rng=rng).as_quat())
    q1 = np.array(rk.Rotation.random(n, rng=rng).as_quat())
    q1[:10] = -q0[:10]  # the same rotation, opposite signs
    q1[10:20] = q0[10:20]
    tiny = rk.Rotation.from_rotvec(rng.normal(size=(10, 3)) * 1e-9)
    q1[20:30] = np.asarray((rk.Rotation.from_quat(q0[20:30]) @ tiny).as_quat())
    p0, p1 = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    t = rng.uniform(0.0, 1.0, n)
    # pairs of samples (q0[k], q1[k]) as rows 2k, 2k + 1: the even segments
    pq = np.empty((2 * n, 7))
    pq[0::2, :4], pq[1::2, :4], pq[0::2, 4:], pq[1::2, 4:] = q0, q1, p0, p1
    stamps = 0.5 * np.arange(2 * n)  # segment 2k from k to k + 0.5
    rows = _segments(pq, stamps, np.diff(stamps))[0::2]
    np.testing.assert_array_equal(rows[:, 14:], np.c_[np.arange(n), np.full(n, 0.5)])
    # each segment's own start and length, of float32's scale
    rows[:, 14], rows[:, 15] = rng.uniform(-1.0, 1.0, n), rng.uniform(0.5, 2.0, n)
    at = rows[:, 14] + t * rows[:, 15]
    for dtype, tol in ((np.float64, 1e-14), (np.float32, 2e-6)):
        s = t.astype(dtype)
        got = pose_slerp_segment(rows.astype(dtype), at.astype(dtype))
        assert got.dtype == dtype
        want = pose_slerp_decoupled(
            np.concatenate([q0, p0], -1).astype(dtype),
            np.concatenate([q1, p1], -1).astype(dtype),
            s,
        )
        np.testing.assert_allclose(got, want, atol=4 * tol)
    # the ends: exactly q0 at t = 0, the rotation of q1 at t = 1
    start = pose_slerp_segment(rows, rows[:, 14])
    np.testing.assert_array_equal(start, np.concatenate([q0, p0], -1))
    end = pose_slerp_segment(rows, rows[:, 14] + rows[:, 15])[:, :4]
    np.testing.assert_allclose(np.abs(np.einsum("ij,ij->i", end, q1)), 1.0, atol=1e-14)


@pytest.mark.parametrize("interpolation", ["decoupled", "screw"])
def test_times_in_order_match_times_in_any_order(robot, interpolation):
    """Times in increasing order (more of them than samples) find their segments
    from the stamps' side; in any other order by a search per time: the same
    segments, so the same poses, and both those of scipy's composition. The times
    include both ends of the common range, stamps of each edge and repeats."""
    g, data = robot
    rng = np.random.default_rng(11)
    (s1, _), (s2, _) = data["map", "odom"], data["odom", "base"]
    lo, hi = max(s1[0], s2[0]), min(s1[-1], s2[-1])
    stamps = [s[(s >= lo) & (s <= hi)] for s in (s1, s2)]
    times = np.sort(np.concatenate([rng.uniform(lo, hi, 300), *stamps, [lo, hi, hi]]))
    times = np.concatenate([times[:50], times[49:]])  # a repeated time
    assert len(times) > 40 and np.all(np.diff(times) >= 0)
    rule = decoupled_reference if interpolation == "decoupled" else screw_reference
    got = g.get("tag", "camera", at=times, interpolation=interpolation)
    np.testing.assert_allclose(got.as_matrix(), explicit(data, times, rule), atol=1e-10)
    # exact equality needs one binding of each kernel: its compiled loop, not the
    # NumPy path that serves while the loop compiles (equal to rounding only)
    drain()
    got = g.get("tag", "camera", at=times, interpolation=interpolation)
    perm = rng.permutation(len(times))
    shuffled = g.get("tag", "camera", at=times[perm], interpolation=interpolation)
    np.testing.assert_array_equal(shuffled.as_matrix(), got[perm].as_matrix())


@pytest.mark.parametrize("interpolation", ["decoupled", "screw"])
def test_many_times_in_blocks(robot, monkeypatch, interpolation):
    """Many times are computed a block of rows at a time: the rows of one pass (and
    scipy's), the error of one pass (a time in the past in a later block than one
    in the future: the past is named, as without blocks), the clamp of one pass."""
    from rigidkit.applications.frames import lookup

    g, data = robot
    rng = np.random.default_rng(12)
    (s1, _), (s2, _) = data["map", "odom"], data["odom", "base"]
    lo, hi = max(s1[0], s2[0]), min(s1[-1], s2[-1])
    rule = decoupled_reference if interpolation == "decoupled" else screw_reference
    times = rng.uniform(lo, hi, 700)
    map_T_tag = matrices(data["map", "tag"][1])[0]
    # across the common ancestor, and up to it (the last compose writes the rows)
    for target, left in (("tag", np.eye(4)), ("map", map_T_tag)):
        g.get(target, "camera", at=times, interpolation=interpolation)
        drain()  # exact equality: the compiled loops (see the test above)
        for at in (times, np.sort(times)):
            monkeypatch.setattr(lookup, "BLOCK", 10**9)
            whole = g.get(target, "camera", at=at, interpolation=interpolation)
            monkeypatch.setattr(lookup, "BLOCK", 64)
            blocks = g.get(target, "camera", at=at, interpolation=interpolation)
            np.testing.assert_array_equal(blocks.as_matrix(), whole.as_matrix())
            want = left @ explicit(data, at, rule)
            np.testing.assert_allclose(blocks.as_matrix(), want, atol=1e-10)
    bad = times.copy()
    bad[10], bad[500] = hi + 1.0, lo - 1.0
    with pytest.raises(rk.ExtrapolationError) as err:
        g.get("tag", "camera", at=bad, interpolation=interpolation)
    assert err.value.direction == "past" and err.value.edge == ("map", "odom")
    # clamped, in any order and in increasing order (whose segments' bounds are
    # found once for the call, then cut per block)
    for at in (bad, np.sort(bad)):
        monkeypatch.setattr(lookup, "BLOCK", 64)
        clamped = g.get("tag", "camera", at=at, extrapolate="clamp")
        monkeypatch.setattr(lookup, "BLOCK", 10**9)
        whole = g.get("tag", "camera", at=at, extrapolate="clamp")
        np.testing.assert_array_equal(clamped.as_matrix(), whole.as_matrix())


@pytest.mark.parametrize("interpolation", ["decoupled", "screw"])
def test_static_pose_above_a_dynamic_edge(robot, interpolation):
    """At many times a static pose above a dynamic edge is folded into the edge's
    samples (S T_i, once per snapshot): the lookup is still the explicit product,
    also after the static pose is replaced and after a new sample arrives."""
    g, data = robot
    rng = np.random.default_rng(13)
    rule = decoupled_reference if interpolation == "decoupled" else screw_reference
    (s1, _), (s2, _) = data["map", "odom"], data["odom", "base"]
    lo, hi = max(s1[0], s2[0]), min(s1[-1], s2[-1])
    map_T_tag = matrices(data["map", "tag"][1])[0]
    for step in range(3):
        world = random_pq(1, rng)[0]
        if step == 0:
            g.add("world", "map", rk.Transform.from_pq(world))
        else:
            g.update_static("world", "map", rk.Transform.from_pq(world))
        if step == 2:  # a newest sample: a new snapshot of map -> odom
            s1 = np.append(s1, s1[-1] + 0.5)
            pq1 = np.concatenate([data["map", "odom"][1], random_pq(1, rng)])
            data["map", "odom"] = (s1, pq1)
            g.add("map", "odom", rk.Transform.from_pq(pq1[-1]), stamps=s1[-1])
        for n in (300, 3):  # folded (many times), and a compose per time (few)
            times = rng.uniform(lo, hi, n)
            want = matrices(world)[0] @ map_T_tag @ explicit(data, times, rule)
            got = g.get("world", "camera", at=times, interpolation=interpolation)
            np.testing.assert_allclose(got.as_matrix(), want, atol=1e-10)


def test_exact_at_samples_and_latest_common_time(robot):
    g, data = robot
    s, pq = data["map", "odom"]
    np.testing.assert_allclose(
        g.get("map", "odom", at=s).as_matrix(), matrices(pq), atol=1e-15
    )
    latest = min(data["map", "odom"][0][-1], data["odom", "base"][0][-1])
    np.testing.assert_allclose(
        g.get("tag", "camera").as_matrix(), explicit(data, [latest])[0], atol=1e-10
    )
    static = g.get("tag", "arm", at=None)  # crosses the dynamic edges, so at=None
    assert static.shape == ()
    assert g.get("arm", "camera", at=[1.0, 2.0]).shape == (2,)  # static, broadcast


def test_insertion_order_repeats_and_trajectory():
    rng = np.random.default_rng(3)
    t = np.arange(10.0)
    pq = random_pq(10, rng)
    perm = rng.permutation(10)
    g = rk.FrameGraph(max_duration=None)
    for i in perm:  # one at a time, out of order
        g.add("a", "b", rk.Transform.from_pq(pq[i]), stamps=t[i])
    h = rk.FrameGraph(max_duration=None)
    h.add("a", "b", rk.Trajectory(t, rk.Transform.from_pq(pq)))
    np.testing.assert_array_equal(
        g.get("a", "b", at=t).as_matrix(), h.get("a", "b", at=t).as_matrix()
    )
    replaced = random_pq(1, rng)[0]
    g.add("a", "b", rk.Transform.from_pq(replaced), stamps=4.0)
    np.testing.assert_allclose(g.get("a", "b", at=4.0).as_matrix(), matrices(replaced)[0])
    assert g.edges[0].count == 10


def test_buffer_limits():
    g = rk.FrameGraph(max_duration=2.0)
    for k in range(50):
        g.add("a", "b", rk.Transform(translation=[k, 0.0, 0.0]), stamps=0.1 * k)
    (e,) = g.edges
    # tf2 keeps every sample not older than newest - cache time
    assert e.range[1] == pytest.approx(4.9) and e.range[0] == pytest.approx(2.9)
    assert e.count == 21
    g = rk.FrameGraph(max_duration=None, max_samples=5)
    g.add("a", "b", rk.Transform(translation=np.ones((30, 3))), stamps=np.arange(30.0))
    assert g.edges[0].count == 5 and g.edges[0].range == (25.0, 29.0)


# -- errors -----------------------------------------------------------------------------
def test_extrapolation_errors(robot):
    g, data = robot
    t0, t1 = data["map", "odom"][0][[0, -1]]
    with pytest.raises(rk.ExtrapolationError, match="'map' -> 'odom'") as err:
        g.get("map", "odom", at=[t0 + 0.1, t1 + 1.0])
    assert err.value.direction == "future" and err.value.edge == ("map", "odom")
    assert err.value.range == (t0, t1) and isinstance(err.value, ValueError)
    assert pickle.loads(pickle.dumps(err.value)).direction == "future"
    with pytest.raises(rk.ExtrapolationError) as err:
        g.get("map", "odom", at=t0 - 1.0)
    assert err.value.direction == "past"
    assert str(t0) in str(err.value)
    clamp = g.get("map", "odom", at=[t0 - 1.0, t1 + 1.0], extrapolate="clamp")
    np.testing.assert_allclose(
        clamp.as_matrix(), g.get("map", "odom", at=[t0, t1]).as_matrix(), atol=0
    )
    for t, end in ((t0 - 1.0, t0), (t1 + 1.0, t1)):  # one time: its own path
        np.testing.assert_array_equal(
            g.get("map", "odom", at=t, extrapolate="clamp").as_matrix(),
            g.get("map", "odom", at=end).as_matrix(),
        )
    hold = g.get("map", "odom", at=t1 + 1.0, extrapolate="hold")
    np.testing.assert_allclose(hold.as_matrix(), g.get("map", "odom", at=t1).as_matrix())
    with pytest.raises(rk.ExtrapolationError, match="past"):
        g.get("map", "odom", at=t0 - 1.0, extrapolate="hold")
    ok, reason = g.can_transform("map", "odom", at=t1 + 1.0)
    assert not ok and "future" in reason
    assert g.can_transform("map", "camera", at=t1 - 0.5) == (True, "")


def test_connectivity_and_lookup_errors(robot):
    g, _ = robot
    g.add("world", "other", rk.Transform())
    with pytest.raises(rk.ConnectivityError, match="'map'.*'world'|'world'.*'map'"):
        g.get("camera", "other")
    with pytest.raises(rk.LookupError, match="closest: 'camera'") as err:
        g.get("map", "camra")
    assert isinstance(err.value, ValueError) and not isinstance(err.value, KeyError)
    ok, reason = g.can_transform("map", "camra")
    assert not ok and "camra" in reason


def test_lookup_error_is_also_the_builtin_kind_and_no_star_import_shadows_it(robot):
    """rk.LookupError is a RigidkitError (a ValueError) and a builtin LookupError, so
    ``except LookupError`` catches it; ``from rigidkit import *`` leaves the builtin
    name alone, so ``except LookupError`` still catches KeyError after it."""
    import builtins

    g, _ = robot
    with pytest.raises(builtins.LookupError) as err:
        g.get("map", "camra")
    assert type(err.value) is rk.LookupError and isinstance(err.value, rk.RigidkitError)
    assert rk.LookupError is not builtins.LookupError
    assert pickle.loads(pickle.dumps(err.value)).args == err.value.args
    space = {}
    exec("from rigidkit import *", space)
    assert "LookupError" not in space and "ExtrapolationError" in space
    assert rk.LookupError is rk.errors.LookupError


# -- time travel and velocities ---------------------------------------------------------
def test_time_travel(robot):
    g, data = robot
    a, b = 1.3, 3.7
    got = g.get("camera", "camera", at=a, source_at=b, fixed="map")
    want = np.linalg.inv(explicit(data, [a])[0]) @ explicit(data, [b])[0]
    # camera at a <- tag (fixed, static in map) -> camera at b
    np.testing.assert_allclose(got.as_matrix(), want, atol=1e-10)
    with pytest.raises(ValueError, match="fixed"):
        g.get("camera", "camera", at=a, source_at=b)


def test_velocity_against_finite_differences_and_twist_from_samples(robot):
    g, _ = robot
    times = np.array([0.8, 1.9, 3.3])
    h = 1e-6
    for frame in ("body", "world"):
        for interpolation in ("decoupled", "screw"):
            V = g.velocity("tag", "camera", times, frame=frame, interpolation=interpolation)
            T0 = g.get("tag", "camera", times - h, interpolation=interpolation).as_matrix()
            T1 = g.get("tag", "camera", times + h, interpolation=interpolation).as_matrix()
            T = g.get("tag", "camera", times, interpolation=interpolation).as_matrix()
            for k in range(3):
                dT = (T1[k] - T0[k]) / (2 * h)
                X = (
                    np.linalg.inv(T[k]) @ dT
                    if frame == "body"
                    else dT @ np.linalg.inv(T[k])
                )
                want = np.r_[X[:3, 3], X[2, 1], X[0, 2], X[1, 0]]
                np.testing.assert_allclose(V[k], want, rtol=1e-5, atol=1e-5)
    # a constant screw motion sampled: the samples' finite differences agree
    xi = np.array([0.3, -0.1, 0.2, 0.1, 0.4, -0.2])
    t = np.linspace(0.0, 2.0, 201)
    g = rk.FrameGraph(max_duration=None)
    g.add("w", "b", rk.Transform.exp(t[:, None] * xi), stamps=t)
    V = g.velocity("w", "b", t[1:-1], frame="body", interpolation="screw")
    ref = rk.kinematics.twist_from_samples(
        rk.Transform.exp(t[:, None] * xi), t, frame="body"
    )
    np.testing.assert_allclose(V, ref[1:-1], atol=1e-4)
    np.testing.assert_allclose(V, np.broadcast_to(xi, V.shape), atol=1e-12)


# -- threads ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "n_stamps", [3000, pytest.param(12500, marks=pytest.mark.exhaustive)]
)
def test_threads_stress(n_stamps):
    """4 writers (one edge each, out of order within bursts of 4) and 4 readers,
    ~8 n_stamps operations (1e5 in the exhaustive run): no exception, and every lookup
    that succeeds equals the single-threaded composition of the written samples (a
    torn read would not)."""
    chains = [("m", "a"), ("a", "b"), ("b", "c"), ("m", "d")]
    rng = np.random.default_rng(11)
    stamps = np.arange(n_stamps) * 0.01
    poses = {e: rk.Transform.from_pq(random_pq(n_stamps, rng)) for e in chains}
    written = {e: np.zeros(n_stamps, dtype=bool) for e in chains}
    g = rk.FrameGraph(max_duration=10.0)
    for e in chains:  # the first two samples, so that readers find every frame
        g.add(*e, poses[e][:2], stamps=stamps[:2])
        written[e][:2] = True
    errors, counts, done = [], {"exact": 0, "past": 0, "reads": 0}, threading.Event()
    progress = dict.fromkeys(chains, 2)

    def writer(e, seed):
        order = np.arange(2, n_stamps)
        r = np.random.default_rng(seed)
        for k in range(0, len(order) - 4, 4):
            order[k : k + 4] = r.permutation(order[k : k + 4])
        try:
            for j, k in enumerate(order):
                g.add(*e, poses[e][int(k)], stamps=stamps[k])
                written[e][k] = True
                progress[e] = j + 2
        except Exception as exc:  # reported by the assertion below
            errors.append(exc)

    def reader(seed):
        r = np.random.default_rng(seed)
        try:
            while not done.is_set() or counts["reads"] < n_stamps:
                # stamps every writer has reached, and not yet trimmed by the fastest
                lo, hi = max(progress.values()) - 900, min(progress.values())
                if lo >= hi:
                    continue
                k = int(r.integers(max(0, lo), hi))
                if not all(written[e][k] for e in chains):
                    continue
                counts["reads"] += 1
                try:
                    got = g.get("d", "c", at=stamps[k])
                except rk.ExtrapolationError as exc:
                    assert exc.direction == "past"  # trimmed by max_duration
                    counts["past"] += 1
                    continue
                want = (
                    poses["m", "d"][k].inv()
                    @ poses["m", "a"][k]
                    @ poses["a", "b"][k]
                    @ poses["b", "c"][k]
                )
                np.testing.assert_allclose(got.as_matrix(), want.as_matrix(), atol=1e-12)
                counts["exact"] += 1
        except Exception as exc:
            errors.append(exc)

    writers = [threading.Thread(target=writer, args=(e, i)) for i, e in enumerate(chains)]
    readers = [threading.Thread(target=reader, args=(10 + i,)) for i in range(4)]
    for th in writers + readers:
        th.start()
    for th in writers:
        th.join()
    done.set()
    for th in readers:
        th.join()
    assert not errors, errors[:3]
    assert counts["exact"] > n_stamps // 2, counts
    assert g.edges[0].count <= 1001  # 10 s of samples at 100 Hz


# -- files and pictures -----------------------------------------------------------------
def test_json_round_trip_is_exact(robot):
    g, _ = robot
    g.add(
        "map",
        "gps",
        rk.Transform(translation=[1.0, 2.0, 3.0]),
        stamps=[0.1],
        cov=np.diag(np.arange(1.0, 7.0)) / 3.0,
    )
    h = rk.FrameGraph.from_json(g.to_json())
    assert h.edges == g.edges and h.frames == g.frames
    assert (h.max_duration, h.max_samples) == (g.max_duration, g.max_samples)
    t = np.linspace(0.5, 4.5, 50)
    np.testing.assert_array_equal(
        h.get("tag", "camera", at=t).as_matrix(), g.get("tag", "camera", at=t).as_matrix()
    )
    snap = {s.child: s for s in (e.snapshot() for e in g._edges.values())}
    for e in h._edges.values():
        s = e.snapshot()
        np.testing.assert_array_equal(s.pq, snap[s.child].pq)
        np.testing.assert_array_equal(s.t, snap[s.child].t)
    np.testing.assert_array_equal(
        h.get("map", "gps", at=0.1, with_covariance=True).cov,
        np.diag(np.arange(1.0, 7.0)) / 3,
    )
    with pytest.raises(ValueError, match="not a rigidkit.FrameGraph"):
        rk.FrameGraph.from_json('{"format": "x"}')


def test_text_and_dot(robot):
    g, data = robot
    text = str(g)
    t0, t1 = (float(x) for x in data["map", "odom"][0][[0, -1]])
    assert text.splitlines()[0] == "map"
    assert f"├── odom  [dynamic, 40 samples, t in [{t0!r}, {t1!r}]]" in text
    assert "│       └── arm  [static]" in text
    assert "└── tag  [static]" in text
    dot = g.to_dot()
    assert dot.startswith("digraph FrameGraph {") and dot.endswith("}")
    assert '"arm" -> "camera" [label="static", style=dashed];' in dot
    assert dot.count("->") == 5


def test_readme_frames_example():
    """The README's robot: the block runs, and its numbers agree with scipy's matrix
    exponential of the base's motion composed with the camera mount by hand."""
    import pathlib
    import re

    from scipy.linalg import expm

    readme = pathlib.Path(__file__).resolve().parents[1] / "README.md"
    (block,) = [
        b
        for b in re.findall(r"```python\n(.*?)```", readme.read_text(), re.S)
        if "rk.FrameGraph(" in b
    ]
    ns: dict = {}
    exec(block, ns)

    def map_T_camera(t):
        xi = t * np.array([1.0, 0, 0, 0, 0, 0.5])
        hat = np.zeros((4, 4))
        hat[:3, 3] = xi[:3]
        hat[1, 0], hat[0, 1] = xi[5], -xi[5]
        mount = np.eye(4)
        mount[:3, :3] = [[0.0, 0, 1], [-1, 0, 0], [0, -1, 0]]
        mount[:3, 3] = [0.3, 0, 1.2]
        return expm(hat) @ mount

    now = ns["now"]
    p = np.r_[ns["p_camera"], 1.0]
    then = map_T_camera(now - 0.2)
    np.testing.assert_allclose(ns["p_map"], (then @ p)[:3], atol=1e-9)
    want = np.linalg.solve(map_T_camera(now), then @ p)[:3]
    np.testing.assert_allclose(ns["p_camera_now"], want, atol=1e-9)
    assert ns["camera_track"].shape == (1000, 3)


def _chain_graph(a, b):
    graph = rk.FrameGraph()
    graph.add("world", "base", rk.Transform.exp(a))
    graph.add("base", "camera", rk.Transform.exp(b))
    return graph


def test_torch_gradient_of_a_lookup_equals_finite_differences(torch):
    """A static path of torch poses stays on autograd's graph: the gradient of a
    weighted sum of camera_T_world's matrix equals central differences of the
    NumPy lookup (step 1e-6)."""
    rng = np.random.default_rng(4)
    a, b, W = rng.uniform(-1, 1, 6), rng.uniform(-1, 1, 6), rng.standard_normal((4, 4))

    def loss_np(x):
        return float((_chain_graph(x, b).get("camera", "world").as_matrix() * W).sum())

    x = torch.tensor(a, requires_grad=True)
    M = _chain_graph(x, torch.tensor(b)).get("camera", "world").as_matrix()
    assert isinstance(M, torch.Tensor)
    (got,) = torch.autograd.grad((M * torch.tensor(W)).sum(), x)
    fd = np.array(
        [(loss_np(a + 1e-6 * e) - loss_np(a - 1e-6 * e)) / 2e-6 for e in np.eye(6)]
    )
    np.testing.assert_allclose(got.numpy(), fd, rtol=1e-6, atol=1e-8)


def test_jax_graph_built_under_jit_equals_numpy(jax):
    """A graph built inside a jitted function: the lookup traces, and equals the
    explicit composition exp(a) exp(b) of NumPy."""
    rng = np.random.default_rng(5)
    a, b = rng.uniform(-1, 1, 6), rng.uniform(-1, 1, 6)
    f = jax.jit(lambda x, y: _chain_graph(x, y).get("world", "camera").as_matrix())
    want = (rk.Transform.exp(a) @ rk.Transform.exp(b)).as_matrix()
    np.testing.assert_allclose(np.asarray(f(a, b)), want, rtol=0, atol=1e-13)


def test_a_batch_of_static_edges_broadcasts_like_one_pose_each():
    """A batch of poses without stamps is a batch of static edges: the lookup
    equals the lookups of graphs of one pose each."""
    rng = np.random.default_rng(6)
    a, b = rng.uniform(-1, 1, (3, 6)), rng.uniform(-1, 1, 6)
    got = _chain_graph(a, b).get("camera", "world").as_matrix()
    assert got.shape == (3, 4, 4)
    for k in range(3):
        want = _chain_graph(a[k], b).get("camera", "world").as_matrix()
        np.testing.assert_allclose(got[k], want, rtol=0, atol=1e-14)


@pytest.mark.parametrize("interpolation", ["decoupled", "screw"])
def test_torch_gradient_through_a_dynamic_edge_equals_finite_differences(
    torch, interpolation
):
    """Stamped torch poses stay on autograd's graph through the interpolation: the
    gradients of a pose lookup and of a velocity (at a time between samples, and
    at a batch of times) equal central differences of the NumPy calls."""
    rng = np.random.default_rng(7)
    X = rng.uniform(-0.5, 0.5, (4, 6))
    stamps = np.arange(4) * 0.5
    at = np.array([0.7, 1.3])

    def outputs(x):
        graph = rk.FrameGraph()
        graph.add("world", "body", rk.Transform.exp(x), stamps=stamps)
        return [
            graph.get("body", "world", 0.7, interpolation=interpolation).as_matrix(),
            graph.get("world", "body", at, interpolation=interpolation).as_matrix(),
            graph.velocity("world", "body", at, frame="world", interpolation=interpolation),
        ]

    weights = [rng.standard_normal(np.shape(o)) for o in outputs(X)]

    def loss_np(x):
        return sum(float((np.asarray(o) * w).sum()) for o, w in zip(outputs(x), weights))

    x = torch.tensor(X, requires_grad=True)
    loss = sum((o * torch.tensor(w)).sum() for o, w in zip(outputs(x), weights))
    (got,) = torch.autograd.grad(loss, x)
    fd = np.zeros_like(X)
    for j in np.ndindex(X.shape):
        e = np.zeros_like(X)
        e[j] = 1e-6
        fd[j] = (loss_np(X + e) - loss_np(X - e)) / 2e-6
    np.testing.assert_allclose(got.numpy(), fd, rtol=1e-6, atol=1e-7)


def test_edge_kind_errors_name_the_edge():
    """Using an edge as the other kind raises ``rk.EdgeKindError`` (a ValueError)
    naming the edge: samples on a static edge, a static pose on a dynamic one, a
    second static pose, ``update_static`` of a dynamic edge, and torch samples
    added one call after another; the graph is unchanged after each."""
    T = rk.Transform(translation=[1.0, 0.0, 0.0])
    moving = rk.Transform(translation=[[0.0, 0, 0], [1.0, 0, 0]])
    g = rk.FrameGraph()
    g.add("map", "odom", T)
    g.add("odom", "base", moving, stamps=[0.0, 1.0])
    cases = [
        (lambda: g.add("map", "odom", moving, stamps=[2.0, 3.0]), "'map' -> 'odom'"),
        (lambda: g.add("odom", "base", T), "'odom' -> 'base'"),
        (lambda: g.add("map", "odom", T), "update_static"),
        (lambda: g.update_static("odom", "base", T), "'odom' -> 'base' is dynamic"),
    ]
    for call, words in cases:
        with pytest.raises(rk.EdgeKindError, match=words) as info:
            call()
        assert isinstance(info.value, ValueError)
    assert [(e.child, e.kind, e.count) for e in g.edges] == [
        ("odom", "static", 1),
        ("base", "dynamic", 2),
    ]
    np.testing.assert_allclose(g.get("map", "base", at=0.5).translation, [1.5, 0, 0])
    torch = pytest.importorskip("torch")
    g.add("base", "arm", rk.Transform(translation=torch.zeros(2, 3)), stamps=[0.0, 1.0])
    with pytest.raises(rk.EdgeKindError, match="'base' -> 'arm'"):
        g.add("base", "arm", rk.Transform(translation=torch.ones(3)), stamps=2.0)


def _cov_graph(lib, scale=1e-2):
    """map -> odom (dynamic, covariances) -> base -> camera (static, covariance)."""
    rng = np.random.default_rng(5)
    moving = rk.Transform.random(2, rng=rng)
    g = rk.FrameGraph()
    cov = np.eye(6) * 0.5 + np.diag(rng.uniform(0.1, 1.0, 6))
    g.add(
        "map",
        "odom",
        rk.Transform.from_pq(lib(np.asarray(moving.as_pq()))),
        stamps=[0.0, 1.0],
        cov=scale * lib(np.stack([cov, 2.0 * cov])),
    )
    g.add(
        "odom",
        "base",
        rk.Transform.from_pq(lib(np.asarray(rk.Transform.random(rng=rng).as_pq()))),
    )
    mount = rk.Transform.from_pq(lib(np.asarray(rk.Transform.random(rng=rng).as_pq())))
    g.add("base", "camera", mount, cov=lib(np.eye(6) * 1e-3))
    return g


@pytest.mark.parametrize("at", [0.3, np.array([0.25, 0.5, 0.75])])
def test_covariance_lookup_stays_in_torch_with_gradients(at):
    """``get(..., with_covariance=True)`` on torch poses and covariances keeps the
    covariance in torch (it was converted to NumPy, and a covariance that
    required grad raised), equal to the NumPy graph's, and its gradient with
    respect to an edge covariance's scale matches central differences of the
    NumPy graph."""
    torch = pytest.importorskip("torch")

    def lib(x):
        return torch.tensor(np.asarray(x), dtype=torch.float64)

    want = _cov_graph(np.asarray).get("camera", "map", at=at, with_covariance=True)
    got = _cov_graph(lib).get("camera", "map", at=at, with_covariance=True)
    assert isinstance(got.cov, torch.Tensor)
    np.testing.assert_allclose(got.cov.numpy(), want.cov, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(
        got.mean.as_matrix().numpy(), want.mean.as_matrix(), atol=1e-14
    )

    scale = torch.tensor(1e-2, dtype=torch.float64, requires_grad=True)
    weights = np.random.default_rng(6).normal(size=np.shape(want.cov))
    out = _cov_graph(lib, scale=scale).get("camera", "map", at=at, with_covariance=True).cov
    (out * lib(weights)).sum().backward()

    def f(s):
        cov = (
            _cov_graph(np.asarray, scale=s)
            .get("camera", "map", at=at, with_covariance=True)
            .cov
        )
        return float((cov * weights).sum())

    h = 1e-6
    fd = (f(1e-2 + h) - f(1e-2 - h)) / (2 * h)
    np.testing.assert_allclose(float(scale.grad), fd, rtol=1e-6)
