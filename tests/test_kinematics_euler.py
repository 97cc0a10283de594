"""Euler-angle rates (issue 8 §2): E, E^-1, E' for all 24 sequences and both frames.

References: central finite differences of scipy's ``from_euler`` (independent of
rigidkit), closed forms written out by hand (the world matrix of intrinsic
``"XYZ"``, whose columns are the axes ``x``, ``Rx y``, ``Rx Ry z``; the world and
body matrices of ``"ZYX"`` and their inverses), the group relation
``omega_world = R omega_body``, and the singularities.
"""

import itertools
import pickle

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk

K = rk.kinematics
SEQS = [
    "".join(p) for p in itertools.product("xyz", repeat=3) if p[0] != p[1] and p[1] != p[2]
]
SEQS = SEQS + [s.upper() for s in SEQS]
assert len(SEQS) == 24


def _angles(seq, rng, shape=()):
    """Random angles away from gimbal lock (middle angle at least 0.2 rad off)."""
    a = rng.uniform(-3.0, 3.0, shape + (3,))
    proper = seq[0].lower() == seq[2].lower()
    a[..., 1] = (
        rng.uniform(0.2, np.pi - 0.2, shape)
        if proper
        else rng.uniform(-np.pi / 2 + 0.2, np.pi / 2 - 0.2, shape)
    )
    return a


def _vee(W):
    return 0.5 * np.stack(
        [
            W[..., 2, 1] - W[..., 1, 2],
            W[..., 0, 2] - W[..., 2, 0],
            W[..., 1, 0] - W[..., 0, 1],
        ],
        axis=-1,
    )


def _fd_omega(seq, angles, rates, frame, h=1e-5):
    """omega from a 4th-order central difference of scipy's from_euler."""

    def R(t):
        return SciRot.from_euler(seq, angles + t * rates).as_matrix()

    R_dot = (-R(2 * h) + 8 * R(h) - 8 * R(-h) + R(-2 * h)) / (12 * h)
    R0 = R(0.0)
    W = (
        R_dot @ np.swapaxes(R0, -1, -2)
        if frame == "world"
        else np.swapaxes(R0, -1, -2) @ R_dot
    )
    return _vee(W)


@pytest.mark.parametrize("seq", SEQS)
@pytest.mark.parametrize("frame", ["world", "body"])
def test_rate_matrix_matches_finite_differences_of_scipy(seq, frame, rng):
    a = _angles(seq, rng, (6,))
    r = rng.standard_normal((6, 3))
    E = K.euler_rate_matrix(seq, a, frame=frame)
    w = np.einsum("...ij,...j->...i", E, r)
    np.testing.assert_allclose(w, _fd_omega(seq, a, r, frame), atol=2e-9)
    np.testing.assert_allclose(
        K.angular_velocity_from_euler_rates(seq, a, r, frame=frame), w, atol=1e-14
    )
    # inverse: rates back, E^-1 E = I
    np.testing.assert_allclose(K.euler_rates(seq, a, w, frame=frame), r, atol=1e-12)
    Ei = K.euler_rate_matrix_inverse(seq, a, frame=frame)
    np.testing.assert_allclose(Ei @ E, np.broadcast_to(np.eye(3), E.shape), atol=1e-13)


@pytest.mark.parametrize("seq", SEQS)
def test_world_and_body_rates_are_related_by_the_rotation(seq, rng):
    a = _angles(seq, rng, (5,))
    r = rng.standard_normal((5, 3))
    wb = K.angular_velocity_from_euler_rates(seq, a, r, frame="body")
    ww = K.angular_velocity_from_euler_rates(seq, a, r, frame="world")
    np.testing.assert_allclose(rk.Rotation.from_euler(seq, a) @ wb, ww, atol=1e-15 * 8)


@pytest.mark.parametrize("seq", SEQS)
@pytest.mark.parametrize("frame", ["world", "body"])
def test_rate_matrix_derivative_and_acceleration(seq, frame, rng):
    """E' against a central difference of E along the rates; alpha against a
    second difference of scipy's rotations (the derivative of omega)."""
    a = _angles(seq, rng, (4,))
    r = rng.standard_normal((4, 3))
    acc = rng.standard_normal((4, 3))
    h = 1e-5
    Ed = K.euler_rate_matrix_derivative(seq, a, r, frame=frame)
    fd = (
        K.euler_rate_matrix(seq, a + h * r, frame=frame)
        - K.euler_rate_matrix(seq, a - h * r, frame=frame)
    ) / (2 * h)
    np.testing.assert_allclose(Ed, fd, atol=1e-9)
    alpha = K.angular_acceleration_from_euler_rates(seq, a, r, acc, frame=frame)

    # angles(t) = a + r t + acc t^2/2: alpha = d/dt omega(t) at 0, by central difference
    def omega(t):
        return _fd_omega(seq, a + r * t + 0.5 * acc * t * t, r + acc * t, frame)

    d = 1e-3
    alpha_fd = (omega(d) - omega(-d)) / (2 * d)
    np.testing.assert_allclose(alpha, alpha_fd, atol=2e-5)
    back = K.euler_accelerations(seq, a, r, alpha, frame=frame)
    np.testing.assert_allclose(back, acc, atol=1e-11)


def test_closed_forms():
    """XYZ in world axes, and ZYX in world and body axes with their inverses."""
    al, be, ga = 0.3, -0.4, 1.1
    c, s = np.cos, np.sin
    xyz = np.array([[1, 0, s(be)], [0, c(al), -s(al) * c(be)], [0, s(al), c(al) * c(be)]])
    np.testing.assert_allclose(
        K.euler_rate_matrix("XYZ", [al, be, ga], frame="world"), xyz, atol=1e-15
    )
    psi, th, phi = 0.7, 0.5, -0.2  # ZYX: yaw psi, pitch theta, roll phi
    # written with columns (phi', theta', psi'), roll first, as aerospace texts do;
    # ours follow the sequence (psi, th, phi)
    world = np.array(
        [[c(psi) * c(th), -s(psi), 0], [s(psi) * c(th), c(psi), 0], [-s(th), 0, 1]]
    )
    body = np.array(
        [[1, 0, -s(th)], [0, c(phi), s(phi) * c(th)], [0, -s(phi), c(phi) * c(th)]]
    )
    world_inv = np.array(
        [
            [c(psi) / c(th), s(psi) / c(th), 0],
            [-s(psi), c(psi), 0],
            [s(th) * c(psi) / c(th), s(th) * s(psi) / c(th), 1],
        ]
    )
    body_inv = np.array(
        [
            [1, s(phi) * np.tan(th), c(phi) * np.tan(th)],
            [0, c(phi), -s(phi)],
            [0, s(phi) / c(th), c(phi) / c(th)],
        ]
    )
    a = [psi, th, phi]
    np.testing.assert_allclose(
        K.euler_rate_matrix("ZYX", a, frame="world")[:, ::-1], world, atol=1e-15
    )
    np.testing.assert_allclose(
        K.euler_rate_matrix("ZYX", a, frame="body")[:, ::-1], body, atol=1e-15
    )
    np.testing.assert_allclose(
        K.euler_rate_matrix_inverse("ZYX", a, frame="world")[::-1], world_inv, atol=1e-15
    )
    np.testing.assert_allclose(
        K.euler_rate_matrix_inverse("ZYX", a, frame="body")[::-1], body_inv, atol=1e-15
    )


def test_intrinsic_equals_extrinsic_reversed(rng):
    a = _angles("XYZ", rng, (5,))
    r = rng.standard_normal((5, 3))
    for frame in ("world", "body"):
        np.testing.assert_allclose(
            K.angular_velocity_from_euler_rates("XYZ", a, r, frame=frame),
            K.angular_velocity_from_euler_rates("zyx", a[:, ::-1], r[:, ::-1], frame=frame),
            atol=1e-15,
        )


def test_degrees():
    a = np.array([30.0, 20.0, 10.0])
    r = np.array([5.0, -3.0, 2.0])  # deg/s
    w_deg = K.angular_velocity_from_euler_rates("ZYX", a, r, frame="body", degrees=True)
    w_rad = K.angular_velocity_from_euler_rates(
        "ZYX", np.radians(a), np.radians(r), frame="body"
    )
    np.testing.assert_allclose(w_deg, w_rad, atol=1e-15)
    np.testing.assert_allclose(
        K.euler_rates("ZYX", a, w_deg, frame="body", degrees=True), r, atol=1e-12
    )


@pytest.mark.parametrize("seq", ["ZYX", "xyz", "ZXZ", "yxy"])
def test_gimbal_lock_raises_with_distance_and_tolerance(seq):
    proper = seq[0].lower() == seq[2].lower()
    lock = 0.0 if proper else np.pi / 2
    a = np.array([[0.3, 0.5, 0.2], [0.3, lock + 1e-10, 0.2], [0.1, 0.2, 0.3]])
    w = np.ones((3, 3))
    with pytest.raises(rk.GimbalLockError) as info:
        K.euler_rates(seq, a, w, frame="body")
    err = info.value
    assert isinstance(err, ValueError)
    assert err.index == (1,)
    assert err.distance == pytest.approx(1e-10, rel=1e-5)
    assert err.tolerance == pytest.approx(1.4901161193847656e-08)
    assert "1e-10 rad" in str(err) and "1.49e-08" in str(err)
    with pytest.raises(rk.GimbalLockError):
        K.euler_rate_matrix_inverse(seq, a, frame="world")
    with pytest.raises(rk.GimbalLockError):
        K.euler_accelerations(seq, a, w, w, frame="world")
    # the forward direction is fine at the lock, and a smaller tol is honoured
    assert np.isfinite(K.euler_rate_matrix(seq, a, frame="world")).all()
    rates = K.euler_rates(seq, a, w, frame="body", tol=1e-12)
    assert np.isfinite(rates).all()
    back = pickle.loads(pickle.dumps(err))
    assert (back.index, back.distance, back.tolerance) == (
        err.index,
        err.distance,
        err.tolerance,
    )


def test_rate_matrix_is_singular_exactly_at_the_lock():
    E = K.euler_rate_matrix("ZYX", [0.4, np.pi / 2, 0.1], frame="world")
    assert abs(np.linalg.det(E)) < 1e-15


def test_frame_is_required_and_named():
    with pytest.raises(TypeError, match="required keyword-only argument: 'frame'"):
        K.euler_rate_matrix("ZYX", [0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="got 'space'"):
        K.euler_rates("ZYX", [0.1, 0.2, 0.3], [1, 2, 3], frame="space")
    with pytest.raises(rk.EulerSequenceError):
        K.euler_rate_matrix("ZZX", [0.1, 0.2, 0.3], frame="body")
    with pytest.raises(rk.NonFiniteError):
        K.euler_rate_matrix("ZYX", [0.1, np.nan, 0.3], frame="body")


def test_batches_broadcast_and_float32(rng):
    a = _angles("ZYX", rng, (4, 1))
    r = rng.standard_normal((3, 3))
    w = K.angular_velocity_from_euler_rates("ZYX", a, r, frame="world")
    assert w.shape == (4, 3, 3)
    w32 = K.angular_velocity_from_euler_rates(
        "ZYX", a.astype(np.float32), r.astype(np.float32), frame="world"
    )
    assert w32.dtype == np.float32
    np.testing.assert_allclose(w32, w, atol=1e-5)
    big = _angles("zxz", rng, (5000,))
    rb = rng.standard_normal((5000, 3))
    E = K.euler_rate_matrix("zxz", big, frame="body")  # the numba path
    np.testing.assert_allclose(
        np.einsum("nij,nj->ni", E, rb),
        K.angular_velocity_from_euler_rates("zxz", big, rb, frame="body"),
        atol=1e-14,
    )


def test_torch_path_and_gradient(torch, rng):
    a = _angles("XYZ", rng, (3,))
    r = rng.standard_normal((3, 3))
    at = torch.tensor(a, requires_grad=True)
    w = K.angular_velocity_from_euler_rates("XYZ", at, torch.tensor(r), frame="body")
    assert isinstance(w, torch.Tensor) and w.dtype == torch.float64
    np.testing.assert_allclose(
        w.detach().numpy(), K.angular_velocity_from_euler_rates("XYZ", a, r, frame="body")
    )
    w.sum().backward()
    # d(sum omega)/d(angles) = sum_i (dE/da_k r)_i: E' along unit angle rates
    expected = [
        K.euler_rate_matrix_derivative("XYZ", a, np.eye(3)[k] + 0 * a, frame="body")
        for k in range(3)
    ]
    grad = np.stack([np.einsum("nij,nj->n", e, r) for e in expected], axis=-1)
    np.testing.assert_allclose(at.grad.numpy(), grad, atol=1e-12)
    rates = K.euler_rates("XYZ", at.detach(), w.detach(), frame="body")
    np.testing.assert_allclose(rates.numpy(), r, atol=1e-12)
    with pytest.raises(rk.GimbalLockError):
        K.euler_rates(
            "XYZ", torch.tensor([0.1, np.pi / 2, 0.2]), w[0].detach(), frame="body"
        )


def test_jax_path(jnp, rng):
    a = _angles("zyz", rng, (3,))
    r = rng.standard_normal((3, 3))
    w = K.angular_velocity_from_euler_rates(
        "zyz", jnp.asarray(a), jnp.asarray(r), frame="world"
    )
    np.testing.assert_allclose(
        np.asarray(w),
        K.angular_velocity_from_euler_rates("zyz", a, r, frame="world"),
        atol=1e-15,
    )
    E = K.euler_rate_matrix_inverse("zyz", jnp.asarray(a), frame="world")
    np.testing.assert_allclose(
        np.asarray(E), K.euler_rate_matrix_inverse("zyz", a, frame="world"), atol=1e-15
    )
