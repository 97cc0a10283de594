"""``rigidkit.scipy.Rotation``: scipy's API, rigidkit's computations.

Every method has the signature, defaults and semantics of
``scipy.spatial.transform.Rotation`` (quaternions ``(x, y, z, w)`` unless
``scalar_first=True``, ``*`` composes, ``apply`` rotates vectors); the work is done
by :class:`rigidkit.Rotation`, which the wrapper holds (``as_rigidkit()``). Unlike
rigidkit's own objects the wrapper is mutable where scipy's is (``r[i] = ...``).
scipy's argument checks are in ``_checks``, the container protocol (shared with
``RigidTransform``) in ``_container``.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import NotARotationError, RigidkitError
from ...functional import conversions as _conv
from ...functional import davenport as _dav
from ...functional import euler as _euler
from ...kernels import pose_formats as _kpf
from ...objects.rotation import Rotation as _RkRotation
from ..alignment import align_vectors as _align_vectors
from ._arrays import as_float, canonical_sign, scalar, wxyz, xyzw
from ._checks import (
    align_args,
    broadcast,
    check_trail,
    davenport_order,
    det3,
    exponent,
    generator,
    shape_arg,
)
from ._container import Batch

__all__ = ["Rotation"]

_wrap_rk = _RkRotation._wrap
_quat_from_xyzw = _kpf.quat_from_xyzw
_axis_angle = _conv.axis_angle_from_quat_unchecked
_from_quat_rk = _RkRotation.from_quat


def _new(r):
    """A wrapper around the rigidkit Rotation ``r`` (no copy, no checks)."""
    obj = object.__new__(Rotation)
    obj._r = r
    return obj


class Rotation(Batch):
    """Rotations in 3 dimensions, with scipy's API (``scipy.spatial.transform.Rotation``).

    A drop-in replacement: ``from rigidkit.scipy import Rotation``. Quaternions
    are scalar last ``(x, y, z, w)`` unless ``scalar_first=True``; ``p * q``
    applies ``q`` first; every computation is :class:`rigidkit.Rotation`'s
    (``as_rigidkit()`` returns it). Works on NumPy (float64, as scipy), torch
    and JAX arrays (the input's namespace and dtype kept).

    Examples
    --------
    >>> import numpy as np
    >>> from rigidkit.scipy import Rotation as R
    >>> r = R.from_euler("z", 90, degrees=True)
    >>> np.round(r.apply([1.0, 0.0, 0.0]), 12) + 0.0
    array([0., 1., 0.])
    >>> np.round(r.as_quat(), 12) + 0.0                  # (x, y, z, w)
    array([0.        , 0.        , 0.70710678, 0.70710678])
    >>> np.round((r * r).as_rotvec(), 12) + 0.0
    array([0.        , 0.        , 3.14159265])
    """

    __slots__ = ("_r",)
    _NAME, _NOUN, _NO_LEN = "Rotation", "rotation", "Single rotation has no len()."

    def __init__(self, quat, normalize=True, copy=True, scalar_first=False):
        q = as_float(quat)
        check_trail(q, (4,), "quat")
        if normalize:
            self._r = _from_quat_rk(q, scalar_first=scalar_first)
        else:  # stored as given (rigidkit keeps (w, x, y, z): a copy when reordered)
            self._r = _wrap_rk((q.copy() if copy else q) if scalar_first else wxyz(q))

    # -- construction ------------------------------------------------------------------
    @staticmethod
    def from_quat(quat, *, scalar_first=False):
        """From quaternions, shape (..., 4), normalised; ``(x, y, z, w)`` unless
        ``scalar_first=True``."""
        q = as_float(quat)
        if q.shape[-1:] != (4,):
            check_trail(q, (4,), "quat")
        if not scalar_first and type(q) is np.ndarray:
            # One pass (reorder and normalise); a zero or non-finite norm sends the
            # call to rigidkit's checked path, which raises naming the batch index.
            wxyz, n = _quat_from_xyzw(q)
            if type(n) is np.ndarray and n.ndim:
                ok = n.size == 0 or (0.0 < n.min() and n.max() < math.inf)
            else:
                ok = 0.0 < n < math.inf
            if ok:
                return _new(_wrap_rk(wxyz))
        return _new(_from_quat_rk(q, scalar_first=scalar_first))

    @staticmethod
    def from_matrix(matrix, *, assume_valid=False):
        """From matrices (..., 3, 3): the nearest rotation of any matrix of positive
        determinant (scipy's projection); ``assume_valid=True`` skips it."""
        m = as_float(matrix)
        if tuple(m.shape[-2:]) != (3, 3) or m.ndim < 2:
            raise ValueError(
                f"Expected `matrix` to have shape (..., 3, 3), got {tuple(m.shape)}"
            )
        if assume_valid:
            return _new(_RkRotation.from_matrix(m, atol=math.inf))
        try:  # the common case, a rotation to rounding: validated and projected
            return _new(_RkRotation.from_matrix(m))
        except NotARotationError:
            pass
        if bool((det3(m) <= 0).any()):
            raise ValueError(
                "Non-positive determinant (left-handed or null coordinate frame) in "
                "rotation matrix."
            )
        return _new(_RkRotation.from_matrix(m, orthonormalize=True))

    @staticmethod
    def from_rotvec(rotvec, degrees=False):
        """From rotation vectors ``angle * axis``, shape (..., 3)."""
        r = as_float(rotvec)
        if r.shape[-1:] != (3,):
            raise ValueError(
                f"Expected `rot_vec` to have shape (3,) or (N, 3), got {tuple(r.shape)}"
            )
        return _new(_RkRotation.from_rotvec(r, degrees=degrees))

    @staticmethod
    def from_mrp(mrp):
        """From modified Rodrigues parameters, shape (..., 3)."""
        p = as_float(mrp)
        if p.shape[-1:] != (3,):
            raise ValueError(
                f"Expected `mrp` to have shape (3,) or (N, 3), got {tuple(p.shape)}"
            )
        return _new(_RkRotation.from_mrp(p))

    @staticmethod
    def from_euler(seq, angles, degrees=False):
        """From Euler angles: ``seq`` of 1 to 3 axes, UPPER intrinsic, lower extrinsic."""
        a = as_float(angles)
        if (
            isinstance(seq, str)
            and 1 <= len(seq) <= 3
            and a.ndim
            and a.shape[-1] != len(seq)
        ):
            raise ValueError(
                "Expected last dimension of `angles` to match number of sequence axes "
                f"specified, got {a.shape[-1]}."
            )
        return _new(_RkRotation.from_euler(seq, a, degrees=degrees))

    @staticmethod
    def from_davenport(axes, order, angles, degrees=False):
        """From Davenport angles about 1 to 3 axes (``order`` "e" or "i")."""
        axes, angles = as_float(axes), as_float(angles)
        davenport_order(order)
        n = 1 if axes.ndim == 1 else axes.shape[-2]
        if (angles.ndim == 0 and n != 1) or (angles.ndim and angles.shape[-1] != n):
            raise ValueError(
                f"Expected `angles` to match number of axes, got {tuple(angles.shape)} "
                f"angles and {tuple(axes.shape)} axes."
            )
        try:
            r = _RkRotation.from_davenport(axes, order, angles, degrees=degrees)
        except RigidkitError as err:
            if "orthogonal" in str(err):
                raise ValueError("Consecutive axes must be orthogonal.") from err
            raise
        return _new(r)

    @staticmethod
    def identity(num=None, *, shape=None):
        """The identity rotation: single, ``num`` of them, or batch ``shape``."""
        return _new(_RkRotation.identity(shape_arg(num, shape)))

    @staticmethod
    def random(num=None, rng=None, *, shape=None, random_state=None):
        """Uniformly distributed rotations (normalised 4-D Gaussian samples, drawn as
        scipy draws them: the same ``rng`` gives the same rotations; ``random_state``
        is scipy's legacy name of ``rng``)."""
        shp = shape_arg(num, shape)
        sample = generator(rng if random_state is None else random_state).normal(
            size=shp + (4,)
        )
        return _new(_from_quat_rk(sample, scalar_first=False))

    @staticmethod
    def create_group(group, axis="Z"):
        """The rotations of a finite symmetry group (``"I"``, ``"O"``, ``"T"``,
        ``"Dn"``, ``"Cn"``)."""
        if not isinstance(group, str):
            raise ValueError("`group` argument must be a string")
        axes = ["x", "y", "z", "X", "Y", "Z"]
        if axis not in axes:
            raise ValueError("`axis` must be one of " + ", ".join(axes))
        if group in ("I", "O", "T"):
            order = 0
        elif group[:1] in ("C", "D") and group[1:].isdigit():
            order = int(group[1:])
            if order < 1:
                raise ValueError("Group order must be positive")
        else:
            raise ValueError("`group` must be one of 'I', 'O', 'T', 'Dn', 'Cn'")
        return _new(_RkRotation.create_group(group, axis.upper()))

    @staticmethod
    def concatenate(rotations):
        """Join rotations (single ones or 1-D stacks) into one stack."""
        if isinstance(rotations, Rotation):
            return _new(rotations._r)
        rotations = list(rotations)
        if not all(isinstance(x, Rotation) for x in rotations):
            raise TypeError("input must contain Rotation objects only")
        return _new(_RkRotation.concatenate([x._r for x in rotations]))

    @staticmethod
    def align_vectors(a, b, weights=None, return_sensitivity=False):
        """The rotation best aligning ``b`` to ``a`` (Wahba), with scipy's returns:
        ``(rotation, rssd)`` or ``(rotation, rssd, sensitivity)``."""
        a2, b2, weights = align_args(a, b, weights, return_sensitivity)
        out = _align_vectors(a2, b2, weights, return_sensitivity=return_sensitivity)
        result = (_new(out[0]), scalar(out[1]))
        return result + ((out[2],) if return_sensitivity else ())

    # -- representations ---------------------------------------------------------------
    def as_quat(self, canonical=False, *, scalar_first=False):
        """Quaternions (..., 4), ``(x, y, z, w)`` unless ``scalar_first=True``;
        ``canonical=True`` gives ``w >= 0`` (scipy's tie-breaking)."""
        q = self._r._quat
        if canonical:
            q = canonical_sign(q)
        if scalar_first:
            return q.copy() if hasattr(q, "copy") else q.clone()
        return xyzw(q)

    def as_matrix(self):
        """Rotation matrices, shape (..., 3, 3)."""
        return self._r.as_matrix()

    def as_rotvec(self, degrees=False):
        """Rotation vectors, angle in [0, pi], shape (..., 3)."""
        return self._r.as_rotvec(degrees=degrees)

    def as_mrp(self):
        """Modified Rodrigues parameters, norm <= 1, shape (..., 3)."""
        return self._r.as_mrp()

    def as_euler(self, seq, degrees=False, *, suppress_warnings=False):
        """Euler angles for a 3-axis ``seq``, shape (..., 3); a gimbal lock warns
        (a :class:`~rigidkit.GimbalLockWarning`, a ``UserWarning``) unless
        ``suppress_warnings=True``."""
        # warn=False, not warnings.catch_warnings(): that swaps the process-wide
        # warning state (before Python 3.14), hiding other threads' warnings.
        return _euler.euler_from_quat_unchecked(
            seq, self._r._quat, degrees=degrees, warn=not suppress_warnings
        )

    def as_davenport(self, axes, order, degrees=False, *, suppress_warnings=False):
        """Davenport angles about three axes, shape (..., 3)."""
        axes = as_float(axes)
        davenport_order(order)
        try:
            return _dav.davenport_from_quat_unchecked(
                axes, order, self._r._quat, degrees=degrees, warn=not suppress_warnings
            )
        except RigidkitError as err:
            if "orthogonal" in str(err):
                raise ValueError("Consecutive axes must be orthogonal.") from err
            raise

    def as_rigidkit(self):
        """The :class:`rigidkit.Rotation` holding these rotations (immutable)."""
        return self._r

    @staticmethod
    def from_rigidkit(rotation):
        """A wrapper of the :class:`rigidkit.Rotation` ``rotation``."""
        if not isinstance(rotation, _RkRotation):
            raise TypeError(f"expected a rigidkit.Rotation, got {type(rotation).__name__}")
        return _new(rotation)

    # -- operations --------------------------------------------------------------------
    def apply(self, vectors, inverse=False):
        """Rotate vectors (..., 3), broadcasting with the rotations' shape."""
        v = as_float(vectors)
        if v.shape[-1:] != (3,):
            raise ValueError(f"Expected input of shape (..., 3), got {tuple(v.shape)}.")
        shape = self._r._quat.shape[:-1]
        if shape and v.ndim > 1:
            broadcast(shape, tuple(v.shape[:-1]))
        return self._r.apply(v, inverse=inverse)

    def __mul__(self, other):
        if not isinstance(other, Rotation):
            return NotImplemented
        a, b = self._r, other._r
        sa, sb = a._quat.shape[:-1], b._quat.shape[:-1]
        if sa != sb and sa and sb:
            broadcast(sa, sb, "rotations")
        return _new(a @ b)

    def __pow__(self, n, modulus=None):
        if modulus is not None:
            raise NotImplementedError("modulus not supported")
        return _new(self._r ** exponent(n))

    def inv(self):
        """The inverse rotations."""
        return _new(self._r.inv())

    def magnitude(self):
        """Rotation angles in [0, pi], shape (...) (a NumPy scalar for one)."""
        # rk.Rotation.magnitude's kernel, called here: three Python calls fewer
        # (~0.3 us of ~1.5 us for one rotation).
        return scalar(_axis_angle(self._r._quat)[1])

    def approx_equal(self, other, atol=None, degrees=False):
        """Whether the angle between the rotations is at most ``atol`` (1e-8 rad if
        None; degrees with ``degrees=True``)."""
        if atol is None:
            if degrees:
                import warnings

                warnings.warn(
                    "atol must be set to use the degrees flag, defaulting to 1e-8 radians.",
                    stacklevel=2,
                )
            atol = 1e-8
        elif degrees:
            atol = math.radians(atol)
        sa, sb = tuple(self._r._quat.shape[:-1]), tuple(other._r._quat.shape[:-1])
        if sa != sb and sa and sb:
            try:
                np.broadcast_shapes(sa, sb)
            except ValueError:
                raise ValueError(
                    f"Expected broadcastable shapes in both rotations, got {sa} "
                    f"rotations in first and {sb} rotations in second object."
                ) from None
        return self._r.angle_to(other._r) <= atol

    def mean(self, weights=None, axis=None):
        """The chordal mean rotation (scipy's), along ``axis`` (default all)."""
        if axis is not None and not isinstance(axis, (int, np.integer, tuple)):
            raise ValueError("`axis` must be None, int, or tuple of ints.")
        shape = self.shape
        if math.prod(shape) == 0 or self.single and False:
            raise ValueError("Mean of an empty rotation set is undefined.")
        nd = len(shape)
        axes = (
            tuple(range(nd))
            if axis is None
            else (axis if isinstance(axis, tuple) else (axis,))
        )
        for ax in axes:
            if not -max(nd, 1) <= ax < max(nd, 1):
                raise ValueError(
                    f"axis {ax} is out of bounds for rotations of {nd} dimensions"
                )
        r = self._r if nd else self._r.reshape(1)
        if weights is not None:
            w = as_float(weights)
            if nd == 0 and w.ndim == 0:
                w = w[None]
            try:
                if np.broadcast_shapes(tuple(w.shape), r.shape) != r.shape:
                    raise ValueError
            except ValueError:
                raise ValueError(
                    "Expected `weights` to be broadcastable to the rotation shape "
                    f"{r.shape}, got {tuple(w.shape)}."
                ) from None
            if bool((w < 0).any()):
                raise ValueError("`weights` must be non-negative.")
            weights = w
        return _new(r.mean(weights, axis=axis))

    def reduce(self, left=None, right=None, return_indices=False):
        """``l * self * r`` of smallest angle over ``l`` in ``left``, ``r`` in
        ``right``; with ``return_indices`` also their indices."""
        out = self._r.reduce(
            None if left is None else left._r,
            None if right is None else right._r,
            return_indices=return_indices,
        )
        if return_indices:
            return (_new(out[0]),) + tuple(out[1:])
        return _new(out)

    # -- container protocol ------------------------------------------------------------
    @property
    def _quat(self):
        # scipy's private name, read by its tests for the array type only.
        return self._r._quat

    @property
    def _data(self):
        return self._r._quat

    @staticmethod
    def _from_data(quat):
        return _new(_wrap_rk(quat))

    def _store(self, quat):
        self._r = _wrap_rk(quat)

    def __reduce__(self):
        return (_unpickle, (self.as_quat(scalar_first=True),))

    def __getstate__(self):
        return self.as_quat(scalar_first=True), self.single

    def __setstate__(self, state):
        self._r = _wrap_rk(state[0])


def _unpickle(quat):
    return _new(_wrap_rk(quat))


Rotation._KIND = Rotation
