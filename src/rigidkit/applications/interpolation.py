"""Geodesic interpolation of rotations and rigid motions: ``rk.slerp`` and ``rk.Slerp``.

The geodesic from ``X0`` (``t = 0``) to ``X1`` (``t = 1``) is ``X0 (X0^-1 X1)^t``,
``X^t = exp(t log X)``, the log's angle in [0, pi] (shortest path, whatever the
quaternion signs). For a :class:`~rigidkit.Transform` it is the screw motion with
constant body twist; ``decoupled=True`` interpolates the rotation by slerp and
the translation on a straight line. Conventions: Hamilton quaternions, scalar
first; ``A_R_C = A_R_B @ B_R_C`` applies ``B_R_C`` first.
"""

from __future__ import annotations

import numpy as np

from .._engine import dask_backend, owned_function
from .._engine.namespace import device_of, is_torch, namespace_of
from .._validate import (
    as_float,
    checks_now,
    finite_array,
    to_numpy,
    validation_enabled,
)
from ..errors import DegenerateInputError, OutOfRangeError, ShapeError
from ..functional import interpolation as _fi
from ..kernels import geodesic as _kg
from ..objects import registry
from ..objects._batch import storage_slots
from ..objects.registry import stored
from ..objects.rotation import Rotation
from ..objects.transform import Transform

__all__ = ["slerp", "Slerp"]


def slerp(a, b, t, *, decoupled=False):
    """Fraction ``t`` of the geodesic a to b: Transforms on the screw; decoupled=True: tf's.

    For two ``Transform`` the geodesic is the SE(3) screw motion; ``decoupled=True``
    slerps the rotation and interpolates the translation linearly, as tf2 and evo do.

    Parameters
    ----------
    a, b : Rotation, Transform, or any other Lie group of rigidkit
        The ends, of one kind; batch shapes broadcast. Groups other than
        ``Rotation`` and ``Transform`` follow ``a exp(t log(a^-1 b))``.
    t : array_like, shape (...)
        Fractions, broadcasting with the batch: 0 gives ``a`` exactly, 1 gives
        ``b``; outside [0, 1] the geodesic is extended.
    decoupled : bool
        Transforms only: slerp the rotation and interpolate the translation
        linearly, ``(1 - t) t_a + t t_b``, instead of the screw motion.

    Returns
    -------
    The kind of ``a`` and ``b``

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> A_R_B = rk.Rotation.identity()
    >>> A_R_C = rk.Rotation.from_rotvec([0.0, 0.0, np.pi / 2])
    >>> np.round(rk.slerp(A_R_B, A_R_C, [0.0, 0.5, 1.0]).as_rotvec()[:, 2], 12)
    array([0.        , 0.78539816, 1.57079633])
    """
    if type(a) is Rotation and type(b) is Rotation and not decoupled:  # the common call
        # ``_data``: the stored array (``registry.stored``), read without a call here
        return _wrap_rotation(_quat_slerp(a._data, b._data, t))
    if isinstance(a, Transform) and isinstance(b, Transform):
        return _wrap_transform(
            _fi.pose_slerp_unchecked(stored(a), stored(b), t, decoupled=decoupled)
        )
    if isinstance(a, Rotation) and isinstance(b, Rotation):
        if decoupled:
            raise TypeError("decoupled= applies to Transform, not Rotation")
        return _wrap_rotation(_fi.quat_slerp_unchecked(stored(a), stored(b), t))
    spec = registry.spec(type(a))
    if type(a) is type(b) and spec is not None and spec.algebra is not None:
        if decoupled:
            raise TypeError(f"decoupled= applies to Transform, not {type(a).__name__}")
        return _geodesic(a, b, t)
    raise TypeError(
        "slerp interpolates two elements of one Lie group (Rotation, Transform, "
        f"Rotation2D, ...), got {type(a).__name__} and {type(b).__name__}"
    )


def _geodesic(a, b, t):
    """``a exp(t log(a^-1 b))`` for any registered Lie group, from its own operations.

    Rotations and transforms have their own kernels (the same curve, with the
    quaternion's shortest path); every other group (``Rotation2D``,
    ``Transform2D``, ``Similarity``, ...) takes this, written once.
    """
    tau = (a.inv() @ b).log()
    xp = namespace_of(tau)
    t = xp.asarray(t, dtype=tau.dtype, device=device_of(tau))
    return a @ type(a).exp(t[..., None] * tau)


# Bound once: each global and attribute lookup is ~30 ns of a ~1 us call.
_wrap_rotation = registry.spec(Rotation).wrap
_wrap_transform = registry.spec(Transform).wrap
_quat_slerp = _fi.quat_slerp_unchecked


def _owned_slerp(general):
    """``general`` made fast for its most frequent call: two NumPy ``Rotation``
    batches of one shape (one batch axis or none) and a float array ``t`` of their
    dtype and batch shape, straight to the compiled loop of ``quat_slerp`` (the
    engine writes it: :func:`rigidkit._engine.owned_function`; the loop tests
    ``t``'s finiteness, ~0.5 us of a ~2 us call at N = 10 in Python). Anything
    else calls ``general``, which checks ``t`` itself and raises for a non-finite
    one with its batch index.
    """
    return owned_function(
        _kg.quat_slerp,
        general,
        Rotation,
        ("a", "b"),
        arrays=("t",),
        off=("decoupled",),
        slots=storage_slots(Rotation),
    )


slerp = _owned_slerp(slerp)


def keyframe_times(times, count, what="keyframes"):
    """``times`` as a strictly increasing float64 NumPy vector of length ``count``."""
    t = np.asarray(to_numpy(finite_array(times, (), "times")), dtype=np.float64)
    if t.ndim != 1:
        raise ShapeError(f"times: expected a 1-D array, got shape {t.shape}")
    if t.shape[0] != count:
        raise ShapeError(f"times: {t.shape[0]} times for {count} {what}")
    if not checks_now(t):  # traced by torch.compile: the values are not readable
        return t
    bad = np.flatnonzero(np.diff(t) <= 0.0)
    if bad.size:
        k = int(bad[0]) + 1
        raise DegenerateInputError(
            f"times must be strictly increasing: times[{k}] = {float(t[k])!r} <= "
            f"times[{k - 1}] = {float(t[k - 1])!r}",
            index=(k,),
        )
    return t


def query_times(times, lo, hi, *, extrapolate=False):
    """Query ``times`` (any shape), checked finite and within [lo, hi].

    The times stay in the caller's namespace (a traced JAX array under ``jit``, a
    torch tensor under ``torch.compile``, a lazy Dask array): the checks read
    values only where they can (:func:`rigidkit.set_validation`); on Dask they
    run at compute time. Integer NumPy input becomes float64. ``extrapolate=True``
    accepts any finite time (no range check).
    """
    q = as_float(finite_array(times, (), "times"))
    if extrapolate:
        return q
    if checks_now(q) and checks_now(lo):
        _check_range(np.asarray(to_numpy(q)), float(lo), float(hi))
    elif validation_enabled() and dask_backend.is_dask(q):
        # at compute time, per chunk, in whatever is computed from the times
        dask_backend.defer(_check_range, (q,), (float(lo), float(hi)), _relabel)
    return q


def _check_range(t, lo, hi):
    """:class:`OutOfRangeError` at the first time of NumPy ``t`` outside [lo, hi]."""
    out = (t < lo) | (t > hi)
    if out.any():
        idx = tuple(int(i) for i in np.argwhere(out)[0])
        raise OutOfRangeError(
            f"time {float(t[idx])!r} {'at index ' + str(idx) + ' ' if idx else ''}is "
            f"outside the interpolation range [{lo!r}, {hi!r}]",
            index=idx,
        )


def _relabel(err, index):
    """The error of a chunk naming the ``index`` in the whole array."""
    text = str(err).replace(f"at index {err.index}", f"at index {index}", 1)
    return type(err)(text, index=index)


def astype_like(x, like):
    """``x`` with the dtype of ``like`` (both of one namespace)."""
    if x.dtype == like.dtype:
        return x
    if is_torch(x):
        return x.to(like.dtype)
    return x.astype(like.dtype)


def keyframe_kind(keyframes, least, what):
    """The class of ``keyframes`` (Rotation or Transform, time axis first), checked."""
    if not isinstance(keyframes, (Rotation, Transform)):
        raise TypeError(
            f"{what} must be a Rotation or a Transform, got {type(keyframes).__name__}"
        )
    if keyframes.single or len(keyframes) < least:
        n = 1 if keyframes.single else len(keyframes)
        raise DegenerateInputError(f"{what}: {n} given, at least {least} needed")
    return type(keyframes)


class Slerp:
    """Piecewise-geodesic interpolation of a keyframe sequence (scipy's ``Slerp``).

    Between ``times[i]`` and ``times[i + 1]`` the result is
    ``slerp(X_i, X_{i+1}, (t - t_i) / (t_{i+1} - t_i))``: continuous, with
    constant angular velocity on each interval.

    Parameters
    ----------
    times : array_like, shape (n,)
        Strictly increasing, ``n >= 2``.
    keyframes : Rotation or Transform, shape (n, ...)
        The keyframes, time axis first (any further batch axes are interpolated
        alike). For transforms, the screw motion unless ``decoupled=True``.
    decoupled : bool
        Transforms only, see :func:`slerp`.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> keys = rk.Rotation.from_rotvec([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 3.0]])
    >>> interp = rk.Slerp([0.0, 1.0, 2.0], keys)
    >>> np.round(interp([0.5, 1.5]).as_rotvec()[:, 2], 12)
    array([0.5, 2. ])
    """

    def __init__(self, times, keyframes, *, decoupled=False):
        kind = keyframe_kind(keyframes, 2, "keyframes")
        if decoupled and kind is Rotation:
            raise TypeError("decoupled= applies to Transform keyframes, not Rotation")
        self.times = keyframe_times(times, len(keyframes))
        self.keyframes = keyframes
        self.decoupled = decoupled
        self._dt = np.diff(self.times)

    def __call__(self, times):
        """The interpolated keyframes at ``times`` (shape (...) -> batch (..., extra)).

        Raises :class:`~rigidkit.OutOfRangeError` outside ``[times[0], times[-1]]``.
        The result is of the namespace of the keyframes or of ``times`` (NumPy
        keyframes meet JAX, torch or Dask times: it traces and stays lazy).
        """
        q = query_times(times, self.times[0], self.times[-1])
        data = stored(self.keyframes)
        q = _fi.meet(q, data)  # NumPy times meet the keyframes' namespace
        data = _fi.meet(data, q)  # NumPy keyframes meet the times'
        flat = q.reshape(-1)
        idx = _fi.segment_index(self.times, flat)
        alpha = (flat - _fi.take_rows(self.times, idx)) / _fi.take_rows(self._dt, idx)
        extra = len(self.keyframes.shape) - 1
        alpha = astype_like(alpha.reshape(tuple(alpha.shape) + (1,) * extra), data)
        x0 = _fi.take_rows(data, idx)
        x1 = _fi.take_rows(data, idx + 1)
        if isinstance(self.keyframes, Transform):
            out = _fi.pose_slerp_unchecked(x0, x1, alpha, decoupled=self.decoupled)
        else:
            out = _fi.quat_slerp_unchecked(x0, x1, alpha)
        wrap = registry.spec(type(self.keyframes)).wrap
        return wrap(out.reshape(tuple(q.shape) + tuple(out.shape[1:])))
