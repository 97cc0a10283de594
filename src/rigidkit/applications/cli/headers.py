"""CSV headers that name the components of a representation.

A header such as ``qx,qy,qz,qw`` says in which order the numbers come; reading
those columns as ``w, x, y, z`` would silently give another rotation. So a
header naming components is honoured (the columns are reordered) when it names
each component of the representation once, and is an error when it names
others; a header of other words (``a,b,c``, ``time,...``) names nothing: the
reader warns that the columns are taken in the representation's order.
"""

from __future__ import annotations

from .representations import CLIError, is_representation

__all__ = ["accepted", "header_order"]

# Roll, pitch and yaw are the angles about x, y and z (aerospace ZYX is
# yaw-pitch-roll, ROS's fixed-axis RPY is xyz), so they name the angles of any
# Euler sequence that turns about three different axes.
_ANGLE_ABOUT = {"roll": "x", "pitch": "y", "yaw": "z"}
_MATRIX_NAMES = {f"{c}{i}{j}" for c in "mr" for i in "123" for j in "123"}
# Every name that denotes a component of some representation: a header using any
# of them is read as naming its columns.
_COMPONENT_NAMES = (
    {"w", "x", "y", "z", "angle", "angle1", "angle2", "angle3"}
    | set(_ANGLE_ABOUT)
    | _MATRIX_NAMES
)
_QUATERNION_PREFIXES = ("quaternion", "quat", "q")
_QUATERNION_NAMES = ("quat", "quat:xyzw", "quat:wxyz")


def _unquote(field: str) -> str:
    return field.strip().strip('"').strip()


def _quaternion_part(comp: str) -> str | None:
    """``w`` for ``qw``, ``q_w``, ``quat_w``, ``w``; None for anything else."""
    for p in _QUATERNION_PREFIXES:
        rest = comp[len(p) :].lstrip("_")
        if comp.startswith(p) and rest in ("w", "x", "y", "z"):
            return rest
    return comp if comp in ("w", "x", "y", "z") else None


def _names_a_component(name: str) -> bool:
    prefix, dot, comp = name.rpartition(".")
    if dot and is_representation(prefix):
        return True
    comp = comp.lower()
    return comp in _COMPONENT_NAMES or _quaternion_part(comp) is not None


def _three_axes(rep) -> bool:
    return rep.seq is not None and len(set(rep.seq.lower())) == 3


def _component(rep, name: str) -> str | None:
    """The column of ``rep`` that the header field ``name`` names, or None.

    Accepted: the column names themselves, a ``REPR.`` prefix (this command's own
    output header, ``quat.w``), ``q``/``quat`` before quaternion components
    (``qx``, ``q_w``), ``r11`` for ``m11``, and roll/pitch/yaw for the angles of
    an Euler sequence about three different axes.
    """
    prefix, dot, comp = name.rpartition(".")
    if dot and prefix != rep.name:
        if not (rep.kind.startswith("quat") and prefix in _QUATERNION_NAMES):
            return None
    comp = comp.lower()
    if rep.kind.startswith("quat"):
        comp = _quaternion_part(comp)
    elif rep.kind == "matrix" and comp in _MATRIX_NAMES:
        comp = "m" + comp[1:]
    elif _three_axes(rep) and comp in _ANGLE_ABOUT:
        comp = f"angle{rep.seq.lower().index(_ANGLE_ABOUT[comp]) + 1}"
    return comp if comp in rep.columns else None


def accepted(rep) -> str:
    names = ", ".join(rep.columns)
    if _three_axes(rep):
        about = {axis: name for name, axis in _ANGLE_ABOUT.items()}
        names += " or " + ", ".join(about[a] for a in rep.seq.lower())
    return names


def header_order(rep, fields) -> list | None:
    """Column permutation for the CSV header ``fields``, or None to keep file order.

    A header whose fields name no component of any representation is ignored.
    One that does must name each column of ``rep`` exactly once: then
    ``data[:, order]`` has the columns in ``rep.columns`` order. Anything else
    contradicts the representation and raises :class:`CLIError`.

    >>> from .representations import representation
    >>> header_order(representation("quat"), ["qx", "qy", "qz", "qw"])
    [3, 0, 1, 2]
    >>> header_order(representation("euler:ZYX"), ["roll", "pitch", "yaw"])
    [2, 1, 0]
    >>> header_order(representation("quat"), ["a", "b", "c", "d"]) is None
    True
    """
    names = [_unquote(f) for f in fields]
    if not any(_names_a_component(n) for n in names):
        return None
    found = [_component(rep, n) for n in names]
    if len(found) == rep.size and set(found) == set(rep.columns):
        return [found.index(c) for c in rep.columns]
    raise CLIError(
        f"the header ({', '.join(names)}) does not name the {rep.size} columns of "
        f"{rep.name} ({accepted(rep)}); fix the representation, or rename or "
        "remove the header"
    )
