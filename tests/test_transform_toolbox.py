"""Transform toolbox: dual quaternions, scipy's exponential coordinates, pose vectors,
the inverse action, the weighted SE(3) distance, and the mean against scipy.

References: scipy's ``RigidTransform`` (dual quaternions, exponential coordinates,
``apply(inverse=True)``, ``mean``), pytransform3d (``pq`` and dual quaternions,
scalar first), a dual-quaternion product written out here with NumPy (the group
homomorphism), ``scipy.linalg.expm`` of the se(3) matrix, and distances computed by
hand from rotation matrices.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from scipy.spatial import transform as _sst

import rigidkit as rk
from conftest import hamilton

SciTf = getattr(_sst, "RigidTransform", None)  # scipy >= 1.16
needs_scipy_tf = pytest.mark.skipif(SciTf is None, reason="scipy without RigidTransform")
try:
    import pytransform3d.transformations as pt
except ImportError:  # pragma: no cover - optional peer
    pt = None


@pytest.fixture
def rng():
    return np.random.default_rng(20240610)


def dual_product(a, b):
    """``(a_r + eps a_d)(b_r + eps b_d) = a_r b_r + eps (a_r b_d + a_d b_r)``."""
    ar, ad, br, bd = a[..., :4], a[..., 4:], b[..., :4], b[..., 4:]
    return np.concatenate([hamilton(ar, br), hamilton(ar, bd) + hamilton(ad, br)], -1)


def same_dual_quat(a, b, atol):
    """Equal up to the sign of all 8 numbers (``q`` and ``-q`` are one motion)."""
    s = np.sign(np.sum(a * b, axis=-1, keepdims=True))
    np.testing.assert_allclose(a, s * b, rtol=0, atol=atol)


def to_xyzw(dq):
    return np.concatenate([dq[..., 1:4], dq[..., :1], dq[..., 5:8], dq[..., 4:5]], -1)


# -- dual quaternions ------------------------------------------------------------------


@needs_scipy_tf
@pytest.mark.parametrize("scalar_first", [True, False])
def test_dual_quat_against_scipy(rng, scalar_first):
    T = rk.Transform.random((4, 50), rng, scale=5.0)
    S = SciTf.from_matrix(T.as_matrix().reshape(-1, 4, 4))
    ours = T.as_dual_quat(scalar_first=scalar_first).reshape(-1, 8)
    same_dual_quat(ours, S.as_dual_quat(scalar_first=scalar_first), 1e-14 * 8)
    back = rk.Transform.from_dual_quat(
        S.as_dual_quat(scalar_first=scalar_first), scalar_first=scalar_first
    )
    np.testing.assert_allclose(back.as_matrix(), S.as_matrix(), rtol=0, atol=1e-14 * 8)
    assert T.as_dual_quat().shape == (4, 50, 8)


@needs_scipy_tf
def test_dual_quat_normalised_as_scipy(rng):
    """Scaled, and with a component of ``q_d`` along ``q_r``: scipy's normalisation."""
    dq = rk.Transform.random(200, rng, scale=3.0).as_dual_quat()
    scale = rng.uniform(0.01, 100.0, (200, 1))
    along = rng.standard_normal((200, 1))
    bad = np.concatenate([dq[:, :4], dq[:, 4:] + along * dq[:, :4]], -1) * scale
    ours = rk.Transform.from_dual_quat(bad)
    ref = SciTf.from_dual_quat(bad, scalar_first=True)
    np.testing.assert_allclose(ours.as_matrix(), ref.as_matrix(), rtol=0, atol=1e-13)
    # ... and the motion of the unit dual quaternion it came from.
    unit = rk.Transform.from_dual_quat(dq)
    assert bool(np.all(ours.approx_equal(unit, atol=1e-13)))


def test_dual_quat_homomorphism(rng):
    """``dq(A @ B) = dq(A) dq(B)`` (dual product), ``dq(T^-1)`` its conjugate."""
    A = rk.Transform.random(100, rng, scale=4.0)
    B = rk.Transform.random(100, rng, scale=4.0)
    same_dual_quat(
        (A @ B).as_dual_quat(), dual_product(A.as_dual_quat(), B.as_dual_quat()), 1e-13
    )
    dq = A.as_dual_quat()
    conj = dq * np.array([1, -1, -1, -1, 1, -1, -1, -1])
    same_dual_quat(A.inv().as_dual_quat(), conj, 1e-13)
    # A point p is the dual quaternion 1 + eps (0, p); T p = dq (1 + eps p) dq^~,
    # where ^~ is the quaternion conjugate and dual negation.
    p = rng.standard_normal((100, 3))
    point = np.concatenate([np.ones((100, 1)), np.zeros((100, 4)), p], -1)
    moved = dual_product(dual_product(dq, point), conj * np.r_[np.ones(4), -np.ones(4)])
    np.testing.assert_allclose(moved[:, 5:], A @ p, rtol=0, atol=1e-13)


def test_dual_quat_by_hand():
    """A quarter turn about z then the translation (1, 2, 3), written out."""
    c = np.sqrt(0.5)
    q = np.array([c, 0.0, 0.0, c])
    t = np.array([1.0, 2.0, 3.0])
    # (0, t) q / 2 with (0, t)(c + c k) = c (0, t) + c (-t_z, t_y, -t_x, 0)
    dual = 0.5 * c * np.array([-3.0, 1.0 + 2.0, 2.0 - 1.0, 3.0])
    T = rk.Transform(rotation=rk.Rotation.from_quat(q), translation=t)
    ulp2 = 4.5e-16  # the stored quaternion is c normalised: an ulp below sqrt(1/2)
    np.testing.assert_allclose(T.as_dual_quat(), np.r_[q, dual], rtol=0, atol=ulp2)
    np.testing.assert_allclose(
        T.as_dual_quat(scalar_first=False), to_xyzw(np.r_[q, dual]), rtol=0, atol=ulp2
    )
    back = rk.Transform.from_dual_quat(np.r_[q, dual])
    np.testing.assert_allclose(back.translation, t, rtol=0, atol=1e-15)


@pytest.mark.skipif(pt is None, reason="pytransform3d not installed")
def test_dual_quat_against_pytransform3d(rng):
    T = rk.Transform.random(20, rng, scale=3.0)
    for i in range(20):
        ref = pt.dual_quaternion_from_transform(T[i].as_matrix())
        same_dual_quat(T[i].as_dual_quat(), ref, 1e-14)


def test_dual_quat_bad_input():
    good = np.zeros((3, 8))
    good[:, 0] = 1.0
    bad = good.copy()
    bad[2, :4] = 0.0
    with pytest.raises(rk.ZeroNormError, match="zero real part") as err:
        rk.Transform.from_dual_quat(bad)
    assert err.value.index == (2,)
    bad = good.copy()
    bad[1, 6] = np.nan
    with pytest.raises(rk.NonFiniteError) as err:
        rk.Transform.from_dual_quat(bad)
    assert err.value.index == (1,)
    bad = good.copy()
    bad[0, 4] = np.inf
    with pytest.raises(rk.NonFiniteError) as err:
        rk.se3.pose_from_dual_quat(bad, scalar_first=False)
    assert err.value.index == (0,)
    with pytest.raises(rk.ShapeError):
        rk.Transform.from_dual_quat(np.zeros((3, 7)))
    with pytest.raises(rk.ZeroNormError):
        rk.Transform.from_dual_quat(np.zeros(8))  # one element: the Python-float path
    assert issubclass(rk.ZeroNormError, ValueError)


# -- scipy's exponential coordinates (w, v) ----------------------------------------------


@needs_scipy_tf
def test_exp_coords_against_scipy(rng):
    c = rng.standard_normal((300, 6)) * np.r_[1.0, 1.0, 1.0, 3.0, 3.0, 3.0]
    c[:5, :3] = 0.0  # pure translations
    c[5:10, :3] *= 1e-9 / np.linalg.norm(c[5:10, :3], axis=-1, keepdims=True)
    T = rk.Transform.from_exp_coords(c)
    np.testing.assert_allclose(
        T.as_matrix(), SciTf.from_exp_coords(c).as_matrix(), rtol=0, atol=1e-13
    )
    S = SciTf.from_matrix(T.as_matrix())
    np.testing.assert_allclose(T.as_exp_coords(), S.as_exp_coords(), rtol=0, atol=1e-11)


def test_exp_coords_against_expm(rng):
    """``expm`` of ``[[hat(w), v], [0, 0]]`` with ``c = (w, v)``: scipy's order."""
    c = rng.standard_normal((20, 6))
    w, v = c[:, :3], c[:, 3:]
    # |w| in (0, 3) < pi: the log's branch, so as_exp_coords must give c back
    w *= rng.uniform(0.0, 3.0, (20, 1)) / np.linalg.norm(w, axis=-1, keepdims=True)
    X = np.zeros((20, 4, 4))
    X[:, :3, :3] = rk.so3.hat(w)
    X[:, :3, 3] = v
    ref = np.stack([scipy.linalg.expm(x) for x in X])
    T = rk.Transform.from_exp_coords(c)
    np.testing.assert_allclose(T.as_matrix(), ref, rtol=0, atol=1e-13)
    np.testing.assert_allclose(T.as_exp_coords(), c, rtol=0, atol=1e-12)
    # The same motion as our twist (v, w): only the order differs.
    assert bool(np.all(T.approx_equal(rk.Transform.exp(np.c_[v, w]), atol=1e-14)))


def test_exp_coords_bad_input():
    c = np.zeros((4, 6))
    c[3, 1] = np.nan
    with pytest.raises(rk.NonFiniteError) as err:
        rk.Transform.from_exp_coords(c)
    assert err.value.index == (3,)
    with pytest.raises(rk.ShapeError):
        rk.Transform.from_exp_coords(np.zeros((4, 7)))


# -- apply(inverse=True) ---------------------------------------------------------------


def test_apply_inverse(rng):
    T = rk.Transform.random((3, 40), rng, scale=5.0)
    p = rng.standard_normal((3, 40, 3))
    np.testing.assert_allclose(
        T.apply(p, inverse=True), T.inv() @ p, rtol=0, atol=1e-14 * 8
    )
    np.testing.assert_allclose(T.apply(T.apply(p), inverse=True), p, rtol=0, atol=1e-13)
    M = np.linalg.inv(T.as_matrix())
    ref = np.einsum("...ij,...j->...i", M[..., :3, :3], p) + M[..., :3, 3]
    np.testing.assert_allclose(T.apply(p, inverse=True), ref, rtol=0, atol=1e-13)
    # One transform, many points (broadcasting).
    cloud = rng.standard_normal((500, 3))
    np.testing.assert_allclose(
        T[1, 2].apply(cloud, inverse=True), T[1, 2].inv() @ cloud, rtol=0, atol=1e-13
    )


@needs_scipy_tf
def test_apply_inverse_against_scipy(rng):
    T = rk.Transform.random(200, rng, scale=5.0)
    p = rng.standard_normal((200, 3))
    ref = SciTf.from_matrix(T.as_matrix()).apply(p, inverse=True)
    np.testing.assert_allclose(T.apply(p, inverse=True), ref, rtol=0, atol=1e-13)


# -- pose vectors (pq) -------------------------------------------------------------------


@pytest.mark.skipif(pt is None, reason="pytransform3d not installed")
def test_pq_against_pytransform3d(rng):
    T = rk.Transform.random(20, rng, scale=3.0)
    pq = T.as_pq()
    for i in range(20):
        np.testing.assert_allclose(
            pt.transform_from_pq(pq[i]), T[i].as_matrix(), rtol=0, atol=1e-14
        )
        ref = pt.pq_from_transform(T[i].as_matrix())
        back = rk.Transform.from_pq(ref)
        assert bool(back.approx_equal(T[i], atol=1e-14))


def test_pq_by_hand(rng):
    """TUM/ROS ``x y z qx qy qz qw``: the scalar moves to the end, nothing else."""
    T = rk.Transform.random((2, 30), rng, scale=3.0)
    q = T.rotation.as_quat()
    t = T.translation
    np.testing.assert_array_equal(T.as_pq(), np.concatenate([t, q], -1))
    tum = T.as_pq(scalar_first=False)
    np.testing.assert_array_equal(tum, np.concatenate([t, q[..., 1:], q[..., :1]], -1))
    back = rk.Transform.from_pq(
        3.0 * np.concatenate([t, q[..., 1:], q[..., :1]], -1) / 3.0, scalar_first=False
    )
    assert bool(np.all(back.approx_equal(T, atol=1e-15)))
    # The quaternion is normalised, the translation is not scaled.
    scaled = np.concatenate([t, 7.0 * q], -1)
    got = rk.Transform.from_pq(scaled)
    np.testing.assert_allclose(got.translation, t, rtol=0, atol=0)
    assert bool(np.all(got.approx_equal(T, atol=1e-15)))


def test_pq_bad_input():
    pq = np.zeros((3, 7))
    pq[:, 3] = 1.0
    bad = pq.copy()
    bad[1, 3] = 0.0
    with pytest.raises(rk.ZeroNormError) as err:
        rk.Transform.from_pq(bad)
    assert err.value.index == (1,)
    bad = pq.copy()
    bad[2, 0] = np.nan
    with pytest.raises(rk.NonFiniteError) as err:
        rk.Transform.from_pq(bad, scalar_first=False)
    assert err.value.index == (2,)
    with pytest.raises(rk.ShapeError):
        rk.Transform.from_pq(np.zeros(6))


# -- the weighted distance -------------------------------------------------------------


def _distance_by_hand(A, B, wr, wt):
    R1, R2 = A.rotation.as_matrix(), B.rotation.as_matrix()
    cos = (np.trace(np.swapaxes(R1, -1, -2) @ R2, axis1=-2, axis2=-1) - 1.0) / 2.0
    theta = np.arccos(np.clip(cos, -1.0, 1.0))
    rel = np.linalg.inv(A.as_matrix()) @ B.as_matrix()
    dt = np.linalg.norm(rel[..., :3, 3], axis=-1)
    return np.sqrt(wr * theta**2 + wt * dt**2)


@pytest.mark.parametrize("wr, wt", [(1.0, 1.0), (4.0, 0.25), (0.0, 1.0), (1.0, 0.0)])
def test_distance_by_hand(rng, wr, wt):
    A = rk.Transform.random(200, rng, scale=2.0)
    B = rk.Transform.random(200, rng, scale=2.0)
    got = A.distance_to(B, rotation_weight=wr, translation_weight=wt)
    # arccos loses digits near 0 and pi: 1e-7 covers it; the test is of the formula
    np.testing.assert_allclose(got, _distance_by_hand(A, B, wr, wt), rtol=0, atol=1e-7)
    np.testing.assert_allclose(
        got, B.distance_to(A, rotation_weight=wr, translation_weight=wt), atol=1e-14
    )
    # Left-invariant: a change of the world frame changes nothing.
    X = rk.Transform.random((), rng, scale=10.0)
    np.testing.assert_allclose(
        (X @ A).distance_to(X @ B, rotation_weight=wr, translation_weight=wt),
        got,
        rtol=0,
        atol=1e-12,
    )
    # The functional form normalises its quaternions first.
    scaled = np.concatenate([3.0 * A.rotation.as_quat(), A.translation], -1)
    np.testing.assert_allclose(
        rk.se3.pose_distance(scaled, B._pose, rotation_weight=wr, translation_weight=wt),
        got,
        rtol=0,
        atol=1e-14,
    )


def test_distance_exact_cases():
    c = np.sqrt(0.5)
    a = rk.Transform()
    b = rk.Transform(rotation=rk.Rotation.from_quat([c, 0, 0, c]), translation=[3, 4, 0])
    assert float(a.distance_to(b, rotation_weight=0.0)) == 5.0
    np.testing.assert_allclose(
        a.distance_to(b, translation_weight=0.0), np.pi / 2, rtol=1e-15
    )
    np.testing.assert_allclose(a.distance_to(b), np.hypot(np.pi / 2, 5.0), rtol=1e-15)
    assert float(b.distance_to(b)) == 0.0
    half = rk.Transform(rotation=rk.Rotation.from_quat([0.0, 1.0, 0.0, 0.0]))
    np.testing.assert_allclose(a.distance_to(half), np.pi, rtol=1e-15)  # at pi exactly
    with pytest.raises(rk.OutOfRangeError):
        a.distance_to(b, rotation_weight=-1.0)
    with pytest.raises(rk.OutOfRangeError):
        rk.se3.pose_distance(a._pose, b._pose, translation_weight=np.nan)
    with pytest.raises(TypeError):
        a.distance_to(np.eye(4))


# -- the mean against scipy --------------------------------------------------------------


@needs_scipy_tf
def test_mean_against_scipy(rng):
    T = rk.Transform.random((3, 40), rng, scale=2.0)
    w = rng.uniform(0.1, 1.0, (3, 40))
    S = SciTf.from_matrix(T.as_matrix())
    np.testing.assert_allclose(
        T.mean(w, axis=1).as_matrix(),
        S.mean(w, axis=1).as_matrix(),
        rtol=0,
        atol=1e-12,
    )


# -- dtypes and backends -----------------------------------------------------------------


def test_float32_kept(rng):
    T = rk.Transform.random(10, rng, dtype=np.float32)
    p = rng.standard_normal((10, 3)).astype(np.float32)
    outs = [
        T.as_dual_quat(),
        T.as_dual_quat(scalar_first=False),
        rk.Transform.from_dual_quat(T.as_dual_quat())._pose,
        T.as_exp_coords(),
        rk.Transform.from_exp_coords(T.as_exp_coords())._pose,
        T.as_pq(),
        rk.Transform.from_pq(T.as_pq(scalar_first=False), scalar_first=False)._pose,
        T.apply(p, inverse=True),
        T.distance_to(T[::-1]),
    ]
    for out in outs:
        assert out.dtype == np.float32
    assert bool(
        np.all(rk.Transform.from_dual_quat(T.as_dual_quat()).approx_equal(T, atol=1e-6))
    )


def test_torch_gradients(torch, rng):
    dq = torch.tensor(rk.Transform.random(5, rng).as_dual_quat(), requires_grad=True)
    T = rk.Transform.from_dual_quat(dq)
    assert isinstance(T.as_pq(), torch.Tensor)
    other = rk.Transform.from_pq(torch.tensor(rk.Transform.random(5, rng).as_pq()))
    d = T.distance_to(other, rotation_weight=2.0)
    p = torch.tensor(rng.standard_normal((5, 3)))
    loss = d.sum() + T.apply(p, inverse=True).sum() + T.as_exp_coords().sum()
    loss.backward()
    assert bool(torch.isfinite(dq.grad).all()) and float(dq.grad.abs().sum()) > 0
    # The distance's gradient against central differences, along a random direction.
    ref = rk.Transform.from_pq(other.as_pq().detach().numpy())
    base = dq.detach().numpy()
    u = rng.standard_normal(base.shape)
    h = 1e-6

    def f(x):
        return float(
            np.sum(rk.Transform.from_dual_quat(x).distance_to(ref, rotation_weight=2.0))
        )

    dq.grad = None
    rk.Transform.from_dual_quat(dq).distance_to(other, rotation_weight=2.0).sum().backward()
    fd = (f(base + h * u) - f(base - h * u)) / (2 * h)
    np.testing.assert_allclose(float((dq.grad * torch.tensor(u)).sum()), fd, rtol=1e-6)


def test_jax_jit(jax, jnp, rng):
    T = rk.Transform.random(6, rng)
    p = rng.standard_normal((6, 3))

    @jax.jit
    def f(dq, pq, pts):
        A = rk.Transform.from_dual_quat(dq)
        B = rk.Transform.from_pq(pq, scalar_first=False)
        C = rk.Transform.from_exp_coords(A.as_exp_coords())
        return (
            A.apply(pts, inverse=True),
            A.distance_to(B),
            C.as_dual_quat(scalar_first=False),
        )

    got = f(
        jnp.asarray(T.as_dual_quat()),
        jnp.asarray(T.as_pq(scalar_first=False)),
        jnp.asarray(p),
    )
    np.testing.assert_allclose(np.asarray(got[0]), T.inv() @ p, rtol=0, atol=1e-13)
    np.testing.assert_allclose(np.asarray(got[1]), 0.0, rtol=0, atol=1e-7)
    same_dual_quat(np.asarray(got[2]), T.as_dual_quat(scalar_first=False), 1e-13)
