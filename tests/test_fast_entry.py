"""The generated fast entry point calls compiled loops without numba's type checks.

Its own checks (exact ndarray type, dtype, rank and trailing shape, C-contiguity,
a writable ``out=``) must therefore send every other input to the general path:
non-contiguous, unaligned, float32, broadcast rows and ``out=`` buffers that are
read-only, of another dtype or not contiguous. Results are checked against scipy
(homogeneous matrices from ``Rotation.from_quat``, products of those matrices),
never against another rigidkit path.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as SciRotation

from rigidkit._engine import numba_backend
from rigidkit.kernels import se3 as K

pytestmark = pytest.mark.skipif(not numba_backend.available(), reason="needs numba")

DTYPES = [np.float64, np.float32]


def _poses(n, dtype, seed=0):
    rng = np.random.default_rng(seed)
    q = rng.standard_normal((n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return np.concatenate([q, rng.standard_normal((n, 3))], axis=1).astype(dtype)


def _scipy_matrix(p):
    """(..., 4, 4) homogeneous matrices of poses (w, x, y, z, t), by scipy."""
    p = np.asarray(p, dtype=np.float64)
    flat = p.reshape(-1, 7)
    m = np.zeros((len(flat), 4, 4))
    m[:, :3, :3] = SciRotation.from_quat(flat[:, :4], scalar_first=True).as_matrix()
    m[:, :3, 3] = flat[:, 4:]
    m[:, 3, 3] = 1.0
    return m.reshape(p.shape[:-1] + (4, 4))


def _tol(dtype):
    return 8 * np.finfo(dtype).eps


def _ready(kern, dtype):
    """Wait for every loop the fast entry of ``kern`` may call at ``dtype``."""
    n_in = len(kern.inputs)
    patterns = [numba_backend.SINGLE, (False,) * n_in]
    if n_in > 1:
        patterns += [tuple(k == j for k in range(n_in)) for j in range(n_in)]
    for bcast in patterns:
        numba_backend.wait(kern, bcast, np.dtype(dtype))
    # The fast path holds entry points, not the dispatchers the general path uses.
    key = np.dtype(dtype)
    assert kern._entry[(False,) * n_in][key] is not kern._ready[(False,) * n_in][key]


def _unaligned(a):
    """A C-contiguous copy of ``a`` whose data starts one byte off alignment."""
    buf = np.zeros(a.nbytes + 1, np.uint8)
    u = np.frombuffer(buf.data, dtype=a.dtype, count=a.size, offset=1).reshape(a.shape)
    u[...] = a
    assert not u.flags.aligned and u.flags.c_contiguous
    return u


def _layouts(p):
    """The same poses as contiguous, strided, Fortran-ordered, unaligned, read-only."""
    strided = np.repeat(p, 2, axis=0)[::2]
    frozen = p.copy()
    frozen.setflags(write=False)
    return {
        "contiguous": p,
        "strided": strided,
        "fortran": np.asfortranarray(p),
        "unaligned": _unaligned(p),
        "read-only": frozen,
    }


@pytest.mark.parametrize("dtype", DTYPES, ids=["f64", "f32"])
def test_matrix_from_pose_any_layout(dtype):
    _ready(K.matrix_from_pose, dtype)
    p = _poses(10, dtype)
    want = _scipy_matrix(p)
    tol = _tol(dtype)
    for label, a in _layouts(p).items():
        for i in (0, 3):  # one element: row i, a view of the batch
            got = K.matrix_from_pose(a[i])
            assert got.shape == (4, 4) and got.dtype == dtype, label
            np.testing.assert_allclose(got, want[i], rtol=0, atol=tol, err_msg=label)
        for n in (1, 2, 10):
            got = K.matrix_from_pose(a[:n])
            assert got.shape == (n, 4, 4) and got.dtype == dtype, label
            assert got.flags.c_contiguous and got.flags.writeable
            np.testing.assert_allclose(got, want[:n], rtol=0, atol=tol, err_msg=label)


@pytest.mark.parametrize("dtype", DTYPES, ids=["f64", "f32"])
def test_pose_compose_broadcast_rows(dtype):
    """Both inputs batched, either one a single row for the batch, and one element."""
    _ready(K.pose_compose, dtype)
    a, b = _poses(10, dtype, 1), _poses(10, dtype, 2)
    ma, mb = _scipy_matrix(a), _scipy_matrix(b)
    cases = {
        "batch @ batch": (a, b, ma @ mb),
        "row @ batch": (a[4], b, ma[4] @ mb),
        "batch @ row": (a, b[7], ma @ mb[7]),
        "one @ one": (a[2], b[5], ma[2] @ mb[5]),
        "strided @ batch": (np.repeat(a, 2, axis=0)[::2], b, ma @ mb),
        "batch @ unaligned": (a, _unaligned(b), ma @ mb),
    }
    for label, (x, y, want) in cases.items():
        got = K.pose_compose(x, y)
        assert got.dtype == dtype and got.shape == want.shape[:-2] + (7,), label
        np.testing.assert_allclose(
            _scipy_matrix(got), want, rtol=0, atol=4 * _tol(dtype), err_msg=label
        )
    # Mixed dtypes leave the fast path and compute in the wider one.
    got = K.pose_compose(a.astype(np.float64), b.astype(np.float32))
    assert got.dtype == np.float64


@pytest.mark.parametrize("n", [None, 10], ids=["one", "batch"])
def test_out_buffers(n):
    """A fitting ``out=`` is written and returned; a read-only one is refused untouched.

    At one element any writable buffer of the shape is written (cast, or strided);
    a batch's must be C-contiguous and of the result's dtype.
    """
    dtype = np.float64
    _ready(K.matrix_from_pose, dtype)
    p = _poses(10, dtype, 3)
    x = p[0] if n is None else p
    shape = (4, 4) if n is None else (n, 4, 4)
    want = _scipy_matrix(x)
    out = np.full(shape, np.nan)
    assert K.matrix_from_pose(x, out=out) is out
    np.testing.assert_allclose(out, want, rtol=0, atol=_tol(dtype))

    frozen = np.full(shape, np.nan)
    frozen.setflags(write=False)
    refused = [("read-only", frozen, ValueError)]
    other_dtype = np.full(shape, np.nan, np.float32)
    strided = np.full(shape[:-1] + (8,), np.nan)[..., ::2]
    if n is None:
        for label, buf in [("float32", other_dtype), ("strided", strided)]:
            assert K.matrix_from_pose(x, out=buf) is buf
            tol = _tol(buf.dtype)
            np.testing.assert_allclose(buf, want, rtol=0, atol=tol, err_msg=label)
    else:
        refused += [("float32", other_dtype, TypeError), ("strided", strided, ValueError)]
    for label, buf, error in refused:
        before = buf.copy()
        with pytest.raises((error, TypeError)):
            K.matrix_from_pose(x, out=buf)
        np.testing.assert_array_equal(buf, before, err_msg=label)


def _loop_layouts(a):
    """Views of ``a`` (n, *trail) that are and are not C-contiguous, as NumPy says."""
    wide = np.repeat(a, 2, axis=-1)
    return {
        "contiguous": (a, True),
        "batch strided": (np.repeat(a, 2, axis=0)[::2], False),
        "trailing strided": (wide[..., ::2], False),
        "fortran": (np.asfortranarray(a), False),
        # Relaxed strides: the batch axis of a batch of one may have any stride.
        "one row of a strided batch": (np.repeat(a, 3, axis=0)[::3][:1], True),
        "empty strided": (np.repeat(a, 2, axis=0)[::2][:0], True),
    }


@pytest.mark.parametrize("dtype", DTYPES, ids=["f64", "f32"])
def test_batch_loop_checks_its_inputs_strides(dtype):
    """The batch loop refuses, untouched, an input that is not C-contiguous.

    The fast entry passes inputs without asking NumPy for their layout; the loop
    reads the strides that come with them and returns 1 (nothing written) unless
    NumPy would call the array C-contiguous, so that the call takes the general
    path. A (3, 4) input checks the inner axes; the results are checked against
    products of matrices by scipy (``@`` of homogeneous 4x4s).
    """
    from rigidkit.kernels import homogeneous as H

    for kern in (K.matrix_from_pose, H.affine_compose, K.pose_compose):
        _ready(kern, dtype)
    p = _poses(6, dtype, 4)
    m = _scipy_matrix(p)
    A = np.ascontiguousarray(m[:, :3, :], dtype=dtype)
    loop_pose = K.matrix_from_pose._entry[(False,)][np.dtype(dtype)]
    loop_affine = H.affine_compose._entry[(False, False)][np.dtype(dtype)]
    for label, (x, contiguous) in _loop_layouts(p).items():
        assert x.flags.c_contiguous == contiguous, label
        out = np.full((len(x), 4, 4), np.nan, dtype)
        assert loop_pose(x, out) == (0 if contiguous else 1), label
        if contiguous:
            np.testing.assert_allclose(out, _scipy_matrix(x), rtol=0, atol=_tol(dtype))
        else:
            assert np.isnan(out).all(), label
        got = K.matrix_from_pose(x)  # through the fast entry, either way right
        np.testing.assert_allclose(got, _scipy_matrix(x), rtol=0, atol=_tol(dtype))
    for label, (x, contiguous) in _loop_layouts(A).items():
        assert x.flags.c_contiguous == contiguous, label
        n = len(x)
        out = np.full((n, 3, 4), np.nan, dtype)
        y = A[:n]
        assert loop_affine(y, x, out) == (0 if contiguous else 1), label
        if not contiguous:
            assert np.isnan(out).all(), label
        x4 = np.concatenate([x, np.broadcast_to(m[:n, 3:, :], (n, 1, 4))], axis=1)
        want = (m[:n] @ x4.astype(np.float64))[:, :3, :]
        got = H.affine_compose(y, x)
        np.testing.assert_allclose(got, want, rtol=0, atol=8 * _tol(dtype), err_msg=label)
    # A broadcast row: its one axis is checked too (a strided row goes the general way).
    row = np.repeat(p[2], 2)[::2]
    loop_row = K.pose_compose._entry[(True, False)][np.dtype(dtype)]
    out = np.full((6, 7), np.nan, dtype)
    assert loop_row(row, p, out) == 1 and np.isnan(out).all()
    assert loop_row(p[2], p, out) == 0
    np.testing.assert_allclose(
        _scipy_matrix(K.pose_compose(row, p)), m[2] @ m, rtol=0, atol=4 * _tol(dtype)
    )


def test_threaded_batches_take_the_loop_that_releases_the_gil(monkeypatch):
    """Loops keep the GIL (~35 ns a call less); a batch split over threads needs
    the variant that releases it. The first such batch runs on one thread and
    asks for that variant; once it is loaded, batches are split. Either way the
    result is scipy's."""
    dtype = np.dtype(np.float64)
    kern = K.matrix_from_pose
    plain = numba_backend.wait(kern, (False,), dtype)
    assert plain.targetoptions["nogil"] is False
    monkeypatch.setattr(numba_backend, "PARALLEL_MIN", 8)
    monkeypatch.setenv("RIGIDKIT_NUM_THREADS", "2")
    runs = []
    run_loop = numba_backend.run_loop

    def recording(loop, n, params, ins, bcast, outs, workers=1):
        runs.append((loop, workers))
        return run_loop(loop, n, params, ins, bcast, outs, workers)

    monkeypatch.setattr(numba_backend, "run_loop", recording)
    p = _poses(40, np.float64, 5).reshape(2, 20, 7)  # N-D: the general path
    for _ in range(2):
        got = K.matrix_from_pose(p)
        np.testing.assert_allclose(got, _scipy_matrix(p), rtol=0, atol=_tol(np.float64))
        threaded = numba_backend.wait(kern, (False,), dtype, nogil=True)
    assert threaded.targetoptions["nogil"] is True
    # The first batch: on one thread, unless an earlier test had the variant loaded.
    assert len(runs) == 2 and runs[0] in [(plain, 1), (threaded, 2)]
    assert runs[1] == (threaded, 2)


def test_general_path_never_takes_a_refusal_for_a_result():
    """The general path makes its inputs C-contiguous, so a loop's refusal there
    (status 1) is a bug of ours: it raises instead of returning unwritten outputs."""
    kern = K.matrix_from_pose
    loop = numba_backend.wait(kern, (False,), np.dtype(np.float64))
    p = _poses(4, np.float64, 6)
    out = np.full((4, 4, 4), np.nan)
    numba_backend.run_loop(loop, 4, [], [p], (False,), [out])
    np.testing.assert_allclose(out, _scipy_matrix(p), rtol=0, atol=_tol(np.float64))
    # What the general path never passes (its dispatcher would refuse the type;
    # the entry point, which does not type its arguments, returns status 1).
    strided = np.repeat(p, 2, axis=0)[::2]
    entry = kern._entry[(False,)][np.dtype(np.float64)]
    with pytest.raises(RuntimeError, match="refused"):
        numba_backend.run_loop(entry, 4, [], [strided], (False,), [out])
