"""Printing one rotation: an aligned table or a JSON document.

Numbers are printed with every digit needed to read back the same float64
(Python ``repr``) unless ``--decimals`` rounds them; table columns align on the
decimal point.
"""

from __future__ import annotations

import json

import numpy as np

__all__ = ["format_table", "json_document", "table_rows"]


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
    """Align ``(name, label, numbers)`` rows; numbers align on their decimal point.

    >>> print(format_table([("a", "x y", [1.5, -10.0]), ("bb", "z", [0.25])]))
    a   x y  1.5   -10.0
    bb  z    0.25
    """
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


def table_rows(targets, outputs, degrees) -> list:
    """``(name, label, numbers)`` per line: one per target, three for a matrix."""
    rows = []
    for rep, out in zip(targets, outputs, strict=True):
        if rep.kind == "matrix":
            m = out.reshape(3, 3)
            rows += [("matrix" if i == 0 else "", f"row {i + 1}", m[i]) for i in range(3)]
        else:
            rows.append((rep.name, rep.describe(degrees), out))
    return rows


def json_document(targets, outputs, degrees, decimals=None) -> str:
    """``{"degrees": ..., TARGET: numbers}``; a matrix as a list of three rows.

    Numbers rounded to ``decimals`` when given, never ``-0.0``.

    >>> from .representations import representation
    >>> print(json_document([representation("rotvec")], [np.array([-0.0, 1e-9, 1 / 3])],
    ...                     False, 4).replace(chr(10), ""))
    {  "degrees": false,  "rotvec": [    0.0,    0.0,    0.3333  ]}
    """
    doc = {"degrees": degrees}
    for rep, out in zip(targets, outputs, strict=True):
        values = np.asarray(out, dtype=np.float64)
        if decimals is not None:
            values = np.round(values, decimals)
        values = values + 0.0  # no negative zero
        values = values.reshape(3, 3) if rep.kind == "matrix" else values
        doc[rep.name] = values.tolist()  # Python floats: json writes them as repr
    return json.dumps(doc, indent=2)
