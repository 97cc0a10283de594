"""scipy parity of the rotation toolbox: Davenport angles, one- and two-axis Euler
sequences, ``apply(inverse=True)``, symmetry groups and ``reduce``.

Every result is compared with scipy.spatial.transform.Rotation (quaternions up to
sign, angles modulo 2 pi, at gimbal lock the rebuilt rotation).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRotation

import rigidkit as rk
from rigidkit import EulerSequenceError, GimbalLockWarning, ShapeError, ZeroNormError
from rigidkit.functional import davenport

TOL = 1e-13


def sci_quat(r):
    return r.as_quat(scalar_first=True)


def assert_same_rotations(q1, q2, tol=TOL):
    """Quaternions equal up to sign (q and -q are one rotation)."""
    q1 = np.asarray(q1, dtype=np.float64)
    q2 = np.asarray(q2, dtype=np.float64)
    assert q1.shape == q2.shape
    dots = np.abs(np.sum(q1 * q2, axis=-1))
    assert np.all(np.abs(dots - 1.0) <= tol), np.abs(dots - 1.0).max()


def angle_diff(a, b):
    """|a - b| modulo 2 pi."""
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))


def random_axes(rng, lam, scale=True):
    """Axes n1, n2, n3 with n2 orthogonal to both and angle ``lam`` from n1 to n3."""
    a = rng.standard_normal(3)
    a /= np.linalg.norm(a)
    b = np.cross(a, rng.standard_normal(3))
    b /= np.linalg.norm(b)
    c = np.cross(a, b)
    axes = np.array([a, b, math.cos(lam) * a + math.sin(lam) * c])
    return axes * rng.uniform(0.5, 3.0, (3, 1)) if scale else axes


E = np.eye(3)
# Euler-like and general axis triples; lam avoids exactly 0 and pi, where the range
# of the middle angle is decided by the sign of a rounding residue (scipy's too).
LAMS = [0.3, -0.3, 1.2, -1.2, math.pi / 2, -math.pi / 2, 2.8, -2.8]


# -- Davenport ---------------------------------------------------------------------------
@pytest.mark.parametrize("order", ["e", "i", "extrinsic", "intrinsic"])
@pytest.mark.parametrize("n", [1, 2, 3])
def test_from_davenport_matches_scipy(rng, order, n):
    for lam in LAMS[:4]:
        axes = random_axes(rng, lam)[:n]
        angles = rng.uniform(-4.0, 4.0, (5, n))
        got = rk.Rotation.from_davenport(axes, order, angles)
        want = SciRotation.from_davenport(axes, order, angles)
        assert got.shape == (5,)
        assert_same_rotations(got.as_quat(), sci_quat(want))
        deg = rk.Rotation.from_davenport(axes, order, np.degrees(angles), degrees=True)
        assert_same_rotations(deg.as_quat(), sci_quat(want))


def test_from_davenport_single_axis_scalar_and_shapes():
    ez = [0.0, 0.0, 3.0]
    R = rk.Rotation.from_davenport(ez, "e", 0.7)
    assert R.shape == ()
    assert_same_rotations(R.as_quat(), sci_quat(SciRotation.from_rotvec([0, 0, 0.7])))
    assert rk.Rotation.from_davenport([ez], "i", [0.7]).shape == ()
    assert rk.Rotation.from_davenport([ez], "i", [[0.7], [0.1]]).shape == (2,)
    # One sequence of axes per element, broadcast against a batch of angles.
    axes = np.stack([random_axes(np.random.default_rng(i), 0.4) for i in range(4)])
    angles = np.random.default_rng(9).uniform(-3, 3, (2, 4, 3))
    got = rk.Rotation.from_davenport(axes, "i", angles)
    assert got.shape == (2, 4)
    for j in range(4):
        want = SciRotation.from_davenport(axes[j], "i", angles[:, j])
        assert_same_rotations(got.as_quat()[:, j], sci_quat(want))


@pytest.mark.parametrize("order", ["e", "i"])
@pytest.mark.parametrize("lam", LAMS)
def test_as_davenport_matches_scipy(rng, order, lam):
    axes = random_axes(rng, lam)
    r = SciRotation.random(300, rng)
    want = r.as_davenport(axes, order)
    got = rk.Rotation.from_quat(sci_quat(r)).as_davenport(axes, order)
    assert np.all(angle_diff(got, want) <= 1e-12), angle_diff(got, want).max()
    # The range of the middle angle: length pi, one end at lam (the angle from the
    # first axis of the matrix product to the last, about -n2), containing 0.
    lam_k = lam if order == "i" else -lam
    lo, hi = (lam_k, lam_k + math.pi) if lam_k <= 0 else (lam_k - math.pi, lam_k)
    assert np.all((got[:, 1] >= lo - 1e-12) & (got[:, 1] <= hi + 1e-12))
    assert np.all(np.abs(got[:, [0, 2]]) <= math.pi)
    back = rk.Rotation.from_davenport(axes, order, got)
    assert_same_rotations(back.as_quat(), sci_quat(r))
    deg = rk.Rotation.from_quat(sci_quat(r)).as_davenport(axes, order, degrees=True)
    assert np.all(angle_diff(np.radians(deg), want) <= 1e-12)


EULER_AXES = {
    "zyx": [E[2], E[1], E[0]],
    "xyz": [E[0], E[1], E[2]],
    "zxz": [E[2], E[0], E[2]],
    "yxy": [E[1], E[0], E[1]],
    "z x -z": [E[2], E[0], [0.0, 0.0, -1.0]],  # not -E[2]: see the test below
}


@pytest.mark.parametrize("name", list(EULER_AXES))
@pytest.mark.parametrize("order", ["e", "i"])
def test_as_davenport_on_coordinate_axes_matches_scipy(rng, name, order):
    """Exactly parallel or antiparallel n1, n3 (lam = 0, pi): scipy's ranges."""
    axes = np.array(EULER_AXES[name])
    r = SciRotation.random(300, rng)
    got = rk.Rotation.from_quat(sci_quat(r)).as_davenport(axes, order)
    want = r.as_davenport(axes, order)
    assert np.all(angle_diff(got, want) <= 1e-12)
    if " " not in name:  # also the Euler angles of the same sequence
        seq = name if order == "e" else name.upper()
        euler_angles = rk.Rotation.from_quat(sci_quat(r)).as_euler(seq)
        assert np.all(angle_diff(got, euler_angles) <= 1e-12)


def test_antiparallel_axes_range_ignores_signed_zeros(rng):
    """n3 = -n1 exactly: the middle angle in [-pi, 0] (lam = -pi), whether the
    zeros of the axes are +0 or -0 (scipy's choice follows the sign of a zero
    triple product, so it flips with -E[2] in place of [0, 0, -1])."""
    q = rk.Rotation.random(200, rng)
    for n3 in ([0.0, 0.0, -1.0], [-0.0, -0.0, -1.0]):
        for order in ("e", "i"):
            got = q.as_davenport([E[2], E[0], n3], order)
            assert np.all(got[:, 1] <= 0.0) and np.all(got[:, 1] >= -math.pi)
            back = rk.Rotation.from_davenport([E[2], E[0], n3], order, got)
            assert np.all(back.approx_equal(q, atol=1e-14))


@pytest.mark.parametrize("order", ["e", "i"])
@pytest.mark.parametrize("lam", [0.0, 0.7, -1.1, math.pi / 2])
def test_as_davenport_at_gimbal_lock(rng, order, lam):
    """Middle angle at a lock (lam + 0 or lam + pi in the auxiliary sequence): a
    warning, the third angle 0 (as scipy), and the angles rebuild the rotation."""
    axes = random_axes(rng, lam, scale=False) if lam else np.array(EULER_AXES["zxz"])
    lam_k = lam if order == "i" else -lam
    lo = lam_k if lam_k <= 0 else lam_k - math.pi
    for mid in (lo, lo + math.pi):
        angles = np.array([[0.4, mid, 1.3], [-2.0, mid, 0.5]])
        q = rk.Rotation.from_davenport(axes, order, angles).as_quat()
        R = rk.Rotation.from_quat(q)
        with pytest.warns(GimbalLockWarning):
            got = R.as_davenport(axes, order)
        assert np.all(got[:, 2] == 0.0)
        assert_same_rotations(rk.Rotation.from_davenport(axes, order, got).as_quat(), q)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            want = SciRotation.from_quat(q, scalar_first=True).as_davenport(axes, order)
        assert np.all(angle_diff(got, want) <= 1e-9), (got, want)


def test_davenport_round_trip_from_angles(rng):
    """Angles inside the ranges come back (well away from the lock)."""
    for lam in (0.5, -0.5, 2.0):
        axes = random_axes(rng, lam)
        for order in ("e", "i"):
            lam_k = lam if order == "i" else -lam
            lo = lam_k if lam_k <= 0 else lam_k - math.pi
            angles = np.column_stack(
                [
                    rng.uniform(-3.1, 3.1, 50),
                    rng.uniform(lo + 0.1, lo + math.pi - 0.1, 50),
                    rng.uniform(-3.1, 3.1, 50),
                ]
            )
            R = rk.Rotation.from_davenport(axes, order, angles)
            np.testing.assert_allclose(R.as_davenport(axes, order), angles, atol=1e-12)


def test_davenport_bad_input():
    ex, ey = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]
    tilted = [1.0, 1e-3, 0.0]
    with pytest.raises(EulerSequenceError) as err:
        rk.Rotation.from_davenport([ex, tilted, ex], "e", [0.1, 0.2, 0.3])
    assert err.value.index == (0,)  # the first pair (n1, n2)
    batch = np.array([[ex, ey, ex], [ex, ey, tilted]])
    with pytest.raises(EulerSequenceError) as err:
        rk.Rotation.from_davenport(batch, "e", [0.1, 0.2, 0.3])
    assert err.value.index == (1, 1)  # element 1, pair (n2, n3)
    with pytest.raises(EulerSequenceError):
        rk.Rotation.identity().as_davenport([ex, tilted, ex], "i")
    with pytest.raises(EulerSequenceError, match="extrinsic"):
        rk.Rotation.from_davenport([ex, ey, ex], "world", [0.1, 0.2, 0.3])
    with pytest.raises(ZeroNormError):
        rk.Rotation.from_davenport([ex, [0.0, 0.0, 0.0]], "e", [0.1, 0.2])
    with pytest.raises(ShapeError):
        rk.Rotation.identity().as_davenport([ex, ey], "e")  # three axes, as scipy
    with pytest.raises(ShapeError):
        rk.Rotation.from_davenport([ex, ey], "e", [0.1, 0.2, 0.3])
    with pytest.raises(rk.NonFiniteError):
        davenport.davenport_from_quat([ex, ey, ex], "e", [np.nan, 0.0, 0.0, 1.0])
    with pytest.raises(ZeroNormError):
        davenport.davenport_from_quat([ex, ey, ex], "e", [0.0, 0.0, 0.0, 0.0])


def _inside_range_angles(rng, n=4):
    """Angles about ``random_axes(rng, 0.6)``, intrinsic: middle in [0.6 - pi, 0.6]."""
    angles = rng.uniform(-2, 2, (n, 3))
    angles[:, 1] = rng.uniform(0.6 - math.pi + 0.1, 0.5, n)
    return angles


def test_davenport_float32(rng):
    axes = random_axes(rng, 0.6)
    angles = _inside_range_angles(rng)
    ref = rk.Rotation.from_davenport(axes, "i", angles)
    r32 = rk.Rotation.from_davenport(axes, "i", angles.astype(np.float32))
    assert r32.dtype == np.float32
    assert_same_rotations(r32.as_quat(), ref.as_quat(), tol=1e-6)
    a32 = rk.Rotation.from_quat(ref.as_quat().astype(np.float32)).as_davenport(axes, "i")
    assert a32.dtype == np.float32
    np.testing.assert_allclose(a32, angles, atol=2e-5)


def test_davenport_torch_gradients(rng, torch):
    axes = random_axes(rng, 0.6)
    angles = _inside_range_angles(rng)
    t = torch.tensor(angles, requires_grad=True)
    q = rk.Rotation.from_davenport(torch.tensor(axes), "i", t).as_quat()
    assert isinstance(q, torch.Tensor)
    assert_same_rotations(
        q.detach().numpy(), rk.Rotation.from_davenport(axes, "i", angles).as_quat()
    )
    back = rk.Rotation.from_quat(q).as_davenport(axes, "i")
    np.testing.assert_allclose(back.detach().numpy(), angles, atol=1e-12)
    # The round trip is the identity map: its Jacobian is I (here the row sums, 1).
    back.sum().backward()
    np.testing.assert_allclose(t.grad.numpy(), 1.0, atol=1e-9)


def test_davenport_under_jax_jit(rng, jax):
    axes = random_axes(rng, 0.6)
    angles = _inside_range_angles(rng)

    @jax.jit
    def round_trip(a):
        return rk.Rotation.from_davenport(axes, "i", a).as_davenport(axes, "i")

    np.testing.assert_allclose(
        np.asarray(round_trip(jax.numpy.asarray(angles))), angles, atol=1e-12
    )


# -- one- and two-axis Euler sequences ----------------------------------------------------
@pytest.mark.parametrize("seq", ["x", "Y", "z", "zy", "XY", "yz", "ZX", "xz"])
def test_short_euler_sequences_match_scipy(rng, seq):
    angles = rng.uniform(-4.0, 4.0, (6, len(seq)))
    got = rk.Rotation.from_euler(seq, angles)
    assert got.shape == (6,)
    assert_same_rotations(got.as_quat(), sci_quat(SciRotation.from_euler(seq, angles)))
    deg = rk.Rotation.from_euler(seq, np.degrees(angles), degrees=True)
    assert_same_rotations(deg.as_quat(), got.as_quat())
    single = rk.Rotation.from_euler(seq, angles[0])
    assert single.shape == ()
    assert_same_rotations(
        single.as_quat(), sci_quat(SciRotation.from_euler(seq, angles[0]))
    )


def test_short_euler_scalar_and_errors():
    R = rk.Rotation.from_euler("z", 0.5)
    assert R.shape == ()
    assert_same_rotations(R.as_quat(), sci_quat(SciRotation.from_euler("z", 0.5)))
    with pytest.raises(ShapeError):
        rk.Rotation.from_euler("zy", [0.1, 0.2, 0.3])  # as scipy: n angles for n axes
    with pytest.raises(ShapeError):
        rk.Rotation.from_euler("zy", 0.1)
    for bad in ("zz", "zY", "w", "xw"):
        with pytest.raises(EulerSequenceError):
            rk.Rotation.from_euler(bad, [0.1] * len(bad))
    with pytest.raises(EulerSequenceError, match="not 3"):
        rk.Rotation.identity().as_euler("zy")  # scipy's as_euler takes 3 axes too
    assert rk.Rotation.from_euler("XY", np.zeros((2, 2), np.float32)).dtype == np.float32


# -- apply(inverse=True) -------------------------------------------------------------------
def test_apply_inverse_matches_scipy(rng):
    r = SciRotation.random(5, rng)
    v = rng.standard_normal((5, 3))
    R = rk.Rotation.from_quat(sci_quat(r))
    np.testing.assert_allclose(
        R.apply(v, inverse=True), r.apply(v, inverse=True), atol=1e-15
    )
    # Broadcasting (one rotation, many vectors) and the out= buffer.
    out = np.empty((5, 3))
    got = R[2].apply(v, inverse=True, out=out)
    assert got is out
    np.testing.assert_allclose(out, r[2].apply(v, inverse=True), atol=1e-15)
    np.testing.assert_allclose(R.apply(R.apply(v), inverse=True), v, atol=1e-15)


# -- symmetry groups and reduce ------------------------------------------------------------
GROUPS = ["I", "O", "T", "D1", "D2", "D3", "D6", "C1", "C2", "C5"]


@pytest.mark.parametrize("group", GROUPS)
@pytest.mark.parametrize("axis", ["X", "y", "Z"])
def test_create_group_matches_scipy(group, axis):
    """The same set of rotations as scipy's (up to order and sign), and a group:
    closed under composition and inverse."""
    G = rk.Rotation.create_group(group, axis)
    want = sci_quat(SciRotation.create_group(group, axis))
    got = G.as_quat()
    assert got.shape == want.shape
    dots = np.abs(got @ want.T)
    assert np.all(np.abs(dots.max(axis=1) - 1.0) <= 1e-14)  # each of ours in scipy's
    assert np.all(np.abs(dots.max(axis=0) - 1.0) <= 1e-14)  # and each of scipy's in ours
    assert np.all(np.abs(np.abs(got @ got.T) - 1.0).min(axis=1) <= 1e-14)
    assert np.all(np.sort(np.abs(got @ got.T) > 1 - 1e-12, axis=1).sum(axis=1) == 1)
    products = (G[:, None] @ G[None, :]).as_quat().reshape(-1, 4)
    assert np.all(np.abs(np.abs(products @ got.T).max(axis=1) - 1.0) <= 1e-13)
    inverses = G.inv().as_quat()
    assert np.all(np.abs(np.abs(inverses @ got.T).max(axis=1) - 1.0) <= 1e-14)


def test_create_group_bad_input():
    for bad in ("A", "C0", "D", "Cx", "I2", 3):
        with pytest.raises(rk.RigidkitError):
            rk.Rotation.create_group(bad)
    with pytest.raises(rk.RigidkitError):
        rk.Rotation.create_group("C3", axis="W")
    assert isinstance(rk.RigidkitError("x"), ValueError)
    assert rk.Rotation.create_group("T", dtype=np.float32).dtype == np.float32


@pytest.mark.parametrize(
    "left, right", [("I", None), (None, "O"), ("T", "D3"), ("C4", "I"), ("O", "O")]
)
def test_reduce_matches_scipy(rng, left, right):
    p = SciRotation.random(40, rng)
    L = None if left is None else rk.Rotation.create_group(left)
    R = None if right is None else rk.Rotation.create_group(right, "X")
    sL = None if left is None else SciRotation.create_group(left)
    sR = None if right is None else SciRotation.create_group(right, "X")
    P = rk.Rotation.from_quat(sci_quat(p))
    reduced, li, ri = P.reduce(L, R, return_indices=True)
    want = p.reduce(sL, sR)
    np.testing.assert_allclose(reduced.magnitude(), want.magnitude(), atol=1e-14)
    if left is None or right is None:
        # With one group the smallest l p (or p r) is unique for random p: scipy's.
        # With both, h l p r h^-1 has the same angle wherever h is in both groups.
        assert_same_rotations(reduced.as_quat(), sci_quat(want), tol=1e-14)
    # The indices name the pair that gives it.
    rebuilt = P
    if L is not None:
        assert li.shape == (40,)
        rebuilt = L[li] @ rebuilt
    else:
        assert li is None
    if R is not None:
        rebuilt = rebuilt @ R[ri]
    else:
        assert ri is None
    assert np.all(rebuilt.approx_equal(reduced, atol=1e-14))
    # And no other pair is smaller (brute force over both groups).
    Ls = rk.Rotation.identity((1,)) if L is None else L
    Rs = rk.Rotation.identity((1,)) if R is None else R
    every = Ls[:, None, None] @ P[None, :, None] @ Rs[None, None, :]
    smallest = every.magnitude().min(axis=(0, 2))
    np.testing.assert_allclose(reduced.magnitude(), smallest, atol=1e-14)


def test_reduce_single_identity_and_backends(rng, torch):
    G = rk.Rotation.create_group("O")
    p = rk.Rotation.random((), rng)
    red, li, ri = p.reduce(left=G, return_indices=True)
    assert red.shape == () and li.shape == () and ri is None
    assert p.reduce() is p
    want = SciRotation.from_quat(p.as_quat(), scalar_first=True).reduce(
        SciRotation.create_group("O")
    )
    assert_same_rotations(red.as_quat(), sci_quat(want), tol=1e-14)
    # torch in, torch out; gradients flow through the selected composition.
    q = torch.tensor(p.as_quat().copy(), requires_grad=True)
    red_t = rk.Rotation.from_quat(q).reduce(G)
    assert isinstance(red_t.as_quat(), torch.Tensor)
    assert_same_rotations(red_t.as_quat().detach().numpy(), red.as_quat())
    red_t.as_quat()[0].backward()
    assert torch.isfinite(q.grad).all()


def test_reduce_under_jax_jit(rng, jax):
    G = rk.Rotation.create_group("T")
    p = rk.Rotation.random(5, rng)

    @jax.jit
    def reduced(q):
        return rk.Rotation.from_quat(q).reduce(G, G).as_quat()

    got = np.asarray(reduced(jax.numpy.asarray(p.as_quat())))
    assert_same_rotations(got, p.reduce(G, G).as_quat(), tol=1e-14)
