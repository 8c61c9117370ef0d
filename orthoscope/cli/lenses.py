"""``orthoscope lenses``: the bundled lens library."""

from __future__ import annotations

import argparse

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["lenses"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = []


def cmd_lenses(args) -> int:
    from raytrace.files.library import list_lenses

    from ..report.lenses import format_lens_table, lens_infos_to_dict
    from .common import print_json

    infos = list_lenses()
    if args.json:
        print_json(lens_infos_to_dict(infos))
    else:
        print(format_lens_table(infos))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "lenses",
        help="List the bundled lenses.",
        description="The bundled lenses with EFL, f-number, field, kind and source.",
        epilog="Example: orthoscope lenses --json",
    )
    q.add_argument("--json", action="store_true", help="Print JSON.")
    q.set_defaults(func=cmd_lenses)
