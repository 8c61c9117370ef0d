"""``orthoscope paraxial``: first-order data of a lens (no numba, no scipy: it starts fast)."""

from __future__ import annotations

import argparse

from .common import (
    add_lens_object_args,
    add_output_args,
    add_wavelength_arg,
    load_input,
    print_result,
    resolve_object,
)

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["paraxial", "cooke-triplet-f4", "--object-distance", "500"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = []


def cmd_paraxial(args) -> int:
    from raytrace.paraxial import paraxial

    from ..report.paraxial import format_paraxial, paraxial_to_dict

    lens = load_input(args)
    od = resolve_object(lens, args)
    par = paraxial(lens, od, args.wavelength)
    print_result(
        args,
        json=lambda: paraxial_to_dict(lens, par),
        text=lambda: format_paraxial(lens, par),
    )
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "paraxial",
        help="First-order data: EFL, BFL, cardinal points, pupils, m_e, Gaussian image.",
        description="Paraxial (first-order) listing of a lens, Pestrecov's HE0, H'E0', m_e "
        "(Eq. 6), and for a finite object s, p0, s' and m0 (Eqs. 5, 7). Positions are z from the "
        "first vertex.",
        epilog="Example: orthoscope paraxial twinplex-like-55-525 --object-s -55.0009",
    )
    add_lens_object_args(q, fields=False, planes=False)
    add_wavelength_arg(q)
    add_output_args(q, csv=False, json_help="Print JSON (keys as in the README).")
    q.set_defaults(func=cmd_paraxial)
