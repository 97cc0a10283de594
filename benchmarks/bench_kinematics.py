"""Kinematics benchmark: rk.kinematics side by side with its peers, in one process.

Rows (issue 8):

* ``euler_rate_matrix`` and ``euler_rates`` (ZYZ, world frame) at N = 1e6, ns per
  element, next to rigidkit's own ``from_euler`` on the same angles (the target:
  within 2x of it per element) and spatialmath-python's ``rotvelxform`` (its only
  peer: one 3x3 matrix per call, timed on a slice and reported per element);
* ``quaternion_derivative`` at N = 1e6, next to numpy-quaternion's
  ``0.5 * q * quaternion(0, w)``;
* ``integrate_angular_velocity`` in ns per step: one trajectory of 3.6 M steps (an
  hour at 1 kHz) and 1,000 trajectories of 1,000 steps, next to a scipy
  ``Rotation`` loop (one step per iteration) and numpy-quaternion's
  ``integrate_angular_velocity`` (an adaptive ODE solver over the sampled rate),
  both on a short trajectory;
* the planar integrators (``kinematics.planar``) on 3.6 M steps: SO(2) (summed
  angles, no compiled loop) and SE(2) (the compiled scan);
* ``angular_velocity_from_samples`` (N = 1e6 samples) next to pytransform3d's
  ``quaternion_gradient`` (on 20,000 samples: it is a Python loop).

``--first-call`` times instead the first ``integrate_angular_velocity`` call of a
fresh interpreter (20,000 and 3.6 M steps), with an empty numba cache and again
with the cache it left: no call compiles on the caller's thread, so the first
calls run on the prefix product until the background thread has the scan.

Every contender is first run on small inputs and compared with rigidkit (a
disagreement is printed as ``CHECK``). A peer that is not installed is skipped
with a note (``pip install spatialmath-python numpy-quaternion pytransform3d``).
Medians of round-robin samples after warm-up (``_common.interleaved_medians``).

    python benchmarks/bench_kinematics.py
    python benchmarks/bench_kinematics.py --n 100000 --repeat 5 --json kin.json
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import warnings
from functools import partial

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _common as C  # noqa: E402

import rigidkit as rk  # noqa: E402

K = rk.kinematics


def _try_import(name):
    try:
        return __import__(name, fromlist=["_"]), None
    except Exception as exc:  # not installed, or broken: skip the peer, say why
        return None, f"{type(exc).__name__}: {exc}"


class Peers:
    def __init__(self):
        self.notes = {}
        from scipy.spatial.transform import Rotation as SR

        self.SR = SR
        self.smb, err = _try_import("spatialmath.base")
        if err:
            self.notes["spatialmath-python"] = f"skipped, not installed ({err})"
        self.nq, err = _try_import("quaternion")
        if err:
            self.notes["numpy-quaternion"] = f"skipped, not installed ({err})"
        self.pr, err = _try_import("pytransform3d.rotations")
        if err:
            self.notes["pytransform3d"] = f"skipped, not installed ({err})"


def zyz_angles(rng, n):
    a = rng.uniform(-np.pi, np.pi, (n, 3))
    a[:, 1] = rng.uniform(0.2, np.pi - 0.2, n)
    return a


def per_element(fn, count):
    """A callable over ``count`` elements, for per-element times of 1-element peers."""

    def run():
        for k in range(count):
            fn(k)

    return run


def check(peers, rng) -> list:
    """Compare each peer with rigidkit on small inputs; messages where they differ."""
    bad = []
    a = zyz_angles(rng, 5)
    r = rng.standard_normal((5, 3))
    E = K.euler_rate_matrix("ZYZ", a, frame="world")
    if peers.smb:
        for k in range(5):
            A = peers.smb.rotvelxform(a[k], representation="eul")
            err = np.abs(A - E[k]).max()
            if err > 1e-12:
                bad.append(f"spatialmath rotvelxform differs by {err:.3g}")
                break
    q = rk.Rotation.random((5,), rng=1).as_quat()
    qd = K.quaternion_derivative(q, r, frame="body")
    if peers.nq:
        nq = peers.nq
        theirs = nq.as_float_array(0.5 * nq.from_float_array(q) * nq.from_vector_part(r))
        err = np.abs(theirs - qd).max()
        if err > 1e-14:
            bad.append(f"numpy-quaternion q' differs by {err:.3g}")
    if peers.pr:
        t = np.arange(50) * 0.01
        R = rk.Rotation.from_rotvec(np.outer(t, [0.3, -0.2, 0.5]))
        ours = K.angular_velocity_from_samples(R, t, frame="world")
        # pytransform3d normalises its input in place: give it a writable copy
        theirs = peers.pr.quaternion_gradient(np.array(R.as_quat()), dt=0.01)
        err = np.abs(ours - theirs)[1:-1].max()
        if err > 1e-9:
            bad.append(f"pytransform3d quaternion_gradient differs by {err:.3g}")
    return bad


def rows(peers, n, rng):
    """``{row: ({contender: callable}, elements per call)}``."""
    out = {}
    a = zyz_angles(rng, n)
    w = rng.standard_normal((n, 3))
    small = 2000  # elements per call for one-element peers
    # euler_rate_matrix ---------------------------------------------------------------
    r = {
        "rigidkit": partial(K.euler_rate_matrix, "ZYZ", a, frame="world"),
        "rk from_euler": partial(rk.Rotation.from_euler, "ZYZ", a),
    }
    if peers.smb:
        f = peers.smb.rotvelxform
        r["spatialmath"] = per_element(lambda k: f(a[k], representation="eul"), small)
    out["euler_rate_matrix ZYZ"] = (
        r,
        {"rigidkit": n, "rk from_euler": n, "spatialmath": small},
    )
    # euler_rates -----------------------------------------------------------------------
    r = {
        "rigidkit": partial(K.euler_rates, "ZYZ", a, w, frame="world"),
        "rk from_euler": partial(rk.Rotation.from_euler, "ZYZ", a),
    }
    if peers.smb:
        f = peers.smb.rotvelxform
        r["spatialmath"] = per_element(
            lambda k: f(a[k], representation="eul", inverse=True) @ w[k], small
        )
    out["euler_rates ZYZ"] = (r, {"rigidkit": n, "rk from_euler": n, "spatialmath": small})
    # quaternion_derivative ------------------------------------------------------------
    q = rk.Rotation.random((n,), rng=3).as_quat()
    r = {"rigidkit": partial(K.quaternion_derivative, q, w, frame="body")}
    if peers.nq:
        nq = peers.nq
        qq = nq.from_float_array(q)
        ww = nq.from_vector_part(w)
        r["numpy-quaternion"] = lambda: 0.5 * qq * ww
    out["quaternion_derivative"] = (r, {"rigidkit": n, "numpy-quaternion": n})
    # integrate_angular_velocity ---------------------------------------------------------
    steps = 3_600_000
    w_long = rng.standard_normal((steps, 3))
    R0 = rk.Rotation.identity()
    w_many = rng.standard_normal((1000, 1000, 3))
    R0_many = rk.Rotation.identity((1000,))
    short = 2000
    w_short = w_long[:short]
    r = {
        "rigidkit 1 x 3.6M": partial(
            K.integrate_angular_velocity, R0, w_long, 1e-3, frame="body"
        ),
        "rigidkit rk4 1 x 3.6M": partial(
            K.integrate_angular_velocity, R0, w_long, 1e-3, frame="body", method="rk4"
        ),
        "rigidkit 1000 x 1000": partial(
            K.integrate_angular_velocity, R0_many, w_many, 1e-3, frame="body"
        ),
    }
    SR = peers.SR

    def scipy_loop():
        R = SR.identity()
        steps_ = SR.from_rotvec(w_short * 1e-3)
        for k in range(short):
            R = R * steps_[k]
        return R

    r["scipy loop"] = scipy_loop
    counts = {
        "rigidkit 1 x 3.6M": steps,
        "rigidkit rk4 1 x 3.6M": steps,
        "rigidkit 1000 x 1000": 1_000_000,
        "scipy loop": short,
    }
    if peers.nq:
        t_s = np.arange(short) * 1e-3
        nq = peers.nq
        r["numpy-quaternion"] = lambda: nq.integrate_angular_velocity(
            (t_s, w_short), 0.0, t_s[-1]
        )
        counts["numpy-quaternion"] = short
    out["integrate_angular_velocity (ns/step)"] = (r, counts)
    # the plane -------------------------------------------------------------------------
    P = K.planar
    V2 = rng.standard_normal((steps, 3))
    r = {
        "rigidkit SO(2) 1 x 3.6M": partial(
            P.integrate_angular_velocity,
            rk.Rotation2D.identity(),
            V2[:, 2:],
            1e-3,
            frame="body",
        ),
        "rigidkit SE(2) 1 x 3.6M": partial(
            P.integrate_twist, rk.Transform2D.identity(), V2, 1e-3, frame="body"
        ),
    }
    out["planar integration (ns/step)"] = (r, {k: steps for k in r})
    # angular_velocity_from_samples -------------------------------------------------------
    t = np.arange(n) * 1e-3
    R = rk.Rotation.from_rotvec(np.cumsum(w * 1e-3, axis=0))
    r = {"rigidkit": partial(K.angular_velocity_from_samples, R, t, frame="world")}
    m = min(n, 20_000)  # pytransform3d loops in Python (~150 us per sample)
    if peers.pr:
        Q = np.array(R[:m].as_quat())  # writable: pytransform3d normalises in place
        r["pytransform3d"] = partial(peers.pr.quaternion_gradient, Q, dt=1e-3)
    out["angular_velocity_from_samples"] = (r, {"rigidkit": n, "pytransform3d": m})
    return out


def warm(all_rows) -> None:
    """Call every rigidkit op, then wait for its compiled loops.

    rigidkit compiles its numba loops on a background thread and serves calls
    from the vectorised NumPy path meanwhile: timing must start once they are in.
    """
    from rigidkit._engine import numba_backend

    drain = getattr(numba_backend, "drain", None)
    for _ in range(2):
        for fns, _counts in all_rows.values():
            for lib, fn in fns.items():
                if lib.startswith("rigidkit") or lib.startswith("rk "):
                    fn()
        if drain is not None:
            drain(timeout=900)


_FIRST_CALL = """
import sys, time
t0 = time.perf_counter()
import numpy as np
import rigidkit as rk
n = int(sys.argv[1])
w = np.random.default_rng(0).standard_normal((n, 3))
t1 = time.perf_counter()
rk.kinematics.integrate_angular_velocity(rk.Rotation.identity(), w, 1e-3, frame="body")
t2 = time.perf_counter()
rk.kinematics.integrate_angular_velocity(rk.Rotation.identity(), w, 1e-3, frame="body")
t3 = time.perf_counter()
print(t2 - t1, t3 - t2)
"""


def first_calls(repeat: int) -> None:
    """First and second call of a fresh interpreter, empty and warm numba cache."""
    import subprocess
    import tempfile

    table = []
    for n in (20_000, 3_600_000):
        for cache in ("empty", "warm"):
            runs = []
            for _ in range(repeat):
                with tempfile.TemporaryDirectory() as folder:
                    env = dict(os.environ, RIGIDKIT_CACHE_DIR=folder)
                    for state in ("empty", "warm"):
                        res = subprocess.run(
                            [sys.executable, "-c", _FIRST_CALL, str(n)],
                            env=env, capture_output=True, text=True, check=True,
                        )  # fmt: skip
                        if state == cache:
                            runs.append([float(x) for x in res.stdout.split()])
            first, second = np.median(np.array(runs), axis=0)
            table.append([f"{n:,}", cache, C.fmt(first * 1e3), C.fmt(second * 1e3)])
    print(C.table(["steps", "numba cache", "first call ms", "second call ms"], table))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--n", type=int, default=1_000_000, help="elements per batch")
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--warmup", type=int, default=2)
    p.add_argument("--min-sample", type=float, default=0.05)
    p.add_argument("--json", metavar="FILE")
    p.add_argument(
        "--first-call", action="store_true", help="first calls in fresh processes"
    )
    args = p.parse_args(argv)
    if args.first_call:
        first_calls(args.repeat)
        return
    peers = Peers()
    py = platform.python_version()
    print(f"rigidkit {rk.__version__}, numpy {np.__version__}, python {py}")
    print(f"{C.cpu_count()} cores, load average {C.load_average()} at the start")
    for lib, note in peers.notes.items():
        print(f"note: {lib}: {note}")
    rng = np.random.default_rng(0)
    for msg in check(peers, rng):
        print("CHECK", msg)
    record = {}
    table = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        all_rows = rows(peers, args.n, rng)
        warm(all_rows)
        for key, (fns, counts) in all_rows.items():
            res = C.interleaved_medians(
                fns, repeat=args.repeat, warmup=args.warmup, min_sample=args.min_sample
            )
            record[key] = {k: {**v, "elements": counts.get(k)} for k, v in res.items()}
            for lib, v in res.items():
                if "median" in v:
                    ns = v["median"] * 1e9 / counts[lib]
                    table.append([key, lib, C.fmt(ns), C.fmt(v["median"] * 1e3)])
                else:
                    table.append([key, lib, "err", v["error"][:50]])
    print(C.table(["op", "contender", "ns/element", "ms/call"], table, left=2))
    print(f"load average {C.load_average()} at the end")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(record, fh, indent=1)


if __name__ == "__main__":
    main()
