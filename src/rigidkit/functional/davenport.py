"""Davenport angles: turns about any axes, consecutive ones orthogonal (arrays in/out).

A generalisation of Euler angles (Shuster & Markley 2003, scipy's
``Rotation.from_davenport``): up to three turns about axes ``n1, n2, n3``, where
``n2`` is orthogonal to ``n1`` and to ``n3`` (``|n_i . n_i+1| <= 1e-7`` once
normalised, scipy's tolerance) and ``n1``, ``n3`` may make any angle ``lam``.
``order="intrinsic"`` (or ``"i"``) turns about the body axes, ``R = R_n1(t1)
R_n2(t2) R_n3(t3)``; ``order="extrinsic"`` (``"e"``) about the fixed world axes,
``R = R_n3(t3) R_n2(t2) R_n1(t1)``. Axes and angles are listed in the order they
are named (``n1`` first), as in scipy. Rotations are active on column vectors;
quaternions Hamilton, scalar first ``(w, x, y, z)``; radians unless
``degrees=True``.

With the coordinate axes these are the Euler angles: axes ``[ez, ey, ex]``
intrinsic are ``"ZYX"``:

>>> import numpy as np
>>> from rigidkit.functional import euler
>>> axes = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
>>> q = quat_from_davenport(axes, "intrinsic", [0.3, 0.2, 0.1])
>>> bool(np.allclose(q, euler.quat_from_euler("ZYX", [0.3, 0.2, 0.1])))
True
>>> np.round(davenport_from_quat(axes, "intrinsic", q), 12) + 0.0
array([0.3, 0.2, 0.1])

Both directions are batched: ``axes`` (..., n, 3) broadcast with the batch of the
angles or quaternions (one sequence for all, or one per element), and run on any
array namespace through the kernels of :mod:`rigidkit.kernels.davenport`; the
checks of the axes read their values (skipped under tracing, where a bad
sequence gives NaN).
"""

from __future__ import annotations

import math

import numpy as np

from .._engine.namespace import device_of, is_numpy, namespace_of
from .._validate import (
    as_array,
    checks_now,
    finite_array,
    raise_where,
    tolerances,
)
from ..errors import EulerSequenceError, ShapeError, ZeroNormError
from ..kernels import davenport as _k
from . import euler as _euler
from ._gimbal_lock import warn_if_locked

__all__ = [
    "LOCK_FACTOR",
    "quat_from_davenport",
    "davenport_from_quat",
    "davenport_from_quat_unchecked",
]

#: The lock tolerance (how far the rotation may move to return the third angle 0)
#: in units of Euler's :func:`rigidkit.euler.lock_tolerance` (2 eps). A quaternion
#: built from lock angles about general axes carries the roundings of the normalised
#: axes and of three products, and the reduction to ``XYX`` adds a product and three
#: projections: over 1200 random lock cases the residue needed up to 4 Euler
#: tolerances (81 exceeded 1). 8 (16 eps: 3.6e-15 rad in float64) leaves a margin and
#: still moves the rotation by no more than a few roundings.
LOCK_FACTOR = 8.0


def _reverse(order) -> int:
    """The kernels' ``reverse`` parameter: 1 for extrinsic, 0 for intrinsic."""
    if order in ("e", "extrinsic"):
        return 1
    if order in ("i", "intrinsic"):
        return 0
    raise EulerSequenceError(
        f"Davenport order must be 'extrinsic' (or 'e', world axes) or 'intrinsic' "
        f"(or 'i', body axes), got {order!r}"
    )


def _unit_axes(axes, *, exactly3, like=None):
    """The axes as unit vectors (..., n, 3), validated; ``n`` the number of axes.

    ``like``: an array whose namespace, floating dtype and device the axes take
    (the quaternions or angles they combine with).
    """
    axes = asarray_like(axes, like)
    a = finite_array(axes, (3,), "Davenport axes")
    if a.ndim == 1:
        a = a[None]
    n = a.shape[-2]
    if (exactly3 and n != 3) or not 1 <= n <= 3:
        want = "3" if exactly3 else "1, 2 or 3"
        raise ShapeError(
            f"Davenport axes: expected shape (3,) for one axis or "
            f"(..., n, 3) with n = {want} axes, got {tuple(a.shape)}"
        )
    unit, norm = _k.unit_axis(a)
    raise_where(
        norm == 0.0,
        ZeroNormError,
        "Davenport axis is zero {where} (the last index is the axis' position)",
    )
    bad = None
    if n > 1:
        xp = namespace_of(unit)
        dots = xp.sum(unit[..., :-1, :] * unit[..., 1:, :], axis=-1)
        tol = tolerances(dots.dtype).axis_orthogonality  # scipy's 1e-7, any dtype
        bad = xp.abs(dots) > tol
        raise_where(
            bad,
            EulerSequenceError,
            "Davenport axes {where} are not orthogonal: consecutive axes must be "
            f"(|n_i . n_i+1| <= {tol:g} once normalised; the last "
            "index is the position of the first of the two)",
        )
    return unit, n, bad


def asarray_like(axes, like):
    """``axes`` in the namespace, floating dtype and device of ``like`` (if any)."""
    dtype = getattr(like, "dtype", None)
    if dtype is None:
        return axes
    xp = namespace_of(like)
    if is_numpy(xp):
        kind = getattr(dtype, "kind", "f")
        return np.asarray(axes, dtype=dtype) if kind == "f" else axes
    if not xp.isdtype(dtype, "real floating"):
        dtype = None
    dev = device_of(like)
    return (
        xp.asarray(axes, dtype=dtype)
        if dev is None
        else xp.asarray(axes, dtype=dtype, device=dev)
    )


def _nan_where_bad(x, bad):
    """``x`` with NaN where the axes failed a check that could not run (tracing)."""
    if bad is None or checks_now(bad):
        return x
    xp = namespace_of(x)
    return xp.where(xp.any(bad, axis=-1)[..., None], math.nan, x)


def quat_from_davenport(axes, order, angles, *, degrees=False):
    """Unit quaternions of Davenport angles: turns about 1 to 3 given axes.

    Conventions: ``order="intrinsic"`` is ``R = R_n1(t1) R_n2(t2) R_n3(t3)``
    (body axes), ``"extrinsic"`` is ``R = R_n3(t3) R_n2(t2) R_n1(t1)`` (world
    axes); consecutive axes orthogonal. Quaternions Hamilton, scalar first.

    Parameters
    ----------
    axes : array_like, shape (3,) or (..., n, 3), n in 1..3
        The axes in the order named; any nonzero length (normalised).
    order : {"intrinsic", "i", "extrinsic", "e"}
    angles : array_like, shape (..., n)
        Radians (degrees with ``degrees=True``); a scalar for one axis. Its batch
        broadcasts with that of ``axes``.
    degrees : bool

    Returns
    -------
    quat : array, shape (..., 4)

    Raises
    ------
    EulerSequenceError
        For a bad ``order``, or consecutive axes that are not orthogonal (naming
        the batch index, the axis position last).
    ShapeError, NonFiniteError, ZeroNormError

    See Also
    --------
    davenport_from_quat : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> q = quat_from_davenport([0.0, 0.0, 2.0], "e", np.pi / 2)   # one axis
    >>> np.round(q, 12) + 0.0
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    rev = _reverse(order)
    a = as_array(angles, (), "Davenport angles")
    unit, n, bad = _unit_axes(axes, exactly3=False, like=a)
    if n == 1 and a.ndim == 0:
        a = a[None]
    a = finite_array(a, (n,), f"Davenport angles for {n} axes")
    ns = [unit[..., min(i, n - 1), :] for i in range(3)]  # padded turns are by 0
    if n < 3:
        a = _euler._concat(a, [namespace_of(a).zeros_like(a[..., :1])] * (3 - n))
    scale = math.pi / 180.0 if degrees else 1.0
    q = _k.quat_from_davenport(rev, scale, ns[0], ns[1], ns[2], a)
    return _nan_where_bad(q, bad)


def davenport_from_quat(axes, order, quat, *, degrees=False):
    """Davenport angles of quaternions (validated) about three given axes.

    Conventions as :func:`quat_from_davenport`. The quaternions may have any
    finite nonzero scale (as in :func:`rigidkit.euler.euler_from_quat`); NaN,
    infinite or zero ones raise, naming the batch index.

    Parameters
    ----------
    axes : array_like, shape (..., 3, 3)
        ``n1, n2, n3`` in the order named, consecutive ones orthogonal.
    order : {"intrinsic", "i", "extrinsic", "e"}
    quat : array_like, shape (..., 4)
    degrees : bool

    Returns
    -------
    angles : array, shape (..., 3)
        First and third in (-pi, pi]; the second in ``[lam, lam + pi]`` if ``lam
        <= 0`` and ``[lam - pi, lam]`` if ``lam > 0`` (scipy's ranges; for Euler
        axes ``[-pi/2, pi/2]`` Tait-Bryan, ``[0, pi]`` proper), where ``lam`` is
        the angle from the first axis of the matrix product to the last about
        ``-n2``: ``lam = atan2(n3 . (n1 x n2), n1 . n3)`` for intrinsic order and
        its negative for extrinsic (there the product starts with ``n3``).
        Exactly parallel ``n1``, ``n3`` give ``lam = 0``, antiparallel ``-pi``.

    Warns
    -----
    GimbalLockWarning
        Near the lock (the middle angle of the underlying proper sequence within
        :func:`rigidkit.euler.gimbal_lock_threshold` of 0 or pi), where only a
        sum or difference of the first and third angle is determined; at lock
        (the rotation moving by at most ``LOCK_FACTOR`` lock tolerances, 3.6e-15
        rad in float64) the third angle is 0, as in scipy and
        :func:`rigidkit.euler.euler_from_quat`.

    See Also
    --------
    quat_from_davenport : the inverse; davenport_from_quat_unchecked for unit input.
    """
    return davenport_from_quat_unchecked(
        axes, order, _euler._checked_quat(quat), degrees=degrees
    )


_LOCK_TEXT = {0: "intrinsic Davenport axes", 1: "extrinsic Davenport axes"}


def davenport_from_quat_unchecked(axes, order, quat, *, degrees=False, warn=True):
    """:func:`davenport_from_quat` for unit quaternions (no checks of ``quat``).

    The axes are still validated. Algorithm: reduction to the proper Euler
    sequence ``XYX`` in a frame built from the axes (see
    :func:`rigidkit.kernels.davenport.davenport_from_quat`), then the Euler
    kernel, accurate to a few ulp also near the lock. ``warn=False`` skips the
    gimbal-lock warning without touching any warning filter.

    >>> import numpy as np
    >>> axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 1.0]]  # n1, n3 at 45 deg
    >>> q = quat_from_davenport(axes, "extrinsic", [0.4, -0.3, 0.2])
    >>> np.round(davenport_from_quat_unchecked(axes, "extrinsic", q), 12) + 0.0
    array([ 0.4, -0.3,  0.2])
    """
    rev = _reverse(order)
    q = as_array(quat, (4,), "quaternion")
    unit, _, bad = _unit_axes(axes, exactly3=True, like=q)
    scale = 180.0 / math.pi if degrees else 1.0
    tol = LOCK_FACTOR * _euler.lock_tolerance(_euler._dtype(q))
    angles, aux = _k.davenport_from_quat(
        rev, scale, tol, q, unit[..., 0, :], unit[..., 1, :], unit[..., 2, :]
    )
    if warn:
        warn_if_locked(_LOCK_SEQ[rev], aux, scale)
    return _nan_where_bad(angles, bad)


# The auxiliary proper sequence whose middle angle measures the distance from the
# lock (0 or pi); only its text, "proper" flag and case are read by the warning.
_LOCK_SEQ = {
    r: _euler.EulerSequence(_LOCK_TEXT[r], (0, 1, 0), r == 0, True, ()) for r in (0, 1)
}
