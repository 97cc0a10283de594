"""Timing helpers shared by the benchmark scripts.

Nothing here imports rigidkit, so the helpers can also time it from the outside
(import time, first call in a fresh process).

How a number is taken
---------------------
* Every callable is called a few times before any timing (warm-up), so JIT
  compiles (rigidkit's numba loops, quaternionic's numba ufuncs) and first-touch
  effects are excluded from the timed samples. The cost of the compile itself is
  reported separately, by :func:`fresh_process`.
* A sample is ``number`` back-to-back calls with the garbage collector off, timed
  with ``time.perf_counter``; ``number`` is calibrated so that a sample lasts at
  least ``min_sample`` seconds (one call for a batch of a million, thousands for
  one element).
* The samples of all contenders of one row are taken round-robin (sample 1 of
  every contender, then sample 2, ...), so load from other processes on a shared
  machine hits every contender alike, and the MEDIAN of the samples is reported.

The memory-bandwidth floor
--------------------------
:class:`StreamFloor` compiles, for a given op, a numba loop that reads exactly the
bytes the op reads (every component of every input row) and writes exactly the
bytes it writes (every component of every output row), doing one addition per
component in between. No implementation of the op can move less data, so the
time of this loop is the floor. It is measured into a preallocated output (the
strict floor) and into a fresh ``np.empty`` output per call (what any function
that returns a new array also pays: page faults and the kernel zeroing the new
pages), on one core, and split in two halves over two threads (``nogil``) for
two cores.
"""

from __future__ import annotations

import gc
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

# -- timing ------------------------------------------------------------------------


CLOCKS = {"wall": time.perf_counter, "thread": time.thread_time}
_clock = time.perf_counter


def set_clock(name: str) -> None:
    """``"wall"`` (default) or ``"thread"`` (CPU time of the calling thread only)."""
    global _clock
    _clock = CLOCKS[name]


def time_calls(fn, number: int) -> float:
    """Seconds per call of ``fn()`` over ``number`` back-to-back calls (GC off)."""
    clock = _clock
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        t0 = clock()
        for _ in range(number):
            fn()
        t1 = clock()
    finally:
        if was_enabled:
            gc.enable()
    return (t1 - t0) / number


def calibrate(fn, min_sample: float) -> int:
    """Smallest number of calls, 1, 2, 5, 10, 20, ..., that lasts ``min_sample``."""
    number = 1
    while True:
        for factor in (1, 2, 5):
            n = number * factor
            if time_calls(fn, n) * n >= min_sample:
                return n
        number *= 10


def interleaved_medians(
    fns: dict, *, repeat: int, warmup: int = 2, min_sample: float = 0.02
) -> dict:
    """Median seconds per call of each zero-argument callable in ``fns``.

    Returns ``{name: {"median": s, "samples": [...], "number": k}}``. A callable
    that raises during warm-up is reported as ``{"error": "..."}`` and not timed.
    """
    plan = {}
    result = {}
    for name, fn in fns.items():
        try:
            for _ in range(warmup):
                fn()
            plan[name] = (fn, calibrate(fn, min_sample))
        except Exception as exc:  # a peer that cannot do this input: say so
            result[name] = {"error": f"{type(exc).__name__}: {exc}"[:200]}
    samples = {name: [] for name in plan}
    for _ in range(repeat):
        for name, (fn, number) in plan.items():
            samples[name].append(time_calls(fn, number))
    for name, (_, number) in plan.items():
        s = samples[name]
        result[name] = {"median": statistics.median(s), "samples": s, "number": number}
    return result


# -- the memory-bandwidth floor -------------------------------------------------------


def _floor_source(in_widths, out_width) -> str:
    args = [f"a{k}" for k in range(len(in_widths))] + ["o"]
    terms = [f"a{k}[i, {c}]" for k, w in enumerate(in_widths) for c in range(w)]
    # Pairwise sum: a short dependency chain, so the loop stays memory-bound.
    while len(terms) > 1:
        terms = [
            f"({terms[j]} + {terms[j + 1]})" if j + 1 < len(terms) else terms[j]
            for j in range(0, len(terms), 2)
        ]
    lines = [
        "def loop(start, stop, " + ", ".join(args) + "):",
        "    for i in range(start, stop):",
        f"        s = {terms[0]}",
    ]
    lines += [f"        o[i, {c}] = s + {float(c)}" for c in range(out_width)]
    return "\n".join(lines) + "\n"


class StreamFloor:
    """A numba loop that streams ``in_widths`` float64 rows in and ``out_width`` out.

    ``time(n, threads, fresh_output)`` returns the callable to time; bytes per
    element are ``8 * sum(in_widths)`` read and ``8 * out_width`` written.
    """

    _cache: dict = {}
    _pool = None

    def __init__(self, in_widths, out_width, dtype=np.float64):
        import numba

        key = (tuple(in_widths), out_width)
        if key not in StreamFloor._cache:
            namespace = {}
            exec(_floor_source(in_widths, out_width), namespace)
            StreamFloor._cache[key] = numba.njit(nogil=True, error_model="numpy")(
                namespace["loop"]
            )
        self.loop = StreamFloor._cache[key]
        self.in_widths = tuple(in_widths)
        self.out_width = out_width
        self.dtype = np.dtype(dtype)

    @property
    def bytes_read(self) -> int:
        return self.dtype.itemsize * sum(self.in_widths)

    @property
    def bytes_written(self) -> int:
        return self.dtype.itemsize * self.out_width

    def callable(self, n: int, threads: int = 1, fresh_output: bool = False):
        rng = np.random.default_rng(0)
        ins = [rng.standard_normal((n, w)).astype(self.dtype) for w in self.in_widths]
        out = np.empty((n, self.out_width), self.dtype)
        out.fill(0.0)  # touch the pages once, so the preallocated case has none to fault
        loop = self.loop
        width = self.out_width
        dtype = self.dtype
        if StreamFloor._pool is None:
            StreamFloor._pool = ThreadPoolExecutor(max_workers=4)
        pool = StreamFloor._pool
        bounds = [n * k // threads for k in range(threads + 1)]

        def run():
            o = np.empty((n, width), dtype) if fresh_output else out
            if threads == 1:
                loop(0, n, *ins, o)
                return o
            futs = [
                pool.submit(loop, bounds[k], bounds[k + 1], *ins, o)
                for k in range(1, threads)
            ]
            loop(bounds[0], bounds[1], *ins, o)
            for f in futs:
                f.result()
            return o

        return run


def cpu_count() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - non-Linux
        return os.cpu_count() or 1


def load_average() -> str:
    try:
        return " ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:  # pragma: no cover
        return "n/a"


# -- fresh processes -------------------------------------------------------------------


def run_python(code: str, env: dict | None = None, timeout: float = 600.0) -> dict:
    """Run ``code`` in a fresh interpreter; it must print one JSON object last."""
    full_env = dict(os.environ)
    if env:
        full_env.update(env)
    proc = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env=full_env,
        timeout=timeout,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"subprocess failed:\n{proc.stderr[-2000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


IMPORT_CODE = """
import json, sys, time
{pre}
t0 = time.perf_counter()
import {module}
t1 = time.perf_counter()
heavy = sorted(m for m in ("numba", "llvmlite", "scipy", "torch", "jax", "sympy")
               if m in sys.modules)
print(json.dumps({{"seconds": t1 - t0, "heavy": heavy}}))
"""


def import_times(module: str, repeat: int, preimport: str = "") -> dict:
    """Median wall time of ``import module`` measured inside fresh interpreters.

    Interpreter start-up is excluded (the clock starts just before the import),
    and so is ``preimport`` (e.g. ``"numpy"``, to see the module's own share);
    the first run warms the OS file cache and is discarded.
    """
    code = IMPORT_CODE.format(module=module, pre=f"import {preimport}" if preimport else "")
    run_python(code)
    runs = [run_python(code) for _ in range(repeat)]
    secs = [r["seconds"] for r in runs]
    return {"median": statistics.median(secs), "samples": secs, "heavy": runs[-1]["heavy"]}


def import_profile(module: str, top: int = 6) -> list:
    """The ``top`` modules by self time in ``python -X importtime -c 'import module'``.

    Returns ``[(milliseconds, name), ...]``; one run, so only a rough guide.
    """
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", f"import {module}"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    rows = []
    for line in proc.stderr.splitlines():
        parts = line.split("|")
        if len(parts) != 3 or not parts[0].strip().startswith("import time:"):
            continue
        try:
            self_us = int(parts[0].split(":")[1])
        except ValueError:
            continue
        rows.append((self_us / 1e3, parts[2].strip()))
    return sorted(rows, reverse=True)[:top]


# -- tables ----------------------------------------------------------------------------


def fmt(x, digits: int = 3) -> str:
    """A short number: 3 significant digits, no exponent for everyday values."""
    if x is None:
        return "-"
    if isinstance(x, str):
        return x
    if x == 0:
        return "0"
    if abs(x) >= 10**digits:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


def table(headers, rows, *, left: int = 1) -> str:
    """Plain-text table; the first ``left`` columns are left-aligned."""
    cells = [[str(c) for c in headers]] + [[str(c) for c in r] for r in rows]
    widths = [max(len(r[j]) for r in cells) for j in range(len(headers))]

    def line(r):
        return "  ".join(
            c.ljust(w) if j < left else c.rjust(w)
            for j, (c, w) in enumerate(zip(r, widths, strict=True))
        )

    out = [line(cells[0]), "  ".join("-" * w for w in widths)]
    out += [line(r) for r in cells[1:]]
    return "\n".join(out)


# -- a table of ops, side by side --------------------------------------------------------
#
# The generic part of a "rigidkit against its peers" script: rows of ops, each with a
# builder per contender, checked against scipy, timed round-robin with the floor,
# judged against the targets and printed.


@dataclass
class Row:
    """One line of the table: an op (or its ``out=`` variant) and who can do it.

    ``impls`` maps a contender to ``builder(data) -> zero-argument callable`` (or
    None where the contender lacks the op at that size); ``floor`` is ``(input
    widths, output width)`` in float64 components per element; ``memory_bound``
    rows must be within the floor factor of the floor.
    """

    key: str
    floor: tuple
    memory_bound: bool
    kind: str  # how the result is compared with the reference
    batched_only: bool = False
    impls: dict = field(default_factory=dict)
    notes: dict = field(default_factory=dict)  # contender -> footnote


def buffer(shape) -> np.ndarray:
    """A float64 output buffer for ``out=``, built before timing."""
    b = np.empty(shape)
    b.fill(0.0)  # a reused buffer: its pages are already mapped
    return b


def per_size(single, batch):
    """A builder that is ``single`` for one element and ``batch`` for a batch."""
    return lambda d: single(d) if d.single else batch(d)


def with_threads(builder, count: int, env: str = "RIGIDKIT_NUM_THREADS"):
    """``builder`` whose callable runs with ``env`` set to ``count`` (batches only)."""

    def build(d):
        fn = builder(d)
        if fn is None or d.single or count > cpu_count():
            return None

        def call():
            saved = os.environ.get(env)
            os.environ[env] = str(count)
            try:
                return fn()
            finally:
                if saved is None:
                    del os.environ[env]
                else:
                    os.environ[env] = saved

        return call

    return build


def check_rows(rows, make_data, canonical, error, sizes) -> dict:
    """Run every contender on ``make_data(n)`` and compare with scipy.

    ``canonical(kind, lib, result)`` brings any contender's result to one form;
    ``error(result, reference)`` returns a message where they disagree, else None.
    A row without scipy (an ``out=`` variant) is compared with its plain op's
    scipy. Returns ``{(row key, contender): message}``.
    """
    bad = {}
    for n in sizes:
        d = make_data(n)
        for r in rows:
            if r.batched_only and d.single:
                continue
            results = {}
            for lib, builder in r.impls.items():
                try:
                    fn = builder(d)
                    if fn is None:
                        continue
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        results[lib] = canonical(r.kind, lib, fn())
                except Exception as exc:
                    bad[(r.key, lib)] = f"{type(exc).__name__}: {exc}"[:160]
            ref = results.get("scipy")
            if ref is None:
                base = next((x for x in rows if x.key == r.key.replace(" out=", "")), None)
                if base is not None and "scipy" in base.impls:
                    ref = canonical(base.kind, "scipy", base.impls["scipy"](d)())
            if ref is None:
                continue
            for lib, res in results.items():
                msg = error(np.asarray(res, dtype=float), ref)
                if msg:
                    bad[(r.key, lib)] = f"{msg} (n={n})"
        del d
    return bad


FLOOR_COLUMNS = ("floor 1c", "floor 2c", "floor+alloc 1c", "floor+alloc 2c")


def time_row(r: Row, d, contenders, *, threads, floor=True, **timing) -> dict:
    """Medians of every contender of ``r`` (in ``contenders`` order) and of the floor.

    ``d`` needs ``n`` and ``single``; ``timing`` goes to :func:`interleaved_medians`.
    """
    fns = {}
    for lib in contenders:
        if lib in r.impls:
            fn = r.impls[lib](d)
            if fn is not None:
                fns[lib] = fn
    if floor and not d.single:
        ins, out = r.floor
        fl = StreamFloor(ins, out)
        for cores in threads:
            fns[f"floor {cores}c"] = fl.callable(d.n, threads=cores)
            fns[f"floor+alloc {cores}c"] = fl.callable(
                d.n, threads=cores, fresh_output=True
            )
    return interleaved_medians(fns, **timing)


def strict_floor(res: dict):
    """The smaller of the preallocated one- and two-thread floors (None if untimed)."""
    return min(
        (
            v["median"]
            for k, v in res.items()
            if k in ("floor 1c", "floor 2c") and "median" in v
        ),
        default=None,
    )


def verdict(
    r: Row, res: dict, single: bool, *, peers, short, single_limit_us, floor_factor
):
    """``("ok" | "MISS ...", {peer: median})`` for one row of one size."""
    rk = res.get("rigidkit", {}).get("median")
    times = {k: v["median"] for k, v in res.items() if k in peers and "median" in v}
    if rk is None:
        return "no rigidkit", times
    misses = []
    if single:
        sc = times.get("scipy")
        if sc is not None and rk > sc:
            misses.append(f"{rk / sc:.3g}x scipy")
        if rk * 1e6 > single_limit_us:
            misses.append(f"> {single_limit_us:g} us")
    else:
        if times:
            best = min(times, key=times.get)
            if rk > times[best]:
                misses.append(f"{rk / times[best]:.3g}x {short.get(best, best)}")
        fl = strict_floor(res)
        if r.memory_bound and fl is not None and rk > floor_factor * fl:
            misses.append(f"{rk / fl:.3g}x floor")
    return ("ok" if not misses else "MISS " + ", ".join(misses)), times


def report_size(
    n,
    rows,
    results,
    checks,
    *,
    contenders,
    peers,
    short,
    single_limit_us,
    floor_factor,
    mark_unbounded=True,
) -> str:
    """The table of one batch size: times, ratios, verdicts and footnotes.

    ``checks`` maps ``(row key, contender)`` to the message of a failed correctness
    check: such a cell is marked ``!``; a contender with a note in ``r.notes`` is
    marked ``*``. With ``mark_unbounded``, rows marked ``#`` are not held to the
    floor target.
    """
    single = n == 1
    unit = "us/call" if single else "ns/element"
    scale = 1e6 if single else 1e9 / n
    present = [r for r in rows if r.key in results]
    cols = [c for c in contenders if any(c in results[r.key] for r in present)]
    floor_cols = (
        []
        if single
        else [c for c in FLOOR_COLUMNS if any(c in results[r.key] for r in present)]
    )
    headers = ["op"] + [short.get(c, c) for c in cols + floor_cols]
    headers += ["rk/scipy", "rk/peer"] + ([] if single else ["rk/floor"]) + ["target"]
    lines = []
    foot = {}
    for r in present:
        res = results[r.key]
        unbounded = mark_unbounded and not (single or r.memory_bound)
        cells = [r.key + (" #" if unbounded else "")]
        for c in cols + floor_cols:
            x = res.get(c)
            if x is None:
                cells.append("")
            elif "error" in x:
                cells.append("err")
                foot[(r.key, c)] = x["error"]
            else:
                mark = ""
                if (r.key, c) in checks:
                    mark = "!"
                    foot[(r.key, c)] = "WRONG RESULT: " + checks[(r.key, c)]
                elif c in r.notes:
                    mark = "*"
                    foot[(r.key, c)] = r.notes[c]
                cells.append(fmt(x["median"] * scale) + mark)
        text, times = verdict(
            r,
            res,
            single,
            peers=peers,
            short=short,
            single_limit_us=single_limit_us,
            floor_factor=floor_factor,
        )
        rk = res.get("rigidkit", {}).get("median")
        sc = times.get("scipy")
        best = min(times.values()) if times else None
        cells.append(fmt(rk / sc) if rk and sc else "-")
        cells.append(fmt(rk / best) if rk and best else "-")
        if not single:
            fl = strict_floor(res)
            cells.append(fmt(rk / fl) if rk and fl else "-")
        cells.append(text)
        lines.append(cells)
    out = [f"N = {n:,}  ({unit}, median)", table(headers, lines)]
    if foot:
        out.append("")
        for (key, c), note in foot.items():
            out.append(f"  [{key} / {short.get(c, c)}] {note}")
    return "\n".join(out)


# -- the first call in a fresh process ---------------------------------------------------


def fresh_process(code: str, sizes) -> dict:
    """Run ``code`` (``SIZES`` replaced by ``sizes``) with an empty kernel cache."""
    with tempfile.TemporaryDirectory(prefix="rigidkit-cache-") as cache:
        code = code.replace("SIZES", repr(list(sizes)))
        return run_python(code, env={"RIGIDKIT_CACHE_DIR": cache})


def report_fresh(fc: dict, sizes) -> str:
    """The first and second call of every op of :func:`fresh_process`, as a table."""
    hdr = ["op"]
    for n in sizes:
        hdr += [f"1st call N={n} (ms)", "2nd (ms)", "JIT?"]
    lines = []
    for name in next(iter(fc["sizes"].values())):
        cells = [name]
        for n in sizes:
            x = fc["sizes"][str(n)][name]
            if "error" in x:
                cells += ["err", "", x["error"][:40]]
            else:
                cells += [
                    fmt(x["first_s"] * 1e3),
                    fmt(x["second_s"] * 1e3),
                    "COMPILED" if x["compiled"] else "no",
                ]
        lines.append(cells)
    head = (
        f"fresh process, empty RIGIDKIT_CACHE_DIR: import {fc['import_s'] * 1e3:.1f} ms, "
        f"numba imported by the end: {fc['numba_imported']}"
    )
    return head + "\n" + table(hdr, lines)
