"""Owned fast paths: functions of objects that go straight to a kernel's loops.

The library's most frequent calls are methods of objects whose stored array
always has its kind's trailing shape: ``a @ b``, ``a.inv()``,
``Transform.as_matrix()``, ``rk.slerp(a, b, t)``. For those the engine writes
the whole function (:func:`owned_function`): it tests only the types, the dtype
and the batch shape, calls the kernel's compiled loop (its entry point, as the
fast entry of :mod:`.dispatch` does), and makes the result; anything else calls
the function written for the general case, ``slow``. The upper layers declare
such a function (which kernel, which operands, which general function) and
never see its source.

>>> import numpy as np
>>> import rigidkit as rk
>>> R = rk.Rotation.random(3, rng=0)
>>> type(R).inv.__wrapped__ is not type(R).inv   # the owned method wraps the general one
True
>>> np.allclose((R @ R.inv()).as_quat()[:, 0] ** 2, 1.0)
True
"""

from __future__ import annotations

import inspect
import math
import sys

import numpy as np

from . import numba_backend
from .loop_source import SINGLE

__all__ = ["owned_function", "owned_source"]

#: Names the generated lines use; no parameter of an owned function may take one.
_RESERVED = {"ndarray", "empty", "isfinite", "PMIN", "K", "E_batch", "E_single"}
_RESERVED |= {"CLS", "new", "slow", "dt", "s", "loop", "o0", "r"}


def owned_source(kernel, names, result, indent=8, user=()) -> list[str]:
    """Lines that run ``kernel`` on arrays an object owns, straight to its loops.

    For the generated methods of objects (``a @ b``, ``a.inv()``) and functions
    of them (``rk.slerp``): ``names`` are the variables holding the kernel's
    input arrays (no static parameters). Each is known to have the kernel's
    input shape after its batch axes (an object's stored array always has its
    kind's trailing shape), except those also named in ``user``: arrays of the
    caller's, of trailing shape ``()`` here (slerp's ``t``), whose number of
    dimensions is tested here, its length and strides by the loop (status 1),
    and its finiteness too (below). So of the fast entry's checks
    only the exact ``ndarray`` type, the dtype and the batch shapes are left:
    all inputs of one batch shape, one batch axis or none. When the loop ran,
    ``result`` (lines that may read the output ``o0``) ends the method;
    otherwise these lines fall through, and the method goes on to call the
    kernel (its fast entry, or the general path). Runs in the namespace of
    :func:`owned_env`. Saves the kernel call's own frame and its shape tests,
    ~0.3 us of a 1 us ``a @ b`` at N = 10.

    A ``user`` array's finiteness: in a batch the loop tests it, so only a
    ``vector_math`` kernel may have one (its loop's status 2, see
    :func:`.loop_source._loop_source`); the one-element loop reports nothing,
    so these lines test it (``isfinite``).
    """
    (out,) = kernel.outputs
    ins = kernel.inputs
    shared = [k for k, b in enumerate(names) if b not in user]
    if kernel.params or any(ins[k] != ins[0] for k in shared) or shared[0] != 0:
        raise ValueError(f"{kernel.name}: owned_source takes one object shape, no params")
    if any(ins[k] != () for k, b in enumerate(names) if b in user) or (
        user and not kernel.vector_math
    ):
        raise ValueError(
            f"{kernel.name}: user arrays are of shape (), in vector_math kernels"
        )
    pad = " " * indent
    rank = len(ins[0])
    a = names[0]
    batch_out = "(" + ", ".join(["s[0]", *map(str, out)]) + ("," if not out else "") + ")"
    mine = [names[k] for k in shared]
    theirs = [b for b in names if b in user]
    # Chained tests (``type(a0) is ndarray is type(a1)``): each operand once, ~20%
    # of these lines' cost at N = 10. A user array's length is its loop's to test
    # (status 1), as its strides are.
    types = " is ".join([f"type({a}) is ndarray"] + [f"type({b})" for b in names[1:]])
    same = [" is ".join(["dt"] + [f"{b}.dtype" for b in names[1:]])] if names[1:] else []
    same += [f"{b}.shape == s" for b in mine[1:]]
    batch = "".join(f" and {b}.ndim == 1" for b in theirs)
    single = "".join(f" and {b}.ndim == 0 and isfinite({b})" for b in theirs)
    lines = [
        f"if {types}:",
        f"    dt = {a}.dtype",
        f"    s = {a}.shape",
        f"    if {' and '.join(same) or 'True'}:",
        f"        if len(s) == {rank + 1}{batch}:",
        "            loop = E_batch.get(dt)",
        "            if loop is not None and s[0] < PMIN and K.BINDING is None:",
        f"                o0 = empty({'s' if out == ins[0] else batch_out}, dt)",
        f"                if not loop({', '.join(names)}, o0):",
        *["                    " + x for x in result],
        f"        elif len(s) == {rank}{single}:",
        "            loop = E_single.get(dt)",
        "            if loop is not None:",
        f"                o0 = empty({tuple(out)!r}, dt)",
        f"                loop({', '.join(names)}, o0)",
        *["                " + x for x in result],
    ]
    return [pad + x for x in lines]


def owned_env(kernel) -> dict:
    """The names :func:`owned_source`'s lines read, for ``kernel``'s loops."""
    return {
        "ndarray": np.ndarray,
        "empty": np.empty,
        "isfinite": math.isfinite,
        "PMIN": numba_backend.PARALLEL_MIN,
        "K": sys.modules[__package__ + ".kernel"],  # its BINDING, read at each call
        "E_batch": kernel._entry.setdefault((False,) * len(kernel.inputs), {}),
        "E_single": kernel._entry.setdefault(SINGLE, {}),
    }


def owned_function(
    kernel,
    slow,
    cls,
    objects,
    *,
    arrays=(),
    off=(),
    result="object",
    slots=("_data",),
    element=None,
    qualname=None,
):
    """``slow`` made fast for objects of ``cls`` whose stored arrays feed ``kernel``.

    Parameters
    ----------
    kernel : Kernel
        Of the stored arrays alone (no static parameters), one output.
    slow : function
        The general function; the generated one has its signature, name,
        module and docstring (``__wrapped__`` is ``slow``), and calls it for
        every case it does not serve itself.
    cls : type
        The kind of the objects: each parameter named in ``objects`` other than
        ``self`` must be exactly of this type (a method's ``self`` is not
        tested), and a ``result="object"`` is a new ``cls``.
    objects : sequence of str
        Parameters whose stored array (``_data``) is the kernel's next input.
    arrays : sequence of str
        Parameters taken as the kernel's last inputs as they are (arrays of the
        caller's, of trailing shape ``()``, in a ``vector_math`` kernel: see
        :func:`owned_source`).
    off : sequence of str
        Keyword parameters that must be at their default (None or False).
    result : {"object", "array"}
        Wrap the kernel's output in a new ``cls`` (its array written into every
        slot of ``slots``, without ``__init__``), or return the array.
    element : tuple, optional
        The trailing shape of one stored element: if the kernel's inputs (and
        its output, for an object result) are not all of it, or it has static
        parameters, ``slow`` itself is returned.
    qualname : str, optional
        The generated function's ``__qualname__`` (``slow``'s by default).
    """
    shapes = [*kernel.inputs[: len(objects)]]
    if result == "object":
        shapes += kernel.outputs
    if element is not None and (
        kernel.params
        or len(kernel.inputs) != len(objects) + len(arrays)
        or any(tuple(t) != tuple(element) for t in shapes)
    ):
        return slow
    sig = inspect.signature(slow)
    params = list(sig.parameters.values())
    clash = {p.name for p in params} & _RESERVED
    if clash:
        raise ValueError(
            f"{slow.__qualname__}: parameter names {sorted(clash)} are reserved"
        )
    call = []
    for p in params:
        if p.default is not inspect.Parameter.empty and p.default not in (None, False):
            raise ValueError(
                f"{slow.__qualname__}: default of {p.name} is not None or False"
            )
        if p.kind is p.KEYWORD_ONLY:
            call.append(f"{p.name}={p.name}")
        elif p.kind is p.POSITIONAL_OR_KEYWORD:
            call.append(p.name)
        else:
            raise ValueError(
                f"{slow.__qualname__}: *args and positional-only are not owned"
            )
    tested = [b for b in objects if b != "self"]
    conds = []
    if tested:
        conds.append(
            " is ".join([f"type({tested[0]}) is CLS", *(f"type({b})" for b in tested[1:])])
        )
    for name in off:
        default = sig.parameters[name].default
        conds.append(f"{name} is None" if default is None else f"not {name}")
    fallback = f"return slow({', '.join(call)})"
    names = [f"a{k}" for k in range(len(objects))]
    if result == "object":
        done = ["r = new(CLS)", f"r.{' = r.'.join(slots)} = o0", "return r"]
    else:
        done = ["return o0"]
    pad = "        " if conds else "    "
    lines = [f"def {slow.__name__}{sig}:"]
    if conds:
        lines.append(f"    if {' and '.join(conds)}:")
    lines += [f"{pad}{a} = {b}._data" for a, b in zip(names, objects)]
    lines += owned_source(kernel, names + list(arrays), done, len(pad), user=tuple(arrays))
    lines.append(f"    {fallback}")
    qualname = qualname or slow.__qualname__
    env = owned_env(kernel) | {"CLS": cls, "new": object.__new__, "slow": slow}
    exec(compile("\n".join(lines) + "\n", f"<rigidkit {qualname} fast>", "exec"), env)
    fn = env[slow.__name__]
    fn.__qualname__, fn.__module__ = qualname, slow.__module__
    fn.__doc__, fn.__wrapped__ = slow.__doc__, slow
    return fn
