"""The group axioms and Lie-group identities, once for every group class.

Every Lie group of the registry (:mod:`rigidkit.objects.registry`) is tested: a class
implementing :class:`rigidkit.objects.group.LieGroup` with the functional module it
declares (``hat``, ``vee``, ``bracket``); a new group needs no line here. References are
independent of the code under test: ``scipy.linalg.expm`` of the hat matrix, NumPy
matrix products and inverses of ``as_matrix()``, the homogeneous action on points, and
the Baker-Campbell-Hausdorff series.

Tangent vectors are sampled at the identity, near it (1e-8), uniformly (rotation
angle below pi), near pi (pi - 1e-6) and exactly at pi, with the other tangent
components standard normal.
"""

from __future__ import annotations

import math
import pickle
from dataclasses import dataclass

import mpmath as mp
import numpy as np
import pytest
import scipy.linalg as sl
from hypothesis import given, settings
from hypothesis import strategies as st

import rigidkit as rk
from conftest import LIE_GROUPS
from rigidkit.objects import registry

EPS = np.finfo(np.float64).eps


@dataclass(frozen=True)
class Group:
    """A group class, its functional module and where its rotation sits in the tangent."""

    cls: type
    alg: object  # the functional module (hat, vee, exp, bracket, ...) or None
    rot: slice  # tangent components of the rotation (angle bounded by pi in log)

    def __repr__(self):
        return self.cls.__name__

    def fn(self, name):
        """Function ``name`` of the functional module; skips the test if it is missing."""
        f = getattr(self.alg, name, None)
        if f is None:
            pytest.skip(f"{self.cls.__name__} has no functional {name}")
        return f


def _group(cls):
    """A ``pytest.param`` for a Lie group of the registry, with what it declares."""
    spec = registry.spec(cls)
    return pytest.param(Group(cls, spec.algebra, spec.part("rotation")), id=cls.__name__)


# Discovered from the registry of groups (each class joins it when it is defined),
# not listed: a new group is tested here as soon as its class exists.
GROUPS = [_group(cls) for cls in LIE_GROUPS]

KINDS = ["identity", "tiny", "uniform", "near_pi", "pi"]
N = 48


def tangents(G: Group, kind: str, n: int, rng, dtype=np.float64) -> np.ndarray:
    """``n`` tangent vectors of ``G`` whose rotation angle is of the given kind."""
    dof = G.cls.dof
    tau = rng.standard_normal((n, dof))
    k = G.rot.stop - G.rot.start
    direction = rng.standard_normal((n, k))
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    angle = {
        "identity": np.zeros(n),
        "tiny": np.full(n, 1e-8),
        "uniform": rng.uniform(0.0, math.pi * (1 - 1e-3), n),
        "near_pi": np.full(n, math.pi - 1e-6),
        "pi": np.full(n, math.pi),
    }[kind]
    tau[:, G.rot] = direction * angle[:, None]
    if kind == "identity":
        tau[:] = 0.0
    if kind == "tiny":
        tau *= 1e-8 / np.abs(tau).max(axis=-1, keepdims=True)
    return tau.astype(dtype)


def elements(G: Group, kind: str, rng, n=N):
    return G.cls.exp(tangents(G, kind, n, rng))


def matrix(X) -> np.ndarray:
    return np.asarray(X.as_matrix(), dtype=np.float64)


def scale_of(tau) -> np.ndarray:
    """``1 + |tau|`` per element: rounding errors grow with the size of the entries."""
    return 1.0 + np.linalg.norm(np.asarray(tau, dtype=np.float64), axis=-1)


def act(M, p, point_dim):
    """The action of matrices on points: linear, or homogeneous ``[p; 1]`` (``[p; 0;
    1]`` for SE_2(3)'s 5x5 matrices, whose 4th column, the velocity, moves no point)."""
    if M.shape[-1] == point_dim:
        return np.einsum("...ij,...j->...i", M, p)
    pad = np.zeros(p.shape[:-1] + (M.shape[-1] - point_dim,))
    pad[..., -1] = 1.0
    q = np.einsum("...ij,...j->...i", M, np.concatenate([p, pad], axis=-1))
    return q[..., :point_dim] / q[..., -1:]


def eye(G):
    return np.eye(G.cls.matrix_size)


groups = pytest.mark.parametrize("G", GROUPS)
kinds = pytest.mark.parametrize("kind", KINDS)


# -- exp and log -----------------------------------------------------------------------


@groups
@kinds
def test_exp_is_expm_of_hat(G, kind, rng):
    """``exp(tau).as_matrix() == scipy.linalg.expm(hat(tau))``.

    expm (Pade with scaling and squaring) has a norm-wise error of a few eps times
    ``|A| |expm(A)|``, so the tolerance is 20 eps (1 + |tau|) max|expm(A)|. Where
    scipy itself misses that bound (Sim(3), whose hat carries ``sigma I``: up to
    200 eps measured), the element is judged against mpmath's expm at 40 digits.
    """
    tau = tangents(G, kind, N, rng)
    A = np.asarray(G.fn("hat")(tau))
    ref = sl.expm(A)
    got = matrix(G.cls.exp(tau))
    size = np.abs(ref).max(axis=(-2, -1))
    tol = 20 * EPS * scale_of(tau) * size
    err = np.abs(got - ref).max(axis=(-2, -1))
    for i in np.flatnonzero(err > tol):
        with mp.workdps(40):
            exact = np.array(mp.expm(mp.matrix(A[i].tolist())).tolist(), dtype=float)
        err[i] = np.abs(got[i] - exact).max()
    assert np.all(err <= tol), (err / size).max() / EPS


@groups
def test_hat_vee_round_trip(G, rng):
    tau = tangents(G, "uniform", N, rng)
    np.testing.assert_array_equal(np.asarray(G.fn("vee")(G.fn("hat")(tau))), tau)
    # hat is linear, and the functional exp agrees with the class.
    np.testing.assert_allclose(
        np.asarray(G.fn("hat")(2.0 * tau)),
        2.0 * np.asarray(G.fn("hat")(tau)),
        rtol=0,
        atol=0,
    )
    np.testing.assert_allclose(
        np.asarray(G.fn("exp")(tau)), matrix(G.cls.exp(tau)), rtol=0, atol=4 * EPS
    )


@groups
@pytest.mark.parametrize("kind", KINDS + ["random"])
def test_exp_of_log(G, kind, rng):
    """``exp(log(X)) == X`` everywhere, including rotations by exactly pi."""
    X = G.cls.random(N, rng) if kind == "random" else elements(G, kind, rng)
    M = matrix(X)
    back = matrix(G.cls.exp(X.log()))
    err = np.abs(back - M).max(axis=(-2, -1))
    assert np.all(err <= 16 * EPS * (1.0 + np.abs(M).max(axis=(-2, -1)))), err.max()


@groups
@pytest.mark.parametrize("kind", ["identity", "tiny", "uniform", "near_pi"])
def test_log_of_exp(G, kind, rng):
    """``log(exp(tau)) == tau`` while the rotation angle is below pi.

    At pi - 1e-6 the rotation part of ``log`` is still well conditioned (atan2 of
    the quaternion), so the same relative tolerance holds.
    """
    tau = tangents(G, kind, N, rng)
    back = np.asarray(G.cls.exp(tau).log())
    err = np.abs(back - tau).max(axis=-1)
    assert np.all(err <= 16 * EPS * scale_of(tau)), err.max()


@groups
def test_log_at_pi_is_a_valid_log(G, rng):
    """At exactly pi, ``log`` returns one of the two logs: its exp is the element."""
    tau = tangents(G, "pi", N, rng)
    X = G.cls.exp(tau)
    back = np.asarray(X.log())
    angle = np.linalg.norm(back[:, G.rot], axis=-1)
    assert np.all(np.abs(angle - math.pi) <= 8 * EPS)
    np.testing.assert_allclose(matrix(G.cls.exp(back)), matrix(X), rtol=0, atol=4e-15 * 8)


# -- group axioms ----------------------------------------------------------------------


@groups
@kinds
def test_identity(G, kind, rng):
    X = elements(G, kind, rng)
    Id = G.cls.identity()
    np.testing.assert_array_equal(matrix(Id), eye(G))
    np.testing.assert_array_equal(np.asarray(Id.log()), np.zeros(G.cls.dof))
    M = matrix(X)
    # Composition renormalises the unit part (a quaternion off unit by an ulp moves
    # by an ulp), so the gap is a few ulp of the entries, which Sim(3)'s scale makes
    # larger than 1.
    tol = 4 * EPS * np.maximum(1.0, np.abs(M).max(axis=(-2, -1), keepdims=True))
    assert np.all(np.abs(matrix(X @ Id) - M) <= tol)
    assert np.all(np.abs(matrix(Id @ X) - M) <= tol)
    assert G.cls.identity((2, 3)).shape == (2, 3)


@groups
@pytest.mark.parametrize("kind", KINDS + ["random"])
def test_inverse(G, kind, rng):
    """``X X^-1 = X^-1 X = I`` and ``inv`` is the matrix inverse."""
    X = G.cls.random(N, rng) if kind == "random" else elements(G, kind, rng)
    M = matrix(X)
    size = 1.0 + np.abs(M).max()
    np.testing.assert_allclose(
        matrix(X @ X.inv()), np.broadcast_to(eye(G), M.shape), rtol=0, atol=8 * EPS * size
    )
    np.testing.assert_allclose(
        matrix(X.inv() @ X), np.broadcast_to(eye(G), M.shape), rtol=0, atol=8 * EPS * size
    )
    np.testing.assert_allclose(
        matrix(X.inv()), np.linalg.inv(M), rtol=0, atol=8 * EPS * size
    )
    np.testing.assert_allclose(matrix(X.inv().inv()), M, rtol=0, atol=4 * EPS * size)


@groups
def test_associativity_and_homomorphism(G, rng):
    """``(XY)Z = X(YZ)``, and ``as_matrix(XY) = as_matrix(X) as_matrix(Y)``."""
    X, Y, Z = (G.cls.random(N, rng) for _ in range(3))
    left = matrix((X @ Y) @ Z)
    right = matrix(X @ (Y @ Z))
    np.testing.assert_allclose(left, right, rtol=0, atol=1e-14 * (1.0 + np.abs(left).max()))
    prod = matrix(X) @ matrix(Y)
    np.testing.assert_allclose(matrix(X @ Y), prod, rtol=0, atol=1e-14 * np.abs(prod).max())


@groups
@kinds
def test_action_on_points(G, kind, rng):
    """``X @ p`` is the matrix action, and ``(XY) p = X (Y p)``."""
    X = elements(G, kind, rng)
    Y = G.cls.random(N, rng)
    p = rng.standard_normal((N, G.cls.point_dim))
    d = G.cls.point_dim
    np.testing.assert_allclose(
        np.asarray(X @ p), act(matrix(X), p, d), rtol=0, atol=4e-15 * 4
    )
    np.testing.assert_allclose(
        np.asarray((X @ Y) @ p), np.asarray(X @ (Y @ p)), rtol=0, atol=4e-14
    )
    np.testing.assert_allclose(
        np.asarray(X.apply(p)), act(matrix(X), p, d), rtol=0, atol=4e-15 * 4
    )


@groups
@kinds
def test_adjoint(G, kind, rng):
    """``X exp(xi) X^-1 = exp(Ad_X xi)`` and ``X hat(xi) X^-1 = hat(Ad_X xi)``."""
    X = elements(G, kind, rng) if kind != "identity" else G.cls.random(N, rng)
    xi = tangents(G, "uniform", N, rng) * 0.5
    Ad = np.asarray(X.adjoint())
    assert Ad.shape == (N, G.cls.dof, G.cls.dof)
    Ad_xi = np.einsum("...ij,...j->...i", Ad, xi)
    lhs = matrix(X @ G.cls.exp(xi) @ X.inv())
    rhs = matrix(G.cls.exp(Ad_xi))
    np.testing.assert_allclose(lhs, rhs, rtol=0, atol=1e-13 * (1 + np.abs(rhs).max()))
    M = matrix(X)
    conj = M @ np.asarray(G.fn("hat")(xi)) @ np.linalg.inv(M)
    np.testing.assert_allclose(
        np.asarray(G.fn("hat")(Ad_xi)), conj, rtol=0, atol=1e-13 * (1 + np.abs(conj).max())
    )


@groups
@pytest.mark.parametrize("side", ["right", "left"])
def test_plus_minus_round_trips(G, side, rng):
    """``X ⊕ (Y ⊖ X) = Y`` and ``(X ⊕ tau) ⊖ X = tau`` (angle of tau below pi)."""
    X = G.cls.random(N, rng)
    Y = G.cls.random(N, rng)
    d = Y.minus(X, side=side)
    np.testing.assert_allclose(matrix(X.plus(d, side=side)), matrix(Y), rtol=0, atol=1e-13)
    tau = tangents(G, "uniform", N, rng)
    back = np.asarray(X.plus(tau, side=side).minus(X, side=side))
    np.testing.assert_allclose(back, tau, rtol=0, atol=1e-12)
    # The two sides are related by the adjoint: X exp(tau) = exp(Ad_X tau) X.
    if side == "right":
        Ad_tau = np.einsum("...ij,...j->...i", np.asarray(X.adjoint()), tau)
        np.testing.assert_allclose(
            matrix(X.plus(tau, side="right")),
            matrix(X.plus(Ad_tau, side="left")),
            rtol=0,
            atol=1e-12,
        )


@groups
def test_bch_second_order(G, rng):
    """``log(exp(a) exp(b)) = a + b + [a, b]/2 + O(eps^3)`` for ``|a|, |b| <= eps``.

    The third-order BCH terms are ``([a,[a,b]] + [b,[b,a]])/12``; with
    ``|[x, y]| <= sqrt(2) |x||y|`` (so(3), se(3), se(2)) they are below
    ``eps^3 / 3``. Dropping ``[a, b]/2`` gives errors of order eps^2, which the
    test also checks it would detect (non-abelian groups).
    """
    eps = 1e-3
    a = tangents(G, "uniform", N, rng)
    b = tangents(G, "uniform", N, rng)
    a *= eps / np.linalg.norm(a, axis=-1, keepdims=True)
    b *= eps / np.linalg.norm(b, axis=-1, keepdims=True)
    got = np.asarray((G.cls.exp(a) @ G.cls.exp(b)).log())
    br = np.asarray(G.fn("bracket")(a, b))
    err = np.abs(got - (a + b + 0.5 * br)).max()
    assert err <= eps**3 / 3, err
    if np.abs(br).max() > 0:  # non-abelian: the bracket term is visible
        assert np.abs(got - (a + b)).max() > 10 * eps**3


@groups
def test_bracket_is_matrix_commutator(G, rng):
    a = tangents(G, "uniform", N, rng)
    b = tangents(G, "uniform", N, rng)
    A, B = np.asarray(G.fn("hat")(a)), np.asarray(G.fn("hat")(b))
    np.testing.assert_allclose(
        np.asarray(G.fn("hat")(G.fn("bracket")(a, b))),
        A @ B - B @ A,
        rtol=0,
        atol=1e-14 * 16,
    )


@groups
def test_jacobians_relations(G, rng):
    """``J_l J_l^-1 = I``, ``J_r J_r^-1 = I`` and ``J_l = Ad(exp tau) J_r``.

    (Each Jacobian against finite differences: ``test_jacobians_fd.py``.)
    """
    tau = tangents(G, "uniform", N, rng)
    Jl = np.asarray(G.fn("left_jacobian")(tau))
    Jr = np.asarray(G.fn("right_jacobian")(tau))
    Jli = np.asarray(G.fn("left_jacobian_inverse")(tau))
    Jri = np.asarray(G.fn("right_jacobian_inverse")(tau))
    I = np.eye(G.cls.dof)
    s = 1e-13 * scale_of(tau).max() ** 2
    np.testing.assert_allclose(Jl @ Jli, np.broadcast_to(I, Jl.shape), rtol=0, atol=s)
    np.testing.assert_allclose(Jr @ Jri, np.broadcast_to(I, Jl.shape), rtol=0, atol=s)
    Ad = np.asarray(G.cls.exp(tau).adjoint())
    np.testing.assert_allclose(Jl, Ad @ Jr, rtol=0, atol=s)


# -- batches, dtypes, backends ---------------------------------------------------------


@groups
def test_broadcasting(G, rng):
    """A (2, 1) batch composed with a (3,) batch gives (2, 3), elementwise."""
    X = G.cls.random((2, 1), rng)
    Y = G.cls.random(3, rng)
    Z = X @ Y
    assert Z.shape == (2, 3)
    MX, MY = matrix(X), matrix(Y)
    np.testing.assert_allclose(matrix(Z), MX @ MY[None], rtol=0, atol=1e-14 * 8)
    p = rng.standard_normal((3, G.cls.point_dim))
    assert np.asarray(X @ p).shape == (2, 3, G.cls.point_dim)
    one = G.cls.random((), rng)
    assert np.asarray(one @ p).shape == (3, G.cls.point_dim)
    assert (one @ Y).shape == (3,)


@groups
def test_batch_shapes(G, rng):
    """Shapes ``()`` and ``(0,)`` and N-D batches go through every operation."""
    dof, n = G.cls.dof, G.cls.matrix_size
    for shape in [(), (0,), (2, 3, 4)]:
        tau = rng.standard_normal(shape + (dof,)) * 0.3
        X = G.cls.exp(tau)
        assert X.shape == shape
        assert np.asarray(X.log()).shape == shape + (dof,)
        assert np.asarray(X.as_matrix()).shape == shape + (n, n)
        assert np.asarray(X.adjoint()).shape == shape + (dof, dof)
        assert (X @ X.inv()).shape == shape
        assert np.asarray(X @ np.zeros(shape + (G.cls.point_dim,))).shape == shape + (
            G.cls.point_dim,
        )
        assert G.cls.identity(shape).shape == shape
        assert G.cls.random(shape, rng).shape == shape
    X = G.cls.random((2, 3, 4), rng)
    assert len(X) == 2
    assert X[1].shape == (3, 4)
    assert X[1, 2, 3].shape == ()
    np.testing.assert_array_equal(matrix(X[1, 2, 3]), matrix(X)[1, 2, 3])
    Y = pickle.loads(pickle.dumps(X))
    np.testing.assert_array_equal(matrix(Y), matrix(X))


@groups
@pytest.mark.parametrize("kind", ["tiny", "uniform", "near_pi"])
def test_float32(G, kind, rng):
    """float32 in, float32 out, within float32 rounding (eps32 = 1.2e-7) of float64."""
    tau = tangents(G, kind, N, rng, dtype=np.float32)
    X = G.cls.exp(tau)
    M = np.asarray(X.as_matrix())
    assert M.dtype == np.float32
    ref = matrix(G.cls.exp(tau.astype(np.float64)))
    np.testing.assert_allclose(M, ref, rtol=0, atol=16 * 1.2e-7 * scale_of(tau).max())
    assert np.asarray(X.log()).dtype == np.float32
    assert np.asarray((X @ X).as_matrix()).dtype == np.float32
    assert np.asarray(X.inv().as_matrix()).dtype == np.float32
    p = np.ones((N, G.cls.point_dim), dtype=np.float32)
    assert np.asarray(X @ p).dtype == np.float32


@groups
def test_torch_backend(G, rng):
    """torch tensors in, torch tensors out, equal to the NumPy results."""
    torch = pytest.importorskip("torch")
    tau = tangents(G, "uniform", 8, rng)
    X = G.cls.exp(tau)
    Xt = G.cls.exp(torch.from_numpy(tau))
    for get in (
        lambda A: A.as_matrix(),
        lambda A: A.log(),
        lambda A: A.adjoint(),
        lambda A: (A @ A.inv() @ A).as_matrix(),
    ):
        out = get(Xt)
        assert isinstance(out, torch.Tensor) and out.dtype == torch.float64
        np.testing.assert_allclose(out.numpy(), np.asarray(get(X)), rtol=0, atol=1e-14)


# -- single elements (the Python-float path), by hypothesis ----------------------------

coord = st.floats(-5.0, 5.0, allow_nan=False, allow_infinity=False)


def _tangent_strategy(G):
    return st.lists(coord, min_size=G.cls.dof, max_size=G.cls.dof).map(np.array)


@pytest.mark.parametrize("G", GROUPS)
@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_single_element_axioms(G, data):
    """One element at a time: associativity, inverse, exp(log X) = X."""
    a, b, c = (data.draw(_tangent_strategy(G)) for _ in range(3))
    X, Y, Z = G.cls.exp(a), G.cls.exp(b), G.cls.exp(c)
    assert X.shape == ()
    # Rounding is relative to the largest entries met (up to e^5 for Sim(3)'s scale).
    MX, MY, MZ = matrix(X), matrix(Y), matrix(Z)
    big = [np.abs(M).max() for M in (MX, MY, MZ)]
    tol = 16 * EPS * big[0] * big[1] * big[2]
    np.testing.assert_allclose(matrix((X @ Y) @ Z), matrix(X @ (Y @ Z)), rtol=0, atol=tol)
    tol = 16 * EPS * big[0] * np.abs(matrix(X.inv())).max()
    np.testing.assert_allclose(matrix(X @ X.inv()), eye(G), rtol=0, atol=tol)
    tol = 16 * EPS * big[0] * (1.0 + np.abs(a).max())
    np.testing.assert_allclose(matrix(G.cls.exp(X.log())), MX, rtol=0, atol=tol)


def test_the_registry_is_the_list_of_groups():
    """Every public transform class is registered (and so tested by every test that
    iterates over the registry), each Lie group with its functional module and the
    rotation part of its tangent; the ladder and ``rk.jacobians`` read the same
    registry."""
    from rigidkit.objects.group import Group as GroupBase
    from rigidkit.objects.group import LieGroup

    public = {
        obj
        for name in rk.__all__
        if isinstance(obj := getattr(rk, name), type) and issubclass(obj, GroupBase)
    }
    assert public == set(registry.groups())
    lie = {cls for cls in public if issubclass(cls, LieGroup)}
    assert lie == set(LIE_GROUPS) == {G.values[0].cls for G in GROUPS}
    for cls in lie:
        spec = registry.spec(cls)
        assert spec.cls is cls and spec.wrap == cls._wrap
        assert spec.algebra.hat(np.zeros(cls.dof)).shape == (cls.matrix_size,) * 2
        rot = spec.part("rotation")
        assert 0 <= rot.start < rot.stop <= cls.dof
        X = rk.jacobians.exp(cls, np.zeros(cls.dof))[0]
        assert type(X) is cls
    with pytest.raises(TypeError, match="Similarity"):
        rk.jacobians.log(rk.Affine.identity())
