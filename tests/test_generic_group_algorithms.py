"""The algorithms written once for every group: the Karcher mean and the geodesic.

The groups come from the registry (``conftest.LIE_GROUPS``), so a new group is
covered as soon as its class exists. The references are independent of rigidkit's
exp and log: scipy's matrix logarithm and exponential of the homogeneous matrices.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm, logm

import rigidkit as rk
from conftest import LIE_GROUPS

groups = pytest.mark.parametrize("G", LIE_GROUPS, ids=lambda G: G.__name__)


def _concentrated(G, n, rng, spread=0.3):
    """``n`` elements ``X0 exp(tau_i)`` about a random ``X0``, ``|tau_i|`` ~ spread."""
    X0 = G.random((), rng=rng)
    tau = spread * rng.standard_normal((n, G.dof)) / np.sqrt(G.dof)
    return X0 @ G.exp(tau)


def _logm_real(M):
    L = logm(M)
    assert np.abs(np.imag(L)).max() < 1e-9
    return np.real(L)


@groups
@pytest.mark.parametrize("weighted", [False, True])
def test_mean_is_the_karcher_fixed_point(G, weighted):
    rng = np.random.default_rng(7)
    X = _concentrated(G, 6, rng)
    w = rng.uniform(0.2, 2.0, 6) if weighted else np.ones(6)
    mu = X.mean(w if weighted else None, method="geodesic")
    assert type(mu) is G and mu.shape == ()
    # sum_i w_i logm(M_mu^-1 M_i) = hat(sum_i w_i log(mu^-1 X_i)), zero at the mean
    M_mu_inv = np.linalg.inv(mu.as_matrix())
    total = sum(wi * _logm_real(M_mu_inv @ Mi) for wi, Mi in zip(w, X.as_matrix()))
    assert np.abs(total).max() < 1e-9


@groups
def test_mean_of_a_symmetric_pair_is_its_centre(G):
    rng = np.random.default_rng(3)
    X0 = G.random((), rng=rng)
    tau = 0.4 * rng.standard_normal(G.dof) / np.sqrt(G.dof)
    pair = X0 @ G.exp(np.stack([tau, -tau]))
    mu = pair.mean(method="geodesic")
    np.testing.assert_allclose(mu.as_matrix(), X0.as_matrix(), atol=1e-12)


@groups
def test_mean_along_an_axis_keeps_the_other(G):
    rng = np.random.default_rng(5)
    X = _concentrated(G, 8, rng).reshape((2, 4))
    mu = X.mean(axis=1, method="geodesic")
    assert mu.shape == (2,)
    for k in range(2):
        one = X[k].mean(method="geodesic")
        np.testing.assert_allclose(mu[k].as_matrix(), one.as_matrix(), atol=1e-12)


@groups
def test_mean_rejects_negative_weights(G):
    X = _concentrated(G, 3, np.random.default_rng(1))
    with pytest.raises(ValueError, match="negative"):
        X.mean([1.0, -1.0, 1.0], method="geodesic")


@groups
def test_slerp_follows_the_matrix_geodesic(G):
    rng = np.random.default_rng(11)
    a = _concentrated(G, 3, rng, spread=0.8)
    b = a @ G.exp(0.8 * rng.standard_normal((3, G.dof)) / np.sqrt(G.dof))
    t = np.array([0.0, 0.3, 1.0])
    got = rk.slerp(a, b, t).as_matrix()
    Ma, Mb = a.as_matrix(), b.as_matrix()
    for k in range(3):
        want = Ma[k] @ expm(t[k] * _logm_real(np.linalg.inv(Ma[k]) @ Mb[k]))
        np.testing.assert_allclose(got[k], want, atol=1e-12)


def test_slerp_refuses_two_kinds():
    with pytest.raises(TypeError, match="one Lie group"):
        rk.slerp(rk.Rotation2D.identity(), rk.Transform2D.identity(), 0.5)


@groups
def test_slerp_on_torch_and_under_jax_jit(G, torch, jax, jnp):
    a, b = G.random(3, rng=1), G.random(3, rng=2)
    t = np.array([0.2, 0.5, 0.9])
    want = rk.slerp(a, b, t).as_matrix()
    ends = [G.exp(torch.tensor(x.log())) for x in (a, b)]
    got = rk.slerp(*ends, torch.tensor(t)).as_matrix()
    assert isinstance(got, torch.Tensor)
    np.testing.assert_allclose(got.numpy(), want, atol=1e-12)
    f = jax.jit(lambda x, y, s: rk.slerp(G.exp(x), G.exp(y), s).as_matrix())
    got = f(jnp.asarray(a.log()), jnp.asarray(b.log()), jnp.asarray(t))
    np.testing.assert_allclose(np.asarray(got), want, atol=1e-12)


@groups
@pytest.mark.parametrize("gap", [0.0, 1e-8])
def test_slerp_gradient_at_coincident_ends(G, gap, torch):
    """d/ds of log(slerp(I, exp(gap e0 + s), 0.3)) by autograd and by central
    differences, where the geodesic's log is at (or next to) its zero."""
    t = torch.tensor(0.3, dtype=torch.float64)
    y = torch.zeros(G.dof, dtype=torch.float64)
    y[0] = gap

    def f(s):
        return rk.slerp(G.identity(), G.exp(y + s), t).log().sum()

    s = torch.zeros(G.dof, dtype=torch.float64, requires_grad=True)
    (g,) = torch.autograd.grad(f(s), s)
    e = torch.eye(G.dof, dtype=torch.float64) * 1e-6
    fd = [(f(e[i]) - f(-e[i])).item() / 2e-6 for i in range(G.dof)]
    np.testing.assert_allclose(g.numpy(), fd, atol=1e-7)


@groups
def test_mean_keeps_float32(G):
    X = G.exp(_concentrated(G, 5, np.random.default_rng(2)).log().astype(np.float32))
    assert X.mean()._data.dtype == np.float32
