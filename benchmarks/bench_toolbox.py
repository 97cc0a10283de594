"""Toolbox benchmark: interpolation, splines, means and alignment against the peers.

Times, in ONE process and side by side, rigidkit and scipy.spatial.transform (and,
when installed, numpy-quaternion, quaternionic and pytransform3d where they have
the op) on

* ``slerp``: N pairs of rotations at N fractions (scipy has no pairwise slerp: its
  ``A * from_rotvec(t (A^-1 B).as_rotvec())``, the formula of its ``Slerp``);
* ``Slerp eval``: a 100-keyframe ``Slerp`` evaluated at N times;
* ``spline eval``: a 100-keyframe ``RotationSpline`` at N times (rotations), and
  its angular rate (``order=1``, body frame);
* ``B-spline eval``: rigidkit's cumulative cubic B-spline on SO(3), 100 control
  points, at N times (no peer has one);
* ``mean chordal`` / ``mean geodesic``: the mean of N rotations (numpy-quaternion's
  ``mean_rotor_in_chordal_metric`` averages the quaternions as given, so it depends
  on their signs: marked);
* ``align_vectors``: N independent problems of 20 vector pairs (scipy and the
  others solve one problem per call: a Python loop over the problems, timed at
  N <= 10,000 only);
* ``from_dual_quat`` / ``as_dual_quat``: N rigid motions from and to unit dual
  quaternions (scipy's ``RigidTransform``, scipy >= 1.16), both scalar first.

Numbers are ns per element (per rotation, time or problem) for a batch and us per
call for N = 1, medians of round-robin samples (see ``_common.py``).

    python benchmarks/bench_toolbox.py                          # N = 1, 1e3, 1e6
    python benchmarks/bench_toolbox.py --sizes 1 10000 --ops slerp mean
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import warnings
from dataclasses import dataclass, field
from functools import partial

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _common as C  # noqa: E402

LIBS = ["rigidkit", "scipy", "numpy-quaternion", "quaternionic", "pytransform3d"]
PEERS = LIBS[1:]
SHORT = {
    "rigidkit": "rigidkit",
    "scipy": "scipy",
    "numpy-quaternion": "np-quat",
    "quaternionic": "qtnionic",
    "pytransform3d": "pt3d",
}
TABLE = dict(
    contenders=LIBS,
    peers=PEERS,
    short=SHORT,
    single_limit_us=math.inf,  # no single-call target for these ops
    floor_factor=math.inf,  # not memory-bound: no floor target
    mark_unbounded=False,
)
KEYS = 100  # keyframes / control points of the interpolants
PAIRS = 20  # vector pairs per alignment problem
LOOP_MAX = 10_000  # largest N at which the one-problem-per-call peers are timed


def _try_import(name):
    try:
        return __import__(name, fromlist=["_"]), None
    except Exception as exc:  # not installed, or broken: skip the peer, say why
        return None, f"{type(exc).__name__}: {exc}"


class Libs:
    """The libraries found in this environment (None where missing)."""

    def __init__(self):
        self.notes = {}
        self.rk, err = _try_import("rigidkit")
        if self.rk is None:
            sys.exit(f"rigidkit is not importable ({err}); install it first")
        from scipy.spatial import transform as st

        self.st = st
        self.nq, err = _try_import("quaternion")
        if err:
            self.notes["numpy-quaternion"] = f"skipped, not installed ({err})"
        self.qn, err = _try_import("quaternionic")
        if err:
            self.notes["quaternionic"] = f"skipped, not installed ({err})"
        self.pr, err = _try_import("pytransform3d.rotations")
        if err:
            self.notes["pytransform3d"] = f"skipped, not installed ({err})"


def unit_quats(rng, shape):
    q = rng.standard_normal(shape + (4,))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


@dataclass
class Data:
    """Inputs for one size; ``single`` means one element (or one problem)."""

    n: int
    single: bool
    q1: np.ndarray
    q2: np.ndarray
    t: np.ndarray
    cluster: np.ndarray  # N quaternions near one rotation, random signs
    times: np.ndarray  # N query times in [0, KEYS - 1]
    keys: np.ndarray  # KEYS keyframe quaternions
    a: np.ndarray  # (N, PAIRS, 3) or (PAIRS, 3)
    b: np.ndarray
    objects: dict = field(default_factory=dict)
    dq: np.ndarray | None = None  # unit dual quaternions (q_r, q_d), scalar first


def make_data(n, libs, seed=0) -> Data:
    rng = np.random.default_rng(seed)
    single = n == 1
    shape = () if single else (n,)
    q1, q2 = unit_quats(rng, shape), unit_quats(rng, shape)
    t = rng.uniform(0.0, 1.0, shape)
    center = unit_quats(rng, ())
    noise = libs.st.Rotation.from_rotvec(0.3 * rng.standard_normal((max(n, 2), 3)))
    cl = (libs.st.Rotation.from_quat(center, scalar_first=True) * noise).as_quat(
        scalar_first=True
    )
    cl *= rng.choice([-1.0, 1.0], size=(len(cl), 1))
    times = rng.uniform(0.0, KEYS - 1.0, shape)
    keys = unit_quats(rng, (KEYS,))
    b = rng.standard_normal(shape + (PAIRS, 3))
    R = libs.st.Rotation.from_quat(unit_quats(rng, (max(n, 1),)), scalar_first=True)
    a = np.einsum("nij,nkj->nki", R.as_matrix(), b.reshape(-1, PAIRS, 3)).reshape(b.shape)
    a += 1e-3 * rng.standard_normal(a.shape)
    rk = libs.rk
    motion = rk.Transform(
        rk.Rotation.from_quat(q1), 3.0 * rng.standard_normal(shape + (3,))
    )
    return Data(n, single, q1, q2, t, cl, times, keys, a, b, dq=motion.as_dual_quat())


def build_rows(libs: Libs) -> list:
    rk, st, nq, qn, pr = libs.rk, libs.st, libs.nq, libs.qn, libs.pr
    SR = st.Rotation
    rows = []

    def row(key, kind, batched_only=False):
        r = C.Row(key, ((4,), 4), False, kind, batched_only)
        rows.append(r)
        return r

    def cached(d, name, make):
        if name not in d.objects:
            d.objects[name] = make()
        return d.objects[name]

    # slerp ----------------------------------------------------------------------------
    r = row("slerp", "rot")
    r.impls["rigidkit"] = lambda d: partial(
        rk.slerp, rk.Rotation.from_quat(d.q1), rk.Rotation.from_quat(d.q2), d.t
    )

    def scipy_slerp(d):
        A = SR.from_quat(d.q1, scalar_first=True)
        B = SR.from_quat(d.q2, scalar_first=True)
        tt = d.t[..., None]
        return lambda: A * SR.from_rotvec((A.inv() * B).as_rotvec() * tt)

    r.notes["scipy"] = "A * from_rotvec(t (A^-1 B).as_rotvec()), as its Slerp"
    r.impls["scipy"] = scipy_slerp
    if nq:
        r.notes["numpy-quaternion"] = "np.slerp_vectorized"
        r.impls["numpy-quaternion"] = lambda d: partial(
            np.slerp_vectorized, nq.from_float_array(d.q1), nq.from_float_array(d.q2), d.t
        )
    if qn:
        r.impls["quaternionic"] = lambda d: partial(
            qn.slerp, qn.array(d.q1), qn.array(d.q2), d.t
        )
    if pr:
        r.impls["pytransform3d"] = C.per_size(
            lambda d: partial(pr.quaternion_slerp, d.q1, d.q2, float(d.t), True),
            lambda d: None,
        )

    # Slerp and spline evaluation --------------------------------------------------------
    kt = np.arange(float(KEYS))
    r = row("Slerp eval", "rot")
    r.impls["rigidkit"] = lambda d: partial(
        cached(d, "rk slerp", lambda: rk.Slerp(kt, rk.Rotation.from_quat(d.keys))), d.times
    )
    r.impls["scipy"] = lambda d: partial(
        cached(
            d, "sc slerp", lambda: st.Slerp(kt, SR.from_quat(d.keys, scalar_first=True))
        ),
        d.times,
    )

    def rk_spline(d):
        return cached(
            d, "rk spline", lambda: rk.RotationSpline(kt, rk.Rotation.from_quat(d.keys))
        )

    def sc_spline(d):
        return cached(
            d,
            "sc spline",
            lambda: st.RotationSpline(kt, SR.from_quat(d.keys, scalar_first=True)),
        )

    r = row("spline eval", "rot")
    r.impls["rigidkit"] = lambda d: partial(rk_spline(d), d.times)
    r.impls["scipy"] = lambda d: partial(sc_spline(d), d.times)
    if nq:
        r.notes["numpy-quaternion"] = "quaternion.squad (C1, not a C2 spline)"
        r.impls["numpy-quaternion"] = lambda d: partial(
            nq.squad, nq.from_float_array(d.keys), kt, np.atleast_1d(d.times)
        )

    r = row("spline rate", "vec")
    r.notes["rigidkit"] = "order=1, frame='body'"
    r.impls["rigidkit"] = lambda d: partial(rk_spline(d), d.times, 1, frame="body")
    r.impls["scipy"] = lambda d: partial(sc_spline(d), d.times, 1)
    for r in rows[-2:]:
        r.notes.setdefault("scipy", "its solve stops 10 steps short of C2 (~1e-7 away)")

    r = row("B-spline eval", "none")
    r.impls["rigidkit"] = lambda d: partial(
        cached(d, "rk bs", lambda: rk.BSplineSO3(rk.Rotation.from_quat(d.keys))),
        d.times * (KEYS - 3) / (KEYS - 1),
    )

    # means -----------------------------------------------------------------------------
    r = row("mean chordal", "rot")
    r.impls["rigidkit"] = lambda d: rk.Rotation.from_quat(d.cluster).mean
    r.impls["scipy"] = lambda d: SR.from_quat(d.cluster, scalar_first=True).mean
    if nq:
        r.notes["numpy-quaternion"] = "mean_rotor_in_chordal_metric: depends on q signs"
        r.impls["numpy-quaternion"] = lambda d: partial(
            nq.mean_rotor_in_chordal_metric, nq.from_float_array(d.cluster)
        )

    r = row("mean geodesic", "none")
    r.impls["rigidkit"] = lambda d: partial(
        rk.Rotation.from_quat(d.cluster).mean, method="geodesic"
    )

    # alignment --------------------------------------------------------------------------
    r = row(f"align_vectors {PAIRS}", "align")
    r.impls["rigidkit"] = lambda d: (
        None if d.n > LOOP_MAX else partial(rk.align_vectors, d.a, d.b)
    )

    def scipy_align(d):
        if d.single:
            return partial(SR.align_vectors, d.a, d.b)
        if d.n > LOOP_MAX:
            return None
        pairs = list(zip(d.a, d.b))
        return lambda: [SR.align_vectors(x, y) for x, y in pairs]

    r.notes["scipy"] = "one call per problem (a Python loop for a batch)"
    r.impls["scipy"] = scipy_align

    # dual quaternions (scipy's RigidTransform, scipy >= 1.16) --------------------------
    ST = getattr(st, "RigidTransform", None)
    r = C.Row("from_dual_quat", ((8,), 7), False, "tf")
    rows.append(r)
    r.impls["rigidkit"] = lambda d: partial(rk.Transform.from_dual_quat, d.dq)
    r = C.Row("as_dual_quat", ((7,), 8), False, "dq")
    rows.append(r)
    r.impls["rigidkit"] = lambda d: rk.Transform.from_dual_quat(d.dq).as_dual_quat
    if ST is not None:
        rows[-2].impls["scipy"] = lambda d: partial(
            ST.from_dual_quat, d.dq, scalar_first=True
        )
        r.impls["scipy"] = lambda d: partial(
            ST.from_dual_quat(d.dq, scalar_first=True).as_dual_quat, scalar_first=True
        )
    return rows


def canonical(kind, lib, x, libs):
    """Rotation-valued (or rate) results of any library as float64 arrays."""
    SR = libs.st.Rotation
    if kind == "none":
        return None
    if kind == "vec":
        return np.asarray(x)
    if kind == "tf":  # a rigid motion of either library: its 4x4 matrix
        return np.asarray(x.as_matrix())
    if kind == "dq":  # q and -q are one motion: the largest |q_r| component made > 0
        x = np.asarray(x, dtype=float)
        big = np.argmax(np.abs(x[..., :4]), axis=-1)[..., None]
        return x * np.sign(np.take_along_axis(x, big, axis=-1))
    if kind == "align":
        if isinstance(x, list):
            return np.stack([np.asarray(r.as_matrix()) for r, _ in x])
        rot = x[0]
        return np.asarray(rot.as_matrix() if isinstance(rot, SR) else rot.as_matrix())
    if isinstance(x, libs.rk.Rotation):
        return np.asarray(x.as_matrix())
    if isinstance(x, SR):
        return x.as_matrix()
    if libs.nq is not None and getattr(x, "dtype", None) == libs.nq.quaternion:
        return libs.nq.as_rotation_matrix(x)
    if libs.nq is not None and isinstance(x, libs.nq.quaternion):
        return libs.nq.as_rotation_matrix(x)
    if libs.qn is not None and isinstance(x, libs.qn.array):
        return np.asarray(x.to_rotation_matrix)
    q = np.asarray(x, dtype=float)
    return (
        SR.from_quat(q.reshape(-1, 4), scalar_first=True)
        .as_matrix()
        .reshape(q.shape[:-1] + (3, 3))
    )


def check_rows(rows, libs, sizes=(1, 5)) -> dict:
    def error(res, ref):
        if res.shape != ref.shape:
            res = res.reshape(ref.shape)
        err = float(np.max(np.abs(res - ref)))
        return None if err <= 1e-9 else f"differs from scipy by {err:.3g}"

    checked = [r for r in rows if r.kind != "none"]
    bad = C.check_rows(
        checked,
        lambda n: make_data(n, libs, seed=1),
        lambda kind, lib, x: canonical(kind, lib, x, libs),
        error,
        sizes,
    )
    # squad is another curve than scipy's spline and the sign-dependent mean another
    # average: they are timed for reference, not held to scipy's result. scipy's
    # RotationSpline stops its solve after 10 steps, ~1e-7 from the exactly C2
    # spline that rigidkit returns (tests/test_interpolation.py compares them with
    # scipy's solve run to convergence).
    for key in (
        ("spline eval", "numpy-quaternion"),
        ("mean chordal", "numpy-quaternion"),
        ("spline eval", "rigidkit"),
        ("spline rate", "rigidkit"),
    ):
        if key in bad and bad[key].startswith("differs"):
            bad.pop(key)
    return bad


def warm_rigidkit(rows, libs, ns=(1, 10, 3, 2000)) -> None:
    """Call every rigidkit op, then wait for its compiled loops (as bench_curve does).

    The steady state is timed: each op is called 100 times at one element (hot
    kernels get their one-element loop) and once at a few batch sizes, twice
    over, and the background thread's compiles are waited for. The first calls
    of a fresh process are bench_curve's fresh-process section.
    """
    from rigidkit._engine import numba_backend

    for _ in range(2):
        for n in ns:
            d = make_data(n, libs)
            for r in rows:
                if r.batched_only and d.single:
                    continue
                builder = r.impls.get("rigidkit")
                fn = builder(d) if builder is not None else None
                if fn is None:
                    continue
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    for _ in range(100 if d.single else 1):
                        fn()
        numba_backend.drain(timeout=900)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sizes", type=int, nargs="+", default=[1, 1000, 10_000, 1_000_000])
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--warmup", type=int, default=3)
    p.add_argument("--min-sample", type=float, default=0.05)
    p.add_argument("--ops", nargs="+", help="only rows whose name starts with one of these")
    p.add_argument("--no-check", action="store_true")
    p.add_argument("--json", metavar="FILE")
    args = p.parse_args(argv)

    libs = Libs()
    rows = build_rows(libs)
    if args.ops:
        rows = [r for r in rows if any(r.key.startswith(o) for o in args.ops)]
    import scipy

    print(
        f"rigidkit {libs.rk.__version__}, numpy {np.__version__}, "
        f"scipy {scipy.__version__}, python {platform.python_version()}; "
        f"{C.cpu_count()} cores, load average {C.load_average()} at the start"
    )
    for lib, note in libs.notes.items():
        print(f"note: {lib}: {note}")
    checks = {} if args.no_check else check_rows(rows, libs)
    for (key, lib), msg in checks.items():
        print(f"CHECK {key} / {lib}: {msg}")
    warm_rigidkit(rows, libs)
    record = {"sizes": {}}
    for n in args.sizes:
        d = make_data(n, libs)
        results = {}
        for r in rows:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # scipy's align_vectors warnings: not timed
                results[r.key] = C.time_row(
                    r,
                    d,
                    LIBS,
                    threads=[1],
                    floor=False,
                    repeat=args.repeat,
                    warmup=args.warmup,
                    min_sample=args.min_sample,
                )
            print(f"  timed {r.key:>18} at N={n}", file=sys.stderr, flush=True)
        print()
        print(C.report_size(n, rows, results, checks, **TABLE))
        record["sizes"][str(n)] = results
        del d
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(record, fh, indent=1, default=str)
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
