"""``orthoscope pupils``: image-side chief-ray angle (telecentricity), real exit and entrance
pupils per field, the viewpoint offset and the exact change of distortion with the image plane
(∂D0/∂s'); :mod:`distortion.telecentricity`."""

from __future__ import annotations

import argparse

from .common import (
    add_force_arg,
    add_lens_object_args,
    add_output_args,
    add_strict_arg,
    add_table_layout_arg,
    add_wavelength_arg,
    check_plot_path,
    check_traced_any,
    field_keyword,
    load_input,
    print_result,
    resolve_object_fields,
    save_plot,
    strict_check,
)

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [
    ["pupils", "cooke-triplet-f4", "--fields", "0,10,20"],
    ["pupils", "twinplex-like-55-525", "--object-s", "-55.0009", "--fields", "0,20,45", "--json"],
]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("--plot", ".png")]


def cmd_pupils(args) -> int:
    import numpy as np

    from distortion.telecentricity import pupil_analysis

    from ..report.telecentricity import format_pupils, pupils_csv, pupils_to_dict

    lens = load_input(args)
    check_plot_path(args.plot, "--plot", args)
    od, fields, kind = resolve_object_fields(lens, args)
    pa = pupil_analysis(
        lens, **field_keyword(fields, kind), object_distance=od, wavelength=args.wavelength
    )
    print_result(
        args,
        json=lambda: {"pupils": pupils_to_dict(pa)},
        csv=lambda: pupils_csv(pa),
        text=lambda: format_pupils(pa, layout=args.table_layout),
    )
    if args.plot:
        check_traced_any(np.isfinite(pa.cra_deg).any())
        from ..plots.telecentricity import plot_pupils

        save_plot(lambda: plot_pupils(pa), args.plot, args)
    strict_check(args, pa.status)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "pupils",
        help="Chief-ray angle (telecentricity), real pupils and viewpoint, dD0/ds' per field.",
        description=(
            "Per field, from the real chief rays (through the centre of the real stop): the "
            "image-side chief-ray angle CRA and the real exit pupil it implies (telecentric "
            "lens: CRA = 0, exit pupil at infinity); the exact rate dD0/ds' = tan CRA - "
            "x dK0/ds' at which the characteristic distortion changes from one image plane to "
            "another (Pestrecov Section V; D0 is affine in s' for a fixed object); and the real "
            "entrance pupil (viewpoint) with its shift from the paraxial E0 and the lateral "
            "offset of the object-space chief ray from E0."
        ),
        epilog=(
            "Examples:\n"
            "  orthoscope pupils super-angulon-de975637 --plot pupils.png\n"
            "  orthoscope pupils twinplex-like-55-525 --object-s -55.0009 --json"
        ),
    )
    add_lens_object_args(q, planes=False)
    add_wavelength_arg(q)
    add_table_layout_arg(q)
    add_strict_arg(q)
    q.add_argument(
        "--plot",
        metavar="FILE",
        help="Save a three-panel chart (.png/.svg/.pdf): chief-ray angle, dD0/ds', entrance "
        "pupil shift and viewpoint offset against the field.",
    )
    add_force_arg(q)
    add_output_args(q)
    q.set_defaults(func=cmd_pupils)
