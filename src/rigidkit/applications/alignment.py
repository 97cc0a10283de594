"""Rotations and rigid motions from data: ``rk.align_vectors`` and ``rk.align_points``.

``align_vectors(a, b)`` returns the rotation ``A_R_B`` with ``a_i ~ A_R_B @ b_i``
(scipy's order) that minimises the weighted squared residuals (Wahba's problem,
Kabsch's SVD with the reflection fix); ``align_points(src, dst)`` the transform
``dst_T_src`` with ``dst_i ~ dst_T_src @ src_i`` (Kabsch on centred points), or a
similarity with ``scale=True`` (Umeyama). Both are batched: inputs ``(..., N, 3)``
give ``...`` problems at once. The algorithms are in
:mod:`rigidkit.functional.alignment`.
"""

from __future__ import annotations

from ..functional import alignment as _fa
from ..objects.registry import spec
from ..objects.rotation import Rotation
from ..objects.transform import Transform

__all__ = ["align_vectors", "align_points"]


def align_vectors(a, b, weights=None, *, return_sensitivity=False):
    """The rotation ``R`` minimising ``sum_i w_i |a_i - R b_i|^2``, and its residual.

    Exact (to rounding) for noiseless data, for a single pair (the shortest arc
    from ``b`` to ``a``) and when all vectors are parallel or antiparallel (the
    rotation about their line is then undetermined; the shortest arc is returned).

    Parameters
    ----------
    a : array_like, shape (..., N, 3)
        Vectors in frame A.
    b : array_like, shape (..., N, 3)
        The same vectors in frame B; batch shapes broadcast (only they: the
        numbers of pairs ``N`` must be equal).
    weights : array_like, shape (..., N), optional
        Non-negative weights (equal if omitted). One weight of a problem may be
        ``inf``: that pair is then aligned exactly and the others only fix the
        turn about it (scipy's primary vector).
    return_sensitivity : bool
        Also return the sensitivity matrix (Markley 1993): times the variance
        of the vectors' angular errors, the covariance of the rotation vector
        error of ``R``; see :func:`rigidkit.functional.alignment.kabsch`.

    Returns
    -------
    rotation : Rotation, shape (...)
        ``A_R_B``.
    rssd : array, shape (...)
        ``sqrt(sum_i w_i |a_i - R b_i|^2)``, computed from the residuals (noiseless
        data gives ~1e-15, not the ~1e-7 of scipy's cancelling formula); an
        infinitely weighted pair counts 0.
    sensitivity : array, shape (..., 3, 3)
        Only with ``return_sensitivity=True``.

    Raises
    ------
    ShapeError
        Different numbers of pairs in ``a`` and ``b``; ``weights`` not of shape
        ``(..., N)``.
    DegenerateInputError
        Negative weights, all pairs zero or of zero weight, more than one
        infinite weight in a problem, or a sensitivity asked for with one.
    NonFiniteError
        NaN or infinity in the input (other than an ``inf`` weight).

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> A_R_B = rk.Rotation.from_rotvec([0.1, 0.2, 0.3])
    >>> b = np.random.default_rng(0).standard_normal((20, 3))
    >>> R, rssd = rk.align_vectors(A_R_B @ b, b)
    >>> bool(R.approx_equal(A_R_B, atol=1e-14)), bool(rssd < 1e-13)
    (True, True)
    >>> R, rssd, sensitivity = rk.align_vectors(A_R_B @ b, b, return_sensitivity=True)
    >>> sensitivity.shape
    (3, 3)
    """
    out = _fa.kabsch(a, b, weights, return_sensitivity=return_sensitivity)
    return (spec(Rotation).wrap(out[0]),) + tuple(out[1:])


def align_points(src, dst, weights=None, *, scale=False):
    """The rigid motion (or similarity) taking points ``src`` onto ``dst``.

    Minimises ``sum_i w_i |dst_i - T @ src_i|^2`` over rigid motions ``T``
    (``scale=False``: Kabsch on the weighted centroids) or similarities
    ``p -> s R p + t`` (``scale=True``: Umeyama 1991).

    Parameters
    ----------
    src, dst : array_like, shape (..., N, 3)
        Corresponding points, ``N >= 3`` of them not collinear; batch shapes
        broadcast.
    weights : array_like, shape (..., N), optional
        Non-negative weights (equal if omitted).
    scale : bool
        Also fit a uniform scale.

    Returns
    -------
    Transform or Similarity, shape (...)
        ``dst_T_src``.

    Raises
    ------
    DegenerateInputError
        Fewer than 3 points; weights negative or summing to zero; points (of
        positive weight) coincident or collinear, naming the batch index.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> dst_T_src = rk.Transform.exp([0.5, -1.0, 2.0, 0.1, 0.2, 0.3])
    >>> src = np.random.default_rng(0).standard_normal((10, 3))
    >>> T = rk.align_points(src, dst_T_src @ src)
    >>> bool(T.approx_equal(dst_T_src, atol=1e-13))
    True
    """
    pose = _fa.umeyama(src, dst, weights, scale=scale)
    if scale:
        from ..objects.similarity import Similarity

        return spec(Similarity).wrap(pose)
    return spec(Transform).wrap(pose)
