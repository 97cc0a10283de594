"""Rates between samples: Lagrange interpolation on the nearest samples.

For step ``k`` (from ``t_k`` to ``t_k + dt_k``) the integrators need the rate at
the middle and at the end of the step. Order 2 interpolates linearly between
samples ``k`` and ``k + 1`` (the last step extrapolates from the last two); order
4 takes the cubic through the four nearest samples (``k - 1 ... k + 2``, shifted
inwards at the ends). The end of a step other than the last is sample ``k + 1``
itself, which the interpolation returns exactly (its weight is 1, the others 0).

Node times are formed relative to ``t_k`` from the few step durations between
them, not as differences of absolute times, so long logs lose no digits.
The weights are computed from the steps in their own namespace (float64 on
NumPy) and applied to the rates, so both trace and carry gradients.
"""

from __future__ import annotations

import numpy as np

from ..._engine import dask_backend
from ..._engine.namespace import device_of, is_numpy, namespace_of
from ..._validate import raise_where
from ...errors import DegenerateInputError


def _node_offsets(d, m: int, xp=np):
    """``t_{j0(k) + i} - t_k`` for ``i < m``, from the step durations ``d`` (..., N).

    Sums of a few consecutive durations, formed by slicing in the namespace ``xp``
    of ``d`` (they trace, and carry gradients in ``d``); ``j0`` (the first node of
    each step's window) depends on the shapes only and is NumPy.
    """
    n = d.shape[-1]
    # The shape-only bookkeeping in Python ints: torch.compile traces NumPy too, and
    # np.unique's size would then depend on traced values.
    starts = [min(max(k - (m // 2 - 1), 0), n - m) for k in range(n)]
    j0 = np.array(starts, dtype=np.intp)
    lead = tuple(d.shape[:-1])
    pad = xp.zeros(lead + (m,), dtype=d.dtype, device=device_of(d))
    p = xp.concat([pad, d, pad], axis=-1)  # p[..., k + m + l] = d_{k+l}
    # offset(k, s) for s = j - k in [-(m-1), m-1], column s + m - 1
    cols = [None] * (2 * m - 1)
    cols[m - 1] = 0.0 * d
    for s in range(1, m):
        cols[m - 1 + s] = cols[m - 2 + s] + p[..., m + s - 1 : m + s - 1 + n]
        cols[m - 1 - s] = cols[m - s] - p[..., m - s : m - s + n]
    # column j0(k) + i - k of row k: a fixed (shape-only) selection
    shift = [starts[k] - k + (m - 1) for k in range(n)]  # the column of node i = 0
    offs = []
    for i in range(m):
        col = 0.0 * d
        for c in sorted({s + i for s in shift}):
            mask = [1.0 if s + i == c else 0.0 for s in shift]
            col = col + _const(xp, mask, d) * cols[c]
        offs.append(col)
    return j0, xp.stack(offs, axis=-1)


def _const(xp, a, like):
    if is_numpy(xp):
        return np.asarray(a, dtype=like.dtype)
    return xp.asarray(a, dtype=like.dtype, device=device_of(like))


def _lagrange(offs, x, xp=np):
    """Weights ``L_i(x)`` of the nodes ``offs`` (..., N, m) at ``x`` (..., N)."""
    m = offs.shape[-1]
    w = []
    for i in range(m):
        num = 1.0
        den = 1.0
        for j in range(m):
            if j != i:
                num = num * (x - offs[..., j])
                den = den * (offs[..., i] - offs[..., j])
        w.append(num / den)
    return xp.stack(w, axis=-1)


def rates_at_step_points(rate, h, *, order: int):
    """Rates at the middle and the end of every step, shape of ``rate`` (..., N, W).

    ``h`` is the step duration, shape () (uniform) or (..., N), a number or an
    array (NumPy, or of the rates' namespace): uniform steps need no values of
    ``h`` (the weights do not change when all steps scale alike); non-uniform
    weights are computed from ``h`` in its namespace (in float64 on NumPy), so
    they trace under ``jax.jit`` and ``torch.compile`` and carry gradients in ``h``.
    """
    n = rate.shape[-2]
    m = 2 if order == 2 else 4
    if n < m:
        raise DegenerateInputError(
            f"the {'midpoint' if m == 2 else 'rk4'} method needs at least {m} samples "
            f"to interpolate the rate, got {n} (use method='exact')"
        )
    if isinstance(h, (int, float)):
        h = np.asarray(h, dtype=np.float64)
    xp = namespace_of(rate)
    numpy = is_numpy(xp)

    def conv(a):
        if numpy and dask_backend.is_dask(a):  # weights from Dask steps stay lazy
            return a.astype(rate.dtype)
        if numpy:
            return np.asarray(a, dtype=rate.dtype)
        return xp.asarray(a, dtype=rate.dtype, device=device_of(rate))

    def rows(idx):
        return (
            rate[..., idx, :]
            if numpy
            else rate[..., xp.asarray(idx, device=device_of(rate)), :]
        )

    if h.ndim == 0 and n > m:
        return _uniform(rate, n, m, conv, rows, xp)
    if h.ndim == 0:  # uniform, n == m: unit steps give the same weights
        j0, w_mid, w_end = _SHORT[m]
        return _apply(j0, conv(w_mid), conv(w_end), rows, m)
    if isinstance(h, np.ndarray):
        d = h.astype(np.float64)
        hx = np
    else:
        d = h
        hx = namespace_of(h)
    # skipped under tracing and with set_validation(False); on Dask at compute time
    raise_where(d <= 0, DegenerateInputError, "step durations dt must be positive {where}")
    j0, offs = _node_offsets(d, m, hx)
    w_mid = conv(_lagrange(offs, 0.5 * d, hx))
    w_end = conv(_lagrange(offs, d, hx))
    return _apply(j0, w_mid, w_end, rows, m)


def _apply(j0, w_mid, w_end, rows, m):
    """``sum_i w[..., i] rate[j0 + i]`` at the middle and the end of each step."""
    mid = 0.0
    end = 0.0
    for i in range(m):
        node = rows(j0 + i)
        mid = mid + w_mid[..., i, None] * node
        end = end + w_end[..., i, None] * node
    return mid, end


def _uniform(rate, n, m, conv, rows, xp):
    """Uniform steps: the same weights on every interior window, applied by slicing.

    The weights are those of :func:`_lagrange` on unit steps for the ``m`` window
    positions (a step at a window's start, middle or end); only the first and
    last steps use shifted windows. The end of step ``k < N - 1`` is sample
    ``k + 1``.
    """
    small = m + 1  # every window position occurs in m + 1 unit steps
    w_mid, w_end = _UNIFORM[m]  # (small, m)
    lead = m // 2 - 1  # steps before the first interior one
    inner = w_mid[lead]
    count = n - m + 1  # interior steps: k = lead ... lead + count - 1
    mid_inner = 0.0
    for i in range(m):
        mid_inner = mid_inner + float(inner[i]) * rate[..., i : i + count, :]
    pieces = []
    head = rate[..., :m, :]
    for k in range(lead):
        pieces.append(_weighted(w_mid[k], head, conv))
    pieces.append(mid_inner)
    tail = rate[..., n - m :, :]
    for c in range(lead + 1, m):  # the last m - lead - 1 steps, window at the end
        pieces.append(_weighted(w_mid[small - m + c], tail, conv))
    mid = xp.concat(pieces, axis=-2)
    last = _weighted(w_end[small - 1], tail, conv)
    end = xp.concat([rate[..., 1:, :], last], axis=-2)
    return mid, end


def _weighted(w, nodes, conv):
    """``sum_i w[i] nodes[..., i, :]`` as shape (..., 1, W)."""
    out = 0.0
    for i in range(nodes.shape[-2]):
        out = out + float(w[i]) * nodes[..., i : i + 1, :]
    return out


def _unit_weights(n, m):
    """``(j0, w_mid, w_end)`` of ``n`` unit steps (NumPy, made once at import)."""
    d = np.ones(n)
    j0, offs = _node_offsets(d, m)
    return j0, _lagrange(offs, 0.5 * d), _lagrange(offs, d)


# Uniform steps need no values of the steps: their weights are constants, made
# here once (as Python floats for the interior windows), so that nothing NumPy
# runs in a traced call (TorchDynamo cannot trace reading a NumPy array's dtype).
_SHORT = {m: _unit_weights(m, m) for m in (2, 4)}
_UNIFORM = {m: tuple(w.tolist() for w in _unit_weights(m + 1, m)[1:]) for m in (2, 4)}
