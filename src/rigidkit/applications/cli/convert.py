"""Converting the numbers read into the numbers to write, errors located by row.

A batch error is placed on its input row from the failing batch index that
rigidkit's errors carry (``err.index``), never from the wording of the message;
an error or warning without an index is located by bisection over the rows.
"""

from __future__ import annotations

import math
import re
import sys
import warnings

import numpy as np

from ..._validate import where_text
from ...errors import GimbalLockWarning, RigidkitError
from .representations import CLIError

__all__ = ["PROG", "check_finite", "convert", "one_line", "warn", "warn_if_degrees"]

PROG = "rigidkit"


def one_line(text) -> str:
    return " ".join(str(text).split())


def warn(text: str) -> None:
    print(f"{PROG}: warning: {one_line(text)}", file=sys.stderr)


def convert(source, values, targets, degrees, *, orthonormalize=False, where=None):
    """Convert ``values`` (..., source.size) into a list of target arrays.

    For a batch (``where`` given, mapping a 0-based row to its description), an
    error or warning is reported at the input row it concerns. Gimbal-lock
    warnings go to stderr as one line each (the angles returned still rebuild
    the rotation).
    """

    def attempt(rows):
        rotation = source.rotation_from(rows, degrees, orthonormalize)
        return [t.values_of(rotation, degrees) for t in targets]

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GimbalLockWarning)
        try:
            outputs = attempt(values)
        except RigidkitError as exc:
            raise CLIError(_error_text(exc, attempt, values, where)) from None
    shown = set()
    for w in caught:
        if not issubclass(w.category, GimbalLockWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            continue
        text = str(w.message)
        if where is not None:
            row = _row_of(w.message) if hasattr(w.message, "index") else None
            if row is None:
                row = _first_row(lambda n: _warns(attempt, values[:n]), len(values))
            text = f"{where(row)}: {_without_index(text, row)}"
        text = in_rows(text)
        if text not in shown:
            shown.add(text)
            warn(text)
    return outputs


def in_rows(text: str) -> str:
    """A gimbal-lock warning in command-line words: rows, not batch elements.

    >>> in_rows("Gimbal lock in 'XYZ': 2 of 5 middle angles are within 1e-08 rad of "
    ...         "+-pi/2 (first); there ...")[22:]
    '2 of 5 rows have their middle angle within 1e-08 rad of +-pi/2; there ...'
    """
    text = text.replace(" (first in the (single) input)", "").replace(" (first)", "")

    def words(m):
        count, total = int(m[1]), int(m[2])
        if total == 1:
            return "the middle angle is within"
        rows = "rows has its" if count == 1 else "rows have their"
        return f"{count} of {total} {rows} middle angle within"

    return re.sub(r"(\d+) of (\d+) middle angles are within", words, text)


def _error_text(exc: RigidkitError, attempt, values, where) -> str:
    # The library's advice, in command-line words.
    text = str(exc).replace("pass orthonormalize=True", "pass --orthonormalize")
    if where is None:
        return text
    row = _row_of(exc)
    if row is None:
        row = _first_row(lambda n: _fails(attempt, values[:n]), len(values))
    return f"{where(row)}: {_without_index(text, row)}"


def _row_of(err) -> int | None:
    """The input row of a batch error or warning, from its ``index`` attribute."""
    index = getattr(err, "index", None)
    if index is None or len(index) != 1:  # a batch of rows has one batch axis
        return None
    return int(index[0])


def _without_index(text: str, row: int) -> str:
    """``text`` without the library's own "at batch index (row,)": the row leads."""
    return text.replace(" " + where_text((row,)), "")


def _first_row(fails, n: int) -> int:
    """The first ``k`` such that ``fails(k + 1)``, by bisection over prefix lengths.

    ``fails(m)`` says whether the first ``m`` rows show the problem, which ``fails(n)``
    does. Costs about log2(n) conversions of prefixes of the batch; only used when
    the library gives no batch index.
    """
    good, bad = 0, n  # the first `good` rows are fine; the first `bad` are not
    while bad - good > 1:
        mid = (good + bad) // 2
        if fails(mid):
            bad = mid
        else:
            good = mid
    return good


def _fails(attempt, rows) -> bool:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", GimbalLockWarning)
            attempt(rows)
    except RigidkitError:
        return True
    return False


def _warns(attempt, rows) -> bool:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GimbalLockWarning)
        attempt(rows)
    return any(issubclass(w.category, GimbalLockWarning) for w in caught)


def check_finite(values, where) -> None:
    """Reject NaN and infinity in the input rows before any conversion."""
    finite = np.isfinite(values)
    if finite.all():
        return
    row, col = np.argwhere(~finite)[0]
    raise CLIError(
        f"{where(int(row))}: field {col + 1} is {float(values[row, col])!r}; "
        "every number must be finite"
    )


def warn_if_degrees(source, values, degrees: bool, where=None) -> None:
    """Warn when angles read as radians exceed 2 pi: they are likely degrees.

    A whole turn or more is legal but rare in these representations, while a
    forgotten ``--degrees`` (``euler:ZYX 30 20 10``) is common and silently gives
    a different rotation.
    """
    if degrees:
        return
    angles = source.angles(values)
    if angles is None:
        return
    big = angles > 2 * math.pi
    if not np.any(big):
        return
    what = {"rotvec": "rotation vector length", "axis-angle": "angle"}.get(
        source.kind, "Euler angle"
    )
    first = int(np.argmax(big))
    at, more = "", ""
    if where is not None:
        at = f"{where(first)}: "
        count = int(np.count_nonzero(big))
        more = f" (and in {count - 1} more rows)" if count > 1 else ""
    warn(
        f"{at}{source.name} {what} {float(np.ravel(angles)[first]):.6g} exceeds 2*pi"
        f"{more}; the numbers are read as radians but look like degrees (pass "
        "--degrees if they are)"
    )
