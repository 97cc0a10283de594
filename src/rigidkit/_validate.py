"""All input validation of rigidkit: shapes, finiteness, norms, matrices, tolerances.

Each check raises a :class:`~rigidkit.errors.RigidkitError` subclass whose message
says what was wrong and where, and whose ``index`` attribute is the first offending
batch index (``()`` for a single input). The checks are one vectorised pass; the
index is looked up only once something is wrong. The policy is in
``docs/architecture.md``: the functional and object layers validate what a user can
get wrong; functions that deliberately skip it are named ``*_unchecked``.

The default tolerances live here too, one function per kind of check:
:func:`default_atol` (membership of SO(n), SE(n), Sim(3), affine bottom rows),
:func:`singular_rtol` (invertibility) and :func:`infinity_rtol` (points at
infinity).

>>> import numpy as np
>>> try:
...     finite_array(np.array([[0.0, 1.0, 2.0], [np.nan, 0.0, 0.0]]), (3,), "points")
... except ValueError as err:
...     print(err, err.index)
points contains NaN or infinity at batch index (1,) (1,)
"""

from __future__ import annotations

import math

import numpy as np

from ._engine.namespace import is_float32, is_numpy, namespace_of
from .errors import NonFiniteError, NotARotationError, ShapeError, SingularMatrixError

# -- arrays, masks and batch indices ----------------------------------------------------


def to_numpy(a):
    """A NumPy view (or copy) of an array of any namespace, for error messages only."""
    if isinstance(a, np.ndarray):
        return a
    if hasattr(a, "detach"):  # torch: off the graph and the device first
        return a.detach().cpu().numpy()
    return np.asarray(a)


def batch_index(mask_batch) -> tuple:
    """Index of the first True in a boolean batch array (a NumPy view of it)."""
    idx = np.argwhere(np.asarray(to_numpy(mask_batch)))
    return tuple(int(i) for i in idx[0]) if idx.size else ()


def where_text(index: tuple) -> str:
    """``"at batch index (1, 2)"``, or ``"in the (single) input"`` for ``()``."""
    return f"at batch index {index}" if index else "in the (single) input"


def any_true(mask) -> bool:
    """Whether any entry of a boolean array (of any namespace, or a bool) is true."""
    if isinstance(mask, (np.ndarray, np.bool_)):
        return bool(mask.any())
    if getattr(mask, "ndim", 0) == 0:
        return bool(mask)
    return bool(namespace_of(mask).any(mask))


def all_true(mask) -> bool:
    """Whether every entry of a boolean array (of any namespace, or a bool) is true."""
    if isinstance(mask, (np.ndarray, np.bool_)):
        return bool(mask.all())
    if getattr(mask, "ndim", 0) == 0:
        return bool(mask)
    return bool(namespace_of(mask).all(mask))


def raise_where(bad, error, message, *, value=None) -> None:
    """Raise ``error`` at the first True of the batch mask ``bad``; nothing if none.

    The one place an error about a batch element is raised, so every such error
    carries its batch index as ``err.index``. ``message`` is a format string: its
    field ``{where}`` becomes the index in words (``"axis is zero {where}"`` reads
    ``"axis is zero at batch index (1, 2)"``) and ``{value}`` the offending element
    of the array ``value`` (a float, or a list for an element with axes of its
    own). A callable ``message`` receives the index and returns the whole text.
    """
    if not any_true(bad):
        return
    idx = batch_index(bad)
    if callable(message):
        raise error(message(idx), index=idx)
    found = None
    if value is not None:
        found = np.asarray(to_numpy(value))[idx]
        found = found.tolist() if found.ndim else float(found)
    raise error(message.format(where=where_text(idx), value=found), index=idx)


def raise_unless(ok, error, message) -> None:
    """:func:`raise_where` at the first False of ``ok`` (a mask or a bool)."""
    if not all_true(ok):
        raise_where(~np.asarray(to_numpy(ok)), error, message)


# -- shapes and values -------------------------------------------------------------------


def shape_text(trail: tuple) -> str:
    """``"(..., 3, 3)"`` for the trailing shape ``(3, 3)``."""
    return "(..., " + ", ".join(map(str, trail)) + ")" if trail else "(...)"


def shape_error(what: str, shape: tuple, trail: tuple) -> ShapeError:
    """The one message of a wrong trailing shape: what, the expected and the actual."""
    return ShapeError(f"{what}: expected shape {shape_text(trail)}, got {tuple(shape)}")


def as_array(x, trail: tuple, what: str):
    """``x`` as an array of its own namespace (NumPy for lists), shape-checked."""
    if type(x) is not np.ndarray and is_numpy(namespace_of(x)):
        x = np.asarray(x)
    if isinstance(x, np.ndarray) and x.dtype.kind not in "fiu":
        raise ShapeError(f"{what}: expected real numbers, got dtype {x.dtype}")
    nt = len(trail)
    shape = tuple(x.shape)
    if len(shape) < nt or shape[len(shape) - nt :] != trail:
        raise shape_error(what, shape, trail)
    return x


def check_finite(x, trail: tuple, what: str) -> None:
    """Raise :class:`NonFiniteError` if any component of ``x`` is NaN or infinite."""
    if isinstance(x, np.ndarray):
        if x.dtype.kind != "f":
            return
        if x.size <= 16:  # a ufunc call costs more than this loop for one element
            if all(map(math.isfinite, x.ravel().tolist())):
                return
        elif np.isfinite(x).all():
            return
        bad = ~np.isfinite(x)
    elif isinstance(x, (int, float)):
        if math.isfinite(x):
            return
        bad = np.asarray(True)
    else:
        xp = namespace_of(x)
        fin = xp.isfinite(x)
        if bool(xp.all(fin)):
            return
        bad = ~to_numpy(fin)
    if trail:
        bad = bad.reshape(bad.shape[: bad.ndim - len(trail)] + (-1,)).any(axis=-1)
    raise_where(bad, NonFiniteError, f"{what} contains NaN or infinity {{where}}")


def finite_array(x, trail: tuple, what: str):
    """:func:`as_array` then :func:`check_finite`: the check of every user array."""
    x = as_array(x, trail, what)
    check_finite(x, trail, what)
    return x


def as_float(a):
    """Integer NumPy input becomes float64; other arrays are kept."""
    if isinstance(a, np.ndarray) and a.dtype.kind != "f":
        return a.astype(np.float64)
    return a


# -- default tolerances ------------------------------------------------------------------


def default_atol(dtype) -> float:
    """Tolerance of group membership: 1e-6 for float64, 1e-4 for float32.

    The largest accepted ``max(|R^T R - I|, |det R - 1|)`` of a rotation (block),
    and deviation of a homogeneous matrix's bottom row from ``[0, ..., 0, 1]``:
    loose enough for matrices written to a few digits or computed in float32 (whose
    rounding alone reaches ~1e-6), tight enough to refuse a scaling by 1 + 1e-5.

    >>> default_atol(np.float64), default_atol(np.float32)
    (1e-06, 0.0001)
    """
    return 1e-4 if is_float32(dtype) else 1e-6


def singular_rtol(dtype) -> float:
    """Default Hadamard-ratio threshold below which a matrix counts as singular.

    The ratio ``|det A| / prod |row_i|`` is about ``1 / cond`` of ``A`` with
    normalised rows (see :mod:`rigidkit.kernels.homogeneous`); below 1e-12
    (float64) or 1e-5 (float32) an inverse keeps fewer than about 4 (resp. 2)
    correct digits, so we refuse it.
    """
    return 1e-5 if is_float32(dtype) else 1e-12


def infinity_rtol(dtype) -> float:
    """Default threshold of ``|w| / max|x, y, z, w|`` below which a point is at infinity.

    64 eps of the dtype: ``w`` is then within a few dozen roundings of zero, so
    its sign, and the side of infinity the point lies on, are noise.
    """
    return _INF_RTOL_32 if is_float32(dtype) else _INF_RTOL_64


_INF_RTOL_32 = 64.0 * float(np.finfo(np.float32).eps)
_INF_RTOL_64 = 64.0 * float(np.finfo(np.float64).eps)


# -- matrices ----------------------------------------------------------------------------


def check_bottom_row(M, atol, kind, error, *, what="homogeneous matrix") -> None:
    """Raise ``error`` where the bottom row of ``M`` (..., n, n) is not ``[0, ..., 0, 1]``.

    The one bottom-row check of every homogeneous kind (SE(2), SE(3), Sim(3),
    affine): ``kind`` names the kind in the message (``"a rigid transform"``),
    ``atol`` defaults to :func:`default_atol` of the dtype.
    """
    n = M.shape[-1]
    tol = default_atol(M.dtype) if atol is None else atol
    if isinstance(M, np.ndarray) and M.ndim == 2:
        # One matrix: a few float comparisons cost less than one ufunc call.
        *zeros, one = M[n - 1].tolist()
        if max(abs(one - 1.0), *map(abs, zeros)) <= tol:
            return
    xp = namespace_of(M)
    bottom = M[..., n - 1, :]
    bad = xp.any(xp.abs(bottom[..., : n - 1]) > tol, axis=-1) | (
        xp.abs(bottom[..., n - 1] - 1.0) > tol
    )
    want = "[" + "0, " * (n - 1) + "1]"
    raise_where(
        bad,
        error,
        f"{what} {{where}} has bottom row {{value}}, not {want}: it is not {kind} "
        f"(tolerance {tol:g})",
        value=bottom,
    )


def why_not_rotation(block, idx) -> str:
    """Why the square matrix ``block[idx]`` is not a rotation, in words (for messages)."""
    a = np.asarray(to_numpy(block)[idx], dtype=np.float64)
    det = float(np.linalg.det(a))
    dev = float(np.abs(a.T @ a - np.eye(a.shape[-1])).max())
    if det < 0:
        return f"det = {det:.6g} < 0 (a reflection)"
    sv = np.linalg.svd(a, compute_uv=False)
    if np.abs(sv - sv.mean()).max() < 1e-3 * max(sv.max(), 1e-300):
        return f"it scales by {sv.mean():.9g} (|R^T R - I| = {dev:.3g})"
    return f"|R^T R - I| = {dev:.3g}, singular values {np.round(sv, 6).tolist()}"


def check_rotation(block, err, atol, *, what="matrix") -> None:
    """Raise where ``err`` (a kernel's ``max(|R^T R - I|, |det R - 1|)``) exceeds ``atol``.

    ``block`` (..., n, n) is the rotation block whose error ``err`` (...) the
    kernel measured; ``atol`` defaults to :func:`default_atol` of its dtype. NaN in
    ``err`` fails the test, so a non-finite ``block`` not checked before raises
    :class:`NonFiniteError` here; anything else raises :class:`NotARotationError`
    saying why (a reflection, a scaling, a shear).
    """
    tol = default_atol(block.dtype) if atol is None else atol
    ok = err <= tol
    if all_true(ok):
        return
    n = block.shape[-1]
    check_finite(block, (n, n), "rotation matrix")

    def message(idx):
        return (
            f"{what} {where_text(idx)} is not a rotation: {why_not_rotation(block, idx)} "
            f"(tolerance {tol:g}; pass orthonormalize=True for the nearest rotation)"
        )

    raise_unless(ok, NotARotationError, message)


def check_rotation_2d(block, norm, err, *, atol, orthonormalize, what="matrix") -> None:
    """The rotation-block check of 2x2 matrices (SO(2), and SE(2)'s ``R``).

    ``norm`` and ``err`` come from the kernel that read the unit complex number
    off ``block`` (..., 2, 2): with ``orthonormalize`` the nearest rotation must be
    unique (``norm > 0``; ``m00 + m11 = m10 - m01 = 0`` has none), else
    :func:`check_rotation` applies.
    """
    if not orthonormalize:
        check_rotation(block, err, atol, what=what)
        return
    raise_where(
        norm == 0.0,
        NotARotationError,
        f"{what} {{where}} has no unique nearest rotation (m00 + m11 = m10 - m01 = 0, "
        "e.g. a reflection)",
    )


def check_invertible(ratio, rtol, what) -> None:
    """Raise :class:`SingularMatrixError` where the Hadamard ``ratio`` is <= ``rtol``."""
    raise_where(
        ratio <= rtol,
        SingularMatrixError,
        f"{what} {{where}} is singular: |det| / prod(|row|) = {{value:.3g}} <= {rtol:g}",
        value=ratio,
    )
