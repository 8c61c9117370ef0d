"""``orthoscope variation`` (Fraser & Shortis 1992), two modes:

data:         ``orthoscope variation PROFILES.csv [--focal-length MM] ...``
prescription: ``orthoscope variation --lens LENS --focus 12x --objects 8x,16x,20x ...``
"""

from __future__ import annotations

import argparse
import math

from .common import (
    CliError,
    add_force_arg,
    add_output_args,
    check_output_path,
    check_plot_suffix,
    load_scaled,
    print_result,
    refuse_flags,
    save_plots,
)

CONJ_HELP = (
    "Distances are positive magnitudes: 'Nx' (also 'NX') is an image scale, Gaussian "
    "magnification -1/N (12x: the image is 1/12 of the object; with unit focusing the object is "
    "f(1+N) in front of the first principal point H); a plain number (or '1.5m') is metres from H "
    "('1500mm' also works; a plain number of 100 or more warns that it looks like millimetres); "
    "'inf' is infinity."
)
UNITS_EPILOG = (
    "Units and signs: radial distance r in mm in the image (the measured, distorted radius); "
    "radial distortion dr in micrometres, positive OUTWARD (pincushion positive, barrel "
    "negative). A profile 'i x (j x)' is the object plane at i x with the lens focused at j x; "
    "'j x' alone is a Gaussian profile (object in the plane of focus). g_ss' is Fraser & Shortis "
    "Eq. (6): dr_ss' = dr_s + g (dr_s' - dr_s); gamma_ss' is Brown's Eq. (2). " + CONJ_HELP
)
#: The Pentax profiles of Fraser & Shortis (1992) Table 1, a file in the repository.
PENTAX_CSV = "lenses/fraser-shortis-1992-table1-pentax.csv"


def units_epilog(*examples: str) -> str:
    """The epilog of ``variation`` and ``coefficients``: :data:`UNITS_EPILOG`, wrapped as argparse
    wraps it (the help formatter keeps a text with line breaks as written), then the examples
    (each run by tests/test_docs.py)."""
    import textwrap

    lines = "\n".join(f"  {e}" for e in examples)
    return textwrap.fill(UNITS_EPILOG, 78) + "\n\nExamples:\n" + lines


#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [
    [
        "variation",
        "--lens",
        "cooke-triplet-f4",
        "--focus",
        "12x",
        "--objects",
        "8x,16x",
        "--n-r",
        "8",
    ],
]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("--profiles-csv", ".csv"), ("--plot", ".png"), ("--plot-g", ".png")]


# ----------------------------------------------------------------------------- variation
def cmd_variation(args) -> int:
    from distortion.variation.analysis import check_analysis_options
    from distortion.variation.traced import trace_variation

    from ..report.variation import format_traced_variation, traced_variation_to_dict

    check_analysis_options(**_analysis_options(args))
    if args.profiles and args.lens:
        raise CliError("give either PROFILES.csv (data mode) or --lens (prescription mode)")
    if not args.profiles and not args.lens:
        raise CliError(
            "give a CSV of measured profiles (PROFILES.csv) or a lens with --lens, --focus and "
            "--objects"
        )
    if args.profiles:
        _check_outputs(args)
        refuse_flags(
            "{} only apply with --lens (prescription mode)",
            (
                ("--focus", args.focus),
                ("--objects", args.objects),
                ("--scale-to-efl", args.scale_to_efl),
                ("--max-field", args.max_field),
                ("--profiles-csv", args.profiles_csv),
            ),
        )
        from distortion.variation.profiles import analyze_csv

        from ..report.variation import format_variation, variation_to_dict

        a = analyze_csv(args.profiles, focal_length_mm=args.focal_length, **_analysis_options(args))
        print_result(
            args,
            json=lambda: {"mode": "data", "variation": variation_to_dict(a)},
            csv=lambda: _g_csv(a),
            text=lambda: format_variation(a),
        )
        _plots(a, args)
        return 0

    if args.focal_length is not None:
        raise CliError(
            "--focal-length is for data mode; in prescription mode f comes from the "
            "lens (use --scale-to-efl to scale the lens)"
        )
    if args.configurations:  # the lens file's focus configurations (docs/focus.md)
        from distortion.variation.focus import focus_study
        from raytrace.files.configurations import read_configured

        from ..report.focus import focus_study_to_dict, format_focus_study

        lens, confs = read_configured(args.lens)
        st = focus_study(lens, confs, focus_index=len(confs) // 2, max_field_deg=args.max_field)
        print_result(
            args, json=lambda: focus_study_to_dict(st), text=lambda: format_focus_study(st)
        )
        return 0
    if not args.focus:
        raise CliError("prescription mode needs --focus (e.g. --focus 12x)")
    if not args.objects:
        raise CliError("prescription mode needs --objects (e.g. --objects 8x,16x,20x)")
    from .common import MAX_FIELDS, check_size

    check_size(args.n_r, MAX_FIELDS, "--n-r", args, per_item_bytes=2000)
    lens = load_scaled(args)  # recorded as the input (args._inputs)
    _check_outputs(args)
    tv = trace_variation(
        lens,
        args.focus,  # as typed ("12x", "8x,16x"): trace_variation reads them (as_conjugates)
        args.objects,
        n_r=args.n_r,
        max_field_deg=args.max_field,
        reference=args.reference,
        **_analysis_options(args),
    )
    if args.profiles_csv:
        _write_profiles_csv(tv, args.profiles_csv, force=args.force, inputs=args._inputs)
    print_result(
        args,
        json=lambda: traced_variation_to_dict(tv),
        csv=lambda: _g_csv(tv.analysis),
        text=lambda: format_traced_variation(tv),
    )
    _plots(tv.analysis, args)
    return 0


def _analysis_options(args) -> dict:
    """The options of the analysis that both modes share: radius range, threshold, g method."""
    return {
        "r_min": args.r_min,
        "r_max": args.r_max,
        "threshold_um": args.threshold_um,
        "method": args.method,
    }


def _check_outputs(args) -> None:
    """Refuse bad output files before any work (same file as an input, existing without
    --force, unknown plot suffix)."""
    if not hasattr(args, "_inputs"):
        args._inputs = [args.profiles] if args.profiles else []
    for path in (args.plot, args.plot_g, getattr(args, "profiles_csv", None)):
        if path:
            check_output_path(path, args)
    for flag, path in (("--plot", args.plot), ("--plot-g", args.plot_g)):
        if path:
            check_plot_suffix(path, flag)


def _plots(a, args) -> None:
    if not (args.plot or args.plot_g):
        return
    from ..plots.variation import plot_g, plot_profiles

    save_plots(((args.plot, plot_profiles), (args.plot_g, plot_g)), a, args)


def _g_csv(a) -> str:
    """--csv: one row per object plane (gamma, g, its standard error, RMS errors)."""

    def v(x):
        return "" if x is None or not math.isfinite(x) else repr(float(x))

    gam = {(g.focus.label, g.obj.label): g.gamma for g in a.gammas}
    rows = ["focus,object,gamma,g,se,n_used,n_excluded,rms_fit_um,rms_mean_g_um,status"]
    for fs in a.focus_summaries:
        for p in fs.planes:
            e = p.estimate
            rows.append(
                ",".join(
                    [
                        p.focus.label,
                        p.obj.label,
                        v(gam.get((p.focus.label, p.obj.label), math.nan)),
                        v(e.g),
                        v(e.se),
                        str(e.n_used),
                        str(e.n_excluded),
                        v(e.rms_fit_um),
                        v(p.rms_mean_g_um),
                        e.status,
                    ]
                )
            )
    return "\n".join(rows)


def _write_profiles_csv(tv, path: str, *, force: bool, inputs) -> None:
    def text(c):
        return (
            f"{c.value:g}x" if c.unit == "x" else ("inf" if math.isinf(c.value) else f"{c.value:g}")
        )

    lines = [
        f"# source: traced by orthoscope from {tv.lens_name}",
        f"# focal_length_mm: {tv.efl_mm:.9g}",
    ]
    lines += [f"# {n}" for n in tv.notes[1:]]
    lines.append("r_mm,dr_um,focus,object")
    for p in tv.profile_set.profiles:
        f, o = text(p.focus), text(p.obj)
        lines += [f"{r:.9g},{d:.9g},{f},{o}" for r, d in zip(p.r_mm, p.dr_um, strict=True)]
    from raytrace.files.output import write_atomic

    write_atomic(path, "\n".join(lines) + "\n", overwrite=force, inputs=inputs, flag="--force")


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "variation",
        help="Variation of radial distortion with object distance (Fraser & Shortis 1992): "
        "Brown's gamma, g_ss' per object plane, mean g, RMS errors; from measured profiles "
        "or predicted from a prescription.",
        description=(
            "Data mode: analyse measured radial distortion profiles from a CSV file (columns "
            "r_mm, dr_um, focus, object; see distortion/profiles.py). Prescription mode (--lens):"
            " trace the profiles of a lens focused by moving it as a whole (unit focusing): "
            "dr_s (object at the focus s), dr_s' (object at s', focused there) and dr_ss' "
            "(object at s', image plane of focus s: Pestrecov's non-Gaussian plane), as "
            "Pestrecov's characteristic distortion relative to the focus setting's principal "
            "distance, compared on a common radius grid; then the same analysis as the data "
            "mode, with Brown's Eq. (1) prediction beside the traced truth."
        ),
        epilog=units_epilog(
            "orthoscope variation --lens super-angulon-de975637 --scale-to-efl 65 --focus 12x "
            "--objects 8x,16x,20x",
            "orthoscope variation --lens tessar-fr1066698-inner-focus --configurations",
            f"orthoscope variation {PENTAX_CSV}",
        ),
    )
    q.add_argument(
        "profiles", nargs="?", metavar="PROFILES.csv", help="CSV of measured profiles (data mode)."
    )
    q.add_argument(
        "--focal-length",
        type=float,
        metavar="MM",
        help="Data mode: focal length in mm (needed when distances are in metres; "
        "overrides the file's '# focal_length_mm:').",
    )
    q.add_argument(
        "--lens", metavar="LENS", help="Prescription mode: lens file or bundled lens name."
    )
    q.add_argument(
        "--focus",
        action="append",
        metavar="D",
        help="Prescription mode: focus setting(s), repeatable or comma-separated "
        "(e.g. 12x). " + CONJ_HELP,
    )
    q.add_argument(
        "--objects",
        metavar="D1,D2,...",
        help="Prescription mode: object planes, e.g. 8x,16x,20x or 0.6,1.1 (metres).",
    )
    q.add_argument(
        "--configurations",
        action="store_true",
        help="Prescription mode: study the lens file's focus configurations (Zemax THIC, CODE V "
        "ZOO THI, TOML [[configurations]]): distortion, principal distance and Brown's model per "
        "focus (docs/focus.md).",
    )
    q.add_argument(
        "--scale-to-efl",
        type=float,
        metavar="MM",
        help="Scale the lens to this focal length first (e.g. 65 for the paper's S65).",
    )
    q.add_argument(
        "--max-field",
        type=float,
        metavar="DEG",
        help="Prescription mode: largest nominal field angle traced (default: the lens's field).",
    )
    q.add_argument(
        "--n-r",
        type=int,
        default=25,
        metavar="N",
        help="Prescription mode: number of common radii (default 25).",
    )
    q.add_argument(
        "--reference",
        default="characteristic",
        choices=["characteristic", "distortion-focal-length", "real-chief-transport"],
        help="Prescription mode: distortion definition (default: Pestrecov's "
        "characteristic distortion in the actual plane).",
    )
    q.add_argument("--r-min", type=float, metavar="MM", help="Smallest radius used (mm).")
    q.add_argument("--r-max", type=float, metavar="MM", help="Largest radius used (mm).")
    q.add_argument(
        "--threshold-um",
        type=float,
        default=0.5,
        metavar="UM",
        help="Radii where |dr_s' - dr_s| is below this (micrometres) are weakly "
        "determined and excluded from g (default 0.5, as in the paper).",
    )
    q.add_argument(
        "--method",
        choices=["lsq", "mean"],
        default="lsq",
        help="g per plane by least squares through the origin (lsq) or as the mean "
        "of the pointwise ratios (mean, the paper's Tables 2-3).",
    )
    add_output_args(
        q,
        json_help="Print JSON (all tables and profiles).",
        csv_help="Print CSV: one row per object plane (gamma, g, se, RMS errors).",
    )
    q.add_argument(
        "--profiles-csv",
        metavar="FILE",
        help="Prescription mode: also write the traced profiles in the data-mode CSV "
        "format (readable by 'orthoscope variation FILE').",
    )
    q.add_argument("--plot", metavar="FILE.png", help="Plot the profiles (paper's Figs. 1-4).")
    q.add_argument(
        "--plot-g",
        metavar="FILE.png",
        help="Plot g_ss' against radial distance (paper's Figs. 5-7).",
    )
    add_force_arg(q)
    q.set_defaults(func=cmd_variation)
