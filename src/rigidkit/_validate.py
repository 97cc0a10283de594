"""All input validation of rigidkit: shapes, finiteness, norms, matrices, tolerances.

Each check raises a :class:`~rigidkit.errors.RigidkitError` subclass whose message
says what was wrong and where, and whose ``index`` attribute is the first offending
batch index (``()`` for a single input). The checks are one vectorised pass; the
index is looked up only once something is wrong. The policy is in
``docs/architecture.md``: the functional and object layers validate what a user can
get wrong; functions that deliberately skip it are named ``*_unchecked``.

The default tolerances (:mod:`rigidkit._tolerances`: one table per dtype, read
with :func:`tolerances`) are re-exported here, with :func:`default_atol`
(membership of SO(n), SE(n), Sim(3), affine bottom rows), :func:`singular_rtol`
(invertibility) and :func:`infinity_rtol` (points at infinity) that the checks
here read; the functional modules read the table for theirs.

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

from . import _raising
from ._engine import dask_backend
from ._engine import namespace as _ns
from ._engine.namespace import is_numpy, namespace_of
from ._raising import (  # noqa: F401  (re-exported: callers import checks from here)
    _deferred,
    _relabel,
    all_true,
    any_true,
    batch_index,
    checks_now,
    concrete,
    dynamo_traces,
    raise_unless,
    raise_where,
    set_validation,
    to_numpy,
    validation_enabled,
    where_text,
)

# The tolerance table, re-exported: callers read checks and their defaults here.
from ._tolerances import (  # noqa: F401
    BFLOAT16,
    FLOAT16,
    FLOAT32,
    FLOAT64,
    Tolerances,
    default_atol,
    infinity_rtol,
    singular_rtol,
    tolerances,
)
from .errors import (
    NonFiniteError,
    NotARotationError,
    ShapeError,
    SingularMatrixError,
    shape_error,
)
from .errors import shape_text as shape_text  # re-exported: callers import checks from here

# -- shapes and values -------------------------------------------------------------------


def as_array(x, trail: tuple, what: str):
    """``x`` as an array of its own namespace (NumPy for lists), shape-checked.

    An object that stands for matrices (a ``rigidkit.Rotation``, scipy's
    ``Rotation`` or ``RigidTransform``, ...) is read as its matrices where square
    matrices of its size are expected, and a scipy ``Rotation`` as its quaternions
    ``(w, x, y, z)`` where quaternions are (:func:`object_array`); any other object
    is a :class:`ShapeError` that says what to pass instead.
    """
    if type(x) is not np.ndarray and is_numpy(namespace_of(x)):
        if type(x) not in _PLAIN and hasattr(x, "as_matrix"):
            x = object_array(x, trail, what)
        elif dask_backend.is_dask(x):  # kept lazy: the engine maps kernels over chunks
            if x.dtype.kind not in "fiu":
                raise ShapeError(f"{what}: expected real numbers, got dtype {x.dtype}")
        elif type(x) is float or type(x) is int:  # real: no dtype to read (TorchDynamo
            return _plain_scalar(x, trail, what)  # cannot read a traced ndarray's dtype)
        else:
            x = np.asarray(x)
    if (
        isinstance(x, np.ndarray)
        and not _ns.COMPILER._is_compiling_flag
        and x.dtype.kind not in "fiu"
    ):
        raise ShapeError(f"{what}: expected real numbers, got dtype {x.dtype}")
    nt = len(trail)
    shape = tuple(x.shape)
    if len(shape) < nt or shape[len(shape) - nt :] != trail:
        raise shape_error(what, shape, trail)
    return x


_PLAIN = (list, tuple, float, int)


def _plain_scalar(x, trail, what):
    """A Python float or int as a 0-d NumPy array (shape-checked: no trailing axes)."""
    if trail:
        raise shape_error(what, (), trail)
    return np.asarray(x)


def scipy_kind(x) -> str | None:
    """``"Rotation"`` or ``"RigidTransform"`` for scipy's objects of those classes (and
    subclasses, such as a ``rigidkit.scipy`` wrapper), else None; scipy is not imported.
    """
    for klass in type(x).__mro__:
        if klass.__module__.startswith("scipy.spatial.transform") and klass.__name__ in (
            "Rotation",
            "RigidTransform",
        ):
            return klass.__name__
    return None


def foreign_object(x):
    """The rigidkit object that ``x`` converts to, its class's name, or None.

    ``x.as_rigidkit()`` where it has one (the ``rigidkit.scipy`` classes); a scipy
    ``Rotation`` or ``RigidTransform`` is returned as is, for its caller to read
    (``("Rotation", x)``). None for anything else.
    """
    make = getattr(x, "as_rigidkit", None)
    if make is not None and callable(make):
        obj = make()
        return type(obj).__name__, obj
    kind = scipy_kind(x)
    return None if kind is None else (kind, x)


def object_array(x, trail: tuple, what: str):
    """The array an object stands for where an array of trailing shape ``trail`` is
    expected: its matrices (shape ``(..., n, n)``) for square ``trail`` of its matrix
    size, a scipy ``Rotation``'s quaternions ``(w, x, y, z)`` for ``trail == (4,)``.

    A single scipy object gives one element (shape ``trail``). Anything else raises
    :class:`ShapeError` naming the object and what to pass instead.

    >>> from scipy.spatial.transform import Rotation as SciRot
    >>> object_array(SciRot.from_quat([0.0, 0.0, 0.0, 1.0]), (4,), "quaternion")
    array([1., 0., 0., 0.])
    """
    made = foreign_object(x)
    kind, obj = made if made is not None else (type(x).__name__, x)
    scipy_made = scipy_kind(obj) is not None
    if len(trail) == 2 and trail[0] == trail[1]:
        matrix = obj.as_matrix()
        if tuple(matrix.shape[-2:]) == trail:
            return matrix
    elif trail == (4,) and kind == "Rotation":
        if scipy_made:
            return obj.as_quat(scalar_first=True)
        return obj.as_quat()
    label = f"scipy {kind}" if scipy_made else f"rigidkit.{kind}"
    raise ShapeError(
        f"{what}: expected an array of shape {shape_text(trail)}, got a {label} object"
        f"; pass the array it stands for (its .as_matrix(), .as_quat(), ...)"
    )


def check_finite(x, trail: tuple, what: str) -> None:
    """Raise :class:`NonFiniteError` if any component of ``x`` is NaN or infinite."""
    if not _raising._ENABLED:
        return
    if isinstance(x, np.ndarray):
        if _ns.COMPILER._is_compiling_flag or x.dtype.kind != "f":
            return
        # A quick test that never passes a NaN or an infinity, before the exact one.
        # 0-d: one float conversion (50 ns). Up to 64 components a Python sum is
        # cheaper than a ufunc and a reduction (0.6 us against 1.4 at 30): a NaN or
        # inf term keeps the sum non-finite, and a sum that overflows only sends us
        # on to the exact test (silently, where NumPy's dot or sum would warn).
        if x.ndim == 0:
            if math.isfinite(x):
                return
        elif x.size <= 64 and math.isfinite(
            sum((x if x.ndim == 1 else x.ravel()).tolist())
        ):
            return
        if np.isfinite(x).all():
            return
        bad = ~np.isfinite(x)
    elif isinstance(x, (int, float)):
        if math.isfinite(x):
            return
        bad = np.asarray(True)
    elif not checks_now(x):
        if _deferred(x):
            dask_backend.defer(
                _check_finite_numpy, (x,), (trail, what), _relabel, (len(trail),)
            )
        return
    else:
        xp = namespace_of(x)
        fin = xp.isfinite(x)
        ok = xp.all(fin)
        # A concrete input inside a trace (a constant closed over by jax.jit or
        # jax.grad) gives a traced test: its value cannot be read, so it is skipped
        # like a traced input's.
        if not concrete(ok) or bool(ok):
            return
        bad = ~to_numpy(fin)
    if trail:
        bad = bad.reshape(bad.shape[: bad.ndim - len(trail)] + (-1,)).any(axis=-1)
    raise_where(bad, NonFiniteError, f"{what} contains NaN or infinity {{where}}")


def _check_finite_numpy(x, trail, what):
    check_finite(x, trail, what)


def finite_array(x, trail: tuple, what: str):
    """:func:`as_array` then :func:`check_finite`: the check of every user array."""
    if type(x) is float or type(x) is int:  # checked as a number (TorchDynamo traces
        check_finite(x, (), what)  # a NumPy array made of it, whose dtype it cannot read)
        return as_array(x, trail, what)
    x = as_array(x, trail, what)
    check_finite(x, trail, what)
    return x


def as_float(a):
    """Integer NumPy input becomes float64; other arrays are kept."""
    if (
        isinstance(a, np.ndarray)
        and not _ns.COMPILER._is_compiling_flag
        and a.dtype.kind != "f"
    ):
        return a.astype(np.float64)
    return a


# -- matrices ----------------------------------------------------------------------------


def check_bottom_row(M, atol, kind, error, *, what="homogeneous matrix") -> None:
    """Raise ``error`` where the bottom row of ``M`` (..., n, n) is not ``[0, ..., 0, 1]``.

    The one bottom-row check of every homogeneous kind (SE(2), SE(3), Sim(3),
    affine): ``kind`` names the kind in the message (``"a rigid transform"``),
    ``atol`` defaults to :func:`default_atol` of the dtype.
    """
    n = M.shape[-1]
    tol = default_atol(M.dtype) if atol is None else atol
    if type(M) is not np.ndarray and not checks_now(M) and not _deferred(M):
        return
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
    if _deferred(err):  # per chunk at compute time: the message reads the block
        dask_backend.defer(_check_rotation_numpy, (err, block), (tol, what), _relabel)
        return
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


def _check_rotation_numpy(err, block, tol, what):
    check_rotation(block, err, tol, what=what)


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
