"""``Trajectory``: a time-stamped sequence of poses."""

from __future__ import annotations

import numpy as np

from ..._engine.namespace import is_torch, namespace_of
from ..._validate import checks_now, concrete, dynamo_traces, to_numpy
from ...errors import OutOfRangeError, ShapeError, TimestampError
from ...objects._batch import expect
from ...objects.similarity import Similarity
from ...objects.transform import Transform
from ..interpolation import Slerp
from ..kinematics import twist_from_samples
from ..splines import BSplineSE3

__all__ = ["Trajectory", "check_stamps", "check_pair", "host_stamps"]


def _moveaxis(x, source: int, destination: int):
    """``np.moveaxis`` for an array of any namespace (NumPy, torch, JAX)."""
    if isinstance(x, np.ndarray):
        return np.moveaxis(x, source, destination)
    perm = list(range(x.ndim))
    perm.insert(destination % x.ndim, perm.pop(source % x.ndim))
    if is_torch(x):
        return x.permute(*perm)
    return namespace_of(x).permute_dims(x, tuple(perm))


def _foreign(x) -> bool:
    """Whether ``x`` is an array of another namespace (torch, JAX, Dask), kept in it."""
    return (
        hasattr(x, "shape")
        and hasattr(x, "dtype")
        and not isinstance(x, (np.ndarray, np.generic))
    )


def _check_values(t, what):
    """The value checks of :func:`check_stamps` on a NumPy array ``t``."""
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.argmax(bad))
        raise TimestampError(f"{what}[{i}] is {float(t[i])!r}, not finite", index=(i,))
    if t.shape[0] > 1:
        step = np.diff(t)
        if not (step > 0.0).all():
            i = int(np.argmax(~(step > 0.0))) + 1
            how = "repeats" if step[i - 1] == 0.0 else "goes backwards from"
            raise TimestampError(
                f"{what}[{i}] = {float(t[i])!r} {how} "
                f"{what}[{i - 1}] = {float(t[i - 1])!r}; "
                "stamps must be strictly increasing",
                index=(i,),
            )


def check_stamps(stamps, n: int, what: str = "stamps"):
    """``stamps`` as an array of shape ``(n,)``, validated.

    NumPy input (and lists) gives a read-only float64 copy. An array of another
    namespace (torch, JAX, Dask) is kept in it, so that its stamps stay on the
    caller's graph (autograd, tracing, lazy Dask); its values are checked only
    where they can be read now (not under tracing, not on Dask, and never with
    ``rk.set_validation(False)``).

    Raises :class:`~rigidkit.ShapeError` for a wrong shape and
    :class:`~rigidkit.TimestampError` (with ``.index``, the first offending
    position) for a non-finite stamp or one not after its predecessor.
    """
    if _foreign(stamps):
        shape = tuple(stamps.shape)
        if shape != (n,):
            raise ShapeError(f"{what} must have shape ({n},) (one per pose), got {shape}")
        if "float" not in str(stamps.dtype):
            stamps = stamps.double() if is_torch(stamps) else stamps.astype(np.float64)
        if checks_now(stamps):
            _check_values(np.asarray(to_numpy(stamps), dtype=np.float64), what)
        return stamps
    t = np.array(stamps, dtype=np.float64)  # a copy: the caller keeps its array
    if t.shape != (n,):
        raise ShapeError(f"{what} must have shape ({n},) (one per pose), got {t.shape}")
    if not dynamo_traces():  # while torch.compile traces, NumPy is a graph value
        _check_values(t, what)
        t.flags.writeable = False
    return t


def host_stamps(stamps):
    """``stamps`` (NumPy, or concrete torch or JAX) as NumPy float64, for the
    searches and sorts of the stamps, which run on the host."""
    if stamps is None or isinstance(stamps, np.ndarray):
        return stamps
    return np.asarray(to_numpy(stamps), dtype=np.float64)


class Trajectory:
    """A sequence of poses ``W_T_B`` at strictly increasing times.

    Immutable, like the other rigidkit objects. The time axis is the last batch
    axis of ``poses``: a ``Transform`` of shape ``(N,)`` is one trajectory, one of
    shape ``(B, N)`` is ``B`` trajectories at the same stamps (the batched form
    that :func:`rigidkit.trajectory.align` and the metrics accept).

    Parameters
    ----------
    stamps : array_like, shape (N,), or None
        Times in seconds, finite and strictly increasing; ``None`` where the
        source has none (a KITTI file): the index then stands in for time where
        one is needed (:meth:`velocities`, :meth:`at`).
    poses : Transform, shape (..., N)
        The poses, ``W_T_B`` (body in world), on any array backend.

    Raises
    ------
    TimestampError
        A stamp is not finite or not after the one before it (``.index`` names it).
    ShapeError
        ``stamps`` does not have one entry per pose.

    Examples
    --------
    >>> import numpy as np
    >>> import rigidkit as rk
    >>> poses = rk.Transform(translation=[[0.0, 0, 0], [3.0, 0, 0], [3.0, 4.0, 0]])
    >>> traj = rk.Trajectory([0.0, 1.0, 2.0], poses)
    >>> len(traj), traj.path_length, traj.duration
    (3, 7.0, 2.0)
    >>> traj[1:].positions
    array([[3., 0., 0.],
           [3., 4., 0.]])
    >>> traj.at([0.5]).positions
    array([[1.5, 0. , 0. ]])
    """

    __slots__ = ("_stamps", "_poses")

    def __init__(self, stamps, poses):
        if not isinstance(poses, Transform):
            poses = expect(poses, Transform, "poses")  # says which constructor to call
        if poses.single:
            raise ShapeError("a Trajectory needs poses with a time axis, shape (..., N)")
        n = poses.shape[-1]
        self._stamps = None if stamps is None else check_stamps(stamps, n)
        self._poses = poses

    @classmethod
    def _trusted(cls, stamps, poses):
        """Without checks: ``stamps`` already validated (a subset in order)."""
        self = object.__new__(cls)
        self._stamps, self._poses = stamps, poses
        return self

    # -- contents ----------------------------------------------------------------------
    @property
    def stamps(self):
        """Times in seconds, shape (N,), read-only; ``None`` where there are none."""
        return self._stamps

    @property
    def poses(self) -> Transform:
        """The poses, a :class:`~rigidkit.Transform` of shape ``(..., N)``."""
        return self._poses

    @property
    def shape(self) -> tuple:
        """The batch shape of the poses, ``(..., N)``."""
        return self._poses.shape

    def __len__(self):
        return self._poses.shape[-1]

    def __bool__(self):
        return len(self) > 0

    def __getitem__(self, index):
        """Poses and stamps along the time axis.

        A slice, a boolean mask of shape (N,) or an array of increasing indices
        gives a :class:`Trajectory`; a single int gives that pose, a
        :class:`~rigidkit.Transform`.
        """
        if isinstance(index, (int, np.integer)):
            return self._poses[..., int(index)]
        if isinstance(index, slice):
            stamps = None if self._stamps is None else self._stamps[index]
            return Trajectory._trusted(stamps, self._poses[..., index])
        idx = np.asarray(index)
        if idx.dtype == bool:
            if idx.shape != (len(self),):
                raise ShapeError(
                    f"a boolean index needs shape ({len(self)},), got {idx.shape}"
                )
            idx = np.flatnonzero(idx)
        elif idx.dtype.kind not in "iu" or idx.ndim != 1:
            raise TypeError(
                "index a Trajectory with an int, a slice, a boolean mask or a 1-D "
                f"array of ints; got {index!r}"
            )
        idx = np.where(idx < 0, idx + len(self), idx)
        poses = self._poses[..., idx]
        if self._stamps is None:
            return Trajectory._trusted(None, poses)
        return Trajectory(self._stamps[idx], poses)  # checks the order

    def __iter__(self):
        raise TypeError("iterate over traj.poses or traj.stamps")

    def __repr__(self):
        span = (
            ""
            if self._stamps is None or not len(self) or not concrete(self._stamps)
            else f", t in [{float(self._stamps[0])!r}, {float(self._stamps[-1])!r}]"
        )
        return f"Trajectory({len(self)} poses{span}, shape={self.shape})"

    @property
    def positions(self):
        """Positions ``W_p_B``, shape (..., N, 3)."""
        return self._poses.translation

    @property
    def path_length(self):
        """Length of the polyline through the positions: ``sum |p_{i+1} - p_i|``.

        A float for one trajectory, an array of shape (...) for a batch; for
        poses on torch or JAX, an array of their namespace (0-d for one
        trajectory), which autograd follows.
        """
        p = self.positions
        if not isinstance(p, np.ndarray):  # torch, JAX: in their namespace (autograd)
            xp = namespace_of(p)
            step = p[..., 1:, :] - p[..., :-1, :]
            return xp.sum(xp.sqrt(xp.sum(step * step, axis=-1)), axis=-1)
        total = np.linalg.norm(np.diff(p, axis=-2), axis=-1).sum(axis=-1)
        return float(total) if total.ndim == 0 else total

    @property
    def duration(self) -> float:
        """``stamps[-1] - stamps[0]`` in seconds (0 for fewer than two poses).

        A float for NumPy stamps; a 0-d array of the stamps' namespace for torch,
        JAX or Dask stamps (differentiable, lazy on Dask).
        """
        if self._stamps is None:
            raise TimestampError("this trajectory has no stamps, so no duration")
        t = self._stamps
        if not isinstance(t, np.ndarray):  # torch, JAX, Dask: in their namespace
            return t[-1] - t[0] if len(self) > 1 else t[:1].sum() * 0.0
        return float(t[-1] - t[0]) if len(self) > 1 else 0.0

    def _times(self):
        """The stamps on the host (NumPy), the index where there are none."""
        if self._stamps is not None:
            return host_stamps(self._stamps)
        return np.arange(len(self), dtype=np.float64)

    # -- operations --------------------------------------------------------------------
    def at(self, times, method="slerp"):
        """The poses at ``times`` (seconds), as a new :class:`Trajectory`.

        Parameters
        ----------
        times : array_like, shape (M,)
            Strictly increasing, within ``[stamps[0], stamps[-1]]``.
        method : {"slerp", "linear", "spline"}
            ``"slerp"``: the SE(3) geodesic (screw motion) between the two poses
            around each time, ``T_i exp(a log(T_i^-1 T_{i+1}))``, ``a`` the
            fraction of the interval (Sola et al. 2018, eq. 178).
            ``"linear"``: positions linearly and rotations by slerp, each on its
            own (what motion-capture tools do). ``"spline"``: a C2-smooth
            :class:`~rigidkit.BSplineSE3` whose control points are the poses
            resampled (slerp) on a uniform grid of ``N`` times over the same span;
            it approximates the poses (a cubic B-spline does not pass through
            its control points).

        Returns
        -------
        Trajectory
            Stamped ``times``; its poses in the namespace of this trajectory's
            (torch, JAX: autograd follows them; the times and the search for
            their intervals stay NumPy float64).

        Raises
        ------
        OutOfRangeError
            A time outside the stamps' range (the message names the range).
        """
        t = self._times()
        # .shape where there is one: np.shape of an array TorchDynamo traces is no int
        shape = tuple(times.shape) if hasattr(times, "shape") else np.shape(times)
        n = shape[0] if shape else -1
        q = host_stamps(check_stamps(times, n, "times"))
        if len(t) < 2:
            raise OutOfRangeError(f"interpolation needs at least 2 poses, got {len(t)}")
        # (checks_now: not while torch.compile traces the NumPy times, nor with
        # rk.set_validation(False), as every check that reads values)
        if len(q) and checks_now(q) and (q[0] < t[0] or q[-1] > t[-1]):
            bad = q[0] if q[0] < t[0] else q[-1]
            raise OutOfRangeError(
                f"time {float(bad)!r} lies outside the trajectory's range "
                f"[{float(t[0])!r}, {float(t[-1])!r}]",
                index=(int(np.argmax((q < t[0]) | (q > t[-1]))),),
            )
        lead = self.shape[:-1]
        # Slerp and the spline take the time axis first.
        # The poses stay in their namespace (torch, JAX): Slerp takes NumPy times
        # and interpolates keyframes of any namespace, autograd included.
        keys = (
            Transform.from_pq(_moveaxis(self._poses.as_pq(), -2, 0))
            if lead
            else self._poses
        )
        if method in ("slerp", "linear"):
            out = Slerp(t, keys, decoupled=method == "linear")(q)
        elif method == "spline":
            grid = np.linspace(t[0], t[-1], len(t))
            grid[-1] = t[-1]
            ctrl = Slerp(t, keys)(grid)
            # Doubling the end control points puts the spline's knots k at
            # grid[k], each blending (c_{k-1}, c_k, c_{k+1}) around c_k.
            ctrl = Transform.concatenate([ctrl[:1], ctrl, ctrl[-1:]])
            dt = (t[-1] - t[0]) / (len(t) - 1)
            spline = BSplineSE3(ctrl, dt=dt, t0=float(t[0]))
            # t_max may round below t[-1]; while torch.compile traces it is a symbol
            # no array op takes, and the range check that needs the clamp is off
            out = spline(np.minimum(q, t[-1] if dynamo_traces() else spline.t_max))
        else:
            raise ValueError(
                f"method must be 'slerp', 'linear' or 'spline', got {method!r}"
            )
        if lead:
            out = Transform.from_pq(_moveaxis(out.as_pq(), 0, -2))
        return Trajectory._trusted(q, out)

    def transform(self, S):
        """Every pose left-multiplied by ``S``: ``S @ T_i`` (a change of world frame).

        ``S`` is a :class:`~rigidkit.Transform` or a
        :class:`~rigidkit.Similarity`; a similarity also scales the positions,
        ``(s R R_i, s R p_i + t)`` with the rotations ``R R_i``. A batch of ``S``
        of shape ``(...)`` applies to a batch of trajectories ``(..., N)``.

        >>> import rigidkit as rk
        >>> traj = rk.Trajectory(None, rk.Transform(translation=[[1.0, 0, 0], [2.0, 0, 0]]))
        >>> traj.transform(rk.Similarity(scale=2.0)).positions
        array([[2., 0., 0.],
               [4., 0., 0.]])
        """
        if not isinstance(S, (Transform, Similarity)):
            raise TypeError(
                f"S must be a Transform or a Similarity, got {type(S).__name__}"
            )
        if not S.single:
            S = S.reshape(S.shape + (1,))
        # compose, not @: TorchDynamo (torch 2.13) traces no @ between two objects
        if isinstance(S, Transform):
            return Trajectory._trusted(self._stamps, S.compose(self._poses))
        rotation = S.rotation.compose(self._poses.rotation)
        translation = S.apply(self.positions)
        return Trajectory._trusted(
            self._stamps, Transform(rotation=rotation, translation=translation)
        )

    def velocities(self, frame):
        """Twists ``(v, omega)`` at each pose, shape (..., N, 6), from the samples.

        :func:`rigidkit.kinematics.twist_from_samples` on the stamps (the index
        where there are none): ``frame="body"`` gives ``vee(T^-1 dT/dt)``,
        ``"world"`` ``vee(dT/dt T^-1)``.
        """
        t = self._times()
        if not isinstance(self._poses.translation, np.ndarray):
            t = np.array(t)  # writable: torch warns on a read-only NumPy array
        return twist_from_samples(self._poses, t, frame=frame)


def check_pair(first, second, purpose: str) -> None:
    """Two ``(name, trajectory)`` pairs: both a :class:`Trajectory`, of one length.

    ``purpose`` completes the length error ("align", "compare"): corresponding
    poses are what :func:`rigidkit.trajectory.associate` returns.
    """
    for name, traj in (first, second):
        if not isinstance(traj, Trajectory):
            raise TypeError(f"{name} must be a Trajectory, got {type(traj).__name__}")
    (n1, t1), (n2, t2) = first, second
    if len(t1) != len(t2):
        raise ShapeError(
            f"{n1} has {len(t1)} poses and {n2} {len(t2)}: {purpose} corresponding "
            "poses (rigidkit.trajectory.associate pairs them)"
        )
