"""Trajectory evaluation benchmark: rigidkit against evo, side by side in one process.

Times reading TUM files, association, SE(3) and Sim(3) alignment, APE and RPE
(frames, and metres with ``all_pairs``, evo's slowest path) and the whole
read-associate-align-APE-RPE job, on a TUM fr2/desk-sized case (21,000 reference
poses at 100 Hz, 2,900 estimated at 30 Hz) and on a synthetic million-pose
trajectory; then the whole ``rigidkit ape`` process against ``evo_ape`` on the
same files (with ``farm-bench`` when it is on PATH). Before timing, every row's
result is compared with evo's (1e-9 relative). See README.md in this folder.

    python benchmarks/bench_trajectory.py                    # both cases
    python benchmarks/bench_trajectory.py --cases desk --repeat 5 --json traj.json
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _common as C  # noqa: E402

# The targets of issue 17.
METRIC_TARGET = 50.0  # x evo in-process, every metric row
JOB_TARGET = 20.0  # x evo for the whole job in one process

CASES = {
    # name: (reference poses, reference rate Hz, estimated poses, estimate rate Hz)
    "desk": (21_000, 100.0, 2_900, 30.0),
    "1e6": (1_000_000, 100.0, 1_000_000, 100.0),
}


def make_files(directory, n_ref, rate_ref, n_est, rate_est, seed=0):
    """A smooth random walk as the reference; the estimate samples it at its own
    rate (stamps jittered by 1 ms), moved by a similarity, with pose noise."""
    import rigidkit as rk

    rng = np.random.default_rng(seed)
    t_ref = 1305031102.0 + np.arange(n_ref) / rate_ref
    acc = rng.normal(0, 1.0, (n_ref, 3))
    vel = np.cumsum(acc, axis=0) / rate_ref
    vel -= vel.mean(axis=0)
    p = np.cumsum(vel, axis=0) / rate_ref
    rv = np.cumsum(rng.normal(0, 0.01, (n_ref, 3)), axis=0)
    ref = rk.Trajectory(t_ref, rk.Transform(rk.Rotation.from_rotvec(rv), p))
    span = (n_ref - 1) / rate_ref
    n_est = min(n_est, int(span * rate_est))
    t_est = t_ref[0] + np.arange(n_est) / rate_est + rng.normal(0, 0.001, n_est)
    t_est = np.sort(np.clip(t_est, t_ref[0], t_ref[-1]))
    t_est = t_est[np.concatenate([[True], np.diff(t_est) > 0])]
    est = ref.at(t_est, method="linear")
    noise = rk.Transform.exp(
        rng.normal(0, [0.01, 0.01, 0.01, 0.002, 0.002, 0.002], (len(est), 6))
    )
    S = rk.Similarity(
        scale=0.8,
        rotation=rk.Rotation.from_rotvec([0.1, -0.2, 0.7]),
        translation=[1.0, -2.0, 0.5],
    )
    est = rk.Trajectory(est.stamps, est.poses @ noise).transform(S)
    ref_path = os.path.join(directory, "ref.txt")
    est_path = os.path.join(directory, "est.txt")
    # As SLAM systems and the TUM tools write them: stamps in microseconds, the
    # rest with 9 decimals (rk.io.write_trajectory writes 17 significant digits,
    # for an exact round trip, which the reader converts by a slower exact path).
    fmt = "%.6f" + " %.9f" * 7
    for path, traj in ((ref_path, ref), (est_path, est)):
        pq = traj.poses.as_pq(scalar_first=False)
        np.savetxt(
            path,
            np.column_stack([traj.stamps, pq]),
            fmt=fmt,
            header="timestamp tx ty tz qx qy qz qw",
        )
    return ref_path, est_path


def contenders(ref_path, est_path, all_pairs_evo, only=None):
    """``{row: {"rigidkit": fn, "evo": fn}}`` and the checks of their results;
    ``only``: the rows whose name contains one of these strings (all if None)."""
    from evo.core import metrics, sync
    from evo.core.units import Unit
    from evo.tools import file_interface

    import rigidkit as rk

    T = rk.trajectory
    r0, e0 = rk.io.read_trajectory(ref_path), rk.io.read_trajectory(est_path)
    er0 = file_interface.read_tum_trajectory_file(ref_path)
    ee0 = file_interface.read_tum_trajectory_file(est_path)
    r, e = T.associate(r0, e0)
    er, ee = sync.associate_trajectories(er0, ee0)
    aligned, _ = T.align(e, r, method="sim3")
    ee_aligned = copy.deepcopy(ee)
    ee_aligned.align(er, correct_scale=True)

    def evo_align(scale):
        def run():
            x = copy.deepcopy(ee)
            x.align(er, correct_scale=scale)
            return x

        return run

    def evo_copy():
        return copy.deepcopy(ee)

    def evo_ape():
        m = metrics.APE(metrics.PoseRelation.translation_part)
        m.process_data((er, ee_aligned))
        return m

    def evo_rpe(delta, unit, all_pairs):
        def run():
            m = metrics.RPE(
                metrics.PoseRelation.translation_part,
                delta=delta,
                delta_unit=unit,
                all_pairs=all_pairs,
            )
            m.process_data((er, ee_aligned))
            return m

        return run

    def rk_job():
        a, b = rk.io.read_trajectory(ref_path), rk.io.read_trajectory(est_path)
        a, b = T.associate(a, b)
        b, _ = T.align(b, a, method="sim3")
        return T.ape(a, b).stats, T.rpe(a, b).stats

    def evo_job():
        a = file_interface.read_tum_trajectory_file(ref_path)
        b = file_interface.read_tum_trajectory_file(est_path)
        a, b = sync.associate_trajectories(a, b)
        b.align(a, correct_scale=True)
        m1 = metrics.APE(metrics.PoseRelation.translation_part)
        m1.process_data((a, b))
        m2 = metrics.RPE(metrics.PoseRelation.translation_part)
        m2.process_data((a, b))
        return m1.get_all_statistics(), m2.get_all_statistics()

    rows = {
        "read (both files)": {
            "rigidkit": lambda: (
                rk.io.read_trajectory(ref_path),
                rk.io.read_trajectory(est_path),
            ),
            "evo": lambda: (
                file_interface.read_tum_trajectory_file(ref_path),
                file_interface.read_tum_trajectory_file(est_path),
            ),
        },
        "associate": {
            "rigidkit": lambda: T.associate(r0, e0),
            "evo": lambda: sync.associate_trajectories(er0, ee0),
        },
        "align se3": {
            "rigidkit": lambda: T.align(e, r, method="se3"),
            "evo": evo_align(False),
            "_evo_overhead": evo_copy,
        },
        "align sim3": {
            "rigidkit": lambda: T.align(e, r, method="sim3"),
            "evo": evo_align(True),
            "_evo_overhead": evo_copy,
        },
        "APE translation": {
            "rigidkit": lambda: T.ape(r, aligned),
            "evo": evo_ape,
        },
        "RPE 1 frame": {
            "rigidkit": lambda: T.rpe(r, aligned),
            "evo": evo_rpe(1, Unit.frames, False),
        },
        "RPE 1 m, all pairs": {
            "rigidkit": lambda: T.rpe(r, aligned, delta=1.0, unit="meters", all_pairs=True),
            "evo": evo_rpe(1.0, Unit.meters, True) if all_pairs_evo else None,
        },
        "whole job": {"rigidkit": rk_job, "evo": evo_job},
    }
    if only:
        rows = {k: v for k, v in rows.items() if any(o in k for o in only)}
    # The checks: each rigidkit result against evo's.
    # Errors are differences of positions: two libraries that sum in different
    # orders agree to ~1e-16 of the positions' extent, which for a path of
    # kilometres and errors of millimetres is more than 1e-9 of the error. So an
    # error agrees when within 1e-9 relative OR 1e-12 of the extent.
    extent = float(np.abs(np.asarray(r.positions)).max())

    def same(a, b):
        return np.allclose(a, b, rtol=1e-9, atol=1e-12 * extent)

    checks = {
        "associate": lambda: (
            np.array_equal(r.stamps, er.timestamps)
            and np.array_equal(e.stamps, ee.timestamps)
        ),
        "align sim3": lambda: same(aligned.positions, ee_aligned.positions_xyz),
        "APE translation": lambda: same(T.ape(r, aligned).errors, evo_ape().error),
        "RPE 1 frame": lambda: same(
            T.rpe(r, aligned).errors, evo_rpe(1, Unit.frames, False)().error
        ),
    }
    if all_pairs_evo:
        checks["RPE 1 m, all pairs"] = lambda: same(
            T.rpe(r, aligned, delta=1.0, unit="meters", all_pairs=True).errors,
            evo_rpe(1.0, Unit.meters, True)().error,
        )
    checks = {k: check() for k, check in checks.items() if k in rows}
    return rows, checks, len(r)


def run_case(name, repeat, all_pairs_max, min_sample, only=None):
    n_ref, rate_ref, n_est, rate_est = CASES[name]
    from rigidkit._engine import numba_backend

    with tempfile.TemporaryDirectory() as d:
        ref_path, est_path = make_files(d, n_ref, rate_ref, n_est, rate_est)
        rows, checks, pairs = contenders(
            ref_path, est_path, pairs_ok := n_est <= all_pairs_max, only
        )
        for fns in rows.values():  # one pass, then let the background compiles land
            fns["rigidkit"]()
        numba_backend.drain()
        results = {}
        for row, fns in rows.items():
            timed = {k: f for k, f in fns.items() if f is not None}
            results[row] = C.interleaved_medians(
                timed, repeat=repeat, min_sample=min_sample, warmup=0
            )
        return results, checks, pairs, pairs_ok


def report(name, results, checks, pairs):
    n_ref, _, n_est, _ = CASES[name]
    out = [f"\n{name}: {n_ref} reference poses, {n_est} estimated, {pairs} pairs"]
    rows = []
    for row, res in results.items():
        rk_s = res["rigidkit"]["median"]
        evo = res.get("evo", {}).get("median")
        if evo is not None and "_evo_overhead" in res:
            evo -= res["_evo_overhead"]["median"]  # evo aligns in place: not the copy
        ratio = None if evo is None else evo / rk_s
        target = JOB_TARGET if row == "whole job" else METRIC_TARGET
        if row.startswith("read"):
            target = None
        ok = (
            "-" if ratio is None or target is None else ("yes" if ratio >= target else "NO")
        )
        check = {True: "ok", False: "DIFFERS"}.get(checks.get(row), "")
        rows.append(
            [
                row,
                C.fmt(rk_s * 1e3),
                C.fmt(None if evo is None else evo * 1e3),
                C.fmt(ratio) + ("x" if ratio else ""),
                f">= {target:g}x" if target else "-",
                ok,
                check,
            ]
        )
    out.append(
        C.table(
            ["row", "rigidkit ms", "evo ms", "speed-up", "target", "met", "equal"], rows
        )
    )
    return "\n".join(out), rows


def whole_process(ref_path_dir, runs):
    """``rigidkit ape`` against ``evo_ape`` as whole processes on the desk files."""
    n_ref, rate_ref, n_est, rate_est = CASES["desk"]
    ref_path, est_path = make_files(ref_path_dir, n_ref, rate_ref, n_est, rate_est)
    bindir = os.path.dirname(sys.executable)
    ours = [os.path.join(bindir, "rigidkit"), "ape", ref_path, est_path, "--align", "sim3"]
    theirs = [os.path.join(bindir, "evo_ape"), "tum", ref_path, est_path, "-as"]
    bench = shutil.which("farm-bench")
    if bench:
        proc = subprocess.run(
            [
                bench,
                "-n",
                str(runs),
                "--timeout",
                "600",
                "--vs",
                " ".join(theirs),
                "--",
                *ours,
            ],
            capture_output=True,
            text=True,
            check=False,
        )
        return "farm-bench, A = rigidkit ape, B = evo_ape:\n" + proc.stdout.strip()
    times = {"rigidkit ape": [], "evo_ape": []}
    for _ in range(runs):
        for label, cmd in (("rigidkit ape", ours), ("evo_ape", theirs)):
            t0 = time.perf_counter()
            subprocess.run(cmd, capture_output=True, check=True)
            times[label].append(time.perf_counter() - t0)
    return "\n".join(
        f"{k}: median {statistics.median(v):.3f} s over {runs} runs"
        for k, v in times.items()
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--min-sample", type=float, default=0.05)
    ap.add_argument(
        "--all-pairs-max",
        type=int,
        default=100_000,
        help="time evo's RPE all_pairs only up to this many poses (its "
        "cost grows with the square)",
    )
    ap.add_argument(
        "--rows",
        nargs="+",
        metavar="TEXT",
        help="time only the rows whose name contains one of these (e.g. associate APE)",
    )
    ap.add_argument("--process-runs", type=int, default=5)
    ap.add_argument("--no-process", action="store_true")
    ap.add_argument("--json", metavar="PATH")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    print(f"{C.load_average()}; numpy {np.__version__}")
    doc = {}
    for name in args.cases:
        results, checks, pairs, _ = run_case(
            name, args.repeat, args.all_pairs_max, args.min_sample, args.rows
        )
        text, rows = report(name, results, checks, pairs)
        print(text, flush=True)
        doc[name] = {
            "rows": rows,
            "raw": {
                r: {k: v.get("median") for k, v in res.items()}
                for r, res in results.items()
            },
        }
    if not args.no_process:
        with tempfile.TemporaryDirectory() as d:
            text = whole_process(d, args.process_runs)
        print("\nwhole process, desk case, --align sim3:\n" + text)
        doc["process"] = text
    if args.json:
        with open(args.json, "w") as f:
            json.dump(doc, f, indent=2)


if __name__ == "__main__":
    main()
