"""docs/backends.md, written from the matrix's declarations.

``python -m tests.backend_matrix.table`` rewrites ``docs/backends.md``;
``test_matrix.py`` checks that the committed file equals :func:`render`, so the page
cannot claim more than the tests show: a cell reads "pass" only where the matrix runs
it and declares no failure.
"""

from __future__ import annotations

import pathlib
import sys

from . import examples, status

DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "backends.md"
COLUMNS = {
    "jax.jit": "the call traces under `jax.jit` (`jax.make_jaxpr`) with NumPy's output "
    "shapes (values: the vmap cell evaluates that program; `RIGIDKIT_MATRIX_XLA=1` "
    "compiles and compares every JAX cell with XLA)",
    "jax.vmap": "`jax.vmap` over two inputs equals the two NumPy calls",
    "jax.grad": "`jax.grad` of a fixed random weighting of the outputs equals central "
    "finite differences (step 1e-6)",
    "torch autograd": "the same gradient by `torch.autograd.grad`",
    "torch.func.vmap": "as jax.vmap, with `torch.func.vmap`",
    "Dask (lazy)": "on Dask arrays the call computes nothing (a scheduler callback counts "
    "0 computes), returns Dask arrays, and `.compute()` equals NumPy",
    "torch.compile": "`torch.compile(fullgraph=True)` equals NumPy; {compile_ci} callables "
    "in CI, the rest in the exhaustive sweep (`pytest -m exhaustive -k compile`, 7 min "
    "on 2 cores with Inductor's cache warm), whose results are recorded here",
}
MARK = {"pass": "✓", "fail": "✗", "na": "–", "untested": "·"}

HEADER = """\
# Backends: every public callable under every transform

Generated from the test matrix (`tests/backend_matrix/`) by
`python -m tests.backend_matrix.table`; `tests/backend_matrix/test_matrix.py` fails
when this page differs from what the matrix declares, so it claims no more than the
tests show. Each cell runs one small example of the callable (float64) and compares
it with the NumPy call:

{columns}

✓ passes; ✗ fails (the reason is listed below the table; the cell is an
`xfail(strict=True)` test, so a fix makes it fail until the declaration goes);
– does not apply (reason below); · not run by the tests so far (a `torch.compile`
cell the exhaustive sweep has not recorded).

Values agree with NumPy to 1e-9 of the result's scale; gradients to rtol 1e-5.
{summary}

"""


def cell_status(name: str, transform: str) -> tuple[str, str]:
    """``(state, reason)`` of one cell: pass, fail, na or untested."""
    ex = examples.example_for(name)
    if not ex.applies(transform):
        return "na", ex.na[transform]
    if (name, transform) in status.FAILS:
        return "fail", status.FAILS[name, transform]
    if (
        transform == "compile"
        and name not in status.COMPILE_CI
        and name not in status.COMPILE_CHECKED
    ):
        return "untested", ""
    return "pass", ""


def rows():
    names = examples.public_callables()
    variants = [n for n in examples.EXAMPLES if "[" in n]
    return [
        n for n in names if not n.startswith(tuple(examples.NOT_APPLICABLE_MODULES))
    ] + sorted(variants)


def render() -> str:
    ts = examples.TRANSFORMS
    counts = {k: 0 for k in MARK}
    lines = [
        "| callable | " + " | ".join(examples.TRANSFORM_TITLES[t] for t in ts) + " |",
        "|---|" + "---|" * len(ts),
    ]
    notes = []
    for name in rows():
        marks = []
        for t in ts:
            state, reason = cell_status(name, t)
            counts[state] += 1
            marks.append(MARK[state])
            if state in ("fail", "na"):
                notes.append((name, t, state, reason))
        lines.append(f"| `{name}` | " + " | ".join(marks) + " |")
    skipped = examples.public_callables()
    skipped = [n for n in skipped if n.startswith(tuple(examples.NOT_APPLICABLE_MODULES))]
    for prefix in examples.NOT_APPLICABLE_MODULES:
        k = sum(n.startswith(prefix) for n in skipped)
        lines.append(
            f"| `{prefix}*` ({k} functions) | " + " | ".join(["–"] * len(ts)) + " |"
        )
    summary = (
        f"\n{len(rows())} callables (and the {len(skipped)} functions of "
        + ", ".join(f"`{p}*`" for p in examples.NOT_APPLICABLE_MODULES)
        + f"), {len(ts)} transforms: {counts['pass']} cells pass, {counts['fail']} fail, "
        f"{counts['na']} do not apply, {counts['untested']} not run."
    )
    out = [
        HEADER.format(
            columns="\n".join(
                ["| column | what the cell checks |", "|---|---|"]
                + [f"| {k} | {v} |" for k, v in COLUMNS.items()]
            ).replace("{compile_ci}", str(len(status.COMPILE_CI))),
            summary=summary,
        ),
        *lines,
        "",
        "## Failing cells",
        "",
        "| callable | transform | reason |",
        "|---|---|---|",
    ]
    for name, t, state, reason in notes:
        if state == "fail":
            out.append(f"| `{name}` | {examples.TRANSFORM_TITLES[t]} | {_cell(reason)} |")
    out += [
        "",
        "## Cells that do not apply",
        "",
        "| callable | transforms | reason |",
        "|---|---|---|",
    ]
    grouped: dict = {}
    for name, t, state, reason in notes:
        if state == "na":
            grouped.setdefault((name, reason), []).append(examples.TRANSFORM_TITLES[t])
    for (name, reason), ts_ in grouped.items():
        which = "all" if len(ts_) == len(ts) else ", ".join(ts_)
        out.append(f"| `{name}` | {which} | {_cell(reason)} |")
    for prefix, reason in examples.NOT_APPLICABLE_MODULES.items():
        out.append(f"| `{prefix}*` | all | {_cell(reason)} |")
    return "\n".join(out) + "\n"


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def main(argv):
    text = render()
    if "--check" in argv:
        return 0 if DOC.read_text() == text else 1
    DOC.write_text(text)
    print(f"wrote {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
