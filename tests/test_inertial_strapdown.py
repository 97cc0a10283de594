"""``rk.inertial.integrate``: strapdown integration against independent references.

* piecewise-constant input: ``X(t) = expm(t (G - N)) X0 expm(t (B + N))`` on the 5x5
  matrices (Barrau & Bonnabel 2017: ``X' = (G - N) X + X (B + N)`` with ``B`` the IMU
  sample, ``G`` gravity and ``N`` the nilpotent that moves ``v`` into ``p``), by
  ``scipy.linalg.expm``;
* a rotating navigation frame: scipy's ``solve_ivp`` (DOP853) of the rotating-frame
  equations written term by term;
* a smooth closed-form motion: the convergence order of each method;
* batches, float32, torch autograd against the closed-form gradient, ``jax.jit``.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk

G = np.array([0.3, -1.2, -9.7])  # not along z


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def mat5(R, v, p):
    M = np.eye(5)
    M[:3, :3], M[:3, 3], M[:3, 4] = R, v, p
    return M


def reference_piecewise(M0, gyro, accel, h, g):
    """States of piecewise-constant samples, one 5x5 expm pair per step."""
    N = np.zeros((5, 5))
    N[3, 4] = 1.0
    Gm = np.zeros((5, 5))
    Gm[:3, 3] = g
    out = [M0]
    for w, f in zip(gyro, accel, strict=True):
        B = np.zeros((5, 5))
        B[:3, :3], B[:3, 3] = hat(w), f
        out.append(sl.expm(h * (Gm - N)) @ out[-1] @ sl.expm(h * (B + N)))
    return np.array(out)


def test_exact_is_the_matrix_exponential_of_piecewise_constant_input(rng):
    X0 = rk.ExtendedPose.random((), rng)
    gyro = 0.8 * rng.standard_normal((40, 3))
    accel = 3.0 * rng.standard_normal((40, 3))
    h = 0.05
    X = rk.inertial.integrate(X0, gyro, accel, h, gravity=G, method="exact")
    want = reference_piecewise(X0.as_matrix(), gyro, accel, h, G)
    np.testing.assert_allclose(X.as_matrix(), want, rtol=0, atol=1e-12 * np.abs(want).max())
    # Per-step durations, and a constant input: every method is exact.
    dts = rng.uniform(0.01, 0.1, 40)
    const_w, const_f = np.tile(gyro[0], (40, 1)), np.tile(accel[0], (40, 1))
    for method in ("exact", "midpoint", "rk4"):
        Y = rk.inertial.integrate(X0, const_w, const_f, dts, gravity=G, method=method)
        M = X0.as_matrix()
        for k in range(40):
            M = reference_piecewise(M, const_w[:1], const_f[:1], dts[k], G)[-1]
        np.testing.assert_allclose(
            Y[-1].as_matrix(), M, rtol=0, atol=1e-11 * np.abs(M).max()
        )


def test_a_rotating_frame_against_an_ode_solver(rng):
    """Coriolis, centrifugal and transport terms: ``R' = R hat(w) - hat(W) R``,
    ``v' = R f + g - 2 W x v - W x (W x p)``, ``p' = v``, solved by DOP853."""
    W = np.array([0.1, -0.2, 0.25])  # large, so each term shows
    X0 = rk.ExtendedPose.random((), rng)
    gyro = 0.5 * rng.standard_normal((5, 3))
    accel = 2.0 * rng.standard_normal((5, 3))
    h = 0.2

    def rhs(t, y):
        k = min(int(t / h), 4)
        R, v, p = y[:9].reshape(3, 3), y[9:12], y[12:]
        dR = R @ hat(gyro[k]) - hat(W) @ R
        dv = R @ accel[k] + G - 2.0 * np.cross(W, v) - np.cross(W, np.cross(W, p))
        return np.concatenate([dR.ravel(), dv, v])

    M0 = X0.as_matrix()
    y = np.concatenate([M0[:3, :3].ravel(), M0[:3, 3], M0[:3, 4]])
    for k in range(5):  # one solve per step: the input jumps between them
        sol = solve_ivp(
            rhs, (k * h, (k + 1) * h - 1e-15), y, method="DOP853", rtol=1e-13, atol=1e-13
        )
        y = sol.y[:, -1]
    X = rk.inertial.integrate(X0, gyro, accel, h, gravity=G, earth_rate=W, method="exact")
    got = X[-1].as_matrix()
    np.testing.assert_allclose(got[:3, :3], y[:9].reshape(3, 3), rtol=0, atol=1e-10)
    np.testing.assert_allclose(got[:3, 3], y[9:12], rtol=0, atol=1e-10)
    np.testing.assert_allclose(got[:3, 4], y[12:], rtol=0, atol=1e-10)


# A smooth closed-form motion: R(t) = exp(u sin t), p(t) = (sin t, cos 2t, t^3/6).
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0


def motion(t):
    t = np.asarray(t, dtype=np.float64)
    R = SciRot.from_rotvec(np.sin(t)[..., None] * AXIS)
    p = np.stack([np.sin(t), np.cos(2 * t), t**3 / 6], axis=-1)
    v = np.stack([np.cos(t), -2 * np.sin(2 * t), t**2 / 2], axis=-1)
    a = np.stack([-np.sin(t), -4 * np.cos(2 * t), t], axis=-1)
    gyro = np.cos(t)[..., None] * AXIS  # the body rate about a fixed axis
    accel = R.apply(a - G, inverse=True)
    return R, v, p, gyro, accel


def state_at(t):
    R, v, p, _, _ = motion(t)
    return rk.ExtendedPose(
        rotation=rk.Rotation.from_quat(R.as_quat(scalar_first=True)), velocity=v, position=p
    )


def final_error(method, n, T=2.0):
    t = np.linspace(0.0, T, n + 1)[:-1]
    _, _, _, gyro, accel = motion(t)
    X = rk.inertial.integrate(state_at(0.0), gyro, accel, T / n, gravity=G, method=method)
    return np.abs(X[-1].as_matrix() - state_at(T).as_matrix()).max()


@pytest.mark.parametrize("method, order", [("exact", 1), ("midpoint", 2), ("rk4", 4)])
def test_convergence_order_on_a_smooth_motion(method, order):
    e1, e2 = final_error(method, 200), final_error(method, 400)
    assert 2 ** (order - 0.3) < e1 / e2 < 2 ** (order + 0.3), (e1, e2)
    if method == "rk4":
        assert e2 < 2e-9


def test_batches_of_logs_and_states(rng):
    X0 = rk.ExtendedPose.random(3, rng)
    gyro = rng.standard_normal((3, 25, 3))
    accel = rng.standard_normal((3, 25, 3))
    dt = rng.uniform(0.01, 0.02, (3, 25))
    X = rk.inertial.integrate(X0, gyro, accel, dt, gravity=G)
    assert X.shape == (3, 26)
    for b in range(3):
        one = rk.inertial.integrate(X0[b], gyro[b], accel[b], dt[b], gravity=G)
        np.testing.assert_allclose(X[b].as_matrix(), one.as_matrix(), rtol=0, atol=1e-13)
    # One state for many logs broadcasts.
    Y = rk.inertial.integrate(X0[0], gyro, accel, dt, gravity=G)
    np.testing.assert_allclose(Y[0].as_matrix(), X[0].as_matrix(), rtol=0, atol=1e-13)


def test_float32_is_kept(rng):
    gyro = rng.standard_normal((50, 3)).astype(np.float32)
    accel = rng.standard_normal((50, 3)).astype(np.float32)
    X0 = rk.ExtendedPose.identity(dtype=np.float32)
    X = rk.inertial.integrate(X0, gyro, accel, 0.01, method="rk4")
    assert X.as_matrix().dtype == np.float32
    ref = rk.inertial.integrate(
        rk.ExtendedPose(), gyro.astype(np.float64), accel.astype(np.float64), 0.01
    )
    np.testing.assert_allclose(X.as_matrix(), ref.as_matrix(), rtol=0, atol=1e-5)


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="method"):
        rk.inertial.integrate(
            rk.ExtendedPose(), np.zeros((4, 3)), np.zeros((4, 3)), 0.1, method="euler"
        )
    with pytest.raises(ValueError, match="accel"):
        rk.inertial.integrate(rk.ExtendedPose(), np.zeros((4, 3)), np.zeros((5, 3)), 0.1)
    with pytest.raises(TypeError, match="ExtendedPose"):
        rk.inertial.integrate(rk.Transform(), np.zeros((4, 3)), np.zeros((4, 3)), 0.1)


def test_torch_autograd_is_the_closed_form(torch, rng):
    """Without rotation, ``p_N = p0 + v0 T + g T^2/2 + sum_k h f_k (T - t_k - h/2)``:
    the gradient of ``p_N`` in ``f_k`` is ``h (T - t_k) - h^2 / 2`` on the diagonal."""
    n, h = 30, 0.1
    accel = torch.tensor(rng.standard_normal((n, 3)), requires_grad=True)
    gyro = torch.zeros((n, 3), dtype=torch.float64)
    X0 = rk.ExtendedPose._wrap(torch.tensor(rk.ExtendedPose()._data))
    for method in ("exact", "rk4"):
        X = rk.inertial.integrate(X0, gyro, accel, h, gravity=G, method=method)
        (g,) = torch.autograd.grad(X._data[-1, 7].sum(), accel)
        tk = h * np.arange(n)
        want = np.zeros((n, 3))
        want[:, 0] = h * (n * h - tk) - h * h / 2 if method == "exact" else want[:, 0]
        if method == "exact":
            np.testing.assert_allclose(g.numpy(), want, rtol=0, atol=1e-13)
        else:  # a smooth signal's weights sum to the same total
            np.testing.assert_allclose(g.numpy()[:, 0].sum(), (n * h) ** 2 / 2, rtol=1e-12)


def test_jax_jit_matches_numpy(jax, jnp, rng):
    gyro = rng.standard_normal((20, 3))
    accel = rng.standard_normal((20, 3))
    X0 = rk.ExtendedPose.random((), rng)

    @jax.jit
    def f(x0, w, a):
        X = rk.inertial.integrate(rk.ExtendedPose._wrap(x0), w, a, 0.01, gravity=G)  # rk4
        return X.as_matrix()

    got = np.asarray(f(jnp.asarray(X0._data), jnp.asarray(gyro), jnp.asarray(accel)))
    want = rk.inertial.integrate(X0, gyro, accel, 0.01, gravity=G).as_matrix()
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


@pytest.mark.exhaustive  # ~40 s of XLA compiles on a small CI machine
def test_jax_vmap_and_grad(jax, jnp, rng):
    """``jax.vmap`` over logs equals the batched NumPy call; ``jax.grad`` of the final
    position in the specific forces is the closed form of the torch test."""
    gyro = rng.standard_normal((4, 16, 3))
    accel = rng.standard_normal((4, 16, 3))
    X0 = rk.ExtendedPose.random((), rng)
    x0 = jnp.asarray(X0._data)

    def final(w, a):
        X = rk.inertial.integrate(
            rk.ExtendedPose._wrap(x0), w, a, 0.01, gravity=G, method="exact"
        )
        return X._data[-1]

    got = np.asarray(jax.vmap(final)(jnp.asarray(gyro), jnp.asarray(accel)))
    want = rk.inertial.integrate(X0, gyro, accel, 0.01, gravity=G, method="exact")._data[
        :, -1
    ]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    zero = jnp.zeros((16, 3))
    g = jax.grad(lambda a: final(zero, a)[7])(jnp.asarray(accel[0]))
    R0 = X0.rotation.as_matrix()
    h, tk = 0.01, 0.01 * np.arange(16)
    weights = h * (16 * h - tk) - h * h / 2  # d p_N / d f_k = R0 (that weight)
    np.testing.assert_allclose(np.asarray(g), np.outer(weights, R0[0]), rtol=0, atol=1e-13)
