"""Where the kernels live, read from the source tree: every one is found, by name.

``rigidkit.kernels.modules()`` is the one list of kernel modules that ``rk.symbolic``,
the precompile step and the engine tests walk; a kernel it missed would have no
SymPy form, no precompiled loop and no binding test. The reference here is the
tree itself: every ``.py`` file under ``kernels/`` (subfolders included) and every
function its source decorates with ``@kernel``, found with :mod:`ast`.

The names users call keep working across the files' moves (issue 16): the
``rk.symbolic`` namespaces of the merged modules, and the pose layouts that
``rk.se3`` offers next to ``rigidkit.functional.pose_formats``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import rigidkit as rk
import rigidkit.kernels
from rigidkit._engine import Kernel

ROOT = Path(rigidkit.kernels.__file__).parent


def _dotted(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _decorated_kernels(path: Path) -> set[str]:
    """Names of the top-level functions of ``path`` decorated ``@kernel(...)``."""
    names = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if not isinstance(node, ast.FunctionDef):
            continue
        for dec in node.decorator_list:
            target = dec.func if isinstance(dec, ast.Call) else dec
            if isinstance(target, ast.Name) and target.id == "kernel":
                names.add(node.name)
    return names


FILES = {_dotted(p): p for p in sorted(ROOT.rglob("*.py")) if _dotted(p)}


def test_modules_lists_every_kernel_file():
    found = [
        m.__name__.removeprefix("rigidkit.kernels.") for m in rigidkit.kernels.modules()
    ]
    assert sorted(found) == found  # a stable order
    assert set(found) == set(FILES)
    assert any("." in name for name in found)  # the kinematics subfolder is walked


def test_every_decorated_kernel_is_reached_through_its_module():
    modules = {
        m.__name__.removeprefix("rigidkit.kernels."): m for m in rigidkit.kernels.modules()
    }
    total = 0
    for name, path in FILES.items():
        for fn in _decorated_kernels(path):
            obj = getattr(modules[name], fn)
            assert isinstance(obj, Kernel), (name, fn)
            assert obj.fn.__module__ == f"rigidkit.kernels.{name}"
            total += 1
    from rigidkit.applications.precompile import shipped_kernels

    assert len(shipped_kernels()) == total


#: Namespaces of ``rk.symbolic`` named after kernel modules since merged or moved,
#: each with kernels it held.
FORMER = {
    "rotvec": ["quat_from_rotvec", "rotvec_from_quat", "matrix_from_rotvec"],
    "so3_jacobians": ["left_jacobian", "left_jacobian_inverse", "bracket"],
    "so3_rates": ["body_rate_from_rotvec_rate", "body_acceleration_from_rotvec_rates"],
    "dual_quaternion": ["pose_from_dual_quat", "dual_quat_from_pose"],
    "kinematics": ["quat_derivative", "twist_from_matrix_derivative", "point_velocity"],
    "kinematics_euler": ["rate_matrix_from_euler", "omega_from_euler_rates"],
    "kinematics_integration": ["so3_chain", "se3_increment_rk4"],
    "kinematics_planar": ["se2_chain", "point_velocity_2d"],
    "kinematics_screw": ["screw_from_twist", "twist_from_screw"],
}


@pytest.mark.parametrize("former", sorted(FORMER))
def test_symbolic_namespaces_of_moved_modules_still_resolve(former):
    pytest.importorskip("sympy")
    from rigidkit.applications import symbolic

    space = getattr(symbolic, former)
    for name in FORMER[former]:
        fn = getattr(space, name)
        assert callable(fn)
        if name in symbolic.__all__:  # one SymPy form per kernel, whatever the path
            assert fn is getattr(symbolic, name)


def test_symbolic_namespaces_follow_the_kernel_tree():
    pytest.importorskip("sympy")
    from rigidkit.applications import symbolic

    for name, path in FILES.items():
        kernels = _decorated_kernels(path)
        if not kernels:
            continue
        space = symbolic
        for part in name.split("."):
            space = getattr(space, part)
        if name in kernels:  # swing_twist: the kernel's own name wins at top level
            assert space.__name__ == name
            continue
        assert {k for k in kernels if hasattr(space, k)} == kernels, name
        assert f"rigidkit.kernels.{name}." in getattr(space, sorted(kernels)[0]).__doc__


def test_se3_offers_the_pose_layouts():
    from rigidkit.functional import pose_formats

    for name in pose_formats.__all__:
        assert getattr(rk.se3, name) is getattr(pose_formats, name)
        assert name in rk.se3.__all__
