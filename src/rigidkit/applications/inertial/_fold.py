"""Preintegration on NumPy in one compiled pass per window (the engine's fold).

The array path of :func:`~rigidkit.inertial.preintegrate` computes every step,
its 9x6 Jacobian, the running products and each step's share of the bias
Jacobians and covariance as whole arrays: about 200 numbers per sample written
and read again. Here one loop per window (``rigidkit._engine.compile_fold`` of
:mod:`rigidkit.kernels.kinematics.inertial_window`'s step helpers: the same step
and Jacobian kernels, inlined) carries the product and sums ``G``, ``P`` in
registers, and the window's end gives the bias Jacobians ``-L G`` and the
covariance ``L P L^T`` (see that module). Like the integration's scan it is
compiled (or loaded from the disk cache) on the engine's background thread, and
calls made before it is ready take the array path, which gives the same numbers
to rounding; calls of fewer than :data:`FOLD_MIN` samples in all never ask for
it. It computes in float64 (float32 input is returned as float32).
"""

from __future__ import annotations

import os

import numpy as np

from ..._engine import compile_fold, idle_workers, in_background, numba_available, run_split
from ...kernels.kinematics import inertial_window as _kw
from ...objects.rotation import Rotation

__all__ = ["FOLD_MIN", "folded", "ready", "wait"]

#: Calls of fewer samples than this (windows x samples) never ask for the fold.
FOLD_MIN = int(os.environ.get("RIGIDKIT_FOLD_MIN", "20000"))

#: Inputs per step of each method: (w, f, h, qg, qa), midpoint (w0, f0, w1, f1, h, ...).
_INPUTS = {
    "exact": (3, 3, 1, 1, 1),
    "forster": (3, 3, 1, 1, 1),
    "midpoint": (3, 3, 3, 3, 1, 1, 1),
}
_CARRIED, _SUMMED = 11, 99  # D; G (54) and P (45)
_FOLDS: dict = {}


def _build(method):
    step = getattr(_kw, f"preintegration_step_{method}")
    fold = compile_fold(step, _CARRIED, _SUMMED, _INPUTS[method], np.dtype(np.float64))
    _FOLDS[method] = fold
    return fold


def _request(method):
    return in_background(("rigidkit preintegration fold", method), lambda: _build(method))


def ready(method, total):
    """The fold of ``method`` if it is ready, else None; a call of ``total`` samples
    (at least :data:`FOLD_MIN`) asks for it."""
    fold = _FOLDS.get(method)
    if fold is None and total >= FOLD_MIN and numba_available():
        _request(method)
    return fold


def wait(method):
    """Block until the fold of ``method`` is ready (tests, benchmarks)."""
    return _request(method).result()


#: Windows x samples per chunk of a fold's call: the inputs (biases taken off, step
#: durations, noise variances) are written into buffers of this many samples,
#: reused from chunk to chunk. Fresh arrays of a million samples cost more in page
#: faults than the fold's own arithmetic (the bias subtraction alone was ~30% of
#: a call at 5,000 windows of 200).
CHUNK = 1 << 15


def folded(fold, method, w, f, h, bg, ba, noise, batch, dtype):
    """``(delta (..., 11), J (..., 9, 6), cov (..., 9, 9) or None)`` by ``fold``.

    ``w``, ``f`` (..., N, 3), ``h`` () or (..., N), ``bg``, ``ba`` (..., 3): NumPy
    arrays that broadcast to the windows ``batch``.
    """
    n = w.shape[-2]
    wb = np.broadcast_to(w, batch + (n, 3)).reshape(-1, n, 3)
    fb = np.broadcast_to(f, batch + (n, 3)).reshape(-1, n, 3)
    m = wb.shape[0]
    bgb = np.broadcast_to(bg, batch + (3,)).reshape(m, 3)
    bab = np.broadcast_to(ba, batch + (3,)).reshape(m, 3)
    hb = None if h.ndim == 0 else np.broadcast_to(h, batch + (n,)).reshape(m, n)
    sg, sa = (
        (0.0, 0.0)
        if noise is None
        else (
            float(noise.gyro_noise_density),
            float(noise.accel_noise_density),
        )
    )
    x0 = np.zeros((m, _CARRIED + _SUMMED))
    x0[:, 0] = 1.0
    out = np.empty_like(x0)
    per = max(1, CHUNK // n)  # windows per chunk

    def run(lo, hi):
        """Windows ``lo:hi``, a chunk at a time, through buffers of this thread."""
        k = min(per, hi - lo)
        bufs = [np.empty((k, n, 3)) for _ in range(4 if method == "midpoint" else 2)]
        hh, inv, qg, qa = (np.empty((k, n, 1)) for _ in range(4))
        if hb is None:
            _noise_inputs(float(h), hh, inv, qg, qa, sg, sa)
        for a in range(lo, hi, k):
            b = min(a + k, hi)
            c = b - a
            ins = [
                _unbiased(wb[a:b], bgb[a:b], bufs[0][:c]),
                _unbiased(fb[a:b], bab[a:b], bufs[1][:c]),
            ]
            if method == "midpoint":  # the next sample ends a step; the last holds
                for x, buf in zip(ins[:2], bufs[2:]):
                    buf[:c, :-1] = x[:, 1:]
                    buf[:c, -1] = x[:, -1]
                ins += [bufs[2][:c], bufs[3][:c]]
            if hb is not None:
                _noise_inputs(hb[a:b], hh[:c], inv[:c], qg[:c], qa[:c], sg, sa)
            fold(x0[a:b], *ins, hh[:c], qg[:c], qa[:c], out[a:b])

    workers = min(m, idle_workers()) if m * n >= 2 * FOLD_MIN else 1
    if workers < 2:
        run(0, m)
    else:
        run_split(run, m, workers, lambda a, b: (a, b))
    delta = out[:, :11]
    G = out[:, 11:65].reshape(m, 9, 6)
    L = _end_map(delta)
    J = -(L @ G)
    cov = None
    if noise is not None:
        P = out[:, 65:110][:, _FULL]
        cov = L @ P @ np.swapaxes(L, -1, -2)
    shape = lambda x, trail: x.reshape(batch + trail).astype(dtype, copy=False)  # noqa: E731
    return (
        shape(delta, (11,)),
        shape(J, (9, 6)),
        None if cov is None else shape(cov, (9, 9)),
    )


def _unbiased(x, bias, buf):
    """``x - bias`` (windows (k, N, 3), biases (k, 3)) in ``buf``, or ``x`` itself
    when the biases are zero and it is a C-contiguous float64 array already."""
    if x.dtype == np.float64 and x.flags.c_contiguous and not bias.any():
        return x
    np.subtract(x, bias[:, None, :], out=buf)
    return buf


def _noise_inputs(h, hh, inv, qg, qa, sg, sa):
    """Step durations and the discrete variances ``sigma^2 / h`` of each step
    (Forster et al. 2017, eq. 45) into the buffers; a step of zero duration
    (padding) adds nothing."""
    hh[..., 0] = h
    inv.fill(0.0)
    np.divide(1.0, hh, out=inv, where=hh > 0)
    np.multiply(inv, sg * sg, out=qg)
    np.multiply(inv, sa * sa, out=qa)


#: The 81 entries of a symmetric 9x9 matrix as indices into its upper triangle, row
#: by row (the order of ``P``).
_FULL = np.zeros((9, 9), dtype=np.int64)
_FULL[np.triu_indices(9)] = np.arange(45)
_FULL.T[np.triu_indices(9)] = np.arange(45)


def _end_map(delta):
    """``L = [[R^T, 0, 0], [-hat(v), I, 0], [-hat(p), t I, I]]`` of each window's end."""
    m = delta.shape[0]
    R = np.asarray(Rotation._wrap(np.ascontiguousarray(delta[:, :4])).as_matrix())
    L = np.zeros((m, 9, 9))
    L[:, :3, :3] = np.swapaxes(R, -1, -2)
    eye = np.eye(3)
    L[:, 3:6, 3:6] = eye
    L[:, 6:9, 6:9] = eye
    L[:, 6:9, 3:6] = delta[:, 10, None, None] * eye
    L[:, 3:6, :3] = -_hat(delta[:, 4:7])
    L[:, 6:9, :3] = -_hat(delta[:, 7:10])
    return L


def _hat(v):
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    o = np.zeros_like(x)
    return np.stack([o, -z, y, z, o, -x, -y, x, o], axis=-1).reshape(-1, 3, 3)
