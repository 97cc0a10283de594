"""One cell of the matrix: one example under one transform, checked against NumPy.

* ``jit``: the example traces under ``jax.jit``, with NumPy's output shapes and
  kinds (the values of that traced program are checked, batched, by ``vmap``).
* ``vmap`` / ``torch_vmap``: ``jax.vmap`` / ``torch.func.vmap`` over two draws of the
  batched argument equal the two NumPy calls.
* ``grad`` / ``torch_grad``: the gradient of ``sum_k <W_k, out_k>`` (fixed random
  weights ``W_k`` on every float output) with respect to the differentiated argument,
  by ``jax.grad`` / ``torch.autograd.grad``, equals central finite differences of the
  NumPy call (step 1e-6, float64).
* ``dask``: on Dask arrays the call computes nothing (a scheduler callback counts
  the computes: 0), every output is a Dask array, and ``.compute()`` equals NumPy.
* ``compile``: ``torch.compile(fullgraph=True)`` of the example equals NumPy.

The JAX cells trace the transformed function as ``jax.jit`` does
(``jax.make_jaxpr``: every concretization error of tracing surfaces there); vmap and
grad evaluate the traced program without XLA compiling it: XLA's compile of ~600 traced
programs would cost the CI minutes and exercises XLA, not rigidkit.
``RIGIDKIT_MATRIX_XLA=1`` compiles each with ``jax.jit`` instead.

Everything runs in float64 (JAX with ``jax_enable_x64``, as ``tests/conftest.py``
sets it); values agree between backends to ``Example.atol`` times the result's
scale, gradients to rtol 1e-5 / atol 1e-6 times the gradient's scale.
"""

from __future__ import annotations

import dataclasses
import importlib
import os

import numpy as np

FD_STEP = 1e-6


def leaves(out) -> list:
    """The arrays of a result, flattened in a fixed order (objects give their array)."""
    if out is None or isinstance(out, str):
        return []
    if isinstance(out, (list, tuple)):
        return [leaf for o in out for leaf in leaves(o)]
    if isinstance(out, dict):
        return [leaf for k in sorted(out) for leaf in leaves(out[k])]
    if hasattr(out, "_data"):  # every object of rigidkit holds one array there
        return [out._data]
    if dataclasses.is_dataclass(out) and not isinstance(out, type):
        return leaves([getattr(out, f.name) for f in dataclasses.fields(out)])
    if hasattr(out, "__dict__") and type(out).__module__.startswith("rigidkit"):
        # sorted names, not (name, value) pairs: TorchDynamo cannot sort tensors
        fields = vars(out)
        return leaves([fields[k] for k in sorted(fields) if not k.startswith("__")])
    return [out]


def to_numpy(x):
    if hasattr(x, "detach"):
        return x.detach().cpu().numpy()
    if hasattr(x, "compute"):
        return np.asarray(x.compute(scheduler="sync"))
    return np.asarray(x)


def reference(example, args) -> list:
    return [np.asarray(leaf) for leaf in leaves(example.fn(*args))]


def compare(got, want, atol, what=""):
    got = [to_numpy(g) for g in got]
    assert len(got) == len(want), f"{what}: {len(got)} outputs, NumPy gives {len(want)}"
    for i, (g, w) in enumerate(zip(got, want)):
        assert g.shape == w.shape, f"{what} output {i}: shape {g.shape}, NumPy {w.shape}"
        if w.dtype.kind in "fc":
            scale = max(1.0, float(np.max(np.abs(w), initial=0.0)))
            np.testing.assert_allclose(
                g, w, rtol=0, atol=atol * scale, err_msg=f"{what} {i}"
            )
        else:
            np.testing.assert_array_equal(g, w, err_msg=f"{what} output {i}")


def _jax():
    jax = importlib.import_module("jax")
    jax.config.update("jax_enable_x64", True)  # as tests/conftest.py's jax fixture
    return jax


def _torch():
    return importlib.import_module("torch")


def traced(f, *args):
    """``f(*args)`` as ``jax.jit`` runs it: traced to a jaxpr, then evaluated (compiled
    by XLA only with ``RIGIDKIT_MATRIX_XLA=1``)."""
    jax = _jax()
    if os.environ.get("RIGIDKIT_MATRIX_XLA", "") not in ("", "0"):
        return jax.jit(f)(*args)
    closed, shape = jax.make_jaxpr(f, return_shape=True)(*args)
    flat = jax.tree_util.tree_leaves(args)
    out = importlib.import_module("jax.extend.core").jaxpr_as_fun(closed)(*flat)
    return jax.tree_util.tree_unflatten(jax.tree_util.tree_structure(shape), out)


def run_jit(example):
    """Traces under ``jax.jit`` with NumPy's output shapes and kinds; the values of the
    same traced program are the vmap cell's (all three with ``RIGIDKIT_MATRIX_XLA=1``)."""
    jax = _jax()
    args = example.inputs()
    want = reference(example, args)
    f = lambda *a: leaves(example.fn(*a))  # noqa: E731
    jargs = [jax.numpy.asarray(a) for a in args]
    if os.environ.get("RIGIDKIT_MATRIX_XLA", "") not in ("", "0"):
        compare(jax.jit(f)(*jargs), want, example.atol, "jax.jit")
        return
    shapes = jax.make_jaxpr(f, return_shape=True)(*jargs)[1]
    assert len(shapes) == len(want), f"jax.jit: {len(shapes)} outputs, NumPy {len(want)}"
    for i, (s, w) in enumerate(zip(shapes, want)):
        assert s.shape == w.shape, f"jax.jit output {i}: shape {s.shape}, NumPy {w.shape}"
        assert np.dtype(s.dtype).kind == w.dtype.kind, f"jax.jit output {i}: {s.dtype}"


def _batched(example):
    """Arguments with the batched one stacked from two draws, ``in_axes``, reference."""
    a0, a1 = example.inputs(0), example.inputs(1)
    b = example.batch
    args = list(a0)
    args[b] = np.stack([a0[b], a1[b]])
    refs = []
    for x in (a0[b], a1[b]):
        one = list(a0)
        one[b] = x
        refs.append(reference(example, one))
    want = [np.stack(r) for r in zip(*refs)]
    axes = tuple(0 if i == b else None for i in range(len(args)))
    return args, axes, want


def run_vmap(example):
    jax = _jax()
    args, axes, want = _batched(example)
    f = jax.vmap(lambda *a: leaves(example.fn(*a)), in_axes=axes)
    compare(
        traced(f, *[jax.numpy.asarray(a) for a in args]), want, example.atol, "jax.vmap"
    )


def run_torch_vmap(example):
    torch = _torch()
    args, axes, want = _batched(example)
    f = torch.func.vmap(lambda *a: tuple(leaves(example.fn(*a))), in_dims=axes)
    compare(f(*[torch.as_tensor(a) for a in args]), want, example.atol, "torch.func.vmap")


def _loss(outs, weights, convert):
    total = 0.0
    for leaf, w in zip(outs, weights):
        if w is not None:
            total = total + (leaf * convert(w)).sum()
    return total


def _weights(want):
    rng = np.random.default_rng(1)
    return [rng.standard_normal(w.shape) if w.dtype.kind == "f" else None for w in want]


def finite_differences(example, args, weights):
    d = example.diff
    x0 = np.array(args[d], dtype=np.float64)
    grad = np.zeros_like(x0)
    for j in np.ndindex(x0.shape):
        values = []
        for sign in (1.0, -1.0):
            x = x0.copy()
            x[j] += sign * FD_STEP
            one = list(args)
            one[d] = x
            values.append(_loss(reference(example, one), weights, np.asarray))
        grad[j] = (values[0] - values[1]) / (2 * FD_STEP)
    return grad


def _check_grad(got, fd, what):
    got = to_numpy(got)
    scale = max(1.0, float(np.max(np.abs(fd), initial=0.0)))
    np.testing.assert_allclose(got, fd, rtol=1e-5, atol=1e-6 * scale, err_msg=what)


def run_grad(example):
    jax = _jax()
    jnp = jax.numpy
    args = example.inputs()
    weights = _weights(reference(example, args))
    d = example.diff
    jargs = [jnp.asarray(a) for a in args]

    def loss(x):
        one = list(jargs)
        one[d] = x
        return _loss(leaves(example.fn(*one)), weights, jnp.asarray)

    got = traced(jax.grad(loss), jargs[d])
    _check_grad(got, finite_differences(example, args, weights), "jax.grad")


def run_torch_grad(example):
    torch = _torch()
    args = example.inputs()
    weights = _weights(reference(example, args))
    d = example.diff
    targs = [torch.as_tensor(a) for a in args]
    x = targs[d].clone().requires_grad_(True)
    targs[d] = x
    loss = _loss(leaves(example.fn(*targs)), weights, torch.as_tensor)
    if getattr(loss, "requires_grad", False):
        (got,) = torch.autograd.grad(loss, x, allow_unused=True, materialize_grads=True)
    else:  # no output depends on x (a constant such as so2.ad): the gradient is 0
        got = torch.zeros_like(x)
    _check_grad(got, finite_differences(example, args, weights), "torch autograd")


def run_dask(example):
    da = importlib.import_module("dask.array")
    from dask.callbacks import Callback

    if example.series:  # the batched argument's axis 0 is a series: chunk it in two
        args = example.inputs()
        b = example.batch
        chunks = [a.shape if a.ndim else () for a in args]
        n = args[b].shape[0]
        chunks[b] = ((n + 1) // 2,) + args[b].shape[1:]
    else:  # two draws stacked along a new batch axis, one chunk each
        args, _, _ = _batched(example)
        chunks = [a.shape if np.ndim(a) else () for a in args]
        chunks[example.batch] = (1,) + args[example.batch].shape[1:]
    want = reference(example, args)
    dargs = [da.from_array(np.asarray(a), chunks=c) for a, c in zip(args, chunks)]

    class Count(Callback):
        starts = 0

        def _start(self, dsk):
            Count.starts += 1

    with Count():
        out = leaves(example.fn(*dargs))
    assert Count.starts == 0, f"the call computed the graph {Count.starts} time(s)"
    eager = [type(o).__name__ for o in out if not type(o).__module__.startswith("dask")]
    assert not eager, f"outputs returned computed, not lazily: {eager}"
    compare(out, want, example.atol, "dask")


def run_compile(example):
    torch = _torch()
    args = example.inputs()
    want = reference(example, args)
    # Every cell's lambda is the same code object: without a reset its compiles
    # count against one recompile limit (8), and from the ninth cell of a sweep on
    # fullgraph fails with "recompile limit exceeded", whatever the callable.
    torch._dynamo.reset()
    f = torch.compile(lambda *a: tuple(leaves(example.fn(*a))), fullgraph=True)
    compare(f(*[torch.as_tensor(a) for a in args]), want, example.atol, "torch.compile")


RUNNERS = {
    "jit": run_jit,
    "vmap": run_vmap,
    "grad": run_grad,
    "torch_grad": run_torch_grad,
    "torch_vmap": run_torch_vmap,
    "dask": run_dask,
    "compile": run_compile,
}
# The optional backend each transform needs (tests/conftest.py's ``needs`` marker).
NEEDS = {
    "jit": "jax",
    "vmap": "jax",
    "grad": "jax",
    "torch_grad": "torch",
    "torch_vmap": "torch",
    "dask": "dask_array",
    "compile": "torch",
}


def run(example, transform):
    RUNNERS[transform](example)
