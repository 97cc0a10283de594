"""Sequences of orientations: quaternion sign continuity and unwrapped angles.

For plots, learning targets and finite differences along time: ``q`` and ``-q``
are one rotation, and angles are defined modulo 2 pi, so a sequence read off a
rotation batch may jump where nothing moved. :func:`quat_continuous` flips signs
so that neighbours have non-negative dot products; :func:`unwrap_euler` adds
multiples of 2 pi so that neighbouring angles differ by at most pi (as
``numpy.unwrap``, per component). Arrays of any namespace; along one axis, any
leading batch shape; jit-safe (a cumulative sum, no data-dependent shapes).

>>> import numpy as np
>>> q = np.array([[1.0, 0.0, 0.0, 0.0], [-0.99, 0.0, 0.0, -0.141], [0.98, 0.0, 0.0, 0.199]])
>>> quat_continuous(q)[:, 0]
array([1.  , 0.99, 0.98])
"""

from __future__ import annotations

import math

import numpy as np

from .._engine.namespace import is_numpy, namespace_of
from .._validate import as_array, finite_array
from ..errors import ShapeError

__all__ = ["quat_continuous", "unwrap_euler"]


def _axis(x, axis, what):
    """``axis`` of ``x`` as a non-negative index that is not the last (component) one."""
    nd = x.ndim
    if not -nd <= axis < nd or axis % nd == nd - 1:
        raise ShapeError(
            f"{what}: axis {axis} must be a sequence axis of shape {tuple(x.shape)}, "
            "not the last (component) axis"
        )
    return axis % nd


def _moveaxis(x, src, dst):
    if isinstance(x, np.ndarray):
        return np.moveaxis(x, src, dst)
    if hasattr(x, "movedim"):  # torch
        return x.movedim(src, dst)
    return namespace_of(x).moveaxis(x, src, dst)


def _concat(xp, arrays, axis):
    if is_numpy(xp):
        return np.concatenate(arrays, axis=axis)
    return xp.concat(arrays, axis=axis)


def quat_continuous(quat, *, axis=-2):
    """Quaternions flipped to ``-q`` so that neighbours have ``q_k . q_k+1 >= 0``.

    The first element keeps its sign; each later one is flipped iff an odd number
    of the dot products before it (between the original neighbours) are
    negative, i.e. ``s_k = s_k-1 sign(q_k-1 . q_k)``. The rotations are
    unchanged. A dot product of exactly 0 (a half-turn step) keeps the sign.

    Parameters
    ----------
    quat : array_like, shape (..., N, ..., 4)
        Any quaternions (not normalised); ``N`` along ``axis``.
    axis : int
        The sequence axis of the array (default -2: shape (..., N, 4)).

    Returns
    -------
    array, same shape

    See Also
    --------
    rigidkit.Rotation.continuous : the same on a Rotation batch.
    """
    q = as_array(quat, (4,), "quaternion sequence")
    ax = _axis(q, axis, "quat_continuous")
    xp = namespace_of(q)
    s = _moveaxis(q, ax, -2)
    if s.shape[-2] < 2:
        return q
    dots = xp.sum(s[..., 1:, :] * s[..., :-1, :], axis=-1)
    flips = (dots < 0.0) * 1  # int 0/1 in every namespace
    parity = flips.cumsum(-1) % 2
    sign = 1.0 - 2.0 * parity
    sign = _concat(xp, [xp.ones_like(sign[..., :1]), sign], -1)
    return _moveaxis(s * sign[..., None], -2, ax)


def unwrap_euler(angles, *, axis=-2, degrees=False):
    """Euler angles made continuous along ``axis``: jumps of more than pi unwrapped.

    Per component exactly ``numpy.unwrap(angles, axis=axis, period=2 pi)`` (360
    with ``degrees=True``): each step is replaced by its representative in
    [-pi, pi) (a step of exactly ``+pi`` stays ``+pi``, and steps of magnitude
    below pi are kept, as in numpy) and the corrections are summed along it.
    The rotations are unchanged. Not repaired: a switch of the decomposition's
    branch (near gimbal lock, or where a proper sequence's middle angle passes 0,
    the first and third angle change by pi together); only 2 pi wraps are.

    Parameters
    ----------
    angles : array_like, shape (..., N, ..., 3)
        Any angles (also other than Euler); ``N`` along ``axis``.
    axis : int
        The sequence axis (default -2: shape (..., N, 3)).
    degrees : bool

    Returns
    -------
    array, same shape

    >>> import numpy as np
    >>> a = np.array([[3.0, 0.0, 0.0], [-3.0, 0.0, 0.1], [-2.9, 0.0, 6.3]])
    >>> np.round(unwrap_euler(a), 6) + 0.0
    array([[3.      , 0.      , 0.      ],
           [3.283185, 0.      , 0.1     ],
           [3.383185, 0.      , 0.016815]])
    """
    a = finite_array(angles, (3,), "Euler angle sequence")
    ax = _axis(a, axis, "unwrap_euler")
    xp = namespace_of(a)
    period = 360.0 if degrees else 2.0 * math.pi
    half = 0.5 * period
    s = _moveaxis(a, ax, -2)
    if s.shape[-2] < 2:
        return a
    d = s[..., 1:, :] - s[..., :-1, :]
    dmod = (d + half) % period - half
    dmod = xp.where((dmod == -half) & (d > 0.0), half, dmod)
    correction = xp.where(xp.abs(d) < half, 0.0 * d, dmod - d)
    rest = s[..., 1:, :] + correction.cumsum(-2)
    return _moveaxis(_concat(xp, [s[..., :1, :], rest], -2), -2, ax)
