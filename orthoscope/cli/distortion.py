"""``orthoscope distortion``: characteristic (and calibrated) distortion in one or more planes."""

from __future__ import annotations

import argparse

from .common import (
    add_field_args,
    add_object_args,
    add_output_args,
    add_plane_args,
    add_wavelength_arg,
)

METHOD_HELP = (
    "Calibration method (Pestrecov Eqs. 10-15): 'two-point' (equal magnitude, opposite sign "
    "at the two --at fields, the paper's example), 'minimax' (smallest max |Dc| over the fields, "
    "exact), 'least-squares', 'zero-at' (Dc = 0 at the --at field), 'given' (--value Fc or Mc)."
)
AT_HELP = "Field(s) for two-point (two) or zero-at (one): degrees or object heights, A,B."
EXAGGERATION_HELP = (
    "Plot exaggeration k of the distortion scale (Eq. 14: tan rho_k = k (Fc/F0 - 1)). Default: 200."
)
REFERENCE_HELP = (
    "Reference definition: 'characteristic' (Pestrecov Eq. 8, paraxial M0/F0 in the actual "
    "plane; default), 'distortion-focal-length' (scale of a near-axis real chief ray in the "
    "evaluation plane), 'real-chief-transport' (Gaussian reference point carried along the real "
    "chief ray to the plane)."
)
TABLE_LAYOUT_HELP = (
    "Table orientation: 'rows' (one row per field; default) or 'paper' (fields across, as "
    "Pestrecov's Tables I, II and V)."
)


#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["distortion", "cooke-triplet-f4", "--fields", "0,10,20", "--calibrate", "minimax"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("--plot", ".png"), ("--plot-rotation", ".png"), ("--layout", ".png")]


def add_calibration_args(q: argparse.ArgumentParser, *, required: bool) -> None:
    from .common import METHODS

    g = q.add_argument_group("calibration")
    if required:
        g.add_argument("--method", required=True, choices=METHODS, help=METHOD_HELP)
        g.add_argument(
            "--criterion",
            dest="method",
            choices=METHODS,
            action=_alias("--method"),
            help=argparse.SUPPRESS,
        )
    else:
        g.add_argument("--calibrate", metavar="METHOD", choices=METHODS, help=METHOD_HELP)
    g.add_argument("--at", metavar="A[,B]", help=AT_HELP)
    g.add_argument("--value", type=float, metavar="K", help="Fc (mm) or Mc for 'given'.")
    g.add_argument("--exaggeration", type=float, default=200.0, metavar="K", help=EXAGGERATION_HELP)
    g.add_argument(
        "--k",
        dest="exaggeration",
        type=float,
        action=_alias("--exaggeration"),
        help=argparse.SUPPRESS,
    )


def _alias(new: str):
    from functools import partial

    from .common import DeprecatedAlias

    return partial(DeprecatedAlias, new=new)


def add_table_layout_arg(q: argparse.ArgumentParser) -> None:
    q.add_argument(
        "--table-layout", choices=["rows", "paper"], default="rows", help=TABLE_LAYOUT_HELP
    )


def at_fields(text: str | None) -> tuple[float, ...] | None:
    from .common import parse_list

    return None if text is None else tuple(parse_list(text, "--at"))


def check_plot_path(path: str | None, flag: str, args) -> None:
    """Refuse a plot file name before any work: suffix, folder, no overwrite without --force."""
    if path is None:
        return
    from pathlib import Path

    from raytrace.files.output import check_output

    from .common import CliError

    check_output(path, inputs=getattr(args, "_inputs", ()), overwrite=args.force, flag="--force")
    if Path(path).suffix.lower() not in (".png", ".svg", ".pdf"):
        raise CliError(f"{flag} {path}: the file must end in .png, .svg or .pdf")


def cmd_distortion(args) -> int:
    import numpy as np

    from distortion.calibration import calibrate
    from distortion.characteristic import characteristic_distortion

    from ..report.distortion import (
        calibration_to_dict,
        characteristic_csv,
        characteristic_to_dict,
        format_calibration,
        format_characteristic,
    )
    from .common import (
        CliError,
        field_keyword,
        load,
        print_json,
        resolve_fields,
        resolve_object,
        resolve_planes,
    )

    lens = load(args.lens)
    args._inputs = [lens.path] if lens.path else []
    od = resolve_object(lens, args)
    fields, kind = resolve_fields(lens, args)
    at = at_fields(args.at)
    if at:
        fields = np.union1d(fields, np.array(at))
    for flag in ("plot", "plot_rotation", "layout"):
        check_plot_path(getattr(args, flag), "--" + flag.replace("_", "-"), args)
    planes = resolve_planes(lens, args)
    if kind == "height" and od == float("inf"):
        raise CliError("object-height fields need a finite object (--object-distance)")
    res = characteristic_distortion(
        lens,
        **field_keyword(fields, kind),
        object_distance=od,
        plane=planes,
        reference=args.reference,
        wavelength=args.wavelength,
    )
    if args.calibrate is None and (args.at is not None or args.value is not None):
        raise CliError("--at and --value need --calibrate METHOD")
    cals = (
        [
            calibrate(res, args.calibrate, at=at, value=args.value, k=args.exaggeration, plane=i)
            for i in range(res.n_planes)
        ]
        if args.calibrate
        else []
    )
    if args.json:
        out = {"distortion": characteristic_to_dict(res)}
        if cals:
            out["calibration"] = [calibration_to_dict(c) for c in cals]
        print_json(out)
    elif args.csv:
        if cals:
            raise CliError("--csv prints the characteristic table; use --json with --calibrate")
        print(characteristic_csv(res))
    else:
        print(format_characteristic(res, layout=args.table_layout))
        for i, c in enumerate(cals):
            print()
            if res.n_planes > 1:
                print(f"Plane {i + 1}: {res.plane_label(i)}")
            print(format_calibration(c, layout=args.table_layout))
    _plots(res, cals, args, lens)
    bad = int(np.count_nonzero(res.status != 0))
    if bad and args.strict:
        raise CliError(f"{bad} field(s) could not be traced (see the table); --strict fails")
    return 0


def _plots(res, cals, args, lens) -> None:
    import numpy as np

    from .common import CliError

    if (args.plot or args.plot_rotation or args.layout) and not np.isfinite(res.yp).any():
        raise CliError("no field could be traced (see the table): there is nothing to plot")

    if args.plot_rotation and not cals:
        raise CliError("--plot-rotation (Fig. 4) needs --calibrate")
    if not (args.plot or args.plot_rotation or args.layout):
        return
    from ..plots.common import offscreen_figures
    from ..plots.distortion import plot_calibrated, plot_characteristic, plot_planes, plot_rotation
    from ..plots.layout import plot_layout
    from ..plots.save import save_figure

    if args.plot:
        with offscreen_figures():
            if res.n_planes > 1:
                fig = plot_planes(res)
            elif cals:
                fig = plot_calibrated(cals[0])
            else:
                fig = plot_characteristic(res)
        save_figure(fig, args.plot, overwrite=args.force, inputs=args._inputs)
    if args.plot_rotation:
        with offscreen_figures():
            fig = plot_rotation(cals[0])
        save_figure(fig, args.plot_rotation, overwrite=args.force)
    if args.layout:
        key = "object_heights_mm" if res.field_kind == "height" else "fields_deg"
        with offscreen_figures():
            fig = plot_layout(
                lens,
                **{key: res.fields},
                object_distance=res.object_distance,
                z_planes=res.z_planes,
                wavelength=args.wavelength,
            )
        save_figure(fig, args.layout, overwrite=args.force)


def add_force_arg(q: argparse.ArgumentParser) -> None:
    q.add_argument(
        "--force", action="store_true", help="Replace existing output files (never an input)."
    )


def register(sub: argparse._SubParsersAction) -> None:
    from .common import REFERENCES

    q = sub.add_parser(
        "distortion",
        help="Characteristic (and calibrated) distortion in one or more image planes.",
        description=(
            "Pestrecov's characteristic distortion D0 = y' - F0 tan(alpha) (or y' - M0 y) with the "
            "paraxial constants of orthoscopy in the ACTUAL image plane (Eq. 8), from real chief "
            "rays. Several planes come from one trace. Prints one row per field (Table I; several "
            "planes: Table V); with --calibrate also Table II. Fields the lens cannot pass are "
            "listed as not traced; the exit status is still 0 unless --strict is given."
        ),
        epilog=(
            "Examples:\n"
            "  orthoscope distortion topogon-like-pestrecov "
            "--fields 0,10,20,25,30,35,37.5,40,42.5,45 --calibrate two-point --at 37.5,45\n"
            "  orthoscope distortion twinplex-like-55-525 --object-s -55.0009 "
            "--s-prime 425,525,625"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    q.add_argument("lens", metavar="LENS", help="Lens file path or bundled lens name.")
    add_object_args(q)
    add_field_args(q)
    add_plane_args(q, repeatable=True)
    q.add_argument("--reference", default="characteristic", choices=REFERENCES, help=REFERENCE_HELP)
    add_calibration_args(q, required=False)
    add_wavelength_arg(q)
    add_table_layout_arg(q)
    q.add_argument(
        "--strict", action="store_true", help="Exit with status 2 when a field cannot be traced."
    )
    g = q.add_argument_group("plots")
    g.add_argument(
        "--plot",
        metavar="FILE",
        help="Save a chart (.png/.svg/.pdf): Fig. 2 style (one plane), Fig. 3 "
        "(with --calibrate), Fig. 6 (several planes).",
    )
    g.add_argument(
        "--plot-rotation",
        metavar="FILE",
        help="Save Fig. 4: the characteristic curve rotated by -rho_k against the "
        "calibrated curve (needs --calibrate).",
    )
    g.add_argument(
        "--layout",
        metavar="FILE",
        help="Save a lens layout drawing with the chief rays to the image plane(s).",
    )
    add_force_arg(q)
    add_output_args(q)
    q.set_defaults(func=cmd_distortion)
