"""Means: Rotation.mean and Transform.mean, chordal and geodesic (Karcher).

References: scipy's Rotation.mean (chordal), the SVD projection of the mean rotation
matrix (the Frobenius definition of the chordal mean), the first-order optimality
of the Karcher mean (its logs sum to zero, checked with scipy's rotation vectors),
symmetric constructions whose mean is known, and the quaternion sign flips that
must not matter.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.linalg import logm
from scipy.spatial.transform import Rotation as SR

import rigidkit as rk
from conftest import quat_angle


def scipy_rot(R):
    return SR.from_quat(np.asarray(R.as_quat()).reshape(-1, 4), scalar_first=True)


def flip_signs(R, rng):
    s = rng.choice([-1.0, 1.0], size=R.shape + (1,))
    return rk.Rotation.from_quat(np.asarray(R.as_quat()) * s)


def cluster(rng, shape, spread):
    center = rk.Rotation.random((), rng)
    noise = rk.Rotation.from_rotvec(spread * rng.standard_normal(shape + (3,)))
    return center, center @ noise


def test_chordal_mean_matches_scipy_with_and_without_weights(rng):
    _, R = cluster(rng, (200,), 0.6)
    w = rng.uniform(0.0, 2.0, 200)
    got = R.mean().as_quat()
    assert quat_angle(got, scipy_rot(R).mean().as_quat(scalar_first=True)) < 1e-13
    got_w = R.mean(w).as_quat()
    assert quat_angle(got_w, scipy_rot(R).mean(w).as_quat(scalar_first=True)) < 1e-13


def test_chordal_mean_is_the_projection_of_the_mean_matrix(rng):
    R = rk.Rotation.random(50, rng)  # spread everywhere: no cluster needed
    w = rng.uniform(0.1, 1.0, 50)
    M = np.einsum("n,nij->ij", w, R.as_matrix())
    u, _, vt = np.linalg.svd(M)
    proj = u @ np.diag([1.0, 1.0, np.linalg.det(u @ vt)]) @ vt
    assert np.allclose(R.mean(w).as_matrix(), proj, atol=1e-12)


@pytest.mark.parametrize("method", ["chordal", "geodesic"])
def test_mean_ignores_quaternion_signs(method, rng):
    _, R = cluster(rng, (100,), 0.4)
    a = R.mean(method=method).as_quat()
    b = flip_signs(R, rng).mean(method=method).as_quat()
    assert quat_angle(a, b) < 1e-14
    assert a[0] >= 0.0


def test_geodesic_mean_is_stationary(rng):
    """At the Karcher mean the weighted logs of mu^-1 R_i sum to zero (scipy's logs)."""
    _, R = cluster(rng, (300,), 0.8)
    w = rng.uniform(0.0, 1.0, 300)
    mean, info = R.mean(w, method="geodesic", return_info=True)
    rel = scipy_rot(mean).inv() * scipy_rot(R)
    grad = (w[:, None] * rel.as_rotvec()).sum(axis=0) / w.sum()
    assert np.linalg.norm(grad) < 1e-12
    assert 1 <= info["iterations"] < 100
    assert R.mean(method="chordal", return_info=True)[1] == {"iterations": 0}


def test_means_of_symmetric_sets_are_known(rng):
    # R0 exp(+-a) for random axes a: both means are R0 exactly (by symmetry).
    center = rk.Rotation.random((), rng)
    a = rng.uniform(-1.0, 1.0, (40, 3))
    R = rk.Rotation.concatenate(
        [center @ rk.Rotation.from_rotvec(a), center @ rk.Rotation.from_rotvec(-a)]
    )
    for method in ("chordal", "geodesic"):
        assert quat_angle(R.mean(method=method).as_quat(), center.as_quat()) < 1e-14


def test_noisy_mean_recovers_the_center_within_the_noise(rng):
    center, R = cluster(rng, (10_000,), 0.01)
    for method in ("chordal", "geodesic"):
        err = quat_angle(R.mean(method=method).as_quat(), center.as_quat())
        assert err < 5 * 0.01 / np.sqrt(10_000)


def test_mean_along_an_axis_is_many_means(rng):
    _, R = cluster(rng, (4, 30, 5), 0.5)
    w = rng.uniform(0.0, 1.0, (4, 30, 5))
    got = R.mean(w, axis=1, method="geodesic")
    assert got.shape == (4, 5)
    for i in (0, 3):
        for j in (1, 4):
            one = R[i, :, j].mean(w[i, :, j], method="geodesic")
            assert quat_angle(got[i, j].as_quat(), one.as_quat()) < 1e-13
    assert R.mean(axis=(0, 2)).shape == (30,)
    assert R.mean(axis=-1).shape == (4, 30)


def test_mean_float32(rng):
    _, R = cluster(rng, (100,), 0.3)
    r32 = rk.Rotation.from_quat(np.asarray(R.as_quat(), dtype=np.float32))
    for method in ("chordal", "geodesic"):
        m = r32.mean(method=method)
        assert m.dtype == np.float32
        assert quat_angle(m.as_quat(), R.mean(method=method).as_quat()) < 1e-5


def test_mean_bad_weights(rng):
    R = rk.Rotation.random(5, rng)
    with pytest.raises(rk.DegenerateInputError, match="negative") as err:
        R.mean([1.0, 1.0, -1.0, 1.0, 1.0])
    assert err.value.index == (2,)
    with pytest.raises(rk.DegenerateInputError, match="sum to zero"):
        R.mean(np.zeros(5))
    with pytest.raises(rk.NonFiniteError):
        R.mean([1.0, np.nan, 1.0, 1.0, 1.0])
    with pytest.raises(ValueError):
        R.mean(method="median")


def test_karcher_warns_when_it_cannot_converge(rng):
    R = rk.Rotation.random(50, rng)
    R.mean(method="geodesic")  # its loops now compile in the background, and
    # the engine keeps numba's warning state to the compile thread, so the warning
    # below is recorded while they do (tests/test_warnings_isolation.py)
    with pytest.warns(rk.ConvergenceWarning):
        R.mean(method="geodesic", tol=1e-300)


def test_mean_on_torch_and_jax(torch, jnp, rng):
    _, R = cluster(rng, (20,), 0.5)
    ref = R.mean(method="geodesic").as_quat()
    q = np.asarray(R.as_quat())
    for arr in (torch.tensor(q), jnp.asarray(q)):
        got = rk.Rotation.from_quat(arr).mean(method="geodesic").as_quat()
        assert quat_angle(np.asarray(got), ref) < 1e-14


def test_chordal_mean_gradient_flows(torch, rng):
    q = torch.tensor(np.asarray(cluster(rng, (10,), 0.3)[1].as_quat()), requires_grad=True)
    rk.Rotation.from_quat(q).mean().as_rotvec().sum().backward()
    assert bool(torch.isfinite(q.grad).all()) and float(q.grad.abs().sum()) > 0


# -- Transform.mean ---------------------------------------------------------------------


def test_transform_chordal_mean_is_rotation_mean_and_mean_translation(rng):
    T = rk.Transform.random(60, rng)
    w = rng.uniform(0.0, 1.0, 60)
    m = T.mean(w)
    assert quat_angle(m.rotation.as_quat(), T.rotation.mean(w).as_quat()) < 1e-15
    assert np.allclose(m.translation, (w[:, None] * T.translation).sum(0) / w.sum())


def test_transform_geodesic_mean_is_the_exponential_barycenter(rng):
    center = rk.Transform.random((), rng)
    T = center @ rk.Transform.exp(0.4 * rng.standard_normal((80, 6)))
    m = T.mean(method="geodesic")
    # sum_i log(m^-1 T_i) = 0, with matrix logarithms as the independent reference.
    rel = np.linalg.inv(m.as_matrix()) @ T.as_matrix()
    logs = np.array([logm(x).real for x in rel])
    assert np.abs(logs.mean(axis=0)).max() < 1e-11
    flipped = rk.Transform(
        rotation=flip_signs(T.rotation, rng), translation=T.translation
    ).mean(method="geodesic")
    assert np.allclose(flipped.as_matrix(), m.as_matrix(), atol=1e-14)


def test_transform_mean_along_axis_and_symmetric(rng):
    center = rk.Transform.random((), rng)
    xi = rng.uniform(-0.5, 0.5, (10, 6))
    T = rk.Transform.concatenate(
        [center @ rk.Transform.exp(xi), center @ rk.Transform.exp(-xi)]
    )
    assert np.allclose(
        T.mean(method="geodesic").as_matrix(), center.as_matrix(), atol=1e-14
    )
    batch = rk.Transform.random((3, 7), rng)
    assert batch.mean(axis=1, method="geodesic").shape == (3,)


def test_no_warning_on_ordinary_means(rng):
    _, R = cluster(rng, (100,), 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        R.mean(method="geodesic")


def test_compiled_chordal_path_matches_the_eigendecomposition(rng):
    """The NumPy fast path (a compiled pass and a 4x4 Jacobi) against linalg.eigh."""
    from rigidkit.functional import averaging

    if not averaging._gram_ready():
        if averaging._GRAM_JOB is None:
            pytest.skip("numba is not available")
        averaging._GRAM_JOB.result()
    _, R = cluster(rng, (6, 500), 1.5)
    w = rng.uniform(0.0, 1.0, (6, 500))
    for dtype, tol in ((np.float64, 1e-13), (np.float32, 1e-5)):
        q = np.asarray(R.as_quat(), dtype=dtype)
        got = rk.Rotation.from_quat(q).mean(w.astype(dtype), axis=1).as_quat()
        M = np.einsum("gk,gki,gkj->gij", w, q.astype(float), q.astype(float))
        ref = np.linalg.eigh(M)[1][..., -1]
        assert got.dtype == dtype
        assert np.all(quat_angle(got, ref) < tol)


def test_jax_geodesic_mean_stops_at_convergence_with_its_implicit_gradient(jax, jnp, rng):
    """Under JAX the Karcher iteration is a while loop that stops at convergence,
    whatever ``max_iter``, differentiated implicitly (a ``custom_jvp``): under
    ``jit`` the values are the NumPy mean's (``tol=1e-14``), the gradient its
    central differences, also under ``vmap``; forward and reverse mode agree,
    with respect to the weights too."""
    from rigidkit.functional.averaging import pose_mean

    T = rk.Transform.exp(rng.normal(size=(12, 6)) * [1.0, 1.0, 1.0, 0.6, 0.6, 0.6])
    x0 = np.concatenate([T.rotation.as_quat(), T.translation], axis=-1)  # (w, x, y, z, t)
    c = rng.normal(size=7)

    def exact(x):
        return pose_mean(x, method="geodesic", tol=1e-14)[0]

    def traced(x):
        return pose_mean(x, method="geodesic", max_iter=100_000)[0]

    x = jnp.asarray(x0)
    np.testing.assert_allclose(np.asarray(jax.jit(traced)(x)), exact(x0), atol=1e-12)
    grad = np.asarray(jax.jit(jax.grad(lambda x: jnp.sum(traced(x) * c)))(x))
    h = 1e-6
    fd = np.zeros_like(x0)
    for idx in np.ndindex(*x0.shape):
        d = np.zeros_like(x0)
        d[idx] = h
        fd[idx] = (exact(x0 + d) @ c - exact(x0 - d) @ c) / (2 * h)
    np.testing.assert_allclose(grad, fd, atol=1e-8)
    both = jax.vmap(jax.jit(traced))(jnp.stack([x, x[::-1]]))
    np.testing.assert_allclose(np.asarray(both), [exact(x0), exact(x0[::-1])], atol=1e-12)
    from rigidkit.functional.averaging import quat_mean

    q, w = x0[:5, :4], rng.uniform(0.5, 2.0, 5)

    def weighted(q, w):
        return quat_mean(q, w, method="geodesic")[0]

    fwd = jax.jit(jax.jacfwd(weighted, argnums=(0, 1)))(jnp.asarray(q), jnp.asarray(w))
    rev = jax.jit(jax.jacrev(weighted, argnums=(0, 1)))(jnp.asarray(q), jnp.asarray(w))
    for a, b in zip(fwd, rev):
        np.testing.assert_allclose(np.asarray(a), np.asarray(b), atol=1e-14)
    d = rng.normal(size=5)
    fd = (weighted(q, w + h * d) - weighted(q, w - h * d)) / (2 * h)
    np.testing.assert_allclose(np.asarray(fwd[1]) @ d, fd, atol=1e-8)
