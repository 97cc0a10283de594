"""Run every cell once, outside pytest, and print which fail and why.

``python -m tests.backend_matrix.discover [transform ...] [--names SUBSTRING]`` prints
the failing cells as ``status.py`` entries (the reason: the exception, its first
line, and the innermost rigidkit frame), and the time each transform took. A tool
for whoever updates ``status.py`` after a fix; the tests never call it.
"""

from __future__ import annotations

import sys
import time
import traceback
import warnings

from . import cells, examples


def reason_of(exc: BaseException) -> str:
    frames = [
        f for f in traceback.extract_tb(exc.__traceback__) if "/rigidkit/" in f.filename
    ]
    where = ""
    if frames:
        f = frames[-1]
        where = f" at {f.filename.split('/rigidkit/')[-1]}:{f.name}"
    msg = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    return f"{type(exc).__name__}: {msg[:140]}{where}"


def main(argv):
    names = None
    if "--names" in argv:
        i = argv.index("--names")
        names = argv[i + 1]
        argv = argv[:i] + argv[i + 2 :]
    transforms = argv or [t for t in examples.TRANSFORMS if t != "compile"]
    import importlib.util

    if importlib.util.find_spec("torch") is not None:
        import rigidkit._engine.torch_setup  # noqa: F401  (as tests/conftest.py)
    warnings.simplefilter("ignore")
    for t in transforms:
        start = time.perf_counter()
        for name, ex in sorted(examples.EXAMPLES.items()):
            if names and names not in name:
                continue
            if not ex.applies(t):
                continue
            try:
                cells.run(ex, t)
            except Exception as exc:  # noqa: BLE001  (every failure is reported)
                print(f"    ({name!r}, {t!r}): {reason_of(exc)!r},", flush=True)
        print(f"# {t}: {time.perf_counter() - start:.1f} s", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
