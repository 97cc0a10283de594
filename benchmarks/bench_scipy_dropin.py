"""``rigidkit.scipy`` against scipy itself: the drop-in classes on scipy's common ops.

Times, in ONE process and interleaved (medians of ``--repeat`` rounds), each op of
``scipy.spatial.transform`` and the same call on ``rigidkit.scipy`` at N = 1 (a
single rotation, shape ``()``), 100, 10,000 and 1,000,000, and prints the ratio
scipy / rigidkit (above 1: the drop-in is faster). The inputs are the same arrays
for both, built before timing; the compiled loops are loaded (``drain``) first.
By default the clock is the CPU time of the whole process (``--clock process``):
on a shared machine it does not count the time the process waits for a core, and
it does not credit rigidkit's loops that split a large batch over threads (their
CPU time is summed); ``--clock wall`` for elapsed time.

    python benchmarks/bench_scipy_dropin.py
    python benchmarks/bench_scipy_dropin.py --sizes 1 100 --repeat 9 --ops from_quat apply
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _common as C  # noqa: E402
import scipy.spatial.transform as sst  # noqa: E402

import rigidkit.scipy as rks  # noqa: E402
from rigidkit._engine import numba_backend  # noqa: E402

SIZES = [1, 100, 10_000, 1_000_000]


def inputs(n, rng):
    """The shared arrays of size ``n`` (``n = 1``: single elements)."""
    shape = () if n == 1 else (n,)
    q = rng.standard_normal(shape + (4,))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    v = rng.standard_normal(shape + (3,))
    e = rng.uniform(-1.5, 1.5, shape + (3,))
    t = rng.standard_normal(shape + (3,))
    keys = rng.standard_normal((10, 4))
    times = rng.uniform(0.0, 9.0, shape)
    return {"q": q, "v": v, "e": e, "t": t, "keys": keys, "times": times}


def ops(lib, d):
    """Zero-argument callables of one library on the arrays ``d``."""
    R, RT, Slerp = lib.Rotation, lib.RigidTransform, lib.Slerp
    r = R.from_quat(d["q"])
    r2 = R.from_quat(d["q"][..., ::-1].copy())
    m = r.as_matrix()
    rv = r.as_rotvec()
    tf = RT.from_components(d["t"], r)
    tf2 = RT.from_components(d["v"], r2)
    slerp = Slerp(np.arange(10.0), R.from_quat(d["keys"]))
    q, v, e, times = d["q"], d["v"], d["e"], d["times"]
    return {
        "from_quat": lambda: R.from_quat(q),
        "as_quat": lambda: r.as_quat(),
        "as_matrix": lambda: r.as_matrix(),
        "from_matrix": lambda: R.from_matrix(m),
        "from_euler": lambda: R.from_euler("xyz", e),
        "as_euler": lambda: r.as_euler("xyz"),
        "from_rotvec": lambda: R.from_rotvec(rv),
        "as_rotvec": lambda: r.as_rotvec(),
        "apply": lambda: r.apply(v),
        "compose *": lambda: r * r2,
        "inv": lambda: r.inv(),
        "magnitude": lambda: r.magnitude(),
        "slerp": lambda: slerp(times),
        "RT apply": lambda: tf.apply(v),
        "RT compose *": lambda: tf * tf2,
    }


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=int, nargs="+", default=SIZES)
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--ops", nargs="+", default=None)
    p.add_argument("--json", default=None)
    p.add_argument("--clock", choices=["process", "wall", "thread"], default="process")
    args = p.parse_args(argv)
    C.CLOCKS.setdefault("process", time.process_time)
    C.set_clock(args.clock)
    rng = np.random.default_rng(0)
    warnings.simplefilter("ignore")  # gimbal-lock warnings of random angles: not timed
    results, rows = {}, []
    names = None
    for n in args.sizes:
        d = inputs(n, rng)
        theirs, ours = ops(sst, d), ops(rks, d)
        names = args.ops or list(theirs)
        for name in names:  # warm up and load every compiled loop first
            ours[name]()
        numba_backend.drain()
        for name in names:
            res = C.interleaved_medians(
                {"scipy": theirs[name], "rigidkit.scipy": ours[name]},
                repeat=args.repeat,
                min_sample=0.005 if n < 1_000_000 else 0.05,
            )
            s, k = res["scipy"]["median"], res["rigidkit.scipy"]["median"]
            results.setdefault(name, {})[n] = {"scipy_s": s, "rigidkit_s": k}
            print(
                f"{name:>14} N={n:<8} scipy {s * 1e6:10.2f} us  rigidkit.scipy "
                f"{k * 1e6:10.2f} us  ratio {s / k:6.2f}",
                flush=True,
            )
    headers = ["op"] + [f"N={n:,}" for n in args.sizes]
    for name in names:
        rows.append(
            [name]
            + [
                f"{results[name][n]['scipy_s'] / results[name][n]['rigidkit_s']:.2f}"
                for n in args.sizes
            ]
        )
    print("\nscipy time / rigidkit.scipy time (medians; > 1: rigidkit.scipy is faster)")
    print(C.table(headers, rows))
    behind = [
        (name, n)
        for name in names
        for n in args.sizes
        if results[name][n]["scipy_s"] < results[name][n]["rigidkit_s"]
    ]
    print("cells behind scipy:", behind or "none")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
