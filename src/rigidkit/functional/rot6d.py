"""The continuous 6D rotation representation (Zhou et al. 2019), arrays in and out.

Layout, shape (..., 6): the first two COLUMNS of the rotation matrix, ``(R00,
R10, R20, R01, R11, R21)`` (matrices active, on column vectors, ``v_A = A_R_B @
v_B``), as in the paper (its ``g_GS`` maps two columns to ``[b1 b2 b3]`` by
Gram-Schmidt). pytorch3d's ``matrix_to_rotation_6d`` takes the first two ROWS
instead, i.e. our 6D of the inverse rotation (``R^T``): convert with
``rot6d_from_quat(rk.quaternion.conjugate(q))``. Quaternions Hamilton, scalar first.

Any 6 numbers whose two 3-vectors are not parallel (nor zero) name a rotation,
which makes the representation continuous where quaternions and Euler angles are
not, and suited to a network's output.

>>> import numpy as np
>>> six = np.array([2.0, 0.0, 0.0, 1.0, 3.0, 0.0])  # x-axis, then a vector in the xy-plane
>>> np.round(quat_from_rot6d(six), 12) + 0.0        # the identity
array([1., 0., 0., 0.])
"""

from __future__ import annotations

from .._validate import finite_array, raise_where, tolerances
from ..errors import DegenerateInputError
from ..kernels import rot6d as _k
from .conversions import quat_normalize

__all__ = ["rot6d_from_quat", "quat_from_rot6d", "quat_from_rot6d_unchecked"]


def rot6d_from_quat(quat):
    """The 6D representation ``(R00, R10, R20, R01, R11, R21)`` of quaternions.

    Parameters
    ----------
    quat : array_like, shape (..., 4)
        Normalised first (validated: NaN/inf/zero raise with the batch index).

    Returns
    -------
    array, shape (..., 6)
        The first two columns of the rotation matrix, column after column.

    See Also
    --------
    quat_from_rot6d : the inverse (Gram-Schmidt).

    >>> import numpy as np
    >>> np.round(rot6d_from_quat([np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5)]), 12) + 0.0
    array([ 0.,  1.,  0., -1.,  0.,  0.])
    """
    return _k.rot6d_from_quat(quat_normalize(quat))


def quat_from_rot6d(rot6d):
    """Unit quaternions of 6D representations, by Gram-Schmidt (validated).

    ``b1 = a1 / |a1|``, ``b2`` the normalised part of ``a2`` orthogonal to
    ``b1``, ``b3 = b1 x b2``, ``R = [b1 b2 b3]`` (columns), for ``(a1, a2) =
    rot6d[..., :3], rot6d[..., 3:]``. Scales of ``a1`` and ``a2`` do not matter.

    Parameters
    ----------
    rot6d : array_like, shape (..., 6)

    Returns
    -------
    quat : array, shape (..., 4)

    Raises
    ------
    NonFiniteError
    DegenerateInputError
        Where ``a1`` or ``a2`` is zero or the two are parallel to rounding (the
        sine of their angle at most 16 eps: 3.6e-15 in float64), so that ``b2``
        is undetermined; naming the batch index. Skipped under tracing.

    See Also
    --------
    rot6d_from_quat : the inverse; quat_from_rot6d_unchecked skips the checks.
    """
    x = finite_array(rot6d, (6,), "6D rotation")
    q, sine = _k.quat_from_rot6d(x)
    raise_where(
        sine <= tolerances(x.dtype).parallel_sine,
        DegenerateInputError,
        "6D rotation {where}: its two vectors are zero or parallel (sine of their "
        "angle {value:.3g}), so Gram-Schmidt determines no rotation",
        value=sine,
    )
    return q


def quat_from_rot6d_unchecked(rot6d):
    """:func:`quat_from_rot6d` without checks (for traced or known-good input).

    A degenerate pair gives some rotation (finite), never an error; NaN gives NaN.
    """
    return _k.quat_from_rot6d(rot6d)[0]
