"""Exceptions and warnings raised by rigidkit.

Every error about bad input subclasses :class:`ValueError` and says what was wrong
and, for batches, at which batch index.
"""

from __future__ import annotations

import builtins

__all__ = [
    "RigidkitError",
    "NotARotationError",
    "NotARigidTransformError",
    "NonFiniteError",
    "ZeroNormError",
    "ShapeError",
    "EulerSequenceError",
    "NotASimilarityError",
    "NotAffineError",
    "SingularMatrixError",
    "PointAtInfinityError",
    "DegenerateInputError",
    "OutOfRangeError",
    "TimestampError",
    "TrajectoryFileError",
    "GimbalLockError",
    "FrameKeywordError",
    "ExtrapolationError",
    "ConnectivityError",
    "EdgeKindError",
    "LookupError",
    "GimbalLockWarning",
    "ConvergenceWarning",
]


class RigidkitError(ValueError):
    """Base class of every input error raised by rigidkit.

    Parameters
    ----------
    message : str
        What was wrong and where, in words.
    index : tuple of int, optional
        The first offending batch index (``()`` for a single input), or ``None``
        when the error is not about one element. Programs (the CLI, for one) read
        this attribute instead of parsing the message.

    >>> err = RigidkitError("quaternion at batch index (2,) is zero", index=(2,))
    >>> err.index
    (2,)
    """

    def __init__(self, message="", *, index=None):
        super().__init__(message)
        self.index = None if index is None else tuple(int(i) for i in index)

    def __reduce__(self):
        return (_rebuild_error, (type(self), str(self), self.index))


def _rebuild_error(cls, message, index):
    return cls(message, index=index)


class NotARotationError(RigidkitError):
    """A matrix is not in SO(3) (or SO(2)) within tolerance."""


class NotARigidTransformError(NotARotationError):
    """A homogeneous matrix is not in SE(3) (or SE(2)): its bottom row is not
    ``[0, ..., 0, 1]`` or its rotation block is not a rotation."""


class NonFiniteError(RigidkitError):
    """An input holds NaN or infinity."""


class ZeroNormError(RigidkitError):
    """A quaternion or axis has zero norm, so it names no rotation or direction."""


class ShapeError(RigidkitError):
    """An array has the wrong trailing shape."""


def shape_text(trail: tuple) -> str:
    """``"(..., 3, 3)"`` for the trailing shape ``(3, 3)``."""
    return "(..., " + ", ".join(map(str, trail)) + ")" if trail else "(...)"


def shape_error(what: str, shape: tuple, trail: tuple) -> ShapeError:
    """The one message of a wrong trailing shape: what, the expected and the actual.

    Raised by the validation (:mod:`rigidkit._validate`) and by every kernel's
    own shape check (:mod:`rigidkit._engine.kernel`) alike.
    """
    return ShapeError(f"{what}: expected shape {shape_text(trail)}, got {tuple(shape)}")


class EulerSequenceError(RigidkitError):
    """An Euler sequence string is not one of the 24 accepted forms."""


class NotASimilarityError(RigidkitError):
    """A scale is not positive, or a matrix is not ``[[s R, t], [0, 1]]`` with ``s > 0``."""


class NotAffineError(RigidkitError):
    """A homogeneous matrix's bottom row is not ``[0, 0, 0, 1]``."""


class SingularMatrixError(RigidkitError):
    """A matrix that must be invertible is singular (to working precision)."""


class PointAtInfinityError(RigidkitError):
    """A projective transform maps a point to infinity (homogeneous ``w = 0``)."""


class DegenerateInputError(RigidkitError):
    """The data do not determine the result: weights that sum to zero or are
    negative, too few (or collinear) points to fix a rotation, all-zero vectors."""


class GimbalLockError(RigidkitError):
    """Euler-angle rates were asked for at (or too near) gimbal lock.

    There the Euler-rate matrix ``E`` (``omega = E @ rates``) is singular: only
    the sum or difference of the first and third rate is determined, and the
    rates grow as ``1 / distance``. ``distance`` is the angle (radians) from the
    middle angle to the lock, ``tolerance`` the smallest accepted; both are in
    the message too.
    """

    def __init__(self, message="", *, index=None, distance=None, tolerance=None):
        super().__init__(message, index=index)
        self.distance = distance
        self.tolerance = tolerance

    def __reduce__(self):
        return (
            _rebuild_lock_error,
            (type(self), str(self), self.index, self.distance, self.tolerance),
        )


def _rebuild_lock_error(cls, message, index, distance, tolerance):
    return cls(message, index=index, distance=distance, tolerance=tolerance)


class FrameKeywordError(RigidkitError):
    """The ``frame=`` keyword of a velocity is missing or not ``"world"`` or ``"body"``.

    A velocity (angular, twist, spline derivative) means nothing without the axes
    it is expressed in, so the functions that take one have no default. The error
    is about that keyword only, not about coordinate frames in general.

    >>> issubclass(FrameKeywordError, ValueError)
    True
    """


class OutOfRangeError(RigidkitError):
    """A query lies outside the domain of an interpolant (a time before the first
    or after the last keyframe or knot)."""


class GimbalLockWarning(UserWarning):
    """Euler angles were requested at (or numerically at) gimbal lock.

    The returned angles still rebuild the rotation; the split between the first
    and third angle is then a convention (the third angle is set to zero at
    exact lock).

    ``index`` is the first locked batch index (``()`` for a single input), as
    :attr:`RigidkitError.index`; programs read it from ``w.message.index`` of a
    caught warning ``w``.

    >>> GimbalLockWarning("gimbal lock at batch index (3,)", index=(3,)).index
    (3,)
    """

    def __init__(self, message="", *, index=None):
        super().__init__(message)
        self.index = None if index is None else tuple(int(i) for i in index)

    def __reduce__(self):
        return (_rebuild_error, (type(self), str(self), self.index))


class ConvergenceWarning(UserWarning):
    """An iteration (the Karcher mean, a spline solve) stopped at its step limit
    before reaching its tolerance; the last iterate is returned."""


class EdgeKindError(RigidkitError):
    """An edge of a :class:`~rigidkit.FrameGraph` used as the other kind: stamped
    samples added to a static edge, a static pose to a dynamic one or a second
    one to a static edge (``update_static`` replaces it; of a dynamic edge it
    raises this too), or torch, JAX or Dask samples added to
    a dynamic edge after its first ``add`` (such an edge takes all its samples in
    one call: its arrays are not written in place). The message names the edge.
    """


class TimestampError(RigidkitError):
    """Time stamps that are not finite or not strictly increasing (``index``: the
    first offending position), or a trajectory without stamps where they are
    needed."""


class TrajectoryFileError(RigidkitError):
    """A trajectory file that cannot be read as its format says.

    The message names the file, the 1-based line and what is wrong; ``path`` and
    ``line`` hold the first two (``line`` is ``None`` for an error about the whole
    file) and ``index`` is the 0-based data row, as for the other errors.

    >>> err = TrajectoryFileError("gt.txt line 4: 7 fields, expected 8", path="gt.txt",
    ...                           line=4, index=(2,))
    >>> err.line, err.index
    (4, (2,))
    """

    def __init__(self, message="", *, path=None, line=None, index=None):
        super().__init__(message, index=index)
        self.path = path
        self.line = None if line is None else int(line)

    def __reduce__(self):
        return (
            _rebuild_file_error,
            (type(self), str(self), self.path, self.line, self.index),
        )


def _rebuild_file_error(cls, message, path, line, index):
    return cls(message, path=path, line=line, index=index)


class ExtrapolationError(RigidkitError):
    """A frame lookup asked for a time outside the data of a dynamic edge.

    The message names the edge (``parent -> child``), its stamp range and the
    requested time; ``edge`` holds ``(parent, child)``, ``range`` the
    ``(first, last)`` stamps and ``direction`` is ``"past"`` (before the first
    sample) or ``"future"`` (after the last), so that a program can wait for data
    in the future and give up on the past.

    >>> err = ExtrapolationError("odom -> base: 5.0 is after [0.0, 4.0]",
    ...                          edge=("odom", "base"), range=(0.0, 4.0),
    ...                          direction="future")
    >>> err.direction, isinstance(err, ValueError)
    ('future', True)
    """

    def __init__(self, message="", *, index=None, edge=None, range=None, direction=None):
        super().__init__(message, index=index)
        self.edge = edge
        self.range = range
        self.direction = direction

    def __reduce__(self):
        return (
            _rebuild_extrapolation_error,
            (type(self), str(self), self.index, self.edge, self.range, self.direction),
        )


def _rebuild_extrapolation_error(cls, message, index, edge, range, direction):
    return cls(message, index=index, edge=edge, range=range, direction=direction)


class ConnectivityError(RigidkitError):
    """Two frames of a frame graph lie in different trees, so no transform links
    them; the message names the root of each tree."""


class LookupError(RigidkitError, builtins.LookupError):  # the builtin's name, on purpose
    """A frame name that the frame graph does not hold; the message lists the
    closest names.

    Both a :class:`ValueError` (a :class:`RigidkitError`, like every rigidkit
    input error) and a subclass of Python's builtin ``LookupError``, so
    ``except LookupError``, ``except ValueError`` and ``except rk.LookupError``
    all catch it. It is not the builtin itself, and so that ``from rigidkit
    import *`` does not replace the builtin name (``except LookupError`` must
    keep catching ``KeyError`` and ``IndexError``) it is left out of
    ``rigidkit.__all__``: use it as ``rk.LookupError``.

    >>> import builtins
    >>> issubclass(LookupError, ValueError), issubclass(LookupError, builtins.LookupError)
    (True, True)
    >>> LookupError is builtins.LookupError
    False
    """
