"""The columns of a headed CSV trajectory, named by its header line.

A time (``t``, ``time``, ``timestamp``, ``stamp``; nanoseconds when the name
says ``ns``), the position (``x, y, z``; ``tx``, ``p_x``, ``pos_x``,
``position.x``) and the quaternion (``qw, qx, qy, qz``, ``q_w``, ``quat_x``,
``orientation.w``); units in brackets (``[m]``, ``(ns)``) are read past.

>>> column_of("timestamp [ns]"), column_of("p_x"), column_of("q_w"), column_of("vel")
(('t', True), ('p', 'x'), ('q', 'w'), None)
"""

from __future__ import annotations

import re

__all__ = ["column_of", "csv_delimiter"]

_UNIT = re.compile(r"\[[^\]]*\]|\([^)]*\)")
_TIME = re.compile(
    r"^(?:#\s*)?(?:t|time|times|timestamp|stamp|sec|secs|seconds)(?:[_.]?(ns|nsec|s))?$"
)
_POS = re.compile(r"^(?:t|p|pos|position|translation|trans)?[_.]?(?:[a-z]+[_.])*?([xyz])$")
_QUAT = re.compile(
    r"^(?:q|quat|quaternion|orientation|rot|rotation)[_.]?(?:[a-z]+[_.])*?([wxyz])$"
)


def column_of(name: str):
    """``("t", ns)``, ``("p", axis)``, ``("q", comp)`` or None for a header name."""
    raw = name.strip().strip('"').strip().lower()
    ns = "[ns]" in raw.replace(" ", "")
    key = _UNIT.sub("", raw).strip().lstrip("#").strip().replace(" ", "_")
    m = _TIME.match(key)
    if m:
        return ("t", ns or m.group(1) in ("ns", "nsec"))
    m = _QUAT.match(key)
    if m:
        return ("q", m.group(1))
    m = _POS.match(key)
    if m and not key.startswith(("q", "rot", "orientation")):
        return ("p", m.group(1))
    return None


def csv_delimiter(line: str):
    """The first of ``,``, ``;`` and tab found in a header line, or None (spaces)."""
    for d in (",", ";", "\t"):
        if d in line:
            return d
    return None
