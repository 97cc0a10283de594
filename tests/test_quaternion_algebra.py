"""The general quaternion algebra: rk.Quaternion and rigidkit.quaternion.

References, all independent of the code under test:
- the Hamilton product from the multiplication table of the basis, written here
  from the defining relations i^2 = j^2 = k^2 = ijk = -1 (so ij = k, jk = i, ki = j),
  and SymPy's ``sympy.algebras.Quaternion`` (also Hamilton);
- exp via ``scipy.linalg.expm`` of the 4x4 real representation ``q+`` (an algebra
  homomorphism, so ``expm(q+) = exp(q)+`` and its first column is ``exp(q)``), and
  log via ``scipy.linalg.logm`` of the same;
- the closed forms ``e^w (cos|v|, sin|v| v/|v|)`` and ``(log|q|, atan2(|v|, w) v/|v|)``
  in mpmath at 50 digits, for the small-|v| bands and the thresholds;
- rotation of vectors against ``rk.Rotation.apply`` and scipy's Rotation.
"""

from __future__ import annotations

import pickle

import mpmath as mp
import numpy as np
import pytest
import scipy.linalg as sl
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk
from rigidkit import quaternion as rq

EPS = np.finfo(np.float64).eps

# -- independent references ---------------------------------------------------------

# Products of basis elements 1, i, j, k (indices 0..3) as (sign, index), from
# i^2 = j^2 = k^2 = -1 and ij = k, jk = i, ki = j (anticommuting).
_TABLE = {
    (0, 0): (1, 0), (0, 1): (1, 1), (0, 2): (1, 2), (0, 3): (1, 3),
    (1, 0): (1, 1), (1, 1): (-1, 0), (1, 2): (1, 3), (1, 3): (-1, 2),
    (2, 0): (1, 2), (2, 1): (-1, 3), (2, 2): (-1, 0), (2, 3): (1, 1),
    (3, 0): (1, 3), (3, 1): (1, 2), (3, 2): (-1, 1), (3, 3): (-1, 0),
}  # fmt: skip


def table_product(a, b):
    """Hamilton product by expanding over the basis table (NumPy, batched)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    out = np.zeros(np.broadcast_shapes(a.shape, b.shape))
    for (m, n), (sign, k) in _TABLE.items():
        out[..., k] += sign * a[..., m] * b[..., n]
    return out


def test_table_satisfies_ijk():
    """The reference table itself: ijk = -1 and i^2 = j^2 = k^2 = -1."""
    i, j, k = np.eye(4)[1], np.eye(4)[2], np.eye(4)[3]
    minus_one = np.array([-1.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(table_product(table_product(i, j), k), minus_one)
    for e in (i, j, k):
        np.testing.assert_array_equal(table_product(e, e), minus_one)


def left_ref(q):
    """``q+ = [[s, -v^T], [v, s I + hat(v)]]``, the matrix of ``p -> q p``."""
    s, (x, y, z) = q[0], q[1:]
    v = np.array([x, y, z])
    hat = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    M = np.empty((4, 4))
    M[0, 0], M[0, 1:], M[1:, 0], M[1:, 1:] = s, -v, v, s * np.eye(3) + hat
    return M


def right_ref(q):
    """``q(+) = [[s, -v^T], [v, s I - hat(v)]]``, the matrix of ``p -> p q``."""
    s, (x, y, z) = q[0], q[1:]
    v = np.array([x, y, z])
    hat = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    M = np.empty((4, 4))
    M[0, 0], M[0, 1:], M[1:, 0], M[1:, 1:] = s, -v, v, s * np.eye(3) - hat
    return M


def mp_exp(q):
    w, v = mp.mpf(q[0]), [mp.mpf(c) for c in q[1:]]
    n = mp.sqrt(sum(c * c for c in v))
    e = mp.exp(w)
    k = e * (mp.sin(n) / n if n != 0 else mp.mpf(1))
    return [e * mp.cos(n)] + [k * c for c in v]


def mp_log(q):
    """Principal log; on the real axis the vector part is ``(atan2(0, w), 0, 0)``
    (0, or ``pi i`` for negative reals: the documented choice of direction)."""
    w, v = mp.mpf(q[0]), [mp.mpf(c) for c in q[1:]]
    n = mp.sqrt(sum(c * c for c in v))
    r = mp.log(mp.sqrt(w * w + n * n))
    if n == 0:
        return [r, mp.atan2(0, w), mp.mpf(0), mp.mpf(0)]
    k = mp.atan2(n, w) / n
    return [r] + [k * c for c in v]


def rel_err(got, want):
    """Largest component error relative to the largest |component| (normwise)."""
    want = [mp.mpf(c) for c in want]
    scale = max(abs(c) for c in want)
    return float(
        max(abs(mp.mpf(float(g)) - c) for g, c in zip(got, want, strict=True)) / scale
    )


quats = st.lists(
    st.floats(-10.0, 10.0, allow_nan=False, allow_subnormal=False), min_size=4, max_size=4
).filter(lambda q: np.linalg.norm(q) > 1e-3)


# -- product ----------------------------------------------------------------------------


def test_product_matches_basis_table(rng):
    a = rng.standard_normal((50, 4))
    b = rng.standard_normal((50, 4))
    got = np.asarray(rk.Quaternion(a) * rk.Quaternion(b))
    np.testing.assert_allclose(got, table_product(a, b), rtol=0, atol=8 * EPS)


def test_basis_relations():
    one, i, j, k = (rk.Quaternion(e) for e in np.eye(4))
    assert np.array_equal(np.asarray(i * j), np.asarray(k))
    assert np.array_equal(np.asarray(j * k), np.asarray(i))
    assert np.array_equal(np.asarray(k * i), np.asarray(j))
    assert np.array_equal(np.asarray(j * i), -np.asarray(k))
    assert np.array_equal(np.asarray(i * j * k), -np.asarray(one))


def test_product_matches_sympy(rng):
    from sympy.algebras.quaternion import Quaternion as SQ

    for _ in range(10):
        a, b = rng.standard_normal(4), rng.standard_normal(4)
        ref = SQ(*a.tolist()) * SQ(*b.tolist())
        want = np.array([float(ref.a), float(ref.b), float(ref.c), float(ref.d)])
        got = rq.multiply(a, b)
        np.testing.assert_allclose(got, want, rtol=0, atol=8 * EPS)


@given(quats, quats, quats)
@settings(max_examples=100)
def test_algebra_identities(a, b, c):
    A, B, C = (rk.Quaternion(np.array(x)) for x in (a, b, c))
    tol = 64 * EPS * (1 + max(np.abs(a).max(), np.abs(b).max(), np.abs(c).max())) ** 3
    # associativity, distributivity, conjugate of a product, |ab| = |a| |b|
    np.testing.assert_allclose(np.asarray((A * B) * C), np.asarray(A * (B * C)), atol=tol)
    np.testing.assert_allclose(np.asarray(A * (B + C)), np.asarray(A * B + A * C), atol=tol)
    np.testing.assert_allclose(
        np.asarray((A * B).conjugate()), np.asarray(B.conjugate() * A.conjugate()), atol=tol
    )
    np.testing.assert_allclose(
        float((A * B).norm()), float(A.norm() * B.norm()), rtol=8 * EPS, atol=0
    )
    # q q* = q* q = |q|^2
    n2 = np.array([np.dot(a, a), 0.0, 0.0, 0.0])
    np.testing.assert_allclose(np.asarray(A * A.conjugate()), n2, atol=tol)
    np.testing.assert_allclose(np.asarray(A.conjugate() * A), n2, atol=tol)


def test_product_matrices(rng):
    """``q1 q2 == q1+ q2 == q2(+) q1``, and both matrices equal their closed forms."""
    a = rng.standard_normal((20, 4))
    b = rng.standard_normal((20, 4))
    A, B = rk.Quaternion(a), rk.Quaternion(b)
    prod = np.asarray(A * B)
    np.testing.assert_allclose(prod, (A.left_matrix() @ b[..., None])[..., 0], atol=8 * EPS)
    np.testing.assert_allclose(
        prod, (B.right_matrix() @ a[..., None])[..., 0], atol=8 * EPS
    )
    for q, L, R in zip(a, rq.left_matrix(a), rq.right_matrix(a), strict=True):
        np.testing.assert_array_equal(L, left_ref(q))
        np.testing.assert_array_equal(R, right_ref(q))
    # homomorphism: (q1 q2)+ = q1+ q2+, and left and right multiplications commute
    np.testing.assert_allclose(
        rq.left_matrix(prod), A.left_matrix() @ B.left_matrix(), atol=1e-14
    )
    np.testing.assert_allclose(
        A.left_matrix() @ B.right_matrix(), B.right_matrix() @ A.left_matrix(), atol=1e-14
    )


# -- norm and inverse -------------------------------------------------------------------


def test_inverse(rng):
    q = rng.standard_normal((100, 4)) * rng.choice([1e-3, 1.0, 1e3], (100, 1))
    Q = rk.Quaternion(q)
    one = np.broadcast_to([1.0, 0.0, 0.0, 0.0], q.shape)
    np.testing.assert_allclose(np.asarray(Q * Q.inv()), one, rtol=0, atol=8 * EPS)
    np.testing.assert_allclose(np.asarray(Q.inv() * Q), one, rtol=0, atol=8 * EPS)
    # q^-1 = q* / |q|^2 (q* / |q|, docs/errata.md E2, is wrong unless |q| = 1)
    ref = q * np.array([1, -1, -1, -1]) / np.sum(q * q, axis=-1, keepdims=True)
    np.testing.assert_allclose(np.asarray(Q.inv()), ref, rtol=4 * EPS, atol=0)
    wrong = q * np.array([1, -1, -1, -1]) / np.linalg.norm(q, axis=-1, keepdims=True)
    assert not np.allclose(np.asarray(Q.inv()), wrong)


@pytest.mark.parametrize("scale", [1e-300, 1e-160, 1e160, 1e300])
def test_norm_and_inverse_do_not_overflow(scale):
    q = np.array([1.0, -2.0, 2.0, 4.0]) * scale  # |q| = 5 scale
    np.testing.assert_allclose(rq.norm(q), 5 * scale, rtol=2 * EPS)
    want = np.array([1.0, 2.0, -2.0, -4.0]) / (25 * scale)
    np.testing.assert_allclose(rq.inv(q), want, rtol=4 * EPS)


def test_zero_quaternion_errors():
    q = np.ones((2, 3, 4))
    q[1, 2] = 0.0
    with pytest.raises(rk.ZeroNormError, match=r"\(1, 2\)"):
        rq.inv(q)
    with pytest.raises(rk.ZeroNormError, match=r"\(1, 2\)"):
        rk.Quaternion(q).log()
    with pytest.raises(rk.ZeroNormError, match=r"\(1, 2\)"):
        rk.Quaternion(q).to_rotation()
    with pytest.raises(rk.ZeroNormError):
        rk.Quaternion(q).rotate([1.0, 0.0, 0.0])
    # the zero quaternion is a fine element otherwise
    Z = rk.Quaternion(np.zeros(4))
    assert float(Z.norm()) == 0.0
    np.testing.assert_array_equal(np.asarray(Z.exp()), [1.0, 0.0, 0.0, 0.0])


# -- exp and log ------------------------------------------------------------------------


def test_exp_matches_expm_of_left_matrix(rng):
    q = rng.standard_normal((60, 4)) * rng.choice([1e-6, 0.1, 1.0, 3.0], (60, 1))
    got = rq.exp(q)
    for g, L in zip(got, rq.left_matrix(q), strict=True):
        E = sl.expm(L)
        # expm(q+) = exp(q)+: first column is exp(q), and it is a left matrix again.
        # scipy's expm is the less accurate side here (up to ~100 ulp, measured
        # against mpmath), hence 1e-13.
        tol = 1e-13 * np.abs(E).max()
        np.testing.assert_allclose(g, E[:, 0], rtol=0, atol=tol)
        np.testing.assert_allclose(rq.left_matrix(g), E, rtol=0, atol=tol)


def test_log_matches_logm_of_left_matrix(rng):
    # (scipy's logm warns about its own accuracy for entries ~1e3; log(c q) = log c +
    # log q is tested through the mpmath comparison below)
    q = rng.standard_normal((20, 4)) * rng.choice([0.1, 1.0, 10.0], (20, 1))
    got = rq.log(q)
    for g, L in zip(got, rq.left_matrix(q), strict=True):
        ref = sl.logm(L)
        assert np.abs(ref.imag).max() < 1e-12
        np.testing.assert_allclose(
            g, ref.real[:, 0], rtol=0, atol=1e-13 * (1 + np.abs(g).max())
        )


BANDS = [
    0.0,
    1e-300,
    1e-12,
    1e-8,
    1e-6,
    1e-4,
    0.0299,
    0.03,
    0.0301,
    0.5,
    1.0,
    3.0,
    3.14,
    10.0,
]


@pytest.mark.parametrize("nv", BANDS)
@pytest.mark.parametrize("w", [-2.0, -1e-8, 0.0, 0.3, 1.0, 5.0])
def test_exp_log_against_mpmath(nv, w):
    mp.mp.dps = 50
    direction = np.array([0.36, -0.48, 0.8])  # unit
    q = np.concatenate([[w], nv * direction])
    got = rq.exp(q)
    # |v| itself is rounded (about eps |v| absolute), which cos and sin pass on:
    # the error bound grows with |v| as it must for any float evaluation.
    assert rel_err(got, mp_exp(q)) <= (4 + 2 * nv) * EPS
    if w == 0.0 and nv == 0.0:
        return
    got = rq.log(q)
    want = mp_log(q)
    # scalar part: absolute accuracy (log|q| may be ~0); vector part: relative
    assert abs(got[0] - float(want[0])) <= 2 * EPS * max(1.0, abs(float(want[0])))
    vec = [mp.mpf(c) for c in want[1:]]
    scale = max(abs(c) for c in vec)
    if scale > 0:
        err = (
            max(abs(mp.mpf(float(g)) - c) for g, c in zip(got[1:], vec, strict=True))
            / scale
        )
        assert float(err) <= 4 * EPS


@given(quats)
@settings(max_examples=150)
def test_exp_log_round_trips(q):
    q = np.array(q)
    Q = rk.Quaternion(q)
    np.testing.assert_allclose(
        np.asarray(Q.log().exp()), q, rtol=0, atol=16 * EPS * np.abs(q).max()
    )
    # log(exp(p)) = p while |vector(p)| < pi (principal branch)
    p = q / max(1.0, np.linalg.norm(q[1:]) / 3.0)
    np.testing.assert_allclose(
        np.asarray(rk.Quaternion(p).exp().log()),
        p,
        rtol=0,
        atol=64 * EPS * (1 + np.abs(p).max()),
    )


def test_log_of_negative_reals_and_branch():
    """log(-a) = log a + i pi (documented choice u = i); exp of it gives -a back."""
    for a in (1.0, 2.5, 1e-200, 1e200):
        got = rq.log([-a, 0.0, 0.0, 0.0])
        np.testing.assert_allclose(got, [np.log(a), np.pi, 0.0, 0.0], rtol=2 * EPS, atol=0)
        back = rq.exp(got) if a < 1e100 else None
        if back is not None:
            # exp amplifies the rounding of log a by |log a|
            tol = 2 * EPS * a * (1 + abs(np.log(a)))
            np.testing.assert_allclose(back, [-a, 0.0, 0.0, 0.0], rtol=0, atol=tol)
    # next to the negative real axis, the direction follows v (a branch cut)
    q = np.array([-1.0, 0.0, -1e-300, 0.0])
    np.testing.assert_allclose(rq.log(q), [0.0, 0.0, -np.pi, 0.0], rtol=EPS, atol=0)


def test_exp_of_pure_quaternion_is_rotation(rng):
    """``exp((0, theta/2 u))`` is the unit quaternion of the rotation ``theta u``."""
    rv = rng.standard_normal((30, 3))
    pure = np.concatenate([np.zeros((30, 1)), rv / 2], axis=-1)
    got = rq.exp(pure)
    want = SciRot.from_rotvec(rv).as_quat(scalar_first=True)
    np.testing.assert_allclose(got, want, rtol=0, atol=4 * EPS)


def test_exp_of_sum_when_commuting(rng):
    """exp(a + b) = exp(a) exp(b) for commuting a, b (parallel vector parts)."""
    u = np.array([0.0, 0.6, 0.0, 0.8])
    a = rk.Quaternion(np.array([0.3, 0, 0, 0]) + 0.7 * u)
    b = rk.Quaternion(np.array([-1.1, 0, 0, 0]) + 1.9 * u)
    np.testing.assert_allclose(
        np.asarray((a + b).exp()), np.asarray(a.exp() * b.exp()), rtol=0, atol=4 * EPS
    )


# -- rotation of vectors and conversions --------------------------------------------


def test_rotate_non_unit(rng):
    q = rng.standard_normal((40, 4)) * rng.uniform(0.01, 100, (40, 1))
    p = rng.standard_normal((40, 3))
    got = rk.Quaternion(q).rotate(p)
    # q p q^-1 expanded over the basis table
    pq = np.concatenate([np.zeros((40, 1)), p], axis=-1)
    qinv = q * np.array([1, -1, -1, -1]) / np.sum(q * q, axis=-1, keepdims=True)
    ref = table_product(table_product(q, pq), qinv)
    np.testing.assert_allclose(got, ref[:, 1:], rtol=0, atol=16 * EPS * np.abs(p).max())
    np.testing.assert_allclose(
        np.abs(ref[:, 0]), 0.0, atol=1e-13
    )  # still a pure quaternion
    np.testing.assert_allclose(
        got, SciRot.from_quat(q, scalar_first=True).apply(p), atol=1e-14
    )
    np.testing.assert_allclose(got, rk.Rotation.from_quat(q).apply(p), atol=1e-14)


def test_rotation_round_trip(rng):
    R = rk.Rotation.random(10, rng)
    Q = rk.Quaternion.from_rotation(R)
    np.testing.assert_array_equal(np.asarray(Q), R.as_quat())
    assert np.all(Q.to_rotation().approx_equal(R, atol=1e-15))
    # to_rotation normalises any nonzero scale
    assert np.all((3.0 * Q).to_rotation().approx_equal(R, atol=1e-15))
    # rotate agrees with the rotation's matrix
    p = rng.standard_normal((10, 3))
    np.testing.assert_allclose(
        Q.rotate(p), (R.as_matrix() @ p[..., None])[..., 0], atol=1e-14
    )


# -- operators, scalars, containers ------------------------------------------------------


def test_scalar_multiplication_and_operators(rng):
    q = rng.standard_normal((3, 4))
    Q = rk.Quaternion(q)
    s = np.array([1.0, -2.0, 0.5])
    np.testing.assert_array_equal(np.asarray(Q * s), q * s[:, None])
    np.testing.assert_array_equal(np.asarray(s * Q), q * s[:, None])  # ndarray defers to us
    assert isinstance(s * Q, rk.Quaternion)
    np.testing.assert_array_equal(np.asarray(2 * Q), 2 * q)
    np.testing.assert_array_equal(np.asarray(np.float64(2.0) * Q), 2 * q)
    np.testing.assert_array_equal(np.asarray(Q / 4), q / 4)
    np.testing.assert_array_equal(np.asarray(-Q), -q)
    np.testing.assert_array_equal(np.asarray(Q - Q), np.zeros_like(q))
    # a non-quaternion operand of * is a real scalar per element, never a quaternion
    with pytest.raises(TypeError):
        Q / Q
    with pytest.raises(TypeError):
        Q @ Q
    with pytest.raises(TypeError):
        Q @ np.ones(3)
    with pytest.raises(TypeError):
        Q + 1.0
    with pytest.raises(TypeError):
        Q * (1 + 2j)
    with pytest.raises(TypeError):
        Q * rk.Rotation.identity()


def test_components_and_construction():
    Q = rk.Quaternion([1, 2, 3, 4])  # ints become float64
    assert Q.dtype == np.float64
    assert (float(Q.w), float(Q.x), float(Q.y), float(Q.z)) == (1.0, 2.0, 3.0, 4.0)
    assert float(Q.scalar) == 1.0
    np.testing.assert_array_equal(Q.vector, [2.0, 3.0, 4.0])
    np.testing.assert_array_equal(np.asarray(Q), [1.0, 2.0, 3.0, 4.0])
    assert np.asarray(Q, dtype=np.float32).dtype == np.float32
    P = rk.Quaternion.from_parts([0.0, 1.0], [[1.0, 2.0, 3.0]])
    np.testing.assert_array_equal(np.asarray(P), [[0, 1, 2, 3], [1, 1, 2, 3]])
    with pytest.raises(rk.ShapeError):
        rk.Quaternion([1.0, 2.0, 3.0])
    with pytest.raises(rk.NonFiniteError, match=r"\(1,\)"):
        rk.Quaternion([[1.0, 0, 0, 0], [np.nan, 0, 0, 0]])


def test_batches_broadcast_and_containers(rng):
    a = rk.Quaternion(rng.standard_normal((2, 1, 4)))
    b = rk.Quaternion(rng.standard_normal((3, 4)))
    c = a * b
    assert c.shape == (2, 3)
    np.testing.assert_allclose(np.asarray(c[1, 2]), np.asarray(a[1, 0] * b[2]), atol=0)
    assert len(c) == 2 and len(list(c)) == 2
    empty = rk.Quaternion(np.zeros((0, 4)))
    assert (empty * empty).shape == (0,)
    assert rk.Quaternion(np.ones((0, 4))).exp().shape == (0,)
    single = rk.Quaternion([1.0, 0.0, 0.0, 0.0])
    assert single.shape == ()
    with pytest.raises(TypeError):
        len(single)


def test_large_batch_numba_matches_python_path(rng):
    q = rng.standard_normal((3000, 4))
    for k in (rq.exp, rq.log, rq.inv):
        big = k(q)  # numba loop
        for i in (0, 1234, 2999):
            np.testing.assert_allclose(
                big[i], k(q[i]), rtol=0, atol=2 * EPS * np.abs(big[i]).max()
            )


def test_float32_is_kept(rng):
    q = rng.standard_normal((5, 4)).astype(np.float32)
    Q = rk.Quaternion(q)
    for r in (Q * Q, Q.inv(), Q.exp(), Q.log(), Q.conjugate(), 2.0 * Q):
        assert r.dtype == np.float32
    assert Q.norm().dtype == np.float32
    ref = rq.exp(q.astype(np.float64))
    np.testing.assert_allclose(
        np.asarray(Q.exp()), ref, rtol=0, atol=4e-6 * np.abs(ref).max()
    )


def test_torch_backend_and_gradients():
    torch = pytest.importorskip("torch")
    q = torch.tensor([[0.3, -0.2, 0.5, 0.1], [-1.0, 2.0, 0.0, 0.5]], dtype=torch.float64)
    Q = rk.Quaternion(q)
    for op in ("exp", "log", "inv", "conjugate"):
        got = getattr(Q, op)()
        assert isinstance(got._q, torch.Tensor)
        want = getattr(rk.Quaternion(q.numpy()), op)()
        np.testing.assert_allclose(np.asarray(got), np.asarray(want), rtol=0, atol=4 * EPS)
    # gradient of |log q| through the torch path vs central differences
    x = q.clone().requires_grad_(True)
    (rk.Quaternion(x).log()._q ** 2).sum().backward()

    def f(v):
        return float((rq.log(v) ** 2).sum())

    h = 1e-6
    num = np.zeros((2, 4))
    base = q.numpy()
    for i in range(2):
        for j in range(4):
            e = np.zeros((2, 4))
            e[i, j] = h
            num[i, j] = (f(base + e) - f(base - e)) / (2 * h)
    np.testing.assert_allclose(x.grad.numpy(), num, rtol=1e-6, atol=1e-8)


def test_repr_pickle_equality(rng):
    Q = rk.Quaternion([1.0, -0.5, 0.25, 2.0])
    assert repr(Q) == "Quaternion([1.0, -0.5, 0.25, 2.0])"
    assert "shape=(3,)" in repr(rk.Quaternion(rng.standard_normal((3, 4))))
    back = pickle.loads(pickle.dumps(Q))
    np.testing.assert_array_equal(np.asarray(back), np.asarray(Q))
    assert bool(back.approx_equal(Q, atol=0.0))
    assert not bool((-Q).approx_equal(Q))  # componentwise, unlike rotations
    assert Q == Q and not (Q == back)  # identity; values via approx_equal
