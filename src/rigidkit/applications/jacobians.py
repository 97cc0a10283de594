"""Jacobians of every group operation: ``rk.jacobians``.

For every Lie group of the registry (:mod:`rigidkit.objects.registry`):
``Rotation`` (SO(3)), ``Transform`` (SE(3)), ``Rotation2D`` (SO(2)),
``Transform2D`` (SE(2)) and ``Similarity`` (Sim(3)). Each function returns the value
of the operation and its Jacobians with respect to each operand, ``(value, J_1,
...)``, batched over leading axes like the operation itself (every Jacobian is
broadcast to the value's batch shape).

Design: a module of functions, ``rk.jacobians.compose(X, Y, side="right")``,
rather than a ``jacobians=True`` keyword on the methods. An option never changes
a return type, the objects stay thin (no Jacobian code in any class), and the
formulas live once, here, for every group, built from what each group already
has: ``adjoint()``, ``inv()``, ``as_matrix()``, and the ``hat`` and
``right_jacobian`` / ``right_jacobian_inverse`` / ``left_jacobian_inverse`` of the
functional module it declares (its ``GroupSpec.algebra``,
:mod:`rigidkit.objects.registry`). The two array-level
formulas shared by all groups (the action's generator and the left-from-right
conversion) are in :mod:`rigidkit.functional.jacobians`.

Conventions (those of manif, Solà et al. 2018, "A micro Lie theory"): tangents
are those of the group (``(v, omega)`` for SE(3), ``(v, omega, sigma)`` for
Sim(3), ``(vx, vy, theta)`` for SE(2)); ``X ⊕ tau = X exp(tau)`` and ``X ⊖ Y =
log(Y^-1 X)`` (the right plus and minus, the default ``side`` of
:meth:`~rigidkit.objects.group.LieGroup.plus`). The ``side`` of a Jacobian says
on which side the perturbation acts, on inputs and output alike (the keyword of
``plus`` and ``minus``; ``frame=`` names world and body velocities elsewhere):

- ``side="right"`` (local, body): ``f(X exp(d)) ~ f(X) exp(J^R d)``, i.e.
  ``J^R = d log(f(X)^-1 f(X exp(d))) / dd`` at ``d = 0``;
- ``side="left"`` (global, world): ``f(exp(d) X) ~ exp(J^L d) f(X)``;

for an operand or a value in a vector space (a point, a tangent) the perturbation
is plain addition. The two are related by ``J^L = Ad(f(X)) J^R Ad(X)^-1``
(:func:`rigidkit.functional.jacobians.to_left`), which is how every left Jacobian
here is formed (the table spells out its result):

=================  ==================================  ===========================
operation          right Jacobians                     left Jacobians
=================  ==================================  ===========================
``compose(X, Y)``  ``Ad(Y)^-1``, ``I``                 ``I``, ``Ad(X)``
``inv(X)``         ``-Ad(X)``                          ``-Ad(X)^-1``
``apply(X, p)``    ``L G(p)``, ``L``                   ``G(X p)``, ``L``
``log(X)``         ``J_r^-1(tau)``                     ``J_l^-1(tau)``
``exp(cls, tau)``  ``J_r(tau)``                        ``J_l(tau)``
``plus(X, tau)``   ``Ad(exp tau)^-1``, ``J_r(tau)``    ``I``, ``Ad(X) J_l(tau)``
``minus(X, Y)``    ``J_r^-1(tau)``, ``-J_l^-1(tau)``   each ``@ Ad(operand)^-1``
``between(X, Y)``  ``-Ad(X^-1 Y)^-1``, ``I``           ``-Ad(X)^-1``, ``Ad(X)^-1``
=================  ==================================  ===========================

with ``compose = X Y`` (``Y`` applied first), ``inv = X^-1``, ``apply = X p``,
``plus = X exp(tau)``, ``tau = log X`` for ``log`` and ``tau = log(Y^-1 X)`` for
``minus``, ``between = X^-1 Y``; ``L`` is the linear block of ``X``'s matrix
(``R``, or ``s R`` for Sim(3)) and ``G(p)`` the velocity of the point ``p`` under
``tau``: ``hat(tau) [p; 1] = G(p) tau``
(:func:`rigidkit.functional.jacobians.action_generator`).
``tests/test_jacobians_ops.py`` checks every entry, right and left, for every group,
against finite differences on the manifold computed with ``scipy.linalg.expm`` and
``logm`` of the matrices (independent of these formulas).

Examples
--------
>>> import numpy as np
>>> import rigidkit as rk
>>> W_R_B = rk.Rotation.from_rotvec([0.0, 0.0, np.pi / 2])
>>> p_B = np.array([1.0, 0.0, 0.0])
>>> p_W, J_R, J_p = rk.jacobians.apply(W_R_B, p_B)        # right: d on the body side
>>> np.round(p_W, 12) + 0.0
array([0., 1., 0.])
>>> np.round(J_R, 12) + 0.0                                # -R hat(p)
array([[ 0.,  0., -1.],
       [ 0.,  0.,  0.],
       [ 0., -1.,  0.]])
"""

from __future__ import annotations

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import device_of, namespace_of
from .._validate import as_array, as_float
from ..functional import jacobians as _fj
from ..objects import registry

__all__ = ["compose", "inv", "apply", "log", "exp", "plus", "minus", "between"]


def _algebra(cls, what):
    """The functional module of the Lie group ``cls`` (hat and the Jacobians of its
    tangent), as the group declares it (:mod:`rigidkit.objects.registry`)."""
    spec = registry.spec(cls)
    if spec is None or spec.algebra is None:
        names = ", ".join(c.__name__ for c in registry.groups(lie=True))
        raise TypeError(f"{what} must be one of {names}, got {cls.__name__}")
    return spec.algebra


def _check_side(side):
    if side not in ("right", "left"):
        raise ValueError(f"side must be 'right' or 'left', got {side!r}")
    return side == "left"


def _same_kind(X, Y, fn):
    alg = _algebra(type(X), f"the first operand of jacobians.{fn}")
    if type(Y) is not type(X):
        raise TypeError(
            f"jacobians.{fn} takes two elements of one group, got {type(X).__name__} "
            f"and {type(Y).__name__} (convert with {type(X).__name__}.include)"
        )
    return alg


def _ad_inv(X):
    return X.inv().adjoint()


def _eye(like, n):
    return namespace_of(like).asarray(np.eye(n), dtype=like.dtype, device=device_of(like))


def _out(value, batch, *jacobians):
    """Each Jacobian broadcast to the value's batch shape (an operand may have fewer).

    A lazy (Dask) value gets lazy Jacobians: a constant one (the identity, or one
    from NumPy operands) becomes a Dask array too, chunked as the value's batch.
    """
    data = registry.stored(value) if registry.spec(type(value)) is not None else value
    if dask_backend.is_dask(data):
        return tuple(_lazy_broadcast(J, tuple(batch), data) for J in jacobians)
    xp = namespace_of(*jacobians)
    return tuple(xp.broadcast_to(J, tuple(batch) + tuple(J.shape[-2:])) for J in jacobians)


def _lazy_broadcast(J, batch, data):
    import dask.array as da

    shape = batch + tuple(J.shape[-2:])
    if dask_backend.is_dask(J):
        return da.broadcast_to(J, shape)
    chunks = tuple(data.chunks[: len(batch)]) + tuple((n,) for n in J.shape[-2:])
    whole = da.from_array(np.asarray(J), chunks=J.shape)
    return da.broadcast_to(whole, shape).rechunk(chunks)


def compose(X, Y, *, side="right"):
    """``Z = X @ Y`` (``Y`` applied first) and ``dZ/dX``, ``dZ/dY``.

    Right: ``(Ad(Y)^-1, I)``; left: ``(I, Ad(X))`` (module docs for the sides).

    Parameters
    ----------
    X, Y : LieGroup
        Elements of one group; batch shapes broadcast.
    side : {"right", "left"}
        ``"right"`` (local): ``f(X exp(d)) ~ f(X) exp(J d)``; ``"left"`` (global):
        ``f(exp(d) X) ~ exp(J d) f(X)``.

    Returns
    -------
    Z : LieGroup
    J_X, J_Y : ndarray, shape Z.shape + (dof, dof)

    See Also
    --------
    between, inv

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> A_T_B = rk.Transform.exp([1.0, 0.0, 0.0, 0.0, 0.0, 0.3])
    >>> B_T_C = rk.Transform.exp([0.0, 2.0, 0.0, 0.1, 0.0, 0.0])
    >>> A_T_C, J_AB, J_BC = rk.jacobians.compose(A_T_B, B_T_C)
    >>> bool(np.allclose(J_AB, B_T_C.inv().adjoint())), bool(np.allclose(J_BC, np.eye(6)))
    (True, True)
    """
    _same_kind(X, Y, "compose")
    left = _check_side(side)
    Z = X.compose(Y)  # not @: TorchDynamo cannot trace it on objects
    J_X = _ad_inv(Y)
    J_Y = _eye(J_X, X.dof)
    if left:
        Ad_Z = Z.adjoint()
        J_X, J_Y = _fj.to_left(J_X, Ad_Z, _ad_inv(X)), _fj.to_left(J_Y, Ad_Z, _ad_inv(Y))
    return (Z, *_out(Z, Z.shape, J_X, J_Y))


def inv(X, *, side="right"):
    """``X^-1`` and its Jacobian: ``-Ad(X)`` (right), ``-Ad(X)^-1`` (left).

    Parameters
    ----------
    X : LieGroup
    side : {"right", "left"}
        As in :func:`compose`.

    Returns
    -------
    X_inv : LieGroup
    J : ndarray, shape X.shape + (dof, dof)

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> R = rk.Rotation.from_rotvec([0.1, 0.2, 0.3])
    >>> R_inv, J = rk.jacobians.inv(R)
    >>> bool(np.allclose(J, -R.as_matrix()))                # Ad(R) = R on so(3)
    True
    """
    _algebra(type(X), "jacobians.inv's operand")
    left = _check_side(side)
    X_inv = X.inv()
    J = -X.adjoint()
    if left:
        J = _fj.to_left(J, X_inv.adjoint(), X_inv.adjoint())
    return X_inv, J


def apply(X, points, *, side="right"):
    """``p' = X @ p`` (the action on points) and ``dp'/dX``, ``dp'/dp``.

    With ``L`` the linear block of ``X``'s matrix (``R``, or ``s R`` for Sim(3))
    and ``G(p)`` the velocity of ``p`` under a tangent (``hat(tau) [p; 1] = G(p)
    tau``; ``[I, -hat(p)]`` for SE(3)): right ``(L G(p), L)``, left ``(G(X p),
    L)``. ``p`` lives in a vector space, so ``dp'/dp`` is the same on both sides.

    Parameters
    ----------
    X : LieGroup
    points : array_like, shape (..., d)
        ``d = X.point_dim``; batch shapes broadcast with ``X``'s.
    side : {"right", "left"}
        Side of the perturbation of ``X`` (as in :func:`compose`).

    Returns
    -------
    p' : ndarray, shape (..., d)
    J_X : ndarray, shape (..., d, dof)
    J_p : ndarray, shape (..., d, d)

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> T = rk.Transform(translation=[1.0, 0.0, 0.0])
    >>> q, J_T, J_p = rk.jacobians.apply(T, np.array([0.0, 0.0, 1.0]))
    >>> q
    array([1., 0., 1.])
    >>> J_T[:, 3:]                                            # -R hat(p)
    array([[ 0.,  1.,  0.],
           [-1.,  0.,  0.],
           [ 0.,  0.,  0.]])
    """
    alg = _algebra(type(X), "jacobians.apply's operand")
    left = _check_side(side)
    d = X.point_dim
    p = as_float(as_array(points, (d,), "points"))
    y = X.apply(p)
    L = X.as_matrix()[..., :d, :d]
    J_X = namespace_of(L).matmul(L, _fj.action_generator(alg.hat, X.dof, d, p))
    if left:
        J_X = _fj.to_left(J_X, None, _ad_inv(X))
    return (y, *_out(y, y.shape[:-1], J_X, L))


def log(X, *, side="right"):
    """``tau = log(X)`` and its Jacobian: ``J_r^-1(tau)`` (right), ``J_l^-1(tau)`` (left).

    Parameters
    ----------
    X : LieGroup
    side : {"right", "left"}
        Side of the perturbation of ``X`` (the tangent is a vector space).

    Returns
    -------
    tau : ndarray, shape X.shape + (dof,)
    J : ndarray, shape X.shape + (dof, dof)

    See Also
    --------
    exp

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> R = rk.Rotation.from_rotvec([0.1, 0.2, 0.3])
    >>> w, J = rk.jacobians.log(R)
    >>> bool(np.allclose(J, rk.so3.right_jacobian_inverse(w)))
    True
    """
    alg = _algebra(type(X), "jacobians.log's operand")
    left = _check_side(side)
    tau = X.log()
    J = alg.right_jacobian_inverse(tau)
    if left:
        J = _fj.to_left(J, None, _ad_inv(X))
    return tau, J


def exp(cls, tau, *, side="right"):
    """``X = cls.exp(tau)`` and its Jacobian: ``J_r(tau)`` (right), ``J_l(tau)`` (left).

    Parameters
    ----------
    cls : type
        The group: ``rk.Rotation``, ``rk.Transform``, ``rk.Rotation2D``,
        ``rk.Transform2D`` or ``rk.Similarity``.
    tau : array_like, shape (..., dof)
        Tangent vectors in the group's order.
    side : {"right", "left"}
        Side of the value's perturbation (the tangent is a vector space).

    Returns
    -------
    X : LieGroup
    J : ndarray, shape X.shape + (dof, dof)

    See Also
    --------
    log

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> X, J = rk.jacobians.exp(rk.Rotation2D, np.array([0.5]))
    >>> J
    array([[1.]])
    """
    alg = _algebra(cls, "jacobians.exp's group")
    left = _check_side(side)
    X = cls.exp(tau)
    J = alg.right_jacobian(tau)
    if left:
        J = _fj.to_left(J, X.adjoint(), None)
    return X, J


def plus(X, tau, *, side="right"):
    """``Y = X ⊕ tau = X @ exp(tau)`` and ``dY/dX``, ``dY/dtau``.

    Right: ``(Ad(exp tau)^-1, J_r(tau))``; left: ``(I, Ad(X) J_l(tau))``.

    Parameters
    ----------
    X : LieGroup
    tau : array_like, shape (..., dof)
        Batch shapes broadcast with ``X``'s.
    side : {"right", "left"}
        As in :func:`compose` (``tau`` is a vector space).

    Returns
    -------
    Y : LieGroup
    J_X, J_tau : ndarray, shape Y.shape + (dof, dof)

    See Also
    --------
    minus

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> X = rk.Transform.identity()
    >>> Y, J_X, J_tau = rk.jacobians.plus(X, np.zeros(6))
    >>> bool(np.allclose(J_X, np.eye(6))), bool(np.allclose(J_tau, np.eye(6)))
    (True, True)
    """
    alg = _algebra(type(X), "jacobians.plus's operand")
    left = _check_side(side)
    D = type(X).exp(tau)
    Y = X.compose(D)
    J_X = _ad_inv(D)
    J_tau = alg.right_jacobian(tau)
    if left:
        Ad_Y = Y.adjoint()
        J_X, J_tau = _fj.to_left(J_X, Ad_Y, _ad_inv(X)), _fj.to_left(J_tau, Ad_Y, None)
    return (Y, *_out(Y, Y.shape, J_X, J_tau))


def minus(X, Y, *, side="right"):
    """``tau = X ⊖ Y = log(Y^-1 @ X)`` and ``dtau/dX``, ``dtau/dY``.

    Right: ``(J_r^-1(tau), -J_l^-1(tau))``; left: each times ``Ad`` of the
    operand's inverse (module docs).

    Parameters
    ----------
    X, Y : LieGroup
        Elements of one group; batch shapes broadcast.
    side : {"right", "left"}
        As in :func:`compose` (the value is a tangent vector).

    Returns
    -------
    tau : ndarray, shape (..., dof)
    J_X, J_Y : ndarray, shape (..., dof, dof)

    See Also
    --------
    plus, between

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> X = rk.Rotation.from_rotvec([0.0, 0.0, 0.4])
    >>> tau, J_X, J_Y = rk.jacobians.minus(X, rk.Rotation.identity())
    >>> bool(np.allclose(tau, [0.0, 0.0, 0.4])), bool(np.allclose(J_Y, -J_X.T))
    (True, True)
    """
    alg = _same_kind(X, Y, "minus")
    left = _check_side(side)
    tau = Y.inv().compose(X).log()
    J_X = alg.right_jacobian_inverse(tau)
    J_Y = -alg.left_jacobian_inverse(tau)
    if left:
        J_X, J_Y = _fj.to_left(J_X, None, _ad_inv(X)), _fj.to_left(J_Y, None, _ad_inv(Y))
    return (tau, *_out(tau, tau.shape[:-1], J_X, J_Y))


def between(X, Y, *, side="right"):
    """``Z = X^-1 @ Y`` (``Y`` seen from ``X``: ``B_T_C = A_T_B^-1 A_T_C``) and
    ``dZ/dX``, ``dZ/dY``.

    Right: ``(-Ad(Z)^-1, I)``; left: ``(-Ad(X)^-1, Ad(X)^-1)``.

    Parameters
    ----------
    X, Y : LieGroup
        Elements of one group; batch shapes broadcast.
    side : {"right", "left"}
        As in :func:`compose`.

    Returns
    -------
    Z : LieGroup
        ``X^-1 Y``, in the batch shape of ``X`` and ``Y`` broadcast.
    J_X, J_Y : ndarray, shape Z.shape + (dof, dof)
        ``dZ/dX`` and ``dZ/dY`` on ``side``.

    See Also
    --------
    compose, minus

    Examples
    --------
    An element seen from itself is the identity: ``dZ/dX = -I``, ``dZ/dY = I``.

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> A_R_B = rk.Rotation.from_rotvec([0.1, 0.2, 0.3])
    >>> B_R_B, J_AB, J_AC = rk.jacobians.between(A_R_B, A_R_B)
    >>> bool(np.allclose(J_AB, -np.eye(3))), bool(np.allclose(J_AC, np.eye(3)))
    (True, True)
    """
    _same_kind(X, Y, "between")
    left = _check_side(side)
    Z = X.inv().compose(Y)
    J_X = -_ad_inv(Z)
    J_Y = _eye(J_X, X.dof)
    if left:
        Ad_Z = Z.adjoint()
        J_X, J_Y = _fj.to_left(J_X, Ad_Z, _ad_inv(X)), _fj.to_left(J_Y, Ad_Z, _ad_inv(Y))
    return (Z, *_out(Z, Z.shape, J_X, J_Y))
