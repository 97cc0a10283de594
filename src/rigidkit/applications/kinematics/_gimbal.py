"""The gimbal-lock check of the inverse Euler-rate functions."""

from __future__ import annotations

import math

from ..._validate import (
    batch_index,
    checks_now,
    raise_where,
    to_numpy,
    validation_enabled,
    where_text,
)
from ...errors import GimbalLockError


def check_lock(lock_sine, tol: float, seq, fn: str) -> None:
    """Raise :class:`GimbalLockError` where the distance to the lock is below ``tol``.

    ``lock_sine`` is the kernel's sine of the angle (radians) from the middle
    angle to the lock; ``asin`` is monotonic, so comparing it with ``sin(tol)``
    is the same test. Where values cannot be read now the check never reads
    them: under tracing (``jax.jit``, ``torch.compile``, ``torch.func``) it is
    skipped and the rates come out large but finite; on a Dask array it runs per
    chunk at compute time (the error names the global batch index), so the call
    computes nothing. ``rk.set_validation(False)`` removes it.
    """
    if not validation_enabled():
        return
    limit = math.sin(min(tol, math.pi / 2))
    lock = "0 or pi" if seq.proper else "+-pi/2"
    advice = (
        "There the Euler-rate matrix is singular (only the sum or difference of the "
        "first and third rate is determined); use quaternions or rotation vectors "
        "near the lock, or pass a smaller tol=."
    )
    if not checks_now(lock_sine):  # traced (skipped) or Dask (deferred, lazy)
        raise_where(
            lock_sine < limit,
            GimbalLockError,
            f"{fn}: gimbal lock in {seq.text!r}: the middle angle {{where}} is "
            f"within {tol:.3g} rad of {lock} (the sine of its distance is "
            f"{{value:.3g}}). {advice}",
            value=lock_sine,
        )
        return
    d = to_numpy(lock_sine)
    if d.size == 0 or float(d.min()) >= limit:
        return
    bad = d < limit
    idx = batch_index(bad)
    dist = math.asin(min(float(d[idx]), 1.0))
    raise GimbalLockError(
        f"{fn}: gimbal lock in {seq.text!r}: the middle angle {where_text(idx)} is "
        f"{dist:.3g} rad from {lock}, closer than the tolerance {tol:.3g} rad "
        f"({int(bad.sum())} of {max(bad.size, 1)} inputs). {advice}",
        index=idx,
        distance=dist,
        tolerance=tol,
    )
