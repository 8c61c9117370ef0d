"""CLI: ``orthoscope convert IN OUT`` between native .toml, Zemax .zmx and CODE V .seq (read)."""

from __future__ import annotations

import argparse
import sys
import warnings


def cmd_convert(args) -> int:
    from raytrace.convert import convert
    from raytrace.library import resolve_lens_path
    from raytrace.zemax import InteropWarning

    src = resolve_lens_path(args.input)  # a path, or the name of a bundled lens
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InteropWarning)
        lens = convert(src, args.output)
    for w in caught:
        if issubclass(w.category, InteropWarning):
            print(f"orthoscope convert: warning: {w.message}", file=sys.stderr)
    print(f"wrote {args.output}: {lens.name} ({lens.n_surfaces} surfaces)")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    from raytrace.convert import convert

    q = sub.add_parser(
        "convert",
        help="Convert a lens between .toml, .zmx (read/write) and .seq (read).",
        description=convert.__doc__.split("\n    Returns")[0].replace("\n   ", "\n"),
    )
    q.add_argument(
        "input",
        metavar="IN",
        help="Lens to read: a .toml, .zmx or .seq file, or a bundled lens name.",
    )
    q.add_argument("output", metavar="OUT", help="Lens file to write (.toml or .zmx).")
    q.set_defaults(func=cmd_convert)
