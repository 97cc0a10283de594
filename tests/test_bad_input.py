"""Bad input gets a clear error: a ``ValueError`` subclass saying what and where.

Never a silent wrong answer, never a hang: non-finite matrices are rejected before
any SVD (the test replaces the SVD by a function that fails, so "before" is checked
without timing anything).
"""

from __future__ import annotations

import numpy as np
import pytest

import rigidkit as rk
from conftest import optional
from rigidkit import conversions as C
from rigidkit import errors

# torch or None: its tests are marked ``needs("torch")`` and skip alone without it.
torch = optional("torch")


def test_every_error_is_a_value_error():
    for name in errors.__all__:
        cls = getattr(errors, name)
        if issubclass(cls, Warning):
            continue
        assert issubclass(cls, ValueError), name
        assert issubclass(cls, rk.RigidkitError), name


def _batch_with_bad(good, bad, shape=(2, 3), at=(1, 2)):
    """A batch of ``good`` elements with ``bad`` at index ``at``."""
    a = np.broadcast_to(np.asarray(good, dtype=np.float64), shape + np.shape(good)).copy()
    a[at] = bad
    return a


def _raises(exc, fn, *where):
    """``fn()`` raises ``exc`` (a ValueError) whose message names each of ``where``."""
    with pytest.raises(exc) as info:
        fn()
    assert isinstance(info.value, ValueError)
    for text in where:
        assert text in str(info.value), f"{text!r} not in {str(info.value)!r}"
    return str(info.value)


# -- quaternions -----------------------------------------------------------------------
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_quaternion(bad):
    q = _batch_with_bad([1.0, 0, 0, 0], [0.5, bad, 0.1, 0.2])
    _raises(rk.NonFiniteError, lambda: rk.Rotation.from_quat(q), "(1, 2)", "quaternion")
    _raises(rk.NonFiniteError, lambda: rk.Rotation.from_quat([bad, 0, 0, 1]), "single")
    _raises(rk.NonFiniteError, lambda: C.quat_normalize(q), "(1, 2)")


def test_zero_quaternion():
    q = _batch_with_bad([1.0, 0, 0, 0], [0.0, 0.0, 0.0, 0.0])
    msg = _raises(rk.ZeroNormError, lambda: rk.Rotation.from_quat(q), "(1, 2)")
    assert "zero norm" in msg
    _raises(
        rk.ZeroNormError, lambda: rk.Rotation.from_quat(np.zeros(4), scalar_first=False)
    )
    _raises(rk.ZeroNormError, lambda: rk.Rotation(np.zeros(4)))
    # The smallest positive quaternion still names a rotation.
    R = rk.Rotation.from_quat([0.0, 5e-324, 0.0, 0.0])
    np.testing.assert_array_equal(R.as_quat(), [0.0, 1.0, 0.0, 0.0])


@pytest.mark.needs("torch")
def test_torch_quaternion_errors():
    q = torch.tensor(_batch_with_bad([1.0, 0, 0, 0], [np.nan, 0, 0, 0]))
    _raises(rk.NonFiniteError, lambda: rk.Rotation.from_quat(q), "(1, 2)")
    q = torch.zeros((3, 4), dtype=torch.float64)
    q[:2, 0] = 1.0
    _raises(rk.ZeroNormError, lambda: rk.Rotation.from_quat(q), "(2,)")


# -- vectors and angles ----------------------------------------------------------------
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_vectors(bad):
    v = _batch_with_bad([0.1, 0.2, 0.3], [0.0, bad, 0.0])
    for fn, what in [
        (rk.Rotation.from_rotvec, "rotation vector"),
        (rk.Rotation.exp, "rotation vector"),
        (rk.so3.exp, "rotation vector"),
        (rk.Rotation.from_mrp, "MRP"),
        (C.quat_from_rotvec, "rotation vector"),
    ]:
        _raises(rk.NonFiniteError, lambda fn=fn: fn(v), "(1, 2)", what)
    axis = np.ones((2, 3, 3))
    angle = _batch_with_bad(0.5, bad)
    _raises(
        rk.NonFiniteError,
        lambda: rk.Rotation.from_axis_angle(axis, angle),
        "(1, 2)",
        "angle",
    )
    _raises(
        rk.NonFiniteError,
        lambda: rk.Rotation.from_axis_angle(v, np.ones((2, 3))),
        "(1, 2)",
        "axis",
    )


def test_zero_axis():
    axis = _batch_with_bad([0.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    msg = _raises(
        rk.ZeroNormError,
        lambda: rk.Rotation.from_axis_angle(axis, np.ones((2, 3))),
        "(1, 2)",
    )
    assert "axis" in msg
    # A tiny axis is fine: it is normalised without underflow.
    R = rk.Rotation.from_axis_angle([0.0, 0.0, 1e-310], np.pi / 2)
    np.testing.assert_allclose(R.as_rotvec(), [0.0, 0.0, np.pi / 2], rtol=1e-15)


# -- matrices --------------------------------------------------------------------------
@pytest.fixture
def no_svd(monkeypatch):
    """Any SVD fails the test: what must be rejected is rejected before one."""

    def svd(*args, **kwargs):
        raise AssertionError("an SVD ran on input that should have been rejected")

    monkeypatch.setattr(np.linalg, "svd", svd)
    if torch is not None:
        monkeypatch.setattr(torch.linalg, "svd", svd)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("orthonormalize", [False, True])
def test_non_finite_matrix_rejected_before_svd(bad, orthonormalize, no_svd):
    m = _batch_with_bad(np.eye(3), np.eye(3))
    m[1, 2, 0, 1] = bad
    _raises(
        rk.NonFiniteError,
        lambda: rk.Rotation.from_matrix(m, orthonormalize=orthonormalize),
        "(1, 2)",
        "matrix",
    )
    _raises(rk.NonFiniteError, lambda: rk.so3.log(m), "(1, 2)")
    full_inf = np.full((3, 3), bad)  # scipy's from_matrix hangs on this one
    _raises(
        rk.NonFiniteError,
        lambda: rk.Rotation.from_matrix(full_inf, orthonormalize=orthonormalize),
    )


@pytest.mark.needs("torch")
@pytest.mark.parametrize("orthonormalize", [False, True])
def test_non_finite_torch_matrix_rejected_before_svd(orthonormalize, no_svd):
    m = _batch_with_bad(np.eye(3), np.eye(3))
    m[1, 2, 0, 1] = np.nan
    t = torch.tensor(m)
    _raises(
        rk.NonFiniteError,
        lambda: rk.Rotation.from_matrix(t, orthonormalize=orthonormalize),
        "(1, 2)",
    )


SHEAR = np.array([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
NOT_ROTATIONS = {
    "reflection": (np.diag([1.0, 1.0, -1.0]), "reflection"),
    "point reflection": (-np.eye(3), "reflection"),
    "scaling": (1.5 * np.eye(3), "scales by 1.5"),
    "small scaling": ((1 + 1e-5) * np.eye(3), "scales by 1.00001"),
    "shear": (SHEAR, "singular values"),
    "zero": (np.zeros((3, 3)), ""),
}


@pytest.mark.parametrize("case", list(NOT_ROTATIONS))
def test_not_a_rotation_names_index_and_reason(case):
    bad, reason = NOT_ROTATIONS[case]
    R = rk.Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
    m = _batch_with_bad(R, bad)
    msg = _raises(
        rk.NotARotationError, lambda: rk.Rotation.from_matrix(m), "(1, 2)", reason
    )
    assert "orthonormalize=True" in msg
    _raises(rk.NotARotationError, lambda: rk.Rotation.from_matrix(bad), "single", reason)
    _raises(rk.NotARotationError, lambda: rk.so3.log(m), "(1, 2)")


@pytest.mark.needs("torch")
@pytest.mark.parametrize("case", list(NOT_ROTATIONS))
def test_not_a_rotation_in_torch(case):
    R = rk.Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
    m = _batch_with_bad(R, NOT_ROTATIONS[case][0])
    _raises(rk.NotARotationError, lambda: C.quat_from_matrix(torch.tensor(m)), "(1, 2)")


def test_tolerance_is_adjustable():
    m = (1 + 1e-5) * np.eye(3)
    with pytest.raises(rk.NotARotationError):
        rk.Rotation.from_matrix(m)
    R = rk.Rotation.from_matrix(m, atol=1e-4)
    np.testing.assert_allclose(R.as_matrix(), np.eye(3), atol=1e-15)
    # float32 matrices get the float32 tolerance, 1e-4.
    m32 = ((1 + 1e-5) * np.eye(3)).astype(np.float32)
    assert rk.Rotation.from_matrix(m32).as_quat().dtype == np.float32


def _nearest_by_svd(m):
    """The rotation nearest ``m`` in Frobenius norm, from an SVD done here."""
    u, _, vt = np.linalg.svd(m)
    d = np.sign(np.linalg.det(u @ vt))
    return (u * np.stack([np.ones_like(d), np.ones_like(d), d], -1)[..., None, :]) @ vt


@pytest.mark.parametrize("noise", [1e-3, 0.3])
def test_orthonormalize_gives_the_nearest_rotation(noise, rng):
    R = rk.Rotation.random(50, rng).as_matrix()
    m = R + noise * rng.standard_normal(R.shape)
    m[0] = np.diag([1.0, 1.0, -1.0])  # a reflection: its nearest rotation flips one axis
    m[1] = SHEAR
    got = rk.Rotation.from_matrix(m, orthonormalize=True).as_matrix()
    want = _nearest_by_svd(m)
    # Both are SVD results; the polar factor is well conditioned unless two singular
    # values nearly cancel (not so for these), so they agree to rounding.
    np.testing.assert_allclose(got, want, atol=1e-14)
    # It is nearer than the input's other candidates: compare with scipy's polar too.
    from scipy.linalg import polar

    for k in range(2, 50):
        np.testing.assert_allclose(got[k], polar(m[k])[0], atol=1e-14)


@pytest.mark.needs("torch")
def test_orthonormalize_torch_in_torch_out(rng):
    R = rk.Rotation.random(50, rng).as_matrix()
    m = R + 0.3 * rng.standard_normal(R.shape)
    m[0] = np.diag([1.0, 1.0, -1.0])
    m[1] = SHEAR
    want = _nearest_by_svd(m)
    t = rk.Rotation.from_matrix(torch.tensor(m), orthonormalize=True).as_matrix()
    assert isinstance(t, torch.Tensor)
    np.testing.assert_allclose(t.numpy(), want, atol=1e-14)


# -- shapes and types ------------------------------------------------------------------
@pytest.mark.parametrize(
    "fn, arg, accepted",
    [
        (rk.Rotation.from_quat, np.zeros(3), "(..., 4)"),
        (rk.Rotation.from_quat, np.zeros((2, 5)), "(..., 4)"),
        (rk.Rotation.from_matrix, np.eye(4), "(..., 3, 3)"),
        (rk.Rotation.from_matrix, np.zeros((3, 2)), "(..., 3, 3)"),
        (rk.Rotation.from_matrix, np.zeros(9), "(..., 3, 3)"),
        (rk.Rotation.from_rotvec, np.zeros(4), "(..., 3)"),
        (rk.Rotation.from_mrp, np.zeros((2, 2)), "(..., 3)"),
        (rk.so3.exp, np.zeros(2), "(..., 3)"),
        (rk.so3.log, np.eye(2), "(..., 3, 3)"),
        (rk.so3.hat, np.zeros(4), "(..., 3)"),
        (rk.so3.vee, np.zeros((2, 3)), "(..., 3, 3)"),
        (rk.Rotation.identity(2).apply, np.zeros((2, 2)), "(..., 3)"),
        (lambda a: rk.Rotation.from_axis_angle(a, 1.0), np.zeros(2), "(..., 3)"),
        (rk.Rotation.from_quat, 1.0, "(..., 4)"),
    ],
)
def test_wrong_shapes_name_the_accepted_shape(fn, arg, accepted):
    msg = _raises(rk.ShapeError, lambda: fn(arg), accepted)
    assert str(np.shape(arg)) in msg  # and what it got


def test_batches_that_do_not_broadcast():
    A = rk.Rotation.identity(2)
    B = rk.Rotation.identity(3)
    _raises(rk.ShapeError, lambda: A @ B, "(2,)", "(3,)")
    _raises(rk.ShapeError, lambda: A @ np.zeros((3, 3)), "broadcast")
    _raises(
        rk.ShapeError,
        lambda: rk.Rotation.from_axis_angle(np.ones((2, 3)), np.ones(3)),
        "broadcast",
    )


@pytest.mark.parametrize(
    "value",
    [np.array([1j, 0, 0, 0]), np.array(["1", "0", "0", "0"]), [True, False, False, True]],
)
def test_non_real_input(value):
    _raises(rk.ShapeError, lambda: rk.Rotation.from_quat(value), "real")


@pytest.mark.parametrize(
    "module, dof", [("so2", 1), ("se2", 3), ("so3", 3), ("se3", 6), ("sim3", 7)]
)
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_every_tangent_check_rejects_non_finite(module, dof, bad):
    """exp of every functional layer rejects NaN/inf, naming the batch index.

    (hat/vee/ad are linear reshuffles and only check shapes: NaN stays visible.)
    """
    import rigidkit as rk

    xi = np.zeros((2, 3, dof))
    xi[1, 2, 0] = bad
    with pytest.raises(rk.NonFiniteError, match=r"\(1, 2\)"):
        getattr(rk, module).exp(xi)
