"""Euler-angle rates and angular velocity, for all 24 sequences.

``omega = E(angles) @ rates`` with the angles and their rates in the sequence's
own order; ``omega`` in the world frame (``hat(omega) = R' R^T``) or the body frame
(``R^T R'``), ``R = from_euler(seq, angles)``. Sequences as in ``from_euler``:
UPPERCASE intrinsic (``"XYZ"`` is ``Rx(a) Ry(b) Rz(c)``), lowercase extrinsic
(``"xyz"`` is ``Rz(c) Ry(b) Rx(a)``). The columns of ``E`` are the axes of the
three turns, each moved by the turns before it (world) or undone by those after
it (body); see :mod:`rigidkit.kernels.kinematics.euler_rates`.

``E`` is singular at gimbal lock (a middle angle of ``+-pi/2`` for Tait-Bryan
sequences, ``0`` or ``pi`` for proper ones): the inverse functions raise
:class:`~rigidkit.GimbalLockError` there, stating the distance to the lock and the
tolerance, instead of returning rates of size ``1 / distance``.

With ``degrees=True`` the angles are in degrees and their rates (and second
derivatives) in degrees per unit time; ``omega`` and ``alpha`` stay in radians.

Sequences of one or two axes (``"ZX"``, ``"zy"``, ``"X"``), which ``from_euler``
takes as scipy does (``"ZX"`` is ``Rz(a) Rx(b)``), have ``n = 1, 2`` angles: ``E``
is 3 x n, its columns the n axes (in the world frame ``z`` and ``Rz(a) x`` for
``"ZX"``). Those columns are orthonormal (a turn about an axis keeps the next,
perpendicular axis perpendicular to it), so ``E`` never loses rank, there is no
gimbal lock, and the inverse functions return the pseudo-inverse ``E^+ = E^T``
(``E^T / s^2`` with ``degrees=True``, ``s = pi/180``): the least-squares rates,
exact whenever ``omega`` is an angular velocity the sequence can have (in the span
of the axes), and the rates of the projection of ``omega`` onto that span
otherwise. ``tol`` has nothing to check there.

>>> import numpy as np
>>> E = euler_rate_matrix("ZYX", [0.3, 0.2, 0.1], frame="body")   # yaw, pitch, roll
>>> bool(np.isclose(np.linalg.det(E), -np.cos(0.2)))              # det = -cos(pitch)
True
"""

from __future__ import annotations

import math

import numpy as np

from ..._engine.namespace import is_numpy, namespace_of
from ..._validate import as_array
from ...functional.euler import (
    gimbal_lock_threshold,
    parse_sequence,
    parse_short_sequence,
)
from ...kernels.kinematics import euler_rates as _k
from ._common import body_flag, vector
from ._gimbal import check_lock

__all__ = [
    "euler_rate_matrix",
    "euler_rate_matrix_inverse",
    "euler_rate_matrix_derivative",
    "angular_velocity_from_euler_rates",
    "euler_rates",
    "angular_acceleration_from_euler_rates",
    "euler_accelerations",
]


def _setup(seq, angles, frame, degrees, fn):
    """Kernel parameters, the angles padded to three, the parsed sequence and ``n``.

    A sequence of ``n = 1`` or ``2`` axes is padded as ``from_euler`` pads it
    (:func:`~rigidkit.functional.euler.parse_short_sequence`): turns by 0 about
    the axes that complete a Tait-Bryan sequence, so the kernels of the 24
    sequences serve it.
    """
    body = body_flag(frame, fn)
    if isinstance(seq, str) and len(seq) == 3:
        s, n = parse_sequence(seq), 3
    else:
        s, n = parse_short_sequence(seq)
    a = _padded(angles, n, f"Euler angles for {seq!r}")
    scale = math.pi / 180.0 if degrees else 1.0
    return (*s.params, body, scale), a, s, n


def _padded(x, n, what):
    """``x`` of ``n`` components (a scalar for ``n = 1``) checked, padded with zeros."""
    if n == 3:
        return vector(x, (3,), what)
    a = as_array(x, (), what)
    if n == 1 and a.ndim == 0:
        a = a[None]
    a = vector(a, (n,), what)
    zeros = [namespace_of(a).zeros_like(a[..., :1])] * (3 - n)
    if isinstance(a, np.ndarray) or is_numpy(namespace_of(a)):
        return np.concatenate([a, *zeros], axis=-1)
    return namespace_of(a).concat([a, *zeros], axis=-1)


def _tol(tol, a):
    return gimbal_lock_threshold(getattr(a, "dtype", None)) if tol is None else tol


def euler_rate_matrix(seq, angles, *, frame, degrees=False):
    """The Euler-rate matrix ``E``: ``omega = E @ d(angles)/dt``.

    Parameters
    ----------
    seq : str
        Three letters of ``xyz``: UPPERCASE intrinsic, lowercase extrinsic; or
        one or two (``"ZX"``: ``R = Rz(a) Rx(b)``), as ``from_euler`` takes them.
    angles : array_like, shape (..., n)
        ``n = len(seq)`` angles in the order of ``seq`` (a scalar for one axis);
        radians, or degrees with ``degrees=True``.
    frame : {"world", "body"}
        The frame of ``omega``. Required.
    degrees : bool
        Angles in degrees and rates in degrees per unit time (``omega`` in rad).

    Returns
    -------
    array, shape (..., 3, n)
        Rows ``x, y, z`` of ``omega``; columns the angles in ``seq`` order.

    See Also
    --------
    euler_rate_matrix_inverse, angular_velocity_from_euler_rates

    Examples
    --------
    Intrinsic ``"XYZ"`` (``R = Rx(a) Ry(b) Rz(c)``) in world axes: the columns are
    the axes the three rates turn about, ``x``, ``Rx(a) y`` and ``Rx(a) Ry(b) z``,
    so ``E = [[1, 0, sb], [0, ca, -sa cb], [0, sa, ca cb]]``:

    >>> import numpy as np
    >>> a, b = 0.3, 0.4
    >>> E = euler_rate_matrix("XYZ", [a, b, 0.5], frame="world")
    >>> bool(np.allclose(E, [[1, 0, np.sin(b)], [0, np.cos(a), -np.sin(a) * np.cos(b)],
    ...                      [0, np.sin(a), np.cos(a) * np.cos(b)]]))
    True

    Two axes: ``"ZX"`` turns about world ``z``, then about the turned ``x``:

    >>> np.round(euler_rate_matrix("ZX", [np.pi / 2, 0.3], frame="world"), 12) + 0.0
    array([[0., 0.],
           [0., 1.],
           [1., 0.]])
    """
    p, a, _, n = _setup(seq, angles, frame, degrees, "euler_rate_matrix")
    E = _k.rate_matrix_from_euler(*p, a)
    return E if n == 3 else E[..., :, :n]


def euler_rate_matrix_inverse(seq, angles, *, frame, degrees=False, tol=None):
    """``E^-1``: ``d(angles)/dt = E^-1 @ omega``; raises at gimbal lock.

    For a sequence of one or two axes, the pseudo-inverse ``E^+ = E^T`` (over
    ``(pi/180)^2`` with ``degrees=True``), shape (..., n, 3): those columns of
    ``E`` are orthonormal, with no lock (see the module docstring).

    Parameters
    ----------
    seq, angles, frame, degrees
        As in :func:`euler_rate_matrix`.
    tol : float, optional
        Smallest accepted distance (radians) of the middle angle from the lock;
        default :func:`rigidkit.euler.gimbal_lock_threshold` of the dtype
        (``sqrt(eps)``: 1.5e-8 for float64, 3.5e-4 for float32). ``E^-1`` grows
        as ``1 / distance`` and its error as ``eps / distance^2``.

    Returns
    -------
    array, shape (..., n, 3)
        Rows: the angles in ``seq`` order; columns ``x, y, z``.

    Raises
    ------
    GimbalLockError
        Where the middle angle is within ``tol`` of the lock (naming the first
        batch index, the distance and ``tol``). Only where values can be read:
        under ``jax.jit``, ``torch.compile`` and ``torch.func`` the check is
        skipped (rows of size ``1 / distance`` come out), on Dask arrays it runs
        at compute time, and ``rk.set_validation(False)`` removes it.

    Examples
    --------
    >>> import numpy as np
    >>> Ei = euler_rate_matrix_inverse("ZYX", [0.3, 0.2, 0.1], frame="world")
    >>> E = euler_rate_matrix("ZYX", [0.3, 0.2, 0.1], frame="world")
    >>> bool(np.allclose(Ei @ E, np.eye(3)))
    True
    """
    p, a, s, n = _setup(seq, angles, frame, degrees, "euler_rate_matrix_inverse")
    if n < 3:
        return _k.rate_matrix_transpose_from_euler(*p, a)[..., :n, :]
    inv, dist = _k.rate_matrix_inverse_from_euler(*p, a)
    check_lock(dist, _tol(tol, a), s, "euler_rate_matrix_inverse")
    return inv


def euler_rate_matrix_derivative(seq, angles, rates, *, frame, degrees=False):
    """``dE/dt`` for angles changing at ``rates``, exact (cross products of the axes).

    Parameters
    ----------
    seq, angles, frame, degrees
        As in :func:`euler_rate_matrix`.
    rates : array_like, shape (..., n)
        ``d(angles)/dt``, in ``seq`` order.

    Returns
    -------
    array, shape (..., 3, n)
        Laid out as :func:`euler_rate_matrix`, per unit time.

    Examples
    --------
    >>> import numpy as np
    >>> Ed = euler_rate_matrix_derivative("ZYX", [0.3, 0.2, 0.1], [1.0, 0, 0], frame="body")
    >>> bool(np.allclose(Ed, 0))   # yaw is the outermost turn: E_body does not depend on it
    True
    """
    p, a, _, n = _setup(seq, angles, frame, degrees, "euler_rate_matrix_derivative")
    Ed = _k.rate_matrix_derivative_from_euler(*p, a, _padded(rates, n, "Euler rates"))
    return Ed if n == 3 else Ed[..., :, :n]


def angular_velocity_from_euler_rates(seq, angles, rates, *, frame, degrees=False):
    """``omega = E(angles) @ rates`` (fused; ``E`` is not stored).

    Parameters
    ----------
    seq, angles, rates, frame, degrees
        As in :func:`euler_rate_matrix_derivative`.

    Returns
    -------
    array, shape (..., 3)
        Angular velocity in ``frame``, radians per unit time.

    See Also
    --------
    euler_rates : the inverse.

    Examples
    --------
    Yaw rate only (``"ZYX"``): the world angular velocity is about world z.

    >>> angles = [0.3, 0.2, 0.1]
    >>> angular_velocity_from_euler_rates("ZYX", angles, [2.0, 0, 0], frame="world")
    array([0., 0., 2.])
    """
    p, a, _, n = _setup(seq, angles, frame, degrees, "angular_velocity_from_euler_rates")
    return _k.omega_from_euler_rates(*p, a, _padded(rates, n, "Euler rates"))


def euler_rates(seq, angles, omega, *, frame, degrees=False, tol=None):
    """Euler-angle rates ``E^-1 @ omega``; raises :class:`GimbalLockError` at the lock.

    For one or two axes, ``E^+ @ omega``: the least-squares rates (exact when
    ``omega`` is in the span of the axes; see the module docstring).

    Parameters
    ----------
    seq, angles, frame, degrees
        As in :func:`euler_rate_matrix`.
    omega : array_like, shape (..., 3)
        Angular velocity in ``frame``, radians per unit time.
    tol : float, optional
        As in :func:`euler_rate_matrix_inverse`.

    Returns
    -------
    array, shape (..., n)
        In ``seq`` order (degrees per unit time with ``degrees=True``).

    Raises
    ------
    GimbalLockError
        Where the middle angle is within ``tol`` of the lock (see
        :func:`euler_rate_matrix_inverse`; skipped under tracing, deferred on
        Dask, off with ``rk.set_validation(False)``).

    Examples
    --------
    >>> import numpy as np
    >>> angles = [0.1, 0.7, 0.3]
    >>> w = angular_velocity_from_euler_rates("zxz", angles, [1.0, 2.0, 3.0], frame="body")
    >>> np.round(euler_rates("zxz", angles, w, frame="body"), 12)
    array([1., 2., 3.])
    """
    p, a, s, n = _setup(seq, angles, frame, degrees, "euler_rates")
    w = vector(omega, (3,), "angular velocity")
    if n < 3:
        return _k.euler_rates_projected(*p, a, w)[..., :n]
    rates, dist = _k.euler_rates_from_omega(*p, a, w)
    check_lock(dist, _tol(tol, a), s, "euler_rates")
    return rates


def angular_acceleration_from_euler_rates(
    seq, angles, rates, accelerations, *, frame, degrees=False
):
    """``alpha = E @ d2(angles)/dt2 + (dE/dt) @ rates``, ``dE/dt`` exact.

    Parameters
    ----------
    seq, angles, frame, degrees
        As in :func:`euler_rate_matrix`.
    rates, accelerations : array_like, shape (..., n)
        First and second time derivatives of the angles, in ``seq`` order.

    Returns
    -------
    array, shape (..., 3)
        Angular acceleration in ``frame`` (the derivative of ``omega`` in its own
        frame; ``alpha_world = R alpha_body``).

    See Also
    --------
    euler_accelerations : the inverse.

    Examples
    --------
    >>> angular_acceleration_from_euler_rates("ZYX", [0, 0, 0], [0, 0, 0], [0, 0, 1.0],
    ...                                       frame="world")
    array([1., 0., 0.])
    """
    p, a, _, n = _setup(
        seq, angles, frame, degrees, "angular_acceleration_from_euler_rates"
    )
    r = _padded(rates, n, "Euler rates")
    d = _padded(accelerations, n, "Euler accelerations")
    return _k.alpha_from_euler_accelerations(*p, a, r, d)


def euler_accelerations(seq, angles, rates, alpha, *, frame, degrees=False, tol=None):
    """Second derivatives of the angles, ``E^-1 (alpha - (dE/dt) @ rates)``.

    Parameters
    ----------
    seq, angles, frame, degrees, tol
        As in :func:`euler_rates`.
    rates : array_like, shape (..., n)
        ``d(angles)/dt`` in ``seq`` order.
    alpha : array_like, shape (..., 3)
        Angular acceleration in ``frame``.

    Returns
    -------
    array, shape (..., n)
        ``d2(angles)/dt2`` in ``seq`` order (degrees per unit time squared with
        ``degrees=True``).

    Raises
    ------
    GimbalLockError
        As :func:`euler_rates`.

    Examples
    --------
    >>> import numpy as np
    >>> a, r = [0.1, 0.2, 0.3], [1, 2, 3]
    >>> al = angular_acceleration_from_euler_rates("XYZ", a, r, [4, 5, 6], frame="body")
    >>> np.round(euler_accelerations("XYZ", a, r, al, frame="body"), 12)
    array([4., 5., 6.])
    """
    p, a, s, n = _setup(seq, angles, frame, degrees, "euler_accelerations")
    r = _padded(rates, n, "Euler rates")
    al = vector(alpha, (3,), "angular acceleration")
    if n < 3:  # E^+ (alpha - E' rates), E^+ = E^T / scale^2 (module docstring)
        zero = namespace_of(r).zeros_like(r)
        rest = al - _k.alpha_from_euler_accelerations(*p, a, r, zero)
        return _k.euler_rates_projected(*p, a, rest)[..., :n]
    acc, dist = _k.euler_accelerations_from_alpha(*p, a, r, al)
    check_lock(dist, _tol(tol, a), s, "euler_accelerations")
    return acc
