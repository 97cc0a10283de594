"""Gimbal lock of Euler angles: its thresholds and the scans that look for it.

The Euler mathematics (sequences, the conversions, the lock convention) is
:mod:`rigidkit.euler`; this module holds what decides whether a result is near the
lock, and the warning: :func:`gimbal_lock_threshold` (where the warning starts),
:func:`lock_tolerance` (how far the rotation may move to return the lock
convention), the band of middle angles far from the lock (:class:`LockBand`), the
fast scan of a NumPy batch (:func:`lock_free`) and the warning itself
(:func:`warn_if_locked`), whose stack level names the caller's line outside
rigidkit. :mod:`rigidkit.euler` offers the two thresholds under their names.

>>> import numpy as np
>>> band = lock_band(False, 1.0, np.float64)  # Tait-Bryan, radians: lock at +-pi/2
>>> lock_free(np.array([0.1, 1.5, 0.2]), band)
True
>>> lock_free(np.array([0.0, np.pi / 2, 0.0]), band)
False
"""

from __future__ import annotations

import math
import os
import sys
import warnings

import numpy as np

from .._engine.namespace import namespace_of
from .._validate import batch_index, checks_now, to_numpy, tolerances, where_text
from ..errors import GimbalLockWarning

__all__ = [
    "gimbal_lock_threshold",
    "lock_tolerance",
    "LockBand",
    "lock_band",
    "lock_free",
    "warn_if_locked",
    "LIST_SCAN_MAX",
]


def gimbal_lock_threshold(dtype) -> float:
    """Distance (radians) of the middle angle from the lock below which we warn.

    ``sqrt(eps)`` of the dtype: 1.5e-8 for float64, 3.5e-4 for float32. The first
    and third angles have condition number about ``1 / distance`` with respect to
    the rotation (only their sum or difference is well determined there), so a
    rotation known to ``eps`` fixes them only to ``eps / distance``: below
    ``sqrt(eps)`` at least half of their significant digits are noise. The
    rebuilt rotation stays exact at any distance.

    >>> gimbal_lock_threshold(np.float64), gimbal_lock_threshold(np.float32)
    (1.4901161193847656e-08, 0.00034526698300124393)
    """
    try:
        return _THRESHOLDS[dtype]
    except (KeyError, TypeError):
        pass
    tol = tolerances(dtype).gimbal_lock
    try:
        _THRESHOLDS[dtype] = tol
    except TypeError:  # unhashable dtype object
        pass
    return tol


_THRESHOLDS: dict = {}


def lock_tolerance(dtype) -> float:
    """Radians the rotation may move to return the lock convention: ``2 eps``.

    4.4e-16 for float64, 2.4e-7 for float32 (the input quaternion's dtype: a
    float32 quaternion carries float32 rounding, whatever precision the kernel
    computes in). Changing every component of a quaternion by one ulp (at most
    ``eps |q_i|``) moves it by at most ``eps |q|``, i.e. the rotation by at most
    ``2 eps`` rad. So the angles returned at a numerical lock are the exact
    angles of a rotation no farther from the given one than one-ulp changes of
    its quaternion reach, and a quaternion computed from lock angles (a rounding
    residue of a few ulp) is cleaned: for ``from_euler`` at lock we measured a
    cost of at most 4.2e-16 over a million random float64 cases, all 24
    sequences, radians and degrees.

    >>> lock_tolerance(np.float64), lock_tolerance(np.float32)
    (4.440892098500626e-16, 2.384185791015625e-07)
    """
    return tolerances(dtype).lock


class LockBand:
    """Where a middle angle is not near the lock: in ``[lo, hi]``, i.e. ``|mid -
    center| <= width``, in the angles' units (see :func:`lock_band`).

    A record with slots, not a ``NamedTuple``: its fields are read on every call,
    and a slot is read as fast as a tuple index (a ``NamedTuple`` field ~30 ns
    slower on CPython 3.11); not a dataclass, whose import would cost
    ``import rigidkit`` ~20 ms.
    """

    __slots__ = ("lo", "hi", "center", "width")

    def __init__(self, lo: float, hi: float, center: float, width: float):
        self.lo, self.hi, self.center, self.width = lo, hi, center, width

    def __repr__(self) -> str:
        return (
            f"LockBand(lo={self.lo!r}, hi={self.hi!r}, center={self.center!r}, "
            f"width={self.width!r})"
        )


def lock_band(proper: bool, scale: float, dtype) -> LockBand:
    """The :class:`LockBand` of a proper (lock at 0 and pi) or Tait-Bryan (lock at
    +-pi/2) sequence, for angles in units of ``scale`` per radian and the
    :func:`gimbal_lock_threshold` of ``dtype``; the arithmetic of
    :func:`warn_if_locked`."""
    tol = gimbal_lock_threshold(dtype) * scale
    half = 0.5 * math.pi * scale
    center = half if proper else 0.0
    return LockBand(center - half + tol, center + half - tol, center, half - tol)


#: NumPy batches up to this long have their middle angles scanned as a sorted Python
#: list (one C call, ~0.6 us at 10 elements, 1.1 us at 32), longer ones with NumPy
#: (~1.5 us: two ufunc calls, or three for proper sequences).
LIST_SCAN_MAX = 40


def lock_free(angles, band: LockBand) -> bool:
    """True when the middle angles of NumPy ``angles`` are all inside ``band``, i.e.
    at least :func:`gimbal_lock_threshold` from the lock, with the arithmetic of
    :func:`warn_if_locked`.

    False sends the call on to :func:`warn_if_locked` (which finds out whether
    any is near the lock) or, in :func:`rigidkit.euler.euler_from_quat`, to the
    full check. A
    NaN may give either answer here (a sorted list with NaN is not ordered, where
    NumPy's max propagates it): it is never a lock, so both are right.
    """
    if angles.ndim == 1:
        return band.lo <= angles.item(1) <= band.hi
    if angles.ndim != 2:
        return False
    n = len(angles)
    if n <= LIST_SCAN_MAX:
        if n == 0:
            return True
        vals = sorted(angles[:, 1].tolist())
        return band.lo <= vals[0] and vals[-1] <= band.hi
    center = band.center
    if center == 0.0:  # Tait-Bryan: the lock at +-pi/2
        dist = np.abs(angles[:, 1])
    else:
        dist = angles[:, 1] - center
        np.abs(dist, out=dist)
    return bool(_MAX(dist) <= band.width)


_MAX = np.maximum.reduce


def warn_if_locked(s, angles, scale: float) -> None:
    """Emit one :class:`GimbalLockWarning` if any middle angle is near the lock.

    ``s`` is the :class:`~rigidkit.euler.EulerSequence` (its ``proper`` and ``text``),
    ``scale`` the angles' units per radian.
    """
    dtype = getattr(angles, "dtype", np.float64)
    tol = gimbal_lock_threshold(dtype) * scale
    half = 0.5 * math.pi * scale
    # Lock at 0 and pi (proper) or -pi/2 and pi/2 (Tait-Bryan): |mid - center| = half.
    center = half if s.proper else 0.0
    if isinstance(angles, np.ndarray) and angles.ndim == 1:  # one element: no reductions
        if abs(float(angles[1]) - center) <= half - tol:
            return
    mid = angles[..., 1]
    if isinstance(mid, np.ndarray) and mid.size <= 64:
        # Small batches: Python's min/max over a list beat two NumPy reductions
        # (~1 us each). A NaN is never a lock: skipped or not, the outcome is right.
        vals = mid.ravel().tolist()
        if not vals or (
            min(vals) >= center - half + tol and max(vals) <= center + half - tol
        ):
            return
    if isinstance(mid, np.ndarray):
        if mid.size == 0 or (
            # Two reductions without temporaries: the common, lock-free case.
            mid.min() >= center - half + tol and mid.max() <= center + half - tol
        ):
            return
        near = np.abs(mid - center) > half - tol  # False for NaN (never a lock)
        if not near.any():
            return
    else:
        if not checks_now(mid):  # traced (or Dask) values: no warning; the angles hold
            return
        xp = namespace_of(mid)
        near = xp.abs(mid - center) > half - tol
        if not bool(xp.any(near)):
            return
    near = to_numpy(near)
    lock = "0 or pi" if s.proper else "+-pi/2"
    first = batch_index(near)
    message = (
        f"Gimbal lock in {s.text!r}: {int(near.sum())} of {max(near.size, 1)} middle "
        f"angles are within {tol / scale:.2g} rad of {lock} (first "
        f"{where_text(first)}); there only the sum or difference of the "
        f"first and third angle is well determined. The angles returned rebuild the "
        f"rotation; at lock (within {lock_tolerance(dtype):.2g} rad) the third angle is 0."
    )
    warnings.warn(GimbalLockWarning(message, index=first), stacklevel=_user_stacklevel())


_PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _user_stacklevel() -> int:
    """``stacklevel`` for ``warnings.warn`` that points at the first caller outside
    rigidkit (so the warning names the user's line, whichever API they called)."""
    frame = sys._getframe(1)
    level = 1
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(
        _PACKAGE_DIR + os.sep
    ):
        frame = frame.f_back
        level += 1
    return level
