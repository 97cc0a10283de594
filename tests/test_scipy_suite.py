"""scipy's own ``spatial.transform`` test suite, run against ``rigidkit.scipy``.

Nothing is vendored: the test modules of the installed scipy
(``scipy/spatial/transform/tests``) are imported with ``Rotation``,
``RigidTransform``, ``Slerp`` and ``RotationSpline`` of ``scipy.spatial.transform``
replaced by rigidkit's drop-in classes while they import, and their test functions
become tests of this module (``test_rotation__from_quat_scalar_first`` is
``test_rotation.py::test_from_quat_scalar_first``). scipy itself is untouched
afterwards. The ``xp`` fixture is NumPy only: scipy's array-API variants (torch,
JAX, ... through ``SCIPY_ARRAY_API=1``) would multiply the time by the number of
libraries; rigidkit's own tests cover those namespaces. The tests that rigidkit
deliberately fails are skipped, each with its reason (``DESELECTED``, explained
in docs/scipy.md). The whole module is skipped where scipy's tests are not
installed.
"""

from __future__ import annotations

import importlib.util
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

sst = pytest.importorskip("scipy.spatial.transform")
TESTS = Path(sst.__file__).parent / "tests"
FILES = {
    "rotation": "test_rotation.py",
    "rigid_transform": "test_rigid_transform.py",
    "rotation_groups": "test_rotation_groups.py",
    "rotation_spline": "test_rotation_spline.py",
}
if not all((TESTS / f).is_file() for f in FILES.values()):
    pytest.skip(
        "scipy's spatial.transform tests are not installed", allow_module_level=True
    )

from scipy._lib import _array_api  # noqa: E402

import rigidkit.scipy as rks  # noqa: E402

CLASSES = ("Rotation", "RigidTransform", "Slerp", "RotationSpline")

#: Tests rigidkit deliberately fails, ``file::test`` -> why (docs/scipy.md explains).
SCIPY_INTERNALS = "tests scipy's private backends, not the public API"
MATRIX_STORAGE = (
    "rigidkit stores a rigid transform as a unit quaternion and a translation, not "
    "a 4x4 matrix: a matrix that is not a rigid motion cannot be kept"
)
DESELECTED = {
    # scipy's private Cython/array-API backends and spline helpers.
    "rotation::test_cython_backend_selection": SCIPY_INTERNALS,
    "rigid_transform::test_copy_flag": MATRIX_STORAGE,
    # A dual quaternion whose real part is zero names no motion: rigidkit raises
    # ZeroNormError, as for a zero quaternion; scipy returns the identity.
    "rigid_transform::test_from_dual_quat": "a zero real part raises ZeroNormError",
    "rigid_transform::test_normalize_dual_quaternion": SCIPY_INTERNALS,
}


def _capabilities():
    """Register rigidkit's classes and methods in scipy's table of array-API
    capabilities (the test decorators read it at import), with the entries of
    scipy's of the same name: scipy 1.17 keys the table by method, 1.18 by class
    (``make_xp_pytest_marks((Rotation, "as_quat"))`` looks up ``Rotation``)."""
    table = _array_api.xp_capabilities_table
    for name in CLASSES:
        theirs, ours = getattr(sst, name), getattr(rks, name)
        if theirs in table:
            table[ours] = table[theirs]
        for attr in dir(theirs):
            f = getattr(theirs, attr, None)
            try:
                caps = table.get(f)
            except TypeError:  # unhashable
                continue
            if caps is not None and hasattr(ours, attr):
                table[getattr(ours, attr)] = caps


def _load(short, filename):
    """Import one of scipy's test modules with rigidkit's classes in scipy's place.

    scipy 1.18's decorators tag the methods they name for its lazy (JAX, Dask)
    variants by replacing them with tagged clones (array_api_extra's
    ``lazy_xp_function``); our classes' own methods are put back afterwards (the
    ``xp`` fixture here is NumPy only, which reads no tag).
    """
    saved = {name: getattr(sst, name) for name in CLASSES}
    own = {name: dict(vars(getattr(rks, name))) for name in CLASSES}
    try:
        for name in CLASSES:
            setattr(sst, name, getattr(rks, name))
        spec = importlib.util.spec_from_file_location(
            f"rigidkit_scipy_suite.{short}", TESTS / filename
        )
        module = importlib.util.module_from_spec(spec)
        with warnings.catch_warnings():  # scipy's own pytest marks, unknown here
            warnings.simplefilter("ignore", pytest.PytestUnknownMarkWarning)
            spec.loader.exec_module(module)
        sys.modules[spec.name] = module
        return module
    finally:
        for name, cls in saved.items():
            setattr(sst, name, cls)
        for name, attrs in own.items():
            cls = getattr(rks, name)
            for attr in set(vars(cls)) - set(attrs):
                delattr(cls, attr)
            for attr, value in attrs.items():
                if vars(cls).get(attr) is not value:
                    setattr(cls, attr, value)


_capabilities()
for _short, _file in FILES.items():
    _module = _load(_short, _file)
    for _name, _obj in list(vars(_module).items()):
        if _name.startswith("test_") and callable(_obj):
            _reason = DESELECTED.get(f"{_short}::{_name}")
            if _reason is not None:
                _obj = pytest.mark.skip(reason=f"rigidkit differs: {_reason}")(_obj)
            globals()[f"test_{_short}__{_name[5:]}"] = _obj
del _short, _file, _module, _name, _obj, _reason


@pytest.fixture
def xp(request):
    """scipy's ``xp`` fixture, NumPy only (honouring ``skip_xp_backends("numpy")``)."""
    for mark in request.node.iter_markers("skip_xp_backends"):
        if "numpy" in mark.args:
            pytest.skip(mark.kwargs.get("reason", "skipped by scipy for NumPy"))
    return _array_api.array_namespace(np.empty(0))
