"""``orthoscope calibrate``: recalibrate a distortion table with no lens (Table I -> Table II)."""

from __future__ import annotations

import argparse

from .common import (
    METHODS,
    CliError,
    add_force_arg,
    add_output_args,
    add_table_layout_arg,
    at_fields,
    bundled_or_path,
    check_plot_paths,
    print_result,
    save_plots,
)
from .distortion import add_calibration_args

#: the bundled copy of Pestrecov's Table I (lenses/pestrecov-1958-table1-topogon.csv)
PESTRECOV_TABLE_I = "pestrecov-1958-table1-topogon"

TABLE_HELP = (
    "Distortion table CSV: a header with the field column (alpha_deg or y_mm), y0p_mm, D0_mm and "
    "optionally Dr_pct; '#' lines are comments (see README). Or the name of a bundled table: "
    f"{PESTRECOV_TABLE_I} (Pestrecov 1958, Table I); an existing file wins over a name."
)


#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["calibrate", "{data}/pestrecov_table1.csv", "--method", "two-point", "--at", "37.5,45"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("--plot", ".png"), ("--plot-rotation", ".png")]


def table_path(word: str) -> str:
    """TABLE as given, or the bundled table of that name (``lenses/NAME.csv``, e.g.
    ``pestrecov-1958-table1-topogon``; :func:`~orthoscope.cli.common.bundled_or_path`)."""
    return bundled_or_path(word, "", ".csv")


def cmd_calibrate(args) -> int:
    from distortion.calibration import calibrate
    from distortion.tablefile import read_distortion_table

    from ..report.distortion import calibration_csv, calibration_to_dict, format_calibration

    if args.method is None:
        raise CliError(f"the following argument is required: --method {{{','.join(METHODS)}}}")
    table = table_path(args.table)
    args._inputs = [table]
    check_plot_paths(args, "plot", "plot_rotation")
    curve = read_distortion_table(table, constant=args.constant)
    res = calibrate(
        curve, args.method, at=at_fields(args.at), value=args.value, k=args.exaggeration
    )
    print_result(
        args,
        json=lambda: calibration_to_dict(res),
        csv=lambda: calibration_csv(res),
        text=lambda: format_calibration(res, layout=args.table_layout),
    )
    if args.plot or args.plot_rotation:
        from ..plots.distortion import plot_calibrated, plot_rotation

        save_plots(((args.plot, plot_calibrated), (args.plot_rotation, plot_rotation)), res, args)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "calibrate",
        help="Recalibrate a distortion table (CSV) with no lens: Table I -> Table II.",
        description=(
            "Calibrated distortion from a data table alone (Pestrecov Eqs. 10-15): the calibrated "
            "constant Fc (or Mc), tan rho = Fc/F0 - 1, rho_k, Dc, Drc, yc', max |Dc|, spreads and "
            "Drc on the axis. F0 (M0) is inferred from y0'/tan(alpha) (y0'/y) unless --constant "
            "gives it."
        ),
        epilog=f"Example: orthoscope calibrate {PESTRECOV_TABLE_I} --method two-point --at 37.5,45",
    )
    q.add_argument("table", metavar="TABLE.csv", help=TABLE_HELP)
    add_calibration_args(q, required=True)
    q.add_argument(
        "--constant",
        type=float,
        metavar="K0",
        help="F0 (mm) or M0 of the table (default: inferred from the table).",
    )
    add_table_layout_arg(q)
    g = q.add_argument_group("plots")
    g.add_argument("--plot", metavar="FILE", help="Save Fig. 3 (calibrated distortion).")
    g.add_argument("--plot-rotation", metavar="FILE", help="Save Fig. 4 (rotated curve).")
    add_force_arg(q)
    add_output_args(q)
    q.set_defaults(func=cmd_calibrate)
