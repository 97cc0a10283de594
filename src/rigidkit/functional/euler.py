"""Euler angles in all 24 sequences (functional layer: arrays in, arrays out).

Conventions: a sequence is three letters of ``xyz``; UPPERCASE = intrinsic (about
the body axes, each turn about the axes moved by the turns before), lowercase =
extrinsic (about the fixed world axes), as in scipy. "Right-multiply body,
left-multiply world":

* intrinsic ``"XYZ"`` with angles ``(a, b, c)`` is ``Rx(a) @ Ry(b) @ Rz(c)``;
* extrinsic ``"xyz"`` with angles ``(a, b, c)`` is ``Rz(c) @ Ry(b) @ Rx(a)``,

so intrinsic ``"XYZ"`` equals extrinsic ``"zyx"`` with the angles reversed.
Proper Euler sequences repeat the first axis last (``"ZXZ"``), Tait-Bryan
sequences use three different axes (``"ZYX"``, yaw-pitch-roll). Rotations are
active and act on column vectors, ``v_A = A_R_B @ v_B``; quaternions are Hamilton,
scalar first ``(w, x, y, z)``. Angles are radians unless ``degrees=True``.

Gimbal lock: when the middle angle is at its lock (0 or pi for proper sequences,
+-pi/2 for Tait-Bryan ones) only the sum or difference of the first and third
angle is determined. We then return the third angle 0 and the whole turn in the
first, also when the quaternion is only numerically at the lock (a float
quaternion of angles ``(a, pi/2, b)`` sits a rounding error away from it), as long
as that moves the rotation by at most :func:`lock_tolerance` (2 eps, 4.4e-16 rad
for float64). Otherwise the angles are the exact split, however close to the lock.

>>> import numpy as np
>>> q = quat_from_euler("ZYX", [90.0, 0.0, 0.0], degrees=True)
>>> np.round(q, 12) + 0.0
array([0.70710678, 0.        , 0.        , 0.70710678])
>>> np.round(euler_from_quat("ZYX", q, degrees=True), 12) + 0.0
array([90.,  0.,  0.])

At the lock, yaw 30, pitch 90, roll 10 is the same rotation as yaw 20, pitch 90:

>>> import warnings
>>> q = quat_from_euler("ZYX", [30.0, 90.0, 10.0], degrees=True)
>>> with warnings.catch_warnings():
...     warnings.simplefilter("ignore")
...     euler_from_quat("ZYX", q, degrees=True)
array([20., 90.,  0.])
"""

from __future__ import annotations

import math

import numpy as np

from .._engine.namespace import is_float32, is_numpy, namespace_of
from .._validate import as_array, finite_array
from ..kernels import euler as _k
from . import conversions as _conv
from ._euler_sequence import EulerSequence, parse_sequence, parse_short_sequence
from ._gimbal_lock import (
    gimbal_lock_threshold,
    lock_band,
    lock_free,
    lock_tolerance,
    warn_if_locked,
)

__all__ = [
    "EulerSequence",
    "parse_sequence",
    "quat_from_euler",
    "euler_from_quat",
    "euler_from_quat_unchecked",
    "matrix_from_euler",
    "euler_from_matrix",
    "gimbal_lock_threshold",
    "lock_tolerance",
]


def _dtype(a):
    return getattr(a, "dtype", None)  # None (lists, floats): computed in float64


def quat_from_euler(seq, angles, *, degrees=False):
    """Unit quaternions of Euler angles, for any of the 24 sequences.

    Conventions: UPPERCASE ``seq`` = intrinsic (body axes), lowercase = extrinsic
    (world axes); intrinsic ``"XYZ"`` is ``Rx(a) @ Ry(b) @ Rz(c)``, extrinsic
    ``"xyz"`` is ``Rz(c) @ Ry(b) @ Rx(a)``. Quaternions are Hamilton, scalar first.

    The quaternion is the product of the three axis quaternions
    ``(cos(t/2), sin(t/2) e_axis)``, in closed form (no matrices).

    Parameters
    ----------
    seq : str
        Three letters of ``xyz`` (see :func:`parse_sequence`), or, as in scipy,
        one or two (``"z"``, ``"zy"``, ``"XY"``: turns about those axes only, see
        :func:`parse_short_sequence`).
    angles : array_like, shape (..., n)
        Angles in the order of ``seq``, ``n = len(seq)``; radians, or degrees with
        ``degrees=True``. With one letter a scalar angle is accepted (shape ()).
    degrees : bool

    Returns
    -------
    quat : array, shape (..., 4)
        ``(w, x, y, z)``, of the namespace and floating dtype of ``angles``.

    Raises
    ------
    EulerSequenceError, ShapeError, NonFiniteError

    See Also
    --------
    euler_from_quat : the inverse (three-letter sequences only, as in scipy).

    Examples
    --------
    >>> import numpy as np
    >>> q = quat_from_euler("XYZ", [np.pi / 2, 0.0, 0.0])
    >>> np.round(q, 12) + 0.0
    array([0.70710678, 0.70710678, 0.        , 0.        ])
    >>> np.round(quat_from_euler("z", np.pi / 2), 12) + 0.0      # one axis
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    try:  # one lookup for a sequence seen before (~0.3 us of parsing and f-string)
        s, n, what = _FROM_EULER[seq]
    except (KeyError, TypeError):
        if isinstance(seq, str) and len(seq) == 3:
            s, n = parse_sequence(seq), 3
        else:
            s, n = parse_short_sequence(seq)
        what = f"Euler angles for {seq!r}"
        _FROM_EULER[seq] = (s, n, what)
    if n == 3:
        a = finite_array(angles, (3,), what)
    else:
        a = as_array(angles, (), what)
        if n == 1 and a.ndim == 0:
            a = a[None]
        a = finite_array(a, (n,), what)
        zero = namespace_of(a).zeros_like(a[..., :1])
        a = _concat(a, [zero] * (3 - n))
    scale = math.pi / 180.0 if degrees else 1.0
    return _k.quat_from_euler(*s.params, scale, a)


_FROM_EULER: dict = {}


def _concat(a, extra):
    """``a`` with the arrays ``extra`` appended along its last axis (any namespace)."""
    if isinstance(a, np.ndarray) or is_numpy(namespace_of(a)):
        return np.concatenate([a, *extra], axis=-1)
    return namespace_of(a).concat([a, *extra], axis=-1)


def euler_from_quat(seq, quat, *, degrees=False, warn=True):
    """Euler angles of unit quaternions, for any of the 24 sequences.

    Conventions: UPPERCASE ``seq`` = intrinsic (body axes), lowercase = extrinsic
    (world axes); quaternions are Hamilton, scalar first ``(w, x, y, z)``.

    Every angle is an ``atan2`` of quantities free of cancellation (Bernardes &
    Viollet 2022), so the angles are accurate to a few ulp and rebuild the
    rotation to about 1e-16 rad everywhere, at and near gimbal lock too.

    At gimbal lock the third angle is 0 and the whole turn about the first axis
    is in the first angle (intrinsic ``"ZYX"`` at pitch +90 degrees: yaw - roll;
    extrinsic ``"zyx"``: yaw + roll; at -90 the signs flip). This holds not only
    at exact lock but whenever returning it moves the rotation by at most
    :func:`lock_tolerance` of the dtype of ``quat`` (2 eps: 4.4e-16 rad for
    float64, 2.4e-7 for float32), e.g. for quaternions computed from angles
    ``(a, 90, b)`` degrees; the middle angle is then that of the nearest such
    rotation. Farther from the lock (1e-12 rad, say) the angles are the exact
    split of ``quat``, accurate, but only their sum or difference is well
    conditioned.

    Parameters
    ----------
    seq : str
        Three letters of ``xyz`` (see :func:`parse_sequence`).
    quat : array_like, shape (..., 4)
        Quaternions of any finite nonzero scale (each names the rotation of
        ``q / |q|``; the angles are computed from ``q`` itself, exactly, see
        ``_checked_quat``). For quaternions known to be unit (a
        :class:`~rigidkit.Rotation`'s) :func:`euler_from_quat_unchecked` skips the
        checks.
    degrees : bool
    warn : bool
        ``False`` skips the gimbal-lock check and its warning (the angles are the
        same). Unlike ``warnings.catch_warnings()``, which swaps the process-wide
        warning state and so may hide or let escape the warnings of other threads,
        this leaves every warning filter alone.

    Returns
    -------
    angles : array, shape (..., 3)
        In the order of ``seq``. First and third angle in (-pi, pi]; the middle in
        [0, pi] for proper sequences, [-pi/2, pi/2] for Tait-Bryan ones (degrees:
        (-180, 180], [0, 180], [-90, 90]).

    Raises
    ------
    EulerSequenceError, ShapeError
    NonFiniteError, ZeroNormError
        For a quaternion with NaN or infinite components, or a zero one, naming
        its batch index (skipped where values cannot be read, e.g. under
        ``jax.jit``, where NaN propagates).

    Warns
    -----
    GimbalLockWarning
        Unless ``warn=False``: once per call, when any middle angle is within
        :func:`gimbal_lock_threshold` (1.5e-8 rad for float64) of the lock (0 or pi
        for proper sequences, +-pi/2 for Tait-Bryan ones). There only the sum or
        difference of the first and third angle is well determined; the angles
        returned still rebuild the rotation, and at lock (within
        :func:`lock_tolerance`) the third is 0.

    See Also
    --------
    quat_from_euler : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> q = quat_from_euler("zxz", [0.1, 0.2, 0.3])
    >>> np.round(euler_from_quat("zxz", q), 12) + 0.0
    array([0.1, 0.2, 0.3])

    At gimbal lock (here a quarter turn about y, pitch +90 degrees in ``"ZYX"``):

    >>> import warnings
    >>> q_lock = np.array([np.sqrt(0.5), 0.0, np.sqrt(0.5), 0.0])
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     angles = euler_from_quat("ZYX", q_lock, degrees=True)
    >>> caught[0].category.__name__, angles + 0.0
    ('GimbalLockWarning', array([ 0., 90.,  0.]))
    """
    try:  # a known (seq, degrees, dtype): the sequence is valid
        e = _CALLS[seq, degrees, quat.dtype]
    except (KeyError, TypeError, AttributeError):
        s = parse_sequence(seq)  # the sequence first: its error is the likelier one
        if type(quat) is not np.ndarray:
            return _euler_from_quat_validated(s, quat, degrees, warn)
        e = _call_record(seq, degrees, quat.dtype)
    s = e.sequence
    dt = quat.dtype
    if type(quat) is not np.ndarray or not (dt is _F64 or dt is _F32):
        return _euler_from_quat_validated(s, quat, degrees, warn)
    if quat.shape[-1:] != (4,):  # the general path raises the ShapeError
        return _euler_from_quat_validated(s, quat, degrees, warn)
    # Validated in the kernel's own pass (see kernels.euler.euler_from_quat_checked):
    # a row that is not finite, zero or of extreme scale has a middle angle of
    # 8 rad, which the lock scan below sends on to the full check.
    angles = _k.euler_from_quat_checked(*e.checked_params, quat)
    if lock_free(angles, e.band):
        return angles
    if bool((angles[..., 1] > 4.0 * e.scale).any()):
        return _euler_from_quat_validated(s, quat, degrees, warn)
    if warn:
        warn_if_locked(s, angles, e.scale)
    return angles


def _euler_from_quat_validated(s: EulerSequence, quat, degrees, warn=True):
    """The general path of :func:`euler_from_quat`: validate first (any namespace)."""
    return euler_from_quat_unchecked(
        s.text, _checked_quat(quat), degrees=degrees, warn=warn
    )


_F64 = np.dtype(np.float64)
_F32 = np.dtype(np.float32)


def _moderate_limit(dtype) -> float:
    """``lim``: quaternions with ``|q|^2`` in ``[1 / lim, lim]`` go to the kernel as
    they are (its lock test multiplies four components: ``lim^2`` must fit)."""
    return 1e16 if is_float32(dtype) else 1e140


def _checked_quat(quat):
    """``quat`` validated (finite, nonzero), itself where its scale is moderate.

    The kernel is homogeneous of degree 0, so the angles returned are those of the
    quaternion given, to the last bit near the lock too, where normalising first
    (one rounding of each component) would move the first and third angle by
    ``eps / distance`` (6e-9 rad at 1e-9 from the lock). Its lock test multiplies
    four components, though, so a quaternion whose norm may be outside
    ``[1e-70, 1e70]`` (float32: ``[1e-8, 1e8]``) is replaced by its unit one.
    """
    q = as_array(quat, (4,), "quaternion")
    unit = _conv.quat_normalize(q)  # raises for NaN, inf or zero, naming the index
    if isinstance(q, np.ndarray) and q.dtype.kind != "f":
        return unit
    xp = namespace_of(q)
    qmax = math.sqrt(_moderate_limit(q.dtype))
    # |q| in [m, 2 m] for the largest component m (|q|^2 itself would overflow).
    m = xp.max(xp.abs(q), axis=-1)
    moderate = (m <= 0.5 * qmax) & (m >= 1.0 / qmax)
    if isinstance(moderate, np.ndarray) and moderate.all():
        return q
    return xp.where(moderate[..., None], q, unit)


def euler_from_quat_unchecked(seq, quat, *, degrees=False, warn=True):
    """:func:`euler_from_quat` for unit quaternions, without normalising or checks.

    The quaternions are taken as they are (the object layer's, unit by
    construction): NaN gives NaN angles, never an error; the kernel is homogeneous
    of degree 0, so a moderately scaled ``q`` gives its rotation's angles and a
    zero one zero angles. Same conventions, ranges and gimbal-lock warning
    (``warn=False`` skips it, leaving every warning filter alone).

    >>> import numpy as np
    >>> q = np.array([np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5)])  # a quarter turn about z
    >>> np.round(euler_from_quat_unchecked("ZYX", q), 12) + 0.0
    array([1.57079633, 0.        , 0.        ])
    """
    try:  # the common case in one lookup: ~0.3 us less on a small batch
        e = _CALLS[seq, degrees, quat.dtype]
    except (KeyError, TypeError, AttributeError):
        e = _call_record(seq, degrees, _dtype(quat))
    angles = _k.euler_from_quat(*e.params, quat)
    if not warn or (type(angles) is np.ndarray and lock_free(angles, e.band)):
        return angles
    warn_if_locked(e.sequence, angles, e.scale)
    return angles


class EulerCall:
    """The constants of one call, memoised per ``(seq, degrees, dtype)``: the parsed
    ``sequence``; ``params`` of the kernel ``euler_from_quat`` (the sequence's,
    ``scale`` and the :func:`lock_tolerance` of the dtype); ``checked_params`` of
    ``euler_from_quat_checked`` (``params`` and the largest accepted ``|q|``, see
    :func:`_moderate_limit`); ``scale``, output units per radian; and the ``band``
    of middle angles far from the lock (see :func:`lock_free`). Slots, read as fast
    as a tuple (see :class:`~rigidkit.functional._gimbal_lock.LockBand`)."""

    __slots__ = ("sequence", "params", "checked_params", "scale", "band")

    def __init__(self, sequence, params, checked_params, scale, band):
        self.sequence, self.params, self.checked_params = sequence, params, checked_params
        self.scale, self.band = scale, band

    def __repr__(self) -> str:
        return f"EulerCall({self.sequence.text!r}, {self.scale!r}, {self.band!r})"


_CALLS: dict = {}


def _call_record(seq, degrees, dtype) -> EulerCall:
    """The :class:`EulerCall` of ``(seq, degrees, dtype)``, memoised per hashable
    dtype."""
    s = parse_sequence(seq)
    scale = 180.0 / math.pi if degrees else 1.0
    params = (*s.params, scale, lock_tolerance(dtype))
    checked = (*params, math.sqrt(_moderate_limit(dtype)))
    record = EulerCall(s, params, checked, scale, lock_band(s.proper, scale, dtype))
    try:
        _CALLS[seq, bool(degrees), dtype] = record
    except TypeError:  # an unhashable dtype object
        pass
    return record


def matrix_from_euler(seq, angles, *, degrees=False):
    """Rotation matrices of Euler angles, shape (..., 3, 3).

    Conventions: UPPERCASE ``seq`` = intrinsic, lowercase = extrinsic; intrinsic
    ``"XYZ"`` is ``Rx(a) @ Ry(b) @ Rz(c)``. Active matrices on column vectors.

    See Also
    --------
    euler_from_matrix : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> np.round(matrix_from_euler("zyx", [90.0, 0.0, 0.0], degrees=True), 12) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    return _conv.matrix_from_quat_unchecked(quat_from_euler(seq, angles, degrees=degrees))


def euler_from_matrix(seq, matrix, *, degrees=False, atol=None, warn=True):
    """Euler angles of rotation matrices (validated, see ``quat_from_matrix``).

    Conventions: UPPERCASE ``seq`` = intrinsic, lowercase = extrinsic. Ranges and
    the gimbal-lock warning (``warn=False`` skips it) as in :func:`euler_from_quat`.

    See Also
    --------
    matrix_from_euler : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> Rz = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    >>> np.round(euler_from_matrix("XYZ", Rz, degrees=True), 12) + 0.0
    array([ 0.,  0., 90.])
    """
    q = _conv.quat_from_matrix(matrix, atol=atol)  # validated, unit
    return euler_from_quat_unchecked(seq, q, degrees=degrees, warn=warn)
