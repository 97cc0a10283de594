"""``rigidkit.scipy.Slerp``: scipy's API on :class:`rigidkit.interpolation.Slerp`."""

from __future__ import annotations

from ..interpolation import Slerp as _RkSlerp
from ._arrays import as_float
from .rotation import Rotation, _new

__all__ = ["Slerp"]


class Slerp:
    """Spherical linear interpolation of rotations (scipy's ``Slerp``).

    Parameters
    ----------
    times : array_like, shape (N,)
        Strictly increasing times of the keyframes, ``N >= 2``.
    rotations : Rotation, shape (N,)
        The keyframes.

    Examples
    --------
    >>> import numpy as np
    >>> from rigidkit.scipy import Rotation, Slerp
    >>> keys = Rotation.from_rotvec([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    >>> np.round(Slerp([0.0, 2.0], keys)(0.5).as_rotvec(), 12) + 0.0
    array([0.  , 0.  , 0.25])
    """

    def __init__(self, times, rotations):
        if not isinstance(rotations, Rotation):
            raise TypeError("`rotations` must be a `Rotation` instance.")
        if rotations.single or len(rotations) <= 1:
            raise ValueError("`rotations` must be a sequence of at least 2 rotations.")
        if len(rotations.shape) > 1:
            raise ValueError(
                "Rotations with more than 1 leading dimension are not supported."
            )
        t = as_float(times)
        if t.ndim != 1:
            raise ValueError(
                "Expected times to be specified in a 1 dimensional array, got "
                f"{t.ndim} dimensions."
            )
        if t.shape[0] != len(rotations):
            raise ValueError(
                "Expected number of rotations to be equal to number of timestamps "
                f"given, got {len(rotations)} rotations and {t.shape[0]} timestamps."
            )
        if bool((t[1:] - t[:-1] <= 0).any()):
            raise ValueError("Times must be in strictly increasing order.")
        self.times = t
        self.timedelta = t[1:] - t[:-1]
        self.rotations = rotations[:-1]
        self._slerp = _RkSlerp(t, rotations._r)

    def __call__(self, times):
        """The interpolated rotations at ``times`` (scalar or 1-D)."""
        t = as_float(times)
        if t.ndim > 1:
            raise ValueError("`times` must be at most 1-dimensional.")
        lo, hi = self.times[0], self.times[-1]
        if bool(((t < lo) | (t > hi)).any()):
            raise ValueError(
                f"Interpolation times must be within the range [{lo}, {hi}], both "
                "inclusive."
            )
        return _new(self._slerp(t))
