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


# A long switch interval magnifies the GIL's convoy effect (numba_loads.switch_fast):
# without the lowered interval the loading thread waited a whole interval for the
# GIL after each of its ~2000 file reads, stats and llvmlite calls whenever the
# caller's thread took it meanwhile (4 s to the loop at 50 ms, 0.4-0.7 s with it).
_SPIN = textwrap.dedent(
    """
    import json, sys, time
    sys.setswitchinterval(0.1)
    import numpy as np
    t0 = time.perf_counter()
    import rigidkit as rk
    from rigidkit._engine import numba_backend

    R = rk.Rotation.from_quat(np.array([0.5, 0.5, 0.5, 0.5]))
    ready, jobs = None, []
    while time.perf_counter() - t0 < 30:  # the caller never idle: it shares the GIL
        for _ in range(200):
            R.as_matrix()
        jobs = list(numba_backend._PENDING.values())
        if jobs and all(j.done.is_set() for j in jobs):
            ready = time.perf_counter() - t0
            break
    print(json.dumps({"ready": ready, "queued": len(jobs),
                      "errors": [repr(j.error) for j in jobs if j.error is not None],
                      "interval": sys.getswitchinterval(),
                      "arrayobj": "numba.np.arrayobj" in sys.modules}))
    """
)


def test_loops_load_while_the_caller_spins(tmp_path):
    if not numba_backend.available():
        pytest.skip("needs numba")
    env = dict(os.environ, RIGIDKIT_CACHE_DIR=str(tmp_path))
    for name in (
        "RIGIDKIT_DISABLE_NUMBA",
        "RIGIDKIT_BACKGROUND_COMPILE",
        "RIGIDKIT_SWITCH_INTERVAL",
    ):
        env.pop(name, None)
    # A warm cache first: the timed process only loads its loop from disk.
    warm = (
        "import numpy as np, rigidkit as rk\n"
        "from rigidkit._engine import numba_backend\n"
        "R = rk.Rotation.from_quat(np.array([0.5, 0.5, 0.5, 0.5]))\n"
        "for _ in range(100):\n    R.as_matrix()\n"
        "assert numba_backend.drain(300)\n"
    )
    for src in (warm, _SPIN):
        res = subprocess.run(
            [sys.executable, "-c", src],
            capture_output=True,
            text=True,
            env=env,
            timeout=300,
        )
        assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert out["queued"] >= 1 and not out["errors"], out
    # ~0.4 s on an idle 2-core machine (numba's import and the load, ~0.17 s of
    # CPU, sharing the GIL with the caller); 8 s or more before the fix.
    assert out["ready"] is not None and out["ready"] < 4.0, out
    assert out["interval"] == pytest.approx(0.1, abs=1e-6), out  # the caller's, restored
    # The one-element loop writes its outputs by index, no reshape: reading it back
    # does not import numba.np.arrayobj (20 ms of the ~170 before it is ready).
    assert not out["arrayobj"], out


def test_switch_interval_lowered_then_restored():
    from rigidkit._engine import numba_loads

    before = sys.getswitchinterval()
    try:
        sys.setswitchinterval(0.02)
        numba_loads.switch_fast()
        assert sys.getswitchinterval() == pytest.approx(numba_loads.SWITCH_INTERVAL)
        numba_loads.switch_back()
        assert sys.getswitchinterval() == 0.02  # exactly: no microsecond lost
        # An interval the process sets meanwhile is its own: kept.
        numba_loads.switch_fast()
        sys.setswitchinterval(0.03)
        numba_loads.switch_back()
        assert sys.getswitchinterval() == 0.03
        # Already shorter than ours: left alone.
        sys.setswitchinterval(1e-4)
        numba_loads.switch_fast()
        assert sys.getswitchinterval() == pytest.approx(1e-4)
        numba_loads.switch_back()
        assert sys.getswitchinterval() == pytest.approx(1e-4)
    finally:
        numba_loads.switch_back()
        sys.setswitchinterval(before)
