"""The quaternion algebra ``H``: general (not necessarily unit) quaternions.

Components ``(w, x, y, z)`` = ``w + x i + y j + z k``, scalar first; Hamilton
convention ``i^2 = j^2 = k^2 = ijk = -1`` (so ``ij = k``). Rotations use only unit
quaternions (:class:`rigidkit.Rotation`); this module is the whole algebra: sums,
the Hamilton product, conjugate, norm, inverse ``q* / |q|^2``, ``exp`` and ``log``,
and the 4x4 matrices of left and right multiplication.

The functions take and return arrays of shape (..., 4), batched over leading axes
(broadcasting like NumPy), in the array namespace and dtype of their input;
:class:`rigidkit.Quaternion` wraps one such array.

>>> import numpy as np
>>> multiply([0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0])   # ij = k
array([0., 0., 0., 1.])
>>> multiply([0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0])   # ji = -k: not commutative
array([ 0.,  0.,  0., -1.])
>>> multiply([0.0, 1.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0])   # i^2 = -1
array([-1.,  0.,  0.,  0.])

:func:`multiply` is the product kernel itself, ``q1 q2 = (w1 w2 - v1.v2, w1 v2 +
w2 v1 + v1 x v2)`` for shapes (..., 4) broadcasting, and :func:`conjugate` the
conjugate kernel, ``q* = (w, -v)`` with ``(q1 q2)* = q2* q1*`` (for a unit
quaternion, the inverse rotation); both take the kernels' ``out=`` (a NumPy buffer
of the result's shape). They are the one name of each operation in rigidkit.

>>> conjugate([1.0, 2.0, 3.0, 4.0])
array([ 1., -2., -3., -4.])
"""

from __future__ import annotations

from .._validate import as_array, as_float, check_finite, raise_where
from ..errors import ZeroNormError
from ..kernels import quaternion as _kq
from ..kernels import quaternion_algebra as _ka
from . import conversions as _conv

__all__ = [
    "multiply",
    "conjugate",
    "norm",
    "inv",
    "exp",
    "log",
    "left_matrix",
    "right_matrix",
    "rotate",
]


def _quat(q, what="quaternion"):
    """``q`` as a float array of shape (..., 4) of its own namespace."""
    return as_float(as_array(q, (4,), what))


def _reject_zero(result, largest, what):
    """``result``, unless ``largest`` (the largest |component|) is 0 somewhere."""
    raise_where(largest == 0.0, ZeroNormError, f"{what} is the zero quaternion {{where}}")
    return result


# The Hamilton product and the conjugate of any quaternions (module docs): the
# kernels themselves, so that a call costs no Python frame beyond the kernel's fast
# entry and takes ``out=``.
multiply = _kq.quat_multiply
conjugate = _kq.quat_conjugate


def norm(q):
    """Euclidean norm ``|q| = sqrt(w^2 + |v|^2)``, shape (...), without overflow.

    ``|q1 q2| = |q1| |q2|``.
    """
    return _kq.quat_normalize(_quat(q))[1]


def inv(q):
    """Multiplicative inverse ``q^-1 = q* / |q|^2``, shape (..., 4).

    ``q q* = |q|^2``, so ``q q^-1 = q^-1 q = 1``; for a unit quaternion the inverse
    is the conjugate.

    Raises
    ------
    ZeroNormError
        For a zero quaternion, naming its batch index.

    >>> inv([0.0, 2.0, 0.0, 0.0])                 # (2i)^-1 = -i/2
    array([ 0. , -0.5, -0. , -0. ])
    """
    return _reject_zero(*_ka.quat_inverse(_quat(q)), "inverse of a quaternion")


def exp(q):
    """Exponential ``exp(w + v) = e^w (cos|v|, sin(|v|) v / |v|)``, shape (..., 4).

    Defined for every quaternion (the series ``sum q^n / n!``); exact for tiny
    ``|v|`` (``sinc`` series). ``exp(q1 + q2) = exp(q1) exp(q2)`` only when ``q1`` and
    ``q2`` commute. For a pure ``q = (0, theta/2 u)`` it is the unit quaternion
    of the rotation by ``theta`` about ``u``.

    >>> import numpy as np
    >>> np.round(exp([0.0, 0.0, 0.0, np.pi / 2]), 12) + 0.0   # e^(k pi/2) = k
    array([0., 0., 0., 1.])

    See Also
    --------
    log
    """
    q = _quat(q)
    check_finite(q, (4,), "quaternion")
    return _ka.quat_exp(q)


def log(q):
    """Principal logarithm ``(log|q|, theta v / |v|)``, ``theta = atan2(|v|, w)``.

    ``theta`` is in [0, pi], so ``exp(log(q)) = q`` for every nonzero ``q`` and
    ``log(exp(p)) = p`` when ``|vector(p)| < pi``. On the negative real axis
    (``v = 0``, ``w < 0``) the logarithm is not unique (``log|w| + pi u`` for any
    unit ``u``); we return ``(log|w|, pi, 0, 0)``, i.e. ``u = i``.

    Raises
    ------
    ZeroNormError
        For a zero quaternion (log 0 is undefined), naming its batch index.

    >>> import numpy as np
    >>> np.round(log([-1.0, 0.0, 0.0, 0.0]), 12) + 0.0           # log(-1) = i pi
    array([0.        , 3.14159265, 0.        , 0.        ])

    See Also
    --------
    exp
    """
    q = _quat(q)
    check_finite(q, (4,), "quaternion")
    return _reject_zero(*_ka.quat_log(q), "logarithm of a quaternion")


def left_matrix(q):
    """``q+``, shape (..., 4, 4), with ``q p == q+ @ p`` for 4-vectors ``p``.

    ``q+ = [[w, -v^T], [v, w I + hat(v)]]`` (left multiplication by ``q``).
    ``q -> q+`` is an algebra homomorphism: ``(q1 q2)+ = q1+ q2+``.
    """
    return _ka.quat_left_matrix(_quat(q))


def right_matrix(q):
    """``q(+)``, shape (..., 4, 4), with ``p q == q(+) @ p`` for 4-vectors ``p``.

    ``q(+) = [[w, -v^T], [v, w I - hat(v)]]`` (right multiplication by ``q``).
    """
    return _ka.quat_right_matrix(_quat(q))


def rotate(q, points):
    """``q p q^-1`` for 3-vectors ``p`` (as pure quaternions), shape (..., 3).

    Works for any nonzero ``q``: the scale of ``q`` cancels, so this is the
    rotation by ``q / |q|`` (active, Hamilton; :meth:`rigidkit.Rotation.apply`).

    Raises
    ------
    ZeroNormError
        For a zero quaternion.
    """
    unit = _conv.quat_normalize(_quat(q), what="quaternion")
    p = as_array(points, (3,), "points")
    return _kq.quat_apply(unit, p)
