"""The README's Python examples run, and their results match independent references;
the public names they use (``rk.so3``, ``rk.kinematics``, ...) are the modules of the
layer folders, each with one import path (docs/architecture.md)."""

import importlib
import pathlib
import re
import sys

import numpy as np
import pytest
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


def _section(title: str) -> str:
    """The README's text from the heading ``title`` to the next heading of any level."""
    text = README.read_text()
    start = text.index(f"\n{title}\n")
    nxt = re.search(r"\n#{2,3} ", text[start + len(title) + 2 :])
    return text[start : start + len(title) + 2 + (nxt.start() if nxt else len(text))]


def test_the_first_screen_shows_install_a_first_result_and_the_quaternion_order():
    first = "\n".join(README.read_text().splitlines()[:50])
    assert "pip install -e . && .venv/bin/rigidkit convert" in first
    assert 'pip install -e ".[test]" && .venv/bin/python -m pytest' in first
    assert "```python" in first and "as_quat()" in first
    assert "`(w, x, y, z)`" in first and "scalar_first=False" in first
    assert "wrong rotation and no" in first
    assert "docs/conventions.md" in README.read_text()


def test_coming_from_ros_the_wrong_order_is_visible():
    """The ROS example: (x, y, z, w) read with scalar_first=False is scipy's rotation
    (scipy reads (x, y, z, w) by default) and tf's roll-pitch-yaw; read as (w, x, y,
    z) it is another rotation, silently."""
    ns: dict = {}
    exec("import numpy as np\nimport rigidkit as rk\n", ns)
    (block,) = re.findall(r"```python\n(.*?)```", _section("### Coming from ROS"), re.S)
    exec(block, ns)
    q = np.asarray(ns["orientation_xyzw"])
    ref = SciRot.from_quat(q)  # scipy: scalar last
    np.testing.assert_allclose(ns["W_R_B"].as_matrix(), ref.as_matrix(), atol=1e-15)
    assert not np.allclose(ns["wrong"].as_matrix(), ref.as_matrix(), atol=0.1)
    np.testing.assert_allclose(float(ns["wrong"].angle), np.pi, atol=1e-6)
    np.testing.assert_allclose(ref.magnitude(), np.pi / 4, atol=1e-6)
    # tf's euler_from_quaternion (axes="sxyz"), by hand for a turn about z only:
    x, y, z, w = q / np.linalg.norm(q)
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    np.testing.assert_allclose(
        [ns["roll"], ns["pitch"], ns["yaw"]], [0.0, 0.0, yaw], atol=1e-12
    )
    np.testing.assert_allclose(ns["back"][:3], ns["position"], atol=1e-15)
    np.testing.assert_allclose(ns["back"][3:], q / np.linalg.norm(q), atol=1e-15)


def test_coming_from_scipy_examples_agree_with_scipy():
    ns: dict = {}
    exec("import numpy as np\nimport rigidkit as rk\n", ns)
    blocks = re.findall(r"```python\n(.*?)```", _section("### Coming from scipy"), re.S)
    assert len(blocks) == 2
    for block in blocks:
        exec(block, ns)
    # The drop-in: scipy's API and order, the rotation of rigidkit's R12 (q or -q).
    ref = (ns["S1"] * ns["S2"]).as_quat()
    q = ns["q_xyzw"]
    np.testing.assert_allclose(q * np.sign(q @ ref), ref, atol=1e-15)
    assert ns["R2"].approx_equal(ns["R12"], atol=1e-15)
    S1, S2 = ns["S1"], ns["S2"]
    np.testing.assert_allclose(ns["R12"].as_matrix(), (S1 * S2).as_matrix(), atol=1e-15)
    np.testing.assert_allclose(ns["q_rk"], np.roll(ns["q_scipy"], 1), atol=1e-15)
    assert ns["same"].approx_equal(ns["R1"], atol=1e-15)
    np.testing.assert_allclose(ns["rates"], np.tile([0.0, 0.0, 0.2], (5, 1)), atol=1e-12)
    assert ns["batch"].shape == (100,)


def test_the_coming_from_table_holds():
    """Each row of the table, against scipy and hand-derived products."""
    from scipy.spatial.transform import RigidTransform

    import rigidkit as rk

    table = _section("### Coming from ROS / scipy / tf / Eigen")
    for row in ("quaternion in", "quaternion out", "roll-pitch-yaw", "angles back",
                "twist / exp coordinates", "composition", "random"):  # fmt: skip
        assert f"| {row} |" in table
    roll, pitch, yaw = 0.3, -0.2, 1.1
    R = rk.Rotation.from_euler("xyz", [roll, pitch, yaw])

    def about(axis, a):  # elementary rotation matrices, by hand
        c, s = np.cos(a), np.sin(a)
        i, j = [(1, 2), (2, 0), (0, 1)][axis]
        m = np.eye(3)
        m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
        return m

    Rz_Ry_Rx = about(2, yaw) @ about(1, pitch) @ about(0, roll)  # ROS setRPY, Eigen
    np.testing.assert_allclose(R.as_matrix(), Rz_Ry_Rx, atol=1e-15)
    assert R.approx_equal(rk.Rotation.from_euler("ZYX", [yaw, pitch, roll]), atol=1e-15)
    np.testing.assert_allclose(R.as_euler("xyz"), [roll, pitch, yaw], atol=1e-14)
    np.testing.assert_allclose(R.as_euler("ZYX"), [yaw, pitch, roll], atol=1e-14)
    np.testing.assert_allclose(
        R.as_quat(scalar_first=False), SciRot.from_matrix(Rz_Ry_Rx).as_quat(), atol=1e-15
    )
    # Twists: ours (v, w), scipy's exponential coordinates (w, v).
    v, w = np.array([0.1, -0.4, 0.2]), np.array([0.3, 0.2, -0.5])
    sci = RigidTransform.from_exp_coords(np.concatenate([w, v]))
    np.testing.assert_allclose(
        rk.Transform.exp(np.concatenate([v, w])).as_matrix(), sci.as_matrix(), atol=1e-15
    )
    np.testing.assert_allclose(
        rk.Transform.from_exp_coords(np.concatenate([w, v])).as_matrix(),
        sci.as_matrix(),
        atol=1e-15,
    )
    # R1 * R2 is refused (scipy's composition is @ here).
    with pytest.raises(TypeError):
        R * R
    assert rk.Rotation.random(3, rng=0).approx_equal(rk.Rotation.random(3, rng=0)).all()
