"""``rigidkit convert``: one rotation from the command line, or a batch of files."""

from __future__ import annotations

import os
import sys

import numpy as np

from ...errors import RigidkitError
from .convert import PROG, check_finite, convert, one_line, warn_if_degrees
from .formatting import format_table, json_document, table_rows
from .parser import build_parser, shield_negative_numbers
from .reading import kind_of, read_csv, read_npy
from .representations import CLIError, representation, targets
from .writing import column_names, write_atomically, write_csv, write_npy

__all__ = ["main"]


def main(argv=None) -> int:
    """Run the ``rigidkit`` command line with ``argv`` (default ``sys.argv[1:]``).

    Returns the exit status (0 success, 2 user error, 130 interrupted); the
    console script and ``python -m rigidkit`` pass it to :func:`sys.exit`.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(run_convert)
    try:
        args = parser.parse_args(shield_negative_numbers(argv))
    except SystemExit as exc:  # --help, --version, or a usage error (already printed)
        return exc.code if isinstance(exc.code, int) else 2
    if args.command is None:
        parser.print_help(sys.stderr)
        return 2
    try:
        return args.func(args)
    except (CLIError, RigidkitError) as exc:
        print(f"{PROG}: error: {one_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # a temporary output file is already removed
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): not an error of ours. Point stdout at
        # devnull so that the interpreter's final flush does not fail again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


def run_convert(args) -> int:
    """The ``convert`` command on parsed ``args``: one rotation, or a batch."""
    to = targets(args.to) if args.to else None
    if args.input is None:
        if args.output is not None:
            raise CLIError(
                "--output needs --input (a batch); one rotation prints to stdout"
            )
        return _convert_one(args, to or targets(["all"]))
    if to is None:
        raise CLIError("a batch needs --to TARGET ... (the representations to write)")
    if args.format != "table":
        raise CLIError(
            "--format is for one rotation; a batch is written as its file's extension "
            "says (.csv, .txt or .npy)"
        )
    return _convert_batch(args, to)


def _convert_one(args, to) -> int:
    tokens = list(args.values)
    if args.source is None:
        if not tokens:
            raise CLIError(
                "give a rotation (REPR VALUE ...), e.g. 'euler:ZYX 30 20 10 --degrees', "
                "or a batch with --input FILE"
            )
        source_name = tokens.pop(0).strip()
    else:
        source_name = args.source
    source = representation(source_name)
    values = _parse_values(tokens, source)
    warn_if_degrees(source, values, args.degrees)
    outputs = convert(source, values, to, args.degrees, orthonormalize=args.orthonormalize)
    if args.format == "json":
        print(json_document(to, outputs, args.degrees, args.decimals))
    else:
        print(format_table(table_rows(to, outputs, args.degrees), args.decimals))
    return 0


def _parse_values(tokens, source) -> np.ndarray:
    values = []
    for k, token in enumerate(tokens):
        try:
            values.append(float(token))
        except ValueError:
            raise CLIError(
                f"value {k + 1} of {source.name} is {token.strip()!r}, not a number"
            ) from None
    if len(values) != source.size:
        raise CLIError(
            f"{source.name} takes {source.size} numbers ({', '.join(source.columns)}), "
            f"got {len(values)}"
        )
    bad = [t.strip() for t, v in zip(tokens, values, strict=True) if not np.isfinite(v)]
    if bad:
        raise CLIError(f"{source.name}: {bad[0]!r} is not finite")
    return np.array(values, dtype=np.float64)


def _batch_source(args):
    """The representation of a batch: ``--from REPR``, or ``REPR`` given first."""
    given = [v.strip() for v in args.values]
    if args.source is None and len(given) == 1:
        return representation(given[0])
    if args.source is None and not given:
        raise CLIError(
            "a batch needs the representation of its rows: --from REPR (or REPR first)"
        )
    if given and given != [args.source]:
        raise CLIError(
            f"with --input, give no rotation on the command line (got {given[0]!r}); "
            "only its representation, once (REPR or --from REPR)"
        )
    return representation(args.source)


def _convert_batch(args, to) -> int:
    source = _batch_source(args)
    output = "-" if args.output is None else args.output
    in_kind = kind_of(args.input, "input")
    out_kind = kind_of(output, "output")
    read = read_npy if in_kind == "npy" else read_csv
    values, where = read(args.input, source)
    check_finite(values, where)
    warn_if_degrees(source, values, args.degrees, where)
    outputs = convert(
        source,
        values,
        to,
        args.degrees,
        orthonormalize=args.orthonormalize,
        where=where,
    )
    table = np.concatenate(outputs, axis=1) if outputs else np.empty((len(values), 0))
    if table.shape[0] != len(values):  # never write fewer rows than were read
        raise CLIError(
            f"{len(values)} rows read but {table.shape[0]} converted; nothing written"
        )
    header = column_names(to)
    digits = args.decimals
    if output == "-":
        write_csv(sys.stdout, header, table, decimals=digits)
    elif out_kind == "npy":
        write_atomically(
            output, lambda f: write_npy(f, table, decimals=digits), binary=True
        )
    else:
        sep = " " if out_kind == "txt" else ","
        write_atomically(
            output,
            lambda f: write_csv(f, header, table, decimals=digits, separator=sep),
            binary=False,
        )
    return 0
