"""Smooth trajectories on SO(3) and SE(3): ``rk.RotationSpline``, ``rk.BSplineSO3``
and ``rk.BSplineSE3``.

``RotationSpline`` interpolates keyframes with continuous angular velocity and
acceleration (C2), as scipy's, solved exactly; the cumulative cubic B-splines
approximate their control points (they pass near, not through, them) on uniform
knots, the continuous-time trajectory of visual-inertial estimation, with
exact first and second derivatives. The formulas are in
:mod:`rigidkit.functional.splines`.

Rates are angular velocities (rad per time unit) and accelerations, or for SE(3)
twists ``(v, w)`` and their derivatives. ``frame="body"`` gives ``R^T dR/dt``
(scipy's ``RotationSpline`` rates), ``frame="world"`` gives ``dR/dt R^T``
(``R`` times the body rate; for SE(3) the adjoint ``Ad_T`` of the body twist);
the derivative of the world rate is the world image of the body one. ``frame=``
is required for orders 1 and 2.
"""

from __future__ import annotations

from .._validate import dynamo_traces
from ..errors import FrameKeywordError
from ..functional import splines as _fs
from ..objects import registry
from ..objects.registry import stored
from ..objects.rotation import Rotation
from ..objects.transform import Transform
from .interpolation import keyframe_kind, keyframe_times, query_times

__all__ = ["RotationSpline", "BSplineSO3", "BSplineSE3"]


def _check_order(order, frame):
    if order not in (0, 1, 2):
        raise ValueError(f"order must be 0, 1 or 2, got {order!r}")
    if order and frame not in ("body", "world"):
        raise FrameKeywordError(
            f"order {order} needs frame='body' (R^T dR/dt, scipy's) or frame='world' "
            f"(dR/dt R^T), got frame={frame!r}"
        )


def _shape(out, q, k):
    """Results (q.size, extra..., k) reshaped to (q.shape, extra..., k)."""
    return out.reshape(tuple(q.shape) + tuple(out.shape[1:-1]) + (k,))


class _Spline:
    """Shared evaluation: validation of ``times``, ``order`` and ``frame``; shapes."""

    kind = Rotation
    t_min = t_max = 0.0
    extrapolate = False

    def __call__(self, times, order=0, *, frame=None):
        """Rotations (order 0), velocities (1) or accelerations (2) at ``times``.

        Parameters
        ----------
        times : array_like, shape (...)
            Within ``[t_min, t_max]``, else :class:`~rigidkit.OutOfRangeError`
            (any finite time for a spline made with ``extrapolate=True``).
        order : {0, 1, 2}
        frame : {"body", "world"}
            Required for orders 1 and 2 (:class:`~rigidkit.FrameKeywordError` otherwise).

        Returns
        -------
        Rotation or Transform of batch ``times.shape + extra``, or an array of shape
        ``times.shape + extra + (3,)`` (SO(3)) or ``(6,)`` (SE(3) twists ``(v, w)``).
        """
        _check_order(order, frame)
        q = query_times(times, self.t_min, self.t_max, extrapolate=self.extrapolate)
        flat = q.reshape(-1)  # the caller's namespace: traces, stays lazy on Dask
        wrap = registry.spec(self.kind).wrap
        if order == 0:
            out = self._eval(flat, 0)
            return wrap(_shape(out, q, out.shape[-1]))
        rate = self._eval(flat, order)
        if frame == "world":
            x = wrap(self._eval(flat, 0))
            rate = x.apply(rate) if self.kind is Rotation else _matvec(x.adjoint(), rate)
        return _shape(rate, q, rate.shape[-1])


def _matvec(m, v):
    return (m @ v[..., None])[..., 0]


class RotationSpline(_Spline):
    """C2 cubic interpolation of rotations (scipy's ``RotationSpline``, solved exactly).

    On ``[t_i, t_{i+1}]``, ``R(t) = R_i exp(hat(r(t - t_i)))`` with a cubic rotation
    vector ``r``; the knot rates make the angular acceleration continuous. scipy
    stops its solve after 10 fixed-point steps (about 1e-9 from the C2 spline); this
    one iterates Newton's method to rounding (:attr:`iterations` steps).

    Parameters
    ----------
    times : array_like, shape (n,)
        Strictly increasing, ``n >= 2``.
    rotations : Rotation, shape (n, ...)
        Keyframes, time axis first; further batch axes give several splines on
        the same times.
    extrapolate : bool
        Outside ``[times[0], times[-1]]``: ``False`` (default) raises
        :class:`~rigidkit.OutOfRangeError`; ``True`` continues the first and last
        cubic segments, as scipy's ``RotationSpline`` does (its rates and
        accelerations too).

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> keys = rk.Rotation.from_euler("XYZ", [[-10, 20, 30], [0, 15, 40], [-30, 45, 30]],
    ...                               degrees=True)
    >>> spline = rk.RotationSpline([0.0, 10.0, 20.0], keys)
    >>> bool(spline([0.0, 10.0, 20.0]).approx_equal(keys).all())
    True
    >>> spline(5.0, 1, frame="body").shape                    # rad per time unit
    (3,)
    >>> ahead = rk.RotationSpline([0.0, 10.0, 20.0], keys, extrapolate=True)
    >>> ahead([-5.0, 25.0]).shape                             # the end cubics continued
    (2,)
    """

    def __init__(self, times, rotations, *, extrapolate=False):
        keyframe_kind(rotations, 2, "rotations")
        if not isinstance(rotations, Rotation):
            raise TypeError(
                "RotationSpline interpolates a Rotation; use BSplineSE3 for poses"
            )
        knots = keyframe_times(times, len(rotations), "rotations")
        # Solved before the first attribute is set: inside torch.compile the solve
        # is a while_loop, and TorchDynamo (torch 2.13) loses an attribute set
        # after one on an object whose attributes were set before it.
        coeffs, iterations = _fs.rotation_spline_coefficients(knots, stored(rotations))
        self.times, self.rotations = knots, rotations
        self.extrapolate = bool(extrapolate)
        self.t_min, self.t_max = float(knots[0]), float(knots[-1])
        self._coeffs, self.iterations = coeffs, iterations

    def _eval(self, flat, order):
        return _fs.rotation_spline_eval(
            self.times, stored(self.rotations), self._coeffs, flat, order
        )


class BSplineSO3(_Spline):
    """Cumulative cubic B-spline on SO(3) with uniform knots.

    ``R(t) = R_s prod_{j=1..3} exp(l_j(u) log(R_{s+j-1}^-1 R_{s+j}))`` on
    ``[t0 + s dt, t0 + (s+1) dt)``, ``u = (t - t0)/dt - s``: C2 everywhere, with
    exact angular velocity and acceleration. It approximates the control points
    (``R(t0 + s dt)`` is a blend of ``R_s, R_{s+1}, R_{s+2}``).

    Parameters
    ----------
    control_points : Rotation, shape (n, ...)
        ``n >= 4``; time axis first.
    dt : float
        Knot spacing (> 0).
    t0 : float
        Start time; the spline is defined on ``[t0, t0 + (n - 3) dt]``.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> ctrl = rk.Rotation.from_rotvec(np.outer(np.arange(5.0), [0.0, 0.0, 0.1]))
    >>> spline = rk.BSplineSO3(ctrl, dt=0.5)
    >>> spline.t_max
    1.0
    >>> np.round(spline([0.0, 0.5], 1, frame="body"), 12) + 0.0  # 0.1 rad per 0.5 s
    array([[0. , 0. , 0.2],
           [0. , 0. , 0.2]])
    """

    kind = Rotation

    def __init__(self, control_points, *, dt=1.0, t0=0.0):
        if keyframe_kind(control_points, 4, "control_points") is not self.kind:
            raise TypeError(f"{type(self).__name__} needs a {self.kind.__name__}")
        dt, t0 = float(dt), float(t0)
        # (a dt made from NumPy stamps that torch.compile traces is a symbol then)
        if not dynamo_traces() and not dt > 0.0:
            raise ValueError(f"dt must be positive, got {dt!r}")
        self.control_points = control_points
        self.dt, self.t0 = dt, t0
        self.t_min, self.t_max = t0, t0 + (len(control_points) - 3) * dt

    def _eval(self, flat, order):
        data = stored(self.control_points)
        return _fs.bspline_so3_eval(data, self.dt, self.t0, flat, order)


class BSplineSE3(BSplineSO3):
    """Cumulative cubic B-spline on SE(3) with uniform knots (twists ``(v, w)``).

    As :class:`BSplineSO3` with ``Transform`` control points and the SE(3) exp and
    log; the rates are twists ``(v, w)``: body ``vee(T^-1 dT/dt)`` or world
    ``vee(dT/dt T^-1)``.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> ctrl = rk.Transform.exp(np.outer(np.arange(4.0), [1.0, 0.0, 0.0, 0.0, 0.0, 0.2]))
    >>> np.round(rk.BSplineSE3(ctrl)(0.5, 1, frame="body"), 12) + 0.0  # a constant screw
    array([1. , 0. , 0. , 0. , 0. , 0.2])
    """

    kind = Transform

    def _eval(self, flat, order):
        data = stored(self.control_points)
        return _fs.bspline_se3_eval(data, self.dt, self.t0, flat, order)
