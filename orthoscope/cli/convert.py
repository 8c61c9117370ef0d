"""``orthoscope convert IN OUT`` between native .toml, Zemax .zmx, CODE V .seq and OSLO .len
(read)."""

from __future__ import annotations

import argparse

from .common import add_force_arg

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["convert", "cooke-triplet-f4", "{tmp}/cooke.zmx"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("OUT", ".zmx")]


def cmd_convert(args) -> int:
    import sys
    import warnings

    from raytrace.files import convert
    from raytrace.files.library import resolve_lens_path
    from raytrace.files.text import InteropWarning

    src = resolve_lens_path(args.input)  # a path, or the name of a bundled lens
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InteropWarning)
        lens = convert(src, args.output, overwrite=args.force, flag="--force")
    for w in caught:
        if issubclass(w.category, InteropWarning):
            print(f"orthoscope convert: warning: {w.message}", file=sys.stderr)
    print(f"wrote {args.output}: {lens.name} ({lens.n_surfaces} surfaces)")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "convert",
        help="Convert a lens between .toml, .zmx (read/write), .seq and .len (read).",
        description=(
            "Convert a lens file: IN (.toml, .zmx, .seq or .len, or a bundled lens name) to OUT "
            "(.toml or .zmx), formats chosen by the suffixes. Numbers are written at full double "
            "precision, so .toml -> .zmx -> .toml reproduces the lens exactly. OUT is never the "
            "same file as IN; an existing OUT is replaced only with --force."
        ),
        epilog="Example: orthoscope convert cooke-triplet-f4 cooke.zmx",
    )
    q.add_argument(
        "input",
        metavar="IN",
        help="Lens to read: a .toml, .zmx, .seq or .len file, or a bundled lens name.",
    )
    q.add_argument("output", metavar="OUT", help="Lens file to write (.toml or .zmx).")
    add_force_arg(q, help="Replace an existing OUT (never the input).")
    q.set_defaults(func=cmd_convert)
