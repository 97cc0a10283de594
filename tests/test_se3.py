"""SE(3): rk.se3 (functional) and rk.Transform.

References: scipy.linalg.expm / logm of the 4x4 hat matrix, mpmath at 50+
digits (``mp.expm``, the series ``J_l = sum_k ad^k / (k+1)!`` and the coefficient
definitions), scipy's ``RigidTransform`` (whose exponential coordinates are
ordered ``(w, v)``, ours ``(v, w)``), and closed forms (Murray, Li & Sastry 1994,
Sec. 2.3) written out here with NumPy. (Central finite differences check
every group's Jacobians at once, in ``test_jacobians_fd.py``.)
"""

from __future__ import annotations

import math
import pickle

import mpmath as mp
import numpy as np
import pytest
import scipy.linalg as sl
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import RigidTransform as SciTf
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk
from rigidkit.kernels import coefficients as coef
from rigidkit.kernels import se3 as k_se3

EPS = np.finfo(np.float64).eps
PI = math.pi
BANDS = [0.0, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-3, 0.03, 0.06, 0.5, 1.0, 2.0, 2.5, 3.0]
NEAR_PI = [PI - 1e-6, math.nextafter(PI, 0.0), PI]


def unit(rng, n=None):
    v = rng.standard_normal((3,) if n is None else (n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def twist(rng, theta, n=None, v_scale=1.0):
    """Twists ``(v, w)`` with ``|w| = theta`` and Gaussian ``v``."""
    w = theta * unit(rng, n)
    v = v_scale * rng.standard_normal(w.shape)
    return np.concatenate([v, w], axis=-1)


def hat_np(w):
    w = np.asarray(w, dtype=float)
    z = np.zeros(w.shape[:-1])
    return np.stack(
        [
            np.stack([z, -w[..., 2], w[..., 1]], -1),
            np.stack([w[..., 2], z, -w[..., 0]], -1),
            np.stack([-w[..., 1], w[..., 0], z], -1),
        ],
        -2,
    )


def se3_hat_np(xi):
    xi = np.asarray(xi, dtype=float)
    M = np.zeros(xi.shape[:-1] + (4, 4))
    M[..., :3, :3] = hat_np(xi[..., 3:])
    M[..., :3, 3] = xi[..., :3]
    return M


def to_scipy(T):
    return SciTf.from_matrix(T.as_matrix())


# -- coefficient helpers of Q against mpmath -------------------------------------------

COEFFICIENTS = {
    "cos_defect4": (
        coef.cos_defect4,
        lambda x: (mp.cos(x) - 1 + x**2 / 2) / x**4,
        1.0 / 24.0,
        [0.06, 4.0],
    ),
    "sin_cos_defect5": (
        coef.sin_cos_defect5,
        lambda x: (2 * x - 3 * mp.sin(x) + x * mp.cos(x)) / (2 * x**5),
        1.0 / 120.0,
        [2.5],
    ),
}


@pytest.mark.parametrize("name", sorted(COEFFICIENTS))
def test_coefficient_against_mpmath(name):
    """<= 4 ulp relative from 1e-12 to 8, across each threshold (mpmath at 150 digits)."""
    helper, ref, at0, points = COEFFICIENTS[name]
    xs = set(np.logspace(-12, 0, 30).tolist()) | set(np.linspace(0.05, 8.0, 120).tolist())
    for p in points:
        xs |= {
            p,
            math.nextafter(p, 0.0),
            math.nextafter(p, 9.0),
            p * (1 - 1e-9),
            p * (1 + 1e-9),
        }
    worst = 0.0
    with mp.workdps(150):
        for x in sorted(xs):
            r = ref(mp.mpf(x))
            for s in (1.0, -1.0):
                worst = max(worst, float(abs((mp.mpf(helper(s * x)) - r) / r)))
    assert worst <= 4 * EPS, worst / EPS
    assert abs(helper(0.0) - at0) <= EPS * at0


# -- exp and log -----------------------------------------------------------------------


def mp_exp(xi):
    with mp.workdps(50):
        return np.array(mp.expm(mp.matrix(se3_hat_np(xi).tolist())).tolist(), dtype=float)


@pytest.mark.parametrize("theta", BANDS + NEAR_PI)
def test_exp_against_mpmath(theta, rng):
    """``se3.exp`` within a few ulp of ``expm`` at 50 digits, across every band."""
    for _ in range(3):
        xi = twist(rng, theta)
        ref = mp_exp(xi)
        np.testing.assert_allclose(
            rk.se3.exp(xi), ref, rtol=0, atol=4 * EPS * (1 + np.abs(ref).max())
        )
        np.testing.assert_allclose(
            rk.Transform.exp(xi).as_matrix(),
            ref,
            rtol=0,
            atol=4 * EPS * (1 + np.abs(ref).max()),
        )


@pytest.mark.parametrize("theta", BANDS + NEAR_PI[:2])
def test_log_against_mpmath(theta, rng):
    """``log(exp(xi)) == xi`` with exp from mpmath, so only log is under test.

    The matrix is exact to rounding; log's rotation part goes through the
    quaternion (atan2, no cancellation), its translation through ``J_l^-1``, whose
    norm stays below 1 + pi/2 up to pi. Tolerance 16 eps (1 + |xi|).
    """
    for _ in range(3):
        xi = twist(rng, theta)
        got = rk.se3.log(mp_exp(xi))
        assert np.abs(got - xi).max() <= 16 * EPS * (1 + np.abs(xi).max())


def test_exp_log_against_scipy_expm_logm(rng):
    xi = twist(rng, 0.0, 200) + np.concatenate(
        [np.zeros((200, 3)), unit(rng, 200) * rng.uniform(0, 3.0, (200, 1))], -1
    )
    M = rk.se3.exp(xi)
    np.testing.assert_allclose(M, sl.expm(se3_hat_np(xi)), rtol=0, atol=2e-14)
    logs = np.array([np.real(sl.logm(m)) for m in M[:12]])
    np.testing.assert_allclose(rk.se3.hat(rk.se3.log(M[:12])), logs, rtol=0, atol=1e-11)
    np.testing.assert_allclose(rk.se3.vee(logs), xi[:12], rtol=0, atol=1e-11)


def test_exp_is_the_errata_closed_form(rng):
    """``t = (I - R)(w x v)/|w|^2 + w w^T v / |w|^2``, ``R = exp(hat w)``.

    Murray, Li & Sastry's form (1994, Sec. 2.3.2), which corrects docs/errata.md E4,
    written out here for ``|w|`` in [0.1, 3] (below 0.1 that form itself cancels).
    """
    n = 300
    xi = twist(rng, 1.0, n) * np.concatenate(
        [np.ones((n, 3)), rng.uniform(0.1, 3, (n, 1)) * np.ones((1, 3))], -1
    )
    v, w = xi[:, :3], xi[:, 3:]
    R = SciRot.from_rotvec(w).as_matrix()
    t2 = np.einsum("ni,ni->n", w, w)[:, None]
    t = np.einsum("nij,nj->ni", np.eye(3) - R, np.cross(w, v)) / t2
    t += w * np.einsum("ni,ni->n", w, v)[:, None] / t2
    M = rk.se3.exp(xi)
    np.testing.assert_allclose(M[:, :3, 3], t, rtol=0, atol=1e-14 * 8)
    np.testing.assert_allclose(M[:, :3, :3], R, rtol=0, atol=4 * EPS)
    # The form hat(w) v (I - R) / |w|^2 of docs/errata.md E4 is indeed different.
    wrong = np.einsum("nij,nj->ni", np.eye(3) - R, np.cross(w, v)) / t2
    assert np.abs(M[:, :3, 3] - wrong).max() > 0.1


def test_pure_translations(rng):
    """``w = 0``: ``exp`` is the translation by ``v``, exactly; ``log`` gives it back."""
    v = rng.standard_normal((50, 3)) * 10
    xi = np.concatenate([v, np.zeros((50, 3))], -1)
    M = rk.se3.exp(xi)
    np.testing.assert_array_equal(M[:, :3, :3], np.broadcast_to(np.eye(3), (50, 3, 3)))
    np.testing.assert_array_equal(M[:, :3, 3], v)
    np.testing.assert_array_equal(rk.se3.log(M), xi)
    T = rk.Transform(translation=v)
    np.testing.assert_array_equal(T.log(), xi)
    np.testing.assert_array_equal(T @ np.zeros(3), v)


def test_exp_and_log_at_pi(rng):
    """Exactly pi: ``exp(log(T)) == T``; ``|w| = pi``."""
    xi = twist(rng, PI, 100)
    T = rk.Transform.exp(xi)
    back = T.log()
    np.testing.assert_allclose(
        np.linalg.norm(back[:, 3:], axis=-1), PI, rtol=0, atol=4 * EPS
    )
    np.testing.assert_allclose(
        rk.Transform.exp(back).as_matrix(), T.as_matrix(), atol=4e-15 * 8
    )


def test_translation_of_screw_along_axis():
    """A screw along its own axis is a pure translation of the axis part of ``v``."""
    xi = np.array([0.0, 0.0, 2.0, 0.0, 0.0, PI / 2])
    M = rk.se3.exp(xi)
    np.testing.assert_allclose(M[:3, 3], [0.0, 0.0, 2.0], atol=1e-15)


# -- Jacobians -------------------------------------------------------------------------


def mp_ad(xi):
    v = [mp.mpf(float(c)) for c in xi[:3]]
    w = [mp.mpf(float(c)) for c in xi[3:]]
    W = mp.matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    V = mp.matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    A = mp.zeros(6, 6)
    for i in range(3):
        for j in range(3):
            A[i, j] = W[i, j]
            A[i, j + 3] = V[i, j]
            A[i + 3, j + 3] = W[i, j]
    return A


def mp_left_jacobian(xi, sign=1):
    """``sum_k (sign ad(xi))^k / (k+1)!`` at 60 digits (remainder < 1e-55)."""
    with mp.workdps(60):
        A = sign * mp_ad(xi)
        term = mp.eye(6)
        total = mp.eye(6)
        k = 0
        while True:
            k += 1
            term = term * A / (k + 1)
            total += term
            if mp.mnorm(term, 1) < mp.mpf(10) ** -55:
                return total


def to_np(M):
    return np.array(M.tolist(), dtype=float)


@pytest.mark.parametrize("theta", BANDS + [PI - 1e-6, PI, 4.0])
def test_jacobians_against_series(theta, rng):
    """Closed forms with Barfoot's Q vs the series of ``ad``: <= 8 eps relative."""
    xi = twist(rng, theta)
    cases = [
        (rk.se3.left_jacobian, 1, False),
        (rk.se3.right_jacobian, -1, False),
        (rk.se3.left_jacobian_inverse, 1, True),
        (rk.se3.right_jacobian_inverse, -1, True),
    ]
    for fn, sign, inverse in cases:
        ref = mp_left_jacobian(xi, sign)
        if inverse:
            with mp.workdps(60):
                ref = mp.inverse(ref)
        ref = to_np(ref)
        got = fn(xi)
        np.testing.assert_allclose(got, ref, rtol=0, atol=8 * EPS * np.abs(ref).max())


def _tf_exp(xi):
    """scipy's exp, with its ``(w, v)`` order."""
    return SciTf.from_exp_coords(np.concatenate([xi[..., 3:], xi[..., :3]], -1))


def _tf_log(T):
    e = T.as_exp_coords()
    return np.concatenate([e[..., 3:], e[..., :3]], -1)


# Finite differences of every group's Jacobians: tests/test_jacobians_fd.py.


def test_jacobian_inverse_and_v_matrix(rng):
    """``J J^-1 = I``; diagonal blocks are SO(3)'s; exp's translation is ``J_l(w) v``."""
    xi = twist(rng, 1.0, 300) * np.concatenate(
        [np.ones((300, 3)), rng.uniform(0, 2 * PI - 0.2, (300, 1)) * np.ones((1, 3))], -1
    )
    for J, Ji in (
        (rk.se3.left_jacobian, rk.se3.left_jacobian_inverse),
        (rk.se3.right_jacobian, rk.se3.right_jacobian_inverse),
    ):
        a, b = J(xi), Ji(xi)
        s = np.abs(a).max(axis=(-2, -1)) * np.abs(b).max(axis=(-2, -1))
        err = np.abs(a @ b - np.eye(6)).max(axis=(-2, -1))
        assert np.all(err <= 32 * EPS * s), (err / s).max()
    Jl = rk.se3.left_jacobian(xi)
    np.testing.assert_array_equal(Jl[:, :3, :3], rk.so3.left_jacobian(xi[:, 3:]))
    np.testing.assert_array_equal(Jl[:, 3:, 3:], rk.so3.left_jacobian(xi[:, 3:]))
    np.testing.assert_array_equal(Jl[:, 3:, :3], 0.0)
    t = np.einsum("nij,nj->ni", Jl[:, :3, :3], xi[:, :3])
    np.testing.assert_allclose(rk.se3.exp(xi)[:, :3, 3], t, rtol=0, atol=1e-13)


def test_gradients_finite_at_identity():
    """Autodiff through the torch path at exactly 0: ``d log(exp(d))/dd = I``."""
    torch = pytest.importorskip("torch")
    z = torch.zeros(6, dtype=torch.float64)
    J = torch.autograd.functional.jacobian(lambda d: rk.Transform.exp(d).log(), z)
    np.testing.assert_allclose(J.numpy(), np.eye(6), rtol=0, atol=1e-15)
    # d exp(d)/dd_k at 0 is the k-th generator hat(e_k).
    G = torch.autograd.functional.jacobian(lambda d: rk.Transform.exp(d).as_matrix(), z)
    np.testing.assert_allclose(
        np.moveaxis(G.numpy(), -1, 0), se3_hat_np(np.eye(6)), atol=1e-15
    )


def test_left_jacobian_by_torch_autograd(rng):
    """``J_l(xi) = d/dd log(exp(xi + d) exp(xi)^-1)`` through rigidkit's torch path."""
    torch = pytest.importorskip("torch")
    for theta in (0.0, 1e-5, 1.3, 3.0):
        xi = twist(rng, theta)
        xi_t = torch.tensor(xi)
        T0inv = rk.Transform.exp(xi_t).inv()

        def f(d, xi_t=xi_t, T0inv=T0inv):
            return (rk.Transform.exp(xi_t + d) @ T0inv).log()

        J = torch.autograd.functional.jacobian(f, torch.zeros(6, dtype=torch.float64))
        np.testing.assert_allclose(J.numpy(), rk.se3.left_jacobian(xi), rtol=0, atol=1e-13)


# -- adjoints and the algebra ----------------------------------------------------------


def test_adjoint_closed_form_and_expm_of_ad(rng):
    """``Ad = [[R, hat(t) R], [0, R]]`` (written here) and ``Ad(exp xi) = expm(ad xi)``."""
    T = rk.Transform.random(100, rng)
    R = T.rotation.as_matrix()
    t = T.translation
    ref = np.zeros((100, 6, 6))
    ref[:, :3, :3] = R
    ref[:, 3:, 3:] = R
    ref[:, :3, 3:] = hat_np(t) @ R
    np.testing.assert_allclose(T.adjoint(), ref, rtol=0, atol=1e-15 * 8)
    np.testing.assert_allclose(rk.se3.adjoint(T.as_matrix()), ref, rtol=0, atol=1e-15 * 8)
    xi = twist(rng, 2.0, 100)
    np.testing.assert_allclose(
        rk.Transform.exp(xi).adjoint(), sl.expm(rk.se3.ad(xi)), rtol=0, atol=1e-13
    )


twist_st = st.lists(st.floats(-4, 4, allow_nan=False), min_size=6, max_size=6).map(np.array)


@settings(max_examples=100, deadline=None)
@given(twist_st, twist_st, twist_st)
def test_bracket_ad_and_jacobi_identity(a, b, c):
    """``ad(a) b = [a, b] = vee([hat a, hat b])``, antisymmetric, Jacobi identity."""
    br = rk.se3.bracket
    A, B = se3_hat_np(a), se3_hat_np(b)
    np.testing.assert_allclose(br(a, b), rk.se3.vee(A @ B - B @ A), rtol=0, atol=1e-13)
    np.testing.assert_allclose(rk.se3.ad(a) @ b, br(a, b), rtol=0, atol=1e-13)
    np.testing.assert_array_equal(br(a, b), -br(b, a))
    jac = br(a, br(b, c)) + br(b, br(c, a)) + br(c, br(a, b))
    assert np.abs(jac).max() <= 1e-12


def test_hat_vee():
    xi = np.arange(6.0)
    M = rk.se3.hat(xi)
    np.testing.assert_array_equal(M, se3_hat_np(xi))
    np.testing.assert_array_equal(rk.se3.vee(M), xi)


# -- Transform against scipy's RigidTransform ------------------------------------------


def test_against_scipy_rigid_transform(rng):
    A = rk.Transform.random(500, rng)
    B = rk.Transform.random(500, rng)
    SA, SB = to_scipy(A), to_scipy(B)
    np.testing.assert_allclose(
        (A @ B).as_matrix(), (SA * SB).as_matrix(), rtol=0, atol=1e-14 * 8
    )
    p = rng.standard_normal((500, 3))
    np.testing.assert_allclose(A @ p, SA.apply(p), rtol=0, atol=1e-14 * 8)
    np.testing.assert_allclose(
        A.inv().as_matrix(), SA.inv().as_matrix(), rtol=0, atol=1e-14 * 8
    )
    # Exponential coordinates: scipy's are (w, v), ours (v, w).
    xi = A.log()
    np.testing.assert_allclose(xi, _tf_log(SA), rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        rk.Transform.exp(xi).as_matrix(), _tf_exp(xi).as_matrix(), rtol=0, atol=1e-13
    )
    # One transform on a point cloud, and the components.
    cloud = rng.standard_normal((1000, 3))
    np.testing.assert_allclose(A[3] @ cloud, SA[3].apply(cloud), rtol=0, atol=1e-14 * 8)
    np.testing.assert_allclose(A.translation, SA.translation, rtol=0, atol=1e-15)
    np.testing.assert_allclose(A.rotation.as_matrix(), SA.rotation.as_matrix(), atol=1e-15)


def test_homogeneous_inverse(rng):
    """``G^-1 = [[R^T, -R^T p], [0, 1]]`` (Murray, Li & Sastry 1994, Sec. 2.3.1)."""
    T = rk.Transform.random((4, 25), rng, scale=10.0)
    R = T.rotation.as_matrix()
    t = T.translation
    ref = np.zeros((4, 25, 4, 4))
    Rt = np.swapaxes(R, -1, -2)
    ref[..., :3, :3] = Rt
    ref[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, t)
    ref[..., 3, 3] = 1.0
    np.testing.assert_allclose(T.inv().as_matrix(), ref, rtol=0, atol=1e-13)
    np.testing.assert_allclose(
        T.inv().as_matrix(), np.linalg.inv(T.as_matrix()), atol=1e-13
    )


# -- construction, validation, container protocol --------------------------------------


def test_constructor_combinations(rng):
    R = rk.Rotation.random(2, rng)
    t = rng.standard_normal((3, 1, 3))
    T = rk.Transform(rotation=R, translation=t)
    assert T.shape == (3, 2)
    np.testing.assert_array_equal(T.translation, np.broadcast_to(t, (3, 2, 3)))
    np.testing.assert_array_equal(
        T.rotation.as_quat(), np.broadcast_to(R.as_quat(), (3, 2, 4))
    )
    assert rk.Transform().shape == ()
    np.testing.assert_array_equal(rk.Transform().as_matrix(), np.eye(4))
    only_r = rk.Transform(rotation=R)
    np.testing.assert_array_equal(only_r.translation, np.zeros((2, 3)))
    only_t = rk.Transform(translation=t[0, 0])
    np.testing.assert_array_equal(only_t.rotation.as_quat(), [1.0, 0.0, 0.0, 0.0])
    with pytest.raises(TypeError, match="Rotation"):
        rk.Transform(rotation=np.eye(3))
    with pytest.raises(rk.ShapeError, match="translation"):
        rk.Transform(translation=[1.0, 2.0])
    with pytest.raises(rk.NonFiniteError, match="translation"):
        rk.Transform(translation=[1.0, np.inf, 2.0])


def test_from_matrix_validation(rng):
    T = rk.Transform.random((2, 3), rng)
    M = T.as_matrix()
    np.testing.assert_allclose(
        rk.Transform.from_matrix(M).as_matrix(), M, rtol=0, atol=1e-15 * 4
    )
    bad = M.copy()
    bad[1, 2, 3, 0] = 1e-3
    with pytest.raises(rk.NotARotationError, match=r"batch index \(1, 2\).*bottom row"):
        rk.Transform.from_matrix(bad)
    bad = M.copy()
    bad[0, 1, :3, :3] *= 1.01  # a scaling
    with pytest.raises(rk.NotARotationError, match=r"rotation block.*batch index \(0, 1\)"):
        rk.Transform.from_matrix(bad)
    with pytest.raises(rk.NotARotationError, match=r"reflection"):
        rk.Transform.from_matrix(np.diag([1.0, 1.0, -1.0, 1.0]))
    fixed = rk.Transform.from_matrix(bad, orthonormalize=True)
    np.testing.assert_allclose(fixed.as_matrix()[0, 1], M[0, 1], rtol=0, atol=1e-14)
    bad[0, 0, 3, 3] = 2.0
    with pytest.raises(rk.NotARotationError, match="bottom row"):
        rk.Transform.from_matrix(bad, orthonormalize=True)
    nan = M.copy()
    nan[1, 1, 0, 3] = np.nan
    with pytest.raises(rk.NonFiniteError, match=r"batch index \(1, 1\)"):
        rk.Transform.from_matrix(nan)
    with pytest.raises(rk.ShapeError):
        rk.Transform.from_matrix(np.eye(3))
    with pytest.raises(rk.NotARotationError, match="bottom row"):
        rk.se3.log(np.ones((4, 4)))
    # Tolerance: a matrix 1e-9 off is accepted with the default atol.
    near = M[0, 0] + 1e-9 * rng.standard_normal((4, 4))
    near[3] = [0, 0, 0, 1]
    rk.Transform.from_matrix(near)


def test_container_protocol_and_pickle(rng):
    T = rk.Transform.random((3, 4), rng)
    assert len(T) == 3
    assert T[0].shape == (4,)
    assert T[1:, 2].shape == (2,)
    assert [U.shape for U in T] == [(4,)] * 3
    np.testing.assert_array_equal(T.reshape(12)[5].as_matrix(), T[1, 1].as_matrix())
    np.testing.assert_array_equal(
        T.reshape((4, 3)).as_matrix(), T.as_matrix().reshape(4, 3, 4, 4)
    )
    C = rk.Transform.concatenate([T[0], T[1], T[2, 0]])
    assert C.shape == (9,)
    U = pickle.loads(pickle.dumps(T))
    np.testing.assert_array_equal(U.as_matrix(), T.as_matrix())
    one = T[0, 0]
    with pytest.raises(TypeError):
        len(one)
    with pytest.raises(TypeError):
        one[0]
    assert repr(rk.Transform()) == (
        "Transform(rotation=Rotation.from_quat([1, 0, 0, 0]), translation=[0, 0, 0])"
    )
    # A batch: its shape and dtype, then its values under its components' names
    # (NumPy's summary of them: tests/test_first_hour.py checks the values).
    assert repr(T).startswith(
        "Transform(shape=(3, 4), dtype=float64, (qw, qx, qy, qz, tx, ty, tz)=\n"
    )
    assert isinstance(T, rk.objects.group.LieGroup)
    assert (T.dof, T.matrix_size, T.point_dim) == (6, 4, 3)


def test_approx_equal(rng):
    T = rk.Transform.random(10, rng)
    assert np.all(T.approx_equal(T, atol=1e-15))
    moved = rk.Transform(rotation=T.rotation, translation=T.translation + [1e-7, 0, 0])
    assert not np.any(T.approx_equal(moved))
    assert np.all(T.approx_equal(moved, atol=2e-7))
    turned = T @ rk.Transform.exp([0, 0, 0, 0, 0, 1e-7])
    assert not np.any(T.approx_equal(turned))
    assert np.all(T.approx_equal(turned, atol=2e-7))
    # q and -q are the same rotation.
    neg = rk.Transform(
        rotation=rk.Rotation.from_quat(-T.rotation.as_quat()), translation=T.translation
    )
    assert np.all(T.approx_equal(neg, atol=1e-12))


def test_mixed_composition_with_rotation(rng):
    T = rk.Transform.random(5, rng)
    R = rk.Rotation.random(5, rng)
    TR = T @ R
    RT = R @ T
    assert isinstance(TR, rk.Transform) and isinstance(RT, rk.Transform)
    Rm = np.zeros((5, 4, 4))
    Rm[:, :3, :3] = R.as_matrix()
    Rm[:, 3, 3] = 1.0
    np.testing.assert_allclose(TR.as_matrix(), T.as_matrix() @ Rm, atol=1e-14 * 4)
    np.testing.assert_allclose(RT.as_matrix(), Rm @ T.as_matrix(), atol=1e-14 * 4)
    with pytest.raises(TypeError, match="not defined"):
        np.ones(3) @ T


def test_torch_namespace_dtype_and_device():
    torch = pytest.importorskip("torch")
    xi = torch.tensor([[0.1, -0.2, 0.3, 0.4, 0.5, -0.6]], dtype=torch.float32)
    T = rk.Transform.exp(xi)
    assert isinstance(T._pose, torch.Tensor) and T.dtype == torch.float32
    out = {
        "matrix": T.as_matrix(),
        "log": T.log(),
        "adjoint": T.adjoint(),
        "apply": T @ torch.ones(3, dtype=torch.float32),
        "inv": T.inv().as_matrix(),
        "translation": T.translation,
    }
    for name, a in out.items():
        assert isinstance(a, torch.Tensor) and a.dtype == torch.float32, name
    ref = rk.Transform.exp(xi.numpy().astype(np.float64))
    np.testing.assert_allclose(out["matrix"].numpy(), ref.as_matrix(), rtol=0, atol=1e-6)
    np.testing.assert_allclose(out["log"].numpy(), xi.numpy(), rtol=0, atol=1e-6)
    T2 = rk.Transform(
        rotation=rk.Rotation.from_rotvec(torch.tensor([0.0, 0.0, 1.0])),
        translation=torch.tensor([1.0, 2.0, 3.0]),
    )
    assert isinstance((T2 @ T2).translation, torch.Tensor)
    assert isinstance(rk.Transform(translation=torch.zeros(2, 3))._pose, torch.Tensor)


def test_functional_layer_on_torch():
    torch = pytest.importorskip("torch")
    xi = torch.tensor([[0.3, -0.2, 0.1, 1.0, 2.0, -0.5]], dtype=torch.float64)
    M = rk.se3.exp(xi)
    assert isinstance(M, torch.Tensor)
    np.testing.assert_allclose(rk.se3.log(M).numpy(), xi.numpy(), rtol=0, atol=1e-15 * 8)
    T = rk.Transform.from_matrix(M)
    assert isinstance(T.translation, torch.Tensor)
    bad = M.clone()
    bad[0, 3, 1] = 0.5
    with pytest.raises(rk.NotARotationError, match=r"batch index \(0,\)"):
        rk.Transform.from_matrix(bad)
    for fn in (rk.se3.left_jacobian, rk.se3.right_jacobian_inverse, rk.se3.ad):
        assert isinstance(fn(xi), torch.Tensor)
    assert isinstance(rk.se3.adjoint(M), torch.Tensor)


def test_float32_numpy(rng):
    xi = twist(rng, 2.0, 20).astype(np.float32)
    T = rk.Transform.exp(xi)
    assert T.dtype == np.float32
    assert T.log().dtype == np.float32
    np.testing.assert_allclose(T.log(), xi, rtol=0, atol=2e-6)
    M = rk.Transform.random(5, rng, dtype=np.float32).as_matrix()
    assert M.dtype == np.float32
    assert rk.Transform.from_matrix(M).dtype == np.float32


# -- the kernel backends agree ---------------------------------------------------------


@pytest.mark.parametrize(
    "name, make",
    [
        ("pose_compose", lambda T, U, p, xi: (T._pose, U._pose)),
        ("pose_apply", lambda T, U, p, xi: (T._pose, p)),
        ("pose_inv", lambda T, U, p, xi: (T._pose,)),
        ("pose_from_twist", lambda T, U, p, xi: (xi,)),
        ("twist_from_pose", lambda T, U, p, xi: (T._pose,)),
    ],
)
def test_backends_agree(name, make, rng):
    """numba loop, array-namespace and Python-float bindings of the pose kernels."""
    k = getattr(k_se3, name)
    T, U = rk.Transform.random(64, rng), rk.Transform.random(64, rng)
    p = rng.standard_normal((64, 3))
    xi = twist(rng, 1.0, 64)
    args = make(T, U, p, xi)
    a = k(*args, backend="xp")
    b = k(*args, backend="numba")
    np.testing.assert_allclose(a, b, rtol=0, atol=4 * EPS * (1 + np.abs(a).max()))
    single = [x[7] for x in args]
    c = k(*single, backend="python")
    np.testing.assert_allclose(c, a[7], rtol=0, atol=4 * EPS * (1 + np.abs(a).max()))


def test_sympy_twin_of_exp():
    """The SymPy binding of ``pose_from_twist``, evaluated at 30 digits, is ``expm``."""
    sp = pytest.importorskip("sympy")
    vals = [
        sp.Rational(1, 3),
        sp.Rational(-1, 2),
        sp.Integer(2),
        sp.Rational(3, 10),
        sp.Rational(-2, 5),
        sp.Rational(1, 2),
    ]
    out = k_se3.pose_from_twist.sympy(*vals)
    got = np.array([float(sp.N(e, 30)) for e in out])
    ref = mp_exp(np.array([float(v) for v in vals]))
    R = SciRot.from_quat(got[:4], scalar_first=True).as_matrix()
    np.testing.assert_allclose(R, ref[:3, :3], rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(got[4:], ref[:3, 3], rtol=0, atol=4 * EPS)


def test_compose_into_buffer_matches_scipy():
    """Transform.compose(out=) / Rotation.compose(out=) write into the caller's buffer."""
    from scipy.spatial.transform import RigidTransform

    rng = np.random.default_rng(21)
    for n in (1, 7, 5000):
        A = rk.Transform.random(n, rng)
        B = rk.Transform.random(n, rng)
        buf = np.empty((n, 7))
        C = A.compose(B, out=buf)
        ref = RigidTransform.from_matrix(A.as_matrix()) * RigidTransform.from_matrix(
            B.as_matrix()
        )
        np.testing.assert_allclose(C.as_matrix(), ref.as_matrix(), atol=1e-14)
        assert np.shares_memory(buf, C._pose)
        qbuf = np.empty((n, 4))
        R = A.rotation.compose(B.rotation, out=qbuf)
        np.testing.assert_allclose(R.as_matrix(), ref.rotation.as_matrix(), atol=1e-14)
        assert np.shares_memory(qbuf, R._quat)
