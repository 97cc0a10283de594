"""The registry of groups: what each group class declares once, for every generic algorithm.

Each kind of transform declares, in its class statement, what the code written
once for every group needs from it: its place on the ladder of kinds (the class
keywords ``family`` and ``rank``, see :mod:`.ladder`) and, for a Lie group, a
:class:`GroupSpec` in the class attribute ``_spec``::

    class Rotation(BatchedArray, LieGroup, family="space", rank=0):
        _spec = GroupSpec(
            algebra=so3,                              # hat, vee, the Jacobians
            tangent=(("rotation", slice(0, 3)),),     # the tangent's layout
            rate="angular velocity",                  # a tangent per unit time
            step=(so3_increment, so3_increment_rk4, so3_chain),
        )

:class:`rigidkit.objects.group.Group` registers the class when it is defined
(:func:`register`, which completes the spec with the class, family and rank);
nothing lists the groups anywhere else. The ladder (:mod:`.ladder`),
``rk.jacobians``, the integrators and the finite differences of
``rk.kinematics``, and the tests read the registry, so a generic algorithm is
written once and a new group is covered by it as soon as its class exists.

:func:`groups` returns the registered classes; since ``import rigidkit`` loads
most classes on first use, it first imports every module of the object layer
(found on disk, not from a list). :func:`stored` and :meth:`GroupSpec.wrap` are
the one documented way for code outside a class to reach its stored array (a
quaternion ``(..., 4)`` for a ``Rotation``, a pose ``(..., 7)`` for a
``Transform``, ...) and to make an object of one without validation.

>>> import rigidkit as rk
>>> from rigidkit.objects import registry
>>> spec = registry.spec(rk.Rotation)
>>> spec.algebra.__name__, spec.part("rotation"), spec.rate
('rigidkit.functional.so3', slice(0, 3, None), 'angular velocity')
>>> [cls.__name__ for cls in registry.groups(lie=True)]
['ExtendedPose', 'Rotation2D', 'Transform2D', 'Rotation', 'Transform', 'Similarity']
"""

from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass, replace

__all__ = ["GroupSpec", "register", "spec", "specs", "groups", "stored"]


@dataclass(frozen=True)
class GroupSpec:
    """What a group class declares once for the code written for every group.

    Attributes
    ----------
    algebra : module or None
        The functional module of a Lie group (:mod:`rigidkit.functional._lie`'s
        vocabulary: ``hat``, ``vee``, ``exp``, ``log``, ``left_jacobian``,
        ``right_jacobian`` and their inverses, ...); None for a kind without an
        exponential here (``Affine``, ``Projective``).
    tangent : tuple of (str, slice)
        The named parts of a tangent vector, in order: ``"translation"``,
        ``"rotation"`` (whose angle ``log`` returns in [0, pi]), ``"scale"``
        (the log of the scale); e.g. SE(3)'s ``(v, omega)`` is
        ``(("translation", slice(0, 3)), ("rotation", slice(3, 6)))``.
    rate : str or None
        The name of a tangent per unit time (``"angular velocity"``, ``"twist"``),
        in the messages of ``rk.kinematics``.
    step : tuple or None
        The kernels of one integration step
        (:mod:`rigidkit.kernels.kinematics.integration`):
        ``(increment, increment_rk4, chain)``, the increment of a step from the
        rate held over it, the increment of Runge-Kutta-Munthe-Kaas order 4 from
        the rates at its start, middle and end, and the product of two stored
        elements in the order of the frame (``body`` parameter). ``chain`` is None
        for a commutative group whose increments are tangents, summed (SO(2)).
    cls : type
        The class (set by :func:`register`), and ``family``, ``rank`` its place on
        the ladder of kinds.
    wrap : callable
        ``wrap(data)``: an object of the class holding ``data`` (its stored
        layout, ``batch + the element's shape``), not validated. It is the class's
        own ``_wrap`` (read from the class when asked, so it is the class's final
        one), so a hot path that binds it once pays no extra call.
    """

    algebra: object = None
    tangent: tuple = ()
    rate: str | None = None
    step: tuple | None = None
    cls: type | None = None
    family: str | None = None
    rank: int | None = None

    def __repr__(self):
        return f"GroupSpec({getattr(self.cls, '__name__', None)})"

    @property
    def dof(self) -> int:
        """The dimension of the tangent (of the Lie algebra)."""
        return self.cls.dof

    @property
    def wrap(self):
        """``wrap(data)``: an object of the class holding ``data``, not validated."""
        return self.cls._wrap

    def part(self, name: str):
        """The slice of the tangent named ``name`` (see ``tangent``), or None."""
        return next((s for n, s in self.tangent if n == name), None)


# class -> its completed GroupSpec; filled by each class statement through ``register``.
_SPECS: dict = {}


def register(cls, family: str, rank: int) -> None:
    """Record ``cls`` at ``rank`` (0 = least general) of ``family`` with its ``_spec``."""
    for other, s in _SPECS.items():
        if (s.family, s.rank) == (family, rank) and other.__qualname__ != cls.__qualname__:
            raise ValueError(f"{other.__name__} already has rank {rank} in {family!r}")
    declared = cls.__dict__.get("_spec") or GroupSpec()
    cls._spec = _SPECS[cls] = replace(declared, cls=cls, family=family, rank=rank)


def spec(cls):
    """The :class:`GroupSpec` of the registered class ``cls``, or None."""
    return _SPECS.get(cls)


def specs() -> dict:
    """The registry as it is now, ``{class: GroupSpec}`` (the classes loaded so far)."""
    return _SPECS


def groups(*, lie: bool = False) -> tuple:
    """Every registered group class, by family and rank; ``lie=True``: the Lie groups.

    Imports each module of the object layer first, so that the classes which
    ``import rigidkit`` loads on first use are registered too.
    """
    package = __name__.rpartition(".")[0]
    for info in pkgutil.iter_modules(importlib.import_module(package).__path__):
        importlib.import_module(f"{package}.{info.name}")
    found = sorted(_SPECS.values(), key=lambda s: (s.family, s.rank))
    return tuple(s.cls for s in found if s.algebra is not None or not lie)


def stored(x):
    """The array an object stores (``batch + its element's shape``), not a copy.

    It is the slot ``_data`` that every kind has (:class:`._batch.BatchedArray`),
    which a hot path may read directly to save this call.
    """
    return x._data
