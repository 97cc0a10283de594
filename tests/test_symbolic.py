"""rk.symbolic Jacobians against SymPy's own differentiation of the exponential.

The reference is independent of the Jacobian kernels: the exponential map
(``matrix_from_rotvec``, ``pose_from_twist`` + ``matrix_from_pose``) is
differentiated by SymPy, and the Jacobians are read off their definitions,

* right: ``exp(x + d) ~ exp(x) exp(J_r(x) d)``, so column ``i`` of ``J_r`` is
  ``vee(X^-1 dX/dx_i)``;
* left: ``exp(x + d) ~ exp(J_l(x) d) exp(x)``, so column ``i`` of ``J_l`` is
  ``vee(dX/dx_i X^-1)``;

evaluated at random points at 30 digits, ``X^-1`` inverted numerically. The
inverses are checked against the numerical inverse of the reference. Points
with a small rotation (``|w| = 0.01``) run the series branches: there the
``closed_form=False`` form is compared, which keeps them.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

sp = pytest.importorskip("sympy")

import rigidkit as rk  # noqa: E402
from rigidkit.objects import registry  # noqa: E402

S = rk.symbolic
TOL = 1e-13


def _so3_vee(M):
    return [M[2, 1], M[0, 2], M[1, 0]]


def _se3_vee(M):
    return [M[0, 3], M[1, 3], M[2, 3], *_so3_vee(M)]


def _se23_vee(M):
    return [M[0, 3], M[1, 3], M[2, 3], M[0, 4], M[1, 4], M[2, 4], *_so3_vee(M)]


def _se2_vee(M):
    return [M[0, 2], M[1, 2], M[1, 0]]


# The reference of each group: (dimension, exp as a matrix of symbols, vee, symbolic
# namespace). Which groups are tested is read from the registry (below), not from here.
REFERENCES = {
    "so3": (3, lambda x: S.matrix_from_rotvec(x), _so3_vee, S.so3),
    "se3": (6, lambda x: S.se3.matrix_from_pose(S.se3.pose_from_twist(x)), _se3_vee, S.se3),
    "se2": (3, lambda x: S.se2.matrix_from_pose(S.se2.pose_from_twist(x)), _se2_vee, S.se2),
    "se23": (
        9,
        lambda x: S.se23.matrix_from_extpose(S.se23.extpose_from_tangent(x)),
        _se23_vee,
        S.se23,
    ),
}


@functools.cache
def _exp_and_derivatives(group):
    n, exp, _, _ = REFERENCES[group]
    x = sp.symbols(f"x0:{n}", real=True)
    X = sp.Matrix(exp(sp.Matrix(x)))
    return x, X, [X.diff(xi) for xi in x]


def _at(M, sub):
    return np.array(sp.Matrix(M).evalf(30, subs=sub).tolist(), dtype=float)


def _reference(group, point):
    """``(J_l, J_r)`` at ``point`` from the derivatives of the exponential."""
    _, _, vee, _ = REFERENCES[group]
    x, X, dX = _exp_and_derivatives(group)
    sub = {xi: sp.Float(v, 30) for xi, v in zip(x, point, strict=True)}
    Xn = _at(X, sub)
    Xinv = np.linalg.inv(Xn)
    dXn = [_at(d, sub) for d in dX]
    left = np.array([vee(sp.Matrix(d @ Xinv)) for d in dXn], dtype=float).T
    right = np.array([vee(sp.Matrix(Xinv @ d)) for d in dXn], dtype=float).T
    return left, right


def _points(group, rng):
    n = REFERENCES[group][0]
    for scale in (0.3, 1.0, 2.5):
        p = rng.standard_normal(n)
        rot = p[-3:] if group != "se2" else p[-1:]
        rot *= scale / np.linalg.norm(rot)
        yield p, False
    p = rng.standard_normal(n)
    rot = p[-3:] if group != "se2" else p[-1:]
    rot *= 0.01 / np.linalg.norm(rot)
    yield p, True


def _eval(fn, point, closed_form):
    """``fn`` at 30-digit Floats (every ``Piecewise`` decided on the way)."""
    M = fn(sp.Matrix([sp.Float(v, 30) for v in point]), closed_form=closed_form)
    return np.array(sp.Matrix(M).evalf(30).tolist(), dtype=float)


def _symbolic_groups():
    """The Lie groups of the registry whose symbolic namespace has the Jacobians."""
    names = []
    for cls in registry.groups(lie=True):
        name = registry.spec(cls).algebra.__name__.rpartition(".")[2]
        if hasattr(getattr(S, name, None), "left_jacobian"):
            names.append(name)
    return names


@pytest.mark.parametrize("group", _symbolic_groups())
def test_jacobians_are_derivatives_of_exp(group):
    assert group in REFERENCES, f"symbolic {group} Jacobians: add its exp to REFERENCES"
    ns = REFERENCES[group][3]
    rng = np.random.default_rng(sum(map(ord, group)))
    for point, small in _points(group, rng):
        left, right = _reference(group, point)
        # closed forms are 0/0 at w = 0; the exact kernels' Piecewise near it
        for closed_form in (False,) if small else (True, False):
            label = f"{group} at {point.round(3)}, closed_form={closed_form}"
            got = {
                "left_jacobian": _eval(ns.left_jacobian, point, closed_form),
                "right_jacobian": _eval(ns.right_jacobian, point, closed_form),
                "left_jacobian_inverse": _eval(
                    ns.left_jacobian_inverse, point, closed_form
                ),
                "right_jacobian_inverse": _eval(
                    ns.right_jacobian_inverse, point, closed_form
                ),
            }
            want = {
                "left_jacobian": left,
                "right_jacobian": right,
                "left_jacobian_inverse": np.linalg.inv(left),
                "right_jacobian_inverse": np.linalg.inv(right),
            }
            for name, ref in want.items():
                err = np.abs(got[name] - ref).max() / max(1.0, np.abs(ref).max())
                assert err < TOL, f"{name}, {label}: error {err:.2e}"


def test_se3_left_jacobian_default_closed_form():
    """The default closed form builds (it raised 'Dummy' object is not subscriptable).

    It is free of the coefficients' thresholds (no ``Piecewise``), and its top-right
    block tends to Barfoot's ``Q(v, 0) = hat(v) / 2`` as the rotation goes to 0
    (``-hat(v) / 2`` for the inverse), evaluated at 50 digits at ``|w| = 1e-10``.
    """
    xi = sp.symbols("x0:6", real=True)
    J = S.se3.left_jacobian(xi)
    Jinv = S.se3.left_jacobian_inverse(xi)
    for M in (J, Jinv):
        assert isinstance(M, sp.MatrixBase) and M.shape == (6, 6)
        assert not M.has(sp.Piecewise)
    v = [sp.Rational(3, 10), sp.Rational(-7, 10), sp.Rational(11, 10)]
    w = [sp.Rational(2, 7 * 10**10), sp.Rational(3, 7 * 10**10), sp.Rational(6, 7 * 10**10)]
    sub = dict(zip(xi, v + w, strict=True))
    Q0 = np.array((S.hat(v) / 2).tolist(), dtype=float)
    for M, sign in ((J, 1.0), (Jinv, -1.0)):
        top_right = np.array(M[:3, 3:].evalf(50, subs=sub).tolist(), dtype=float)
        assert np.abs(top_right - sign * Q0).max() < 1e-9
