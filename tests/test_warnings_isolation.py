"""The caller's warnings while the engine compiles loops in the background.

numba's compiler enters ``warnings.catch_warnings()`` and sets filters around its
passes; before Python 3.14 that state is the process's, so without the engine's
shim (``_engine/compile_warnings.py``) a warning issued on the caller's thread
meanwhile missed the caller's ``catch_warnings(record=True)`` (or was recorded
twice, or by numba), about 1 call in 1,000 while a loop compiled. The stress
test records warnings on the main thread, in a fresh process with an empty
kernel cache, for as long as the background thread compiles.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import warnings

import pytest

pytest.importorskip("numba")

from rigidkit._engine import compile_warnings  # noqa: E402

_STRESS = textwrap.dedent(
    """
    import json, sys, time, warnings
    import numpy as np
    import rigidkit as rk
    from rigidkit._engine import numba_backend as nb

    filters = list(warnings.filters)
    # Threads switch every 20 us (5 ms by default): many more interleavings of
    # this thread's warnings with numba's, so that a few seconds show a race.
    sys.setswitchinterval(2e-5)
    # numba imported and its context set up here first: the background thread
    # then goes straight to compiling, where numba's warning state changes.
    from numba.core.registry import cpu_target
    cpu_target.target_context.refresh()
    R = rk.Rotation.random(3, rng=0)
    # Cold cache: each of these asks the background thread for a compile.
    R.as_matrix(); R @ R; R.inv()
    gimbal = rk.Rotation.from_euler("ZYX", [0.3, np.pi / 2, 0.1])
    calls = missed = foreign = lock_missed = during = 0
    end = time.monotonic() + SECONDS
    while time.monotonic() < end:
        busy = not nb.drain(0)
        for k in range(200):
            with warnings.catch_warnings(record=True) as log:
                warnings.simplefilter("always")
                if k % 50:
                    warnings.warn("mine", UserWarning)
                    want = UserWarning
                else:  # rigidkit's own warning, as pytest.warns sees it
                    gimbal.as_euler("ZYX")
                    want = rk.GimbalLockWarning
            calls += 1
            during += busy
            mine = [w for w in log if w.category is want]
            if len(mine) != 1:
                missed += 1
                lock_missed += want is not UserWarning
            foreign += len(log) - len(mine)
        if not busy:
            break
    print(json.dumps({
        "calls": calls, "during": during, "missed": missed, "foreign": foreign,
        "lock_missed": lock_missed, "filters_kept": list(warnings.filters) == filters,
    }))
    """
)
SECONDS = 5


def test_warnings_recorded_while_loops_compile(tmp_path):
    """Every warning of the caller's reaches its recording, none of numba's does,
    and the filters are the caller's, while loops compile (a cold cache)."""
    env = dict(os.environ, RIGIDKIT_CACHE_DIR=str(tmp_path))
    env.pop("RIGIDKIT_DISABLE_NUMBA", None)
    res = subprocess.run(
        [sys.executable, "-c", f"SECONDS = {SECONDS}\n" + _STRESS],
        capture_output=True,
        text=True,
        env=env,
        timeout=240,
    )
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout.strip().splitlines()[-1])
    # The recording overlapped the compiles (numba's import and two loops).
    assert out["during"] > 1000, out
    assert out["missed"] == 0, out
    assert out["foreign"] == 0, out
    assert out["filters_kept"], out


def test_shim_is_warnings_off_the_compile_thread():
    """On any thread but the compile thread the shim is :mod:`warnings` itself."""
    with warnings.catch_warnings(record=True) as log:
        warnings.simplefilter("always")
        compile_warnings.SHIM.warn("through the shim", RuntimeWarning)
    assert [(w.category, str(w.message)) for w in log] == [
        (RuntimeWarning, "through the shim")
    ]
    assert log[0].filename == __file__  # attributed to the caller, not the shim


def test_shim_keeps_warnings_on_an_isolated_thread():
    """Inside ``isolate()`` numba's recordings and filters are the thread's own:
    the process's filters are untouched and nothing reaches its recording."""
    shim = compile_warnings.SHIM
    with warnings.catch_warnings(record=True) as outer:
        warnings.simplefilter("always")
        filters = list(warnings.filters)
        with compile_warnings.isolate():
            with shim.catch_warnings(record=True) as inner:
                shim.simplefilter("ignore")
                assert list(warnings.filters) == filters
                shim.warn_explicit("numba's", UserWarning, "f.py", 3)
            shim.warn("unrecorded", UserWarning)
        assert list(warnings.filters) == filters
    assert outer == []
    got = [(str(w.message), w.filename, w.lineno) for w in inner]
    assert got == [("numba's", "f.py", 3)]
    assert str(compile_warnings.compile_warnings()[-1].message) == "unrecorded"


_FIRST_COMPILE = textwrap.dedent(
    """
    import json, sys, threading, warnings
    import numpy as np

    # Every call that changes the process's warning state, by thread name.
    seen = []
    real_enter = warnings.catch_warnings.__enter__
    def enter(self):
        seen.append(("catch_warnings", threading.current_thread().name))
        return real_enter(self)
    warnings.catch_warnings.__enter__ = enter
    for name in ("filterwarnings", "simplefilter", "resetwarnings"):
        real = getattr(warnings, name)
        def spy(*a, _real=real, _name=name, **k):
            seen.append((_name, threading.current_thread().name))
            return _real(*a, **k)
        setattr(warnings, name, spy)

    assert "scipy" not in sys.modules
    import rigidkit as rk
    R = rk.Rotation.random(3, rng=0)
    # A cold cache: numba's first compile, with its BLAS probe's scipy import.
    m = rk.kernels.so3.quat_from_rotvec(R.as_rotvec(), backend="numba")
    print(json.dumps({
        "compile_thread": [c for c in seen if c[1] == "rigidkit-numba"],
        "scipy_util": "scipy._lib._util" in sys.modules,
        "shim": type(sys.modules["scipy._lib._util"].warnings).__name__,
        "warnings_module": sys.modules["warnings"] is warnings,
    }))
    """
)


def test_first_compile_imports_keep_warnings_on_the_compile_thread(tmp_path):
    """numba's first compile imports scipy.linalg, whose ``scipy._lib._util``
    enters ``catch_warnings`` in its body: on the compile thread that never
    reaches the process's warning state (a cold cache, scipy not imported)."""
    env = dict(os.environ, RIGIDKIT_CACHE_DIR=str(tmp_path))
    env.pop("RIGIDKIT_DISABLE_NUMBA", None)
    res = subprocess.run(
        [sys.executable, "-c", _FIRST_COMPILE],
        capture_output=True,
        text=True,
        env=env,
        timeout=240,
    )
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    pytest.importorskip("scipy")
    assert out["scipy_util"], out  # the case arose
    assert out["compile_thread"] == [], out
    assert out["shim"] == "_Shim" and out["warnings_module"], out
