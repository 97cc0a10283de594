"""The Rotation API on torch tensors and array-api-strict arrays.

A result has the namespace and dtype of its input (torch in, torch out; float32
stays float32), and gradients flow through the torch path: ``gradcheck`` compares
the autograd Jacobian with central finite differences in float64 (eps 1e-6,
tolerance atol 1e-5 / rtol 1e-3, torch's defaults), at generic points, at the
identity (where ``|r|`` has no derivative) and near pi. The numbers themselves are
compared with the NumPy path (which ``test_engine`` ties to numba and the
references) to 1e-15.
"""

from __future__ import annotations

import math

import array_api_strict as xps
import numpy as np
import pytest

import rigidkit as rk

# torch comes from the ``torch`` fixture (tests/conftest.py): only these tests skip
# where it is not installed.
TORCH_DTYPES = pytest.mark.parametrize("dtype_name", ["float32", "float64"])


def _np(t):
    return t.detach().cpu().numpy() if hasattr(t, "detach") else np.asarray(t)


def _outputs(R, v):
    """Every array a Rotation gives, with a name."""
    axis, angle = R.as_axis_angle()
    return {
        "as_quat": R.as_quat(),
        "as_quat xyzw": R.as_quat(scalar_first=False),
        "as_quat canonical": R.as_quat(canonical=True),
        "as_matrix": R.as_matrix(),
        "as_rotvec": R.as_rotvec(),
        "as_rotvec degrees": R.as_rotvec(degrees=True),
        "as_mrp": R.as_mrp(),
        "axis": axis,
        "angle": angle,
        "apply": R.apply(v),
        "@ v": R @ v,
        "compose": (R @ R).as_quat(),
        "inv": R.inv().as_quat(),
        "log": R.log(),
        "minus": R.minus(R.inv()),
        "plus": R.plus(R.log()).as_quat(),
    }


def _constructors(make, q, xp_name):
    """Rotations built from every representation, in namespace ``make``."""
    R0 = rk.Rotation.from_quat(q)
    axis, angle = R0.as_axis_angle()
    return {
        "from_quat": rk.Rotation.from_quat(make(q)),
        "from_quat xyzw": rk.Rotation.from_quat(
            make(q[..., [1, 2, 3, 0]]), scalar_first=False
        ),
        "from_matrix": rk.Rotation.from_matrix(make(R0.as_matrix())),
        "from_rotvec": rk.Rotation.from_rotvec(make(R0.as_rotvec())),
        "from_mrp": rk.Rotation.from_mrp(make(R0.as_mrp())),
        "from_axis_angle": rk.Rotation.from_axis_angle(make(axis), make(angle)),
        "exp": rk.Rotation.exp(make(R0.as_rotvec())),
    }


@TORCH_DTYPES
def test_torch_in_torch_out(torch, dtype_name):
    dtype = getattr(torch, dtype_name)
    q = np.random.default_rng(0).standard_normal((6, 4))
    ref = rk.Rotation.from_quat(q)
    v = np.random.default_rng(1).standard_normal((6, 3))
    want = {k: _np(a) for k, a in _outputs(ref, v).items()}
    tol = 1e-15 if dtype == torch.float64 else 5e-7

    def make(a):
        return torch.tensor(np.asarray(a), dtype=dtype)

    for name, R in _constructors(make, q, "torch").items():
        assert R.shape == (6,)
        for what, out in _outputs(R, make(v)).items():
            assert isinstance(out, torch.Tensor), (name, what, type(out))
            assert out.dtype == dtype, (name, what, out.dtype)
            scale = max(1.0, float(np.abs(want[what]).max()))
            # Orientation-valued outputs are compared as given (same quaternion sign).
            if what in ("as_quat", "as_quat xyzw", "compose", "inv", "plus"):
                if name not in ("from_quat", "from_quat xyzw"):
                    continue  # another constructor may store -q
            np.testing.assert_allclose(
                _np(out), want[what], rtol=0, atol=4 * tol * scale, err_msg=f"{name} {what}"
            )


def test_torch_single_rotation_and_mixed_inputs(torch):
    R = rk.Rotation.from_rotvec(torch.tensor([0.0, 0.0, math.pi / 2], dtype=torch.float64))
    assert R.shape == ()
    out = R @ torch.tensor([1.0, 0.0, 0.0], dtype=torch.float64)
    assert isinstance(out, torch.Tensor)
    np.testing.assert_allclose(_np(out), [0.0, 1.0, 0.0], atol=1e-15)
    # A NumPy rotation applied to a torch vector, or the other way: one namespace wins
    # or a clear TypeError, never a silent NumPy copy of a tensor that needs grad.
    Rn = rk.Rotation.from_rotvec([0.0, 0.0, math.pi / 2])
    v = torch.tensor([1.0, 0.0, 0.0], dtype=torch.float64)
    try:
        got = Rn @ v
    except TypeError:
        return
    np.testing.assert_allclose(_np(got), [0.0, 1.0, 0.0], atol=1e-15)


# -- gradients -------------------------------------------------------------------------
def _points(torch):
    v = np.random.default_rng(2).standard_normal((5, 3))
    return torch.tensor(v, dtype=torch.float64)


ROTVECS = {
    "generic": [0.3, -1.2, 0.8],
    "identity": [0.0, 0.0, 0.0],
    "tiny": [1e-9, -2e-9, 3e-10],
    "series threshold": [0.06, 0.0, 0.0],  # sinc(theta/2) switches at theta/2 = 0.03
    "near pi": [0.0, math.pi - 1e-6, 0.0],
    "batch": [[0.3, -1.2, 0.8], [1.0, 0.5, -2.0], [0.0, 0.0, 1e-5]],
}


@pytest.mark.parametrize("case", list(ROTVECS))
def test_gradcheck_from_rotvec_apply(torch, case):
    r = torch.tensor(ROTVECS[case], dtype=torch.float64, requires_grad=True)
    pts = _points(torch)
    if r.ndim == 2:
        pts = pts[:3]
    assert torch.autograd.gradcheck(lambda r: rk.Rotation.from_rotvec(r).apply(pts), (r,))
    # and with respect to the points too
    p = pts.clone().requires_grad_(True)
    assert torch.autograd.gradcheck(lambda r, p: rk.Rotation.from_rotvec(r) @ p, (r, p))


QUATS = {
    "generic": [0.9, 0.1, -0.3, 0.2],
    "identity": [1.0, 0.0, 0.0, 0.0],
    "w = 0 (pi)": [0.0, 0.6, 0.0, 0.8],
    "w < 0": [-0.5, 0.5, 0.5, -0.5],
    "not unit": [2.0, -1.0, 0.5, 3.0],
    "batch": [[0.9, 0.1, -0.3, 0.2], [0.0, 1.0, 0.0, 0.0], [1.0, 1e-7, 0.0, 0.0]],
}


@pytest.mark.parametrize("case", list(QUATS))
def test_gradcheck_from_quat_apply(torch, case):
    q = torch.tensor(QUATS[case], dtype=torch.float64, requires_grad=True)
    pts = _points(torch)[:3] if q.ndim == 2 else _points(torch)
    if q.ndim == 2:
        pts = pts[:, None, :]  # each of 3 rotations on each of 3 points -> (3, 3, 3)
    assert torch.autograd.gradcheck(lambda q: rk.Rotation.from_quat(q).apply(pts), (q,))
    assert torch.autograd.gradcheck(lambda q: rk.Rotation.from_quat(q).as_matrix(), (q,))


@pytest.mark.parametrize("case", ["generic", "identity", "w < 0", "not unit", "small"])
def test_gradcheck_as_rotvec(torch, case):
    """log has a derivative everywhere below pi, the identity included.

    (At pi, w = 0, it jumps from ``pi a`` to ``-pi a``: no derivative there.)
    """
    q = QUATS[case] if case in QUATS else [[1.0, 1e-7, 0.0, 0.0], [1.0, 0.0, -0.01, 0.02]]
    q = torch.tensor(q, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(lambda q: rk.Rotation.from_quat(q).as_rotvec(), (q,))


def test_gradcheck_from_matrix_and_compose(torch):
    A = rk.Rotation.from_rotvec([0.3, -1.2, 0.8])
    m = torch.tensor(A.as_matrix(), dtype=torch.float64, requires_grad=True)
    q = torch.tensor([0.9, 0.1, -0.3, 0.2], dtype=torch.float64, requires_grad=True)
    pts = _points(torch)

    def f(m, q):
        # Finite differences step 1e-6 off SO(3): accept it (atol) for the check.
        return (rk.Rotation.from_matrix(m, atol=1e-5) @ rk.Rotation.from_quat(q)).apply(pts)

    assert torch.autograd.gradcheck(f, (m, q))


def test_gradient_at_identity_is_finite_and_right(torch):
    """d/dr sum(exp(hat r) v) at r = 0 is sum(r x v)' = v x (1, 1, 1)."""
    r = torch.zeros(3, dtype=torch.float64, requires_grad=True)
    v = torch.tensor([1.0, 2.0, 3.0], dtype=torch.float64)
    rk.Rotation.from_rotvec(r).apply(v).sum().backward()
    np.testing.assert_allclose(_np(r.grad), np.cross(_np(v), np.ones(3)), atol=1e-15)


# -- array-api-strict ------------------------------------------------------------------
@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_array_api_strict_end_to_end(dtype):
    xdt = getattr(xps, dtype)
    q = np.random.default_rng(3).standard_normal((4, 4))
    v = np.random.default_rng(4).standard_normal((4, 3))
    ref = rk.Rotation.from_quat(q)
    want = {k: _np(a) for k, a in _outputs(ref, v).items()}
    tol = 1e-15 if dtype == "float64" else 5e-7

    def make(a):
        return xps.asarray(np.asarray(a), dtype=xdt)

    for name, R in _constructors(make, q, "strict").items():
        assert R.shape == (4,)
        for what, out in _outputs(R, make(v)).items():
            assert type(out).__module__.startswith("array_api_strict"), (name, what)
            assert out.dtype == xdt, (name, what, out.dtype)
            if what in ("as_quat", "as_quat xyzw", "compose", "inv", "plus"):
                if name not in ("from_quat", "from_quat xyzw"):
                    continue
            scale = max(1.0, float(np.abs(want[what]).max()))
            np.testing.assert_allclose(
                np.asarray(out),
                want[what],
                rtol=0,
                atol=4 * tol * scale,
                err_msg=f"{name} {what}",
            )
    # Containers: indexing, iteration, concatenate, reshape, identity compose.
    R = rk.Rotation.from_quat(make(q))
    assert R[1].shape == () and len(list(R)) == 4
    both = rk.Rotation.concatenate([R, R[:2]])
    assert both.shape == (6,) and type(both.as_quat()).__module__.startswith(
        "array_api_strict"
    )
    assert R.reshape(2, 2).shape == (2, 2)
    assert bool(xps.all(R.approx_equal(rk.Rotation.from_quat(-R.as_quat()), atol=1e-6)))
