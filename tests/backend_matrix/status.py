"""The cells of the matrix that fail, with the reason (``xfail(strict=True)``).

A fix makes its cell pass, strict xfail turns that into a failure, and the entry
goes. ``python -m tests.backend_matrix.discover`` lists the failing cells of the
current tree in this format.
"""

from __future__ import annotations

# torch.compile(fullgraph=True) in CI: a representative handful (10-30 s each): a
# kernel call through an object, a composition of objects, a function with a string
# argument and a gimbal-lock tolerance.
COMPILE_CI = {
    "rk.Rotation.apply",
    "rk.Transform.__matmul__",
    "rk.kinematics.euler_rates",
}
# Further compile cells whose status was recorded from the exhaustive sweep.
COMPILE_CHECKED: set = set()

FAILS = {
    ("rk.Transform.__matmul__", "compile"): (
        "Unsupported: Failed to trace builtin operator (torch.compile fullgraph)"
    ),
}
