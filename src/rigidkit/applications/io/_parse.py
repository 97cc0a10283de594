"""A one-pass parser of numeric text tables, compiled with numba.

``np.loadtxt`` costs ~0.5 us a line of a TUM file (0.5 s for a million poses)
and keeps no line numbers; this loop reads the bytes once, in about a third of
that CPU time, and records the file line of every row, so that a later check (a
zero quaternion, a stamp going backwards) names its line without a second pass.

Numbers are converted exactly: a decimal with at most 18 significant digits whose
integer mantissa ``m`` is below 2^53 and whose power of ten ``e`` has ``|e| <=
22`` is ``m * 10^e`` or ``m / 10^-e``, one correctly rounded operation on two
exact doubles (Clinger 1990, "How to read floating point numbers accurately",
the fast path). Every other token (more digits, larger exponents, ``inf``,
``nan``) is marked, and Python's ``float`` (correctly rounded) converts it
afterwards: the result equals ``float(token)`` for every token.
"""

from __future__ import annotations

import numpy as np

from ..._engine import (
    compile_host_loop,
    idle_workers,
    in_background,
    numba_available,
    run_split,
)

__all__ = ["parse_table"]

# Status codes of the loop.
OK, BAD_COUNT, BAD_TOKEN = 0, 1, 2
# From this many bytes a file is parsed in parts, one per idle core (a part
# starts a thread and its values are copied once more, ~0.1 ms a megabyte).
PARALLEL_MIN = 1 << 20

_POW10 = np.array([10.0**k for k in range(23)])
_JOB = None


def _loop(buf, ncols, exact, delim, pow10, out, lines, slow):
    """Parse ``buf`` (uint8) into ``out`` (rows, ncols); see :func:`parse_table`.

    One pass over the bytes. ``delim`` is 0 for runs of spaces and tabs, else
    the byte of the delimiter (blanks around a field are then ignored). Returns
    ``(status, rows, line, field, nslow)``: on an error the 1-based line, and
    the 1-based field (a bad token) or the count of fields (a wrong count).
    """
    n = buf.shape[0]
    pos = 0
    line = 1
    row = 0
    col = 0
    nslow = 0
    comment = False
    after_delim = False  # a delimiter was read: a field must follow
    while pos <= n:
        c = 10 if pos == n else buf[pos]
        if c == 10:
            if after_delim:
                return BAD_TOKEN, row, line, col + 1, nslow
            if col > 0:
                if col < ncols or (exact and col != ncols):
                    return BAD_COUNT, row, line, col, nslow
                lines[row] = line
                row += 1
                col = 0
            line += 1
            comment = False
            pos += 1
            continue
        if comment or c == 32 or c == 9 or c == 13:
            pos += 1
            continue
        if c == 35:  # '#': the rest of the line is a comment
            if after_delim:
                return BAD_TOKEN, row, line, col + 1, nslow
            comment = True
            pos += 1
            continue
        if delim != 0:
            if c == delim:
                if after_delim or col == 0:  # an empty field
                    return BAD_TOKEN, row, line, col + 1, nslow
                after_delim = True
                pos += 1
                continue
            if col > 0 and not after_delim:  # two fields without a delimiter
                return BAD_TOKEN, row, line, col + 1, nslow
            after_delim = False
        # A token: [+-]digits[.digits][(e|E)[+-]digits].
        start = pos
        neg = False
        if c == 43 or c == 45:
            neg = c == 45
            pos += 1
        # The fast scan: every digit into mant (exact while there are at most
        # 18 of them: mant < 10^18 < 2^63), with at most one point among them;
        # more digits are scanned again below.
        first = pos
        mant = 0
        point = -1  # where the fraction's digits begin, once a point is read
        while pos < n:
            d = np.int64(buf[pos]) - 48
            if d >= 0 and d <= 9:
                mant = mant * 10 + d
            elif d == -2 and point < 0:  # '.'
                point = pos + 1
            else:
                break
            pos += 1
        frac = 0 if point < 0 else pos - point
        seen = pos - first - (0 if point < 0 else 1)
        drop = 0
        inexact = False
        if seen > 18:
            # The careful scan of the same digits: the first 18 significant ones
            # into mant, the rest counted (the integer part's) or checked to be
            # zeros.
            mant = 0
            ndig = 0
            frac = 0
            fstart = pos if point < 0 else point
            for k in range(first, pos):
                d = np.int64(buf[k]) - 48
                if d == -2:  # the point
                    continue
                if ndig < 18:
                    if mant > 0 or d != 0:
                        ndig += 1
                    mant = mant * 10 + d
                    if k >= fstart:
                        frac += 1
                elif k < fstart:  # a digit of the integer part
                    drop += 1
                    inexact = True
                elif d != 0:
                    inexact = True
        exp = 0
        good = seen > 0
        if good and pos < n and (buf[pos] == 101 or buf[pos] == 69):
            pos += 1
            eneg = False
            if pos < n and (buf[pos] == 43 or buf[pos] == 45):
                eneg = buf[pos] == 45
                pos += 1
            edig = 0
            while pos < n:
                d = np.int64(buf[pos]) - 48
                if d < 0 or d > 9:
                    break
                if exp < 100000:
                    exp = exp * 10 + d
                edig += 1
                pos += 1
            good = edig > 0
            if eneg:
                exp = -exp
        # The token ends at a blank, the delimiter, a comment or the line end;
        # anything else makes it a token for Python to judge.
        if pos < n:
            c = buf[pos]
            if not (c == 32 or c == 9 or c == 10 or c == 13 or c == 35 or c == delim):
                good = False
                while pos < n:
                    c = buf[pos]
                    if c == 32 or c == 9 or c == 10 or c == 13 or c == 35 or c == delim:
                        break
                    pos += 1
        if col < ncols:
            e10 = exp - frac + drop
            # Trailing zeros of the mantissa move into the exponent (exactly).
            while mant >= 9007199254740992 and mant % 10 == 0:
                mant //= 10
                e10 += 1
            if good and not inexact and mant < 9007199254740992 and -22 <= e10 <= 22:
                v = float(mant)
                if e10 >= 0:
                    v = v * pow10[e10]
                else:
                    v = v / pow10[-e10]
                out[row, col] = -v if neg else v
            else:
                out[row, col] = 0.0
                if nslow < slow.shape[0]:
                    slow[nslow, 0] = row
                    slow[nslow, 1] = col
                    slow[nslow, 2] = start
                    slow[nslow, 3] = pos
                    slow[nslow, 4] = line
                nslow += 1
        col += 1
    return OK, row, line, 0, nslow


def _build():
    """The compiled loop (on the engine's background thread)."""
    return compile_host_loop(
        _loop,
        ("r1:uint8", "int", "bool", "int", "r1", "w2", "w1:int64", "w2:int64"),
        dtypes=("float64",),
        returns=("int", "int", "int", "int", "int"),
        nogil=True,  # a large file's parts parse at once on idle cores
    )


def _job():
    """The loop's build, queued on first use; None without numba."""
    global _JOB
    if _JOB is None and numba_available():
        _JOB = in_background("rigidkit.io text tables", _build)
    return _JOB


def loop_ready() -> bool:
    """Whether the compiled loop is ready (asking starts its build)."""
    job = _job()
    return job is not None and job.done.is_set() and job.error is None


def parse_table(data: bytes, ncols: int, exact: bool, delimiter, engine="auto"):
    """Parse ``data`` into ``(values, lines, status, line, field)``.

    ``values`` (rows, ncols) float64 and ``lines`` (rows,) the 1-based file
    line of each row, for the rows read before any error; ``status`` is
    ``"ok"``, ``"count"`` (the line ``line`` has ``field`` fields) or ``"token"``
    (field ``field`` of line ``line`` is not a number). Lines that are blank or
    start with ``#`` are skipped, and ``#`` ends a line's data. Only the first
    ``ncols`` fields are read; with ``exact`` a line must have exactly that many.
    ``delimiter``: ``None`` for runs of spaces and tabs, else one character.
    ``engine``: ``"numba"`` (this module's loop, waiting for its build),
    ``"numpy"`` (``np.loadtxt``; a failure is diagnosed by the loop, or by a
    line-by-line scan without numba) or ``"auto"``: the loop once the engine's
    background thread has built it (the first use queues the build: loading
    numba costs a process ~1 s, more than ``np.loadtxt`` spends on a
    million lines), ``np.loadtxt`` until then. All give the same values.
    """
    if engine == "auto":
        engine = "numba" if loop_ready() else "numpy"
    if engine == "numpy":
        parsed = _parse_numpy(data, ncols, exact, delimiter)
        if parsed is not None:
            return parsed
        if _job() is None:
            return _parse_python(data, ncols, exact, delimiter)
    job = _job()
    if job is None:
        return _parse_python(data, ncols, exact, delimiter)
    loop = job.result()
    buf = np.frombuffer(data, dtype=np.uint8)
    delim = 0 if delimiter is None else ord(delimiter)
    parts = _parts(data, idle_workers() if len(data) >= PARALLEL_MIN else 1)
    done = run_split(
        lambda k, _: _parse_part(loop, buf[slice(*parts[k])], ncols, exact, delim),
        len(parts),
        len(parts),
        lambda start, stop: (start, stop),
    )
    # The parts' rows, lines and slow tokens in the whole file's numbering, up to
    # the first part that stops at an error.
    outs, numbers, slows = [], [], []
    row0 = newlines = prev = 0
    status, line, field = OK, 0, 0
    for (start, _), result in zip(parts, done):
        status, nrows, line, field, part_out, part_lines, slow = result
        newlines += data.count(b"\n", prev, start)  # the lines before the part
        prev = start
        outs.append(part_out[:nrows])
        numbers.append(part_lines[:nrows] + newlines)
        slow[:, 0] += row0
        slow[:, 2:4] += start
        slow[:, 4] += newlines
        slows.append(slow)
        row0 += nrows
        line += newlines
        if status != OK:
            break
    out = outs[0] if len(outs) == 1 else np.concatenate(outs)
    lines = numbers[0] if len(numbers) == 1 else np.concatenate(numbers)
    slow = slows[0] if len(slows) == 1 else np.concatenate(slows)
    if len(slow):
        bad = _convert_slow(buf, data, slow, out)
        if bad is not None:
            r, c, ln = bad
            if status == OK or ln < line or (ln == line and c + 1 < field):
                return out[:r], lines[:r], "token", ln, c + 1
    if status != OK:
        kind = "count" if status == BAD_COUNT else "token"
        return out, lines, kind, line, field
    return out, lines, "ok", 0, 0


def _parts(data, workers):
    """``workers`` byte ranges ``(start, stop)`` of ``data`` that begin at line
    starts (a line is never split), fewer where lines are long."""
    cuts = [0]
    for k in range(1, workers):
        at = data.find(b"\n", len(data) * k // workers)
        at = len(data) if at < 0 else at + 1
        if cuts[-1] < at < len(data):
            cuts.append(at)
    cuts.append(len(data))
    return list(zip(cuts[:-1], cuts[1:]))


def _parse_part(loop, buf, ncols, exact, delim):
    """The compiled loop on the bytes ``buf``: ``(status, rows, line, field,
    values, lines, slow)``, lines and positions counted from the part's start."""
    # A row takes at least 2 ncols bytes ("1 2 3\n"): a bound on the rows that
    # costs no pass over the data (np.empty's untouched pages cost nothing).
    rows = (len(buf) + 1) // (2 * ncols) + 1
    out = np.empty((rows, ncols))
    lines = np.empty(rows, dtype=np.int64)
    # Tokens off the fast path are rare in files written with up to 16 digits; a
    # file full of them (17-digit round-trip output) is parsed twice.
    slow = np.empty((min(rows * ncols, max(4096, rows * ncols // 16)), 5), dtype=np.int64)
    while True:
        status, nrows, line, field, nslow = loop(
            buf, ncols, exact, delim, _POW10, out, lines, slow
        )
        if nslow <= len(slow):
            return status, nrows, line, field, out, lines, slow[:nslow]
        slow = np.empty((nslow, 5), dtype=np.int64)


def _convert_slow(buf, data, slow, out):
    """Convert the tokens off the fast path into ``out``; the first that is not a
    number as ``(row, col, line)``, else None.

    NumPy's cast of byte strings to float64 (correctly rounded, as ``float``)
    converts them all at once; a token it rejects is looked for one by one.
    """
    start, end = slow[:, 2], slow[:, 3]
    width = int((end - start).max())
    if 0 < width <= 64:
        k = np.arange(width)
        idx = np.minimum(start[:, None] + k, len(buf) - 1)
        chars = np.where(k < (end - start)[:, None], buf[idx], 0).astype(np.uint8)
        try:
            values = np.ascontiguousarray(chars).view(f"S{width}")[:, 0].astype(np.float64)
        except ValueError:
            pass
        else:
            out[slow[:, 0], slow[:, 1]] = values
            return None
    for r, c, a, b, ln in slow.tolist():
        try:
            out[r, c] = float(data[a:b].decode("utf-8", "replace"))
        except ValueError:
            return r, c, ln
    return None


def _parse_numpy(data, ncols, exact, delimiter):
    """:func:`parse_table` by ``np.loadtxt``; None where it fails (then the loop
    finds what is wrong)."""
    import warnings

    lines = data.decode("utf-8", "replace").splitlines()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
            values = np.loadtxt(
                lines,
                delimiter=delimiter,
                comments="#",
                ndmin=2,
                dtype=np.float64,
                usecols=None if exact else range(ncols),
            )
    except ValueError:
        return None
    numbers = np.array(
        [n for n, line in enumerate(lines, start=1) if line.strip()[:1] not in ("", "#")],
        dtype=np.int64,
    )
    if values.size == 0:
        values = np.zeros((0, ncols))
    if values.shape != (len(numbers), ncols):
        return None
    return values, numbers, "ok", 0, 0


def _parse_python(data, ncols, exact, delimiter):
    """:func:`parse_table` line by line in Python (without numba): the same rules."""
    values, numbers = [], []
    for n, raw in enumerate(data.decode("utf-8", "replace").splitlines(), start=1):
        text = raw.split("#", 1)[0]
        if not text.strip():
            continue
        if delimiter is None:
            fields = text.split()
        else:
            fields = [f.strip() for f in text.split(delimiter)]
        row = []
        for k, field in enumerate(fields):
            if k >= ncols:  # not read; only an empty field is an error
                if not field:
                    return _done(values, numbers, ncols, "token", n, k + 1)
                continue
            try:
                row.append(float(field))
            except ValueError:
                return _done(values, numbers, ncols, "token", n, k + 1)
        if len(fields) < ncols or (exact and len(fields) != ncols):
            return _done(values, numbers, ncols, "count", n, len(fields))
        values.append(row)
        numbers.append(n)
    return _done(values, numbers, ncols, "ok", 0, 0)


def _done(values, numbers, ncols, status, line, field):
    out = np.array(values, dtype=np.float64).reshape(len(values), ncols)
    return out, np.array(numbers, dtype=np.int64), status, line, field
