"""The ladder of transform kinds: which kind includes which, and where ``a @ b`` lands.

The kinds of transform of one space are nested, each included in the next::

    Rotation  ⊂  Transform  ⊂  Similarity  ⊂  Affine  ⊂  Projective     family "space"
     SO(3)        SE(3)         Sim(3)       (A, t)     PGL(4)

    Rotation2D  ⊂  Transform2D                                         family "plane"
     SO(2)          SE(2)

``a @ b`` of two kinds of one family is computed in the more general of the two
(``Transform @ Affine`` is an ``Affine``, ``Similarity @ Projective`` a
``Projective``): :func:`compose` includes both operands into that kind (its class
method ``include``) and composes them there.

Each class places itself on the ladder when it is defined, with the class keywords
of :class:`rigidkit.objects.group.Group` (``class Similarity(..., family="space",
rank=2)``), which record it in the registry of groups (:mod:`.registry`). So this
module imports no class, and no class imports another to learn its rank: the
families and ranks are read from that registry, the one list of groups.
"""

from __future__ import annotations

import numpy as np

from .._engine.namespace import device_of, namespace_of
from .registry import specs

__all__ = ["kind_of", "compose", "check_included", "homogeneous_matrix"]

# class -> its GroupSpec (family, rank, ...): the registry's own dict, bound once.
_SPECS = specs()


def kind_of(x):
    """``(kind, family, rank)`` of the transform ``x``, or ``None`` for anything else.

    The kind is the registered class of ``x``, or of the nearest registered base
    class for a subclass of one.
    """
    s = _SPECS.get(type(x))
    if s is not None:  # the common case, a registered class itself
        return type(x), s.family, s.rank
    for cls in type(x).__mro__[1:]:
        s = _SPECS.get(cls)
        if s is not None:
            return cls, s.family, s.rank
    return None


def _family_names(family: str) -> str:
    kinds = sorted((s.rank, c.__name__) for c, s in _SPECS.items() if s.family == family)
    return ", ".join(name for _, name in kinds)


def compose(a, b):
    """``a @ b`` (``b`` applied first) in the more general kind of the two.

    >>> import rigidkit as rk
    >>> S = rk.Similarity(scale=2.0)
    >>> T = rk.Transform(translation=[1.0, 0.0, 0.0])
    >>> type(compose(T, S)).__name__, type(compose(S, rk.Projective.identity())).__name__
    ('Similarity', 'Projective')
    """
    ka, kb = kind_of(a), kind_of(b)
    if ka is None or kb is None or ka[1] != kb[1]:
        family = (ka or kb or (None, "space"))[1]
        raise TypeError(
            f"cannot compose {type(a).__name__} with {type(b).__name__}: both must be "
            f"kinds of one family ({_family_names(family)})"
        )
    # Both are on one ladder (checked above): include the lower one into the other.
    if ka[2] > kb[2]:
        b = ka[0]._include(b)
    elif ka[2] < kb[2]:
        a = kb[0]._include(a)
    return a._wrap(a._compose_kernel(a._data, b._data))


def check_included(cls, x, what: str) -> None:
    """Raise :class:`TypeError` unless ``x`` is of a kind included in ``cls``."""
    kx = kind_of(x)
    s = next(_SPECS[c] for c in cls.__mro__ if c in _SPECS)
    family, rank = s.family, s.rank
    if kx is None or kx[1] != family or kx[2] > rank:
        raise TypeError(f"{what} takes a transform of a kind included in {cls.__name__}")


def homogeneous_matrix(x):
    """The 4x4 homogeneous matrix of any kind of the "space" family.

    ``[[R, 0], [0, 1]]`` for a rotation (whose own ``as_matrix`` is 3x3), the
    kind's ``as_matrix()`` for every other.
    """
    if kind_of(x)[2] != 0:
        return x.as_matrix()
    R = x.as_matrix()
    xp = namespace_of(R)
    dev = device_of(R)
    batch = tuple(R.shape[:-2])
    if isinstance(R, np.ndarray):
        M = np.zeros(batch + (4, 4), dtype=R.dtype)
        M[..., :3, :3] = R
        M[..., 3, 3] = 1.0
        return M
    col = xp.zeros(batch + (3, 1), dtype=R.dtype, device=dev)
    last = xp.asarray([0.0, 0.0, 0.0, 1.0], dtype=R.dtype, device=dev)
    last = xp.broadcast_to(last, batch + (1, 4))
    return xp.concat([xp.concat([R, col], axis=-1), last], axis=-2)
