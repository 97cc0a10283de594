"""Interpolation and splines: rk.slerp, powers, rk.Slerp, rk.RotationSpline, B-splines.

References: scipy's Slerp, RotationSpline and Rotation.__pow__ (with its spline solve
run to convergence where the exactly C2 spline is compared), closed forms (rotations
about one axis, constant screws), finite differences of the evaluated curves, and
the one-sided limits at the knots.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.linalg import expm, logm
from scipy.spatial.transform import Rotation as SR
from scipy.spatial.transform import RotationSpline as SRotationSpline
from scipy.spatial.transform import Slerp as SSlerp

import rigidkit as rk
from conftest import quat_angle


def scipy_rot(R):
    return SR.from_quat(np.asarray(R.as_quat()).reshape(-1, 4), scalar_first=True)


def vee(W):
    return np.stack([W[..., 2, 1], W[..., 0, 2], W[..., 1, 0]], axis=-1)


def twist_of(X):
    """``(v, w)`` of 4x4 se(3) matrices."""
    return np.concatenate([X[..., :3, 3], vee(X[..., :3, :3])], axis=-1)


# -- slerp and powers --------------------------------------------------------------------


def test_slerp_about_one_axis_is_linear_in_the_angle():
    axis = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    a = rk.Rotation.from_rotvec(0.3 * axis)
    b = rk.Rotation.from_rotvec(2.9 * axis)
    t = np.linspace(-0.5, 1.5, 21)
    got = rk.slerp(a, b, t)
    want = rk.Rotation.from_rotvec(np.outer(0.3 + t * 2.6, axis))
    assert np.all(quat_angle(got.as_quat(), want.as_quat()) < 1e-15)


def test_slerp_ends_exact_and_sign_independent(rng):
    a = rk.Rotation.random(100, rng)
    b = rk.Rotation.random(100, rng)
    minus_b = rk.Rotation.from_quat(-np.asarray(b.as_quat()))
    assert np.array_equal(rk.slerp(a, b, 0.0).as_quat(), a.as_quat())
    assert np.all(quat_angle(rk.slerp(a, b, 1.0).as_quat(), b.as_quat()) < 1e-15)
    mid, mid2 = rk.slerp(a, b, 0.37), rk.slerp(a, minus_b, 0.37)
    assert np.all(quat_angle(mid.as_quat(), mid2.as_quat()) < 1e-15)


def test_slerp_matches_scipy_slerp_and_takes_the_short_way(rng):
    a = rk.Rotation.random(200, rng)
    b = rk.Rotation.random(200, rng)
    t = rng.uniform(0.0, 1.0, 200)
    got = rk.slerp(a, b, t)
    sa, sb = scipy_rot(a), scipy_rot(b)
    for k in range(0, 200, 17):
        ref = SSlerp([0.0, 1.0], SR.concatenate([sa[k], sb[k]]))(t[k])
        assert quat_angle(got[k].as_quat(), ref.as_quat(scalar_first=True)) < 1e-14
    # Shortest path: the angle travelled is t times the angle between the ends.
    gap = quat_angle(a.as_quat(), b.as_quat())
    assert np.allclose(quat_angle(a.as_quat(), got.as_quat()), t * gap, atol=1e-13)


def test_slerp_near_a_half_turn_stays_on_the_geodesic():
    a = rk.Rotation.identity()
    b = rk.Rotation.from_rotvec([0.0, 0.0, np.pi - 1e-9])
    got = rk.slerp(a, b, 0.5).as_rotvec()
    assert np.allclose(got, [0.0, 0.0, (np.pi - 1e-9) / 2], atol=1e-15)


def test_slerp_broadcasts_and_keeps_float32(rng):
    a = rk.Rotation.random((3, 1), rng, dtype=np.float32)
    b = rk.Rotation.random((1, 4), rng, dtype=np.float32)
    got = rk.slerp(a, b, np.float32(0.25))
    assert got.shape == (3, 4) and got.dtype == np.float32
    t = np.linspace(0, 1, 5, dtype=np.float32).reshape(5, 1, 1)
    assert rk.slerp(a, b, t).shape == (5, 3, 4)


def test_transform_slerp_is_the_screw_geodesic(rng):
    a = rk.Transform.random(20, rng)
    b = rk.Transform.random(20, rng)
    t = rng.uniform(0.0, 1.0, 20)
    got = rk.slerp(a, b, t).as_matrix()
    A, B = a.as_matrix(), b.as_matrix()
    for k in range(20):
        ref = A[k] @ expm(t[k] * logm(np.linalg.inv(A[k]) @ B[k]).real)
        assert np.allclose(got[k], ref, atol=1e-10)


def test_transform_slerp_decoupled_is_straight_for_the_origin(rng):
    a = rk.Transform.random(10, rng)
    b = rk.Transform.random(10, rng)
    t = rng.uniform(0.0, 1.0, 10)
    got = rk.slerp(a, b, t, decoupled=True)
    want_t = (1 - t)[:, None] * a.translation + t[:, None] * b.translation
    assert np.allclose(got.translation, want_t, atol=1e-15)
    rot = rk.slerp(a.rotation, b.rotation, t)
    assert np.all(quat_angle(got.rotation.as_quat(), rot.as_quat()) < 1e-15)
    assert np.array_equal(rk.slerp(a, b, 1.0, decoupled=True).translation, b.translation)


def test_slerp_rejects_mixed_kinds():
    with pytest.raises(TypeError):
        rk.slerp(rk.Rotation.identity(), rk.Transform.identity(), 0.5)
    with pytest.raises(TypeError):
        rk.slerp(rk.Rotation.identity(), rk.Rotation.identity(), 0.5, decoupled=True)
    with pytest.raises(rk.NonFiniteError):
        rk.slerp(rk.Rotation.identity(), rk.Rotation.identity(), np.nan)


def test_power_matches_scipy(rng):
    R = rk.Rotation.random(300, rng)
    for n in (-2.5, -1.0, 0.0, 0.3, 1.0, 2.0, 7.0):
        got = (R**n).as_quat()
        ref = (scipy_rot(R) ** n).as_quat(scalar_first=True)
        assert np.all(quat_angle(got, ref) < 1e-13), n


def test_power_is_repeated_composition_and_inverse(rng):
    R = rk.Rotation.from_rotvec(rng.uniform(-0.9, 0.9, (50, 3)))  # angles < pi/3
    assert np.all(quat_angle((R**3).as_quat(), (R @ R @ R).as_quat()) < 1e-14)
    assert np.all(quat_angle((R**-1).as_quat(), R.inv().as_quat()) < 1e-15)
    T = rk.Transform.exp(rng.uniform(-0.5, 0.5, (50, 6)))
    assert np.allclose((T**2).as_matrix(), (T @ T).as_matrix(), atol=1e-14)
    assert np.allclose(
        (T**0.5).as_matrix() @ (T**0.5).as_matrix(), T.as_matrix(), atol=1e-14
    )


def test_transform_power_matches_matrix_power(rng):
    T = rk.Transform.random(10, rng)
    M = T.as_matrix()
    got = (T**0.7).as_matrix()
    for k in range(10):
        assert np.allclose(got[k], expm(0.7 * logm(M[k]).real), atol=1e-10)


def test_slerp_on_torch_and_gradients(torch):
    q0 = torch.tensor([1.0, 0.0, 0.0, 0.0], dtype=torch.float64)
    q1 = torch.tensor([0.6, 0.0, 0.8, 0.0], dtype=torch.float64)
    t = torch.tensor(0.4, dtype=torch.float64, requires_grad=True)
    out = rk.slerp(rk.Rotation.from_quat(q0), rk.Rotation.from_quat(q1), t)
    angle = out.angle
    angle.backward()
    full = 2.0 * np.arctan2(0.8, 0.6)
    assert abs(float(angle.detach()) - 0.4 * full) < 1e-14
    assert abs(float(t.grad) - full) < 1e-12  # d(angle)/dt along a geodesic


def test_slerp_on_jax(jnp):
    a = rk.Rotation.from_quat(jnp.asarray([1.0, 0.0, 0.0, 0.0]))
    b = rk.Rotation.from_quat(jnp.asarray([0.0, 0.0, 0.0, 1.0]))
    out = rk.slerp(a, b, jnp.asarray([0.0, 0.5]))
    assert np.allclose(np.asarray(out.as_rotvec())[:, 2], [0.0, np.pi / 2], atol=1e-15)


# -- Slerp --------------------------------------------------------------------------------


def test_slerp_class_matches_scipy(rng):
    times = np.cumsum(rng.uniform(0.1, 2.0, 12))
    keys = rk.Rotation.random(12, rng)
    query = np.concatenate([times, rng.uniform(times[0], times[-1], 300)])
    got = rk.Slerp(times, keys)(query)
    ref = SSlerp(times, scipy_rot(keys))(query)
    assert np.all(quat_angle(got.as_quat(), ref.as_quat(scalar_first=True)) < 1e-14)
    one = rk.Slerp(times, keys)(times[3])
    assert one.shape == () and quat_angle(one.as_quat(), keys[3].as_quat()) < 1e-14


def test_slerp_class_on_transforms_and_batches(rng):
    times = np.array([0.0, 1.0, 3.0])
    keys = rk.Transform.random((3, 2), rng)
    interp = rk.Slerp(times, keys)
    got = interp(np.array([[0.5, 2.0]]))
    assert got.shape == (1, 2, 2)
    ref = rk.slerp(keys[1], keys[2], 0.5)  # t = 2 is halfway through [1, 3]
    assert np.allclose(got[0, 1].as_matrix(), ref.as_matrix(), atol=1e-15)
    dec = rk.Slerp(times, keys, decoupled=True)(0.5)
    assert np.allclose(dec.translation, 0.5 * (keys[0].translation + keys[1].translation))


def test_slerp_class_rejects_bad_times(rng):
    keys = rk.Rotation.random(3, rng)
    with pytest.raises(rk.DegenerateInputError, match="strictly increasing") as err:
        rk.Slerp([0.0, 2.0, 1.0], keys)
    assert err.value.index == (2,)
    with pytest.raises(rk.ShapeError):
        rk.Slerp([0.0, 1.0], keys)
    with pytest.raises(rk.DegenerateInputError):
        rk.Slerp([0.0], keys[:1])
    with pytest.raises(rk.OutOfRangeError):
        rk.Slerp([0.0, 1.0, 2.0], keys)([0.5, 2.5])


# -- RotationSpline -----------------------------------------------------------------------


def converged_scipy_spline(times, keys):
    """scipy's RotationSpline with its fixed-point solve run to convergence."""

    class Converged(SRotationSpline):
        MAX_ITER = 10_000
        TOL = 1e-16

    return Converged(times, scipy_rot(keys))


@pytest.fixture
def keyframes(rng):
    times = np.cumsum(rng.uniform(0.5, 2.0, 7))
    return times, rk.Rotation.random(7, rng)


def test_rotation_spline_matches_converged_scipy(keyframes):
    times, keys = keyframes
    spline = rk.RotationSpline(times, keys)
    ref = converged_scipy_spline(times, keys)
    t = np.linspace(times[0], times[-1], 200)
    assert np.all(
        quat_angle(spline(t).as_quat(), ref(t).as_quat(scalar_first=True)) < 1e-13
    )
    assert np.allclose(spline(t, 1, frame="body"), ref(t, 1), atol=1e-12)
    assert np.allclose(spline(t, 2, frame="body"), ref(t, 2), atol=1e-11)
    assert np.all(quat_angle(spline(times).as_quat(), keys.as_quat()) < 1e-14)


def test_rotation_spline_extrapolates_as_scipy(keyframes):
    """``extrapolate=True`` continues the end cubics exactly as scipy's spline does."""
    times, keys = keyframes
    spline = rk.RotationSpline(times, keys, extrapolate=True)
    ref = converged_scipy_spline(times, keys)
    span = times[-1] - times[0]
    t = np.concatenate(
        [np.linspace(times[0] - 0.3 * span, times[0], 40, endpoint=False),
         np.linspace(times[-1], times[-1] + 0.3 * span, 40)[1:]]
    )  # fmt: skip
    assert np.all(
        quat_angle(spline(t).as_quat(), ref(t).as_quat(scalar_first=True)) < 1e-12
    )
    assert np.allclose(spline(t, 1, frame="body"), ref(t, 1), atol=1e-11)
    assert np.allclose(spline(t, 2, frame="body"), ref(t, 2), atol=1e-11)
    world = spline(t).apply(spline(t, 1, frame="body"))
    assert np.allclose(spline(t, 1, frame="world"), world, atol=1e-12)
    inside = np.linspace(times[0], times[-1], 50)  # the option changes nothing inside
    assert np.array_equal(
        spline(inside).as_quat(), rk.RotationSpline(times, keys)(inside).as_quat()
    )
    # the default keeps rejecting times outside the range
    with pytest.raises(rk.OutOfRangeError):
        rk.RotationSpline(times, keys)(times[-1] + 0.1)


def test_rotation_spline_is_exactly_c2_where_scipys_is_not(keyframes):
    """The one-sided limits of the angular acceleration agree at every interior knot.

    Each limit is extrapolated from four points on its side (error O(e^4)); scipy's
    10-step solve leaves a jump far above that.
    """
    times, keys = keyframes
    spline = rk.RotationSpline(times, keys)
    scipy_spline = SRotationSpline(times, scipy_rot(keys))
    knots = times[1:-1]
    e = 1e-3
    weights = np.array([4.0, -6.0, 4.0, -1.0])  # cubic extrapolation to 0 from 1..4

    def jump(f):
        left = sum(w * f(knots - (j + 1) * e) for j, w in enumerate(weights))
        right = sum(w * f(knots + (j + 1) * e) for j, w in enumerate(weights))
        return np.abs(left - right).max()

    ours = jump(lambda t: spline(t, 2, frame="body"))
    theirs = jump(lambda t: scipy_spline(t, 2))
    assert ours < 1e-8
    assert theirs > 100 * ours
    assert jump(lambda t: spline(t, 1, frame="body")) < 1e-8


def test_rotation_spline_rates_are_derivatives(keyframes):
    times, keys = keyframes
    spline = rk.RotationSpline(times, keys)
    t = np.linspace(times[0] + 0.01, times[-1] - 0.01, 40)
    h = 1e-5
    R, dR = spline(t).as_matrix(), (spline(t + h).as_matrix() - spline(t - h).as_matrix())
    dR /= 2 * h
    body = vee(np.swapaxes(R, -1, -2) @ dR)
    world = vee(dR @ np.swapaxes(R, -1, -2))
    assert np.allclose(spline(t, 1, frame="body"), body, atol=1e-8)
    assert np.allclose(spline(t, 1, frame="world"), world, atol=1e-8)
    for frame in ("body", "world"):
        fd = (spline(t + h, 1, frame=frame) - spline(t - h, 1, frame=frame)) / (2 * h)
        assert np.allclose(spline(t, 2, frame=frame), fd, atol=1e-7)


def test_rotation_spline_about_one_axis_is_the_scalar_spline():
    # About one fixed axis the spline is the clamped cubic spline of the angle, with
    # end slopes theta_0/h_0 and theta_n/h_n (scipy's end conditions).
    from scipy.interpolate import CubicSpline

    times = np.array([0.0, 1.0, 2.5, 3.0, 4.5])
    angles = np.array([0.0, 0.4, -0.3, 0.8, 1.2])
    keys = rk.Rotation.from_rotvec(np.outer(angles, [0.0, 0.0, 1.0]))
    slopes = np.diff(angles) / np.diff(times)
    ref = CubicSpline(times, angles, bc_type=((1, slopes[0]), (1, slopes[-1])))
    t = np.linspace(0.0, 4.5, 50)
    spline = rk.RotationSpline(times, keys)
    assert np.allclose(spline(t).as_rotvec()[:, 2], ref(t), atol=1e-14)
    assert np.allclose(spline(t, 1, frame="world")[:, 2], ref(t, 1), atol=1e-13)
    assert np.allclose(spline(t, 2, frame="body")[:, 2], ref(t, 2), atol=1e-12)


def test_rotation_spline_two_keyframes_and_batches(rng):
    keys = rk.Rotation.random(2, rng)
    spline = rk.RotationSpline([0.0, 2.0], keys)
    ref = rk.Slerp([0.0, 2.0], keys)
    t = np.linspace(0.0, 2.0, 9)
    assert np.all(quat_angle(spline(t).as_quat(), ref(t).as_quat()) < 1e-14)
    many = rk.Rotation.random((5, 3), rng)
    times = np.array([0.0, 1.0, 2.0, 4.0, 5.0])
    batched = rk.RotationSpline(times, many)
    assert batched(np.array([0.5, 3.0])).shape == (2, 3)
    single = rk.RotationSpline(times, many[:, 1])
    assert np.allclose(batched(3.0, 2, frame="body")[1], single(3.0, 2, frame="body"))


def test_rotation_spline_float32_and_errors(keyframes):
    times, keys = keyframes
    k32 = rk.Rotation.from_quat(np.asarray(keys.as_quat(), dtype=np.float32))
    spline = rk.RotationSpline(times, k32)
    assert spline(times[1]).dtype == np.float32
    ref = rk.RotationSpline(times, keys)
    assert np.allclose(
        spline(times, 1, frame="body"), ref(times, 1, frame="body"), atol=1e-3
    )
    with pytest.raises(rk.FrameKeywordError):
        spline(times[1], 1)
    with pytest.raises(ValueError):
        spline(times[1], 3, frame="body")
    with pytest.raises(rk.OutOfRangeError):
        spline(times[-1] + 1.0)


def test_rotation_spline_on_torch(torch, keyframes):
    times, keys = keyframes
    tk = rk.Rotation.from_quat(torch.tensor(np.asarray(keys.as_quat())))
    got = rk.RotationSpline(times, tk)(times[2] + 0.1, 2, frame="world")
    ref = rk.RotationSpline(times, keys)(times[2] + 0.1, 2, frame="world")
    assert isinstance(got, torch.Tensor)
    assert np.allclose(got.numpy(), ref, atol=1e-12)


# -- cumulative B-splines -------------------------------------------------------------


@pytest.fixture
def so3_spline(rng):
    ctrl = rk.Rotation.from_rotvec(rng.standard_normal((8, 3)))
    return rk.BSplineSO3(ctrl, dt=0.7, t0=1.0)


@pytest.fixture
def se3_spline(rng):
    return rk.BSplineSE3(rk.Transform.exp(rng.standard_normal((8, 6))), dt=0.7, t0=1.0)


def test_bspline_so3_derivatives_are_finite_differences(so3_spline):
    sp = so3_spline
    t = np.linspace(sp.t_min + 0.01, sp.t_max - 0.01, 25)
    h = 1e-5
    R = sp(t).as_matrix()
    dR = (sp(t + h).as_matrix() - sp(t - h).as_matrix()) / (2 * h)
    assert np.allclose(sp(t, 1, frame="body"), vee(np.swapaxes(R, -1, -2) @ dR), atol=1e-8)
    assert np.allclose(sp(t, 1, frame="world"), vee(dR @ np.swapaxes(R, -1, -2)), atol=1e-8)
    for frame in ("body", "world"):
        fd = (sp(t + h, 1, frame=frame) - sp(t - h, 1, frame=frame)) / (2 * h)
        assert np.allclose(sp(t, 2, frame=frame), fd, atol=1e-7)


def test_bspline_se3_derivatives_are_finite_differences(se3_spline):
    sp = se3_spline
    t = np.linspace(sp.t_min + 0.01, sp.t_max - 0.01, 25)
    h = 1e-5
    M = sp(t).as_matrix()
    dM = (sp(t + h).as_matrix() - sp(t - h).as_matrix()) / (2 * h)
    assert np.allclose(sp(t, 1, frame="body"), twist_of(np.linalg.inv(M) @ dM), atol=1e-8)
    assert np.allclose(sp(t, 1, frame="world"), twist_of(dM @ np.linalg.inv(M)), atol=1e-8)
    for frame in ("body", "world"):
        fd = (sp(t + h, 1, frame=frame) - sp(t - h, 1, frame=frame)) / (2 * h)
        assert np.allclose(sp(t, 2, frame=frame), fd, atol=1e-7)


@pytest.mark.parametrize("group", ["so3", "se3"])
def test_bspline_is_c2_at_the_knots(group, rng):
    """Left limits come from the spline cut at the knot (its last point, u = 1)."""
    if group == "so3":
        ctrl, make = rk.Rotation.from_rotvec(rng.standard_normal((8, 3))), rk.BSplineSO3
    else:
        ctrl, make = rk.Transform.exp(rng.standard_normal((8, 6))), rk.BSplineSE3
    full = make(ctrl, dt=0.7, t0=1.0)
    for s in range(4):  # knot t0 + (s + 1) dt, between segments s and s + 1
        cut = make(ctrl[: s + 5], dt=0.7, t0=1.0)
        knot = cut.t_max
        assert np.allclose(cut(knot).as_matrix(), full(knot).as_matrix(), atol=1e-14)
        for order in (1, 2):
            left = cut(knot, order, frame="body")
            right = full(knot, order, frame="body")
            assert np.allclose(left, right, atol=1e-12), (s, order)


def test_bspline_of_a_geodesic_is_that_geodesic():
    # Control points on a one-parameter subgroup: the cumulative spline reproduces
    # it with constant velocity (the basis sums are affine in u).
    xi = np.array([0.3, -0.1, 0.2, 0.1, 0.4, -0.2])
    ctrl = rk.Transform.exp(np.outer(np.arange(6.0), xi))
    sp = rk.BSplineSE3(ctrl, dt=0.5)
    t = np.linspace(sp.t_min, sp.t_max, 11)
    # At t the curve is exp((1 + t/dt) xi): knot s sits at the blend of points s..s+2.
    assert np.allclose(
        sp(t).as_matrix(), rk.Transform.exp(np.outer(1 + t / 0.5, xi)).as_matrix()
    )
    assert np.allclose(sp(t, 1, frame="body"), xi / 0.5, atol=1e-13)
    assert np.allclose(sp(t, 2, frame="world"), 0.0, atol=1e-12)


def test_bspline_batches_float32_and_errors(rng):
    ctrl = rk.Rotation.random((6, 2), rng, dtype=np.float32)
    sp = rk.BSplineSO3(ctrl, dt=0.1)
    assert sp(np.array([0.05, 0.2]), 1, frame="body").shape == (2, 2, 3)
    assert sp(0.05).dtype == np.float32
    with pytest.raises(rk.OutOfRangeError):
        sp(0.31)
    with pytest.raises(rk.DegenerateInputError):
        rk.BSplineSO3(ctrl[:3])
    with pytest.raises(TypeError):
        rk.BSplineSE3(ctrl)
    with pytest.raises(rk.FrameKeywordError):
        sp(0.1, 2)


def test_bspline_on_torch_has_gradients(torch, rng):
    rv = torch.tensor(rng.standard_normal((5, 3)), requires_grad=True)
    sp = rk.BSplineSO3(rk.Rotation.from_rotvec(rv), dt=1.0)
    w = sp(np.array([0.3, 1.7]), 1, frame="world")
    w.sum().backward()
    assert rv.grad is not None and bool(torch.isfinite(rv.grad).all())
    ref = rk.BSplineSO3(rk.Rotation.from_rotvec(rv.detach().numpy()), dt=1.0)
    assert np.allclose(w.detach().numpy(), ref(np.array([0.3, 1.7]), 1, frame="world"))


def test_no_warnings_on_ordinary_input(keyframes):
    times, keys = keyframes
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rk.RotationSpline(times, keys)(times)


def test_versinc2_rate_against_mpmath():
    """The angular-acceleration coefficient (2(1 - cos x) - x sin x)/x^4, to a few ulp."""
    import mpmath

    from rigidkit.kernels.so3 import versinc2_rate

    xs = np.concatenate([np.geomspace(1e-9, 1.0, 40), np.linspace(1.0, 6.2, 40)])
    with mpmath.workdps(80):  # the closed form cancels ~x^-2 digits near 0
        for x in xs:
            xm = mpmath.mpf(float(x))
            ref = float((2 * (1 - mpmath.cos(xm)) - xm * mpmath.sin(xm)) / xm**4)
            assert abs(versinc2_rate(float(x)) - ref) <= 8 * np.finfo(float).eps * ref, x


def test_rotation_spline_traces_with_traced_keyframes(jax, jnp):
    """Traced keyframes, concrete knot times: under jax.jit the spline equals the
    converged scipy spline and takes the eager Newton steps; jax.grad of a rate
    with respect to the keyframes' rotation vectors equals central differences."""
    rng = np.random.default_rng(5)
    times = np.cumsum(rng.uniform(0.5, 2.0, 5))
    r = rng.standard_normal((5, 3))
    t = np.linspace(times[0], times[-1], 9)

    def build(rv):
        return rk.RotationSpline(times, rk.Rotation.from_rotvec(rv))

    def run(rv):
        spline = build(rv)
        return spline(t).as_quat(), spline(t, 1, frame="body"), spline.iterations

    q, w, its = jax.jit(run)(jnp.asarray(r))
    ref = converged_scipy_spline(times, rk.Rotation.from_rotvec(r))
    assert np.all(quat_angle(np.asarray(q), ref(t).as_quat(scalar_first=True)) < 1e-13)
    np.testing.assert_allclose(np.asarray(w), ref(t, 1), atol=1e-12)
    assert int(its) == build(r).iterations

    weights = rng.standard_normal((9, 3))

    def loss(rv):
        return (build(rv)(t, 2, frame="world") * weights).sum()

    grad = np.asarray(jax.grad(loss)(jnp.asarray(r)))
    fd = np.zeros_like(r)
    for j in np.ndindex(r.shape):
        e = np.zeros_like(r)
        e[j] = 1e-6
        fd[j] = (float(loss(r + e)) - float(loss(r - e))) / 2e-6
    np.testing.assert_allclose(grad, fd, rtol=1e-6, atol=1e-6 * np.abs(fd).max())


def test_rotation_spline_under_torch_vmap(torch):
    """torch.func.vmap over keyframe sets equals one spline per set."""
    rng = np.random.default_rng(6)
    times = np.cumsum(rng.uniform(0.5, 2.0, 5))
    r = rng.standard_normal((2, 5, 3))
    t = np.linspace(times[0], times[-1], 7)

    def run(rv):
        return rk.RotationSpline(times, rk.Rotation.from_rotvec(rv))(t).as_quat()

    got = torch.func.vmap(run)(torch.as_tensor(r)).numpy()
    for b in range(2):
        ref = converged_scipy_spline(times, rk.Rotation.from_rotvec(r[b]))
        assert np.all(quat_angle(got[b], ref(t).as_quat(scalar_first=True)) < 1e-13)


def test_block_tridiagonal_solve_against_a_dense_solve():
    """The rotation spline's block-Thomas solve (3x3 blocks inverted by the
    adjugate kernel) against ``numpy.linalg.solve`` of the assembled dense system,
    for block-diagonally dominant systems as the spline's, with a batch axis."""
    from rigidkit.functional._block_tridiagonal import solve_block_tridiagonal

    rng = np.random.default_rng(5)
    m, batch = 5, 2
    lower = rng.normal(size=(m, batch, 3, 3))
    upper = rng.normal(size=(m, batch, 3, 3))
    diag = rng.normal(size=(m, batch, 3, 3)) + 12.0 * np.eye(3)
    rhs = rng.normal(size=(m, batch, 3))
    x = solve_block_tridiagonal(np, lower, diag, upper, rhs)
    for b in range(batch):
        dense = np.zeros((3 * m, 3 * m))
        for e in range(m):
            dense[3 * e : 3 * e + 3, 3 * e : 3 * e + 3] = diag[e, b]
            if e:
                dense[3 * e : 3 * e + 3, 3 * e - 3 : 3 * e] = lower[e, b]
            if e < m - 1:
                dense[3 * e : 3 * e + 3, 3 * e + 3 : 3 * e + 6] = upper[e, b]
        want = np.linalg.solve(dense, rhs[:, b].reshape(-1)).reshape(m, 3)
        np.testing.assert_allclose(x[:, b], want, rtol=0, atol=1e-14)
