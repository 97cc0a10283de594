"""``rk.inertial.preintegrate``: IMU preintegration against independent references.

* ``"exact"``: the product of ``scipy.linalg.expm`` of the 5x5 Galilean steps
  ``[[hat(w), f, 0], [0, 0, 1], [0, 0, 0]] h``;
* ``"forster"``: Forster et al. 2017 transcribed here (eqs. 26-33 for the increments,
  Appendix B for the bias Jacobians, eq. 63 for the covariance), loops over samples;
* bias Jacobians of every method against central finite differences;
* the covariance against Monte-Carlo sampling of noisy measurements;
* ``predict`` against eq. 44 written out, gravity not along z, and against
  ``integrate``; ``corrected`` to second order; ``residual`` and its Jacobians;
* GTSAM's ``PreintegratedImuMeasurements`` (skipped without gtsam).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk

G = np.array([0.4, -0.3, -9.78])


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def log_R(R):
    return SciRot.from_matrix(R).as_rotvec()


def jr(phi):
    """SO(3) right Jacobian from its series definition, ``sum (-ad)^k / (k+1)!``."""
    A, out, term = -hat(phi), np.eye(3), np.eye(3)
    for k in range(1, 30):
        term = term @ A / (k + 1)
        out = out + term
    return out


def log(rng, n):
    return 0.8 * rng.standard_normal((n, 3)), 2.0 * rng.standard_normal((n, 3))


def errors(pim, ref_R, ref_v, ref_p):
    """``(Log(R_ref^T R), v - v_ref, p - p_ref)`` of a Preintegrated (..., 9)."""
    R = pim.delta_R.as_matrix()
    phi = SciRot.from_matrix(np.swapaxes(ref_R, -1, -2) @ R).as_rotvec()
    return np.concatenate([phi, pim.delta_v - ref_v, pim.delta_p - ref_p], axis=-1)


def test_exact_is_the_product_of_galilean_matrix_exponentials(rng):
    w, f = log(rng, 30)
    dt = rng.uniform(0.005, 0.05, 30)
    M = np.eye(5)
    for k in range(30):
        A = np.zeros((5, 5))
        A[:3, :3], A[:3, 3], A[3, 4] = hat(w[k]), f[k], 1.0
        M = M @ sl.expm(dt[k] * A)
    pim = rk.inertial.preintegrate(w, f, dt)
    np.testing.assert_allclose(pim.delta_R.as_matrix(), M[:3, :3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(pim.delta_v, M[:3, 3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(pim.delta_p, M[:3, 4], rtol=0, atol=1e-12)
    np.testing.assert_allclose(pim.delta_t, M[3, 4], rtol=0, atol=1e-14)


def forster_reference(w, f, h, sg, sa):
    """Forster et al. 2017 as printed: increments (eqs. 26-33), bias Jacobians
    (Appendix B), covariance (eq. 63, ``A`` and ``B`` in Forster's (phi, v, p))."""
    R, v, p = np.eye(3), np.zeros(3), np.zeros(3)
    dR_bg, dv_bg, dv_ba, dp_bg, dp_ba = (np.zeros((3, 3)) for _ in range(5))
    S = np.zeros((9, 9))
    for wk, fk in zip(w, f, strict=True):
        E = SciRot.from_rotvec(wk * h).as_matrix()
        J = jr(wk * h)
        A = np.eye(9)
        A[:3, :3] = E.T
        A[3:6, :3] = -R @ hat(fk) * h
        A[6:9, :3] = -0.5 * R @ hat(fk) * h * h
        A[6:9, 3:6] = np.eye(3) * h
        B = np.zeros((9, 6))
        B[:3, :3] = J * h
        B[3:6, 3:] = R * h
        B[6:9, 3:] = 0.5 * R * h * h
        S = A @ S @ A.T + B @ np.diag([sg**2 / h] * 3 + [sa**2 / h] * 3) @ B.T
        dp_ba = dp_ba + dv_ba * h - 0.5 * R * h * h
        dp_bg = dp_bg + dv_bg * h - 0.5 * R @ hat(fk) @ dR_bg * h * h
        dv_ba = dv_ba - R * h
        dv_bg = dv_bg - R @ hat(fk) @ dR_bg * h
        dR_bg = E.T @ dR_bg - J * h
        p = p + v * h + 0.5 * R @ fk * h * h
        v = v + R @ fk * h
        R = R @ E
    Jg = np.concatenate([dR_bg, dv_bg, dp_bg])
    Ja = np.concatenate([np.zeros((3, 3)), dv_ba, dp_ba])
    return R, v, p, Jg, Ja, S


def test_forster_is_the_paper_transcribed(rng):
    w, f = log(rng, 40)
    h, sg, sa = 0.01, 1.7e-3, 2e-2
    noise = rk.inertial.ImuNoise(sg, sa, 0.0, 0.0)
    pim = rk.inertial.preintegrate(w, f, h, method="forster", noise=noise)
    R, v, p, Jg, Ja, S = forster_reference(w, f, h, sg, sa)
    np.testing.assert_allclose(pim.delta_R.as_matrix(), R, rtol=0, atol=1e-13)
    np.testing.assert_allclose(pim.delta_v, v, rtol=0, atol=1e-13)
    np.testing.assert_allclose(pim.delta_p, p, rtol=0, atol=1e-13)
    np.testing.assert_allclose(pim.jacobian_gyro_bias, Jg, rtol=0, atol=1e-13)
    np.testing.assert_allclose(pim.jacobian_accel_bias, Ja, rtol=0, atol=1e-13)
    np.testing.assert_allclose(pim.covariance, S, rtol=0, atol=1e-13 * np.abs(S).max())


@pytest.mark.parametrize("method", ["exact", "forster", "midpoint"])
def test_bias_jacobians_are_finite_differences(method, rng):
    w, f = log(rng, 25)
    bg, ba = 0.05 * rng.standard_normal(3), 0.1 * rng.standard_normal(3)
    dt = rng.uniform(0.01, 0.03, 25)
    pim = rk.inertial.preintegrate(w, f, dt, gyro_bias=bg, accel_bias=ba, method=method)
    R0, v0, p0 = pim.delta_R.as_matrix(), pim.delta_v, pim.delta_p
    e = 1e-6
    for which, J in (("g", pim.jacobian_gyro_bias), ("a", pim.jacobian_accel_bias)):
        fd = np.zeros((9, 3))
        for i in range(3):
            d = np.zeros(3)
            d[i] = e
            cols = []
            for s in (1, -1):
                kw = (
                    {"gyro_bias": bg + s * d, "accel_bias": ba}
                    if which == "g"
                    else {"gyro_bias": bg, "accel_bias": ba + s * d}
                )
                cols.append(
                    errors(
                        rk.inertial.preintegrate(w, f, dt, method=method, **kw), R0, v0, p0
                    )
                )
            fd[:, i] = (cols[0] - cols[1]) / (2 * e)
        np.testing.assert_allclose(J, fd, rtol=0, atol=2e-8)


def test_covariance_against_monte_carlo(rng):
    """1e4 noisy copies of one window, preintegrated in one batched call."""
    n, h, sg, sa = 50, 0.01, 0.02, 0.2
    w, f = log(rng, n)
    noise = rk.inertial.ImuNoise(sg, sa, 0.0, 0.0)
    pim = rk.inertial.preintegrate(w, f, h, noise=noise)
    m = 10000
    wn = w + sg / np.sqrt(h) * rng.standard_normal((m, n, 3))
    fn = f + sa / np.sqrt(h) * rng.standard_normal((m, n, 3))
    batch = rk.inertial.preintegrate(wn, fn, h)
    err = errors(batch, pim.delta_R.as_matrix(), pim.delta_v, pim.delta_p)
    C = np.cov(err.T)
    sd = np.sqrt(np.diag(pim.covariance))
    # Each entry's sampling error is about sqrt(2/m) of sd_i sd_j: 1.4%.
    np.testing.assert_allclose(
        C / np.outer(sd, sd), pim.covariance / np.outer(sd, sd), rtol=0, atol=0.06
    )


def test_predict_is_forsters_equation_44(rng):
    w, f = log(rng, 20)
    pim = rk.inertial.preintegrate(w, f, 0.02)
    X = rk.ExtendedPose.random(4, rng)
    Y = pim.predict(X, gravity=G)
    R, v, p, t = X.rotation.as_matrix(), X.velocity, X.position, 0.4
    dR, dv, dp = pim.delta_R.as_matrix(), pim.delta_v, pim.delta_p
    np.testing.assert_allclose(Y.rotation.as_matrix(), R @ dR, rtol=0, atol=1e-13)
    np.testing.assert_allclose(Y.velocity, v + G * t + R @ dv, rtol=0, atol=1e-13)
    np.testing.assert_allclose(
        Y.position, p + v * t + 0.5 * G * t * t + R @ dp, rtol=0, atol=1e-13
    )
    # The same as strapdown integration of the same samples (both exact).
    Z = rk.inertial.integrate(X[0], w, f, 0.02, gravity=G, method="exact")[-1]
    np.testing.assert_allclose(Z.as_matrix(), Y[0].as_matrix(), rtol=0, atol=1e-12)


def test_corrected_is_second_order(rng):
    w, f = log(rng, 30)
    pim = rk.inertial.preintegrate(w, f, 0.02)
    direction = rng.standard_normal(6)
    gaps = []
    for s in (1e-2, 5e-3):
        bg, ba = s * direction[:3], s * direction[3:]
        ref = rk.inertial.preintegrate(w, f, 0.02, gyro_bias=bg, accel_bias=ba)
        c = pim.corrected(bg, ba)
        gaps.append(
            np.abs(errors(c, ref.delta_R.as_matrix(), ref.delta_v, ref.delta_p)).max()
        )
    assert 3.5 < gaps[0] / gaps[1] < 4.5, gaps


def test_residual_and_its_jacobians(rng):
    w, f = log(rng, 20)
    bg0 = 0.01 * rng.standard_normal(3)
    pim = rk.inertial.preintegrate(w, f, 0.02, gyro_bias=bg0)
    Xi = rk.ExtendedPose.random((), rng)
    Xj = pim.predict(Xi, gravity=G)
    r, *_ = pim.residual(Xi, Xj, gravity=G)
    np.testing.assert_allclose(r, 0.0, atol=1e-12)
    Xj = Xj.plus(0.1 * rng.standard_normal(9))
    bg, ba = bg0 + 0.01 * rng.standard_normal(3), 0.02 * rng.standard_normal(3)
    r, Ji, Jj, Jbg, Jba = pim.residual(Xi, Xj, gravity=G, gyro_bias=bg, accel_bias=ba)
    e = 1e-6

    def res(xi=None, xj=None, g=bg, a=ba):
        A = Xi if xi is None else Xi.plus(xi)
        B = Xj if xj is None else Xj.plus(xj)
        return pim.residual(A, B, gravity=G, gyro_bias=g, accel_bias=a)[0]

    for J, call, k in (
        (Ji, lambda d: res(xi=d), 9),
        (Jj, lambda d: res(xj=d), 9),
        (Jbg, lambda d: res(g=bg + d), 3),
        (Jba, lambda d: res(a=ba + d), 3),
    ):
        fd = np.stack([(call(e * u) - call(-e * u)) / (2 * e) for u in np.eye(k)], axis=-1)
        np.testing.assert_allclose(J, fd, rtol=0, atol=1e-7)


def test_windows_of_a_long_log_in_one_call(rng):
    t = np.cumsum(rng.uniform(0.004, 0.006, 400))
    w, f = log(rng, 400)
    kf = np.array([t[0], t[57] + 0.001, t[190], t[399] - 0.002])
    gw, fw, dt = rk.inertial.split_windows(t, w, f, kf)
    batch = rk.inertial.preintegrate(gw, fw, dt, noise=rk.inertial.ImuNoise(1e-3, 1e-2))
    assert batch.shape == (3,)
    np.testing.assert_allclose(batch.delta_t, np.diff(kf), rtol=0, atol=1e-12)
    # The windows compose to the whole span: the flow of the state is a group action.
    a, b = kf[0], kf[-1]
    sel = (t >= a) & (t < b)
    steps = np.diff(np.append(t[sel], b))
    whole = rk.inertial.preintegrate(w[sel], f[sel], steps)
    X0 = rk.ExtendedPose.random((), rng)
    X = X0
    for k in range(3):
        X = batch[k].predict(X, gravity=G)
    Xw = whole.predict(X0, gravity=G)
    np.testing.assert_allclose(X.as_matrix(), Xw.as_matrix(), rtol=0, atol=1e-12)


def test_split_windows_stamps_must_be_host_numbers(jax, rng):
    """The stamps fix the windows' shape: traced stamps raise a DegenerateInputError
    that says so; traced samples with host stamps are gathered (jit traces)."""
    t = np.cumsum(rng.uniform(0.05, 0.15, 8))
    w, f = log(rng, 8)
    kf = np.array([t[0], t[3] + 0.01, t[7]])
    want = rk.inertial.split_windows(t, w, f, kf)
    got = jax.jit(lambda w, f: rk.inertial.split_windows(t, w, f, kf))(w, f)
    for g, x in zip(got, want):
        np.testing.assert_array_equal(np.asarray(g), x)
    with pytest.raises(rk.errors.DegenerateInputError, match="times must be concrete"):
        jax.jit(lambda t: rk.inertial.split_windows(t, w, f, kf))(t)


def test_split_windows_keeps_float32(rng):
    t = np.arange(6) * 0.1
    w, f = log(rng, 6)
    g, a, dt = rk.inertial.split_windows(
        t, w.astype(np.float32), f.astype(np.float32), [0.0, 0.25, 0.5]
    )
    assert g.dtype == a.dtype == dt.dtype == np.float32
    np.testing.assert_allclose(dt.sum(axis=-1), [0.25, 0.25], rtol=1e-6)


def test_residual_broadcasts_windows_against_states(rng):
    """A batch of windows against one pair of states (and one window against a batch
    of states) gives each pair's residual and Jacobians, as the calls one by one."""
    w, f = log(rng, 3 * 12)
    pim = rk.inertial.preintegrate(
        w.reshape(3, 12, 3), f.reshape(3, 12, 3), 0.01, gyro_bias=[0.01, 0.0, -0.02]
    )
    Xi, Xj = rk.ExtendedPose.random((), rng), rk.ExtendedPose.random((), rng)
    bg = np.array([0.02, -0.01, 0.03])
    got = pim.residual(Xi, Xj, gravity=G, gyro_bias=bg)
    for k in range(3):
        one = pim[k].residual(Xi, Xj, gravity=G, gyro_bias=bg)
        for a, b in zip(got, one):
            np.testing.assert_allclose(
                a[k], b, rtol=0, atol=1e-15 * max(1, np.abs(b).max())
            )
    Xs = rk.ExtendedPose.random((4,), rng)
    got = pim[1].residual(Xs, Xj, gravity=G, gyro_bias=bg)
    for k in range(4):
        one = pim[1].residual(Xs[k], Xj, gravity=G, gyro_bias=bg)
        for a, b in zip(got, one):
            np.testing.assert_allclose(
                a[k], b, rtol=0, atol=1e-15 * max(1, np.abs(b).max())
            )


def test_float32_and_batches(rng):
    w, f = log(rng, 16)
    pim = rk.inertial.preintegrate(
        w.astype(np.float32),
        f.astype(np.float32),
        0.01,
        noise=rk.inertial.ImuNoise(1e-3, 1e-2),
    )
    assert pim.delta_v.dtype == np.float32 and pim.covariance.dtype == np.float32
    ref = rk.inertial.preintegrate(w, f, 0.01)
    np.testing.assert_allclose(pim.delta_p, ref.delta_p, atol=1e-6)


def test_torch_and_jax(torch, jax, jnp, rng):
    w, f = log(rng, 12)
    ref = rk.inertial.preintegrate(w, f, 0.02)
    ft = torch.tensor(f, requires_grad=True)
    pim = rk.inertial.preintegrate(torch.tensor(w), ft, 0.02)
    (g,) = torch.autograd.grad(pim.delta_v[..., 0].sum(), ft)
    np.testing.assert_allclose(pim.delta_v.detach().numpy(), ref.delta_v, atol=1e-13)
    fd = np.zeros_like(f)
    for k in range(12):
        for i in range(3):
            d = np.zeros_like(f)
            d[k, i] = 1e-6
            fd[k, i] = (
                rk.inertial.preintegrate(w, f + d, 0.02).delta_v[0]
                - rk.inertial.preintegrate(w, f - d, 0.02).delta_v[0]
            ) / 2e-6
    np.testing.assert_allclose(g.numpy(), fd, atol=1e-8)
    out = jax.jit(lambda a, b: rk.inertial.preintegrate(a, b, 0.02).delta_p)(
        jnp.asarray(w), jnp.asarray(f)
    )
    np.testing.assert_allclose(np.asarray(out), ref.delta_p, atol=1e-13)
    # Covariance, correction and residual on both, against NumPy's.
    noise = rk.inertial.ImuNoise(1e-3, 1e-2)
    want = rk.inertial.preintegrate(w, f, 0.02, noise=noise)
    Xi, Xj = rk.ExtendedPose.random(2, rng)
    r0 = want.residual(Xi, Xj, gyro_bias=[0.01, 0.0, 0.0])
    for xp in (torch.tensor, jnp.asarray):
        got = rk.inertial.preintegrate(xp(w), xp(f), 0.02, noise=noise)
        np.testing.assert_allclose(np.asarray(got.covariance), want.covariance, atol=1e-18)
        A, B = (rk.ExtendedPose._wrap(xp(np.asarray(X._data))) for X in (Xi, Xj))
        r = got.residual(A, B, gyro_bias=xp(np.array([0.01, 0.0, 0.0])))
        for a, b in zip(r, r0, strict=True):
            np.testing.assert_allclose(np.asarray(a), b, atol=1e-14)


def _gtsam_pim(gtsam, w, f, h, sg, sa):
    p = gtsam.PreintegrationParams.MakeSharedU(9.81)
    p.setGyroscopeCovariance(np.eye(3) * sg**2)
    p.setAccelerometerCovariance(np.eye(3) * sa**2)
    p.setIntegrationCovariance(np.zeros((3, 3)))
    pim = gtsam.PreintegratedImuMeasurements(p, gtsam.imuBias.ConstantBias())
    for k in range(len(w)):
        pim.integrateMeasurement(f[k], w[k], h)
    return pim


@pytest.mark.parametrize("method", ["exact", "forster", "midpoint"])
def test_against_gtsam_converging_at_first_order(method):
    """GTSAM's tangent-space preintegration and ours tend to the same limit as one
    smooth signal is sampled finer (both first order in the step): the gap of the
    increments and of the covariances halves with the step."""
    gtsam = pytest.importorskip("gtsam")
    sg, sa = 0.01, 0.03

    def gap(n):
        t = np.arange(n) / n
        w = np.stack([0.5 * np.sin(t), 0.3 * np.cos(2 * t), 0.2 + 0 * t], -1)
        f = np.stack([np.cos(t), 1 + np.sin(3 * t), 9.81 + 0 * t], -1)
        ref = _gtsam_pim(gtsam, w, f, 1 / n, sg, sa)
        ours = rk.inertial.preintegrate(
            w, f, 1 / n, method=method, noise=rk.inertial.ImuNoise(sg, sa)
        )
        zeta, cov = rk.inertial.to_gtsam(ours)
        C = ref.preintMeasCov()
        return np.abs(zeta - ref.preintegrated()).max(), np.abs(cov - C).max() / np.abs(
            C
        ).max()

    (z1, c1), (z2, c2) = gap(100), gap(200)
    assert 1.8 < z1 / z2 < 2.2 and 1.8 < c1 / c2 < 2.2, (z1, z2, c1, c2)
    # The conversion round trip, and its layout against GTSAM's own accessors.
    ref = _gtsam_pim(
        gtsam,
        np.tile([0.1, 0.2, 0.3], (50, 1)),
        np.tile([1.0, 0.0, 9.8], (50, 1)),
        0.01,
        sg,
        sa,
    )
    R, v, p, cov = rk.inertial.from_gtsam(ref.preintegrated(), ref.preintMeasCov())
    np.testing.assert_allclose(R.as_matrix(), ref.deltaRij().matrix(), atol=1e-14)
    np.testing.assert_allclose(v, ref.deltaVij(), atol=1e-14)
    np.testing.assert_allclose(p, ref.deltaPij(), atol=1e-14)
    ours = rk.inertial.preintegrate(
        np.tile([0.1, 0.2, 0.3], (50, 1)), np.tile([1.0, 0.0, 9.8], (50, 1)), 0.01
    )
    back = rk.inertial.Preintegrated(
        ours._delta, ours._jacobian, cov, ours.gyro_bias, ours.accel_bias
    )
    np.testing.assert_allclose(
        rk.inertial.to_gtsam(back)[1], ref.preintMeasCov(), atol=1e-15
    )


def test_the_rate_of_cos_defect4_against_mpmath():
    """``(d cos_defect4 / dx) / x``, the one coefficient the exact step's Jacobian adds
    (:func:`rigidkit.kernels.kinematics.inertial_jacobians.cos_defect4_rate`): within a
    few ulp of mpmath's derivative of ``(cos x - 1 + x^2/2) / x^4`` at 50 digits, from
    1e-8 to 6 (its series-free form has no threshold to straddle)."""
    mp = pytest.importorskip("mpmath")
    from rigidkit.kernels.kinematics.inertial_jacobians import cos_defect4_rate

    mp.mp.dps = 50
    x = np.concatenate([np.geomspace(1e-8, 1e-1, 30), np.linspace(0.1, 6.0, 60)])
    got = np.array([cos_defect4_rate(float(v)) for v in x])  # the scalar binding

    def c2(t):
        return (mp.cos(t) - 1 + t**2 / 2) / t**4

    def ref(v):
        t = mp.mpf(v)
        if t < mp.mpf("1e-3"):  # the series: -1/360 + t^2/10080 - t^4/604800
            return float(-mp.mpf(1) / 360 + t**2 / 10080 - t**4 / 604800)
        return float(mp.diff(c2, t) / t)

    want = np.array([ref(v) for v in x])
    np.testing.assert_allclose(got, want, rtol=8 * np.finfo(float).eps, atol=0)


# -- the compiled fold (NumPy's path for large calls) ----------------------------------
@pytest.fixture
def folds(monkeypatch):
    """Every call takes the compiled fold (built, or loaded from the disk cache,
    first): FOLD_MIN 0, and each method's fold waited for."""
    from rigidkit.applications.inertial import _fold

    if not rk._engine.numba_available():
        pytest.skip("numba is not installed")
    for method in ("exact", "forster", "midpoint"):
        _fold.wait(method)
    monkeypatch.setattr(_fold, "FOLD_MIN", 0)
    return _fold


def _array_path(w, f, h, bg, ba, noise, method):
    """The array path (steps, Jacobians, scan and sensitivities as whole arrays)."""
    from rigidkit.applications.inertial import preintegration as P

    return P._preintegrate(w, f, h, bg, ba, noise, method, np)


@pytest.mark.parametrize("method", ["exact", "forster", "midpoint"])
def test_the_fold_is_the_array_path(folds, method, rng):
    """One compiled pass per window (the running product with the sums ``G``, ``P``
    and the end map ``L``) gives the array path's increments, bias Jacobians and
    covariance to rounding: windows of a (2, 3) batch, per-window biases, per-step
    durations with zero-duration padding, and no noise (no covariance)."""
    n = 40
    w = 0.8 * rng.standard_normal((2, 3, n, 3))
    f = 2.0 * rng.standard_normal((2, 3, n, 3))
    h = rng.uniform(0.002, 0.02, (2, 3, n))
    h[1, 2, 30:] = 0.0  # a shorter window, padded
    bg = 0.05 * rng.standard_normal((2, 3, 3))
    ba = 0.1 * rng.standard_normal(3)
    noise = rk.inertial.ImuNoise(2e-3, 3e-2)
    pim = rk.inertial.preintegrate(
        w, f, h, gyro_bias=bg, accel_bias=ba, noise=noise, method=method
    )
    ref = _array_path(w, f, h, bg, ba, noise, method)
    assert pim.shape == (2, 3)
    np.testing.assert_allclose(pim._delta, ref._delta, rtol=0, atol=1e-14)
    np.testing.assert_allclose(
        pim._jacobian, ref._jacobian, rtol=0, atol=1e-14 * np.abs(ref._jacobian).max()
    )
    scale = np.abs(ref.covariance).max()
    np.testing.assert_allclose(pim.covariance, ref.covariance, rtol=0, atol=1e-14 * scale)
    np.testing.assert_array_equal(pim.gyro_bias, np.broadcast_to(bg, (2, 3, 3)))
    # the padded window ends where its last real step does
    short = _array_path(
        w[1, 2, :30], f[1, 2, :30], h[1, 2, :30], bg[1, 2], ba, noise, method
    )
    if method != "midpoint":  # midpoint's last real step reads the next sample
        np.testing.assert_allclose(pim[1, 2]._delta, short._delta, rtol=0, atol=1e-14)
    quiet = rk.inertial.preintegrate(w[0, 0], f[0, 0], 0.01, method=method)
    assert quiet.covariance is None
    ref = _array_path(
        w[0, 0], f[0, 0], np.asarray(0.01), np.zeros(3), np.zeros(3), None, method
    )
    np.testing.assert_allclose(quiet._jacobian, ref._jacobian, rtol=0, atol=1e-14)


def test_the_fold_keeps_float32_and_its_jacobians_are_finite_differences(folds, rng):
    w, f = log(rng, 25)
    dt = rng.uniform(0.01, 0.03, 25)
    pim = rk.inertial.preintegrate(
        w.astype(np.float32), f.astype(np.float32), dt.astype(np.float32), method="exact"
    )
    assert pim._delta.dtype == np.float32 and pim._jacobian.dtype == np.float32
    ref = _array_path(w, f, dt, np.zeros(3), np.zeros(3), None, "exact")
    np.testing.assert_allclose(pim._delta, ref._delta, rtol=0, atol=2e-5)
    # The fold's bias Jacobians against central differences of the fold itself.
    bg = 0.05 * rng.standard_normal(3)
    pim = rk.inertial.preintegrate(w, f, dt, gyro_bias=bg, method="exact")
    R0, v0, p0 = pim.delta_R.as_matrix(), pim.delta_v, pim.delta_p
    e = 1e-6
    fd = np.zeros((9, 3))
    for i in range(3):
        d = np.zeros(3)
        d[i] = e
        cols = [
            errors(rk.inertial.preintegrate(w, f, dt, gyro_bias=bg + s * d), R0, v0, p0)
            for s in (1, -1)
        ]
        fd[:, i] = (cols[0] - cols[1]) / (2 * e)
    np.testing.assert_allclose(pim.jacobian_gyro_bias, fd, rtol=0, atol=2e-8)


def test_against_pypose_converging_at_first_order():
    """pypose's ``IMUPreintegrator`` (Forster's recursion, gravity removed per sample in
    the body frame) and our ``"forster"`` increments with ``predict`` from the
    identity: the same rotation (a product of ``Exp(w h)``), and velocity and position
    gaps that halve with the step (pypose removes gravity with the rotation at a
    step's end, Forster's recursion with the increments at its start: first order).
    Skipped without pypose."""
    pp = pytest.importorskip("pypose")
    torch = pytest.importorskip("torch")
    g = 9.81007

    def gap(n):
        t = np.arange(n) / n
        w = np.stack([0.5 * np.sin(t), 0.3 * np.cos(2 * t), 0.2 + 0 * t], -1)
        f = np.stack([np.cos(t), 1 + np.sin(3 * t), g + 0 * t], -1)
        integrator = pp.module.IMUPreintegrator(
            gravity=g, prop_cov=False, reset=True
        ).double()
        with torch.no_grad():
            out = integrator(
                torch.full((1, n, 1), 1 / n, dtype=torch.float64),
                torch.tensor(w[None]),
                torch.tensor(f[None]),
            )
        X = rk.inertial.preintegrate(w, f, 1 / n, method="forster").predict(
            rk.ExtendedPose(), gravity=(0.0, 0.0, -g)
        )
        quat = out["rot"][0, -1].tensor().numpy()  # pypose: (x, y, z, w)
        R = SciRot.from_quat(quat).as_matrix()
        np.testing.assert_allclose(R, X.rotation.as_matrix(), rtol=0, atol=1e-12)
        return (
            np.abs(out["vel"][0, -1].numpy() - X.velocity).max(),
            np.abs(out["pos"][0, -1].numpy() - X.position).max(),
        )

    (v1, p1), (v2, p2) = gap(100), gap(200)
    assert 1.8 < v1 / v2 < 2.2 and 1.8 < p1 / p2 < 2.2, (v1, v2, p1, p2)
