"""The ``rigidkit`` command line: ``rigidkit convert``.

One rotation given on the command line, or a whole ``.csv`` / ``.npy`` batch, is
converted from any representation into others. Conventions: Hamilton quaternions,
scalar first ``(w, x, y, z)`` unless ``quat:xyzw``; active rotations on column
vectors, ``v_A = A_R_B @ v_B``; Euler sequences UPPER = intrinsic, lower =
extrinsic; radians unless ``--degrees`` (which applies to angles read and written).

Exit status: 0 on success, 2 for any error the user can fix (arguments, a
malformed input row, an invalid rotation, an unreadable or unwritable file; one
line on stderr, never a traceback). A batch output file is written to a temporary
file in the same directory and renamed over the target only once everything has
succeeded, so a failed run leaves no partial file and never clobbers an existing
one.

>>> main(["convert", "rotvec", "0", "0", "90", "--degrees", "--to", "quat:xyzw",
...       "--decimals", "6"])
quat:xyzw  x y z w  0.000000  0.000000  0.707107  0.707107
0
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import io
import json
import os
import re
import sys
import tempfile
import warnings
from dataclasses import dataclass

import numpy as np

from .. import __version__
from ..errors import GimbalLockWarning, RigidkitError
from ..objects.rotation import Rotation

__all__ = ["main"]

PROG = "rigidkit"


class CLIError(Exception):
    """A user error found by the command line itself (one line, exit status 2)."""


# -- representations -------------------------------------------------------------------


@dataclass(frozen=True)
class Representation:
    """One rotation representation as named on the command line.

    ``columns`` name the numbers of one rotation in the order they are read and
    written; ``label`` describes them for the table (``degrees`` adds the unit).
    """

    name: str
    columns: tuple
    label: str
    angle_unit: bool = False  # does --degrees change some of its numbers?
    seq: str | None = None  # Euler sequence, for euler:SEQ

    @property
    def size(self) -> int:
        return len(self.columns)

    def describe(self, degrees: bool) -> str:
        unit = "deg" if degrees else "rad"
        return f"{self.label} ({unit})" if self.angle_unit else self.label

    def rotation_from(self, values, degrees: bool, orthonormalize=False) -> Rotation:
        """The rotations of ``values``, shape (..., size), as a :class:`Rotation`.

        ``orthonormalize`` (matrices only): the nearest rotation instead of an error.
        """
        kind = self.name if self.seq is None else "euler"
        if kind == "quat":
            return Rotation.from_quat(values, scalar_first=True)
        if kind == "quat:xyzw":
            return Rotation.from_quat(values, scalar_first=False)
        if kind == "matrix":
            m = values.reshape(values.shape[:-1] + (3, 3))
            return Rotation.from_matrix(m, orthonormalize=orthonormalize)
        if kind == "rotvec":
            return Rotation.from_rotvec(values, degrees=degrees)
        if kind == "axis-angle":
            return Rotation.from_axis_angle(
                values[..., :3], values[..., 3], degrees=degrees
            )
        if kind == "mrp":
            return Rotation.from_mrp(values)
        return Rotation.from_euler(self.seq, values, degrees=degrees)

    def values_of(self, rotation: Rotation, degrees: bool) -> np.ndarray:
        """This representation of ``rotation``, shape ``rotation.shape + (size,)``.

        Quaternions are canonical (``w >= 0``); rotation vectors and axis-angle
        have angles in [0, pi]; MRPs have norm <= 1.
        """
        kind = self.name if self.seq is None else "euler"
        if kind == "quat":
            out = rotation.as_quat(scalar_first=True, canonical=True)
        elif kind == "quat:xyzw":
            out = rotation.as_quat(scalar_first=False, canonical=True)
        elif kind == "matrix":
            out = rotation.as_matrix()
        elif kind == "rotvec":
            out = rotation.as_rotvec(degrees=degrees)
        elif kind == "axis-angle":
            axis, angle = rotation.as_axis_angle(degrees=degrees)
            out = np.concatenate([axis, np.asarray(angle)[..., None]], axis=-1)
        elif kind == "mrp":
            out = rotation.as_mrp()
        else:
            out = rotation.as_euler(self.seq, degrees=degrees)
        return np.asarray(out, dtype=np.float64).reshape(rotation.shape + (self.size,))


_FIXED = {
    "quat": Representation("quat", ("w", "x", "y", "z"), "w x y z"),
    "quat:xyzw": Representation("quat:xyzw", ("x", "y", "z", "w"), "x y z w"),
    "matrix": Representation(
        "matrix", tuple(f"m{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)), "row-major"
    ),
    "rotvec": Representation("rotvec", ("x", "y", "z"), "x y z", angle_unit=True),
    "axis-angle": Representation(
        "axis-angle", ("x", "y", "z", "angle"), "axis x y z, angle", angle_unit=True
    ),
    "mrp": Representation("mrp", ("x", "y", "z"), "x y z"),
}
# The explicit spelling of the default order is accepted too.
_ALIASES = {"quat:wxyz": "quat"}

#: What ``--to all`` prints, in order. The Euler sequences are the common ones:
#: ZYX (yaw-pitch-roll, aerospace), XYZ, ZXZ (classical), ZYZ (robot wrists), and
#: extrinsic xyz (roll-pitch-yaw about fixed axes; the same angles as ZYX reversed).
ALL = (
    "quat",
    "quat:xyzw",
    "matrix",
    "rotvec",
    "axis-angle",
    "mrp",
    "euler:ZYX",
    "euler:XYZ",
    "euler:ZXZ",
    "euler:ZYZ",
    "euler:xyz",
)

_NAMES_HELP = "quat, quat:xyzw, matrix, rotvec, axis-angle, mrp, euler:SEQ (e.g. euler:ZYX)"


def representation(name: str) -> Representation:
    """The :class:`Representation` called ``name`` on the command line.

    Raises :class:`CLIError` naming the accepted forms (and the closest match).
    """
    name = _ALIASES.get(name, name)
    if name in _FIXED:
        return _FIXED[name]
    if name.startswith("euler:"):
        seq = name[len("euler:") :]
        from ..functional.euler import parse_sequence

        try:
            # The library's parser is the one source of truth for the 24 accepted
            # forms and for the wording of the error.
            parse_sequence(seq)
        except RigidkitError as exc:
            raise CLIError(f"bad representation {name!r}: {exc}") from None
        kind = "intrinsic" if seq.isupper() else "extrinsic"
        return Representation(
            name,
            ("angle1", "angle2", "angle3"),
            f"{' '.join(seq)} {kind}",
            angle_unit=True,
            seq=seq,
        )
    close = difflib.get_close_matches(name, [*_FIXED, "axis-angle", "euler:ZYX"], n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise CLIError(f"unknown representation {name!r}{hint}; expected one of: {_NAMES_HELP}")


def _targets(tokens) -> list:
    """The ``--to`` list: names separated by spaces or commas, ``all`` expanded."""
    names = []
    for token in tokens:
        for name in token.strip().split(","):
            if not name:
                continue
            if _is_number(name):
                raise CLIError(
                    f"--to takes representation names, not the number {name!r}; "
                    "give the rotation (REPR VALUE ...) before --to"
                )
            names.extend(ALL if name == "all" else [name])
    reps = []
    for name in dict.fromkeys(names):  # drop repeats, keep order
        rep = representation(name)
        if rep not in reps:
            reps.append(rep)
    return reps


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


# -- errors located in a batch ---------------------------------------------------------

# rigidkit's validators name the first bad element as "at batch index (i,)".
_BATCH_INDEX = re.compile(r" ?at batch index \((\d+),\)")


def _locate(message: str, where, *, inline=False) -> str | None:
    """``message`` with its batch index ``i`` replaced by the row ``where(i)``.

    The row leads the message (``"where: message"``) unless ``inline``; None when
    the message names no batch index.
    """
    found = _BATCH_INDEX.search(message)
    if found is None:
        return None
    row = where(int(found.group(1)))
    if inline:
        return f"{message[: found.start()]} at {row}{message[found.end() :]}"
    return f"{row}: {message[: found.start()]}{message[found.end() :]}"


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _os_text(exc: Exception) -> str:
    """The reason of an I/O error without the (possibly temporary) file name."""
    return _one_line(getattr(exc, "strerror", None) or exc)


def _convert(source, values, targets, degrees, *, orthonormalize=False, where=None):
    """Convert ``values`` (..., source.size) into a list of target arrays.

    For a batch (``where`` given), an error or warning naming a batch index is
    rewritten to name the input row instead. Gimbal-lock warnings go to stderr as
    one line each (the angles returned still rebuild the rotation).
    """

    def attempt(rows):
        rotation = source.rotation_from(rows, degrees, orthonormalize)
        return [t.values_of(rotation, degrees) for t in targets]

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GimbalLockWarning)
        try:
            outputs = attempt(values)
        except RigidkitError as exc:
            # The library's advice, in command-line words.
            text = str(exc).replace("pass orthonormalize=True", "pass --orthonormalize")
            if where is None:
                raise CLIError(text) from None
            message = _locate(text, where)
            if message is None:
                row = _first_failing_row(attempt, values)
                message = f"{where(row)}: {text}"
            raise CLIError(message) from None
    shown = set()
    for w in caught:
        if issubclass(w.category, GimbalLockWarning):
            text = str(w.message)
            text = (_locate(text, where, inline=True) or text) if where else text
            if text not in shown:
                shown.add(text)
                print(f"{PROG}: warning: {_one_line(text)}", file=sys.stderr)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return outputs


def _first_failing_row(attempt, values) -> int:
    """Index of the first row on which ``attempt`` raises, found by bisection.

    Only used when an error message names no batch index; costs about
    log2(N) conversions of prefixes of the batch.
    """
    good, bad = 0, len(values)  # values[:good] converts; values[:bad] fails
    while bad - good > 1:
        mid = (good + bad) // 2
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", GimbalLockWarning)
                attempt(values[:mid])
        except RigidkitError:
            bad = mid
        else:
            good = mid
    return good


def _check_finite(values, where) -> None:
    """Reject NaN and infinity in the input rows before any conversion."""
    finite = np.isfinite(values)
    if finite.all():
        return
    row, col = np.argwhere(~finite)[0]
    raise CLIError(
        f"{where(int(row))}: field {col + 1} is {float(values[row, col])!r}; "
        "every number must be finite"
    )


# -- one rotation on the command line --------------------------------------------------


def _format_number(x: float, decimals) -> str:
    x = float(x) + 0.0  # turns -0.0 into 0.0 for display
    if decimals is None:
        return repr(x)  # the shortest string that reads back as the same float64
    text = f"{x:.{decimals}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    return text


def _split_at_point(text: str):
    """Split a number at its decimal point (or exponent), to align columns on it."""
    for mark in (".", "e"):
        k = text.find(mark)
        if k >= 0:
            return text[:k], text[k:]
    return text, ""


def format_table(rows, decimals=None) -> str:
    """Align ``(name, label, numbers)`` rows; numbers align on their decimal point."""
    cells = [
        (name, label, [_split_at_point(_format_number(x, decimals)) for x in nums])
        for name, label, nums in rows
    ]
    ncol = max((len(c[2]) for c in cells), default=0)
    name_w = max((len(c[0]) for c in cells), default=0)
    label_w = max((len(c[1]) for c in cells), default=0)
    left_w = [
        max((len(c[2][j][0]) for c in cells if j < len(c[2])), default=0)
        for j in range(ncol)
    ]
    right_w = [
        max((len(c[2][j][1]) for c in cells if j < len(c[2])), default=0)
        for j in range(ncol)
    ]
    lines = []
    for name, label, nums in cells:
        parts = [name.ljust(name_w), label.ljust(label_w)]
        parts += [a.rjust(left_w[j]) + b.ljust(right_w[j]) for j, (a, b) in enumerate(nums)]
        lines.append("  ".join(parts).rstrip())
    return "\n".join(lines)


def _table_rows(targets, outputs, degrees):
    rows = []
    for rep, out in zip(targets, outputs, strict=True):
        if rep.name == "matrix":
            m = out.reshape(3, 3)
            rows += [("matrix" if i == 0 else "", f"row {i + 1}", m[i]) for i in range(3)]
        else:
            rows.append((rep.name, rep.describe(degrees), out))
    return rows


def _json_document(targets, outputs, degrees) -> str:
    doc = {"degrees": degrees}
    for rep, out in zip(targets, outputs, strict=True):
        values = out.reshape(3, 3) if rep.name == "matrix" else out
        doc[rep.name] = values.tolist()  # Python floats: json writes them as repr
    return json.dumps(doc, indent=2)


def _parse_values(tokens, source) -> np.ndarray:
    values = []
    for k, token in enumerate(tokens):
        try:
            values.append(float(token))
        except ValueError:
            raise CLIError(
                f"value {k + 1} of {source.name} is {token.strip()!r}, not a number"
            ) from None
    if len(values) != source.size:
        raise CLIError(
            f"{source.name} takes {source.size} numbers ({', '.join(source.columns)}), "
            f"got {len(values)}"
        )
    bad = [t.strip() for t, v in zip(tokens, values, strict=True) if not np.isfinite(v)]
    if bad:
        raise CLIError(f"{source.name}: {bad[0]!r} is not finite")
    return np.array(values, dtype=np.float64)


def _convert_one(args, targets) -> int:
    tokens = list(args.values)
    if args.source is None:
        if not tokens:
            raise CLIError(
                "give a rotation (REPR VALUE ...), e.g. 'euler:ZYX 30 20 10 --degrees', "
                "or a batch with --input FILE"
            )
        source_name = tokens.pop(0).strip()
    else:
        source_name = args.source
    source = representation(source_name)
    values = _parse_values(tokens, source)
    outputs = _convert(
        source, values, targets, args.degrees, orthonormalize=args.orthonormalize
    )
    if args.format == "json":
        print(_json_document(targets, outputs, args.degrees))
    else:
        print(format_table(_table_rows(targets, outputs, args.degrees), args.decimals))
    return 0


# -- batches: .npy and .csv files ------------------------------------------------------


def _kind_of(path: str, what: str) -> str:
    if path == "-":
        return "csv"
    ext = os.path.splitext(path)[1].lower()
    if ext in (".npy", ".csv"):
        return ext[1:]
    raise CLIError(
        f"cannot tell the format of {what} {path!r} from its extension; "
        "use a .npy or .csv file (or - for CSV on stdin/stdout)"
    )


def _read_npy(path: str, source):
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise CLIError(f"cannot read {path!r}: {_os_text(exc)}") from None
    if data.dtype.kind not in "fiu":
        raise CLIError(
            f"{path!r}: expected an array of real numbers, got dtype {data.dtype}"
        )
    if source.name == "matrix" and data.ndim == 3 and data.shape[1:] == (3, 3):
        data = data.reshape(len(data), 9)
    if data.ndim != 2 or data.shape[1] != source.size:
        alt = " or (N, 3, 3)" if source.name == "matrix" else ""
        raise CLIError(
            f"{path!r}: {source.name} needs an array of shape (N, {source.size}){alt} "
            f"({', '.join(source.columns)} per row), got shape {data.shape}"
        )

    def where(i):
        return f"{path} row {i + 1} (index {i})"

    return np.ascontiguousarray(data, dtype=np.float64), where


def _is_skipped(line: str) -> bool:
    """Blank lines and ``#`` comment lines carry no data."""
    s = line.strip()
    return not s or s.startswith("#")


def _is_header(line: str) -> bool:
    """A first line is a header when none of its fields is a number."""
    return not any(_is_number(f) for f in line.split(","))


def _data_lines(lines):
    """``(line_number, line)`` of every data line: no blanks, comments or header."""
    first = True
    for number, line in enumerate(lines, start=1):
        if _is_skipped(line):
            continue
        if first:
            first = False
            if _is_header(line):
                continue
        yield number, line


def _read_csv(path: str, source):
    name = "<stdin>" if path == "-" else path
    try:
        if path == "-":
            text = sys.stdin.read()
        else:
            with open(path, encoding="utf-8") as f:
                text = f.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise CLIError(f"cannot read {name!r}: {_os_text(exc)}") from None
    lines = text.splitlines()
    # Line numbers of the data rows, only computed when an error needs them.
    line_of = []

    def where(i):
        if not line_of:
            line_of.extend(n for n, _ in _data_lines(lines))
        return f"{name} line {line_of[i]} (data row {i + 1})"

    header_at = next((k for k, line in enumerate(lines) if not _is_skipped(line)), None)
    if header_at is None:
        return np.empty((0, source.size)), where
    skip = header_at + 1 if _is_header(lines[header_at]) else header_at
    try:
        # The fast path: numpy's C parser. It says little about what went wrong, so
        # a failure is diagnosed by the slow scan below.
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
            data = np.loadtxt(
                io.StringIO(text), delimiter=",", skiprows=skip, ndmin=2, dtype=np.float64
            )
    except ValueError as exc:
        _diagnose_csv(lines, source, name, exc)
    if data.size == 0:
        return np.empty((0, source.size)), where
    if data.shape[1] != source.size:
        _diagnose_csv(lines, source, name, None)
    return data, where


def _diagnose_csv(lines, source, name, exc):
    """Raise a :class:`CLIError` for the first malformed data line."""
    for row, (number, line) in enumerate(_data_lines(lines)):
        fields = line.split(",")
        at = f"{name} line {number} (data row {row + 1})"
        if len(fields) != source.size:
            raise CLIError(
                f"{at}: {source.name} needs {source.size} fields "
                f"({', '.join(source.columns)}), got {len(fields)}"
            )
        for k, field in enumerate(fields):
            if not _is_number(field):
                raise CLIError(f"{at}: field {k + 1} is {field.strip()!r}, not a number")
    reason = f": {_one_line(exc)}" if exc is not None else ""
    raise CLIError(f"cannot parse {name!r} as CSV{reason}")


def _column_names(targets) -> list:
    return [f"{t.name}.{c}" for t in targets for c in t.columns]


def _write_csv(stream, header, table) -> None:
    """CSV with a header line; numbers as shortest round-trip ``repr``."""
    stream.write(",".join(header) + "\n")
    if table.shape[0] == 0:
        return
    # One format string per block of rows: far fewer Python calls than a loop
    # over rows (np.savetxt), and repr of each float64 reads back exactly.
    block = 4096
    ncol = table.shape[1]
    row_fmt = ",".join(["%r"] * ncol) + "\n"
    full = row_fmt * block
    for start in range(0, table.shape[0], block):
        chunk = table[start : start + block]
        fmt = full if len(chunk) == block else row_fmt * len(chunk)
        stream.write(fmt % tuple(chunk.ravel().tolist()))


def _write_atomically(path: str, write_to, *, binary: bool) -> None:
    """Write through ``write_to(stream)`` into a temporary file, then rename it.

    The temporary file lives in the target's directory so that ``os.replace`` is
    an atomic rename; it is removed on any failure (including Ctrl-C), so the
    target is either the complete new file or untouched.
    """
    directory = os.path.dirname(os.path.abspath(path))
    try:
        fd, tmp = tempfile.mkstemp(
            dir=directory, prefix=f".{os.path.basename(path)}.", suffix=".part"
        )
    except OSError as exc:
        raise CLIError(f"cannot write {path!r}: {_os_text(exc)}") from None
    try:
        with (
            os.fdopen(fd, "wb")
            if binary
            else os.fdopen(fd, "w", encoding="ascii", newline="\n")
        ) as stream:
            write_to(stream)
            stream.flush()
            os.fsync(stream.fileno())
        os.chmod(tmp, _new_file_mode(path))  # mkstemp makes 0600 files
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise CLIError(f"cannot write {path!r}: {_os_text(exc)}") from None
        raise


def _new_file_mode(path: str) -> int:
    """Keep an existing file's permissions; otherwise what ``open`` would give."""
    try:
        return os.stat(path).st_mode & 0o777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def _convert_batch(args, targets) -> int:
    if args.source is None:
        raise CLIError("a batch needs --from REPR, the representation of the input rows")
    if args.values:
        raise CLIError(
            f"with --input, give no rotation on the command line (got {args.values[0]!r})"
        )
    source = representation(args.source)
    in_kind = _kind_of(args.input, "input")
    out_kind = _kind_of(args.output, "output")
    if in_kind == "npy":
        values, where = _read_npy(args.input, source)
    else:
        values, where = _read_csv(args.input, source)
    _check_finite(values, where)
    outputs = _convert(
        source,
        values,
        targets,
        args.degrees,
        orthonormalize=args.orthonormalize,
        where=where,
    )
    table = np.concatenate(outputs, axis=1) if outputs else np.empty((len(values), 0))
    if args.output == "-":
        _write_csv(sys.stdout, _column_names(targets), table)
    elif out_kind == "npy":
        _write_atomically(args.output, lambda f: np.save(f, table), binary=True)
    else:
        header = _column_names(targets)
        _write_atomically(args.output, lambda f: _write_csv(f, header, table), binary=False)
    return 0


def _run_convert(args) -> int:
    targets = _targets(args.to) if args.to else None
    if args.input is None:
        if args.output is not None:
            raise CLIError(
                "--output needs --input (a batch); one rotation prints to stdout"
            )
        return _convert_one(args, targets or _targets(["all"]))
    if targets is None:
        raise CLIError("a batch needs --to TARGET ... (the representations to write)")
    if args.decimals is not None or args.format != "table":
        raise CLIError(
            "--decimals and --format are for one rotation; batch files always hold "
            "every digit"
        )
    if args.output is None:
        args.output = "-"
    return _convert_batch(args, targets)


# -- argument parsing ------------------------------------------------------------------

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
  all          (--to only) quat, quat:xyzw, matrix, rotvec, axis-angle, mrp and
               euler:ZYX, XYZ, ZXZ, ZYZ, xyz

Rotations are active on column vectors (v_A = A_R_B @ v_B). Angles are radians
unless --degrees, which applies to the angles read and written (rotvec, the angle
of axis-angle, Euler angles). Output quaternions are canonical (w >= 0), rotation
vectors and axis-angle have their angle in [0, pi], MRPs have norm <= 1.
"""

_CONVERT_EPILOG = (
    _REPRESENTATIONS_HELP
    + """
one rotation: rigidkit convert REPR VALUE ... [--to TARGET ...]
  Prints a table, one line per target (three for matrix); the first column is the
  name to pass back as REPR. Numbers are printed with every digit needed to read
  back the same float64 (Python repr); --decimals N rounds them for reading.
  Default --to: all. Negative numbers need no quoting (euler:ZYX -30 20 10).

batch: rigidkit convert --from REPR -i IN -o OUT --to TARGET ...
  IN and OUT are .npy or .csv files (- is CSV on stdin / stdout). Input .npy: a
  float array of shape (N, k), k the numbers per rotation (matrix also (N, 3, 3)).
  Input .csv: k comma-separated numbers per line; blank lines and lines starting
  with # are skipped; the first line is a header, and skipped, if none of its
  fields is a number. Output: the targets' columns side by side, in --to order
  (quat: w x y z; matrix: m11 m12 ... m33 row-major; axis-angle: x y z angle),
  as a float64 array of shape (N, total columns) in .npy, or as CSV with a header
  line naming each column TARGET.COMPONENT (quat.w, matrix.m12, euler:ZYX.angle1)
  and numbers written as shortest round-trip repr. All arithmetic is float64.
  Errors name the row: 1-based data row (CSV: header, comments and blank lines are
  not counted; the file line number is given too; .npy: row i is index i - 1).
  On any error nothing is written and an existing OUT is left untouched.

exit status: 0 success; 2 bad arguments, malformed row, invalid rotation (e.g. a
  matrix that is not a rotation, a zero quaternion), unreadable or unwritable file.

examples:
  rigidkit convert euler:ZYX 30 20 10 --degrees --to quat matrix rotvec
  rigidkit convert quat 0.7071 0 0 0.7071 --to all --decimals 6
  rigidkit convert matrix 0 -1 0  1 0 0  0 0 1 --to euler:zyx --degrees
  rigidkit convert --from euler:ZYX -i angles.csv -o quats.npy --to quat --degrees
"""
)


def build_parser() -> argparse.ArgumentParser:
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
            "       %(prog)s --from REPR -i IN [-o OUT] --to TARGET ... [options]"
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
        help="representation of the input (required with --input)",
    )
    convert.add_argument(
        "--degrees", action="store_true", help="angles in and out are in degrees"
    )
    convert.add_argument(
        "--orthonormalize",
        action="store_true",
        help="matrix input: use the nearest rotation (SVD) instead of rejecting a matrix "
        "that is not a rotation within 1e-6 (e.g. one typed with few digits)",
    )
    convert.add_argument("-i", "--input", metavar="IN", help="batch input: .npy, .csv or -")
    convert.add_argument(
        "-o", "--output", metavar="OUT", help="batch output: .npy, .csv or - (default -)"
    )
    convert.add_argument(
        "--decimals",
        type=_nonnegative_int,
        metavar="N",
        help="one rotation: print N decimals instead of all round-trip digits",
    )
    convert.add_argument(
        "--format",
        choices=("table", "json"),
        default="table",
        help="one rotation: an aligned table (default) or JSON",
    )
    convert.set_defaults(func=_run_convert)
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


def _shield_negative_numbers(argv) -> list:
    """Prefix numbers like ``-30``, ``-1e-3``, ``-inf`` with a space.

    argparse takes any word starting with ``-`` for an option unless it matches
    its narrow negative-number pattern (``-1e-3`` and ``-inf`` do not). A word
    that does not start with ``-`` is always positional, and ``float`` and
    ``int`` ignore the leading space.
    """
    out = []
    for k, arg in enumerate(argv):
        if arg == "--":
            return out + list(argv[k:])
        out.append(" " + arg if arg.startswith("-") and _is_number(arg) else arg)
    return out


def main(argv=None) -> int:
    """Run the ``rigidkit`` command line with ``argv`` (default ``sys.argv[1:]``).

    Returns the exit status (0 success, 2 user error); the console script and
    ``python -m rigidkit`` pass it to :func:`sys.exit`.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser()
    try:
        args = parser.parse_args(_shield_negative_numbers(argv))
    except SystemExit as exc:  # --help, --version, or a usage error (already printed)
        return exc.code if isinstance(exc.code, int) else 2
    if args.command is None:
        parser.print_help(sys.stderr)
        return 2
    try:
        return args.func(args)
    except (CLIError, RigidkitError) as exc:
        print(f"{PROG}: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # a temporary output file is already removed
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): not an error of ours. Point stdout at
        # devnull so that the interpreter's final flush does not fail again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
