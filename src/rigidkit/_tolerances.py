"""The default tolerances of rigidkit: one table per dtype.

Machine epsilon and every threshold derived from it or chosen for a check, each
defined once (:class:`Tolerances`, read with :func:`tolerances`).
:func:`default_atol` (membership of SO(n), SE(n), Sim(3), affine bottom rows),
:func:`singular_rtol` (invertibility) and :func:`infinity_rtol` (points at
infinity) read it for the checks of :mod:`rigidkit._validate`; the functional
modules read it for theirs. Kernels receive their tolerances as parameters.
"""

from __future__ import annotations

import math

import numpy as np


class Tolerances:
    """Machine epsilon and the default tolerances of one floating dtype.

    Every default tolerance of rigidkit is an attribute here, defined once per
    dtype; the function that applies it documents why it has that value. A
    read-only record with slots: its fields are read on every call, and a slot is
    read as fast as a tuple index (a ``NamedTuple`` field ~20 ns slower on CPython
    3.11); not a dataclass, whose import would cost ``import rigidkit`` ~20 ms.

    Attributes
    ----------
    eps : float
        Machine epsilon: the spacing of the dtype's numbers just above 1.
    atol : float
        Largest ``max(|R^T R - I|, |det R - 1|)`` of a group member
        (:func:`default_atol`).
    singular_rtol : float
        Hadamard ratio at or below which a matrix is singular (:func:`singular_rtol`).
    infinity_rtol : float
        ``|w| / max |x, y, z, w|`` at or below which a point is at infinity, 64 eps
        (:func:`infinity_rtol`).
    rank_rtol : float
        ``sigma_2 / sigma_1`` at or below which a cross-covariance has rank 1, 64 eps
        (:func:`rigidkit.functional.alignment.rank_rtol`).
    parallel_sine : float
        Sine of the angle of a 6D rotation's two vectors at or below which they
        are parallel, 16 eps (:func:`rigidkit.functional.rot6d.quat_from_rot6d`).
    newton_rtol : float
        Newton step of the rotation spline's solve, relative to the rates, at or
        below which it has converged, 16 eps (:mod:`rigidkit.functional.splines`).
    mean_tol : float
        Norm of the mean log at or below which a Karcher mean has converged
        (radians; length units), :mod:`rigidkit.functional.averaging`.
    axis_orthogonality : float
        Largest ``|n_i . n_i+1|`` of consecutive unit Davenport axes (scipy's
        1e-7), :mod:`rigidkit.functional.davenport`.
    lock : float
        Radians the rotation may move to return the Euler lock convention, 2 eps
        (:func:`rigidkit.euler.lock_tolerance`).
    gimbal_lock : float
        Distance (radians) of the middle Euler angle from the lock below which we
        warn, ``sqrt(eps)`` (:func:`rigidkit.euler.gimbal_lock_threshold`).
    """

    __slots__ = (
        "eps",
        "atol",
        "singular_rtol",
        "infinity_rtol",
        "rank_rtol",
        "parallel_sine",
        "newton_rtol",
        "mean_tol",
        "axis_orthogonality",
        "lock",
        "gimbal_lock",
    )

    def __init__(self, eps: float, *, atol: float, singular_rtol: float, mean_tol: float):
        fields = {
            "eps": eps,
            "atol": atol,
            "singular_rtol": singular_rtol,
            "infinity_rtol": 64.0 * eps,
            "rank_rtol": 64.0 * eps,
            "parallel_sine": 16.0 * eps,
            "newton_rtol": 16.0 * eps,
            "mean_tol": mean_tol,
            "axis_orthogonality": 1e-7,
            "lock": 2.0 * eps,
            "gimbal_lock": math.sqrt(eps),
        }
        for name, value in fields.items():
            object.__setattr__(self, name, value)

    def __setattr__(self, name, value):
        raise AttributeError("a row of the tolerance table is read-only")

    def replace(self, **changes) -> Tolerances:
        """A copy of this row with the given fields changed."""
        new = object.__new__(Tolerances)
        for name in self.__slots__:
            object.__setattr__(new, name, changes.get(name, getattr(self, name)))
        return new

    def __repr__(self) -> str:
        inner = ", ".join(f"{name}={getattr(self, name)!r}" for name in self.__slots__)
        return f"Tolerances({inner})"


FLOAT64 = Tolerances(2.220446049250313e-16, atol=1e-5, singular_rtol=1e-12, mean_tol=1e-12)
# float32 cannot represent a mean log below ~1e-7, hence its Karcher tolerance.
FLOAT32 = Tolerances(1.1920928955078125e-07, atol=1e-4, singular_rtol=1e-5, mean_tol=1e-6)
# Half precision (computed in float32, returned in its own dtype) has its own
# membership tolerance, the rounding of its entries (see default_atol); its other
# fields are float64's.
FLOAT16 = FLOAT64.replace(atol=4e-3)
BFLOAT16 = FLOAT64.replace(atol=3e-2)


def tolerances(dtype) -> Tolerances:
    """The row of the tolerance table for a dtype of any namespace.

    float32 has its own row, float16 and bfloat16 theirs (float64's but for
    ``atol``); every other dtype (float64, integers, ``None`` for Python numbers,
    which are computed in float64) reads float64's. One ``str(dtype)`` at most,
    as :func:`~rigidkit._engine.namespace.is_float32`.

    >>> tolerances(np.float32).eps, tolerances(np.float64).infinity_rtol
    (1.1920928955078125e-07, 1.4210854715202004e-14)
    """
    if dtype is _F64:  # the common cases first, without str(dtype) (~1 us)
        return FLOAT64
    if dtype is _F32 or dtype is np.float32:
        return FLOAT32
    name = str(dtype)  # once (is_float32 and is_half would each call it)
    if "float32" in name:
        return FLOAT32
    if "float16" in name:
        return BFLOAT16 if "bfloat16" in name else FLOAT16
    return FLOAT64


def default_atol(dtype) -> float:
    """Tolerance of group membership: 1e-5 for float64, 1e-4 for float32.

    The largest accepted ``max(|R^T R - I|, |det R - 1|)`` of a rotation (block),
    and deviation of a homogeneous matrix's bottom row from ``[0, ..., 0, 1]``.
    Loose enough for rotation matrices written to 6 decimals, as CAD and
    calibration files have them (measured over 200,000 random rotations: up to
    1.9e-6, and a quarter of them above the former 1e-6), or computed in float32
    (whose rounding alone reaches ~1e-6); such a matrix is then projected onto the
    nearest rotation (see :func:`rigidkit.conversions.quat_from_matrix`). Tight
    enough to refuse a scaling by 1 + 1e-5 (``det - 1 = 3e-5``), and every shear,
    reflection or scaling that is not rounding noise. With 5 decimals (up to
    1.9e-5) pass ``atol=`` or ``orthonormalize=True``. Half precision rounds each
    entry by up to 2^-12 (float16) or 2^-9 (bfloat16), ``|R^T R - I|`` by up to
    about three times that: 4e-3 and 3e-2.

    >>> default_atol(np.float64), default_atol(np.float32), default_atol(np.float16)
    (1e-05, 0.0001, 0.004)
    """
    if dtype is _F64:  # the common case without a call (every matrix check reads it)
        return FLOAT64.atol
    return tolerances(dtype).atol


_F64 = np.dtype(np.float64)
_F32 = np.dtype(np.float32)


def singular_rtol(dtype) -> float:
    """Default Hadamard-ratio threshold below which a matrix counts as singular.

    The ratio ``|det A| / prod |row_i|`` is about ``1 / cond`` of ``A`` with
    normalised rows (see :mod:`rigidkit.kernels.homogeneous`); below 1e-12
    (float64) or 1e-5 (float32) an inverse keeps fewer than about 4 (resp. 2)
    correct digits, so we refuse it.
    """
    return tolerances(dtype).singular_rtol


def infinity_rtol(dtype) -> float:
    """Default threshold of ``|w| / max|x, y, z, w|`` below which a point is at infinity.

    64 eps of the dtype: ``w`` is then within a few dozen roundings of zero, so
    its sign, and the side of infinity the point lies on, are noise.
    """
    return tolerances(dtype).infinity_rtol
