"""SymPy derivations of the kinematics formulas, from the numeric kernels themselves.

Each function evaluates the kernel that rigidkit runs on numbers over SymPy
symbols and returns a simplified ``sympy.Matrix``, so the formula printed is the
formula computed (and an oracle for tests):

* :func:`euler_matrix` -- ``R`` of an Euler sequence (``quat_from_euler``, then
  ``matrix_from_quat``: products of half-angle terms, rewritten in full angles);
* :func:`euler_rate_matrix` -- ``E`` with ``omega = E d(angles)/dt``
  (``rate_matrix_from_euler``);
* :func:`euler_rate_matrix_inverse` -- ``E^-1`` with ``d(angles)/dt = E^-1 omega``
  (``rate_matrix_inverse_from_euler``; the pseudo-inverse ``E^T`` for one or two
  axes);
* :func:`quaternion_matrix` -- the matrix of ``v -> q v q^-1`` for any nonzero
  ``q`` (``quat_multiply``, ``quat_conjugate``; ``q^-1 = q* / |q|^2``);
* :func:`twist_exp` -- ``exp(hat(V) t)`` of a twist ``(v, omega)``
  (``pose_from_twist``, ``matrix_from_pose``).

Special-case branches of the kernels (small-angle series below a threshold) are
taken at a generic point, where the closed form holds: the results are the
mathematics, valid away from the removable singularities (``omega = 0`` for
:func:`twist_exp`), as in ``rigidkit.symbolic(closed_form=True)``.

>>> import sympy as sp
>>> a, b, c = sp.symbols("alpha beta gamma", real=True)
>>> euler_rate_matrix("XYZ", (a, b, c), frame="world")
Matrix([
[1,          0,             sin(beta)],
[0, cos(alpha), -sin(alpha)*cos(beta)],
[0, sin(alpha),  cos(alpha)*cos(beta)]])
"""

from __future__ import annotations

from fractions import Fraction

import sympy as sp

from .._engine.primitives import sympy_bindings
from ..functional.euler import parse_sequence, parse_short_sequence
from ..kernels import euler as _euler
from ..kernels import matrix as _matrix
from ..kernels import quaternion as _quat
from ..kernels import se3 as _se3
from ..kernels.kinematics import euler_rates as _ke
from .kinematics._common import body_flag

__all__ = [
    "euler_matrix",
    "euler_rate_matrix",
    "euler_rate_matrix_inverse",
    "quaternion_matrix",
    "twist_exp",
]


def _exact(expr):
    """Float literals of the kernels as the exact small rationals they spell."""

    def rational(f):
        q = Fraction(float(f)).limit_denominator(10**6)
        return sp.Rational(q.numerator, q.denominator) if float(q) == float(f) else f

    return expr.xreplace({f: rational(f) for f in expr.atoms(sp.Float)})


def _generic_bindings(symbols):
    """SymPy primitives whose ``where`` takes the branch chosen at a generic point.

    The point gives every symbol a large, distinct value (so every series
    threshold is passed and the closed forms are chosen).
    """
    point = {s: sp.Float(101.3 + 2.7 * k) for k, s in enumerate(symbols)}
    env = dict(sympy_bindings())

    def where(cond, a, b):
        if isinstance(cond, bool) or cond in (sp.true, sp.false):
            return a if bool(cond) else b
        return a if bool(cond.xreplace(point)) else b

    env["where"] = where
    return env


def _symbols(symbols, names, n):
    if symbols is None:
        return sp.symbols(names, real=True)
    out = tuple(sp.sympify(s) for s in symbols)
    if len(out) != n:
        raise ValueError(f"expected {n} symbols, got {len(out)}")
    return out


def _full_angles(expr, pairs):
    """Rewrite products of half-angle terms in full angles.

    ``pairs`` maps ``(cos(h), sin(h))`` to the full angle ``2h``. Each entry is a
    polynomial of degree 2 in every pair (a quadratic form in the quaternion),
    so ``c^2 = (1 + cos)/2``, ``s^2 = (1 - cos)/2`` and ``c s = sin/2`` rewrite it
    exactly.
    """
    gens = []
    sub = {}
    for k, (ch, sh, full) in enumerate(pairs):
        c, s = sp.Dummy(f"c{k}"), sp.Dummy(f"s{k}")
        sub[ch] = c
        sub[sh] = s
        gens.append((c, s, full))
    e = sp.expand(expr.xreplace(sub))
    for c, s, full in gens:
        e = sp.expand(e)
        terms = sp.Add.make_args(e)
        out = 0
        for t in terms:
            pc = sp.degree(t, c)
            ps = sp.degree(t, s)
            rest = t / (c**pc * s**ps)
            if (pc, ps) == (2, 0):
                factor = (1 + sp.cos(full)) / 2
            elif (pc, ps) == (0, 2):
                factor = (1 - sp.cos(full)) / 2
            elif (pc, ps) == (1, 1):
                factor = sp.sin(full) / 2
            elif (pc, ps) == (0, 0):
                factor = 1
            else:
                factor = c**pc * s**ps
            out += rest * factor
        e = out
    return sp.expand(e)


def euler_matrix(seq, symbols=None):
    """Rotation matrix of the Euler sequence ``seq`` over symbols, as ``sympy.Matrix``.

    Conventions as ``from_euler``: UPPERCASE intrinsic (``"XYZ"`` is ``Rx(a) Ry(b)
    Rz(c)``), lowercase extrinsic. Built from the kernels ``quat_from_euler`` and
    ``matrix_from_quat`` (products of half-angle cosines and sines, rewritten
    exactly in the full angles).

    Parameters
    ----------
    seq : str
    symbols : sequence of 3 SymPy expressions, optional
        The angles in ``seq`` order (default real ``alpha, beta, gamma``).

    Examples
    --------
    >>> import sympy as sp
    >>> phi, theta, psi = sp.symbols("phi theta psi", real=True)
    >>> euler_matrix("ZYX", (psi, theta, phi))[2, :]
    Matrix([[-sin(theta), sin(phi)*cos(theta), cos(phi)*cos(theta)]])
    """
    s = parse_sequence(seq)
    angles = _symbols(symbols, "alpha beta gamma", 3)
    half = tuple(sp.Dummy(f"h{k}", real=True) for k in range(3))
    fn = _euler.quat_from_euler.bound(_generic_bindings(half))
    q = fn(*s.params, sp.Integer(1), *(2 * h for h in half))
    m = _matrix.matrix_from_quat.bound(_generic_bindings(half))(*q)
    pairs = [(sp.cos(h), sp.sin(h), a) for h, a in zip(half, angles)]
    return sp.Matrix(3, 3, [_full_angles(_exact(sp.sympify(e)), pairs) for e in m])


def euler_rate_matrix(seq, symbols=None, *, frame):
    """``E`` with ``omega = E @ d(angles)/dt`` over symbols, as ``sympy.Matrix``.

    From the kernel ``rate_matrix_from_euler`` (all 24 sequences; ``frame`` as in
    :func:`rigidkit.kinematics.euler_rate_matrix`).

    Parameters
    ----------
    seq : str
        Three letters, or one or two (``"ZX"``: ``E`` is 3 x n).
    symbols : sequence of n SymPy expressions, optional
        The angles in ``seq`` order (default real ``alpha, beta, gamma``).
    frame : {"world", "body"}

    Examples
    --------
    The body matrix of intrinsic ``"ZYX"`` (yaw ``psi``, pitch ``theta``, roll
    ``phi``), its columns reordered to ``(phi', theta', psi')``:

    >>> import sympy as sp
    >>> phi, theta, psi = sp.symbols("phi theta psi", real=True)
    >>> euler_rate_matrix("ZYX", (psi, theta, phi), frame="body")[:, ::-1]
    Matrix([
    [1,         0,         -sin(theta)],
    [0,  cos(phi), sin(phi)*cos(theta)],
    [0, -sin(phi), cos(phi)*cos(theta)]])
    """
    n, e = _rate_entries(seq, symbols, frame, inverse=False)
    E = sp.Matrix(3, 3, [sp.expand(_exact(sp.sympify(x))) for x in e])
    return E[:, :n]


def _rate_entries(seq, symbols, frame, *, inverse):
    """``n`` and the 9 row-major entries of ``E`` (or of ``E^-1``) over symbols.

    The kernel ``rate_matrix_from_euler``; with ``inverse``,
    ``rate_matrix_inverse_from_euler``, or ``rate_matrix_transpose_from_euler``
    for one or two axes (``"ZX"``), which are padded with turns by 0, as
    ``from_euler`` pads them (:func:`~rigidkit.functional.euler.parse_short_sequence`).
    """
    name = "euler_rate_matrix_inverse" if inverse else "euler_rate_matrix"
    body = body_flag(frame, f"symbolic.{name}")
    if isinstance(seq, str) and len(seq) == 3:
        s, n = parse_sequence(seq), 3
    else:
        s, n = parse_short_sequence(seq)
    angles = _symbols(symbols, " ".join(("alpha", "beta", "gamma")[:n]) + ",", n)
    padded = tuple(angles) + (sp.Integer(0),) * (3 - n)
    if not inverse:
        k = _ke.rate_matrix_from_euler
    elif n < 3:
        k = _ke.rate_matrix_transpose_from_euler
    else:
        k = _ke.rate_matrix_inverse_from_euler
    e = k.bound(_generic_bindings(angles))(*s.params, body, sp.Integer(1), *padded)
    return n, e[:9]


def euler_rate_matrix_inverse(seq, symbols=None, *, frame):
    """``E^-1`` with ``d(angles)/dt = E^-1 @ omega`` over symbols, as ``sympy.Matrix``.

    From the kernel ``rate_matrix_inverse_from_euler`` (rows the angles in ``seq``
    order, columns ``x, y, z``; ``frame`` as in
    :func:`rigidkit.kinematics.euler_rate_matrix_inverse`), simplified. It is
    singular at gimbal lock: the entries divide by ``cos`` (Tait-Bryan) or
    ``sin`` (proper) of the middle angle. For one or two axes (``"ZX"``), the
    pseudo-inverse ``E^T`` (n x 3), the columns of ``E`` being orthonormal.

    Parameters
    ----------
    seq, symbols, frame
        As in :func:`euler_rate_matrix`.

    Examples
    --------
    For intrinsic ``"ZYX"`` (yaw ``psi``, pitch ``theta``, roll ``phi``), in the
    body frame: the rows ``psi'`` (top) to ``phi'``, from ``omega_body``:

    >>> import sympy as sp
    >>> phi, theta, psi = sp.symbols("phi theta psi", real=True)
    >>> euler_rate_matrix_inverse("ZYX", (psi, theta, phi), frame="body")
    Matrix([
    [0, sin(phi)/cos(theta), cos(phi)/cos(theta)],
    [0,            cos(phi),           -sin(phi)],
    [1, sin(phi)*tan(theta), cos(phi)*tan(theta)]])
    """
    n, e = _rate_entries(seq, symbols, frame, inverse=True)
    E = sp.Matrix(3, 3, [sp.simplify(_exact(sp.sympify(x))) for x in e])
    return E[:n, :]


def quaternion_matrix(symbols=None):
    """Matrix of ``v -> q (0, v) q^-1`` for a nonzero quaternion ``q = (w, x, y, z)``.

    ``q^-1 = q* / |q|^2``, so this is the rotation matrix of ``q / |q|`` for any
    scale: ``(1/|q|^2) [[w^2 + x^2 - y^2 - z^2, 2(xy - wz), 2(xz + wy)], ...]``,
    which for a unit quaternion is the usual ``[[1 - 2(y^2 + z^2), ...]]``.
    Built from the
    kernels ``quat_multiply`` and ``quat_conjugate``.

    Parameters
    ----------
    symbols : sequence of 4 SymPy expressions, optional
        ``(w, x, y, z)``, default real ``w, x, y, z``.

    Examples
    --------
    >>> import sympy as sp
    >>> w, x, y, z = sp.symbols("w x y z", real=True)
    >>> R = quaternion_matrix((w, x, y, z))
    >>> sp.factor(R[0, 1])
    2*(-w*z + x*y)/(w**2 + x**2 + y**2 + z**2)
    """
    q = _symbols(symbols, "w x y z", 4)
    env = _generic_bindings(q)
    mul = _quat.quat_multiply.bound(env)
    conj = _quat.quat_conjugate.bound(env)(*q)
    norm2 = mul(*q, *conj)[0]
    v = sp.symbols("v_x v_y v_z", real=True)
    image = mul(*mul(*q, 0, *v), *conj)
    rows = [[sp.diff(image[1 + i], v[j]) / norm2 for j in range(3)] for i in range(3)]
    return sp.Matrix(rows).applyfunc(lambda e: sp.factor(sp.expand(_exact(e))))


def twist_exp(symbols=None, t=None):
    """``exp(hat(V) t)`` of a twist ``V = (v, omega)``, ``omega != 0``, as a 4x4 Matrix.

    From the kernels ``pose_from_twist`` (applied to ``V t``) and
    ``matrix_from_pose``; the rotation block is Rodrigues' formula, the
    translation ``(I - R)(omega x v)/|omega|^2 + omega omega^T v t / |omega|^2``
    (Murray, Li & Sastry 1994, Sec. 2.3.2, with ``omega`` not normalised).

    Parameters
    ----------
    symbols : sequence of 6 SymPy expressions, optional
        ``(v_x, v_y, v_z, w_x, w_y, w_z)``, default real symbols of those names.
    t : SymPy expression, optional
        Time, default a positive symbol ``t``.

    Examples
    --------
    >>> import sympy as sp
    >>> M = twist_exp()
    >>> M[3, :]
    Matrix([[0, 0, 0, 1]])
    """
    V = _symbols(symbols, "v_x v_y v_z w_x w_y w_z", 6)
    t = sp.Symbol("t", positive=True) if t is None else sp.sympify(t)
    env = _generic_bindings((*V, t))
    pose = _se3.pose_from_twist.bound(env)(*(c * t for c in V))
    m = _se3.matrix_from_pose.bound(env)(*pose)
    theta = sp.sqrt(sum(sp.expand((c * t) ** 2) for c in V[3:]))
    ch, sh = sp.cos(theta / 2), sp.sin(theta / 2)
    entries = []
    for e in m:
        e = _exact(sp.sympify(e))
        entries.append(sp.factor_terms(sp.together(_full_angles(e, [(ch, sh, theta)]))))
    return sp.Matrix(4, 4, entries)
