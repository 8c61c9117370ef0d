"""``orthoscope compensate``: residual distortion of a print (Pestrecov Section VI)."""

from __future__ import annotations

import argparse
import math

from .common import (
    METHODS,
    CliError,
    NotedStore,
    add_alias,
    add_output_args,
    at_fields,
    bundled_or_path,
    load,
    parse_list,
    print_result,
)

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [
    ["compensate", "topogon-us2031792-fig1", "twinplex-like-55-525", "--fields", "0,10,20,30"]
]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = []


def _curve_from(arg: str, role: str, args, camera_curve=None):
    """A DistortionCurve from a CSV table or from a lens (traced)."""
    from pathlib import Path

    import numpy as np

    from distortion.characteristic import characteristic_distortion
    from distortion.tablefile import read_distortion_table

    table = bundled_or_path(arg, "", ".csv")  # a bundled table by name, as calibrate takes it
    if Path(table).suffix.lower() == ".csv":
        if role == "camera" and args.fields:
            raise CliError(f"--fields goes with a CAMERA lens; the table {arg} has its own fields")
        return read_distortion_table(table)
    lens = load(arg)
    if role == "camera":
        if lens.field.kind != "angle" and not args.fields:
            raise CliError(f"camera {arg}: give --fields (angles in degrees)")
        fields = (
            parse_list(args.fields, "--fields")
            if args.fields
            else np.linspace(0.0, lens.field.value, 11)
        )
        return characteristic_distortion(lens, fields, object_distance=math.inf).curve(0)
    # printer: finite conjugates, object heights covering the camera's negative
    if math.isinf(lens.object_distance):
        raise CliError(f"printer {arg}: the lens file must define a finite object distance")
    hmax = float(np.max(np.abs(camera_curve.yp))) * 1.02
    h = np.linspace(0.0, hmax, 41)
    return characteristic_distortion(lens, object_heights_mm=h).curve(0)


def cmd_compensate(args) -> int:
    from distortion.compensation import compensate

    from ..report.distortion import compensation_to_dict, format_compensation

    m = args.magnification
    if m is not None and not (math.isfinite(m) and m != 0.0):
        raise CliError(
            f"--magnification {m:g}: the print magnification factor M must be a finite nonzero "
            "number, of the sign of the printer's M2 (default: M2)"
        )
    cam = _curve_from(args.camera, "camera", args)
    prn = _curve_from(args.printer, "printer", args, camera_curve=cam)
    res = compensate(
        cam, prn, method=args.method, magnification=args.magnification, at=at_fields(args.at)
    )
    print_result(
        args, json=lambda: compensation_to_dict(res), text=lambda: format_compensation(res)
    )
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "compensate",
        help="Residual distortion of a print: camera distortion compensated by a printer.",
        description=(
            "Pestrecov Section VI: a camera (object at infinity; F1, D1) and a printer (finite "
            "conjugates; M2, D2 referred to the negative). Prints the residual "
            "R = D1 - D2 - (M/M2 - 1) F1 tan(alpha) (Eq. 16) and the print magnification factor M "
            "chosen by --method. CAMERA and PRINTER are distortion tables (.csv) or lenses "
            "(files or bundled names; the printer file must define its finite object distance)."
        ),
        epilog="Example: orthoscope compensate topogon-us2031792-fig1 twinplex-like-55-525 "
        "--fields 0,10,20,30,35",
    )
    q.add_argument("camera", metavar="CAMERA", help="Camera distortion table (.csv) or lens.")
    q.add_argument("printer", metavar="PRINTER", help="Printer distortion table (.csv) or lens.")
    q.add_argument(
        "--method",
        action=NotedStore,
        default="given",
        choices=METHODS,
        help="How M is chosen: 'given' (--magnification, default M2: Pestrecov's condition for "
        "characteristic curves) or a calibration method over the camera fields.",
    )
    add_alias(
        q, "--criterion", "--method", "method", what="the method that chooses M", choices=METHODS
    )
    q.add_argument(
        "--magnification",
        action=NotedStore,
        type=float,
        metavar="M",
        help="Print magnification factor M for 'given' (default M2): of the sign of M2; more "
        "than 10%% from M2 warns, more than a factor of 2 is refused.",
    )
    add_alias(
        q,
        "--M",
        "--magnification",
        "magnification",
        what="the print magnification factor M",
        type=float,
    )
    q.add_argument("--at", metavar="A[,B]", help="Field(s) for two-point or zero-at (degrees).")
    q.add_argument(
        "--fields", metavar="F1,F2,...", help="Camera field angles (deg) when CAMERA is a lens."
    )
    add_output_args(q, csv=False, json_help="Print JSON.")
    q.set_defaults(func=cmd_compensate)
