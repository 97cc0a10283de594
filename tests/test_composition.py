"""Composition: unit norm whatever the history, ``@`` only, and across kinds.

* Every op that yields a rotation yields a unit quaternion (unit complex number in
  2D) to a few ulp, whatever its inputs' history: ``R = R @ R`` sixty times (the
  norm error doubles at each squaring without renormalisation: -1e-4 after forty),
  1,000 chained compositions, ``rs = rs @ r @ rs`` fifty times, and the same for
  every kind that stores a rotation. The norm is measured in extended precision
  (``np.longdouble``, 64-bit significand on x86), independently of rigidkit.
* ``R @ R`` stays the group operation after many steps: the product equals
  scipy's, and ``as_matrix()`` of the result is accepted by ``from_matrix``.
* ``*`` is refused with a ``TypeError`` that points to ``@`` (scipy's ``R1 * R2``).
* ``compose`` of two kinds works as ``@`` does (``Transform.compose(Rotation)``).
* ``R @ X`` with a (3, 3) array rotates the rows of ``X`` (the last axis is the
  vector, as in ``apply``); the matrix product is ``R.as_matrix() @ X``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRotation

import rigidkit as rk

ULPS = 4  # "a few ulp" of |q| - 1

KINDS = {
    # kind: (slice of the unit part in the stored array, builder)
    "Rotation": (slice(0, 4), lambda n, rng: rk.Rotation.random(n, rng)),
    "Transform": (slice(0, 4), lambda n, rng: rk.Transform.random(n, rng)),
    # Scale 1: squaring sixty times raises any other scale to the power 2^60.
    "Similarity": (
        slice(0, 4),
        lambda n, rng: rk.Similarity(rotation=rk.Rotation.random(n, rng)),
    ),
    "Rotation2D": (slice(0, 2), lambda n, rng: rk.Rotation2D.random(n, rng)),
    "Transform2D": (slice(0, 2), lambda n, rng: rk.Transform2D.random(n, rng)),
}


def norm_error(x, part):
    """``max | |unit part| - 1 |`` in units of the dtype's eps, in long double."""
    data = np.asarray(x._data)
    eps = np.finfo(data.dtype).eps
    u = data[..., part].astype(np.longdouble)
    n = np.sqrt(np.sum(u * u, axis=-1))
    return float(np.max(np.abs(n - 1))) / eps


def cast(x, dtype):
    return type(x)._wrap(np.asarray(x._data, dtype=dtype))


DTYPES = pytest.mark.parametrize("dtype", [np.float64, np.float32], ids=["f64", "f32"])


@pytest.mark.parametrize("kind", list(KINDS))
@DTYPES
def test_repeated_squaring_keeps_the_norm(kind, dtype):
    part, build = KINDS[kind]
    X = cast(build(64, np.random.default_rng(1)), dtype)
    for _ in range(60):
        X = X @ X
        assert norm_error(X, part) <= ULPS, kind


@pytest.mark.parametrize("kind", list(KINDS))
@DTYPES
def test_long_chains_keep_the_norm(kind, dtype):
    part, build = KINDS[kind]
    rng = np.random.default_rng(2)
    step = cast(build(16, rng), dtype)
    X = cast(build(16, rng), dtype)
    for _ in range(1000):
        X = X @ step
    assert norm_error(X, part) <= ULPS
    Y = cast(build(16, rng), dtype)
    for _ in range(50):
        Y = Y @ step @ Y
        assert norm_error(Y, part) <= ULPS
    one = cast(build((), rng), dtype)  # a single element: the Python-float path
    Z = one
    for _ in range(60):  # (the translation grows as 2^k: 60 steps stay finite)
        Z = Z @ Z @ one
    assert norm_error(Z, part) <= ULPS


def test_the_reported_case_against_scipy():
    """``R = R @ R`` forty times: |q| - 1 was -1e-4; scipy's stays at 1e-16, and the
    rotation is scipy's (the renormalisation does not move it)."""
    q = SciRotation.random(random_state=3).as_quat(scalar_first=True)
    R = rk.Rotation.from_quat(q)
    S = SciRotation.from_quat(q, scalar_first=True)
    for _ in range(40):
        R = R @ R
        S = S * S
    assert norm_error(R, slice(0, 4)) <= ULPS
    # Both are exact squarings up to rounding; the angles then differ by 2^40 eps
    # of the first angle at most (the squaring map amplifies any difference).
    gap = rk.Rotation.from_quat(S.as_quat(scalar_first=True)).approx_equal(R, atol=1e-3)
    assert bool(gap)
    # 60 squarings: the library accepts its own matrices.
    for _ in range(20):
        R = R @ R
    rk.Rotation.from_matrix(R.as_matrix(), atol=1e-12)


@DTYPES
def test_renormalised_product_is_the_product(dtype):
    """The renormalisation moves a product of unit quaternions by rounding only."""
    rng = np.random.default_rng(4)
    a = SciRotation.random(200, random_state=5)
    b = SciRotation.random(200, random_state=6)
    ref = (a * b).as_quat(scalar_first=True)
    got = (
        rk.Rotation.from_quat(a.as_quat(scalar_first=True).astype(dtype))
        @ rk.Rotation.from_quat(b.as_quat(scalar_first=True).astype(dtype))
    ).as_quat()
    sign = np.sign(np.sum(ref * got, axis=-1, keepdims=True))
    tol = 8 * np.finfo(dtype).eps
    np.testing.assert_allclose(got * sign, ref, rtol=0, atol=tol)
    del rng


@DTYPES
def test_other_rotation_producing_ops_are_unit(dtype):
    """inv, powers, interpolation, means, exp, plus/minus, the rotation of a pose."""
    rng = np.random.default_rng(7)
    R = cast(rk.Rotation.random(50, rng), dtype)
    R2 = cast(rk.Rotation.random(50, rng), dtype)
    T = cast(rk.Transform.random(50, rng), dtype)
    tau = rng.standard_normal((50, 3)).astype(dtype)
    part = slice(0, 4)
    results = {
        "inv": R.inv(),
        "pow": R ** np.asarray(0.3, dtype=dtype),
        "pow_big": R ** np.asarray(7.7, dtype=dtype),
        "exp": rk.Rotation.exp(tau),
        "plus": R.plus(tau),
        "plus_left": R.plus(tau, side="left"),
        "mean": R.mean(),
        "T.rotation": T.rotation,
        "T.inv": T.inv(),
        "T.pow": T ** np.asarray(0.6, dtype=dtype),
        "T.exp": rk.Transform.exp(T.log()),
        "T@R": T @ R2,
        "R@T": R2 @ T,
    }
    for name, X in results.items():
        assert norm_error(X, part) <= ULPS, name


# -- * is not composition -----------------------------------------------------------------


@pytest.mark.parametrize(
    "make",
    [
        lambda: rk.Rotation.random((), 1),
        lambda: rk.Transform.random((), 1),
        lambda: rk.Similarity.random((), 1),
        lambda: rk.Rotation2D.random((), 1),
        lambda: rk.Transform2D.random((), 1),
        lambda: rk.Affine.random((), 1),
        lambda: rk.Projective.random((), 1),
    ],
)
def test_star_raises_type_error_pointing_to_matmul(make):
    X = make()
    for expr in (lambda: X * X, lambda: 2.0 * X, lambda: X * 2.0, lambda: np.eye(3) * X):
        with pytest.raises(TypeError, match="@"):
            expr()


# -- compose across kinds, as @ ----------------------------------------------------------


def test_transform_compose_rotation_is_matmul():
    rng = np.random.default_rng(8)
    T = rk.Transform.random(5, rng)
    R = rk.Rotation.random(5, rng)
    p = rng.standard_normal((5, 3))
    # Reference: 4x4 homogeneous matrices, built here.
    Rm = SciRotation.from_quat(R.as_quat(), scalar_first=True).as_matrix()
    H_R = np.zeros((5, 4, 4))
    H_R[:, :3, :3] = Rm
    H_R[:, 3, 3] = 1.0
    for got, ref in (
        (T.compose(R), T.as_matrix() @ H_R),
        (R.compose(T), H_R @ T.as_matrix()),
    ):
        assert type(got) is rk.Transform
        np.testing.assert_allclose(got.as_matrix(), ref, atol=1e-14)
    np.testing.assert_allclose(T.compose(R) @ p, T @ (R @ p), atol=1e-14)
    # More general kinds: the result is of the more general kind, as with @.
    S = rk.Similarity.random(5, rng)
    assert type(T.compose(S)) is rk.Similarity
    np.testing.assert_allclose(T.compose(S).as_matrix(), (T @ S).as_matrix(), atol=1e-14)
    # out= receives the stored poses of the result's kind.
    out = np.empty((5, 7))
    got = T.compose(R, out=out)
    np.testing.assert_allclose(got.as_matrix(), (T @ R).as_matrix(), atol=1e-15)
    np.testing.assert_array_equal(np.asarray(got._data), out)


def test_compose_refuses_arrays_and_other_families():
    T = rk.Transform.random((), 1)
    with pytest.raises(TypeError):
        T.compose(np.zeros(3))
    with pytest.raises(TypeError):
        T.compose(rk.Rotation2D.random((), 1))


# -- R @ X: the last axis is the vector --------------------------------------------------


def test_matmul_with_a_3x3_array_rotates_its_rows():
    rng = np.random.default_rng(9)
    R = rk.Rotation.random((), rng)
    X = rng.standard_normal((3, 3))
    Rm = SciRotation.from_quat(R.as_quat(), scalar_first=True).as_matrix()
    np.testing.assert_allclose(R @ X, X @ Rm.T, atol=1e-14)  # rows rotated
    np.testing.assert_allclose(R @ X, R.apply(X), atol=0)
    np.testing.assert_allclose(R.as_matrix() @ X, Rm @ X, atol=1e-14)  # columns
    assert np.abs((R @ X) - (R.as_matrix() @ X)).max() > 1e-3  # they differ
