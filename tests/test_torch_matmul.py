"""``X @ tensor`` under ``torch.compile(fullgraph=True)``.

TorchDynamo (torch 2.13) turns an ``@`` with a tensor operand into torch's
``matmul`` without calling the object's ``__matmul__``; an object that is no
tensor then breaks the graph ("Missing as_proxy() implementation"), unless it has
``__torch_function__``, which dynamo calls with the operands swapped so that the
tensor comes first. The objects' ``Group.__torch_function__`` turns that call
back into ``X @ p`` while compiling. The reference is scipy's rotation of the
same vectors. torch.compile costs 10-30 s a call here: two compiles in all.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRotation

import rigidkit as rk

torch = pytest.importorskip("torch")

R_VEC = np.array([[0.3, -1.2, 0.5], [2.0, 0.1, -0.4]])
V = np.array([[1.0, 2.0, -3.0], [-0.5, 0.25, 4.0]])


def test_matmul_with_a_tensor_traces_under_fullgraph():
    """``R @ v`` compiles without a graph break and rotates as scipy does; the
    reversed ``v @ R`` (a TypeError eager) compiles to ``R @ v`` too, since
    dynamo hands both to ``__torch_function__`` as ``(v, R)``: held here so that a
    torch that keeps the order shows up."""
    r, v = torch.as_tensor(R_VEC), torch.as_tensor(V)

    def f(r, v):
        R = rk.Rotation.from_rotvec(r)
        return R @ v, v @ R

    forward, reversed_ = torch.compile(f, fullgraph=True, backend="eager")(r, v)
    ref = SciRotation.from_rotvec(R_VEC).apply(V)
    assert isinstance(forward, torch.Tensor)
    np.testing.assert_allclose(forward.numpy(), ref, rtol=0, atol=1e-14)
    np.testing.assert_allclose(reversed_.numpy(), ref, rtol=0, atol=1e-14)
    # Eager: @ with a tensor on the right acts, on the left it is refused.
    R = rk.Rotation.from_rotvec(r)
    np.testing.assert_allclose((R @ v).numpy(), ref, rtol=0, atol=1e-14)
    with pytest.raises(TypeError, match="array @ Rotation is not defined"):
        v @ R
    with pytest.raises(TypeError):
        torch.matmul(v, R)


@pytest.mark.parametrize("case", ["object @ tensor", "object @ object"])
def test_plain_object_matmul_breaks_fullgraph(case):
    """The minimal reproductions in plain torch, of TorchDynamo itself: an object
    whose ``__matmul__`` would trace fails ``fullgraph=True`` in ``@`` with a
    tensor ("as_proxy": why the objects carry ``__torch_function__``) and in ``@``
    with another object (dynamo has no ``@`` of objects, with or without the
    protocol: inside compiled code compose with ``R1.compose(R2)``)."""

    class Scale:
        def __init__(self, s):
            self.s = s

        def __matmul__(self, other):
            if isinstance(other, Scale):
                return Scale(self.s * other.s)
            return self.s * other

    def f(s, v):
        return Scale(s) @ v if case == "object @ tensor" else (Scale(s) @ Scale(s)).s * v

    s, v = torch.tensor(2.0), torch.ones(3)
    assert torch.equal(f(s, v), (2.0 if case == "object @ tensor" else 4.0) * v)  # eager
    match = "as_proxy" if case == "object @ tensor" else "builtin operator `matmul`"
    with pytest.raises(Exception, match=match):
        torch.compile(f, fullgraph=True, backend="eager")(s, v)


def test_power_and_scalar_operators_with_a_tensor_trace_under_fullgraph():
    """``R ** t``, ``T ** t``, ``s * q``, ``q * s`` and ``q / s`` with tensor ``t``
    and ``s``: dynamo hands them to ``__torch_function__`` as torch's ``__rpow__``,
    ``mul`` and ``__rtruediv__``/``div`` (which returned ``NotImplemented``: "All
    __torch_function__ overrides returned NotImplemented", "Missing as_proxy()").
    References: scipy's ``R ** t``, ``T ** t`` as ``exp(t log T)`` by
    ``scipy.linalg.expm``/``logm``, and the componentwise scalar products."""
    from scipy.linalg import expm, logm

    t, s = 0.35, -1.75
    q = np.array([0.5, -1.0, 2.0, 0.25])
    T = rk.Transform.exp(np.array([0.4, -0.2, 0.9, 0.3, -1.1, 0.6]))

    def f(r, x, q, t, s):
        Q = rk.Quaternion(q)
        return (
            (rk.Rotation.from_rotvec(r) ** t).as_matrix(),
            (rk.Transform.exp(x) ** t).as_matrix(),
            (s * Q)._data,
            (Q * s)._data,
            (Q / s)._data,
        )

    args = [torch.as_tensor(np.asarray(a)) for a in (R_VEC, T.log(), q, t, s)]
    got = torch.compile(f, fullgraph=True, backend="eager")(*args)
    want = (
        (SciRotation.from_rotvec(R_VEC) ** t).as_matrix(),
        expm(t * logm(T.as_matrix())).real,
        s * q,
        q * s,
        q / s,
    )
    for g, w in zip(got, want):
        assert isinstance(g, torch.Tensor)
        np.testing.assert_allclose(g.numpy(), w, rtol=0, atol=1e-12)
