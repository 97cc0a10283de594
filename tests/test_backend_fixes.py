"""Regression tests: functions that read values in Python broke jax.jit, Dask laziness
and torch.compile (issue 22).

Each test runs a call under the transform and compares it with the same call on
NumPy (the reference: the eager NumPy path, itself tested against scipy and
closed forms elsewhere), with value checks on and off (``rk.set_validation``).
Dask calls must compute nothing (a callback counts graph executions) and give the
NumPy result after ``.compute()``. The generated matrix (tests/backend_matrix/)
covers every public callable; these are the failures found, small and fast.
"""

from __future__ import annotations

import numpy as np
import pytest

import rigidkit as rk

needs = pytest.mark.needs


@pytest.fixture(params=[True, False], ids=["checks", "no-checks"])
def validation(request):
    with rk.set_validation(request.param):
        yield request.param


class _Computes:
    """Counts Dask graph executions (``with _Computes() as c: ...; c.n``)."""

    def __enter__(self):
        from dask.callbacks import Callback

        outer = self
        self.n = 0

        class Count(Callback):
            def _start(self, dsk):
                outer.n += 1

        self._cb = Count()
        self._cb.__enter__()
        return self

    def __exit__(self, *exc):
        self._cb.__exit__(*exc)


def lazily(dask_array, fn, *numpy_args, chunks=2):
    """``fn`` on Dask versions of ``numpy_args``: (result, computes during the call)."""
    args = [dask_array.from_array(a, chunks=chunks) for a in numpy_args]
    with _Computes() as c:
        out = fn(*args)
    return out, c.n


@pytest.fixture
def keys():
    rng = np.random.default_rng(7)
    times = np.cumsum(rng.uniform(0.5, 1.5, 6))
    rotations = rk.Rotation.random(6, rng)
    transforms = rk.Transform.exp(rng.normal(size=(6, 6)))
    return times, rotations, transforms


def _interpolators(times, rotations, transforms):
    """name -> (interpolator's call of query times, queries within its range)."""
    span = times[-1] - times[0]
    inside = times[0] + span * np.array([0.0, 0.13, 0.5, 0.77, 1.0])
    bspline_t = 3.0 * np.array([0.0, 0.3, 0.5, 0.91, 1.0])
    return {
        "Slerp": (lambda q: rk.Slerp(times, rotations)(q).as_quat(), inside),
        "Slerp-Transform": (lambda q: rk.Slerp(times, transforms)(q).as_matrix(), inside),
        "RotationSpline": (
            lambda q: rk.RotationSpline(times, rotations)(q).as_quat(),
            inside,
        ),
        "RotationSpline-rate": (
            lambda q: rk.RotationSpline(times, rotations)(q, 1, frame="world"),
            inside,
        ),
        "RotationSpline-extrapolated": (
            lambda q: rk.RotationSpline(times, rotations, extrapolate=True)(
                q, 2, frame="body"
            ),
            inside + np.array([-1.0, 0.0, 0.0, 0.0, 1.0]),
        ),
        "BSplineSO3": (lambda q: rk.BSplineSO3(rotations)(q, 1, frame="body"), bspline_t),
        "BSplineSE3": (lambda q: rk.BSplineSE3(transforms)(q).as_matrix(), bspline_t),
    }


INTERPOLATORS = [
    "Slerp",
    "Slerp-Transform",
    "RotationSpline",
    "RotationSpline-rate",
    "RotationSpline-extrapolated",
    "BSplineSO3",
    "BSplineSE3",
]


@pytest.mark.parametrize(
    "name, checks",
    [(name, True) for name in INTERPOLATORS]
    + [(name, False) for name in ("Slerp", "RotationSpline", "BSplineSO3")],
)
def test_interpolators_trace_under_jit(name, checks, keys, jax, jnp):
    """Query times stay JAX arrays (they were turned into NumPy), checks on or off."""
    fn, q = _interpolators(*keys)[name]
    with rk.set_validation(checks):
        out = jax.jit(fn)(jnp.asarray(q))
    assert np.allclose(np.asarray(out), fn(q), rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", INTERPOLATORS)
def test_interpolators_stay_lazy_on_dask(name, keys, dask_array):
    """Dask query times give a Dask result and compute nothing during the call."""
    fn, q = _interpolators(*keys)[name]
    out, computes = lazily(dask_array, fn, q)
    assert computes == 0
    assert isinstance(out, dask_array.Array)
    assert np.allclose(out.compute(), fn(q), rtol=0, atol=1e-12)


def test_interpolation_range_checked_at_compute_time_on_dask(keys, dask_array):
    times, rotations, _ = keys
    q = np.array([times[0], times[-1] + 0.5, times[1]])
    out, computes = lazily(dask_array, lambda t: rk.Slerp(times, rotations)(t).as_quat(), q)
    assert computes == 0
    with pytest.raises(rk.OutOfRangeError, match=r"at index \(1,\)"):
        out.compute()


@pytest.mark.parametrize(
    "name, checks",
    [(name, True) for name in INTERPOLATORS] + [("RotationSpline", False)],
)
def test_interpolators_compile_with_numpy_knots(name, checks, keys, torch):
    """torch.compile(fullgraph=True) of an interpolator made inside the compiled
    function from NumPy knots and keyframes of torch tensors, queried at torch
    times. TorchDynamo traces the NumPy knots as graph values, whose dtype it
    cannot read and whose values it cannot branch on, so the knot and range checks
    must skip them (they broke the graph: "Unsupported ndarray attribute access")."""
    times, rotations, transforms = keys

    def fn(q, quats, poses):
        R, T = rk.Rotation.from_quat(quats), rk.Transform.from_pq(poses)
        return _interpolators(times, R, T)[name][0](q)

    q = _interpolators(*keys)[name][1]
    args = (q, rotations.as_quat(), transforms.as_pq())
    torch._dynamo.reset()
    compiled = torch.compile(fn, fullgraph=True, backend="eager")
    with rk.set_validation(checks):
        out = compiled(*[torch.tensor(a) for a in args])
    assert isinstance(out, torch.Tensor)
    assert np.allclose(out.numpy(), fn(*args), rtol=0, atol=1e-12)
    if name == "Slerp":  # and against scipy's Slerp, an independent reference
        from scipy.spatial.transform import Rotation as SciRotation
        from scipy.spatial.transform import Slerp as SciSlerp

        sci_keys = SciRotation.from_quat(rotations.as_quat(), scalar_first=True)
        want = SciSlerp(times, sci_keys)(q).as_matrix()
        got = rk.Rotation.from_quat(out.numpy()).as_matrix()
        assert np.allclose(got, want, rtol=0, atol=1e-14)


def test_compiled_rotation_spline_gradient_in_the_keyframes(keys, torch):
    """Inside torch.compile the spline's Newton solve is a while_loop on values cut
    from autograd, then one Newton step on the live equations (the implicit
    derivative at the solution; the loop has no backward). The gradient of a rate
    in the keyframe quaternions equals central differences of the NumPy spline."""
    times, rotations, _ = keys
    queries = times[0] + np.array([0.4, 1.3, 2.9])
    weights = np.random.default_rng(3).normal(size=(3, 3))

    def loss(quats):
        rate = rk.RotationSpline(times, rk.Rotation.from_quat(quats))(
            queries, 1, frame="body"
        )
        return (rate * weights).sum()

    quats = rotations.as_quat()
    x = torch.tensor(quats, requires_grad=True)
    torch._dynamo.reset()
    (grad,) = torch.autograd.grad(torch.compile(loss, backend="eager")(x), x)
    eps, fd = 1e-6, np.zeros_like(quats)
    for idx in np.ndindex(quats.shape):
        up, down = quats.copy(), quats.copy()
        up[idx] += eps
        down[idx] -= eps
        fd[idx] = (loss(up) - loss(down)) / (2 * eps)
    assert np.allclose(grad.numpy(), fd, rtol=0, atol=1e-6)


def test_knots_as_a_list_and_a_python_time_compile(keys, torch):
    """Knots given as a Python list and a query time as a Python float, inside
    torch.compile: both become NumPy arrays, which Dynamo traces."""
    times, rotations, _ = keys
    t_list, t_mid = times.tolist(), float(times[1] + 0.25)

    def f(q):
        R = rk.Rotation.from_quat(q)
        return rk.Slerp(t_list, R)(t_mid).as_quat(), rk.BSplineSO3(R)(1.5).as_quat()

    torch._dynamo.reset()
    quats = rotations.as_quat()
    got = torch.compile(f, fullgraph=True, backend="eager")(torch.tensor(quats))
    want = f(quats)
    for g, w in zip(got, want):
        assert np.allclose(g.numpy(), w, rtol=0, atol=1e-12)


@pytest.mark.parametrize("method", ["slerp", "linear", "spline"])
def test_trajectory_resampling_compiles_with_numpy_stamps(method, torch):
    """``Trajectory(stamps, poses).at(times)`` inside torch.compile with NumPy stamps
    and times (traced by Dynamo: their range check and ``np.shape`` read values)
    and poses from a tensor; equals the NumPy call."""
    x = np.random.default_rng(1).uniform(-0.5, 0.5, (6, 6))

    def f(x):
        traj = rk.Trajectory(np.arange(6) * 0.5, rk.Transform.exp(x))
        return traj.at(np.array([0.2, 1.3, 2.5]), method=method).poses.as_matrix()

    torch._dynamo.reset()
    out = torch.compile(f, fullgraph=True, backend="eager")(torch.tensor(x))
    assert np.allclose(out.numpy(), f(x), rtol=0, atol=1e-12)


def test_interpolators_on_torch_keep_the_graph(keys, torch):
    """Torch query times: the result is a tensor, differentiable in the times."""
    times, rotations, _ = keys
    spline = rk.RotationSpline(times, rotations)
    q = torch.tensor(
        [times[0] + 0.3, times[2] + 0.1], dtype=torch.float64, requires_grad=True
    )
    rate = spline(q, 1, frame="body")
    (g,) = torch.autograd.grad(rate.sum(), q)
    eps = 1e-6
    qn = q.detach().numpy()
    fd = (spline(qn + eps, 1, frame="body") - spline(qn - eps, 1, frame="body")) / (2 * eps)
    assert np.allclose(g.numpy(), fd.sum(axis=-1), atol=1e-6)
    assert np.allclose(
        spline(q.detach()).as_quat().numpy(), spline(qn).as_quat(), atol=1e-14
    )


# -- kinematics -------------------------------------------------------------------------


@pytest.fixture
def samples():
    rng = np.random.default_rng(11)
    times = np.cumsum(rng.uniform(0.05, 0.15, 7))
    rotations = rk.Rotation.from_rotvec(np.cumsum(rng.normal(scale=0.2, size=(7, 3)), 0))
    transforms = rk.Transform.exp(np.cumsum(rng.normal(scale=0.2, size=(7, 6)), 0))
    omega = rng.normal(size=(7, 3))
    return times, rotations, transforms, omega


def _kinematics(times, rotations, transforms, omega, twists=None):
    """name -> (function of one array argument, its NumPy value)."""
    kin = rk.kinematics
    twists = np.concatenate([omega, omega], -1) if twists is None else twists
    steps = np.diff(times, append=times[-1] + 0.1)
    return {
        "angular_velocity_from_samples": (
            lambda t: kin.angular_velocity_from_samples(rotations, t, frame="body"),
            times,
        ),
        "twist_from_samples": (
            lambda t: kin.twist_from_samples(transforms, t, frame="world"),
            times,
        ),
        "twist_from_screw": (
            lambda u: kin.twist_from_screw(omega[0], u, 0.3, 1.2),
            omega[1:4],
        ),
        "integrate_angular_velocity-rk4-float-dt": (
            lambda w: kin.integrate_angular_velocity(
                rotations[0], w, 0.01, frame="body", method="rk4"
            ).as_quat(),
            omega,
        ),
        "integrate_angular_velocity-rk4-steps": (
            lambda h: kin.integrate_angular_velocity(
                rotations[0], omega, h, frame="world", method="rk4"
            ).as_quat(),
            steps,
        ),
        "integrate_twist-midpoint-steps": (
            lambda h: kin.integrate_twist(
                transforms[0],
                twists,
                h,
                frame="body",
                method="midpoint",
            ).as_matrix(),
            steps,
        ),  # fmt: skip
    }


KINEMATICS = [
    "angular_velocity_from_samples",
    "twist_from_samples",
    "twist_from_screw",
    "integrate_angular_velocity-rk4-float-dt",
    "integrate_angular_velocity-rk4-steps",
    "integrate_twist-midpoint-steps",
]


@pytest.mark.parametrize("name", KINEMATICS)
def test_kinematics_trace_under_jit(name, samples, jax, jnp, validation):
    """``bool()`` of traced times, directions and steps; steps turned into NumPy."""
    fn, x = _kinematics(*samples)[name]
    out = jax.jit(fn)(jnp.asarray(x))
    assert np.allclose(np.asarray(out), fn(x), rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", KINEMATICS)
def test_kinematics_compile_fullgraph(name, samples, torch):
    """The same calls inside torch.compile(fullgraph=True), keyframes and samples
    as tensors: they broke the graph on data-dependent branches (the step times, a
    zero direction) and on ``str.startswith`` in the integrators."""
    times, rotations, transforms, omega = samples
    fn, x = _kinematics(*samples)[name]
    on_torch = _kinematics(
        times,
        rk.Rotation.from_quat(torch.tensor(rotations.as_quat())),
        rk.Transform.from_pq(torch.tensor(transforms.as_pq())),
        torch.tensor(omega),
        torch.tensor(np.concatenate([omega, omega], -1)),
    )[name][0]
    torch._dynamo.reset()
    out = torch.compile(on_torch, fullgraph=True, backend="eager")(torch.tensor(x))
    assert np.allclose(out.numpy(), fn(x), rtol=0, atol=1e-12)


def test_rk4_gradient_in_the_steps(samples, jax, jnp):
    """Non-uniform steps now carry gradients (the weights were NumPy constants)."""
    fn, h = _kinematics(*samples)["integrate_angular_velocity-rk4-steps"]
    dh = np.zeros_like(h)
    dh[2] = 1.0
    g = jax.grad(lambda s: fn(s)[-1, 1])(jnp.asarray(h))
    eps = 1e-6
    fd = (fn(h + eps * dh)[-1, 1] - fn(h - eps * dh)[-1, 1]) / (2 * eps)
    assert np.isclose(float(g[2]), fd, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("name", ["angular_velocity_from_samples", "twist_from_screw"])
def test_kinematics_value_checks_still_raise(name, samples):
    """The checks that moved stay: non-increasing times, a zero screw direction."""
    fn, x = _kinematics(*samples)[name]
    x = x.copy()
    x[2] = x[1] if name.startswith("angular") else 0.0
    err = rk.DegenerateInputError if name.startswith("angular") else rk.ZeroNormError
    with pytest.raises(err, match=r"\(1,\)" if name.startswith("angular") else r"\(2,\)"):
        fn(x)


# -- the geodesic (Karcher) mean -----------------------------------------------------------


@pytest.fixture
def spread():
    return np.random.default_rng(3).normal(scale=0.6, size=(8, 3))


def _geodesic_mean(r):
    return rk.Rotation.from_rotvec(r).mean(method="geodesic").as_rotvec()


def test_geodesic_mean_under_jit_vmap_and_grad(spread, jax, jnp, validation):
    """``float()`` of the step norm broke jit, vmap and grad; the traced loop runs
    ``max_iter`` steps, each mean frozen once converged, as the eager one stops."""
    ref = _geodesic_mean(spread)
    assert np.allclose(jax.jit(_geodesic_mean)(jnp.asarray(spread)), ref, atol=1e-14)
    if not validation:
        return
    both = jax.jit(jax.vmap(_geodesic_mean))(jnp.stack([spread, 0.5 * spread]))
    assert np.allclose(both[1], _geodesic_mean(0.5 * spread), atol=1e-14)
    grad = jax.jit(jax.grad(lambda r: _geodesic_mean(r)[1]))
    g = np.asarray(grad(jnp.asarray(spread)))
    eps = 1e-6
    for i, j in [(0, 0), (3, 1), (7, 2)]:
        d = np.zeros_like(spread)
        d[i, j] = eps
        fd = (_geodesic_mean(spread + d)[1] - _geodesic_mean(spread - d)[1]) / (2 * eps)
        assert np.isclose(g[i, j], fd, rtol=1e-6, atol=1e-9)


def test_geodesic_mean_of_transforms_under_jit(jax, jnp):
    tw = np.random.default_rng(4).normal(scale=0.5, size=(6, 6))

    def mean(x):
        return rk.Transform.exp(x).mean(method="geodesic").as_matrix()

    assert np.allclose(jax.jit(mean)(jnp.asarray(tw)), mean(tw), atol=1e-13)


def test_geodesic_mean_under_torch_func(spread, torch):
    from torch.func import grad, vmap

    r = torch.tensor(spread)
    both = vmap(_geodesic_mean)(torch.stack([r, 0.5 * r]))
    assert np.allclose(both[1].numpy(), _geodesic_mean(0.5 * spread), atol=1e-14)
    g = grad(lambda x: _geodesic_mean(x)[1])(r)
    eager = r.clone().requires_grad_()
    _geodesic_mean(eager)[1].backward()  # the eager loop, which reads the values
    assert np.allclose(g.numpy(), eager.grad.numpy(), atol=1e-10)


def test_geodesic_mean_under_torch_compile(spread, torch):
    """Inside torch.compile (no gradient asked) the Karcher loop is one while_loop
    node stopping at convergence (100 unrolled steps took Inductor 750 s), for a
    mean of rotations, of poses and of a generic group (Similarity): each equals
    the eager NumPy mean, with a batch of two means converging differently."""
    poses = rk.Transform.exp(np.random.default_rng(5).normal(scale=0.5, size=(2, 8, 6)))
    sims = rk.Similarity.exp(np.random.default_rng(6).normal(scale=0.3, size=(8, 7)))
    cases = [
        (_geodesic_mean, spread),
        (lambda x: rk.Transform.exp(x).mean(method="geodesic", axis=1).log(), poses.log()),
        (lambda x: rk.Similarity.exp(x).mean().log(), sims.log()),
    ]
    for fn, x in cases:
        torch._dynamo.reset()
        got = torch.compile(fn, fullgraph=True, backend="eager")(torch.tensor(x))
        assert np.allclose(got.numpy(), fn(x), rtol=0, atol=1e-12)
    # and the defining property, independent of the code: at the compiled rotation
    # mean mu the logs log(mu^-1 R_i) sum to zero (the Karcher condition)
    torch._dynamo.reset()
    mu = rk.Rotation.from_rotvec(
        torch.compile(_geodesic_mean, fullgraph=True, backend="eager")(
            torch.tensor(spread)
        ).numpy()
    )
    logs = (mu.inv() @ rk.Rotation.from_rotvec(spread)).as_rotvec()
    assert np.abs(logs.sum(axis=0)).max() < 1e-10


def test_reduce_of_one_rotation_compiles(torch):
    """``Rotation.reduce`` of a single rotation picks its group element with a 0-d
    index tensor, which torch read as a data-dependent Python int: torch.compile
    failed. The reference is scipy's ``reduce`` with the same group."""
    from scipy.spatial.transform import Rotation as SciRotation

    group = rk.Rotation.create_group("C3")
    q = rk.Rotation.from_rotvec([0.4, -1.9, 2.2]).as_quat()

    def f(q):
        return rk.Rotation.from_quat(q).reduce(group).as_matrix()

    torch._dynamo.reset()
    got = torch.compile(f, fullgraph=True, backend="eager")(torch.tensor(q))
    sci_group = SciRotation.from_quat(group.as_quat(), scalar_first=True)
    want = SciRotation.from_quat(q, scalar_first=True).reduce(sci_group).as_matrix()
    assert np.allclose(got.numpy(), want, rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    "kw, text",
    [
        ({"weights": np.ones(3)}, r"shape \(3,\) does not broadcast to the batch shape"),
        ({"weights": np.ones((2, 4))}, r"weights: shape \(2, 4\)"),
        ({"axis": "0"}, "axis must be None, an int or a tuple of ints"),
        ({"axis": 1.5}, "axis must be None, an int or a tuple of ints"),
        ({"axis": 1}, "axis 1 is out of bounds for a batch of 1 dimensions"),
    ],
)  # fmt: skip
@pytest.mark.parametrize("method", ["chordal", "geodesic"])
def test_mean_bad_weights_and_axis_are_shape_errors(kw, text, method):
    """Issue 20: NumPy's broadcast ValueError and an internal TypeError before."""
    R = rk.Rotation.random(4, np.random.default_rng(0))
    with pytest.raises(rk.ShapeError, match=text):
        R.mean(method=method, **kw)
    with pytest.raises(rk.ShapeError, match=text):
        rk.Transform.exp(np.ones((4, 6))).mean(method=method, **kw)


def test_mean_bad_weights_on_dask_is_a_shape_error(dask_array):
    R = rk.Rotation(
        dask_array.from_array(rk.Rotation.random(4, np.random.default_rng(0)).as_quat())
    )
    with pytest.raises(rk.ShapeError, match="weights"):
        R.mean(weights=np.ones(3))


# -- Jacobians on Dask -------------------------------------------------------------------


@pytest.mark.parametrize("side", ["right", "left"])
def test_jacobians_stay_lazy_on_dask(side, dask_array):
    """compose's identity and plus's Jacobians of a NumPy tangent were NumPy arrays
    next to a lazy result."""
    rng = np.random.default_rng(5)
    a, b, tau = rng.normal(size=(3, 4, 6))
    calls = {
        "compose": lambda x, y: rk.jacobians.compose(
            rk.Transform.exp(x), rk.Transform.exp(y), side=side
        ),
        "plus": lambda x, y: rk.jacobians.plus(rk.Transform.exp(x), tau, side=side),
        "between": lambda x, y: rk.jacobians.between(
            rk.Transform.exp(x), rk.Transform.exp(y), side=side
        ),
    }
    for name, fn in calls.items():
        out, computes = lazily(dask_array, fn, a, b)
        ref = fn(a, b)
        assert computes == 0, name
        for got, want in zip(out[1:], ref[1:]):
            assert isinstance(got, dask_array.Array), name
            assert got.shape == want.shape
            assert np.allclose(got.compute(), want, atol=1e-12), name
        assert np.allclose(out[0].as_matrix().compute(), ref[0].as_matrix(), atol=1e-12)


def test_twist_from_screw_takes_python_numbers_with_tensors(torch):
    """A Python pitch and magnitude with torch point and direction raised TypeError
    (``torch.abs`` of a NumPy array); now they meet the tensors' dtype and device."""
    q = np.array([1.0, 0.0, 0.0])
    u = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 1.0]])
    ref = rk.kinematics.twist_from_screw(q, u, 0.3, 1.2)
    out = rk.kinematics.twist_from_screw(torch.tensor(q), torch.tensor(u), 0.3, 1.2)
    assert isinstance(out, torch.Tensor)
    assert np.allclose(out.numpy(), ref, atol=1e-15)
    out32 = rk.kinematics.twist_from_screw(
        torch.tensor(q, dtype=torch.float32), torch.tensor(u, dtype=torch.float32), 0.3, 1.2
    )
    assert out32.dtype == torch.float32
