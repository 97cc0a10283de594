"""``Similarity``: the group Sim(3) of similarity transforms ``p -> s R p + t``.

A rotation, a translation and a uniform scale ``s > 0``; homogeneous matrix
``[[s R, t], [0, 1]]``. Twists are ordered ``(v, omega, sigma)`` with ``sigma =
log s``: ``hat(xi) = [[hat(omega) + sigma I, v], [0, 0]]``, extending the SE(3)
order ``(v, omega)`` (docs/conventions.md). Quaternions are Hamilton, scalar first.

Storage: one array of shape (..., 8), ``(w, x, y, z, tx, ty, tz, s)``. We store the
scale itself rather than ``log s``: a scale given by the user reads back exactly
(``exp(log 3) != 3`` in floating point), ``apply`` and ``as_matrix`` need ``s``
(no ``exp`` per point), and ``s > 0`` is kept by every operation (products and
reciprocals of positive numbers). ``log`` takes one ``log(s)``.
"""

from __future__ import annotations

import numpy as np

from .._engine.namespace import device_of, namespace_of
from .._validate import as_array, as_float, check_finite, raise_where, to_numpy
from ..errors import NotASimilarityError
from ..functional import conversions as _conv
from ..functional import sim3 as _fsim3
from ..kernels import sim3 as _k
from ._batch import BatchedArray, batch_shape, expect
from ._frozen import frozen
from .affine import Affine
from .group import LieGroup
from .projective import Projective
from .registry import GroupSpec
from .rotation import Rotation
from .transform import pose_gap

__all__ = ["Similarity", "NotASimilarityError"]


class Similarity(BatchedArray, LieGroup, family="space", rank=2):
    """A batch of similarity transforms ``p -> s R p + t`` (the group Sim(3)).

    ``S1 @ S2`` applies ``S2`` first: ``(s1 s2, R1 R2, s1 R1 t2 + t1)``; ``S @ p``
    maps points (..., 3). Composing with a :class:`~rigidkit.Transform` or
    :class:`~rigidkit.Rotation` gives a ``Similarity``; with an
    :class:`~rigidkit.Affine` or :class:`~rigidkit.Projective`, that kind.

    Parameters
    ----------
    scale : array_like, shape (...), optional
        ``s > 0`` (1 when omitted); a nonpositive scale raises
        :class:`NotASimilarityError`.
    rotation : Rotation, optional
        ``R`` (identity when omitted).
    translation : array_like, shape (..., 3), optional
        ``t`` (zero when omitted). The three batch shapes broadcast.

    Examples
    --------
    >>> import rigidkit as rk
    >>> S = rk.Similarity(scale=2.0, rotation=rk.Rotation.from_rotvec([0, 0, np.pi / 2]),
    ...                   translation=[0.0, 0.0, 1.0])
    >>> np.round(S @ np.array([1.0, 0.0, 0.0]), 12) + 0.0
    array([0., 2., 1.])
    >>> xi = S.log()                     # (v, omega, log s)
    >>> bool(rk.Similarity.exp(xi).approx_equal(S))
    True
    """

    __slots__ = ("_data",)
    _trail = (8,)
    _repr_columns = "(qw, qx, qy, qz, tx, ty, tz, s)"
    _identity = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)  # (q, t, s)
    _compose_kernel = _k.sim3_compose
    dof, matrix_size, point_dim = 7, 4, 3
    _spec = GroupSpec(
        algebra=_fsim3,
        tangent=(
            ("translation", slice(0, 3)),
            ("rotation", slice(3, 6)),
            ("scale", slice(6, 7)),
        ),
    )

    def __init__(self, scale=None, rotation=None, translation=None):
        if rotation is not None and not isinstance(rotation, Rotation):
            rotation = expect(rotation, Rotation, "rotation")
        q = None if rotation is None else rotation.as_quat()
        t = None
        if translation is not None:
            t = as_float(as_array(translation, (3,), "translation"))
            check_finite(t, (3,), "translation")
        s = None
        if scale is not None:
            s = scale if isinstance(scale, (int, float)) else as_array(scale, (), "scale")
            s = as_float(s) if not isinstance(s, (int, float)) else s
            check_finite(s, (), "scale")
            _check_positive(s)
        self._data = _assemble(q, t, s)

    @classmethod
    def from_matrix(cls, matrix, *, atol=None):
        """From homogeneous matrices ``[[s R, t], [0, 1]]``, shape (..., 4, 4), validated.

        ``s`` is the root mean square of the singular values of the 3x3 block
        (``|A|_F / sqrt 3``) and ``R = A / s`` must be a rotation within ``atol``.

        Parameters
        ----------
        atol : float, optional
            Tolerance of the bottom row and of ``A / s`` from SO(3); default 1e-5
            (float64) or 1e-4 (float32), as :meth:`Rotation.from_matrix`.

        Raises
        ------
        NonFiniteError
            NaN or infinity anywhere.
        NotASimilarityError
            The bottom row is not ``[0, 0, 0, 1]``, or the 3x3 block is not a
            positive scalar times a rotation (zero, a reflection, a non-uniform
            scaling, a shear); the message names the first batch index and why.
        """
        return cls._wrap(_fsim3.pose_from_matrix(matrix, atol=atol))

    @classmethod
    def from_transform(cls, transform):
        """The inclusion: a :class:`~rigidkit.Transform` (or ``Rotation``), ``s = 1``."""
        return cls.include(transform)

    @classmethod
    def _include(cls, x):
        if isinstance(x, Rotation):
            return cls(rotation=x)
        q, t = x.rotation.as_quat(), x.translation
        ones = t[..., :1] * 0.0 + 1.0  # (t is finite; the torch adapter has no ones_like)
        return cls._wrap(namespace_of(t).concat([q, t, ones], axis=-1))

    @classmethod
    def exp(cls, tau):
        """``expm(hat(xi))`` of twists ``xi = (v, omega, sigma)``, shape (..., 7).

        ``hat(xi) = [[hat(omega) + sigma I, v], [0, 0]]``; ``omega`` in radians. As
        ``hat(omega)`` and ``sigma I`` commute, the closed form is ``s = e^sigma``,
        ``R = exp(hat(omega))`` (Rodrigues) and ``t = V v`` with (``theta = |omega|``)

            V = int_0^1 e^(u sigma) exp(u hat(omega)) du
              = a I + b hat(omega) + c hat(omega)^2,
            a = (e^sigma - 1) / sigma,
            b = int_0^1 e^(u sigma) sin(u theta) / theta du,
            c = int_0^1 e^(u sigma) (1 - cos(u theta)) / theta^2 du.

        ``b`` and ``c`` are ``Im f(z) / theta`` and ``(f(sigma) - Re f(z)) / theta^2``
        with ``f(z) = (e^z - 1) / z``, ``z = sigma + i theta``: closed forms away from
        0, the power series of ``f`` for ``|z| < 1.5`` (see
        :mod:`rigidkit.kernels.sim3`). For ``sigma = 0`` this is SE(3)'s left
        Jacobian; for ``omega = 0`` it is ``t = (e^sigma - 1) / sigma v``.

        >>> S = Similarity.exp([1.0, 0.0, 0.0, 0.0, 0.0, 0.0, np.log(2.0)])
        >>> float(S.scale), np.round(S.translation, 12) + 0.0   # t = (2 - 1)/log 2 v
        (2.0, array([1.44269504, 0.        , 0.        ]))
        """
        xi = as_float(as_array(tau, (7,), "sim(3) twist"))
        check_finite(xi, (7,), "sim(3) twist")
        return cls._wrap(_k.sim3_exp(xi))

    @classmethod
    def random(cls, shape=(), rng=None, *, dtype=None):
        """Random similarities: Haar rotations, standard normal translations, and
        log-normal scales (``log s`` normal with standard deviation 1/2).

        ``rng`` is a :class:`numpy.random.Generator` or a seed.
        """
        shape = batch_shape(shape)
        rng = np.random.default_rng(rng)
        q = _conv.quat_normalize(rng.standard_normal(shape + (4,)))
        t = rng.standard_normal(shape + (3,))
        s = np.exp(0.5 * rng.standard_normal(shape + (1,)))
        data = np.concatenate([q, t, s], axis=-1)
        return cls._wrap(data.astype(dtype) if dtype is not None else data)

    # -- parts and representations ------------------------------------------------------
    @property
    def rotation(self) -> Rotation:
        """The rotation part ``R``."""
        return Rotation._wrap(self._data[..., :4])

    @property
    def translation(self):
        """The translation ``t``, shape (..., 3) (read-only for NumPy storage)."""
        return frozen(self._data[..., 4:7])

    @property
    def scale(self):
        """The scale ``s > 0``, shape (...) (read-only for NumPy storage)."""
        return frozen(self._data[..., 7])

    def as_matrix(self):
        """Homogeneous matrices ``[[s R, t], [0, 1]]``, shape (..., 4, 4)."""
        return _k.sim3_matrix(self._data)

    def as_affine(self):
        """The same transforms as :class:`~rigidkit.Affine`."""
        return Affine.include(self)

    def as_projective(self):
        """The same transforms as :class:`~rigidkit.Projective`."""
        return Projective.include(self)

    def log(self):
        """Twists ``(v, omega, log s)``, shape (..., 7), ``|omega|`` in [0, pi].

        ``omega`` is the rotation vector of ``R`` and ``v = V^-1 t`` (closed form, see
        :mod:`rigidkit.kernels.sim3`); the inverse of :meth:`exp`.
        """
        return _k.sim3_log(self._data)

    def adjoint(self):
        """Adjoint ``[[s R, hat(t) R, -t], [0, R, 0], [0, 0, 1]]``, shape (..., 7, 7).

        For twists ``(v, omega, sigma)``: ``S exp(xi) S^-1 = exp(Ad xi)``.
        """
        return _k.sim3_adjoint(self._data)

    # -- group operations ---------------------------------------------------------------
    def apply(self, points):
        """``s R p + t`` for points of shape (..., 3), broadcasting with the batch shape."""
        return _k.sim3_apply(self._data, as_array(points, (3,), "points"))

    def inv(self):
        """Inverse transforms ``(1/s, R^T, -R^T t / s)`` (closed form)."""
        return Similarity._wrap(_k.sim3_inverse(self._data))

    def approx_equal(self, other, *, atol=1e-8):
        """Elementwise: rotation angle, translation gap and |log(s1/s2)| all <= ``atol``."""
        other = Similarity.include(other)
        a, b = self._data, other._data
        angle, dist = pose_gap(a, b)
        xp = namespace_of(angle)
        dscale = xp.abs(xp.log(a[..., 7] / b[..., 7]))
        return (angle <= atol) & (dist <= atol) & (dscale <= atol)

    # -- container protocol (shape, len, [], reshape, ...): BatchedArray ------------------
    def _repr_single(self):
        d = to_numpy(self._data).tolist()
        q = ", ".join(f"{c:.6g}" for c in d[:4])
        t = ", ".join(f"{c:.6g}" for c in d[4:7])
        return (
            f"Similarity(scale={d[7]:.6g}, rotation=Rotation.from_quat([{q}]), "
            f"translation=[{t}])"
        )


def _check_positive(s):
    if isinstance(s, (int, float)):
        if not s > 0:
            raise NotASimilarityError(f"scale must be positive, got {float(s)!r}")
        return
    raise_where(
        ~(s > 0),
        NotASimilarityError,
        "scale {where} is {value:g}; it must be positive",
        value=s,
    )


def _assemble(q, t, s):
    """``(q, t, s)`` broadcast to one (..., 8) array; missing parts are the identity's."""
    arrays = [a for a in (q, t, s) if a is not None and not isinstance(a, (int, float))]
    xp = namespace_of(*arrays) if arrays else np
    if arrays and all(getattr(a, "dtype", None) == arrays[0].dtype for a in arrays):
        dt = arrays[0].dtype
    elif arrays and isinstance(arrays[0], np.ndarray):
        dt = np.result_type(*arrays)
    else:
        dt = xp.float64
    dev = next((device_of(a) for a in arrays if device_of(a) is not None), None)
    q = xp.asarray([1.0, 0.0, 0.0, 0.0] if q is None else q, dtype=dt, device=dev)
    t = xp.asarray([0.0, 0.0, 0.0] if t is None else t, dtype=dt, device=dev)
    s = xp.asarray(1.0 if s is None else s, dtype=dt, device=dev)
    batch = tuple(
        np.broadcast_shapes(tuple(q.shape[:-1]), tuple(t.shape[:-1]), tuple(s.shape))
    )
    return xp.concat(
        [
            xp.broadcast_to(q, batch + (4,)),
            xp.broadcast_to(t, batch + (3,)),
            xp.broadcast_to(s[..., None], batch + (1,)),
        ],
        axis=-1,
    )
