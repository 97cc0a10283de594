"""The one interface every matrix Lie group of rigidkit implements.

Each group class (``Rotation`` = SO(3), ``Transform`` = SE(3), ``Rotation2D`` =
SO(2), ``Transform2D`` = SE(2), ``Similarity`` = Sim(3)) holds one array and
implements these operations; ``tests/test_group_axioms.py`` checks the axioms once
for all of them.

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


class LieGroup(ABC):
    """Abstract matrix Lie group, batched over leading axes (see module docs)."""

    dof: int
    matrix_size: int
    point_dim: int

    @classmethod
    @abstractmethod
    def exp(cls, tau): ...

    @abstractmethod
    def log(self): ...

    @abstractmethod
    def inv(self): ...

    @abstractmethod
    def __matmul__(self, other): ...

    @abstractmethod
    def adjoint(self): ...

    @abstractmethod
    def as_matrix(self): ...

    @classmethod
    @abstractmethod
    def identity(cls, shape=()): ...

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
            return self @ delta
        if side == "left":
            return delta @ self
        raise ValueError(f"side must be 'right' or 'left', got {side!r}")

    def minus(self, other, *, side="right"):
        """``X ⊖ Y``: ``log(Y^-1 @ X)`` (right) or ``log(X @ Y^-1)`` (left)."""
        if side == "right":
            return (other.inv() @ self).log()
        if side == "left":
            return (self @ other.inv()).log()
        raise ValueError(f"side must be 'right' or 'left', got {side!r}")
