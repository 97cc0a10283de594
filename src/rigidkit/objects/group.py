"""The interfaces every transform kind of rigidkit implements.

:class:`Group` is the base of every kind of transform (``Rotation``, ``Transform``,
``Rotation2D``, ``Transform2D``, ``Similarity``, ``Affine``, ``Projective``): it
defines ``@``, once. :class:`LieGroup` adds the Lie calculus of the matrix Lie
groups (all of them but ``Affine`` and ``Projective``, which have no ``exp`` here);
``tests/test_group_axioms.py`` checks the axioms once for all of them.

======================  =====================================================
``exp(tau)``            group element ``expm(hat(tau))`` (classmethod)
``log()``               tangent vector ``tau`` with ``exp(tau) == self``
``inv()``               group inverse
``a @ b``               composition, ``b`` applied first; ``a @ p`` acts on points
``adjoint()``           matrix ``Ad`` with ``X exp(tau) X^-1 = exp(Ad tau)``
``plus(tau, side)``     right: ``X exp(tau)``; left: ``exp(tau) X``
``minus(Y, side)``      right: ``log(Y^-1 X)``; left: ``log(X Y^-1)``
``as_matrix()``         homogeneous matrix, shape (..., n, n)
``identity(shape)``     identity elements of a batch shape (classmethod)
``random(shape, rng)``  random elements (classmethod)
======================  =====================================================

Class attributes: ``dof`` (tangent dimension), ``matrix_size`` (n), and
``point_dim`` (dimension of the points the group acts on).
"""

from __future__ import annotations

from abc import ABC, abstractmethod

from .._engine import owned_function
from . import ladder, registry
from ._batch import compiled_operator, storage_slots

__all__ = ["Group", "LieGroup"]


class Group(ABC):
    """A batch of transforms: ``a @ b`` composes them, ``a @ p`` acts on points.

    ``@``, :meth:`include` and :meth:`identity` are defined here for every kind (a
    :class:`~rigidkit.objects._batch.BatchedArray` too). A subclass registers
    itself (:mod:`rigidkit.objects.registry`: its place on the ladder of kinds, and
    a Lie group's declaration ``_spec``) with class keywords,
    ``class Transform(BatchedArray, LieGroup, family="space", rank=1)``, stores its
    identity element in ``_identity`` and the kernel composing two of its stored
    arrays in ``_compose_kernel``, and implements ``apply`` (to points), ``inv``
    and, when a lower kind exists, the class method ``_include`` (an element of a
    lower kind of its family, as this kind). Then

    - ``a @ b`` of one kind is ``a.compose(b)``;
    - ``a @ b`` of two kinds of one family is composed in the more general kind
      (``Rotation @ Transform`` is a ``Transform``, see :func:`ladder.compose`);
    - ``a @ p`` for anything else is ``a.apply(p)``: the last axis of ``p`` is one
      point or vector, so ``R @ X`` with a (3, 3) array rotates the rows of ``X``
      (the matrix product is ``R.as_matrix() @ X``);
    - ``array @ a`` is refused with a :class:`TypeError`.
    """

    __slots__ = ()
    # NumPy's binary operators defer to ours, so ``ndarray @ X`` reaches
    # ``__rmatmul__`` (and fails clearly) instead of broadcasting over X.
    __array_ufunc__ = None

    def __init_subclass__(cls, *, family=None, rank=None, **kwargs):
        super().__init_subclass__(**kwargs)
        if family is not None:
            registry.register(cls, family, rank)
        if cls._compose_kernel is not None:
            cls.__matmul__ = owned_method(
                cls, cls._compose_kernel, Group.__matmul__, "other"
            )
        if cls._inverse_kernel is not None:
            cls.inv = owned_method(cls, cls._inverse_kernel, cls.inv)

    # The kernel that composes two stored arrays of this kind; each kind sets it.
    _compose_kernel = None
    # The kernel that inverts one, for kinds whose ``inv`` is that kernel alone.
    _inverse_kernel = None

    def __matmul__(self, other):
        if type(other) is type(self):  # the common case: one frame from ``@`` to the kernel
            return self._wrap(self._compose_kernel(self._data, other._data))
        if isinstance(other, Group):
            return ladder.compose(self, other)
        return self.apply(other)

    def compose(self, other, *, out=None):
        """``self @ other`` (``other`` applied first) for a transform ``other``.

        ``other`` of another kind of the same family composes as with ``@``, in
        the more general kind (``Transform.compose(Rotation)`` is a ``Transform``).

        ``out``: a C-contiguous NumPy array of the stored shape of the result's
        kind (``batch`` plus the shape of one stored element: quaternions (..., 4)
        for a ``Rotation``, poses (..., 7) for a ``Transform``, ...) that receives
        the result, which then wraps it (no copy); reusing one saves the page
        faults of a fresh large output. The result then shares ``out``'s memory:
        write to ``out`` again only once the result is no longer needed.

        >>> import rigidkit as rk
        >>> R = rk.Rotation.from_rotvec([0.0, 0.0, 0.5])
        >>> R.compose(R).as_rotvec()
        array([0., 0., 1.])
        >>> A_T_B = rk.Transform(translation=[1.0, 0.0, 0.0]).compose(R)
        >>> type(A_T_B).__name__, A_T_B.translation, A_T_B.rotation.as_rotvec()
        ('Transform', array([1., 0., 0.]), array([0. , 0. , 0.5]))
        """
        if type(other) is not type(self):
            if not isinstance(other, Group):
                raise TypeError(
                    f"{type(self).__name__}.compose takes a transform, got "
                    f"{type(other).__name__}; apply it to points with X @ p or X.apply(p)"
                )
            if out is None:
                return ladder.compose(self, other)
            other = type(self).include(other)  # out= has the stored shape of self's kind
        return self._wrap(self._compose_kernel(self._data, other._data, out=out))

    # ``*`` has no meaning here (one operator, one meaning: ``@`` composes or acts,
    # docs/architecture.md); scipy users
    # write ``R1 * R2`` for what is ``R1 @ R2`` in rigidkit, so the error says so.
    def __mul__(self, other):
        raise TypeError(_no_mul(self, other))

    def __rmul__(self, other):
        raise TypeError(_no_mul(other, self))

    def __rmatmul__(self, other):
        name = type(self).__name__
        raise TypeError(
            f"array @ {name} is not defined; apply it to points with X @ p or X.apply(p)"
        )

    @classmethod
    def __torch_function__(cls, func, types, args=(), kwargs=None):
        """``X @ tensor`` and ``X ** tensor`` inside ``torch.compile``; nothing else.

        TorchDynamo makes them torch's ``matmul`` and ``__rpow__`` and calls this
        (:func:`~rigidkit.objects._batch.compiled_operator`). It swaps ``p @ X`` into
        the same call as ``X @ p``, so a compiled ``p @ X`` gives ``X @ p``, where
        eager code raises ``TypeError`` (``tests/test_torch_matmul.py`` holds both).
        Eager, every torch function of an object returns ``NotImplemented`` here:
        ``p @ X`` reaches :meth:`__rmatmul__` as before.
        """
        return compiled_operator(Group, func, args, kwargs)

    @classmethod
    def include(cls, x):
        """``x`` as an element of this kind: ``x`` itself, or of a kind included in it.

        The inclusions of the ladder (:mod:`rigidkit.objects.ladder`): a rotation is
        the rigid transform with zero translation, a rigid transform the similarity
        of scale 1, ... Raises :class:`TypeError` for anything else (a more general
        kind, another family, an array).

        >>> import rigidkit as rk
        >>> rk.Transform.include(rk.Rotation.identity())
        Transform(rotation=Rotation.from_quat([1, 0, 0, 0]), translation=[0, 0, 0])
        """
        if type(x) is cls:
            return x
        ladder.check_included(cls, x, f"{cls.__name__}.include")
        return cls._include(x)

    @classmethod
    def _include(cls, x):
        """``x``, of a kind strictly below ``cls`` on its ladder, as ``cls`` (the hook
        of :meth:`include`; a kind with nothing below it keeps this default)."""
        raise TypeError(f"nothing is included in {cls.__name__}")

    @classmethod
    def identity(cls, shape=(), *, dtype=None):
        """Identity elements of batch ``shape`` (``()`` for one), float64 by default.

        Each kind stores its identity element as the class attribute ``_identity``.
        """
        return cls._wrap(cls._filled(cls._identity, shape, dtype))

    @abstractmethod
    def apply(self, points): ...

    @abstractmethod
    def inv(self): ...


class LieGroup(Group):
    """Abstract matrix Lie group, batched over leading axes (see module docs)."""

    __slots__ = ()

    dof: int
    matrix_size: int
    point_dim: int

    def mean(
        self, weights=None, *, method="geodesic", axis=None, return_info=False, tol=None
    ):
        """The Karcher (geodesic) mean along batch ``axis`` (default all).

        ``mu <- mu exp(sum w_i log(mu^-1 X_i) / sum w_i)``, from the first element,
        until the norm of the mean log is below ``tol`` (1e-12; 1e-6 in float32):
        the weighted Frechet mean of the left-invariant metric, unique for data
        concentrated enough (Pennec and Arsigny 2012). Written once for every
        group, from its ``inv``, ``@``, ``exp`` and ``log``
        (:func:`rigidkit.functional.averaging.lie_mean_unchecked`); ``Rotation``
        and ``Transform`` also have ``method="chordal"`` (their default).
        ``weights`` (shape (...), >= 0) broadcast with the batch;
        ``return_info=True`` returns ``(mean, {"iterations": k})``.

        >>> import numpy as np
        >>> import rigidkit as rk
        >>> X = rk.Rotation2D.from_angle([0.1, 0.3])
        >>> round(float(X.mean().angle), 12)
        0.2
        """
        from ..functional.averaging import lie_mean_unchecked, lie_steps

        cls = type(self)
        wrap = cls._wrap
        # compose, not @: TorchDynamo (torch 2.13) traces no @ between two objects
        steps = lie_steps(
            lambda a, b: wrap(a).compose(wrap(b))._data,
            lambda a: wrap(a).inv()._data,
            lambda tau: cls.exp(tau)._data,
            lambda a: wrap(a).log(),
        )
        data, k = lie_mean_unchecked(
            self._data, weights, steps=steps, method=method, axis=axis, tol=tol
        )
        return (wrap(data), {"iterations": k}) if return_info else wrap(data)

    @classmethod
    @abstractmethod
    def exp(cls, tau): ...

    @abstractmethod
    def log(self): ...

    @abstractmethod
    def adjoint(self): ...

    @abstractmethod
    def as_matrix(self): ...

    @classmethod
    @abstractmethod
    def random(cls, shape=(), rng=None): ...

    @property
    @abstractmethod
    def shape(self) -> tuple: ...

    def plus(self, tau, *, side="right"):
        """``X ⊕ tau``: ``X @ exp(tau)`` (right, local) or ``exp(tau) @ X`` (left)."""
        delta = type(self).exp(tau)
        if side == "right":
            return self.compose(delta)  # not @: TorchDynamo cannot trace it
        if side == "left":
            return delta.compose(self)
        raise ValueError(f"side must be 'right' or 'left', got {side!r}")

    def minus(self, other, *, side="right"):
        """``X ⊖ Y``: ``log(Y^-1 @ X)`` (right) or ``log(X @ Y^-1)`` (left)."""
        if side == "right":
            return other.inv().compose(self).log()
        if side == "left":
            return self.compose(other.inv()).log()
        raise ValueError(f"side must be 'right' or 'left', got {side!r}")


def _no_mul(a, b) -> str:
    x = next(c for c in (a, b) if isinstance(c, Group))
    k = type(x).__name__[0]
    return (
        f"{type(a).__name__} * {type(b).__name__} is not defined: compose with @ "
        f"({k}1 @ {k}2 applies {k}2 first, like scipy's {k}1 * {k}2) and act on points "
        f"with {k} @ p"
    )


def owned_method(cls, kernel, slow, other=None, *, array=False, out=False):
    """``cls``'s method ``slow`` made fast where it counts: ``a @ b``, ``a.inv()``, ...

    For NumPy storage of one batch axis (or one element), and ``b`` of the same
    kind and shape, the method goes from the call straight to the kernel's
    compiled loop (the engine writes it: :func:`rigidkit._engine.owned_function`):
    these are the library's most frequent calls, at N = 10 about 1 us in all, of
    which the method, the kernel's entry and the new object are most. Anything
    else calls ``slow``, the method written for the general case (whose
    docstring this one keeps). A kernel that is not of this kind's stored arrays
    alone leaves ``slow`` as it is.

    ``other``: the name of the second operand (``a @ b``), else None (``a.inv()``);
    ``array``: the method returns the kernel's array (``as_matrix``), not an
    object of ``cls``; ``out``: it takes ``out=`` (the fast path when it is None).
    """
    return owned_function(
        kernel,
        slow,
        cls,
        ("self", other) if other else ("self",),
        off=("out",) if out else (),
        result="array" if array else "object",
        slots=storage_slots(cls),
        element=cls._trail,
        qualname=f"{cls.__name__}.{slow.__name__}",
    )
