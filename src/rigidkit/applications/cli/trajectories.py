"""``rigidkit ape``, ``rigidkit rpe`` and ``rigidkit kitti``: trajectory errors.

Each reads two trajectory files (:func:`rigidkit.io.read_trajectory`), pairs
their poses by time (:func:`rigidkit.trajectory.associate`; by index where a
file has no stamps), aligns the estimate (:func:`rigidkit.trajectory.align`)
and prints the statistics of the errors as a table, or writes them as JSON.
The trajectory modules load only when one of these commands runs, so that
``rigidkit convert`` starts as fast as before.
"""

from __future__ import annotations

import argparse
import json

from .representations import CLIError

__all__ = ["add_trajectory_commands"]

_FORMATS = ("tum", "kitti", "euroc", "csv")
_ALIGN = ("none", "se3", "sim3", "scale", "yaw", "origin")
_RELATIONS = ("translation", "rotation_angle", "rotation_part", "full", "point_distance")
_STATS = ("rmse", "mean", "median", "std", "min", "max", "sse")

_COMMON_EPILOG = """\
files: REF and EST are TUM (t x y z qx qy qz qw), KITTI (12 numbers: a 3x4
  matrix, row-major), EuRoC (the ASL ground-truth CSV) or CSV with a header naming
  its columns; the format is detected from the content unless given. Poses are
  paired by time (the nearest stamp within --max-diff seconds, after adding
  --offset to EST's stamps); a file without stamps (KITTI) is paired by index.

alignment (--align): none (default), se3 (Umeyama rigid), sim3 (with scale, for
  monocular estimates), scale (scale only), yaw (4-DoF: translation and rotation
  about gravity z), origin (the first poses coincide); --first N fits on the
  first N pairs only.

exit status: 0 success; 2 bad arguments, an unreadable or malformed file (the
  message names the file and line), no pose pair.
"""


def _nonnegative(text):
    value = float(text)
    if not value >= 0.0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, got {text.strip()!r}")
    return value


def _positive_int(text):
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}")
    return n


def _add_common(p, relation=True):
    p.add_argument("ref", metavar="REF", help="reference (ground-truth) trajectory file")
    p.add_argument("est", metavar="EST", help="estimated trajectory file")
    p.add_argument("--format", choices=_FORMATS, help="the format of both files")
    p.add_argument("--ref-format", choices=_FORMATS, help="the format of REF")
    p.add_argument("--est-format", choices=_FORMATS, help="the format of EST")
    p.add_argument(
        "--max-diff",
        type=_nonnegative,
        default=0.01,
        metavar="S",
        help="largest stamp difference of a pair, seconds (default 0.01)",
    )
    p.add_argument(
        "--offset", type=float, default=0.0, metavar="S", help="added to EST's stamps"
    )
    p.add_argument("--align", choices=_ALIGN, default="none", help="alignment of EST")
    p.add_argument(
        "--first", type=_positive_int, metavar="N", help="align on the first N pairs"
    )
    if relation:
        p.add_argument(
            "--relation",
            choices=_RELATIONS,
            default="translation",
            help="what of each error pose is measured (default translation)",
        )
        p.add_argument("--degrees", action="store_true", help="rotation_angle in degrees")
    p.add_argument(
        "--json", metavar="PATH", help="write the results as JSON to PATH (- for stdout)"
    )
    p.add_argument(
        "--plot",
        metavar="PATH",
        help="save plots to PATH (.png, .pdf, .svg; needs matplotlib)",
    )


def _command(commands, name, help, description, example, run, relation=True):
    """A subcommand ``name`` with the options every trajectory command takes."""
    p = commands.add_parser(
        name,
        help=help,
        description=description,
        epilog=_COMMON_EPILOG + f"\nexample:\n  rigidkit {name} {example}\n",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        allow_abbrev=False,
    )
    _add_common(p, relation=relation)
    p.set_defaults(func=run)
    return p


def add_trajectory_commands(commands) -> None:
    """Add ``ape``, ``rpe`` and ``kitti`` to the subparsers ``commands``."""
    _command(
        commands,
        "ape",
        "absolute pose error of an estimated trajectory",
        "Absolute pose error: E_i = est_i^-1 ref_i for each pose pair.",
        "groundtruth.txt estimate.txt --align sim3",
        run_ape,
    )
    rpe = _command(
        commands,
        "rpe",
        "relative pose error (drift) of an estimated trajectory",
        "Relative pose error: E_ij = (ref_i^-1 ref_j)^-1 (est_i^-1 est_j) over pose\n"
        "pairs DELTA apart (in frames, metres or degrees of rotation).",
        "gt.txt est.txt --delta 1 --unit meters --all-pairs",
        run_rpe,
    )
    rpe.add_argument(
        "--delta", type=float, default=1.0, help="pair spacing in --unit (default 1)"
    )
    rpe.add_argument(
        "--unit",
        choices=("frames", "meters", "degrees", "radians"),
        default="frames",
        help="unit of --delta (default frames)",
    )
    rpe.add_argument(
        "--all-pairs",
        action="store_true",
        help="every pair DELTA apart, not consecutive ones",
    )
    rpe.add_argument(
        "--tolerance",
        type=_nonnegative,
        default=0.1,
        help="--all-pairs in metres or angles: relative tolerance of DELTA (default 0.1)",
    )
    rpe.add_argument(
        "--pairs-from",
        choices=("estimate", "reference"),
        default="estimate",
        help="the trajectory whose path chooses the pairs (default estimate)",
    )
    kitti = _command(
        commands,
        "kitti",
        "KITTI odometry errors (%% and deg/100 m over 100-800 m segments)",
        "The KITTI odometry benchmark's errors: drift over path segments of\n"
        "100, 200, ..., 800 m starting every 10th frame (Geiger et al. 2012).",
        "00.txt 00_orb.txt",
        run_kitti,
        relation=False,
    )
    kitti.add_argument(
        "--step", type=_positive_int, default=10, help="spacing of first frames (10)"
    )


# -- running ---------------------------------------------------------------------------


def _load(args):
    """Read, pair and align: ``(ref, est, aligned_est, S)``."""
    from ..io import read_trajectory
    from ..trajectory import align, associate

    ref = read_trajectory(args.ref, args.ref_format or args.format)
    est = read_trajectory(args.est, args.est_format or args.format)
    if ref.stamps is not None and est.stamps is not None:
        ref, est = associate(ref, est, max_diff=args.max_diff, offset=args.offset)
    elif len(ref) != len(est):
        raise CLIError(
            f"{args.ref} has {len(ref)} poses and {args.est} {len(est)}; without stamps "
            "in both, poses are paired by index and the counts must match"
        )
    if args.first is not None and args.first > len(est):
        raise CLIError(f"--first {args.first}: only {len(est)} pose pairs")
    aligned, S = align(est, ref, method=args.align, first=args.first)
    return ref, est, aligned, S


def _alignment_json(method, S):
    from ...objects.similarity import Similarity

    doc = {"method": method, "matrix": S.as_matrix().tolist()}
    doc["scale"] = float(S.scale) if isinstance(S, Similarity) else 1.0
    return doc


def _emit(args, doc, lines):
    if args.json is None:
        print("\n".join(lines))
        return
    text = json.dumps(doc, indent=2, allow_nan=False)
    if args.json == "-":
        print(text)
        return
    try:
        with open(args.json, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    except OSError as exc:
        raise CLIError(f"cannot write {args.json!r}: {exc.strerror or exc}") from None
    print("\n".join(lines))


def _table(title, stats, unit):
    width = max(len(f"{v:.6f}") for v in stats.values())
    out = [title]
    for key in _STATS:
        out.append(f"  {key:>6}  {stats[key]:>{width}.6f}  {unit}")
    return out


def _describe(args, n, S):
    from ...objects.similarity import Similarity

    align = args.align
    if isinstance(S, Similarity):
        align += f" (scale {float(S.scale):.6g})"
    return f"{n} pose pairs, alignment {align}"


def _plot(args, ref, est, result, title):
    if args.plot is None:
        return
    from ..trajectory.plot import save_report

    try:
        save_report(args.plot, ref, est, result, title=title)
    except ImportError as exc:
        raise CLIError(str(exc)) from None
    except (OSError, ValueError) as exc:
        raise CLIError(f"cannot write the plot {args.plot!r}: {exc}") from None


def run_ape(args) -> int:
    """The ``ape`` command on parsed ``args``."""
    from ..trajectory import ape

    ref, _, aligned, S = _load(args)
    result = ape(ref, aligned, relation=args.relation, degrees=args.degrees)
    title = f"APE, {args.relation} [{result.unit}]"
    doc = {
        "metric": "ape",
        "relation": args.relation,
        "unit": result.unit,
        "n": int(len(result.errors)),
        "stats": result.stats,
        "alignment": _alignment_json(args.align, S),
    }
    _emit(
        args,
        doc,
        _table(f"{title}: {_describe(args, len(ref), S)}", result.stats, result.unit),
    )
    _plot(args, ref, aligned, result, title)
    return 0


def run_rpe(args) -> int:
    """The ``rpe`` command on parsed ``args``."""
    from ..trajectory import rpe

    ref, _, aligned, S = _load(args)
    if args.unit == "frames" and not float(args.delta).is_integer():
        raise CLIError(f"--delta in frames must be a whole number, got {args.delta!r}")
    delta = int(args.delta) if args.unit == "frames" else args.delta
    if not delta > 0:
        raise CLIError(f"--delta must be positive, got {args.delta!r}")
    result = rpe(
        ref,
        aligned,
        delta=delta,
        unit=args.unit,
        relation=args.relation,
        all_pairs=args.all_pairs,
        tolerance=args.tolerance,
        degrees=args.degrees,
        pairs_from=args.pairs_from,
    )
    title = f"RPE, {args.relation} [{result.unit}], delta {delta} {args.unit}"
    doc = {
        "metric": "rpe",
        "relation": args.relation,
        "unit": result.unit,
        "delta": delta,
        "delta_unit": args.unit,
        "all_pairs": args.all_pairs,
        "n": int(len(result.errors)),
        "stats": result.stats,
        "alignment": _alignment_json(args.align, S),
    }
    lines = _table(
        f"{title}: {len(result.errors)} pairs of {_describe(args, len(ref), S)}",
        result.stats,
        result.unit,
    )
    _emit(args, doc, lines)
    _plot(args, ref, aligned, result, title)
    return 0


def run_kitti(args) -> int:
    """The ``kitti`` command on parsed ``args``."""
    from ..trajectory import kitti_errors

    ref, _, aligned, S = _load(args)
    result = kitti_errors(ref, aligned, step=args.step)
    described = _describe(args, len(ref), S)
    lines = [
        f"KITTI odometry errors: {len(result.first)} segments, {described}",
        f"  translation  {result.translation_percent:.4f} %",
        f"  rotation     {result.rotation_deg_per_100m:.4f} deg/100m",
        "  length [m]  translation [%]  rotation [deg/100m]  segments",
    ]
    for L, (t, r, count) in result.table.items():
        lines.append(f"  {L:>10g}  {t:>15.4f}  {r:>19.4f}  {count:>8d}")
    doc = {
        "metric": "kitti",
        "n": len(ref),
        "segments": int(len(result.first)),
        "translation_percent": result.translation_percent,
        "rotation_deg_per_100m": result.rotation_deg_per_100m,
        "lengths": {
            str(L): {"translation_percent": t, "rotation_deg_per_100m": r, "segments": c}
            for L, (t, r, c) in result.table.items()
        },
        "alignment": _alignment_json(args.align, S),
    }
    _emit(args, doc, lines)
    if args.plot is not None:
        from ..trajectory import ape

        _plot(args, ref, aligned, ape(ref, aligned), "KITTI sequence, APE [m]")
    return 0
