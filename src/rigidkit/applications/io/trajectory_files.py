"""Reading and writing trajectories: TUM, KITTI, EuRoC and headed CSV.

Formats (one pose per line; blank lines and lines starting with ``#`` are
skipped):

- ``"tum"``: ``t x y z qx qy qz qw`` separated by spaces (Sturm et al. 2012);
  the quaternion is scalar last.
- ``"kitti"``: the 12 numbers of the 3x4 matrix ``[R | t]``, row-major
  (Geiger et al. 2012); no stamps (``stamps=`` gives them: an array or the
  path of a file with one time per line, as the KITTI odometry ``times.txt``).
- ``"euroc"``: the ASL ground-truth CSV: ``timestamp [ns], p_x, p_y, p_z, q_w,
  q_x, q_y, q_z`` then any further columns (ignored).
- ``"csv"``: comma (or semicolon, tab) separated, with a header line naming the
  columns: a time (``t``, ``time``, ``timestamp``, ``stamp``; nanoseconds when
  the name says ``ns``), the position (``x, y, z``; ``tx``, ``p_x``,
  ``pos_x``, ``position.x``) and the quaternion (``qw, qx, qy, qz``, ``q_w``,
  ``quat_x``, ``orientation.w``) in any order; other columns are ignored.

Every reader checks the whole file before it returns anything: a malformed line
raises :class:`~rigidkit.TrajectoryFileError` naming the file, the 1-based line
and what is wrong (a field that is not a number, a wrong number of fields, a
quaternion of zero norm, a matrix that is not a rotation, a stamp that repeats
or goes backwards).
"""

from __future__ import annotations

import os
import warnings

import numpy as np

from ...errors import TimestampError, TrajectoryFileError, ZeroNormError
from ...objects.transform import Transform
from ..trajectory.trajectory import Trajectory, check_stamps
from ._csv_header import column_of, csv_delimiter
from ._parse import parse_table

__all__ = ["FORMATS", "KITTI_ATOL", "read_trajectory", "write_trajectory"]

FORMATS = ("tum", "kitti", "euroc", "csv")
# KITTI files hold 6-7 significant digits ("%e"), so R^T R misses I by ~1e-6; a
# matrix further than this from a rotation is an error, a nearer one is replaced
# by its nearest rotation (SVD).
KITTI_ATOL = 1e-4
_TUM_HEADER = "# timestamp tx ty tz qx qy qz qw"
_EUROC_HEADER = (
    "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],"
    "q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []"
)


def _fail(path, line, message, row=None):
    where = f"{path} line {line}" if line is not None else str(path)
    raise TrajectoryFileError(
        f"{where}: {message}",
        path=str(path),
        line=line,
        index=None if row is None else (row,),
    )


def _is_skipped(line: str) -> bool:
    s = line.strip()
    return not s or s.startswith("#")


def _split(line: str, delimiter):
    text = line.split("#", 1)[0] if delimiter is None else line
    return text.split() if delimiter is None else [f.strip() for f in text.split(delimiter)]


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


class _Text:
    """A file's bytes; its text and lines are decoded only where needed."""

    def __init__(self, path):
        self.path = os.fspath(path)
        try:
            with open(self.path, "rb") as f:
                data = f.read()
        except OSError as exc:
            reason = getattr(exc, "strerror", None) or exc
            raise TrajectoryFileError(
                f"cannot read {self.path!r}: {reason}", path=self.path
            ) from None
        self.data = data.removeprefix(b"\xef\xbb\xbf")  # a byte-order mark
        self._lines = None

    @property
    def head(self) -> str:
        """The first 64 KiB as text: enough to tell the format."""
        return self.data[:65536].decode("utf-8", "replace")

    def head_lines(self, where):
        """The first ``(number, line)`` of the head for which ``where(line)`` holds.

        The first 4 KiB (cut after their last whole line) are decoded first and
        the 64 KiB head only when they hold no such line: decoding and splitting
        the whole head cost a 21,000-line file a tenth of its reading.
        """
        for size in (4096, 65536):
            chunk = self.data[:size]
            if size < len(self.data):
                chunk = chunk[: chunk.rfind(b"\n") + 1]
            lines = chunk.decode("utf-8", "replace").splitlines()
            found = next(((n, x) for n, x in enumerate(lines, start=1) if where(x)), None)
            if found is not None or size >= len(self.data):
                return found
        return None

    @property
    def lines(self):
        if self._lines is None:
            self._lines = self.data.decode("utf-8", "replace").splitlines()
        return self._lines


def _table(src: _Text, delimiter, ncols: int, exact: bool, skip: int, what: str):
    """``(data, rows)``: the numbers (M, ncols) of the data lines after line ``skip``.

    ``rows()`` gives the 1-based line number of each data row. Lines with fewer
    fields (or, if ``exact``, more) or a field that is not a number raise
    :class:`TrajectoryFileError`.
    """
    offset = 0
    for _ in range(skip):
        offset = (
            src.data.index(b"\n", offset) + 1
            if b"\n" in src.data[offset:]
            else len(src.data)
        )
    data, lines, status, line, field = parse_table(
        src.data[offset:], ncols, exact, delimiter
    )
    lines += skip
    line += skip
    if status != "ok":
        sep = "spaces" if delimiter is None else repr(delimiter)
        row = len(data)
        if status == "count":
            _fail(
                src.path,
                line,
                f"{field} fields separated by {sep}, expected "
                f"{ncols if exact else f'at least {ncols}'} ({what})",
                row,
            )
        fields = _split(src.lines[line - 1], delimiter)
        token = fields[field - 1] if field <= len(fields) else ""
        what = f"{token!r}, not a number" if token else "empty"
        _fail(src.path, line, f"field {field} is {what}", row)
    return data, lambda: lines


def _check_finite(src, data, rows):
    if np.isfinite(data.sum()):  # no inf or nan (nor values summing past 1e308)
        return
    bad = ~np.isfinite(data).all(axis=1)
    if bad.any():
        row = int(np.argmax(bad))
        k = int(np.argmax(~np.isfinite(data[row])))
        value = float(data[row, k])
        _fail(src.path, rows()[row], f"field {k + 1} is {value!r}, not finite", row)


def _checked_stamps(src, stamps, rows):
    try:
        return check_stamps(stamps, len(stamps))
    except TimestampError as exc:
        row = exc.index[0]
        i = row - 1
        how = "repeats" if stamps[row] == stamps[i] else "goes backwards from"
        _fail(
            src.path,
            rows()[row],
            f"stamp {float(stamps[row])!r} {how} the previous line's {float(stamps[i])!r}; "
            "stamps must be strictly increasing",
            row,
        )


def _poses_from_pq(src, pq, scalar_first, rows):
    """Poses from rows ``(x, y, z)`` and a quaternion of any nonzero norm."""
    # The conversion checks the norms itself (no pass of its own over them
    # here) and names the first zero one's row.
    try:
        return Transform.from_pq(np.ascontiguousarray(pq), scalar_first=scalar_first)
    except ZeroNormError as exc:
        row = exc.index[0]
    _fail(src.path, rows()[row], "the quaternion has zero norm", row)


# -- the formats -----------------------------------------------------------------------


def _read_tum(src):
    data, rows = _table(src, None, 8, True, 0, "TUM: t x y z qx qy qz qw")
    _check_finite(src, data, rows)
    stamps = _checked_stamps(src, data[:, 0], rows)
    poses = _poses_from_pq(src, data[:, 1:], False, rows)
    return Trajectory._trusted(stamps, poses)


def _read_kitti(src, stamps, atol):
    data, rows = _table(src, None, 12, True, 0, "KITTI: a 3x4 matrix, row-major")
    _check_finite(src, data, rows)
    m = data.reshape(-1, 3, 4)
    R = m[:, :, :3]
    err = np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)).max(axis=(1, 2), initial=0)
    det = np.linalg.det(R) if len(R) else np.zeros(0)
    bad = ~((err <= atol) & (det > 0))
    if bad.any():
        row = int(np.argmax(bad))
        _fail(
            src.path,
            rows()[row],
            f"the 3x3 block is not a rotation (max |R^T R - I| = {err[row]:.3g}, det "
            f"{det[row]:.6g}; tolerance {atol:g})",
            row,
        )
    M = np.zeros((len(m), 4, 4))
    M[:, :3, :] = m
    M[:, 3, 3] = 1.0
    poses = Transform.from_matrix(M, orthonormalize=True)
    if stamps is not None:
        if isinstance(stamps, (str, os.PathLike)):
            times = _Text(stamps)
            t, trows = _table(times, None, 1, True, 0, "one time per line")
            _check_finite(times, t, trows)
            t = t[:, 0]
            if len(t) != len(m):
                _fail(times.path, None, f"{len(t)} times for {len(m)} poses in {src.path}")
            return Trajectory._trusted(_checked_stamps(times, t, trows), poses)
        return Trajectory(stamps, poses)
    return Trajectory._trusted(None, poses)


def _read_euroc(src):
    delimiter = "," if "," in src.head[:4096] else None
    data, rows = _table(
        src, delimiter, 8, False, 0, "EuRoC: t[ns] p_x p_y p_z q_w q_x q_y q_z"
    )
    _check_finite(src, data, rows)
    stamps = _checked_stamps(src, data[:, 0] / 1e9, rows)
    poses = _poses_from_pq(src, data[:, 1:8], True, rows)
    return Trajectory._trusted(stamps, poses)


def _read_csv(src):
    first = src.head_lines(str.strip)
    if first is None:
        _fail(src.path, None, "is empty; a CSV trajectory needs a header line")
    n, header = first
    delimiter = csv_delimiter(header)
    names = _split(header.lstrip("#") if header.startswith("#") else header, delimiter)
    if any(_is_number(x) for x in names):
        _fail(
            src.path,
            n,
            "a CSV trajectory needs a header naming its columns (t, x, y, z, qw, qx, "
            "qy, qz); this line holds numbers",
        )
    found = {}
    for k, name in enumerate(names):
        col = column_of(name)
        if col is None:
            continue
        key = "t" if col[0] == "t" else col
        if key in found:
            _fail(
                src.path,
                n,
                f"column {name.strip()!r} repeats {names[found[key]].strip()!r}",
            )
        found[key] = k
        if col[0] == "t":
            ns = col[1]
    need = [("p", a) for a in "xyz"] + [("q", c) for c in "wxyz"]
    missing = [
        f"{kind}{c}" if kind == "q" else c for kind, c in need if (kind, c) not in found
    ]
    if missing:
        _fail(
            src.path,
            n,
            f"the header ({', '.join(x.strip() for x in names)}) names no column for "
            f"{', '.join(missing)}; name the position x, y, z and the quaternion qw, "
            "qx, qy, qz",
        )
    data, rows = _table(src, delimiter, len(names), True, n, f"{len(names)} columns")
    _check_finite(src, data, rows)
    xyz = data[:, [found[k] for k in need[:3]]]
    wxyz = data[:, [found[k] for k in need[3:]]]
    stamps = None
    if "t" in found:
        t = data[:, found["t"]]
        stamps = _checked_stamps(src, t / 1e9 if ns else t, rows)
    pq = np.concatenate([xyz, wxyz], axis=1)
    return Trajectory._trusted(stamps, _poses_from_pq(src, pq, True, rows))


def _detect(src) -> str:
    first = src.head_lines(str.strip)
    if first is None:
        _fail(src.path, None, "is empty: no pose to read")
    n, line = first
    low = line.lower()
    if low.startswith("#"):
        if "," in low and "timestamp" in low and ("q_" in low or "qw" in low):
            return "euroc"
        data = src.head_lines(lambda x: not _is_skipped(x))
        if data is None:
            _fail(src.path, None, "holds no pose (only comments)")
        n, line = data
    if "," in line or ";" in line or "\t" in line.strip():
        fields = _split(line, csv_delimiter(line))
        if not all(_is_number(f) for f in fields):
            return "csv"
        if len(fields) >= 8 and abs(float(fields[0])) > 1e15:
            warnings.warn(
                f"{src.path}: read as EuRoC (comma-separated numbers without a header, "
                "nanosecond stamps); pass format= to choose",
                UserWarning,
                stacklevel=3,
            )
            return "euroc"
        _fail(
            src.path,
            n,
            f"cannot tell the format of {len(fields)} separated numbers without a "
            "header; pass format= or add a header naming the columns",
        )
    fields = line.split()
    if len(fields) == 8:
        return "tum"
    if len(fields) == 12:
        return "kitti"
    _fail(
        src.path,
        n,
        f"cannot tell the format: {len(fields)} fields (TUM has 8: t x y z qx qy qz "
        "qw; KITTI 12: a 3x4 matrix); pass format=",
    )


def read_trajectory(path, format=None, *, stamps=None, atol=KITTI_ATOL):
    """The trajectory in the file ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    format : {"tum", "kitti", "euroc", "csv"}, optional
        Detected from the content when omitted: an EuRoC header, a CSV header,
        8 numbers a line (TUM) or 12 (KITTI); a guess that the content does not
        settle (EuRoC numbers without the header) warns with the format chosen.
    stamps : array_like or str, optional
        KITTI only: the time of each pose, or the path of a file of one time
        per line (KITTI's ``times.txt``).
    atol : float
        KITTI only: the largest ``|R^T R - I|`` accepted; the rotation used is
        the nearest one.

    Returns
    -------
    Trajectory
        NumPy float64 poses, stamps in seconds (``None`` for KITTI without
        ``stamps``).

    Raises
    ------
    TrajectoryFileError
        The file cannot be read, or a line is malformed (naming the file, the
        1-based line and what is wrong); nothing is returned.

    Examples
    --------
    >>> import os, tempfile
    >>> import rigidkit as rk
    >>> path = os.path.join(tempfile.mkdtemp(), "gt.txt")
    >>> with open(path, "w") as f:
    ...     _ = f.write("# t x y z qx qy qz qw\\n0.0 1 2 3 0 0 0 1\\n0.1 1 2 4 0 0 0 1\\n")
    >>> traj = rk.io.read_trajectory(path)
    >>> traj.stamps, traj.positions[1]
    (array([0. , 0.1]), array([1., 2., 4.]))
    """
    src = _Text(path)
    fmt = _detect(src) if format is None else format
    if fmt not in FORMATS:
        raise ValueError(f"format must be one of {', '.join(FORMATS)}; got {format!r}")
    if stamps is not None and fmt != "kitti":
        raise ValueError(f"stamps= is for KITTI files (without stamps), not {fmt}")
    if fmt == "tum":
        return _read_tum(src)
    if fmt == "kitti":
        return _read_kitti(src, stamps, float(atol))
    if fmt == "euroc":
        return _read_euroc(src)
    return _read_csv(src)


def _rows(columns) -> str:
    table = np.column_stack(columns)
    fmt = " ".join(["%.17g"] * table.shape[1])
    return "".join(fmt % tuple(r) + "\n" for r in table.tolist())


def write_trajectory(path, trajectory, format="tum"):
    """Write ``trajectory`` to ``path`` in ``format`` (see :func:`read_trajectory`).

    Every number is written with 17 significant digits, so that reading the file
    back gives the same float64 values (the quaternion scalar-last for TUM,
    scalar-first for EuRoC and CSV; KITTI writes the matrix). EuRoC stamps are
    rounded to whole nanoseconds. The file is written whole or not at all
    (a temporary file is renamed).

    >>> import os, tempfile
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> traj = rk.Trajectory([0.0, 0.5], rk.Transform.random(2, rng=0))
    >>> path = os.path.join(tempfile.mkdtemp(), "est.txt")
    >>> rk.io.write_trajectory(path, traj, "tum")
    >>> back = rk.io.read_trajectory(path)
    >>> bool(np.array_equal(back.positions, traj.positions))
    True
    """
    if format not in FORMATS:
        raise ValueError(f"format must be one of {', '.join(FORMATS)}; got {format!r}")
    if not isinstance(trajectory, Trajectory):
        raise TypeError(f"expected a Trajectory, got {type(trajectory).__name__}")
    if len(trajectory.shape) != 1:
        raise ValueError("a file holds one trajectory (poses of shape (N,)), not a batch")
    pq = np.asarray(trajectory.poses.as_pq(), dtype=np.float64)  # x y z w qx qy qz
    t = trajectory.stamps
    if t is None and format in ("tum", "euroc"):
        raise TimestampError(f"{format} files need stamps; this trajectory has none")
    if format == "tum":
        text = _TUM_HEADER + "\n" + _rows([t, pq[:, :3], pq[:, 4:], pq[:, 3]])
    elif format == "kitti":
        m = np.asarray(trajectory.poses.as_matrix())[:, :3, :].reshape(-1, 12)
        text = _rows([m])
    elif format == "euroc":
        ns = np.round(t * 1e9).astype(np.int64)
        body = _rows([pq[:, :3], pq[:, 3:]]).replace(" ", ",").splitlines()
        text = (
            _EUROC_HEADER + "\n" + "".join(f"{a},{b}\n" for a, b in zip(ns.tolist(), body))
        )
    else:
        names = ["x", "y", "z", "qw", "qx", "qy", "qz"]
        cols = [pq[:, :3], pq[:, 3:]]
        if t is not None:
            names, cols = ["t", *names], [t, *cols]
        text = ",".join(names) + "\n" + _rows(cols).replace(" ", ",")
    directory = os.path.dirname(os.path.abspath(os.fspath(path)))
    tmp = os.path.join(directory, f".{os.path.basename(os.fspath(path))}.part")
    try:
        with open(tmp, "w", encoding="ascii", newline="\n") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
