"""Writing a converted batch: CSV (to a file or stdout) or ``.npy``, atomically.

A batch output file is written to a temporary file in the same directory and
renamed over the target only once everything has succeeded, so a failed run
leaves no partial file and never clobbers an existing one.
"""

from __future__ import annotations

import contextlib
import os
import tempfile

import numpy as np

from .reading import os_text
from .representations import CLIError

__all__ = ["column_names", "rounded", "write_atomically", "write_csv", "write_npy"]


def column_names(targets) -> list:
    """``TARGET.COMPONENT`` for each output column (``quat.w``, ``matrix.m12``)."""
    return [f"{t.name}.{c}" for t in targets for c in t.columns]


def rounded(table, decimals=None):
    """``table`` rounded to ``decimals`` (None: as is), with no negative zero.

    ``-0.0`` (and anything that rounds to it, ``-1e-17`` at 6 decimals) becomes
    ``0.0``: adding ``+0.0`` turns a negative zero positive and changes no other
    float.

    >>> rounded(np.array([-0.0, -1e-17, 0.123456789]), 3).tolist()
    [0.0, 0.0, 0.123]
    """
    table = np.asarray(table, dtype=np.float64)
    if decimals is not None:
        table = np.round(table, decimals)
    return table + 0.0


def write_csv(stream, header, table, *, decimals=None, separator=",") -> None:
    """CSV with a header line; numbers as shortest round-trip ``repr``, or with
    ``decimals`` decimals. ``separator=" "`` writes a whitespace-separated text
    file whose header is a ``#`` comment (as TUM logs have)."""
    if separator == ",":
        stream.write(",".join(header) + "\n")
    else:
        stream.write("# " + separator.join(header) + "\n")
    if table.shape[0] == 0:
        return
    table = rounded(table, decimals)
    # One format string per block of rows: far fewer Python calls than a loop
    # over rows (np.savetxt), and repr of each float64 reads back exactly.
    block = 4096
    ncol = table.shape[1]
    cell = "%r" if decimals is None else f"%.{decimals}f"
    row_fmt = separator.join([cell] * ncol) + "\n"
    full = row_fmt * block
    for start in range(0, table.shape[0], block):
        chunk = table[start : start + block]
        fmt = full if len(chunk) == block else row_fmt * len(chunk)
        stream.write(fmt % tuple(chunk.ravel().tolist()))


def write_npy(stream, table, *, decimals=None) -> None:
    np.save(stream, rounded(table, decimals))


def write_atomically(path: str, write_to, *, binary: bool) -> None:
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
        raise CLIError(f"cannot write {path!r}: {os_text(exc)}") from None
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
            raise CLIError(f"cannot write {path!r}: {os_text(exc)}") from None
        raise


def _new_file_mode(path: str) -> int:
    """Keep an existing file's permissions; otherwise what ``open`` would give."""
    try:
        return os.stat(path).st_mode & 0o777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask
