"""The Karcher (Frechet) mean iteration shared by every mean of a Lie group.

``mu <- mu exp(sum w_i log(mu^-1 X_i) / sum w_i)`` until the mean log is below
``tol`` (Pennec and Arsigny 2012): :func:`karcher` on concrete values, stopping
when converged, and :func:`karcher_traced` under ``jax.jit``, ``vmap``, ``grad``,
``torch.compile`` or ``torch.func``, where it runs ``max_iter`` steps with each
mean frozen once converged. The group enters through its steps
``(log_from, retract)`` (:func:`lie_steps`); the callers are
:mod:`rigidkit.functional.averaging`'s means.
"""

from __future__ import annotations

import math
import warnings

import numpy as np  # noqa: F401  (the doctests' namespace)

from .._validate import concrete, to_numpy, tolerances
from ..errors import ConvergenceWarning

__all__ = ["lie_steps"]


def karcher(xp, mean, g, w, total, method, tol, max_iter, steps):
    """``(mean, iterations)``: the Karcher fixed point from the chordal ``mean``.

    For ``method="chordal"`` the chordal mean itself (0 iterations). ``steps`` is
    the group's ``(log_from, retract)``: ``log_from(mean, g)`` the tangents
    ``log(mean^-1 g_i)`` (kept, K, c) and ``retract(mean, step) = mean exp(step)``.
    """
    if method == "chordal":
        return mean, 0
    if method != "geodesic":
        raise ValueError(f"method must be 'chordal' or 'geodesic', got {method!r}")
    log_from, retract = steps
    tol = _tol(tol, g.dtype)
    if not concrete(g):  # traced (jit, vmap, grad, torch.compile, torch.func)
        return karcher_traced(xp, mean, g, w, total, tol, max_iter, steps)
    for iterations in range(1, max_iter + 1):
        step = _average(xp, log_from(mean, g), w, total)
        mean = retract(mean, step)
        if _converged(xp, step, tol):
            return mean, iterations
    _warn_unconverged(max_iter, tol)
    return mean, max_iter


def karcher_traced(xp, mean, g, w, total, tol, max_iter, steps):
    """The Karcher iteration without reading values: ``max_iter`` steps, each mean
    frozen (``where``) once its own step is below ``tol``, as the eager loop stops.

    On JAX one ``lax.fori_loop`` (a scan: the body traced once, reverse-mode
    differentiable); elsewhere (torch.compile, torch.func) the steps unrolled.
    ``iterations`` is then an array: the most steps any mean took (a mean that
    never converged is not reported under tracing).
    """
    log_from, retract = steps
    tol2 = tol * tol

    def body(_, state):
        mean, done, count = state
        step = _average(xp, log_from(mean, g), w, total)
        new = retract(mean, step)
        mean = xp.where(done[..., None], mean, new)
        count = count + xp.where(done, 0.0 * count, 1.0 + 0.0 * count)
        done = done | (xp.sum(step * step, axis=-1) <= tol2)
        return mean, done, count

    first = mean[..., 0]
    state = (mean, first != first, 0.0 * first)  # not done (NaN aside), 0 steps
    if type(g).__module__.startswith("jax"):
        import jax

        mean, _, count = jax.lax.fori_loop(0, max_iter, body, state)
    else:
        for i in range(max_iter):
            state = body(i, state)
        mean, _, count = state
    return mean, xp.max(count)


def lie_steps(compose, inverse, exp, log):
    """The Karcher steps ``(log_from, retract)`` of a group from four of its operations.

    ``compose(a, b)``, ``inverse(a)``, ``exp(tau)`` and ``log(a)`` act on the
    group's stored arrays (``(..., c)``: quaternions, poses, ...) and tangents
    ``(..., dof)``; they are its kernels, or any functions with their signatures.
    ``log_from(mean, g)`` is ``log(mean^-1 g_i)`` for ``mean`` (kept, c) and
    ``g`` (kept, K, c); ``retract(mean, step)`` is ``mean exp(step)``. Every mean
    of every group iterates these (:func:`lie_mean_unchecked`), so the fixed point
    ``sum w_i log(mean^-1 g_i) = 0`` is written once.

    >>> from rigidkit.kernels import quaternion as kq, so3 as ks
    >>> log_from, retract = lie_steps(
    ...     kq.quat_multiply, kq.quat_conjugate, ks.quat_from_rotvec, ks.rotvec_from_quat
    ... )
    >>> q = np.array([[[np.cos(0.1), 0.0, 0.0, np.sin(0.1)]]])  # 0.2 rad about z
    >>> np.round(log_from(np.array([[1.0, 0.0, 0.0, 0.0]]), q), 12)
    array([[[0. , 0. , 0.2]]])
    """

    def log_from(mean, g):
        return log(compose(inverse(mean[..., None, :]), g))

    def retract(mean, step):
        return compose(mean, exp(step))

    return log_from, retract


def _average(xp, x, w, total):
    """Weighted mean over the K axis of x (kept, K, c)."""
    if w is None:
        return xp.sum(x, axis=-2) / x.shape[-2]
    return xp.sum(x * w[..., None], axis=-2) / total[..., None]


def _tol(tol, dtype):
    if tol is not None:
        return float(tol)
    return tolerances(dtype).mean_tol


def _converged(xp, step, tol) -> bool:
    largest = xp.max(xp.sum(step * step, axis=-1))
    return math.sqrt(float(to_numpy(largest))) <= tol  # detached: no autograd warning


def _warn_unconverged(max_iter, tol):
    warnings.warn(
        f"the Karcher mean did not converge to {tol:g} in {max_iter} steps "
        "(the data may be spread over more than a hemisphere); returning the last iterate",
        ConvergenceWarning,
        stacklevel=4,
    )
