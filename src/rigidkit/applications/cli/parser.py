"""The argument parser of ``rigidkit``, with its help texts."""

from __future__ import annotations

import argparse

from ... import __version__
from .convert import PROG
from .representations import is_number
from .trajectories import add_trajectory_commands

__all__ = ["build_parser", "shield_negative_numbers"]

_REPRESENTATIONS_HELP = """\
representations (REPR, and the names --to accepts):
  quat         4 numbers  w x y z   Hamilton quaternion, scalar first (any nonzero norm)
  quat:xyzw    4 numbers  x y z w   scalar last (scipy, ROS, Eigen storage order)
  matrix       9 numbers            3x3 rotation matrix, row-major (validated)
  rotvec       3 numbers  x y z     rotation vector: angle * unit axis
  axis-angle   4 numbers  x y z a   axis (any nonzero length), then the angle
  mrp          3 numbers  x y z     modified Rodrigues parameters: axis * tan(angle/4)
  euler:SEQ    3 numbers            angles in sequence order; SEQ is three letters of
                                    xyz, UPPER = intrinsic (body axes, e.g. ZYX =
                                    yaw-pitch-roll), lower = extrinsic (world axes)
  rpy          3 numbers  r p y     roll, pitch, yaw in that order, as ROS, URDF and
                                    tf write them: about the fixed x, y, z axes
                                    (= euler:xyz; euler:ZYX takes yaw pitch roll)
  all          (--to only) quat, quat:xyzw, matrix, rotvec, axis-angle, mrp and
               euler:ZYX, XYZ, ZXZ, ZYZ, xyz

Rotations are active on column vectors (v_A = A_R_B @ v_B). Angles are radians
unless --degrees, which applies to the angles read and written (rotvec, the angle
of axis-angle, Euler angles); angles over 2*pi read as radians get a warning that
they look like degrees. Output quaternions are canonical (w >= 0), rotation
vectors and axis-angle have their angle in [0, pi], MRPs have norm <= 1.
"""

_CONVERT_EPILOG = (
    _REPRESENTATIONS_HELP
    + """
one rotation: rigidkit convert REPR VALUE ... [--to TARGET ...]
  Prints a table, one line per target (three for matrix); the first column is the
  name to pass back as REPR. Numbers are printed with every digit needed to read
  back the same float64 (Python repr); --decimals N rounds them (in the table,
  JSON and batch files alike). A negative zero is printed as 0.
  Default --to: all. Negative numbers need no quoting (euler:ZYX -30 20 10).

batch: rigidkit convert [--from] REPR -i IN -o OUT --to TARGET ...
  IN and OUT are .npy, .csv or .txt files (- is CSV on stdin / stdout). Input
  .npy: a float array of shape (N, k), k the numbers per rotation (matrix also
  (N, 3, 3)). Input .csv or .txt: k numbers per line, separated by commas (,),
  semicolons (;), tabs, or runs of spaces and tabs (as in TUM and KITTI logs),
  whichever splits the lines into k fields; with commas, semicolons or tabs a
  field may be in double quotes. Blank lines and lines starting with # are
  skipped. The first line is a header only if none of its fields is a number.
  A header naming the components (w,x,y,z or qx,qy,qz,qw; m11..m33; angle1..3
  or roll,pitch,yaw for Euler sequences about three different axes; or this
  command's own TARGET.COMPONENT) sets the order of the columns; one naming
  other components than REPR's is an error, and one naming none is read with a
  warning (the columns taken in REPR's order). Output: the targets' columns
  side by side, in --to order (quat: w x y z; matrix: m11 m12 ... m33
  row-major; axis-angle: x y z angle), as a float64 array of shape (N, total
  columns) in .npy, as CSV with a header line naming each column
  TARGET.COMPONENT (quat.w, matrix.m12, euler:ZYX.angle1), or as .txt with the
  numbers separated by spaces under a '# ' header line. Numbers are written as
  shortest round-trip repr, or rounded to --decimals N in every format. All
  arithmetic is float64. Errors name the row: 1-based data row (CSV: header,
  comments and blank lines are not counted; the file line number is given too;
  .npy: row i is index i - 1). On any error nothing is written and an existing
  OUT is left untouched; every input row gives one output row.

exit status: 0 success; 2 bad arguments, malformed row, invalid rotation (e.g. a
  matrix that is not a rotation, a zero quaternion), unreadable or unwritable file.

examples:
  rigidkit convert euler:ZYX 30 20 10 --degrees --to quat matrix rotvec
  rigidkit convert quat 0.7071 0 0 0.7071 --to all --decimals 6
  rigidkit convert matrix 0 -1 0  1 0 0  0 0 1 --to euler:zyx --degrees
  rigidkit convert --from euler:ZYX -i angles.csv -o quats.npy --to quat --degrees
  rigidkit convert euler:ZYX -i angles.csv -o quats.csv --to quat --degrees
"""
)


def build_parser(run_convert) -> argparse.ArgumentParser:
    """The parser; ``run_convert(args)`` runs the ``convert`` command."""
    parser = argparse.ArgumentParser(
        prog=PROG,
        description=(
            "rigidkit: rigid-body rotations in every representation.\n"
            "Conventions: Hamilton quaternions (w, x, y, z); active rotations on\n"
            "column vectors (v_A = A_R_B @ v_B); Euler UPPER = intrinsic, lower =\n"
            "extrinsic; radians unless --degrees."
        ),
        epilog=(
            "example:\n  rigidkit convert euler:ZYX 30 20 10 --degrees --to quat matrix\n\n"
            "Run 'rigidkit convert --help' for the representations, batch files "
            "and more examples."
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        allow_abbrev=False,
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    convert = commands.add_parser(
        "convert",
        help="convert rotations between representations (one, or a .csv/.npy batch)",
        description=(
            "Convert one rotation given on the command line, or a batch of rotations\n"
            "in a .npy or .csv file, from one representation into others."
        ),
        usage=(
            "%(prog)s REPR VALUE ... [--to TARGET ...] [options]\n"
            "       %(prog)s [--from] REPR -i IN [-o OUT] --to TARGET ... [options]"
        ),
        epilog=_CONVERT_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
        allow_abbrev=False,
    )
    convert.add_argument(
        "values", nargs="*", metavar="REPR VALUE", help="representation, then its numbers"
    )
    convert.add_argument(
        "--to",
        nargs="+",
        metavar="TARGET",
        help="representations to output (space- or comma-separated, or 'all')",
    )
    convert.add_argument(
        "--from",
        dest="source",
        metavar="REPR",
        help="representation of the input (with --input, or give REPR first)",
    )
    convert.add_argument(
        "--degrees", action="store_true", help="angles in and out are in degrees"
    )
    convert.add_argument(
        "--orthonormalize",
        action="store_true",
        help="matrix input: use the nearest rotation (SVD) instead of rejecting a matrix "
        "that is not a rotation within 1e-5 (e.g. one typed with few digits)",
    )
    convert.add_argument(
        "-i", "--input", metavar="IN", help="batch input: .npy, .csv, .txt or -"
    )
    convert.add_argument(
        "-o",
        "--output",
        metavar="OUT",
        help="batch output: .npy, .csv, .txt or - (default -)",
    )
    convert.add_argument(
        "--decimals",
        type=_nonnegative_int,
        metavar="N",
        help="round every number written (table, JSON, .csv, .txt, .npy) to N "
        "decimals instead of all round-trip digits",
    )
    convert.add_argument(
        "--format",
        choices=("table", "json"),
        default="table",
        help="one rotation: an aligned table (default) or JSON",
    )
    convert.set_defaults(func=run_convert)
    add_trajectory_commands(commands)
    return parser


def _nonnegative_int(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = -1
    if n < 0:
        raise argparse.ArgumentTypeError(
            f"expected a whole number >= 0, got {text.strip()!r}"
        )
    return n


def shield_negative_numbers(argv) -> list:
    """Prefix numbers like ``-30``, ``-1e-3``, ``-inf`` with a space.

    argparse takes any word starting with ``-`` for an option unless it matches
    its narrow negative-number pattern (``-1e-3`` and ``-inf`` do not). A word
    that does not start with ``-`` is always positional, and ``float`` and
    ``int`` ignore the leading space.

    >>> shield_negative_numbers(["rotvec", "-1e-3", "--to", "quat", "--", "-x"])
    ['rotvec', ' -1e-3', '--to', 'quat', '--', '-x']
    """
    out = []
    for k, arg in enumerate(argv):
        if arg == "--":
            return out + list(argv[k:])
        out.append(" " + arg if arg.startswith("-") and is_number(arg) else arg)
    return out
