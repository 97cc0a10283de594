"""Euler sequence strings (``"ZYX"``, ``"zxz"``, scipy's short ``"zy"``), parsed once.

A parsed sequence (:class:`EulerSequence`) carries the static parameters of the
kernels of :mod:`rigidkit.kernels.euler`; parses are cached by the string.
:mod:`rigidkit.functional.euler` re-exports these names.
"""

from __future__ import annotations

from typing import NamedTuple

from ..errors import EulerSequenceError

__all__ = ["EulerSequence", "parse_sequence", "parse_short_sequence"]

_ACCEPTED = (
    "an Euler sequence is three letters of x, y, z, all UPPERCASE (intrinsic, body "
    "axes: 'ZYX', 'XYZ', 'ZXZ', ...) or all lowercase (extrinsic, world axes: "
    "'zyx', 'xyz', 'zxz', ...), with no axis repeated in consecutive places"
)
_SHORT = "; from_euler also takes one or two letters ('z', 'ZY'), as scipy does"


class EulerSequence(NamedTuple):
    """A parsed Euler sequence and the static kernel parameters it stands for.

    ``axes`` are the axis indices (0 = x, 1 = y, 2 = z) in the order written;
    ``intrinsic`` is True for UPPERCASE; ``proper`` is True when the first axis is
    repeated last. ``params`` are the parameters of the kernels in
    :mod:`rigidkit.kernels.euler` (matrix-product order, parity, flags).
    """

    text: str
    axes: tuple
    intrinsic: bool
    proper: bool
    params: tuple


_PARSED: dict = {}


def parse_sequence(seq) -> EulerSequence:
    """Parse an Euler sequence string such as ``"ZYX"`` (intrinsic) or ``"zxz"``.

    Raises
    ------
    EulerSequenceError
        For anything but three letters of ``xyz`` in one case with no axis
        repeated consecutively ("XXY", "xYz", "abc", "XYZX", "", non-strings).

    Examples
    --------
    >>> s = parse_sequence("ZXZ")
    >>> s.axes, s.intrinsic, s.proper
    ((2, 0, 2), True, True)
    >>> parse_sequence("xYz")
    Traceback (most recent call last):
    ...
    rigidkit.errors.EulerSequenceError: 'xYz' mixes upper and lower case; an Euler ...
    """
    try:
        return _PARSED[seq]
    except (KeyError, TypeError):
        pass
    parsed = _parse(seq)
    _PARSED[seq] = parsed
    return parsed


def parse_short_sequence(seq) -> tuple:
    """``(parsed, n)``: a sequence of 1 to 3 letters, padded to three, and ``n``.

    ``from_euler`` accepts one or two axes as scipy does (``"z"``, ``"zy"``,
    ``"XY"``): the missing turns are turns by 0, about the axes that make a
    Tait-Bryan sequence (``"zy"`` -> ``"zyx"``, ``"X"`` -> ``"XYZ"``), so the
    kernels of the 24 sequences serve these too. A zero angle is exact (``cos 0 =
    1``, ``sin 0 = 0``): the padded product is the product of the given turns.

    >>> s, n = parse_short_sequence("zy")
    >>> s.text, n
    ('zyx', 2)
    """
    key = ("short", seq)
    try:
        return _PARSED[key]
    except (KeyError, TypeError):
        pass
    if isinstance(seq, str) and 1 <= len(seq) <= 2:
        _check_letters(seq, _ACCEPTED + _SHORT)
        first = "xyz".index(seq[0].lower())
        second = "xyz".index(seq[1].lower()) if len(seq) == 2 else (first + 1) % 3
        rest = ("xyz"[second] if len(seq) == 1 else "") + "xyz"[3 - first - second]
        parsed = (_parse(seq + (rest.upper() if seq.isupper() else rest)), len(seq))
    else:
        parsed = (_parse(seq, short=True), 3)
    _PARSED[key] = parsed
    return parsed


def _check_letters(seq: str, accepted: str) -> None:
    """One case, letters of xyz, no axis repeated consecutively (else the error)."""
    if seq.lower() != seq and seq.upper() != seq:
        raise EulerSequenceError(f"{seq!r} mixes upper and lower case; {accepted}")
    low = seq.lower()
    if any(c not in "xyz" for c in low):
        raise EulerSequenceError(f"{seq!r} has letters other than x, y, z; {accepted}")
    if any(low[i] == low[i + 1] for i in range(len(low) - 1)):
        raise EulerSequenceError(
            f"{seq!r} repeats an axis in consecutive places (two turns about one "
            f"axis are one turn); {accepted}"
        )


def _parse(seq, *, short=False) -> EulerSequence:
    accepted = _ACCEPTED + (_SHORT if short else "")
    if not isinstance(seq, str):
        raise EulerSequenceError(
            f"Euler sequence must be a string, got {type(seq).__name__}; {accepted}"
        )
    if len(seq) != 3:
        want = "1 to 3" if short else "3"
        raise EulerSequenceError(f"{seq!r} has {len(seq)} letters, not {want}; {accepted}")
    _check_letters(seq, accepted)
    axes = tuple("xyz".index(c) for c in seq.lower())
    intrinsic = seq.isupper()
    # Matrix-product order: R_e1 R_e2 R_e3. Intrinsic "IJK" is R_I R_J R_K with the
    # angles as given; extrinsic "ijk" is R_k R_j R_i, the angles reversed.
    e1, e2, e3 = axes if intrinsic else axes[::-1]
    # Levi-Civita symbol of (e1, e2, m), m the remaining axis: +1 for xy, yz, zx.
    parity = 1 if (e2 - e1) % 3 == 1 else -1
    proper = e1 == e3
    params = (e1, e2, parity, int(proper), 0 if intrinsic else 1)
    return EulerSequence(seq, axes, intrinsic, proper, params)
