"""The symbolic derivations (issue 8 §7): closed forms derived from the kernels, and
each erratum of the lecture notes listed in docs/errata.md shown (E1, E4, E6, ...).

References: SymPy's own differentiation and matrix exponential of hand-written
elementary rotations, independent of rigidkit's kernels.
"""

import numpy as np
import pytest
import sympy as sp

import rigidkit as rk

S = rk.symbolic
t = sp.Symbol("t", real=True)


def Rx(a):
    return sp.Matrix([[1, 0, 0], [0, sp.cos(a), -sp.sin(a)], [0, sp.sin(a), sp.cos(a)]])


def Ry(a):
    return sp.Matrix([[sp.cos(a), 0, sp.sin(a)], [0, 1, 0], [-sp.sin(a), 0, sp.cos(a)]])


def Rz(a):
    return sp.Matrix([[sp.cos(a), -sp.sin(a), 0], [sp.sin(a), sp.cos(a), 0], [0, 0, 1]])


def vee(W):
    return sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])


def zero(M):
    return sp.simplify(M) == sp.zeros(*M.shape)


def vanishes(M, functions, trials=3):
    """``M`` (in functions of t and their derivatives) is 0 at random values of them.

    The derivatives are replaced by symbols, highest order first, then numbers:
    a check of an identity that needs no simplification (fast)."""
    rng = np.random.default_rng(0)
    for _ in range(trials):
        x = M
        for k in (2, 1, 0):  # highest derivative first: a(t) -> number would erase them
            for f in functions:
                x = x.subs(f.diff(t, k) if k else f, sp.Float(rng.uniform(-2, 2)))
        if max(abs(complex(v)) for v in sp.Matrix(x).evalf()) > 1e-12:
            return False
    return True


phi, theta, psi = sp.symbols("phi theta psi", real=True)


def test_euler_matrices_and_the_r_xyz_erratum():
    """R_XYZ = Rx(phi) Ry(theta) Rz(psi) and R_ZYX, and docs/errata.md E1: a printed
    R_XYZ[2, 1] of ``c(phi) s(psi) s(theta) + s(phi) c(phi)``, whose last factor is
    ``c(psi)``."""
    R = S.euler_matrix("XYZ", (phi, theta, psi))
    assert zero(R - Rx(phi) * Ry(theta) * Rz(psi))
    assert zero(S.euler_matrix("ZYX", (psi, theta, phi)) - Rz(psi) * Ry(theta) * Rx(phi))
    c, s = sp.cos, sp.sin
    correct = c(phi) * s(psi) * s(theta) + s(phi) * c(psi)
    printed = c(phi) * s(psi) * s(theta) + s(phi) * c(phi)
    assert sp.simplify(R[2, 1] - correct) == 0
    assert sp.simplify(R[2, 1] - printed) != 0
    # R_ZYX written out by hand, entry by entry
    zyx_by_hand = sp.Matrix(
        [
            [c(psi) * c(theta), -s(psi) * c(phi) + c(psi) * s(theta) * s(phi),
             s(psi) * s(phi) + c(psi) * s(theta) * c(phi)],
            [s(psi) * c(theta), c(psi) * c(phi) + s(psi) * s(theta) * s(phi),
             -c(psi) * s(phi) + s(psi) * s(theta) * c(phi)],
            [-s(theta), c(theta) * s(phi), c(theta) * c(phi)],
        ]
    )  # fmt: skip
    assert zero(S.euler_matrix("ZYX", (psi, theta, phi)) - zyx_by_hand)


@pytest.mark.parametrize("seq", ["XYZ", "zxz", "yzy", "xzy"])
@pytest.mark.parametrize("frame", ["world", "body"])
def test_euler_rate_matrix_is_the_derivative_of_the_rotation(seq, frame):
    """E from the kernel against vee(R' R^T) / vee(R^T R') of hand-written factors."""
    f = [sp.Function(n, real=True)(t) for n in ("a", "b", "c")]
    axes = {"x": Rx, "y": Ry, "z": Rz}
    factors = [axes[c.lower()](a) for c, a in zip(seq, f)]
    R = (
        factors[0] * factors[1] * factors[2]
        if seq.isupper()
        else (factors[2] * factors[1] * factors[0])
    )
    Rd = R.diff(t)
    W = Rd * R.T if frame == "world" else R.T * Rd
    rates = sp.Matrix([g.diff(t) for g in f])
    E = S.euler_rate_matrix(seq, f, frame=frame)
    assert vanishes(vee(W) - E * rates, f)


def test_rate_matrices_derived():
    """XYZ in world axes, and ZYX in world and body axes with their inverses."""
    al, be, ga = sp.symbols("alpha beta gamma", real=True)
    c, s = sp.cos, sp.sin
    assert S.euler_rate_matrix("XYZ", (al, be, ga), frame="world") == sp.Matrix(
        [[1, 0, s(be)], [0, c(al), -s(al) * c(be)], [0, s(al), c(al) * c(be)]]
    )
    Ew = S.euler_rate_matrix("ZYX", (psi, theta, phi), frame="world")[:, ::-1]
    Eb = S.euler_rate_matrix("ZYX", (psi, theta, phi), frame="body")[:, ::-1]
    assert Ew == sp.Matrix(
        [[c(psi) * c(theta), -s(psi), 0], [s(psi) * c(theta), c(psi), 0], [-s(theta), 0, 1]]
    )
    assert Eb == sp.Matrix(
        [[1, 0, -s(theta)], [0, c(phi), s(phi) * c(theta)], [0, -s(phi), c(phi) * c(theta)]]
    )
    body_inv_by_hand = sp.Matrix(
        [
            [1, s(phi) * sp.tan(theta), c(phi) * sp.tan(theta)],
            [0, c(phi), -s(phi)],
            [0, s(phi) / c(theta), c(phi) / c(theta)],
        ]
    )
    assert zero(Eb.inv() - body_inv_by_hand)


def test_derivative_at_zero_sign_erratum():
    """d/dt Rx(w1 t) Ry(w2 t) Rz(w3 t) at 0 is hat(w), whose (3,1) entry is -w2, not
    the +w2 of docs/errata.md E6."""
    w = sp.symbols("w1 w2 w3", real=True)
    R = S.euler_matrix("XYZ", tuple(wi * t for wi in w))
    D = R.diff(t).subs(t, 0)
    hat = sp.Matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    assert zero(D - hat)
    assert D[2, 0] == -w[1]


def test_rotational_acceleration_erratum():
    """q'' = (hat(w') + hat(w)^2) q, not (hat(w) + hat(w)^2) q (docs/errata.md E3)."""
    f = [sp.Function(n, real=True)(t) for n in ("a", "b", "c")]
    R = S.euler_matrix("ZYX", f)
    rates = sp.Matrix([g.diff(t) for g in f])
    w = S.euler_rate_matrix("ZYX", f, frame="world") * rates

    def hat(v):
        return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    Rdd = R.diff(t, 2)
    assert vanishes(Rdd - (hat(w.diff(t)) + hat(w) ** 2) * R, f)
    assert not vanishes((hat(w) + hat(w) ** 2) * R - Rdd, f)


def test_quaternion_matrix_and_the_inverse_erratum():
    """The rotation matrix of a unit q; for any q, q v q^-1 needs q^-1 = q*/|q|^2
    (q*/|q|, docs/errata.md E2, scales by |q|)."""
    w, x, y, z = sp.symbols("w x y z", real=True)
    R = S.quaternion_matrix((w, x, y, z))
    n2 = w**2 + x**2 + y**2 + z**2
    assert zero(R.T * R - sp.eye(3))
    assert sp.simplify(R.det() - 1) == 0
    by_hand = sp.Matrix(
        [
            [1 - 2 * y**2 - 2 * z**2, 2 * x * y - 2 * w * z, 2 * w * y + 2 * x * z],
            [2 * x * y + 2 * w * z, 1 - 2 * x**2 - 2 * z**2, 2 * y * z - 2 * w * x],
            [2 * x * z - 2 * w * y, 2 * w * x + 2 * y * z, 1 - 2 * x**2 - 2 * y**2],
        ]
    )
    unit = {w: sp.sqrt(1 - x**2 - y**2 - z**2)}
    assert zero((R - by_hand).subs(unit))
    # with q*/|q| the conjugation is |q| R: not a rotation unless |q| = 1
    wrong = R * sp.sqrt(n2)
    assert sp.simplify((wrong.T * wrong)[0, 0] - n2) == 0
    # the kernel's inverse is q*/|q|^2 (rk.symbolic's closed form of quat_inverse)
    inv = S.quat_inverse(w, x, y, z)
    qinv = inv[0] if isinstance(inv, tuple) else inv
    prod = S.quat_multiply([w, x, y, z], list(qinv))
    vals = {w: 0.3, x: -1.2, y: 0.5, z: 2.0}
    np.testing.assert_allclose(
        np.array(prod.subs(vals).evalf(), dtype=float).ravel(), [1, 0, 0, 0], atol=1e-14
    )


def test_twist_exponential_erratum():
    """docs/errata.md E4: exp(hat(V) t) has translation
    (I - R)(w x v)/|w|^2 + w w^T v t/|w|^2, not hat(w) v (I - R)/|w|^2."""
    v = sp.symbols("v_x v_y v_z", real=True)
    w = sp.symbols("w_x w_y w_z", real=True)
    tt = sp.Symbol("t", positive=True)
    M = S.twist_exp((*v, *w), tt)
    vals = {
        v[0]: sp.Rational(3, 10), v[1]: sp.Rational(-7, 10), v[2]: sp.Rational(11, 10),
        w[0]: sp.Rational(2, 5), w[1]: sp.Rational(1, 5), w[2]: sp.Rational(-9, 10),
        tt: sp.Rational(13, 10),
    }  # fmt: skip
    hatV = sp.zeros(4, 4)
    hatV[:3, :3] = sp.Matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    hatV[:3, 3] = sp.Matrix(v)
    ref = np.array((hatV.subs(vals) * vals[tt]).exp().evalf(30), dtype=float)
    ours = np.array(M.subs(vals).evalf(30), dtype=float)
    np.testing.assert_allclose(ours, ref, atol=1e-14)
    Wm, vv = hatV[:3, :3], sp.Matrix(v)
    wv = sp.Matrix(w)
    n2 = wv.dot(wv)
    R = M[:3, :3]
    corrected = (sp.eye(3) - R) * (wv.cross(vv)) / n2 + wv * (wv.T * vv) * tt / n2
    e4 = (sp.eye(3) - R) * Wm * vv / n2  # hat(w) v (I - R) / |w|^2, as a vector
    np.testing.assert_allclose(
        np.array(corrected.subs(vals).evalf(30), dtype=float).ravel(),
        ref[:3, 3],
        atol=1e-14,
    )
    assert (
        np.abs(np.array(e4.subs(vals).evalf(30), dtype=float).ravel() - ref[:3, 3]).max()
        > 0.1
    )
    # points are [q; 1]: the last row is (0, 0, 0, 1)
    assert list(M[3, :]) == [0, 0, 0, 1]


def test_symbolic_rate_matrix_is_the_numeric_one():
    rng = np.random.default_rng(3)
    a = rng.uniform(-1, 1, 3)
    for seq in ("ZXZ", "xyz"):
        E = S.euler_rate_matrix(seq, frame="body")
        sym = sp.symbols("alpha beta gamma", real=True)
        num = np.array(E.subs(dict(zip(sym, a))).evalf(), dtype=float)
        np.testing.assert_allclose(
            num, rk.kinematics.euler_rate_matrix(seq, a, frame="body"), atol=1e-15
        )
    with pytest.raises(TypeError, match="'frame'"):
        S.euler_rate_matrix("XYZ")
