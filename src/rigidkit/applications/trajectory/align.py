"""Aligning an estimated trajectory to a reference one."""

from __future__ import annotations

import numpy as np

from ..._engine.namespace import namespace_of
from ..._validate import raise_unless
from ...errors import DegenerateInputError
from ...objects.rotation import Rotation
from ...objects.similarity import Similarity
from ...objects.transform import Transform
from ..alignment import align_points
from .trajectory import check_pair

__all__ = ["METHODS", "align"]

METHODS = ("se3", "sim3", "scale", "yaw", "origin", "none")


def _yaw_fit(src, dst):
    """4-DoF fit: rotation about ``z`` and translation taking ``src`` onto ``dst``.

    Minimises ``sum |dst_i - (Rz(psi) src_i + t)|^2`` in closed form: with the
    centred points, ``psi = atan2(sum (x_s y_d - y_s x_d), sum (x_s x_d + y_s
    y_d))`` and ``t = mean(dst) - Rz mean(src)`` (the 4-DoF alignment of Zhang &
    Scaramuzza 2018, Sec. IV, for visual-inertial odometry, where gravity makes
    roll and pitch observable). Batched over the leading axes.
    """
    xp = namespace_of(src, dst)
    n = src.shape[-2]
    ms, md = xp.sum(src, axis=-2) / n, xp.sum(dst, axis=-2) / n
    a, b = src - ms[..., None, :], dst - md[..., None, :]
    sin = xp.sum(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0], axis=-1)
    cos = xp.sum(a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1], axis=-1)
    raise_unless(
        (sin != 0.0) | (cos != 0.0),
        DegenerateInputError,
        "yaw alignment: the positions do not move in the x-y plane, so no yaw "
        "can be fitted",
    )
    psi = xp.atan2(sin, cos)
    zero = xp.zeros_like(psi)
    R = Rotation.from_rotvec(xp.stack([zero, zero, psi], axis=-1))
    return Transform(rotation=R, translation=md - R.apply(ms))


def align(est, ref, method="se3", first=None):
    """``est`` moved onto ``ref``: ``(aligned_est, ref_S_est)``.

    The fit uses the positions of corresponding poses (associate the two first,
    :func:`rigidkit.trajectory.associate`).

    Parameters
    ----------
    est, ref : Trajectory
        Of equal length ``N``; batches of shape ``(..., N)`` align each pair at
        once (one transform per pair).
    method : {"se3", "sim3", "scale", "yaw", "origin", "none"}
        ``"se3"``: the rigid motion minimising ``sum |p_ref - (R p_est + t)|^2``
        (Umeyama 1991, without scale); ``"sim3"``: with the scale ``s`` too
        (Umeyama 1991, eq. 42, for monocular estimates); ``"scale"``: only that
        Umeyama scale, about the world origin (evo's ``correct_only_scale``);
        ``"yaw"``: translation and a rotation about the gravity axis ``z`` (4-DoF,
        Zhang & Scaramuzza 2018); ``"origin"``: the motion that makes the first
        poses coincide, ``ref_0 est_0^-1``; ``"none"``: the identity.
    first : int, optional
        Fit on the first ``first`` pairs only (all by default); the transform
        moves every pose.

    Returns
    -------
    aligned_est : Trajectory
        ``ref_S_est`` applied to every pose of ``est`` (:meth:`Trajectory.transform`).
    ref_S_est : Transform or Similarity
        A :class:`~rigidkit.Similarity` for ``"sim3"`` and ``"scale"``, else a
        :class:`~rigidkit.Transform`; batch shape ``(...)``.

    Raises
    ------
    DegenerateInputError
        Fewer than 3 pairs, or positions on one line (``se3``, ``sim3``, ``scale``).

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> ref = rk.Trajectory(None, rk.Transform.random(10, rng=0))
    >>> S = rk.Similarity(scale=0.5, rotation=rk.Rotation.random(rng=1),
    ...                   translation=[1.0, 2.0, 3.0])
    >>> est = ref.transform(S)
    >>> aligned, ref_S_est = rk.trajectory.align(est, ref, method="sim3")
    >>> round(float(ref_S_est.scale), 12)
    2.0
    >>> bool(np.allclose(aligned.positions, ref.positions, atol=1e-12))
    True
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}; got {method!r}")
    check_pair(("est", est), ("ref", ref), "align")
    lead = np.broadcast_shapes(est.shape[:-1], ref.shape[:-1])
    n = len(est) if first is None else int(first)
    if not 1 <= n <= len(est):
        raise ValueError(f"first must be in [1, {len(est)}], got {first!r}")
    if method == "none":
        S = Transform()
        if lead:
            S = Transform.from_pq(np.broadcast_to(S.as_pq(), lead + (7,)))
        return est.transform(S) if lead else est, S
    if method == "origin":
        S = ref.poses[..., 0].compose(est.poses[..., 0].inv())  # @ would not compile
        return est.transform(S), S
    # The positions of the poses' namespace: on torch and JAX the fit, and the
    # transform it applies, are differentiable (the SVD of Umeyama's method, for
    # distinct singular values).
    src = est.positions[..., :n, :]
    dst = ref.positions[..., :n, :]
    if method == "yaw":
        shape = np.broadcast_shapes(src.shape, dst.shape)
        xp = namespace_of(src, dst)
        S = _yaw_fit(xp.broadcast_to(src, shape), xp.broadcast_to(dst, shape))
    else:
        S = align_points(src, dst, scale=method != "se3")
        if method == "scale":
            S = Similarity(scale=S.scale)
    return est.transform(S), S
