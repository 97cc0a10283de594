"""``rk.ExtendedPose``, SE_2(3): what the generic group tests do not see.

The axioms, the Jacobians, the generated methods and immutability are tested for it
by the tests that iterate over the registry of groups (``tests/test_group_axioms.py``,
``test_jacobians_fd.py``, ``test_jacobians_ops.py``, ...). Here: its own layout (the
5x5 matrix and the tangent order ``(rho_v, rho_p, w)``) against ``scipy.linalg.expm``
and ``logm`` of that matrix written out by hand, the constructor, validation,
float32, and the torch and JAX paths.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk
from rigidkit.errors import NotARigidTransformError


def hat5(xi):
    """The 5x5 ``[[hat(w), rho_v, rho_p], [0, 0, 0], [0, 0, 0]]``, written out here."""
    a, b, w = xi[:3], xi[3:6], xi[6:]
    M = np.zeros((5, 5))
    M[:3, :3] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    M[:3, 3], M[:3, 4] = a, b
    return M


def tangents(rng, n, angle):
    xi = rng.standard_normal((n, 9))
    w = rng.standard_normal((n, 3))
    xi[:, 6:] = w / np.linalg.norm(w, axis=-1, keepdims=True) * np.asarray(angle)[..., None]
    return xi


@pytest.mark.parametrize("angle", [0.0, 1e-9, 1e-4, 0.03, 0.5, 2.0, np.pi - 1e-6])
def test_exp_is_expm_of_the_5x5_matrix(angle, rng):
    xi = tangents(rng, 16, np.full(16, angle))
    got = rk.ExtendedPose.exp(xi).as_matrix()
    want = np.array([sl.expm(hat5(x)) for x in xi])
    np.testing.assert_allclose(got, want, rtol=0, atol=2e-15 * np.abs(want).max())
    np.testing.assert_allclose(
        rk.se23.exp(xi), want, rtol=0, atol=2e-15 * np.abs(want).max()
    )


@pytest.mark.parametrize("angle", [1e-9, 1e-4, 0.5, 2.0, 3.0])
def test_log_is_logm_of_the_5x5_matrix(angle, rng):
    xi = tangents(rng, 16, np.full(16, angle))
    M = np.array([sl.expm(hat5(x)) for x in xi])
    X = rk.ExtendedPose.from_matrix(M)
    want = np.array([np.real(sl.logm(m)) for m in M])
    got = X.log()
    np.testing.assert_allclose(
        np.array([hat5(g) for g in got]), want, rtol=0, atol=1e-12 * np.abs(want).max()
    )
    np.testing.assert_allclose(got, xi, rtol=0, atol=1e-12 * (1 + np.abs(xi).max()))
    np.testing.assert_allclose(rk.se23.log(M), got, rtol=0, atol=1e-15)


def test_parts_and_layout(rng):
    R = SciRot.random(5, random_state=1)
    v, p = rng.standard_normal((5, 3)), rng.standard_normal((5, 3))
    X = rk.ExtendedPose(
        rotation=rk.Rotation.from_matrix(R.as_matrix()), velocity=v, position=p
    )
    M = X.as_matrix()
    np.testing.assert_allclose(M[:, :3, :3], R.as_matrix(), atol=1e-15)
    np.testing.assert_array_equal(M[:, :3, 3], v)
    np.testing.assert_array_equal(M[:, :3, 4], p)
    np.testing.assert_array_equal(M[:, 3:], np.broadcast_to(np.eye(5)[3:], (5, 2, 5)))
    np.testing.assert_array_equal(X.velocity, v)
    np.testing.assert_array_equal(X.position, p)
    # The pose part moves points: R x + p; the inverse action R^T (x - p).
    x = rng.standard_normal((5, 3))
    np.testing.assert_allclose(X @ x, R.apply(x) + p, atol=1e-14)
    np.testing.assert_allclose(
        X.apply(x, inverse=True), R.apply(x - p, inverse=True), atol=1e-14
    )
    np.testing.assert_allclose(X.pose.as_matrix()[:, :3, 3], p)
    # Only the velocity given: identity rotation, zero position, broadcast batch.
    Y = rk.ExtendedPose(velocity=[[1.0, 2.0, 3.0]])
    assert Y.shape == (1,)
    np.testing.assert_array_equal(
        Y.as_matrix()[0], np.eye(5) + np.pad([[1.0], [2], [3]], ((0, 2), (3, 1)))
    )
    assert rk.ExtendedPose().shape == ()
    assert "velocity=[1, 2, 3]" in repr(Y[0])


def test_plus_minus_are_right_and_left_products(rng):
    X = rk.ExtendedPose.random(4, rng)
    xi = 0.3 * rng.standard_normal((4, 9))
    E = np.array([sl.expm(hat5(x)) for x in xi])
    np.testing.assert_allclose(X.plus(xi).as_matrix(), X.as_matrix() @ E, atol=1e-13)
    np.testing.assert_allclose(
        X.plus(xi, side="left").as_matrix(), E @ X.as_matrix(), atol=1e-13
    )
    np.testing.assert_allclose(X.plus(xi).minus(X), xi, atol=1e-13)
    np.testing.assert_allclose(
        X.plus(xi, side="left").minus(X, side="left"), xi, atol=1e-13
    )


def test_from_matrix_rejects_what_is_not_an_extended_pose():
    M = np.eye(5)
    M[3, 4] = 0.5  # the 4th row is not [0, 0, 0, 1, 0]
    with pytest.raises(NotARigidTransformError, match="4th row"):
        rk.ExtendedPose.from_matrix(M)
    M = np.stack([np.eye(5), np.eye(5)])
    M[1, 4, 3] = 1.0
    with pytest.raises(NotARigidTransformError) as err:
        rk.ExtendedPose.from_matrix(M)
    assert err.value.index == (1,)
    M = np.eye(5)
    M[0, 0] = 2.0
    with pytest.raises(NotARigidTransformError, match="rotation block"):
        rk.ExtendedPose.from_matrix(M)
    with pytest.raises(TypeError, match="Rotation"):
        rk.ExtendedPose(rotation=np.eye(3))


def test_float32_is_kept(rng):
    xi = rng.standard_normal((8, 9)).astype(np.float32)
    X = rk.ExtendedPose.exp(xi)
    for a in (
        X.as_matrix(),
        X.log(),
        (X @ X).as_matrix(),
        X.inv().as_matrix(),
        X.adjoint(),
    ):
        assert a.dtype == np.float32
    np.testing.assert_allclose(X.log(), xi, atol=2e-5)


def test_torch_autograd_matches_finite_differences(torch, rng):
    """The gradient of ``|log(A exp(xi))|^2`` in ``xi`` by autograd, against central
    differences of the NumPy path."""
    A = rk.ExtendedPose.random((), rng)
    xi0 = 0.4 * rng.standard_normal(9)

    def f_np(x):
        return float(np.sum((A @ rk.ExtendedPose.exp(x)).log() ** 2))

    At = rk.ExtendedPose._wrap(torch.tensor(np.asarray(A._data)))
    x = torch.tensor(xi0, requires_grad=True)
    y = ((At @ rk.ExtendedPose.exp(x)).log() ** 2).sum()
    y.backward()
    h = 1e-6
    fd = np.array([(f_np(xi0 + h * e) - f_np(xi0 - h * e)) / (2 * h) for e in np.eye(9)])
    np.testing.assert_allclose(x.grad.numpy(), fd, rtol=0, atol=1e-7)


def test_jax_jit_and_grad(jax, jnp, rng):
    xi = rng.standard_normal((6, 9))
    Y = rk.ExtendedPose.random(6, rng)

    @jax.jit
    def f(x, y):
        return (rk.ExtendedPose.exp(x) @ rk.ExtendedPose._wrap(y)).inv().as_matrix()

    got = np.asarray(f(jnp.asarray(xi), jnp.asarray(Y._data)))
    want = np.linalg.inv(np.array([sl.expm(hat5(x)) for x in xi]) @ Y.as_matrix())
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
    # log(exp(x)) = x: its gradient of the sum is a row of ones.
    g = jax.grad(lambda x: jnp.sum(rk.ExtendedPose.exp(x).log()))(jnp.asarray(xi[0]))
    np.testing.assert_allclose(np.asarray(g), np.ones(9), atol=1e-10)
