"""Integration of angular velocity and twists, and velocities from samples (issue 8 §4, §6).

References: closed-form motions (``R(t) = exp(hat(r(t)))`` with the body rate
``J_r(r) r'`` from the SO(3) right Jacobian), scipy's Rotation (a step-by-step
loop) and RotationSpline (whose rates are body-frame), scipy.linalg.expm for
SE(3), and the measured convergence orders.
"""

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.spatial.transform import Rotation as SciRot
from scipy.spatial.transform import RotationSpline

import rigidkit as rk
from conftest import LIE_GROUPS
from rigidkit.applications.kinematics import _scan
from rigidkit.applications.kinematics.integration import integrate
from rigidkit.applications.kinematics.samples import velocity_from_samples
from rigidkit.objects import registry

K = rk.kinematics


def angle(a, b):
    """Rotation angle between two rigidkit Rotations (float64 NumPy)."""
    return np.asarray(rk.conversions.quat_angle_between(a.as_quat(), b.as_quat()))


def r_of(t):
    return np.stack(
        [0.8 * np.sin(1.3 * t), 0.5 * np.cos(0.7 * t) - 0.5, 0.6 * np.sin(2.1 * t + 0.3)],
        -1,
    )


def r_dot(t):
    return np.stack(
        [1.04 * np.cos(1.3 * t), -0.35 * np.sin(0.7 * t), 1.26 * np.cos(2.1 * t + 0.3)], -1
    )


def sampled(t, frame):
    """Orientations R(t) = exp(hat(r(t))) and their angular velocity in ``frame``."""
    R = rk.Rotation.from_rotvec(r_of(t))
    wb = np.einsum("...ij,...j->...i", rk.so3.right_jacobian(r_of(t)), r_dot(t))
    return R, (wb if frame == "body" else R.apply(wb))


def test_constant_rate_reproduces_the_exponential_over_1e5_steps():
    w = np.array([0.3, -0.2, 0.5])
    N, dt = 100_000, 1e-3
    ref = rk.Rotation.from_rotvec(w * N * dt)
    for method in ("exact", "midpoint", "rk4"):
        for frame in ("body", "world"):
            traj = K.integrate_angular_velocity(
                rk.Rotation.identity(), np.tile(w, (N, 1)), dt, frame=frame, method=method
            )
            assert traj.shape == (N + 1,)
            assert angle(traj[-1], ref) < 1e-12
            norms = np.linalg.norm(traj.as_quat(), axis=-1)
            assert np.abs(norms - 1.0).max() < 1e-15 * 4


@pytest.mark.parametrize("frame", ["body", "world"])
def test_convergence_orders(frame):
    """Measured orders on a smooth non-commuting rate: 1 (ZOH), 2, 4."""
    T = 2.0
    expected = {"exact": 1.0, "midpoint": 2.0, "rk4": 4.0}
    for method, order in expected.items():
        errs = []
        for N in (100, 200, 400, 800):
            t = np.linspace(0.0, T, N + 1)
            R, w = sampled(t, frame)
            traj = K.integrate_angular_velocity(
                R[0], w[:-1], T / N, frame=frame, method=method
            )
            errs.append(float(angle(traj[-1], R[-1])))
        measured = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
        # pre-asymptotic at the coarsest steps, approaching the order
        assert abs(measured[-1] - order) < 0.08, (method, measured)
        assert np.all(np.abs(measured - order) < 0.25), (method, measured)


def test_non_uniform_steps_keep_the_order():
    T = 2.0
    errs = []
    for N in (100, 200, 400):
        u = np.linspace(0.0, 1.0, N + 1)
        t = T * (u + 0.15 * np.sin(np.pi * u) ** 2 * np.sign(np.cos(3 * u)) / np.pi / 3)
        t = np.sort(t)
        R, w = sampled(t, "body")
        traj = K.integrate_angular_velocity(
            R[0], w[:-1], np.diff(t), frame="body", method="rk4"
        )
        errs.append(float(angle(traj[-1], R[-1])))
        # every intermediate orientation is close too
        assert angle(traj, R).max() < 50 * errs[-1] + 1e-13
    measured = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(measured > 3.7), measured


def test_exact_method_equals_a_scipy_rotation_loop(rng):
    w = rng.standard_normal((200, 3))
    dt = 0.01
    R = SciRot.identity()
    body = [R]
    for k in range(200):
        R = R * SciRot.from_rotvec(w[k] * dt)
        body.append(R)
    ref = np.stack([r.as_quat(scalar_first=True) for r in body])
    traj = K.integrate_angular_velocity(rk.Rotation.identity(), w, dt, frame="body")
    assert angle(traj, rk.Rotation.from_quat(ref)).max() < 1e-13
    # world frame: left multiplication
    R = SciRot.identity()
    for k in range(200):
        R = SciRot.from_rotvec(w[k] * dt) * R
    trw = K.integrate_angular_velocity(np.eye(3), w, dt, frame="world")
    np.testing.assert_allclose(trw[-1], R.as_matrix(), atol=1e-13)
    assert trw.shape == (201, 3, 3)


def test_batched_trajectories_and_both_scan_bindings(rng, monkeypatch):
    """Many trajectories at once; the compiled scan and the prefix product agree."""
    from rigidkit.kernels.kinematics import integration as kint

    w = rng.standard_normal((3, 4, 500, 3))
    R0 = rk.Rotation.random((4,), rng=2)  # broadcasts against (3, 4)
    dt = rng.uniform(0.001, 0.01, 500)
    _scan.wait(kint.so3_chain, np.float64)
    ran = []
    real = _scan._numba_product
    monkeypatch.setattr(_scan, "_numba_product", lambda *a: ran.append(1) or real(*a))
    for method in ("exact", "rk4"):
        monkeypatch.setattr(_scan, "COMPILE_MIN", 1000)  # 6,000 steps: compiled
        a = K.integrate_angular_velocity(R0, w, dt, frame="body", method=method)
        assert a.shape == (3, 4, 501) and ran
        monkeypatch.setattr(_scan, "COMPILE_MIN", 10**12)  # the prefix product
        ran.clear()
        b = K.integrate_angular_velocity(R0, w, dt, frame="body", method=method)
        assert not ran
        assert angle(a, b).max() < 1e-13
        one = K.integrate_angular_velocity(R0[2], w[1, 2], dt, frame="body", method=method)
        assert angle(a[1, 2], one).max() < 1e-14


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 13, 64, 100])
def test_prefix_product_of_every_length(n, rng):
    """The pairwise prefix scheme equals the step-by-step product at odd and even
    lengths (the recursion's ends), both frames."""
    from rigidkit.kernels.kinematics import integration as kint

    q0 = rk.Rotation.random((2,), rng=n).as_quat()
    inc = rk.Rotation.random((2, n), rng=n + 1).as_quat()
    for body in (0, 1):
        got = _scan._prefix_product(kint.so3_chain, body, q0, inc, (2,), np)
        want = [q0]
        for k in range(n):
            a, b = rk.Rotation.from_quat(want[-1]), rk.Rotation.from_quat(inc[:, k])
            want.append((a @ b if body else b @ a).as_quat())
        want = rk.Rotation.from_quat(np.stack(want, axis=1))
        assert angle(rk.Rotation.from_quat(got), want).max() < 1e-14


def test_no_call_compiles_the_scan(rng, monkeypatch):
    """A cold scan is built on the engine's background thread, never the caller's;
    calls made before it is ready get the prefix product, later ones the scan."""
    import threading

    from rigidkit._engine import numba_backend

    if not numba_backend.available():
        pytest.skip("numba is not available")
    built_on = []
    real = _scan._build

    def build(*args):
        built_on.append(threading.current_thread() is threading.main_thread())
        return real(*args)

    # A cold start: no scan ready, no job queued.
    monkeypatch.setattr(_scan, "_SCANS", {})
    monkeypatch.setattr(numba_backend, "_PENDING", {})
    monkeypatch.setattr(_scan, "_build", build)
    monkeypatch.setattr(_scan, "COMPILE_MIN", 2000)
    w = rng.standard_normal((3000, 3)).astype(np.float32)
    R0 = rk.Rotation.identity(dtype=np.float32)
    first = K.integrate_angular_velocity(R0, w, 1e-3, frame="world")
    numba_backend.drain()
    assert built_on == [False]
    assert ("so3_chain", 4, "f") in _scan._SCANS
    ran = []
    real_product = _scan._numba_product
    monkeypatch.setattr(
        _scan, "_numba_product", lambda *a: ran.append(1) or real_product(*a)
    )
    second = K.integrate_angular_velocity(R0, w, 1e-3, frame="world")
    assert ran and second.dtype == np.float32
    assert angle(first, second).max() < 1e-5


def test_a_scan_ready_mid_call_takes_over(rng, monkeypatch):
    """Waiting for the scan, a long call runs the prefix product chunk by chunk
    (each from the last state) and hands the rest to the scan once it is ready."""
    from rigidkit.kernels.kinematics import integration as kint

    _scan.wait(kint.so3_chain, np.float64)
    key = ("so3_chain", 4, "d")
    scan = _scan._SCANS[key]
    w = rng.standard_normal((2, 1000, 3))
    R0 = rk.Rotation.random((2,), rng=5)
    monkeypatch.setattr(_scan, "COMPILE_MIN", 10**12)
    ref = K.integrate_angular_velocity(R0, w, 0.01, frame="body", method="rk4")
    monkeypatch.setattr(_scan, "COMPILE_MIN", 100)
    monkeypatch.setattr(_scan, "CHUNK", 300)  # 150 steps of both trajectories
    monkeypatch.setattr(_scan, "_SCANS", {})  # as if not built yet
    monkeypatch.setattr(_scan, "prepare", lambda *a: None)
    chunks, ran = [], []
    real_prefix, real_numba = _scan._prefix_product, _scan._numba_product

    def prefix(*a):
        chunks.append(a[3].shape)
        if len(chunks) == 2:
            _scan._SCANS[key] = scan  # lands during the second chunk
        return real_prefix(*a)

    monkeypatch.setattr(_scan, "_prefix_product", prefix)
    monkeypatch.setattr(
        _scan, "_numba_product", lambda *a: ran.append(a[6]) or real_numba(*a)
    )
    got = K.integrate_angular_velocity(R0, w, 0.01, frame="body", method="rk4")
    assert chunks == [(2, 150, 4)] * 2 and ran == [700]
    assert got.shape == (2, 1001)
    assert angle(got, ref).max() < 1e-13


def test_float32_and_torch_jax_paths(rng, torch, jnp):
    w = rng.standard_normal((300, 3))
    ref = K.integrate_angular_velocity(
        rk.Rotation.identity(), w, 0.01, frame="body", method="rk4"
    )
    w32 = w.astype(np.float32)
    R0_32 = rk.Rotation.identity(dtype=np.float32)
    t32 = K.integrate_angular_velocity(R0_32, w32, 0.01, frame="body", method="rk4")
    assert t32.dtype == np.float32 and angle(t32, ref).max() < 1e-4
    wt = torch.tensor(w, requires_grad=True)
    R0 = rk.Rotation.from_quat(torch.tensor([1.0, 0.0, 0.0, 0.0], dtype=torch.float64))
    tt = K.integrate_angular_velocity(R0, wt, 0.01, frame="body", method="rk4")
    assert isinstance(tt.as_quat(), torch.Tensor)
    np.testing.assert_allclose(
        angle(rk.Rotation.from_quat(tt.as_quat().detach().numpy()), ref).max(),
        0,
        atol=1e-12,
    )
    tt.as_quat()[-1, 1].backward()
    assert torch.isfinite(wt.grad).all() and float(wt.grad.abs().sum()) > 0
    tj = K.integrate_angular_velocity(
        rk.Rotation.from_quat(jnp.asarray([1.0, 0, 0, 0])),
        jnp.asarray(w),
        0.01,
        frame="world",
    )
    refw = K.integrate_angular_velocity(rk.Rotation.identity(), w, 0.01, frame="world")
    assert angle(rk.Rotation.from_quat(np.asarray(tj.as_quat())), refw).max() < 1e-12


def test_integrate_twist_dead_reckoning(rng):
    V = np.array([1.0, 0.2, -0.1, 0.1, -0.3, 0.5])
    N, dt = 2000, 1e-3
    ref = sl.expm(
        np.block([[rk.so3.hat(V[3:]), V[:3, None]], [np.zeros((1, 4))]]) * (N * dt)
    )
    T0 = rk.Transform.random(rng=3)
    for method in ("exact", "midpoint", "rk4"):
        tb = K.integrate_twist(T0, np.tile(V, (N, 1)), dt, frame="body", method=method)
        np.testing.assert_allclose(tb[-1].as_matrix(), T0.as_matrix() @ ref, atol=1e-11)
        tw = K.integrate_twist(
            T0.as_matrix(), np.tile(V, (N, 1)), dt, frame="world", method=method
        )
        np.testing.assert_allclose(tw[-1], ref @ T0.as_matrix(), atol=1e-11)
    # orders on a varying twist: T(t) = exp(X(t)) with a known body twist from samples
    errs = {m: [] for m in ("exact", "midpoint", "rk4")}
    for N in (200, 400, 800):
        t = np.linspace(0.0, 1.0, N + 1)
        X = np.stack(
            [
                np.sin(t),
                0.5 * t * t,
                np.cos(2 * t) - 1,
                0.4 * np.sin(2 * t),
                0.3 * t,
                -0.5 * t * t,
            ],
            -1,
        )
        T = rk.Transform.exp(X)
        Vb = K.twist_from_samples(T, t, frame="body")  # 2nd-order, not the reference
        Vexact = np.stack([_body_twist(X[k], _xdot(t[k])) for k in range(N + 1)])
        assert np.abs(Vb - Vexact).max() < 30.0 / N**2
        for m in errs:
            tr = K.integrate_twist(T[0], Vexact[:-1], 1.0 / N, frame="body", method=m)
            errs[m].append(float(np.abs(tr[-1].as_matrix() - T[-1].as_matrix()).max()))
    for m, order in (("exact", 1), ("midpoint", 2), ("rk4", 4)):
        measured = np.log2(np.array(errs[m][:-1]) / np.array(errs[m][1:]))
        assert np.all(np.abs(measured - order) < 0.2), (m, measured)


def _xdot(t):
    return np.array([np.cos(t), t, -2 * np.sin(2 * t), 0.8 * np.cos(2 * t), 0.3, -t])


def _body_twist(X, Xd):
    """Body twist of exp(X(t)): vee(T^-1 T'), from expm of the block matrix (Van Loan)."""
    A = np.block([[rk.so3.hat(X[3:]), X[:3, None]], [np.zeros((1, 4))]])
    B = np.block([[rk.so3.hat(Xd[3:]), Xd[:3, None]], [np.zeros((1, 4))]])
    big = sl.expm(np.block([[A, B], [np.zeros((4, 4)), A]]))
    T, T_dot = big[:4, :4], big[:4, 4:]
    return rk.se3.vee(np.linalg.inv(T) @ T_dot)


def test_integration_errors():
    w = np.ones((3, 3))
    with pytest.raises(TypeError, match="'frame'"):
        K.integrate_angular_velocity(rk.Rotation.identity(), w, 0.1)
    with pytest.raises(ValueError, match="method"):
        K.integrate_angular_velocity(
            rk.Rotation.identity(), w, 0.1, frame="body", method="euler"
        )
    with pytest.raises(rk.DegenerateInputError, match="at least 4"):
        K.integrate_angular_velocity(
            rk.Rotation.identity(), w, 0.1, frame="body", method="rk4"
        )
    with pytest.raises(rk.ShapeError):
        K.integrate_angular_velocity(rk.Rotation.identity(), w, np.ones(5), frame="body")
    with pytest.raises(rk.NonFiniteError):
        K.integrate_angular_velocity(rk.Rotation.identity(), w * np.nan, 0.1, frame="body")


def test_one_hour_at_1khz_runs(rng):
    """3.6 M steps: runs and stays unit (its time is measured in the benchmark)."""
    w = rng.standard_normal((3_600_000, 3)).astype(np.float64)
    traj = K.integrate_angular_velocity(rk.Rotation.identity(), w, 1e-3, frame="body")
    n = np.linalg.norm(traj.as_quat()[-1000:], axis=-1)
    assert np.abs(n - 1).max() < 1e-15 * 4


# -- velocities from samples -----------------------------------------------------------


@pytest.mark.parametrize("frame", ["body", "world"])
def test_constant_velocity_is_exact_with_non_uniform_times(frame, rng):
    w = np.array([0.4, -1.1, 0.7])
    R0 = rk.Rotation.random(rng=1)
    t = np.cumsum(rng.uniform(0.01, 0.3, 12))
    step = rk.Rotation.from_rotvec(np.outer(t, w))
    R = R0 @ step if frame == "body" else step @ R0
    np.testing.assert_allclose(
        K.angular_velocity_from_samples(R, t, frame=frame), np.tile(w, (12, 1)), atol=1e-9
    )
    V = rng.standard_normal(6)
    T0 = rk.Transform.random(rng=2)
    E = rk.Transform.exp(np.outer(t, V))
    T = T0 @ E if frame == "body" else E @ T0
    np.testing.assert_allclose(
        K.twist_from_samples(T, t, frame=frame), np.tile(V, (12, 1)), atol=1e-9
    )


def _constant_velocity(cls, rng, frame, t):
    """``X_k = X0 exp(t_k V)`` (body) or ``exp(t_k V) X0`` (world), with the matrices
    of the reference made by ``scipy.linalg.expm`` of ``hat(t_k V)``."""
    spec = registry.spec(cls)
    V = rng.standard_normal(cls.dof)
    rot = spec.part("rotation")
    V[rot] *= 1.0 / np.linalg.norm(V[rot])  # |omega| = 1: each step turns < pi
    X0 = cls.random(rng=rng)
    E = cls.exp(np.outer(t, V))
    X = X0 @ E if frame == "body" else E @ X0
    hats = np.asarray(spec.algebra.hat(np.outer(t, V)))
    M0 = np.asarray(X0.as_matrix())
    ref = [M0 @ sl.expm(H) if frame == "body" else sl.expm(H) @ M0 for H in hats]
    return V, X0, X, np.stack(ref)


@pytest.mark.parametrize("frame", ["body", "world"])
@pytest.mark.parametrize("cls", LIE_GROUPS, ids=lambda c: c.__name__)
def test_every_group_constant_velocity_from_samples(cls, frame, rng):
    """The one finite-difference algorithm, for every Lie group of the registry: a
    constant velocity is recovered exactly (to rounding) from non-uniform samples."""
    t = np.cumsum(rng.uniform(0.01, 0.3, 9))
    V, _, X, ref = _constant_velocity(cls, rng, frame, t)
    np.testing.assert_allclose(np.asarray(X.as_matrix()), ref, rtol=0, atol=1e-12)
    got = velocity_from_samples(X, t, int(frame == "body"), "test", "samples")
    np.testing.assert_allclose(got, np.tile(V, (len(t), 1)), rtol=0, atol=1e-9)


@pytest.mark.parametrize("method", ["exact", "midpoint", "rk4"])
@pytest.mark.parametrize("frame", ["body", "world"])
@pytest.mark.parametrize(
    "cls", [c for c in LIE_GROUPS if registry.spec(c).step], ids=lambda c: c.__name__
)
def test_every_group_integrates_a_constant_rate_exactly(cls, frame, method, rng):
    """The one integrator, for every group of the registry that declares its step:
    a constant rate gives ``X0 exp(t V)`` (body) or ``exp(t V) X0`` (world) with
    every method, against ``scipy.linalg.expm``."""
    dt = 0.05
    t = dt * np.arange(13)
    V, X0, _, ref = _constant_velocity(cls, rng, frame, t)
    traj = integrate(X0, np.tile(V, (12, 1)), dt, method, "test", int(frame == "body"))
    assert type(traj) is cls and traj.shape == (13,)
    np.testing.assert_allclose(np.asarray(traj.as_matrix()), ref, rtol=0, atol=1e-12)


def test_samples_agree_with_scipy_rotation_spline():
    """Body rates: scipy's RotationSpline(t, 1) is the body angular velocity of its
    C2 interpolant (4th order in the interior, natural ends). Our second-order
    differences approach it at the rate h^2."""
    gaps = []
    for n in (301, 601):
        t = np.linspace(0.0, 3.0, n)
        R, wb = sampled(t, "body")
        spline = RotationSpline(t, SciRot.from_quat(R.as_quat(), scalar_first=True))
        ours = K.angular_velocity_from_samples(R, t, frame="body")
        theirs = spline(t, 1)
        inner = slice(n // 20, n - n // 20)  # away from the spline's natural ends
        assert np.abs(theirs[inner] - wb[inner]).max() < 1e-7
        gaps.append(np.abs(ours[inner] - theirs[inner]).max())
        ww = K.angular_velocity_from_samples(R.as_matrix(), t, frame="world")
        np.testing.assert_allclose(ww, R.apply(ours), atol=1e-10)
    assert gaps[1] < 1e-4
    assert 3.6 < gaps[0] / gaps[1] < 4.4, gaps


def test_samples_second_order_and_errors():
    errs = []
    for N in (50, 100, 200):
        t = np.linspace(0.0, 2.0, N + 1) ** 1.2  # non-uniform
        R, wb = sampled(t, "body")
        errs.append(np.abs(K.angular_velocity_from_samples(R, t, frame="body") - wb).max())
    measured = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(measured > 1.8), measured
    # poses: world and body twists related by the adjoint at every sample, ends too
    t = np.linspace(0.0, 1.0, 40) ** 1.3
    X = np.stack([np.sin(t), t * t, np.cos(t), 0.5 * t, np.sin(2 * t), -t], -1)
    T = rk.Transform.exp(X)
    Vb = K.twist_from_samples(T, t, frame="body")
    Vw = K.twist_from_samples(T.as_matrix(), t, frame="world")
    np.testing.assert_allclose(Vw, (T.adjoint() @ Vb[..., None])[..., 0], atol=1e-10)
    R = rk.Rotation.random((3,), rng=1)
    with pytest.raises(rk.DegenerateInputError):
        K.angular_velocity_from_samples(R, [0.0, 1.0, 1.0], frame="body")
    with pytest.raises(rk.ShapeError):
        K.angular_velocity_from_samples(R, [0.0, 1.0], frame="body")
    with pytest.raises(rk.DegenerateInputError):
        K.angular_velocity_from_samples(R[:1], [0.0], frame="body")


def test_readme_kinematics_example_against_an_ode_solver():
    """The README's gyroscope example: the rk4 trajectory against scipy's solve_ivp of
    q' = q (0, w(t)) / 2 with the rate's closed form, and its Euler-rate example
    against finite differences of scipy's from_euler."""
    import pathlib
    import re

    from scipy.integrate import solve_ivp

    readme = pathlib.Path(__file__).resolve().parents[1] / "README.md"
    ns: dict = {}
    for block in re.findall(r"```python\n(.*?)```", readme.read_text(), re.S):
        exec(block, ns)

    def rhs(t, q):
        w = np.array([0.2 * np.sin(t), 0.1, 0.3 * np.cos(t)])
        return 0.5 * rk.quaternion.multiply(q, np.concatenate([[0.0], w]))

    sol = solve_ivp(rhs, (0.0, 10.0), [1.0, 0, 0, 0], rtol=1e-12, atol=1e-13, t_eval=[10.0])
    end = rk.Rotation.from_quat(sol.y[:, -1])
    assert angle(ns["trajectory"][-1], end) < 1e-8
    ypr, rates = ns["ypr"], ns["ypr_rates"]
    h = 1e-6
    R = [SciRot.from_euler("ZYX", ypr + s * h * rates).as_matrix() for s in (1, -1)]
    W = (R[0] - R[1]) / (2 * h) @ SciRot.from_euler("ZYX", ypr).as_matrix().T
    w_world = 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])
    np.testing.assert_allclose(ns["w_world"], w_world, atol=1e-9)


def _computes(da):
    """A scheduler callback counting the graph computes made in its block."""
    from dask.callbacks import Callback

    class Count(Callback):
        starts = 0

        def _start(self, dsk):
            Count.starts += 1

    return Count


@pytest.mark.parametrize("method", ["exact", "rk4"])
def test_dask_integration_is_lazy_and_equals_a_scipy_loop(method, rng, dask_array):
    """Dask rates chunked along the batch and along the samples: nothing is computed
    during the call, each trajectory runs with its samples in one chunk, and the
    result equals a SciPy rotation loop (zero-order hold) or the NumPy call (rk4)."""
    da = dask_array
    w = rng.standard_normal((3, 40, 3))
    dt = rng.uniform(0.005, 0.02, 40)
    q0 = SciRot.random(3, random_state=1)
    R0 = rk.Rotation.from_quat(da.from_array(q0.as_quat(scalar_first=True), chunks=(2, 4)))
    wd = da.from_array(w, chunks=(2, 15, 3))
    count = _computes(da)
    with count():
        traj = K.integrate_angular_velocity(
            R0, wd, da.from_array(dt, chunks=10), frame="body", method=method
        )
    assert count.starts == 0
    q = traj.as_quat()
    assert type(q).__module__.startswith("dask")
    assert q.chunks[0] == (2, 1) and q.chunks[1] == (41,)
    got = rk.Rotation.from_quat(q.compute())
    if method == "exact":
        for b in range(3):
            R = q0[b]
            ref = [R]
            for k in range(40):
                R = R * SciRot.from_rotvec(w[b, k] * dt[k])
                ref.append(R)
            want = rk.Rotation.from_quat(
                np.stack([r.as_quat(scalar_first=True) for r in ref])
            )
            assert angle(got[b], want).max() < 1e-13
    else:
        want = K.integrate_angular_velocity(
            rk.Rotation.from_quat(q0.as_quat(scalar_first=True)),
            w,
            dt,
            frame="body",
            method=method,
        )
        assert angle(got, want).max() < 1e-13


def test_dask_twist_integration_is_lazy(rng, dask_array):
    """Poses from Dask twists (world frame, midpoint): lazy, and equal to a loop of
    matrix exponentials of the midpoint twists (scipy.linalg.expm)."""
    da = dask_array
    V = rng.standard_normal((2, 12, 6))
    dt = 0.05
    count = _computes(da)
    with count():
        traj = K.integrate_twist(
            np.eye(4), da.from_array(V, chunks=(1, 5, 6)), dt, frame="world",
            method="midpoint",
        )  # fmt: skip
    assert count.starts == 0 and type(traj).__module__.startswith("dask")
    got = traj.compute()
    for b in range(2):
        mid = 0.5 * (V[b, :-1] + V[b, 1:])
        mid = np.concatenate([mid, [1.5 * V[b, -1] - 0.5 * V[b, -2]]])
        T = np.eye(4)
        for k in range(12):
            T = sl.expm(rk.se3.hat(mid[k] * dt)) @ T
            np.testing.assert_allclose(got[b, k + 1], T, atol=1e-12)
