"""``orthoscope distortion``: characteristic (and calibrated) distortion in one or more planes."""

from __future__ import annotations

import argparse

from .common import (
    MAX_FIELDS,
    METHODS,
    REFERENCES,
    CliError,
    NotedStore,
    add_alias,
    add_force_arg,
    add_lens_object_args,
    add_output_args,
    add_strict_arg,
    add_table_layout_arg,
    add_wavelength_arg,
    at_fields,
    check_finite_object,
    check_plot_paths,
    check_size,
    check_traced_any,
    field_keyword,
    load_input,
    print_json,
    print_result,
    refuse_flags,
    resolve_fields,
    resolve_object,
    resolve_planes,
    save_plot,
    save_plots,
    strict_check,
)

METHOD_HELP = (
    "Calibration method (Pestrecov Eqs. 10-15): 'two-point' (equal magnitude, opposite sign "
    "at the two --at fields, the paper's example), 'minimax' (smallest max |Dc| over the fields, "
    "exact), 'least-squares', 'zero-at' (Dc = 0 at the --at field), 'given' (--value Fc or Mc)."
)
AT_HELP = (
    "Field(s) for two-point (two) or zero-at (one): degrees or object heights, A,B; traced with "
    "the run's fields (a value up to pi/2 that is no field of the run but, read as radians, lands "
    "on one is refused as looking like radians; list it in --fields to calibrate there)."
)
EXAGGERATION_HELP = (
    "Plot exaggeration k of the distortion scale (Eq. 14: tan rho_k = k (Fc/F0 - 1)). Default: 200."
)
REFERENCE_HELP = (
    "Reference definition: 'characteristic' (Pestrecov Eq. 8, paraxial M0/F0 in the actual "
    "plane; default), 'distortion-focal-length' (scale of a near-axis real chief ray in the "
    "evaluation plane), 'real-chief-transport' (Gaussian reference point carried along the real "
    "chief ray to the plane)."
)


#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [
    ["distortion", "cooke-triplet-f4", "--fields", "0,10,20", "--calibrate", "minimax"],
    ["distortion", "cooke-triplet-f4", "--grid", "5x5"],
    ["distortion", "cooke-triplet-f4", "--sensor", "24x16", "--grid", "7x5", "--sensor-metrics"],
]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("--plot", ".png"), ("--plot-rotation", ".png"), ("--layout", ".png")]


def add_calibration_args(q: argparse.ArgumentParser, *, required: bool) -> None:
    g = q.add_argument_group("calibration")
    if required:
        # required, checked by the command (argparse's required=True would refuse the
        # deprecated spelling --criterion, which stores to the same place)
        g.add_argument(
            "--method", action=NotedStore, choices=METHODS, help=METHOD_HELP + " Required."
        )
        add_alias(
            g, "--criterion", "--method", "method", what="the calibration method", choices=METHODS
        )
    else:
        g.add_argument("--calibrate", metavar="METHOD", choices=METHODS, help=METHOD_HELP)
    g.add_argument("--at", metavar="A[,B]", help=AT_HELP)
    g.add_argument("--value", type=float, metavar="K", help="Fc (mm) or Mc for 'given'.")
    g.add_argument(
        "--exaggeration",
        action=NotedStore,
        type=float,
        default=200.0,
        metavar="K",
        help=EXAGGERATION_HELP,
    )
    add_alias(
        g, "--k", "--exaggeration", "exaggeration", what="the plot exaggeration k", type=float
    )


def cmd_distortion(args) -> int:
    import numpy as np

    from distortion.calibration import calibrate, calibration_fields, looks_like_radians

    from ..report.distortion import (
        calibration_to_dict,
        characteristic_csv,
        characteristic_to_dict,
        format_calibration,
        format_characteristic,
    )

    lens = load_input(args)
    if _grid_mode(args):  # 2-D distortion: --grid / --plot-grid / --plot-vectors (below)
        return _grid(args, lens)
    od = resolve_object(lens, args)
    fields, kind = resolve_fields(lens, args)
    check_plot_paths(args, "plot", "plot_rotation", "layout")
    planes = resolve_planes(lens, args)
    check_finite_object(kind, od)
    if args.definition is not None:  # named definitions: orthoscope/cli/definitions.py
        from .definitions import run_definition

        return run_definition(lens, fields, kind, od, planes, args)
    if args.focal is not None:
        raise CliError("--focal needs --definition NAME")
    if args.wavelengths is not None:
        return _by_wavelength(lens, fields, kind, od, planes, args)
    if args.calibrate is None and (args.at is not None or args.value is not None):
        raise CliError("--at and --value need --calibrate METHOD")
    at = at_fields(args.at) or ()
    if args.calibrate:  # --at names fields of the run: calibrate's own check, before the trace
        # the --at fields are traced too, except one that looks like radians (0.65 where the
        # run has 37.5°): unless the run's fields hold it, calibrate's check refuses it, saying so
        fields = np.union1d(
            fields, [a for a in at if kind != "angle" or not looks_like_radians(a, fields)]
        )
        calibration_fields(fields, args.calibrate, at, angles=kind == "angle")
    res = _characteristic(lens, fields, kind, od, planes, args, wavelength=args.wavelength)
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
    strict_check(args, res.status)
    return 0


def _characteristic(lens, fields, kind, od, planes, args, **kw):
    """Characteristic distortion at the fields, object and planes of the run, with --reference
    (``kw``: the wavelength keywords)."""
    from distortion.characteristic import characteristic_distortion

    return characteristic_distortion(
        lens,
        **field_keyword(fields, kind),
        object_distance=od,
        plane=planes,
        reference=args.reference,
        **kw,
    )


def _by_wavelength(lens, fields, kind, od, planes, args) -> int:
    """--wavelengths: distortion per wavelength (one trace), against --scale."""
    from ..report.colour import chromatic_distortion_to_dict, format_chromatic_distortion

    refuse_flags(
        "--wavelengths does not combine with {}",
        (
            ("--wavelength", args.wavelength is not None),
            ("--calibrate", args.calibrate is not None),
            ("--at", args.at is not None),
            ("--value", args.value is not None),
            ("--csv", args.csv),
            ("--plot-rotation", args.plot_rotation),
            ("--layout", args.layout),
        ),
    )
    cd = _characteristic(
        lens, fields, kind, od, planes, args, wavelengths=args.wavelengths, scale=args.scale
    )
    print_result(
        args,
        json=lambda: {"distortion_by_wavelength": chromatic_distortion_to_dict(cd)},
        text=lambda: format_chromatic_distortion(cd),
    )
    if args.plot:
        from ..plots.colour import plot_distortion_by_wavelength

        save_plot(lambda: plot_distortion_by_wavelength(cd), args.plot, args)
    strict_check(args, cd.status, "ray(s)")
    return 0


def _plots(res, cals, args, lens) -> None:
    import numpy as np

    if args.plot or args.plot_rotation or args.layout:
        check_traced_any(np.isfinite(res.yp).any())

    if args.plot_rotation and not cals:
        raise CliError("--plot-rotation (Fig. 4) needs --calibrate")
    if not (args.plot or args.plot_rotation or args.layout):
        return
    from ..plots.distortion import plot_calibrated, plot_characteristic, plot_planes, plot_rotation
    from ..plots.layout import plot_layout

    if args.plot:
        if res.n_planes > 1:
            plot, data = plot_planes, res
        elif cals:
            plot, data = plot_calibrated, cals[0]
        else:
            plot, data = plot_characteristic, res
        save_plot(lambda: plot(data), args.plot, args)
    if args.plot_rotation:
        save_plot(lambda: plot_rotation(cals[0]), args.plot_rotation, args)
    if args.layout:
        key = "object_heights_mm" if res.field_kind == "height" else "fields_deg"
        save_plot(
            lambda: plot_layout(
                lens,
                **{key: res.fields},
                object_distance=res.object_distance,
                z_planes=res.z_planes,
                wavelength=args.wavelength,
            ),
            args.layout,
            args,
        )


def register(sub: argparse._SubParsersAction) -> None:
    from .colour import add_scale_arg, add_wavelengths_arg
    from .definitions import add_definition_args

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
    )
    add_lens_object_args(q, repeatable=True)
    q.add_argument("--reference", default="characteristic", choices=REFERENCES, help=REFERENCE_HELP)
    add_calibration_args(q, required=False)
    add_wavelength_arg(q)
    add_wavelengths_arg(
        q,
        help="Distortion per wavelength from one trace (nm, 0.5876um, line letters F,d,C, or "
        "'lens'), in the planes of the reference wavelength; see --scale.",
    )
    add_scale_arg(q)
    add_definition_args(q)
    add_table_layout_arg(q)
    add_strict_arg(q)
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
    _add_grid_args(q)
    add_force_arg(q)
    add_output_args(q)
    q.set_defaults(func=cmd_distortion)


# ------------------------------------------------------------------ 2-D distortion (--grid)
GRID_HELP = (
    "2-D distortion on an NXxNY grid of fields (e.g. 21x21) whose corners lie at the lens's field "
    "(or --max-field): distortion vectors about a named reference point, their decomposition "
    "(radial, decentering, thin prism) and the Brown-Conrady (Fraser 1997) fit per plane."
)
REFERENCE_POINT_HELP = (
    "Reference point of the 2-D ideal image: 'axial' (image of the axial object point; "
    "default), 'ppa' (principal point of autocollimation), 'ppbs' (point of best symmetry)."
)


def _add_grid_args(q: argparse.ArgumentParser) -> None:
    g = q.add_argument_group("2-D distortion")
    g.add_argument("--grid", metavar="NXxNY", help=GRID_HELP)
    g.add_argument(
        "--sensor", metavar="WxH", help="Fill a sensor of W x H mm with the grid (ideal image)."
    )
    g.add_argument(
        "--reference-point", choices=["axial", "ppa", "ppbs"], default="axial",
        help=REFERENCE_POINT_HELP,
    )  # fmt: skip
    g.add_argument(
        "--plot-grid", metavar="FILE",
        help="Save the grid-distortion picture (ideal and exaggerated real grid).",
    )  # fmt: skip
    g.add_argument(
        "--plot-vectors", metavar="FILE", help="Save the vector plot of the distortion field."
    )
    _add_sensor_metrics_arg(g)


def _grid_mode(args) -> bool:
    keys = ("grid", "sensor", "plot_grid", "plot_vectors", "sensor_metrics")
    return any(getattr(args, k, None) for k in keys)


def _grid_size(text: str | None) -> tuple[int, int]:
    if text is None:
        return (21, 21)
    parts = text.lower().replace("×", "x").split("x")
    try:
        vals = tuple(int(p) for p in parts)
    except ValueError:
        vals = ()
    if len(vals) == 1:
        vals = (vals[0], vals[0])
    if len(vals) != 2 or min(vals) < 2:
        raise CliError(f"--grid {text}: write NXxNY with at least 2 points each, e.g. 21x21")
    return vals


def _grid(args, lens) -> int:
    """``--grid``: the 2-D distortion field, its decomposition and Brown-Conrady fit per plane."""
    import numpy as np

    from distortion.grid import decompose_distortion, distortion_grid, fit_brown_conrady

    from ..report.grid import format_grid, grid_to_dict

    refuse_flags(
        "--grid (2-D distortion) does not combine with {}",
        (
            ("--fields", args.fields is not None),
            ("--steps", args.steps is not None),
            ("--calibrate", args.calibrate is not None),
            ("--at", args.at is not None),
            ("--value", args.value is not None),
            ("--csv", args.csv),
            ("--plot", args.plot),
            ("--plot-rotation", args.plot_rotation),
            ("--layout", args.layout),
            ("--wavelengths", getattr(args, "wavelengths", None) is not None),
        ),
    )
    nx, ny = _grid_size(args.grid)
    check_size(nx * ny, MAX_FIELDS, "--grid (fields)", args, per_item_bytes=400)
    _check_sensor_metrics(args, nx, ny)
    check_plot_paths(args, "plot_grid", "plot_vectors")
    od = resolve_object(lens, args)
    planes = resolve_planes(lens, args)
    kw = {}
    if args.sensor is not None:
        if args.max_field is not None:
            raise CliError("give --sensor or --max-field, not both")
        kw["sensor"] = args.sensor
    elif args.max_field is not None:
        import math

        kind = args.field_kind or lens.field.kind
        m = float(args.max_field)
        if kind == "angle":
            if not 0 < m < 90:
                raise CliError("--max-field must lie between 0 and 90 degrees")
            a = np.degrees(np.arctan(np.linspace(-1, 1, nx) * math.tan(math.radians(m)) / 2**0.5))
            b = np.degrees(np.arctan(np.linspace(-1, 1, ny) * math.tan(math.radians(m)) / 2**0.5))
            kw.update(fields_x_deg=a, fields_y_deg=b)
        else:
            kw.update(
                object_x_mm=np.linspace(-m, m, nx) / 2**0.5,
                object_y_mm=np.linspace(-m, m, ny) / 2**0.5,
            )
    g = distortion_grid(
        lens,
        grid=(nx, ny),
        object_distance=od,
        plane=planes,
        reference_point=args.reference_point,
        wavelength=args.wavelength,
        allow_large=getattr(args, "allow_large", False),
        **kw,
    )
    decs, fits = [], []
    for p in range(g.n_planes):  # a fit the grid cannot determine says why (not_determined)
        decs.append(decompose_distortion(g, p))
        fits.append(fit_brown_conrady(g, p))
    metrics = _sensor_metrics(args, g)
    print_result(
        args,
        json=lambda: {"distortion_grid": grid_to_dict(g, decs, fits), **metrics[0]},
        text=lambda: format_grid(g, decs, fits) + metrics[1],
    )
    if args.plot_grid or args.plot_vectors:
        check_traced_any(np.isfinite(g.actual).any(), see="")
        from ..plots.grid import plot_distortion_vectors, plot_grid_distortion

        save_plots(
            ((args.plot_grid, plot_grid_distortion), (args.plot_vectors, plot_distortion_vectors)),
            g,
            args,
        )
    strict_check(args, g.status, see="")
    return 0


# ------------------------------------------------ picture metrics of a sensor (--sensor-metrics)
SENSOR_METRICS_HELP = (
    "With --sensor: the picture metrics of the sensor from the grid - TV distortion (SMIA 1.0 "
    "(A-B)/B and the traditional dH/H = half of it), keystone, line straightness of the edges "
    "and centre lines, anamorphic ratio. The grid counts must be odd (default 21x21)."
)


def _add_sensor_metrics_arg(g) -> None:
    g.add_argument("--sensor-metrics", action="store_true", help=SENSOR_METRICS_HELP)


def _check_sensor_metrics(args, nx: int, ny: int) -> None:
    """Refuse --sensor-metrics without --sensor or with even counts, before any trace."""
    if not getattr(args, "sensor_metrics", False):
        return
    if args.sensor is None:
        raise CliError("--sensor-metrics needs --sensor WxH (the picture it measures)")
    if nx % 2 == 0 or ny % 2 == 0:
        raise CliError(
            f"--sensor-metrics with --grid {nx}x{ny}: the edge centres must be grid points; give "
            f"odd counts, e.g. --grid {nx + (nx % 2 == 0)}x{ny + (ny % 2 == 0)}"
        )


def _sensor_metrics(args, g) -> tuple[dict, str]:
    """(JSON entries, text) of the picture metrics per plane; empty without --sensor-metrics."""
    if not getattr(args, "sensor_metrics", False):
        return {}, ""
    from distortion.sensor_metrics import sensor_metrics

    from ..report.sensor_metrics import format_sensor_metrics, sensor_metrics_to_dict

    ms = [sensor_metrics(g, p) for p in range(g.n_planes)]
    return {"sensor_metrics": [sensor_metrics_to_dict(m) for m in ms]}, (
        "\n\n" + format_sensor_metrics(ms)
    )
