"""Shared test settings: hypothesis profiles, optional backends, small helpers.

Hypothesis runs with ``deadline=None`` (a first call may wait for a numba compile)
and a modest number of examples; ``HYPOTHESIS_PROFILE=thorough`` runs more.

Optional backends (torch, JAX, Dask) are installed on some platforms only (torch's
CPU wheel exists for Python 3.11 x86_64 here), so a test asks for one and is skipped
alone when it is missing; every other test of the file still runs. Three spellings:

* a fixture argument: ``def test_x(torch): ...`` (also ``jax``, ``jnp``, ``dask_array``);
* a marker, for tests that reach the backend through module-level helpers:
  ``@needs("torch")`` (``needs = pytest.mark.needs``);
* a module-level import that never fails: ``torch = optional("torch")`` gives the
  module or ``None``, for helpers and parametrisations that mention it.

``pytest.importorskip`` at module level is not used: it skips every test of the file.

Compiled loops: the test processes run as with ``RIGIDKIT_BACKGROUND_COMPILE=0``
(unless the environment sets that variable), so a batch whose loop is not ready is
served by the Python-float and element-wise NumPy bindings, and no loop is compiled
speculatively for each broadcast pattern and dtype a test happens to meet (on a
cold cache, hundreds of 1-3 s compiles per test process: most of CI's time). Every
kernel's compiled loop is still checked against the other bindings
(tests/test_engine.py, ``backend="numba"``); tests of the background loader itself
ask for it with the ``background_compiles`` fixture.
"""

from __future__ import annotations

import importlib
import importlib.util
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

from rigidkit.objects import registry

# The module (rigidkit._engine's ``kernel`` is the decorator).
_kernel = importlib.import_module("rigidkit._engine.kernel")

# See the module docstring. Set on the engine, not in the environment: processes the
# tests start (the CLI, fresh-process checks of the loader) run as users get them.
if "RIGIDKIT_BACKGROUND_COMPILE" not in os.environ:
    _kernel.BACKGROUND = False

# torch's setup (bindings, adapter, pytree nodes) once per test process, where torch
# is installed: as the doctest collection of rigidkit._engine.torch_setup did before
# it was left out of collection (pyproject.toml: it imports torch at its top level).
# The setup done lazily, at the first tensor, is tested in fresh processes
# (tests/test_engine.py).
if importlib.util.find_spec("torch") is not None:
    import rigidkit._engine.torch_setup  # noqa: F401

settings.register_profile(
    "default",
    max_examples=100,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("thorough", max_examples=2000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

# Optional backends: the import name of each, by the name tests use for it.
OPTIONAL = {
    "torch": "torch",
    "jax": "jax",
    "jnp": "jax.numpy",
    "dask_array": "dask.array",
    "distributed": "distributed",
}


def optional(module: str):
    """``module`` imported, or ``None`` where it is not installed."""
    try:
        return importlib.import_module(module)
    except ImportError:
        return None


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "needs(name, ...): skip this test unless each optional backend imports"
    )


def pytest_runtest_setup(item):
    for mark in item.iter_markers("needs"):
        for name in mark.args:
            pytest.importorskip(OPTIONAL.get(name, name))


def _backend_fixture(name: str):
    def fixture():
        module = pytest.importorskip(OPTIONAL[name])
        if name in ("jax", "jnp"):
            # float64 everywhere, as NumPy: tolerances are written for it.
            importlib.import_module("jax").config.update("jax_enable_x64", True)
        return module

    fixture.__name__ = name
    fixture.__doc__ = f"``{OPTIONAL[name]}``, or skip this test where it is not installed."
    return pytest.fixture(name=name)(fixture)


torch = _backend_fixture("torch")
jax = _backend_fixture("jax")
jnp = _backend_fixture("jnp")
dask_array = _backend_fixture("dask_array")


@pytest.fixture
def background_compiles(monkeypatch):
    """The engine as users get it: loops not ready are compiled in the background
    (the suite runs without, see the module docstring)."""
    monkeypatch.setattr(_kernel, "BACKGROUND", True)


@pytest.fixture
def rng():
    """A seeded generator, fresh for every test (tests stay independent of order)."""
    return np.random.default_rng(20240607)


# Every kind of transform (objects.group.Group), for tests run once per kind: read
# from the registry of groups, which each class joins when it is defined, so a new
# kind is tested by every test that iterates over these without being listed here.
GROUP_KINDS = list(registry.groups())
# The Lie groups among them (those with an exponential and a functional module).
LIE_GROUPS = list(registry.groups(lie=True))


def hamilton(a, b):
    """Hamilton product of scalar-first quaternions (..., 4), written out by hand
    (the tests' reference, independent of the kernels)."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def quat_angle(q1, q2):
    """Angle (radians) of the rotation between unit quaternions, in float64 NumPy.

    An independent reference for "the same orientation": ``2 atan2(|v|, |w|)`` of
    ``q1* q2`` written out here, so ``q`` and ``-q`` compare equal.
    """
    q1 = np.asarray(q1, dtype=np.float64)
    q2 = np.asarray(q2, dtype=np.float64)
    w1, v1 = q1[..., 0], q1[..., 1:]
    w2, v2 = q2[..., 0], q2[..., 1:]
    w = w1 * w2 + np.sum(v1 * v2, axis=-1)
    v = w1[..., None] * v2 - w2[..., None] * v1 - np.cross(v1, v2)
    return 2.0 * np.arctan2(np.linalg.norm(v, axis=-1), np.abs(w))
