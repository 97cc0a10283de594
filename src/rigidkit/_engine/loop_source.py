"""The source of a kernel's numba loops (and of a chain's scan), generated as text.

For each kernel and broadcast pattern we write one small Python module
(:func:`module_source`): the primitive prelude, the source of the kernel and of
every helper it calls (each ``@numba.njit``, inlined into the loop), and a loop
over the batch that reads the components of each input, calls the kernel, and
writes each output component. :mod:`.numba_backend` imports it from the disk
cache and compiles it. Nothing here imports numba: this is text.

The same generator writes the scan of :func:`scan_source` (a running product of
a ``chain`` kernel along the steps of each trajectory), which
:func:`.host_loops.compile_scan` compiles, and the fold of :func:`fold_source` (a
running state and running sums, only the last written), which
:func:`.host_loops.compile_fold` compiles.
"""

from __future__ import annotations

from .binding import function_source
from .primitives import NUMBA_PRELUDE, numba_prelude

#: Rows at most this wide are read and written through flat 1-D views with a
#: constant stride (``a[4 * i + c]``), which LLVM vectorises; wider rows (3x3
#: matrices) stay 2-D (``a[i, c]``): a stride-9 interleaved store vectorises badly.
FLAT_MAX = 4


#: Outputs wider than ``FLAT_MAX`` whose last axis is this long (4x4 and 3x4
#: matrices), in a loop that writes more numbers than it reads, are written a row
#: at a time, each row one vector store (:func:`.numba_stores.store_row`): numba
#: writes a component at a time, and LLVM does not merge those stores. Such a loop
#: waits on its stores: SE(3) ``Transform.as_matrix`` (7 in, 16 out), with the
#: cheaper off-diagonal of ``matrix_entries_from_quat``, 4.7 -> 4.3 us at N = 1e3,
#: 41 -> 38 us at 1e4 (scipy's copy: 3.5 and 32); the loops of ``quat_left_matrix``
#: and ``se3.hat`` -35%, ``sim3_matrix`` -10%. A loop that computes more than it
#: stores waits on its arithmetic, and building the vectors costs it shuffles:
#: ``projective_compose`` (32 in, 16 out) +5%, so it keeps scalar stores.
ROW_STORE = 4


#: The broadcast pattern of a kernel's one-element loop: every input and output of
#: exactly its trailing shape (no batch axis), one evaluation, no loop.
SINGLE = "single"


def _single_source(kernel) -> str:
    """One evaluation on arrays of exactly their trailing shapes (see ``SINGLE``).

    Inputs are read by their own indices (``A0[1, 2]``), not through a flat view:
    they may be strided (see :func:`signature`). Outputs are written by theirs
    too: a ``reshape`` would be numba's ``normalize_reshape_value``, whose
    environment, read back with the loop from the disk cache, imports
    ``numba.np.arrayobj`` (20 ms of the background thread's ~170 before a
    script's first loop is ready).
    """
    nparams = len(kernel.params)
    args = [f"p{k}" for k in range(nparams)]
    call = [f"p{k}" for k in range(nparams)]
    for k, shape in enumerate(kernel.inputs):
        args.append(f"A{k}")
        call += [f"A{k}[{index}]" for index in _indices(shape)]
    body = [f"    r = {kernel.name}({', '.join(call)})"]
    j = 0
    for k, shape in enumerate(kernel.outputs):
        args.append(f"O{k}")
        for index in _indices(shape):
            body.append(f"    O{k}[{index}] = r[{j}]")
            j += 1
    return f"def loop({', '.join(args)}):\n" + "\n".join(body) + "\n"


def _indices(shape) -> list[str]:
    """The index of each element of an array of ``shape``, in C order: ``"1, 2"``
    (a 0-d array's: ``"()"``)."""
    out = []
    for c in range(_size(shape)):
        index, rest = [], c
        for d in reversed(shape):
            index.insert(0, str(rest % d))
            rest //= d
        out.append(", ".join(index) or "()")
    return out


def _loop_source(kernel, bcast=()) -> str:
    """The loop over the batch, on arrays of their natural shape.

    Arguments: the static parameters, one C-contiguous array per input of shape
    ``(n, *input_shape)`` (a broadcast input, flagged in ``bcast``: its single row,
    flattened), then one per output of shape ``(n, *output_shape)``. Rows at most
    ``FLAT_MAX`` wide are read through flat views with a constant stride
    (``a[4 * i + c]``), which LLVM vectorises; the loop runs over ``range(n)``
    (a known non-negative index). A broadcast row is read once, before the loop.
    """
    nparams = len(kernel.params)
    args = [f"p{k}" for k in range(nparams)]
    pre = ["    n = O0.shape[0]"]
    strided = []
    call = [f"p{k}" for k in range(nparams)]
    for k, shape in enumerate(kernel.inputs):
        args.append(f"A{k}")
        w = _size(shape)
        if k < len(bcast) and bcast[k]:
            strided += _stride_tests(f"A{k}", (w,), batch=False)
            pre += [f"    b{k}_{c} = A{k}[{c}]" for c in range(w)]
            call += [f"b{k}_{c}" for c in range(w)]
            continue
        # Its length too: a generated function may pass a caller's array whose
        # length it has not tested (owned.owned_source's user arrays).
        strided += [f"A{k}.shape[0] != n", *_stride_tests(f"A{k}", shape)]
        if w <= FLAT_MAX:
            pre.append(f"    a{k} = A{k}.reshape(A{k}.size)")
            call += [f"a{k}[{w} * i + {c}]" for c in range(w)]
        else:
            pre.append(f"    a{k} = A{k}.reshape(n, {w})")
            call += [f"a{k}[i, {c}]" for c in range(w)]
    body = [f"        r = {kernel.name}({', '.join(call)})"]
    j = 0
    for k, shape in enumerate(kernel.outputs):
        args.append(f"O{k}")
        w = _size(shape)
        if _row_stores(kernel, shape):
            pre.append(f"    o{k} = O{k}.reshape(O{k}.size)")
            for c in range(0, w, ROW_STORE):
                row = ", ".join(f"r[{j + d}]" for d in range(ROW_STORE))
                body.append(f"        store_row(o{k}, {w} * i + {c}, ({row},))")
                j += ROW_STORE
            continue
        if w <= FLAT_MAX:
            pre.append(f"    o{k} = O{k}.reshape(O{k}.size)")
        else:
            pre.append(f"    o{k} = O{k}.reshape(n, {w})")
        for c in range(w):
            target = f"o{k}[{w} * i + {c}]" if w <= FLAT_MAX else f"o{k}[i, {c}]"
            body.append(f"        {target} = r[{j}]")
            j += 1
    done = "    return 0"
    if kernel.vector_math:
        # Status 2 if any input or result is not finite, a NaN of the fast sin and
        # cos among them (|x| > 2^19): one sum an element, which a NaN or an
        # infinity keeps non-finite (a sum that overflows only costs a recompute).
        # The or-reduction of a flag vectorises; an early exit would not.
        terms = call[nparams:] + [f"r[{k}]" for k in range(j)]
        body += [f"        v = {' + '.join(terms)}", "        bad |= v - v != 0.0"]
        pre.append("    bad = False")
        done = "    return 2 if bad else 0"
    if strided:  # not C-contiguous, or short: status 1, nothing read or written
        pre[1:1] = [
            "    if n > 0:",
            f"        if {' or '.join(strided)}:",
            "            return 1",
        ]
    head = f"def loop({', '.join(args)}):\n"
    lines = pre + ["    for i in range(n):"] + body + [done]
    return head + "\n".join(lines) + "\n"


def _stride_tests(name, shape, batch=True) -> list[str]:
    """Tests that input ``name``, typed C-contiguous, is not, for a batch of n > 0.

    The fast entry passes an input's array without asking NumPy whether it is
    C-contiguous (``flags.c_contiguous`` costs ~0.05 us an input), so the loop
    asks instead, for nothing: an array's own strides travel with it, whatever
    its type says. ``shape``: the shape after the batch axis, or with
    ``batch=False`` the whole shape (a broadcast row). As in NumPy, an axis of
    length 1 may have any stride, and so may the batch axis of a batch of one.
    """
    tests, step = [], 1
    first = 1 if batch else 0
    for axis in reversed(range(len(shape))):
        if shape[axis] != 1:
            tests.append(f"{name}.strides[{first + axis}] != {step} * {name}.itemsize")
        step *= shape[axis]
    if batch:
        tests.append(f"(n > 1 and {name}.strides[0] != {step} * {name}.itemsize)")
    return tests


def _row_stores(kernel, shape) -> bool:
    """True if a batch loop writes this output a row at a time (see ``ROW_STORE``)."""
    w = _size(shape)
    return (
        w > FLAT_MAX
        and len(shape) > 0
        and shape[-1] == ROW_STORE
        and w > sum(_size(s) for s in kernel.inputs)
    )


def _size(shape) -> int:
    n = 1
    for s in shape:
        n *= s
    return n


def _has_star_call(fn) -> bool:
    """True if ``fn`` calls something with ``*args`` (numba cannot inline that).

    Read from the bytecode (``CALL_FUNCTION_EX``), not by ``ast.parse``: this runs
    on the background thread, and on CPython 3.11 before 3.11.8 two threads that
    build ``ast`` objects at once can make either raise ``SystemError: AST
    constructor recursion depth mismatch`` (CPython gh-106905), in the user's
    thread as much as in ours.
    """
    import dis

    def star(code) -> bool:
        ops = {i.opname for i in dis.get_instructions(code)}
        return "CALL_FUNCTION_EX" in ops or any(
            star(c) for c in code.co_consts if hasattr(c, "co_code")
        )

    return star(fn.__code__)


def module_source(kernel, bcast=(), nogil=False) -> str:
    fns = [*kernel.dependencies(), kernel]
    # With the fast atan2 where it pays (batch loops that numba can vectorise).
    parts = [
        numba_prelude(
            [f.fn for f in fns], batch=bcast != SINGLE, vector_math=kernel.vector_math
        )
    ]
    nargs = len(kernel.params) + sum(_size(s) for s in kernel.inputs)
    # Inlined at numba-IR level, the kernel and its helpers fuse into the loop body
    # (LLVM alone does not inline across numba functions). Numba's inliner cannot
    # take calls with *args, nor very long argument lists (32: a 4x4 times a 4x4).
    inline = nargs < 32 and not any(_has_star_call(f.fn) for f in fns)
    deco = (
        "@numba.njit(inline='always', error_model='numpy')"
        if inline
        else ("@numba.njit(error_model='numpy')")
    )
    for f in fns:
        parts.append("\n\n" + deco + "\n" + function_source(f.fn))
    loop = _single_source(kernel) if bcast == SINGLE else _loop_source(kernel, bcast)
    if bcast != SINGLE and any(_row_stores(kernel, s) for s in kernel.outputs):
        from .numba_stores import VERSION

        # The version is part of the source, hence of the module's name and cache.
        parts.append(
            f"\n\nfrom rigidkit._engine.numba_stores import store_row  # v{VERSION}\n"
        )
    parts.append("\n\n" + loop)
    # numba's disk cache is keyed by the source, not by the options: a loop cached
    # with other options must not be taken for this one.
    parts.append(f"\n# compiled with {sorted(loop_options(nogil).items())!r}\n")
    return "\n".join(parts)


def loop_options(nogil=False) -> dict:
    """The options a loop is compiled with (also written into its module's source).

    A loop allocates nothing, so it needs no NRT (numba's reference counting):
    without it a call unboxes each array without allocating a meminfo for it,
    ~0.1 us less per call (SE(3) compose at one element 1.23 -> 1.04 us). Loops
    keep the GIL: releasing and taking it back costs ~35 ns a call (compose at
    N = 10: 0.20 vs 0.17 us for the loop's call), which only a batch split over
    threads (``nogil=True``, at least ``PARALLEL_MIN`` long, see
    :func:`run_loop`) gets back. That variant is compiled when such a batch
    first comes, in the background; until it is ready, batches run on one thread.
    """
    return {"nogil": nogil, "error_model": "numpy", "_nrt": False}


def scan_source(chain, width: int) -> str:
    """The module of ``scan(body, x0, inc, out)``: running products of ``chain``.

    ``out[b, 0] = x0[b]``, ``out[b, k + 1] = chain(body, out[b, k], inc[b, k])``
    for every trajectory ``b`` and step ``k``; ``chain(body, *a, *b)`` is a kernel
    of two ``width``-vectors (and the frame flag ``body``), inlined.
    """
    fns = [*chain.dependencies(), chain]
    parts = [NUMBA_PRELUDE]
    for f in fns:
        parts.append(
            "\n\n@numba.njit(inline='always', error_model='numpy')\n"
            + function_source(f.fn)
        )
    w = range(width)
    state = ", ".join(f"s{c}" for c in w)
    lines = [
        "def scan(body, x0, inc, out):",
        "    n, steps = inc.shape[0], inc.shape[1]",
        "    for b in range(n):",
        *[f"        s{c} = x0[b, {c}]" for c in w],
        *[f"        out[b, 0, {c}] = s{c}" for c in w],
        "        for k in range(steps):",
        f"            r = {chain.name}(body, {state}, "
        + ", ".join(f"inc[b, k, {c}]" for c in w)
        + ")",
        *[f"            s{c} = r[{c}]" for c in w],
        *[f"            out[b, k + 1, {c}] = s{c}" for c in w],
    ]
    parts.append("\n\n" + "\n".join(lines) + "\n")
    return "\n".join(parts)


def fold_source(step, carried: int, summed: int, inputs) -> str:
    """The module of ``fold(x0, in0, in1, ..., out)``: a running state and sums.

    For every trajectory ``b``: the state ``s = x0[b, :carried]`` and the sums
    ``a = x0[b, carried:]``; for each step ``k``, ``r = step(*s, *in0[b, k],
    *in1[b, k], ...)``, then ``s = r[:carried]`` and ``a += r[carried:]``; at the
    end ``out[b] = (s, a)``. ``step`` is a helper or kernel of scalars (inlined)
    returning ``carried + summed`` numbers; ``inputs`` are the widths of the
    per-step arrays ``(n, N, width)``. Nothing per step is written: a window's
    running product and the sums over its steps in one pass, in registers.
    """
    fns = [*step.dependencies(), step]
    parts = [NUMBA_PRELUDE]
    for f in fns:  # numba's inliner cannot take a call with *args: such a one is called
        inline = "" if _has_star_call(f.fn) else "inline='always', "
        parts.append(
            f"\n\n@numba.njit({inline}error_model='numpy')\n" + function_source(f.fn)
        )
    names = [f"in{j}" for j in range(len(inputs))]
    args = [f"{name}[b, k, {c}]" for name, w in zip(names, inputs) for c in range(w)]
    state = [f"s{c}" for c in range(carried)]
    lines = [
        f"def fold(x0, {', '.join(names)}, out):",
        "    n, steps = in0.shape[0], in0.shape[1]",
        "    for b in range(n):",
        *[f"        s{c} = x0[b, {c}]" for c in range(carried)],
        *[f"        a{c} = x0[b, {carried + c}]" for c in range(summed)],
        "        for k in range(steps):",
        f"            r = {step.name}({', '.join(state + args)})",
        *[f"            s{c} = r[{c}]" for c in range(carried)],
        *[f"            a{c} += r[{carried + c}]" for c in range(summed)],
        *[f"        out[b, {c}] = s{c}" for c in range(carried)],
        *[f"        out[b, {carried + c}] = a{c}" for c in range(summed)],
    ]
    parts.append("\n\n" + "\n".join(lines) + "\n")
    return "\n".join(parts)
