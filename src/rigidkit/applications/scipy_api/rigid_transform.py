"""``rigidkit.scipy.RigidTransform``: scipy's API, rigidkit's computations.

The signatures, defaults and semantics of ``scipy.spatial.transform.RigidTransform``
(``*`` composes, exponential coordinates ``(omega, v)``, dual quaternions scalar
last unless ``scalar_first=True``); the work is done by :class:`rigidkit.Transform`,
which the wrapper holds (``as_rigidkit()``). Where scipy stores a 4x4 matrix,
rigidkit stores a unit quaternion and a translation: a matrix is always a rigid
motion here (``normalize=False`` still projects its rotation block, and
``copy=False`` shares no memory with the matrix).
"""

from __future__ import annotations

import math

import numpy as np

from ...objects.transform import Transform as _RkTransform
from ._arrays import as_float
from ._checks import broadcast, det3, exponent, shape_arg
from ._container import Batch
from .rotation import Rotation, _new

__all__ = ["RigidTransform"]

_wrap_tf = _RkTransform._wrap


def _tf(t):
    """A wrapper around the rigidkit Transform ``t`` (no copy, no checks)."""
    obj = object.__new__(RigidTransform)
    obj._t = t
    return obj


def _matrix_in(matrix):
    m = as_float(matrix)
    if m.ndim < 2 or tuple(m.shape[-2:]) != (4, 4):
        raise ValueError(
            f"Expected `matrix` to have shape (..., 4, 4), got {tuple(m.shape)}."
        )
    row = m[..., 3, :]
    ok = (row[..., 0] == 0) & (row[..., 1] == 0) & (row[..., 2] == 0) & (row[..., 3] == 1)
    if not bool(ok.all()):
        bad = np.argwhere(~np.asarray(ok))
        idx = tuple(int(i) for i in bad[0]) if bad.size else ()
        raise ValueError(
            f"Expected last row of transformation matrix {idx} to be exactly "
            f"[0, 0, 0, 1], got {m[idx + (3, Ellipsis)]}"
        )
    return m


class RigidTransform(Batch):
    """Rigid transforms in 3 dimensions, with scipy's API (``RigidTransform``).

    A drop-in replacement: ``from rigidkit.scipy import RigidTransform``.
    ``p * q`` applies ``q`` first; exponential coordinates are ``(omega, v)``
    (rigidkit's own twists are ``(v, omega)``); every computation is
    :class:`rigidkit.Transform`'s (``as_rigidkit()`` returns it).

    Examples
    --------
    >>> import numpy as np
    >>> from rigidkit.scipy import RigidTransform, Rotation
    >>> r = Rotation.from_euler("z", 90, degrees=True)
    >>> tf = RigidTransform.from_components([1.0, 0.0, 0.0], r)
    >>> np.round(tf.apply([1.0, 0.0, 0.0]), 12) + 0.0
    array([1., 1., 0.])
    >>> np.round(tf.as_exp_coords()[:3], 12) + 0.0          # omega first
    array([0.        , 0.        , 1.57079633])
    """

    __slots__ = ("_t",)
    _NAME, _NOUN, _NO_LEN = "RigidTransform", "transform", "Single transform has no len"

    def __init__(self, matrix, normalize=True, copy=True):
        m = _matrix_in(matrix)
        if normalize and bool((det3(m[..., :3, :3]) <= 0).any()):
            raise ValueError(
                "Non-positive determinant (left-handed or null coordinate frame) in "
                "rotation matrix."
            )
        self._t = _RkTransform.from_matrix(m, orthonormalize=True)

    # -- construction ------------------------------------------------------------------
    @staticmethod
    def from_matrix(matrix):
        """From homogeneous matrices (..., 4, 4); the rotation block is projected
        onto the nearest rotation."""
        return RigidTransform(matrix)

    @staticmethod
    def from_rotation(rotation):
        """A pure rotation."""
        if not isinstance(rotation, Rotation):
            raise TypeError(
                f"Expected `rotation` to be a `Rotation` instance, got {type(rotation)}."
            )
        return _tf(_RkTransform._include(rotation._r))

    @staticmethod
    def from_translation(translation):
        """A pure translation, shape (..., 3)."""
        t = as_float(translation)
        if t.shape[-1:] != (3,):
            raise ValueError(
                f"Expected `translation` to have shape (..., 3), got {tuple(t.shape)}."
            )
        return _tf(_RkTransform(translation=t))

    @staticmethod
    def from_components(translation, rotation):
        """``p -> R p + t``: rotation applied first, then the translation."""
        t = as_float(translation)
        if t.shape[-1:] != (3,):
            raise ValueError(
                f"Expected `translation` to have shape (..., 3), got {tuple(t.shape)}."
            )
        if not isinstance(rotation, Rotation):
            raise TypeError(
                f"Expected `rotation` to be a `Rotation` instance, got {type(rotation)}."
            )
        broadcast(rotation.shape, tuple(t.shape[:-1]), "rotations")
        return _tf(_RkTransform(rotation=rotation._r, translation=t))

    @staticmethod
    def from_exp_coords(exp_coords):
        """From exponential coordinates ``(omega, v)``, shape (..., 6)."""
        c = as_float(exp_coords)
        if c.shape[-1:] != (6,):
            raise ValueError(
                f"Expected `exp_coords` to have shape (..., 6), got {tuple(c.shape)}."
            )
        return _tf(_RkTransform.from_exp_coords(c))

    @staticmethod
    def from_dual_quat(dual_quat, *, scalar_first=False):
        """From unit dual quaternions (..., 8), both parts scalar last unless
        ``scalar_first=True``; normalised as scipy does."""
        d = as_float(dual_quat)
        if d.shape[-1:] != (8,):
            raise ValueError(
                f"Expected `dual_quat` to have shape (..., 8), got {tuple(d.shape)}."
            )
        return _tf(_RkTransform.from_dual_quat(d, scalar_first=scalar_first))

    @staticmethod
    def identity(num=None, *, shape=None):
        """The identity: single, ``num`` of them, or batch ``shape``."""
        if num is not None and shape is not None:
            raise ValueError("Only one of `num` and `shape` can be specified.")
        try:
            shp = shape_arg(num, shape)
        except ValueError:
            raise ValueError("`shape` must be an int or a tuple of ints or None.") from None
        return _tf(_RkTransform.identity(shp))

    @staticmethod
    def concatenate(transforms):
        """Join transforms (single ones or 1-D stacks) into one stack."""
        if isinstance(transforms, RigidTransform):
            return _tf(transforms._t)
        transforms = list(transforms)
        if not all(isinstance(x, RigidTransform) for x in transforms):
            raise TypeError("input must contain RigidTransform objects only")
        return _tf(_RkTransform.concatenate([x._t for x in transforms]))

    # -- representations ---------------------------------------------------------------
    def as_matrix(self):
        """Homogeneous matrices (..., 4, 4)."""
        return self._t.as_matrix()

    def as_components(self):
        """``(translation, rotation)``: the motion is the rotation, then the translation."""
        return self.translation, self.rotation

    def as_exp_coords(self):
        """Exponential coordinates ``(omega, v)``, shape (..., 6)."""
        return self._t.as_exp_coords()

    def as_dual_quat(self, *, scalar_first=False):
        """Unit dual quaternions (..., 8), scalar last unless ``scalar_first=True``."""
        return self._t.as_dual_quat(scalar_first=scalar_first)

    def as_rigidkit(self):
        """The :class:`rigidkit.Transform` holding these transforms (immutable)."""
        return self._t

    @staticmethod
    def from_rigidkit(transform):
        """A wrapper of the :class:`rigidkit.Transform` ``transform``."""
        if not isinstance(transform, _RkTransform):
            raise TypeError(
                f"expected a rigidkit.Transform, got {type(transform).__name__}"
            )
        return _tf(transform)

    @property
    def rotation(self):
        """The rotation part (a :class:`Rotation`)."""
        return _new(self._t.rotation)

    @property
    def translation(self):
        """The translation part, shape (..., 3)."""
        t = self._t._pose[..., 4:]
        return t.copy() if hasattr(t, "copy") else t.clone()

    # -- operations --------------------------------------------------------------------
    def apply(self, vector, inverse=False):
        """Move points (..., 3), broadcasting with the transforms' shape."""
        v = as_float(vector)
        if v.shape[-1:] != (3,):
            raise ValueError(
                f"Expected vector to have shape (..., 3), got {tuple(v.shape)}."
            )
        shape = tuple(self._t._pose.shape[:-1])
        if shape and v.ndim > 1:
            try:
                np.broadcast_shapes(shape, tuple(v.shape[:-1]))
            except ValueError:
                raise ValueError("operands could not be broadcast together") from None
        return self._t.apply(v, inverse=inverse)

    def __mul__(self, other):
        if not isinstance(other, RigidTransform):
            if not isinstance(other, Rotation):
                return NotImplemented
            other = RigidTransform.from_rotation(other)  # scipy 1.18's promotion
        sa, sb = self.shape, other.shape
        if sa != sb and sa and sb:
            broadcast(sa, sb, "transforms")
        return _tf(self._t @ other._t)

    def __rmul__(self, other):
        # Rotation * RigidTransform (Rotation.__mul__ declines): the rotation promoted.
        if isinstance(other, Rotation):
            return RigidTransform.from_rotation(other) * self
        return NotImplemented

    def __pow__(self, n):
        return _tf(self._t ** exponent(n))

    def inv(self):
        """The inverse transforms."""
        return _tf(self._t.inv())

    def mean(self, weights=None, axis=None):
        """Chordal mean: the mean rotation (scipy's) and the weighted mean translation."""
        if axis is not None and not isinstance(axis, (int, np.integer, tuple)):
            raise ValueError("`axis` must be None, int, or tuple of ints.")
        shape = self.shape
        if math.prod(shape) == 0:
            raise ValueError("Mean of an empty rotation set is undefined.")
        nd = len(shape)
        t = self._t if nd else self._t.reshape(1)
        if weights is not None:
            w = as_float(weights)
            if tuple(w.shape) != t.shape:
                raise ValueError(
                    "Expected `weights` to match transform shape, got shape "
                    f"{tuple(w.shape)} for {t.shape} transformations."
                )
            if bool((w < 0).any()):
                raise ValueError("`weights` must be non-negative.")
            weights = w
        return _tf(t.mean(weights, axis=axis))

    # -- container protocol ------------------------------------------------------------
    @property
    def _matrix(self):
        # scipy's private name, read by its tests for the array type only.
        return self.as_matrix()

    @property
    def _data(self):
        return self._t._pose

    @staticmethod
    def _from_data(pose):
        return _tf(_wrap_tf(pose))

    def _store(self, pose):
        self._t = _wrap_tf(pose)

    def __reduce__(self):
        p = self._t._pose
        return (_unpickle, (np.array(p) if type(p) is np.ndarray else p,))


def _unpickle(pose):
    return _tf(_wrap_tf(pose))


RigidTransform._KIND = RigidTransform
