"""The learning and plotting side of the rotation toolbox: the 6D representation,
swing-twist, distances between rotations, quaternion sign continuity and Euler
unwrapping. References: a hand Gram-Schmidt, scipy, Frobenius norms of matrices,
numpy.unwrap, explicit sign flips and constructions with known factors.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRotation

import rigidkit as rk
from rigidkit import DegenerateInputError, NonFiniteError, ShapeError, ZeroNormError
from rigidkit.functional import distances, rot6d, swing_twist


def unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def assert_same_rotations(q1, q2, tol=1e-14):
    dots = np.abs(np.sum(np.asarray(q1) * np.asarray(q2), axis=-1))
    assert np.all(np.abs(dots - 1.0) <= tol), np.abs(dots - 1.0).max()


# -- 6D --------------------------------------------------------------------------------
def hand_gram_schmidt(six):
    """Zhou et al.'s g_GS written out with NumPy: columns b1, b2, b1 x b2."""
    a1, a2 = six[..., :3], six[..., 3:]
    b1 = a1 / np.linalg.norm(a1, axis=-1, keepdims=True)
    u = a2 - np.sum(b1 * a2, axis=-1, keepdims=True) * b1
    b2 = u / np.linalg.norm(u, axis=-1, keepdims=True)
    return np.stack([b1, b2, np.cross(b1, b2)], axis=-1)


def test_as_6d_is_the_first_two_columns(rng):
    R = rk.Rotation.random((3, 4), rng)
    M = SciRotation.from_quat(R.as_quat().reshape(-1, 4), scalar_first=True).as_matrix()
    M = M.reshape(3, 4, 3, 3)
    six = R.as_6d()
    assert six.shape == (3, 4, 6)
    np.testing.assert_allclose(six[..., :3], M[..., :, 0], atol=1e-15)
    np.testing.assert_allclose(six[..., 3:], M[..., :, 1], atol=1e-15)
    # pytorch3d's layout (the first two rows) is the 6D of the inverse.
    rows = R.inv().as_6d()
    np.testing.assert_allclose(rows[..., :3], M[..., 0, :], atol=1e-15)
    np.testing.assert_allclose(rows[..., 3:], M[..., 1, :], atol=1e-15)


def test_from_6d_matches_hand_gram_schmidt(rng):
    six = rng.standard_normal((50, 6)) * rng.uniform(0.01, 100.0, (50, 1))
    got = rk.Rotation.from_6d(six).as_matrix()
    np.testing.assert_allclose(got, hand_gram_schmidt(six), atol=1e-14)
    R = rk.Rotation.random(20, rng)
    assert np.all(rk.Rotation.from_6d(R.as_6d()).approx_equal(R, atol=1e-15))
    # Only the direction of a1 and the half-plane of a2 matter.
    scaled = np.concatenate([3.0 * six[:, :3], 0.5 * six[:, 3:] + 2.0 * six[:, :3]], 1)
    assert np.all(
        rk.Rotation.from_6d(scaled).approx_equal(rk.Rotation.from_6d(six), atol=1e-13)
    )


def test_from_6d_degenerate_and_nonfinite():
    good = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    for bad in (
        [1.0, 1.0, 0.0, 2.0, 2.0, 0.0],  # parallel (rounding residue, not exactly 0)
        [1.0, 0.0, 0.0, -3.0, 0.0, 0.0],  # antiparallel
        [0.0, 0.0, 0.0, 0.0, 1.0, 0.0],  # zero a1
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],  # zero a2
    ):
        with pytest.raises(DegenerateInputError) as err:
            rk.Rotation.from_6d(np.array([good, good, bad]))
        assert err.value.index == (2,)
    with pytest.raises(NonFiniteError) as err:
        rk.Rotation.from_6d([good, [np.nan] + good[1:]])
    assert err.value.index == (1,)
    assert np.isfinite(rot6d.quat_from_rot6d_unchecked([1.0, 0, 0, 2.0, 0, 0])).all()
    with pytest.raises(ShapeError):
        rk.Rotation.from_6d(np.zeros((2, 5)))


def test_6d_float32_and_torch_gradient(rng, torch):
    six = rng.standard_normal((4, 6))
    r32 = rk.Rotation.from_6d(six.astype(np.float32))
    assert r32.dtype == np.float32 and r32.as_6d().dtype == np.float32
    np.testing.assert_allclose(r32.as_matrix(), hand_gram_schmidt(six), atol=1e-6)
    # Autodiff through torch against central differences of the NumPy path.
    x = torch.tensor(six[0], requires_grad=True)
    jac = torch.autograd.functional.jacobian(
        lambda v: rk.Rotation.from_6d(v).as_matrix().reshape(9), x
    ).numpy()
    h = 1e-6
    fd = np.column_stack(
        [
            (
                rk.Rotation.from_6d(six[0] + h * e).as_matrix()
                - rk.Rotation.from_6d(six[0] - h * e).as_matrix()
            ).reshape(9)
            / (2 * h)
            for e in np.eye(6)
        ]
    )
    np.testing.assert_allclose(jac, fd, atol=1e-8)


# -- swing-twist -----------------------------------------------------------------------
def check_swing_twist(R, n, swing, twist):
    n = unit(n)
    assert np.all((swing @ twist).approx_equal(R, atol=1e-15))
    qs, qt = swing.as_quat(), twist.as_quat()
    # twist about n: vector part parallel to n; swing: vector part orthogonal to n
    np.testing.assert_allclose(np.cross(qt[..., 1:], n), 0.0, atol=1e-15)
    np.testing.assert_allclose(np.sum(qs[..., 1:] * n, axis=-1), 0.0, atol=1e-15)
    assert np.all(qt[..., 0] >= 0.0)


def test_swing_twist_properties_and_batches(rng):
    R = rk.Rotation.random(200, rng)
    n = rng.standard_normal((200, 3)) * 5.0
    swing, twist = R.swing_twist(n)
    check_swing_twist(R, n, swing, twist)
    # One axis for a whole batch (broadcast), given with any length.
    swing, twist = R.swing_twist([0.0, 0.0, 0.2])
    check_swing_twist(R, [0.0, 0.0, 1.0], swing, twist)


def test_swing_twist_recovers_known_factors(rng):
    """R = S(alpha about m, m orthogonal to n) @ T(beta about n): both recovered."""
    n = unit(rng.standard_normal(3))
    m = unit(np.cross(n, rng.standard_normal(3)))
    for alpha, beta in [(0.3, 1.1), (2.5, -0.4), (1e-9, 3.0), (0.7, -math.pi + 1e-6)]:
        S = rk.Rotation.from_axis_angle(m, alpha)
        T = rk.Rotation.from_axis_angle(n, beta)
        swing, twist = (S @ T).swing_twist(n)
        assert swing.approx_equal(S, atol=1e-15) and twist.approx_equal(T, atol=1e-15)
        twist_angle = 2.0 * math.atan2(
            float(twist.as_quat()[1:] @ n), float(twist.as_quat()[0])
        )
        assert abs(twist_angle - beta) <= 1e-14


def test_swing_twist_edge_cases(rng):
    n = unit([1.0, 2.0, -0.5])
    # A twist of pi: R is the half turn about n; swing the identity.
    R = rk.Rotation.from_axis_angle(n, math.pi)
    swing, twist = R.swing_twist(n)
    assert twist.approx_equal(R, atol=1e-15) and swing.approx_equal(
        rk.Rotation.identity(), atol=1e-15
    )
    assert abs(float(twist.angle) - math.pi) <= 1e-15
    # A swing of 180 degrees: every twist fits; the identity is returned.
    m = unit(np.cross(n, [0.0, 0.0, 1.0]))
    for beta in (0.0, 0.9, -2.0):
        R = rk.Rotation.from_axis_angle(m, math.pi) @ rk.Rotation.from_axis_angle(n, beta)
        swing, twist = R.swing_twist(n)
        check_swing_twist(R, n, swing, twist)
        assert abs(float(swing.angle) - math.pi) <= 1e-14
        if beta == 0.0:
            assert twist.approx_equal(rk.Rotation.identity(), atol=0.0)
    # The identity and a turn about n only.
    swing, twist = rk.Rotation.identity().swing_twist(n)
    assert swing.angle == 0.0 and twist.angle == 0.0
    with pytest.raises(ZeroNormError):
        rk.Rotation.identity().swing_twist([0.0, 0.0, 0.0])
    with pytest.raises(NonFiniteError):
        swing_twist.swing_twist([1.0, 0.0, 0.0, 0.0], [np.nan, 0.0, 1.0])


# -- distances -------------------------------------------------------------------------
def test_distances_match_scipy_and_frobenius(rng):
    r1, r2 = SciRotation.random(100, rng), SciRotation.random(100, rng)
    R1 = rk.Rotation.from_quat(r1.as_quat(scalar_first=True))
    R2 = rk.Rotation.from_quat(r2.as_quat(scalar_first=True))
    np.testing.assert_allclose(R1.angle_to(R2), (r1.inv() * r2).magnitude(), atol=1e-14)
    np.testing.assert_allclose(rk.geodesic_distance(R1, R2), R1.angle_to(R2), rtol=0)
    frob = np.linalg.norm(r1.as_matrix() - r2.as_matrix(), axis=(-2, -1))
    np.testing.assert_allclose(R1.chordal_distance(R2), frob, atol=1e-14)
    np.testing.assert_allclose(rk.chordal_distance(R1, R2), frob, atol=1e-14)
    # Broadcasting: one rotation against a batch; symmetric; invariant.
    np.testing.assert_allclose(R1[0].angle_to(R2), R2.angle_to(R1[0]), atol=1e-15)
    A = rk.Rotation.random((), rng)
    np.testing.assert_allclose((A @ R1).chordal_distance(A @ R2), frob, atol=1e-14)
    # The functional form takes any scale of quaternion (validated).
    q1 = 3.0 * r1.as_quat(scalar_first=True)
    np.testing.assert_allclose(
        distances.chordal_distance(q1, R2.as_quat()), frob, atol=1e-14
    )
    with pytest.raises(NonFiniteError):
        distances.chordal_distance([np.nan, 0, 0, 1.0], [1.0, 0, 0, 0])


def test_distances_small_and_half_turn(rng):
    """Relative accuracy at tiny angles (|I - R|_F = 2 sqrt(2) sin(theta/2) ~ sqrt(2)
    theta) and the largest chordal distance 2 sqrt(2) at a half turn."""
    I = rk.Rotation.identity()
    e = unit(rng.standard_normal((5, 3)))
    for theta in (1e-150, 1e-12, 1e-8, 1e-4):
        R2 = rk.Rotation.from_rotvec(theta * e)  # exact to rounding, relatively
        np.testing.assert_allclose(I.angle_to(R2), theta, rtol=1e-15)
        np.testing.assert_allclose(
            I.chordal_distance(R2), math.sqrt(2.0) * theta, rtol=1e-8
        )
    # A rotated pair: the stored quaternions round by ~1e-16, absolutely.
    R1 = rk.Rotation.random(5, rng)
    R2 = R1 @ rk.Rotation.from_rotvec(1e-8 * e)
    np.testing.assert_allclose(R1.chordal_distance(R2), math.sqrt(2.0) * 1e-8, atol=1e-15)
    R2 = R1 @ rk.Rotation.from_rotvec(math.pi * e)
    np.testing.assert_allclose(R1.chordal_distance(R2), 2.0 * math.sqrt(2.0), rtol=1e-15)
    np.testing.assert_allclose(R1.angle_to(R2), math.pi, rtol=1e-15)


# -- quaternion continuity and Euler unwrapping ----------------------------------------
def smooth_quats(rng, n=60):
    t = np.linspace(0.0, 6.0, n)[:, None]
    rotvec = np.hstack([np.sin(t), 0.5 * t, np.cos(2 * t)])
    return rk.Rotation.from_rotvec(rotvec).as_quat(canonical=False).copy()


def test_quat_continuous_against_explicit_flips(rng):
    q = smooth_quats(rng)
    q = rk.quat_continuous(q)  # the reference: a continuous sequence
    assert np.all(np.sum(q[1:] * q[:-1], axis=-1) >= 0.0)
    flips = rng.choice([-1.0, 1.0], size=len(q))
    flips[0] = 1.0
    got = rk.quat_continuous(q * flips[:, None])
    np.testing.assert_array_equal(got, q)
    # The first element keeps its sign.
    np.testing.assert_array_equal(rk.quat_continuous(-q), -q)
    # Another sequence axis, with a batch axis after it.
    both = np.stack([q * flips[:, None], -q], axis=1)  # (N, 2, 4)
    got = rk.quat_continuous(both, axis=0)
    np.testing.assert_array_equal(got[:, 0], q)
    np.testing.assert_array_equal(got[:, 1], -q)
    # The Rotation form: same rotations, continuous storage.
    R = rk.Rotation.from_quat(q * flips[:, None])
    C = R.continuous()
    assert np.all(C.approx_equal(R, atol=1e-15))
    assert np.all(np.sum(C.as_quat()[1:] * C.as_quat()[:-1], axis=-1) >= 0.0)
    with pytest.raises(ShapeError):
        rk.quat_continuous(q, axis=-1)


def test_unwrap_euler_matches_numpy_unwrap(rng):
    raw = np.cumsum(rng.uniform(-2.5, 2.5, (3, 40, 3)), axis=1)
    wrapped = (raw + np.pi) % (2 * np.pi) - np.pi
    got = rk.unwrap_euler(wrapped)
    np.testing.assert_allclose(got, np.unwrap(wrapped, axis=-2), atol=1e-12)
    # The steps are below pi, so unwrapping recovers the walk up to one offset.
    offset = got - raw
    np.testing.assert_allclose(
        offset, np.broadcast_to(offset[:, :1], offset.shape), atol=1e-12
    )
    deg = np.degrees(wrapped)
    np.testing.assert_allclose(
        rk.unwrap_euler(deg, degrees=True), np.unwrap(deg, axis=-2, period=360.0), atol=1e-9
    )
    along0 = np.moveaxis(wrapped, 1, 0)  # (40, 3 batch, 3)
    np.testing.assert_allclose(
        rk.unwrap_euler(along0, axis=0), np.unwrap(along0, axis=0), atol=1e-12
    )
    # numpy's convention at exactly +-pi steps.
    edge = np.array([[0.0, 0.0, 0.0], [np.pi, -np.pi, 0.0], [0.0, 0.0, 0.0]])
    np.testing.assert_array_equal(rk.unwrap_euler(edge), np.unwrap(edge, axis=0))


def test_unwrap_a_yaw_sweep():
    """Euler angles of a yaw sweep past pi jump by 2 pi; unwrapped they are the sweep."""
    yaw = np.linspace(0.0, 4 * np.pi, 101)
    angles = np.column_stack([yaw, np.full(101, 0.2), np.full(101, -0.1)])
    read = rk.Rotation.from_euler("ZYX", angles).as_euler("ZYX")
    assert np.abs(np.diff(read[:, 0])).max() > 6.0
    np.testing.assert_allclose(rk.unwrap_euler(read), angles, atol=1e-12)


def test_sequences_on_torch_and_under_jit(rng, torch, jax):
    q = smooth_quats(rng, 20)
    q = rk.quat_continuous(q)
    flips = np.where(np.arange(20) % 3 == 1, -1.0, 1.0)[:, None]
    got = rk.quat_continuous(torch.tensor(q * flips))
    assert isinstance(got, torch.Tensor)
    np.testing.assert_array_equal(got.numpy(), q)
    jq = jax.jit(rk.quat_continuous)(jax.numpy.asarray(q * flips))
    np.testing.assert_array_equal(np.asarray(jq), q)
    wrapped = (np.cumsum(rng.uniform(-2.5, 2.5, (30, 3)), 0) + np.pi) % (2 * np.pi) - np.pi
    ju = jax.jit(rk.unwrap_euler)(jax.numpy.asarray(wrapped))
    np.testing.assert_allclose(np.asarray(ju), np.unwrap(wrapped, axis=0), atol=1e-12)
    tu = rk.unwrap_euler(torch.tensor(wrapped))
    np.testing.assert_allclose(tu.numpy(), np.unwrap(wrapped, axis=0), atol=1e-12)
