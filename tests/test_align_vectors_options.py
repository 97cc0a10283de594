"""``rk.align_vectors``: shapes (only batch axes broadcast), infinite weights and the
sensitivity matrix, against scipy's ``Rotation.align_vectors`` problem by problem."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRotation

import rigidkit as rk
from rigidkit import DegenerateInputError, ShapeError


def _same(q_wxyz, sci, tol=1e-12):
    dot = abs(float(np.dot(q_wxyz, sci.as_quat(scalar_first=True))))
    assert abs(dot - 1.0) <= tol


@pytest.fixture
def problem(rng):
    a = rng.standard_normal((4, 6, 3))
    b = rng.standard_normal((4, 6, 3))
    w = rng.uniform(0.2, 2.0, (4, 6))
    return a, b, w


def test_pair_counts_must_match():
    """2 pairs against 1 used to broadcast silently; now a ShapeError naming both."""
    a = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    b = np.array([[0.0, 1.0, 0.0]])
    with pytest.raises(ShapeError, match=r"2 in a .* but 1 in b"):
        rk.align_vectors(a, b)
    with pytest.raises(ShapeError, match=r"4 in src .* but 3 in dst"):
        rk.align_points(np.eye(4, 3), np.eye(3))
    # Batch axes still broadcast: one pair set against a batch of two.
    R, _ = rk.align_vectors(np.stack([a, a]), b.repeat(2, 0))
    assert R.shape == (2,)


@pytest.mark.parametrize("shape", [(3,), (1, 6, 1), (6, 2), ()])
def test_badly_shaped_weights_are_shape_errors(rng, shape):
    a = rng.standard_normal((6, 3))
    w = np.ones(shape)
    with pytest.raises(ShapeError) as info:
        rk.align_vectors(a, a, w)
    assert type(info.value) is ShapeError and "weights" in str(info.value)
    with pytest.raises(ShapeError):
        rk.align_points(a, a, w)


def test_weights_batch_broadcast(problem):
    a, b, w = problem
    R, rssd = rk.align_vectors(a[0], b[0], w)  # one pair set, four weightings
    assert R.shape == (4,)
    for k in range(4):
        sci, r = SciRotation.align_vectors(a[0], b[0], w[k])
        _same(R.as_quat()[k], sci)
        assert abs(rssd[k] - r) <= 1e-12


def test_sensitivity_matches_scipy(problem):
    a, b, w = problem
    R, rssd, sens = rk.align_vectors(a, b, w, return_sensitivity=True)
    assert sens.shape == (4, 3, 3)
    for k in range(4):
        sci, r, s = SciRotation.align_vectors(a[k], b[k], w[k], return_sensitivity=True)
        _same(R.as_quat()[k], sci)
        assert abs(rssd[k] - r) <= 1e-12
        assert np.abs(sens[k] - s).max() <= 1e-12 * np.abs(s).max()


def test_sensitivity_is_the_covariance_of_the_estimate(rng):
    """Monte Carlo: isotropic angular noise sigma on unit vectors gives rotation
    vector errors of covariance sigma^2 * sensitivity (Markley 1993), here with
    the vectors turned by rotation vectors of independent N(0, sigma^2) components."""
    b = rng.standard_normal((8, 3))
    b /= np.linalg.norm(b, axis=-1, keepdims=True)
    sigma, n = 1e-3, 4000
    noise = rk.Rotation.from_rotvec(rng.normal(scale=sigma, size=(n, 8, 3)))
    a = noise.apply(b)  # true rotation: identity
    R, _, sens = rk.align_vectors(a, b, return_sensitivity=True)
    err = R.as_rotvec()
    cov = err.T @ err / n
    assert np.abs(cov - sigma**2 * sens[0]).max() <= 0.1 * sigma**2 * np.abs(sens[0]).max()


@pytest.mark.parametrize("k", [0, 3, 5])
def test_infinite_weight_matches_scipy(problem, k):
    a, b, w = problem
    w = w.copy()
    w[:, k] = np.inf
    R, rssd = rk.align_vectors(a, b, w)
    for j in range(4):
        sci, r = SciRotation.align_vectors(a[j], b[j], w[j])
        _same(R.as_quat()[j], sci)
        assert abs(rssd[j] - r) <= 1e-12
    # The primary pair is aligned exactly (its direction).
    got = R.apply(b[:, k])
    want = (
        a[:, k]
        * (np.linalg.norm(b[:, k], axis=-1) / np.linalg.norm(a[:, k], axis=-1))[:, None]
    )
    assert np.abs(got - want).max() <= 1e-14 * 8


def test_infinite_weight_in_part_of_a_batch(problem):
    a, b, w = problem
    w = w.copy()
    w[1, 2] = np.inf
    R, rssd = rk.align_vectors(a, b, w)
    for j in range(4):
        sci, r = SciRotation.align_vectors(a[j], b[j], w[j])
        _same(R.as_quat()[j], sci)


def test_infinite_weight_errors(problem):
    a, b, w = problem
    w = w.copy()
    w[2, 1] = w[2, 4] = np.inf
    with pytest.raises(DegenerateInputError, match=r"more than one infinite .*\(2,\)"):
        rk.align_vectors(a, b, w)
    w[2, 4] = 1.0
    with pytest.raises(DegenerateInputError, match="sensitivity"):
        rk.align_vectors(a, b, w, return_sensitivity=True)
    a = a.copy()
    a[2, 1] = 0.0
    with pytest.raises(DegenerateInputError, match="zero vector"):
        rk.align_vectors(a, b, w)
    with pytest.raises(rk.NonFiniteError):
        rk.align_vectors(a, b, np.where(np.isinf(w), -np.inf, w))
    with pytest.raises(rk.NonFiniteError):
        rk.align_points(a, b, w)  # align_points takes no infinite weight


def test_options_on_torch(problem):
    torch = pytest.importorskip("torch")
    a, b, w = problem
    w = w.copy()
    w[:, 0] = np.inf
    R, rssd = rk.align_vectors(torch.tensor(a), torch.tensor(b), torch.tensor(w))
    want, want_rssd = rk.align_vectors(a, b, w)
    assert isinstance(rssd, torch.Tensor)
    assert np.all(R.approx_equal(want, atol=1e-13).numpy())
    _, _, sens = rk.align_vectors(torch.tensor(a), torch.tensor(b), return_sensitivity=True)
    assert (
        np.abs(sens.numpy() - rk.align_vectors(a, b, return_sensitivity=True)[2]).max()
        < 1e-12
    )
