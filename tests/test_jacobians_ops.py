"""``rk.jacobians``: the Jacobians of every group operation, against finite differences.

One test for every Lie group of the registry, the eight operations and both sides, at
random points and near the identity (1e-8). The reference never uses the formulas under
test: each operation is recomputed on the matrices of its operands (NumPy products and
inverses, the matrix exponential and principal logarithm of this file, checked against
``scipy.linalg.expm`` and ``logm``), each operand is perturbed on the manifold, ``X
expm(hat(h e_k))`` (right) or ``expm(hat(h e_k)) X`` (left), or by ``h e_k`` for a point
or a tangent, and the change of the value is read on the same side: ``vee(F_0^-1 (F_+ -
F_-) / 2h)`` (right) or ``vee((F_+ - F_-) / 2h F_0^-1)`` (left) for a group value,
``(F_+ - F_-) / 2h`` for a vector. ``vee`` is the least-squares coordinates on the
generators ``hat(e_k)``.

Tolerance: central differences with ``h = 1e-5`` err by ``h^2/6 |f'''|`` (truncation,
~2e-11 for third derivatives of order 1) plus ``eps |F_0^-1| |F| / h`` (rounding of
the reference ``expm``/``log``, a few ulp, over ``2h``: ~1e-11 times the size of the
entries, which grows with the scale ``e^sigma`` of Sim(3) and with translations).
The largest error measured over five seeds is 1.6e-10 of ``1 + max |J|`` (Sim(3)
``minus``); ``FD_TOL = 1e-8`` leaves a margin of 60. A wrong formula is off by O(1):
the Jacobian of the other side differs from the finite differences by at least
0.05 of ``1 + max |J|`` at the random points (all groups but the abelian SO(2)).

Sim(3)'s ``J_l`` (a series, :func:`rigidkit.sim3.left_jacobian`) is also checked
against ``scipy.linalg.expm`` of ``[[ad, I], [0, 0]]`` (whose upper right block is
``sum ad^k / (k+1)!``) at large arguments.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
import scipy.linalg as sl

import rigidkit as rk
from conftest import LIE_GROUPS
from rigidkit.objects import registry

H = 1e-5
FD_TOL = 1e-8


@dataclass(frozen=True)
class Group:
    cls: type
    alg: object  # the functional module (its hat)
    rot: slice  # the rotation components of the tangent
    scale: slice | None = None  # the log-scale component (Sim(3))

    def __repr__(self):
        return self.cls.__name__

    @property
    def dof(self):
        return self.cls.dof

    def hat(self, tau):
        return np.asarray(self.alg.hat(np.asarray(tau)), dtype=np.float64)

    def vee(self, M):
        if self.cls not in _VEE:
            # Least-squares coordinates on the generators hat(e_k), as one matrix.
            gens = np.stack([self.hat(e).ravel() for e in np.eye(self.dof)], axis=-1)
            _VEE[self.cls] = np.linalg.pinv(gens)
        return _VEE[self.cls] @ np.ravel(M)

    def expm(self, tau):
        return matrix_exp(self.hat(tau))

    def step(self, k, sign):
        """``expm(hat(sign h e_k))`` (the same few matrices for every point)."""
        key = (self.cls, k, sign)
        if key not in _STEPS:
            _STEPS[key] = self.expm(sign * H * np.eye(self.dof)[k])
        return _STEPS[key]

    def logm(self, M):
        return self.vee(principal_log(M))


_VEE = {}
_STEPS = {}


def matrix_exp(A):
    """``expm(A)`` by scaling and squaring: the Taylor series of ``A / 2^s``,
    ``|A / 2^s| <= 1/2``, to the 24th power (``0.5^25 / 25!`` is far below eps).

    ``scipy.linalg.expm`` costs up to ~8 ms per call on a loaded machine (BLAS
    threads on tiny matrices); this is ~50 us. Checked against it in
    :func:`test_reference_exp_and_log_against_scipy`.
    """
    A = np.asarray(A, dtype=np.float64)
    s = max(0, int(np.ceil(np.log2(max(np.abs(A).sum(axis=-1).max(), 1e-300) / 0.5))))
    X = A / 2.0**s
    eye = np.eye(len(A))
    E = eye
    for n in range(24, 0, -1):
        E = eye + X @ E / n
    for _ in range(s):
        E = E @ E
    return E


def principal_log(M):
    """The principal matrix logarithm by inverse scaling and squaring.

    ``scipy.linalg.logm`` costs 5-30 ms per 4x4 matrix on a loaded machine (its
    complex Schur form), too slow for hundreds of calls. Square roots by the
    product form of the Denman-Beavers iteration until ``|A - I| <= 1/4``, then
    ``log A = 2 atanh(Z)``, ``Z = (A - I)(A + I)^-1`` (``|Z| <~ 0.13``), summed to
    ``Z^41`` (``0.13^43 / 43`` is far below eps), times ``2^k``. Measured against
    mpmath: within 4e-15 (``logm``: 1e-15); checked against ``logm`` in
    :func:`test_reference_exp_and_log_against_scipy`.
    """
    A = np.array(M, dtype=np.float64)
    eye = np.eye(len(A))
    k = 0
    while np.abs(A - eye).max() > 0.25:
        Y, N = A, A
        for _ in range(30):
            N_inv = np.linalg.inv(N)
            Y = 0.5 * Y @ (eye + N_inv)
            N = 0.5 * (eye + 0.5 * (N + N_inv))
            if np.abs(N - eye).max() < 1e-15:
                break
        A, k = Y, k + 1
    Z = (A - eye) @ np.linalg.inv(A + eye)
    Z2 = Z @ Z
    S = np.zeros_like(Z)
    for n in range(20, -1, -1):
        S = eye / (2 * n + 1) + Z2 @ S
    return (2.0 ** (k + 1)) * (Z @ S)


def _group(cls):
    spec = registry.spec(cls)
    return Group(cls, spec.algebra, spec.part("rotation"), spec.part("scale"))


# Every Lie group of the registry (:mod:`rigidkit.objects.registry`), not a list.
GROUPS = [_group(cls) for cls in LIE_GROUPS]


def tangent(G, where, rng, max_angle=2.5):
    """A tangent: rotation angle uniform in (0.1, max_angle), or of norm 1e-8."""
    tau = rng.standard_normal(G.dof)
    if G.scale is not None:
        tau[G.scale] *= 0.5
    k = G.rot.stop - G.rot.start
    axis = rng.standard_normal(k)
    tau[G.rot] = axis / np.linalg.norm(axis) * rng.uniform(0.1, max_angle)
    if where == "identity":
        tau *= 1e-8 / np.linalg.norm(tau)
    return tau


# Each operation: (operand kinds, the call of rk.jacobians, the reference on matrices,
# the kind of the value). "g" a group element (matrix), "t" a tangent, "p" a point.
def _apply(M, p):
    d = p.shape[-1]
    if M.shape[-1] == d:
        return M @ p
    return M[:d, :d] @ p + M[:d, -1]  # the last column (SE_2(3): its 5th, the position)


OPS = {
    "compose": ("gg", lambda G, X, Y, f: rk.jacobians.compose(X, Y, side=f),
                lambda G, A, B: A @ B, "g"),
    "inv": ("g", lambda G, X, f: rk.jacobians.inv(X, side=f),
            lambda G, A: np.linalg.inv(A), "g"),
    "apply": ("gp", lambda G, X, p, f: rk.jacobians.apply(X, p, side=f),
              lambda G, A, p: _apply(A, p), "p"),
    "log": ("g", lambda G, X, f: rk.jacobians.log(X, side=f),
            lambda G, A: G.logm(A), "t"),
    "exp": ("t", lambda G, tau, f: rk.jacobians.exp(G.cls, tau, side=f),
            lambda G, tau: G.expm(tau), "g"),
    "plus": ("gt", lambda G, X, tau, f: rk.jacobians.plus(X, tau, side=f),
             lambda G, A, tau: A @ G.expm(tau), "g"),
    "minus": ("gg", lambda G, X, Y, f: rk.jacobians.minus(X, Y, side=f),
              lambda G, A, B: G.logm(np.linalg.inv(B) @ A), "t"),
    "between": ("gg", lambda G, X, Y, f: rk.jacobians.between(X, Y, side=f),
                lambda G, A, B: np.linalg.inv(A) @ B, "g"),
}  # fmt: skip


def operands(G, op, where, rng, n=2):
    """``n`` sets of operands: (objects / arrays for rk, NumPy references)."""
    kinds = OPS[op][0]
    cols = []
    first = None
    for kind in kinds:
        if kind == "p":
            val = rng.standard_normal((n, G.cls.point_dim))
            cols.append((val, list(val)))
            continue
        tau = np.stack([tangent(G, where, rng) for _ in range(n)])
        if kind == "t":
            cols.append((tau, list(tau)))
            continue
        X = G.cls.exp(tau)
        if op == "minus" and first is not None:
            # Y = X exp(b): the rotation of Y^-1 X well inside logm's principal range.
            X = first @ G.cls.exp(tau)
        first = X if first is None else first
        cols.append((X, list(np.asarray(X.as_matrix(), dtype=np.float64))))
    return cols


def fd_jacobians(G, op, refs, side):
    """Finite-difference Jacobians of ``op`` at one set of operands ``refs``."""
    kinds, _, ref, out_kind = OPS[op]
    F0 = ref(G, *refs)
    F0_inv = np.linalg.inv(F0) if out_kind == "g" else None
    jacobians = []
    for i, kind in enumerate(kinds):
        dim = G.dof if kind in "gt" else G.cls.point_dim
        cols = []
        for e in np.eye(dim):
            F = []
            for sign in (1.0, -1.0):
                args = list(refs)
                if kind == "g":
                    step = G.step(int(np.argmax(e)), sign)
                    args[i] = args[i] @ step if side == "right" else step @ args[i]
                else:
                    args[i] = args[i] + sign * H * e
                F.append(ref(G, *args))
            dF = (F[0] - F[1]) / (2 * H)
            if out_kind == "g":
                dF = G.vee(F0_inv @ dF if side == "right" else dF @ F0_inv)
            cols.append(dF)
        jacobians.append(np.stack(cols, axis=-1))
    return F0, jacobians


@pytest.mark.parametrize("where", ["random", "identity"])
@pytest.mark.parametrize("side", ["right", "left"])
@pytest.mark.parametrize("op", list(OPS))
@pytest.mark.parametrize("G", GROUPS, ids=repr)
def test_jacobians_by_finite_differences_on_the_manifold(G, op, side, where, rng):
    kinds, call, ref, out_kind = OPS[op]
    cols = operands(G, op, where, rng)
    value, *J = call(G, *[c[0] for c in cols], side)
    assert len(J) == len(kinds)
    for b in range(2):
        refs = [c[1][b] for c in cols]
        F0, J_fd = fd_jacobians(G, op, refs, side)
        got = np.asarray(value.as_matrix() if out_kind == "g" else value)[b]
        np.testing.assert_allclose(got, F0, rtol=0, atol=1e-12 * (1 + np.abs(F0).max()))
        for k, (J_rk, J_ref) in enumerate(zip(J, J_fd, strict=True)):
            J_rk = np.asarray(J_rk)[b]
            assert J_rk.shape == J_ref.shape
            err = np.abs(J_rk - J_ref).max()
            assert err <= FD_TOL * (1 + np.abs(J_ref).max()), (op, side, k, err)


def test_reference_exp_and_log_against_scipy(rng):
    """The test's own ``expm`` and ``logm`` (above) agree with scipy's."""
    for G in GROUPS:
        for where in ("random", "identity"):
            tau = tangent(G, where, rng, max_angle=3.0)
            A = G.hat(tau)
            M = sl.expm(A)
            np.testing.assert_allclose(matrix_exp(A), M, rtol=0, atol=1e-13)
            np.testing.assert_allclose(principal_log(M), np.real(sl.logm(M)), atol=1e-12)


def _large_sim3_twists(rng, n):
    """Twists with ``|omega|`` up to pi - 1e-3 and ``|sigma|`` up to 3, corners included."""
    xi = rng.standard_normal((n, 7)) * 3.0
    axis = rng.standard_normal((n, 3))
    angle = rng.uniform(0.0, math.pi - 1e-3, n)
    angle[: n // 2] = math.pi - 1e-3
    xi[:, 3:6] = axis / np.linalg.norm(axis, axis=-1, keepdims=True) * angle[:, None]
    xi[:, 6] = rng.uniform(-3.0, 3.0, n)
    xi[: n // 4, 6] = 3.0
    xi[n // 4 : n // 2, 6] = -3.0
    return xi


def test_sim3_left_jacobian_against_expm(rng):
    """``J_l = sum ad^k/(k+1)!`` is the upper right block of ``expm([[ad, I], [0, 0]])``.

    ``expm`` itself errs by up to 6e-14 of ``max |J_l|`` at these arguments (measured
    against mpmath at 40 digits; the series: 1.5e-15), so the bound is 2e-13.
    """
    xi = _large_sim3_twists(rng, 40)
    J = np.asarray(rk.sim3.left_jacobian(xi))
    J_inv = np.asarray(rk.sim3.left_jacobian_inverse(xi))
    ad = np.asarray(rk.sim3.ad(xi))
    for i in range(len(xi)):
        block = np.zeros((14, 14))
        block[:7, :7] = ad[i]
        block[:7, 7:] = np.eye(7)
        ref = sl.expm(block)[:7, 7:]
        scale = np.abs(ref).max()
        np.testing.assert_allclose(J[i], ref, rtol=0, atol=2e-13 * scale)
        np.testing.assert_allclose(J_inv[i] @ ref, np.eye(7), rtol=0, atol=1e-12 * scale)
    Jr = np.asarray(rk.sim3.right_jacobian(xi))
    np.testing.assert_array_equal(Jr, np.asarray(rk.sim3.left_jacobian(-xi)))


@pytest.mark.parametrize("G", GROUPS, ids=repr)
def test_batch_shapes_and_float32(G, rng):
    """Jacobians broadcast to the value's batch shape; float32 stays float32."""
    X = G.cls.random((2, 1), rng)
    Y = G.cls.random(3, rng)
    tau = rng.standard_normal((3, G.dof)) * 0.3
    p = rng.standard_normal((2, 3, G.cls.point_dim))
    dof, d = G.dof, G.cls.point_dim
    shapes = {
        "compose": (rk.jacobians.compose(X, Y), [(dof, dof)] * 2),
        "between": (rk.jacobians.between(X, Y), [(dof, dof)] * 2),
        "minus": (rk.jacobians.minus(X, Y), [(dof, dof)] * 2),
        "plus": (rk.jacobians.plus(X, tau), [(dof, dof)] * 2),
        "apply": (rk.jacobians.apply(X, p), [(d, dof), (d, d)]),
    }
    for name, ((_, *J), trails) in shapes.items():
        for Jk, trail in zip(J, trails, strict=True):
            assert np.asarray(Jk).shape == (2, 3) + trail, name
    assert np.asarray(rk.jacobians.inv(X)[1]).shape == (2, 1, dof, dof)
    assert np.asarray(rk.jacobians.log(Y, side="left")[1]).shape == (3, dof, dof)
    assert np.asarray(rk.jacobians.exp(G.cls, tau)[1]).shape == (3, dof, dof)
    # float32: every Jacobian float32, within float32 rounding of the float64 ones.
    t32 = tau.astype(np.float32)
    X32, Y32 = G.cls.exp(t32), G.cls.exp(t32[::-1].copy())
    X64, Y64 = G.cls.exp(tau), G.cls.exp(tau[::-1].copy())
    for side in ("right", "left"):
        got = rk.jacobians.minus(X32, Y32, side=side)[1:]
        want = rk.jacobians.minus(X64, Y64, side=side)[1:]
        for a, b in zip(got, want, strict=True):
            assert a.dtype == np.float32
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-4 * (1 + np.abs(b).max()))
        _, J_X, J_p = rk.jacobians.apply(X32, p[0].astype(np.float32), side=side)
        assert J_X.dtype == J_p.dtype == np.float32


def test_bad_arguments():
    R = rk.Rotation.identity()
    with pytest.raises(ValueError, match="side must be 'right' or 'left'"):
        rk.jacobians.compose(R, R, side="body")
    with pytest.raises(TypeError, match="one group"):
        rk.jacobians.minus(R, rk.Transform.identity())
    with pytest.raises(TypeError, match="must be one of"):
        rk.jacobians.log(rk.Affine.identity())


def test_jax_jit(jax, jnp, rng):
    """Under ``jax.jit`` (objects as pytrees), equal to the NumPy results."""
    tau_x = rng.standard_normal((4, 3)) * 0.5
    tau_y = rng.standard_normal((4, 3)) * 0.5
    X, Y = rk.Rotation.exp(tau_x), rk.Rotation.exp(tau_y)

    @jax.jit
    def f(X, Y):
        return rk.jacobians.compose(X, Y, side="left")

    got = f(rk.Rotation.exp(jnp.asarray(tau_x)), rk.Rotation.exp(jnp.asarray(tau_y)))
    got = (got[0].as_matrix(), *got[1:])
    want = rk.jacobians.compose(X, Y, side="left")
    want = (want[0].as_matrix(), *want[1:])
    for a, b in zip(got, want, strict=True):
        np.testing.assert_allclose(np.asarray(a), b, rtol=0, atol=1e-12)


def test_torch_gradients_flow(torch, rng):
    """torch in, torch out, equal to NumPy; the Jacobians are differentiable."""
    tau = rng.standard_normal((3, 6)) * 0.5
    p = rng.standard_normal((3, 3))
    want = rk.jacobians.apply(rk.Transform.exp(tau), p, side="left")
    t = torch.tensor(tau, requires_grad=True)
    got = rk.jacobians.apply(rk.Transform.exp(t), torch.tensor(p), side="left")
    for a, b in zip(got, want, strict=True):
        assert isinstance(a, torch.Tensor) and a.dtype == torch.float64
        np.testing.assert_allclose(a.detach().numpy(), b, rtol=0, atol=1e-13)
    got[1].sum().backward()
    assert t.grad is not None and bool(torch.isfinite(t.grad).all())
