"""SymPy forms of rigidkit's kernels: the formulas it evaluates, as expressions.

Every kernel of :mod:`rigidkit.kernels` is here under its own name, generated from
the kernel itself (``Kernel.sympy``), so the symbolic and the numeric formula are
one text. Conventions are the library's: Hamilton quaternions ``(w, x, y, z)``,
active rotations on column vectors, row-major matrices.

>>> import sympy as sp
>>> from rigidkit import symbolic
>>> w, x, y, z = sp.symbols("w x y z", real=True)
>>> R = symbolic.matrix_from_quat(w, x, y, z)
>>> R[0, 1]
-2*w*z + 2*x*y
>>> unit = {w: sp.sqrt(1 - x**2 - y**2 - z**2)}
>>> sp.simplify((R.T * R - sp.eye(3)).subs(unit))
Matrix([
[0, 0, 0],
[0, 0, 0],
[0, 0, 0]])
>>> symbolic.hat(x, y, z)
Matrix([
[ 0, -z,  y],
[ z,  0, -x],
[-y,  x,  0]])

Calling convention
------------------
Arguments are the kernel's static parameters (if any), then its input components:
flat (``matrix_from_quat(w, x, y, z)``) or grouped, one sequence or ``Matrix``
per input (``quat_multiply([w1, x1, y1, z1], q2)``). An output of shape ``()`` is
an expression, ``(n,)`` a column ``Matrix``, ``(n, m)`` an ``n x m`` ``Matrix``;
a kernel with several outputs returns a tuple.

``closed_form=True`` (the default) gives the mathematics: each special-case
coefficient (``sinc``, ``versinc2``, ... of :mod:`rigidkit.kernels.coefficients`,
and every other helper marked ``numerical``: a Taylor series below a threshold
and the closed form above it) appears as its
closed form, ``sin(t)/t``, taken from the coefficient's own code at a generic
(large, positive) argument; and the float literals of the code become the exact
rationals they spell (``0.5`` is ``1/2``). These closed forms hold away from the
coefficients' removable singularities (``sin(t)/t`` is 0/0 at ``t = 0``): for
numbers there, or the exact arithmetic of the numeric kernels, ``closed_form=False``
gives exactly what the kernels evaluate, series and thresholds included, as
``Piecewise``. The branches a kernel or its other helpers take (the sign flip to
``w >= 0``, a zero norm, Shepperd's four cases) stay ``Piecewise`` in both forms;
SymPy decides them where the symbols' assumptions allow (``positive=True``, say).

Names: the kernels of SO(3) and quaternions (modules ``so3``, ``quaternion``,
``matrix``, ``mrp``, ``axis_angle``, ``euler``, ``quaternion_algebra``) are
top-level, and so is any name defined by a single kernel module; every kernel
module is also a namespace (``symbolic.se3.hat``, ``symbolic.so3.left_jacobian``),
and ``symbolic.kinematics`` holds the kernels of every module of
:mod:`rigidkit.kernels.kinematics`, also by module
(``symbolic.kinematics.rotation``). Next to
each ``left_jacobian`` and ``left_jacobian_inverse`` (SO(3), SE(2), SE(3)) stand
``right_jacobian`` and ``right_jacobian_inverse``, the left ones at ``-x``
(``J_r(x) = J_l(-x)``):

>>> w = sp.Matrix(sp.symbols("w0:3", real=True))
>>> sp.simplify(symbolic.so3.right_jacobian(w) - symbolic.left_jacobian(-w))
Matrix([
[0, 0, 0],
[0, 0, 0],
[0, 0, 0]])
"""

from __future__ import annotations

import inspect
import math
import types
from fractions import Fraction

import sympy as sp

from .. import kernels as _kernels_pkg
from .._engine import Helper, Kernel, rebind
from .._engine.primitives import sympy_bindings

#: Kernel modules whose names are top-level, first one first for shared names.
_PREFERRED = (
    "so3",
    "quaternion",
    "matrix",
    "mrp",
    "axis_angle",
    "euler",
    "quaternion_algebra",
)

#: A generic point for a helper's special cases: large, positive, all different.
_GENERIC = (101.3, 103.7, 107.9, 109.1, 113.3, 117.7, 119.9, 123.1, 127.3)


def _generic(k: int) -> sp.Float:
    """The generic value of the ``k``-th scalar argument (any ``k``)."""
    return sp.Float(_GENERIC[k % len(_GENERIC)] + 30.0 * (k // len(_GENERIC)))


def _rational(expr):
    """Float literals as the exact small rationals they spell (0.5 -> 1/2)."""

    def exact(f):
        q = Fraction(float(f)).limit_denominator(10**6)
        return sp.Rational(q.numerator, q.denominator) if float(q) == float(f) else f

    return expr.xreplace({f: exact(f) for f in expr.atoms(sp.Float)})


def _generic_branches(expr, point):
    """Replace each Piecewise by the branch its conditions choose at ``point``."""

    def choose(pw):
        for value, cond in pw.args:
            if cond is sp.true or bool(cond.xreplace(point)):
                return value
        return pw.args[-1].expr

    return expr.replace(lambda e: isinstance(e, sp.Piecewise), choose)


def _closed_helper(helper: Helper, env: dict):
    """A numerical ``helper`` over SymPy, its special cases replaced by the generic branch.

    The helper is expanded once per structure of its arguments (scalars, or
    tuples of scalars) over dummy symbols, its branches chosen at a generic
    point, and the arguments substituted afterwards.
    """
    raw = rebind(helper.fn, env)
    cache: dict = {}

    def call(*args):
        shape = tuple(len(a) if isinstance(a, (tuple, list)) else None for a in args)
        if shape not in cache:
            dummies, dargs = [], []
            for n in shape:
                ds = [sp.Dummy(f"a{len(dummies) + k}", real=True) for k in range(n or 1)]
                dummies += ds
                dargs.append(ds[0] if n is None else tuple(ds))
            point = {d: _generic(k) for k, d in enumerate(dummies)}
            out = raw(*dargs)
            if isinstance(out, tuple):
                out = tuple(_generic_branches(sp.sympify(o), point) for o in out)
            else:
                out = _generic_branches(sp.sympify(out), point)
            cache[shape] = (dummies, out)
        dummies, out = cache[shape]
        sub = dict(zip(dummies, map(sp.sympify, _flatten(args)), strict=True))
        if isinstance(out, tuple):
            return tuple(o.xreplace(sub) for o in out)
        return out.xreplace(sub)

    return call


def _closed_function(kernel: Kernel):
    """The kernel over SymPy with its numerical helpers in closed form.

    Other helpers and kernels it calls are expanded as written, branches
    included, like the kernel's own body.
    """
    env = dict(sympy_bindings())
    for dep in kernel.dependencies():
        env[dep.name] = _closed_helper(dep, env) if dep.numerical else rebind(dep.fn, env)
    return rebind(kernel.fn, env)


def _flatten(args) -> list:
    flat = []
    for a in args:
        if isinstance(a, sp.MatrixBase):
            flat += list(a)
        elif isinstance(a, (list, tuple)):
            flat += _flatten(a)
        elif hasattr(a, "shape") and hasattr(a, "ravel"):  # a NumPy array of symbols
            flat += a.ravel().tolist()
        else:
            flat.append(a)
    return flat


def _shape_outputs(kernel: Kernel, comps):
    outs = []
    pos = 0
    for shape in kernel.outputs:
        m = math.prod(shape)
        part = list(comps[pos : pos + m])
        pos += m
        if not shape:
            outs.append(part[0])
        elif len(shape) == 1:
            outs.append(sp.Matrix(shape[0], 1, part))
        else:
            outs.append(sp.Matrix(shape[0], math.prod(shape[1:]), part))
    return outs[0] if len(outs) == 1 else tuple(outs)


def _make(kernel: Kernel, module: str):
    ncomp = sum(math.prod(s) for s in kernel.inputs)
    nargs = len(kernel.params) + ncomp
    expanded = {}  # static parameters -> (dummies, closed-form components)

    def closed(params, comps):
        """The closed form over dummy symbols, once per set of static parameters.

        Expanding over symbols first keeps the float literals of the code apart
        from the arguments, so they turn into the exact rationals they spell.
        """
        if params not in expanded:
            dummies = tuple(sp.Dummy(f"c{k}", real=True) for k in range(ncomp))
            out = _closed_function(kernel)(*params, *dummies)
            expanded[params] = (dummies, [_rational(sp.sympify(c)) for c in out])
        dummies, out = expanded[params]
        sub = dict(zip(dummies, comps))
        return [c.xreplace(sub) for c in out]

    def symbolic_form(*args, closed_form=True):
        flat = _flatten(args)
        if len(flat) != nargs:
            want = ", ".join(kernel.params) + (", " if kernel.params else "")
            raise TypeError(
                f"{kernel.name} takes {want}{ncomp} input components "
                f"(inputs of shape {kernel.inputs}), got {len(flat)} values"
            )
        params = tuple(flat[: len(kernel.params)])
        comps = [sp.sympify(a) for a in flat[len(kernel.params) :]]
        if not closed_form:
            return _shape_outputs(kernel, kernel.sympy(*params, *comps))
        return _shape_outputs(kernel, closed(params, comps))

    symbolic_form.__name__ = kernel.name
    symbolic_form.__qualname__ = kernel.name
    symbolic_form.__module__ = __name__
    symbolic_form.__doc__ = (
        f"SymPy form of ``rigidkit.kernels.{module}.{kernel.name}``: inputs "
        f"{kernel.inputs}, outputs {kernel.outputs}"
        + (f", static parameters {kernel.params}" if kernel.params else "")
        + ".\n\n(See :mod:`rigidkit.symbolic` for the calling convention.)\n\n"
        + inspect.cleandoc(kernel.fn.__doc__ or "")
    )
    return symbolic_form


def _right(left, name: str):
    """The right Jacobian (or its inverse) from the left one: ``J_r(x) = J_l(-x)``.

    ``exp(x + d) ~ exp(x) exp(J_r(x) d)`` and ``exp(x + d) ~ exp(J_l(x) d) exp(x)``
    to first order in ``d``; since ``exp(-x) = exp(x)^-1``, inverting the second
    at ``-x`` gives the first.
    """

    def right(*args, closed_form=True):
        return left(*[-sp.sympify(a) for a in _flatten(args)], closed_form=closed_form)

    right.__name__ = right.__qualname__ = name
    right.__module__ = __name__
    right.__doc__ = (
        f"SymPy form of the right-side ``{name}``: ``{left.__name__}`` at ``-x`` "
        f"(``J_r(x) = J_l(-x)``), same calling convention.\n\n" + (left.__doc__ or "")
    )
    return right


def _collect():
    by_module: dict[str, dict] = {}
    for mod in _kernels_pkg.modules():
        module = mod.__name__.removeprefix(f"{_kernels_pkg.__name__}.")
        found = {
            obj.name: _make(obj, module)
            for obj in vars(mod).values()
            if isinstance(obj, Kernel) and obj.fn.__module__ == mod.__name__
        }
        if found:
            by_module[module] = found
    for fns in by_module.values():
        for left in ("left_jacobian", "left_jacobian_inverse"):
            if left in fns:
                right = left.replace("left", "right", 1)
                fns.setdefault(right, _right(fns[left], right))
    top: dict[str, object] = {}
    for module in _PREFERRED:
        for name, fn in by_module.get(module, {}).items():
            top.setdefault(name, fn)
    owners: dict[str, list] = {}
    for module, fns in by_module.items():
        for name in fns:
            owners.setdefault(name, []).append(module)
    for name, modules in owners.items():
        if len(modules) == 1:
            top.setdefault(name, by_module[modules[0]][name])
    return by_module, top


def _namespaces(by_module: dict) -> dict:
    """A namespace per kernel module; a subpackage's (``kinematics``) holds its
    modules' namespaces and, flat, all their kernels."""
    spaces = {module: types.SimpleNamespace(**fns) for module, fns in by_module.items()}
    for module, fns in by_module.items():
        parent, _, leaf = module.rpartition(".")
        if parent:
            space = spaces.setdefault(parent, types.SimpleNamespace())
            setattr(space, leaf, spaces[module])
            for name, fn in fns.items():
                vars(space).setdefault(name, fn)
    return {module: space for module, space in spaces.items() if "." not in module}


#: Namespaces of kernel modules since merged or moved (issue 16), kept by name.
_FORMER = {
    "rotvec": "so3",
    "so3_jacobians": "so3",
    "so3_rates": "so3",
    "dual_quaternion": "pose_formats",
    "kinematics_euler": "kinematics",
    "kinematics_integration": "kinematics",
    "kinematics_planar": "kinematics",
    "kinematics_screw": "screw",
}

_BY_MODULE, _TOP = _collect()
_SPACES = _namespaces(_BY_MODULE)
globals().update(_TOP)
for _module, _space in _SPACES.items():
    if _module not in globals():
        globals()[_module] = _space
for _former, _module in _FORMER.items():
    globals().setdefault(_former, _SPACES[_module])

__all__ = sorted(_TOP) + sorted(m for m in _SPACES if m not in _TOP)

# The kinematics derivations (issue 8) live in their own module.
from .symbolic_kinematics import (  # noqa: E402
    euler_matrix,
    euler_rate_matrix,
    euler_rate_matrix_inverse,
    quaternion_matrix,
    twist_exp,
)

__all__ += [
    "euler_matrix",
    "euler_rate_matrix",
    "euler_rate_matrix_inverse",
    "quaternion_matrix",
    "twist_exp",
]
