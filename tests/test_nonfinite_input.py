"""A NaN or an infinity anywhere in any input of any constructor raises NonFiniteError.

For each public constructor of every object class and each of its array inputs, a
batch of three valid inputs gets NaN (then +inf, then -inf) in one component of
element 1; the constructor must raise :class:`rigidkit.NonFiniteError` (a
``ValueError``) whose ``index`` is ``(1,)``, never return NaN. Every component of
the input element is tried in turn, so an input whose NaN reaches only some
components of the result (a matrix entry that a formula reads in one branch only)
is caught too.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest

import rigidkit as rk

N = 3
BAD = (np.nan, np.inf, -np.inf)


def _valid():
    rng = np.random.default_rng(11)
    R = rk.Rotation.random(N, rng=rng)
    T = rk.Transform.random(N, rng=rng)
    R2 = rk.Rotation2D.random(N, rng=rng)
    T2 = rk.Transform2D.random(N, rng=rng)
    S = rk.Similarity.random(N, rng=rng)
    A = rk.Affine.random(N, rng=rng)
    return rng, R, T, R2, T2, S, A


# Inputs where an infinity is valid (by documentation): the pitch of a screw, inf for
# a pure translation. NaN is still refused there.
INF_ALLOWED = {("Transform.from_screw", 2)}


def cases():
    """``(name, build, inputs)``: ``build(*inputs)`` constructs from valid arrays."""
    rng, R, T, R2, T2, S, A = _valid()
    v3 = rng.standard_normal((N, 3))
    ang = rng.uniform(-3, 3, N)
    yield "Rotation", lambda q: rk.Rotation(q), [R.as_quat()]
    yield "Rotation.from_quat", lambda q: rk.Rotation.from_quat(q), [R.as_quat()]
    yield (
        "Rotation.from_quat(xyzw)",
        lambda q: rk.Rotation.from_quat(q, scalar_first=False),
        [R.as_quat(scalar_first=False)],
    )
    yield "Rotation.from_matrix", lambda m: rk.Rotation.from_matrix(m), [R.as_matrix()]
    yield (
        "Rotation.from_matrix(orthonormalize)",
        lambda m: rk.Rotation.from_matrix(m, orthonormalize=True),
        [R.as_matrix()],
    )
    yield "Rotation.from_rotvec", lambda r: rk.Rotation.from_rotvec(r), [v3]
    yield (
        "Rotation.from_rotvec(degrees)",
        lambda r: rk.Rotation.from_rotvec(r, degrees=True),
        [v3],
    )
    yield "Rotation.exp", lambda r: rk.Rotation.exp(r), [v3]
    yield (
        "Rotation.from_axis_angle",
        lambda a, t: rk.Rotation.from_axis_angle(a, t),
        [v3, ang],
    )
    yield "Rotation.from_mrp", lambda p: rk.Rotation.from_mrp(p), [R.as_mrp()]
    yield "Rotation.from_euler", lambda e: rk.Rotation.from_euler("ZYX", e), [v3]
    yield (
        "Rotation.from_euler(degrees)",
        lambda e: rk.Rotation.from_euler("zxz", e, degrees=True),
        [v3],
    )
    yield "Transform(translation)", lambda t: rk.Transform(R, t), [v3]
    yield "Transform.from_matrix", lambda m: rk.Transform.from_matrix(m), [T.as_matrix()]
    yield (
        "Transform.from_matrix(orthonormalize)",
        lambda m: rk.Transform.from_matrix(m, orthonormalize=True),
        [T.as_matrix()],
    )
    yield "Transform.exp", lambda x: rk.Transform.exp(x), [T.log()]
    yield (
        "Transform.from_screw",
        lambda p, d, h, t: rk.Transform.from_screw(p, d, h, t),
        [v3, rng.standard_normal((N, 3)), rng.uniform(0.1, 1, N), ang],
    )
    yield "Rotation.from_6d", lambda a: rk.Rotation.from_6d(a), [R.as_6d()]
    yield (
        "Rotation.from_davenport(angles)",
        lambda t: rk.Rotation.from_davenport(np.eye(3)[[2, 1, 2]], "e", t),
        [v3],
    )
    yield (
        "Transform.from_dual_quat",
        lambda d: rk.Transform.from_dual_quat(d),
        [T.as_dual_quat()],
    )
    yield (
        "Transform.from_dual_quat(xyzw)",
        lambda d: rk.Transform.from_dual_quat(d, scalar_first=False),
        [T.as_dual_quat(scalar_first=False)],
    )
    yield "Transform.from_exp_coords", lambda c: rk.Transform.from_exp_coords(c), [T.log()]
    yield "Transform.from_pq", lambda p: rk.Transform.from_pq(p), [T.as_pq()]
    yield (
        "Transform.from_pq(xyzw)",
        lambda p: rk.Transform.from_pq(p, scalar_first=False),
        [T.as_pq(scalar_first=False)],
    )
    yield "Rotation2D", lambda c: rk.Rotation2D(c), [np.array(R2._data)]
    yield "Rotation2D.from_angle", lambda t: rk.Rotation2D.from_angle(t), [ang]
    yield "Rotation2D.exp", lambda t: rk.Rotation2D.exp(t), [ang[:, None]]
    yield (
        "Rotation2D.from_matrix",
        lambda m: rk.Rotation2D.from_matrix(m),
        [R2.as_matrix()],
    )
    yield (
        "Rotation2D.from_matrix(orthonormalize)",
        lambda m: rk.Rotation2D.from_matrix(m, orthonormalize=True),
        [R2.as_matrix()],
    )
    yield "Transform2D", lambda t: rk.Transform2D(R2, t), [v3[:, :2]]
    yield (
        "Transform2D.from_matrix",
        lambda m: rk.Transform2D.from_matrix(m),
        [T2.as_matrix()],
    )
    yield "Transform2D.exp", lambda x: rk.Transform2D.exp(x), [T2.log()]
    yield (
        "Similarity",
        lambda s, t: rk.Similarity(scale=s, rotation=R, translation=t),
        [np.abs(ang) + 0.5, v3],
    )
    yield "Similarity.from_matrix", lambda m: rk.Similarity.from_matrix(m), [S.as_matrix()]
    yield "Similarity.exp", lambda x: rk.Similarity.exp(x), [S.log()]
    yield (
        "Affine",
        lambda m, t: rk.Affine(matrix=m, translation=t),
        [np.array(A.matrix), v3],
    )
    yield "Affine.from_matrix", lambda m: rk.Affine.from_matrix(m), [A.as_matrix()]
    P = rk.Projective.random(N, rng=rng).as_matrix()
    yield "Projective", lambda m: rk.Projective(m), [P]
    yield "Projective.from_matrix", lambda m: rk.Projective.from_matrix(m), [P]
    yield "Quaternion", lambda q: rk.Quaternion(q), [rng.standard_normal((N, 4))]
    yield (
        "Quaternion.from_parts",
        lambda s, v: rk.Quaternion.from_parts(s, v),
        [ang, v3],
    )


CASES = list(cases())


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_valid_input_constructs(case):
    _, build, inputs = case
    build(*inputs)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("bad", BAD, ids=["nan", "inf", "-inf"])
def test_nonfinite_input_raises_with_index(case, bad):
    name, build, inputs = case
    for k, good in enumerate(inputs):
        if np.isinf(bad) and (name, k) in INF_ALLOWED:
            continue
        trail = good.shape[1:]
        for comp in np.ndindex(trail):
            args = [np.array(a, dtype=np.float64, copy=True) for a in inputs]
            args[k][(1,) + comp] = bad
            with pytest.raises(rk.NonFiniteError) as info:
                build(*args)
            assert info.value.index == (1,), (name, k, comp, info.value.index)


def test_from_complex_nonfinite():
    z = np.exp(1j * np.array([0.1, 0.2, 0.3]))
    for bad in (complex(np.nan, 0.0), complex(0.5, np.nan), complex(np.inf, 0.0)):
        zz = z.copy()
        zz[1] = bad
        with pytest.raises(rk.NonFiniteError) as info:
            rk.Rotation2D.from_complex(zz)
        assert info.value.index == (1,)


def test_single_nan_matrix_names_the_single_input():
    """The reported case: a NaN entry of one matrix raised nothing and gave NaN."""
    M = np.eye(3)
    M[0, 1] = np.nan
    with pytest.raises(rk.NonFiniteError) as info:
        rk.Rotation.from_matrix(M)
    assert info.value.index == ()


@pytest.mark.parametrize("binding", ["numba", "xp", None])
def test_nan_matrix_on_every_numpy_binding(binding, monkeypatch):
    """The compiled loop, the element-wise NumPy path and the automatic choice alike
    (their ``maximum`` primitives treat NaN differently)."""
    kernel_module = importlib.import_module("rigidkit._engine.kernel")
    monkeypatch.setattr(kernel_module, "BINDING", binding)
    M = np.broadcast_to(np.eye(3), (40, 3, 3)).copy()
    for entry in np.ndindex(3, 3):
        bad = M.copy()
        bad[(17,) + entry] = np.nan
        with pytest.raises(rk.NonFiniteError) as info:
            rk.Rotation.from_matrix(bad)
        assert info.value.index == (17,), entry
