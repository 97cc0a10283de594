"""Euler angles, all 24 sequences: ``rigidkit.euler`` and ``Rotation.from_euler/as_euler``.

Independent references:

* the elementary rotations ``Rx``, ``Ry``, ``Rz`` written out, multiplied in the order
  "right-multiply body, left-multiply world": intrinsic ``"XYZ"`` is
  ``Rx @ Ry @ Rz``, extrinsic ``"xyz"`` is ``Rz @ Ry @ Rx``;
* ``scipy.spatial.transform.Rotation`` (conventions, all 24 sequences);
* the closed forms of ``R_XYZ`` (with docs/errata.md E1 corrected) and ``R_ZYX``,
  written out by hand;
* mpmath at 50+ digits: the rotation of exact angles (products of axis
  quaternions), the exact Euler angles of a float quaternion (Newton's method on
  that product, which never uses our inverse formulas), and the angle between
  two rotations (the rebuild error);
* central finite differences for torch gradients.

Tolerances: float64 angles and rebuilt rotations within 1e-15 rad, a few ulp of
pi (4.4e-16): each angle is one ``atan2`` of quantities with a few ulp relative
error. float32 within 5e-7 (a few float32 ulp of pi, 2.4e-7).
"""

from __future__ import annotations

import math
import warnings

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk
from conftest import optional, quat_angle
from rigidkit import euler
from rigidkit.errors import (
    EulerSequenceError,
    GimbalLockWarning,
    NonFiniteError,
    ShapeError,
)
from rigidkit.kernels import euler as kernels

SEQS = [
    s
    for a in "xyz"
    for b in "xyz"
    for c in "xyz"
    if a != b and b != c
    for s in (a + b + c, (a + b + c).upper())
]
assert len(SEQS) == 24

TOL64 = 1e-15
TOL32 = 5e-7
# Lock cleaning tolerances (rad): 2 eps of the dtype, the rotation change of one ulp in
# every component of a unit quaternion.
LOCK64 = 2 * float(np.finfo(np.float64).eps)
LOCK32 = 2 * float(np.finfo(np.float32).eps)


def is_proper(seq):
    return seq[0].lower() == seq[2].lower()


def lock_values(seq):
    """The two middle angles at gimbal lock."""
    return (0.0, math.pi) if is_proper(seq) else (-math.pi / 2, math.pi / 2)


def lock_distance(seq, mid):
    lo, hi = lock_values(seq)
    return np.minimum(np.abs(mid - lo), np.abs(hi - mid))


def random_angles(seq, rng, n, dtype=np.float64):
    """Angles in the canonical ranges of ``seq``."""
    a = rng.uniform(-math.pi, math.pi, (n, 3))
    a[:, 1] = np.abs(a[:, 1]) if is_proper(seq) else a[:, 1] / 2
    return a.astype(dtype)


def wrap(d):
    """An angle difference folded into [-pi, pi]."""
    return np.angle(np.exp(1j * np.asarray(d, dtype=np.float64)))


# -- elementary rotations, written out ----------------------------------------------
def elementary(axis, t):
    c, s = np.cos(t), np.sin(t)
    one, zero = np.ones_like(t), np.zeros_like(t)
    rows = {
        0: [[one, zero, zero], [zero, c, -s], [zero, s, c]],
        1: [[c, zero, s], [zero, one, zero], [-s, zero, c]],
        2: [[c, -s, zero], [s, c, zero], [zero, zero, one]],
    }[axis]
    return np.moveaxis(np.array(rows), (0, 1), (-2, -1))


def matrix_by_products(seq, angles):
    """Intrinsic ``"abc"``: ``R_a(t0) @ R_b(t1) @ R_c(t2)``; extrinsic: the reverse."""
    mats = [elementary("xyz".index(ch), angles[..., k]) for k, ch in enumerate(seq.lower())]
    if seq.isupper():
        return mats[0] @ mats[1] @ mats[2]
    return mats[2] @ mats[1] @ mats[0]


# -- mpmath references ---------------------------------------------------------------
DPS = 60


def mp_axis_quat(axis, angle):
    h = mp.mpf(angle) / 2
    q = [mp.cos(h), mp.mpf(0), mp.mpf(0), mp.mpf(0)]
    q[1 + axis] = mp.sin(h)
    return q


def mp_mul(p, q):
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return [
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    ]


def mp_quat_from_euler(seq, angles):
    """The product of the three axis quaternions (exact angles, mpmath)."""
    f = [
        mp_axis_quat("xyz".index(ch), t) for ch, t in zip(seq.lower(), angles, strict=True)
    ]
    if seq.isupper():
        return mp_mul(mp_mul(f[0], f[1]), f[2])
    return mp_mul(mp_mul(f[2], f[1]), f[0])


def mp_unit(q):
    q = [mp.mpf(float(c)) if not isinstance(c, mp.mpf) else c for c in q]
    n = mp.sqrt(sum(c * c for c in q))
    return [c / n for c in q]


def mp_angle_between(q1, q2):
    """Rotation angle of ``q1* q2``: ``2 atan2(|v|, |w|)`` at mpmath precision."""
    q1, q2 = mp_unit(q1), mp_unit(q2)
    e = mp_mul([q1[0], -q1[1], -q1[2], -q1[3]], q2)
    return 2 * mp.atan2(mp.sqrt(e[1] ** 2 + e[2] ** 2 + e[3] ** 2), abs(e[0]))


def mp_rebuild_error(seq, angles, quat):
    """Angle (rad) between the rotation of float ``angles`` and that of float ``quat``."""
    with mp.workdps(DPS):
        exact = mp_quat_from_euler(seq, [mp.mpf(float(a)) for a in angles])
        return float(mp_angle_between(exact, quat))


def mp_exact_angles(seq, start, quat):
    """The exact Euler angles of the float ``quat``, by Newton's method from ``start``.

    The residual is the rotation vector of ``q(angles)* q``; only the forward
    product of axis quaternions is used. Converges quadratically wherever the
    Jacobian is invertible (anywhere but exact lock).
    """
    with mp.workdps(DPS):
        qt = mp_unit(quat)
        th = [mp.mpf(float(a)) for a in start]

        def residual(th):
            q = mp_quat_from_euler(seq, th)
            e = mp_mul([q[0], -q[1], -q[2], -q[3]], qt)
            s = 1 if e[0] >= 0 else -1
            return mp.matrix([2 * s * e[1], 2 * s * e[2], 2 * s * e[3]])

        h = mp.mpf("1e-22")
        for _ in range(12):
            f = residual(th)
            if mp.norm(f) < mp.mpf("1e-45"):
                return th
            jac = mp.matrix(3, 3)
            for k in range(3):
                tp, tm = list(th), list(th)
                tp[k] += h
                tm[k] -= h
                col = (residual(tp) - residual(tm)) / (2 * h)
                for r in range(3):
                    jac[r, k] = col[r]
            step = mp.lu_solve(jac, -f)
            th = [th[k] + step[k] for k in range(3)]
        raise AssertionError("Newton did not converge")


def mp_angle_error(got, exact):
    """|got - exact| folded modulo 2 pi, per angle."""
    with mp.workdps(DPS):
        out = []
        for g, e in zip(got, exact, strict=True):
            d = mp.mpf(float(g)) - e
            out.append(abs(float(mp.atan2(mp.sin(d), mp.cos(d)))))
        return np.array(out)


def float_quat(mp_q):
    return np.array([float(c) for c in mp_q])


# -- conventions -----------------------------------------------------------------------
@pytest.mark.parametrize("seq", SEQS)
def test_matrix_is_product_of_elementary_rotations(seq, rng):
    """Right-multiply body (intrinsic), left-multiply world (extrinsic)."""
    a = rng.uniform(-4.0, 4.0, (60, 3))  # also outside the canonical ranges
    np.testing.assert_allclose(
        euler.matrix_from_euler(seq, a), matrix_by_products(seq, a), rtol=0, atol=TOL64
    )


def test_right_multiply_body_left_multiply_world():
    phi, theta, psi = 0.3, -0.7, 1.9
    Rx, Ry, Rz = elementary(0, phi), elementary(1, theta), elementary(2, psi)
    R_XYZ = rk.Rotation.from_euler("XYZ", [phi, theta, psi]).as_matrix()
    R_xyz = rk.Rotation.from_euler("xyz", [phi, theta, psi]).as_matrix()
    np.testing.assert_allclose(R_XYZ, Rx @ Ry @ Rz, rtol=0, atol=TOL64)
    np.testing.assert_allclose(R_xyz, Rz @ Ry @ Rx, rtol=0, atol=TOL64)
    # Turning about the body axis = right-multiplying; about the world axis = left.
    A_R_B = rk.Rotation.from_euler("ZYX", [0.4, 0.5, 0.6])
    body = rk.Rotation.from_euler("XYZ", [psi, 0.0, 0.0])
    np.testing.assert_allclose(
        (A_R_B @ body).as_matrix(), A_R_B.as_matrix() @ elementary(0, psi), atol=TOL64
    )
    np.testing.assert_allclose(
        (body @ A_R_B).as_matrix(), elementary(0, psi) @ A_R_B.as_matrix(), atol=TOL64
    )


@pytest.mark.parametrize("seq", SEQS)
def test_from_euler_matches_scipy(seq, rng):
    a = rng.uniform(-4.0, 4.0, (60, 3))
    got = rk.Rotation.from_euler(seq, a).as_matrix()
    np.testing.assert_allclose(got, SciRot.from_euler(seq, a).as_matrix(), atol=TOL64)
    deg = np.degrees(a)
    got = rk.Rotation.from_euler(seq, deg, degrees=True).as_matrix()
    want = SciRot.from_euler(seq, deg, degrees=True).as_matrix()
    np.testing.assert_allclose(got, want, atol=TOL64)


@pytest.mark.parametrize("seq", SEQS)
def test_as_euler_matches_scipy_away_from_lock(seq, rng):
    """Same angles as scipy where both are well conditioned (0.1 rad from the lock)."""
    R = rk.Rotation.random(300, rng)
    ours = R.as_euler(seq)
    theirs = SciRot.from_quat(R.as_quat(scalar_first=False)).as_euler(seq)
    keep = lock_distance(seq, theirs[:, 1]) > 0.1
    assert keep.sum() > 200
    # Condition number <= 1/sin(0.1) = 10 for the first and third angle.
    assert np.abs(wrap(ours - theirs))[keep].max() <= 10 * TOL64


@pytest.mark.parametrize("upper", [s for s in SEQS if s.isupper()])
def test_intrinsic_equals_extrinsic_reversed(upper, rng):
    a = random_angles(upper, rng, 40)
    intrinsic = euler.quat_from_euler(upper, a)
    extrinsic = euler.quat_from_euler(upper[::-1].lower(), a[:, ::-1])
    assert quat_angle(intrinsic, extrinsic).max() <= TOL64
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        back = euler.euler_from_quat(upper[::-1].lower(), intrinsic)
    np.testing.assert_allclose(wrap(back[:, ::-1] - a), 0.0, atol=1e-13)


def test_closed_forms_r_xyz_and_r_zyx():
    """``R_XYZ = Rx Ry Rz`` and ``R_ZYX = Rz Ry Rx`` written out (docs/errata.md E1)."""
    phi, theta, psi = 0.7, -0.4, 2.3  # about x, y, z
    c, s = math.cos, math.sin
    cf, sf, ct, st_, cp, sp = c(phi), s(phi), c(theta), s(theta), c(psi), s(psi)
    R_XYZ = np.array(
        [
            [ct * cp, -ct * sp, st_],
            [sf * st_ * cp + cf * sp, -sf * st_ * sp + cf * cp, -sf * ct],
            # [2, 1] corrected: c(phi) s(theta) s(psi) + s(phi) c(psi).
            [-cf * st_ * cp + sf * sp, cf * st_ * sp + sf * cp, cf * ct],
        ]
    )
    R_ZYX = np.array(
        [
            [cp * ct, -sp * cf + cp * st_ * sf, sp * sf + cp * st_ * cf],
            [sp * ct, cp * cf + sp * st_ * sf, -cp * sf + sp * st_ * cf],
            [-st_, ct * sf, ct * cf],
        ]
    )
    got_xyz = euler.matrix_from_euler("XYZ", [phi, theta, psi])
    got_zyx = euler.matrix_from_euler("ZYX", [psi, theta, phi])
    np.testing.assert_allclose(got_xyz, R_XYZ, rtol=0, atol=TOL64)
    np.testing.assert_allclose(got_zyx, R_ZYX, rtol=0, atol=TOL64)
    # The printed entry of docs/errata.md E1, c(phi) s(psi) s(theta) + s(phi) c(phi),
    # is wrong.
    assert abs(got_xyz[2, 1] - (cf * sp * st_ + sf * cf)) > 0.1


# -- accuracy against mpmath -----------------------------------------------------------
def hard_points(seq, rng):
    """Exact angles: every lock band from 1e-4 to 1e-15, first near pi, tiny middle."""
    lo, hi = (mp.mpf(0), mp.pi) if is_proper(seq) else (-mp.pi / 2, mp.pi / 2)
    pts = []
    for d in ("1e-4", "1e-9", "1e-12", "1e-15"):
        for lock, sign in ((lo, 1), (hi, -1)):
            a, c = rng.uniform(-3.1, 3.1, 2)
            pts.append([mp.mpf(a), lock + sign * mp.mpf(d), mp.mpf(c)])
    middle = mp.mpf("0.3") + (mp.pi / 2 if is_proper(seq) else 0)
    pts.append([mp.pi - mp.mpf("1e-12"), middle, -mp.pi + mp.mpf("1e-12")])
    pts.append([-mp.pi + mp.mpf("1e-12"), middle, mp.pi])
    pts.append([mp.mpf(0), (mp.pi / 2 if is_proper(seq) else 0) + mp.mpf("1e-12"), 0])
    pts.append([mp.mpf("1e-12"), mp.mpf("0.5") + (1 if is_proper(seq) else 0), 0])
    return pts


@pytest.mark.parametrize("seq", SEQS)
def test_as_euler_against_mpmath(seq, rng):
    """Angles within 1e-15 of the exact angles of the float quaternion, and of the
    exact angles the rotation was built from where those are well conditioned."""
    with mp.workdps(DPS):
        pts = hard_points(seq, rng)
        quats = np.array([float_quat(mp_quat_from_euler(seq, p)) for p in pts])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        got = euler.euler_from_quat(seq, quats)
    for p, q, g in zip(pts, quats, got, strict=True):
        exact_of_q = mp_exact_angles(seq, g, q)
        err = mp_angle_error(g, exact_of_q)
        dist = float(lock_distance(seq, float(p[1])))
        if g[2] == 0.0 and err[2] > TOL64:
            # Cleaned to the lock convention: only where that moves the rotation by
            # at most LOCK64 (checked by the rebuild below), i.e. within a few ulp.
            assert dist < 1e-14, (seq, [float(x) for x in p])
            assert err[1] <= TOL64
        else:
            assert err.max() <= TOL64, (seq, [float(x) for x in p], err)
        assert mp_rebuild_error(seq, g, q) <= TOL64
        if dist > 0.1:  # well conditioned: also the angles the rotation was built from
            assert mp_angle_error(g, p).max() <= TOL64, (seq, [float(x) for x in p])


@pytest.mark.parametrize("seq", SEQS)
def test_small_middle_angle_is_relatively_accurate(seq):
    """A turn about the middle axis alone: the angle to ~1e-15 *relative*, down to
    1e-300 (no ``2 atan2(...) - pi/2``, which would leave only absolute accuracy)."""
    ts = [1e-300, 1e-100, 1e-12, 3e-9, 1e-6, 1e-3]
    ts += [-t for t in ts] if not is_proper(seq) else []
    with mp.workdps(DPS):
        quats = np.array([float_quat(mp_quat_from_euler(seq, [0, t, 0])) for t in ts])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        got = euler.euler_from_quat(seq, quats)
    # The float quaternion carries sin(t/2) to 0.5 ulp; the kernel adds a few ulp.
    np.testing.assert_allclose(got[:, 1], ts, rtol=1e-15, atol=0)
    np.testing.assert_allclose(got[:, [0, 2]], 0.0, atol=0)


def exact_lock_quats(seq, phis):
    """Rotations exactly at lock, in float: ``q_P0(phi) q_P1(lock)``.

    ``P0, P1`` are the first two axes in matrix-product order. The lock factor is
    exact in float ((1, 0), (0, e), or (r, +-r e) with the same float r), so each
    component of the product is one rounded product: the lock survives rounding.
    """
    axes = ["xyz".index(ch) for ch in seq.lower()]
    p0, p1 = (axes[0], axes[1]) if seq.isupper() else (axes[2], axes[1])
    r = math.sqrt(0.5)
    factors = []
    for mid in ("lo", "hi"):
        f = np.zeros(4)
        if is_proper(seq):
            f[0 if mid == "lo" else 1 + p1] = 1.0
        else:
            f[0] = r
            f[1 + p1] = -r if mid == "lo" else r
        factors.append(f)
    out = []
    for phi in phis:
        first = np.zeros(4)
        first[0], first[1 + p0] = math.cos(phi / 2), math.sin(phi / 2)
        for f in factors:
            out.append(hamilton(first, f))
    return np.array(out)


def hamilton(p, q):
    """Hamilton product, written out (for floats, and for SymPy expressions)."""
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return [
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    ]


@pytest.mark.parametrize("seq", SEQS)
def test_gimbal_lock_bands(seq, rng):
    """At exact lock and 1e-9, 1e-12 from it: one warning, exact rebuild, and at
    exact lock the third angle 0."""
    exact = exact_lock_quats(seq, [0.0, 0.8, -2.5, math.pi])
    near = []
    lo, hi = (mp.mpf(0), mp.pi) if is_proper(seq) else (-mp.pi / 2, mp.pi / 2)
    with mp.workdps(DPS):
        for d in ("1e-9", "1e-12"):
            for lock, sign in ((lo, 1), (hi, -1)):
                a, c = rng.uniform(-3.1, 3.1, 2)
                angles = [mp.mpf(a), lock + sign * mp.mpf(d), mp.mpf(c)]
                near.append(float_quat(mp_quat_from_euler(seq, angles)))
    quats = np.concatenate([exact, np.array(near)])
    R = rk.Rotation.from_quat(quats)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got = R.as_euler(seq)
    assert [w.category for w in caught] == [GimbalLockWarning]
    assert f"{len(quats)} of {len(quats)}" in str(caught[0].message)
    stored = R.as_quat()
    for g, q in zip(got, stored, strict=True):
        assert mp_rebuild_error(seq, g, q) <= TOL64, (seq, g)
    lo_f, hi_f = lock_values(seq)
    n = len(exact)
    assert (got[:n, 2] == 0.0).all()
    np.testing.assert_allclose(got[:n:2, 1], lo_f, rtol=0, atol=4.5e-16)
    np.testing.assert_allclose(got[1:n:2, 1], hi_f, rtol=0, atol=4.5e-16)
    # The whole rotation is in the first angle: q_P0(first) q_P1(lock).
    np.testing.assert_allclose(
        quat_angle(euler.quat_from_euler(seq, got[:n]), stored[:n]), 0, atol=TOL64
    )


# -- numerical lock: the lock convention within lock_tolerance ------------------------
CYCLIC = {("x", "y"), ("y", "z"), ("z", "x")}


def combined_angle(seq, a, c, mid):
    """First angle at lock when the third is 0, derived by hand (mpmath or floats).

    Proper ``"IJI"``: ``R_I(a) R_J(0) R_I(c) = R_I(a + c)``; at pi, ``R_J(pi)`` flips
    the I axis, so ``R_J(pi) R_I(c) = R_I(-c) R_J(pi)``: ``a - c`` (extrinsic alike).
    Tait-Bryan ``"IJK"`` at ``s pi/2``: ``R_J(s pi/2)`` maps the K axis onto
    ``s * parity`` times the I axis (parity +1 for IJ in xy, yz, zx), so intrinsic
    gives ``a + s parity c``; extrinsic ``R_k(c) R_j(s pi/2) R_i(a)`` has ``R_k``
    on the left, pulled through with the inverse turn: ``a - s parity c``.
    """
    low = seq.lower()
    if low[0] == low[2]:
        return a + c if abs(mid) < 1 else a - c
    parity = 1 if (low[0], low[1]) in CYCLIC else -1
    s = 1 if mid > 0 else -1
    return a + (1 if seq.isupper() else -1) * s * parity * c


def lock_angle_cases(seq, rng):
    """``(a, lock, c)`` in radians and in degrees, both locks of ``seq``."""
    lo, hi = lock_values(seq)
    pairs = np.concatenate(
        [rng.uniform(-math.pi, math.pi, (10, 2)), [[0.5, 0.0], [0.3, 0.3], [math.pi, 0.1]]]
    )
    rad = np.array([[a, mid, c] for a, c in pairs for mid in (lo, hi)])
    deg_pairs = np.concatenate(
        [np.round(rng.uniform(-180, 180, (10, 2)), 2), [[30, 10], [90, 45], [-170, 170]]]
    )
    deg = np.array(
        [[a, math.degrees(mid), c] for a, c in deg_pairs for mid in (lo, hi)]
    ).round(9)  # the lock exactly 0, 180, -90 or 90 degrees
    return rad, deg


@pytest.mark.parametrize("seq", SEQS)
def test_numerical_lock_gives_lock_convention(seq, rng):
    """Angles ``(a, lock, c)``: their float quaternion sits a rounding error from the
    lock, and comes back with the third angle exactly 0, the middle at the lock and
    the first the combined angle ``a +- c`` (closed form, checked with scipy), on the
    element-wise, numba and single-element paths, radians and degrees."""
    rad, deg = lock_angle_cases(seq, rng)
    for angles, degrees in ((rad, False), (deg, True)):
        q = euler.quat_from_euler(seq, angles, degrees=degrees)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            got = euler.euler_from_quat(seq, q)  # radians out, element-wise
        assert [w.category for w in caught] == [GimbalLockWarning]
        assert (got[:, 2] == 0.0).all(), got[got[:, 2] != 0]
        mids = np.radians(angles[:, 1]) if degrees else angles[:, 1]
        np.testing.assert_allclose(got[:, 1], mids, rtol=0, atol=4.5e-16)  # 2 ulp
        with mp.workdps(DPS):
            for g, row in zip(got, angles, strict=True):
                a, mid, c = [mp.radians(mp.mpf(v)) if degrees else mp.mpf(v) for v in row]
                err = mp_angle_error([g[0]], [combined_angle(seq, a, c, float(mid))])
                assert err.max() <= TOL64, (seq, row, g)
        # The closed form is the same rotation (scipy, an independent reference).
        comb = np.array([combined_angle(seq, r[0], r[2], r[1]) for r in angles])
        alt = np.stack([comb, angles[:, 1], np.zeros(len(angles))], axis=-1)
        S1 = SciRot.from_euler(seq, angles, degrees=degrees)
        S2 = SciRot.from_euler(seq, alt, degrees=degrees)
        assert (S1.inv() * S2).magnitude().max() <= TOL64
        # Other paths: the numba loop, one element, degrees out.
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", GimbalLockWarning)
            big = euler.euler_from_quat(seq, np.tile(q, (40, 1)))
            np.testing.assert_array_equal(big[: len(q), 2], 0.0)
            assert np.abs(wrap(big[: len(q)] - got)).max() <= TOL64
            one = rk.Rotation.from_euler(seq, angles[0], degrees=degrees)
            back = one.as_euler(seq, degrees=degrees)
            assert back[2] == 0.0
            in_deg = euler.euler_from_quat(seq, q, degrees=True)
            assert (in_deg[:, 2] == 0.0).all()
            np.testing.assert_allclose(in_deg, np.degrees(got), rtol=1e-15, atol=1e-13)
    # The rebuilt rotation: within LOCK64 of the quaternion plus rounding.
    for g, qq in zip(got[::5], q[::5], strict=True):
        assert mp_rebuild_error(seq, g, qq) <= TOL64


def test_numerical_lock_examples():
    """The examples of the issue: yaw 30, pitch 90, roll 10 (degrees) is yaw 20."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        got = rk.Rotation.from_euler("ZYX", [0.5, math.pi / 2, 0.0]).as_euler("ZYX")
        np.testing.assert_allclose(got, [0.5, math.pi / 2, 0.0], rtol=0, atol=TOL64)
        assert got[2] == 0.0
        R = rk.Rotation.from_euler("ZYX", [30, 90, 10], degrees=True)
        got = R.as_euler("ZYX", degrees=True)
        np.testing.assert_allclose(got, [20.0, 90.0, 0.0], rtol=0, atol=1e-13)
        assert got[2] == 0.0
        got = R.as_euler("xyz", degrees=True)  # the same rotation, extrinsic reversed
        assert got[2] == 0.0


@pytest.mark.parametrize("seq", SEQS)
def test_lock_tolerance_is_the_cost_of_the_nearest_lock_decomposition(seq):
    """The lock convention is returned iff it moves the rotation by at most ``tol``,
    and then it is the nearest such decomposition.

    A middle angle ``d`` from the lock and a third angle ``t0``: the nearest rotation
    with third angle 0 is ``2 asin(sin(d/2) h)`` away, ``h = |sin t0|`` for
    ``|t0| <= pi/2`` (project ``z_s`` on its ray), else 1 (``z_s`` to 0). With
    ``tol = 1e-10`` (far above rounding) we build rotations at ``f * tol`` and
    measure the rebuild error of the returned angles with mpmath.
    """
    tol = 1e-10
    params = (*euler.parse_sequence(seq).params, 1.0, tol)
    lo, hi = (mp.mpf(0), mp.pi) if is_proper(seq) else (-mp.pi / 2, mp.pi / 2)
    for t0 in ("0.7", "-1.2", "2.5", "-3.0"):
        with mp.workdps(DPS):
            t0 = mp.mpf(t0)
            h = abs(mp.sin(t0)) if abs(t0) <= mp.pi / 2 else 1
        for f in (0.5, 0.9, 1.1, 2.0):
            for lock, sign in ((lo, 1), (hi, -1)):
                with mp.workdps(DPS):
                    d = 2 * mp.asin(mp.sin(f * tol / 2) / h)
                    angles = [mp.mpf("0.4"), lock + sign * d, t0]
                    q = float_quat(mp_quat_from_euler(seq, angles))
                g = np.array(kernels.euler_from_quat.python(*params, *q))
                rebuild = mp_rebuild_error(seq, g, q)
                if f < 1:
                    assert g[2] == 0.0, (seq, float(t0), f)
                    # The cost predicted, to rounding (q and the angles: 2e-16).
                    assert abs(rebuild - f * tol) <= 1e-15 * f, (seq, float(t0), f)
                else:
                    assert g[2] != 0.0
                    assert rebuild <= TOL64
                    exact = mp_exact_angles(seq, g, q)
                    assert mp_angle_error(g, exact).max() <= TOL64


def test_lock_tolerance():
    assert euler.lock_tolerance(np.float64) == LOCK64
    assert euler.lock_tolerance(np.float32) == LOCK32


def test_lock_tolerance_of_torch_dtypes(torch):
    assert euler.lock_tolerance(torch.float32) == LOCK32


@pytest.mark.parametrize("seq", ["ZYX", "xzx", "YXZ", "zyz"])
def test_float32_numerical_lock(seq, rng):
    """float32 quaternions carry float32 rounding: cleaned within 2 eps of float32."""
    rad, _ = lock_angle_cases(seq, rng)
    a32 = rad.astype(np.float32)
    for n in (1, 40):  # element-wise (float32 arithmetic) and the numba loop
        q32 = euler.quat_from_euler(seq, np.tile(a32, (n, 1)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", GimbalLockWarning)
            got = euler.euler_from_quat(seq, q32)
        assert got.dtype == np.float32
        assert (got[:, 2] == 0.0).all()
        comb = [combined_angle(seq, float(r[0]), float(r[2]), float(r[1])) for r in a32]
        assert np.abs(wrap(got[: len(a32), 0] - comb)).max() <= TOL32
        np.testing.assert_allclose(got[:, 1], np.tile(a32[:, 1], n), atol=TOL32)


def test_gimbal_lock_threshold():
    """Warn within sqrt(eps) = 1.5e-8 rad of the lock, not outside."""
    assert euler.gimbal_lock_threshold(np.float64) == pytest.approx(1.49e-8, rel=1e-2)
    for d, warns in ((1e-6, False), (2e-8, False), (1e-8, True), (1e-9, True)):
        q = rk.Rotation.from_euler("ZYX", [0.3, math.pi / 2 - d, 0.2])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            q.as_euler("ZYX")
        assert bool(caught) == warns, d


def test_no_warning_for_nan_or_ordinary_batches(rng):
    R = rk.Rotation.random(2000, rng)
    with warnings.catch_warnings():
        warnings.simplefilter("error", GimbalLockWarning)
        R.as_euler("zxz")
        euler.euler_from_quat_unchecked("XYZ", np.full((3, 4), np.nan))
        euler.euler_from_quat_unchecked("XYZ", np.full(4, np.nan))


def test_public_euler_from_quat_validates():
    """The public functional checks its quaternions (NaN, inf, zero), naming the
    batch index, like every public conversion; the unchecked one passes NaN on."""
    q = np.tile([1.0, 0.0, 0.0, 0.0], (3, 1))
    q[2, 1] = np.nan
    with pytest.raises(rk.NonFiniteError) as err:
        euler.euler_from_quat("XYZ", q)
    assert err.value.index == (2,)
    assert np.isnan(euler.euler_from_quat_unchecked("XYZ", q)[2]).all()
    q[2] = 0.0
    with pytest.raises(rk.ZeroNormError) as err:
        euler.euler_from_quat("zxz", q)
    assert err.value.index == (2,)
    # Any finite nonzero scale names a rotation: the angles of the unit quaternion.
    q1 = rk.Rotation.from_rotvec([0.3, -0.2, 0.1]).as_quat()
    np.testing.assert_allclose(
        euler.euler_from_quat("ZYX", 1e-3 * q1),
        euler.euler_from_quat_unchecked("ZYX", q1),
        rtol=0,
        atol=1e-15,
    )


@pytest.mark.parametrize("how", ["rotation", "functional", "matrix"])
def test_warning_points_at_the_caller(how):
    q = np.array([math.sqrt(0.5), 0.0, math.sqrt(0.5), 0.0])  # pitch 90 degrees
    with pytest.warns(GimbalLockWarning) as record:
        if how == "rotation":
            rk.Rotation.from_quat(q).as_euler("ZYX")
        elif how == "functional":
            euler.euler_from_quat("ZYX", q)
        else:
            euler.euler_from_matrix("ZYX", rk.Rotation.from_quat(q).as_matrix())
    assert len(record) == 1
    assert record[0].filename == __file__


# -- round trips (hypothesis) ----------------------------------------------------------
angle = st.floats(-math.pi, math.pi, allow_nan=False)


@settings(max_examples=150, deadline=None)
@given(
    seq=st.sampled_from(SEQS),
    a=angle,
    b=st.floats(0.0, 1.0, allow_nan=False),
    c=angle,
)
def test_round_trip_angles(seq, a, b, c):
    """Canonical angles come back, within 1e-15 divided by the conditioning."""
    lo, hi = lock_values(seq)
    mid = lo + b * (hi - lo)
    angles = np.array([a, mid, c])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        back = rk.Rotation.from_euler(seq, angles).as_euler(seq)
        dist = lock_distance(seq, mid)
        # First/third move by ~eps / sin(dist); the middle by a few ulp.
        if dist > 1e-6:
            tol = 2 * TOL64 / math.sin(min(dist, 1.0))
            assert np.abs(wrap(back - angles)).max() <= tol, back
        assert abs(back[1] - mid) <= 2 * TOL64
        q = euler.quat_from_euler(seq, angles)
        assert quat_angle(euler.quat_from_euler(seq, back), q) <= 2 * TOL64


quat_component = st.one_of(
    st.floats(-1.0, 1.0, allow_nan=False), st.sampled_from([0.0, -0.0, 0.5, -0.5])
)


@settings(max_examples=150, deadline=None)
@given(seq=st.sampled_from(SEQS), comps=st.lists(quat_component, min_size=4, max_size=4))
def test_round_trip_quaternions(seq, comps):
    """Any rotation (exact zeros and locks included) is rebuilt to 1e-15 rad."""
    q = np.array(comps)
    if np.linalg.norm(q) < 1e-3:
        q[0] = 1.0
    R = rk.Rotation.from_quat(q)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        got = R.as_euler(seq)
    assert mp_rebuild_error(seq, got, R.as_quat()) <= TOL64
    assert_in_ranges(seq, got)


def assert_in_ranges(seq, angles, half_turn=math.pi):
    angles = np.asarray(angles, dtype=np.float64)
    for k in (0, 2):
        assert (angles[..., k] > -half_turn).all() and (angles[..., k] <= half_turn).all()
    mid = angles[..., 1]
    if is_proper(seq):
        assert (mid >= 0).all() and (mid <= half_turn).all()
    else:
        assert (np.abs(mid) <= half_turn / 2).all()


@pytest.mark.parametrize("seq", ["ZYX", "zxz", "XZX", "yxz"])
def test_ranges_with_signed_zeros(seq):
    """-0.0 components must not produce -pi (the range is (-pi, pi])."""
    q = np.array(
        [
            [0.0, -0.0, -0.0, -1.0],
            [0.0, -1.0, -0.0, -0.0],
            [-0.0, 0.0, -1.0, 0.0],
            [-1.0, -0.0, -0.0, -0.0],
            [0.0, -0.0, 1.0, -0.0],
        ]
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        got = euler.euler_from_quat(seq, q)
        deg = euler.euler_from_quat(seq, q, degrees=True)
    assert_in_ranges(seq, got)
    assert_in_ranges(seq, deg, half_turn=180.0)
    for g, qq in zip(got, q, strict=True):
        assert mp_rebuild_error(seq, g, qq) <= TOL64


# -- degrees, dtypes, batches, backends -----------------------------------------------
@pytest.mark.parametrize("seq", ["ZYX", "xzx"])
def test_degrees(seq, rng):
    deg = np.degrees(random_angles(seq, rng, 30))
    q_deg = euler.quat_from_euler(seq, deg, degrees=True)
    q_rad = euler.quat_from_euler(seq, np.radians(deg))
    assert quat_angle(q_deg, q_rad).max() <= TOL64
    back = euler.euler_from_quat(seq, q_deg, degrees=True)
    np.testing.assert_allclose(
        back, np.degrees(euler.euler_from_quat(seq, q_deg)), rtol=1e-15
    )
    np.testing.assert_allclose(wrap(np.radians(back - deg)), 0.0, atol=1e-12)
    ints = rk.Rotation.from_euler(seq, [90, 45, 0], degrees=True).as_euler(
        seq, degrees=True
    )
    np.testing.assert_allclose(ints, [90.0, 45.0, 0.0], atol=1e-12)


@pytest.mark.parametrize("n", [40, 3000])  # NumPy element-wise and the numba loop
@pytest.mark.parametrize("seq", SEQS)
def test_float32(seq, n, rng):
    a32 = random_angles(seq, rng, n, np.float32)
    a32[:8, 1] = lock_values(seq)[0] + np.float32(1e-3) * (1 if is_proper(seq) else -1)
    q32 = euler.quat_from_euler(seq, a32)
    assert q32.dtype == np.float32
    exact = SciRot.from_euler(seq, a32.astype(np.float64)).as_quat(scalar_first=True)
    assert quat_angle(q32, exact).max() <= TOL32
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GimbalLockWarning)
        back = euler.euler_from_quat(seq, q32)
    assert back.dtype == np.float32
    q64 = q32.astype(np.float64)
    q64 /= np.linalg.norm(q64, axis=-1, keepdims=True)
    rebuilt = euler.quat_from_euler(seq, back.astype(np.float64))
    assert quat_angle(rebuilt, q64).max() <= TOL32
    ref = euler.euler_from_quat(seq, q64)
    well = lock_distance(seq, ref[:, 1]) > 0.5  # condition number <= 2
    assert np.abs(wrap(back - ref))[well].max() <= TOL32


def test_batch_shapes(rng):
    a = rng.uniform(-1, 1, (2, 3, 5, 3))
    q = euler.quat_from_euler("ZXZ", a)
    assert q.shape == (2, 3, 5, 4)
    np.testing.assert_allclose(q[1, 2, 3], euler.quat_from_euler("ZXZ", a[1, 2, 3]))
    R = rk.Rotation.from_euler("yzx", a)
    assert R.shape == (2, 3, 5)
    assert R.as_euler("XYX").shape == (2, 3, 5, 3)
    empty = rk.Rotation.from_euler("XYZ", np.zeros((0, 3)))
    assert empty.shape == (0,)
    with warnings.catch_warnings():
        warnings.simplefilter("error", GimbalLockWarning)
        assert empty.as_euler("XYZ").shape == (0, 3)
        assert euler.euler_from_quat("zyz", np.zeros((4, 0, 4))).shape == (4, 0, 3)
    one = rk.Rotation.from_euler("ZYX", [0.1, 0.2, 0.3])
    assert one.shape == () and one.as_euler("ZYX").shape == (3,)
    np.testing.assert_allclose(one.as_euler("ZYX"), [0.1, 0.2, 0.3], atol=TOL64)


def test_torch_gradients_through_from_euler_and_apply():
    torch = pytest.importorskip("torch")
    a0 = np.array([[0.3, -0.6, 2.0], [1.1, 0.4, -0.2]])
    v = torch.tensor([[0.5, -1.0, 2.0], [1.5, 0.2, -0.3]], dtype=torch.float64)
    w = torch.tensor([[1.0, 2.0, -0.5], [0.3, -0.7, 1.2]], dtype=torch.float64)

    def loss(angles):
        return (rk.Rotation.from_euler("ZYX", angles).apply(v) * w).sum()

    a = torch.tensor(a0, requires_grad=True)
    value = loss(a)
    assert isinstance(value, torch.Tensor)
    (grad,) = torch.autograd.grad(value, a)
    h = 1e-6
    fd = np.zeros_like(a0)
    for idx in np.ndindex(a0.shape):
        ap, am = a0.copy(), a0.copy()
        ap[idx] += h
        am[idx] -= h
        fd[idx] = (float(loss(torch.tensor(ap))) - float(loss(torch.tensor(am)))) / (2 * h)
    np.testing.assert_allclose(grad.numpy(), fd, rtol=1e-7, atol=1e-8)
    # Values agree with NumPy; as_euler keeps torch and float32.
    R = rk.Rotation.from_euler("ZYX", torch.tensor(a0))
    np.testing.assert_allclose(R.as_matrix().numpy(), euler.matrix_from_euler("ZYX", a0))
    back = R.as_euler("ZYX")
    assert isinstance(back, torch.Tensor)
    np.testing.assert_allclose(back.numpy(), a0, atol=TOL64)
    a32 = torch.tensor(a0, dtype=torch.float32)
    assert rk.Rotation.from_euler("zxz", a32).as_euler("zxz").dtype == torch.float32


def test_torch_gimbal_lock_warning():
    torch = pytest.importorskip("torch")
    q = torch.tensor([[math.sqrt(0.5), 0.0, math.sqrt(0.5), 0.0], [1.0, 0.0, 0.0, 0.0]])
    with pytest.warns(GimbalLockWarning, match="1 of 2"):
        got = euler.euler_from_quat("ZYX", q)
    assert isinstance(got, torch.Tensor) and got.dtype == torch.float32
    np.testing.assert_allclose(got.numpy()[0], [0.0, math.pi / 2, 0.0], atol=1e-7)


# -- one kernel, every binding -------------------------------------------------------
@pytest.mark.parametrize("seq", SEQS)
def test_bindings_agree(seq, rng):
    """numba loop, element-wise (NumPy, torch, array-api-strict) and Python floats."""
    params = (*euler.parse_sequence(seq).params, 1.0)
    inv_params = (*params, LOCK64)
    a = np.concatenate([random_angles(seq, rng, 1500), [[0.0, lock_values(seq)[1], 0.0]]])
    q = kernels.quat_from_euler(*params, a, backend="numba")
    np.testing.assert_allclose(
        kernels.quat_from_euler(*params, a, backend="xp"), q, atol=TOL64
    )
    numerical_lock = euler.quat_from_euler(seq, lock_angle_cases(seq, rng)[0][:6])
    qs = np.concatenate([q, exact_lock_quats(seq, [0.5, -3.0]), numerical_lock])
    e = kernels.euler_from_quat(*inv_params, qs, backend="numba")
    assert (e[-6:, 2] == 0.0).all()
    e_xp = kernels.euler_from_quat(*inv_params, qs, backend="xp")
    assert np.abs(wrap(e_xp - e)).max() <= TOL64
    if seq in ("ZYX", "xzy", "YXY", "zxz"):  # other array namespaces, both parities
        # torch where installed (its binding is also checked, or visibly skipped, in
        # test_engine); a skip here would drop the Python-float checks below.
        import array_api_strict as xps

        torch = optional("torch")
        for ns in (xps.asarray,) + ((torch.asarray,) if torch is not None else ()):
            q_ns = np.asarray(kernels.quat_from_euler(*params, ns(a)))
            np.testing.assert_allclose(q_ns, q, rtol=0, atol=TOL64)
            e_ns = np.asarray(kernels.euler_from_quat(*inv_params, ns(qs)))
            assert np.abs(wrap(e_ns - e)).max() <= TOL64
    for i in (0, 1, len(a) - 1):
        one = np.array(kernels.quat_from_euler.python(*params, *a[i]))
        np.testing.assert_allclose(one, q[i], rtol=0, atol=TOL64)
    for i in (0, 1, len(a) - 1, len(a) + 1, len(qs) - 2, len(qs) - 1):
        one = np.array(kernels.euler_from_quat.python(*inv_params, *qs[i]))
        assert np.abs(wrap(one - e[i])).max() <= TOL64


@pytest.mark.parametrize("seq", ["XYZ", "xyz", "ZXZ", "yzy"])
def test_sympy_binding(seq):
    """The SymPy twin: exactly the product of the three axis quaternions."""
    sp = pytest.importorskip("sympy")
    params = (*euler.parse_sequence(seq).params, sp.Integer(1))
    t = sp.symbols("t0:3", real=True)
    q_expr = kernels.quat_from_euler.sympy(*params, *t)

    def axis_quat(ch, angle):
        q = [sp.cos(angle / 2), 0, 0, 0]
        q[1 + "xyz".index(ch)] = sp.sin(angle / 2)
        return q

    f = [axis_quat(ch, angle) for ch, angle in zip(seq.lower(), t, strict=True)]
    if seq.isupper():
        ref = hamilton(hamilton(f[0], f[1]), f[2])
    else:
        ref = hamilton(hamilton(f[2], f[1]), f[0])
    for got, want in zip(q_expr, ref, strict=True):
        assert sp.expand(got - want) == 0
    # The inverse over SymPy numbers (its lock branches make symbols unwieldy).
    angles = (0.3, 1.1, -2.0)
    qv = euler.quat_from_euler(seq, angles)
    back = kernels.euler_from_quat.sympy(
        *params, LOCK64, *[sp.Float(float(c), 30) for c in qv]
    )
    np.testing.assert_allclose([float(e) for e in back], angles, atol=TOL64)


# -- bad input -------------------------------------------------------------------------
BAD_SEQS = [
    "XXY",
    "xYz",
    "abc",
    "XYZX",
    "",
    "xx",  # one or two letters are from_euler sequences (scipy's), but not repeats
    "xxz",
    "zyy",
    "XyZ",
    "x y",
    123,
    None,
    b"XYZ",
]


@pytest.mark.parametrize("seq", BAD_SEQS)
def test_bad_sequences(seq):
    for call in (
        lambda: rk.Rotation.from_euler(seq, [0.1, 0.2, 0.3]),
        lambda: rk.Rotation.identity().as_euler(seq),
        lambda: euler.parse_sequence(seq),
    ):
        with pytest.raises(EulerSequenceError) as info:
            call()
        assert isinstance(info.value, ValueError)
        message = str(info.value)
        assert "UPPERCASE (intrinsic" in message and "lowercase (extrinsic" in message


@pytest.mark.parametrize("shape", [(), (2,), (4,), (3, 2), (5, 1)])
def test_bad_angle_shapes(shape):
    with pytest.raises(ShapeError, match=r"\(\.\.\., 3\)"):
        rk.Rotation.from_euler("ZYX", np.zeros(shape))


def test_non_finite_angles():
    a = np.zeros((3, 3))
    a[1, 2] = np.nan
    with pytest.raises(NonFiniteError, match=r"batch index \(1,\)"):
        rk.Rotation.from_euler("ZYX", a)
    with pytest.raises(NonFiniteError):
        euler.quat_from_euler("zxz", [0.0, np.inf, 0.0])


def test_parse_sequence():
    s = euler.parse_sequence("ZYX")
    assert (s.axes, s.intrinsic, s.proper) == ((2, 1, 0), True, False)
    s = euler.parse_sequence("xzx")
    assert (s.axes, s.intrinsic, s.proper) == ((0, 2, 0), False, True)
    assert euler.parse_sequence("ZYX") is euler.parse_sequence("ZYX")
