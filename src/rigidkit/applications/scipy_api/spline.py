"""``rigidkit.scipy.RotationSpline``: scipy's API on :class:`rigidkit.RotationSpline`.

scipy's C2 cubic rotation spline: ``spline(times)`` rotations, ``spline(times, 1)``
angular rates and ``spline(times, 2)`` angular accelerations in the body frame
(``R^T dR/dt``), any finite time (outside the keyframes the end cubics continue,
as scipy's piecewise polynomial extrapolates). rigidkit solves the spline's
equations to rounding where scipy stops after 10 fixed-point steps (~1e-9 from
the exact spline).
"""

from __future__ import annotations

import numpy as np

from ...objects.rotation import Rotation as _RkRotation
from ..splines import RotationSpline as _RkSpline
from .rotation import Rotation, _new

__all__ = ["RotationSpline"]


class RotationSpline:
    """Interpolate rotations with continuous angular rate and acceleration (scipy's).

    Parameters
    ----------
    times : array_like, shape (N,)
        Strictly increasing times of the keyframes, ``N >= 2``.
    rotations : Rotation, shape (N,)
        The keyframes.

    Examples
    --------
    >>> import numpy as np
    >>> from rigidkit.scipy import Rotation, RotationSpline
    >>> keys = Rotation.from_rotvec([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 2.0]])
    >>> spline = RotationSpline([0.0, 1.0, 2.0], keys)
    >>> np.round(spline(1.5).as_rotvec(), 12) + 0.0
    array([0. , 0. , 1.5])
    >>> np.round(spline(0.5, 1), 12) + 0.0                # rad per time unit
    array([0., 0., 1.])
    """

    def __init__(self, times, rotations):
        if not isinstance(rotations, Rotation):
            raise TypeError("`rotations` must be a `Rotation` instance.")
        if rotations.single:
            raise ValueError("`rotations` must be a sequence of rotations.")
        if len(rotations.shape) > 1:
            raise ValueError(
                "Rotations with more than 1 leading dimension are not supported."
            )
        if len(rotations) == 1:
            raise ValueError("`rotations` must contain at least 2 rotations.")
        t = np.asarray(times, dtype=float)
        if t.ndim != 1:
            raise ValueError("`times` must be 1-dimensional.")
        if len(t) != len(rotations):
            raise ValueError(
                "Expected number of rotations to be equal to number of timestamps "
                f"given, got {len(rotations)} rotations and {len(t)} timestamps."
            )
        if np.any(np.diff(t) <= 0):
            raise ValueError("Values in `times` must be in a strictly increasing order.")
        q = rotations._r._quat
        if type(q) is not np.ndarray:  # scipy's spline is NumPy only: so are its results
            q = np.asarray(q.detach().cpu() if hasattr(q, "detach") else q, dtype=float)
        self.times = t
        self.rotations = _new(_RkRotation._wrap(q))
        self._spline = _RkSpline(t, self.rotations._r, extrapolate=True)

    def __call__(self, times, order=0):
        """Rotations (``order=0``), body angular rates (1) or accelerations (2)."""
        if order not in (0, 1, 2):
            raise ValueError("`order` must be 0, 1 or 2.")
        t = np.asarray(times, dtype=float)
        if t.ndim > 1:
            raise ValueError("`times` must be at most 1-dimensional.")
        if order == 0:
            return _new(self._spline(t))
        return self._spline(t, order, frame="body")

    def as_rigidkit(self):
        """The :class:`rigidkit.RotationSpline` (``extrapolate=True``) behind it."""
        return self._spline
