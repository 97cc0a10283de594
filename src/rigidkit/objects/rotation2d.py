"""``Rotation2D``: a batch of planar rotations (SO(2)), stored as unit complex numbers.

Conventions: a rotation by ``θ`` (radians, counter-clockwise) is ``e^{iθ}`` and
the matrix ``exp(θ J) = [[cos θ, -sin θ], [sin θ, cos θ]]``,
``J = [[0, -1], [1, 0]]``; rotations are active and act on column vectors,
``p_A = A_R_B @ p_B``; ``R1 @ R2`` applies ``R2`` first. Tangent vectors are
1-vectors ``(θ,)``, shape (..., 1).
"""

from __future__ import annotations

import math

import numpy as np

from .._engine.namespace import is_torch, namespace_of
from .._validate import as_array, check_finite, finite_array, to_numpy
from ..errors import ShapeError
from ..functional import so2 as _so2
from ..kernels import so2 as _k
from ..kernels.kinematics import planar as _kp
from ._batch import BatchedArray, batch_shape
from .group import LieGroup
from .registry import GroupSpec

__all__ = ["Rotation2D"]


class Rotation2D(BatchedArray, LieGroup, family="plane", rank=0):
    """A batch of planar rotations of any shape, one unit complex number each.

    Stored as ``(cos θ, sin θ)``, shape (..., 2). Rotations are active and act on
    column vectors, ``p_A = A_R_B @ p_B``; ``A_R_C = A_R_B @ B_R_C``. Tangent
    vectors (``exp``, ``log``, ``plus``, ``minus``) have shape (..., 1); the
    array namespace (NumPy, torch, ...) and dtype of the input are kept.

    Parameters
    ----------
    cos_sin : array_like, shape (..., 2)
        ``(re, im)`` of nonzero complex numbers, normalised here.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> A_R_B = rk.Rotation2D.from_angle(90.0, degrees=True)
    >>> np.round(A_R_B @ np.array([1.0, 0.0]), 12) + 0.0
    array([0., 1.])
    >>> A_R_B.as_complex().round(12) + 0.0
    np.complex128(1j)
    >>> float(A_R_B.angle)
    1.5707963267948966
    """

    __slots__ = ("_data",)
    _trail = (2,)
    _repr_columns = "(cos, sin)"
    _identity = (1.0, 0.0)  # (cos 0, sin 0)
    _compose_kernel = _k.complex_multiply
    _inverse_kernel = _k.complex_conjugate
    dof, matrix_size, point_dim = 1, 2, 2
    # SO(2) commutes: its integration steps are angles, summed (no chain).
    _spec = GroupSpec(
        algebra=_so2,
        tangent=(("rotation", slice(0, 1)),),
        rate="angular velocity",
        step=(_kp.so2_increment, _kp.so2_increment_rk4, None),
    )

    def __init__(self, cos_sin):
        self._data = _so2.complex_normalize(cos_sin, what="(cos, sin) pair")

    # -- construction -------------------------------------------------------
    @classmethod
    def from_angle(cls, angle, *, degrees=False):
        """Rotations by ``angle`` (counter-clockwise), shape (...).

        >>> Rotation2D.from_angle([0.0, -np.pi]).angle
        array([0.        , 3.14159265])
        """
        t = finite_array(angle, (), "angle")
        if degrees:
            t = t * (math.pi / 180.0)
        return cls._wrap(_k.complex_from_angle(t[..., None]))

    @classmethod
    def exp(cls, tau):
        """``exp(θ J)`` for tangent vectors ``(θ,)``, shape (..., 1), radians."""
        t = as_array(tau, (1,), "so(2) tangent vector (shape (..., 1))")
        check_finite(t, (1,), "so(2) tangent vector")
        return cls._wrap(_k.complex_from_angle(t))

    @classmethod
    def from_complex(cls, z):
        """From nonzero complex numbers ``r e^{iθ}``, shape (...): the rotation by ``θ``.

        The modulus ``r`` is divided out, as :meth:`Rotation.from_quat` divides
        out a quaternion's norm (and as scipy does): ``3 + 4j`` is the rotation
        by ``atan2(4, 3)``; keep ``abs(z)`` yourself where the scale matters. A
        zero raises :class:`~rigidkit.ZeroNormError` (it names no rotation) and
        NaN or infinity :class:`~rigidkit.NonFiniteError`, naming the batch index.
        NumPy (or Python) complex numbers, or complex torch, JAX or Dask arrays
        (kept in their namespace; Dask stays lazy).

        >>> float(Rotation2D.from_complex(2j).angle)
        1.5707963267948966
        >>> Rotation2D.from_complex([3 + 4j, 0j])
        Traceback (most recent call last):
        ...
        rigidkit.errors.ZeroNormError: complex number is zero at batch index (1,); ...
        """
        if is_torch(z):
            import torch

            if not torch.is_complex(z):
                raise ShapeError(f"from_complex: expected a complex tensor, got {z.dtype}")
            pairs = torch.stack([z.real, z.imag], dim=-1)
        else:
            if not (hasattr(z, "dtype") and hasattr(z, "real")):
                z = np.asarray(z)  # Python numbers and lists
            # JAX, Dask, CuPy: their dtypes are NumPy's; their own real and imag
            if getattr(z.dtype, "kind", None) != "c":
                raise ShapeError(
                    f"from_complex: expected complex numbers, got dtype {z.dtype}; "
                    "use Rotation2D(cos_sin) for (..., 2) real pairs"
                )
            xp = np if isinstance(z, np.ndarray) else namespace_of(z)
            pairs = xp.stack([z.real, z.imag], axis=-1)
        return cls._wrap(_so2.complex_normalize(pairs))

    @classmethod
    def from_matrix(cls, matrix, *, atol=None, orthonormalize=False):
        """From rotation matrices, shape (..., 2, 2), validated.

        Raises :class:`~rigidkit.NotARotationError` (naming the batch index) when a
        matrix is not a rotation within ``atol``; ``orthonormalize=True`` takes the
        nearest rotation instead. See :func:`rigidkit.so2.complex_from_matrix`.
        """
        return cls._wrap(
            _so2.complex_from_matrix(matrix, atol=atol, orthonormalize=orthonormalize)
        )

    @classmethod
    def random(cls, shape=(), rng=None, *, dtype=None):
        """Uniformly distributed (Haar) rotations: angles uniform in [-pi, pi).

        ``rng`` is a :class:`numpy.random.Generator` or a seed.
        """
        rng = np.random.default_rng(rng)
        t = rng.uniform(-math.pi, math.pi, batch_shape(shape) + (1,))
        z = _k.complex_from_angle(t)
        return cls._wrap(z.astype(dtype) if dtype is not None else z)

    # -- representations ------------------------------------------------------
    def as_complex(self):
        """Unit complex numbers ``e^{iθ}``, shape (...).

        A complex NumPy array (complex64 for float32) for NumPy storage, a complex
        tensor for torch; for other namespaces ``cos + 1j * sin``.
        """
        c = self._data[..., 0]
        s = self._data[..., 1]
        if is_torch(self._data):
            import torch

            return torch.complex(c, s)
        if isinstance(self._data, np.ndarray):  # (a Dask array takes the lazy sum below)
            out = np.empty(c.shape, dtype=np.result_type(c.dtype, np.complex64))
            out.real = c
            out.imag = s
            return out
        return c + s * 1j

    def as_matrix(self, *, out=None):
        """Rotation matrices ``[[c, -s], [s, c]]``, shape (..., 2, 2)."""
        return _k.matrix_from_complex(self._data, out=out)

    @property
    def angle(self):
        """Rotation angle in (-pi, pi], shape (...), radians."""
        return self.log()[..., 0]

    def log(self):
        """Tangent vectors ``(θ,)``, θ in (-pi, pi], shape (..., 1); see :meth:`exp`."""
        return _k.angle_from_complex(self._data)

    def adjoint(self):
        """``Ad = [[1]]``, shape (..., 1, 1): SO(2) is commutative."""
        return _k.adjoint_from_complex(self._data)

    # -- group operations ----------------------------------------------------------
    # ``R1 @ R2`` composes (``R2`` first), ``R @ p`` rotates points: Group.
    def apply(self, points, *, out=None):
        """Rotate points, shape (..., 2) broadcasting with the rotation's shape."""
        p = as_array(points, (2,), "points")
        return _k.complex_apply(self._data, p, out=out)

    def inv(self):
        """Inverse rotations (conjugate complex numbers)."""
        return Rotation2D._wrap(self._inverse_kernel(self._data))

    def approx_equal(self, other, *, atol=1e-8):
        """Elementwise: the angle between the rotations is at most ``atol`` (radians)."""
        return _k.angle_between(self._data, other._data) <= atol

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        return f"Rotation2D.from_angle({float(to_numpy(self.angle)):.6g})"
