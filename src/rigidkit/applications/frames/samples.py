"""The samples given for one edge of a :class:`~rigidkit.FrameGraph`, checked.

Stamps, poses and covariances as the edge buffer (:mod:`.buffer`) stores them:
NumPy stamps, poses in the stored layout of a ``Transform`` (NumPy ones
contiguous, torch/JAX/Dask ones kept in their namespace).
"""

from __future__ import annotations

import numpy as np

from ..._engine.namespace import device_of, namespace_of
from ...errors import ShapeError, TimestampError
from ...objects import registry
from ...objects.transform import Transform

__all__ = ["as_samples"]


def as_samples(parent_T_child, stamps, cov):
    """``(stamps, pq, cov)`` as float64 arrays ``(M,)``, ``(M, 7)``, ``(M, 6, 6)`` or None.

    ``parent_T_child`` is a :class:`~rigidkit.Transform` (shape ``()`` or
    ``(M,)``), a :class:`~rigidkit.Trajectory` (its own stamps unless ``stamps``
    is given) or an array of ``(M, 7)`` pq rows ``(tx, ty, tz, w, x, y, z)``
    (:meth:`~rigidkit.Transform.from_pq`). ``stamps=None`` means static
    (``stamps`` returned as None, the poses as ``(1, ..., 7)``: one pose, or a
    batch of static edges, kept in their namespace). The poses are returned in
    the stored layout of a ``Transform``, rows ``(w, x, y, z, tx, ty, tz)``.
    """
    from ..trajectory import Trajectory  # a sibling application, loaded on use

    if isinstance(parent_T_child, Trajectory):
        if stamps is None:
            stamps = parent_T_child.stamps
            if stamps is None:
                raise TimestampError("a Trajectory without stamps needs stamps=")
        parent_T_child = parent_T_child.poses
    if not isinstance(parent_T_child, Transform):
        if not _foreign(parent_T_child):
            parent_T_child = np.asarray(parent_T_child, dtype=np.float64)
        parent_T_child = Transform.from_pq(parent_T_child)
    pq = registry.stored(parent_T_child)
    if stamps is None:
        # One pose, or a batch of shape (...): a batch of static edges (of as many
        # graphs), which the lookups broadcast (with the times' shape where the
        # path has dynamic edges). torch, JAX, Dask: the pose stays in its
        # namespace (on the caller's graph, traced, lazy), composed by the
        # objects' operations.
        if not _foreign(pq):
            pq = np.ascontiguousarray(pq, dtype=np.float64)
        if cov is not None:
            cov = _checked_cov(_as_cov(cov, pq), 1)
        return None, pq.reshape((1,) + tuple(pq.shape)), cov
    # A dynamic edge's stamps are NumPy (searched on the host); its poses stay in
    # their namespace (torch, JAX, Dask), NumPy ones in a buffer written in place.
    if not _foreign(pq):
        pq = np.asarray(pq, dtype=np.float64)
    t = np.array(stamps, dtype=np.float64, ndmin=1)
    pq = pq.reshape((-1, 7))
    if t.ndim != 1 or t.shape[0] != pq.shape[0]:
        raise ShapeError(
            f"stamps of shape {np.shape(stamps)} for {pq.shape[0]} poses; "
            "one stamp per pose"
        )
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        i = int(bad[0])
        raise TimestampError(f"stamps[{i}] is {float(t[i])!r}, not finite", index=(i,))
    if cov is not None:
        cov = _checked_cov(_as_cov(cov, pq), pq.shape[0])
    return t, (pq if _foreign(pq) else np.ascontiguousarray(pq)), cov


def _as_cov(cov, pq):
    """A covariance in the poses' namespace: a NumPy copy for NumPy poses (the
    buffer's own array); for torch, JAX or Dask poses a covariance of theirs as
    its copy (autograd through it, tracing), anything else converted to it."""
    if not _foreign(pq):
        return np.array(cov, dtype=np.float64)
    xp = namespace_of(pq)
    if _foreign(cov):
        return xp.asarray(cov, copy=True)  # not the caller's storage
    return xp.asarray(
        np.asarray(cov, dtype=np.float64), dtype=pq.dtype, device=device_of(pq)
    )


def _checked_cov(cov, m):
    """``cov`` (6, 6) or (m, 6, 6) as (m, 6, 6), in its namespace."""
    shape = tuple(cov.shape)
    if shape == (6, 6):
        if _foreign(cov):
            return namespace_of(cov).broadcast_to(cov[None], (m, 6, 6))
        cov = np.broadcast_to(cov, (m, 6, 6)).copy()
    elif shape != (m, 6, 6):
        raise ShapeError(f"cov: expected shape (6, 6) or ({m}, 6, 6), got {shape}")
    return cov


def _foreign(x) -> bool:
    """Whether ``x`` is an array of another namespace than NumPy (torch, JAX, Dask)."""
    return (
        hasattr(x, "shape")
        and hasattr(x, "dtype")
        and not isinstance(x, (np.ndarray, np.generic))
    )
