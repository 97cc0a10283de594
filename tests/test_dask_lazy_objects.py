"""Dask input stays lazy through Affine, Quaternion's scalar algebra, Rotation2D's
complex form, the nearest rotation matrix and Sim(3)'s inverse Jacobians.

Each op is built on chunked Dask arrays with a callback counting scheduler starts
(0 allowed), then computed and compared with the same op on the NumPy arrays (the
reference); the backend matrix covers float64 with one batch axis, these add the
mixed and float32 dtypes, two batch axes and the checks deferred to compute time.
"""

from __future__ import annotations

import numpy as np
import pytest

import rigidkit as rk
from rigidkit.errors import NonFiniteError, NotAffineError, SingularMatrixError


class _Computes:
    """Counts how often a Dask scheduler starts (i.e. computes) inside ``with``."""

    def __enter__(self):
        from dask.callbacks import Callback

        outer = self
        self.starts = 0

        class Count(Callback):
            def _start(self, dsk):
                outer.starts += 1

        self._cb = Count()
        self._cb.__enter__()
        return self

    def __exit__(self, *exc):
        self._cb.__exit__(*exc)


def _lazy(fn, *args):
    """``fn(*args)``, asserting it built a Dask graph without computing it."""
    with _Computes() as c:
        out = fn(*args)
    assert c.starts == 0, f"building the graph computed it {c.starts} time(s)"
    assert type(out).__module__.startswith("dask"), type(out)
    return out


def _chunked(da, a):
    """``a`` as a Dask array with one batch element per chunk along axis 0."""
    return da.from_array(a, chunks=(1,) + a.shape[1:])


def test_affine_from_mixed_dtypes_stays_lazy(dask_array, rng):
    A = (np.eye(3) + 0.3 * rng.standard_normal((2, 3, 3))).astype(np.float32)
    t = rng.standard_normal((2, 3))
    out = _lazy(
        lambda a, b: rk.Affine(a, b)._data, _chunked(dask_array, A), _chunked(dask_array, t)
    )
    assert out.dtype == np.float64
    np.testing.assert_array_equal(out.compute(), rk.Affine(A, t)._data)


def test_affine_singular_dask_input_raises_at_compute(dask_array, rng):
    A = np.eye(3) + 0.3 * rng.standard_normal((2, 3, 3))
    A[1, 2] = A[1, 0]  # rank 2
    out = _lazy(lambda a: rk.Affine(a)._data, _chunked(dask_array, A))
    with pytest.raises(SingularMatrixError) as err:
        out.compute()
    assert err.value.index == (1,)


def test_quaternion_scalar_algebra_on_dask_stays_lazy(dask_array, rng):
    q = rng.standard_normal((2, 4))
    s = rng.uniform(0.5, 2.0, 2)
    n = np.array([2, 3])  # integer scalars are real scalars too
    dq, ds, dn = (_chunked(dask_array, a) for a in (q, s, n))
    for fn, args, ref in (
        (lambda a, b: (a * rk.Quaternion(b))._data, (ds, dq), s[:, None] * q),
        (lambda a, b: (rk.Quaternion(a) / b)._data, (dq, ds), q / s[:, None]),
        (lambda a, b: (a * rk.Quaternion(b))._data, (dn, dq), n[:, None] * q),
    ):
        np.testing.assert_allclose(_lazy(fn, *args).compute(), ref, rtol=1e-15)


def test_quaternion_from_parts_on_dask_keeps_float32(dask_array, rng):
    v = rng.standard_normal((2, 3)).astype(np.float32)
    out = _lazy(lambda b: rk.Quaternion.from_parts(0.5, b)._data, _chunked(dask_array, v))
    assert out.dtype == np.float32
    want = np.concatenate([np.full((2, 1), 0.5, np.float32), v], axis=-1)
    np.testing.assert_array_equal(out.compute(), want)


def test_rotation2d_as_complex_on_dask_float32(dask_array, rng):
    theta = rng.uniform(-np.pi, np.pi, (2, 1)).astype(np.float32)
    out = _lazy(lambda a: rk.Rotation2D.exp(a).as_complex(), _chunked(dask_array, theta))
    assert out.dtype == np.complex64
    np.testing.assert_allclose(out.compute(), np.exp(1j * theta[:, 0]), rtol=1e-6)


def test_nearest_rotation_matrix_on_dask_two_batch_axes(dask_array, rng):
    m = rng.standard_normal((2, 3, 3, 3))
    dm = dask_array.from_array(m, chunks=(1, 2, 3, 3))
    out = _lazy(rk.conversions.nearest_rotation_matrix, dm).compute()
    # The orthogonal Procrustes solution (Higham 1988, polar factor) with det +1:
    # U diag(1, 1, det(U V^T)) V^T, by NumPy's SVD per matrix.
    for idx in np.ndindex(2, 3):
        u, _, vt = np.linalg.svd(m[idx])
        d = np.linalg.det(u @ vt)
        np.testing.assert_allclose(out[idx], u @ np.diag([1.0, 1.0, d]) @ vt, atol=1e-13)
    np.testing.assert_allclose(np.linalg.det(out), 1.0, atol=1e-13)


def test_nearest_rotation_matrix_on_dask_checks_finite_at_compute(dask_array, rng):
    m = rng.standard_normal((2, 3, 3, 3))
    m[1, 2, 0, 1] = np.nan
    dm = dask_array.from_array(m, chunks=(1, 2, 3, 3))
    out = _lazy(rk.conversions.nearest_rotation_matrix, dm)
    with pytest.raises(NonFiniteError) as err:
        out.compute()
    assert err.value.index == (1, 2)


@pytest.mark.parametrize("side", ["left", "right"])
def test_sim3_jacobian_inverse_on_dask_two_batch_axes(side, dask_array, rng):
    xi = rng.uniform(-1.0, 1.0, (2, 3, 7))
    dxi = dask_array.from_array(xi, chunks=(1, 2, 7))
    inv = _lazy(getattr(rk.sim3, f"{side}_jacobian_inverse"), dxi).compute()
    J = getattr(rk.sim3, f"{side}_jacobian")(xi)  # NumPy: the Jacobian itself
    np.testing.assert_allclose(J @ inv, np.broadcast_to(np.eye(7), J.shape), atol=1e-12)


def test_affine_from_matrix_on_dask_checks_bottom_row_at_compute(dask_array, rng):
    M = np.broadcast_to(np.eye(4), (3, 4, 4)).copy()
    M[..., :3, :] += 0.1 * rng.standard_normal((3, 3, 4))
    M[2, 3, 0] = 0.5  # not [0, 0, 0, 1]: a projective matrix
    out = _lazy(lambda m: rk.Affine.from_matrix(m)._data, _chunked(dask_array, M))
    with pytest.raises(NotAffineError) as err:
        out.compute()
    assert err.value.index == (2,)
    ok = _lazy(lambda m: rk.Affine.from_matrix(m)._data, _chunked(dask_array, M[:2]))
    np.testing.assert_array_equal(ok.compute(), M[:2, :3, :])


def test_projective_singular_dask_input_raises_at_compute(dask_array, rng):
    H = np.eye(4) + 0.2 * rng.standard_normal((3, 4, 4))
    H[1, 3] = 2.0 * H[1, 1]  # rank 3
    out = _lazy(lambda h: rk.Projective(h)._data, _chunked(dask_array, H))
    with pytest.raises(SingularMatrixError) as err:
        out.compute()
    assert err.value.index == (1,)
    ok = _lazy(lambda h: rk.Projective(h).inv()._data, _chunked(dask_array, H[[0, 2]]))
    np.testing.assert_allclose(ok.compute(), np.linalg.inv(H[[0, 2]]), atol=1e-12)
