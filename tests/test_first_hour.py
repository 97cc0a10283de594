"""A newcomer's first hour: errors that name the constructor to call, scipy's objects
accepted where ours are, signatures that show which keywords are required, defaults
that do not surprise, reprs that show values (issues 20 and 21)."""

import inspect
import types
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import RigidTransform as SciTransform
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk

# -- errors that point to the right constructor ---------------------------------------


@pytest.mark.parametrize(
    "make, hint",
    [
        (lambda: rk.Transform(np.eye(4)), "rk.Transform.from_matrix(M)"),
        (lambda: rk.Transform(rotation=np.eye(4)), "rk.Transform.from_matrix(M)"),
        (
            lambda: rk.Transform(rotation=[0.0, 0.0, 0.0, 1.0]),
            "rk.Rotation.from_quat(q, scalar_first=False) for (x, y, z, w)",
        ),
        (lambda: rk.Transform(np.zeros(7)), "rk.Transform.from_pq(pq)"),
        (lambda: rk.Transform(rotation=np.eye(3)), "rk.Rotation.from_matrix(M)"),
        (lambda: rk.Similarity(rotation=np.eye(3)), "rk.Rotation.from_matrix(M)"),
        (
            lambda: rk.ExtendedPose(rotation=[0.0, 0.0, 0.0, 1.0]),
            "scalar_first=False",
        ),
        (lambda: rk.Transform2D(rotation=0.3), "rk.Rotation2D.from_angle(theta)"),
        (
            lambda: rk.Transform().distance_to(np.eye(4)),
            "rk.Transform.from_matrix(M)",
        ),
        (
            lambda: rk.Trajectory(np.arange(3.0), np.tile(np.eye(4), (3, 1, 1))),
            "rk.Transform.from_matrix(M)",
        ),
        (
            lambda: rk.Trajectory(np.arange(3.0), np.zeros((3, 7))),
            "rk.Transform.from_pq(pq, scalar_first=False) for (x, y, z, qx, qy, qz, qw)",
        ),
        (
            lambda: rk.UncertainTransform(np.eye(4), np.eye(6)),
            "rk.Transform.from_matrix(M)",
        ),
    ],
)
def test_an_array_where_an_object_is_expected_names_the_constructor(make, hint):
    with pytest.raises(TypeError, match="must be a rigidkit") as err:
        make()
    assert hint in str(err.value)


def test_comparisons_take_scipy_objects_and_name_the_constructor_for_arrays():
    S = SciRot.from_rotvec([[0.1, 0.2, 0.3], [0.0, 0.0, 2.0]])
    R = rk.Rotation.from_rotvec([[0.1, 0.2, 0.3], [0.0, 0.0, 1.0]])
    assert R.approx_equal(S).tolist() == [True, False]
    np.testing.assert_allclose(R.angle_to(S), [0.0, 1.0], atol=1e-12)
    ref = np.linalg.norm(R.as_matrix() - S.as_matrix(), axis=(-2, -1))
    np.testing.assert_allclose(R.chordal_distance(S), ref, atol=1e-12)
    sci_T = SciTransform.from_exp_coords([0.0, 0.0, 0.5, 1.0, 2.0, 3.0])
    assert bool(rk.Transform.from_matrix(sci_T.as_matrix()).approx_equal(sci_T))
    with pytest.raises(TypeError, match=r"rk.Rotation.from_matrix\(M\)"):
        R.approx_equal(np.eye(3))
    with pytest.raises(TypeError, match=r"rk.Transform.from_matrix\(M\)"):
        rk.Transform().approx_equal(np.eye(4))


def test_an_object_where_an_array_is_expected_says_so():
    with pytest.raises(rk.ShapeError, match="got a rigidkit.Transform object"):
        rk.kinematics.quaternion_derivative(rk.Transform(), np.zeros(3), frame="body")


# -- scipy's objects accepted wherever ours are (issue 20) ------------------------------


def test_rotation_converts_scipy_rotations():
    r = SciRot.random(5, rng=0)
    for R in (rk.Rotation(r), rk.Rotation.from_quat(r, scalar_first=False)):
        assert R.shape == (5,)
        np.testing.assert_allclose(R.as_matrix(), r.as_matrix(), atol=1e-15)
    assert rk.Rotation(r[0]).shape == ()
    # A scipy Rotation as a transform's rotation, a scipy RigidTransform as a Transform.
    t = np.array([1.0, 2.0, 3.0])
    T = rk.Transform(rotation=r[1], translation=t)
    np.testing.assert_allclose(
        T.as_matrix(), SciTransform.from_components(t, r[1]).as_matrix(), atol=1e-15
    )
    sci_T = SciTransform.from_exp_coords(np.random.default_rng(1).normal(size=(3, 6)))
    np.testing.assert_allclose(
        rk.Transform(sci_T).as_matrix(), sci_T.as_matrix(), atol=1e-14
    )


def test_functions_take_scipy_rotations_where_they_take_ours():
    times = np.linspace(0.0, 1.0, 6)
    r = SciRot.from_rotvec(np.outer(times, [0.0, 0.3, 0.6]))
    ours = rk.kinematics.angular_velocity_from_samples(rk.Rotation(r), times, frame="body")
    got = rk.kinematics.angular_velocity_from_samples(r, times, frame="body")
    np.testing.assert_allclose(got, ours, atol=1e-15)
    # Constant rate: the reference is the rotation vector's rate (0, 0.3, 0.6).
    np.testing.assert_allclose(got, np.tile([0.0, 0.3, 0.6], (6, 1)), atol=1e-12)
    # Where matrices are read: scipy's Rotation as its matrices.
    np.testing.assert_allclose(
        rk.conversions.quat_from_matrix(r[2]), r[2].as_quat(scalar_first=True), atol=1e-15
    )


# -- required keywords look required ------------------------------------------------------


def _public_callables():
    seen, found = set(), []

    def walk(obj, name, depth):
        if id(obj) in seen or depth > 3:
            return
        seen.add(id(obj))
        if isinstance(obj, types.ModuleType):
            if obj.__name__.startswith("rigidkit"):
                names = getattr(obj, "__all__", [n for n in dir(obj) if n[0] != "_"])
                for n in names:
                    walk(getattr(obj, n, None), f"{name}.{n}", depth + 1)
        elif inspect.isclass(obj):
            if obj.__module__.startswith("rigidkit"):
                for n in vars(obj):
                    if n[0] != "_" or n == "__call__":
                        found.append((f"{name}.{n}", getattr(obj, n, None)))
        elif callable(obj):
            found.append((name, obj))

    walk(rk, "rk", 0)
    return [(n, f) for n, f in found if callable(f)]


def test_frame_is_required_in_every_signature_that_needs_it():
    optional = []
    for name, fn in _public_callables():
        try:
            params = inspect.signature(fn).parameters
        except (TypeError, ValueError):
            continue
        frame = params.get("frame")
        if frame is not None and frame.default is None:
            optional.append(name)
    # A spline's order-0 call (rotations, not rates) needs no frame.
    assert [n for n in optional if not n.endswith(".__call__")] == []
    with pytest.raises(TypeError, match="required keyword-only argument: 'frame'"):
        rk.kinematics.angular_velocity_from_samples(rk.Rotation.identity(3), np.arange(3.0))


# -- defaults that do not surprise ---------------------------------------------------------

_X64_OFF = """
import warnings
warnings.simplefilter("error")  # JAX's "float64 requested ... truncated" fails the run
import jax, jax.numpy as jnp, numpy as np, rigidkit as rk
assert not jax.config.jax_enable_x64
R = rk.Rotation.random(4, rng=0, xp=jnp)
I = rk.Rotation.identity(3, xp=jnp)
T = rk.Transform.identity(xp=jnp)
ref = rk.Rotation.random(4, rng=0).as_matrix()
print(R.dtype, I.dtype, T.dtype, float(np.abs(np.asarray(R.as_matrix()) - ref).max()))
"""


def test_random_and_identity_take_the_namespace_default_float(jax):
    import subprocess
    import sys

    run = subprocess.run(
        [sys.executable, "-c", _X64_OFF], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr
    d1, d2, d3, err = run.stdout.split()
    assert (d1, d2, d3) == ("float32", "float32", "float32")
    assert float(err) < 1e-6  # the same rotations as NumPy's, rounded to float32
    # With x64 on (this process), JAX's default is float64; an explicit dtype wins.
    assert rk.Rotation.random(2, rng=0, xp=jax.numpy).dtype == jax.numpy.float64
    assert rk.Rotation.identity(xp=jax.numpy, dtype="float32").dtype == jax.numpy.float32


def test_torch_default_dtype_is_followed(torch):
    assert rk.Rotation.random(2, rng=0, xp=torch).dtype == torch.get_default_dtype()
    assert rk.Transform.identity(xp=torch).dtype == torch.get_default_dtype()


def test_bad_input_under_jit_does_what_the_readme_says(jax):
    """The README's sentence on traced bad input, checked: NaN propagates as NaN; a
    finite input that names no rotation gives a finite, meaningless result."""
    jnp = jax.numpy
    readme = " ".join((Path(__file__).parents[1] / "README.md").read_text().split())
    for words in ("NaN or infinity propagates as NaN", "a zero quaternion gives the zero",
                  "an all-zero matrix the identity"):  # fmt: skip
        assert words in readme
    matrix = jax.jit(lambda q: rk.Rotation.from_quat(q).as_matrix())
    quat = jax.jit(lambda m: rk.Rotation.from_matrix(m).as_quat())
    assert np.isnan(np.asarray(matrix(jnp.array([np.nan, 0.0, 0.0, 1.0])))).all()
    assert np.isnan(np.asarray(quat(jnp.full((3, 3), np.inf)))).all()
    np.testing.assert_array_equal(np.asarray(matrix(jnp.zeros(4))), np.zeros((3, 3)))
    np.testing.assert_array_equal(np.asarray(quat(jnp.zeros((3, 3)))), [1.0, 0.0, 0.0, 0.0])
    # Eagerly, the same input is an error naming what is wrong.
    with pytest.raises(rk.ZeroNormError):
        rk.Rotation.from_quat(jnp.zeros(4))
    with pytest.raises(rk.NotARotationError):
        rk.Rotation.from_matrix(jnp.zeros((3, 3)))


# -- a repr shows values ------------------------------------------------------------


@pytest.mark.parametrize(
    "make",
    [
        lambda: rk.Rotation.from_rotvec([[0.0, 0.0, 0.1], [0.2, 0.0, 0.0]]),
        lambda: rk.Transform.exp([[0.5, 0, 0, 0, 0, 0.25], [0, 2.5, 0, 0.125, 0, 0]]),
        lambda: rk.Similarity(scale=[2.0, 3.0]),
        lambda: rk.Quaternion([[1.0, 2.0, 3.0, 4.0], [0.5, 0.0, 0.0, 0.0]]),
        lambda: rk.Affine.identity(2),
        lambda: rk.ExtendedPose(velocity=[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]),
    ],
)
def test_the_repr_of_a_batch_shows_its_values(make):
    X = make()
    text = repr(X)
    assert f"shape={X.shape}" in text
    stored = np.asarray(X._data)
    shown = np.array(
        [
            float(t)
            for t in text.split("=\n", 1)[1]
            .replace("[", " ")
            .replace("]", " ")
            .replace(",", " ")
            .replace(")", " ")
            .split()
        ]  # fmt: skip
    )
    np.testing.assert_allclose(shown, stored.ravel(), atol=5e-7)


def test_a_long_batch_repr_shows_a_few_rows_as_numpy_does():
    R = rk.Rotation.random(10_000, rng=0)
    text = repr(R)
    assert "..." in text and len(text.splitlines()) == 8  # 3 first, ..., 3 last
    first = ", ".join(f"{v:.6f}" for v in R[0].as_quat())
    assert first.split(", ")[0].lstrip("-") in text.splitlines()[1]


def test_every_stored_kind_names_its_components_in_its_repr():
    """A batch's repr labels its values with the stored components, never the
    generic "values" (Rotation2D showed "values=" before)."""
    for X in (
        rk.Rotation2D.from_angle([0.1, 0.2]),
        rk.Transform2D.identity(2),
        rk.Rotation.identity(2),
        rk.Transform.identity(2),
    ):
        head = repr(X).split("=\n", 1)[0]
        assert "values" not in head and head.endswith(")"), head
