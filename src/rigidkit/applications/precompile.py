"""Compile every shipped kernel's numba loops into the disk cache (an install step).

``python -m rigidkit.applications.precompile [-v]`` compiles the plain loop of every
kernel for float64 and float32, then runs the common calls of the object layer once
with every batch waiting for its loop, which compiles the remaining variants they
use (one rotation applied to many points, Euler sequences and their parameters).
A later process's background thread then only loads loops from disk: numba's
import (~0.5 s) and a few ms per loop, with no compile. Without this step the
first process that batches a kernel compiles its loop in the background
(0.2-1 s each) while the vectorised NumPy path serves its calls.

The cache folder is ``$RIGIDKIT_CACHE_DIR`` or ``~/.cache/rigidkit``.
"""

from __future__ import annotations

import sys
import time


def shipped_kernels() -> list:
    """Every kernel defined in :mod:`rigidkit.kernels`."""
    import rigidkit.kernels as pkg
    from rigidkit._engine import Kernel

    found = {}
    for module in pkg.modules():
        for obj in vars(module).values():
            if isinstance(obj, Kernel):
                found[(obj.fn.__module__, obj.name)] = obj
    return sorted(found.values(), key=lambda k: (k.fn.__module__, k.name))


def common_calls(dtype) -> None:
    """The object layer's common batched calls, once each, on 2 elements of ``dtype``."""
    import numpy as np

    import rigidkit as rk

    rng = np.random.default_rng(0)
    R = rk.Rotation.from_quat(rng.standard_normal((2, 4)).astype(dtype))
    v = rng.standard_normal((2, 3)).astype(dtype)
    R @ R
    R.apply(v)
    R[0].apply(v)
    R.inv()
    R.as_matrix()
    rk.Rotation.from_matrix(R.as_matrix())
    R.as_rotvec()
    rk.Rotation.from_rotvec(v)
    for seq in ("ZYX", "XYZ", "ZYZ", "zyx", "xyz", "zxz"):
        for degrees in (False, True):
            e = R.as_euler(seq, degrees=degrees)
            rk.Rotation.from_euler(seq, e, degrees=degrees)
    T = rk.Transform(rotation=R, translation=v)
    T @ T
    T @ v
    T[0] @ v
    T.inv()
    T.as_matrix()
    rk.Transform.from_matrix(T.as_matrix())
    T.log()
    rk.Transform.exp(T.log())


def main(argv=None) -> int:
    import numpy as np

    from rigidkit._engine import cache_dir, numba_available, precompile, waiting_for_loops

    argv = sys.argv[1:] if argv is None else argv
    verbose = "-v" in argv
    if not numba_available():
        print("rigidkit: numba is not available; nothing to compile")
        return 0
    t0 = time.perf_counter()
    count = precompile(shipped_kernels(), verbose=verbose)
    with waiting_for_loops():  # every batch below waits for (compiles) its loop
        for dtype in (np.float64, np.float32):
            common_calls(dtype)
    dt = time.perf_counter() - t0
    print(
        f"rigidkit: {count} kernel loops and the common variants compiled or loaded "
        f"in {dt:.1f} s into {cache_dir()}"
    )
    return 0


if __name__ == "__main__":  # pragma: no cover - install step
    sys.exit(main())
