"""APE, RPE and alignment on torch and JAX poses: computed in the poses' namespace,
equal to the NumPy path, and differentiable: torch's autograd and jax.grad
against central differences of the NumPy computation, and under jax.jit."""

from __future__ import annotations

import numpy as np
import pytest

import rigidkit as rk

T = rk.trajectory
RELATIONS = ("translation", "rotation_angle", "rotation_part", "full", "point_distance")
N = 9
STAMPS = np.arange(N, dtype=np.float64) * 0.1


def _pq(seed, n=N):
    """Poses as ``(x, y, z, qw, qx, qy, qz)`` rows, a smooth random walk (so
    that metric-unit pairs exist) with quaternions not of unit norm."""
    rng = np.random.default_rng(seed)
    p = np.cumsum(rng.normal(0.0, 0.5, (n, 3)), axis=0)
    q = rk.Rotation.from_rotvec(np.cumsum(rng.normal(0.0, 0.3, (n, 3)), axis=0)).as_quat()
    return np.concatenate([p, q * rng.uniform(0.8, 1.2, (n, 1))], axis=1)


REF, EST = _pq(1), _pq(2)


def _traj(pq):
    return T.Trajectory(STAMPS, rk.Transform.from_pq(pq))


# Each case: a scalar of the estimate's poses (the reference fixed).
CASES = {
    "ape translation rmse": lambda r, e: T.ape(r, e).stats["rmse"],
    "ape rotation_angle mean": lambda r, e: T.ape(r, e, "rotation_angle").stats["mean"],
    "ape full max": lambda r, e: T.ape(r, e, "full").stats["max"],
    "ape rotation_part median": lambda r, e: T.ape(r, e, "rotation_part").stats["median"],
    "rpe translation std": lambda r, e: T.rpe(r, e).stats["std"],
    "rpe rotation_angle deg sse": lambda r, e: T.rpe(
        r, e, delta=2, relation="rotation_angle", degrees=True
    ).stats["sse"],
    "rpe point_distance min": lambda r, e: T.rpe(r, e, relation="point_distance").stats[
        "min"
    ],
    "rpe full 1 m all pairs": lambda r, e: T.rpe(
        r, e, delta=1.0, unit="meters", relation="full", all_pairs=True
    ).stats["rmse"],
    "sim3 then ape rmse": lambda r, e: T.ape(r, T.align(e, r, method="sim3")[0]).stats[
        "rmse"
    ],
    "se3 then rpe mean": lambda r, e: T.rpe(r, T.align(e, r, method="se3")[0]).stats[
        "mean"
    ],
    "yaw then ape sse": lambda r, e: T.ape(r, T.align(e, r, method="yaw")[0]).stats["sse"],
    "scale then ape mean": lambda r, e: T.ape(r, T.align(e, r, method="scale")[0]).stats[
        "mean"
    ],
}


def _central_differences(f, x, h=1e-6):
    g = np.zeros_like(x)
    for idx in np.ndindex(x.shape):
        up, down = x.copy(), x.copy()
        up[idx] += h
        down[idx] -= h
        g[idx] = (f(up) - f(down)) / (2 * h)
    return g


@pytest.mark.parametrize("metric", ["ape", "rpe"])
@pytest.mark.parametrize("relation", RELATIONS)
def test_errors_in_the_poses_namespace_equal_numpy(torch, jnp, metric, relation):
    fn = getattr(T, metric)
    expected = fn(_traj(REF), _traj(EST), relation=relation)
    for make in (lambda x: torch.tensor(x, requires_grad=True), jnp.asarray):
        got = fn(_traj(make(REF)), _traj(make(EST)), relation=relation)
        assert type(got.errors) is type(make(REF)) and got.errors.dtype == make(REF).dtype
        np.testing.assert_allclose(
            rk._validate.to_numpy(got.errors), expected.errors, rtol=1e-12, atol=1e-15
        )
        for k, v in expected.stats.items():
            assert float(rk._validate.to_numpy(got.stats[k])) == pytest.approx(v, rel=1e-12)
        np.testing.assert_array_equal(got.stamps, expected.stamps)
        if metric == "rpe":
            np.testing.assert_array_equal(got.pairs, expected.pairs)


def test_batched_ape_on_torch_equals_numpy(torch):
    ref = np.stack([REF, _pq(3)])
    est = np.stack([EST, _pq(4)])
    want = T.ape(_traj(ref), _traj(est), "full")
    got = T.ape(_traj(torch.tensor(ref)), _traj(torch.tensor(est)), "full")
    assert got.errors.shape == (2, N)
    np.testing.assert_allclose(got.errors.numpy(), want.errors, rtol=1e-12)
    for k in want.stats:
        np.testing.assert_allclose(got.stats[k].numpy(), want.stats[k], rtol=1e-12)


@pytest.mark.parametrize("case", list(CASES))
def test_torch_gradient_equals_central_differences(torch, case):
    fn = CASES[case]
    ref = _traj(REF)

    def f(pq):
        return float(fn(ref, _traj(pq)))

    x = torch.tensor(EST, requires_grad=True)
    value = fn(_traj(torch.tensor(REF)), _traj(x))
    assert float(value.detach()) == pytest.approx(f(EST), rel=1e-12)
    value.backward()
    fd = _central_differences(f, EST)
    assert np.abs(fd).max() > 1e-3  # the statistic depends on the poses
    # Central differences: O(h^2) truncation plus ~1e-16 / h rounding.
    np.testing.assert_allclose(x.grad.numpy(), fd, rtol=1e-6, atol=1e-7)


def _jax_against_torch(torch, jnp, case, jit):
    import jax

    fn = CASES[case]
    ref_j = _traj(jnp.asarray(REF))

    def f(pq):
        return fn(ref_j, _traj(pq))

    x = torch.tensor(EST, requires_grad=True)
    fn(_traj(torch.tensor(REF)), _traj(x)).backward()
    grads = [jax.grad(f)]
    if jit:
        value = float(fn(_traj(REF), _traj(EST)))
        assert float(jax.jit(f)(jnp.asarray(EST))) == pytest.approx(value, rel=1e-12)
        grads.append(jax.jit(jax.grad(f)))
    for grad in grads:
        np.testing.assert_allclose(
            np.asarray(grad(jnp.asarray(EST))), x.grad.numpy(), rtol=1e-10, atol=1e-13
        )


@pytest.mark.parametrize(
    "case,jit",
    [
        ("ape translation rmse", True),
        ("rpe translation std", False),
        ("ape full max", False),
    ],
)
def test_jax_grad_equals_torch(torch, jnp, case, jit):
    _jax_against_torch(torch, jnp, case, jit)


@pytest.mark.exhaustive
@pytest.mark.parametrize("case", [c for c in CASES if "1 m" not in c])
def test_jax_jit_of_every_case(torch, jnp, case):
    # jit compiles of the alignment's SVD take tens of seconds on a loaded machine.
    # Pairs in metres need pairs= under tracing (test_traced_poses_need_pairs...).
    _jax_against_torch(torch, jnp, case, True)


def test_traced_poses_need_pairs_for_a_metric_unit(jnp):
    import jax

    ref = _traj(REF)
    pairs = T.pair_indices(_traj(EST).poses, 1.0, unit="meters", all_pairs=True)

    def f(pq, **kw):
        return T.rpe(_traj(jnp.asarray(REF)), _traj(pq), **kw).stats["rmse"]

    with pytest.raises(rk.errors.RigidkitError, match="pairs="):
        jax.grad(lambda pq: f(pq, delta=1.0, unit="meters", all_pairs=True))(
            jnp.asarray(EST)
        )
    want = T.rpe(ref, _traj(EST), delta=1.0, unit="meters", all_pairs=True)
    np.testing.assert_array_equal(want.pairs, pairs)
    got = jax.jit(lambda pq: f(pq, pairs=pairs))(jnp.asarray(EST))
    assert float(got) == pytest.approx(want.stats["rmse"], rel=1e-12)
    fd = _central_differences(
        lambda pq: T.rpe(ref, _traj(pq), pairs=pairs).stats["rmse"], EST
    )
    np.testing.assert_allclose(
        np.asarray(jax.grad(lambda pq: f(pq, pairs=pairs))(jnp.asarray(EST))),
        fd,
        rtol=1e-6,
        atol=1e-7,
    )


def test_pairs_are_checked():
    ref, est = _traj(REF), _traj(EST)
    got = T.rpe(ref, est, pairs=[[0, 3], [2, 8]])
    assert got.pairs.tolist() == [[0, 3], [2, 8]] and got.errors.shape == (2,)
    with pytest.raises(rk.ShapeError, match=r"shape \(M, 2\)"):
        T.rpe(ref, est, pairs=[0, 3])
    with pytest.raises(rk.ShapeError, match=r"pairs\[1\] = \[2, 9\]") as info:
        T.rpe(ref, est, pairs=[[0, 3], [2, 9]])
    assert info.value.index == (1,)


def test_zero_error_has_a_finite_gradient(torch):
    # Identical positions: every error is 0 (a norm's kink); the subgradient 0.
    x = torch.tensor(REF, requires_grad=True)
    r = T.ape(_traj(torch.tensor(REF)), _traj(x))
    (r.stats["rmse"] + r.stats["std"] + r.stats["mean"]).backward()
    assert float(r.stats["rmse"].detach()) == 0.0
    assert torch.isfinite(x.grad).all() and float(x.grad.abs().max()) == 0.0


@pytest.mark.parametrize("method", ["nearest", "interpolate"])
def test_the_whole_job_on_torch_is_differentiable(torch, method):
    # associate (stamps: NumPy) -> align sim3 -> APE rmse + RPE mean, against
    # central differences of the NumPy job.
    rng = np.random.default_rng(5)
    t_est = np.sort(rng.uniform(0.05, 0.75, 6))
    ref = _traj(REF)

    def job(est):
        r, e = T.associate(ref_of(est), est, max_diff=0.03, method=method)
        e, _ = T.align(e, r, method="sim3")
        return T.ape(r, e).stats["rmse"] + T.rpe(r, e).stats["mean"]

    def ref_of(est):
        return ref if isinstance(est.positions, np.ndarray) else _traj(torch.tensor(REF))

    est_pq = _pq(6, n=6)
    x = torch.tensor(est_pq, requires_grad=True)
    value = job(T.Trajectory(t_est, rk.Transform.from_pq(x)))
    value.backward()

    def f(pq):
        return float(job(T.Trajectory(t_est, rk.Transform.from_pq(pq))))

    assert float(value.detach()) == pytest.approx(f(est_pq), rel=1e-12)
    np.testing.assert_allclose(
        x.grad.numpy(), _central_differences(f, est_pq), rtol=1e-6, atol=1e-7
    )


def test_associate_and_ape_under_jax_jit(jnp):
    import jax

    t_est = STAMPS[::2] + 0.004
    ref = _traj(REF)

    def f(pq):
        r, e = T.associate(
            _traj(jnp.asarray(REF)), T.Trajectory(t_est, rk.Transform.from_pq(pq))
        )
        return T.ape(r, e, "full").stats["rmse"]

    est_pq = _pq(7, n=len(t_est))
    r, e = T.associate(ref, T.Trajectory(t_est, rk.Transform.from_pq(est_pq)))
    want = T.ape(r, e, "full").stats["rmse"]
    assert float(jax.jit(f)(jnp.asarray(est_pq))) == pytest.approx(want, rel=1e-12)
    fd = _central_differences(
        lambda pq: float(
            T.ape(
                *T.associate(ref, T.Trajectory(t_est, rk.Transform.from_pq(pq))), "full"
            ).stats["rmse"]
        ),
        est_pq,
    )
    np.testing.assert_allclose(
        np.asarray(jax.grad(f)(jnp.asarray(est_pq))), fd, rtol=1e-6, atol=1e-7
    )
