"""The project's own lint: ruff check and ruff format, as configured in pyproject.toml."""

import pathlib
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


def _ruff():
    exe = shutil.which("ruff") or str(pathlib.Path(sys.executable).with_name("ruff"))
    if not pathlib.Path(exe).exists():
        pytest.skip("ruff is not installed (it is in the [test] extra)")
    return exe


@pytest.mark.parametrize(
    "args", [["check"], ["format", "--check"]], ids=["check", "format"]
)
def test_ruff(args):
    paths = [str(ROOT / p) for p in ("src", "tests", "benchmarks")]
    res = subprocess.run([_ruff(), *args, *paths], capture_output=True, text=True)
    assert res.returncode == 0, res.stdout + res.stderr
