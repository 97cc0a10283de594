"""The samples of one edge of a :class:`~rigidkit.FrameGraph`, and their interpolation.

An edge ``parent -> child`` holds ``parent_T_child``: one pose (a static edge) or a
time-ordered buffer of stamped poses (a dynamic edge). The buffer is written by
one thread at a time (the graph's lock) and read by any number of threads without
it: a reader takes a :class:`Snapshot` (views of the arrays) under the lock and
computes outside it. That is safe because the stored samples are never written in
place: a new newest sample goes into spare capacity past the end of every
snapshot, dropping old samples only moves the start, and anything else (an
out-of-order sample, a repeated stamp, a full buffer) builds new arrays.
"""

from __future__ import annotations

import numpy as np

from ..._engine import dask_backend
from ..._engine.namespace import device_of, namespace_of
from ...errors import EdgeKindError, ExtrapolationError
from ...kernels.geodesic import pose_slerp as _slerp_screw
from ...kernels.geodesic import pose_slerp_decoupled as _slerp_decoupled
from ...kernels.geodesic import pose_slerp_segment as _slerp_segment
from ...kernels.quaternion import quat_multiply as _quat_multiply
from ...kernels.se3 import pose_compose as _pose_compose
from ...kernels.se3 import pose_from_twist as _pose_from_twist
from ...objects import registry
from ...objects.transform import Transform
from ..interpolation import slerp
from .samples import _foreign, as_samples

__all__ = ["EdgeBuffer", "Snapshot", "as_samples", "wrap_pq"]

#: Rows ``(w, x, y, z, tx, ty, tz)`` (a Transform's stored layout; called ``pq``
#: in this package) as a ``Transform`` without re-validation:
#: every stored row went through ``Transform.from_pq`` (normalised) on insertion.
wrap_pq = registry.spec(Transform).wrap

_CONJUGATE = np.array([1.0, -1.0, -1.0, -1.0])
_array = np.array
_EXTRAPOLATE = (None, "clamp", "hold")
_INTERPOLATION = ("decoupled", "screw")


class Snapshot:
    """What a lookup reads of one edge: arrays that no writer changes afterwards.

    ``t`` (N,) stamps (None for a static edge), ``pq`` (N, 7), ``cov`` (N, 6, 6)
    or None; ``parent`` and ``child`` name the edge for error messages.
    """

    __slots__ = ("parent", "child", "t", "pq", "cov", "pose", "_inc", "_last")

    def __init__(self, parent, child, t, pq, cov):
        self.parent, self.child, self.t, self.pq, self.cov = parent, child, t, pq, cov
        self._inc = {}
        self._last = None
        #: a static edge's pose, made once (snapshots are cached by their buffer)
        self.pose = wrap_pq(pq[0]) if t is None else None

    @property
    def static(self):
        return self.t is None

    def check_one(self, q, extrapolate):
        """:meth:`check` of one time, a Python float (the single lookup's path)."""
        t0, t1 = float(self.t[0]), float(self.t[-1])
        if q < t0:
            if extrapolate == "clamp":
                return t0
            raise self.extrapolation_error(q, "past")
        if q > t1:
            if extrapolate is not None:
                return t1
            raise self.extrapolation_error(q, "future")
        return q

    def at_one(self, q, interpolation, want_cov=False):
        """:meth:`at` of one time (a float within range): a single ``Transform``.

        The last segment used is kept (successive lookups mostly fall in the
        same one): its index, ends and poses, replaced as a whole (one tuple) so
        that threads sharing the snapshot each see a consistent segment. Between
        its ends the pose is ``rk.slerp``'s kernel on the two stored rows (valid
        poses, so called without the objects' checks; ``a`` is finite).
        """
        seg = self._last
        if seg is None or not (seg[1] <= q < seg[2]):
            t = self.t
            n = t.shape[0]
            if n == 1:
                return wrap_pq(self.pq[0]), (
                    self.cov[0] if want_cov and self.cov is not None else None
                )
            i = min(max(int(t.searchsorted(q, side="right")) - 1, 0), n - 2)
            seg = self._last = (i, float(t[i]), float(t[i + 1]), self.pq[i], self.pq[i + 1])
        i, t0, t1, x0, x1 = seg
        a = (q - t0) / (t1 - t0)
        if a == 0.0:  # at a sample (slerp's value at 0 too, without the call)
            T = wrap_pq(x0)
        else:
            kernel = _slerp_decoupled if interpolation == "decoupled" else _slerp_screw
            T = wrap_pq(kernel(x0, x1, _array(a)))
        cov = None
        if want_cov and self.cov is not None:
            cov = self.cov[i] if a == 0.0 else (1.0 - a) * self.cov[i] + a * self.cov[i + 1]
        return T, cov

    def check(self, q, extrapolate):
        """``q`` (float64 array) after the range test: raises or clamps.

        Raises :class:`~rigidkit.ExtrapolationError` for a time outside
        ``[t[0], t[-1]]`` (``extrapolate=None``), for one before ``t[0]``
        (``"hold"``, which holds only the newest pose into the future).
        """
        t0, t1 = self.t[0], self.t[-1]
        below = q < t0
        above = q > t1
        past = bool(below.any())
        future = bool(above.any())
        if not (past or future):
            return q
        if extrapolate == "clamp" or (extrapolate == "hold" and not past):
            return np.clip(q, t0, t1)
        mask = below if past else above
        i = int(np.argmax(mask))
        raise self.extrapolation_error(
            float(q.reshape(-1)[i]), "past" if past else "future"
        )

    def extrapolation_error(self, time, direction):
        t0, t1 = float(self.t[0]), float(self.t[-1])
        where = "before" if direction == "past" else "after"
        return ExtrapolationError(
            f"edge {self.parent!r} -> {self.child!r}: time {time!r} is {where} its "
            f"data [{t0!r}, {t1!r}] ({len(self.t)} samples); extrapolation into "
            f"the {direction}",
            edge=(self.parent, self.child),
            range=(t0, t1),
            direction=direction,
        )

    def index(self, q):
        """Segment index ``i`` of each time: between ``t[i]`` and ``t[i + 1]``
        (``q`` already within range, at least two samples).

        ``i`` is the number of interior stamps ``t[1], ..., t[N - 2]`` at or before
        each time (``searchsorted(t, q, "right") - 1``, clipped to the last
        segment). Times in increasing order (a replay, a resampling, more of them
        than samples) are counted from the other side (:meth:`_runs`) instead of
        by a binary search per time (``O(M log N)``, ~10x slower at M = 1e5, N =
        2,000).
        """
        runs = self._runs(q)
        if runs is not None:
            return np.repeat(np.arange(self.t.shape[0] - 1), runs)
        i = self.t.searchsorted(q, side="right") - 1
        np.clip(i, 0, self.t.shape[0] - 2, out=i)
        return i

    def bounds(self, q):
        """For times ``q`` in increasing order and more of them than samples:
        where each segment's times begin, (N,) with ``0`` first and ``M`` last,
        from where each interior stamp falls among the times (``O(N log M)``);
        else None."""
        t = self.t
        n, m = t.shape[0], q.shape[0]
        if m <= n or (q[1:] < q[:-1]).any():
            return None
        ends = np.empty(n, dtype=np.intp)
        ends[0], ends[-1] = 0, m
        ends[1:-1] = q.searchsorted(t[1:-1], side="left")
        return ends

    def _runs(self, q, span=None):
        """How many of the times ``q`` fall in each segment (N - 1,), or None
        (:meth:`bounds`). ``span = (bounds, lo)``: ``q`` is the block of the
        call's times from ``lo`` on, whose bounds were found once for the call
        (a search per block and edge cost 5% of a lookup at 1e5 times)."""
        if span is None:
            ends = self.bounds(q)
            return None if ends is None else ends[1:] - ends[:-1]
        ends, lo = span
        ends = np.minimum(np.maximum(ends, lo), lo + q.shape[0])  # np.clip: 3x slower
        return ends[1:] - ends[:-1]

    def rows(self, q, span=None):
        """The rows of :meth:`increments` ``("decoupled")`` of each time's segment
        (``span``: see :meth:`_runs`)."""
        table = self.increments("decoupled")
        runs = self._runs(q, span)
        if runs is not None:  # a run of one row per segment: ~12% faster than take
            return np.repeat(table, runs, axis=0)
        return np.take(table, self.index(q), axis=0)

    def locate(self, q, many=None):
        """Segment index ``i`` (:meth:`index`) and fraction ``a`` of each time
        (``i = 0``, ``a = 0`` for one sample)."""
        t = self.t
        n = t.shape[0]
        if n == 1:
            return np.zeros(q.shape, dtype=np.intp), np.zeros(q.shape)
        i = self.index(q)
        a = q - np.take(t, i)
        if 4 * (q.shape[0] if many is None else many) >= n:  # once per snapshot
            a /= np.take(self.increments("steps"), i)
        else:  # few times on a long buffer: O(M)
            a /= np.take(t, i + 1) - np.take(t, i)
        return i, a

    def at(self, q, interpolation, want_cov=False, *, many=None, span=None):
        """``parent_T_child`` at times ``q`` (shape (M,) array, within range).

        Returns ``(Transform of shape (M,), cov (M, 6, 6) or None)``. Between two
        samples: ``"decoupled"`` (tf2's rule) interpolates the translation
        linearly and slerps the rotation; ``"screw"`` follows the SE(3) geodesic
        ``T_i exp(a log(T_i^-1 T_{i+1}))`` (Sola et al. 2018, eq. 178). The
        covariance is interpolated linearly, ``(1 - a) C_i + a C_{i+1}``.
        ``many``: the call's total count of times when ``q`` is one block of it
        (the way of interpolating is chosen for the call, so a block's rows are
        those of the call without blocks); ``span = (bounds, lo)``: the call's
        times were in increasing order and ``bounds`` is their :meth:`bounds`,
        ``q`` those from ``lo`` on.

        At least a quarter as many times as samples (NumPy samples): from the
        per-segment tables of :meth:`increments`, taken once per snapshot. The
        decoupled rule is then one gather of a segment's row per time and one
        fused kernel, ``pose_slerp_segment`` (the fraction, the slerp from the
        segment's angle and axis, and the lerp in one pass): a 3-edge lookup at
        1e5 sorted times took 9.2 ms through a fraction pass, a relative slerp
        and a lerp (see ``benchmarks/bench_frames.py``).
        """
        many = q.shape[0] if many is None else many
        pq = self.pq
        cov = None
        if pq.shape[0] == 1:
            T = wrap_pq(np.broadcast_to(pq[0], q.shape + (7,)).copy())
            if want_cov and self.cov is not None:
                cov = np.broadcast_to(self.cov[0], q.shape + (6, 6)).copy()
            return T, cov
        tables = 4 * many >= pq.shape[0] and not _foreign(pq)
        want_cov = want_cov and self.cov is not None
        if tables and interpolation == "decoupled" and not want_cov:
            return wrap_pq(_slerp_segment(self.rows(q, span), q)), None
        i, a = self.locate(q, many)
        if tables:
            T = self._from_increments(i, a, interpolation)
        else:
            T = slerp(
                wrap_pq(pq[i]),
                wrap_pq(pq[i + 1]),
                a,
                decoupled=interpolation == "decoupled",
            )
        if want_cov:
            w = a[..., None, None]
            if _foreign(self.cov):  # torch, JAX, Dask: the weights in its namespace
                xp = namespace_of(self.cov)
                w = xp.asarray(w, dtype=self.cov.dtype, device=device_of(self.cov))
            cov = (1.0 - w) * self.cov[i] + w * self.cov[i + 1]
        return T, cov

    def premultiplied(self, S):
        """This edge with samples ``S T_i`` (``S`` a single ``Transform``): the same
        stamps and names (so the same errors), kept for the last ``S`` asked."""
        kept = self._inc.get("premultiplied")
        if kept is not None and kept[0] is S:
            return kept[1]
        pq = registry.stored(S @ wrap_pq(self.pq))
        snap = Snapshot(self.parent, self.child, self.t, pq, None)
        self._inc["premultiplied"] = (S, snap)  # one tuple: consistent for threads
        return snap

    def increments(self, interpolation):
        """Per-segment tables, computed once per snapshot (many times on one
        snapshot share them): ``log(T_i^-1 T_{i+1})`` (N - 1, 6) for ``"screw"``;
        for ``"decoupled"`` the rows ``(q_i, p_i, p_{i+1} - p_i, phi_i, u_i, t_i,
        t_{i+1} - t_i)`` (N - 1, 16) of
        :func:`~rigidkit.kernels.geodesic.pose_slerp_segment`, with
        ``q_i^* q_{i+1} = +-(cos phi_i, sin phi_i u_i)``, ``phi_i`` in [0, pi/2];
        ``"steps"``: ``t[i + 1] - t[i]`` (N - 1,)."""
        inc = self._inc.get(interpolation)
        if inc is None:
            if interpolation == "steps":
                inc = np.diff(self.t)
            elif interpolation == "screw":
                T = wrap_pq(self.pq)
                inc = np.asarray((T[:-1].inv() @ T[1:]).log())
            else:
                inc = _segments(self.pq, self.t, self.increments("steps"))
            self._inc[interpolation] = inc  # a race computes the same array twice
        return inc

    def _from_increments(self, i, a, interpolation):
        """The interpolant from :meth:`increments`: ``T_i exp(a xi_i)`` (screw), or
        ``q_i (q_i^* q_{i+1})^a`` with ``p_i + a (p_{i+1} - p_i)`` (decoupled): the
        geodesics of :func:`~rigidkit.slerp`, with the per-segment parts (the
        screw's log; the relative rotation's angle and axis) taken once instead
        of at every time. The stored rows are unit quaternions (normalised on
        insertion), so the kernels take them without the objects' validation.
        np.take: ~4x faster than fancy indexing for rows.
        """
        step = np.take(self.increments(interpolation), i, axis=0)
        if interpolation == "screw":
            step *= a[:, None]
            return wrap_pq(
                _pose_compose(np.take(self.pq, i, axis=0), _pose_from_twist(step))
            )
        step[:, 14] = 0.0  # the row's time: a = (a - 0) / 1
        step[:, 15] = 1.0
        return wrap_pq(_slerp_segment(step, a))

    def body_twist(self, q, interpolation):
        """Body twist ``vee(T^-1 dT/dt)`` of the interpolant at ``q``, shape (M, 6).

        Constant on each segment: ``log(T_i^-1 T_{i+1}) / dt`` for ``"screw"``;
        for ``"decoupled"``, ``(R(t)^T (p_{i+1} - p_i) / dt, log(R_i^T R_{i+1}) / dt)``
        (the rotation part is the body angular velocity of the slerp). Zero for
        a static edge or a single sample.
        """
        if self.t is None or self.t.shape[0] == 1:
            return np.zeros(q.shape + (6,))
        i, _ = self.locate(q)
        dt = (self.t[i + 1] - self.t[i])[:, None]
        if _foreign(self.pq) and not dask_backend.is_dask(self.pq):
            dt = namespace_of(self.pq).asarray(dt)  # torch, JAX: in their namespace
        T0, T1 = wrap_pq(self.pq[i]), wrap_pq(self.pq[i + 1])
        if interpolation == "screw":
            return (T0.inv() @ T1).log() / dt
        omega = (T0.rotation.inv() @ T1.rotation).as_rotvec() / dt
        T, _ = self.at(q, interpolation)
        v = T.rotation.inv().apply((self.pq[i + 1, 4:] - self.pq[i, 4:]) / dt)
        if _foreign(v):
            return namespace_of(v).concat([v, omega], axis=-1)
        return np.concatenate([v, omega], axis=-1)


def _segments(pq, t, steps):
    """The decoupled interpolation's rows ``(q_i, p_i, p_{i+1} - p_i, phi_i, u_i,
    t_i, t_{i+1} - t_i)`` (N - 1, 16) of the samples ``pq`` (N, 7) at stamps ``t``:
    the relative rotation ``d = q_i^* q_{i+1}``, flipped to ``w >= 0`` (the
    shortest way, as ``quat_slerp``), as its half angle ``phi = atan2(|v|, w)``
    and unit axis ``v / |v|`` (0 where ``v = 0``)."""
    q = pq[:, :4]
    d = _quat_multiply(q[:-1] * _CONJUGATE, q[1:])
    d *= np.where(d[:, :1] < 0.0, -1.0, 1.0)
    norm = np.sqrt(np.einsum("ij,ij->i", d[:, 1:], d[:, 1:]))
    out = np.empty((pq.shape[0] - 1, 16), dtype=pq.dtype)
    out[:, :7] = pq[:-1]
    out[:, 7:10] = pq[1:, 4:] - pq[:-1, 4:]
    out[:, 10] = np.arctan2(norm, d[:, 0])
    np.divide(d[:, 1:], norm[:, None], out=out[:, 11:14], where=norm[:, None] > 0.0)
    out[:, 11:14][norm == 0.0] = 0.0
    out[:, 14] = t[:-1]
    out[:, 15] = steps
    return out


class EdgeBuffer:
    """The samples of one edge ``parent -> child``, bounded in time and count.

    Parameters
    ----------
    parent, child : str
    t, pq, cov
        Samples as :func:`as_samples` returns them (``t=None`` for a static edge).
    max_duration : float or None
        Samples older than ``newest - max_duration`` are dropped (tf2's cache
        time); None keeps every sample.
    max_samples : int or None
        At most this many samples are kept (the newest).
    """

    __slots__ = ("parent", "child", "_t", "_pq", "_cov", "_lo", "_hi", "_limits", "_snap")

    def __init__(self, parent, child, t, pq, cov, max_duration, max_samples):
        self.parent, self.child = parent, child
        self._limits = (max_duration, max_samples)
        self._snap = None
        self._t = None
        self._pq, self._cov = pq, cov
        self._lo, self._hi = 0, pq.shape[0]
        if t is not None and _foreign(pq):
            # poses of another namespace: kept as one array, in stamp order
            t, pq, cov = _merge(t[:0], pq[:0], None, t, pq, cov)
            self._t, self._pq, self._cov = t, pq, cov
            self._lo, self._hi = 0, t.shape[0]
            self._trim()
        elif t is not None:
            self._replace(*_merge(t[:0], pq[:0], None, t, pq, cov))

    @property
    def static(self):
        return self._t is None

    def __len__(self):
        return self._hi - self._lo

    def snapshot(self) -> Snapshot:
        """The current samples (cached until the next change: lookups take it often)."""
        snap = self._snap
        if snap is None:
            lo, hi = self._lo, self._hi
            t = None if self._t is None else self._t[lo:hi]
            cov = None if self._cov is None else self._cov[lo:hi]
            snap = self._snap = Snapshot(self.parent, self.child, t, self._pq[lo:hi], cov)
        return snap

    def set_static(self, pq, cov):
        """Replace the pose of a static edge (new arrays: snapshots keep the old)."""
        self._pq, self._cov, self._lo, self._hi = pq, cov, 0, 1
        self._snap = None

    def insert(self, t, pq, cov):
        """Add samples (any order); a stamp already held is replaced by the new pose."""
        lo, hi = self._lo, self._hi
        if _foreign(pq) or _foreign(self._pq):
            raise EdgeKindError(
                f"edge {self.parent!r} -> {self.child!r}: samples of torch, JAX or "
                "Dask poses are given at once (add them with all their stamps)"
            )
        if (
            t.shape[0] == 1
            and t[0] > self._t[hi - 1]
            and hi < self._t.shape[0]
            and (cov is None) == (self._cov is None)
        ):
            # The common case, a newest sample: written past every snapshot's end.
            self._t[hi] = t[0]
            self._pq[hi] = pq[0]
            if cov is not None:
                self._cov[hi] = cov[0]
            self._hi = hi + 1
            self._trim()
            self._snap = None
            return
        old_cov = self._cov[lo:hi] if self._cov is not None else None
        self._replace(*_merge(self._t[lo:hi], self._pq[lo:hi], old_cov, t, pq, cov))

    def _replace(self, t, pq, cov):
        n = t.shape[0]
        cap = max(16, 2 * n)
        self._t = np.empty(cap)
        self._t[:n] = t
        self._pq = np.empty((cap, 7))
        self._pq[:n] = pq
        if cov is None:
            self._cov = None
        else:
            self._cov = np.empty((cap, 6, 6))
            self._cov[:n] = cov
        self._lo, self._hi = 0, n
        self._trim()
        self._snap = None

    def _trim(self):
        max_duration, max_samples = self._limits
        lo, hi = self._lo, self._hi
        if max_duration is not None:
            cut = self._t[hi - 1] - max_duration
            if self._t[lo] < cut:
                lo += int(np.searchsorted(self._t[lo:hi], cut, side="left"))
        if max_samples is not None and hi - lo > max_samples:
            lo = hi - max_samples
        self._lo = lo


def _merge(t0, pq0, cov0, t1, pq1, cov1):
    """The samples of both sets in time order; at a repeated stamp the last one given wins.

    A missing covariance (one set has them, the other not) is taken as zero: a
    pose given without one is exact.
    """
    if cov0 is None and cov1 is not None:
        cov0 = np.zeros((t0.shape[0], 6, 6))
    if cov1 is None and cov0 is not None:
        cov1 = np.zeros((t1.shape[0], 6, 6))
    t = np.concatenate([t0, t1])
    order = np.argsort(t, kind="stable")
    ts = t[order]
    # Stable sort keeps equal stamps in the order given: the last of each run wins.
    keep = np.ones(ts.shape[0], dtype=bool)
    keep[:-1] = ts[1:] != ts[:-1]
    order = order[keep]
    if t0.shape[0] == 0 and _foreign(pq1):  # a new edge of torch, JAX, Dask poses
        return t[order], pq1[order], None if cov1 is None else cov1[order]
    pq = np.concatenate([pq0, pq1])[order]
    cov = None if cov0 is None else np.concatenate([cov0, cov1])[order]
    return t[order], pq, cov


def check_options(interpolation, extrapolate):
    if interpolation not in _INTERPOLATION:
        raise ValueError(
            f"interpolation must be 'decoupled' or 'screw', got {interpolation!r}"
        )
    if extrapolate not in _EXTRAPOLATE:
        raise ValueError(
            f"extrapolate must be None, 'clamp' or 'hold', got {extrapolate!r}"
        )
