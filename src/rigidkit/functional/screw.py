"""Screws: the axis, pitch and magnitude of a twist (arrays in, arrays out, batched).

Chasles' theorem: every rigid motion is a turn by ``angle`` about an axis (a point
``q`` on it and a direction ``u``) combined with a slide of ``pitch * angle`` along
it. For a twist ``V = (v, w)`` (Murray, Li & Sastry 1994, Sec. 2.3.3, whose
twists are ordered so too): ``u = w / |w|``, magnitude
``|w|``, pitch ``h = w . v / |w|^2`` (length per radian) and ``q = w x v / |w|^2``,
the axis point nearest the origin; ``v = -w x q + h w``. A twist with ``w = 0`` is
a pure translation: pitch ``inf``, ``u = v / |v|``, magnitude ``|v|``, ``q = 0``.
Applied to ``Transform.log()`` these are the screw parameters of the motion
(magnitude = the rotation angle, in [0, pi]).

>>> import numpy as np
>>> V = np.array([0.0, 0.0, 0.5, 0.0, 0.0, 2.0])   # turn about z at 2 rad/s, slide 0.5
>>> q, u, h, m = screw_from_twist(V)
>>> u, float(h), float(m)
(array([0., 0., 1.]), 0.25, 2.0)
>>> bool(np.allclose(twist_from_screw(q, u, h, m), V))
True
"""

from __future__ import annotations

import math

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import device_of, namespace_of
from .._validate import as_array, check_finite, finite_array, raise_where
from ..errors import ZeroNormError
from ..kernels import screw as _k

__all__ = ["screw_from_twist", "twist_from_screw"]


def screw_from_twist(twist):
    """Screw parameters ``(point, direction, pitch, magnitude)`` of twists ``(v, w)``.

    Parameters
    ----------
    twist : array_like, shape (..., 6)
        Twists ``(v, w)``; ``w`` in radians (per unit time for a velocity).

    Returns
    -------
    point : array, shape (..., 3)
        The axis point nearest the origin, ``w x v / |w|^2`` (0 for a translation).
    direction : array, shape (..., 3)
        Unit axis ``w / |w|``; ``v / |v|`` for a pure translation, ``+x`` for 0.
    pitch : array, shape (...)
        ``w . v / |w|^2``, length per radian; ``inf`` for a pure translation.
    magnitude : array, shape (...)
        ``|w|``, or ``|v|`` for a pure translation.

    See Also
    --------
    twist_from_screw : the inverse.
    """
    V = finite_array(twist, (6,), "twist")
    q, u, h, m, rotates = _k.screw_from_twist(V)
    xp = namespace_of(h)
    translates = (rotates < 0.5) & (m > 0.0)
    if isinstance(h, np.ndarray) or xp is np:
        h = np.where(translates, np.inf, h)[()]
    else:
        h = xp.where(translates, xp.asarray(math.inf, dtype=h.dtype), h)
    return q, u, h, m


def twist_from_screw(point, direction, pitch, magnitude):
    """Twist ``(v, w)`` of a screw: ``w = m u``, ``v = q x w + h w``.

    Parameters
    ----------
    point : array_like, shape (..., 3)
        Any point ``q`` on the axis.
    direction : array_like, shape (..., 3)
        Axis direction, any nonzero length (normalised here).
    pitch : array_like, shape (...)
        Length per radian; ``inf`` (or ``-inf``) for a pure translation along
        ``direction``.
    magnitude : array_like, shape (...)
        The angle (radians; or a rate) of the turn, or the length of a pure
        translation.

    Returns
    -------
    array, shape (..., 6)
        Batch shapes broadcast.

    Raises
    ------
    ZeroNormError
        A zero direction, naming the batch index.
    NonFiniteError
        NaN anywhere, or infinity other than in ``pitch``.

    See Also
    --------
    screw_from_twist : the inverse.
    """
    q = finite_array(point, (3,), "screw axis point")
    u = finite_array(direction, (3,), "screw direction")
    m = finite_array(magnitude, (), "screw magnitude")
    h = as_array(pitch, (), "screw pitch")
    xp = namespace_of(u, q, h, m)
    like = next((a for a in (u, q, h, m) if not isinstance(a, np.ndarray)), None)
    if like is None:
        h = np.asarray(h, dtype=np.result_type(h, u.dtype, np.float32))
    elif not dask_backend.any_dask(u, q, h, m):  # NumPy numbers meet the others
        q, u, h, m = (
            xp.asarray(a, dtype=like.dtype, device=device_of(like))
            if isinstance(a, np.ndarray)
            else a
            for a in (q, u, h, m)
        )
    zero = xp.all(u == 0, axis=-1)
    # skipped under tracing and with set_validation(False); on Dask at compute time
    raise_where(zero, ZeroNormError, "screw direction is the zero vector {where}")
    infinite = xp.abs(h) == math.inf
    finite_h = xp.where(infinite, xp.zeros_like(h), h)
    check_finite(finite_h, (), "screw pitch")
    rotates = xp.where(infinite, xp.zeros_like(finite_h), xp.ones_like(finite_h))
    return _k.twist_from_screw(q, u, finite_h, m, rotates)
