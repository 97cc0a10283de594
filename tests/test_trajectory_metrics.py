"""Association, alignment, APE and RPE against evo (the reference), and by hand.

evo (GPLv3) is only called, never copied: the tests write TUM files, read them
with both libraries and compare every error to 1e-9 relative. Where evo is not
installed those tests skip; the hand-computed cases always run.
"""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest

import rigidkit as rk
from rigidkit.applications.trajectory import align, ape, associate, rpe

RTOL = 1e-9


def _write_tum(path, t, p, q_xyzw):
    np.savetxt(path, np.column_stack([t, p, q_xyzw]), fmt="%.9f")


def _rotvecs_to_xyzw(rv):
    # Via rigidkit's own conversion; the file is the shared input of both libraries.
    return rk.Rotation.from_rotvec(rv).as_quat(scalar_first=False)


@pytest.fixture(scope="module")
def tum_pair(tmp_path_factory):
    """A reference of 1,500 poses at ~100 Hz and a noisy, scaled, moved estimate of
    400 of them with jittered stamps (some beyond max_diff)."""
    rng = np.random.default_rng(7)
    n = 1500
    t = 100.0 + np.arange(n) * 0.03 + rng.uniform(0, 0.003, n)
    p = np.cumsum(rng.normal(size=(n, 3)) * 0.05, axis=0)
    rv = np.cumsum(rng.normal(size=(n, 3)) * 0.03, axis=0)
    idx = np.sort(rng.choice(n, 400, replace=False))
    te = np.sort(t[idx] + rng.normal(0, 0.006, len(idx)))
    S = rk.Rotation.from_rotvec([0.1, -0.2, 0.5])
    pe = 0.7 * S.apply(p[idx]) + [1.0, 2.0, 3.0] + rng.normal(0, 0.02, (len(idx), 3))
    Re = (
        S
        @ rk.Rotation.from_rotvec(rv[idx])
        @ rk.Rotation.from_rotvec(rng.normal(0, 0.01, (len(idx), 3)))
    )
    d = tmp_path_factory.mktemp("tum")
    ref_path, est_path = d / "ref.txt", d / "est.txt"
    _write_tum(ref_path, t, p, _rotvecs_to_xyzw(rv))
    _write_tum(est_path, te, pe, Re.as_quat(scalar_first=False))
    return str(ref_path), str(est_path)


def _evo():
    return pytest.importorskip("evo")


def _evo_pair(tum_pair):
    _evo()
    from evo.core import sync
    from evo.tools import file_interface

    ref = file_interface.read_tum_trajectory_file(tum_pair[0])
    est = file_interface.read_tum_trajectory_file(tum_pair[1])
    return sync.associate_trajectories(ref, est, max_diff=0.01)


def _ours(tum_pair):
    ref = rk.io.read_trajectory(tum_pair[0], "tum")
    est = rk.io.read_trajectory(tum_pair[1], "tum")
    return associate(ref, est, max_diff=0.01)


def _evo_relation(relation, degrees=False):
    from evo.core.metrics import PoseRelation

    return {
        "translation": PoseRelation.translation_part,
        "rotation_angle": (
            PoseRelation.rotation_angle_deg if degrees else PoseRelation.rotation_angle_rad
        ),
        "rotation_part": PoseRelation.rotation_part,
        "full": PoseRelation.full_transformation,
        "point_distance": PoseRelation.point_distance,
    }[relation]


def _assert_close(ours, theirs):
    theirs = np.asarray(theirs, dtype=np.float64)
    assert ours.shape == theirs.shape
    # An error that is zero in exact arithmetic (the first pose after "origin"
    # alignment) is rounding noise in both (~1e-16), with no relative precision.
    exact_zero = theirs < 1e-14
    np.testing.assert_allclose(ours[~exact_zero], theirs[~exact_zero], rtol=RTOL, atol=0.0)
    assert (ours[exact_zero] < 1e-14).all()


def _assert_stats(ours, theirs):
    for key in ("rmse", "mean", "median", "std", "min", "max", "sse"):
        if theirs[key] < 1e-14:  # a zero in exact arithmetic (see _assert_close)
            assert ours[key] < 1e-14
            continue
        np.testing.assert_allclose(ours[key], theirs[key], rtol=RTOL, atol=0.0, err_msg=key)


def test_association_equals_evo(tum_pair):
    a, b = _evo_pair(tum_pair)
    r, e = _ours(tum_pair)
    assert 300 < len(r) < 400  # some estimate stamps are beyond max_diff
    np.testing.assert_array_equal(r.stamps, a.timestamps)
    np.testing.assert_array_equal(e.stamps, b.timestamps)
    np.testing.assert_array_equal(r.positions, a.positions_xyz)


def _evo_aligned(a, b, method):
    b = copy.deepcopy(b)
    a = copy.deepcopy(a)
    if method == "se3":
        b.align(a)
    elif method == "sim3":
        b.align(a, correct_scale=True)
    elif method == "scale":
        b.align(a, correct_only_scale=True)
    elif method == "origin":
        b.align_origin(a)
    return a, b


@pytest.mark.parametrize("method", ["none", "se3", "sim3", "scale", "origin"])
@pytest.mark.parametrize(
    "relation", ["translation", "rotation_angle", "rotation_part", "full", "point_distance"]
)
def test_ape_equals_evo(tum_pair, method, relation):
    from evo.core import metrics

    a, b = _evo_aligned(*_evo_pair(tum_pair), method)
    r, e = _ours(tum_pair)
    aligned, _ = align(e, r, method=method)
    degrees = relation == "rotation_angle" and method == "se3"
    m = metrics.APE(_evo_relation(relation, degrees))
    m.process_data((a, b))
    ours = ape(r, aligned, relation=relation, degrees=degrees)
    _assert_close(ours.errors, m.error)
    _assert_stats(ours.stats, m.get_all_statistics())
    np.testing.assert_array_equal(ours.stamps, a.timestamps)


def test_alignment_first_n_equals_evo(tum_pair):
    a, b = _evo_pair(tum_pair)
    b = copy.deepcopy(b)
    b.align(a, correct_scale=True, n=50)
    r, e = _ours(tum_pair)
    aligned, S = align(e, r, method="sim3", first=50)
    np.testing.assert_allclose(aligned.positions, b.positions_xyz, rtol=0, atol=1e-12)
    assert isinstance(S, rk.Similarity)


_RPE_CASES = [
    (1, "frames", False),
    (7, "frames", False),
    (7, "frames", True),
    (0.5, "meters", False),
    (0.5, "meters", True),
    (2.0, "meters", True),
    (10.0, "degrees", False),
    (0.2, "radians", False),
    (10.0, "degrees", True),
]


@pytest.mark.parametrize("delta,unit,all_pairs", _RPE_CASES)
@pytest.mark.parametrize(
    "relation", ["translation", "rotation_angle", "rotation_part", "full", "point_distance"]
)
def test_rpe_equals_evo(tum_pair, delta, unit, all_pairs, relation):
    from evo.core import metrics
    from evo.core.units import Unit

    a, b = _evo_aligned(*_evo_pair(tum_pair), "sim3")
    r, e = _ours(tum_pair)
    aligned, _ = align(e, r, method="sim3")
    evo_unit = {
        "frames": Unit.frames,
        "meters": Unit.meters,
        "degrees": Unit.degrees,
        "radians": Unit.radians,
    }[unit]
    m = metrics.RPE(
        _evo_relation(relation),
        delta=delta,
        delta_unit=evo_unit,
        all_pairs=all_pairs,
        rel_delta_tol=0.1,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m.process_data((a, b))
    ours = rpe(r, aligned, delta=delta, unit=unit, relation=relation, all_pairs=all_pairs)
    if relation == "point_distance":
        # A difference of two lengths |d_est| - |d_ref|: its rounding is relative to
        # the lengths (the aligned positions of the two libraries differ by ~1e-15),
        # so it is compared to 1e-9 of them, not of the (possibly tiny) difference.
        i, j = ours.pairs.T
        span = np.linalg.norm(r.positions[j] - r.positions[i], axis=-1)
        assert np.all(np.abs(ours.errors - m.error) <= RTOL * np.maximum(span, m.error))
    else:
        _assert_close(ours.errors, m.error)
        _assert_stats(ours.stats, m.get_all_statistics())


@pytest.mark.parametrize("delta,unit,all_pairs", _RPE_CASES[:6])
def test_rpe_pairs_from_reference_equals_evo(tum_pair, delta, unit, all_pairs):
    from evo.core import metrics
    from evo.core.units import Unit

    a, b = _evo_aligned(*_evo_pair(tum_pair), "se3")
    r, e = _ours(tum_pair)
    aligned, _ = align(e, r, method="se3")
    m = metrics.RPE(
        metrics.PoseRelation.translation_part,
        delta=delta,
        delta_unit=Unit.frames if unit == "frames" else Unit.meters,
        all_pairs=all_pairs,
        pairs_from_reference=True,
    )
    m.process_data((a, b))
    ours = rpe(
        r, aligned, delta=delta, unit=unit, all_pairs=all_pairs, pairs_from="reference"
    )
    _assert_close(ours.errors, m.error)


# -- by hand ---------------------------------------------------------------------------


def _line(x, y=None):
    x = np.asarray(x, dtype=np.float64)
    y = np.zeros_like(x) if y is None else np.asarray(y, dtype=np.float64)
    return rk.Trajectory(
        np.arange(len(x)) * 1.0, rk.Transform(translation=np.c_[x, y, 0 * x])
    )


def test_ape_by_hand():
    ref = _line([0.0, 1.0, 2.0])
    est = _line([0.0, 1.0, 2.0], [0.0, 3.0, 4.0])
    r = ape(ref, est)
    np.testing.assert_array_equal(r.errors, [0.0, 3.0, 4.0])
    assert r.stats["sse"] == 25.0
    assert r.stats["rmse"] == np.sqrt(25.0 / 3)
    assert r.stats["median"] == 3.0 and r.stats["max"] == 4.0 and r.stats["min"] == 0.0
    assert r.stats["std"] == pytest.approx(
        np.sqrt(((0 - 7 / 3) ** 2 + (3 - 7 / 3) ** 2 + (4 - 7 / 3) ** 2) / 3), rel=1e-15
    )


def test_rotation_relations_by_hand():
    # est = ref rotated by 0.3 rad about z at the same place: E = Rz(-0.3).
    stamps = [0.0, 1.0]
    ref = rk.Trajectory(stamps, rk.Transform(translation=[[0.0, 0, 0], [1.0, 0, 0]]))
    R = rk.Rotation.from_rotvec([0.0, 0.0, 0.3])
    est = rk.Trajectory(
        stamps, rk.Transform(rotation=R, translation=[[0.0, 0, 0], [1.0, 0, 0]])
    )
    np.testing.assert_allclose(ape(ref, est, "rotation_angle").errors, 0.3, rtol=1e-15)
    np.testing.assert_allclose(
        ape(ref, est, "rotation_angle", degrees=True).errors, np.degrees(0.3), rtol=1e-15
    )
    # |Rz(a) - I|_F^2 = 4 (1 - cos a) from the matrix entries.
    np.testing.assert_allclose(
        ape(ref, est, "rotation_part").errors, np.sqrt(4 * (1 - np.cos(0.3))), rtol=1e-14
    )
    # E = est^-1 ref: translation -Rz(-0.3) p? no: R^T p - R^T p = 0 at equal positions.
    np.testing.assert_allclose(
        ape(ref, est, "full").errors, np.sqrt(4 * (1 - np.cos(0.3))), rtol=1e-14
    )


def test_rpe_by_hand_frames_and_meters():
    # Steps of 1, 2, 1, 2 along x; the estimate drifts 10 % in the second half.
    x = np.array([0.0, 1.0, 3.0, 4.0, 6.0])
    xe = np.array([0.0, 1.0, 3.0, 4.1, 6.3])
    ref, est = _line(x), _line(xe)
    r = rpe(ref, est, delta=2)
    np.testing.assert_array_equal(r.pairs, [[0, 2], [2, 4]])
    np.testing.assert_allclose(r.errors, [0.0, 0.3], rtol=1e-14)
    r = rpe(ref, est, delta=1, all_pairs=True)
    np.testing.assert_array_equal(r.pairs, [[0, 1], [1, 2], [2, 3], [3, 4]])
    # Metres on the estimate's path (0, 1, 3, 4.1, 6.3): from 0, the first index at
    # >= 3 m is 2; from 2 (3 m), 4 is the first at >= 3 m further.
    r = rpe(ref, est, delta=3.0, unit="meters")
    np.testing.assert_array_equal(r.pairs, [[0, 2], [2, 4]])
    # all pairs: for each i the j closest to 3 m: 0->2 (3.0), 1->3 (3.1),
    # 2->4 (3.3, within 10 %), 3 has only 2.2 m left (27 % off: dropped).
    r = rpe(ref, est, delta=3.0, unit="meters", all_pairs=True)
    np.testing.assert_array_equal(r.pairs, [[0, 2], [1, 3], [2, 4]])


def test_associate_by_hand():
    ref = _line(np.arange(5.0))  # stamps 0..4
    est = rk.Trajectory([0.995, 1.004, 2.5, 3.009], rk.Transform.random(4, rng=0))
    r, e = associate(ref, est, max_diff=0.01)
    # est is the shorter: each of its stamps takes the nearest ref stamp; ref's
    # stamp 1.0 is used twice.
    np.testing.assert_array_equal(r.stamps, [1.0, 1.0, 3.0])
    np.testing.assert_array_equal(e.stamps, [0.995, 1.004, 3.009])
    r, e = associate(ref, est, max_diff=0.01, offset=-0.005)
    np.testing.assert_array_equal(e.stamps, [1.004, 3.009])
    with pytest.raises(rk.TimestampError, match=r"ref spans \[0.0, 4.0\]"):
        associate(ref, est, max_diff=0.01, offset=100.0)


@pytest.mark.parametrize("seed", range(4))
def test_nearest_pairs_compiled_and_numpy_agree_with_brute_force(seed):
    """The compiled merge, the NumPy binary search and a brute-force argmin
    (np.argmin takes the first of equal minima: the earlier stamp on a tie)."""
    import importlib

    from rigidkit._engine import drain, numba_available
    from rigidkit.applications.trajectory import _loops

    assoc = importlib.import_module("rigidkit.applications.trajectory.associate")

    rng = np.random.default_rng(seed)
    # Stamps on a grid of 1/8 s make exact ties (a stamp halfway between two).
    long = np.unique(rng.integers(0, 400, 150)) / 8.0
    short = np.unique(rng.integers(-10, 420, 60)) / 8.0 + rng.choice([0.0, 1 / 16], 1)
    short = short[: rng.integers(1, len(short) + 1)]
    max_diff = 1 / 16
    gap = np.abs(long[None, :] - short[:, None])
    near = np.argmin(gap, axis=1)
    keep = gap[np.arange(len(short)), near] <= max_diff
    expected = (np.flatnonzero(keep), near[keep])
    numpy_pairs = assoc._nearest_numpy(short, long, max_diff)
    for got in (numpy_pairs, assoc.nearest_pairs(short, long, max_diff)):
        np.testing.assert_array_equal(got[0], expected[0])
        np.testing.assert_array_equal(got[1], expected[1])
    if numba_available():
        _loops.nearest_loop()
        drain()
        assert _loops.nearest_loop() is not None
        i_s, i_l, strict = assoc._pairs(short, long, max_diff)
        np.testing.assert_array_equal(i_s, expected[0])
        np.testing.assert_array_equal(i_l, expected[1])
        assert strict == bool((np.diff(expected[1]) > 0).all())
        # ref the longer one: the pairs come back as (i_ref, i_est).
        i_l2, i_s2, _ = assoc._pairs(long, short, max_diff)
        np.testing.assert_array_equal(i_s2, expected[0])
        np.testing.assert_array_equal(i_l2, expected[1])


def test_associate_interpolate():
    x = np.arange(5.0)
    ref = _line(2 * x)
    est = rk.Trajectory([0.5, 1.25, 3.5, 4.5], rk.Transform.random(4, rng=0))
    r, e = associate(ref, est, method="interpolate")
    np.testing.assert_array_equal(e.stamps, [0.5, 1.25, 3.5])
    np.testing.assert_allclose(r.positions[:, 0], [1.0, 2.5, 7.0], rtol=1e-15)
    gappy = rk.Trajectory([0.0, 1.0, 3.0], rk.Transform(translation=np.zeros((3, 3))))
    r, e = associate(gappy, est, method="interpolate", max_gap=1.5)
    np.testing.assert_array_equal(e.stamps, [0.5])


def test_align_methods_recover_a_known_motion():
    rng = np.random.default_rng(0)
    ref = rk.Trajectory(None, rk.Transform.random(20, rng=rng))
    yaw = rk.Transform(rotation=rk.Rotation.from_rotvec([0, 0, 0.7]), translation=[1, 2, 3])
    est = ref.transform(yaw.inv())
    aligned, S = align(est, ref, method="yaw")
    assert bool(S.approx_equal(yaw, atol=1e-12))
    np.testing.assert_allclose(aligned.positions, ref.positions, atol=1e-12)
    aligned, S = align(est, ref, method="origin")
    assert bool((aligned.poses[0]).approx_equal(ref.poses[0], atol=1e-12))
    aligned, S = align(est, ref, method="none")
    np.testing.assert_array_equal(aligned.positions, est.positions)


def test_align_batched_equals_one_by_one():
    rng = np.random.default_rng(1)
    ref = rk.Trajectory(None, rk.Transform.random((3, 30), rng=rng))
    est = rk.Trajectory(None, rk.Transform.random((3, 30), rng=rng))
    for method in ("se3", "sim3", "yaw", "origin"):
        aligned, S = align(est, ref, method=method)
        assert S.shape == (3,)
        for k in range(3):
            one, Sk = align(
                rk.Trajectory(None, est.poses[k]), rk.Trajectory(None, ref.poses[k]), method
            )
            np.testing.assert_allclose(aligned.positions[k], one.positions, atol=1e-12)
        errors = ape(ref, aligned).errors
        assert errors.shape == (3, 30)


# -- KITTI -----------------------------------------------------------------------------


def _devkit_reference(gt, est, lengths, step):
    """The KITTI odometry devkit's rule written out with 4x4 matrices and loops
    (evaluate_odometry.cpp: trajectoryDistances, lastFrameFromSegmentLength,
    calcSequenceErrors), as the independent reference."""
    dist = [0.0]
    for i in range(1, len(gt)):
        dist.append(dist[-1] + np.linalg.norm(gt[i][:3, 3] - gt[i - 1][:3, 3]))
    errors = []
    for first in range(0, len(gt), step):
        for L in lengths:
            last = next((i for i in range(first, len(gt)) if dist[i] > dist[first] + L), -1)
            if last == -1:
                continue
            d_gt = np.linalg.inv(gt[first]) @ gt[last]
            d_est = np.linalg.inv(est[first]) @ est[last]
            E = np.linalg.inv(d_est) @ d_gt
            angle = np.arccos(np.clip(0.5 * (np.trace(E[:3, :3]) - 1.0), -1.0, 1.0))
            errors.append((first, last, L, angle / L, np.linalg.norm(E[:3, 3]) / L))
    return errors


def test_kitti_errors_follow_the_devkit_rule():
    rng = np.random.default_rng(11)
    n = 400
    # A car-like path: forward at ~1 m per frame, turning slowly; the estimate
    # accumulates small random motion errors (drift).
    steps = np.zeros((n, 6))
    steps[:, 0] = 1.0 + 0.1 * np.sin(np.arange(n) / 30)
    steps[:, 5] = 0.02 * np.sin(np.arange(n) / 50)
    inc = rk.Transform.exp(steps)
    noisy = inc @ rk.Transform.exp(
        rng.normal(0, [0.01, 0.01, 0.01, 1e-3, 1e-3, 1e-3], (n, 6))
    )
    gt_pq, est_pq = [np.eye(4)], [np.eye(4)]
    for k in range(n - 1):
        gt_pq.append(gt_pq[-1] @ inc[k].as_matrix())
        est_pq.append(est_pq[-1] @ noisy[k].as_matrix())
    gt = rk.Trajectory(None, rk.Transform.from_matrix(np.array(gt_pq), orthonormalize=True))
    est = rk.Trajectory(
        None, rk.Transform.from_matrix(np.array(est_pq), orthonormalize=True)
    )
    lengths = (50, 100, 200, 300)
    r = rk.trajectory.kitti_errors(gt, est, lengths=lengths, step=10)
    ref = _devkit_reference(gt.poses.as_matrix(), est.poses.as_matrix(), lengths, 10)
    assert len(ref) == len(r.first) > 40
    np.testing.assert_array_equal(r.first, [e[0] for e in ref])
    np.testing.assert_array_equal(r.last, [e[1] for e in ref])
    np.testing.assert_array_equal(r.length, [e[2] for e in ref])
    np.testing.assert_allclose(r.translation, [e[4] for e in ref], rtol=1e-9)
    # The devkit's acos((tr R - 1) / 2) rounds to ~1e-8 rad at these ~1e-2 rad
    # angles (acos' slope near 1); the reference's own rounding sets the bound.
    np.testing.assert_allclose(r.rotation, [e[3] for e in ref], rtol=1e-6)
    t_mean = np.mean([e[4] for e in ref])
    assert r.translation_percent == pytest.approx(100 * t_mean, rel=1e-9)
    r_mean = np.mean([e[3] for e in ref])
    assert r.rotation_deg_per_100m == pytest.approx(np.degrees(r_mean) * 100, rel=1e-6)
    for L in lengths:
        sel = [e for e in ref if e[2] == L]
        assert r.table[L][2] == len(sel)
        assert r.table[L][0] == pytest.approx(100 * np.mean([e[4] for e in sel]), rel=1e-9)


def test_kitti_errors_of_a_scaled_estimate():
    x = np.arange(0.0, 1000.0, 0.5)
    gt = rk.Trajectory(None, rk.Transform(translation=np.c_[x, 0 * x, 0 * x]))
    est = gt.transform(rk.Similarity(scale=1.02))
    r = rk.trajectory.kitti_errors(gt, est)
    # Each segment spans the first 0.5 m step past L: 2 % of (L + 0.5) m per L.
    for L, (t, rot, count) in r.table.items():
        assert t == pytest.approx(2.0 * (L + 0.5) / L, rel=1e-12)
        assert rot == 0.0
        assert count == len(range(0, len(x), 10)) - sum(x[::10] + L >= x[-1])


@pytest.mark.parametrize("n", [1, 2, 3, 4, 7, 10, 1000, 1001])
def test_statistics_equal_numpy(n):
    e = np.abs(np.random.default_rng(n).normal(size=n))
    s = rk.trajectory.statistics(e)
    assert s["median"] == np.median(e) and s["min"] == e.min() and s["max"] == e.max()
    np.testing.assert_allclose(
        [s["mean"], s["std"], s["sse"], s["rmse"]],
        [e.mean(), e.std(), (e**2).sum(), np.sqrt((e**2).mean())],
        rtol=1e-14,
    )
    batch = rk.trajectory.statistics(np.stack([e, 2 * e]))
    np.testing.assert_allclose(batch["rmse"], [s["rmse"], 2 * s["rmse"]], rtol=1e-14)


@pytest.mark.parametrize("special", [np.nan, np.inf])
def test_statistics_min_max_with_a_nan_or_inf_as_numpy(special):
    e = np.abs(np.random.default_rng(3).normal(size=10))
    e[4] = special
    kept = e.copy()
    with np.errstate(invalid="ignore"):  # the deviations: inf - inf
        s = rk.trajectory.statistics(e)
    np.testing.assert_array_equal(e, kept)  # the errors are not reordered
    np.testing.assert_equal([s["min"], s["max"]], [e.min(), e.max()])


@pytest.mark.parametrize("n", [5, 16384 * 3 + 17])
def test_position_distances_in_blocks_equal_the_norm(n):
    """The blocked pass (above 16,384 rows) and the whole-array one, on strided
    views into 7-number poses as Transform stores them, against np.linalg.norm."""
    import importlib

    metrics = importlib.import_module("rigidkit.applications.trajectory.metrics")
    rng = np.random.default_rng(n)
    a, b = rng.normal(size=(n, 7)), rng.normal(size=(n, 7))
    got = metrics._distance(a[:, :3], b[:, :3])
    expected = np.linalg.norm(a[:, :3] - b[:, :3], axis=-1)
    np.testing.assert_allclose(got, expected, rtol=1e-15)
    # A batch broadcasting against one trajectory.
    batch = metrics._distance(np.stack([a[:, :3], b[:, :3]]), b[:, :3])
    np.testing.assert_allclose(batch[0], expected, rtol=1e-15)
    np.testing.assert_array_equal(batch[1], 0.0)


def test_statistics_of_torch_and_jax_errors_are_differentiable():
    """``rk.trajectory.statistics`` of a torch or JAX series: the same numbers as the
    NumPy path, in that namespace, with gradients equal to central differences."""
    torch = pytest.importorskip("torch")
    jax = pytest.importorskip("jax")
    rng = np.random.default_rng(7)
    e = rng.uniform(0.1, 2.0, size=7)
    ref = rk.trajectory.statistics(e)
    t = torch.tensor(e, requires_grad=True)
    got = rk.trajectory.statistics(t)
    for key, value in ref.items():
        assert torch.is_tensor(got[key])
        assert abs(float(got[key]) - value) <= 1e-12 * max(1.0, abs(value))
    h = 1e-6
    for key in ("rmse", "mean", "median", "std", "min", "max", "sse"):
        (g,) = torch.autograd.grad(rk.trajectory.statistics(t)[key], t)
        fd = np.empty_like(e)
        for i in range(e.size):
            up, down = e.copy(), e.copy()
            up[i] += h
            down[i] -= h
            fd[i] = (
                rk.trajectory.statistics(up)[key] - rk.trajectory.statistics(down)[key]
            ) / (2 * h)
        np.testing.assert_allclose(g.numpy(), fd, atol=1e-6)
    x = jax.numpy.asarray(e)  # float64 with jax_enable_x64, else float32
    gj = jax.jit(jax.grad(lambda x: rk.trajectory.statistics(x)["rmse"]))(x)
    (gt,) = torch.autograd.grad(rk.trajectory.statistics(t)["rmse"], t)
    rtol = 1e-12 if x.dtype == jax.numpy.float64 else 1e-6
    np.testing.assert_allclose(np.asarray(gj), gt.numpy(), rtol=rtol)


@pytest.mark.parametrize(
    "relation", ["translation", "rotation_angle", "rotation_part", "full", "point_distance"]
)
def test_dask_poses_give_lazy_metrics_equal_to_numpy(dask_array, relation):
    """APE and RPE (pairs by frames: from the length alone) of Dask poses compute
    nothing during the call, and equal the NumPy path's errors and statistics
    (which compute np.median, np.std... on the host: an independent reference)."""
    da = dask_array
    from dask.callbacks import Callback

    computes = []

    class Count(Callback):
        def _start(self, dsk):
            computes.append(1)

    t = np.arange(9) * 0.1
    a, b = rk.Transform.random(9, rng=3), rk.Transform.random(9, rng=4)

    def lazy(T):
        return rk.Trajectory(t, rk.Transform.from_pq(da.from_array(T.as_pq(), chunks=4)))

    for metric, kw in ((ape, {}), (rpe, {"delta": 2})):
        want = metric(rk.Trajectory(t, a), rk.Trajectory(t, b), relation=relation, **kw)
        with Count():
            got = metric(lazy(a), lazy(b), relation=relation, **kw)
        assert not computes, (metric.__name__, len(computes))
        assert type(got.errors).__module__.startswith("dask")
        np.testing.assert_allclose(got.errors.compute(), want.errors, rtol=0, atol=1e-14)
        for key, value in want.stats.items():
            assert type(got.stats[key]).__module__.startswith("dask"), key
            np.testing.assert_allclose(got.stats[key].compute(), value, rtol=1e-13)
