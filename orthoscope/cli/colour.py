"""``orthoscope colour``: longitudinal colour (focal shift), lateral colour and distortion per
wavelength of a lens. Also the ``--wavelengths`` / ``--scale`` flags other commands share."""

from __future__ import annotations

import argparse

from .common import (
    CliError,
    add_force_arg,
    add_lens_object_args,
    add_output_args,
    check_plot_path,
    field_keyword,
    load_input,
    print_result,
    resolve_object_fields,
    resolve_planes,
    save_plot,
)

#: Quick runs of this command for the per-command tests: argv lists with {data} = tests/data,
#: {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["colour", "cooke-triplet-f4", "--fields", "0,10,20", "--wavelengths", "F,d,C"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("--plot", ".png")]

WAVELENGTHS_HELP = (
    "Comma-separated wavelengths: nm (a bare number; values below 100 are refused as looking "
    "like um), a number with a unit (0.5876um, 587.6nm), a spectral line letter (F, d, C, e, g, "
    "h, i, F', C', D, r, s, t) or 'lens' for the lens file's own wavelengths."
)
SCALE_HELP = (
    "What each wavelength's distortion is measured against: 'reference' (default: the lens's "
    "reference wavelength's F0/M0 for every wavelength — one camera constant for all colour "
    "channels, as a calibration sees it) or 'own' (each wavelength's own F0/M0)."
)


def wavelengths_arg(text: str):
    """argparse type of --wavelengths: ``"lens"`` or a tuple of nm
    (:func:`raytrace.units.wavelengths_nm`: the one check also the API uses)."""
    from raytrace.units import UnitError, wavelengths_nm

    if text.strip().lower() == "lens":
        return "lens"
    try:
        return wavelengths_nm(text, "--wavelengths")
    except UnitError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def add_wavelengths_arg(p, *, help: str = WAVELENGTHS_HELP) -> None:
    p.add_argument("--wavelengths", type=wavelengths_arg, metavar="W1,W2,...", help=help)


def add_scale_arg(p) -> None:
    p.add_argument("--scale", choices=["reference", "own"], default="reference", help=SCALE_HELP)


def _pair(text: str):
    v = wavelengths_arg(text)
    if v == "lens" or len(v) != 2:
        raise argparse.ArgumentTypeError("--pair takes two wavelengths, e.g. F,C or 450,650")
    return v


def cmd_colour(args) -> int:
    from distortion.characteristic import characteristic_distortion
    from distortion.colour import focal_shift, lateral_colour

    from ..report.colour import (
        chromatic_distortion_to_dict,
        focal_shift_to_dict,
        format_chromatic_distortion,
        format_focal_shift,
        format_lateral_colour,
        lateral_colour_to_dict,
    )

    lens = load_input(args)
    if args.plot:
        check_plot_path(args.plot, "--plot", args)
    od, fields, kind = resolve_object_fields(lens, args)
    planes = resolve_planes(lens, args)
    wls = args.wavelengths
    if wls is None:
        wls = "lens" if len(lens.wavelengths) > 1 else (486.1327, 587.5618, 656.2725)
    wl_list = tuple(lens.wavelengths) if wls == "lens" else tuple(wls)
    pair = args.pair or (min(wl_list), max(wl_list))
    if pair[0] == pair[1]:
        raise CliError("lateral colour needs two different wavelengths (--pair or --wavelengths)")
    fkw = field_keyword(fields, kind)
    fs = focal_shift(lens, wl_list, kind=args.focus, object_distance=od)
    lc = lateral_colour(lens, wavelengths=pair, object_distance=od, plane=planes, **fkw)
    cd = characteristic_distortion(
        lens, **fkw, object_distance=od, plane=planes, wavelengths=wl_list, scale=args.scale
    )
    print_result(
        args,
        json=lambda: {
            "focal_shift": focal_shift_to_dict(fs),
            "lateral_colour": lateral_colour_to_dict(lc),
            "distortion": chromatic_distortion_to_dict(cd),
        },
        text=lambda: "\n\n".join(
            (format_focal_shift(fs), format_lateral_colour(lc), format_chromatic_distortion(cd))
        ),
    )
    if args.plot:
        from ..plots.colour import plot_colour_summary

        curve = focal_shift(lens, kind=args.focus, object_distance=od)
        save_plot(lambda: plot_colour_summary(curve, lc, cd), args.plot, args)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "colour",
        help="Colour: focal shift, lateral colour and distortion per wavelength.",
        description=(
            "Longitudinal colour (the image plane of each wavelength relative to the reference "
            "wavelength's: paraxial, or best focus), lateral colour (real chief-ray height "
            "y'(W1) - y'(W2) per field, linear and relative to the reference image height) and "
            "characteristic distortion per wavelength. All wavelengths are traced in one call, "
            "in the image planes and for the object points of the lens's reference wavelength. "
            "Default wavelengths: the lens file's, or F, d, C for a file with one."
        ),
        epilog=(
            "Examples:\n"
            "  orthoscope colour cooke-triplet-f4 --wavelengths F,d,C --fields 0,5,10,15,20\n"
            "  orthoscope colour tessar-fr1066698 --focus best-focus --scale own --plot colour.png"
        ),
    )
    add_lens_object_args(q, repeatable=True)
    add_wavelengths_arg(q)
    q.add_argument(
        "--pair",
        type=_pair,
        metavar="W1,W2",
        help="The two wavelengths of lateral colour y'(W1) - y'(W2) (default: the shortest and "
        "the longest of --wavelengths).",
    )
    q.add_argument(
        "--focus",
        choices=["paraxial", "best-focus"],
        default="paraxial",
        help="Focal shift of the paraxial image (default) or of the plane of least RMS spot "
        "radius of the axial point.",
    )
    add_scale_arg(q)
    q.add_argument(
        "--plot",
        metavar="FILE",
        help="Save a chart (.png/.svg/.pdf): focal-shift curve, lateral colour, distortion per "
        "wavelength.",
    )
    add_force_arg(q, help="Replace an existing plot file (never an input).")
    add_output_args(q, csv=False)
    q.set_defaults(func=cmd_colour)
