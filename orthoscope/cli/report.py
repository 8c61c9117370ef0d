"""``orthoscope report``: the calibration certificate of a design — calibrated focal length, PPA and
PPBS, radial distortion along the four semi-diagonals, decentering profile — as text, JSON and a
one-page PDF (:mod:`distortion.certificate`)."""

from __future__ import annotations

import argparse

from raytrace.limits import MAX_FIELDS

from .common import (
    CliError,
    add_force_arg,
    add_lens_object_args,
    add_output_args,
    add_wavelength_arg,
    check_plot_path,
    load_input,
    print_result,
    resolve_object,
    resolve_one_plane,
    save_plot,
)

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [
    ["report", "cooke-triplet-f4", "--sensor", "24x16"],
    ["report", "topogon-us2031792-fig1", "--field-step", "10", "--json"],
]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("-o", ".pdf")]

METHOD_HELP = (
    "Criterion of the calibrated focal length: 'minimax' (equal largest positive and negative "
    "mean radial distortion over the format: the ASPRS definition; default) or 'least-squares'."
)
REFERENCE_POINT_HELP = (
    "Point the radial distortion is measured from: 'ppbs' (point of best symmetry; default), "
    "'ppa' (principal point of autocollimation), 'axial' (image of the axial object point)."
)


def cmd_report(args) -> int:
    from distortion.certificate import calibration_certificate

    from ..report.certificate import certificate_to_dict, format_certificate

    lens = load_input(args)
    check_plot_path(args.output, "-o", args)
    if args.sensor is not None and args.max_field is not None:
        raise CliError("give --sensor or --max-field, not both")
    od = resolve_object(lens, args)
    planes = resolve_one_plane(lens, args, "a certificate is for one image plane: give one value")
    # the work limit is checked there, before any trace (its message in flags: cli_words)
    cert = calibration_certificate(
        lens,
        sensor=args.sensor,
        object_distance=od,
        plane=planes,
        wavelength=args.wavelength,
        reference_point=args.reference_point,
        method=args.method,
        field_step_deg=args.field_step,
        max_field_deg=args.max_field,
        date=args.date,
        allow_large=bool(getattr(args, "allow_large", False)),
    )
    d = certificate_to_dict(cert)
    print_result(args, json=lambda: {"certificate": d}, text=lambda: format_certificate(d))
    if args.output:
        from ..plots.certificate import plot_certificate

        save_plot(lambda: plot_certificate(d), args.output, args)
    return 0


def _date(text: str) -> str:
    from distortion.certificate import iso_date
    from distortion.errors import DataError

    try:
        return iso_date(text)
    except DataError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def _step(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of degrees") from None
    if not 0.0 < v < 90.0:
        raise argparse.ArgumentTypeError(f"{text}: give a step between 0 and 90 degrees")
    return v


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "report",
        help="Calibration certificate of the design: calibrated focal length, PPA/PPBS, radial "
        "distortion along the semi-diagonals, decentering (text, JSON, one-page PDF).",
        description=(
            "The calibration certificate a laboratory would issue for a camera built exactly to "
            "the prescription (the USGS / ASPRS aerial-camera form), predicted by real chief rays "
            "at the stated object distance, wavelength, image plane and reference point: the "
            "calibrated focal length with its criterion, the principal points of autocollimation "
            "and of best symmetry, radial distortion in um along the four semi-diagonals of the "
            "format at regular field steps and their mean, the decentering profile J r^2 and its "
            "axis, and radial coefficients of the mean curve. -o writes it as a one-page PDF "
            "with its plots (or .png / .svg)."
        ),
        epilog=(
            "Examples:\n"
            "  orthoscope report topogon-like-pestrecov -o certificate.pdf\n"
            "  orthoscope report cooke-triplet-f4 --sensor 36x24 --object-distance 2m --json"
        ),
    )
    add_lens_object_args(q, fields=False)
    add_wavelength_arg(q)
    g = q.add_argument_group("format and form")
    g.add_argument(
        "--sensor",
        metavar="WxH",
        help="The format, W x H mm: the semi-diagonals run from the lens axis to its corners "
        "(default: the lens's field, semi-diagonals at 45, 135, 225, 315 deg).",
    )
    g.add_argument(
        "--max-field", type=float, metavar="DEG", help="The field without --sensor (deg)."
    )
    g.add_argument(
        "--field-step",
        type=_step,
        default=7.5,
        metavar="DEG",
        help=f"Step of the tabulated field angles (default 7.5). A step giving more than "
        f"{MAX_FIELDS} chief rays on the four semi-diagonals is refused without --allow-large; "
        "a long table prints one row per field in the text and every k-th field on the page.",
    )
    g.add_argument(
        "--reference-point",
        choices=["ppbs", "ppa", "axial"],
        default="ppbs",
        help=REFERENCE_POINT_HELP,
    )
    g.add_argument(
        "--method", choices=["minimax", "least-squares"], default="minimax", help=METHOD_HELP
    )
    g.add_argument(
        "--date", type=_date, metavar="YYYY-MM-DD", help="Date printed (default: today)."
    )
    q.add_argument(
        "-o",
        "--output",
        metavar="FILE",
        help="Write the one-page certificate: .pdf (A4), or .png / .svg of the same page.",
    )
    add_force_arg(q)
    add_output_args(q, csv=False)
    q.set_defaults(func=cmd_report)
