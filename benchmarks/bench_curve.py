"""The whole curve: us per call at N = 1, 10, ..., 1e6 for every op, against every peer.

For each op of ``bench_so3.py`` and ``bench_se3.py`` (the same rows, inputs and
idioms, built by their ``build_rows``), this times rigidkit and every installed
peer (scipy, numpy-quaternion, quaternionic, pytransform3d; a missing one is
skipped with a note) side by side in ONE process, at each batch size, and prints
microseconds per call with, for rigidkit, the ratio to the fastest peer in each
cell (``0.5x`` = twice as fast as the best peer). Then, in fresh interpreters:
``import rigidkit``, the first small and the first large call (with the kernel
cache on disk, and with an empty one), and a whole short script (import and
compose 2,000 rotations) against the same with scipy.

```
python benchmarks/bench_curve.py                       # everything (~10 min)
python benchmarks/bench_curve.py --sizes 1 10 100 --ops compose apply --no-fresh
python benchmarks/bench_curve.py --markdown curve.md   # also the README table
```

How a number is taken (see ``_common.py``): every callable is called before timing;
rigidkit's compiled loops are loaded by its background thread first
(``numba_backend.drain``), so the steady state is timed and the first calls are
reported separately (the fresh-process section). A sample is ``k`` back-to-back
calls lasting at least ``--min-sample``; the samples of all contenders of a cell are
taken round-robin and the median is reported.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

_argv = sys.argv[1:]
if "--clock" in _argv[:-1] and _argv[_argv.index("--clock") + 1] == "thread":
    # The thread clock counts only the calling thread: keep BLAS on it too.
    for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _common as C  # noqa: E402
import bench_se3 as SE3  # noqa: E402
import bench_so3 as SO3  # noqa: E402

SIZES = [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000]
SO3_OPS = [
    "compose",
    "apply",
    "apply cloud",
    "inv",
    "as_matrix",
    "as_matrix out=",
    "from_matrix",
    "from_euler ZYX",
    "as_euler ZYX",
    "from_euler ZYZ",
    "as_euler ZYZ",
    "from_rotvec",
    "as_rotvec",
    "apply out=",
]
SE3_OPS = [
    "compose",
    "apply",
    "apply cloud",
    "inv",
    "exp",
    "log",
    "as_matrix",
    "from_matrix",
]
SO3_PEERS = ["scipy", "numpy-quaternion", "quaternionic", "pytransform3d"]
SE3_PEERS = ["scipy", "pytransform3d", "pt3d dq"]
SHORT = {
    "rigidkit": "rigidkit",
    "scipy": "scipy",
    "numpy-quaternion": "np-quat",
    "quaternionic": "qtnionic",
    "pytransform3d": "pt3d",
    "pt3d dq": "pt3d dq",
}


def size_label(n: int) -> str:
    return {1: "1", 10: "10", 100: "100"}.get(n) or f"1e{round(np.log10(n))}"


class Group:
    """One family of ops (SO(3) or SE(3)): its module, libraries, rows and peers."""

    def __init__(self, name, module, peers, ops):
        self.name, self.module, self.peers = name, module, peers
        self.libs = module.Libs()
        rows = {r.key: r for r in module.build_rows(self.libs)}
        self.rows = [rows[k] for k in ops if k in rows]
        self.data = {}

    def make(self, n):
        if self.module is SO3:
            return SO3.make_data(n, self.libs)
        return SE3.make_data(n)


def warm_rigidkit(groups, ns=(1, 10, 3, 2000)) -> None:
    """Call every rigidkit op, then wait for its compiled loops (the background thread).

    The loops depend on the dtype and broadcast pattern, not on N, so a few sizes
    reach every one (2,000 also warms an engine that compiles only above 1,000
    elements); later ops (a result fed to another kernel) ask for theirs on the
    second round. Each op is called 100 times at one element, so that hot kernels
    get their one-element loop.
    """
    from rigidkit._engine import numba_backend

    for _ in range(2):
        for g in groups:
            for n in ns:
                d = g.make(n)
                for r in g.rows:
                    if r.batched_only and d.single:
                        continue
                    fn = r.impls["rigidkit"](d)
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        for _ in range(100 if d.single else 1):
                            fn()
        drain = getattr(numba_backend, "drain", None)
        if drain is not None:  # an engine without a background loader compiles inline
            drain(timeout=900)


def time_cell(g, r, d, args) -> dict:
    fns = {}
    for lib in ["rigidkit", *g.peers]:
        builder = r.impls.get(lib)
        if builder is None:
            continue
        fn = builder(d)
        if fn is not None:
            fns[lib] = fn
    repeat = args.repeat if d.n <= 10_000 else max(3, args.repeat // 2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = C.interleaved_medians(fns, repeat=repeat, min_sample=args.min_sample)
    return {lib: v["median"] * 1e6 for lib, v in res.items() if "median" in v}


def ratio(cell: dict, peers) -> float | None:
    best = [cell[p] for p in peers if p in cell]
    if "rigidkit" not in cell or not best:
        return None
    return cell["rigidkit"] / min(best)


def fmt_us(x) -> str:
    if x is None:
        return "-"
    if x >= 1e4:
        return f"{x / 1e3:.0f}k" if x < 1e6 else f"{x / 1e6:.2f}M"
    return f"{x:.3g}" if x < 100 else f"{x:.0f}"


def print_group(g, results, sizes) -> None:
    print(f"\n## {g.name}: us per call (median); rk/best = rigidkit / fastest peer\n")
    for r in g.rows:
        cells = results[(g.name, r.key)]
        libs = [
            lib for lib in ["rigidkit", *g.peers] if any(lib in c for c in cells.values())
        ]
        rows = []
        for lib in libs:
            rows.append([SHORT[lib]] + [fmt_us(cells[n].get(lib)) for n in sizes])
        rat = [ratio(cells[n], g.peers) for n in sizes]
        rows.append(["rk/best"] + [("-" if x is None else f"{x:.2f}x") for x in rat])
        print(C.table([r.key] + [f"N={size_label(n)}" for n in sizes], rows))
        print()


def markdown(groups, results, sizes) -> str:
    """One table per group: rigidkit us per call and the ratio to the best peer."""
    out = []
    for g in groups:
        head = "| op | " + " | ".join(f"N={size_label(n)}" for n in sizes) + " |"
        out += [f"**{g.name}**: rigidkit us per call (ratio to the fastest peer)", ""]
        out += [head, "|---" * (len(sizes) + 1) + "|"]
        for r in g.rows:
            cells = results[(g.name, r.key)]
            parts = []
            for n in sizes:
                c = cells.get(n, {})
                if "rigidkit" not in c:
                    parts.append("-")
                    continue
                x = ratio(c, g.peers)
                parts.append(fmt_us(c["rigidkit"]) + ("" if x is None else f" ({x:.2f}x)"))
            out.append(f"| {r.key} | " + " | ".join(parts) + " |")
        out.append("")
    return "\n".join(out)


# -- fresh processes -------------------------------------------------------------------
FIRST_CALLS = """
import json, time
t0 = time.perf_counter()
import numpy as np
LIB = {lib!r}
if LIB == "rigidkit":
    import rigidkit as rk
    make = rk.Rotation.from_quat
    compose = lambda a, b: a @ b
else:
    from scipy.spatial.transform import Rotation as SR
    make = lambda q: SR.from_quat(q, scalar_first=True)
    compose = lambda a, b: a * b
t1 = time.perf_counter()
rng = np.random.default_rng(0)
q1 = rng.standard_normal(({n}, 4))
q2 = rng.standard_normal(({n}, 4))
t2 = time.perf_counter()
a, b = make(q1), make(q2)
t3 = time.perf_counter()
compose(a, b)
t4 = time.perf_counter()
compose(a, b)
t5 = time.perf_counter()
# Until when is rigidkit on its interim path? Poll a small compose.
ready = None
if LIB == "rigidkit":
    s1, s2 = make(q1[:10]), make(q2[:10])
    while time.perf_counter() - t0 < {poll}:
        u = time.perf_counter()
        for _ in range(20):
            s1 @ s2
        if (time.perf_counter() - u) / 20 < 5e-6:
            ready = time.perf_counter() - t1
            break
        time.sleep(0.01)
print(json.dumps(dict(imp=t1 - t0, build=t3 - t2, first=t4 - t3, second=t5 - t4,
                      ready=ready)))
"""


def first_calls(lib, n, cache=None, poll=0.0) -> dict:
    env = {"RIGIDKIT_CACHE_DIR": cache} if cache else None
    return C.run_python(FIRST_CALLS.format(lib=lib, n=n, poll=poll), env=env)


SCRIPT = {
    "rigidkit": "import numpy as np, rigidkit as rk\n"
    "q = np.random.default_rng(0).standard_normal((2, 2000, 4))\n"
    "rk.Rotation.from_quat(q[0]) @ rk.Rotation.from_quat(q[1])\n",
    "scipy": "import numpy as np\nfrom scipy.spatial.transform import Rotation as SR\n"
    "q = np.random.default_rng(0).standard_normal((2, 2000, 4))\n"
    "SR.from_quat(q[0], scalar_first=True) * SR.from_quat(q[1], scalar_first=True)\n",
}


def script_wall(lib, repeat, cache=None) -> float:
    """Median wall seconds of a whole interpreter running ``SCRIPT[lib]``."""
    env = dict(os.environ)
    if cache:
        env["RIGIDKIT_CACHE_DIR"] = cache
    times = []
    for _ in range(repeat + 1):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", SCRIPT[lib]], check=True, env=env)
        times.append(time.perf_counter() - t0)
    return statistics.median(times[1:])  # the first warms the OS file cache


def fresh_section(args) -> dict:
    out = {}
    imp = C.import_times("rigidkit", args.import_repeat)
    out["import"] = imp
    print(
        f"\n## Fresh processes\n\nimport rigidkit: {imp['median'] * 1e3:.0f} ms "
        f"(median of {args.import_repeat}; heavy modules imported: "
        f"{', '.join(imp['heavy']) or 'none'})\n"
    )
    rows = []
    with tempfile.TemporaryDirectory() as empty:
        cases = [("rigidkit", "disk cache", None), ("rigidkit", "empty cache", empty)]
        cases.append(("scipy", "-", None))
        for lib, label, cache in cases:
            for n in (10, args.large):
                if cache is empty:  # a new empty cache for each run
                    cache = tempfile.mkdtemp(dir=empty)
                poll = 30.0 if lib == "rigidkit" else 0.0
                r = first_calls(lib, n, cache, poll=poll)
                out[(lib, label, n)] = r
                rows.append(
                    [
                        lib,
                        label,
                        f"{n:,}",
                        f"{r['imp'] * 1e3:.0f}",
                        f"{r['build'] * 1e3:.2f}",
                        f"{r['first'] * 1e3:.2f}",
                        f"{r['second'] * 1e3:.3f}",
                        "-" if r["ready"] is None else f"{r['ready']:.2f}",
                    ]
                )
    print(
        C.table(
            [
                "lib",
                "kernels",
                "N",
                "import ms",
                "2x from_quat ms",
                "1st compose ms",
                "2nd ms",
                "loops ready s",
            ],
            rows,
            left=2,
        )
    )
    print(
        "\n(loops ready: seconds after the import until a 10-element compose takes "
        "its compiled loop; before that the vectorised NumPy path serves.)\n"
    )
    with tempfile.TemporaryDirectory() as empty:
        walls = {
            "rigidkit (disk cache)": script_wall("rigidkit", args.import_repeat),
            "rigidkit (empty cache)": script_wall("rigidkit", args.import_repeat, empty),
            "scipy": script_wall("scipy", args.import_repeat),
        }
    out["script"] = walls
    print("whole process, import + compose 2,000 rotations (median wall):")
    for k, v in walls.items():
        print(f"  {k:24s} {v * 1e3:6.0f} ms")
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sizes", type=int, nargs="+", default=SIZES)
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--min-sample", type=float, default=0.01)
    p.add_argument("--ops", nargs="+", help="only rows whose name starts with one of these")
    p.add_argument("--groups", nargs="+", default=["SO(3)", "SE(3)"])
    p.add_argument("--no-fresh", action="store_true")
    p.add_argument("--import-repeat", type=int, default=5)
    p.add_argument("--large", type=int, default=100_000, help="the first large call's N")
    p.add_argument("--markdown", metavar="FILE", help="write the summary tables here")
    p.add_argument("--json", metavar="FILE")
    p.add_argument(
        "--clock",
        choices=["wall", "thread"],
        default="wall",
        help="wall clock (default), or CPU time of the calling thread: steadier on a "
        "busy machine; then rigidkit runs on one thread (RIGIDKIT_NUM_THREADS=1)",
    )
    args = p.parse_args(argv)
    C.set_clock(args.clock)
    if args.clock == "thread":
        os.environ["RIGIDKIT_NUM_THREADS"] = "1"

    groups = []
    if "SO(3)" in args.groups:
        groups.append(Group("SO(3)", SO3, SO3_PEERS, SO3_OPS))
    if "SE(3)" in args.groups:
        groups.append(Group("SE(3)", SE3, SE3_PEERS, SE3_OPS))
    for g in groups:
        if args.ops:
            g.rows = [r for r in g.rows if any(r.key.startswith(o) for o in args.ops)]
        for lib, note in g.libs.notes.items():
            print(f"note: {lib}: {note}")
    import rigidkit

    print(
        f"rigidkit {rigidkit.__version__}, numpy {np.__version__}, python "
        f"{platform.python_version()}; {C.cpu_count()} cores, load average "
        f"{C.load_average()} at the start"
    )
    for g in groups:
        bad = g.module.check_rows(g.rows, g.libs, sizes=(1, 5))
        for (key, lib), msg in bad.items():
            print(f"CHECK {g.name} {key} / {lib}: {msg}")
    warm_rigidkit(groups)

    results = {(g.name, r.key): {} for g in groups for r in g.rows}
    for n in args.sizes:
        for g in groups:
            d = g.make(n)
            for r in g.rows:
                if r.batched_only and d.single:
                    results[(g.name, r.key)][n] = {}
                    continue
                results[(g.name, r.key)][n] = time_cell(g, r, d, args)
            del d
        print(f"N={n:,} done, load average {C.load_average()}", file=sys.stderr)
    print(f"load average {C.load_average()} at the end of the timing")
    for g in groups:
        print_group(g, results, args.sizes)
    md = markdown(groups, results, args.sizes)
    fresh = None if args.no_fresh else fresh_section(args)
    if args.markdown:
        with open(args.markdown, "w") as fh:
            fh.write(md)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(
                {
                    "results": {f"{k[0]} {k[1]}": v for k, v in results.items()},
                    "fresh": None
                    if fresh is None
                    else {str(k): v for k, v in fresh.items()},
                },
                fh,
                indent=1,
            )


if __name__ == "__main__":
    main()
