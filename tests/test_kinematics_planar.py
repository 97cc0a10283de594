"""Planar kinematics (issue 8 §4-5 in the plane): integration on SO(2) and SE(2),
planar twists between frames.

References: closed forms (``exp(omega t)``, ``theta(t)`` of a rate with a known
integral), ``scipy.linalg.expm`` of the 3x3 ``hat(V)``, scipy's ``solve_ivp`` of
``T' = T hat(V(t))`` on the matrices, the 3D integrators on the plane's embedding
(``(vx, vy, 0, 0, 0, omega)``, themselves checked against scipy), and the
measured convergence orders.
"""

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.integrate import solve_ivp

import rigidkit as rk

P = rk.kinematics.planar
METHODS = ("exact", "midpoint", "rk4")


def hat2(V):
    """3x3 ``[[omega J, v], [0, 0]]`` of planar twists ``(vx, vy, omega)``."""
    V = np.asarray(V, dtype=float)
    out = np.zeros(V.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 1, 0] = -V[..., 2], V[..., 2]
    out[..., 0, 2], out[..., 1, 2] = V[..., 0], V[..., 1]
    return out


def rot2(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


# -- SO(2) ------------------------------------------------------------------------------


def test_constant_rate_is_the_exponential_over_1e5_steps():
    N, dt, w = 100_000, 1e-3, -0.7
    R0 = rk.Rotation2D.from_angle(0.4)
    for method in METHODS:
        for frame in ("body", "world"):
            traj = P.integrate_angular_velocity(
                R0, np.full((N, 1), w), dt, frame=frame, method=method
            )
            assert traj.shape == (N + 1,)
            np.testing.assert_allclose(
                traj[-1].as_matrix(), rot2(0.4 + w * N * dt), atol=1e-12
            )
            assert np.abs(np.linalg.norm(traj._data, axis=-1) - 1).max() < 4e-16
    # every sample: R0 exp(J w t_k)
    k = np.arange(N + 1)[::997]
    np.testing.assert_allclose(traj[k].as_matrix(), rot2(0.4 + w * dt * k), atol=1e-12)


def _theta(t):
    return np.sin(1.3 * t) / 1.3 - 0.5 * np.cos(2.1 * t) / 2.1 + 0.2 * t * t


def _omega(t):
    return np.cos(1.3 * t) + 0.5 * np.sin(2.1 * t) + 0.4 * t


def test_so2_convergence_orders_uniform_and_not():
    """theta(T) - theta(0) = integral of omega: orders 1 (ZOH), 2, 4 measured."""
    T = 3.0
    for uniform in (True, False):
        errs = {m: [] for m in METHODS}
        for N in (100, 200, 400, 800):
            u = np.linspace(0.0, 1.0, N + 1)
            t = T * (u if uniform else u + 0.1 * np.sin(np.pi * u) ** 2 * np.sin(5 * u))
            dt = T / N if uniform else np.diff(t)
            w = _omega(t[:-1])[:, None]
            for m in METHODS:
                R = P.integrate_angular_velocity(np.eye(2), w, dt, frame="body", method=m)
                ref = rot2(_theta(t) - _theta(0.0))
                errs[m].append(np.abs(R - ref).max())
        for m, order in zip(METHODS, (1, 2, 4)):
            measured = np.log2(np.array(errs[m][:-1]) / np.array(errs[m][1:]))
            assert np.all(np.abs(measured - order) < 0.25), (uniform, m, measured)


def test_so2_agrees_with_the_3d_integrator_about_z(rng):
    w = rng.standard_normal((3, 400, 1))
    dt = rng.uniform(0.001, 0.02, 400)
    R0 = rk.Rotation2D.random((3,), rng=4)
    w3 = np.concatenate([np.zeros((3, 400, 2)), w], -1)
    Q0 = rk.Rotation.from_rotvec(np.concatenate([np.zeros((3, 2)), R0.log()], -1))
    for m in METHODS:
        two = P.integrate_angular_velocity(R0, w, dt, frame="world", method=m)
        three = rk.kinematics.integrate_angular_velocity(
            Q0, w3, dt, frame="world", method=m
        )
        assert two.shape == (3, 401)
        np.testing.assert_allclose(
            two.as_matrix(), three.as_matrix()[..., :2, :2], atol=1e-13
        )


# -- SE(2) ------------------------------------------------------------------------------


def test_constant_twist_is_the_exponential():
    V = np.array([1.2, -0.4, 0.9])
    N, dt = 20_000, 5e-4
    T0 = rk.Transform2D.random(rng=5)
    E = sl.expm(hat2(V) * (N * dt))
    for m in METHODS:
        tb = P.integrate_twist(T0, np.tile(V, (N, 1)), dt, frame="body", method=m)
        np.testing.assert_allclose(tb[-1].as_matrix(), T0.as_matrix() @ E, atol=1e-11)
        tw = P.integrate_twist(
            T0.as_matrix(), np.tile(V, (N, 1)), dt, frame="world", method=m
        )
        assert tw.shape == (N + 1, 3, 3)
        np.testing.assert_allclose(tw[-1], E @ T0.as_matrix(), atol=1e-11)
        np.testing.assert_allclose(tw[0], T0.as_matrix(), rtol=0, atol=4e-16)


def _twist(t):
    return np.stack(
        [1.0 + 0.5 * np.sin(2 * t), 0.3 * np.cos(t), 0.8 * np.sin(1.7 * t) + 0.2], -1
    )


@pytest.mark.parametrize("frame", ["body", "world"])
def test_se2_orders_against_an_ode_solver(frame):
    """T' = T hat(V(t)) (body) or hat(V(t)) T (world), solved by DOP853 at 1e-13."""
    T_end = 2.0
    M0 = rk.Transform2D.random(rng=6).as_matrix()

    def rhs(t, y):
        M = y.reshape(3, 3)
        H = hat2(_twist(t))
        return (M @ H if frame == "body" else H @ M).ravel()

    sol = solve_ivp(rhs, (0, T_end), M0.ravel(), method="DOP853", rtol=1e-13, atol=1e-14)
    ref = sol.y[:, -1].reshape(3, 3)
    errs = {m: [] for m in METHODS}
    for N in (50, 100, 200, 400):
        t = np.linspace(0.0, T_end, N + 1)
        V = _twist(t[:-1])
        for m in METHODS:
            tr = P.integrate_twist(M0, V, T_end / N, frame=frame, method=m)
            errs[m].append(np.abs(tr[-1] - ref).max())
    for m, order in zip(METHODS, (1, 2, 4)):
        measured = np.log2(np.array(errs[m][:-1]) / np.array(errs[m][1:]))
        assert abs(measured[-1] - order) < 0.1, (m, measured)
        assert np.all(np.abs(measured - order) < 0.3), (m, measured)


def test_se2_agrees_with_the_3d_integrator_on_the_plane(rng):
    V = rng.standard_normal((2, 300, 3))
    V6 = np.zeros((2, 300, 6))
    V6[..., :2], V6[..., 5] = V[..., :2], V[..., 2]
    T0 = rk.Transform2D.random((2,), rng=7)
    M0 = np.zeros((2, 4, 4))
    M0[:, :2, :2], M0[:, :2, 3] = T0.as_matrix()[:, :2, :2], T0.as_matrix()[:, :2, 2]
    M0[:, 2, 2] = M0[:, 3, 3] = 1.0
    for m in METHODS:
        for frame in ("body", "world"):
            two = P.integrate_twist(T0, V, 0.01, frame=frame, method=m).as_matrix()
            three = rk.kinematics.integrate_twist(M0, V6, 0.01, frame=frame, method=m)
            np.testing.assert_allclose(two[..., :2, :2], three[..., :2, :2], atol=1e-13)
            np.testing.assert_allclose(two[..., :2, 2], three[..., :2, 3], atol=1e-12)


def test_float32_torch_and_jax(rng, torch, jnp):
    V = rng.standard_normal((200, 3))
    ref = P.integrate_twist(rk.Transform2D.identity(), V, 0.01, frame="body", method="rk4")
    t32 = P.integrate_twist(
        rk.Transform2D.identity(dtype=np.float32),
        V.astype(np.float32),
        0.01,
        frame="body",
        method="rk4",
    )
    assert t32._data.dtype == np.float32
    np.testing.assert_allclose(t32._data, ref._data, atol=2e-5)
    w32 = V[:, 2:].astype(np.float32)
    r32 = P.integrate_angular_velocity(np.eye(2, dtype=np.float32), w32, 0.01, frame="body")
    assert r32.dtype == np.float32
    Vt = torch.tensor(V, requires_grad=True)
    T0 = rk.Transform2D.identity()
    tt = P.integrate_twist(
        rk.Transform2D._wrap(torch.tensor(T0._data)), Vt, 0.01, frame="body", method="rk4"
    )
    assert isinstance(tt._data, torch.Tensor)
    np.testing.assert_allclose(tt._data.detach().numpy(), ref._data, atol=1e-12)
    tt._data[-1, 2].backward()
    assert torch.isfinite(Vt.grad).all() and float(Vt.grad.abs().sum()) > 0
    wt = torch.tensor(V[:, 2:], requires_grad=True)
    z0 = rk.Rotation2D._wrap(torch.tensor([1.0, 0.0], dtype=torch.float64))
    rt = P.integrate_angular_velocity(z0, wt, 0.01, frame="world", method="rk4")
    rt._data[-1, 1].backward()
    # A constant rate integrates exactly (theta = w T), so the weights of the
    # samples in theta_N sum to T = 2: the gradient of sin(theta_N) sums to 2 cos.
    cos_N = float(rt._data[-1, 0].detach())
    np.testing.assert_allclose(float(wt.grad.sum()), 2.0 * cos_N, rtol=1e-12)
    tj = P.integrate_twist(
        rk.Transform2D._wrap(jnp.asarray(T0._data)), jnp.asarray(V), 0.01, frame="world"
    )
    refw = P.integrate_twist(rk.Transform2D.identity(), V, 0.01, frame="world")
    np.testing.assert_allclose(np.asarray(tj._data), refw._data, atol=1e-12)


def test_integration_errors():
    w = np.ones((5, 1))
    with pytest.raises(TypeError, match="'frame'"):
        P.integrate_angular_velocity(rk.Rotation2D.identity(), w, 0.1)
    with pytest.raises(rk.ShapeError, match=r"w\[:, None\]"):
        P.integrate_angular_velocity(
            rk.Rotation2D.identity(), np.ones(5), 0.1, frame="body"
        )
    with pytest.raises(rk.ShapeError, match=r"\(\.\.\., N, 3\)"):
        P.integrate_twist(rk.Transform2D.identity(), np.ones((5, 6)), 0.1, frame="body")
    with pytest.raises(ValueError, match="method"):
        P.integrate_twist(
            rk.Transform2D.identity(), np.ones((5, 3)), 0.1, frame="body", method="euler"
        )
    with pytest.raises(rk.DegenerateInputError, match="at least 4"):
        P.integrate_angular_velocity(np.eye(2), w[:3], 0.1, frame="body", method="rk4")
    with pytest.raises(rk.NotARotationError):
        P.integrate_angular_velocity(np.ones((2, 2)), w, 0.1, frame="body")
    with pytest.raises(rk.NonFiniteError):
        P.integrate_twist(np.eye(3), np.full((5, 3), np.nan), 0.1, frame="world")


# -- velocities from samples -------------------------------------------------------------


@pytest.mark.parametrize("frame", ["body", "world"])
def test_velocities_from_samples_second_order(frame):
    """``T(t) = [rot(theta), p]`` with ``theta = sin t`` and a curved ``p``: the body
    twist ``(R^T p', theta')`` and the world twist ``(p' - theta' J p, theta')`` in
    closed form (``hat(V) = T^-1 T'`` or ``T' T^-1``); the differences converge at
    second order on non-uniform times, on matrices and on objects alike."""
    errs, rate_errs = [], []
    for n in (50, 100, 200):
        t = np.linspace(0.0, 2.0, n + 1) ** 1.2
        theta, dtheta = np.sin(t), np.cos(t)
        p = np.stack([t * t, np.sin(2 * t)], -1)
        dp = np.stack([2 * t, 2 * np.cos(2 * t)], -1)
        R = rot2(theta)
        M = np.zeros((n + 1, 3, 3))
        M[:, :2, :2], M[:, :2, 2], M[:, 2, 2] = R, p, 1.0
        if frame == "body":
            v = np.einsum("kji,kj->ki", R, dp)
        else:
            v = dp - dtheta[:, None] * np.stack([-p[:, 1], p[:, 0]], -1)
        ref = np.concatenate([v, dtheta[:, None]], -1)
        got = P.twist_from_samples(M, t, frame=frame)
        np.testing.assert_array_equal(
            got, P.twist_from_samples(rk.Transform2D.from_matrix(M), t, frame=frame)
        )
        errs.append(np.abs(got - ref).max())
        w = P.angular_velocity_from_samples(rk.Rotation2D.from_matrix(R), t, frame=frame)
        assert w.shape == (n + 1, 1)
        rate_errs.append(np.abs(w[:, 0] - dtheta).max())
    for e in (errs, rate_errs):
        measured = np.log2(np.array(e[:-1]) / np.array(e[1:]))
        assert np.all(measured > 1.8), measured


def test_velocities_from_samples_errors():
    R = rk.Rotation2D.from_angle([0.0, 0.1, 0.2])
    with pytest.raises(TypeError, match="'frame'"):
        P.angular_velocity_from_samples(R, [0.0, 1.0, 2.0])
    with pytest.raises(rk.DegenerateInputError, match="increase"):
        P.angular_velocity_from_samples(R, [0.0, 1.0, 1.0], frame="body")
    with pytest.raises(rk.ShapeError, match="time axis"):
        P.twist_from_samples(rk.Transform2D.identity(), [0.0], frame="body")
    with pytest.raises(rk.NotARotationError):
        P.angular_velocity_from_samples(np.ones((3, 2, 2)), [0.0, 1.0, 2.0], frame="body")


# -- planar twists between frames -------------------------------------------------------


def test_twist_to_world_and_body_are_the_adjoint(rng):
    T = rk.Transform2D.random((7,), rng=8)
    M = T.as_matrix()
    Vb = rng.standard_normal((7, 3))
    Vw = P.twist_to_world(T, Vb)
    # hat(V_world) = T hat(V_body) T^-1, on the matrices
    np.testing.assert_allclose(hat2(Vw), M @ hat2(Vb) @ np.linalg.inv(M), atol=1e-13)
    np.testing.assert_allclose(P.twist_to_body(M, Vw), Vb, atol=1e-13)
    # the derivative T' = T hat(V_body) seen from the world
    T_dot = P.transform_derivative(M, Vb, frame="body")
    np.testing.assert_allclose(
        P.twist_from_derivative(M, T_dot, frame="world"), Vw, atol=1e-13
    )
