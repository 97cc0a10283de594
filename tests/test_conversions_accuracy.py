"""Accuracy of the SO(3) conversions against a 50-digit mpmath reference.

Every input is a float array; the reference is computed from the exact values of
those floats at 50 digits, so the measured error is the conversion's own.

Bands: angles ``theta`` log-uniform in [1e-12, 1e-4] ("small") and
``pi - theta`` for such ``theta`` ("near pi"), with the band edges included;
quaternions with ``w`` near and at 0; quaternions scaled by 1e-300 ... 1e300;
matrices perturbed by 1e-10 away from SO(3).

Measures (all must be <= 1e-15 in float64 and <= 5e-7 in float32):

* vectors (rotation vector, MRP, angle): ``|x - x_ref| / |x_ref|``;
* rotations (quaternion, matrix): the angle of the rotation between result and
  reference, divided by ``min(1, theta_ref)`` (relative for small angles,
  absolute in radians otherwise), and, separately, the absolute error of the
  components (``max |q - q_ref|`` up to sign, ``max |R - R_ref|``), which also
  bounds how far the result is from unit norm / orthogonality;
* unit axes: ``|axis - axis_ref|``.

The matrix inputs are float roundings of rotations, so slightly off SO(3); their
reference is the rotation nearest them (the orthogonal polar factor, by Newton's
iteration at 50 digits), which is what ``from_matrix`` promises.

Each conversion runs on both NumPy bindings: the numba loop and the element-wise
NumPy evaluation (forced by fixtures); the single-element Python path runs the
same formula and is compared to these in ``test_engine.py``.

Measured maxima (both bindings; ``pytest -s`` prints the table from
``test_report_table``): float64 conversions <= 5.4e-16 (so3.exp near pi; most
below 3e-16), coefficient sweeps <= 8e-16 (cot_defect2 near its pole at 2 pi,
otherwise <= 4.2e-16); float32 <= 2.9e-7.
"""

from __future__ import annotations

import importlib
import math

import mpmath as mp
import numpy as np
import pytest

import rigidkit as rk
from rigidkit import conversions as C
from rigidkit import so3
from rigidkit._engine import numba_backend

# The module (the package re-exports the decorator under the same name).
kernel_module = importlib.import_module("rigidkit._engine.kernel")

DPS = 50
TOL = {np.float64: 1e-15, np.float32: 5e-7}
N = 120  # elements per band (mpmath is ~0.1 ms per reference value)


# -- 50-digit reference ----------------------------------------------------------------
def _mp(x):
    return [mp.mpf(float(c)) for c in np.ravel(x)]


def _norm(v):
    return mp.sqrt(mp.fsum(c * c for c in v))


def mp_quat_from_rotvec(r):
    theta = _norm(r)
    s = mp.sin(theta / 2) / theta if theta else mp.mpf("0.5")
    return [mp.cos(theta / 2)] + [s * c for c in r]


def mp_quat_normalize(q):
    n = _norm(q)
    return [c / n for c in q]


def mp_matrix_from_quat(q):
    w, x, y, z = mp_quat_normalize(q)
    return mp.matrix(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def mp_polar(m):
    """Orthogonal polar factor (nearest rotation) of a nearly orthogonal matrix.

    Newton-Schulz, ``X <- X (3 I - X^T X) / 2``, converges quadratically from
    here; iterate until ``|X^T X - I| < 1e-45``.
    """
    x = mp.matrix(m) if not isinstance(m, mp.matrix) else m
    eye = mp.eye(3)
    for _ in range(60):
        d = x.T * x - eye
        if mp.mnorm(d, 1) < mp.mpf("1e-45"):
            return x
        x = x * (3 * eye - x.T * x) / 2
    raise AssertionError("Newton-Schulz did not converge")


def mp_quat_from_rotation(r):
    """Quaternion (w >= 0) of an exact rotation matrix, from its largest entry."""
    t = [1 + r[0, 0] + r[1, 1] + r[2, 2]]
    t += [1 + 2 * r[i, i] - (r[0, 0] + r[1, 1] + r[2, 2]) for i in range(3)]
    k = max(range(4), key=lambda i: t[i])
    if k == 0:
        q = [t[0], r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]
    elif k == 1:
        q = [r[2, 1] - r[1, 2], t[1], r[0, 1] + r[1, 0], r[0, 2] + r[2, 0]]
    elif k == 2:
        q = [r[0, 2] - r[2, 0], r[0, 1] + r[1, 0], t[2], r[1, 2] + r[2, 1]]
    else:
        q = [r[1, 0] - r[0, 1], r[0, 2] + r[2, 0], r[1, 2] + r[2, 1], t[3]]
    q = mp_quat_normalize(q)
    return [-c for c in q] if q[0] < 0 else q


def mp_rotvec_from_quat(q):
    w, x, y, z = mp_quat_normalize(q)
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    n = _norm([x, y, z])
    if n == 0:
        return [mp.mpf(0)] * 3
    k = 2 * mp.atan2(n, w) / n
    return [k * x, k * y, k * z]


def mp_mrp_from_quat(q):
    w, x, y, z = mp_quat_normalize(q)
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    return [x / (1 + w), y / (1 + w), z / (1 + w)]


def mp_quat_from_mrp(p):
    p2 = mp.fsum(c * c for c in p)
    return [(1 - p2) / (1 + p2)] + [2 * c / (1 + p2) for c in p]


def mp_axis_angle_from_quat(q):
    w, x, y, z = mp_quat_normalize(q)
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    n = _norm([x, y, z])
    return [x / n, y / n, z / n], 2 * mp.atan2(n, w)


def mp_quat_from_axis_angle(axis, angle):
    a = [c / _norm(axis) for c in axis]
    return [mp.cos(angle / 2)] + [mp.sin(angle / 2) * c for c in a]


def mp_angle_of_quat(q):
    w, x, y, z = mp_quat_normalize(q)
    return 2 * mp.atan2(_norm([x, y, z]), abs(w))


# -- error measures --------------------------------------------------------------------
def vec_err(got, ref, alt=None):
    """|x - x_ref| / |x_ref| at 50 digits; with ``alt``, to the nearer of the two."""
    g = got if isinstance(got, list) else [mp.mpf(float(c)) for c in np.ravel(got)]
    err = _norm([a - b for a, b in zip(g, ref, strict=True)])
    if alt is not None:
        err = min(err, _norm([a - b for a, b in zip(g, alt, strict=True)]))
    return float(err / _norm(ref))


def rotvec_err(got, ref, theta=None):
    """Relative error of a rotation vector, to the nearer representative.

    ``theta a`` and ``(theta - 2 pi) a`` are the same rotation; log returns the one
    with angle <= pi, but within rounding of pi (float32 near pi) either is right
    and the sign of the axis is decided by rounding. Away from pi the other
    representative is ~2 pi away and changes nothing.
    """
    t = _norm(ref)
    return vec_err(got, ref, [c * (1 - 2 * mp.pi / t) for c in ref])


def mrp_err(got, ref, theta=None):
    """Relative error of MRPs, to the nearer of ``p`` and its shadow ``-p / |p|^2``."""
    p2 = mp.fsum(c * c for c in ref)
    return vec_err(got, ref, [-c / p2 for c in ref])


def quat_err(got, ref, theta):
    """(angle between rotations / min(1, theta), max component error up to sign)."""
    g = _mp(got)
    rw, rx, ry, rz = ref
    w, x, y, z = g
    # ref* (x) got
    dw = rw * w + rx * x + ry * y + rz * z
    dv = [rw * x - rx * w - ry * z + rz * y, rw * y + rx * z - ry * w - rz * x]
    dv.append(rw * z - rx * y + ry * x - rz * w)
    angle = 2 * mp.atan2(_norm(dv), abs(dw))
    sign = 1 if dw >= 0 else -1
    comp = max(abs(sign * gi - ri) for gi, ri in zip(g, ref, strict=True))
    return float(angle / min(1, theta)), float(comp)


def matrix_err(got, ref, theta):
    """(angle of ref^T got / min(1, theta), max |got - ref|)."""
    g = mp.matrix([[mp.mpf(float(got[i, j])) for j in range(3)] for i in range(3)])
    d = ref.T * g
    # The rotation part of ref^T got is I + hat(e) to first order: e = vee(skew).
    e = [(d[2, 1] - d[1, 2]) / 2, (d[0, 2] - d[2, 0]) / 2, (d[1, 0] - d[0, 1]) / 2]
    comp = max(abs(g[i, j] - ref[i, j]) for i in range(3) for j in range(3))
    return float(_norm(e) / min(1, theta)), float(comp)


# -- inputs ----------------------------------------------------------------------------
def _axes(rng, n):
    v = rng.standard_normal((n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def band_angles(band, rng, n=N):
    """Angles of a band, float64, with its edges."""
    e = np.concatenate([[1e-12, 1e-4], 10.0 ** rng.uniform(-12, -4, n - 2)])
    if band == "small":
        return e
    if band == "near_pi":
        return math.pi - e
    if band == "uniform":
        return np.concatenate([[1e-4, math.pi - 1e-4], rng.uniform(1e-4, math.pi, n - 2)])
    raise ValueError(band)


def band_rotations(band, rng, dtype):
    """(angles, axes) of a band and the exact (mp) quaternion of each rotation."""
    theta = band_angles(band, rng)
    axes = _axes(rng, len(theta))
    rotvec = (axes * theta[:, None]).astype(dtype)
    return rotvec, [mp_quat_from_rotvec(_mp(r)) for r in rotvec]


def _round(x, dtype):
    return np.array([float(c) for c in x], dtype=dtype)


def _round_matrix(m, dtype):
    return np.array([[float(m[i, j]) for j in range(3)] for i in range(3)], dtype=dtype)


@pytest.fixture(autouse=True)
def _mp_precision():
    with mp.workdps(DPS):
        yield


# -- binding fixtures ------------------------------------------------------------------
@pytest.fixture(params=["numba", "xp"])
def binding(request, monkeypatch):
    """Force every kernel call with more than one element onto one NumPy binding.

    The numba loops run are counted, to check that the binding asked for is used.
    """
    runs = []
    run_loop = numba_backend.run_loop

    def counting(*args, **kwargs):
        runs.append(1)
        return run_loop(*args, **kwargs)

    monkeypatch.setattr(numba_backend, "run_loop", counting)
    monkeypatch.setattr(kernel_module, "BINDING", request.param)
    yield request.param
    assert bool(runs) == (request.param == "numba"), f"{request.param}: {len(runs)} loops"


DTYPES = pytest.mark.parametrize("dtype", [np.float64, np.float32], ids=["f64", "f32"])
BANDS = pytest.mark.parametrize("band", ["small", "near_pi", "uniform"])

#: Worst errors seen, printed by test_report_table (pytest -s).
MEASURED: dict[tuple, float] = {}


def _record(key, errs, tol):
    worst = float(np.max(errs))
    MEASURED[key] = max(MEASURED.get(key, 0.0), worst)
    assert worst <= tol, f"{key}: worst error {worst:.3g} > {tol:g}"


def _check(name, band, dtype, got, refs, measure, thetas):
    """Record and check ``measure(got[i], refs[i], theta[i])`` over a batch."""
    assert got.dtype == dtype, f"{name}: dtype {got.dtype}, input {np.dtype(dtype)}"
    tol = TOL[dtype]
    errs = [measure(g, r, t) for g, r, t in zip(got, refs, thetas, strict=True)]
    errs = np.atleast_2d(np.array(errs, dtype=np.float64).T)
    labels = ["angle", "components"] if errs.shape[0] == 2 else ["rel"]
    for lab, e in zip(labels, errs, strict=True):
        _record((name, band, np.dtype(dtype).name, lab), e, tol)


# -- the conversions on the angle bands ------------------------------------------------
@BANDS
@DTYPES
def test_quat_from_rotvec(band, dtype, binding, rng):
    rotvec, refs = band_rotations(band, rng, dtype)
    theta = [float(mp_angle_of_quat(q)) for q in refs]
    got = C.quat_from_rotvec(rotvec)
    _check("rotvec->quat", band, dtype, got, refs, quat_err, theta)
    # Rotation.from_rotvec stores the same quaternion.
    got = rk.Rotation.from_rotvec(rotvec).as_quat()
    _check("rotvec->quat", band, dtype, got, refs, quat_err, theta)


@BANDS
@DTYPES
def test_rotvec_from_quat(band, dtype, binding, rng):
    _, exact = band_rotations(band, rng, np.float64)
    q = np.array([_round(e, dtype) for e in exact])
    refs = [mp_rotvec_from_quat(_mp(qi)) for qi in q]
    theta = [None] * len(q)
    got = C.rotvec_from_quat(q)
    _check("quat->rotvec", band, dtype, got, refs, rotvec_err, theta)
    got = rk.Rotation.from_quat(q).as_rotvec()
    _check("quat->rotvec", band, dtype, got, refs, rotvec_err, theta)


@BANDS
@DTYPES
def test_matrix_from_quat(band, dtype, binding, rng):
    _, exact = band_rotations(band, rng, np.float64)
    q = np.array([_round(e, dtype) for e in exact])
    refs = [mp_matrix_from_quat(_mp(qi)) for qi in q]
    theta = [float(mp_angle_of_quat(_mp(qi))) for qi in q]
    got = C.matrix_from_quat(q)
    _check("quat->matrix", band, dtype, got, refs, matrix_err, theta)


@BANDS
@DTYPES
def test_quat_from_matrix(band, dtype, binding, rng):
    _, exact = band_rotations(band, rng, np.float64)
    m = np.array([_round_matrix(mp_matrix_from_quat(e), dtype) for e in exact])
    refs = [mp_quat_from_rotation(mp_polar(_mp_matrix(mi))) for mi in m]
    theta = [float(mp_angle_of_quat(r)) for r in refs]
    got = C.quat_from_matrix(m)
    _check("matrix->quat", band, dtype, got, refs, quat_err, theta)
    got = rk.Rotation.from_matrix(m).as_quat()
    _check("matrix->quat", band, dtype, got, refs, quat_err, theta)


def _mp_matrix(m):
    return mp.matrix([[mp.mpf(float(m[i, j])) for j in range(3)] for i in range(3)])


@BANDS
@DTYPES
def test_so3_exp(band, dtype, binding, rng):
    rotvec, refs = band_rotations(band, rng, dtype)
    mats = [mp_matrix_from_quat(q) for q in refs]
    theta = [float(mp_angle_of_quat(q)) for q in refs]
    got = so3.exp(rotvec)
    _check("rotvec->matrix (so3.exp)", band, dtype, got, mats, matrix_err, theta)


@BANDS
@DTYPES
def test_so3_log(band, dtype, binding, rng):
    _, exact = band_rotations(band, rng, np.float64)
    m = np.array([_round_matrix(mp_matrix_from_quat(e), dtype) for e in exact])
    refs = [
        mp_rotvec_from_quat(mp_quat_from_rotation(mp_polar(_mp_matrix(mi)))) for mi in m
    ]
    theta = [None] * len(m)
    got = so3.log(m)
    _check("matrix->rotvec (so3.log)", band, dtype, got, refs, rotvec_err, theta)
    got = rk.Rotation.from_matrix(m).as_rotvec()
    _check("matrix->rotvec (so3.log)", band, dtype, got, refs, rotvec_err, theta)


@BANDS
@DTYPES
def test_mrp_both_ways(band, dtype, binding, rng):
    _, exact = band_rotations(band, rng, np.float64)
    # quat -> mrp
    q = np.array([_round(e, dtype) for e in exact])
    refs = [mp_mrp_from_quat(_mp(qi)) for qi in q]
    got = C.mrp_from_quat(q)
    _check("quat->mrp", band, dtype, got, refs, mrp_err, [None] * len(q))
    got = rk.Rotation.from_quat(q).as_mrp()
    _check("quat->mrp", band, dtype, got, refs, mrp_err, [None] * len(q))
    # mrp -> quat, from float MRPs of the band's rotations
    p = np.array([_round(mp_mrp_from_quat(e), dtype) for e in exact])
    refs = [mp_quat_from_mrp(_mp(pi)) for pi in p]
    theta = [float(mp_angle_of_quat(r)) for r in refs]
    got = C.quat_from_mrp(p)
    _check("mrp->quat", band, dtype, got, refs, quat_err, theta)
    got = rk.Rotation.from_mrp(p).as_quat()
    _check("mrp->quat", band, dtype, got, refs, quat_err, theta)


@BANDS
@DTYPES
def test_axis_angle_both_ways(band, dtype, binding, rng):
    theta = band_angles(band, rng).astype(dtype)
    axes = (_axes(rng, len(theta)) * rng.uniform(0.5, 2.0, (len(theta), 1))).astype(dtype)
    refs = [mp_quat_from_axis_angle(_mp(a), mp.mpf(float(t))) for a, t in zip(axes, theta)]
    th = [float(t) for t in theta]
    got = C.quat_from_axis_angle(axes, theta)
    _check("axis-angle->quat", band, dtype, got, refs, quat_err, th)
    got = rk.Rotation.from_axis_angle(axes, theta).as_quat()
    _check("axis-angle->quat", band, dtype, got, refs, quat_err, th)
    # quat -> axis, angle: the angle on its own, axis * angle as a rotation vector
    # (the axis's sign is undetermined within rounding of pi), and |axis| = 1.
    q = np.array([_round(r, dtype) for r in refs])
    ref_aa = [mp_axis_angle_from_quat(_mp(qi)) for qi in q]
    axis, angle = C.axis_angle_from_quat(q)
    assert axis.dtype == dtype and angle.dtype == dtype
    rv = [[mp.mpf(float(c)) * mp.mpf(float(t)) for c in a] for a, t in zip(axis, angle)]
    rv_ref = [[c * ra[1] for c in ra[0]] for ra in ref_aa]
    errs = [rotvec_err(g, r) for g, r in zip(rv, rv_ref, strict=True)]
    key = np.dtype(dtype).name
    _record(("quat->axis*angle", band, key, "rel"), errs, TOL[dtype])
    errs = [abs(float((mp.mpf(float(g)) - ra[1]) / ra[1])) for g, ra in zip(angle, ref_aa)]
    _record(("quat->angle", band, key, "rel"), errs, TOL[dtype])
    errs = [abs(float(_norm(_mp(a)) - 1)) for a in axis]
    _record(("quat->axis", band, key, "|axis| - 1"), errs, TOL[dtype])


# -- quaternions near w = 0 ------------------------------------------------------------
W_NEAR_0 = [0.0, 5e-324, 1e-300, 1e-200, 1e-16, 1e-12, 1e-8, 1e-4]


def _near_w0(rng, dtype):
    ws = np.array([s * w for w in W_NEAR_0 for s in (1.0, -1.0)] * 4)
    v = _axes(rng, len(ws))
    exact = []
    for w, a in zip(ws, v, strict=True):
        w = mp.mpf(float(w))
        k = mp.sqrt(1 - w * w)
        exact.append([w] + [k * mp.mpf(float(c)) for c in a])
    q = np.array([_round(e, dtype) for e in exact])
    return q


@DTYPES
def test_quats_near_w0(dtype, binding, rng):
    q = _near_w0(rng, dtype)
    exact = [_mp(qi) for qi in q]
    theta = [float(mp_angle_of_quat(e)) for e in exact]
    band = "w~0"
    R = rk.Rotation.from_quat(q)
    _check(
        "quat->rotvec",
        band,
        dtype,
        R.as_rotvec(),
        [mp_rotvec_from_quat(e) for e in exact],
        rotvec_err,
        theta,
    )
    _check(
        "quat->matrix",
        band,
        dtype,
        R.as_matrix(),
        [mp_matrix_from_quat(e) for e in exact],
        matrix_err,
        theta,
    )
    _check(
        "quat->mrp",
        band,
        dtype,
        R.as_mrp(),
        [mp_mrp_from_quat(e) for e in exact],
        mrp_err,
        theta,
    )
    axis, angle = R.as_axis_angle()
    ref_aa = [mp_axis_angle_from_quat(e) for e in exact]
    errs = [abs(float((mp.mpf(float(g)) - ra[1]) / ra[1])) for g, ra in zip(angle, ref_aa)]
    _record(("quat->angle", band, np.dtype(dtype).name, "rel"), errs, TOL[dtype])
    rv = [[mp.mpf(float(c)) * mp.mpf(float(t)) for c in a] for a, t in zip(axis, angle)]
    rv_ref = [[c * ra[1] for c in ra[0]] for ra in ref_aa]
    errs = [rotvec_err(g, r) for g, r in zip(rv, rv_ref, strict=True)]
    _record(("quat->axis*angle", band, np.dtype(dtype).name, "rel"), errs, TOL[dtype])
    # And back from the matrix of such a rotation (a rotation by pi - tiny).
    m = np.array([_round_matrix(mp_matrix_from_quat(e), dtype) for e in exact])
    refs = [mp_quat_from_rotation(mp_polar(_mp_matrix(mi))) for mi in m]
    th = [float(mp_angle_of_quat(r)) for r in refs]
    _check("matrix->quat", band, dtype, C.quat_from_matrix(m), refs, quat_err, th)


# -- non-unit quaternions at any scale -------------------------------------------------
@DTYPES
def test_scaled_quaternions_normalise(dtype, binding, rng):
    """Any finite nonzero scale, 1e-300 ... 1e300 (1e-38 ... 1e38 in float32)."""
    span = 300 if dtype == np.float64 else 37
    unit = np.concatenate([np.eye(4), _axes4(rng, 60)])
    scales = np.concatenate(
        [
            10.0 ** np.array([-span, -span // 2, -10, 0, 10, span // 2, span]),
            10.0 ** rng.uniform(-span, span, len(unit) - 7),
        ]
    )
    q = (unit * scales[:, None]).astype(dtype)
    exact = [mp_quat_normalize(_mp(qi)) for qi in q]
    theta = [max(float(mp_angle_of_quat(e)), 1.0) for e in exact]  # absolute measure
    band = "scaled 1e±300" if dtype == np.float64 else "scaled 1e±37"
    _check("quat normalise", band, dtype, C.quat_normalize(q), exact, quat_err, theta)
    R = rk.Rotation.from_quat(q)
    _check("quat normalise", band, dtype, R.as_quat(), exact, quat_err, theta)
    mats = [mp_matrix_from_quat(e) for e in exact]
    _check("quat->matrix", band, dtype, R.as_matrix(), mats, matrix_err, theta)
    # scalar-last input, the same numbers
    R2 = rk.Rotation.from_quat(q[:, [1, 2, 3, 0]], scalar_first=False)
    _check("quat normalise", band, dtype, R2.as_quat(), exact, quat_err, theta)


def _axes4(rng, n):
    v = rng.standard_normal((n, 4))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


@DTYPES
def test_rotvec_from_quat_is_scale_invariant(dtype, binding, rng):
    """The raw kernel takes non-unit quaternions whose squared norm stays in range."""
    span = 100 if dtype == np.float64 else 12
    unit = _axes4(rng, 60)
    q = (unit * 10.0 ** rng.uniform(-span, span, (len(unit), 1))).astype(dtype)
    refs = [mp_rotvec_from_quat(_mp(qi)) for qi in q]
    _check(
        "quat->rotvec",
        f"scaled 1e±{span}",
        dtype,
        C.rotvec_from_quat(q),
        refs,
        rotvec_err,
        [None] * len(q),
    )


# -- nearly orthogonal matrices --------------------------------------------------------
@pytest.mark.parametrize("band", ["small", "near_pi", "uniform"])
@DTYPES
def test_nearly_orthogonal_matrices(band, dtype, binding, rng):
    """A rotation plus noise of 1e-10 (1e-5 in float32): the nearest rotation comes out.

    The Newton step in the kernel leaves ``3/8 |M^T M - I|^2`` (4e-20, 4e-11 in
    float32) of the distance to the polar factor. Measured in radians (absolute).
    """
    _, exact = band_rotations(band, rng, np.float64)
    eps = 1e-10 if dtype == np.float64 else 1e-5
    m = np.array([_round_matrix(mp_matrix_from_quat(e), np.float64) for e in exact])
    m = (m + eps * rng.standard_normal(m.shape)).astype(dtype)
    polar = [mp_polar(_mp_matrix(mi)) for mi in m]
    refs = [mp_quat_from_rotation(p) for p in polar]
    ones = [1.0] * len(m)
    label = f"perturbed {eps:g}, {band}"
    _check("matrix->quat", label, dtype, C.quat_from_matrix(m), refs, quat_err, ones)
    got = rk.Rotation.from_matrix(m).as_matrix()
    _check("matrix->matrix", label, dtype, got, polar, matrix_err, ones)
    rv = [mp_rotvec_from_quat(r) for r in refs]
    _check("matrix->rotvec (so3.log)", label, dtype, so3.log(m), rv, rotvec_err, ones)


# -- the coefficient helpers across their thresholds -----------------------------------
def _hp(x, digits_per_decade):
    """Working precision for a cancelling closed form at ``x``: 60 digits plus the loss."""
    lost = max(0, -int(math.floor(math.log10(abs(x))))) * digits_per_decade if x else 0
    return 60 + lost


def _ref_even(f, k):
    """Reference of an even coefficient with a cancellation of order x^k at 0."""

    def ref(x):
        with mp.workdps(_hp(x, k)):
            v = f(mp.mpf(x))
            return +v

    return ref


COEF_REFS = {
    # name: (reference at 50+ digits, arity)
    "sinc": (_ref_even(lambda x: mp.sin(x) / x, 2), 1),
    "versinc2": (_ref_even(lambda x: (1 - mp.cos(x)) / x**2, 2), 1),
    "sin_defect3": (_ref_even(lambda x: (x - mp.sin(x)) / x**3, 3), 1),
    "cos_defect4": (_ref_even(lambda x: (mp.cos(x) - 1 + x**2 / 2) / x**4, 4), 1),
    "cot_defect2": (_ref_even(lambda x: (1 - (x / 2) * mp.cot(x / 2)) / x**2, 2), 1),
    "sin_cos_defect5": (
        _ref_even(lambda x: (2 * x - 3 * mp.sin(x) + x * mp.cos(x)) / (2 * x**5), 5),
        1,
    ),
    "exprel": (_ref_even(lambda x: mp.expm1(x) / x, 1), 1),
    # The forms given the sine (and cosine): swept through sin_defect3 and
    # sin_cos_defect5, which pass sin(x), cos(x) to them.
    "sin_defect3_from_sin": (lambda x, s: COEF_REFS["sin_defect3"][0](x), 2),
    "sin_cos_defect5_from_sincos": (lambda x, s, c: COEF_REFS["sin_cos_defect5"][0](x), 3),
    "atan_ratio": (lambda n, w: mp.atan2(mp.mpf(n), mp.mpf(w)) / mp.mpf(n), 2),
    "norm3": (lambda x, y, z: mp.sqrt(mp.mpf(x) ** 2 + mp.mpf(y) ** 2 + mp.mpf(z) ** 2), 3),
}
#: Largest |x| where the coefficient is used (cot_defect2 has a pole at 2 pi).
COEF_DOMAIN = {"cot_defect2": 6.2}
COEF_ODD_DOMAIN = {"exprel"}  # not even: negative arguments are sampled too


def _coef_helpers():
    from rigidkit._engine.kernel import Helper
    from rigidkit.kernels import coefficients

    return {
        name: h
        for name, h in vars(coefficients).items()
        if isinstance(h, Helper) and h.fn.__module__ == coefficients.__name__
    }


def _thresholds():
    """Every threshold constant in coefficients.py: ``abs(x) < c`` and ``n < c * w``."""
    import inspect
    import re

    from rigidkit.kernels import coefficients

    src = inspect.getsource(coefficients)
    found = re.findall(r"abs\(\w+\) < ([0-9.]+)", src) + re.findall(
        r"< ([0-9.]+) \* \w+", src
    )
    return sorted({float(c) for c in found})


def test_every_coefficient_has_a_reference():
    missing = sorted(set(_coef_helpers()) - set(COEF_REFS))
    assert not missing, f"add an mpmath reference for {missing} to COEF_REFS"


def test_thresholds_found():
    # sinc and versinc2 0.03, atan_ratio 0.02, sin_defect3 2, exprel 1, ... 2.5
    assert {0.02, 0.03, 2.0} <= set(_thresholds())


def _sweep_points():
    """log-spaced 1e-20 ... 10, and each threshold t (and 2t, t/2: helpers of x/2)."""
    pts = [np.logspace(-20, 1, 421)]
    for t in _thresholds():
        for c in (t, 2 * t, t / 2):
            pts.append(c * (1 + np.array([-1e-3, -1e-8, 1e-8, 1e-3])))
            pts.append([np.nextafter(c, 0), c, np.nextafter(c, np.inf)])
    return np.unique(np.concatenate(pts))


@pytest.fixture(scope="module")
def helper_kernels(tmp_path_factory):
    """Each one-argument helper wrapped in a kernel, so the numba loop can run it.

    The wrappers are written to a real file: the engine generates the numba module
    from the kernel's source text.
    """
    import importlib.util

    names = [
        name
        for name, (_, arity) in COEF_REFS.items()
        if name in _coef_helpers() and arity == 1
    ]
    lines = [
        "from rigidkit._engine import kernel",
        f"from rigidkit.kernels.coefficients import {', '.join(names)}",
        "",
    ]
    for name in names:
        lines += [
            "",
            "@kernel(inputs=[()], outputs=[()])",
            f"def sweep_{name}(x):",
            f"    return ({name}(x),)",
            "",
        ]
    path = tmp_path_factory.mktemp("coef") / "rigidkit_coef_sweep.py"
    path.write_text("\n".join(lines))
    spec = importlib.util.spec_from_file_location("rigidkit_coef_sweep", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return {
        name[len("sweep_") :]: k
        for name, k in vars(module).items()
        if name.startswith("sweep_")
    }


@pytest.mark.parametrize("name", [n for n, (_, a) in COEF_REFS.items() if a == 1])
def test_coefficient_sweep(name, helper_kernels):
    """Relative error <= 1e-15 (4.5 ulp) on every binding, across every threshold."""
    if name not in _coef_helpers():
        pytest.skip(f"{name} is not in coefficients.py")
    ref_fn, _ = COEF_REFS[name]
    x = _sweep_points()
    x = x[x <= COEF_DOMAIN.get(name, 10.0)]
    x = np.concatenate([x, -x])
    ref = np.array([float(ref_fn(float(v))) for v in x])
    h = _coef_helpers()[name]
    from rigidkit._engine.primitives import xp_bindings

    results = {
        "python": np.array([h(float(v)) for v in x]),
        "numpy-xp": h.bound(xp_bindings(np, np.dtype(np.float64), None))(x),
        "numba": helper_kernels[name](x, backend="numba"),
    }
    for label, got in results.items():
        err = np.abs(got - ref) / np.abs(ref)
        i = int(np.argmax(err))
        MEASURED[(name, "sweep", "float64", label)] = float(err[i])
        assert err[i] <= 1e-15, (
            f"{name} on {label}: rel. error {err[i]:.3g} at x = {x[i]!r}"
        )


def test_atan_ratio_sweep():
    """``atan2(n, w) / n`` for n >= 0, w >= 0, across its threshold n = 0.02 w."""
    from rigidkit.kernels.coefficients import atan_ratio

    t = _sweep_points()
    errs = []
    for w in (1.0, 0.7, 1e-3, 1e-150):
        for n in t * w:
            r = COEF_REFS["atan_ratio"][0](n, w)
            errs.append(abs(float((atan_ratio(float(n), w) - r) / r)))
    for n in (1e-300, 1.0, 1e300):  # w = 0: pi / (2 n)
        r = COEF_REFS["atan_ratio"][0](n, 0.0)
        errs.append(abs(float((atan_ratio(n, 0.0) - r) / r)))
    MEASURED[("atan_ratio", "sweep", "float64", "python")] = max(errs)
    assert max(errs) <= 1e-15


def test_report_table():
    """Print the worst errors measured by this module (run with ``pytest -s``)."""
    if not MEASURED:
        pytest.skip("run the whole module to fill the table")
    width = max(len(" / ".join(k[:2])) for k in MEASURED)
    print()
    print(f"{'conversion / band'.ljust(width)}  dtype     measure     max error")
    for key in sorted(MEASURED):
        name, band, dtype, measure = key
        print(
            f"{(name + ' / ' + band).ljust(width)}  {dtype:8s}  {measure:10s}  "
            f"{MEASURED[key]:.2e}"
        )
