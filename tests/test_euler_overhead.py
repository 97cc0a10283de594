"""The lean paths of ``euler_from_quat``: validation inside the kernel's pass, and the
scan of the middle angles for gimbal lock at every batch size.

``rigidkit.euler.euler_from_quat`` validates with the kernel
``euler_from_quat_checked`` (a bad row gets a middle angle of 8 rad) and scans the
middle angles once, as a Python list for small batches and with NumPy for larger
ones (``LIST_SCAN_MAX``). These tests pin what that must not change: the errors
and their batch indices (NaN, inf, zero, at every position, below and above the
list threshold, 1-D and N-D batches), the angles of quaternions of extreme scale
(against scipy, after an independent normalisation in mpmath), and the gimbal-lock
warning exactly at :func:`gimbal_lock_threshold` on either side, for Tait-Bryan
and proper sequences, in radians and degrees.
"""

from __future__ import annotations

import math
import warnings

import mpmath as mp
import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk
from rigidkit import euler
from rigidkit.errors import GimbalLockWarning, NonFiniteError, ZeroNormError
from rigidkit.functional._gimbal_lock import LIST_SCAN_MAX
from rigidkit.kernels import euler as kernels

SIZES = [1, 2, 7, LIST_SCAN_MAX, LIST_SCAN_MAX + 1, 150]
SEQS = ["ZYX", "xyz", "zxz", "YXY"]  # Tait-Bryan and proper, intrinsic and extrinsic


def _unit(rng, n, dtype=np.float64):
    q = rng.standard_normal((n, 4))
    return (q / np.linalg.norm(q, axis=1, keepdims=True)).astype(dtype)


def _batch(rng, n):
    """n unit quaternions as a (n, 4) batch, or a single (4,) one for n == 1."""
    q = _unit(rng, n)
    return q[0] if n == 1 else q


# -- the checked kernel ---------------------------------------------------------------
@pytest.mark.parametrize("backend", ["numba", "xp", "python"])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_checked_kernel_flags_exactly_the_rows_out_of_range(backend, dtype, rng):
    """Rows with |q| in [2/qmax, qmax/2] (computed here in float64; qmax 1e70, 1e8
    in float32) have the plain kernel's angles, bit for bit; rows outside [1/qmax,
    qmax] and NaN, inf or zero ones have a middle angle of 8 rad (times the degree
    factor), outside every valid range. (In between, within the factor of 2 of the
    kernel's cheap scale measure, either; none is drawn there.)"""
    qmax = 1e70 if dtype == np.float64 else 1e8
    span = math.log10(qmax)
    exps = rng.uniform(-2 * span, 2 * span, 60)
    exps = exps[np.abs(np.abs(exps) - span) > 0.35][:32]  # 10^0.35 > 2
    scales = np.concatenate(
        [[1.0, 10.0 ** (span - 1), 10.0 ** (1 - span), 10.0 ** (span + 1)]]
        + [[10.0 ** -(span + 1), 0.0, np.inf, np.nan], 10.0**exps]
    )
    q = (_unit(rng, len(scales)) * scales[:, None]).astype(dtype)
    q[3, 2] = np.nan  # one NaN component in a row of moderate scale
    q[4, :2] = [np.inf, -np.inf]
    with np.errstate(over="ignore", invalid="ignore"):
        norm = np.sqrt(np.sum(q.astype(np.float64) ** 2, axis=1))
    ok = (norm >= 1.0 / qmax) & (norm <= qmax)  # False for NaN
    assert ok.sum() > 10 and (~ok).sum() > 8
    lim = qmax
    # The plain kernel is element-wise: bad rows replaced, the good ones unchanged.
    q_safe = np.where(ok[:, None], q, np.array([1.0, 0.0, 0.0, 0.0], dtype))
    for seq, degrees in [("ZYX", False), ("zxz", True)]:
        s = euler.parse_sequence(seq)
        scale = 180.0 / math.pi if degrees else 1.0
        params = (*s.params, scale, euler.lock_tolerance(dtype))
        if backend == "python":
            got = np.array(
                [
                    kernels.euler_from_quat_checked.python(*params, lim, *r)
                    for r in q.tolist()
                ],
                dtype,
            )
            plain = np.array(
                [kernels.euler_from_quat.python(*params, *r) for r in q_safe.tolist()],
                dtype,
            )
        else:
            got = kernels.euler_from_quat_checked(*params, lim, q, backend=backend)
            plain = kernels.euler_from_quat(*params, q_safe, backend=backend)
        np.testing.assert_array_equal(got[ok], plain[ok])
        np.testing.assert_array_equal(got[~ok, 1], np.full((~ok).sum(), 8.0 * scale, dtype))


# -- errors of the public functional ------------------------------------------------
@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("bad", ["nan", "inf", "-inf", "zero"])
def test_errors_name_the_first_bad_row(n, bad, rng):
    q = _unit(rng, n)
    value = {"nan": np.nan, "inf": np.inf, "-inf": -np.inf, "zero": 0.0}[bad]
    error = ZeroNormError if bad == "zero" else NonFiniteError
    for where in sorted({0, n // 2, n - 1}):
        bad_q = q.copy()
        if bad == "zero":
            bad_q[where] = 0.0
        else:
            bad_q[where, where % 4] = value
        if n > 2 and where + 1 < n:  # a later bad row too: the first is named
            bad_q[n - 1] = 0.0 if bad == "zero" else value
        batch = bad_q[0] if n == 1 else bad_q
        for seq in SEQS:
            with pytest.raises(error) as err:
                euler.euler_from_quat(seq, batch, degrees=seq.islower())
            assert err.value.index == (() if n == 1 else (where,)), (seq, where)


def test_errors_in_nd_batches_and_float32(rng):
    q = _unit(rng, 24).reshape(2, 3, 4, 4)
    q[1, 2, 0, 3] = np.nan
    with pytest.raises(NonFiniteError) as err:
        euler.euler_from_quat("ZYX", q)
    assert err.value.index == (1, 2, 0)
    q32 = _unit(rng, 50, np.float32)
    q32[37] = 0.0
    with pytest.raises(ZeroNormError) as err:
        euler.euler_from_quat("zyz", q32)
    assert err.value.index == (37,)


def test_bad_row_next_to_a_locked_one_still_raises(rng):
    """The lock scan fails first (a lock row); the bad row must still be found."""
    q = _unit(rng, 60)
    q[5] = [math.sqrt(0.5), 0.0, math.sqrt(0.5), 0.0]  # ZYX pitch +90 degrees
    q[50] = [np.nan, 0.0, 0.0, 0.0]
    with pytest.raises(NonFiniteError) as err, warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        euler.euler_from_quat("ZYX", q)
    assert err.value.index == (50,)


def test_torch_input_is_validated(torch):
    q = torch.tensor([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]], dtype=torch.float64)
    with pytest.raises(ZeroNormError) as err:
        euler.euler_from_quat("ZYX", q)
    assert err.value.index == (1,)


# -- extreme scales -----------------------------------------------------------------
@pytest.mark.parametrize("n", [1, 5, 100])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_any_finite_nonzero_scale_gives_the_unit_quaternions_angles(n, dtype, rng):
    span = 300 if dtype == np.float64 else 37
    unit = _unit(rng, n)
    scales = 10.0 ** rng.uniform(-span, span, n)
    scales[: min(n, 2)] = [10.0**span, 10.0**-span][: min(n, 2)]
    q = (unit * scales[:, None]).astype(dtype)
    # The reference: scipy's angles of q normalised at 30 digits (scipy's own
    # normalisation would overflow at these scales).
    with mp.workdps(30):
        ref_q = []
        for row in q:
            c = [mp.mpf(float(v)) for v in row]
            norm = mp.sqrt(sum(v * v for v in c))
            ref_q.append([float(v / norm) for v in c])
    ref_q = np.array(ref_q)
    tol = 1e-12 if dtype == np.float64 else 2e-6
    for seq in SEQS:
        ref = SciRot.from_quat(ref_q[:, [1, 2, 3, 0]]).as_euler(seq)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # scipy near its lock
            got = euler.euler_from_quat(seq, q[0] if n == 1 else q)
        got = np.atleast_2d(got)
        mid_ok = (
            np.abs(np.cos(ref[:, 1] if seq[0] != seq[2] else ref[:, 1] - math.pi / 2))
            > 1e-3
        )
        diff = np.angle(np.exp(1j * (got.astype(np.float64) - ref)))  # wrapped
        assert np.abs(diff[mid_ok]).max() < tol, seq


# -- the lock scan: warn exactly at the threshold ---------------------------------------
def _near_lock(seq, distance, degrees):
    """A quaternion of ``seq`` whose middle angle is ``distance`` rad from a lock."""
    proper = seq[0].lower() == seq[2].lower()
    mid = distance if proper else math.pi / 2 - distance
    return euler.quat_from_euler(seq, [0.4, mid, -0.3])


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("seq", SEQS)
def test_lock_warning_at_every_batch_size(n, seq, rng):
    """One warning when one row is 0.5x the threshold from the lock, wherever it is
    in the batch; none when it is 2x (the threshold: sqrt(eps), 1.5e-8 rad)."""
    thr = euler.gimbal_lock_threshold(np.float64)
    q = _unit(rng, n)
    # Keep the random rows far from the lock, so only the planted one counts.
    mids = np.atleast_2d(euler.euler_from_quat_unchecked(seq, q))[:, 1]
    proper = seq[0].lower() == seq[2].lower()
    dist = np.minimum(mids, math.pi - mids) if proper else math.pi / 2 - np.abs(mids)
    q = q[dist > 1e-3]
    q = np.concatenate([q, _unit(rng, n - len(q))]) if len(q) < n else q
    for factor, warns in [(0.5, True), (2.0, False)]:
        row = _near_lock(seq, factor * thr, False)
        for where in sorted({0, n - 1, n // 3}):
            batch = q.copy()
            batch[where] = row
            batch = batch[0] if n == 1 else batch
            R = rk.Rotation.from_quat(batch)
            for call in (
                lambda b=batch: euler.euler_from_quat(seq, b),
                lambda b=batch: euler.euler_from_quat(seq, b, degrees=True),
                lambda b=batch: euler.euler_from_quat_unchecked(seq, b),
                lambda R=R: R.as_euler(seq, degrees=True),
            ):
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    call()
                lock = [w for w in caught if issubclass(w.category, GimbalLockWarning)]
                assert len(lock) == int(warns), (seq, n, factor, where)
                if warns:
                    assert lock[0].message.index == (() if n == 1 else (where,))


@pytest.mark.parametrize("n", SIZES)
def test_nan_rows_of_the_unchecked_path_never_warn(n):
    q = np.full((n, 4), np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("error", GimbalLockWarning)
        got = euler.euler_from_quat_unchecked("zxz", q[0] if n == 1 else q)
    assert np.isnan(got).all()


def test_empty_batches():
    for f in (euler.euler_from_quat, euler.euler_from_quat_unchecked):
        assert f("ZYX", np.zeros((0, 4))).shape == (0, 3)
