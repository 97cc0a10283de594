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


def test_largest_quaternions_name_rotations():
    """|q| above the largest float (its norm overflows) is a valid, finite input."""
    big = np.finfo(np.float64).max
    q = np.array([[big, big, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, -big, big, big]])
    unit = C.quat_normalize(q)
    h, t = np.sqrt(0.5), np.sqrt(1.0 / 3.0)
    np.testing.assert_allclose(unit, [[h, h, 0, 0], [1, 0, 0, 0], [0, -t, t, t]], 1e-15)
    np.testing.assert_allclose(C.quat_normalize(q[0]), unit[0], rtol=1e-15)
    R = rk.Rotation.from_quat(q)
    np.testing.assert_allclose(R.as_rotvec()[0], [np.pi / 2, 0, 0], rtol=1e-15)
    q[1] = 0.0  # a zero row among them is still refused, with its index
    _raises(rk.ZeroNormError, lambda: C.quat_normalize(q), "(1,)")


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


# -- the batch index as an attribute (err.index), for programs such as the CLI ---------
def _rotations_with_one_reflection():
    m = _batch_with_bad(np.eye(3), np.diag([1.0, 1.0, -1.0]))
    return m


def _homogeneous_with(block=None, bottom=None, n=4):
    m = _batch_with_bad(np.eye(n), np.eye(n))
    if block is not None:
        m[1, 2, : n - 1, : n - 1] = block
    if bottom is not None:
        m[1, 2, n - 1] = bottom
    return m


def _singular_affine_block():
    A = _batch_with_bad(np.eye(3), np.eye(3))
    A[1, 2] = [[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]]  # rank 2
    return A


def _projective_point_at_infinity():
    H = np.eye(4)
    H[3, 2] = 1.0  # w' = z + 1
    p = _batch_with_bad(np.zeros(3), [0.0, 0.0, -1.0])
    return lambda: rk.Projective(H) @ p


INDEXED_ERRORS = {
    "quaternion zero": (
        rk.ZeroNormError,
        lambda: rk.Rotation.from_quat(_batch_with_bad([1.0, 0, 0, 0], [0.0] * 4)),
    ),
    "quaternion nan": (
        rk.NonFiniteError,
        lambda: rk.Rotation.from_quat(_batch_with_bad([1.0, 0, 0, 0], [np.nan, 0, 0, 0])),
    ),
    "functional matrix_from_quat zero": (
        rk.ZeroNormError,
        lambda: C.matrix_from_quat(_batch_with_bad([1.0, 0, 0, 0], [0.0] * 4)),
    ),
    "functional quat_apply nan": (
        rk.NonFiniteError,
        lambda: C.quat_apply(_batch_with_bad([1.0, 0, 0, 0], [np.nan] * 4), np.ones(3)),
    ),
    "rotation matrix reflection": (
        rk.NotARotationError,
        lambda: rk.Rotation.from_matrix(_rotations_with_one_reflection()),
    ),
    "so3.adjoint of a reflection": (
        rk.NotARotationError,
        lambda: rk.so3.adjoint(_rotations_with_one_reflection()),
    ),
    "SE(3) bottom row": (
        rk.NotARigidTransformError,
        lambda: rk.Transform.from_matrix(_homogeneous_with(bottom=[0.0, 0.1, 0.0, 1.0])),
    ),
    "SE(3) rotation block": (
        rk.NotARigidTransformError,
        lambda: rk.se3.adjoint(_homogeneous_with(block=2.0 * np.eye(3))),
    ),
    "SE(2) bottom row": (
        rk.NotARigidTransformError,
        lambda: rk.Transform2D.from_matrix(_homogeneous_with(bottom=[0.1, 0.0, 1.0], n=3)),
    ),
    "SO(2) scaling": (
        rk.NotARotationError,
        lambda: rk.Rotation2D.from_matrix(_batch_with_bad(np.eye(2), 2.0 * np.eye(2))),
    ),
    "SO(2) zero pair": (
        rk.ZeroNormError,
        lambda: rk.Rotation2D(_batch_with_bad([1.0, 0.0], [0.0, 0.0])),
    ),
    "Sim(3) shear": (
        rk.NotASimilarityError,
        lambda: rk.Similarity.from_matrix(
            _homogeneous_with(block=np.diag([1.0, 1.0, 2.0]))
        ),
    ),
    "Sim(3) zero block": (
        rk.NotASimilarityError,
        lambda: rk.sim3.log(_homogeneous_with(block=np.zeros((3, 3)))),
    ),
    "Sim(3) scale": (
        rk.NotASimilarityError,
        lambda: rk.Similarity(scale=_batch_with_bad(1.0, -2.0)),
    ),
    "affine bottom row": (
        rk.NotAffineError,
        lambda: rk.Affine.from_matrix(_homogeneous_with(bottom=[0.0, 0.0, 0.5, 1.0])),
    ),
    "affine singular": (
        rk.SingularMatrixError,
        lambda: rk.Affine(matrix=_singular_affine_block()),
    ),
    "projective point at infinity": (
        rk.PointAtInfinityError,
        _projective_point_at_infinity(),
    ),
    "zero axis": (
        rk.ZeroNormError,
        lambda: rk.Rotation.from_axis_angle(_batch_with_bad([1.0, 0, 0], [0.0] * 3), 1.0),
    ),
    "zero quaternion inverse": (
        rk.ZeroNormError,
        lambda: rk.quaternion.inv(_batch_with_bad([1.0, 0, 0, 0], [0.0] * 4)),
    ),
    "non-finite twist": (
        rk.NonFiniteError,
        lambda: rk.se3.right_jacobian(_batch_with_bad(np.zeros(6), [np.nan] * 6)),
    ),
}


@pytest.mark.parametrize("case", sorted(INDEXED_ERRORS))
def test_errors_carry_the_batch_index(case):
    """``err.index`` is the first bad batch index, the same the message names."""
    exc, fn = INDEXED_ERRORS[case]
    with pytest.raises(exc) as info:
        fn()
    assert info.value.index == (1, 2), str(info.value)
    assert "(1, 2)" in str(info.value)


def test_a_single_bad_input_has_the_empty_index():
    with pytest.raises(rk.ZeroNormError) as info:
        C.matrix_from_quat([0.0, 0.0, 0.0, 0.0])
    assert info.value.index == ()
    with pytest.raises(rk.NotARotationError) as info:
        rk.so3.log(np.diag([1.0, 1.0, -1.0]))
    assert info.value.index == ()


def test_every_indexed_raise_passes_index():
    """Statically: a ``raise`` whose message names the batch index passes ``index=``.

    (Indexed errors are raised through ``rigidkit._validate.raise_where``, which
    always does; this catches a message built by hand.)
    """
    import ast
    from pathlib import Path

    root = Path(rk.__file__).parent
    missing = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not (isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call)):
                continue
            text = ast.unparse(node.exc)
            names_index = "where_text" in text or "batch index" in text
            if names_index and not any(k.arg == "index" for k in node.exc.keywords):
                missing.append(f"{path.relative_to(root)}:{node.lineno}")
    assert missing == []


# -- messages print numbers as numbers ---------------------------------------------------
# NumPy 2 writes repr(np.float64(2.0)) as "np.float64(2.0)"; a message shows "2.0".
NUMBER_MESSAGES = {
    "times not increasing": (
        rk.DegenerateInputError,
        lambda: rk.Slerp(np.array([0.0, 2.0, 1.0]), rk.Rotation.identity(3)),
        "times[2] = 1.0 <= times[1] = 2.0",
    ),
    "slerp query out of range": (
        rk.OutOfRangeError,
        lambda: rk.Slerp(np.array([0.0, 1.0, 2.0]), rk.Rotation.identity(3))(
            np.array([5.0])
        ),
        "time 5.0 at index (0,) is outside the interpolation range [0.0, 2.0]",
    ),
    "spline query out of range": (
        rk.OutOfRangeError,
        lambda: rk.RotationSpline(np.array([0.0, 1.0]), rk.Rotation.identity(2))(
            np.array([-0.5])
        ),
        "time -0.5 at index (0,) is outside the interpolation range [0.0, 1.0]",
    ),
    "NumPy scalar scale": (
        rk.NotASimilarityError,
        lambda: rk.Similarity(scale=np.float64(-2.0)),
        "got -2.0",
    ),
    "bad frame": (
        rk.FrameKeywordError,
        lambda: rk.kinematics.euler_rate_matrix("ZYX", np.zeros(3), frame="space"),
        "got 'space'",
    ),
}


@pytest.mark.parametrize("case", sorted(NUMBER_MESSAGES))
def test_messages_print_plain_numbers(case):
    exc, fn, text = NUMBER_MESSAGES[case]
    message = _raises(exc, fn, text)
    assert "np." not in message


@pytest.mark.parametrize("case", sorted(INDEXED_ERRORS))
def test_indexed_messages_print_plain_numbers(case):
    exc, fn = INDEXED_ERRORS[case]
    with pytest.raises(exc) as info:
        fn()
    assert "np." not in str(info.value)


# -- functional conversions validate like the classes ----------------------------------
def test_functional_conversions_normalise_the_quaternion():
    q = np.array([[2.0, 0.0, 0.0, 0.0], [0.5, -1.0, 2.0, -3.0]])
    np.testing.assert_array_equal(C.matrix_from_quat(q)[0], np.eye(3))
    # scipy reads (x, y, z, w) and normalises, as Rotation.from_quat does
    from scipy.spatial.transform import Rotation as SR

    ref = SR.from_quat(q[:, [1, 2, 3, 0]])
    np.testing.assert_allclose(C.matrix_from_quat(q), ref.as_matrix(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(C.rotvec_from_quat(q), ref.as_rotvec(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(C.mrp_from_quat(q), ref.as_mrp(), rtol=0, atol=1e-15)
    v = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(C.quat_apply(q, v), ref.apply(v), rtol=0, atol=1e-14)
    axis, angle = C.axis_angle_from_quat(q)
    np.testing.assert_allclose(axis * angle[..., None], ref.as_rotvec(), atol=1e-15)
    np.testing.assert_allclose(
        C.quat_angle_between(q[0], 5.0 * q[1]), ref[1].magnitude(), rtol=0, atol=1e-15
    )
    # The unchecked variants are the bare kernels: a scaled quaternion is not a rotation.
    np.testing.assert_array_equal(C.matrix_from_quat_unchecked(q[0]), 4.0 * np.eye(3))


def test_functional_poses_normalise_their_rotation():
    pose = np.array([0.0, 0.0, 0.0, 2.0, 1.0, 2.0, 3.0])  # quaternion 2k: a half turn
    M = rk.se3.matrix_from_pose(pose)
    np.testing.assert_allclose(M[:3, :3], np.diag([-1.0, -1.0, 1.0]), atol=1e-15)
    np.testing.assert_array_equal(M[:3, 3], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(rk.se3.twist_from_pose(pose), rk.se3.log(M), atol=1e-15)
    T2 = rk.se2.matrix_from_pose([0.0, 3.0, 1.0, 2.0])  # (cos, sin) = 3 (0, 1): 90 deg
    np.testing.assert_allclose(
        T2, [[0.0, -1.0, 1.0], [1.0, 0.0, 2.0], [0, 0, 1]], atol=1e-15
    )
    with pytest.raises(rk.ZeroNormError):
        rk.se3.matrix_from_pose(np.zeros(7))
    with pytest.raises(rk.ZeroNormError):
        rk.se2.matrix_from_pose(np.zeros(4))


def test_functional_adjoints_are_new_validated_arrays(rng):
    R = rk.Rotation.random(3, rng).as_matrix()
    Ad = rk.so3.adjoint(R)
    assert Ad is not R and not np.shares_memory(Ad, R)
    np.testing.assert_allclose(Ad, R, rtol=0, atol=1e-15)
    with pytest.raises(rk.NotARotationError):
        rk.so3.adjoint(2.0 * R)
    M = rk.Transform.random(3, rng).as_matrix()
    M[1, 3, 0] = 0.5
    with pytest.raises(rk.NotARigidTransformError, match="bottom row"):
        rk.se3.adjoint(M)
