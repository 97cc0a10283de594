"""Splines on SO(3) and SE(3), arrays in and out: the C2 rotation spline and
cumulative cubic B-splines.

Quaternions are Hamilton, scalar first; poses ``(w, x, y, z, tx, ty, tz)``; twists
``(v, w)``. Rates are body-frame here (``R^T dR/dt``, ``T^-1 dT/dt``); the object
layer maps them to the world frame. Keyframes and control points carry the time
(knot) axis first, then any batch axes, so one call builds many splines that
share their times. Written against the array API (namespace of the input). The
knot times are NumPy (concrete: they select the segment of each query); the
keyframes, control points and query times may be traced (``jax.jit``, ``vmap``,
``grad``, ``torch.func``): the Newton solve of the rotation spline then runs a
fixed number of steps, each frozen (``where``) once the eager convergence test
is met (:func:`rotation_spline_coefficients`). Dask keyframes
stay lazy: the spline solve couples all keyframes, so the time axis is made whole
(one chunk) and each chunk of the further batch axes is solved on its own
(:func:`rotation_spline_coefficients`); evaluation gathers segments lazily.

Rotation spline (scipy's ``RotationSpline``): between keyframes ``R_i`` and
``R_{i+1}``, ``R(t) = R_i exp(hat(r(t - t_i)))`` with ``r(s) = a s^3 + b s^2 + c s``,
a cubic rotation vector; the rates at the knots are those for which the angular
acceleration is continuous (solved by Newton's method to rounding, where scipy
stops after 10 fixed-point steps), with the end rates ``theta_0 / h_0`` and
``theta_{n-2} / h_{n-2}`` (scipy's choice).

Cumulative cubic B-spline (Kim, Kim and Shin 1995; Sommer et al. 2020), uniform
knots ``t0 + k dt``: on ``[t0 + s dt, t0 + (s+1) dt)``, ``u`` in [0, 1),
``X(t) = X_s prod_{j=1..3} exp(l_j(u) d_{s+j})`` with ``d_k = log(X_{k-1}^-1 X_k)``
and the cumulative basis ``l_1 = (5 + 3u - 3u^2 + u^3)/6``,
``l_2 = (1 + 3u + 3u^2 - 2u^3)/6``, ``l_3 = u^3/6``. With ``A_j = exp(l_j d_j)`` the
body velocity and its derivative follow the recursion
``w_j = Ad(A_j^-1) w_{j-1} + l_j' d_j`` and
``w_j' = Ad(A_j^-1) w_{j-1}' + l_j'' d_j + [w_j, l_j' d_j]`` (exact, no
differencing).
"""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import device_of, namespace_of
from .._engine.traced_loops import compiled_while, torch_compiling
from .._validate import concrete, tolerances
from ..errors import ConvergenceWarning
from ..kernels import quaternion as _kq
from ..kernels import se3 as _kse3
from ..kernels import so3 as _kso3
from ._block_tridiagonal import matvec as _matvec
from ._block_tridiagonal import solve_block_tridiagonal

__all__ = [
    "rotation_spline_coefficients",
    "rotation_spline_eval",
    "bspline_basis",
    "bspline_so3_eval",
    "bspline_se3_eval",
]


def _const(xp, values, like):
    return xp.asarray(values, dtype=like.dtype, device=device_of(like))


def _expand(h, ndim):
    """``h`` of shape (m,) reshaped to (m, 1, ..., 1) for ``ndim`` trailing axes."""
    return h.reshape((h.shape[0],) + (1,) * ndim)


def _relative_rotvecs(quats):
    """``log(R_k^-1 R_{k+1})`` of consecutive keyframes (n, ..., 4) -> (n - 1, ..., 3)."""
    return _kso3.rotvec_from_quat(
        _kq.quat_multiply(_kq.quat_conjugate(quats[:-1]), quats[1:])
    )


def _nonlinear(theta, rdot):
    """The ``(dJ_r/dt) r'`` term of the angular acceleration (``r'' = 0``)."""
    return _kso3.body_acceleration_from_rotvec_rates(theta, rdot, rdot * 0.0)


def rotation_spline_coefficients(times, quats, *, max_iter=50):
    """Cubic coefficients of the C2 rotation spline through keyframes.

    Parameters
    ----------
    times : ndarray, shape (n,)
        Strictly increasing knot times, ``n >= 2`` (checked by the caller).
    quats : array, shape (n, ..., 4)
        Unit keyframe quaternions, time axis first.
    max_iter : int
        Newton steps at most; the solve stops once a step changes no rate by more
        than 16 ulp of the largest rate.

    Returns
    -------
    coeffs : array, shape (n - 1, ..., 3, 3)
        ``(a, b, c)`` of each segment, ``r(s) = a s^3 + b s^2 + c s``.
    iterations : int
        Newton steps taken (0 for two keyframes); a 0-d integer array where the
        keyframes are traced (:func:`_newton_traced`: ``max_iter`` steps, the
        rates frozen once converged).

    Notes
    -----
    Dask keyframes stay lazy: the time axis is made whole (one chunk: the solve
    couples all keyframes) and each chunk of the further batch axes (one spline
    each) is solved on its own, testing convergence per chunk; ``iterations`` is
    then a 0-d Dask array (the most steps of any chunk).
    """
    if dask_backend.any_dask(quats):
        return _lazy_coefficients(times, quats, max_iter)
    xp = namespace_of(quats)
    n = quats.shape[0]
    theta = _relative_rotvecs(quats)
    hn = np.diff(np.asarray(times, dtype=np.float64))
    h = _expand(_const(xp, hn, theta), theta.ndim - 1)
    rates = theta / h  # per segment: the initial rate guess (scipy's)
    omega = [rates[0]] + [rates[k] for k in range(1, n - 1)] + [rates[n - 2]]
    iterations = 0
    if n > 2:
        jr = _kso3.left_jacobian(-theta)  # J_r(theta) = J_l(-theta)
        jr_inv = _kso3.left_jacobian_inverse(-theta)
        eye = _const(xp, np.eye(3), theta)
        m = n - 2
        # Equation e (interior knot k = e + 1), linear part:
        # 2/h0 J_r(th0) w_{k-1} + 4 (1/h0 + 1/h1) w_k + 2/h1 J_r^-1(th1) w_{k+1}.
        h0, h1 = h[:-1], h[1:]
        lower = 2.0 / h0[..., None] * jr[:-1]
        upper = 2.0 / h1[..., None] * jr_inv[1:]
        center = 4.0 * (1.0 / h0 + 1.0 / h1)[..., None] * eye
        beta = 6.0 * (theta[:-1] / (h0 * h0) + theta[1:] / (h1 * h1))
        w = xp.stack(omega[1:-1], axis=0)
        first, last = omega[0], omega[-1]

        params = (theta[:-1], jr_inv[:-1], lower, center, upper, beta, first, last)
        done = tolerances(theta.dtype).newton_rtol
        if concrete(theta):
            w, iterations = _newton_eager(xp, params, w, rates, done, max_iter)
        else:  # traced (jit, vmap, grad, torch.compile, torch.func)
            w, iterations = _newton_traced(xp, params, w, rates, done, max_iter)
        omega = [first] + [w[e] for e in range(m)] + [last]
    full = xp.stack(omega, axis=0)
    c = full[:-1]
    d = _matvec(
        _kso3.left_jacobian_inverse(-theta), full[1:]
    )  # r'(h) = J_r^-1(theta) w_{i+1}
    a = (-2.0 * theta + h * c + h * d) / (h * h * h)
    b = (3.0 * theta - 2.0 * h * c - h * d) / (h * h)
    return xp.stack([a, b, c], axis=-2), iterations


def _newton_step(xp, params, w):
    """One Newton step of the spline equations on the interior rates ``w``:
    ``(w - step, step)``; ``params`` are the equations' fixed parts."""
    theta, jr_inv, lower, center, upper, beta, first, last = params
    full = xp.concat([first[None], w, last[None]], axis=0)
    rdot = _matvec(jr_inv, full[1:-1])  # r'(h) at the end of segment k-1
    base = _nonlinear(theta, rdot)
    res = (
        _matvec(lower, full[:-2])
        + _matvec(center, full[1:-1])
        + _matvec(upper, full[2:])
        + base
        - beta
    )
    # N(theta, r') is quadratic in r', so its derivative along e is exactly
    # (N(r' + s e) - N(r') - N(s e)) / s: a polarisation, not a difference.
    s = 1.0 + xp.max(xp.abs(rdot))
    cols = []
    for k in range(3):
        e = _const(xp, np.eye(3)[k], theta) * s
        dn = _nonlinear(theta, rdot + e) - base - _nonlinear(theta, e)
        cols.append(dn / s)
    g = xp.stack(cols, axis=-1) @ jr_inv
    step = solve_block_tridiagonal(xp, lower, center + g, upper, res)
    return w - step, step


def _newton_eager(xp, params, w, rates, done, max_iter):
    """Newton steps until one changes no rate by more than ``done`` times the
    largest rate, or stops contracting at rounding level; ``(w, steps taken)``."""
    scale = float(xp.max(xp.abs(rates)))
    prev = math.inf
    for iterations in range(1, max_iter + 1):  # noqa: B007 (the count is returned)
        w, step = _newton_step(xp, params, w)
        size = float(xp.max(xp.abs(step)))
        ref = max(float(xp.max(xp.abs(w))), scale, 1e-300)
        # Done at rounding level, or when Newton stops contracting there.
        if size <= done * ref or (size > 0.5 * prev and size < 1e-8 * ref):
            return w, iterations
        prev = size
    warnings.warn(
        f"the rotation spline solve did not converge in {max_iter} Newton steps "
        f"(last step {size:.3g}); the spline is C2 only to that level",
        ConvergenceWarning,
        stacklevel=4,
    )
    return w, max_iter


def _newton_traced(xp, params, w, rates, done, max_iter):
    """:func:`_newton_eager` without reading values; ``iterations`` is then a 0-d
    array. No warning is given for a solve that did not converge (its values
    cannot be read).

    On JAX one ``lax.while_loop`` to the eager test (per spline under ``vmap``),
    on values cut from the gradient (``stop_gradient``), then one more Newton step
    on the live equations: at the solution that step's derivative is the
    implicit one, ``-F_w^-1 dF`` (the implicit function theorem; Newton's step
    at a root), so ``grad`` needs no differentiation of the loop. Inside
    ``torch.compile`` the same with torch's ``while_loop``
    (:mod:`rigidkit._engine.traced_loops`). Under torch.func ``max_iter`` steps
    unrolled, each spline's rates frozen (``where``) from the step that meets the
    eager test on.
    """
    zero = 0.0 * xp.max(xp.abs(rates))
    state = (w, zero != zero, zero + math.inf, zero)  # not stopped (NaN aside)
    if type(w).__module__.startswith("jax"):
        import jax

        cut = jax.tree_util.tree_map(jax.lax.stop_gradient, (params, w, rates))
        fixed, w0, scale = cut[0], cut[1], xp.max(xp.abs(cut[2]))

        def go(state):
            return ~state[1] & (state[3] < max_iter)

        def step(state):
            return _newton_update(xp, fixed, done, scale, state, freeze=False)

        w, _, _, count = jax.lax.while_loop(go, step, (w0,) + state[1:])
        w = _newton_step(xp, params, jax.lax.stop_gradient(w))[0]
        return w, count
    if torch_compiling(w):  # the same: torch's while_loop node (it has no backward)
        fixed, w0, cut = _detached((params, w, rates))
        scale = xp.max(xp.abs(cut))

        def go(*state):
            return ~state[1] & (state[3] < max_iter)

        def step(*state):
            return _newton_update(xp, fixed, done, scale, state, freeze=False)

        w, _, _, count = compiled_while(go, step, (w0,) + state[1:])
        return _newton_step(xp, params, w)[0], count
    scale = xp.max(xp.abs(rates))
    for _ in range(max_iter):
        state = _newton_update(xp, params, done, scale, state, freeze=True)
    return state[0], state[3]


def _detached(x):
    """Tensors (in nested tuples) cut from autograd's graph, as copies: the
    while_loop node refuses inputs that alias each other (the end rates are views
    of one tensor)."""
    if isinstance(x, (tuple, list)):
        return type(x)(_detached(a) for a in x)
    return x.detach().clone()


def _newton_update(xp, params, done, scale, state, freeze):
    """One step of :func:`_newton_traced`: ``(w, stopped, last size, steps)``."""
    w, stop, prev, count = state
    new, step = _newton_step(xp, params, w)
    size = xp.max(xp.abs(step))
    ref = xp.maximum(xp.maximum(xp.max(xp.abs(new)), scale), 1e-300 + 0.0 * scale)
    met = (size <= done * ref) | ((size > 0.5 * prev) & (size < 1e-8 * ref))
    if not freeze:
        return new, met, size, count + 1.0
    w = xp.where(stop, w, new)
    count = xp.where(stop, count, count + 1.0)
    prev = xp.where(stop, prev, size)
    return w, stop | met, prev, count


def _lazy_coefficients(times, quats, max_iter):
    import dask.array as da

    block = functools.partial(_coefficients_block, np.asarray(times), max_iter)
    n = quats.shape[0]
    coeffs, iterations = dask_backend.map_batched(
        block, [da.moveaxis(quats, 0, -2)], [2],
        outputs=[((n - 1, 3, 3), quats.dtype), ((), np.int64)],
    )  # fmt: skip
    return da.moveaxis(coeffs, -3, 0), iterations.max()


def _coefficients_block(times, max_iter, quats):
    """One chunk of splines, time axis second to last (as :func:`map_batched` wants)."""
    coeffs, k = rotation_spline_coefficients(
        times, np.moveaxis(quats, -2, 0), max_iter=max_iter
    )
    return np.moveaxis(coeffs, 0, -3), np.full(quats.shape[:-2], k, dtype=np.int64)


def rotation_spline_eval(times, quats, coeffs, query, order):
    """Evaluate the rotation spline (see :func:`rotation_spline_coefficients`).

    Parameters
    ----------
    times : ndarray, shape (n,)
    quats : array, shape (n, ..., 4)
    coeffs : array, shape (n - 1, ..., 3, 3)
    query : ndarray, shape (q,)
        Within ``[times[0], times[-1]]`` (checked by the caller).
    order : {0, 1, 2}

    Returns
    -------
    array, shape (q, ..., 4) for order 0, else (q, ..., 3)
        Quaternions, body angular velocity or body angular acceleration.
    """
    from .interpolation import meet, segment_index, take_rows

    query = meet(query, quats)  # NumPy times meet the keyframes' namespace
    quats, coeffs = meet(quats, query), meet(coeffs, query)  # and the other way
    idx = segment_index(times, query)
    tau = query - take_rows(np.asarray(times, dtype=np.float64), idx)
    cf = take_rows(coeffs, idx)
    s = _expand(_astype(tau, coeffs), cf.ndim - 2)
    a, b, c = cf[..., 0, :], cf[..., 1, :], cf[..., 2, :]
    r = ((a * s + b) * s + c) * s
    if order == 0:
        q = take_rows(quats, idx)
        return _kq.quat_multiply(q, _kso3.quat_from_rotvec(r))
    rdot = (3.0 * a * s + 2.0 * b) * s + c
    if order == 1:
        return _kso3.body_rate_from_rotvec_rate(r, rdot)
    return _kso3.body_acceleration_from_rotvec_rates(r, rdot, 6.0 * a * s + 2.0 * b)


def _astype(x, like):
    """``x`` with the dtype of ``like`` (one namespace)."""
    if x.dtype == like.dtype:
        return x
    if hasattr(x, "to") and not hasattr(x, "astype"):  # torch
        return x.to(like.dtype)
    return x.astype(like.dtype)


def bspline_basis(u):
    """Cumulative cubic B-spline basis ``l_1, l_2, l_3`` at ``u`` and its derivatives.

    Parameters
    ----------
    u : array, shape (...)
        Position in the segment, in [0, 1].

    Returns
    -------
    tuple of three arrays, shape (..., 3)
        ``l``, ``dl/du``, ``d2l/du2`` (``l_0 = 1`` is omitted).

    >>> l, dl, ddl = bspline_basis(np.array(0.0))
    >>> l * 6.0, dl, ddl
    (array([5., 1., 0.]), array([0.5, 0.5, 0. ]), array([-1.,  1.,  0.]))
    """
    xp = namespace_of(u)
    u2 = u * u
    u3 = u2 * u
    sixth = 1.0 / 6.0
    l = xp.stack(
        [
            (5.0 + 3.0 * u - 3.0 * u2 + u3) * sixth,
            (1.0 + 3.0 * u + 3.0 * u2 - 2.0 * u3) * sixth,
            u3 * sixth,
        ],
        axis=-1,
    )
    v = 1.0 - u
    dl = xp.stack([0.5 * v * v, 0.5 + u - u2, 0.5 * u2], axis=-1)
    ddl = xp.stack([u - 1.0, 1.0 - 2.0 * u, u], axis=-1)
    return l, dl, ddl


def _bspline_setup(n, dt, t0, query, like):
    """Namespace, segment and position of each query; ``like`` met by the query."""
    from .interpolation import meet, uniform_segment

    query = meet(query, like)
    like = meet(like, query)
    seg, u = uniform_segment((query - t0) / dt, n - 3)
    return like, seg, _astype(u, like)


def bspline_so3_eval(quats, dt, t0, query, order):
    """Evaluate a cumulative cubic B-spline on SO(3) (see the module doc).

    Parameters
    ----------
    quats : array, shape (n, ..., 4)
        Control rotations, unit quaternions, ``n >= 4``; knot spacing ``dt``.
    dt, t0 : float
    query : ndarray, shape (q,)
        Within ``[t0, t0 + (n - 3) dt]`` (checked by the caller).
    order : {0, 1, 2}

    Returns
    -------
    array, shape (q, ..., 4) for order 0, else (q, ..., 3)
        Quaternions, body angular velocity (rad per time unit) or acceleration.
    """
    quats, seg, u = _bspline_setup(quats.shape[0], dt, t0, query, quats)
    d_all = _relative_rotvecs(quats)
    return _cumulative_eval(quats, d_all, seg, u, dt, order, _SO3_OPS)


def bspline_se3_eval(poses, dt, t0, query, order):
    """Evaluate a cumulative cubic B-spline on SE(3) (see the module doc).

    As :func:`bspline_so3_eval` with poses ``(n, ..., 7)``; the rates are body
    twists ``(v, w)`` (``T^-1 dT/dt``) and their derivatives.
    """
    poses, seg, u = _bspline_setup(poses.shape[0], dt, t0, query, poses)
    d_all = _kse3.twist_from_pose(_kse3.pose_compose(_kse3.pose_inv(poses[:-1]), poses[1:]))
    return _cumulative_eval(poses, d_all, seg, u, dt, order, _SE3_OPS)


def _cumulative_eval(ctrl, d_all, seg, u, dt, order, ops):
    """The B-spline value or body rate of the module doc, on one group.

    ``ctrl`` are the control elements (n, ..., k), ``d_all`` their relative
    tangents ``log(X_{k-1}^-1 X_k)``, ``seg`` and ``u`` the segment and position of
    each query (:func:`_bspline_setup`). ``ops`` are the group's ``(exp, compose,
    inverse_adjoint, apply_adjoint, bracket)``: ``apply_adjoint(inverse_adjoint(A),
    w) = Ad(A^-1) w``, the inverse formed once per factor.
    """
    exp, compose, inverse_adjoint, apply_adjoint, bracket = ops
    u = _expand(u, ctrl.ndim - 2)
    l, dl, ddl = bspline_basis(u)
    x = ctrl[seg]
    w = dw = None
    for j in range(3):
        d = d_all[seg + j]
        a = exp(l[..., j : j + 1] * d)
        x = compose(x, a)
        if order == 0:
            continue
        vel = dl[..., j : j + 1] * d
        if w is None:
            w, dw = vel, ddl[..., j : j + 1] * d
            continue
        ad_inv = inverse_adjoint(a)
        w = apply_adjoint(ad_inv, w) + vel
        dw = apply_adjoint(ad_inv, dw) + ddl[..., j : j + 1] * d + bracket(w, vel)
    if order == 0:
        return x
    return w / dt if order == 1 else dw / (dt * dt)


def _pose_inverse_adjoint(pose):
    return _kse3.adjoint_from_pose(_kse3.pose_inv(pose))


# (exp, compose, inverse_adjoint, apply_adjoint, bracket) of :func:`_cumulative_eval`;
# on SO(3) ``Ad(A^-1)`` is the rotation ``A^-1``, kept as the conjugate quaternion.
_SO3_OPS = (
    _kso3.quat_from_rotvec,
    _kq.quat_multiply,
    _kq.quat_conjugate,
    _kq.quat_apply,
    _kso3.bracket,
)
_SE3_OPS = (
    _kse3.pose_from_twist,
    _kse3.pose_compose,
    _pose_inverse_adjoint,
    _matvec,
    _kse3.bracket,
)
