"""Scalar kernels; see :mod:`rigidkit._engine` and ``docs/architecture.md``.

Each kernel is a plain function of scalar components. Free names are primitives
(``sqrt``, ``where``, ...) bound per backend, which is why linters see them as
undefined here.

One rule places them: a group's Lie vocabulary (hat, vee, exp, log, adjoints,
bracket, Jacobians, its operations) is one module named after the group
(:mod:`.so2`, :mod:`.se2`, :mod:`.so3`, :mod:`.se3`, :mod:`.sim3`); a
representation's conversions are one module named after the representation
(:mod:`.quaternion`, :mod:`.matrix`, :mod:`.euler`, :mod:`.pose_formats`, ...);
motion (velocities, accelerations, integration steps) is in the subpackage
:mod:`.kinematics`; helpers shared by all are in :mod:`.coefficients` and
:mod:`.vector`.
"""


def modules() -> list:
    """Every kernel module, those of subpackages included, imported, sorted by name.

    The one place that lists them (for ``rk.symbolic``, the precompile step and
    the tests): a new module is found without being registered anywhere.
    """
    import importlib
    import pkgutil

    names = sorted(info.name for info in pkgutil.walk_packages(__path__, f"{__name__}."))
    return [importlib.import_module(name) for name in names]
