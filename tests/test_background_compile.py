"""``RIGIDKIT_BACKGROUND_COMPILE=0``: no speculative compile, the same numbers.

By default a NumPy batch whose compiled loop is not ready queues that loop on the
engine's background thread; with the variable set to 0 nothing is queued unless a
caller waits for a loop (``backend="numba"``), and the batch is served by the
Python-float and element-wise NumPy bindings. Checked in fresh processes on a cold
cache (the variable is read at import); the reference is scipy.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

from rigidkit._engine import numba_backend

_CODE = textwrap.dedent(
    """
    import json
    import numpy as np
    from scipy.spatial.transform import Rotation as R_scipy
    import rigidkit as rk
    from rigidkit._engine import numba_backend

    rotvecs = np.random.default_rng(0).normal(size=(40, 3))
    worst = 0.0
    for dtype in (np.float64, np.float32):
        for _ in range(80):  # past the one-element threshold too
            m = rk.Rotation.from_rotvec(rotvecs.astype(dtype)).as_matrix()
            one = rk.Rotation.from_rotvec(rotvecs[0].astype(dtype)).as_matrix()
        ref = R_scipy.from_rotvec(rotvecs).as_matrix()
        assert m.dtype == dtype and one.dtype == dtype
        unit = 1e-15 if dtype is np.float64 else 1e-6
        worst = max(worst, float(np.abs(m - ref).max()) / unit)
    queued = len(numba_backend._PENDING)
    waited = rk.kernels.so3.quat_from_rotvec(rotvecs, backend="numba")
    print(json.dumps({"queued": queued, "after_wait": len(numba_backend._PENDING),
                      "worst": worst, "waited_ok": bool(np.isfinite(waited).all())}))
    """
)


def _run(tmp_path, value):
    env = dict(os.environ, RIGIDKIT_CACHE_DIR=str(tmp_path))
    env.pop("RIGIDKIT_DISABLE_NUMBA", None)
    env.pop("RIGIDKIT_BACKGROUND_COMPILE", None)
    if value is not None:
        env["RIGIDKIT_BACKGROUND_COMPILE"] = value
    res = subprocess.run(
        [sys.executable, "-c", _CODE], capture_output=True, text=True, env=env, timeout=300
    )
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_off_queues_nothing_and_computes_the_same(tmp_path):
    if not numba_backend.available():
        pytest.skip("needs numba")
    out = _run(tmp_path, "0")
    assert out["queued"] == 0, out
    assert out["worst"] <= 4, out  # within 4 ulp-scale units of scipy, both dtypes
    # A caller that waits still gets the compiled loop.
    assert out["after_wait"] >= 1 and out["waited_ok"], out


def test_default_queues_the_loops(tmp_path):
    if not numba_backend.available():
        pytest.skip("needs numba")
    out = _run(tmp_path, None)
    assert out["queued"] >= 2, out  # at least a batch loop per dtype
    assert out["worst"] <= 4, out
