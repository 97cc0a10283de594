"""Helpers and rebinding: one scalar function, evaluated with other primitives.

A kernel (:mod:`.kernel`) or a :func:`helper` is a plain Python function whose free
names are primitives (:mod:`.primitives`) and the helpers and kernels its module
defines or imports. Binding it to a backend is giving it other globals:
:func:`rebind` makes a copy of the function whose globals are a dict of
primitives (``math`` for Python floats, ``xp`` functions for an array namespace,
SymPy for symbols) plus the rebound helpers it calls. Over Python floats the
function is first rewritten so that ``where(c, a, b)`` is ``a if c else b``
(:func:`_scalar_version`).

>>> import math
>>> from rigidkit._engine import helper, rebind
>>> @helper
... def hypot2(x, y):
...     return sqrt(x * x + y * y)
>>> rebind(hypot2.fn, {"sqrt": math.sqrt})(3.0, 4.0)
5.0
"""

from __future__ import annotations

import builtins
import types

from .primitives import PRIMITIVES, math_bindings


def function_source(fn) -> str:
    """Source of ``fn`` without decorators, dedented."""
    import inspect  # these imports cost ~20 ms, paid only when a kernel is compiled
    import textwrap

    src = textwrap.dedent(inspect.getsource(fn))
    lines = src.splitlines()
    start = next(i for i, line in enumerate(lines) if line.lstrip().startswith("def "))
    return "\n".join(lines[start:]) + "\n"


def _free_names(fn) -> set[str]:
    names = set(fn.__code__.co_names)
    for const in fn.__code__.co_consts:
        if isinstance(const, types.CodeType):
            names |= set(const.co_names)
    return names


def rebind(fn, bindings: dict):
    """A copy of ``fn`` whose globals are ``bindings`` (primitives + helpers).

    The public way to evaluate a kernel's or helper's function (``.fn``) with
    other primitives: :mod:`rigidkit.applications.symbolic` binds helpers to its
    own SymPy closed forms with it.
    """
    return types.FunctionType(fn.__code__, bindings, fn.__name__, fn.__defaults__)


class _Rebindable:
    """Shared machinery of helpers and kernels: dependency walk and rebinding.

    A function's callees are resolved in its own module, at definition: every free
    name that is not a primitive is a :class:`Helper` or :class:`Kernel` (whose
    scalar function is then called like a helper) that the module defines or
    imports under its own name. There is no global registry, so two modules may
    each have a helper ``f``; but one function's callees, transitively, must
    have distinct names (the numba binding writes them into one module), which
    is checked here.
    """

    #: See :func:`helper`; kernels are never ``numerical``.
    numerical = False

    def __init__(self, fn):
        self.fn = fn
        self.name = fn.__name__
        self.__doc__ = fn.__doc__
        self.__wrapped__ = fn
        self._deps = self._resolve()

    def _resolve(self) -> list[_Rebindable]:
        """The callees of ``fn``, transitively, callees first (see the class doc)."""
        order: list[_Rebindable] = []
        seen: dict[str, _Rebindable] = {self.name: self}
        for name in sorted(_free_names(self.fn)):
            if name in PRIMITIVES:
                continue
            callee = self.fn.__globals__.get(name)
            if not isinstance(callee, _Rebindable):
                if _is_builtin(name):
                    continue
                raise NameError(
                    f"kernel {self.name} uses {name!r}, which is neither a primitive "
                    f"nor a helper or kernel of its module {self.fn.__module__}"
                )
            if callee.name != name:
                raise NameError(
                    f"kernel {self.name} calls {callee.name!r} as {name!r}: import "
                    f"helpers under their own name"
                )
            for dep in (*callee._deps, callee):
                prev = seen.setdefault(dep.name, dep)
                if prev is dep:
                    if dep not in order:
                        order.append(dep)
                    continue
                raise NameError(
                    f"kernel {self.name} depends on two functions named {dep.name!r} "
                    f"(from {prev.fn.__module__} and {dep.fn.__module__}); rename one"
                )
        return order

    def dependencies(self) -> list[_Rebindable]:
        """Helpers (and kernels) called by this function, transitively, callees first."""
        return list(self._deps)

    def bound(self, primitives: dict, *, scalar=False):
        """This function with ``primitives`` and rebound helpers as its globals.

        ``scalar=True`` (Python floats) first rewrites ``where(c, a, b)`` into
        ``a if c else b`` (see :func:`_scalar_version`): several times faster,
        and only the branch taken is evaluated.
        """
        make = _scalar_version if scalar else rebind
        env = dict(primitives)
        env["__builtins__"] = builtins
        for dep in self.dependencies():
            env[dep.name] = make(dep.fn, env)
        return make(self.fn, env)


def _inline_branches():
    """A transformer: ``where(c, a, b)`` -> ``(a if c else b)``; max/min likewise."""
    import ast

    class InlineBranches(ast.NodeTransformer):
        """``where(c, a, b)`` -> ``(a if c else b)``; ``maximum``/``minimum`` likewise."""

        def visit_Call(self, node):
            self.generic_visit(node)
            if isinstance(node.func, ast.Name) and not node.keywords:
                name, args = node.func.id, node.args
                if name == "where" and len(args) == 3:
                    return ast.IfExp(test=args[0], body=args[1], orelse=args[2])
                if name in ("maximum", "minimum") and len(args) == 2:
                    op = ast.GtE() if name == "maximum" else ast.LtE()
                    a, b = args
                    if isinstance(a, ast.Name) and isinstance(b, ast.Name):
                        test = ast.Compare(left=a, ops=[op], comparators=[b])
                        return ast.IfExp(test=test, body=a, orelse=b)
            return node

    return InlineBranches()


def _scalar_version(fn, env: dict):
    """``fn`` compiled with branches inlined for Python floats (falls back to ``fn``)."""
    import ast  # only when a kernel is first evaluated on Python floats

    try:
        tree = ast.parse(function_source(fn))
    except (OSError, TypeError):  # no source (defined interactively): plain rebind
        return rebind(fn, env)
    tree = ast.fix_missing_locations(_inline_branches().visit(tree))
    namespace = dict(env)
    exec(compile(tree, f"<rigidkit scalar {fn.__name__}>", "exec"), namespace)
    return namespace[fn.__name__]


def _is_builtin(name: str) -> bool:
    return hasattr(builtins, name)


class Helper(_Rebindable):
    """A scalar function shared by kernels (a coefficient with its series, say)."""

    def __init__(self, fn):
        super().__init__(fn)
        self._py = None

    def __call__(self, *args):
        if self._py is None:
            self._py = self.bound(math_bindings(), scalar=True)
        return self._py(*args)


def _refuse_redefinition(fn) -> None:
    """Refuse a second helper or kernel of one name in one module.

    Callees are looked up by name in the module (see :class:`_Rebindable`), so a
    second definition would silently replace the first for every function
    defined after it. Running the same definition again (a module reload) is
    not a second one.
    """
    prev = fn.__globals__.get(fn.__name__)
    if not isinstance(prev, _Rebindable):
        return
    same = (prev.fn.__module__, prev.fn.__code__.co_firstlineno) == (
        fn.__module__,
        fn.__code__.co_firstlineno,
    )
    if not same:
        raise NameError(
            f"{fn.__module__} already has a helper or kernel {fn.__name__!r} (from "
            f"{prev.fn.__module__}, line {prev.fn.__code__.co_firstlineno}); a second "
            f"one of the same name would replace it: rename one"
        )


def helper(fn=None, *, numerical=False):
    """Make ``fn`` a helper that kernels of its module, or importing it, may call.

    ``@helper(numerical=True)`` marks a helper whose ``where`` branches are
    numerical devices, not cases of the mathematics: a series below a threshold
    and the closed form above it, or a safe argument that keeps a gradient
    finite. Its exact value is one function, which the SymPy closed form
    (:mod:`rigidkit.symbolic`) writes as the branch taken at a generic point.
    """

    def make(fn):
        _refuse_redefinition(fn)
        h = Helper(fn)
        h.numerical = numerical
        return h

    return make if fn is None else make(fn)
