"""The gimbal-lock check of the inverse Euler-rate functions."""

from __future__ import annotations

import math

from ..._validate import batch_index, to_numpy, where_text
from ...errors import GimbalLockError


def check_lock(lock_sine, tol: float, seq, fn: str) -> None:
    """Raise :class:`GimbalLockError` where the distance to the lock is below ``tol``.

    ``lock_sine`` is the kernel's sine of the angle (radians) from the middle
    angle to the lock; ``asin`` is monotonic, so comparing it with ``sin(tol)``
    is the same test. Under tracing (``jax.jit``: no concrete values) the check
    is skipped and the rates come out large but finite.
    """
    try:
        d = to_numpy(lock_sine)
    except Exception:  # a tracer: no concrete value to check
        return
    limit = math.sin(min(tol, math.pi / 2))
    if d.size == 0 or float(d.min()) >= limit:
        return
    bad = d < limit
    idx = batch_index(bad)
    dist = math.asin(min(float(d[idx]), 1.0))
    lock = "0 or pi" if seq.proper else "+-pi/2"
    raise GimbalLockError(
        f"{fn}: gimbal lock in {seq.text!r}: the middle angle {where_text(idx)} is "
        f"{dist:.3g} rad from {lock}, closer than the tolerance {tol:.3g} rad "
        f"({int(bad.sum())} of {max(bad.size, 1)} inputs). There the Euler-rate "
        f"matrix is singular (only the sum or difference of the first and third "
        f"rate is determined); use quaternions or rotation vectors near the lock, "
        f"or pass a smaller tol=.",
        index=idx,
        distance=dist,
        tolerance=tol,
    )
