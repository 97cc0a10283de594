"""``GimbalLockWarning`` carries the first locked batch index, as errors do.

Programs (the CLI among them) read ``w.message.index`` of a caught warning instead
of parsing its text. The lock is built here from angles with the middle one at
+-90 degrees (Tait-Bryan) or 0 (proper), an exact lock.
"""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest

import rigidkit as rk


def caught_locks(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fn()
    return [w for w in caught if issubclass(w.category, rk.GimbalLockWarning)]


@pytest.mark.parametrize(
    ("seq", "lock"), [("ZYX", 90.0), ("xyz", -90.0), ("ZXZ", 0.0), ("yxy", 180.0)]
)
def test_warning_index_is_the_first_locked_element(seq, lock):
    angles = np.array([[10.0, 20.0, 30.0]] * 6)
    angles[[3, 5], 1] = lock
    R = rk.Rotation.from_euler(seq, angles.reshape(2, 3, 3), degrees=True)
    (w,) = caught_locks(lambda: R.as_euler(seq))
    assert w.message.index == (1, 0)  # flat 3 in a (2, 3) batch
    (w,) = caught_locks(
        lambda: rk.Rotation.from_euler(seq, angles, degrees=True).as_euler(seq)
    )
    assert w.message.index == (3,)
    (w,) = caught_locks(lambda: R[1, 0].as_euler(seq))
    assert w.message.index == ()


def test_warning_survives_pickling():
    w = rk.GimbalLockWarning("gimbal lock at batch index (3,)", index=(3,))
    back = pickle.loads(pickle.dumps(w))
    assert back.index == (3,) and str(back) == str(w)


@pytest.mark.parametrize("fn", ["euler_from_quat", "euler_from_quat_unchecked"])
def test_warn_false_gives_the_same_angles_without_a_warning(fn):
    # At lock in one element of a batch: warn=False records nothing (and touches no
    # warning filter); the angles are those of the warning call, bit for bit.
    euler = getattr(rk.functional.euler, fn)
    angles = np.array([[10.0, 20.0, 30.0], [10.0, 90.0, 30.0]])
    q = rk.functional.euler.quat_from_euler("ZYX", angles, degrees=True)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        quiet = euler("ZYX", q, degrees=True, warn=False)
        filters = list(warnings.filters)
        loud = euler("ZYX", q, degrees=True)
    assert [w.category for w in caught] == [rk.GimbalLockWarning]
    assert filters[0][0] == "always"  # the recording's own filter, left in place
    np.testing.assert_array_equal(quiet, loud)
