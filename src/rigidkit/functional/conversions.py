"""Functional conversions between rotation representations (arrays in, arrays out).

Names read right to left, ``target_from_source``. Quaternions are Hamilton,
scalar first ``(w, x, y, z)``; matrices are active and act on column vectors
(``v_A = A_R_B @ v_B``). Every function is batched over leading axes, keeps the
array namespace and dtype of its input, and validates what a user could get wrong.

>>> import numpy as np
>>> q = quat_from_rotvec(np.array([0.0, 0.0, np.pi / 2]))
>>> np.round(matrix_from_quat(q), 12) + 0.0
array([[ 0., -1.,  0.],
       [ 1.,  0.,  0.],
       [ 0.,  0.,  1.]])
"""

from __future__ import annotations

import math

import numpy as np

from .._engine.namespace import is_float32, is_numpy, namespace_of
from .._validate import as_array, batch_index, check_finite, finite_array, where_text
from ..errors import NotARotationError, ZeroNormError
from ..kernels import axis_angle as _aa
from ..kernels import matrix as _mat
from ..kernels import mrp as _mrp
from ..kernels import quaternion as _q
from ..kernels import rotvec as _rv

__all__ = [
    "quat_normalize",
    "quat_canonical",
    "quat_multiply",
    "quat_conjugate",
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
]

quat_multiply = _q.quat_multiply
quat_conjugate = _q.quat_conjugate
quat_apply = _q.quat_apply
quat_canonical = _q.quat_canonical
quat_angle_between = _q.quat_angle_between
matrix_from_quat = _mat.matrix_from_quat
rotvec_from_quat = _rv.rotvec_from_quat
mrp_from_quat = _mrp.mrp_from_quat
axis_angle_from_quat = _aa.axis_angle_from_quat


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
    if type(q) is np.ndarray and q.ndim == 1:  # one element: Python floats, no warnings
        unit, norm = _q.quat_normalize(q)
    else:
        with _quiet():
            unit, norm = _q.quat_normalize(q)
    # One test on the kernel's norm output catches zero, NaN and inf inputs alike
    # (NaN fails every comparison), so valid input costs no separate pass.
    ok = (norm > 0.0) & (norm < math.inf)
    if not _all(ok):
        check_finite(q, (4,), what)
        raise ZeroNormError(
            f"{what} has zero norm {where_text(batch_index(~_np(ok)))}; "
            "it names no rotation"
        )
    return unit


def _quiet():
    """Silence NumPy's NaN/inf warnings around a kernel whose outputs are checked.

    Invalid input (NaN, inf, zero) is detected from a kernel's outputs, after it
    ran; the element-wise NumPy path would first warn about the NaN it computes.
    """
    return np.errstate(invalid="ignore", divide="ignore", over="ignore")


def _all(mask) -> bool:
    if getattr(mask, "ndim", 0) == 0:
        return bool(mask)
    return bool(namespace_of(mask).all(mask))


def _np(a):
    return np.asarray(a.detach().cpu().numpy() if hasattr(a, "detach") else a)


def quat_wxyz_from_xyzw(q):
    """Reorder scalar-last ``(x, y, z, w)`` to scalar-first ``(w, x, y, z)``."""
    xp = namespace_of(q)
    q = np.asarray(q) if is_numpy(xp) else q
    return xp.concat([q[..., 3:], q[..., :3]], axis=-1)


def quat_xyzw_from_wxyz(q):
    """Reorder scalar-first ``(w, x, y, z)`` to scalar-last ``(x, y, z, w)``."""
    xp = namespace_of(q)
    q = np.asarray(q) if is_numpy(xp) else q
    return xp.concat([q[..., 1:], q[..., :1]], axis=-1)


def default_atol(dtype) -> float:
    """Tolerance of :func:`quat_from_matrix`: 1e-6 for float64, 1e-4 for float32."""
    return 1e-4 if is_float32(dtype) else 1e-6


def quat_from_matrix(matrix, *, atol=None, orthonormalize=False):
    """Unit quaternion of a rotation matrix, validated.

    Parameters
    ----------
    matrix : array_like, shape (..., 3, 3)
        Active rotation matrices acting on column vectors.
    atol : float, optional
        Largest accepted ``max(|R^T R - I|, |det R - 1|)``; default 1e-6 (float64)
        or 1e-4 (float32).
    orthonormalize : bool
        Instead of raising, replace each matrix by the nearest rotation (SVD).

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
    if type(m) is np.ndarray and m.ndim == 2:
        q, err = _mat.quat_from_matrix(m)
    else:
        with _quiet():
            q, err = _mat.quat_from_matrix(m)
    tol = default_atol(getattr(q, "dtype", None)) if atol is None else atol
    # NaN fails every comparison, so non-finite input is caught here too.
    ok = err <= tol
    if not _all(ok):
        check_finite(m, (3, 3), "rotation matrix")
        idx = batch_index(~_np(ok))
        raise NotARotationError(
            f"matrix {where_text(idx)} is not a rotation: {_why(m, idx)} "
            f"(tolerance {tol:g}; pass orthonormalize=True for the nearest rotation)"
        )
    return q


def _why(m, idx) -> str:
    a = np.asarray(m.detach().cpu().numpy() if hasattr(m, "detach") else m)[idx]
    a = a.astype(np.float64)
    det = float(np.linalg.det(a))
    dev = float(np.abs(a.T @ a - np.eye(3)).max())
    if det < 0:
        return f"det = {det:.6g} < 0 (a reflection)"
    sv = np.linalg.svd(a, compute_uv=False)
    if np.abs(sv - sv.mean()).max() < 1e-3 * max(sv.max(), 1e-300):
        return f"it scales by {sv.mean():.9g} (|R^T R - I| = {dev:.3g})"
    return f"|R^T R - I| = {dev:.3g}, singular values {np.round(sv, 6).tolist()}"


def nearest_rotation_matrix(matrix):
    """The rotation closest in Frobenius norm: ``U diag(1, 1, det(U V^T)) V^T``."""
    xp = namespace_of(matrix)
    m = np.asarray(matrix) if is_numpy(xp) else matrix
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
    xp = namespace_of(a)
    zero = xp.all(a == 0, axis=-1)
    if bool(xp.any(zero)):
        raise ZeroNormError(f"axis is the zero vector {where_text(batch_index(zero))}")
    return _aa.quat_from_axis_angle(a, t)
