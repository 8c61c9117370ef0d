"""``orthoscope trace``: real chief rays to an image plane."""

from __future__ import annotations

import argparse

from .common import (
    add_lens_object_args,
    add_output_args,
    add_strict_arg,
    add_wavelength_arg,
    check_finite_object,
    load_input,
    plane_origin,
    print_result,
    resolve_fields,
    resolve_object,
    resolve_one_plane,
    strict_check,
)

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["trace", "cooke-triplet-f4", "--fields", "0,10,20"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = []


def cmd_trace(args) -> int:
    from raytrace.paraxial import paraxial, plane_z
    from raytrace.trace import aim

    from ..report.trace import format_trace, image_plane_dict, trace_csv, trace_to_dict

    lens = load_input(args)
    od = resolve_object(lens, args)
    fields, kind = resolve_fields(lens, args)
    par = paraxial(lens, od, args.wavelength)
    planes = resolve_one_plane(
        lens, args, "trace takes one image plane; 'orthoscope distortion' takes several"
    )
    z_img = float(plane_z(par, planes)[0])
    check_finite_object(kind, od)
    cr = aim(lens, fields, kind, od, args.wavelength)
    plane = image_plane_dict(par, z_img, plane_origin(args))
    print_result(
        args,
        json=lambda: trace_to_dict(lens, par, cr, plane),
        csv=lambda: trace_csv(cr, z_img),
        text=lambda: format_trace(lens, par, cr, plane),
    )
    strict_check(args, cr.status)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "trace",
        help="Real chief rays: image height, landing angle, real entrance pupil, status.",
        description="Trace the real chief rays (aimed at the centre of the real stop) and report "
        "per field the real image height y' on the image plane, the landing angle, the real "
        "entrance-pupil position (z from the first vertex) and the ray status.",
        epilog="Example: orthoscope trace topogon-us2031792-fig1 --max-field 50 --steps 10 --json",
    )
    add_lens_object_args(q)
    add_wavelength_arg(q)
    add_strict_arg(q)
    add_output_args(q)
    q.set_defaults(func=cmd_trace)
