"""SO(2) / SE(2): rk.so2, rk.se2, rk.Rotation2D, rk.Transform2D.

References: closed forms written here with numpy, scipy.linalg.expm / logm /
expm_frechet of the hat matrices, mpmath at 50 digits, central finite
differences, the group axioms, and the 3D classes restricted to the plane.
"""

import math
import pickle

import mpmath as mp
import numpy as np
import pytest
import scipy.linalg as sl
from hypothesis import given, settings
from hypothesis import strategies as st

import rigidkit as rk
from rigidkit.kernels import se2 as k_se2
from rigidkit.kernels import so2 as k_so2
from rigidkit.objects.group import LieGroup

GROUPS = [rk.Rotation2D, rk.Transform2D]
HAT = {rk.Rotation2D: rk.so2.hat, rk.Transform2D: rk.se2.hat}
VEE = {rk.Rotation2D: rk.so2.vee, rk.Transform2D: rk.se2.vee}
EPS = np.finfo(np.float64).eps

# Angles across the series thresholds of the coefficients, near 0 and near ±pi.
SMALL = [0.0, 1e-300, 1e-12, 1e-9, 1e-6, 1e-4, 1e-3, 0.0299, 0.0301, 0.1, 1.0, 1.999, 2.001]
NEAR_PI = [
    math.pi,
    math.pi - 1e-12,
    math.pi - 1e-8,
    math.pi - 1e-4,
    math.nextafter(math.pi, 0),
]
ANGLES = sorted(set(SMALL + [-a for a in SMALL] + NEAR_PI + [-a for a in NEAR_PI[1:]]))

settings.register_profile("rk2d", max_examples=80, deadline=None)
angle_st = st.floats(-math.pi, math.pi, allow_nan=False)
coord_st = st.floats(-10.0, 10.0, allow_nan=False)
twist_st = st.tuples(coord_st, coord_st, angle_st).map(np.array)


def rot_matrix(theta):
    """Closed form [[cos, -sin], [sin, cos]], written independently of the kernels."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def expm_batch(A):
    A = np.asarray(A, dtype=np.float64)
    return np.array([sl.expm(a) for a in A.reshape(-1, *A.shape[-2:])]).reshape(A.shape)


def random_tangent(G, shape, rng, scale=1.0):
    tau = scale * rng.standard_normal(tuple(shape) + (G.dof,))
    tau[..., -1] = np.clip(tau[..., -1], -3.0, 3.0)  # angle inside (-pi, pi]
    return tau


# -- mpmath references (50 digits) -------------------------------------------------
mp.mp.dps = 50


def _mp_VAB(w):
    w = mp.mpf(w)
    if w == 0:
        return mp.mpf(1), mp.mpf(0)
    return mp.sin(w) / w, (1 - mp.cos(w)) / w


def mp_exp_se2(vx, vy, w):
    a, b = _mp_VAB(w)
    vx, vy = mp.mpf(vx), mp.mpf(vy)
    return [mp.cos(w), mp.sin(w), a * vx - b * vy, b * vx + a * vy]


def mp_log_se2(c, s, tx, ty):
    w = mp.atan2(mp.mpf(s), mp.mpf(c))
    a, b = _mp_VAB(w)
    d = a * a + b * b
    tx, ty = mp.mpf(tx), mp.mpf(ty)
    return [(a * tx + b * ty) / d, (a * ty - b * tx) / d, w]


def rel_err(got, ref):
    ref = [float(r) for r in ref]
    scale = max(max(abs(r) for r in ref), 1e-300)
    return max(abs(float(g) - r) for g, r in zip(got, ref, strict=True)) / scale


# ================================================================== SO(2) ======
class TestSO2:
    def test_from_angle_matches_closed_form(self):
        t = np.linspace(-7, 7, 101)
        R = rk.Rotation2D.from_angle(t)
        np.testing.assert_allclose(R.as_matrix(), rot_matrix(t), rtol=0, atol=1e-15)
        np.testing.assert_allclose(R.as_complex(), np.exp(1j * t), rtol=0, atol=1e-15)
        np.testing.assert_allclose(
            rk.Rotation2D.from_angle(np.degrees(t), degrees=True).as_matrix(),
            rot_matrix(t),
            atol=1e-14,
        )

    def test_exp_is_expm_of_hat(self):
        w = np.linspace(-3, 3, 13)[:, None]
        np.testing.assert_allclose(rk.so2.exp(w), expm_batch(rk.so2.hat(w)), atol=1e-14)
        # exp(ω J t): hat(ω) = ω J with J = R(pi/2)
        J = np.array([[0.0, -1.0], [1.0, 0.0]])
        np.testing.assert_allclose(rk.so2.hat([0.7]), 0.7 * J)
        np.testing.assert_allclose(rk.so2.hat([1.0]), rot_matrix(math.pi / 2), atol=1e-16)

    def test_log_is_logm(self):
        t = np.linspace(-3.1, 3.1, 21)
        R = rot_matrix(t)
        ref = np.array([sl.logm(r).real for r in R])
        np.testing.assert_allclose(rk.so2.hat(rk.so2.log(R)), ref, atol=1e-13)
        np.testing.assert_allclose(rk.so2.vee(ref), t[:, None], atol=1e-13)

    @pytest.mark.parametrize("theta", ANGLES)
    def test_angle_round_trip_and_range(self, theta):
        got = float(rk.Rotation2D.from_angle(theta).angle)
        ref = mp.atan2(mp.sin(mp.mpf(theta)), mp.cos(mp.mpf(theta)))
        assert -math.pi < got <= math.pi
        assert abs(got - float(ref)) <= 2 * EPS * max(abs(theta), 1e-300) + 1e-300
        if theta == -math.pi or abs(theta) == math.pi:
            assert got == math.pi

    @given(angle_st, angle_st)
    @settings(settings.get_profile("rk2d"))
    def test_compose_is_angle_addition(self, a, b):
        R = rk.Rotation2D.from_angle(a) @ rk.Rotation2D.from_angle(b)
        M = rot_matrix(a + b)
        np.testing.assert_allclose(R.as_matrix(), M, rtol=0, atol=4 * EPS)
        np.testing.assert_allclose(rk.so2.exp(R.log()), M, rtol=0, atol=8 * EPS)
        if abs(abs(math.remainder(a + b, 2 * math.pi)) - math.pi) > 1e-6:
            # logm is ill-conditioned (and the real log not unique) at pi
            np.testing.assert_allclose(R.log(), rk.so2.vee(sl.logm(M).real), atol=1e-13)
        back = float(rk.Rotation2D.from_angle(a).angle)
        assert back == pytest.approx(a if a != -math.pi else math.pi, abs=2 * EPS)

    def test_angle_is_in_half_open_interval(self):
        R = rk.Rotation2D(np.array([[-1.0, -0.0], [-1.0, 0.0], [-1.0, -1e-20]]))
        assert np.all(R.angle == math.pi)

    def test_from_complex_and_as_complex(self):
        z = np.array([2.0 + 0j, -3j, 1 + 1j, -1e-200 + 1e-200j, 1e300 - 1e300j])
        R = rk.Rotation2D.from_complex(z)
        np.testing.assert_allclose(R.as_complex(), z / np.abs(z), atol=1e-15)
        assert rk.Rotation2D.from_angle(np.float32(1.0)).as_complex().dtype == np.complex64

    def test_compose_apply_inverse(self):
        a, b = 0.4, -2.9
        Ra, Rb = rk.Rotation2D.from_angle(a), rk.Rotation2D.from_angle(b)
        np.testing.assert_allclose(
            (Ra @ Rb).as_matrix(), rot_matrix(a) @ rot_matrix(b), atol=1e-15
        )
        p = np.array([[1.0, 2.0], [-3.0, 0.5]])
        np.testing.assert_allclose(Ra @ p, p @ rot_matrix(a).T, atol=1e-15)
        np.testing.assert_allclose(Ra.inv().as_matrix(), rot_matrix(a).T, atol=1e-16)
        assert np.allclose(Ra.adjoint(), [[1.0]])

    def test_functional_jacobians_and_ad(self):
        w = np.array([[0.3], [-2.0]])
        for f in (
            rk.so2.left_jacobian,
            rk.so2.right_jacobian,
            rk.so2.left_jacobian_inverse,
            rk.so2.right_jacobian_inverse,
        ):
            np.testing.assert_array_equal(f(w), np.ones((2, 1, 1)))
        np.testing.assert_array_equal(rk.so2.ad(w), np.zeros((2, 1, 1)))
        np.testing.assert_array_equal(rk.so2.bracket(w, w[::-1]), np.zeros((2, 1)))
        np.testing.assert_array_equal(
            rk.so2.adjoint(rot_matrix(w[:, 0])), np.ones((2, 1, 1))
        )
        # (finite differences of every group's Jacobians: tests/test_jacobians_fd.py)

    def test_matches_3d_rotation_about_z(self):
        t = np.linspace(-3.1, 3.1, 17)
        R3 = rk.Rotation.from_rotvec(np.stack([0 * t, 0 * t, t], -1)).as_matrix()
        np.testing.assert_allclose(
            rk.Rotation2D.from_angle(t).as_matrix(), R3[:, :2, :2], atol=1e-15
        )
        np.testing.assert_allclose(
            rk.Rotation2D.from_matrix(R3[:, :2, :2]).angle, t, atol=1e-15
        )
        np.testing.assert_allclose(
            rk.Rotation2D.from_angle(t).angle,
            rk.Rotation.from_matrix(R3).as_rotvec()[:, 2],
            atol=1e-15,
        )

    def test_from_matrix_nearest_rotation(self):
        rng = np.random.default_rng(1)
        M = rot_matrix(rng.uniform(-3, 3, 20)) + 0.05 * rng.standard_normal((20, 2, 2))
        with pytest.raises(rk.NotARotationError, match=r"batch index \(0,\)"):
            rk.Rotation2D.from_matrix(M)
        got = rk.Rotation2D.from_matrix(M, orthonormalize=True).as_matrix()
        ref = np.array([sl.polar(m)[0] for m in M])  # orthogonal polar factor
        assert np.all(np.linalg.det(ref) > 0)
        np.testing.assert_allclose(got, ref, atol=1e-14)
        # huge and tiny scalings are projected without overflow
        for s in (1e300, 1e-300):
            R = rk.Rotation2D.from_matrix(s * rot_matrix(0.5), orthonormalize=True)
            assert abs(float(R.angle) - 0.5) < 1e-15


# ================================================================== SE(2) ======
def se2_matrix(vx, vy, w):
    """Closed form of exp with V(θ) written out (numpy, not the kernels)."""
    A = np.sinc(w / np.pi)  # numpy's sinc is the normalised one
    B = (1 - np.cos(w)) / w if w != 0 else 0.0
    T = np.eye(3)
    T[:2, :2] = rot_matrix(w)
    T[:2, 2] = [A * vx - B * vy, B * vx + A * vy]
    return T


class TestSE2:
    def test_exp_matches_expm_and_closed_form(self):
        rng = np.random.default_rng(2)
        xi = random_tangent(rk.Transform2D, (50,), rng, scale=2.0)
        got = rk.se2.exp(xi)
        np.testing.assert_allclose(got, expm_batch(rk.se2.hat(xi)), atol=1e-13)
        np.testing.assert_allclose(got, np.array([se2_matrix(*x) for x in xi]), atol=1e-14)
        np.testing.assert_allclose(
            rk.Transform2D.exp(xi).as_matrix(), expm_batch(rk.se2.hat(xi)), atol=1e-13
        )

    def test_hat_vee(self):
        xi = np.array([1.0, 2.0, 3.0])
        np.testing.assert_array_equal(rk.se2.hat(xi), [[0, -3, 1], [3, 0, 2], [0, 0, 0]])
        np.testing.assert_array_equal(rk.se2.vee(rk.se2.hat(xi)), xi)

    def test_log_is_logm(self):
        rng = np.random.default_rng(3)
        T = rk.Transform2D.random(40, rng)
        M = T.as_matrix()
        ref = np.array([rk.se2.vee(sl.logm(m).real) for m in M])
        np.testing.assert_allclose(T.log(), ref, atol=1e-12)
        np.testing.assert_allclose(rk.se2.log(M), ref, atol=1e-12)

    def test_pure_translation(self):
        T = rk.Transform2D.exp([3.0, -4.0, 0.0])
        np.testing.assert_array_equal(T.as_matrix(), [[1, -0.0, 3], [0, 1, -4], [0, 0, 1]])
        np.testing.assert_array_equal(T.log(), [3.0, -4.0, 0.0])

    @pytest.mark.parametrize("w", ANGLES)
    def test_exp_log_vs_mpmath(self, w):
        v = (0.7, -1.3)
        pose = k_se2.pose_from_twist(np.array([*v, w]))
        assert rel_err(pose[2:], mp_exp_se2(*v, w)[2:]) < 4 * EPS
        np.testing.assert_allclose(pose[:2], [math.cos(w), math.sin(w)], rtol=0, atol=EPS)
        tw = rk.Transform2D._wrap(pose).log()
        ref = mp_log_se2(*pose)
        assert rel_err(tw, ref) < 4 * EPS, (tw, ref)
        if w > -math.pi:  # -pi maps to +pi, the same element
            assert np.abs(tw - [*v, w]).max() < 8 * EPS * max(1.0, abs(w)) * 2

    @given(twist_st)
    @settings(settings.get_profile("rk2d"))
    def test_exp_log_round_trip(self, xi):
        got = rk.Transform2D.exp(xi).log()
        if xi[2] == -math.pi:
            # Angle -pi is returned as +pi; the twist's v then changes too (V(-pi) !=
            # V(pi)), so compare the group elements via scipy's expm instead.
            assert got[2] == math.pi
            tol = 1e-13 * max(1.0, np.abs(xi).max())
            want = sl.expm(rk.se2.hat(xi))
            np.testing.assert_allclose(sl.expm(rk.se2.hat(got)), want, rtol=0, atol=tol)
            return
        np.testing.assert_allclose(got, xi, rtol=0, atol=1e-13 * max(1.0, np.abs(xi).max()))

    def test_log_near_pi_matches_mpmath(self):
        for w in (math.pi, -math.pi + 1e-13, math.pi - 1e-13):
            for tx, ty in ((1.0, 0.0), (0.0, 1.0), (-3.0, 2.0)):
                pose = np.array([math.cos(w), math.sin(w), tx, ty])
                got = k_se2.twist_from_pose(pose)
                ref = mp_log_se2(*pose)
                assert (
                    max(abs(float(g) - float(r)) for g, r in zip(got, ref, strict=True))
                    < 4 * EPS * 4
                )

    def test_inverse_compose_apply_closed_form(self):
        rng = np.random.default_rng(4)
        A, B = rk.Transform2D.random(10, rng), rk.Transform2D.random(10, rng)
        MA, MB = A.as_matrix(), B.as_matrix()
        np.testing.assert_allclose((A @ B).as_matrix(), MA @ MB, atol=1e-14)
        np.testing.assert_allclose(A.inv().as_matrix(), np.linalg.inv(MA), atol=1e-14)
        p = rng.standard_normal((10, 2))
        ph = np.concatenate([p, np.ones((10, 1))], -1)
        np.testing.assert_allclose(
            A @ p, np.einsum("nij,nj->ni", MA, ph)[:, :2], atol=1e-14
        )
        # the homogeneous inverse [R^T, -R^T t]
        R, t = MA[:, :2, :2], MA[:, :2, 2]
        np.testing.assert_allclose(
            A.inv().translation, -np.einsum("nji,nj->ni", R, t), atol=1e-15
        )

    def test_adjoint_closed_form(self):
        T = rk.Transform2D(rotation=rk.Rotation2D.from_angle(0.3), translation=[2.0, -5.0])
        c, s = math.cos(0.3), math.sin(0.3)
        np.testing.assert_allclose(
            T.adjoint(), [[c, -s, -5.0], [s, c, -2.0], [0, 0, 1]], atol=1e-16
        )
        np.testing.assert_allclose(
            rk.se2.adjoint(T.as_matrix()),
            [[c, -s, -5.0], [s, c, -2.0], [0, 0, 1]],
            atol=1e-16,
        )

    def test_ad_and_bracket(self):
        rng = np.random.default_rng(5)
        a, b = rng.standard_normal((2, 20, 3))
        Ha, Hb = rk.se2.hat(a), rk.se2.hat(b)
        np.testing.assert_allclose(
            rk.se2.hat(rk.se2.bracket(a, b)), Ha @ Hb - Hb @ Ha, atol=1e-14
        )
        np.testing.assert_allclose(
            np.einsum("nij,nj->ni", rk.se2.ad(a), b), rk.se2.bracket(a, b), atol=1e-15
        )
        # Ad(exp ξ) = expm(ad ξ)
        np.testing.assert_allclose(
            rk.Transform2D.exp(a).adjoint(), expm_batch(rk.se2.ad(a)), atol=1e-13
        )
        # Jacobi identity
        c = rng.standard_normal((20, 3))
        br = rk.se2.bracket
        jac = br(a, br(b, c)) + br(b, br(c, a)) + br(c, br(a, b))
        np.testing.assert_allclose(jac, 0, atol=1e-13)

    def test_from_matrix_validation(self):
        good = rk.Transform2D.random((2, 3), 6).as_matrix()
        bad = good.copy()
        bad[1, 2, 2, 1] = 0.01
        with pytest.raises(
            rk.NotARotationError, match=r"batch index \(1, 2\) has bottom row"
        ):
            rk.Transform2D.from_matrix(bad)
        with pytest.raises(rk.NotARotationError, match="bottom row"):
            rk.Transform2D.from_matrix(bad, orthonormalize=True)
        refl = good.copy()
        refl[0, 1, :2, 1] *= -1
        with pytest.raises(rk.NotARotationError, match=r"batch index \(0, 1\).*reflection"):
            rk.Transform2D.from_matrix(refl)
        scaled = good.copy()
        scaled[1, 0, :2, :2] *= 1.1
        with pytest.raises(rk.NotARotationError, match=r"\(1, 0\).*scales by 1.1"):
            rk.Transform2D.from_matrix(scaled)
        fixed = rk.Transform2D.from_matrix(scaled, orthonormalize=True)
        np.testing.assert_allclose(fixed.as_matrix(), good, atol=1e-15)


# ================================================================ Jacobians ======
def _jacobian_frechet(xi, side):
    """Exact, via expm_frechet: ``hat(J_l e_i) = D expm(hat ξ)[hat e_i] expm(-hat ξ)``,
    ``hat(J_r e_i) = expm(-hat ξ) D expm(hat ξ)[hat e_i]``.

    (Finite differences of every group's Jacobians: tests/test_jacobians_fd.py.)
    """
    H = rk.se2.hat(xi)
    cols = []
    for i in range(3):
        L = sl.expm_frechet(H, rk.se2.hat(np.eye(3)[i]), compute_expm=False)
        cols.append(rk.se2.vee(L @ sl.expm(-H) if side == "left" else sl.expm(-H) @ L))
    return np.stack(cols, -1)


JAC_TWISTS = [
    np.array([0.3, -0.8, 1.1]),
    np.array([2.0, 1.0, -2.9]),
    np.array([-1.0, 0.5, 1e-3]),
    np.array([1.0, 2.0, 1e-9]),
    np.array([1.0, 2.0, 0.0]),
    np.array([0.0, 0.0, 0.7]),
]


class TestJacobians:
    @pytest.mark.parametrize("xi", JAC_TWISTS)
    def test_left_jacobian(self, xi):
        Jl = rk.se2.left_jacobian(xi)
        np.testing.assert_allclose(Jl, _jacobian_frechet(xi, "left"), atol=2e-14)

    @pytest.mark.parametrize("xi", JAC_TWISTS)
    def test_right_jacobian(self, xi):
        # exp(ξ + δ) ≈ exp(ξ) exp(J_r δ)
        Jr = rk.se2.right_jacobian(xi)
        np.testing.assert_allclose(Jr, _jacobian_frechet(xi, "right"), atol=2e-14)

    @pytest.mark.parametrize("xi", JAC_TWISTS + [np.array([1.0, -1.0, 6.0])])
    def test_inverses(self, xi):
        for J, Jinv in (
            (rk.se2.left_jacobian, rk.se2.left_jacobian_inverse),
            (rk.se2.right_jacobian, rk.se2.right_jacobian_inverse),
        ):
            np.testing.assert_allclose(
                Jinv(xi), np.linalg.inv(J(xi)), rtol=1e-13, atol=1e-14
            )

    def test_small_angle_band_vs_mpmath(self):
        # Third column of J_l: ((ω - sin ω) vx + (1 - cos ω) vy) / ω^2, ...
        for w in SMALL[1:] + [-1e-5, 0.5, 3.0]:
            got = rk.se2.left_jacobian(np.array([1.0, 0.5, w]))
            with mp.workdps(700):  # w - sin(w) cancels ~600 digits at w = 1e-300
                W = mp.mpf(w)
                e = (W - mp.sin(W)) / W**2
                d = (1 - mp.cos(W)) / W**2
                ref = [e * 1 + d * mp.mpf(0.5), e * mp.mpf(0.5) - d * 1]
            assert rel_err(got[:2, 2], ref) < 4 * EPS


# ============================================================ group axioms ======
@pytest.mark.parametrize("G", GROUPS)
class TestGroupAxioms:
    def test_interface(self, G):
        assert issubclass(G, LieGroup)
        assert G.matrix_size == {rk.Rotation2D: 2, rk.Transform2D: 3}[G]
        X = G.random((3,), 0)
        assert X.as_matrix().shape == (3, G.matrix_size, G.matrix_size)
        assert X.log().shape == (3, G.dof)
        assert X.adjoint().shape == (3, G.dof, G.dof)
        assert (X @ np.zeros(G.point_dim)).shape == (3, G.point_dim)

    def test_associativity_identity_inverse(self, G):
        rng = np.random.default_rng(7)
        A, B, C = (G.random(30, rng) for _ in range(3))
        M = lambda X: X.as_matrix()  # noqa: E731
        np.testing.assert_allclose(M((A @ B) @ C), M(A @ (B @ C)), atol=1e-14)
        np.testing.assert_allclose(M((A @ B) @ C), M(A) @ M(B) @ M(C), atol=1e-13)
        I = G.identity(30)  # noqa: E741
        assert np.all((A @ I).approx_equal(A, atol=0) & (I @ A).approx_equal(A, atol=0))
        assert np.all((A @ A.inv()).approx_equal(I, atol=1e-15))
        np.testing.assert_allclose(M(A.inv()), np.linalg.inv(M(A)), atol=1e-14)

    @pytest.mark.parametrize("scale", [1e-12, 1e-8, 1e-4, 1.0])
    def test_exp_log(self, G, scale):
        rng = np.random.default_rng(8)
        tau = random_tangent(G, (40,), rng, scale)
        X = G.exp(tau)
        np.testing.assert_allclose(
            X.as_matrix(), expm_batch(HAT[G](tau)), rtol=0, atol=1e-14
        )
        np.testing.assert_allclose(X.log(), tau, rtol=1e-14, atol=1e-16 * scale)
        Y = G.random(40, rng)
        assert np.all(G.exp(Y.log()).approx_equal(Y, atol=1e-14))

    def test_exp_log_near_pi(self, G):
        tau = np.zeros((len(NEAR_PI) * 2, G.dof))
        tau[:, -1] = NEAR_PI + [-a for a in NEAR_PI]
        tau[:, :-1] = 0.6
        X = G.exp(tau)
        np.testing.assert_allclose(X.as_matrix(), expm_batch(HAT[G](tau)), atol=1e-14)
        assert np.all(G.exp(X.log()).approx_equal(X, atol=1e-14))
        back = X.log()
        assert np.all(back[:, -1] > -math.pi) and np.all(back[:, -1] <= math.pi)

    def test_adjoint(self, G):
        rng = np.random.default_rng(9)
        X = G.random(25, rng)
        tau = random_tangent(G, (25,), rng)
        Ad = X.adjoint()
        lhs = (X @ G.exp(tau) @ X.inv()).as_matrix()
        rhs = G.exp(np.einsum("nij,nj->ni", Ad, tau)).as_matrix()
        np.testing.assert_allclose(lhs, rhs, atol=1e-13)
        # the algebra form: X hat(τ) X^-1 = hat(Ad τ)
        M = X.as_matrix()
        np.testing.assert_allclose(
            M @ HAT[G](tau) @ np.linalg.inv(M),
            HAT[G](np.einsum("nij,nj->ni", Ad, tau)),
            atol=1e-13,
        )
        # Ad is a homomorphism
        Y = G.random(25, rng)
        np.testing.assert_allclose((X @ Y).adjoint(), Ad @ Y.adjoint(), atol=1e-13)

    def test_plus_minus(self, G):
        rng = np.random.default_rng(10)
        X = G.random(20, rng)
        tau = random_tangent(G, (20,), rng, 0.5)
        for side in ("right", "left"):
            np.testing.assert_allclose(
                X.plus(tau, side=side).minus(X, side=side), tau, atol=1e-13
            )
        np.testing.assert_allclose(
            X.plus(tau).as_matrix(), X.as_matrix() @ expm_batch(HAT[G](tau)), atol=1e-13
        )

    def test_bch_second_order(self, G):
        rng = np.random.default_rng(11)
        a = random_tangent(G, (20,), rng, 1e-3)
        b = random_tangent(G, (20,), rng, 1e-3)
        Ha, Hb = HAT[G](a), HAT[G](b)
        approx = a + b + 0.5 * VEE[G](Ha @ Hb - Hb @ Ha)
        got = (G.exp(a) @ G.exp(b)).log()
        assert np.abs(got - approx).max() < 1e-8  # third order: |a|^3 ~ 1e-9

    def test_container(self, G):
        X = G.random((2, 3), 12)
        assert X.shape == (2, 3) and len(X) == 2
        assert X[1].shape == (3,) and X[1, 2].shape == ()
        assert [x.shape for x in X] == [(3,), (3,)]
        assert G.concatenate([X[0], X[1]]).shape == (6,)
        assert G.concatenate([X[0, 0], X[1, 1]]).shape == (2,)
        assert np.all(X.reshape(6).approx_equal(G.concatenate([X[0], X[1]]), atol=0))
        Y = pickle.loads(pickle.dumps(X))
        assert type(Y) is G and np.all(Y.approx_equal(X, atol=0))
        assert "shape=(2, 3)" in repr(X)
        single = X[0, 0]
        assert repr(single).startswith(G.__name__)
        with pytest.raises(TypeError):
            len(single)
        with pytest.raises(TypeError):
            np.zeros(G.point_dim) @ single
        assert G.identity().shape == () and G.identity(4).shape == (4,)
        assert G.identity(dtype=np.float32).dtype == np.float32

    def test_empty_and_nd_batches(self, G):
        rng = np.random.default_rng(13)
        E = G.exp(np.zeros((0, G.dof)))
        assert E.shape == (0,) and E.log().shape == (0, G.dof)
        assert (E @ E).shape == (0,) and E.inv().as_matrix().shape == (
            0,
            G.matrix_size,
            G.matrix_size,
        )
        assert G.random((0, 3), rng).shape == (0, 3)
        tau = random_tangent(G, (2, 3, 4), rng)
        X = G.exp(tau)
        assert X.shape == (2, 3, 4)
        np.testing.assert_allclose(X.log(), tau, atol=1e-14)
        # broadcasting: (3, 1) @ (4,) -> (3, 4); points (5, 1, 2) by (4,) -> (5, 4, 2)
        A, B = G.random((3, 1), rng), G.random(4, rng)
        AB = A @ B
        assert AB.shape == (3, 4)
        np.testing.assert_allclose(
            AB.as_matrix(), A.as_matrix() @ B.as_matrix(), atol=1e-14
        )
        assert (B @ rng.standard_normal((5, 1, 2))).shape == (5, 4, 2)

    def test_float32(self, G):
        rng = np.random.default_rng(14)
        tau = random_tangent(G, (50,), rng)
        X32 = G.exp(tau.astype(np.float32))
        assert X32.dtype == np.float32
        for arr in (
            X32.as_matrix(),
            X32.log(),
            X32.adjoint(),
            X32.inv().as_matrix(),
            (X32 @ X32).as_matrix(),
        ):
            assert arr.dtype == np.float32
        assert (X32 @ np.ones((50, 2), np.float32)).dtype == np.float32
        np.testing.assert_allclose(X32.as_matrix(), G.exp(tau).as_matrix(), atol=1e-6)
        np.testing.assert_allclose(X32.log(), tau, atol=4e-6)
        # tiny angles in float32 (series branch) stay exact
        small = tau.astype(np.float32) * np.float32(1e-6)
        np.testing.assert_allclose(G.exp(small).log(), small, rtol=1e-6, atol=1e-12)

    def test_numba_matches_xp(self, G):
        rng = np.random.default_rng(15)
        tau = random_tangent(G, (1500,), rng)
        data = G.exp(tau)._data
        for kern, args in _kernel_calls(G, data, tau, rng):
            a = kern(*args, backend="numba")
            b = kern(*args, backend="xp")
            np.testing.assert_allclose(a, b, rtol=0, atol=4e-16)


def _kernel_calls(G, data, tau, rng):
    if G is rk.Rotation2D:
        return [
            (k_so2.complex_from_angle, (tau,)),
            (k_so2.angle_from_complex, (data,)),
            (k_so2.complex_multiply, (data, data[::-1])),
            (k_so2.complex_apply, (data, rng.standard_normal((len(data), 2)))),
        ]
    return [
        (k_se2.pose_from_twist, (tau,)),
        (k_se2.twist_from_pose, (data,)),
        (k_se2.pose_multiply, (data, data[::-1])),
        (k_se2.pose_apply, (data, rng.standard_normal((len(data), 2)))),
    ]


# ============================================================== bad input ======
class TestBadInput:
    def test_shapes(self):
        with pytest.raises(rk.ShapeError, match=r"\(\.\.\., 1\)"):
            rk.Rotation2D.exp(np.zeros(3))
        with pytest.raises(rk.ShapeError, match=r"\(\.\.\., 3\)"):
            rk.Transform2D.exp(np.zeros(2))
        with pytest.raises(rk.ShapeError):
            rk.Rotation2D.from_matrix(np.eye(3))
        with pytest.raises(rk.ShapeError):
            rk.Transform2D.from_matrix(np.eye(2))
        with pytest.raises(rk.ShapeError, match="complex"):
            rk.Rotation2D.from_complex(np.array([1.0, 0.0]))
        with pytest.raises(rk.ShapeError):
            rk.Rotation2D.from_angle(0.1) @ np.zeros(3)
        with pytest.raises(rk.ShapeError):
            rk.Transform2D(translation=[1.0, 2.0, 3.0])
        with pytest.raises(TypeError):
            rk.Transform2D(rotation=rk.Rotation.identity())

    def test_non_finite_and_zero(self):
        with pytest.raises(rk.NonFiniteError, match=r"batch index \(1,\)"):
            rk.Rotation2D.from_angle([0.0, np.nan])
        with pytest.raises(rk.NonFiniteError, match=r"batch index \(2,\)"):
            rk.Transform2D.exp(np.array([[0, 0, 0], [1, 2, 3], [np.inf, 0, 0.0]]))
        with pytest.raises(rk.NonFiniteError):
            rk.se2.log(np.full((3, 3), np.nan))
        with pytest.raises(rk.ZeroNormError, match=r"batch index \(1,\)"):
            rk.Rotation2D.from_complex(np.array([1j, 0j]))
        with pytest.raises(rk.ZeroNormError):
            rk.Rotation2D(np.zeros(2))
        # all errors are ValueErrors
        with pytest.raises(ValueError):
            rk.Rotation2D.from_matrix(np.diag([1.0, -1.0]))

    def test_not_a_rotation(self):
        M = np.stack([np.eye(2), np.diag([1.0, -1.0]), 2 * np.eye(2)])
        with pytest.raises(rk.NotARotationError, match=r"batch index \(1,\).*reflection"):
            rk.Rotation2D.from_matrix(M)
        with pytest.raises(rk.NotARotationError, match=r"batch index \(1,\).*nearest"):
            rk.Rotation2D.from_matrix(M, orthonormalize=True)
        with pytest.raises(rk.NotARotationError, match="scales by 2"):
            rk.so2.log(M[2])
        np.testing.assert_allclose(
            rk.Rotation2D.from_matrix(M[[0, 2]], orthonormalize=True).angle, 0.0
        )
        # within tolerance passes; float32 has a looser default
        assert rk.Rotation2D.from_matrix(np.eye(2) * (1 + 1e-7)).shape == ()
        assert (
            rk.Rotation2D.from_matrix(
                np.eye(2, dtype=np.float32) * np.float32(1 + 1e-5)
            ).dtype
            == np.float32
        )

    def test_bad_side(self):
        with pytest.raises(ValueError):
            rk.Rotation2D.identity().plus(np.zeros(1), side="middle")


# ============================================================ construction ======
class TestTransform2DSurface:
    def test_constructor_parts(self):
        R = rk.Rotation2D.from_angle([0.1, 0.2, 0.3])
        T = rk.Transform2D(rotation=R, translation=[1.0, 2.0])
        assert T.shape == (3,)
        np.testing.assert_allclose(T.rotation.angle, [0.1, 0.2, 0.3], atol=1e-16)
        np.testing.assert_array_equal(T.translation, [[1.0, 2.0]] * 3)
        assert rk.Transform2D().approx_equal(rk.Transform2D.identity())
        assert rk.Transform2D(rotation=R[0]).translation.tolist() == [0.0, 0.0]
        assert (
            rk.Transform2D(translation=np.zeros((4, 2))).rotation.angle.tolist()
            == [0.0] * 4
        )
        T32 = rk.Transform2D(rotation=R.reshape(3), translation=np.ones((3, 2), np.float32))
        assert T32.shape == (3,)

    def test_mixed_rotation_composition(self):
        R = rk.Rotation2D.from_angle(0.5)
        T = rk.Transform2D(rotation=rk.Rotation2D.from_angle(-1.0), translation=[3.0, 1.0])
        MR = np.eye(3)
        MR[:2, :2] = rot_matrix(0.5)
        assert isinstance(R @ T, rk.Transform2D) and isinstance(T @ R, rk.Transform2D)
        np.testing.assert_allclose((R @ T).as_matrix(), MR @ T.as_matrix(), atol=1e-15)
        np.testing.assert_allclose((T @ R).as_matrix(), T.as_matrix() @ MR, atol=1e-15)

    def test_repr(self):
        T = rk.Transform2D(rotation=rk.Rotation2D.from_angle(0.5), translation=[1.0, -2.0])
        assert (
            repr(T)
            == "Transform2D(rotation=Rotation2D.from_angle(0.5), translation=[1, -2])"
        )
        assert repr(rk.Rotation2D.from_angle(-0.25)) == "Rotation2D.from_angle(-0.25)"

    def test_matches_3d_transform_about_z(self):
        if not hasattr(rk, "Transform"):
            pytest.skip("rk.Transform not available yet")
        rng = np.random.default_rng(16)
        xi = random_tangent(rk.Transform2D, (20,), rng)
        xi3 = np.zeros((20, 6))
        xi3[:, :2] = xi[:, :2]
        xi3[:, 5] = xi[:, 2]
        M3 = rk.Transform.exp(xi3).as_matrix()
        M2 = rk.Transform2D.exp(xi).as_matrix()
        idx = np.ix_(range(20), [0, 1, 3], [0, 1, 3])
        np.testing.assert_allclose(M2, M3[idx], atol=1e-14)
        A6 = rk.Transform.exp(xi3).adjoint()
        np.testing.assert_allclose(
            rk.Transform2D.exp(xi).adjoint(),
            A6[np.ix_(range(20), [0, 1, 5], [0, 1, 5])],
            atol=1e-14,
        )


# ================================================================== torch ======
class TestTorch:
    # ``torch`` is the conftest fixture: these tests skip alone where it is missing
    # (an importorskip in the class body would skip the whole module on import).
    def test_tensors_in_tensors_out(self, torch):
        xi = torch.tensor([[0.3, -0.2, 1.0], [1.0, 2.0, -3.0]], dtype=torch.float64)
        T = rk.Transform2D.exp(xi)
        assert isinstance(T._data, torch.Tensor)
        for out in (
            T.as_matrix(),
            T.log(),
            T.adjoint(),
            (T @ T.inv()).as_matrix(),
            T @ torch.ones(2, 2, dtype=torch.float64),
        ):
            assert isinstance(out, torch.Tensor) and out.dtype == torch.float64
        np.testing.assert_allclose(
            T.as_matrix().numpy(), rk.se2.exp(xi.numpy()), atol=1e-15
        )
        np.testing.assert_allclose(
            rk.se2.left_jacobian(xi).numpy(), rk.se2.left_jacobian(xi.numpy()), atol=1e-15
        )
        R = rk.Rotation2D.from_angle(torch.tensor([0.5, -1.0], dtype=torch.float32))
        assert R.dtype == torch.float32
        z = R.as_complex()
        assert torch.is_complex(z) and z.dtype == torch.complex64
        R2 = rk.Rotation2D.from_complex(z)
        assert isinstance(R2._data, torch.Tensor)
        np.testing.assert_allclose(R2.angle.numpy(), [0.5, -1.0], atol=1e-6)
        T2 = rk.Transform2D(rotation=R, translation=torch.zeros(2, 2))
        assert isinstance(T2.translation, torch.Tensor)
        with pytest.raises(rk.NotARotationError):
            rk.Transform2D.from_matrix(torch.zeros(3, 3, dtype=torch.float64))

    def test_gradients(self, torch):
        for w in (0.0, 1e-9, 0.5, 3.0):
            xi = torch.tensor([0.4, -0.3, w], dtype=torch.float64, requires_grad=True)
            assert torch.autograd.gradcheck(lambda x: rk.Transform2D.exp(x).log(), (xi,))
            out = rk.Transform2D.exp(xi).as_matrix().sum()
            (g,) = torch.autograd.grad(out, xi)
            assert torch.all(torch.isfinite(g))


# ====================================================== array-api-strict ======
def test_array_api_strict():
    xp = pytest.importorskip("array_api_strict")
    xi_np = np.array([[0.3, -0.2, 1.0], [1.0, 2.0, 3.0]])
    T = rk.Transform2D.exp(xp.asarray(xi_np))
    assert isinstance(T._data, type(xp.asarray(0.0)))
    np.testing.assert_allclose(np.asarray(T.log()), xi_np, atol=1e-15)
    np.testing.assert_allclose(
        np.asarray((T @ T[0]).as_matrix()),
        rk.se2.exp(xi_np) @ rk.se2.exp(xi_np[0]),
        atol=1e-15,
    )
    np.testing.assert_allclose(
        np.asarray(rk.se2.right_jacobian(xp.asarray(xi_np))),
        rk.se2.right_jacobian(xi_np),
        atol=0,
    )
    R = rk.Rotation2D.from_angle(xp.asarray([0.1, 0.2]))
    np.testing.assert_allclose(
        np.asarray(R.as_complex()), np.exp(1j * np.array([0.1, 0.2])), atol=1e-16
    )
    assert R.reshape(2, 1)[1, 0].shape == ()
