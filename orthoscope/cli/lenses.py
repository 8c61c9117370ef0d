"""``orthoscope lenses``: the bundled lens library."""

from __future__ import annotations

import argparse

from .common import add_output_args, print_result

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["lenses"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = []


def cmd_lenses(args) -> int:
    from raytrace.files.library import list_lenses

    from ..report.lenses import format_lens_table, lens_infos_to_dict

    infos = list_lenses()
    print_result(
        args, json=lambda: lens_infos_to_dict(infos), text=lambda: format_lens_table(infos)
    )
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "lenses",
        help="List the bundled lenses.",
        description="The bundled lenses with EFL, f-number, field, kind and source.",
        epilog="Example: orthoscope lenses --json",
    )
    add_output_args(q, csv=False, json_help="Print JSON.")
    q.set_defaults(func=cmd_lenses)
