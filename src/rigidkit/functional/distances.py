"""Distances between rotations (arrays in and out).

=================  ====================================================  =========
geodesic angle     ``theta = |log(R1^T R2)|``, the angle of the relative  [0, pi]
                   rotation (the Riemannian distance on SO(3)):
                   :func:`rigidkit.conversions.quat_angle_between`
chordal distance   ``|R1 - R2|_F = 2 sqrt(2) sin(theta / 2)``, the        [0, 2.83]
                   Frobenius norm of the matrix difference (Hartley et
                   al. 2013, "Rotation averaging")
=================  ====================================================  =========

Both are invariant (``d(A R1 B, A R2 B) = d(R1, R2)``) and independent of the
quaternion signs. Quaternions Hamilton, scalar first.

>>> import numpy as np
>>> q1 = [1.0, 0.0, 0.0, 0.0]
>>> q2 = [0.0, 0.0, 0.0, 1.0]                     # a half turn about z
>>> float(np.round(chordal_distance(q1, q2) ** 2, 12))  # |diag(2, 2, 0)|^2
8.0
"""

from __future__ import annotations

import math

from .._engine.namespace import namespace_of
from .conversions import quat_angle_between, quat_angle_between_unchecked

__all__ = ["chordal_distance", "chordal_distance_unchecked"]


def chordal_distance(quat1, quat2):
    """Frobenius norm ``|R1 - R2|_F`` of rotations given as quaternions, shape (...).

    ``|R1 - R2|_F^2 = 2 (3 - tr(R1^T R2)) = 8 sin^2(theta / 2)``, so it is
    ``2 sqrt(2) sin(theta / 2)`` of the geodesic angle ``theta`` (computed by
    ``atan2``, no cancellation near 0 or pi), accurate to a few ulp *relative*.
    Both inputs are normalised first (validated); batch shapes broadcast.

    Parameters
    ----------
    quat1, quat2 : array_like, shape (..., 4)

    Returns
    -------
    array, shape (...)
        In [0, 2 sqrt(2)].
    """
    return _from_angle(quat_angle_between(quat1, quat2))


def chordal_distance_unchecked(quat1, quat2):
    """:func:`chordal_distance` for unit quaternions, without normalising or checks."""
    return _from_angle(quat_angle_between_unchecked(quat1, quat2))


def _from_angle(theta):
    xp = namespace_of(theta)
    return (2.0 * math.sqrt(2.0)) * xp.sin(0.5 * theta)
