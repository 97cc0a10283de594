"""Bugs found in review (issue 20 part 3, issue 22's Euler-rate items), each with a
test that failed before its fix.

References: exact IEEE identities (``q* q`` has a vector part of exactly 0 when each
pair of terms that cancels is summed first), scipy (``RotationSpline`` of a constant
attitude has rate exactly 0), mpmath at 60 digits (the exponential of a rotation
vector of 1e300 rad), central finite differences of scipy's ``from_euler``, SymPy's
own matrix inverse, and a Dask callback that counts computes.
"""

from __future__ import annotations

import zlib

import mpmath
import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRot
from scipy.spatial.transform import RotationSpline as SciSpline

import rigidkit as rk
from rigidkit.kernels import quaternion as kq

# -- 1. q^-1 q is exactly the identity ------------------------------------------------


def _quats(n, seed=0):
    return rk.Rotation.random((n,), rng=seed).as_quat()


@pytest.mark.parametrize("backend", ["numba", "xp"])
@pytest.mark.parametrize("kern", [kq.quat_multiply, kq.quat_compose])
def test_inverse_times_rotation_is_exactly_identity(kern, backend):
    q = _quats(2000, seed=1)
    qc = q * np.array([1.0, -1.0, -1.0, -1.0])
    for a, b in ((qc, q), (q, qc)):
        r = kern(a, b, backend=backend)
        assert np.all(r[:, 1:] == 0.0), np.abs(r[:, 1:]).max()


def test_rotation_inv_matmul_is_exactly_identity_single_and_batch():
    for R in (rk.Rotation.random((), rng=1), rk.Rotation.random((300,), rng=2)):
        for P in (R.inv() @ R, R @ R.inv()):
            v = np.asarray(P.as_quat())[..., 1:]
            assert np.all(v == 0.0), np.abs(v).max()
            assert np.allclose(P.as_quat()[..., 0], 1.0, rtol=0, atol=4e-16)


def test_inverse_product_exact_on_torch_and_jax():
    torch = pytest.importorskip("torch")
    jnp = pytest.importorskip("jax.numpy")
    q = _quats(200, seed=3)
    for arr in (torch.tensor(q), jnp.asarray(q, dtype=jnp.float32)):
        R = rk.Rotation.from_quat(arr)
        v = np.asarray((R.inv() @ R).as_quat())[..., 1:]
        assert np.all(v == 0.0)


def test_spline_of_constant_attitude_has_rate_exactly_zero():
    q = np.broadcast_to(rk.Rotation.random((), rng=5).as_quat(), (6, 4)).copy()
    t = np.arange(6.0)
    tt = np.linspace(0.0, 5.0, 23)
    ref = SciSpline(t, SciRot.from_quat(q, scalar_first=True))
    assert np.all(ref(tt, 1) == 0.0)  # the reference: scipy's is exactly 0
    s = rk.RotationSpline(t, rk.Rotation.from_quat(q))
    for frame in ("body", "world"):
        assert np.all(s(tt, 1, frame=frame) == 0.0)
        assert np.all(s(tt, 2, frame=frame) == 0.0)


# -- 2. from_rotvec of a huge finite rotation vector ----------------------------------


def _mp_quat(r):
    """The exact exponential of the float vector ``r`` at 60 digits."""
    with mpmath.workdps(60):
        v = [mpmath.mpf(float(c)) for c in r]
        th = mpmath.sqrt(sum(c * c for c in v))
        h = th / 2
        s = mpmath.sin(h) / th
        return np.array([float(mpmath.cos(h))] + [float(s * c) for c in v])


@pytest.mark.parametrize(
    "r",
    [
        [1e300, 0.0, 0.0],
        [0.0, -1e300, 0.0],
        [0.0, 0.0, 4e307],
        [1e152, 0.0, 0.0],
        [3e20, 0.0, 0.0],
        [1e18, 0.0, 0.0],
        [2.5e17, 0.0, 0.0],
    ],
)
def test_from_rotvec_huge_angle_is_the_exact_unit_quaternion(r):
    ref = _mp_quat(r)
    single = rk.Rotation.from_rotvec(r).as_quat()
    batch = rk.Rotation.from_rotvec(np.array([r, r])).as_quat()
    for got in (single, batch[0], batch[1]):
        assert np.all(np.isfinite(got))
        assert abs(np.dot(got, got) - 1.0) < 4e-16
        # q and -q are one rotation; the half angle is reduced exactly
        assert np.allclose(got * np.sign(got @ ref), ref, rtol=0, atol=2e-16)


def test_from_rotvec_huge_in_all_components_is_unit_and_finite():
    r = np.array([[1e300, 3e299, 1e200], [1e30, 1e30, 1e30], [1.7e308, 1.7e308, -1.7e308]])
    for rr in (r, r[0]):
        q = rk.Rotation.from_rotvec(rr).as_quat()
        assert np.all(np.isfinite(q))
        n2 = np.sum(np.asarray(q) ** 2, axis=-1).reshape(-1)
        assert np.allclose(n2[:2], 1.0, rtol=0, atol=4e-16)
        # Beyond |r| ~ 4.5e307, sin(theta/2)/theta is subnormal: unit to ~10 ulp.
        assert np.all(abs(n2[2:] - 1.0) < 5e-15)
    # float32: |r|^2 overflows from 1e19
    r32 = np.array([[3e38, 3e38, 3e38], [1e20, 0.0, 0.0]], dtype=np.float32)
    q32 = rk.Rotation.from_rotvec(r32).as_quat()
    assert q32.dtype == np.float32 and np.all(np.isfinite(q32))
    assert np.allclose(np.sum(q32.astype(np.float64) ** 2, axis=-1), 1.0, atol=1e-6)


def test_from_rotvec_huge_on_torch():
    torch = pytest.importorskip("torch")
    r = [[1e300, 0.0, 0.0], [0.0, 1e152, 0.0]]
    got = rk.Rotation.from_rotvec(torch.tensor(r, dtype=torch.float64)).as_quat().numpy()
    for g, ri in zip(got, r):
        ref = _mp_quat(ri)
        assert np.allclose(g * np.sign(g @ ref), ref, rtol=0, atol=2e-16)


@pytest.mark.parametrize("bad", [np.inf, -np.inf, np.nan])
def test_from_rotvec_nonfinite_still_raises(bad):
    with pytest.raises(rk.NonFiniteError):
        rk.Rotation.from_rotvec([bad, 0.0, 0.0])
    with pytest.raises(rk.NonFiniteError) as e:
        rk.Rotation.from_rotvec([[0.0, 0.0, 1.0], [1e300, bad, 0.0]])
    assert e.value.index == (1,)


# -- 3. scalar_first= on the kinematics of quaternions --------------------------------


def _sci_quat_path(rng, frame, n=4, h=1e-5):
    """scipy quaternions (x, y, z, w) of ``R(t) = R0 exp(t w)`` (body) or
    ``exp(t w) R0`` (world), their derivatives at t = 0 by 4th-order central
    differences (a continuous sign along t), and ``w``."""
    R0 = SciRot.random(n, random_state=rng)
    w = rng.standard_normal((n, 3))

    def q(t):
        step = SciRot.from_rotvec(t * w)
        return (R0 * step if frame == "body" else step * R0).as_quat()

    d1 = (-q(2 * h) + 8 * q(h) - 8 * q(-h) + q(-2 * h)) / (12 * h)
    h2 = 1e-3
    d2 = (-q(2 * h2) + 16 * q(h2) - 30 * q(0.0) + 16 * q(-h2) - q(-2 * h2)) / (12 * h2**2)
    return q(0.0), d1, d2, w


@pytest.mark.parametrize("frame", ["world", "body"])
def test_quaternion_kinematics_take_scipy_order(frame):
    K = rk.kinematics
    rng = np.random.default_rng(7)
    q_xyzw, dq_ref, ddq_ref, w = _sci_quat_path(rng, frame)
    dq = K.quaternion_derivative(q_xyzw, w, frame=frame, scalar_first=False)
    assert np.allclose(dq, dq_ref, rtol=0, atol=1e-9)
    ddq = K.quaternion_second_derivative(
        q_xyzw, w, np.zeros(3), frame=frame, scalar_first=False
    )
    assert np.allclose(ddq, ddq_ref, rtol=0, atol=1e-6)
    w_back = K.angular_velocity_from_quaternion_derivative(
        q_xyzw, dq_ref, frame=frame, scalar_first=False
    )
    assert np.allclose(w_back, w, rtol=0, atol=1e-9)
    # the default order (w, x, y, z) reads the same numbers as another rotation
    wrong = K.angular_velocity_from_quaternion_derivative(q_xyzw, dq_ref, frame=frame)
    assert not np.allclose(wrong, w, atol=1e-3)
    # a Rotation carries its own order; the arrays follow scalar_first
    R = rk.Rotation.from_quat(q_xyzw, scalar_first=False)
    assert np.allclose(
        K.quaternion_derivative(R, w, frame=frame, scalar_first=False), dq, atol=1e-15
    )
    w_R = K.angular_velocity_from_quaternion_derivative(
        R, dq_ref, frame=frame, scalar_first=False
    )
    assert np.allclose(w_R, w, rtol=0, atol=1e-9)


def test_quaternion_kinematics_scalar_first_on_torch():
    torch = pytest.importorskip("torch")
    K = rk.kinematics
    q_xyzw, dq_ref, _, w = _sci_quat_path(np.random.default_rng(8), "body")
    dq = K.quaternion_derivative(
        torch.tensor(q_xyzw), torch.tensor(w), frame="body", scalar_first=False
    )
    assert isinstance(dq, torch.Tensor)
    assert np.allclose(dq.numpy(), dq_ref, rtol=0, atol=1e-9)


# -- 4. Euler rates of sequences of one and two axes ----------------------------------

SHORT = ["ZX", "zx", "XY", "yz", "YZ", "xz", "Z", "x"]


def _vee(W):
    return np.stack([W[..., 2, 1], W[..., 0, 2], W[..., 1, 0]], axis=-1)


def _fd_omega_short(seq, a, r, frame, h=1e-5):
    """omega of scipy's from_euler along a + t r (4th-order central differences)."""

    def R(t):
        return SciRot.from_euler(seq, a + t * r).as_matrix()

    Rd = (-R(2 * h) + 8 * R(h) - 8 * R(-h) + R(-2 * h)) / (12 * h)
    R0T = np.swapaxes(R(0.0), -1, -2)
    return _vee(Rd @ R0T if frame == "world" else R0T @ Rd)


@pytest.mark.parametrize("frame", ["world", "body"])
@pytest.mark.parametrize("seq", SHORT)
def test_short_sequence_rates_against_scipy(seq, frame):
    K = rk.kinematics
    n = len(seq)
    rng = np.random.default_rng(zlib.crc32((seq + frame).encode()))
    a = rng.uniform(-3.0, 3.0, (6, n))
    r = rng.standard_normal((6, n))
    w_ref = _fd_omega_short(seq, a, r, frame)
    w = K.angular_velocity_from_euler_rates(seq, a, r, frame=frame)
    assert np.allclose(w, w_ref, rtol=0, atol=1e-9)
    E = K.euler_rate_matrix(seq, a, frame=frame)
    assert E.shape == (6, 3, n)
    assert np.allclose(np.einsum("...ij,...j->...i", E, r), w_ref, rtol=0, atol=1e-9)
    # the inverse is the pseudo-inverse (numpy's), and gives the rates back
    Ei = K.euler_rate_matrix_inverse(seq, a, frame=frame)
    assert Ei.shape == (6, n, 3)
    assert np.allclose(Ei, np.linalg.pinv(E), rtol=0, atol=1e-14)
    assert np.allclose(K.euler_rates(seq, a, w_ref, frame=frame), r, rtol=0, atol=1e-9)
    # an omega off the span: the least-squares rates (numpy's lstsq)
    w_off = rng.standard_normal((6, 3))
    ls = np.stack([np.linalg.lstsq(E[i], w_off[i], rcond=None)[0] for i in range(6)])
    assert np.allclose(K.euler_rates(seq, a, w_off, frame=frame), ls, rtol=0, atol=1e-14)
    # dE/dt against a central difference of E along the rates
    h = 1e-6
    Ed_ref = (
        K.euler_rate_matrix(seq, a + h * r, frame=frame)
        - K.euler_rate_matrix(seq, a - h * r, frame=frame)
    ) / (2 * h)
    Ed = K.euler_rate_matrix_derivative(seq, a, r, frame=frame)
    assert np.allclose(Ed, Ed_ref, rtol=0, atol=1e-8)
    # alpha against a central difference of omega along a + t r + t^2/2 acc
    acc = rng.standard_normal((6, n))

    def omega_at(t):
        return K.angular_velocity_from_euler_rates(
            seq, a + t * r + 0.5 * t * t * acc, r + t * acc, frame=frame
        )

    al_ref = (omega_at(h) - omega_at(-h)) / (2 * h)
    al = K.angular_acceleration_from_euler_rates(seq, a, r, acc, frame=frame)
    assert np.allclose(al, al_ref, rtol=0, atol=1e-8)
    assert np.allclose(K.euler_accelerations(seq, a, r, al, frame=frame), acc, atol=1e-12)


def test_short_sequence_degrees_scalar_and_no_lock():
    K = rk.kinematics
    # one axis: a scalar angle, its rate is the component along the axis
    assert np.allclose(K.euler_rates("Z", 0.3, [0.1, 0.2, 2.0], frame="world"), [2.0])
    # degrees: rates in degrees per unit time, omega in radians
    a, r = np.array([10.0, 20.0]), np.array([30.0, -40.0])
    w = K.angular_velocity_from_euler_rates("ZX", a, r, frame="body", degrees=True)
    w_ref = _fd_omega_short("ZX", np.radians(a), np.radians(r), "body")
    assert np.allclose(w, w_ref, atol=1e-9)
    assert np.allclose(K.euler_rates("ZX", a, w, frame="body", degrees=True), r)
    E = K.euler_rate_matrix("ZX", a, frame="body", degrees=True)
    Ei = K.euler_rate_matrix_inverse("ZX", a, frame="body", degrees=True)
    assert np.allclose(Ei, np.linalg.pinv(E), atol=1e-12)
    # where "ZXY" would be at gimbal lock, "ZX" has none: no error, exact rates
    a90 = [0.4, np.pi / 2]
    w = K.angular_velocity_from_euler_rates("ZX", a90, [1.0, 2.0], frame="world")
    assert np.allclose(K.euler_rates("ZX", a90, w, frame="world"), [1.0, 2.0])
    with pytest.raises(rk.ShapeError):
        K.euler_rates("ZX", [0.1, 0.2, 0.3], w, frame="world")
    with pytest.raises(rk.EulerSequenceError):
        K.euler_rates("ZZ", [0.1, 0.2], w, frame="world")


def test_short_sequence_rates_on_torch_and_jax():
    torch = pytest.importorskip("torch")
    jnp = pytest.importorskip("jax.numpy")
    K = rk.kinematics
    a = np.array([[0.3, -1.2], [2.0, 0.5]])
    w = np.array([[0.1, 0.2, 0.3], [-1.0, 0.5, 2.0]])
    ref = K.euler_rates("zy", a, w, frame="body")
    t = K.euler_rates("zy", torch.tensor(a), torch.tensor(w), frame="body")
    assert isinstance(t, torch.Tensor) and np.allclose(t.numpy(), ref, atol=1e-15)
    j = K.euler_rate_matrix_inverse("zy", jnp.asarray(a, dtype=jnp.float32), frame="body")
    assert j.dtype == jnp.float32
    Ei = K.euler_rate_matrix_inverse("zy", a, frame="body")
    assert np.allclose(np.asarray(j), Ei, atol=1e-6)


# -- 5. The lock check of the inverse Euler-rate functions: lazy, traceable, optional --

LOCK_FNS = ("euler_rates", "euler_rate_matrix_inverse", "euler_accelerations")


def _call(name, a, w):
    K = rk.kinematics
    if name == "euler_rates":
        return K.euler_rates("ZYX", a, w, frame="body")
    if name == "euler_rate_matrix_inverse":
        return K.euler_rate_matrix_inverse("ZYX", a, frame="body")
    return K.euler_accelerations("ZYX", a, w, w, frame="body")


def _lock_inputs():
    rng = np.random.default_rng(21)
    a = rng.uniform(-1.0, 1.0, (8, 3))
    a[5, 1] = np.pi / 2  # ZYX: pitch at +90 degrees
    return a, rng.standard_normal((8, 3))


@pytest.mark.parametrize("name", LOCK_FNS)
def test_lock_check_on_dask_computes_nothing_during_the_call(name):
    da = pytest.importorskip("dask.array")
    from dask.callbacks import Callback

    computes = []

    class Count(Callback):
        def _start(self, dsk):
            computes.append(1)

    a, w = _lock_inputs()
    good = a.copy()
    good[5, 1] = 0.3
    with Count():
        lazy = _call(name, da.from_array(good, chunks=3), da.from_array(w, chunks=3))
        lazy_bad = _call(name, da.from_array(a, chunks=3), da.from_array(w, chunks=3))
    assert computes == []
    assert isinstance(lazy, da.Array)
    assert np.allclose(lazy.compute(), _call(name, good, w), rtol=0, atol=0)
    with pytest.raises(rk.GimbalLockError) as e:
        lazy_bad.compute()
    assert e.value.index == (5,)


@pytest.mark.parametrize("name", LOCK_FNS)
def test_lock_check_never_reads_values_while_torch_compiles(name, monkeypatch):
    """While ``torch.compile`` traces, values cannot be read (``rk``'s ``concrete`` is
    False: ``torch.compiler.is_compiling()``), and a check that reads them anyway
    guards on data, which fails ``fullgraph=True``. Faked here so that the test takes
    milliseconds; the real compile is the exhaustive test below."""
    torch = pytest.importorskip("torch")
    from rigidkit import _raising, _validate

    a, w = _lock_inputs()
    with pytest.raises(rk.GimbalLockError):  # eager torch: checked
        _call(name, torch.tensor(a), torch.tensor(w))

    # concrete lives in _raising (read there by checks_now), re-exported by _validate
    for module in (_raising, _validate):
        monkeypatch.setattr(module, "concrete", lambda x: not torch.is_tensor(x))
    out = _call(name, torch.tensor(a), torch.tensor(w))  # no GimbalLockError
    assert torch.all(torch.isfinite(out))


@pytest.mark.parametrize("name", LOCK_FNS)
def test_set_validation_false_removes_the_lock_check(name):
    a, w = _lock_inputs()
    with pytest.raises(rk.GimbalLockError):
        _call(name, a, w)
    ok = np.delete(np.arange(8), 5)
    ref = _call(name, a[ok], w[ok])
    with rk.set_validation(False):
        out = _call(name, a, w)  # no GimbalLockError
    assert np.all(np.isfinite(out))
    assert np.array_equal(out[ok], ref)


@pytest.mark.exhaustive
def test_lock_check_under_torch_compile_fullgraph():
    torch = pytest.importorskip("torch")
    a, w = _lock_inputs()
    good = a.copy()
    good[5, 1] = 0.3

    def f(a, w):
        return tuple(_call(name, a, w) for name in LOCK_FNS)

    g = torch.compile(f, fullgraph=True)
    for x, y in zip(g(torch.tensor(good), torch.tensor(w)), f(good, w)):
        assert np.allclose(x.numpy(), y, rtol=0, atol=1e-12)


# -- 6. rk.symbolic.euler_rate_matrix_inverse ------------------------------------------

SEQS24 = [
    s for s in (a + b + c for a in "xyz" for b in "xyz" for c in "xyz" if a != b and b != c)
]
SEQS24 = SEQS24 + [s.upper() for s in SEQS24]


@pytest.mark.parametrize("frame", ["world", "body"])
@pytest.mark.parametrize("seq", ["ZYX", "zxz", "XYZ", "yxy", "ZX", "x"])
def test_symbolic_euler_rate_matrix_inverse(seq, frame):
    import sympy as sp

    n = len(seq)
    syms = sp.symbols(f"a0:{n}", real=True)
    E = rk.symbolic.euler_rate_matrix(seq, syms, frame=frame)
    Ei = rk.symbolic.euler_rate_matrix_inverse(seq, syms, frame=frame)
    assert Ei.shape == (n, 3)
    # SymPy's own algebra: E^-1 E = I (E^+ E = I for one or two axes)
    assert sp.simplify(Ei * E - sp.eye(n)) == sp.zeros(n, n)
    if n < 3:
        assert sp.simplify(Ei - (E.T * E).inv() * E.T) == sp.zeros(n, 3)
    # numerically equal to rk.kinematics at random angles
    rng = np.random.default_rng(zlib.crc32((seq + frame).encode()))
    for _ in range(3):
        a = rng.uniform(0.2, 1.3, n)
        num = np.array(Ei.subs(dict(zip(syms, a))).evalf(), dtype=float)
        ref = rk.kinematics.euler_rate_matrix_inverse(seq, a, frame=frame)
        assert np.allclose(num, ref, rtol=0, atol=1e-14)


@pytest.mark.exhaustive
@pytest.mark.parametrize("seq", SEQS24)
def test_symbolic_euler_rate_matrix_inverse_all_sequences(seq):
    import sympy as sp

    syms = sp.symbols("a0:3", real=True)
    a = np.array([0.7, 0.4, -1.1])
    for frame in ("world", "body"):
        Ei = rk.symbolic.euler_rate_matrix_inverse(seq, syms, frame=frame)
        num = np.array(Ei.subs(dict(zip(syms, a))).evalf(), dtype=float)
        E = rk.kinematics.euler_rate_matrix(seq, a, frame=frame)
        assert np.allclose(num @ E, np.eye(3), rtol=0, atol=1e-14)


# -- 7. Rotation2D.from_complex: the modulus, zero, and other namespaces --------------


def test_from_complex_divides_out_the_modulus_as_from_quat_does():
    rng = np.random.default_rng(31)
    z = rng.standard_normal(5) * 10 + 1j * rng.standard_normal(5) * 10
    R = rk.Rotation2D.from_complex(z)
    assert np.allclose(R.angle, np.angle(z), rtol=0, atol=1e-15)  # NumPy's angle
    # the same policy as from_quat: any nonzero scale is the same rotation
    q = rk.Rotation.from_quat([2.0, 0.0, 0.0, 0.0]).as_quat()
    assert np.array_equal(q, [1.0, 0.0, 0.0, 0.0])
    with pytest.raises(rk.ZeroNormError) as e:
        rk.Rotation2D.from_complex(np.array([1.0 + 1.0j, 0.0j, 2.0j]))
    assert e.value.index == (1,)
    with pytest.raises(rk.ZeroNormError):
        rk.Rotation.from_quat([0.0, 0.0, 0.0, 0.0])
    with pytest.raises(rk.NonFiniteError) as e:
        rk.Rotation2D.from_complex(np.array([1.0j, complex(np.nan, 1.0)]))
    assert e.value.index == (1,)


def test_from_complex_keeps_jax_and_dask():
    jnp = pytest.importorskip("jax.numpy")
    da = pytest.importorskip("dask.array")
    from dask.callbacks import Callback

    z = np.array([2.0j, 3.0 + 4.0j, -1.0 + 0.0j])
    ref = np.angle(z)
    j = rk.Rotation2D.from_complex(jnp.asarray(z))
    assert type(j.angle).__module__.startswith("jax")
    assert np.allclose(np.asarray(j.angle), ref, rtol=0, atol=1e-6)
    computes = []

    class Count(Callback):
        def _start(self, dsk):
            computes.append(1)

    with Count():
        d = rk.Rotation2D.from_complex(da.from_array(z, chunks=2))
        d_bad = rk.Rotation2D.from_complex(da.from_array(np.array([1j, 0j]), chunks=1))
    assert computes == []
    assert np.allclose(d.angle.compute(), ref, rtol=0, atol=1e-15)
    with pytest.raises(rk.ZeroNormError) as e:
        d_bad.angle.compute()
    assert e.value.index == (1,)
