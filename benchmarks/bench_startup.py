"""Start-up curve: the cost of a one-element call against the time since import.

Each run is a fresh process (a warm disk cache: the loops are compiled once
beforehand, as ``python -m rigidkit.applications.precompile`` does at install)
that imports rigidkit, then calls one op on one element in blocks of
``--block`` calls for ``--seconds`` seconds, and reports each block's time per
call with the time since ``import rigidkit`` began. Per time window the median
over the blocks of a run, then the median over ``--runs`` runs, and the ratio
of each window to the steady state (the last window). Also the time from
import to the loops of the op's first calls, the caller idle and the caller
calling the op all along (sharing the GIL with the loading thread), and the
import time (medians over the runs).

    python benchmarks/bench_startup.py
    python benchmarks/bench_startup.py --ops as_matrix compose --runs 7
    python benchmarks/bench_startup.py --json out.json
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

#: Window edges in seconds since import began; the last window is the steady state.
EDGES = (0.0, 0.1, 0.2, 0.3, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0)

#: One-element ops: setup code (``rk``, ``np`` in scope) and the call timed.
OPS = {
    "as_matrix": (
        "R = rk.Rotation.from_quat(np.array([0.5, 0.5, 0.5, 0.5]))",
        "R.as_matrix()",
    ),
    "compose": (
        "R = rk.Rotation.from_quat(np.array([0.5, 0.5, 0.5, 0.5]))",
        "R @ R",
    ),
    "apply": (
        "R = rk.Rotation.from_quat(np.array([0.5, 0.5, 0.5, 0.5]))\n"
        "v = np.array([1.0, 2.0, 3.0])",
        "R.apply(v)",
    ),
    "from_rotvec": ("r = np.array([0.1, 0.2, 0.3])", "rk.Rotation.from_rotvec(r)"),
    "transform_matrix": (
        "T = rk.Transform.from_pq(np.array([1.0, 2, 3]), np.array([0.5, 0.5, 0.5, 0.5]))",
        "T.as_matrix()",
    ),
}

_CHILD = r"""
import sys, time, json
t0 = time.perf_counter()
import numpy as np
t_np = time.perf_counter()
import rigidkit as rk
t_imp = time.perf_counter()
{setup}
def call():
    {call}
block, seconds = {block}, {seconds}
out = []
pc = time.perf_counter
while True:
    a = pc()
    for _ in range(block):
        call()
    b = pc()
    out.append((a - t_np, (b - a) / block))
    if b - t_np > seconds:
        break
print(json.dumps({{"import": t_imp - t_np, "blocks": out}}))
"""


_READY = r"""
import time, json
import numpy as np
t0, c0 = time.perf_counter(), time.process_time()
import rigidkit as rk
from rigidkit._engine import numba_backend
t1 = time.perf_counter()
{setup}
for _ in range(100):  # past the calls after which a one-element loop is asked for
    {call}
numba_backend.drain()  # the caller's thread idle: the time is the loading thread's
print(json.dumps({{"import": t1 - t0, "wall": time.perf_counter() - t1,
                  "cpu": time.process_time() - c0}}))
"""


_SPIN = r"""
import time, json
import numpy as np
import rigidkit as rk
from rigidkit._engine import numba_backend
t1 = time.perf_counter()
{setup}
def call():
    {call}
jobs = numba_backend._PENDING
while True:  # the caller busy: it and the loading thread share the GIL
    for _ in range(200):
        call()
    if jobs and all(j.done.is_set() for j in list(jobs.values())):
        break
print(json.dumps({{"wall": time.perf_counter() - t1}}))
"""


def run_ready(op, env, spin=False):
    """Seconds from import to the loops of ``op``'s first calls ready, the caller
    idle (wall and the process's CPU time, import included: the latter hardly
    depends on the machine's load), or ``spin``: the caller calling ``op`` all
    along (wall only)."""
    setup, call = OPS[op]
    src = (_SPIN if spin else _READY).format(setup=setup, call=call)
    res = subprocess.run(
        [sys.executable, "-c", src], capture_output=True, text=True, env=env, check=True
    )
    return json.loads(res.stdout.strip().splitlines()[-1])


def run_child(op, block, seconds, env):
    setup, call = OPS[op]
    src = _CHILD.format(setup=setup, call=call, block=block, seconds=seconds)
    res = subprocess.run(
        [sys.executable, "-c", src], capture_output=True, text=True, env=env, check=True
    )
    return json.loads(res.stdout.strip().splitlines()[-1])


def windows(blocks, stat):
    """``stat`` (median or mean) of the time per call of the blocks in each window
    of ``EDGES``. The median is the call's own cost; the mean also counts the
    blocks in which the thread waited for the GIL (a loading thread holds it)."""
    res = []
    for lo, hi in zip(EDGES[:-1], EDGES[1:]):
        xs = [dt for t, dt in blocks if lo <= t < hi]
        res.append(stat(xs) if xs else float("nan"))
    return res


def _settled(med, steady, factor=1.3):
    """The start of the first window from which every median is within ``factor``
    of the steady state (windows with no block count as within)."""
    k = len(med)
    while k > 0 and not med[k - 1] > factor * steady:
        k -= 1
    return EDGES[k]


def warm_cache(ops, env):
    """Run each op long enough, once, that every loop it uses is on disk."""
    for op in ops:
        setup, call = OPS[op]
        src = (
            "import numpy as np, rigidkit as rk\n"
            "from rigidkit._engine import numba_backend\n"
            f"{setup}\n"
            f"for _ in range(200):\n    {call}\n"
            "numba_backend.drain()\n"
            f"for _ in range(200):\n    {call}\n"
            "numba_backend.drain()\n"
        )
        subprocess.run([sys.executable, "-c", src], env=env, check=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ops", nargs="+", default=["as_matrix", "compose"], choices=OPS)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--block", type=int, default=200)
    ap.add_argument("--seconds", type=float, default=EDGES[-1])
    ap.add_argument("--json", help="write the medians to this file")
    ap.add_argument("--ready-only", action="store_true", help="only the time to the loops")
    args = ap.parse_args(argv)
    env = dict(os.environ)
    warm_cache(args.ops, env)
    report = {}
    head = "".join(f"{f'{lo:g}-{hi:g}s':>10}" for lo, hi in zip(EDGES[:-1], EDGES[1:]))
    print(
        f"time per call (us) since import, median over {args.runs} fresh processes "
        "of each window's median (mean: with the GIL waits) block; ratio: to the last"
    )
    print(f"{'op':<18}{head}")
    imports = []
    for op in [] if args.ready_only else args.ops:
        medians, means = [], []
        for _ in range(args.runs):
            res = run_child(op, args.block, args.seconds, env)
            imports.append(res["import"])
            medians.append(windows(res["blocks"], statistics.median))
            means.append(windows(res["blocks"], statistics.fmean))
        med = [statistics.median(col) * 1e6 for col in zip(*medians)]
        mean = [statistics.median(col) * 1e6 for col in zip(*means)]
        steady = med[-1]
        print(f"{op + ' median':<18}" + "".join(f"{m:10.2f}" for m in med))
        print(f"{'  ratio':<18}" + "".join(f"{m / steady:10.2f}" for m in med))
        print(f"{'  mean':<18}" + "".join(f"{m:10.2f}" for m in mean))
        print(f"{'  ratio':<18}" + "".join(f"{m / mean[-1]:10.2f}" for m in mean))
        since = _settled(med, steady)
        print(f"{'  within 1.3x':<18}from {since:g} s after import")
        report[op] = {"median_us": med, "mean_us": mean, "within_1.3x_from_s": since}
    for op in args.ops:
        runs = [run_ready(op, env) for _ in range(args.runs)]
        imports += [r["import"] for r in runs]
        wall = statistics.median(r["wall"] for r in runs)
        cpu = statistics.median(r["cpu"] for r in runs)
        print(
            f"{op}: loops ready {wall * 1e3:.0f} ms after import (caller idle), "
            f"process CPU from import to ready {cpu * 1e3:.0f} ms"
        )
        spun = statistics.median(run_ready(op, env, True)["wall"] for _ in range(args.runs))
        pad = " " * (len(op) + 2)
        print(f"{pad}loops ready {spun * 1e3:.0f} ms after import (caller spinning)")
        report.setdefault(op, {}).update(ready_s=wall, ready_cpu_s=cpu, ready_spin_s=spun)
    imp = statistics.median(imports)
    print(f"import rigidkit: {imp * 1e3:.0f} ms (median of {len(imports)} processes)")
    report["import_s"] = imp
    report["edges_s"] = list(EDGES)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(report, fh, indent=1)


if __name__ == "__main__":
    main()
