"""The rotation representations as named on the command line.

Each :class:`Representation` knows its numbers (``columns``), how to build a
:class:`~rigidkit.Rotation` from them and how to write one back, and which CSV
header names denote its components (see :mod:`.headers`).
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass

import numpy as np

from ...errors import RigidkitError
from ...objects.rotation import Rotation

__all__ = ["ALL", "CLIError", "Representation", "is_number", "representation", "targets"]


class CLIError(Exception):
    """A user error found by the command line itself (one line, exit status 2)."""


def is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


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

    @property
    def kind(self) -> str:
        return self.name if self.seq is None else "euler"

    def describe(self, degrees: bool) -> str:
        unit = "deg" if degrees else "rad"
        return f"{self.label} ({unit})" if self.angle_unit else self.label

    def rotation_from(self, values, degrees: bool, orthonormalize=False) -> Rotation:
        """The rotations of ``values``, shape (..., size), as a :class:`Rotation`.

        ``orthonormalize`` (matrices only): the nearest rotation instead of an error.
        """
        kind = self.kind
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
        kind = self.kind
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

    def angles(self, values) -> np.ndarray | None:
        """The angles in ``values`` (..., size), one per rotation, or None if it has none.

        For the degrees check: Euler angles, the angle of axis-angle, and the
        length of a rotation vector.
        """
        if self.seq is not None:
            return np.max(np.abs(values), axis=-1)
        if self.kind == "axis-angle":
            return np.abs(values[..., 3])
        if self.kind == "rotvec":
            return np.linalg.norm(values, axis=-1)
        return None


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
# Roll-pitch-yaw as ROS (REP 103), URDF and tf write it: roll about the fixed x
# axis, then pitch about fixed y, then yaw about fixed z, the angles in that order
# (roll, pitch, yaw): extrinsic xyz, which is intrinsic ZYX with the angles reversed.
_FIXED["rpy"] = Representation(
    "rpy",
    ("angle1", "angle2", "angle3"),
    "roll pitch yaw (x y z extrinsic)",
    angle_unit=True,
    seq="xyz",
)
# The explicit spelling of the default order is accepted too.
_ALIASES = {"quat:wxyz": "quat", "euler:rpy": "rpy"}

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

_NAMES_HELP = (
    "quat, quat:xyzw, matrix, rotvec, axis-angle, mrp, rpy, euler:SEQ (e.g. euler:ZYX)"
)


def representation(name: str) -> Representation:
    """The :class:`Representation` called ``name`` on the command line.

    Raises :class:`CLIError` naming the accepted forms (and the closest match).
    """
    name = _ALIASES.get(name, name)
    if name in _FIXED:
        return _FIXED[name]
    if name.startswith("euler:"):
        seq = name[len("euler:") :]
        from ...functional.euler import parse_sequence

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


def is_representation(name: str) -> bool:
    """Whether ``name`` is a valid representation name (no error raised)."""
    try:
        representation(name)
    except CLIError:
        return False
    return True


def targets(tokens) -> list:
    """The ``--to`` list: names separated by spaces or commas, ``all`` expanded."""
    names = []
    for token in tokens:
        for name in token.strip().split(","):
            if not name:
                continue
            if is_number(name):
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
