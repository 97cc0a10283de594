"""The README's Python examples run, and their results match independent references;
the public names they use (``rk.so3``, ``rk.kinematics``, ...) are the modules of the
layer folders, each with one import path (docs/architecture.md)."""

import importlib
import pathlib
import re
import sys

import numpy as np
import scipy.linalg as sl
from scipy.spatial.transform import Rotation as SciRot

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def test_readme_examples_run_and_agree_with_scipy():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert len(blocks) >= 2
    ns: dict = {}
    for block in blocks:
        if "import jax" not in block:  # run by test_readme_jax_example, where jax is
            exec(block, ns)
    ref = SciRot.from_euler("ZYX", [30, 20, 10], degrees=True)
    np.testing.assert_allclose(ns["A_R_B"].as_matrix(), ref.as_matrix(), atol=1e-15)
    np.testing.assert_allclose(ns["v_A"], ref.apply([1.0, 0.0, 0.0]), atol=1e-15)
    # The SE(3) example: log is the inverse of exp, checked with scipy's expm.
    rk = ns["rk"]
    hat = rk.se3.hat(ns["xi"])
    np.testing.assert_allclose(sl.expm(hat), ns["W_T_C"].as_matrix(), atol=1e-14)
    # The inertial example: 40 windows of 0.5 s whose predictions drift by millimetres
    # (biases unknown), and a noise-free log integrates back onto the spline.
    np.testing.assert_allclose(ns["pim"].delta_t, 0.5, atol=1e-12)
    assert ns["drift"].shape == (40,) and ns["drift"].max() < 0.02
    flight, times = ns["flight"], ns["log"].times
    gyro, accel = rk.inertial.imu_from_trajectory(flight, times)
    ideal = rk.inertial.integrate(ns["truth"][0], gyro, accel, ns["log"].dt)[-1]
    end = rk.inertial.states_from_trajectory(flight, 20.0)
    np.testing.assert_allclose(ideal.position, end.position, atol=1e-3)


def test_readme_jax_example(jax):
    """The jitted example: 100 steps of 0.5 rad/s about z for 10 ms turn by 0.5 rad."""
    (block,) = [
        b
        for b in re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
        if "import jax" in b
    ]
    ns: dict = {}
    exec(block, ns)
    ref = SciRot.from_rotvec([0.0, 0.0, 0.5])
    np.testing.assert_allclose(float(ns["turned"]), 0.5, atol=1e-12)
    np.testing.assert_allclose(
        np.asarray(ns["W_R_B"].as_matrix()), ref.as_matrix(), atol=1e-12
    )
    assert type(ns["W_R_B"].as_quat()).__module__.startswith("jax")


# rk.<name> and the one import path of the module it holds.
PUBLIC_MODULES = {
    "conversions": "rigidkit.functional.conversions",
    "euler": "rigidkit.functional.euler",
    "quaternion": "rigidkit.functional.quaternion",
    "so3": "rigidkit.functional.so3",
    "se3": "rigidkit.functional.se3",
    "so2": "rigidkit.functional.so2",
    "se2": "rigidkit.functional.se2",
    "sim3": "rigidkit.functional.sim3",
    "se23": "rigidkit.functional.se23",
    "symbolic": "rigidkit.applications.symbolic",
    "kinematics": "rigidkit.applications.kinematics",
    "inertial": "rigidkit.applications.inertial",
    "trajectory": "rigidkit.applications.trajectory",
    "io": "rigidkit.applications.io",
    "jacobians": "rigidkit.applications.jacobians",
    "cli": "rigidkit.applications.cli",
}


def test_each_public_module_has_one_import_path():
    import rigidkit as rk

    for name, path in PUBLIC_MODULES.items():
        module = getattr(rk, name)
        assert module is importlib.import_module(path), name
        assert module.__name__ == path
        # Not a second path: no finder makes ``rigidkit.so3`` importable.
        try:
            importlib.import_module(f"rigidkit.{name}")
        except ModuleNotFoundError:
            pass
        else:
            raise AssertionError(f"rigidkit.{name} is importable")
        assert f"rigidkit.{name}" not in sys.modules


def test_the_project_cites_no_document_it_does_not_hold():
    """No source or test cites the lecture notes as if the reader had them, nor the
    design documents that are not in the repository: docs/errata.md holds their
    errata, and docstrings cite published sources."""
    root = README.parent
    # Spelled in pieces so that this file does not match itself.
    banned = ["the " + "notes", "notes" + "'", "DESIGN" + ".md", "STYLE" + ".md"]
    found = [
        f"{path.relative_to(root)}:{n}: {line.strip()}"
        for folder in ("src", "tests")
        for path in sorted((root / folder).rglob("*.py"))
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if any(word in line for word in banned)
    ]
    assert found == []
    assert (root / "docs" / "errata.md").is_file()
