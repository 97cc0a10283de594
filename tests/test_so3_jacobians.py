"""SO(3) calculus: Jacobians, their inverses, the bracket, and the identities of hat.

References: mpmath at 50 digits (the coefficient definitions and the series
``J_l = sum_k hat(w)^k / (k+1)!``), torch autograd through rigidkit's own torch path,
and the identities of the cross product written out with NumPy. (Central finite differences
check every group's Jacobians at once, in ``test_jacobians_fd.py``.)

Convention under test: ``exp(w + d) ~ exp(J_l d) exp(w) ~ exp(w) exp(J_r d)``.
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
import scipy.linalg as sl
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk
from rigidkit.kernels import coefficients as coef

EPS = np.finfo(np.float64).eps
PI = math.pi

# Angles across every threshold the Jacobians meet: sinc and versinc2 switch at
# 0.03 (and at 0.06 for the half-angle forms), sin_defect3 at 2 (4 for half
# angles), plus the 1e-12 ... 1e-4 bands, near pi and, for J^-1, up to 2 pi.
BANDS = [0.0, 1e-300, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-3]
AROUND = [0.0299, 0.03, 0.0301, 0.0599, 0.06, 0.0601, 0.5, 1.0, 1.999, 2.0, 2.001]
NEAR_PI = [PI - 1e-6, math.nextafter(PI, 0.0), PI, PI + 1e-6, 3.9999, 4.0, 4.0001]
ANGLES = BANDS + AROUND + NEAR_PI


def mp_hat(w):
    return mp.matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def mp_left_jacobian(w, sign=1):
    """``sum_k (sign hat(w))^k / (k+1)!`` at 60 digits, to a 1e-55 remainder."""
    with mp.workdps(60):
        W = sign * mp_hat([mp.mpf(float(c)) for c in w])
        term = mp.eye(3)
        total = mp.eye(3)
        k = 0
        while True:
            k += 1
            term = term * W / (k + 1)
            total += term
            if mp.mnorm(term, 1) < mp.mpf(10) ** -55:
                return total


def to_np(M):
    return np.array(M.tolist(), dtype=float)


def unit(rng, n=None):
    v = rng.standard_normal((3,) if n is None else (n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# -- coefficient helpers against mpmath ------------------------------------------------


def _sweep(points):
    xs = set()
    for p in points:
        xs.add(p)
        for k in range(1, 4):
            xs.add(math.nextafter(p, math.inf) if k == 1 else p * (1 + k * 1e-9))
            xs.add(math.nextafter(p, 0.0) if k == 1 else p * (1 - k * 1e-9))
    xs |= set(np.logspace(-12, 0, 25).tolist())
    return sorted(x for x in xs if x > 0)


COEFFICIENTS = {
    # name: (helper, 50-digit definition, where it is finite, points to cross)
    "cot_defect2": (
        coef.cot_defect2,
        lambda x: (1 - (x / 2) * mp.cot(x / 2)) / x**2,
        6.2,
        [0.06, 4.0, PI, 6.0],
    ),
}


@pytest.mark.parametrize("name", sorted(COEFFICIENTS))
def test_coefficient_against_mpmath(name):
    """Relative error <= 4 ulp across the sub-thresholds (0.06, 4) and up to 6.2.

    The definitions cancel catastrophically, so mpmath evaluates them at 150
    digits (100 lost at 1e-12 leaves 50).
    """
    helper, ref, top, points = COEFFICIENTS[name]
    xs = [x for x in _sweep(points) + np.linspace(0.1, top, 60).tolist() if x <= top]
    worst = 0.0
    with mp.workdps(150):
        for x in xs:
            r = ref(mp.mpf(x))
            for s in (1.0, -1.0):  # even functions
                got = helper(s * x)
                worst = max(worst, float(abs((mp.mpf(got) - r) / r)))
    assert worst <= 4 * EPS, worst / EPS
    assert abs(helper(0.0) - 1.0 / 12.0) <= EPS / 12.0


# -- Jacobians against the mpmath series -----------------------------------------------


@pytest.mark.parametrize("theta", ANGLES)
def test_left_and_right_jacobian_against_series(theta, rng):
    w = theta * unit(rng)
    for fn, sign in ((rk.so3.left_jacobian, 1), (rk.so3.right_jacobian, -1)):
        ref = to_np(mp_left_jacobian(w, sign))
        got = fn(w)
        np.testing.assert_allclose(got, ref, rtol=0, atol=4 * EPS)


@pytest.mark.parametrize("theta", ANGLES + [5.0, 6.0, 2 * PI - 0.05])
def test_jacobian_inverses_against_series(theta, rng):
    """``J^-1`` from mpmath's inverse of the series; finite up to 2 pi.

    Its entries grow like ``1/|sinc(t/2)|``, so the bound is relative to them, and
    near the pole at 2 pi the coefficient amplifies the rounding of ``t = |w|``
    (itself ~eps relative) by its condition number ``1 + t / (2 pi - t)``.
    """
    w = theta * unit(rng)
    cond = 1.0 + theta / (2 * PI - theta)
    for fn, sign in (
        (rk.so3.left_jacobian_inverse, 1),
        (rk.so3.right_jacobian_inverse, -1),
    ):
        with mp.workdps(60):
            ref = to_np(mp.inverse(mp_left_jacobian(w, sign)))
        got = fn(w)
        np.testing.assert_allclose(
            got, ref, rtol=0, atol=8 * EPS * cond * np.abs(ref).max()
        )


def test_jacobian_times_inverse_is_identity(rng):
    w = unit(rng, 400) * rng.uniform(0.0, 2 * PI - 0.1, (400, 1))
    for J, Ji in (
        (rk.so3.left_jacobian, rk.so3.left_jacobian_inverse),
        (rk.so3.right_jacobian, rk.so3.right_jacobian_inverse),
    ):
        a, b = J(w), Ji(w)
        scale = np.abs(b).max(axis=(-2, -1), keepdims=True)
        assert np.abs(a @ b - np.eye(3)).max() <= 1e-15 * 8 * scale.max()
        assert np.all(np.abs(b @ a - np.eye(3)) <= 8 * EPS * scale)


def test_structure_of_the_jacobians(rng):
    """``J_r = J_l^T``, ``J_l = R J_r`` and ``J_l w = w`` (the axis is fixed)."""
    w = unit(rng, 100) * rng.uniform(0.0, PI, (100, 1))
    Jl = rk.so3.left_jacobian(w)
    Jr = rk.so3.right_jacobian(w)
    np.testing.assert_allclose(Jr, np.swapaxes(Jl, -1, -2), rtol=0, atol=2 * EPS)
    R = SciRot.from_rotvec(w).as_matrix()
    np.testing.assert_allclose(Jl, R @ Jr, rtol=0, atol=8 * EPS)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", Jl, w), w, rtol=0, atol=8 * EPS)


# -- Jacobians by autodiff (finite differences: tests/test_jacobians_fd.py) -----------


def test_right_jacobian_by_torch_autograd(torch, rng):
    """Autodiff through rigidkit's torch path: ``2 q(w)* dq/dw = (0, J_r(w))``.

    Differentiating ``q(w + d) = q(w) exp((J_r d) / 2)`` at ``d = 0``.
    """
    for theta in (1e-6, 0.7, 2.9):
        w = theta * unit(rng)

        def quat(v):
            return rk.Rotation.exp(v).as_quat()

        w_t = torch.tensor(w)
        dq = torch.autograd.functional.jacobian(quat, w_t).numpy()  # (4, 3)
        q = quat(w_t).detach().numpy()
        # Rows 1..3 of the Hamilton product q* (x) dq_k, column by column.
        qw, qv = q[0], q[1:]
        vec = qw * dq[1:] - qv[:, None] * dq[0] - np.cross(qv, dq[1:].T).T
        np.testing.assert_allclose(2 * vec, rk.so3.right_jacobian(w), rtol=0, atol=1e-14)
        np.testing.assert_allclose(qw * dq[0] + qv @ dq[1:], 0.0, atol=1e-15)


# -- identities of the cross product and hat --------------------------------------------


vec = st.lists(st.floats(-10, 10, allow_nan=False), min_size=3, max_size=3).map(np.array)


@settings(max_examples=100, deadline=None)
@given(vec, vec, vec)
def test_jacobi_identity_and_double_cross_product(a, b, c):
    """Jacobi, ``a x (b x c) = b (a.c) - c (a.b)``, ``[hat a, hat b] = hat(a x b)``."""
    br = rk.so3.bracket
    jacobi = br(a, br(b, c)) + br(b, br(c, a)) + br(c, br(a, b))
    size = (1 + np.abs(a).max()) * (1 + np.abs(b).max()) * (1 + np.abs(c).max())
    assert np.abs(jacobi).max() <= 16 * EPS * size
    np.testing.assert_allclose(
        br(a, br(b, c)), b * (a @ c) - c * (a @ b), rtol=0, atol=16 * EPS * size
    )
    A, B = rk.so3.hat(a), rk.so3.hat(b)
    np.testing.assert_allclose(
        A @ B - B @ A, rk.so3.hat(np.cross(a, b)), rtol=0, atol=16 * EPS * size
    )
    # ad(a) b = [a, b] = a x b, against NumPy's cross product.
    np.testing.assert_allclose(
        rk.so3.ad(a) @ b, np.cross(a, b), rtol=0, atol=4 * EPS * size
    )


def test_conjugated_hat_and_hat_squared(rng):
    """``(R w)^ = R hat(w) R^T`` and ``hat(w)^2 = w w^T - |w|^2 I``."""
    w = rng.standard_normal((200, 3)) * 3.0
    R = SciRot.random(200, random_state=1).as_matrix()
    Rw = np.einsum("nij,nj->ni", R, w)
    W = rk.so3.hat(w)
    np.testing.assert_allclose(rk.so3.hat(Rw), R @ W @ np.swapaxes(R, -1, -2), atol=1e-14)
    outer = w[:, :, None] * w[:, None, :]
    sq = np.einsum("ni,ni->n", w, w)[:, None, None] * np.eye(3)
    np.testing.assert_allclose(W @ W, outer - sq, rtol=0, atol=4 * EPS * sq.max())
    # The adjoint of SO(3) is R itself: R exp(w) R^T = exp(R w).
    lhs = R @ rk.so3.exp(w) @ np.swapaxes(R, -1, -2)
    np.testing.assert_allclose(
        lhs, rk.so3.exp(np.einsum("nij,nj->ni", rk.so3.adjoint(R), w)), rtol=0, atol=1e-14
    )


def test_exp_log_against_scipy_expm_logm(rng):
    """``so3.exp = expm(hat)`` and ``hat(so3.log(R)) = logm(R)`` (angles below pi)."""
    w = unit(rng, 100) * rng.uniform(0.0, 3.0, (100, 1))
    R = rk.so3.exp(w)
    np.testing.assert_allclose(R, sl.expm(rk.so3.hat(w)), rtol=0, atol=1e-14)
    logs = np.array([np.real(sl.logm(m)) for m in R[:10]])
    np.testing.assert_allclose(rk.so3.hat(rk.so3.log(R[:10])), logs, rtol=0, atol=1e-12)


# -- batches, dtypes, errors -----------------------------------------------------------


def test_batches_dtypes_and_namespaces(rng):
    w = rng.standard_normal((2, 5, 3))
    for fn in (
        rk.so3.left_jacobian,
        rk.so3.right_jacobian,
        rk.so3.left_jacobian_inverse,
        rk.so3.right_jacobian_inverse,
    ):
        assert fn(w).shape == (2, 5, 3, 3)
        assert fn(np.zeros((0, 3))).shape == (0, 3, 3)
        assert fn(w[0, 0]).shape == (3, 3)
        f32 = fn(w.astype(np.float32))
        assert f32.dtype == np.float32
        np.testing.assert_allclose(f32, fn(w), rtol=0, atol=2e-6 * np.abs(fn(w)).max())
    assert rk.so3.bracket(w, w[0, 0]).shape == (2, 5, 3)


def test_torch_in_torch_out(torch, rng):
    w = rng.standard_normal((2, 5, 3))
    t = rk.so3.left_jacobian(torch.tensor(w, dtype=torch.float32))
    assert isinstance(t, torch.Tensor) and t.dtype == torch.float32
    np.testing.assert_allclose(
        t.numpy(), rk.so3.left_jacobian(w), rtol=0, atol=2e-6 * np.abs(t.numpy()).max()
    )


def test_bad_input_raises():
    with pytest.raises(rk.ShapeError, match="rotation vector"):
        rk.so3.left_jacobian(np.zeros((2, 4)))
    with pytest.raises(rk.NonFiniteError, match=r"batch index \(1,\)"):
        rk.so3.right_jacobian_inverse([[0.0, 0.0, 0.0], [np.nan, 0.0, 0.0]])
