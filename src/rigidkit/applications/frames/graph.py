"""``FrameGraph``: a time-aware tree of named coordinate frames (tf2 without ROS)."""

from __future__ import annotations

import math

import numpy as np

from ..._engine import Lock
from ...errors import (
    ConnectivityError,
    EdgeKindError,
    ExtrapolationError,
    FrameKeywordError,
    LookupError,
)
from ...objects.transform import Transform
from .buffer import EdgeBuffer, as_samples, check_options
from .lookup import (
    body_twist_path,
    compose_path,
    fold_static,
    query_times,
    shaped,
)
from .tree import check_new_edge, check_parent, info, unknown, up

__all__ = ["FrameGraph"]


class FrameGraph:
    """A tree of named frames whose edges are static or time-stamped transforms.

    Each frame has at most one parent; an edge ``parent -> child`` holds
    ``parent_T_child`` (it maps coordinates in ``child`` to coordinates in
    ``parent``), either one pose (static) or a buffer of stamped poses (dynamic),
    interpolated between samples. Lookups compose along the path through the
    two frames' common ancestor only (ros/geometry2#439), over a whole array of
    stamps at once.

    Thread-safe like tf2's buffer: samples may be added from several threads
    while others look up. Every lookup sees the graph as it was at one instant
    (the lock is held only to take views of the edges' arrays, never during the
    arithmetic).

    Parameters
    ----------
    max_duration : float or None
        Seconds of samples kept behind the newest sample of each dynamic edge
        (tf2's cache time, 10 s by default); None keeps everything.
    max_samples : int or None
        At most this many samples per dynamic edge (the newest).

    Examples
    --------
    A camera on a base that drives along x at 1 m/s: where is the camera in the
    map frame at t = 0.5 s?

    >>> import numpy as np
    >>> import rigidkit as rk
    >>> graph = rk.FrameGraph()
    >>> graph.add("map", "base", rk.Transform(translation=[[0.0, 0, 0], [1.0, 0, 0]]),
    ...           stamps=[0.0, 1.0])
    >>> graph.add("base", "camera", rk.Transform(translation=[0.0, 0.0, 1.5]))
    >>> graph.get("map", "camera", at=0.5).translation
    array([0.5, 0. , 1.5])
    >>> graph.path("camera", "map")
    ['camera', 'base', 'map']
    >>> print(graph)
    map
    └── base  [dynamic, 2 samples, t in [0.0, 1.0]]
        └── camera  [static]
    >>> rk.FrameGraph.from_json(graph.to_json()).edges == graph.edges
    True
    """

    def __init__(self, max_duration=10.0, max_samples=None):
        if max_duration is not None and not max_duration >= 0:
            raise ValueError(f"max_duration must be >= 0 or None, got {max_duration!r}")
        if max_samples is not None and int(max_samples) < 1:
            raise ValueError(f"max_samples must be >= 1 or None, got {max_samples!r}")
        self.max_duration = None if max_duration is None else float(max_duration)
        self.max_samples = None if max_samples is None else int(max_samples)
        self._lock = Lock()
        self._edges = {}  # child -> EdgeBuffer (its edge to its parent)
        self._children = {}  # frame -> list of children, in insertion order
        self._paths = {}  # (target, source) -> (up_s, up_t), cleared on changes

    # -- building ------------------------------------------------------------------
    def add(self, parent, child, parent_T_child, stamps=None, *, cov=None):
        """Add a static edge or samples of a dynamic edge ``parent -> child``.

        Parameters
        ----------
        parent, child : str
            Frame names; ``parent_T_child`` maps ``child`` coordinates to
            ``parent`` coordinates.
        parent_T_child : Transform, Trajectory or array_like (..., 7)
            One pose, a batch of shape (M,) (one per stamp), a
            :class:`~rigidkit.Trajectory` (its stamps are used unless ``stamps``
            is given) or pq rows ``(w, x, y, z, tx, ty, tz)``.
        stamps : float or array_like (M,), optional
            None: a static edge. Otherwise the times of the samples, in any order;
            a stamp the edge already holds is replaced by the new pose.
        cov : array_like, shape (6, 6) or (M, 6, 6), optional
            Covariance of each pose, of a right perturbation ``T exp(xi)`` with
            ``xi = (v, omega)`` (the convention of :class:`UncertainTransform`).

        Poses of torch, JAX or Dask stay in their namespace (autograd, tracing
        with the graph built inside the traced function, lazy Dask); lookups and
        :meth:`velocity` compose and interpolate them there, the stamps are
        searched on the host (NumPy). Such a dynamic edge takes its samples in
        one call. A batch of poses without stamps is a batch of static edges,
        broadcast by the lookups.

        Raises
        ------
        ConnectivityError
            ``child`` already has another parent, or the edge closes a cycle.
        EdgeKindError
            Static samples for a dynamic edge or the reverse, a second static
            pose (use :meth:`update_static`), or torch, JAX or Dask samples added
            to a dynamic edge that has some.
        """
        t, pq, cov = as_samples(parent_T_child, stamps, cov)
        parent, child = str(parent), str(child)
        with self._lock:
            edge = self._edges.get(child)
            if edge is None:
                self._attach_locked(
                    EdgeBuffer(
                        parent, child, t, pq, cov, self.max_duration, self.max_samples
                    )
                )
                return
            check_parent(edge, parent, child)
            if edge.static or t is None:
                kind = "static" if edge.static else "dynamic"
                hint = (
                    "; use update_static to replace it" if edge.static and t is None else ""
                )
                raise EdgeKindError(
                    f"edge {parent!r} -> {child!r} is {kind}, cannot add "
                    f"{'a static pose' if t is None else 'stamped samples'} to it{hint}"
                )
            edge.insert(t, pq, cov)

    def update_static(self, parent, child, parent_T_child, *, cov=None):
        """Replace the pose of the static edge ``parent -> child`` (added if absent).

        >>> import rigidkit as rk
        >>> graph = rk.FrameGraph()
        >>> graph.add("base", "camera", rk.Transform(translation=[0.0, 0, 1.0]))
        >>> graph.update_static("base", "camera", rk.Transform(translation=[0.0, 0, 1.2]))
        >>> graph.get("base", "camera").translation
        array([0. , 0. , 1.2])
        """
        _, pq, cov = as_samples(parent_T_child, None, cov)
        parent, child = str(parent), str(child)
        with self._lock:
            edge = self._edges.get(child)
            if edge is None:
                pass
            elif not edge.static:
                raise EdgeKindError(
                    f"edge {edge.parent!r} -> {child!r} is dynamic, not static"
                )
            else:
                check_parent(edge, parent, child)
                edge.set_static(pq, cov)
                self._paths.clear()  # the plans hold composed static poses
                return
        self.add(parent, child, parent_T_child, cov=cov)

    def remove(self, child):
        """Remove the edge from ``child`` to its parent (``child`` keeps its subtree).

        >>> import rigidkit as rk
        >>> graph = rk.FrameGraph()
        >>> graph.add("map", "base", rk.Transform())
        >>> graph.add("base", "camera", rk.Transform())
        >>> graph.remove("base")
        >>> graph.parent("base"), graph.children("base"), graph.frames
        (None, ['camera'], ['base', 'camera'])
        """
        child = str(child)
        with self._lock:
            edge = self._edges.pop(child, None)
            if edge is None:
                raise unknown(self._children, child, "has no parent edge to remove")
            self._children[edge.parent].remove(child)
            for name in (edge.parent, child):
                if not self._children.get(name) and name not in self._edges:
                    self._children.pop(name, None)
            self._paths.clear()

    def _attach(self, edge):
        """Add a new edge built elsewhere (``from_json``)."""
        with self._lock:
            if edge.child in self._edges:
                check_parent(self._edges[edge.child], edge.parent, edge.child)
                raise ValueError(f"edge {edge.parent!r} -> {edge.child!r} given twice")
            self._attach_locked(edge)

    def _attach_locked(self, edge):
        check_new_edge(self._edges, edge.parent, edge.child)
        self._edges[edge.child] = edge
        self._children.setdefault(edge.parent, []).append(edge.child)
        self._children.setdefault(edge.child, [])
        self._paths.clear()

    # -- structure -----------------------------------------------------------------
    @property
    def frames(self):
        """Every frame name, in the order first seen."""
        with self._lock:
            return list(self._children)

    @property
    def edges(self):
        """Every edge as an :class:`EdgeInfo` (parent, child, kind, range, count)."""
        with self._lock:
            snaps = [e.snapshot() for e in self._edges.values()]
        return [info(s) for s in snaps]

    def parent(self, frame):
        """The parent of ``frame``, or None for a root."""
        frame = str(frame)
        with self._lock:
            self._known(frame)
            edge = self._edges.get(frame)
            return None if edge is None else edge.parent

    def children(self, frame):
        """The children of ``frame``, in the order they were added."""
        frame = str(frame)
        with self._lock:
            self._known(frame)
            return list(self._children[frame])

    def path(self, a, b):
        """Frame names from ``a`` to ``b`` through their common ancestor, ends included."""
        with self._lock:
            up_a, up_b = self._resolve(str(b), str(a))
        return [str(a), *(e.parent for e in up_a), *(e.child for e in reversed(up_b))]

    def _known(self, frame):
        if frame not in self._children:
            raise unknown(self._children, frame, "is not a frame of this graph")

    def _resolve(self, target, source):
        """Edges from ``source`` and from ``target`` up to their common ancestor.

        Called with the lock held. Cached per pair until the tree changes.
        """
        key = (target, source)
        found = self._paths.get(key)
        if found is not None:
            return found
        self._known(target)
        self._known(source)
        up_s, root_s = up(self._edges, source)
        up_t, root_t = up(self._edges, target)
        if root_s != root_t:
            raise ConnectivityError(
                f"no path from {source!r} to {target!r}: {source!r} is in the tree "
                f"rooted at {root_s!r}, {target!r} in the tree rooted at {root_t!r}"
            )
        # Drop the shared top of both chains: compose only up to the common ancestor.
        while up_s and up_t and up_s[-1] is up_t[-1]:
            up_s.pop()
            up_t.pop()
        found = self._paths[key] = (tuple(up_s), tuple(up_t))
        return found

    def _snap(self, target, source):
        with self._lock:
            up_s, up_t = self._resolve(target, source)
            return [e.snapshot() for e in up_s], [e.snapshot() for e in up_t]

    def _planned(self, target, source):
        """The two chains of :meth:`_resolve` with each run of static edges composed
        once (cached with the path until the tree or a static pose changes), and a
        snapshot of each dynamic edge: ``(items_s, items_t, moving)``, each item a
        static ``Transform`` or a dynamic edge's :class:`Snapshot`, from the top
        down; ``moving``: whether any edge is dynamic."""
        key = (target, source, "plan")
        with self._lock:
            plan = self._paths.get(key)
            if plan is None:
                up_s, up_t = self._resolve(target, source)
                items_s, items_t = fold_static(up_s), fold_static(up_t)
                moving = any(type(x) is not Transform for x in items_s + items_t)
                plan = self._paths[key] = (items_s, items_t, moving)
            return (
                [x if type(x) is Transform else x.snapshot() for x in plan[0]],
                [x if type(x) is Transform else x.snapshot() for x in plan[1]],
                plan[2],
            )

    # -- lookups -------------------------------------------------------------------
    def get(
        self,
        target,
        source,
        at=None,
        *,
        source_at=None,
        fixed=None,
        interpolation="decoupled",
        extrapolate=None,
        with_covariance=False,
    ):
        """``target_T_source``: the pose of ``source`` in ``target`` at time ``at``.

        Parameters
        ----------
        target, source : str
            Frame names. The result maps ``source`` coordinates to ``target``
            coordinates: ``p_target = graph.get(target, source) @ p_source``.
        at : float or array_like (...), optional
            Time(s) in seconds. None: the latest time at which every dynamic edge
            of the path has data (tf2's time 0). An array gives a batched
            ``Transform`` of its shape, computed with one compose per edge.
        source_at, fixed : optional
            Time travel (tf2's advanced lookup): ``target`` at ``at`` and
            ``source`` at ``source_at``, linked through the frame ``fixed``, which
            does not move between the two times:
            ``target_T_fixed(at) @ fixed_T_source(source_at)``.
        interpolation : {"decoupled", "screw"}
            Between two samples: ``"decoupled"`` (tf2's rule: linear translation,
            slerp rotation, so results match a ROS system) or ``"screw"``, the
            SE(3) geodesic (Sola et al. 2018, eq. 178).
        extrapolate : {None, "clamp", "hold"}
            Outside an edge's data: None raises; ``"clamp"`` uses the first sample
            before the data and the last after; ``"hold"`` holds the last sample
            into the future but still raises for the past.
        with_covariance : bool
            Return an :class:`UncertainTransform` whose covariance is propagated
            along the path to first order from the edges' covariances (right
            perturbations, ``(v, omega)`` order; an edge without one is exact).

        Returns
        -------
        Transform or UncertainTransform
            Shape of ``at`` (``()`` for a single time or an all-static path).

        Raises
        ------
        LookupError
            An unknown frame (the message lists the closest names).
        ConnectivityError
            The two frames lie in different trees.
        ExtrapolationError
            A time outside an edge's data (``.edge``, ``.range``, ``.direction``).

        Examples
        --------
        >>> import numpy as np
        >>> import rigidkit as rk
        >>> graph = rk.FrameGraph()
        >>> graph.add("odom", "base", rk.Transform(translation=[[0.0, 0, 0], [2.0, 0, 0]]),
        ...           stamps=[0.0, 1.0])
        >>> graph.get("base", "odom", at=[0.25, 0.5]).translation   # base_T_odom
        array([[-0.5, -0. , -0. ],
               [-1. , -0. , -0. ]])
        >>> graph.get("odom", "base").translation                   # the latest: t = 1
        array([2., 0., 0.])
        >>> try:
        ...     graph.get("odom", "base", at=1.5)
        ... except rk.ExtrapolationError as err:
        ...     print(err.direction, err.range)
        future (0.0, 1.0)
        >>> graph.get("odom", "base", at=1.5, extrapolate="hold").translation
        array([2., 0., 0.])
        """
        check_options(interpolation, extrapolate)
        if fixed is not None:
            A = self.get(
                target,
                fixed,
                at,
                interpolation=interpolation,
                extrapolate=extrapolate,
                with_covariance=with_covariance,
            )
            B = self.get(
                fixed,
                source,
                at if source_at is None else source_at,
                interpolation=interpolation,
                extrapolate=extrapolate,
                with_covariance=with_covariance,
            )
            return A @ B if not with_covariance else A.compose(B)
        if source_at is not None:
            raise ValueError("source_at= needs fixed=, the frame that links the two times")
        if with_covariance:
            from .uncertain import path_covariance

            up_s, up_t = self._snap(str(target), str(source))
            q, shape = query_times(at, up_s + up_t)
            return path_covariance(up_s, up_t, q, shape, interpolation, extrapolate)
        up_s, up_t, moving = self._planned(str(target), str(source))
        if type(at) is float and moving and math.isfinite(at):
            q, shape = at, ()  # one time, the most frequent call: query_times's result
        else:
            q, shape = query_times(at, [x for x in up_s + up_t if type(x) is not Transform])
        T = compose_path(up_s, up_t, q, interpolation, extrapolate)
        return shaped(T, shape)

    def can_transform(self, target, source, at=None, **options):
        """``(True, "")`` if :meth:`get` would succeed, else ``(False, reason)``.

        ``options`` are those of :meth:`get`; the reason is the message of the
        error :meth:`get` would raise.

        >>> import rigidkit as rk
        >>> graph = rk.FrameGraph()
        >>> graph.add("map", "odom", rk.Transform())
        >>> graph.can_transform("map", "odm")
        (False, "'odm' is not a frame of this graph; closest: 'odom'")
        """
        try:
            self.get(target, source, at, **options)
        except (LookupError, ConnectivityError, ExtrapolationError) as err:
            return False, str(err)
        return True, ""

    def velocity(
        self, target, source, at, *, frame, interpolation="decoupled", extrapolate=None
    ):
        """Twist ``(v, omega)`` of ``source`` relative to ``target``, shape (..., 6).

        The derivative of the interpolant ``T(t) = target_T_source(t)`` (constant
        on each interval between samples; at a sample the interval that starts
        there): ``frame="body"`` gives ``vee(T^-1 dT/dt)`` (in ``source`` axes),
        ``"world"`` gives ``vee(dT/dt T^-1)`` (in ``target`` axes), the
        definitions of :func:`rigidkit.kinematics.twist_from_samples`.

        >>> import numpy as np
        >>> import rigidkit as rk
        >>> graph = rk.FrameGraph()
        >>> turning = rk.Transform.exp([[0.0, 0, 0, 0, 0, 0], [1.0, 0, 0, 0, 0, 0.5]])
        >>> graph.add("odom", "base", turning, stamps=[0.0, 1.0])
        >>> V = graph.velocity("odom", "base", 0.5, frame="body", interpolation="screw")
        >>> np.round(V, 12) + 0.0
        array([1. , 0. , 0. , 0. , 0. , 0.5])
        """
        if frame not in ("body", "world"):
            raise FrameKeywordError(f"frame must be 'world' or 'body', got {frame!r}")
        check_options(interpolation, extrapolate)
        up_s, up_t = self._snap(str(target), str(source))
        q, shape = query_times(at, up_s + up_t)
        if q is None:
            return np.zeros(shape + (6,))
        q = np.reshape(q, -1)
        V, T = body_twist_path(up_s, up_t, q, interpolation, extrapolate)
        if frame == "world":
            V = (T.adjoint() @ V[..., None])[..., 0]  # any namespace
        return V.reshape(shape + (6,))

    # -- pictures and files ----------------------------------------------------------
    def __str__(self):
        from .serialise import tree_text

        return tree_text(self)

    def __repr__(self):
        with self._lock:
            n, m = len(self._children), len(self._edges)
        return f"FrameGraph({n} frames, {m} edges, max_duration={self.max_duration!r})"

    def to_dot(self):
        """Graphviz source of the tree (``dot -Tpng``), edges labelled with their kind."""
        from .serialise import to_dot

        return to_dot(self)

    def to_json(self):
        """A JSON string of every frame, edge, stamp, pose and covariance (exact)."""
        from .serialise import to_json

        return to_json(self)

    @classmethod
    def from_json(cls, text):
        """The graph that :meth:`to_json` wrote, sample for sample."""
        from .serialise import from_json

        return from_json(cls, text)

    def _export(self):
        """Under the lock: settings, roots, and (snapshot, children) of every edge."""
        with self._lock:
            snaps = {c: e.snapshot() for c, e in self._edges.items()}
            children = {f: list(c) for f, c in self._children.items()}
        return snaps, children
