"""The README's Python examples run, and their results match independent references."""

import pathlib
import re

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
