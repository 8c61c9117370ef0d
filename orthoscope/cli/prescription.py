"""``orthoscope prescription``: the surface table of a lens with its first-order summary."""

from __future__ import annotations

import argparse

from .common import add_lens_arg, add_output_args, load_input, print_result

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["prescription", "cooke-triplet-f4"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = []


def cmd_prescription(args) -> int:
    from raytrace.listing import format_prescription

    from ..report.prescription import prescription_to_dict

    lens = load_input(args)
    print_result(
        args, json=lambda: prescription_to_dict(lens), text=lambda: format_prescription(lens)
    )
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "prescription",
        help="The surface table of a lens (radii, thicknesses, media, stop) and its EFL, BFL.",
        description="Print a lens's prescription: one row per surface (radius, thickness to the "
        "next vertex, medium after the surface, semi-diameter, conic, aspheric terms, stop) and "
        "its first-order summary. The same table is str(lens) in Python.",
        epilog="Example: orthoscope prescription cooke-triplet-f4",
    )
    add_lens_arg(q)
    add_output_args(q, csv=False, json_help="Print JSON (keys carry units).")
    q.set_defaults(func=cmd_prescription)
