"""Alignment from data: rk.align_vectors (Wahba/Kabsch) and rk.align_points (Umeyama).

References: scipy's align_vectors; known rotations and motions recovered from
noiseless data (to 1e-12 and better); noisy data within the noise level; the
residual sum recomputed here from its definition; closed forms for one pair and
for parallel or antiparallel vectors (the shortest arc).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SR

import rigidkit as rk
from conftest import quat_angle


def apply_all(R, v):
    """``R @ v`` for a batch of rotations (...) and vectors (..., N, 3), by matrices."""
    return np.einsum("...ij,...nj->...ni", R.as_matrix(), v)


def test_known_rotation_recovered_from_noiseless_vectors(rng):
    R = rk.Rotation.random((), rng)
    b = rng.standard_normal((20, 3))
    got, rssd = rk.align_vectors(apply_all(R, b), b)
    assert quat_angle(got.as_quat(), R.as_quat()) < 1e-15
    assert rssd < 1e-13  # scipy's formula cancels down to ~1e-7 here


def test_matches_scipy_on_noisy_weighted_vectors(rng):
    R = rk.Rotation.random((), rng)
    b = rng.standard_normal((30, 3))
    a = apply_all(R, b) + 0.05 * rng.standard_normal((30, 3))
    w = rng.uniform(0.1, 2.0, 30)
    got, rssd = rk.align_vectors(a, b, w)
    ref, ref_rssd = SR.align_vectors(a, b, w)
    assert quat_angle(got.as_quat(), ref.as_quat(scalar_first=True)) < 1e-13
    assert abs(rssd - ref_rssd) < 1e-12
    resid = a - apply_all(got, b)
    assert abs(rssd - np.sqrt(np.sum(w * np.sum(resid**2, axis=-1)))) < 1e-14
    # Noise 0.05 per component over 30 pairs: the error is ~0.05/sqrt(30) rad.
    assert quat_angle(got.as_quat(), R.as_quat()) < 0.05


def test_reflection_is_never_returned(rng):
    # a = a reflection of b: the best proper rotation, not the reflection.
    b = rng.standard_normal((10, 3))
    a = b * np.array([1.0, 1.0, -1.0])
    got, _ = rk.align_vectors(a, b)
    assert np.isclose(np.linalg.det(got.as_matrix()), 1.0)
    ref, _ = SR.align_vectors(a, b)
    assert quat_angle(got.as_quat(), ref.as_quat(scalar_first=True)) < 1e-12


def test_single_pair_is_the_shortest_arc():
    a = np.array([[0.0, 0.0, 2.0]])
    b = np.array([[1.0, 0.0, 0.0]])
    got, rssd = rk.align_vectors(a, b)
    # +x to +z: a quarter turn about -y.
    want = rk.Rotation.from_rotvec([0.0, -np.pi / 2, 0.0])
    assert quat_angle(got.as_quat(), want.as_quat()) < 1e-15
    assert abs(rssd - 1.0) < 1e-15  # |a - R b| = |2 - 1|


def test_single_pair_matches_scipy(rng):
    for _ in range(20):
        a, b = rng.standard_normal((2, 1, 3))
        got, rssd = rk.align_vectors(a, b)
        ref, ref_rssd = SR.align_vectors(a, b)
        assert quat_angle(got.as_quat(), ref.as_quat(scalar_first=True)) < 1e-14
        assert abs(rssd - ref_rssd) < 1e-12


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_parallel_and_antiparallel_vectors(sign, rng):
    u = rng.standard_normal(3)
    u /= np.linalg.norm(u)
    b = np.outer([1.0, -2.0, 0.5], u)  # all along u, both senses
    a = sign * b
    got, rssd = rk.align_vectors(a, b)
    assert np.allclose(apply_all(got, b), a, atol=1e-14)
    assert rssd < 1e-14
    expected_angle = 0.0 if sign > 0 else np.pi
    assert abs(float(got.angle) - expected_angle) < 1e-14


def test_antiparallel_single_pairs_along_the_axes():
    for axis in np.eye(3):
        got, rssd = rk.align_vectors(-axis[None], axis[None])
        assert np.allclose(got.apply(axis), -axis, atol=1e-15)
        assert abs(float(got.angle) - np.pi) < 1e-15 and rssd < 1e-15


def test_batched_problems(rng):
    R = rk.Rotation.random((4, 25), rng)
    b = rng.standard_normal((4, 25, 20, 3))
    got, rssd = rk.align_vectors(apply_all(R, b), b)
    assert got.shape == (4, 25) and rssd.shape == (4, 25)
    assert np.all(quat_angle(got.as_quat(), R.as_quat()) < 1e-14)
    # Broadcasting: one set of b for all problems.
    got2, _ = rk.align_vectors(apply_all(R, b[0, 0]), b[0, 0])
    assert np.all(quat_angle(got2.as_quat(), R.as_quat()) < 1e-14)


def test_float32(rng):
    R = rk.Rotation.random((), rng)
    b = rng.standard_normal((20, 3)).astype(np.float32)
    got, rssd = rk.align_vectors(apply_all(R, b).astype(np.float32), b)
    assert got.dtype == np.float32 and rssd.dtype == np.float32
    assert quat_angle(got.as_quat(), R.as_quat()) < 1e-6


def test_degenerate_vectors_raise():
    with pytest.raises(rk.DegenerateInputError, match="zero"):
        rk.align_vectors(np.zeros((3, 3)), np.ones((3, 3)))
    with pytest.raises(rk.DegenerateInputError, match="zero"):
        rk.align_vectors(np.eye(3), np.eye(3), np.zeros(3))
    with pytest.raises(rk.DegenerateInputError, match="negative"):
        rk.align_vectors(np.eye(3), np.eye(3), [1.0, -1.0, 1.0])
    with pytest.raises(rk.NonFiniteError):
        rk.align_vectors(np.full((3, 3), np.nan), np.eye(3))
    with pytest.raises(rk.ShapeError):
        rk.align_vectors(np.eye(3)[0], np.eye(3)[0])
    with pytest.raises(rk.DegenerateInputError) as err:
        batch = np.ones((3, 2, 3))
        batch[1] = 0.0
        rk.align_vectors(batch, np.ones((3, 2, 3)))
    assert err.value.index == (1,)


def test_align_vectors_on_torch_with_gradients(torch, rng):
    R = rk.Rotation.random((), rng)
    b = rng.standard_normal((10, 3))
    a = torch.tensor(
        apply_all(R, b) + 0.01 * rng.standard_normal((10, 3)), requires_grad=True
    )
    got, rssd = rk.align_vectors(a, torch.tensor(b))
    ref, ref_rssd = rk.align_vectors(a.detach().numpy(), b)
    assert quat_angle(got.as_quat().detach().numpy(), ref.as_quat()) < 1e-14
    rssd.backward()
    assert bool(torch.isfinite(a.grad).all())


def test_align_vectors_on_jax(jnp, rng):
    R = rk.Rotation.random((5,), rng)
    b = rng.standard_normal((5, 8, 3))
    got, _ = rk.align_vectors(jnp.asarray(apply_all(R, b)), jnp.asarray(b))
    assert np.all(quat_angle(np.asarray(got.as_quat()), R.as_quat()) < 1e-14)


# -- align_points -----------------------------------------------------------------------


def test_known_transform_recovered_from_noiseless_points(rng):
    T = rk.Transform.random((), rng, scale=5.0)
    src = rng.standard_normal((15, 3))
    got = rk.align_points(src, T @ src)
    assert isinstance(got, rk.Transform)
    assert quat_angle(got.rotation.as_quat(), T.rotation.as_quat()) < 1e-14
    assert np.allclose(got.translation, T.translation, atol=1e-13)


def test_known_similarity_recovered(rng):
    R = rk.Rotation.random((), rng)
    t = rng.standard_normal(3)
    src = rng.standard_normal((12, 3))
    dst = 3.7 * apply_all(R, src) + t
    got = rk.align_points(src, dst, scale=True)
    assert isinstance(got, rk.Similarity)
    assert np.allclose(got @ src, dst, atol=1e-13)
    assert np.allclose(got.as_matrix()[:3, 3], t, atol=1e-13)
    assert abs(np.linalg.det(got.as_matrix()[:3, :3]) ** (1 / 3) - 3.7) < 1e-13


def test_noisy_points_and_weights(rng):
    T = rk.Transform.random((), rng)
    src = rng.standard_normal((500, 3))
    dst = T @ src + 0.01 * rng.standard_normal((500, 3))
    got = rk.align_points(src, dst)
    assert quat_angle(got.rotation.as_quat(), T.rotation.as_quat()) < 5 * 0.01 / np.sqrt(
        500
    )
    # Zero weights remove points: the same as leaving them out.
    w = np.ones(500)
    w[::3] = 0.0
    keep = w > 0
    a = rk.align_points(src, dst, w)
    b = rk.align_points(src[keep], dst[keep])
    assert np.allclose(a.as_matrix(), b.as_matrix(), atol=1e-13)
    # Weights scale out: the weighted problem with 2 w is the same problem.
    c = rk.align_points(src, dst, 2 * w)
    assert np.allclose(a.as_matrix(), c.as_matrix(), atol=1e-13)


def test_align_points_minimises_the_residual(rng):
    # The fit beats every nearby rigid motion (first-order optimality, by sampling).
    src = rng.standard_normal((30, 3))
    dst = rng.standard_normal((30, 3))
    best = rk.align_points(src, dst)

    def cost(T):
        return np.sum((dst - T @ src) ** 2)

    for _ in range(20):
        nearby = best @ rk.Transform.exp(1e-4 * rng.standard_normal(6))
        assert cost(nearby) >= cost(best)


def test_align_points_batched(rng):
    T = rk.Transform.random((10,), rng)
    src = rng.standard_normal((10, 20, 3))
    dst = np.einsum("bij,bnj->bni", T.as_matrix()[:, :3, :3], src) + T.translation[:, None]
    got = rk.align_points(src, dst)
    assert got.shape == (10,)
    assert np.allclose(got.as_matrix(), T.as_matrix(), atol=1e-13)


def test_degenerate_points_raise(rng):
    src = rng.standard_normal((2, 3))
    with pytest.raises(rk.DegenerateInputError, match="at least 3"):
        rk.align_points(src, src)
    line = np.outer(np.arange(6.0), [1.0, 2.0, -1.0])
    with pytest.raises(rk.DegenerateInputError, match="collinear"):
        rk.align_points(line, line + 1.0)
    same = np.ones((5, 3))
    with pytest.raises(rk.DegenerateInputError, match="coincident"):
        rk.align_points(same, same)
    pts = rng.standard_normal((5, 3))
    with pytest.raises(rk.DegenerateInputError, match="sum to zero"):
        rk.align_points(pts, pts, np.zeros(5))
    with pytest.raises(rk.DegenerateInputError, match="collinear"):
        rk.align_points(pts, pts, [1.0, 1.0, 0.0, 0.0, 0.0])  # two points remain
    batch = np.stack([pts, line[:5]])
    with pytest.raises(rk.DegenerateInputError) as err:
        rk.align_points(batch, batch)
    assert err.value.index == (1,)


def test_no_warnings(rng):
    b = rng.standard_normal((5, 3))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rk.align_vectors(b, b)
        rk.align_points(b, b, scale=True)
