"""A :class:`~rigidkit.FrameGraph` as JSON, as an indented tree and as Graphviz source.

JSON keeps every float exactly (Python writes the shortest repr that reads back to
the same float64), so ``FrameGraph.from_json(graph.to_json())`` holds the same
samples bit for bit. Poses are written as pq rows ``(tx, ty, tz, w, x, y, z)``
(:meth:`~rigidkit.Transform.as_pq`'s layout) and read back without
renormalisation.
"""

from __future__ import annotations

import json

import numpy as np

from .buffer import EdgeBuffer

__all__ = ["to_json", "from_json", "tree_text", "to_dot"]

FORMAT = "rigidkit.FrameGraph"
VERSION = 1
# Stored rows are (w, x, y, z, tx, ty, tz); pq rows are (tx, ty, tz, w, x, y, z).
_TO_PQ = [4, 5, 6, 0, 1, 2, 3]
_FROM_PQ = [3, 4, 5, 6, 0, 1, 2]


def to_json(graph):
    snaps, _ = graph._export()
    edges = []
    for s in snaps.values():
        edge = {
            "parent": s.parent,
            "child": s.child,
            "kind": "static" if s.t is None else "dynamic",
            "pq": s.pq[:, _TO_PQ].tolist(),
        }
        if s.t is not None:
            edge["stamps"] = s.t.tolist()
        if s.cov is not None:
            edge["cov"] = s.cov.tolist()
        edges.append(edge)
    doc = {
        "format": FORMAT,
        "version": VERSION,
        "max_duration": graph.max_duration,
        "max_samples": graph.max_samples,
        "edges": edges,
    }
    return json.dumps(doc)


def from_json(cls, text):
    doc = json.loads(text)
    if doc.get("format") != FORMAT:
        raise ValueError(f"not a {FORMAT} document (format: {doc.get('format')!r})")
    if doc.get("version") != VERSION:
        raise ValueError(f"{FORMAT} version {doc.get('version')!r}; this reads {VERSION}")
    graph = cls(max_duration=doc["max_duration"], max_samples=doc["max_samples"])
    for e in doc["edges"]:
        pq = np.ascontiguousarray(np.array(e["pq"], dtype=np.float64)[:, _FROM_PQ])
        t = None if e["kind"] == "static" else np.array(e["stamps"], dtype=np.float64)
        cov = None if "cov" not in e else np.array(e["cov"], dtype=np.float64)
        # The samples as written (already normalised and ordered): no re-validation.
        graph._attach(
            EdgeBuffer(
                e["parent"], e["child"], t, pq, cov, graph.max_duration, graph.max_samples
            )
        )
    return graph


def _label(s):
    if s.t is None:
        return "static"
    t0, t1 = float(s.t[0]), float(s.t[-1])
    n = len(s.t)
    return f"dynamic, {n} sample{'s' if n != 1 else ''}, t in [{t0!r}, {t1!r}]"


def tree_text(graph):
    """Each tree from its root, children indented under their parent with the edge's
    kind, sample count and stamp range."""
    snaps, children = graph._export()
    roots = [f for f in children if f not in snaps]
    lines = []

    def walk(frame, prefix):
        kids = children.get(frame, [])
        for k, child in enumerate(kids):
            last = k == len(kids) - 1
            lines.append(
                f"{prefix}{'└── ' if last else '├── '}{child}  [{_label(snaps[child])}]"
            )
            walk(child, prefix + ("    " if last else "│   "))

    for root in roots:
        lines.append(root)
        walk(root, "")
    if not lines:
        return "FrameGraph (empty)"
    return "\n".join(lines)


def to_dot(graph):
    snaps, children = graph._export()
    lines = ["digraph FrameGraph {", "  rankdir=TB;", "  node [shape=box];"]
    for frame in children:
        lines.append(f"  {json.dumps(frame)};")
    for s in snaps.values():
        style = ", style=dashed" if s.t is None else ""
        label = _label(s).replace(", t in", "\\nt in")
        lines.append(
            f'  {json.dumps(s.parent)} -> {json.dumps(s.child)} [label="{label}"{style}];'
        )
    lines.append("}")
    return "\n".join(lines)
