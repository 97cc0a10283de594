"""The ``Rotation`` API against ``scipy.spatial.transform.Rotation`` (conventions).

scipy is the independent reference for every convention: quaternion order
(scipy's default is scalar-last ``(x, y, z, w)``, ours scalar-first), matrices,
rotation vectors, MRPs, composition order (scipy's ``a * b`` applies ``b``
first, like our ``a @ b``), ``apply``, ``inv``, canonical quaternions. Orientations
are compared as matrices, or as quaternions up to sign (``conftest.quat_angle``).

Tolerances: 1e-15 for entries of matrices and unit vectors/quaternions (both
libraries are accurate to a few 1e-16 on these), relative 1e-15 for rotation vectors
and MRPs of generic rotations; round trips must land within 1e-15 rad.
"""

from __future__ import annotations

import math
import pickle
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk
from conftest import quat_angle

ATOL = 1e-15


def _random(n, seed=0):
    """rigidkit and scipy rotations holding the same quaternions."""
    R = rk.Rotation.random(n, seed)
    return R, SciRot.from_quat(R.as_quat(scalar_first=False))


# -- representations vs scipy ----------------------------------------------------------
def test_from_quat_both_orders(rng):
    q_wxyz = rng.standard_normal((50, 4)) * rng.uniform(0.1, 10, (50, 1))
    q_xyzw = q_wxyz[:, [1, 2, 3, 0]]
    S = SciRot.from_quat(q_xyzw)
    A = rk.Rotation.from_quat(q_wxyz)
    B = rk.Rotation.from_quat(q_xyzw, scalar_first=False)
    np.testing.assert_allclose(A.as_matrix(), S.as_matrix(), atol=ATOL)
    np.testing.assert_allclose(B.as_matrix(), S.as_matrix(), atol=ATOL)
    # The stored quaternion is q / |q| (its sign kept), in either order.
    unit = q_wxyz / np.linalg.norm(q_wxyz, axis=-1, keepdims=True)
    np.testing.assert_allclose(A.as_quat(), unit, atol=ATOL)
    np.testing.assert_allclose(
        A.as_quat(scalar_first=False), unit[:, [1, 2, 3, 0]], atol=ATOL
    )


def test_as_quat_canonical_matches_scipy():
    special = np.array(
        [
            [-1.0, 0, 0, 0],
            [0.0, -1, 0, 0],
            [0.0, 0, -1, 0],
            [0.0, 0, 0, -1],
            [0.0, 0, -0.6, 0.8],
            [0.0, -0.6, 0.8, 0],
            [-0.5, 0.5, -0.5, 0.5],
        ]
    )
    q = np.concatenate([special, np.random.default_rng(1).standard_normal((40, 4))])
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    R = rk.Rotation.from_quat(q)
    S = SciRot.from_quat(q, scalar_first=True)
    np.testing.assert_allclose(
        R.as_quat(canonical=True), S.as_quat(canonical=True, scalar_first=True), atol=ATOL
    )
    np.testing.assert_allclose(
        R.as_quat(canonical=True, scalar_first=False), S.as_quat(canonical=True), atol=ATOL
    )
    assert (R.as_quat(canonical=True)[:, 0] >= 0).all()


def test_matrix_both_ways():
    R, S = _random(100)
    np.testing.assert_allclose(R.as_matrix(), S.as_matrix(), atol=ATOL)
    M = S.as_matrix()
    back = rk.Rotation.from_matrix(M)
    assert (quat_angle(back.as_quat(), S.as_quat(scalar_first=True)) <= 1e-15).all()
    # Active, column vectors: the first column is the image of e_x.
    Rz = rk.Rotation.from_rotvec([0.0, 0.0, math.pi / 2])
    np.testing.assert_allclose(Rz.as_matrix()[:, 0], [0.0, 1.0, 0.0], atol=ATOL)


@pytest.mark.parametrize("degrees", [False, True])
def test_rotvec_both_ways(degrees):
    R, S = _random(100, 2)
    got = R.as_rotvec(degrees=degrees)
    want = S.as_rotvec(degrees=degrees)
    np.testing.assert_allclose(
        got, want, rtol=1e-15 * 180, atol=ATOL * (180 if degrees else 4)
    )
    back = rk.Rotation.from_rotvec(want, degrees=degrees)
    np.testing.assert_allclose(back.as_matrix(), S.as_matrix(), atol=2 * ATOL)


def test_mrp_both_ways():
    R, S = _random(100, 3)
    np.testing.assert_allclose(R.as_mrp(), S.as_mrp(), rtol=1e-15, atol=ATOL)
    p = S.as_mrp()
    np.testing.assert_allclose(
        rk.Rotation.from_mrp(p).as_matrix(), S.as_matrix(), atol=ATOL
    )
    # The shadow set -p/|p|^2 names the same rotation.
    shadow = -p / np.sum(p * p, axis=-1, keepdims=True)
    assert (quat_angle(rk.Rotation.from_mrp(shadow).as_quat(), R.as_quat()) < 1e-15).all()


@pytest.mark.parametrize("degrees", [False, True])
def test_axis_angle_both_ways(degrees, rng):
    axis = rng.standard_normal((60, 3)) * rng.uniform(0.01, 100, (60, 1))
    angle = rng.uniform(-2 * math.pi, 2 * math.pi, 60)
    unit = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    S = SciRot.from_rotvec(unit * angle[:, None])
    scale = 180 / math.pi if degrees else 1.0
    R = rk.Rotation.from_axis_angle(axis, angle * scale, degrees=degrees)
    np.testing.assert_allclose(R.as_matrix(), S.as_matrix(), atol=4 * ATOL)
    a, t = R.as_axis_angle(degrees=degrees)
    np.testing.assert_allclose(np.linalg.norm(a, axis=-1), 1.0, atol=ATOL)
    rv = S.as_rotvec()
    # Input angles up to 2 pi carry ulp(2 pi) = 8.9e-16 each, so two correct results
    # (ours from sin(angle/2), scipy's from unit * angle) differ by a few of those.
    np.testing.assert_allclose(
        t / scale, np.linalg.norm(rv, axis=-1), rtol=1e-15, atol=4e-15
    )
    # The axis of a rotation by t is conditioned like eps / t (t >= 0.04 here).
    np.testing.assert_allclose(
        a, rv / np.linalg.norm(rv, axis=-1, keepdims=True), atol=1e-14
    )
    # The angle and axis properties against scipy's magnitude and rotation vector.
    np.testing.assert_allclose(R.angle, S.magnitude(), rtol=1e-15, atol=4e-15)
    np.testing.assert_allclose(
        R.axis, rv / np.linalg.norm(rv, axis=-1, keepdims=True), atol=1e-14
    )
    # The identity: angle 0, axis +x (documented).
    a0, t0 = rk.Rotation.identity().as_axis_angle()
    np.testing.assert_array_equal(a0, [1.0, 0.0, 0.0])
    assert t0 == 0.0


# -- group operations ------------------------------------------------------------------
def test_compose_order_and_apply():
    A, SA = _random(50, 4)
    B, SB = _random(50, 5)
    AB = A @ B
    np.testing.assert_allclose(AB.as_matrix(), A.as_matrix() @ B.as_matrix(), atol=4 * ATOL)
    np.testing.assert_allclose(AB.as_matrix(), (SA * SB).as_matrix(), atol=4 * ATOL)
    v = np.random.default_rng(6).standard_normal((50, 3))
    np.testing.assert_allclose(A @ v, SA.apply(v), rtol=1e-15, atol=4 * ATOL)
    np.testing.assert_allclose(
        A.apply(v), np.einsum("nij,nj->ni", A.as_matrix(), v), atol=4e-15
    )
    # (A @ B) @ v == A @ (B @ v): B is applied first.
    np.testing.assert_allclose(AB @ v, A @ (B @ v), atol=4e-15)


def test_right_body_left_world():
    """R @ Rx(a) turns about the body x-axis, Rx(a) @ R about the world x-axis."""
    R = rk.Rotation.from_rotvec([0.3, -1.1, 0.7])
    Rx = rk.Rotation.from_rotvec([0.5, 0.0, 0.0])
    body_x = R.as_matrix()[:, 0]
    # Turning about the body x-axis leaves the body x-axis where it is.
    np.testing.assert_allclose((R @ Rx).as_matrix()[:, 0], body_x, atol=ATOL)
    # Turning about the world x-axis leaves every world x-coordinate where it is.
    np.testing.assert_allclose((Rx @ R).as_matrix()[0], R.as_matrix()[0], atol=ATOL)


def test_inverse_and_identity():
    R, S = _random(30, 7)
    np.testing.assert_allclose(R.inv().as_matrix(), S.inv().as_matrix(), atol=ATOL)
    np.testing.assert_allclose(R.inv().as_matrix(), np.swapaxes(R.as_matrix(), -1, -2))
    assert (quat_angle((R @ R.inv()).as_quat(), [1.0, 0, 0, 0]) <= 1e-15).all()
    I = rk.Rotation.identity()
    assert I.shape == ()
    np.testing.assert_array_equal(I.as_matrix(), np.eye(3))
    I23 = rk.Rotation.identity((2, 3))
    assert I23.shape == (2, 3)
    np.testing.assert_array_equal(I23.as_quat(), np.broadcast_to([1.0, 0, 0, 0], (2, 3, 4)))
    assert rk.Rotation.identity(4, dtype=np.float32).as_quat().dtype == np.float32


def test_random_is_uniform_and_seeded():
    R = rk.Rotation.random(20000, np.random.default_rng(42))
    assert R.shape == (20000,)
    # Haar measure: each matrix entry has mean 0 and variance 1/3.
    M = R.as_matrix()
    sigma = math.sqrt(1 / 3 / len(M))
    assert np.abs(M.mean(axis=0)).max() < 5 * sigma
    np.testing.assert_allclose((M**2).mean(axis=0), 1 / 3, atol=0.02)
    # The angle has density (1 - cos t) / pi on [0, pi]: P(t <= a) = (a - sin a) / pi.
    t = R.angle
    for a in (0.5, math.pi / 2, 2.5):
        p = (a - math.sin(a)) / math.pi
        assert abs((t <= a).mean() - p) < 5 * math.sqrt(p * (1 - p) / len(t))
    # Seeded: the same generator state gives the same rotations.
    a = rk.Rotation.random((2, 3), 7).as_quat()
    b = rk.Rotation.random((2, 3), np.random.default_rng(7)).as_quat()
    np.testing.assert_array_equal(a, b)
    assert a.shape == (2, 3, 4)
    assert rk.Rotation.random(rng=1).shape == ()


def test_approx_equal_q_and_minus_q():
    R, _ = _random(20, 8)
    minus = rk.Rotation.from_quat(-R.as_quat())
    assert np.all(R.approx_equal(minus, atol=1e-15))
    turned = R @ rk.Rotation.from_rotvec([1e-6, 0.0, 0.0])
    assert not np.any(R.approx_equal(turned, atol=1e-7))
    assert np.all(R.approx_equal(turned, atol=2e-6))


def test_plus_minus_identities():
    X, SX = _random(40, 9)
    Y, SY = _random(40, 10)
    tau = np.random.default_rng(11).standard_normal((40, 3))
    E = rk.Rotation.from_rotvec(tau)
    # right: X (+) tau = X exp(tau); left: exp(tau) X
    assert (quat_angle(X.plus(tau).as_quat(), (X @ E).as_quat()) <= 1e-15).all()
    assert (
        quat_angle(X.plus(tau, side="left").as_quat(), (E @ X).as_quat()) <= 1e-15
    ).all()
    # right: X (-) Y = log(Y^-1 X), against scipy; Y (+) (X (-) Y) = X
    np.testing.assert_allclose(X.minus(Y), (SY.inv() * SX).as_rotvec(), atol=4e-15)
    assert (quat_angle(Y.plus(X.minus(Y)).as_quat(), X.as_quat()) <= 2e-15).all()
    np.testing.assert_allclose(
        X.minus(Y, side="left"), (SX * SY.inv()).as_rotvec(), atol=4e-15
    )
    back = Y.plus(X.minus(Y, side="left"), side="left")
    assert (quat_angle(back.as_quat(), X.as_quat()) <= 2e-15).all()
    with pytest.raises(ValueError, match="side"):
        X.plus(tau, side="middle")


def test_exp_log():
    R, S = _random(30, 12)
    np.testing.assert_allclose(R.log(), S.as_rotvec(), rtol=1e-15, atol=4 * ATOL)
    w = S.as_rotvec()
    np.testing.assert_allclose(rk.Rotation.exp(w).as_matrix(), S.as_matrix(), atol=2 * ATOL)


# -- containers ------------------------------------------------------------------------
def test_shape_len_index_iter():
    R = rk.Rotation.random((4, 3), 13)
    assert R.shape == (4, 3) and len(R) == 4
    q = R.as_quat()
    np.testing.assert_array_equal(R[1].as_quat(), q[1])
    np.testing.assert_array_equal(R[1, 2].as_quat(), q[1, 2])
    assert R[1, 2].shape == ()
    np.testing.assert_array_equal(R[1:3].as_quat(), q[1:3])
    np.testing.assert_array_equal(R[np.array([0, 3])].as_quat(), q[[0, 3]])
    np.testing.assert_array_equal(R[:, 0].as_quat(), q[:, 0])
    rows = list(R)
    assert len(rows) == 4 and all(r.shape == (3,) for r in rows)
    np.testing.assert_array_equal(rows[2].as_quat(), q[2])
    single = R[0, 0]
    with pytest.raises(TypeError):
        len(single)
    with pytest.raises(TypeError):
        single[0]
    with pytest.raises(TypeError):
        iter(single).__next__()


def test_concatenate_and_reshape():
    A = rk.Rotation.random(3, 14)
    B = rk.Rotation.random(2, 15)
    c = rk.Rotation.random(rng=16)
    AB = rk.Rotation.concatenate([A, B, c])
    assert AB.shape == (6,)
    np.testing.assert_array_equal(
        AB.as_quat(), np.concatenate([A.as_quat(), B.as_quat(), c.as_quat()[None]])
    )
    R = AB.reshape(2, 3)
    assert R.shape == (2, 3)
    np.testing.assert_array_equal(R.as_quat(), AB.as_quat().reshape(2, 3, 4))
    assert AB.reshape((3, 2)).shape == (3, 2)
    with pytest.raises(ValueError):
        rk.Rotation.concatenate([])


def test_repr():
    R = rk.Rotation.from_rotvec([0.0, 0.0, math.pi / 2])
    text = repr(R)
    assert text.startswith("Rotation.from_quat(")
    again = eval(text, {"Rotation": rk.Rotation})
    assert quat_angle(again.as_quat(), R.as_quat()) < 1e-5  # printed to 6 digits
    batch = repr(rk.Rotation.identity((2, 3)))
    assert "(2, 3)" in batch and "float64" in batch


@pytest.mark.parametrize("shape", [(), (5,), (2, 3)])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_pickle_round_trip(shape, dtype):
    R = rk.Rotation.random(shape, 17, dtype=dtype)
    back = pickle.loads(pickle.dumps(R))
    assert isinstance(back, rk.Rotation) and back.shape == shape
    assert back.as_quat().dtype == dtype
    np.testing.assert_array_equal(back.as_quat(), R.as_quat())


# -- N-D batches and broadcasting ------------------------------------------------------
def test_compose_broadcasts():
    A = rk.Rotation.random((2, 1), 18)
    B = rk.Rotation.random((3,), 19)
    AB = A @ B
    assert AB.shape == (2, 3)
    want = A.as_matrix() @ B.as_matrix()  # NumPy broadcasting of the matrices
    np.testing.assert_allclose(AB.as_matrix(), want, atol=4 * ATOL)
    # A single rotation composes with any batch.
    c = rk.Rotation.random(rng=20)
    assert (c @ AB).shape == (2, 3) and (AB @ c).shape == (2, 3)


def test_apply_broadcasts():
    A = rk.Rotation.random((2, 1), 21)
    v = np.random.default_rng(22).standard_normal((3, 3))
    out = A @ v
    assert out.shape == (2, 3, 3)
    want = np.einsum("aij,bj->abi", A.as_matrix()[:, 0], v)
    np.testing.assert_allclose(out, want, atol=4e-15)
    # One rotation on a point cloud, and a batch on one point.
    c = rk.Rotation.random(rng=23)
    cloud = np.random.default_rng(24).standard_normal((4, 5, 3))
    np.testing.assert_allclose(c @ cloud, cloud @ c.as_matrix().T, atol=4e-15)
    assert (A @ np.ones(3)).shape == (2, 1, 3)
    # out= writes into a buffer (here on the numba path, more than 1000 points)
    big = np.random.default_rng(25).standard_normal((2000, 3))
    buf = np.empty_like(big)
    res = c.apply(big, out=buf)
    assert res is buf
    np.testing.assert_allclose(buf, big @ c.as_matrix().T, atol=4e-15)


def test_empty_batches():
    R = rk.Rotation.from_quat(np.zeros((0, 4)))
    assert R.shape == (0,) and len(R) == 0
    assert R.as_matrix().shape == (0, 3, 3)
    assert (R @ np.zeros((0, 3))).shape == (0, 3)
    assert rk.Rotation.from_matrix(np.zeros((0, 3, 3))).shape == (0,)
    assert rk.Rotation.from_rotvec(np.zeros((2, 0, 3))).shape == (2, 0)


def test_float32_stays_float32():
    q = np.random.default_rng(26).standard_normal((10, 4)).astype(np.float32)
    R = rk.Rotation.from_quat(q)
    for out in (
        R.as_quat(),
        R.as_matrix(),
        R.as_rotvec(),
        R.as_mrp(),
        R.as_axis_angle()[0],
        R.angle,
        R @ np.ones((10, 3), np.float32),
        (R @ R).as_quat(),
        R.inv().as_quat(),
        R.log(),
        rk.Rotation.from_matrix(R.as_matrix()).as_quat(),
        rk.Rotation.from_rotvec(R.as_rotvec()).as_quat(),
        rk.Rotation.from_mrp(R.as_mrp()).as_quat(),
    ):
        assert out.dtype == np.float32


# -- round trips (hypothesis): every representation ------------------------------------
finite = st.floats(-1.0, 1.0, allow_nan=False, width=64)
quats = arrays(np.float64, (4,), elements=finite).filter(lambda q: np.linalg.norm(q) > 0.1)
special = st.sampled_from(
    [
        np.array([1.0, 0, 0, 0]),
        np.array([0.0, 1, 0, 0]),
        np.array([0.0, 0.6, 0.8, 0]),
        np.array([1e-9, 0.6, 0, 0.8]),
        np.array([-1e-13, 0, 1, 0]),
        np.array([1.0, 1e-9, 0, 0]),
        np.array([1.0, 0, -1e-13, 1e-14]),
    ]
)
rotations = st.one_of(quats, special).map(lambda q: rk.Rotation.from_quat(q))


def _same(A, B, tol=1e-15):
    angle = quat_angle(A.as_quat(), B.as_quat())
    assert angle <= tol, f"round trip off by {angle:.3g} rad"


@given(rotations)
def test_round_trip_quat(R):
    _same(rk.Rotation.from_quat(R.as_quat()), R)
    _same(rk.Rotation.from_quat(R.as_quat(scalar_first=False), scalar_first=False), R)
    _same(rk.Rotation.from_quat(R.as_quat(canonical=True)), R)


@given(rotations)
def test_round_trip_matrix(R):
    M = R.as_matrix()
    # Exactly (rational arithmetic on the float entries): each entry is within 5e-16
    # of the true rotation's, so M^T M - I and det M - 1 are within ~2e-15.
    F = [[Fraction(float(c)) for c in row] for row in M]
    gram = [[sum(F[k][i] * F[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    assert (
        max(abs(float(gram[i][j] - (i == j))) for i in range(3) for j in range(3)) <= 2e-15
    )
    det = (
        F[0][0] * (F[1][1] * F[2][2] - F[1][2] * F[2][1])
        - F[0][1] * (F[1][0] * F[2][2] - F[1][2] * F[2][0])
        + F[0][2] * (F[1][0] * F[2][1] - F[1][1] * F[2][0])
    )
    assert abs(float(det - 1)) <= 2e-15
    _same(rk.Rotation.from_matrix(M), R)


@given(rotations)
def test_round_trip_rotvec(R):
    r = R.as_rotvec()
    assert np.linalg.norm(r) <= math.pi * (1 + 1e-15)
    _same(rk.Rotation.from_rotvec(r), R)
    _same(rk.Rotation.from_rotvec(R.as_rotvec(degrees=True), degrees=True), R, 2e-15)


@given(rotations)
def test_round_trip_mrp(R):
    p = R.as_mrp()
    assert np.linalg.norm(p) <= 1 + 1e-15
    _same(rk.Rotation.from_mrp(p), R)


@given(rotations)
def test_round_trip_axis_angle(R):
    axis, angle = R.as_axis_angle()
    assert 0 <= angle <= math.pi
    _same(rk.Rotation.from_axis_angle(axis, angle), R)
    axis, angle = R.as_axis_angle(degrees=True)
    _same(rk.Rotation.from_axis_angle(axis, angle, degrees=True), R, 2e-15)


@given(rotations, rotations)
def test_compose_matches_matrix_product(A, B):
    np.testing.assert_allclose(
        (A @ B).as_matrix(), A.as_matrix() @ B.as_matrix(), atol=4 * ATOL
    )
    _same((A @ B).inv(), B.inv() @ A.inv(), 2e-15)


# -- SymPy forms (rk.symbolic): the corrected seed formulas ------------------------------
sp = pytest.importorskip("sympy")


def _zero(M):
    return all(sp.simplify(e) == 0 for e in sp.Matrix(M))


def test_import_rigidkit_does_not_import_sympy():
    import subprocess
    import sys

    code = "import sys, rigidkit; assert 'sympy' not in sys.modules; rigidkit.symbolic; "
    code += "assert 'sympy' in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_symbolic_matrix_is_orthogonal_for_unit_quaternions():
    S = rk.symbolic
    w, x, y, z = sp.symbols("w x y z", real=True)
    R = S.matrix_from_quat(w, x, y, z)
    assert isinstance(R, sp.MatrixBase) and R.shape == (3, 3)
    unit = {w: sp.sqrt(1 - x**2 - y**2 - z**2)}
    assert _zero((R.T * R - sp.eye(3)).subs(unit))
    assert sp.simplify(R.det().subs(unit) - 1) == 0
    # The same matrix as the grouped call, and numerically as the kernel.
    assert R == S.matrix_from_quat([w, x, y, z])
    q = rk.Rotation.random(rng=3).as_quat()
    num = R.subs(dict(zip((w, x, y, z), q.tolist(), strict=True)))
    np.testing.assert_allclose(
        np.array(num, dtype=float), rk.Rotation.from_quat(q).as_matrix()
    )


def test_symbolic_quaternion_product_is_matrix_product():
    """M(q1 q2) = M(q1) M(q2) as polynomials (Hamilton product, R1 @ R2 order)."""
    S = rk.symbolic
    q1 = sp.symbols("a0:4", real=True)
    q2 = sp.symbols("b0:4", real=True)
    lhs = S.matrix_from_quat(S.quat_multiply(q1, q2))
    rhs = S.matrix_from_quat(q1) * S.matrix_from_quat(q2)
    assert (lhs - rhs).expand() == sp.zeros(3, 3)


def test_symbolic_hat_identities():
    S = rk.symbolic
    w = sp.Matrix(sp.symbols("w0:3", real=True))
    W = S.hat(w)
    # 000 erratum: the (3, 1) entry of hat(w) is -w2 (1-based; w = (w1, w2, w3)).
    assert W[2, 0] == -w[1]
    assert W.T == -W
    v = sp.Matrix(sp.symbols("v0:3", real=True))
    assert (W * v - w.cross(v)).expand() == sp.zeros(3, 1)
    assert S.vee(W) == w
    # hat(w)^2 = w w^T - |w|^2 I
    assert (W * W - (w * w.T - (w.T * w)[0] * sp.eye(3))).expand() == sp.zeros(3, 3)
    # (R w)^ = R hat(w) R^T for a rotation R
    q = sp.symbols("q0:4", real=True)
    R = S.matrix_from_quat(q)
    unit = {q[0]: sp.sqrt(1 - q[1] ** 2 - q[2] ** 2 - q[3] ** 2)}
    assert _zero((S.hat(R * w) - R * W * R.T).subs(unit))


def test_symbolic_rodrigues_and_exp():
    """exp(t hat(a)) = I + sin t hat(a) + (1 - cos t) hat(a)^2 and d/dt R = hat(a) R."""
    S = rk.symbolic
    t = sp.symbols("t", positive=True)
    a = sp.Matrix([2, 3, 6]) / 7  # an exact unit axis
    K = S.hat(a)
    R = S.matrix_from_rotvec(t * a)
    rodrigues = sp.eye(3) + sp.sin(t) * K + (1 - sp.cos(t)) * K * K
    assert _zero(R - rodrigues)
    assert _zero(R.diff(t) - K * R)
    # The rotation vector of R(t) is t a again (for t < pi), through the quaternion.
    q = S.quat_from_rotvec(t * a)
    rv = S.rotvec_from_quat(q).subs(t, sp.Rational(1, 3))
    assert _zero(rv - a / 3)


def test_symbolic_rotational_acceleration():
    """000 erratum: p'' = (hat(w') + hat(w)^2) p for p(t) = R(t) p0, hat(w) = R' R^T.

    R(t) is the rotation of the quaternion (1, t, t^2, 1 - t) / |q|: entries are
    rational functions of t, so the identity is checked exactly by ``cancel``.
    """
    S = rk.symbolic
    t = sp.symbols("t", real=True)
    q = sp.Matrix([1, t, t**2, 1 - t])
    R = S.matrix_from_quat(q / sp.sqrt((q.T * q)[0]))
    R = R.applyfunc(sp.cancel)
    assert (R.T * R - sp.eye(3)).applyfunc(sp.cancel) == sp.zeros(3, 3)
    W = (R.diff(t) * R.T).applyfunc(sp.cancel)
    assert (W + W.T).applyfunc(sp.cancel) == sp.zeros(3, 3)  # skew: an angular velocity
    p0 = sp.Matrix(sp.symbols("p0:3", real=True))
    p = R * p0
    residual = p.diff(t, 2) - (W.diff(t) + W * W) * p
    assert residual.applyfunc(sp.cancel) == sp.zeros(3, 1)
    # Without the derivative of hat(w) (docs/errata.md E3) it is wrong here.
    assert (p.diff(t, 2) - W * W * p).applyfunc(sp.cancel) != sp.zeros(3, 1)


def test_symbolic_quaternion_inverse():
    """002 erratum: q^-1 = q* / |q|^2 (not / |q|)."""
    S = rk.symbolic
    if not hasattr(S, "quat_inverse"):
        pytest.skip("no quat_inverse kernel")
    # q0 > 0 lets SymPy decide the kernel's own zero-norm branch (m > 0).
    q = (sp.Symbol("q0", positive=True),) + sp.symbols("q1:4", real=True)
    inverse = S.quat_inverse(q)
    inverse = inverse[0] if isinstance(inverse, tuple) else inverse
    assert _zero(S.quat_multiply(q, inverse) - sp.Matrix([1, 0, 0, 0]))


def test_symbolic_closed_form_and_exact_kernel_agree():
    """closed_form=False is the kernel as evaluated (series, thresholds); both agree."""
    S = rk.symbolic
    for r in ([0.1, -0.2, 0.3], [1e-3, 2e-3, 0.0], [3.0, 0.1, 0.0]):
        exact = S.matrix_from_rotvec(*r, closed_form=False)
        closed = S.matrix_from_rotvec(*map(sp.Rational, map(str, r)))
        np.testing.assert_allclose(
            np.array(exact, dtype=float),
            np.array(closed.evalf(30), dtype=float),
            atol=1e-15,
        )
        np.testing.assert_allclose(np.array(exact, dtype=float), rk.so3.exp(r), atol=1e-15)
    with pytest.raises(TypeError, match="takes"):
        S.matrix_from_quat(1, 2, 3)
