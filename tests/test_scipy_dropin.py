"""``rigidkit.scipy``: what scipy's own suite (tests/test_scipy_suite.py) does not
cover: other array namespaces, the conversions to and from rigidkit's objects,
mutability, the extrapolating spline and the documented differences, each against
``scipy.spatial.transform`` itself."""

from __future__ import annotations

import copy
import pickle
import sys
import threading
import time
import warnings

import numpy as np
import pytest
import scipy.spatial.transform as sst

import rigidkit as rk
from rigidkit.scipy import RigidTransform, Rotation, RotationSpline, Slerp


def _same_rotations(q1, q2, tol=1e-13):
    dots = np.abs(np.sum(np.asarray(q1) * np.asarray(q2), axis=-1))
    assert np.all(np.abs(dots - 1.0) <= tol)


@pytest.fixture
def quats(rng):
    q = rng.standard_normal((6, 4))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def test_import_path_and_the_real_scipy():
    import rigidkit.scipy as rks

    assert rks.Rotation is Rotation and "rigidkit" not in sys.modules["scipy"].__file__
    assert sst.Rotation is not Rotation  # scipy's own class is untouched


def test_conversions_both_ways(quats):
    r = Rotation.from_quat(quats)
    k = r.as_rigidkit()
    assert isinstance(k, rk.Rotation)
    np.testing.assert_array_equal(k.as_quat(scalar_first=False), r.as_quat())
    back = Rotation.from_rigidkit(k)
    np.testing.assert_array_equal(back.as_quat(), r.as_quat())
    tf = RigidTransform.from_components([1.0, 2.0, 3.0], r)
    assert isinstance(tf.as_rigidkit(), rk.Transform)
    np.testing.assert_allclose(
        RigidTransform.from_rigidkit(tf.as_rigidkit()).as_matrix(), tf.as_matrix()
    )
    with pytest.raises(TypeError):
        Rotation.from_rigidkit(sst.Rotation.identity())


def test_numpy_float32_is_promoted_as_scipy(quats):
    q32 = quats.astype(np.float32)
    assert (
        Rotation.from_quat(q32).as_quat().dtype
        == sst.Rotation.from_quat(q32).as_quat().dtype
    )


def test_setitem_mutates_the_wrapper_only(quats):
    r = Rotation.from_quat(quats)
    k = r.as_rigidkit()
    before = k.as_quat().copy()
    r[1:3] = Rotation.identity(2)
    s = sst.Rotation.from_quat(quats)
    s[1:3] = sst.Rotation.identity(2)
    _same_rotations(r.as_quat(), s.as_quat())
    np.testing.assert_array_equal(k.as_quat(), before)  # rigidkit's object is immutable
    tf = RigidTransform.from_rotation(Rotation.from_quat(quats))
    tf[0] = RigidTransform.from_translation([1.0, 2.0, 3.0])
    np.testing.assert_allclose(tf[0].translation, [1.0, 2.0, 3.0])


def test_pickle_and_deepcopy(quats):
    r = Rotation.from_quat(quats)
    for other in (pickle.loads(pickle.dumps(r)), copy.deepcopy(r)):
        np.testing.assert_array_equal(other.as_quat(), r.as_quat())
    tf = RigidTransform.from_components([1.0, 0.0, 0.0], r)
    np.testing.assert_array_equal(
        pickle.loads(pickle.dumps(tf)).as_matrix(), tf.as_matrix()
    )


@pytest.mark.parametrize("lib", ["torch", "jax"])
def test_other_namespaces_in_and_out(quats, rng, lib):
    if lib == "torch":
        torch = pytest.importorskip("torch")
        to = torch.tensor
        is_ns = lambda x: isinstance(x, torch.Tensor)  # noqa: E731
    else:
        jnp = pytest.importorskip("jax.numpy")
        to = jnp.asarray
        is_ns = lambda x: type(x).__module__.startswith("jax")  # noqa: E731
    v = rng.standard_normal((6, 3))
    r = Rotation.from_quat(to(quats))
    s = sst.Rotation.from_quat(quats)
    # The input's dtype is kept: float64 (torch), float32 (JAX without x64).
    dtype = r.as_quat().dtype
    assert dtype == to(quats).dtype
    atol = 1e-12 if "64" in str(dtype) else 2e-6
    for got, want in [
        (r.as_quat(), s.as_quat()),
        (r.as_matrix(), s.as_matrix()),
        (r.apply(to(v)), s.apply(v)),
        ((r * r.inv()).as_rotvec(), np.zeros((6, 3))),
        (r.magnitude(), s.magnitude()),
        (r.as_euler("ZYX"), s.as_euler("ZYX")),
    ]:
        assert is_ns(got) and got.dtype == dtype
        np.testing.assert_allclose(np.asarray(got), want, atol=atol)
    tf = RigidTransform.from_components(to(v), r)
    st = sst.RigidTransform.from_components(v, s)
    assert is_ns(tf.apply(to(v)))
    np.testing.assert_allclose(np.asarray(tf.apply(to(v))), st.apply(v), atol=4 * atol)
    np.testing.assert_allclose(
        np.asarray(tf.as_exp_coords()), st.as_exp_coords(), atol=4 * atol
    )


def test_align_vectors_primary_and_sensitivity(rng):
    a = rng.standard_normal((5, 3))
    b = rng.standard_normal((5, 3))
    w = np.array([1.0, np.inf, 2.0, 0.5, 1.0])
    got, rssd = Rotation.align_vectors(a, b, w)
    want, want_rssd = sst.Rotation.align_vectors(a, b, w)
    _same_rotations(got.as_quat(), want.as_quat(), 1e-12)
    assert abs(rssd - want_rssd) <= 1e-12
    got, rssd, sens = Rotation.align_vectors(a, b, return_sensitivity=True)
    want, want_rssd, want_sens = sst.Rotation.align_vectors(a, b, return_sensitivity=True)
    np.testing.assert_allclose(sens, want_sens, rtol=1e-12)
    with pytest.raises(ValueError, match="Only one infinite weight"):
        Rotation.align_vectors(a, b, np.full(5, np.inf))


def test_rotation_spline_extrapolates_as_scipy(rng):
    times = np.array([0.0, 1.0, 2.5, 3.0])
    keys = rng.standard_normal((4, 4))
    ours = RotationSpline(times, Rotation.from_quat(keys))
    theirs = sst.RotationSpline(times, sst.Rotation.from_quat(keys))
    t = np.array([-0.7, -0.1, 0.4, 2.9, 3.2, 4.0])
    _same_rotations(ours(t).as_quat(), theirs(t).as_quat(), 1e-8)
    # scipy stops its solve after 10 steps (~1e-9 from the exact spline); ours is exact
    for order in (1, 2):
        np.testing.assert_allclose(ours(t, order), theirs(t, order), atol=1e-6)
    assert ours(0.5).single and ours(0.5, 1).shape == (3,)


def test_slerp_matches_scipy(quats, rng):
    times = np.cumsum(rng.uniform(0.1, 1.0, 6))
    t = rng.uniform(times[0], times[-1], 20)
    got = Slerp(times, Rotation.from_quat(quats))(t)
    want = sst.Slerp(times, sst.Rotation.from_quat(quats))(t)
    _same_rotations(got.as_quat(), want.as_quat())


def test_dual_quaternions_match_scipy_and_a_zero_real_part_raises(rng):
    """scipy's test_from_dual_quat is deselected for its last case only: a dual
    quaternion whose real part is zero, which scipy maps to the identity."""
    tf = sst.RigidTransform.from_exp_coords(rng.standard_normal((5, 6)))
    dq = tf.as_dual_quat() * rng.uniform(0.5, 2.0, (5, 1))  # non-unit, as scipy allows
    for scalar_first in (False, True):
        d = tf.as_dual_quat(scalar_first=scalar_first) * 1.5
        got = RigidTransform.from_dual_quat(d, scalar_first=scalar_first)
        np.testing.assert_allclose(got.as_matrix(), tf.as_matrix(), atol=1e-13)
    np.testing.assert_allclose(
        RigidTransform.from_dual_quat(dq).as_matrix(),
        sst.RigidTransform.from_dual_quat(dq).as_matrix(),
        atol=1e-13,
    )
    with pytest.raises(rk.ZeroNormError):
        RigidTransform.from_dual_quat(np.zeros(8))


@pytest.mark.parametrize("bad", [0.0, np.nan, np.inf])
def test_from_quat_one_pass_still_checks(quats, bad):
    """The one-pass path of from_quat (scalar last) hands a zero or non-finite norm
    to rigidkit's checked path: an error naming the batch index, as scipy raises for
    a zero quaternion (scipy lets NaN through)."""
    q = quats.copy()
    q[3] = bad
    with pytest.raises(ValueError, match=r"\(3,\)"):
        Rotation.from_quat(q)
    if bad == 0.0:
        with pytest.raises(ValueError):
            sst.Rotation.from_quat(q)


def test_suppress_warnings_leaves_other_threads_recording_alone():
    # as_euler(suppress_warnings=True) at gimbal lock in one thread while another
    # records its own warnings: the recording holds exactly that thread's warning
    # every time. (warnings.catch_warnings() in the suppressing thread swapped the
    # process-wide filters and showwarning: the recorder lost its "always" filter
    # or its list, and got a stray GimbalLockWarning.)
    locked = Rotation.from_euler("ZYX", [[10.0, 90.0, 30.0]] * 4, degrees=True)
    theirs = sst.Rotation.from_quat(locked.as_quat())
    expected = theirs.as_euler("ZYX", degrees=True, suppress_warnings=True)
    axes = np.eye(3)[::-1]  # Davenport angles about z, y, x: the same lock
    expected_dav = theirs.as_davenport(axes, "i", degrees=True, suppress_warnings=True)
    stop, bad, calls = threading.Event(), [], [0]

    def suppress():
        while not stop.is_set():
            angles = locked.as_euler("ZYX", degrees=True, suppress_warnings=True)
            dav = locked.as_davenport(axes, "i", degrees=True, suppress_warnings=True)
            calls[0] += 1
            if not (
                np.allclose(angles, expected, atol=1e-9)
                and np.allclose(dav, expected_dav, atol=1e-9)
            ):
                bad.append((angles, dav))

    switch = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    worker = threading.Thread(target=suppress)
    worker.start()
    lost = 0
    try:
        for k in range(2000):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                time.sleep(0)  # the other thread runs inside this block
                warnings.warn(f"mine {k}", UserWarning, stacklevel=1)
            lost += [str(w.message) for w in caught] != [f"mine {k}"]
    finally:
        stop.set()
        worker.join()
        sys.setswitchinterval(switch)
    assert calls[0] > 0 and not bad
    assert lost == 0, f"{lost} of 2000 recordings disturbed ({calls[0]} calls)"


def test_rotation_promoted_in_composition_and_tuple_indexing(quats, rng):
    # scipy 1.18 composes a Rotation with a RigidTransform either way (the
    # rotation promoted); checked against scipy's matrices of the promoted product.
    t = rng.standard_normal((6, 3))
    tf, r = RigidTransform.from_components(t, Rotation.from_quat(quats)), Rotation(quats)
    s_tf = sst.RigidTransform.from_components(t, sst.Rotation.from_quat(quats))
    s_r = sst.RigidTransform.from_rotation(sst.Rotation.from_quat(quats))
    for ours, theirs in ((tf * r, s_tf * s_r), (r * tf, s_r * s_tf)):
        assert isinstance(ours, RigidTransform)
        np.testing.assert_allclose(ours.as_matrix(), theirs.as_matrix(), atol=1e-14)
    # A tuple index holding an index array (was: "truth value ... ambiguous"
    # for transforms) selects as the bare array does (NumPy's a[(i,)] == a[i]).
    idx = [4, 0, 2]
    want = s_tf[idx].as_matrix()
    np.testing.assert_allclose(tf[(np.array(idx),)].as_matrix(), want, atol=1e-14)
    np.testing.assert_allclose(tf[idx].as_matrix(), want, atol=1e-14)
    want = sst.Rotation(quats)[idx].as_quat()
    np.testing.assert_allclose(r[(np.array(idx),)].as_quat(), want, atol=1e-15)
