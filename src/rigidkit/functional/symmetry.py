"""Finite rotation groups (symmetries of solids) and reduction by them (arrays in/out).

``quat_group`` lists the elements of the rotation groups of scipy's
``Rotation.create_group``: icosahedral ``"I"`` (60), octahedral ``"O"`` (24),
tetrahedral ``"T"`` (12), dihedral ``"Dn"`` (2n) and cyclic ``"Cn"`` (n), the last
two about a coordinate axis. ``quat_reduce`` finds, for each rotation ``p``, the
elements ``l`` of a left and ``r`` of a right group that make ``l p r`` of smallest
angle (scipy's ``Rotation.reduce``): the alignment of two objects with those
symmetries. Quaternions are Hamilton, scalar first ``(w, x, y, z)``; the element
sets equal scipy's (up to order and the sign of each quaternion).

The groups are built NumPy-side (they are constants); ``quat_reduce`` runs on the
quaternions' array namespace (a matrix product and an ``argmax``), also under
``jax.jit``; on Dask arrays lazily, chunk by chunk of the batch.

>>> import numpy as np
>>> q = quat_group("C4")                         # quarter turns about z
>>> np.round(q, 12) + 0.0
array([[ 1.        ,  0.        ,  0.        ,  0.        ],
       [ 0.70710678,  0.        ,  0.        ,  0.70710678],
       [ 0.        ,  0.        ,  0.        ,  1.        ],
       [-0.70710678,  0.        ,  0.        ,  0.70710678]])
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np

from .._engine import dask_backend
from .._engine.namespace import namespace_of
from .._validate import _relabel, as_array
from ..errors import RigidkitError
from ..kernels import quaternion as _kq
from .davenport import asarray_like
from .interpolation import take_rows

__all__ = ["quat_group", "quat_reduce"]

_AXES = {"x": 0, "y": 1, "z": 2}


def quat_group(group, axis="Z", *, dtype=np.float64):
    """Unit quaternions of the elements of a finite rotation group, shape (n, 4).

    Parameters
    ----------
    group : {"I", "O", "T", "Dn", "Cn"}
        Icosahedral (60 elements), octahedral (24), tetrahedral (12), dihedral of
        order ``n`` (``"D3"``: 2n elements: the ``Cn`` turns and n half turns about
        axes orthogonal to ``axis``) or cyclic (``"C5"``: n turns by ``2 pi k / n``
        about ``axis``); ``n >= 1``.
    axis : {"X", "Y", "Z"} (or lowercase)
        The principal axis of ``Dn`` and ``Cn``; ignored for ``I``, ``O``, ``T``
        (whose axes are those of scipy's: the coordinate axes are 2-fold (``T``,
        ``I``) or 4-fold (``O``) axes).
    dtype : NumPy float dtype

    Returns
    -------
    quat : ndarray, shape (n, 4)
        ``(w, x, y, z)``, the identity first.

    Raises
    ------
    RigidkitError
        (a ValueError) for an unknown group or axis, or ``n < 1``.

    Examples
    --------
    >>> [len(quat_group(g)) for g in ("I", "O", "T", "D3", "C5")]
    [60, 24, 12, 6, 5]
    """
    if not isinstance(axis, str) or axis.lower() not in _AXES:
        raise RigidkitError(f"group axis must be one of 'X', 'Y', 'Z', got {axis!r}")
    a = _AXES[axis.lower()]
    if group == "I":
        q = np.concatenate([_tetrahedral(), _icosians()])
    elif group == "O":
        q = np.concatenate([_tetrahedral(), _octahedral_extra()])
    elif group == "T":
        q = _tetrahedral()
    elif isinstance(group, str) and group[:1] in ("C", "D") and group[1:].isdigit():
        n = int(group[1:])
        if n < 1:
            raise RigidkitError(f"group order must be positive, got {group!r}")
        q = (
            _cyclic(n, a)
            if group[0] == "C"
            else np.concatenate([_cyclic(n, a), _flips(n, a)])
        )
    else:
        raise RigidkitError(
            "group must be 'I', 'O', 'T', 'Dn' or 'Cn' (n a positive integer), "
            f"got {group!r}"
        )
    return np.ascontiguousarray(q, dtype=dtype)


def _tetrahedral():
    """The 12 of T: 1, i, j, k and the 8 ``(+-1 +-i +-j +-k) / 2`` up to sign."""
    signs = np.array(list(itertools.product((1.0, -1.0), repeat=3)))
    halves = 0.5 * np.column_stack([np.ones(8), signs])
    return np.concatenate([np.eye(4), halves])


def _octahedral_extra():
    """O minus T: quarter turns ``(1 +- e_a)/sqrt 2`` and ``(e_a +- e_b)/sqrt 2``."""
    out = []
    for a in range(1, 4):
        for s in (1.0, -1.0):
            q = np.zeros(4)
            q[0], q[a] = 1.0, s
            out.append(q)
    for a, b in itertools.combinations(range(1, 4), 2):
        for s in (1.0, -1.0):
            q = np.zeros(4)
            q[a], q[b] = 1.0, s
            out.append(q)
    return np.array(out) / math.sqrt(2.0)


def _icosians():
    """I minus T: even permutations of ``(0, +-1, +-1/phi, +-phi) / 2`` (48, up to sign).

    This orientation (not its mirror, the odd permutations) is scipy's.
    """
    phi = (1.0 + math.sqrt(5.0)) / 2.0
    out = []
    for perm in itertools.permutations(range(4)):
        inversions = sum(perm[i] > perm[j] for i in range(4) for j in range(i + 1, 4))
        if inversions % 2:
            continue
        # The 1 keeps its sign (a sign for the others): one of each pair q, -q.
        for s2, s3 in itertools.product((1.0, -1.0), repeat=2):
            q = np.zeros(4)
            q[perm[1]] = 0.5
            q[perm[2]] = 0.5 * s2 / phi
            q[perm[3]] = 0.5 * s3 * phi
            out.append(q)
    return np.array(out)


def _cyclic(n, a):
    """Turns by ``2 pi k / n`` about the coordinate axis ``a``, k = 0..n-1."""
    half = np.pi * np.arange(n) / n
    q = np.zeros((n, 4))
    q[:, 0] = np.cos(half)
    q[:, 1 + a] = np.sin(half)
    return q


def _flips(n, a):
    """Half turns about the axes at angles ``pi k / n`` in the plane orthogonal to
    axis ``a`` (scipy's: from the next axis cyclically, towards the one after)."""
    theta = np.pi * np.arange(n) / n
    q = np.zeros((n, 4))
    q[:, 1 + (a + 1) % 3] = np.cos(theta)
    q[:, 1 + (a + 2) % 3] = np.sin(theta)
    return q


def quat_reduce(quat, left=None, right=None):
    """``l p r`` of smallest angle over ``l`` in ``left`` and ``r`` in ``right``.

    For each unit quaternion ``p`` the pair maximising ``|scalar(l p r)|`` (the
    cosine of half the angle), as scipy's ``Rotation.reduce``: the scalar part of
    ``l x`` is ``l_w x_w - l_v . x_v``, so all pairs are one matrix product of
    ``p r`` (..., m, 4) with the conjugates of ``left``. Ties go to the first pair
    in the order (left index, right index), as scipy's.

    Parameters
    ----------
    quat : array_like, shape (..., 4)
        Unit quaternions (not normalised here).
    left, right : array_like, shape (k, 4), optional
        Unit quaternions of the group elements (e.g. :func:`quat_group`); None is
        the identity alone.

    Returns
    -------
    reduced : array, shape (..., 4)
    left_index, right_index : integer arrays, shape (...)
        Indices into ``left`` and ``right`` (0 where that group is None).

    Memory: ``k_left * k_right`` numbers per rotation (3600 for ``I`` on both sides).
    Dask input stays lazy: each chunk of the batch is reduced on its own.

    Examples
    --------
    >>> import numpy as np
    >>> p = np.array([np.cos(0.8), 0.0, 0.0, np.sin(0.8)])      # 1.6 rad about z
    >>> reduced, li, ri = quat_reduce(p, right=quat_group("C4"))
    >>> float(np.round(2 * np.arccos(abs(reduced[0])), 12)), int(ri)  # 1.6 - pi/2
    (0.029203673205, 3)
    """
    q = as_array(quat, (4,), "quaternion")
    if dask_backend.any_dask(q):
        groups = [None if g is None else np.asarray(g) for g in (left, right)]
        fn = functools.partial(quat_reduce, left=groups[0], right=groups[1])
        return dask_backend.map_batched(fn, [q], [1], _relabel)
    xp = namespace_of(q)
    ident = [[1.0, 0.0, 0.0, 0.0]]
    L = asarray_like(ident if left is None else left, q)
    R = asarray_like(ident if right is None else right, q)
    L = as_array(L, (4,), "left group")
    R = as_array(R, (4,), "right group")
    if L.ndim != 2 or R.ndim != 2:
        raise RigidkitError("left and right groups must have shape (k, 4)")
    nl, nr = L.shape[0], R.shape[0]
    pr = _kq.quat_multiply(q[..., None, :], R)  # (..., nr, 4)
    sign = asarray_like([1.0, -1.0, -1.0, -1.0], q)
    # (..., nl, 4) @ (..., 4, nr): the scalar parts of l_i p r_j, left-major.
    w = xp.matmul(L * sign, pr.mT)
    best = xp.reshape(xp.abs(w), tuple(w.shape[:-2]) + (nl * nr,)).argmax(-1)
    li = best // nr
    ri = best % nr
    reduced = _kq.quat_compose(_kq.quat_compose(take_rows(L, li), q), take_rows(R, ri))
    return reduced, li, ri
