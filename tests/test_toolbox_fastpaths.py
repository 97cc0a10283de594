"""The NumPy fast paths of slerp and the chordal mean against independent references.

``Rotation.mean()`` (unweighted, whole batch) goes straight to the compiled Gram
loop and its Jacobi solve once that is compiled; ``rk.slerp`` checks a few ``t``
values in Python. References: ``numpy.linalg.eigh`` of the 4x4 sum (the chordal
mean's definition) and scipy's ``A * from_rotvec(t (A^-1 B).as_rotvec())``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SR

import rigidkit as rk
from conftest import quat_angle


def _ready_gram():
    from rigidkit.functional import averaging

    if not averaging._gram_ready():
        if averaging._GRAM_JOB is None:
            pytest.skip("numba is not available")
        averaging._GRAM_JOB.result()


@pytest.mark.parametrize(
    "shape, dtype, tol",
    [((2,), np.float64, 1e-13), ((37,), np.float64, 1e-13), ((3, 5), np.float64, 1e-13),
     ((40,), np.float32, 1e-5)],
)  # fmt: skip
def test_unweighted_mean_fast_path_is_the_dominant_eigenvector(shape, dtype, tol, rng):
    _ready_gram()
    q = rng.standard_normal(shape + (4,))
    q[..., 0] += 2.0  # a cluster, so the top eigenvalue is well separated
    q *= rng.choice([-1.0, 1.0], size=shape + (1,))  # signs must not matter
    R = rk.Rotation.from_quat(q.astype(dtype))
    got = R.mean().as_quat()
    flat = np.asarray(R.as_quat(), dtype=np.float64).reshape(-1, 4)
    ref = np.linalg.eigh(flat.T @ flat)[1][:, -1]
    assert got.shape == (4,) and got.dtype == dtype
    assert got[0] >= 0.0
    assert quat_angle(got, ref) < tol
    # A strided view takes the general path and must give the same mean.
    wide = rk.Rotation.from_quat(np.repeat(q.astype(dtype), 2, axis=0))
    assert quat_angle(wide[::2].mean().as_quat(), got) < tol


def test_slerp_fraction_checks(rng):
    q = rng.standard_normal((2, 5, 4))
    A, B = rk.Rotation.from_quat(q[0]), rk.Rotation.from_quat(q[1])
    t = rng.uniform(-0.5, 1.5, 5)
    sa = SR.from_quat(np.asarray(A.as_quat()), scalar_first=True)
    sb = SR.from_quat(np.asarray(B.as_quat()), scalar_first=True)
    ref = (sa * SR.from_rotvec((sa.inv() * sb).as_rotvec() * t[:, None])).as_quat(
        scalar_first=True
    )
    assert np.all(quat_angle(rk.slerp(A, B, t).as_quat(), ref) < 1e-14)
    np.testing.assert_array_equal(rk.slerp(A[0], B[0], 0.0).as_quat(), A[0].as_quat())
    for bad in (np.nan, np.inf, np.array([0.5, np.nan, 0.1, 0.2, 0.3])):
        with pytest.raises(rk.NonFiniteError):
            rk.slerp(A, B, bad)


def test_slerp_fraction_check_of_many_values(rng):
    """Above 16 values t is checked by one isfinite pass: NaN or inf anywhere is
    caught, with its index; finite t pass."""
    q = rng.standard_normal((2, 40, 4))
    A, B = rk.Rotation.from_quat(q[0]), rk.Rotation.from_quat(q[1])
    for bad in (np.nan, np.inf, -np.inf):
        t = rng.uniform(0.0, 1.0, (5, 8))
        t[3, 6] = bad
        with pytest.raises(rk.NonFiniteError) as err:
            rk.slerp(A.reshape(5, 8), B.reshape(5, 8), t)
        assert tuple(err.value.index) == (3, 6)
    t = np.zeros(40)
    t[1::2] = 1.0
    out = rk.slerp(A, B, t).as_quat()
    np.testing.assert_array_equal(out[::2], A.as_quat()[::2])
    assert np.all(quat_angle(out[1::2], B.as_quat()[1::2]) < 1e-14)


@pytest.mark.parametrize("n", [None, 1, 10, 64, 65])
def test_slerp_quick_fraction_check_keeps_every_error(n, rng):
    """The quick test of t that rk.slerp takes (check_finite's: 0-d, a float
    conversion; up to 64 values, a Python sum) lets no NaN or inf through, reports
    its index, and does not reject finite values whose sum overflows."""
    shape = () if n is None else (n,)
    q = rng.standard_normal((2,) + shape + (4,))
    A, B = rk.Rotation.from_quat(q[0]), rk.Rotation.from_quat(q[1])
    k = () if n is None else (n - 1,)
    for bad in (np.nan, np.inf, -np.inf):
        t = rng.uniform(0.0, 1.0, shape)
        t[k] = bad
        with pytest.raises(rk.NonFiniteError) as err:
            rk.slerp(A, B, t)
        assert tuple(err.value.index) == k
        if n is None:  # a Python float takes its own path
            with pytest.raises(rk.NonFiniteError):
                rk.slerp(A, B, float(bad))
        with rk.set_validation(False):  # unchecked: NaN propagates, no error
            assert np.isnan(
                rk.slerp(A, B, np.where(np.isfinite(t), t, np.nan)).as_quat()[k]
            ).all()
    t = np.full(shape, 1e308)  # finite; a sum of two overflows
    got = rk.slerp(A, B, t).as_quat()
    assert np.all(np.isfinite(got))
    np.testing.assert_allclose(np.linalg.norm(got, axis=-1), 1.0, rtol=1e-14)
    t = rng.uniform(-0.5, 1.5, shape)
    sa = SR.from_quat(np.asarray(A.as_quat()), scalar_first=True)
    sb = SR.from_quat(np.asarray(B.as_quat()), scalar_first=True)
    ref = (sa * SR.from_rotvec((sa.inv() * sb).as_rotvec() * t[..., None])).as_quat(
        scalar_first=True
    )
    assert np.all(quat_angle(rk.slerp(A, B, t).as_quat(), ref) < 1e-14)
    if n is None:
        assert np.all(quat_angle(rk.slerp(A, B, float(t)).as_quat(), ref) < 1e-14)


@pytest.mark.parametrize("shape", [(), (10,)])
@pytest.mark.parametrize("t", [0.3, 2, -1.5])
def test_a_python_number_t_keeps_float32(shape, t, rng):
    """A Python float or int t is weak, as in NumPy: float32 ends give float32
    (slerp, power, pose slerp), equal to scipy's float64 geodesic within float32."""
    from rigidkit.functional import interpolation as fi

    q = rng.standard_normal((2,) + shape + (4,))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    sa = SR.from_quat(q[0].reshape(-1, 4), scalar_first=True)
    sb = SR.from_quat(q[1].reshape(-1, 4), scalar_first=True)
    ref = (sa * SR.from_rotvec((sa.inv() * sb).as_rotvec() * t)).as_quat(scalar_first=True)
    A, B = (rk.Rotation.from_quat(x.astype(np.float32)) for x in q)
    got = rk.slerp(A, B, t).as_quat()
    assert got.dtype == np.float32 and got.shape == shape + (4,)
    assert np.all(quat_angle(got.reshape(-1, 4).astype(np.float64), ref) < 1e-5)
    power = fi.quat_power(q[0].astype(np.float32), t)
    ref_power = SR.from_rotvec(sa.as_rotvec() * t).as_quat(scalar_first=True)
    assert power.dtype == np.float32
    assert np.all(quat_angle(power.reshape(-1, 4).astype(np.float64), ref_power) < 1e-5)
    poses = np.concatenate([q, rng.standard_normal((2,) + shape + (3,))], axis=-1)
    p32 = poses.astype(np.float32)
    mid = fi.pose_slerp(p32[0], p32[1], t, decoupled=True)
    assert mid.dtype == np.float32
    # decoupled: the rotations' geodesic, and the straight line between translations
    assert np.all(quat_angle(mid[..., :4].reshape(-1, 4).astype(np.float64), ref) < 1e-5)
    line = (1.0 - t) * poses[0, ..., 4:] + t * poses[1, ..., 4:]
    np.testing.assert_allclose(
        mid[..., 4:],
        line,
        rtol=0,
        atol=8 * np.finfo(np.float32).eps * (1 + 2 * abs(t)) * np.abs(poses).max(),
    )
    assert fi.pose_power(p32[0], t).dtype == np.float32


def test_a_python_number_t_keeps_torch_float32(torch, rng):
    q = rng.standard_normal((2, 6, 4))
    A, B = (rk.Rotation.from_quat(torch.tensor(x, dtype=torch.float32)) for x in q)
    got = rk.slerp(A, B, 0.25).as_quat()
    assert got.dtype == torch.float32
    sa = SR.from_quat(q[0], scalar_first=True)
    sb = SR.from_quat(q[1], scalar_first=True)
    ref = (sa * SR.from_rotvec((sa.inv() * sb).as_rotvec() * 0.25)).as_quat(
        scalar_first=True
    )
    assert np.all(quat_angle(got.double().numpy(), ref) < 1e-5)


def _ready_slerp(dtype):
    """The loops rk.slerp's own path calls (batch and one element), compiled."""
    from rigidkit._engine import numba_backend
    from rigidkit.kernels import geodesic

    if not numba_backend.available():
        pytest.skip("numba is not available")
    for pattern in ((False, False, False), numba_backend.SINGLE):
        numba_backend.wait(geodesic.quat_slerp, pattern, np.dtype(dtype))


def _scipy_slerp(qa, qb, t):
    sa = SR.from_quat(np.asarray(qa, np.float64).reshape(-1, 4), scalar_first=True)
    sb = SR.from_quat(np.asarray(qb, np.float64).reshape(-1, 4), scalar_first=True)
    rv = (sa.inv() * sb).as_rotvec() * np.reshape(t, (-1, 1))
    return (sa * SR.from_rotvec(rv)).as_quat(scalar_first=True)


@pytest.mark.parametrize("dtype, tol", [(np.float64, 1e-14), (np.float32, 2e-6)])
@pytest.mark.parametrize("n", [None, 1, 10, 17, 1000])
def test_slerp_straight_to_its_loop(n, dtype, tol, rng):
    """Two NumPy batches and a t array of theirs go from rk.slerp to the compiled
    loop (its vectorised sin, cos, atan2): the geodesic of scipy, a new array,
    every non-finite t reported with its index, and a t beyond the fast sine's
    range (t phi > 2^19) computed again, still on the geodesic."""
    _ready_slerp(dtype)
    shape = () if n is None else (n,)
    q = rng.standard_normal((2,) + shape + (4,)).astype(dtype)
    A, B = rk.Rotation.from_quat(q[0]), rk.Rotation.from_quat(q[1])
    t = rng.uniform(-0.5, 1.5, shape).astype(dtype)
    got = rk.slerp(A, B, t)
    out = got.as_quat()
    assert out.dtype == dtype and out.shape == shape + (4,)
    assert np.all(quat_angle(out.reshape(-1, 4), _scipy_slerp(q[0], q[1], t)) < tol)
    for stored in (A._quat, B._quat, t):
        assert not np.shares_memory(got._quat, stored)
    k = () if n is None else (n // 2,)
    for bad in (np.nan, np.inf, -np.inf):
        tb = t.copy()
        tb[k] = bad
        with pytest.raises(rk.NonFiniteError) as err:
            rk.slerp(A, B, tb)
        assert tuple(err.value.index) == k
    # Far beyond [0, 1]: |t phi| > 2^19 where the angle is not tiny.
    big = np.full(shape, dtype(3e6))
    far = rk.slerp(A, B, big).as_quat()
    ref = _scipy_slerp(q[0], q[1], big)
    assert np.all(np.isfinite(far))
    np.testing.assert_allclose(
        np.linalg.norm(far, axis=-1), 1.0, rtol=8 * np.finfo(dtype).eps
    )
    if dtype == np.float64:
        # The angle t theta (up to 3e6 pi ~ 1e7 rad) is rounded in both, each to a
        # few ulp of itself: the geodesic to that precision (1.7e-8 rad).
        assert np.all(quat_angle(far, ref) < 3e6 * np.pi * 8 * np.finfo(dtype).eps)
    # float32: the relative angle carries ~1e-7 rad, times 3e6, so no geodesic is
    # left to compare; what must hold is a finite unit quaternion (no NaN of the
    # fast sine let through), asserted above.


def test_slerp_of_other_layouts_and_dtypes_takes_the_general_path(rng):
    """A strided t, a t of another dtype, or ends of two batch shapes: the same
    geodesic through the general path."""
    _ready_slerp(np.float64)
    q = rng.standard_normal((2, 12, 4))
    A, B = rk.Rotation.from_quat(q[0]), rk.Rotation.from_quat(q[1])
    t = rng.uniform(0.0, 1.0, 24)
    for tt in (t[::2], t[::2].astype(np.float32), t[::2].tolist()):
        ref = _scipy_slerp(q[0], q[1], np.asarray(tt, np.float64))
        assert np.all(quat_angle(rk.slerp(A, B, tt).as_quat(), ref) < 1e-14)
    row = rk.slerp(A[:1], B, t[::2]).as_quat()
    assert np.all(
        quat_angle(row, _scipy_slerp(np.repeat(q[0, :1], 12, 0), q[1], t[::2])) < 1e-14
    )


def test_slerp_of_one_fraction_or_one_pair_broadcasts(rng):
    """A t of one value for many pairs, or one pair for many t: the lengths differ,
    the loop refuses them (status 1) and the general path broadcasts."""
    _ready_slerp(np.float64)
    q = rng.standard_normal((2, 6, 4))
    A, B = rk.Rotation.from_quat(q[0]), rk.Rotation.from_quat(q[1])
    t = rng.uniform(0.0, 1.0, 6)
    got = rk.slerp(A, B, t[:1]).as_quat()
    assert got.shape == (6, 4)
    assert np.all(quat_angle(got, _scipy_slerp(q[0], q[1], np.repeat(t[:1], 6))) < 1e-14)
    got = rk.slerp(A[:1], B[:1], t).as_quat()
    assert got.shape == (6, 4)
    ref = _scipy_slerp(np.repeat(q[0, :1], 6, 0), np.repeat(q[1, :1], 6, 0), t)
    assert np.all(quat_angle(got, ref) < 1e-14)
