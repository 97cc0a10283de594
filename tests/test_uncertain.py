"""rk.UncertainTransform against Monte-Carlo sampling (scipy's exp and log of SE(3),
independent of rigidkit), GTSAM's Pose3 Jacobians where GTSAM is installed, and
FrameGraph.get(..., with_covariance=True) against explicit propagation."""

import numpy as np
import pytest
from scipy.spatial.transform import RigidTransform as RT
from scipy.spatial.transform import Rotation as R

import rigidkit as rk

N = 100_000
SWAP = np.r_[3:6, 0:3]  # (v, omega) <-> (omega, v): scipy's and GTSAM's order


def exp(xi):
    """SE(3) exponential of (v, omega) rows, with scipy."""
    return RT.from_exp_coords(np.asarray(xi)[..., SWAP])


def log(T):
    """(v, omega) rows of the SE(3) logarithm, with scipy."""
    return T.as_exp_coords()[..., SWAP]


def to_rt(T):
    return RT.from_matrix(T.as_matrix())


def random_cov(rng, scale):
    A = rng.normal(size=(6, 6))
    C = A @ A.T / 6 + 0.2 * np.eye(6)
    return scale**2 * C


def draws(cov, rng, n=N):
    return rng.multivariate_normal(np.zeros(len(cov)), cov, size=n)


def samples(U, rng):
    """Poses drawn from ``U``: mean exp(xi) (right) or exp(xi) mean (left)."""
    xi = draws(np.asarray(U.cov), rng)
    return to_rt(U.mean) * exp(xi) if U.side == "right" else exp(xi) * to_rt(U.mean)


def second_moment(Z, mean, side):
    """Sample E[xi xi^T] of the perturbation of the poses Z about ``mean``."""
    M = to_rt(mean)
    xi = log(M.inv() * Z) if side == "right" else log(Z * M.inv())
    return xi.T @ xi / len(xi)


def rel(A, B):
    return np.linalg.norm(A - B) / np.linalg.norm(B)


@pytest.fixture
def pair():
    rng = np.random.default_rng(5)
    X = rk.Transform.from_pq(
        np.r_[1.0, -2.0, 0.5, R.random(rng=rng).as_quat(scalar_first=True)]
    )
    Y = rk.Transform.from_pq(
        np.r_[0.3, 1.0, 2.0, R.random(rng=rng).as_quat(scalar_first=True)]
    )
    return X, Y, rng


@pytest.mark.parametrize("side", ["right", "left"])
def test_compose_first_order_matches_monte_carlo(pair, side):
    X, Y, rng = pair
    A = rk.UncertainTransform(X, random_cov(rng, 0.02), side)
    B = rk.UncertainTransform(Y, random_cov(rng, 0.03), side)
    Z = A.compose(B)
    assert Z.side == side
    mc = second_moment(samples(A, rng) * samples(B, rng), Z.mean, side)
    assert rel(np.asarray(Z.cov), mc) < 0.02  # sampling noise ~ sqrt(2 / N) per entry
    np.testing.assert_allclose(Z.mean.as_matrix(), (X @ Y).as_matrix(), atol=1e-14)


def test_first_order_error_shrinks_and_order4_is_closer(pair):
    X, Y, rng = pair
    C1, C2 = random_cov(rng, 1.0), random_cov(rng, 1.0)
    errors = {}
    for s in (0.02, 0.3):
        A = rk.UncertainTransform(X, s**2 * C1, "left")
        B = rk.UncertainTransform(Y, s**2 * C2, "left")
        Zs = samples(A, rng) * samples(B, rng)
        mc = second_moment(Zs, X @ Y, "left")
        errors[s] = {k: rel(np.asarray(A.compose(B, order=k).cov), mc) for k in (1, 4)}
    assert errors[0.02][1] < 0.02, errors
    assert errors[0.3][1] > 3 * errors[0.02][1]  # the neglected terms grow with cov
    assert errors[0.3][4] < 0.5 * errors[0.3][1]  # Barfoot & Furgale 2014, Fig. 3
    # the right side gives the same distribution, converted
    A = rk.UncertainTransform(X, 0.09 * C1, "left").to_side("right")
    B = rk.UncertainTransform(Y, 0.09 * C2, "left").to_side("right")
    Z4 = A.compose(B, order=4).to_side("left")
    np.testing.assert_allclose(
        Z4.cov,
        rk.UncertainTransform(X, 0.09 * C1, "left")
        .compose(rk.UncertainTransform(Y, 0.09 * C2, "left"), order=4)
        .cov,
        atol=1e-12,
    )


def test_joint_covariance(pair):
    X, Y, rng = pair
    L = rng.normal(size=(12, 12)) * 0.02
    J = L @ L.T
    xi = draws(J, rng)
    Zs = to_rt(X) * exp(xi[:, :6]) * to_rt(Y) * exp(xi[:, 6:])
    A = rk.UncertainTransform(X, J[:6, :6])
    B = rk.UncertainTransform(Y, J[6:, 6:])
    Z = A.compose(B, joint_cov=J)
    mc = second_moment(Zs, X @ Y, "right")
    assert rel(np.asarray(Z.cov), mc) < 0.02
    assert rel(np.asarray(A.compose(B).cov), mc) > 0.05  # the correlation matters


@pytest.mark.parametrize("side", ["right", "left"])
def test_inverse_between_and_point(pair, side):
    X, Y, rng = pair
    A = rk.UncertainTransform(X, random_cov(rng, 0.3), side)
    As = samples(A, rng)
    # the inverse's covariance is exact (a linear map of the perturbation) even at
    # large covariance, and is not the covariance itself (colmap/colmap#3155)
    Ai = A.inv()
    mc = second_moment(As.inv(), X.inv(), side)
    assert rel(np.asarray(Ai.cov), mc) < 0.02
    assert rel(np.asarray(A.cov), mc) > 0.1
    B = rk.UncertainTransform(Y, random_cov(rng, 0.02), side)
    small = rk.UncertainTransform(X, random_cov(rng, 0.02), side)
    D = small.between(B)
    mc = second_moment(samples(small, rng).inv() * samples(B, rng), X.inv() @ Y, side)
    assert rel(np.asarray(D.cov), mc) < 0.02
    p, Cp = np.array([0.5, -1.0, 2.0]), np.diag([0.01, 0.02, 0.005])
    y, Cy = small.transform_point(p, Cp)
    ps = p + rng.multivariate_normal(np.zeros(3), Cp, size=N)
    ys = samples(small, rng).apply(ps)
    np.testing.assert_allclose(y, X.apply(p), atol=1e-14)
    assert rel(Cy, np.cov(ys.T)) < 0.02


def test_batched_and_validation(pair):
    X, Y, rng = pair
    Xs = rk.Transform.from_pq(np.stack([X.as_pq(), Y.as_pq()]))
    C = np.stack([random_cov(rng, 0.1), random_cov(rng, 0.2)])
    U = rk.UncertainTransform(Xs, C)
    V = U.compose(U.inv())
    assert V.shape == (2,) and V.cov.shape == (2, 6, 6)
    for k in range(2):
        one = rk.UncertainTransform(Xs[k], C[k])
        np.testing.assert_allclose(V.cov[k], one.compose(one.inv()).cov, atol=1e-14)
    with pytest.raises(rk.ShapeError):
        rk.UncertainTransform(X, np.eye(3))
    with pytest.raises(ValueError, match="side"):
        rk.UncertainTransform(X, np.eye(6), side="body")


def test_against_gtsam_jacobians(pair):
    try:  # a wheel built for a newer NumPy than CI's floor may fail on import
        import gtsam
    except Exception as err:  # ImportError, or what a binary mismatch raises
        pytest.skip(f"gtsam not usable: {err}")
    X, Y, rng = pair

    def pose(T):
        return gtsam.Pose3(T.as_matrix())

    C1, C2 = random_cov(rng, 0.1), random_cov(rng, 0.2)
    H1, H2 = np.zeros((6, 6), order="F"), np.zeros((6, 6), order="F")
    pose(X).compose(pose(Y), H1, H2)
    # GTSAM's tangent is (omega, v); its perturbation is on the right
    want = H1 @ C1[np.ix_(SWAP, SWAP)] @ H1.T + H2 @ C2[np.ix_(SWAP, SWAP)] @ H2.T
    got = rk.UncertainTransform(X, C1).compose(rk.UncertainTransform(Y, C2)).cov
    np.testing.assert_allclose(np.asarray(got)[np.ix_(SWAP, SWAP)], want, atol=1e-12)
    pose(X).between(pose(Y), H1, H2)
    want = H1 @ C1[np.ix_(SWAP, SWAP)] @ H1.T + H2 @ C2[np.ix_(SWAP, SWAP)] @ H2.T
    got = rk.UncertainTransform(X, C1).between(rk.UncertainTransform(Y, C2)).cov
    np.testing.assert_allclose(np.asarray(got)[np.ix_(SWAP, SWAP)], want, atol=1e-12)
    H = np.zeros((6, 6), order="F")
    pose(X).inverse(H)  # the inverse's covariance: Ad(X), not the identity
    got = rk.UncertainTransform(X, C1).inv().cov
    np.testing.assert_allclose(
        np.asarray(got)[np.ix_(SWAP, SWAP)], H @ C1[np.ix_(SWAP, SWAP)] @ H.T, atol=1e-12
    )
    Hp, Hq = np.zeros((3, 6), order="F"), np.zeros((3, 3), order="F")
    p = np.array([0.5, -1.0, 2.0])
    pose(X).transformFrom(p, Hp, Hq)
    _, got = rk.UncertainTransform(X, C1).transform_point(p)
    np.testing.assert_allclose(got, Hp @ C1[np.ix_(SWAP, SWAP)] @ Hp.T, atol=1e-12)


def test_graph_with_covariance(pair):
    X, Y, rng = pair
    C1, C2, C3 = (random_cov(rng, 0.05) for _ in range(3))
    g = rk.FrameGraph()
    g.add(
        "map",
        "odom",
        rk.Transform.from_pq(np.stack([X.as_pq(), X.as_pq()])),
        stamps=[0.0, 1.0],
        cov=np.stack([C1, 3 * C1]),
    )
    g.add("odom", "base", Y, cov=C2)
    g.add("map", "tag", Y.inv(), cov=C3)
    got = g.get("tag", "base", at=0.5, with_covariance=True)
    # explicit: tag_T_base = (map_T_tag)^-1 (map_T_odom odom_T_base), the odom edge
    # with the covariance interpolated linearly (2 C1 at the midpoint)
    U = lambda T, C: rk.UncertainTransform(T, C)  # noqa: E731
    want = U(Y.inv(), C3).inv().compose(U(X, 2 * C1).compose(U(Y, C2)))
    np.testing.assert_allclose(got.mean.as_matrix(), want.mean.as_matrix(), atol=1e-12)
    np.testing.assert_allclose(got.cov, want.cov, atol=1e-12)
    batch = g.get("tag", "base", at=[0.25, 0.5], with_covariance=True)
    assert batch.shape == (2,) and batch.cov.shape == (2, 6, 6)
    np.testing.assert_allclose(batch.cov[1], want.cov, atol=1e-12)
    mc = second_moment(
        samples(U(Y.inv(), C3), rng).inv()
        * samples(U(X, 2 * C1), rng)
        * samples(U(Y, C2), rng),
        want.mean,
        "right",
    )
    assert rel(np.asarray(got.cov), mc) < 0.03


def test_torch_inputs_stay_torch(torch, pair):
    """First-order propagation on torch tensors: torch out, numbers as NumPy's."""
    X, Y, rng = pair
    C1, C2 = random_cov(rng, 0.1), random_cov(rng, 0.2)
    tX = rk.Transform.from_pq(torch.tensor(np.asarray(X.as_pq())))
    tY = rk.Transform.from_pq(torch.tensor(np.asarray(Y.as_pq())))
    for side in ("right", "left"):
        A, B = rk.UncertainTransform(X, C1, side), rk.UncertainTransform(Y, C2, side)
        tA = rk.UncertainTransform(tX, torch.tensor(C1), side)
        tB = rk.UncertainTransform(tY, torch.tensor(C2), side)
        for ours, ref in (
            (tA.compose(tB), A.compose(B)),
            (tA.inv(), A.inv()),
            (tA.between(tB), A.between(B)),
        ):
            assert isinstance(ours.cov, torch.Tensor)
            np.testing.assert_allclose(ours.cov.numpy(), ref.cov, atol=1e-12)
        y, cov = tA.transform_point(torch.tensor([0.5, -1.0, 2.0], dtype=torch.float64))
        assert isinstance(cov, torch.Tensor)
        np.testing.assert_allclose(
            cov.numpy(), A.transform_point(np.array([0.5, -1.0, 2.0]))[1], atol=1e-12
        )


def test_jax_inputs_stay_jax_and_trace(jax, jnp, pair):
    """First-order propagation on JAX arrays: JAX out, NumPy's numbers, and the same
    under ``jax.jit`` (the composed covariance as a function of the two means)."""
    X, Y, rng = pair
    C1, C2 = random_cov(rng, 0.1), random_cov(rng, 0.2)
    pX, pY = jnp.asarray(np.asarray(X.as_pq())), jnp.asarray(np.asarray(Y.as_pq()))
    for side in ("right", "left"):
        A, B = rk.UncertainTransform(X, C1, side), rk.UncertainTransform(Y, C2, side)
        jA = rk.UncertainTransform(rk.Transform.from_pq(pX), jnp.asarray(C1), side)
        jB = rk.UncertainTransform(rk.Transform.from_pq(pY), jnp.asarray(C2), side)
        for ours, ref in (
            (jA.compose(jB), A.compose(B)),
            (jA.compose(jB, order=4), A.compose(B, order=4)),
            (jA.inv(), A.inv()),
            (jA.between(jB), A.between(B)),
        ):
            assert isinstance(ours.cov, jax.Array)
            np.testing.assert_allclose(np.asarray(ours.cov), ref.cov, atol=1e-12)

        def composed(a, b, side=side):
            U = rk.UncertainTransform(rk.Transform.from_pq(a), jnp.asarray(C1), side)
            V = rk.UncertainTransform(rk.Transform.from_pq(b), jnp.asarray(C2), side)
            return U.compose(V).cov

        got = jax.jit(composed)(pX, pY)
        np.testing.assert_allclose(np.asarray(got), A.compose(B).cov, atol=1e-12)
