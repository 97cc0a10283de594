"""The ``rigidkit`` command line: ``rigidkit convert``.

One rotation given on the command line, or a whole ``.csv`` / ``.npy`` batch, is
converted from any representation into others. Conventions: Hamilton quaternions,
scalar first ``(w, x, y, z)`` unless ``quat:xyzw``; active rotations on column
vectors, ``v_A = A_R_B @ v_B``; Euler sequences UPPER = intrinsic, lower =
extrinsic; radians unless ``--degrees`` (which applies to angles read and written).

Exit status: 0 on success, 2 for any error the user can fix (arguments, a
malformed input row, an invalid rotation, an unreadable or unwritable file; one
line on stderr, never a traceback). A failed batch writes nothing.

The modules, in the order a run goes through them: :mod:`.parser` (arguments and
help), :mod:`.representations` (names, columns, CSV header names),
:mod:`.reading` (``.npy`` / ``.csv`` input), :mod:`.convert` (the conversion,
errors and warnings placed on their input row), :mod:`.formatting` (one
rotation's table or JSON), :mod:`.writing` (atomic batch output), and
:mod:`.command`, which ties them together.

>>> main(["convert", "rotvec", "0", "0", "90", "--degrees", "--to", "quat:xyzw",
...       "--decimals", "6"])
quat:xyzw  x y z w  0.000000  0.000000  0.707107  0.707107
0
"""

from .command import main
from .representations import ALL

__all__ = ["ALL", "main"]
