"""Reading a batch of rotations from a ``.npy`` or ``.csv`` file (or stdin).

Each reader returns ``(values, where)``: a float64 array of shape (N, k) in the
representation's column order, and ``where(i)``, the description of 0-based row
``i`` for messages (``in.csv line 6 (data row 3)``, ``in.npy row 4 (index 3)``).

CSV files guess nothing that the data does not show: the delimiter is the one of
``,``, ``;``, tab and spaces (preferred in that order) that splits most of the
first lines into the representation's number of fields; the first line is a
header only when none of its fields is a number (quoted or not); a header naming
the components (``qx,qy,qz,qw``, ``roll,pitch,yaw``) sets the column order or,
when it names other components, is an error; every data line yields one row, or
the run fails.
"""

from __future__ import annotations

import csv
import os
import sys
import warnings

import numpy as np

from .convert import one_line, warn
from .headers import accepted, header_order
from .representations import CLIError, is_number

__all__ = ["kind_of", "os_text", "read_csv", "read_npy"]

# The delimiters tried, in order of preference; None: runs of spaces or tabs (as
# numpy's savetxt writes), without quoting.
_DELIMITERS = {",": "','", ";": "';'", "\t": "tab", None: "spaces"}
_SAMPLE = 20  # lines looked at to choose the delimiter


def os_text(exc: Exception) -> str:
    """The reason of an I/O error without the (possibly temporary) file name."""
    return one_line(getattr(exc, "strerror", None) or exc)


def kind_of(path: str, what: str) -> str:
    """``"npy"``, ``"csv"`` or ``"txt"`` from a file's extension (``-`` is CSV).

    ``.txt`` is read as CSV (whitespace-separated columns are detected, as in TUM
    and KITTI logs) and written with the numbers separated by spaces.
    """
    if path == "-":
        return "csv"
    ext = os.path.splitext(path)[1].lower()
    if ext in (".npy", ".csv", ".txt"):
        return ext[1:]
    raise CLIError(
        f"cannot tell the format of {what} {path!r} from its extension; "
        "use a .npy, .csv or .txt file (or - for CSV on stdin/stdout)"
    )


# -- .npy ------------------------------------------------------------------------------


def _npy_dtype(path: str):
    """The dtype in a ``.npy`` header, read before the data.

    Knowing it first gives "not a numeric array" for object arrays instead of
    numpy's advice about ``allow_pickle`` (which would run code from the file).
    Returns None for a header version this numpy reads only through ``load``.
    """
    fmt = np.lib.format
    with open(path, "rb") as f:
        if f.read(len(fmt.MAGIC_PREFIX)) != fmt.MAGIC_PREFIX:
            raise CLIError(f"{path!r} is not a .npy file (it has no NumPy header)")
        f.seek(0)
        version = fmt.read_magic(f)
        readers = {(1, 0): fmt.read_array_header_1_0, (2, 0): fmt.read_array_header_2_0}
        if version not in readers:
            return None
        return readers[version](f)[2]


def read_npy(path: str, source):
    """``(values, where)`` of ``path``: shape (N, k), or (N, 3, 3) for matrices."""
    try:
        dtype = _npy_dtype(path)
        if dtype is not None and dtype.kind not in "fiu":
            raise CLIError(_not_numeric(path, dtype))
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise CLIError(f"cannot read {path!r}: {os_text(exc)}") from None
    if data.dtype.kind not in "fiu":
        raise CLIError(_not_numeric(path, data.dtype))
    if source.kind == "matrix" and data.ndim == 3 and data.shape[1:] == (3, 3):
        data = data.reshape(len(data), 9)
    if data.ndim != 2 or data.shape[1] != source.size:
        alt = " or (N, 3, 3)" if source.kind == "matrix" else ""
        raise CLIError(
            f"{path!r}: {source.name} needs an array of shape (N, {source.size}){alt} "
            f"({', '.join(source.columns)} per row), got shape {data.shape}"
        )

    def where(i):
        return f"{path} row {i + 1} (index {i})"

    return np.ascontiguousarray(data, dtype=np.float64), where


def _not_numeric(path: str, dtype) -> str:
    held = "Python objects" if dtype.hasobject else f"dtype {dtype}"
    return (
        f"{path!r} is not a numeric array (it holds {held}); "
        "expected an array of real numbers"
    )


# -- .csv ------------------------------------------------------------------------------


def _is_skipped(line: str) -> bool:
    """Blank lines and ``#`` comment lines carry no data."""
    s = line.strip()
    return not s or s.startswith("#")


def _fields(line: str, delimiter) -> list:
    """The fields of one line, quotes removed, a trailing ``# comment`` dropped."""
    text = line.partition("#")[0]
    if delimiter is None:
        return text.split()
    return next(csv.reader([text], delimiter=delimiter), [""])


def _choose_delimiter(sample, size: int):
    """The delimiter that splits most ``sample`` lines into ``size`` fields.

    Ties go to the comma; with no such delimiter, the one giving the most fields
    on the first line (so that the error names a field count that makes sense).
    """
    scores = {d: sum(len(_fields(line, d)) == size for line in sample) for d in _DELIMITERS}
    best = max(scores, key=scores.get)  # max keeps the first of equal scores
    if scores[best]:
        return best
    return max(_DELIMITERS, key=lambda d: len(_fields(sample[0], d)))


def read_csv(path: str, source):
    """``(values, where)`` of the CSV file ``path`` (``-``: stdin); see the module."""
    name = "<stdin>" if path == "-" else path
    try:
        if path == "-":
            text = sys.stdin.read()
        else:
            with open(path, encoding="utf-8") as f:
                text = f.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise CLIError(f"cannot read {name!r}: {os_text(exc)}") from None
    lines = text.removeprefix("\ufeff").splitlines()  # Excel's byte-order mark
    # File line numbers (1-based) of the data rows.
    numbers = [n for n, line in enumerate(lines, start=1) if not _is_skipped(line)]
    if not numbers:
        return np.empty((0, source.size)), _where(name, numbers)
    sample = [lines[n - 1] for n in numbers[:_SAMPLE]]
    delimiter = _choose_delimiter(sample, source.size)
    first = _fields(sample[0], delimiter)
    order = None
    # A header has no number in any field: "10 20 30" read with commas is one
    # field, but no header.
    if not any(is_number(word) for field in first for word in field.split()):
        try:
            order = header_order(source, first)
        except CLIError as exc:
            raise CLIError(f"{name} line {numbers[0]}: {exc}") from None
        if order is None:  # said, not skipped silently: the order is a guess
            names = ", ".join(f.strip().strip('"').strip() for f in first)
            warn(
                f"{name} line {numbers[0]}: the header ({names}) names none of the "
                f"components of {source.name} ({accepted(source)}); its columns are "
                f"read in the order {', '.join(source.columns)}"
            )
        start = numbers.pop(0)  # the header line
    else:
        start = numbers[0] - 1
    where = _where(name, numbers)
    if not numbers:
        return np.empty((0, source.size)), where
    try:
        # The fast path: numpy's C parser. It says little about what went wrong, so
        # a failure is diagnosed by the slow scan below.
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
            data = np.loadtxt(
                lines[start:],
                delimiter=delimiter,
                quotechar=None if delimiter is None else '"',
                ndmin=2,
                dtype=np.float64,
            )
    except ValueError as exc:
        _diagnose(name, lines, numbers, delimiter, source, where, exc)
    if data.shape[1] != source.size:
        _diagnose(name, lines, numbers, delimiter, source, where, None)
    if len(data) != len(numbers):  # never drop a row silently
        raise CLIError(
            f"{name}: read {len(data)} rows from {len(numbers)} data lines; "
            "nothing was converted"
        )
    return (data if order is None else data[:, order]), where


def _where(name: str, numbers):
    def where(i):
        return f"{name} line {numbers[i]} (data row {i + 1})"

    return where


def _diagnose(name, lines, numbers, delimiter, source, where, exc):
    """Raise a :class:`CLIError` for the first malformed data line."""
    for row, n in enumerate(numbers):
        fields = _fields(lines[n - 1], delimiter)
        if len(fields) != source.size:
            sep = (
                "separated by ',', ';', tab or spaces"
                if len(fields) == 1
                else f"separated by {_DELIMITERS[delimiter]}"
            )
            raise CLIError(
                f"{where(row)}: {source.name} needs {source.size} fields "
                f"({', '.join(source.columns)}), got {len(fields)} ({sep})"
            )
        for k, field in enumerate(fields):
            if not is_number(field):
                hint = " (a decimal comma? write 1.5, not 1,5)" if "," in field else ""
                raise CLIError(
                    f"{where(row)}: field {k + 1} is {field.strip()!r}, not a number{hint}"
                )
    reason = f": {one_line(exc)}" if exc is not None else ""
    raise CLIError(f"cannot parse {name!r} as CSV{reason}")
