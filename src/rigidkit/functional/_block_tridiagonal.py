"""A block-tridiagonal solve with 3x3 blocks (block Thomas), for the C2 rotation
spline's Newton steps (:mod:`rigidkit.functional.splines`).

Written in the array namespace of its blocks, so it traces under ``jax.jit``, the
torch transforms and ``torch.compile`` (inside a ``while_loop``), and stays lazy
per chunk on Dask.
"""

from __future__ import annotations

from ..kernels import homogeneous as _kh

__all__ = ["matvec", "solve_block_tridiagonal"]


def matvec(m, v):
    """``m v`` for stacks of matrices (..., n, n) and vectors (..., n)."""
    return (m @ v[..., None])[..., 0]


def solve_block_tridiagonal(xp, lower, diag, upper, rhs):
    """Block Thomas: solve ``lower[e] x[e-1] + diag[e] x[e] + upper[e] x[e+1] = rhs[e]``.

    Blocks (m, ..., 3, 3), right-hand sides (m, ..., 3); ``lower[0]`` and
    ``upper[-1]`` are ignored. The spline systems are block diagonally dominant
    (diagonal ``4 (1/h + 1/h')``, off-diagonal norms ``<= 2/h`` and ``<= pi/h'``),
    so no pivoting is needed. One Python step per block row.
    """
    m = diag.shape[0]
    d_inv = [None] * m
    r = [None] * m
    d_inv[0], r[0] = _inv3(xp, diag[0]), rhs[0]
    for e in range(1, m):
        w = lower[e] @ d_inv[e - 1]
        d_inv[e] = _inv3(xp, diag[e] - w @ upper[e - 1])
        r[e] = rhs[e] - matvec(w, r[e - 1])
    x = [None] * m
    x[m - 1] = matvec(d_inv[m - 1], r[m - 1])
    for e in range(m - 2, -1, -1):
        x[e] = matvec(d_inv[e], r[e] - matvec(upper[e], x[e + 1]))
    return xp.stack(x, axis=0)


def _inv3(xp, a):
    """Inverses of 3x3 blocks (..., 3, 3) by the adjugate of ``a / max|a_ij|``
    (:func:`rigidkit.kernels.homogeneous.affine_inverse`), not ``linalg.inv``:
    torch's checks its input for singularity as a side effect, which Inductor
    cannot compile inside the Newton solve's while_loop (torch 2.13). The blocks
    are diagonally dominant (above), so the adjugate loses nothing."""
    return _kh.affine_inverse(xp.concat([a, a[..., :1] * 0.0], axis=-1))[0][..., :3]
