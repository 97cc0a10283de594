"""Swing-twist decomposition of rotations about an axis (arrays in and out).

``q = swing twist`` (Hamilton product, ``twist`` applied first): the twist is a
turn about the given axis ``n`` (in the frame the rotation acts on, i.e. body axis
of ``q``: ``R = R_swing @ R_twist``), the swing a turn about an axis orthogonal to
``n``; the twist has ``w >= 0``, its angle in [-pi, pi] about ``+n``. For the
other order, ``q = twist' swing'``, decompose ``q*`` and invert both. Quaternions
Hamilton, scalar first ``(w, x, y, z)``.

>>> import numpy as np
>>> q = np.array([np.cos(0.5), 0.0, 0.0, np.sin(0.5)])    # 1 rad about z
>>> swing, twist = swing_twist(q, [0.0, 0.0, 1.0])
>>> np.round(swing, 12) + 0.0, np.round(twist, 12) + 0.0
(array([1., 0., 0., 0.]), array([0.87758256, 0.        , 0.        , 0.47942554]))
"""

from __future__ import annotations

from .._validate import finite_array, raise_where
from ..errors import ZeroNormError
from ..kernels import davenport as _kd
from ..kernels import swing_twist as _k
from .conversions import quat_normalize

__all__ = ["swing_twist", "swing_twist_unchecked"]


def swing_twist(quat, axis):
    """``(swing, twist)`` with ``quat = swing twist`` and ``twist`` about ``axis``.

    Parameters
    ----------
    quat : array_like, shape (..., 4)
        Normalised first (validated).
    axis : array_like, shape (..., 3)
        Any nonzero length; broadcasts with ``quat``.

    Returns
    -------
    swing, twist : arrays, shape (..., 4)
        ``twist = (cos(t/2), sin(t/2) n)`` with ``t`` in [-pi, pi]; ``swing`` turns
        about an axis orthogonal to ``n``. Where the swing is a half turn every
        twist would do (``w = v . n = 0``): the twist is then the identity.

    Raises
    ------
    NonFiniteError, ZeroNormError
    """
    n = finite_array(axis, (3,), "twist axis")
    unit, norm = _kd.unit_axis(n)
    raise_where(norm == 0.0, ZeroNormError, "twist axis is zero {where}")
    return _k.swing_twist(quat_normalize(quat), unit)


def swing_twist_unchecked(quat, axis):
    """:func:`swing_twist` for unit quaternions and unit axes, without checks."""
    return _k.swing_twist(quat, axis)
