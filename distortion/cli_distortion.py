"""CLI: ``orthoscope distortion``, ``orthoscope calibrate``, ``orthoscope compensate``."""

from __future__ import annotations

import argparse
import csv
import io
import math
from pathlib import Path

import numpy as np

from .cli import (
    DEFOCUS_HELP,
    IMAGE_HELP,
    VERTEX_HELP,
    CliError,
    add_field_args,
    add_object_args,
    add_output_args,
    load,
    parse_list,
    print_json,
    resolve_fields,
    resolve_object_distance,
)

CRITERION_HELP = (
    "Calibration criterion (Pestrecov Eqs. 10-15): 'two-point' (equal magnitude, opposite sign "
    "at the two --at fields, the paper's example), 'minimax' (smallest max |Dc| over the fields, "
    "exact), 'least-squares', 'zero-at' (Dc = 0 at the --at field), 'given' (--value Fc or Mc)."
)
AT_HELP = (
    "Field(s) for two-point (two) or zero-at (one): degrees or object heights, comma-separated."
)
K_HELP = "Plot exaggeration k of the distortion scale (Eq. 14: tan rho_k = k (Fc/F0 - 1)); 200."
REFERENCE_HELP = (
    "Reference definition (see README): 'characteristic' (Pestrecov Eq. 8, paraxial M0/F0 in the "
    "actual plane; default), 'distortion-focal-length' (scale of a near-axis real chief ray in the "
    "evaluation plane), 'real-chief-transport' (Gaussian reference point carried along the real "
    "chief ray to the plane)."
)
TABLE_HELP = (
    "Distortion table CSV: a header with the field column (alpha_deg or y_mm), y0p_mm, D0_mm and "
    "optionally Dr_pct; '#' lines are comments (see README)."
)


def _at(text: str | None) -> tuple[float, ...] | None:
    return None if text is None else tuple(parse_list(text, "--at"))


def _check_plot_path(path: str | None, flag: str) -> None:
    if path is None:
        return
    if Path(path).suffix.lower() not in (".png", ".svg", ".pdf"):
        raise CliError(f"{flag} {path}: the file must end in .png, .svg or .pdf")
    parent = Path(path).resolve().parent
    if not parent.is_dir():
        raise CliError(f"{flag} {path}: the folder {parent} does not exist")


def _planes(args) -> dict:
    """The image-plane keyword for characteristic_distortion (repeatable flags)."""
    given = {
        k: v
        for k, v in (
            ("s_prime", args.image_distance),
            ("image_distance", args.image_from_vertex),
            ("defocus", args.defocus),
        )
        if v
    }
    if given and args.gaussian:
        raise CliError(
            "--gaussian names the image plane: give it alone, or give the planes with "
            "--image-distance / --image-from-vertex / --defocus (which may include 0)"
        )
    if len(given) > 1:
        raise CliError(
            "give image planes with only one of --image-distance, --image-from-vertex, "
            "--defocus (each may be repeated)"
        )
    if not given and args.gaussian:
        return {}
    if not given:
        return {"file": True}
    return given


def _calibrations(res, args) -> list:
    from .calibration import calibrate

    if args.calibrate is None:
        if args.at is not None or args.value is not None:
            raise CliError("--at and --value need --calibrate CRITERION")
        return []
    return [
        calibrate(res.curve(i), args.calibrate, at=_at(args.at), value=args.value, k=args.k)
        for i in range(res.n_planes)
    ]


def _csv_rows(res) -> str:
    from raytrace.trace import STATUS_NAMES

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    fname = {"angle": "alpha_deg", "height": "y_mm", "nominal-angle": "nominal_alpha_deg"}[
        res.field_kind
    ]
    w.writerow(
        ["s_prime_mm", "defocus_mm", fname, "y_mm", "y0p_mm", "yp_mm", "D0_mm", "Dr_pct", "status"]
    )
    for p in range(res.n_planes):
        for i in range(res.fields.size):
            ok = res.status[i] == 0
            w.writerow(
                [
                    repr(float(res.s_prime[p])),
                    repr(float(res.defocus[p])),
                    repr(float(res.fields[i])),
                    "" if math.isnan(res.y[i]) else repr(float(res.y[i])),
                    repr(float(res.y0p[p, i])),
                    repr(float(res.yp[p, i])) if ok else "",
                    repr(float(res.D0[p, i])) if ok else "",
                    repr(float(100.0 * res.Dr[p, i])) if ok else "",
                    STATUS_NAMES[int(res.status[i])],
                ]
            )
    return buf.getvalue().rstrip("\n")


def cmd_distortion(args) -> int:
    from .calibration import calibration_to_dict, format_calibration
    from .characteristic import (
        characteristic_distortion,
        characteristic_to_dict,
        format_characteristic,
    )

    lens = load(args.lens)
    od = resolve_object_distance(lens, args.object_distance, args.s)
    fields, kind = resolve_fields(lens, args)
    at = _at(args.at)
    if at:
        fields = np.union1d(fields, np.array(at))
    for flag in ("plot", "plot_rotation", "layout"):
        _check_plot_path(getattr(args, flag), "--" + flag.replace("_", "-"))
    planes = _planes(args)
    if planes.pop("file", False) and lens.image_solve != "gaussian":
        # the image plane the lens file defines (its last thickness); a "gaussian" solve in the
        # file means the Gaussian plane of the object being traced (the default of the call)
        planes = {"image_distance": [lens.surfaces[-1].thickness]}
    if kind == "height" and math.isinf(od):
        raise CliError("object-height fields need a finite object (--object-distance)")
    res = characteristic_distortion(
        lens,
        fields,
        field_kind=kind,
        object_distance=od,
        reference=args.reference,
        wavelength=args.wavelength,
        **planes,
    )
    cals = _calibrations(res, args)
    if args.json:
        out = {"distortion": characteristic_to_dict(res)}
        if cals:
            out["calibration"] = [calibration_to_dict(c) for c in cals]
        print_json(out)
    elif args.csv:
        if cals:
            raise CliError("--csv prints the characteristic table; use --json with --calibrate")
        print(_csv_rows(res))
    else:
        print(format_characteristic(res))
        for i, c in enumerate(cals):
            print()
            if res.n_planes > 1:
                print(f"Plane {i + 1}: {res.plane_label(i)}")
            print(format_calibration(c))
    _plots(res, cals, args, lens)
    return 0


def _plots(res, cals, args, lens) -> None:
    if args.plot:
        from .plots import plot_calibrated, plot_characteristic, plot_planes

        if res.n_planes > 1:
            plot_planes([res.curve(i) for i in range(res.n_planes)], args.plot)
        elif cals:
            plot_calibrated(cals[0], args.plot)
        else:
            plot_characteristic(res.curve(0), args.plot)
    if args.plot_rotation:
        if not cals:
            raise CliError("--plot-rotation (Fig. 4) needs --calibrate")
        from .plots import plot_rotation

        plot_rotation(cals[0], args.plot_rotation)
    if args.layout:
        from .layout import plot_layout

        plot_layout(
            lens,
            res.fields,
            field_kind=args.field_kind or lens.field.kind,
            object_distance=res.object_distance,
            z_planes=res.z_planes,
            path=args.layout,
            wavelength=args.wavelength,
        )


def cmd_calibrate(args) -> int:
    from .calibration import calibrate, calibration_to_dict, format_calibration
    from .tables import read_distortion_table

    for flag in ("plot", "plot_rotation"):
        _check_plot_path(getattr(args, flag), "--" + flag.replace("_", "-"))
    curve = read_distortion_table(args.table, constant=args.constant)
    res = calibrate(curve, args.criterion, at=_at(args.at), value=args.value, k=args.k)
    if args.json:
        print_json(calibration_to_dict(res))
    elif args.csv:
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        fname = "alpha_deg" if not curve.finite else "y_mm"
        w.writerow([fname, "ycp_mm", "Dc_mm", "Drc_pct"])
        for i in range(curve.fields.size):
            w.writerow(
                [
                    repr(float(curve.fields[i])),
                    repr(float(res.ycp[i])),
                    repr(float(res.Dc[i])),
                    repr(float(100 * res.Drc[i])),
                ]
            )
        print(buf.getvalue().rstrip("\n"))
    else:
        print(format_calibration(res, layout=args.layout))
    if args.plot:
        from .plots import plot_calibrated

        plot_calibrated(res, args.plot)
    if args.plot_rotation:
        from .plots import plot_rotation

        plot_rotation(res, args.plot_rotation)
    return 0


def _curve_from(arg: str, role: str, args, camera_curve=None):
    """A DistortionCurve from a CSV table or from a lens (traced)."""
    from .characteristic import characteristic_distortion
    from .tables import read_distortion_table

    p = Path(arg)
    if p.suffix.lower() == ".csv":
        return read_distortion_table(p)
    lens = load(arg)
    if role == "camera":
        fields = (
            parse_list(args.fields, "--fields")
            if args.fields
            else np.linspace(0.0, lens.field.value if lens.field.kind == "angle" else 0.0, 11)
        )
        if lens.field.kind != "angle" and not args.fields:
            raise CliError(f"camera {arg}: give --fields (angles in degrees)")
        return characteristic_distortion(
            lens, fields, field_kind="angle", object_distance=math.inf
        ).curve(0)
    # printer: finite conjugates, object heights covering the camera's negative
    if math.isinf(lens.object_distance):
        raise CliError(f"printer {arg}: the lens file must define a finite object distance")
    hmax = float(np.max(np.abs(camera_curve.yp))) * 1.02
    h = np.linspace(0.0, hmax, 41)
    return characteristic_distortion(lens, h, field_kind="height").curve(0)


def cmd_compensate(args) -> int:
    from .compensation import compensate, compensation_to_dict, format_compensation

    cam = _curve_from(args.camera, "camera", args)
    prn = _curve_from(args.printer, "printer", args, camera_curve=cam)
    res = compensate(cam, prn, criterion=args.criterion, M=args.M, at=_at(args.at))
    if args.json:
        print_json(compensation_to_dict(res))
    else:
        print(format_compensation(res))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "distortion",
        help="Characteristic (and calibrated) distortion in one or more image planes.",
        description=(
            "Pestrecov's characteristic distortion D0 = y' - F0 tan(alpha) (or y' - M0 y) with the "
            "paraxial constants of orthoscopy in the ACTUAL image plane (Eq. 8), from real chief "
            "rays. Several planes come from one trace. Prints a table in the paper's layout "
            "(Table I for one plane, Table V for several); with --calibrate also Table II."
        ),
        epilog=(
            "Examples:\n"
            "  orthoscope distortion topogon-like-pestrecov "
            "--fields 0,10,20,25,30,35,37.5,40,42.5,45 --calibrate two-point --at 37.5,45\n"
            "  orthoscope distortion twinplex-like-55-525 --s -55.0009 --image-distance 425 "
            "--image-distance 525 --image-distance 625 --plot fig6.png"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    q.add_argument("lens", metavar="LENS", help="Lens file path or bundled lens name.")
    add_object_args(q)
    add_field_args(q)
    q.add_argument(
        "--image-distance",
        type=float,
        action="append",
        metavar="S'",
        help=IMAGE_HELP + " Repeatable.",
    )
    q.add_argument(
        "--image-from-vertex",
        type=float,
        action="append",
        metavar="D",
        help=VERTEX_HELP + " Repeatable.",
    )
    q.add_argument(
        "--defocus", type=float, action="append", metavar="DZ", help=DEFOCUS_HELP + " Repeatable."
    )
    q.add_argument(
        "--gaussian",
        action="store_true",
        help="Use the Gaussian image plane of the object instead of the file's plane.",
    )
    q.add_argument(
        "--reference",
        default="characteristic",
        choices=["characteristic", "distortion-focal-length", "real-chief-transport"],
        help=REFERENCE_HELP,
    )
    q.add_argument(
        "--calibrate",
        metavar="CRITERION",
        choices=["two-point", "minimax", "least-squares", "zero-at", "given"],
        help=CRITERION_HELP,
    )
    q.add_argument("--at", metavar="A[,B]", help=AT_HELP)
    q.add_argument("--value", type=float, metavar="K", help="Fc (mm) or Mc for --calibrate given.")
    q.add_argument("--k", type=float, default=200.0, help=K_HELP)
    q.add_argument("--wavelength", type=float, metavar="NM", help="Wavelength in nm.")
    q.add_argument(
        "--plot",
        metavar="FILE",
        help="Save a chart (.png/.svg/.pdf): Fig. 2 style (one plane), Fig. 3 "
        "(with --calibrate), Fig. 6 (several planes).",
    )
    q.add_argument(
        "--plot-rotation",
        metavar="FILE",
        help="Save Fig. 4: the characteristic curve rotated by -rho_k against the "
        "calibrated curve (needs --calibrate).",
    )
    q.add_argument(
        "--layout",
        metavar="FILE",
        help="Save a lens layout drawing with the chief rays to the image plane(s).",
    )
    add_output_args(q)
    q.set_defaults(func=cmd_distortion)

    q = sub.add_parser(
        "calibrate",
        help="Recalibrate a distortion table (CSV) with no lens: Table I -> Table II.",
        description=(
            "Calibrated distortion from a data table alone (Pestrecov Eqs. 10-15): the calibrated "
            "constant Fc (or Mc), tan rho = Fc/F0 - 1, rho_k, Dc, Drc, yc', max |Dc|, spreads and "
            "Drc on the axis. F0 (M0) is inferred from y0'/tan(alpha) (y0'/y) unless --constant "
            "gives it."
        ),
        epilog="Example: orthoscope calibrate table1.csv --criterion two-point --at 37.5,45",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    q.add_argument("table", metavar="TABLE.csv", help=TABLE_HELP)
    q.add_argument(
        "--criterion",
        required=True,
        choices=["two-point", "minimax", "least-squares", "zero-at", "given"],
        help=CRITERION_HELP,
    )
    q.add_argument("--at", metavar="A[,B]", help=AT_HELP)
    q.add_argument("--value", type=float, metavar="K", help="Fc (mm) or Mc for 'given'.")
    q.add_argument(
        "--constant",
        type=float,
        metavar="K0",
        help="F0 (mm) or M0 of the table (default: inferred from the table).",
    )
    q.add_argument("--k", type=float, default=200.0, help=K_HELP)
    q.add_argument(
        "--layout",
        choices=["auto", "paper", "rows"],
        default="auto",
        help="Table layout: the paper's (fields across) or one row per field.",
    )
    q.add_argument("--plot", metavar="FILE", help="Save Fig. 3 (calibrated distortion).")
    q.add_argument("--plot-rotation", metavar="FILE", help="Save Fig. 4 (rotated curve).")
    add_output_args(q)
    q.set_defaults(func=cmd_calibrate)

    q = sub.add_parser(
        "compensate",
        help="Residual distortion of a print: camera distortion compensated by a printer.",
        description=(
            "Pestrecov Section VI: a camera (object at infinity; F1, D1) and a printer (finite "
            "conjugates; M2, D2 referred to the negative). Prints the residual "
            "R = D1 - D2 - (M/M2 - 1) F1 tan(alpha) (Eq. 16) and the print magnification factor M "
            "chosen by --criterion. CAMERA and PRINTER are distortion tables (.csv) or lenses "
            "(files or bundled names; the printer file must define its finite object distance)."
        ),
    )
    q.add_argument("camera", metavar="CAMERA", help="Camera distortion table (.csv) or lens.")
    q.add_argument("printer", metavar="PRINTER", help="Printer distortion table (.csv) or lens.")
    q.add_argument(
        "--criterion",
        default="given",
        choices=["given", "two-point", "minimax", "least-squares", "zero-at"],
        help="How M is chosen: 'given' (--M, default M2: Pestrecov's condition for "
        "characteristic curves) or a calibration criterion over the camera fields.",
    )
    q.add_argument("--M", type=float, help="Print magnification factor M for 'given'.")
    q.add_argument("--at", metavar="A[,B]", help=AT_HELP)
    q.add_argument(
        "--fields", metavar="F1,F2,...", help="Camera field angles (deg) when CAMERA is a lens."
    )
    q.add_argument("--json", action="store_true", help="Print JSON.")
    q.set_defaults(func=cmd_compensate)
