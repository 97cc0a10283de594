"""Rotation matrices read from files: 6 decimals are accepted and projected.

A rotation matrix written to 6 decimals (CAD exports, calibration files) is off
SO(3) by up to ~2e-6. scipy accepts such matrices; so must ``from_matrix`` with its
default tolerance, in float64 and float32, returning the nearest rotation (the
orthogonal polar factor, computed here with scipy's SVD-based ``polar``). Matrices
that are not rotations (a scaling by 1 + 1e-5 or more, a shear, a reflection) are
still refused with ``NotARotationError`` naming the batch index.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.spatial.transform import Rotation as SciRotation

import rigidkit as rk


def six_decimals(n, seed):
    return np.round(SciRotation.random(n, random_state=seed).as_matrix(), 6)


def polar_factor(M):
    return np.array([sl.polar(m)[0] for m in M])


def test_six_decimal_matrices_are_accepted_like_scipy():
    M = six_decimals(20000, 1)
    SciRotation.from_matrix(M)  # the reference accepts them
    got = rk.Rotation.from_matrix(M).as_matrix()
    # The nearest rotation, to second order in the defect (|C| <= 2e-6 here).
    ref = polar_factor(M[:500])
    np.testing.assert_allclose(got[:500], ref, rtol=0, atol=5e-12)
    assert np.abs(got - M).max() < 2e-6


def test_six_decimals_in_poses_and_float32():
    M = six_decimals(2000, 2)
    H = np.zeros((2000, 4, 4))
    H[:, :3, :3] = M
    H[:, :3, 3] = np.round(np.random.default_rng(3).standard_normal((2000, 3)), 6)
    H[:, 3, 3] = 1.0
    T = rk.Transform.from_matrix(H)
    np.testing.assert_allclose(
        T.as_matrix()[:200, :3, :3], polar_factor(M[:200]), atol=5e-12
    )
    R32 = rk.Rotation.from_matrix(M.astype(np.float32))
    assert R32.dtype == np.float32
    ref = polar_factor(M[:200])
    np.testing.assert_allclose(R32.as_matrix()[:200], ref, atol=1e-6)


def test_the_reported_case():
    """One matrix of the kind a file holds, off by more than the old 1e-6."""
    for seed in range(200):
        M = six_decimals(1, seed)[0]
        off = np.abs(M.T @ M - np.eye(3)).max()
        if off > 1.2e-6:
            break
    else:
        pytest.fail("no 6-decimal matrix off by more than 1.2e-6 found")
    R = rk.Rotation.from_matrix(M)
    np.testing.assert_allclose(R.as_matrix(), sl.polar(M)[0], atol=2e-12)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_non_rotations_are_refused(dtype):
    R = SciRotation.random(4, random_state=5).as_matrix()
    shear = np.eye(3)
    shear[0, 1] = 1e-3
    cases = {
        "scale 1 + 1e-5": R * (1 + 1e-5) if dtype == np.float64 else R * (1 + 1e-3),
        "scale 1.01": R * 1.01,
        "shear": R @ shear,
        "reflection": R @ np.diag([1.0, 1.0, -1.0]),
    }
    for name, bad in cases.items():
        batch = R.copy()
        batch[2] = bad[2]
        with pytest.raises(rk.NotARotationError) as info:
            rk.Rotation.from_matrix(batch.astype(dtype))
        assert info.value.index == (2,), name
