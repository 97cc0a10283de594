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

import functools
import math
import warnings

import numpy as np  # noqa: F401  (the doctests' namespace)

from .._engine.traced_loops import compiled_while, needs_grad, torch_compiling
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
    """The Karcher iteration without reading values: each mean frozen (``where``)
    once its own step is below ``tol``, as the eager loop stops.

    On JAX a ``lax.while_loop`` that stops when every mean has converged (or at
    ``max_iter``), differentiated implicitly (:func:`_karcher_jax`); elsewhere
    (torch.compile, torch.func) ``max_iter`` steps unrolled, differentiated
    through. ``iterations`` is then an array: the most steps any mean took (a
    mean that never converged is not reported under tracing).
    """
    if type(g).__module__.startswith("jax"):
        return _karcher_jax(xp, mean, g, w, total, tol, max_iter, steps)
    if torch_compiling(mean, g) and not needs_grad(mean, g, w, total):
        return _karcher_torch_while(xp, mean, g, w, total, tol, max_iter, steps)
    first = mean[..., 0]
    state = (mean, first != first, 0.0 * first)  # not done (NaN aside), 0 steps
    for _ in range(max_iter):
        state = _frozen_step(xp, steps, g, w, total, tol * tol, state)
    mean, _, count = state
    return mean, xp.max(count)


def _karcher_torch_while(xp, mean, g, w, total, tol, max_iter, steps):
    """:func:`karcher_traced` inside ``torch.compile`` without gradients: one
    ``while_loop`` node that stops when every mean has converged (the unrolled
    ``max_iter`` steps took Inductor 750 s to compile)."""
    first = mean[..., 0]
    zero = 0.0 * xp.max(first)  # a 0-d step counter of the dtype and device

    def more(mean, done, count, i):
        return (i < max_iter) & ~xp.all(done)

    def body(mean, done, count, i):
        state = _frozen_step(xp, steps, g, w, total, tol * tol, (mean, done, count))
        return (*state, i + 1.0)

    state = (mean, first != first, 0.0 * first, zero)  # not done (NaN aside), 0 steps
    mean, _, count, _ = compiled_while(more, body, state)
    return mean, xp.max(count)


def _frozen_step(xp, steps, g, w, total, tol2, state):
    """One Karcher step of ``(mean, done, count)``: each mean moves and counts the
    step until its own step is below ``sqrt(tol2)``, then stays (``where``)."""
    log_from, retract = steps
    mean, done, count = state
    step = _average(xp, log_from(mean, g), w, total)
    mean = xp.where(done[..., None], mean, retract(mean, step))
    count = count + xp.where(done, 0.0 * count, 1.0 + 0.0 * count)
    done = done | (xp.sum(step * step, axis=-1) <= tol2)
    return mean, done, count


def _karcher_jax(xp, mean, g, w, total, tol, max_iter, steps):
    """:func:`karcher_traced` on JAX: the fixed point found without derivatives,
    differentiated implicitly (the implicit function theorem).

    The iteration is a ``lax.while_loop``, so it stops when every mean has
    converged (a handful of steps, not ``max_iter``), and nothing differentiates
    through it (a while loop has no reverse mode; a scan of ``max_iter`` steps
    had, at ``max_iter`` steps' cost). Its derivative is a ``custom_jvp``: the
    mean ``mu`` solves ``F(mu, X, w) = sum w_i log(mu^-1 X_i) / sum w_i = 0``, so
    a tangent ``dX, dw`` moves it by ``mu exp(delta)`` with ``H delta = -dF``,
    ``H = dF(mu exp(delta))/d delta`` at 0 (forward mode, one column a tangent
    direction) and ``dF`` the derivative of ``F`` along ``dX, dw`` at fixed
    ``mu``. Linear in the tangents, so reverse mode transposes it. Exact at the
    fixed point; at the converged iterate (mean log below ``tol``) to first order
    in what is left of the mean log. ``H`` is formed only when derivatives are
    taken: ``jit`` of the mean alone compiles the loop only.
    """
    import jax
    import jax.numpy as jnp

    log_from, retract = steps

    def residual(mu, g, w, total):
        return _average(xp, log_from(mu, g), w, total)

    def solve(mu, g, w, total):
        def body(state):
            *state, i = state
            return (*_frozen_step(xp, steps, g, w, total, tol * tol, state), i + 1)

        def more(state):
            return (state[3] < max_iter) & ~jnp.all(state[1])

        first = mu[..., 0]
        state = (mu, first != first, 0.0 * first, 0)  # not done (NaN aside), 0 steps
        mu, _, count, _ = jax.lax.while_loop(more, body, state)
        return mu, count

    @jax.custom_jvp
    def fixed_point(mu0, g, w, total):
        return solve(mu0, g, w, total)

    @fixed_point.defjvp
    def fixed_point_jvp(primals, tangents):
        mu0, g, w, total = primals
        _, dg, dw, dtotal = tangents
        mu, count = solve(mu0, g, w, total)
        F = functools.partial(residual, mu)
        dF = jax.jvp(F, (g, w, total), (dg, dw, dtotal))[1]
        zero = jnp.zeros_like(dF)

        def column(direction):  # H's column along one tangent direction
            moved = functools.partial(retract, mu)
            return jax.jvp(
                lambda d: residual(moved(d), g, w, total),
                (zero,),
                (jnp.broadcast_to(direction, zero.shape),),
            )[1]

        basis = jnp.eye(dF.shape[-1], dtype=dF.dtype)
        H = jax.vmap(column, out_axes=-1)(basis)  # the directions in one pass
        delta = -jnp.linalg.solve(H, dF[..., None])[..., 0]
        dmu = jax.jvp(functools.partial(retract, mu), (zero,), (delta,))[1]
        return (mu, count), (dmu, jnp.zeros_like(count))

    mu, count = fixed_point(mean, g, w, total)
    return mu, xp.max(count)


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
