"""rk.Trajectory: construction, indexing, geometry, interpolation, transforms."""

from __future__ import annotations

import numpy as np
import pytest

import rigidkit as rk

scipy_rotation = pytest.importorskip("scipy.spatial.transform")


def _screw(t, twist):
    """The constant-twist motion exp(t V), a closed form to interpolate."""
    return rk.Transform.exp(np.outer(t, twist))


def test_construction_checks_stamps_and_types():
    poses = rk.Transform.random(3, rng=0)
    with pytest.raises(rk.TimestampError, match=r"stamps\[2\] = 1.0 repeats"):
        rk.Trajectory([0.0, 1.0, 1.0], poses)
    with pytest.raises(rk.TimestampError, match="goes backwards") as info:
        rk.Trajectory([0.0, 2.0, 1.0], poses)
    assert info.value.index == (2,)
    with pytest.raises(rk.TimestampError, match="not finite"):
        rk.Trajectory([0.0, np.nan, 1.0], poses)
    with pytest.raises(rk.ShapeError, match=r"shape \(3,\)"):
        rk.Trajectory([0.0, 1.0], poses)
    with pytest.raises(TypeError, match="Transform"):
        rk.Trajectory([0.0], np.zeros((1, 7)))
    with pytest.raises(rk.ShapeError, match="time axis"):
        rk.Trajectory(None, rk.Transform())


def test_is_immutable_and_copies_its_stamps():
    stamps = np.array([0.0, 1.0])
    traj = rk.Trajectory(stamps, rk.Transform.random(2, rng=0))
    stamps[0] = 5.0
    assert traj.stamps[0] == 0.0
    with pytest.raises(ValueError):
        traj.stamps[0] = 1.0
    with pytest.raises(AttributeError):
        traj.stamps = None


def test_indexing_keeps_stamps_with_poses():
    traj = rk.Trajectory(np.arange(6.0) * 0.5, rk.Transform.random(6, rng=1))
    p = np.asarray(traj.positions)
    sub = traj[1:5:2]
    assert sub.stamps.tolist() == [0.5, 1.5]
    np.testing.assert_array_equal(sub.positions, p[1:5:2])
    mask = np.array([True, False, False, True, True, False])
    np.testing.assert_array_equal(traj[mask].stamps, [0.0, 1.5, 2.0])
    np.testing.assert_array_equal(traj[np.array([0, -1])].positions, p[[0, -1]])
    one = traj[2]
    assert isinstance(one, rk.Transform) and one.single
    np.testing.assert_array_equal(one.translation, p[2])
    with pytest.raises(rk.TimestampError):
        traj[np.array([3, 1])]  # out of order: stamps would go backwards
    assert len(traj) == 6 and bool(traj) and not bool(traj[:0])


def test_path_length_duration_and_batches():
    x = np.array([0.0, 3.0, 3.0, 0.0])
    y = np.array([0.0, 0.0, 4.0, 0.0])
    traj = rk.Trajectory([1.0, 2.0, 4.0, 7.0], rk.Transform(translation=np.c_[x, y, 0 * x]))
    assert traj.path_length == 3.0 + 4.0 + 5.0
    assert traj.duration == 6.0
    batch = rk.Trajectory(
        None, rk.Transform(translation=np.stack([np.c_[x, y, 0 * x]] * 2))
    )
    assert batch.shape == (2, 4) and len(batch) == 4
    np.testing.assert_array_equal(batch.path_length, [12.0, 12.0])
    with pytest.raises(rk.TimestampError):
        _ = batch.duration


def test_at_slerp_follows_a_screw_motion_exactly():
    twist = np.array([1.0, -0.5, 0.2, 0.3, 0.1, -0.4])
    t = np.array([0.0, 0.4, 1.0, 1.7, 2.0])
    traj = rk.Trajectory(t, _screw(t, twist))
    q = np.array([0.0, 0.1, 0.55, 1.3, 2.0])
    got = traj.at(q)
    assert got.stamps.tolist() == q.tolist()
    assert bool(got.poses.approx_equal(_screw(q, twist), atol=1e-14).all())


def test_at_linear_equals_scipy_slerp_and_np_interp():
    rng = np.random.default_rng(2)
    t = np.sort(rng.uniform(0, 10, 8))
    traj = rk.Trajectory(t, rk.Transform.random(8, rng=rng))
    q = np.sort(rng.uniform(t[0], t[-1], 20))
    got = traj.at(q, method="linear")
    R = scipy_rotation.Rotation.from_quat(traj.poses.rotation.as_quat(scalar_first=False))
    expected = scipy_rotation.Slerp(t, R)(q).as_quat()
    np.testing.assert_allclose(
        got.poses.rotation.as_quat(scalar_first=False, canonical=True),
        expected * np.sign(expected[:, 3:]),
        atol=1e-14,
    )
    p = np.asarray(traj.positions)
    for k in range(3):
        np.testing.assert_allclose(
            got.positions[:, k], np.interp(q, t, p[:, k]), atol=1e-13
        )


def test_at_spline_is_smooth_and_exact_on_a_screw_motion():
    # Cubic B-splines reproduce linear functions: on uniformly sampled constant-twist
    # motion the spline is the motion itself, away from the two end segments.
    twist = np.array([0.5, 0.0, 0.1, 0.0, 0.2, 0.3])
    t = np.linspace(0.0, 4.0, 9)
    traj = rk.Trajectory(t, _screw(t, twist))
    q = np.linspace(1.0, 3.0, 7)
    got = traj.at(q, method="spline")
    assert bool(got.poses.approx_equal(_screw(q, twist), atol=1e-12).all())
    whole = traj.at(np.linspace(0.0, 4.0, 50), method="spline")
    assert len(whole) == 50


def test_at_outside_the_range_names_it():
    traj = rk.Trajectory([1.0, 2.0], rk.Transform.random(2, rng=0))
    with pytest.raises(rk.OutOfRangeError, match=r"2.5 lies outside .* \[1.0, 2.0\]"):
        traj.at([1.5, 2.5])
    with pytest.raises(ValueError, match="method"):
        traj.at([1.5], method="cubic")


def test_at_on_a_batch():
    twist = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.5])
    t = np.arange(4.0)
    poses = _screw(t, twist)
    batch = rk.Trajectory(t, rk.Transform.from_pq(np.stack([poses.as_pq()] * 3)))
    got = batch.at([0.5, 2.5])
    assert got.shape == (3, 2)
    assert bool(
        got.poses.approx_equal(_screw(np.array([0.5, 2.5]), twist), atol=1e-14).all()
    )


def test_transform_by_a_similarity_scales_positions():
    traj = rk.Trajectory([0.0, 1.0], rk.Transform.random(2, rng=3))
    S = rk.Similarity(
        scale=2.5, rotation=rk.Rotation.from_rotvec([0.1, 0.2, 0.3]), translation=[1, 2, 3]
    )
    moved = traj.transform(S)
    M = S.as_matrix()
    expected_p = (M[:3, :3] @ np.asarray(traj.positions).T).T + M[:3, 3]
    np.testing.assert_allclose(moved.positions, expected_p, atol=1e-14)
    R_S = S.rotation.as_matrix()
    np.testing.assert_allclose(
        moved.poses.rotation.as_matrix(), R_S @ traj.poses.rotation.as_matrix(), atol=1e-15
    )
    T = rk.Transform.random(rng=4)
    np.testing.assert_allclose(
        traj.transform(T).poses.as_matrix(),
        T.as_matrix() @ traj.poses.as_matrix(),
        atol=1e-14,
    )


def test_velocities_of_a_constant_twist():
    twist = np.array([1.0, 0.0, 0.5, 0.0, 0.0, 0.25])
    t = np.linspace(0.0, 2.0, 11)
    traj = rk.Trajectory(t, _screw(t, twist))
    np.testing.assert_allclose(
        traj.velocities(frame="body"), np.tile(twist, (11, 1)), atol=1e-12
    )


def test_plot_functions_draw_on_new_or_given_axes():
    pytest.importorskip("matplotlib")
    t = np.linspace(0.0, 2.0, 20)
    traj = rk.Trajectory(t, _screw(t, np.array([1.0, 0.0, 0.2, 0.0, 0.0, 1.0])))
    ax = rk.trajectory.plot(
        [traj, traj.transform(rk.Transform(translation=[0, 1, 0]))], labels=["a", "b"]
    )
    assert len(ax.lines) == 2 and ax.get_legend() is not None
    ax3 = rk.trajectory.plot(traj, plane="3d")
    assert ax3.name == "3d"
    result = rk.trajectory.ape(traj, traj.transform(rk.Transform(translation=[0, 0, 0.1])))
    ax = rk.trajectory.plot_errors(result)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), result.errors)
    ax = rk.trajectory.plot_error_colored(traj, result.errors, plane="xz")
    assert len(ax.collections) == 1
    with pytest.raises(ValueError, match="plane"):
        rk.trajectory.plot(traj, plane="xyz")


def test_torch_poses_give_the_numpy_numbers():
    torch = pytest.importorskip("torch")
    a = rk.Transform.random(12, rng=5)
    b = rk.Transform.random(12, rng=6)
    t = np.arange(12.0)
    ref, est = rk.Trajectory(t, a), rk.Trajectory(t, b)
    ref_t = rk.Trajectory(t, rk.Transform.from_pq(torch.tensor(a.as_pq())))
    est_t = rk.Trajectory(t, rk.Transform.from_pq(torch.tensor(b.as_pq())))
    assert isinstance(ref_t.positions, torch.Tensor)
    assert ref_t.path_length == pytest.approx(ref.path_length, rel=1e-14)
    for relation in ("translation", "full", "rotation_angle"):
        np.testing.assert_allclose(
            rk.trajectory.rpe(ref_t, est_t, relation=relation).errors,
            rk.trajectory.rpe(ref, est, relation=relation).errors,
            rtol=1e-12,
        )
        np.testing.assert_allclose(
            rk.trajectory.ape(ref_t, est_t, relation=relation).errors,
            rk.trajectory.ape(ref, est, relation=relation).errors,
            rtol=1e-12,
        )


def _screw_keys(n=7, seed=3):
    """Poses with sizeable rotations between stamps (rotation vectors, positions)."""
    rng = np.random.default_rng(seed)
    return rng.normal(0, 0.6, (n, 3)), rng.normal(0, 2.0, (n, 3))


@pytest.mark.parametrize("method", ["slerp", "linear", "spline"])
def test_torch_and_jax_trajectories_keep_their_namespace(torch, jnp, method):
    rv, p = _screw_keys()
    t = np.array([0.0, 0.4, 1.0, 1.7, 2.0, 3.1, 4.0])
    q = np.array([0.1, 0.4, 1.35, 2.999, 4.0])
    ref = rk.Trajectory(t, rk.Transform(rk.Rotation.from_rotvec(rv), p))
    for xp in (torch, jnp):
        traj = rk.Trajectory(
            t, rk.Transform(rk.Rotation.from_rotvec(xp.asarray(rv)), xp.asarray(p))
        )
        at = traj.at(q, method=method)
        assert type(at.positions) is type(traj.positions)
        np.testing.assert_allclose(
            np.asarray(at.positions), ref.at(q, method=method).positions, rtol=1e-13
        )
        np.testing.assert_allclose(
            np.asarray(at.poses.rotation.as_matrix()),
            ref.at(q, method=method).poses.rotation.as_matrix(),
            rtol=1e-13,
            atol=1e-15,
        )
        length = traj.path_length
        assert type(length) is type(traj.positions) and length.shape == ()
        assert float(length) == pytest.approx(ref.path_length, rel=1e-14)
        v = traj.velocities(frame="body")
        assert type(v) is type(traj.positions)
        np.testing.assert_allclose(
            np.asarray(v), ref.velocities(frame="body"), rtol=1e-12, atol=1e-14
        )
        S = rk.Similarity(scale=1.5, rotation=rk.Rotation.from_rotvec([0, 0.3, 0]))
        moved = traj.transform(S)
        assert type(moved.positions) is type(traj.positions)
        np.testing.assert_allclose(
            np.asarray(moved.positions), ref.transform(S).positions, rtol=1e-13
        )


def test_torch_and_jax_batched_at_keeps_the_time_axis(torch, jnp):
    rv, p = _screw_keys(n=5)
    rv2, p2 = _screw_keys(n=5, seed=4)
    t = np.arange(5.0)
    rvb, pb = np.stack([rv, rv2]), np.stack([p, p2])
    ref = rk.Trajectory(t, rk.Transform(rk.Rotation.from_rotvec(rvb), pb))
    q = np.array([0.5, 2.25, 3.75])
    for xp in (torch, jnp):
        traj = rk.Trajectory(
            t, rk.Transform(rk.Rotation.from_rotvec(xp.asarray(rvb)), xp.asarray(pb))
        )
        at = traj.at(q)
        assert at.shape == (2, 3) and type(at.positions) is type(traj.positions)
        np.testing.assert_allclose(
            np.asarray(at.positions), ref.at(q).positions, rtol=1e-13
        )


@pytest.mark.parametrize("method", ["slerp", "linear"])
def test_torch_autograd_through_at_matches_finite_differences(torch, method):
    """d(sum of interpolated positions . w)/d(rotation vectors, positions) by
    torch's autograd against central differences of the NumPy computation."""
    rv, p = _screw_keys(n=5)
    t = np.array([0.0, 0.5, 1.5, 2.0, 3.0])
    q = np.array([0.2, 0.9, 1.6, 2.7])
    w = np.random.default_rng(1).normal(size=(len(q), 3))

    def f(rv, p):
        traj = rk.Trajectory(t, rk.Transform(rk.Rotation.from_rotvec(rv), p))
        return float(np.sum(traj.at(q, method=method).positions * w))

    rv_t = torch.tensor(rv, requires_grad=True)
    p_t = torch.tensor(p, requires_grad=True)
    traj = rk.Trajectory(t, rk.Transform(rk.Rotation.from_rotvec(rv_t), p_t))
    value = (traj.at(q, method=method).positions * torch.tensor(w)).sum()
    assert float(value.detach()) == pytest.approx(f(rv, p), rel=1e-13)
    value.backward()
    h = 1e-6
    for x, grad in ((rv, rv_t.grad.numpy()), (p, p_t.grad.numpy())):
        fd = np.zeros_like(x)
        for idx in np.ndindex(x.shape):
            up, down = x.copy(), x.copy()
            up[idx] += h
            down[idx] -= h
            args = (up, p) if x is rv else (rv, up)
            args_down = (down, p) if x is rv else (rv, down)
            fd[idx] = (f(*args) - f(*args_down)) / (2 * h)
        # Central differences: O(h^2) truncation plus ~1e-16 / h rounding.
        np.testing.assert_allclose(grad, fd, rtol=1e-7, atol=1e-8)
    # The screw motion moves the positions with the rotations; "linear" does not.
    assert (np.abs(rv_t.grad.numpy()).max() > 0.1) == (method == "slerp")


def test_torch_stamps_stay_on_the_graph_and_are_checked(torch):
    """Stamps of torch are kept as torch (duration's gradient is d(t[-1] - t[0])/dt,
    by hand: -1 at the first stamp, +1 at the last), their values checked while
    concrete, and searched on the host (``at`` equals the NumPy stamps' result)."""
    poses = rk.Transform.random(4, rng=2)
    t = torch.tensor([0.0, 0.5, 1.25, 2.0], dtype=torch.float64, requires_grad=True)
    traj = rk.Trajectory(t, poses)
    assert traj.stamps is t
    (grad,) = torch.autograd.grad(traj.duration, t)
    np.testing.assert_array_equal(grad.numpy(), [-1.0, 0.0, 0.0, 1.0])
    np.testing.assert_allclose(
        traj.at([0.3, 1.9]).poses.as_pq(),
        rk.Trajectory(t.detach().numpy(), poses).at([0.3, 1.9]).poses.as_pq(),
        rtol=0,
        atol=1e-15,
    )
    with pytest.raises(rk.TimestampError, match="goes backwards") as info:
        rk.Trajectory(torch.tensor([0.0, 2.0, 1.0, 3.0]), poses)
    assert info.value.index == (2,)
    with pytest.raises(rk.ShapeError, match=r"shape \(4,\)"):
        rk.Trajectory(torch.zeros(3), poses)
    with rk.set_validation(False):  # the value checks are off; the shape's stays
        rk.Trajectory(torch.tensor([0.0, 2.0, 1.0, 3.0]), poses)


def test_dask_stamps_stay_lazy(dask_array):
    da = dask_array
    from dask.callbacks import Callback

    computes = []

    class Count(Callback):
        def _start(self, dsk):
            computes.append(1)

    stamps = da.from_array(np.array([0.0, 0.5, 1.25, 2.0]), chunks=2)
    with Count():
        duration = rk.Trajectory(stamps, rk.Transform.identity(4)).duration
    assert not computes and type(duration).__module__.startswith("dask")
    assert float(duration.compute()) == 2.0
