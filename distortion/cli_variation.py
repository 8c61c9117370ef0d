"""``orthoscope variation`` and ``orthoscope coefficients`` (Fraser & Shortis 1992; issue 5).

variation — two modes:
  data:         ``orthoscope variation PROFILES.csv [--focal-length MM] ...``
  prescription: ``orthoscope variation --lens LENS --focus 12x --objects 8x,16x,20x ...``
coefficients — Brown–Conrady (Gaussian and balanced) fit and OpenCV k1, k2, k3 of one profile,
  from a CSV file or traced from a lens at a focus setting.
"""

from __future__ import annotations

import argparse
import math

from .cli import CliError, print_json

CONJ_HELP = (
    "Distances are positive magnitudes: 'Nx' (also 'NX') is an image scale, Gaussian "
    "magnification -1/N (12x: the image is 1/12 of the object; with unit focusing the object is "
    "f(1+N) in front of the first principal point H); a plain number (or '1.5m') is metres from H; "
    "'inf' is infinity."
)
UNITS_EPILOG = (
    "Units and signs: radial distance r in mm in the image (the measured, distorted radius); "
    "radial distortion dr in micrometres, positive OUTWARD (pincushion positive, barrel "
    "negative). A profile 'i x (j x)' is the object plane at i x with the lens focused at j x; "
    "'j x' alone is a Gaussian profile (object in the plane of focus). g_ss' is Fraser & Shortis "
    "Eq. (6): dr_ss' = dr_s + g (dr_s' - dr_s); gamma_ss' is Brown's Eq. (2). " + CONJ_HELP
)


def _lens(args):
    from raytrace.library import load_lens
    from raytrace.paraxial import paraxial

    lens = load_lens(args.lens)
    if args.scale_to_efl is not None:
        if not (args.scale_to_efl > 0 and math.isfinite(args.scale_to_efl)):
            raise CliError(
                f"--scale-to-efl must be a positive focal length in mm, got {args.scale_to_efl}"
            )
        efl = paraxial(lens, math.inf).efl
        if not efl > 0:
            raise CliError(f"{lens.name}: EFL {efl:g} mm is not positive; cannot scale it")
        lens = lens.scaled(args.scale_to_efl / efl)
    return lens


def _focus_list(values: list[str] | None):
    from .variation_trace import parse_conjugates

    out = []
    for v in values or []:
        out.extend(parse_conjugates(v))
    return out


# ----------------------------------------------------------------------------- variation
def cmd_variation(args) -> int:
    from .variation_trace import (
        format_traced_variation,
        parse_conjugates,
        trace_variation,
        traced_variation_to_dict,
    )

    for name in ("r_min", "r_max"):
        v = getattr(args, name)
        if v is not None and not (v >= 0 and math.isfinite(v)):
            raise CliError(f"--{name.replace('_', '-')} must be a non-negative radius in mm")
    if not (args.threshold_um >= 0):
        raise CliError("--threshold-um must be >= 0 (micrometres)")
    if args.profiles and args.lens:
        raise CliError("give either PROFILES.csv (data mode) or --lens (prescription mode)")
    if not args.profiles and not args.lens:
        raise CliError(
            "give a CSV of measured profiles (PROFILES.csv) or a lens with --lens, --focus and "
            "--objects"
        )
    if args.profiles:
        bad = [
            f
            for f, v in (
                ("--focus", args.focus),
                ("--objects", args.objects),
                ("--scale-to-efl", args.scale_to_efl),
                ("--max-field", args.max_field),
                ("--profiles-csv", args.profiles_csv),
            )
            if v
        ]
        if bad:
            raise CliError(f"{', '.join(bad)} only apply with --lens (prescription mode)")
        from .profiles import analyze_csv
        from .variation import format_variation, variation_to_dict

        a = analyze_csv(
            args.profiles,
            focal_length_mm=args.focal_length,
            r_min=args.r_min,
            r_max=args.r_max,
            threshold_um=args.threshold_um,
            method=args.method,
        )
        if args.json:
            print_json({"mode": "data", "variation": variation_to_dict(a)})
        elif args.csv:
            _print_g_csv(a)
        else:
            print(format_variation(a))
        _plots(a, args)
        return 0

    if args.focal_length is not None:
        raise CliError(
            "--focal-length is for data mode; in prescription mode f comes from the "
            "lens (use --scale-to-efl to scale the lens)"
        )
    if not args.focus:
        raise CliError("prescription mode needs --focus (e.g. --focus 12x)")
    if not args.objects:
        raise CliError("prescription mode needs --objects (e.g. --objects 8x,16x,20x)")
    lens = _lens(args)
    tv = trace_variation(
        lens,
        _focus_list(args.focus),
        parse_conjugates(args.objects),
        r_min=args.r_min,
        r_max=args.r_max,
        n_r=args.n_r,
        max_field_deg=args.max_field,
        threshold_um=args.threshold_um,
        method=args.method,
        reference=args.reference,
    )
    if args.profiles_csv:
        _write_profiles_csv(tv, args.profiles_csv)
    if args.json:
        print_json(traced_variation_to_dict(tv))
    elif args.csv:
        _print_g_csv(tv.analysis)
    else:
        print(format_traced_variation(tv))
    _plots(tv.analysis, args)
    return 0


def _plots(a, args) -> None:
    if not (args.plot or args.plot_g):
        return
    import matplotlib.pyplot as plt

    from .variation_plots import plot_g, plot_profiles

    for path, fn in ((args.plot, plot_profiles), (args.plot_g, plot_g)):
        if path:
            try:
                fig = fn(a, path)
            except OSError as e:
                raise CliError(f"cannot write plot {path}: {e.strerror or e}") from None
            plt.close(fig)


def _print_g_csv(a) -> None:
    gam = {(g.focus.label, g.obj.label): g.gamma for g in a.gammas}
    print("focus,object,gamma,g,se,n_used,n_excluded,rms_fit_um,rms_mean_g_um,status")
    for fs in a.focus_summaries:
        for p in fs.planes:
            e = p.estimate

            def v(x):
                return "" if x is None or not math.isfinite(x) else repr(float(x))

            print(
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


def _write_profiles_csv(tv, path: str) -> None:
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
    try:
        with open(path, "w", encoding="utf-8") as fh:
            fh.write("\n".join(lines) + "\n")
    except OSError as e:
        raise CliError(f"cannot write {path}: {e.strerror or e}") from None


# ----------------------------------------------------------------------------- coefficients
def cmd_coefficients(args) -> int:
    from .coefficients import (
        fit_radial,
        format_opencv,
        format_radial_fit,
        opencv_model,
        opencv_to_dict,
        radial_fit_to_dict,
    )

    if args.profiles and args.lens:
        raise CliError("give either PROFILES.csv or --lens, not both")
    for name in ("focal_length_px", "pixel_pitch_um", "principal_distance_mm"):
        v = getattr(args, name)
        if v is not None and not (v > 0 and math.isfinite(v)):
            raise CliError(f"--{name.replace('_', '-')} must be positive and finite, got {v}")
    if args.profiles:
        r, dr, label, c, source = _csv_profile(args)
    elif args.lens:
        r, dr, label, c, source = _traced_profile(args)
    else:
        raise CliError("give a CSV profile (PROFILES.csv) or a lens (--lens LENS --focus 12x)")
    gauss = fit_radial(r, dr, form="gaussian", radius="measured")
    bal = fit_radial(r, dr, form="balanced", radius="measured")
    cv = None
    pitch, fpx = args.pixel_pitch_um, args.focal_length_px
    if c is not None and fpx is not None and pitch is not None:
        raise CliError(
            "the principal distance is known here: give --focal-length-px OR "
            "--pixel-pitch-um, not both"
        )
    if c is not None and (fpx is not None or pitch is not None):
        if pitch is None:
            pitch = c / fpx * 1000.0
        cv = opencv_model(
            r, dr, principal_distance_mm=c, pixel_pitch_um=pitch, balanced=args.balanced
        )
    elif c is None and fpx is not None and pitch is not None:
        cv = opencv_model(r, dr, focal_length_px=fpx, pixel_pitch_um=pitch, balanced=args.balanced)
    elif c is not None:
        cv = opencv_model(r, dr, principal_distance_mm=c, balanced=args.balanced)
    note = None
    if cv is None:
        note = (
            "OpenCV k1..k3 need the principal distance: give --principal-distance-mm, or "
            "--focal-length-px with --pixel-pitch-um"
        )
    if args.json:
        print_json(
            {
                "profile": {
                    "label": label,
                    "source": source,
                    "r_mm": [float(x) for x in r],
                    "dr_um": [float(x) for x in dr],
                    "principal_distance_mm": c,
                },
                "units": "r in mm (measured radius), dr positive outward; K_i in mm^-(2i)",
                "gaussian_fit": radial_fit_to_dict(gauss),
                "balanced_fit": radial_fit_to_dict(bal),
                "opencv": None if cv is None else opencv_to_dict(cv),
                "notes": [note] if note else [],
            }
        )
        return 0
    print(f"Radial distortion coefficients — {label} ({source})")
    if c is not None:
        print(f"principal distance of the profile: {c:.6f} mm")
    print(format_radial_fit(gauss))
    print(format_radial_fit(bal))
    if cv is not None:
        print(format_opencv(cv))
    if note:
        print(f"note: {note}")
    return 0


def _csv_profile(args):
    from .profiles import read_profiles_csv
    from .variation_trace import parse_conjugate

    extra = _lens_only(args)
    if extra:
        raise CliError(f"{', '.join(extra)} only apply with --lens")
    ps = read_profiles_csv(args.profiles, min_profiles=1)
    profs = list(ps.profiles)
    if args.profile:
        parts = [p.strip() for p in args.profile.split(",")]
        if len(parts) != 2:
            raise CliError(
                "--profile takes 'FOCUS,OBJECT' as written in the file (e.g. '8,1.5' or '12x,8x')"
            )
        want = [parse_conjugate(p) for p in parts]
        profs = [
            p
            for p in profs
            if (p.focus.value, p.obj.value) == (want[0].value, want[1].value)
            and (p.focus.unit, p.obj.unit) == (want[0].unit, want[1].unit)
        ]
        if not profs:
            have = "; ".join(f"{p.focus.text},{p.obj.text}" for p in ps.profiles)
            raise CliError(f"no profile {args.profile!r} in {args.profiles}; it has: {have}")
    elif len(profs) > 1:
        have = "; ".join(f"{p.focus.text},{p.obj.text}" for p in ps.profiles)
        raise CliError(
            f"{args.profiles} holds {len(profs)} profiles: choose one with --profile "
            f"FOCUS,OBJECT ({have})"
        )
    p = profs[0]
    return p.r_mm, p.dr_um, p.label, args.principal_distance_mm, args.profiles


def _traced_profile(args):
    from raytrace.paraxial import paraxial

    from .variation_trace import DEFAULT_N_FIELDS, parse_conjugate, trace_setting

    if args.profile:
        raise CliError(
            "--profile selects a profile of a CSV file; with --lens use --focus and --object"
        )
    if args.principal_distance_mm is not None:
        raise CliError(
            "with --lens the principal distance comes from the trace; drop --principal-distance-mm"
        )
    if not args.focus:
        raise CliError("--lens needs --focus (e.g. --focus 12x or --focus inf)")
    lens = _lens(args)
    focus = parse_conjugate(args.focus)
    obj = parse_conjugate(args.object) if args.object else focus
    fmax = args.max_field
    if fmax is None:
        fmax = lens.field.value if lens.field.kind == "angle" else None
    if fmax is None or not 0 < fmax < 90:
        raise CliError("give --max-field (degrees, nominal field angle) for this lens")
    import numpy as np

    st = trace_setting(lens, focus, obj, np.linspace(0.0, fmax, DEFAULT_N_FIELDS))
    r, dr = st.valid()
    if args.r_max is not None:
        keep = r <= args.r_max
        r, dr = r[keep], dr[keep]
    r, dr = r[1:], dr[1:]  # drop the axis point (r = 0)
    if r.size < 5:
        raise CliError("fewer than 5 traced points in the radial range")
    # principal distance of the plane: F0 = p0'/m_e (Eq. 8), the scale of the Gaussian-form
    # profile; for a finite object it is M0·p0.
    if math.isinf(st.s):
        c = abs(st.constant)
    else:
        par = paraxial(lens, st.object_distance)
        c = abs(st.constant * par.p0)
    return r, dr, st.label, c, f"traced from {lens.name}"


# ----------------------------------------------------------------------------- parsers
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
        epilog=UNITS_EPILOG,
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
    g = q.add_mutually_exclusive_group()
    g.add_argument("--json", action="store_true", help="Print JSON (all tables and profiles).")
    g.add_argument(
        "--csv",
        action="store_true",
        help="Print CSV: one row per object plane (gamma, g, se, RMS errors).",
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
    q.set_defaults(func=cmd_variation)

    c = sub.add_parser(
        "coefficients",
        help="Brown-Conrady radial coefficients (Gaussian and balanced) and OpenCV k1, k2, k3 "
        "of a distortion profile (CSV or traced).",
        description=(
            "Fit dr = K1 r^3 + K2 r^5 + K3 r^7 (Gaussian form, no linear term) and "
            "dr = K0 r + K1 r^3 + ... (balanced form: K0 <=> a calibrated principal distance "
            "c_b = c_g (1 - K0)) to one radial profile, r = measured radius in mm, K_i in "
            "mm^-(2i); then convert to OpenCV k_i = K_i c^(2i) (c = Gaussian principal distance) "
            "for x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) in normalised coordinates. The profile is "
            "read from a CSV (choose it with --profile) or traced: --lens LENS --focus 12x "
            "[--object 8x] gives Pestrecov's characteristic distortion in the image plane of the "
            "focus setting, whose principal distance is F0 = p0'/m_e (Eq. 8)."
        ),
        epilog=UNITS_EPILOG,
    )
    c.add_argument("profiles", nargs="?", metavar="PROFILES.csv", help="CSV of profiles.")
    c.add_argument(
        "--profile",
        metavar="FOCUS,OBJECT",
        help="Which profile of the CSV, as written in its focus and object columns "
        "(e.g. '8,1.5' or '12x,8x').",
    )
    c.add_argument(
        "--principal-distance-mm",
        type=float,
        metavar="C",
        help="CSV mode: principal distance (mm) the profile refers to.",
    )
    c.add_argument("--lens", metavar="LENS", help="Trace the profile from this lens.")
    c.add_argument("--focus", metavar="D", help="Focus setting for --lens. " + CONJ_HELP)
    c.add_argument(
        "--object",
        metavar="D",
        help="Object plane for --lens (default: the focus, the Gaussian profile).",
    )
    c.add_argument(
        "--scale-to-efl",
        type=float,
        metavar="MM",
        help="Scale the lens to this focal length first.",
    )
    c.add_argument(
        "--max-field",
        type=float,
        metavar="DEG",
        help="Largest nominal field angle traced (default: the lens's).",
    )
    c.add_argument("--r-max", type=float, metavar="MM", help="Largest radius fitted (mm).")
    c.add_argument(
        "--focal-length-px", type=float, metavar="PX", help="Focal length in pixels (OpenCV fx)."
    )
    c.add_argument("--pixel-pitch-um", type=float, metavar="UM", help="Pixel pitch (micrometres).")
    c.add_argument(
        "--balanced",
        action="store_true",
        help="Derive the OpenCV coefficients from the balanced fit (c_g = c (1 + K0)).",
    )
    c.add_argument(
        "--json",
        action="store_true",
        help="Print JSON: fits and an 'opencv' block with dist_coeffs [k1,k2,p1,p2,k3].",
    )
    c.set_defaults(func=cmd_coefficients)


def _lens_only(args) -> list[str]:
    return [
        f
        for f, v in (
            ("--focus", args.focus),
            ("--object", args.object),
            ("--scale-to-efl", args.scale_to_efl),
            ("--max-field", args.max_field),
        )
        if v
    ]
