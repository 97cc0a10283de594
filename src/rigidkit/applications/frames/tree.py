"""The tree rules of a :class:`~rigidkit.FrameGraph`: one parent per frame, no cycle,
known names; and :class:`EdgeInfo`, the public record of an edge.

Functions of the graph's ``edges`` mapping (child -> its edge to its parent), called
with the graph's lock held.
"""

from __future__ import annotations

import difflib
from typing import NamedTuple

from ...errors import ConnectivityError, LookupError

__all__ = ["EdgeInfo", "info", "check_parent", "check_new_edge", "unknown", "up"]


class EdgeInfo(NamedTuple):
    """One edge of a :class:`~rigidkit.FrameGraph`, as ``graph.edges`` lists it."""

    parent: str
    child: str
    kind: str  #: "static" or "dynamic"
    range: tuple | None  #: (first, last) stamp of a dynamic edge, None if static
    count: int  #: samples held (1 for a static edge)


def info(s):
    """The :class:`EdgeInfo` of an edge's snapshot."""
    if s.t is None:
        return EdgeInfo(s.parent, s.child, "static", None, 1)
    return EdgeInfo(s.parent, s.child, "dynamic", (float(s.t[0]), float(s.t[-1])), len(s.t))


def check_parent(edge, parent, child):
    """Raise :class:`~rigidkit.ConnectivityError` if ``child``'s edge has another parent."""
    if edge.parent != parent:
        raise ConnectivityError(
            f"frame {child!r} already has parent {edge.parent!r}; cannot also "
            f"attach it to {parent!r} (a frame has one parent)"
        )


def check_new_edge(edges, parent, child):
    """Raise :class:`~rigidkit.ConnectivityError` if ``parent -> child`` closes a cycle
    (``child`` is ``parent`` or one of its ancestors), naming the cycle."""
    if parent == child:
        raise ConnectivityError(f"an edge from {parent!r} to itself is a cycle")
    chain = [parent]
    while chain[-1] in edges:
        chain.append(edges[chain[-1]].parent)
        if chain[-1] == child:
            cycle = " -> ".join([child, *reversed(chain[:-1]), child])
            raise ConnectivityError(
                f"edge {parent!r} -> {child!r} would close the cycle {cycle}"
            )


def unknown(frames, frame, what):
    """A :class:`~rigidkit.LookupError` for ``frame``, listing the closest names."""
    close = difflib.get_close_matches(frame, list(frames), n=3, cutoff=0.5)
    hint = f"; closest: {', '.join(map(repr, close))}" if close else ""
    known = f" (frames: {len(frames)})" if not close else ""
    return LookupError(f"{frame!r} {what}{hint}{known}")


def up(edges, frame):
    """The edges from ``frame`` up to its root, and the root's name."""
    chain = []
    while frame in edges:
        edge = edges[frame]
        chain.append(edge)
        frame = edge.parent
    return chain, frame
