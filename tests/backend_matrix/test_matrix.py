"""The backend matrix: every public callable's example under every transform.

One test per cell (callable x transform, ``cells.py`` says what each checks); the
cells declared failing in ``status.py`` are ``xfail(strict=True)``, so a fix turns
them into an unexpected pass until the declaration is removed. ``torch.compile``
runs in CI for ``status.COMPILE_CI`` only (10-30 s a callable); the rest of that
column is ``exhaustive``. The other tests prove the registry covers the public API
and that docs/backends.md is what the declarations imply.
"""

from __future__ import annotations

import pytest

from . import cells, examples, status, table


def _cells():
    for name in sorted(examples.EXAMPLES):
        ex = examples.EXAMPLES[name]
        for t in examples.TRANSFORMS:
            if not ex.applies(t):
                continue
            marks = [pytest.mark.needs(cells.NEEDS[t])]
            if (name, t) in status.FAILS:
                marks.append(pytest.mark.xfail(strict=True, reason=status.FAILS[name, t]))
            if t == "compile" and name not in status.COMPILE_CI:
                marks.append(pytest.mark.exhaustive)
            yield pytest.param(name, t, marks=marks, id=f"{name}-{t}")


@pytest.mark.parametrize(("name", "transform"), list(_cells()))
def test_cell(name, transform):
    cells.run(examples.EXAMPLES[name], transform)


def test_every_public_callable_has_an_example():
    missing = [n for n in examples.public_callables() if examples.example_for(n) is None]
    assert not missing, (
        f"{len(missing)} public callables have no example in "
        f"tests/backend_matrix/examples.py: {missing}"
    )


def test_every_example_names_a_public_callable():
    public = set(examples.public_callables())
    stale = [n for n in examples.EXAMPLES if n.split("[")[0] not in public]
    assert not stale, f"examples of names that are not public callables: {stale}"


def test_declarations_name_cells_that_run():
    for (name, t), reason in status.FAILS.items():
        assert name in examples.EXAMPLES, name
        assert examples.EXAMPLES[name].applies(t), (name, t, "declared failing and n/a")
        assert reason.strip(), (name, t)
    for name in status.COMPILE_CI | status.COMPILE_CHECKED:
        assert examples.EXAMPLES[name].applies("compile"), name
    for ex in examples.EXAMPLES.values():
        assert all(r.strip() for r in ex.na.values()), ex.name
        if ex.fn is not None:
            assert ex.gens, ex.name


def test_docs_backends_md_is_generated_from_the_matrix():
    assert table.DOC.read_text() == table.render(), (
        "docs/backends.md differs from the matrix's declarations: "
        "run `python -m tests.backend_matrix.table`"
    )
