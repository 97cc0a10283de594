"""Lookups along a path of edge snapshots: poses, covariances and twists.

A path from ``source`` to ``target`` through their common ancestor ``A`` is two
chains of edges, each listed from the frame upwards: ``up_s`` from ``source`` to
``A`` and ``up_t`` from ``target`` to ``A``. Then ``A_T_source`` is the product
of ``up_s``'s edges ``parent_T_child`` from the top down, likewise ``A_T_target``,
and ``target_T_source = A_T_target^-1 A_T_source``: one compose per edge and one
inverse, on whole batches of stamps at once.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import ExtrapolationError
from ...kernels.se3 import pose_compose as _pose_compose
from ...objects import registry
from ...objects.transform import Transform
from .buffer import wrap_pq

__all__ = [
    "query_times",
    "latest_common_time",
    "fold_left",
    "chain",
    "compose_path",
    "body_twist_path",
    "shaped",
]


def latest_common_time(snaps):
    """The newest time at which every dynamic edge of ``snaps`` has data (tf2's time 0).

    ``None`` when every edge is static. Raises
    :class:`~rigidkit.ExtrapolationError` when the ranges do not overlap, naming
    the edge whose data end first.
    """
    dynamic = [s for s in snaps if s.t is not None]
    if not dynamic:
        return None
    ends = [float(s.t[-1]) for s in dynamic]
    k = int(np.argmin(ends))
    latest = ends[k]
    for s in dynamic:
        if float(s.t[0]) > latest:
            raise ExtrapolationError(
                f"no common time on the path: edge {dynamic[k].parent!r} -> "
                f"{dynamic[k].child!r} ends at {latest!r} (data "
                f"[{float(dynamic[k].t[0])!r}, {latest!r}]) before edge "
                f"{s.parent!r} -> {s.child!r} begins (data "
                f"[{float(s.t[0])!r}, {float(s.t[-1])!r}])",
                edge=(s.parent, s.child),
                range=(float(s.t[0]), float(s.t[-1])),
                direction="past",
            )
    return latest


def _edge(snap, q, interpolation, extrapolate, want_cov):
    """``(parent_T_child, cov or None)`` of one edge at ``q``: a float (one pose),
    an (M,) array (a batch), or None (a static edge's one pose)."""
    if snap.t is None:
        T = snap.pose
        cov = snap.cov[0] if (want_cov and snap.cov is not None) else None
        return T, cov
    if type(q) is float:
        return snap.at_one(snap.check_one(q, extrapolate), interpolation, want_cov)
    return snap.at(snap.check(q, extrapolate), interpolation, want_cov)


def fold_static(up):
    r"""The edges of ``up`` from the top down, each run of static edges replaced by
    the product of its poses (one ``Transform``); dynamic edges stay
    :class:`~rigidkit.applications.frames.buffer.EdgeBuffer`\ s."""
    items, run = [], None
    for edge in reversed(up):
        if edge.static:
            pose = edge.snapshot().pose
            run = pose if run is None else run @ pose
            continue
        if run is not None:
            items.append(run)
            run = None
        items.append(edge)
    if run is not None:
        items.append(run)
    return tuple(items)


def fold_left(items, m):
    """``items`` with each static pose that precedes a dynamic edge folded into the
    edge's samples, for a lookup at ``m`` times.

    ``S E(t)`` with ``E`` interpolated between samples ``T_i`` is the edge
    interpolated between ``S T_i``: both interpolations commute with a constant
    factor on the left, as they depend on the samples through ``T_i`` and the
    relative motion ``T_i^-1 T_{i+1}`` only (slerp and the screw geodesic are
    left-invariant; the lerp of positions is affine). One compose per sample,
    once per snapshot, instead of one per time: only where the edge interpolates
    from its segment tables (at least a quarter as many times as samples, see
    :meth:`Snapshot.at`). A factor on the right has no such form for tf2's rule.
    """
    out = []
    k = 0
    while k < len(items):
        it = items[k]
        nxt = items[k + 1] if k + 1 < len(items) else None
        if (
            type(it) is Transform
            and nxt is not None
            and type(nxt) is not Transform
            and 1 < nxt.t.shape[0] <= 4 * m
        ):
            out.append(nxt.premultiplied(it))
            k += 2
        else:
            out.append(it)
            k += 1
    return out


def _planned_chain(items, q, interpolation, extrapolate):
    """``A_T_frame`` from :func:`fold_static`'s items (snapshots taken), or None."""
    if type(q) is np.ndarray:
        items = fold_left(items, q.shape[0])
    T = None
    for it in items:
        if type(it) is not Transform:
            it = _edge(it, q, interpolation, extrapolate, False)[0]
        T = it if T is None else T @ it
    return T


def chain(up, q, interpolation, extrapolate, want_cov=False):
    """``A_T_frame`` along ``up`` (edges from the frame up to ``A``) at times ``q``.

    Returns ``(Transform or None, [(edge pose, edge cov), ...] from the top down)``;
    None stands for the identity (an empty chain).
    """
    parts = [_edge(s, q, interpolation, extrapolate, want_cov) for s in reversed(up)]
    T = None
    for E, _ in parts:
        T = E if T is None else T @ E
    return T, parts


#: Times per block of a batched lookup. A lookup at M times makes a dozen arrays
#: of M rows per dynamic edge; at M = 1e5 (30 MB) allocating them afresh cost
#: more in page faults (~7,600 a call, system time 1-1.5x the arithmetic) than
#: the arithmetic. Blocks of 16,384 rows (~4 MB in all) reuse the same memory
#: from block to block and stay in cache; the rows are those of one pass.
BLOCK = 16384


def compose_path(items_s, items_t, q, interpolation, extrapolate):
    """``target_T_source`` at times ``q`` (an (M,) array, a float, or None for
    static paths), from the two chains' :func:`fold_static` items."""
    if type(q) is np.ndarray and q.shape[0] > BLOCK:
        return _compose_blocks(items_s, items_t, q, interpolation, extrapolate)
    A_T_s = _planned_chain(items_s, q, interpolation, extrapolate)
    A_T_t = _planned_chain(items_t, q, interpolation, extrapolate)
    return _link(A_T_s, A_T_t)


def _link(A_T_s, A_T_t):
    """``target_T_source = A_T_t^-1 A_T_s`` (None: the identity)."""
    if A_T_t is None:
        return A_T_s if A_T_s is not None else Transform()
    if A_T_s is None:
        return A_T_t.inv()
    return A_T_t.inv() @ A_T_s


def _compose_blocks(items_s, items_t, q, interpolation, extrapolate):
    """:func:`compose_path` at many times, :data:`BLOCK` rows at a time.

    Every edge's range test runs first on all the times, in the order of one
    pass, so an error (or a clamp) is the same as without blocks.
    """
    m = q.shape[0]
    items_s, items_t = fold_left(items_s, m), fold_left(items_t, m)
    items = items_s + items_t
    times = [None if type(it) is Transform else it.check(q, extrapolate) for it in items]
    # Where each segment's times begin, once for the call (times in order only)
    spans = [
        None if tk is None or interpolation != "decoupled" else it.bounds(tk)
        for it, tk in zip(items, times)
    ]
    out = np.empty((m, 7))
    ns = len(items_s)
    last = len(items) - 1 if not items_t else None
    for lo in range(0, m, BLOCK):
        hi = min(lo + BLOCK, m)
        chains = [None, None]
        for k, (it, tk, ends) in enumerate(zip(items, times, spans)):
            if tk is not None:
                span = None if ends is None else (ends, lo)
                it = it.at(tk[lo:hi], interpolation, many=m, span=span)[0]
            c = 0 if k < ns else 1
            if k == last and chains[0] is not None:
                # target is an ancestor of source: the last compose writes the rows
                _pose_compose(
                    registry.stored(chains[0]), registry.stored(it), out=out[lo:hi]
                )
                break
            chains[c] = it if chains[c] is None else chains[c] @ it
        else:
            out[lo:hi] = registry.stored(_link(*chains))
    return wrap_pq(out)


def body_twist_path(up_s, up_t, q, interpolation, extrapolate):
    """Body twist of ``target_T_source(t)`` at ``q``, shape (M, 6), and the pose.

    For a product ``T = E_1 E_2 ... E_k`` the body twist is
    ``sum_i Ad(E_{i+1} ... E_k)^-1 V_i`` with ``V_i`` each factor's body twist
    (Murray, Li & Sastry 1994, Sec. 2.4); an inverted factor ``E^-1`` has body
    twist ``-Ad(E) V``.
    """
    # Factors of target_T_source in order: the target chain inverted (bottom up),
    # then the source chain (top down); each as a batch with its body twist.
    factors = []
    for s in up_t:
        E, V = _moving_edge(s, q, interpolation, extrapolate)
        factors.append((E.inv(), -_act(E.adjoint(), V)))
    for s in reversed(up_s):
        factors.append(_moving_edge(s, q, interpolation, extrapolate))
    total = None
    tail = None  # E_{i+1} ... E_k, built from the right
    for E, V in reversed(factors):
        if tail is None:
            total = V
            tail = E
        else:
            total = total + _act(tail.inv().adjoint(), V)
            tail = E @ tail
    if tail is None:
        return np.zeros(q.shape + (6,)), Transform()
    return total, tail


def _act(M, v):
    """``M @ v`` over a batch of matrices (M, 6, 6) and vectors (M, 6)."""
    return (M @ v[..., None])[..., 0]  # any namespace (torch, JAX, Dask)


def _moving_edge(s, q, interpolation, extrapolate):
    """An edge's pose at ``q`` as a batch (M,) and its body twist (M, 6)."""
    if s.t is None:
        E = s.pose
        if E.single:
            E = wrap_pq(np.broadcast_to(s.pq[0], q.shape + (7,)).copy())
        return E, np.zeros(q.shape + (6,))
    q = s.check(q, extrapolate)
    E, _ = s.at(q, interpolation)
    return E, s.body_twist(q, interpolation)


def shaped(T, shape):
    """``T`` (shape (M,) of a flat query, or one pose) in the query's shape."""
    if T.single:
        if shape:  # an all-static path asked at many times: the one pose, broadcast
            return wrap_pq(np.broadcast_to(registry.stored(T), shape + (7,)).copy())
        return T
    if not shape:  # one time: a batch of static edges' batch shape, as it is
        return T
    return T.reshape(shape) if shape != T.shape else T


def query_times(at, snaps):
    """The query times as a flat float64 array (or None: all static) and the shape."""
    if at is None:
        latest = latest_common_time(snaps)
        return (None, ()) if latest is None else (latest, ())
    if type(at) is float or isinstance(at, (int, np.floating, np.integer)):
        at = float(at)  # one time: the lookup works on Python floats
        if not math.isfinite(at):
            raise ValueError(f"at: times must be finite, got {at!r}")
        return (None if all(s.t is None for s in snaps) else at), ()
    q = np.asarray(at, dtype=np.float64)
    shape = q.shape
    if not np.isfinite(q).all():
        raise ValueError(f"at: times must be finite, got {at!r}")
    if all(s.t is None for s in snaps):
        return None, shape
    return q.reshape(-1), shape
