"""Array-level pieces of the Jacobians of group operations (see :mod:`rigidkit.jacobians`).

Two formulas shared by every group, written once here (arrays in, arrays out):

- :func:`action_generator`: ``G(p)`` with ``hat(tau) p = G(p) tau`` (``p``
  homogeneous, ``[p; 1]``, when the group's matrices are ``(d+1) x (d+1)``): the
  velocity of the point ``p`` under the motion ``tau``. It is built from the
  group's ``hat`` alone, so no group writes it by hand.
- :func:`to_left`: the left (global) Jacobian from the right (local) one,
  ``J^L = Ad(f(X)) J^R Ad(X)^-1``, where the ``Ad`` of a vector-space input or
  output is omitted (the identity).

>>> import numpy as np
>>> from rigidkit import se3
>>> p = np.array([1.0, 2.0, 3.0])
>>> tau = np.array([0.1, 0.2, 0.3, -0.4, 0.5, -0.6])      # (v, omega)
>>> G = action_generator(se3.hat, 6, 3, p)
>>> bool(np.allclose(G @ tau, tau[:3] + np.cross(tau[3:], p)))
True
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .._engine.namespace import device_of, is_numpy, namespace_of
from .._validate import as_array, as_float

__all__ = ["action_generator", "to_left"]


@cache
def _generator_rows(hat, dof, point_dim):
    # ``H[i, k, j] = hat(e_k)[i, j]`` for the first ``point_dim`` rows i: the
    # generators, reordered so that ``H @ p`` stacks the columns ``hat(e_k) p``.
    gens = np.asarray(hat(np.eye(dof)), dtype=np.float64)  # (dof, n, n)
    return np.ascontiguousarray(gens[:, :point_dim, :].transpose(1, 0, 2))


def action_generator(hat, dof, point_dim, points):
    """``G(p)``, shape (..., d, dof), with ``hat(tau) [p; 1] = [G(p) tau; 0]``.

    For a group of matrices ``n x n`` acting on points of dimension ``d`` (``n = d``
    for rotations, ``n = d + 1`` for homogeneous transforms, whose points are ``[p;
    1]``; ``[p; 0; 1]`` for SE_2(3)), ``G(p)`` is the derivative of ``exp(tau) p``
    at ``tau = 0``; for SE(3),
    ``G(p) = [I, -hat(p)]``, for Sim(3) ``[I, -hat(p), p]``.

    Parameters
    ----------
    hat : callable
        The group's ``hat``, (..., dof) -> (..., n, n) (a linear map).
    dof, point_dim : int
        Tangent dimension and point dimension ``d``.
    points : array_like, shape (..., d)

    Returns
    -------
    ndarray, shape (..., d, dof)
    """
    points = as_float(as_array(points, (point_dim,), "points"))
    xp = namespace_of(points)
    if is_numpy(xp):
        rows = _generator_rows(hat, dof, point_dim)
        H = xp.asarray(rows, dtype=points.dtype)
    else:  # made in the points' namespace: torch.compile would trace NumPy's making
        eye = xp.asarray(np.eye(dof), dtype=points.dtype, device=device_of(points))
        gens = hat(eye)
        H = xp.stack([gens[:, i, :] for i in range(point_dim)], axis=0)
    if H.shape[-1] > point_dim:
        # (p is finite; the torch adapter has no ones_like of a slice's shape)
        zero = points[..., :1] * 0.0
        # ``[p; 1]``, or ``[p; 0; 1]`` for SE_2(3), whose velocity column moves no point
        pad = [zero] * (H.shape[-1] - point_dim - 1)
        points = xp.concat([points, *pad, zero + 1.0], axis=-1)
    return xp.matmul(H, points[..., None, :, None])[..., 0]


def to_left(J_right, out_adjoint=None, in_adjoint_inverse=None):
    """``Ad(f(X)) J^R Ad(X)^-1``: the left Jacobian of ``f`` from its right one.

    With ``f(X exp(d)) ~ f(X) exp(J^R d)`` and ``X exp(d) = exp(Ad(X) d) X``, the
    same first-order change seen on the left is ``J^L = Ad(f(X)) J^R Ad(X)^-1``.
    ``out_adjoint`` is ``Ad(f(X))`` (None for an output in a vector space, a point
    or a tangent), ``in_adjoint_inverse`` is ``Ad(X)^-1 = Ad(X^-1)`` (None for an
    input in a vector space).

    Parameters
    ----------
    J_right : array_like, shape (..., m, k)
    out_adjoint : array_like, shape (..., m, m), optional
    in_adjoint_inverse : array_like, shape (..., k, k), optional

    Returns
    -------
    ndarray, shape (..., m, k)
    """
    xp = namespace_of(J_right, out_adjoint, in_adjoint_inverse)
    J = J_right
    if out_adjoint is not None:
        J = xp.matmul(out_adjoint, J)
    if in_adjoint_inverse is not None:
        J = xp.matmul(J, in_adjoint_inverse)
    return J
