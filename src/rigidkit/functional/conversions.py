"""Functional conversions between rotation representations (arrays in, arrays out).

Names read right to left, ``target_from_source``. Quaternions are Hamilton,
scalar first ``(w, x, y, z)``; matrices are active and act on column vectors
(``v_A = A_R_B @ v_B``). Every function is batched over leading axes, keeps the
array namespace and dtype of its input, and validates what a user could get wrong,
as the classes do: a quaternion is normalised first (any finite nonzero scale names
a rotation, as in :meth:`rigidkit.Rotation.from_quat`), and a zero or non-finite
one raises :class:`~rigidkit.ZeroNormError` or :class:`~rigidkit.NonFiniteError`
naming its batch index.

``quat_canonical`` takes any quaternion as it is (no normalisation). The product
and the conjugate of the algebra are :func:`rigidkit.quaternion.multiply` and
:func:`rigidkit.quaternion.conjugate` (the conjugate of a unit quaternion is the
inverse rotation); ``quat_compose`` is the product as the composition of rotations
(``q2`` first), renormalised so that long chains of compositions stay unit to a
few ulp (``Rotation @`` uses it).

Unchecked variants: ``matrix_from_quat_unchecked``, ``rotvec_from_quat_unchecked``,
``mrp_from_quat_unchecked``, ``axis_angle_from_quat_unchecked``,
``quat_apply_unchecked`` and ``quat_angle_between_unchecked`` are the kernels
themselves, for quaternions already known to be unit (the object layer's, unit by
construction). They neither normalise nor check anything: a non-unit quaternion
gives a wrong result and a NaN one NaN, never an error.

>>> import numpy as np
>>> q = quat_from_rotvec(np.array([0.0, 0.0, np.pi / 2]))
>>> np.round(matrix_from_quat(q), 12) + 0.0
array([[ 0., -1.,  0.],
       [ 1.,  0.,  0.],
       [ 0.,  0.,  1.]])
>>> matrix_from_quat([2.0, 0.0, 0.0, 0.0])       # normalised first: the identity
array([[1., 0., 0.],
       [0., 1., 0.],
       [0., 0., 1.]])
"""

from __future__ import annotations

import math

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import namespace_of
from .._validate import (
    _relabel,
    all_true,
    as_array,
    check_finite,
    check_rotation,
    default_atol,
    finite_array,
    raise_unless,
    raise_where,
)
from ..errors import ZeroNormError
from ..kernels import axis_angle as _aa
from ..kernels import matrix as _mat
from ..kernels import mrp as _mrp
from ..kernels import quaternion as _q
from ..kernels import so3 as _rv

__all__ = [
    "quat_normalize",
    "quat_canonical",
    "quat_compose",
    "quat_apply",
    "quat_angle_between",
    "matrix_from_quat",
    "quat_from_matrix",
    "quat_from_rotvec",
    "rotvec_from_quat",
    "quat_from_mrp",
    "mrp_from_quat",
    "quat_from_axis_angle",
    "axis_angle_from_quat",
    "quat_wxyz_from_xyzw",
    "quat_xyzw_from_wxyz",
    "nearest_rotation_matrix",
    "default_atol",
]

quat_compose = _q.quat_compose  # the product as composition of rotations: renormalised
quat_canonical = _q.quat_canonical

# The unchecked variants (module docs): the kernels, for quaternions known to be unit.
matrix_from_quat_unchecked = _mat.matrix_from_quat
rotvec_from_quat_unchecked = _rv.rotvec_from_quat
mrp_from_quat_unchecked = _mrp.mrp_from_quat
axis_angle_from_quat_unchecked = _aa.axis_angle_from_quat
quat_apply_unchecked = _q.quat_apply
quat_angle_between_unchecked = _q.quat_angle_between


def quat_normalize(q, *, what="quaternion"):
    """Unit quaternion ``q / |q|``, for any finite nonzero ``q`` (no overflow).

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Raises
    ------
    NonFiniteError, ZeroNormError
        For NaN/inf components or a zero quaternion, naming the batch index.
    """
    q = as_array(q, (4,), what)
    # One element runs on Python floats, and other namespaces never warn: no errstate
    # (which torch.compile cannot trace either).
    if type(q) is not np.ndarray or q.ndim == 1:
        unit, norm = _q.quat_normalize(q)
    else:
        with _quiet():
            unit, norm = _q.quat_normalize(q)
    # One test on the kernel's norm output catches zero, NaN and inf inputs alike
    # (NaN fails every comparison), so valid input costs no separate pass.
    ok = (norm > 0.0) & (norm < math.inf)
    if not all_true(ok):
        check_finite(q, (4,), what)
        # Finite input: an infinite norm is |q| above the largest float (the unit
        # quaternion, scaled by the largest component, is right); only zero fails.
        raise_unless(
            norm > 0.0,
            ZeroNormError,
            f"{what} has zero norm {{where}}; it names no rotation",
        )
    return unit


def _quiet():
    """Silence NumPy's NaN/inf warnings around a kernel whose outputs are checked.

    Invalid input (NaN, inf, zero) is detected from a kernel's outputs, after it
    ran; the element-wise NumPy path would first warn about the NaN it computes.
    """
    return np.errstate(invalid="ignore", divide="ignore", over="ignore")


def matrix_from_quat(quat, *, out=None):
    """Rotation matrices of quaternions, normalised first: (..., 4) -> (..., 3, 3).

    ``R = I + 2 w hat(v) + 2 hat(v)^2`` for the unit ``(w, v) = q / |q|``.
    ``out``: a NumPy buffer of shape (..., 3, 3) for the result.

    See Also
    --------
    quat_from_matrix : the inverse; matrix_from_quat_unchecked for unit input.
    """
    return _mat.matrix_from_quat(quat_normalize(quat), out=out)


def rotvec_from_quat(quat):
    """Rotation vectors ``angle * axis``, angle in [0, pi], of quaternions (..., 4).

    Normalised first; ``q`` and ``-q`` give the same vector. See Also:
    :func:`quat_from_rotvec` (the inverse).
    """
    return _rv.rotvec_from_quat(quat_normalize(quat))


def mrp_from_quat(quat):
    """Modified Rodrigues parameters ``axis * tan(angle / 4)`` (norm <= 1), (..., 3).

    Of quaternions (..., 4), normalised first; the shadow set is never returned.
    See Also: :func:`quat_from_mrp` (the inverse).
    """
    return _mrp.mrp_from_quat(quat_normalize(quat))


def axis_angle_from_quat(quat):
    """``(axis, angle)``: unit axes (..., 3) and angles (...) in [0, pi] of quaternions.

    Normalised first; the identity has axis ``+x`` and angle 0. See Also:
    :func:`quat_from_axis_angle` (the inverse).
    """
    return _aa.axis_angle_from_quat(quat_normalize(quat))


def quat_apply(quat, vectors, *, out=None):
    """Rotate vectors (..., 3) by quaternions (..., 4), normalised first; shapes broadcast.

    ``v -> q v q*`` for the unit ``q / |q|`` (active rotation, Hamilton).

    >>> np.round(quat_apply([1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), 12) + 0.0
    array([0., 1., 0.])
    """
    v = as_array(vectors, (3,), "vectors")
    return _q.quat_apply(quat_normalize(quat), v, out=out)


def quat_angle_between(quat1, quat2):
    """Angle (radians, [0, pi]) of the rotation between quaternions, shape (...).

    Both are normalised first; ``q`` and ``-q`` are the same rotation (angle 0).
    """
    return _q.quat_angle_between(quat_normalize(quat1), quat_normalize(quat2))


def quat_wxyz_from_xyzw(q):
    """Reorder scalar-last ``(x, y, z, w)`` to scalar-first ``(w, x, y, z)``, (..., 4).

    Only the order changes (no normalisation): any quaternion, scipy's or ROS's.
    """
    q = as_array(q, (4,), "quaternion (x, y, z, w)")
    return namespace_of(q).concat([q[..., 3:], q[..., :3]], axis=-1)


def quat_xyzw_from_wxyz(q):
    """Reorder scalar-first ``(w, x, y, z)`` to scalar-last ``(x, y, z, w)``, (..., 4)."""
    q = as_array(q, (4,), "quaternion (w, x, y, z)")
    return namespace_of(q).concat([q[..., 1:], q[..., :1]], axis=-1)


def quat_from_matrix(matrix, *, atol=None, orthonormalize=False):
    """Unit quaternion of a rotation matrix, validated.

    Parameters
    ----------
    matrix : array_like, shape (..., 3, 3)
        Active rotation matrices acting on column vectors.
    atol : float, optional
        Largest accepted distance from SO(3), ``max(|R^T R - I|, |det R - 1|)``
        (largest entry); default :func:`default_atol`: 1e-5 (float64), 1e-4
        (float32). A matrix within it is taken as the nearest rotation (its
        orthogonal polar factor, to ``3/8 atol^2``): matrices written to 6
        decimals (as in CAD and calibration files; up to 2e-6 off) pass, a
        scaling by 1 + 1e-5, a shear or a reflection does not.
    orthonormalize : bool
        Instead of raising, replace each matrix by the nearest rotation (SVD),
        however far it is.

    Raises
    ------
    NonFiniteError
        NaN or inf anywhere (checked before any SVD).
    NotARotationError
        A matrix is not a rotation within ``atol`` (a reflection, a scaling, a
        shear); the message names the first such batch index and why.
    """
    m = as_array(matrix, (3, 3), "rotation matrix")
    if orthonormalize:
        check_finite(m, (3, 3), "rotation matrix")  # before the SVD, which hangs on inf
        m = nearest_rotation_matrix(m)
    if type(m) is not np.ndarray or m.ndim == 2:  # no warnings to silence (see above)
        q, err = _mat.quat_from_matrix(m)
    else:
        with _quiet():
            q, err = _mat.quat_from_matrix(m)
    check_rotation(m, err, atol)
    return q


def nearest_rotation_matrix(matrix):
    """The rotation closest in Frobenius norm: ``U diag(1, 1, det(U V^T)) V^T``.

    ``matrix`` (..., 3, 3) must be finite (checked before the SVD, which can hang
    on infinities); a rank-deficient matrix gets one of its nearest rotations.
    """
    m = as_array(matrix, (3, 3), "matrix")
    if dask_backend.is_dask(m):  # Dask's SVD takes one 2D matrix: one per element,
        return dask_backend.map_batched(  # each chunk checked finite before its SVD
            _nearest_rotation_numpy, [m], [2], _relabel, outputs=[((3, 3), m.dtype)]
        )
    check_finite(m, (3, 3), "matrix")
    return _nearest_rotation(m)


def _nearest_rotation_numpy(m):
    check_finite(m, (3, 3), "matrix")
    return _nearest_rotation(m)


def _nearest_rotation(m):
    xp = namespace_of(m)
    u, _, vt = xp.linalg.svd(m)
    d = xp.linalg.det(u @ vt)
    ones = xp.ones_like(d)
    fix = xp.stack([ones, ones, d], axis=-1)
    return (u * fix[..., None, :]) @ vt


def quat_from_rotvec(rotvec):
    """Unit quaternion of a rotation vector ``theta * axis`` (radians)."""
    r = finite_array(rotvec, (3,), "rotation vector")
    return _rv.quat_from_rotvec(r)


def quat_from_mrp(mrp):
    """Unit quaternion of modified Rodrigues parameters ``axis * tan(theta/4)``."""
    p = finite_array(mrp, (3,), "MRP")
    return _mrp.quat_from_mrp(p)


def quat_from_axis_angle(axis, angle):
    """Unit quaternion of a rotation by ``angle`` (radians) about ``axis``.

    ``axis`` (shape (..., 3)) need not be unit but must be nonzero; ``angle`` has
    shape (...); the two broadcast.
    """
    a = as_array(axis, (3,), "axis")
    t = as_array(angle, (), "angle")
    check_finite(a, (3,), "axis")
    check_finite(t, (), "angle")
    zero = namespace_of(a).all(a == 0, axis=-1)
    raise_where(zero, ZeroNormError, "axis is the zero vector {where}")
    return _aa.quat_from_axis_angle(a, t)
