"""Similarity (Sim(3)), Affine and Projective transforms, and the ladder of kinds.

References, independent of the code under test:
- ``scipy.linalg.expm`` / ``logm`` of the 4x4 hat matrix ``[[hat(w) + sigma I, v],
  [0, 0]]`` and ``mpmath.expm`` at 40 digits (for the series threshold and the
  small-angle bands);
- the coefficients ``a, b, c`` of ``V`` as mpmath quadratures of their defining
  integrals;
- NumPy products, inverses and homogeneous divides of ``as_matrix()``;
- hand-built matrices (scaled rotations from scipy, shears, reflections).
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
from scipy.spatial.transform import Rotation as SciRot
from scipy.special import exprel as sc_exprel

import rigidkit as rk
from rigidkit.kernels.coefficients import exprel
from rigidkit.kernels.sim3 import sim3_v_coeffs
from rigidkit.objects.group import LieGroup

EPS = np.finfo(np.float64).eps


def skew(w):
    w = np.asarray(w, dtype=np.float64)
    S = np.zeros(w.shape[:-1] + (3, 3))
    S[..., 0, 1], S[..., 0, 2], S[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    S[..., 1, 0], S[..., 2, 0], S[..., 2, 1] = w[..., 2], -w[..., 1], w[..., 0]
    return S


def sim3_hat(xi):
    """``[[hat(omega) + sigma I, v], [0, 0]]`` for twists ``(v, omega, sigma)``."""
    xi = np.asarray(xi, dtype=np.float64)
    M = np.zeros(xi.shape[:-1] + (4, 4))
    M[..., :3, :3] = skew(xi[..., 3:6]) + xi[..., 6, None, None] * np.eye(3)
    M[..., :3, 3] = xi[..., :3]
    return M


def sim3_vee(M):
    return np.concatenate(
        [M[..., :3, 3], [M[2, 1], M[0, 2], M[1, 0]], [np.trace(M[:3, :3]) / 3.0]]
    )


def sim_matrix(s, quat, t):
    """``[[s R, t], [0, 1]]`` built from scipy's rotation matrix."""
    M = np.zeros(np.shape(s) + (4, 4))
    M[..., :3, :3] = np.asarray(s)[..., None, None] * SciRot.from_quat(
        np.reshape(quat, (-1, 4)), scalar_first=True
    ).as_matrix().reshape(np.shape(s) + (3, 3))
    M[..., :3, 3] = t
    M[..., 3, 3] = 1.0
    return M


def twists(rng, n, angle=None, sigma_scale=1.0):
    xi = rng.standard_normal((n, 7))
    xi[:, 6] *= sigma_scale
    if angle is not None:
        d = rng.standard_normal((n, 3))
        xi[:, 3:6] = (
            d / np.linalg.norm(d, axis=-1, keepdims=True) * np.asarray(angle)[..., None]
        )
    return xi


def assert_close_normwise(got, want, rtol):
    """Each matrix of a batch within ``rtol`` times its largest |entry|."""
    scale = np.abs(want).max(axis=(-2, -1), keepdims=True)
    assert np.all(np.abs(got - want) <= rtol * scale)


def assert_inverse_close(got, M):
    """``got`` vs ``np.linalg.inv(M)``: both have forward errors ~ cond(M) eps."""
    ref = np.linalg.inv(M)
    cond = np.linalg.cond(M)[..., None, None]
    assert np.all(
        np.abs(got - ref) <= 8 * EPS * cond * np.abs(ref).max(axis=(-2, -1), keepdims=True)
    )


def homog(X):
    """The 4x4 homogeneous matrix of any kind, ``[[R, 0], [0, 1]]`` for a rotation."""
    M = np.asarray(X.as_matrix(), dtype=np.float64)
    if M.shape[-1] == 4:
        return M
    out = np.zeros(M.shape[:-2] + (4, 4))
    out[..., :3, :3] = M
    out[..., 3, 3] = 1.0
    return out


# -- Sim(3): coefficients -------------------------------------------------------------


def test_exprel_against_scipy_and_mpmath():
    mp.mp.dps = 40
    x = np.concatenate([np.linspace(-5, 5, 401), [0.0, 1e-300, -1e-12, 0.999999, 1.000001]])
    got = np.array([exprel(float(v)) for v in x])
    np.testing.assert_allclose(got, sc_exprel(x), rtol=4 * EPS, atol=0)
    for v, g in zip(x, got, strict=True):
        ref = mp.expm1(mp.mpf(v)) / v if v else mp.mpf(1)
        assert abs(g - ref) <= 1.5 * EPS * abs(ref)
    assert exprel(-800.0) == 1.0 / 800.0


def _coeffs_ref(sigma, theta):
    """``a, b, c`` of ``V`` by quadrature of their defining integrals (mpmath)."""
    s, t = mp.mpf(sigma), mp.mpf(theta)

    def half_versinc(u):  # (1 - cos(u t)) / t^2 = u^2 versinc2(u t)
        x = u * t
        return u * u * (2 * mp.sin(x / 2) ** 2 / (x * x) if x != 0 else mp.mpf(1) / 2)

    a = mp.quad(lambda u: mp.exp(u * s), [0, 1])
    b = mp.quad(lambda u: mp.exp(u * s) * u * mp.sinc(u * t), [0, 1])
    c = mp.quad(lambda u: mp.exp(u * s) * half_versinc(u), [0, 1])
    return a, b, c


def _coeff_points():
    pts = [
        (s, t)
        for s in (-3.0, -1.0, -1e-3, 0.0, 1e-8, 0.3, 1.0, 2.0)
        for t in (0.0, 1e-8, 1e-3, 0.7, 1.5, 3.0, math.pi)
    ]
    # both sides of the series threshold |z| = 1.5
    for ang in np.linspace(0.0, math.pi, 9):
        for r in (1.5 * (1 - 1e-9), 1.5, 1.5 * (1 + 1e-9)):
            pts.append((r * math.cos(ang), r * math.sin(ang)))
    return pts


def test_sim3_coefficients_against_quadrature():
    """Max error measured: a 1 ulp, b 3 ulp, c 5 ulp (just above |z| = 1.5)."""
    mp.mp.dps = 30
    for sigma, theta in _coeff_points():
        got = sim3_v_coeffs(sigma, theta)
        for g, r, ulps in zip(got, _coeffs_ref(sigma, theta), (2, 4, 6), strict=True):
            assert abs(g - r) <= ulps * EPS * abs(r), (sigma, theta, g, r)


# -- Sim(3): exp and log -------------------------------------------------------------------


@pytest.mark.parametrize("scale", [1e-6, 0.1, 1.0])
def test_sim3_exp_against_expm(rng, scale):
    xi = twists(rng, 40) * scale
    got = rk.Similarity.exp(xi).as_matrix()
    ref = sl.expm(sim3_hat(xi))
    # scipy's expm is the less accurate side: up to ~80 ulp at this scale (and
    # ~2000 ulp for twists twice as long), measured against mpmath; ours stays
    # within a few ulp (next tests).
    tol = 1e-13 * np.abs(ref).max(axis=(-2, -1), keepdims=True)
    assert np.all(np.abs(got - ref) <= tol)


def _mp_expm(xi):
    E = mp.expm(mp.matrix(sim3_hat(xi).tolist()))
    return np.array(E.tolist(), dtype=object)


SWEEP = [
    # (sigma, theta): identity, tiny bands, both sides of |z| = 1.5, near and at pi
    (0.0, 0.0),
    (1e-12, 1e-12),
    (1e-8, 0.0),
    (0.0, 1e-8),
    (-1e-4, 1e-4),
    (1.0, 1.118 * (1 - 1e-9)),
    (1.0, 1.118 * (1 + 1e-9)),
    (-1.4999999, 0.0),
    (-1.5000001, 0.0),
    (0.3, math.pi - 1e-6),
    (-2.0, math.pi),
    (0.0, math.pi),
    (5.0, 0.5),
    (-5.0, 2.5),
]


def _mp_err(M, xi):
    """Largest entry error of ``M`` against mpmath's expm, relative to the largest entry."""
    ref = _mp_expm(xi)
    scale = max(abs(float(r)) for r in ref.ravel())
    err = max(
        abs(mp.mpf(float(a)) - b) for a, b in zip(M.ravel(), ref.ravel(), strict=True)
    )
    return float(err) / scale


def test_sim3_exp_long_twists_against_mpmath(rng):
    """Long twists: the rounding of theta and sigma themselves is passed on by cos,
    sin and exp, so the error grows like (1 + theta + |sigma|) eps (measured
    <= 0.7 (1 + theta + |sigma|) eps over 200 twists with |xi_i| ~ N(0, 4))."""
    mp.mp.dps = 30
    xi = twists(rng, 20) * 2.0
    got = rk.Similarity.exp(xi).as_matrix()
    for g, x in zip(got, xi, strict=True):
        bound = 2 * (1 + np.linalg.norm(x[3:6]) + abs(x[6])) * EPS
        assert _mp_err(g, x) <= bound


@pytest.mark.parametrize(("sigma", "theta"), SWEEP)
def test_sim3_exp_against_mpmath(rng, sigma, theta):
    mp.mp.dps = 40
    xi = twists(rng, 3, angle=np.full(3, theta))
    xi[:, 6] = sigma
    got = rk.Similarity.exp(xi).as_matrix()
    for g, x in zip(got, xi, strict=True):
        assert _mp_err(g, x) <= 8 * EPS


def test_sim3_log_against_logm(rng):
    xi = twists(rng, 12)
    xi[:, 3:6] *= np.minimum(1.0, 3.0 / np.linalg.norm(xi[:, 3:6], axis=-1))[:, None]
    S = rk.Similarity.exp(xi)
    got = S.log()
    for g, M in zip(got, S.as_matrix(), strict=True):
        ref = sl.logm(M)
        assert np.abs(ref.imag).max() < 1e-12
        np.testing.assert_allclose(
            g, sim3_vee(ref.real), rtol=0, atol=1e-12 * (1 + np.abs(g).max())
        )


@given(
    st.lists(st.floats(-5, 5, allow_subnormal=False), min_size=3, max_size=3),
    st.lists(st.floats(-1, 1, allow_subnormal=False), min_size=3, max_size=3),
    st.floats(0.0, math.pi * (1 - 1e-6)),
    st.floats(-4, 4, allow_subnormal=False),
)
@settings(max_examples=150)
def test_sim3_log_exp_round_trip(v, axis, angle, sigma):
    axis = np.array(axis)
    if np.linalg.norm(axis) < 1e-3:
        axis = np.array([0.0, 0.0, 1.0])
    w = axis / np.linalg.norm(axis) * angle
    xi = np.concatenate([v, w, [sigma]])
    back = rk.Similarity.exp(xi).log()
    # measured over 2e5 samples: <= 6.6 eps (1 + max|xi_i|), largest near theta = pi
    np.testing.assert_allclose(back, xi, rtol=0, atol=16 * EPS * (1 + np.abs(xi).max()))


def test_sim3_exp_of_log_and_identity(rng):
    S = rk.Similarity.random(50, rng)
    back = rk.Similarity.exp(S.log())
    np.testing.assert_allclose(back.as_matrix(), S.as_matrix(), rtol=0, atol=1e-14 * 8)
    np.testing.assert_array_equal(rk.Similarity.identity().log(), np.zeros(7))
    np.testing.assert_array_equal(rk.Similarity.exp(np.zeros(7)).as_matrix(), np.eye(4))
    # pure scaling and pure translation
    np.testing.assert_allclose(
        rk.Similarity.exp([0, 0, 0, 0, 0, 0, math.log(3.0)]).scale, 3.0, rtol=2 * EPS
    )
    T = rk.Similarity.exp([1.0, 2.0, 3.0, 0, 0, 0, 0])
    np.testing.assert_array_equal(T.translation, [1.0, 2.0, 3.0])


# -- Sim(3): group operations -----------------------------------------------------------


def test_sim3_ops_against_matrices(rng):
    X, Y = rk.Similarity.random(20, rng), rk.Similarity.random(20, rng)
    MX, MY = X.as_matrix(), Y.as_matrix()
    np.testing.assert_allclose(
        MX, sim_matrix(X.scale, X.rotation.as_quat(), X.translation), atol=4 * EPS * 8
    )
    np.testing.assert_allclose((X @ Y).as_matrix(), MX @ MY, rtol=0, atol=1e-14 * 8)
    assert_inverse_close(X.inv().as_matrix(), MX)
    p = rng.standard_normal((20, 3))
    ph = np.concatenate([p, np.ones((20, 1))], axis=-1)
    np.testing.assert_allclose(X @ p, (MX @ ph[..., None])[..., :3, 0], atol=1e-14 * 8)
    np.testing.assert_allclose(X.apply(p), (MX @ ph[..., None])[..., :3, 0], atol=1e-14 * 8)
    # axioms
    Z = rk.Similarity.random(20, rng)
    np.testing.assert_allclose(
        ((X @ Y) @ Z).as_matrix(), (X @ (Y @ Z)).as_matrix(), atol=1e-13
    )
    np.testing.assert_allclose(
        (X @ X.inv()).as_matrix(), np.broadcast_to(np.eye(4), MX.shape), atol=1e-14 * 8
    )


def test_sim3_adjoint(rng):
    X = rk.Similarity.random(30, rng)
    xi = twists(rng, 30) * 0.5
    Ad = X.adjoint()
    assert Ad.shape == (30, 7, 7)
    Ad_xi = (Ad @ xi[..., None])[..., 0]
    # each within 32 eps of the largest entry (measured <= 14 eps over 3000 samples)
    lhs = (X @ rk.Similarity.exp(xi) @ X.inv()).as_matrix()
    rhs = rk.Similarity.exp(Ad_xi).as_matrix()
    assert_close_normwise(lhs, rhs, 32 * EPS)
    M = X.as_matrix()
    conj = M @ sim3_hat(xi) @ np.linalg.inv(M)
    assert_close_normwise(sim3_hat(Ad_xi), conj, 32 * EPS)
    # Ad is a homomorphism: Ad(XY) = Ad(X) Ad(Y)
    Y = rk.Similarity.random(30, rng)
    assert_close_normwise((X @ Y).adjoint(), Ad @ Y.adjoint(), 32 * EPS)


def test_sim3_plus_minus(rng):
    X = rk.Similarity.random(10, rng)
    tau = twists(rng, 10) * 0.3
    for side in ("right", "left"):
        np.testing.assert_allclose(
            X.plus(tau, side=side).minus(X, side=side), tau, atol=1e-13
        )


# -- Sim(3): construction and validation ---------------------------------------------------


def test_similarity_from_matrix(rng):
    X = rk.Similarity.random((4, 5), rng)
    Y = rk.Similarity.from_matrix(X.as_matrix())
    assert Y.shape == (4, 5)
    np.testing.assert_allclose(Y.as_matrix(), X.as_matrix(), atol=1e-14 * 8)
    np.testing.assert_allclose(Y.scale, X.scale, rtol=4 * EPS)
    # a hand-built scaled rotation
    M = sim_matrix(
        np.array(2.5),
        SciRot.from_rotvec([0.1, 0.2, 0.3]).as_quat(scalar_first=True),
        [1, 2, 3],
    )
    S = rk.Similarity.from_matrix(M)
    assert abs(float(S.scale) - 2.5) <= 4 * EPS * 2.5
    np.testing.assert_allclose(S.rotation.as_rotvec(), [0.1, 0.2, 0.3], atol=1e-15)


def _bad_matrix(kind):
    M = np.tile(np.eye(4), (2, 3, 1, 1))
    A = M[1, 2]
    if kind == "bottom":
        A[3, 0] = 0.1
    elif kind == "reflection":
        A[0, 0] = -1.0
    elif kind == "nonuniform":
        A[:3, :3] = np.diag([1.0, 2.0, 3.0])
    elif kind == "shear":
        A[0, 1] = 0.5
    elif kind == "zero":
        A[:3, :3] = 0.0
    return M


@pytest.mark.parametrize(
    ("kind", "words"),
    [
        ("bottom", "bottom row"),
        ("reflection", "reflection"),
        ("nonuniform", "singular values"),
        ("shear", "singular values"),
        ("zero", "zero"),
    ],
)
def test_similarity_from_matrix_rejects(kind, words):
    with pytest.raises(rk.NotASimilarityError, match=r"\(1, 2\)") as err:
        rk.Similarity.from_matrix(_bad_matrix(kind))
    assert words in str(err.value)
    assert isinstance(err.value, ValueError)


def test_similarity_constructor(rng):
    R = rk.Rotation.random(3, rng)
    S = rk.Similarity(scale=[1.0, 2.0, 3.0], rotation=R, translation=[[0.0, 0.0, 1.0]])
    assert S.shape == (3,)
    np.testing.assert_array_equal(S.scale, [1.0, 2.0, 3.0])
    assert S.rotation.approx_equal(R, atol=1e-15).all()
    assert rk.Similarity().approx_equal(rk.Similarity.identity(), atol=0)
    assert rk.Similarity(scale=np.ones((2, 1)), rotation=R).shape == (2, 3)
    with pytest.raises(rk.NotASimilarityError, match=r"\(1,\)"):
        rk.Similarity(scale=[1.0, -2.0])
    with pytest.raises(rk.NotASimilarityError):
        rk.Similarity(scale=0.0)
    with pytest.raises(rk.NonFiniteError):
        rk.Similarity(scale=[1.0, np.nan])
    with pytest.raises(TypeError):
        rk.Similarity(rotation=np.eye(3))
    with pytest.raises(rk.NonFiniteError):
        rk.Similarity.exp([0, 0, 0, 0, 0, np.inf, 0])
    with pytest.raises(rk.ShapeError):
        rk.Similarity.exp(np.zeros(6))


def test_similarity_float32(rng):
    xi = twists(rng, 20).astype(np.float32)
    S = rk.Similarity.exp(xi)
    assert S.dtype == np.float32
    assert (S @ S).dtype == np.float32 and S.inv().dtype == np.float32
    assert S.log().dtype == np.float32 and S.as_matrix().dtype == np.float32
    ref = sl.expm(sim3_hat(xi.astype(np.float64)))
    np.testing.assert_allclose(S.as_matrix(), ref, rtol=0, atol=2e-6 * np.abs(ref).max())
    f32 = rk.Similarity(scale=2.0, translation=np.ones(3, dtype=np.float32))
    assert f32.dtype == np.float32


def test_similarity_torch():
    torch = pytest.importorskip("torch")
    rng = np.random.default_rng(3)
    xi = twists(rng, 5)
    S = rk.Similarity.exp(torch.tensor(xi))
    assert isinstance(S._data, torch.Tensor)
    np.testing.assert_allclose(S._data.numpy(), rk.Similarity.exp(xi)._data, atol=4 * EPS)
    np.testing.assert_allclose(S.log().numpy(), xi, atol=1e-13 * (1 + np.abs(xi).max()))


def test_similarity_numba_batch_matches_python(rng):
    xi = twists(rng, 2000)
    S = rk.Similarity.exp(xi)
    for i in (0, 999, 1999):
        one = rk.Similarity.exp(xi[i])
        np.testing.assert_allclose(S._data[i], one._data, rtol=0, atol=4 * EPS * 8)
        np.testing.assert_allclose(S.log()[i], one.log(), rtol=0, atol=1e-14 * 8)


def test_similarity_containers(rng):
    S = rk.Similarity.random((2, 3), rng)
    assert S[1].shape == (3,) and S[1, 2].shape == () and len(S) == 2
    back = pickle.loads(pickle.dumps(S))
    np.testing.assert_array_equal(back._data, S._data)
    assert repr(rk.Similarity(scale=2.0)).startswith("Similarity(scale=2,")
    assert "shape=(2, 3)" in repr(S)
    assert rk.Similarity.dof == 7 and rk.Similarity.matrix_size == 4
    assert rk.Similarity.point_dim == 3
    assert isinstance(S, LieGroup)


# -- Affine -----------------------------------------------------------------------------


def test_affine_ops_against_matrices(rng):
    X, Y = rk.Affine.random(20, rng), rk.Affine.random(20, rng)
    MX, MY = X.as_matrix(), Y.as_matrix()
    np.testing.assert_array_equal(MX[:, 3], np.broadcast_to([0.0, 0.0, 0.0, 1.0], (20, 4)))
    np.testing.assert_allclose((X @ Y).as_matrix(), MX @ MY, rtol=0, atol=1e-14 * 8)
    assert_inverse_close(X.inv().as_matrix(), MX)
    p = rng.standard_normal((20, 3))
    np.testing.assert_allclose(
        X @ p, (X.matrix @ p[..., None])[..., 0] + X.translation, atol=1e-14
    )
    back = rk.Affine.from_matrix(MX)
    np.testing.assert_array_equal(back.as_matrix(), MX)
    np.testing.assert_allclose(
        (X @ X.inv()).as_matrix(), np.broadcast_to(np.eye(4), MX.shape), atol=1e-12
    )


@pytest.mark.parametrize("scale", [1e-150, 1e150])
def test_affine_inverse_extreme_scales(rng, scale):
    A = (np.eye(3) + 0.3 * rng.standard_normal((3, 3))) * scale
    X = rk.Affine(matrix=A, translation=np.array([1.0, 2.0, 3.0]) * scale)
    inv = X.inv()
    np.testing.assert_allclose(inv.matrix, np.linalg.inv(A), rtol=1e-13)
    np.testing.assert_allclose(inv @ (X @ np.ones(3)), np.ones(3), rtol=1e-12)


def test_affine_validation():
    A = np.tile(np.eye(3), (2, 2, 1, 1))
    A[1, 0] = [[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]]  # rank 2
    with pytest.raises(rk.SingularMatrixError, match=r"\(1, 0\)") as err:
        rk.Affine(matrix=A)
    assert isinstance(err.value, ValueError)
    # nearly parallel rows: Hadamard ratio ~1e-13 (below the default 1e-12)
    near = np.array([[1.0, 0.0, 0.0], [1.0, 1e-13, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(rk.SingularMatrixError):
        rk.Affine(matrix=near)
    assert rk.Affine(matrix=near, rtol=1e-14).shape == ()  # the threshold is the user's
    # scaling a row is harmless: diag(1, 1, 1e-13) has an exact inverse
    small = rk.Affine(matrix=np.diag([1.0, 1.0, 1e-13]))
    np.testing.assert_array_equal(small.inv().matrix, np.diag([1.0, 1.0, 1e13]))
    with pytest.raises(rk.NonFiniteError):
        rk.Affine(matrix=np.full((3, 3), np.nan))
    M = np.tile(np.eye(4), (3, 1, 1))
    M[2, 3, 1] = 0.5
    with pytest.raises(rk.NotAffineError, match=r"\(2,\)"):
        rk.Affine.from_matrix(M)
    S = np.eye(4)
    S[:3, :3] = 0.0
    with pytest.raises(rk.SingularMatrixError):
        rk.Affine.from_matrix(S)
    # a reflection or a shear is a fine affine map
    assert rk.Affine(matrix=np.diag([-1.0, 1.0, 1.0])).shape == ()
    # inv of a product that became singular to working precision is refused
    X = rk.Affine(matrix=[[1.0, 0.0, 0.0], [1.0, 1e-7, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(rk.SingularMatrixError):
        (X @ X).inv()


def test_affine_broadcast_and_float32(rng):
    X = rk.Affine(
        matrix=np.eye(3, dtype=np.float32) * 2, translation=np.zeros((4, 3), np.float32)
    )
    assert X.shape == (4,) and X.dtype == np.float32
    assert (X @ X).dtype == np.float32 and X.inv().dtype == np.float32
    np.testing.assert_allclose(
        X.inv() @ np.ones(3, dtype=np.float32), 0.5 * np.ones((4, 3))
    )
    assert rk.Affine(translation=[1, 2, 3]).dtype == np.float64
    assert "matrix=" in repr(rk.Affine()) and "shape=(4,)" in repr(X)
    back = pickle.loads(pickle.dumps(X))
    np.testing.assert_array_equal(back.as_matrix(), X.as_matrix())


# -- Projective ---------------------------------------------------------------------------


def test_projective_ops_against_matrices(rng):
    X, Y = rk.Projective.random(20, rng), rk.Projective.random(20, rng)
    H, G = X.as_matrix(), Y.as_matrix()
    np.testing.assert_allclose((X @ Y).as_matrix(), H @ G, rtol=0, atol=1e-14 * 16)
    assert_inverse_close(X.inv().as_matrix(), H)
    p = rng.standard_normal((20, 3)) * 0.3
    h = (H @ np.concatenate([p, np.ones((20, 1))], axis=-1)[..., None])[..., 0]
    np.testing.assert_allclose(X.apply_homogeneous(p), h, rtol=0, atol=1e-14 * 8)
    np.testing.assert_allclose(X @ p, h[:, :3] / h[:, 3:], rtol=1e-13)
    np.testing.assert_allclose(X.inv() @ (X @ p), p, rtol=0, atol=1e-12)
    # H and cH are the same transform
    Z = rk.Projective(-3.0 * H)
    assert np.all(Z.approx_equal(X))
    np.testing.assert_allclose(Z @ p, X @ p, rtol=1e-13)
    assert not np.any(X.approx_equal(Y))


def test_points_at_infinity():
    H = np.eye(4)
    H[2] = [0.0, 0.0, 0.0, 1.0]
    H[3] = [0.0, 0.0, 1.0, 0.0]  # (x, y, z) -> (x, y, 1) / z: z = 0 goes to infinity
    P = rk.Projective(H)
    pts = np.array([[[1.0, 2.0, 4.0], [1.0, 2.0, 0.0]], [[3.0, 3.0, 1.0], [0.0, 0.0, 2.0]]])
    with pytest.raises(rk.PointAtInfinityError, match=r"\(0, 1\)") as err:
        P @ pts
    assert isinstance(err.value, ValueError)
    got = P.apply(pts, at_infinity="nan")
    assert np.all(np.isnan(got[0, 1]))
    np.testing.assert_array_equal(got[0, 0], [0.25, 0.5, 0.25])
    np.testing.assert_array_equal(got[1], [[3.0, 3.0, 1.0], [0.0, 0.0, 0.5]])
    np.testing.assert_array_equal(P.apply_homogeneous(pts)[0, 1], [1.0, 2.0, 1.0, 0.0])
    # close to the plane but above the tolerance: a large, correct, finite point
    far = P @ np.array([1.0, 0.0, 1e-10])
    np.testing.assert_allclose(far, [1e10, 0.0, 1e10], rtol=1e-15)
    # below the tolerance (64 eps relative): reported, never divided by ~0
    with pytest.raises(rk.PointAtInfinityError):
        P @ np.array([1.0, 0.0, 1e-15])
    assert P.apply(np.array([1.0, 0.0, 1e-15]), rtol=0.0)[0] == pytest.approx(1e15)
    with pytest.raises(ValueError, match="at_infinity"):
        P.apply(pts, at_infinity="inf")


def test_projective_validation_and_float32(rng):
    H = np.tile(np.eye(4), (3, 1, 1))
    H[1, 3] = H[1, 2]  # two equal rows
    with pytest.raises(rk.SingularMatrixError, match=r"\(1,\)"):
        rk.Projective(H)
    with pytest.raises(rk.SingularMatrixError):
        rk.Projective.from_matrix(np.zeros((4, 4)))
    with pytest.raises(rk.NonFiniteError):
        rk.Projective(np.full((4, 4), np.inf))
    with pytest.raises(rk.ShapeError):
        rk.Projective(np.eye(3))
    X = rk.Projective(np.eye(4, dtype=np.float32) * 2)
    assert (X @ X).dtype == np.float32 and X.inv().dtype == np.float32
    assert (X @ np.ones(3, dtype=np.float32)).dtype == np.float32
    big = rk.Projective(rk.Projective.random((), rng).as_matrix() * 1e200)
    np.testing.assert_allclose(
        big.inv().as_matrix() @ big.as_matrix(), np.eye(4), atol=1e-12
    )


# -- the ladder: inclusions and mixed composition ------------------------------------------


def _one_of_each(rng, n=6):
    return [
        rk.Rotation.random(n, rng),
        rk.Transform.random(n, rng),
        rk.Similarity.random(n, rng),
        rk.Affine.random(n, rng),
        rk.Projective.random(n, rng),
    ]


def test_inclusions_commute_with_as_matrix(rng):
    T = rk.Transform.random(8, rng)
    S = rk.Similarity.from_transform(T)
    np.testing.assert_array_equal(S.scale, np.ones(8))
    np.testing.assert_allclose(S.as_matrix(), T.as_matrix(), rtol=0, atol=0)
    S = rk.Similarity.random(8, rng)
    A = rk.Affine.from_similarity(S)
    np.testing.assert_array_equal(A.as_matrix(), S.as_matrix())
    np.testing.assert_array_equal(S.as_affine().as_matrix(), S.as_matrix())
    P = rk.Projective.from_affine(A)
    np.testing.assert_array_equal(P.as_matrix(), A.as_matrix())
    np.testing.assert_array_equal(A.as_projective().as_matrix(), A.as_matrix())
    np.testing.assert_array_equal(S.as_projective().as_matrix(), S.as_matrix())
    # the chain equals the direct inclusion, and rotations enter at the bottom
    chain = rk.Projective.from_affine(
        rk.Affine.from_similarity(rk.Similarity.from_transform(T))
    )
    np.testing.assert_array_equal(
        chain.as_matrix(), rk.Projective.from_affine(T).as_matrix()
    )
    R = rk.Rotation.random(8, rng)
    M = np.tile(np.eye(4), (8, 1, 1))
    M[:, :3, :3] = R.as_matrix()
    for K, f in (
        (rk.Similarity, "from_transform"),
        (rk.Affine, "from_similarity"),
        (rk.Projective, "from_affine"),
    ):
        np.testing.assert_allclose(getattr(K, f)(R).as_matrix(), M, rtol=0, atol=1e-15)
    # points are mapped the same way at every rung
    p = rng.standard_normal((8, 3))
    for X in (S, A, P):
        np.testing.assert_allclose(X @ p, S @ p, rtol=0, atol=1e-14 * 8)


def test_inclusion_refuses_a_more_general_kind(rng):
    with pytest.raises(TypeError):
        rk.Similarity.from_transform(rk.Affine.random((), rng))
    with pytest.raises(TypeError):
        rk.Affine.from_similarity(rk.Projective.random((), rng))
    with pytest.raises(TypeError):
        rk.Projective.from_affine(np.eye(4))


KIND_NAMES = ["Rotation", "Transform", "Similarity", "Affine", "Projective"]


@pytest.mark.parametrize("j", range(5), ids=KIND_NAMES)
@pytest.mark.parametrize("i", range(5), ids=KIND_NAMES)
def test_mixed_composition_gives_the_most_general_kind(rng, i, j):
    if i < 2 and j < 2:
        pytest.skip("Rotation/Transform among themselves are tested with SE(3)")
    a = _one_of_each(rng)[i]
    b = _one_of_each(np.random.default_rng(7))[j]
    c = a @ b
    assert type(c).__name__ == KIND_NAMES[max(i, j)]
    np.testing.assert_allclose(homog(c), homog(a) @ homog(b), rtol=0, atol=1e-13)
    p = rng.standard_normal((6, 3)) * 0.2
    np.testing.assert_allclose(c @ p, a @ (b @ p), rtol=1e-12, atol=1e-12)


def test_mixed_composition_broadcasts(rng):
    S = rk.Similarity.random((2, 1), rng)
    A = rk.Affine.random(3, rng)
    C = S @ A
    assert isinstance(C, rk.Affine) and C.shape == (2, 3)
    np.testing.assert_allclose(C.as_matrix(), S.as_matrix() @ A.as_matrix(), atol=1e-13)


def test_array_on_the_left_is_refused(rng):
    for X in _one_of_each(rng)[2:]:
        with pytest.raises(TypeError, match="not defined"):
            np.eye(4) @ X
        with pytest.raises(rk.ShapeError):
            X @ "points"


def test_affine_projective_torch_and_array_api(rng):
    torch = pytest.importorskip("torch")
    A = np.eye(3) + 0.3 * rng.standard_normal((4, 3, 3))
    t = rng.standard_normal((4, 3))
    H = np.eye(4) + 0.2 * rng.standard_normal((4, 4, 4))
    p = rng.standard_normal((4, 3)) * 0.3
    X, P = rk.Affine(matrix=A, translation=t), rk.Projective(H)
    Xt = rk.Affine(matrix=torch.tensor(A), translation=torch.tensor(t))
    Pt = rk.Projective(torch.tensor(H))
    S = rk.Similarity.random(4, rng)
    St = rk.Similarity(
        scale=torch.tensor(S.scale),
        rotation=rk.Rotation.from_quat(torch.tensor(S.rotation.as_quat())),
        translation=torch.tensor(S.translation),
    )
    for got, want in [
        ((Xt @ Xt).as_matrix(), (X @ X).as_matrix()),
        (Xt.inv().as_matrix(), X.inv().as_matrix()),
        (Xt @ torch.tensor(p), X @ p),
        ((Pt @ Pt).as_matrix(), (P @ P).as_matrix()),
        (Pt.inv().as_matrix(), P.inv().as_matrix()),
        (Pt @ torch.tensor(p), P @ p),
        ((St @ Xt).as_matrix(), (S @ X).as_matrix()),
        ((Xt @ Pt).as_matrix(), (X @ P).as_matrix()),
    ]:
        assert isinstance(got, torch.Tensor)
        np.testing.assert_allclose(got.numpy(), want, rtol=0, atol=1e-13)
    assert bool(Xt.approx_equal(Xt).all()) and bool(Pt.approx_equal(Pt).all())

    import array_api_strict as xps

    Xa = rk.Affine(matrix=xps.asarray(A), translation=xps.asarray(t))
    np.testing.assert_allclose(
        np.asarray((Xa @ Xa).as_matrix()), (X @ X).as_matrix(), atol=1e-14
    )


def test_identities(rng):
    p = rng.standard_normal((5, 3))
    for K in (rk.Similarity, rk.Affine, rk.Projective):
        Id = K.identity((5,))
        assert Id.shape == (5,)
        np.testing.assert_array_equal(Id @ p, p)
        np.testing.assert_array_equal(homog(K.identity()), np.eye(4))


def test_sim3_functional_layer(rng):
    xi = twists(rng, 20) * 0.7
    eta = twists(rng, 20)
    np.testing.assert_array_equal(rk.sim3.hat(xi), sim3_hat(xi))
    np.testing.assert_array_equal(rk.sim3.vee(rk.sim3.hat(xi)), xi)
    # bracket = vee of the matrix commutator, and ad(xi) @ eta = bracket(xi, eta)
    A, B = sim3_hat(xi), sim3_hat(eta)
    br = rk.sim3.bracket(xi, eta)
    np.testing.assert_allclose(rk.sim3.hat(br), A @ B - B @ A, rtol=0, atol=1e-14 * 16)
    np.testing.assert_allclose(
        (rk.sim3.ad(xi) @ eta[..., None])[..., 0], br, atol=1e-14 * 8
    )
    # Ad(exp(xi)) = expm(ad(xi))
    M = rk.sim3.exp(xi)
    np.testing.assert_allclose(
        rk.Similarity.exp(xi).as_matrix(),
        np.array([sl.expm(a) for a in sim3_hat(xi)]),
        rtol=0,
        atol=1e-14 * 8 * np.abs(M).max(),
    )
    for Ad, a in zip(rk.sim3.adjoint(M), rk.sim3.ad(xi), strict=True):
        np.testing.assert_allclose(Ad, sl.expm(a), rtol=0, atol=1e-13 * np.abs(Ad).max())
    np.testing.assert_allclose(rk.sim3.log(M), xi, rtol=0, atol=1e-14 * 8)
    with pytest.raises(rk.NotASimilarityError):
        rk.sim3.log(np.diag([1.0, 2.0, 3.0, 1.0]))


# -- the ladder of kinds (rigidkit.objects.ladder) ---------------------------------------
def test_ladder_ranks_and_families():
    from rigidkit.objects import ladder, registry

    ranks = [ladder.kind_of(x)[1:] for x in _one_of_each(np.random.default_rng(1))]
    assert ranks == [("space", r) for r in range(5)]
    assert ladder.kind_of(rk.Transform2D.identity())[1:] == ("plane", 1)
    assert ladder.kind_of(np.eye(4)) is None
    with pytest.raises(ValueError, match="already has rank"):
        registry.register(type("Impostor", (), {}), "space", 2)


def test_ladder_homogeneous_matrix_of_a_rotation(rng):
    from rigidkit.objects import ladder

    R = rk.Rotation.random((2, 3), rng)
    np.testing.assert_array_equal(ladder.homogeneous_matrix(R), homog(R))


def test_families_do_not_mix(rng):
    with pytest.raises(TypeError, match="family"):
        rk.Rotation.random((), rng) @ rk.Rotation2D.random((), rng)
    with pytest.raises(TypeError, match="family"):
        rk.Transform2D.random((), rng) @ rk.Similarity.random((), rng)
    with pytest.raises(TypeError):
        rk.Transform2D.include(rk.Rotation.identity())


def test_include_is_the_inclusion_map(rng):
    R = rk.Rotation.random(4, rng)
    T = rk.Transform.include(R)
    assert type(T) is rk.Transform
    np.testing.assert_allclose(T.as_matrix(), homog(R), rtol=0, atol=1e-15)
    assert rk.Transform.include(T) is T
    R2 = rk.Rotation2D.random(4, rng)
    M2 = np.asarray(rk.Transform2D.include(R2).as_matrix())
    np.testing.assert_array_equal(M2[..., :2, :2], R2.as_matrix())
    np.testing.assert_array_equal(M2[..., :2, 2], 0.0)
    with pytest.raises(TypeError):
        rk.Rotation.include(T)  # a more general kind is not included
    with pytest.raises(TypeError):
        rk.Similarity.include(rk.Affine.identity())


def test_a_subclass_keeps_its_place_on_the_ladder(rng):
    class MyRotation(rk.Rotation):
        __slots__ = ()

    R = MyRotation._wrap(rk.Rotation.random(3, rng).as_quat())
    T = rk.Transform.random(3, rng)
    np.testing.assert_allclose((R @ T).as_matrix(), homog(R) @ homog(T), atol=1e-14)
    np.testing.assert_allclose((T @ R).as_matrix(), homog(T) @ homog(R), atol=1e-14)
