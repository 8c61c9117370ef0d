"""``orthoscope coefficients``: Brown–Conrady (Gaussian and balanced) fit and OpenCV k1, k2, k3 of
one radial profile, from a CSV file or traced from a lens at a focus setting."""

from __future__ import annotations

import argparse
import math

from .common import (
    CliError,
    add_output_args,
    add_strict_arg,
    load_scaled,
    print_json,
    refuse_flags,
    warn,
)
from .variation import CONJ_HELP, PENTAX_CSV, units_epilog

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [["coefficients", "--lens", "cooke-triplet-f4", "--focus", "12x"]]
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = []


def cmd_coefficients(args) -> int:
    from distortion.coefficients import fit_radial, opencv_model

    from ..report.coefficients import (
        format_opencv,
        format_radial_fit,
        opencv_to_dict,
        radial_fit_to_dict,
    )

    if args.profiles and args.lens:
        raise CliError("give either PROFILES.csv or --lens, not both")
    for name in ("focal_length_px", "pixel_pitch_um", "principal_distance_mm", "r_max"):
        v = getattr(args, name)
        if v is not None and not (v > 0 and math.isfinite(v)):
            raise CliError(f"--{name.replace('_', '-')} must be positive and finite, got {v}")
    traced = None
    if args.profiles:
        r, dr, label, c, source = _csv_profile(args)
    elif args.lens:
        r, dr, label, c, source, traced = _traced_profile(args)
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
                "traced": traced,
                "notes": [note] if note else [],
                "warnings": [traced["warning"]] if traced and traced["warning"] else [],
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
    from distortion.variation.profiles import read_profiles_csv
    from distortion.variation.traced import parse_conjugate

    refuse_flags(
        "{} only apply with --lens",
        (
            ("--focus", args.focus),
            ("--object", args.object),
            ("--scale-to-efl", args.scale_to_efl),
            ("--max-field", args.max_field),
            ("--strict", args.strict),
        ),
    )
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
    r, dr = _cut(p.r_mm, p.dr_um, args.r_max)
    return r, dr, p.label, args.principal_distance_mm, args.profiles


def _cut(r, dr, r_max):
    """The points of a profile at radii up to --r-max (all without it)."""
    if r_max is None:
        return r, dr
    keep = r <= r_max
    if not keep.any():
        raise CliError(f"--r-max {r_max:g} mm keeps no point (the smallest radius is {r.min():g})")
    return r[keep], dr[keep]


def _traced_profile(args):
    from distortion.variation.traced import DEFAULT_N_FIELDS, parse_conjugate, trace_setting
    from raytrace.paraxial import paraxial

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
    lens = load_scaled(args)
    focus = parse_conjugate(args.focus)
    obj = parse_conjugate(args.object) if args.object else focus
    fmax = args.max_field
    if fmax is not None and not (0 < fmax < 90):
        raise CliError(
            f"--max-field {fmax:g}: the largest nominal field angle must lie between 0 and 90 "
            "degrees (exclusive)"
        )
    if fmax is None:
        if lens.field.kind != "angle":
            raise CliError(
                f"{lens.name} gives its field as an object height: give --max-field (degrees, "
                "the largest nominal field angle, between 0 and 90)"
            )
        fmax = lens.field.value
        if not 0 < fmax < 90:
            raise CliError(
                f"{lens.name}: its field {fmax:g} deg is not between 0 and 90; give --max-field "
                "(degrees, the largest nominal field angle)"
            )
    import numpy as np

    st = trace_setting(lens, focus, obj, np.linspace(0.0, fmax, DEFAULT_N_FIELDS))
    traced = _traced_summary(st, fmax)
    if traced["warning"]:
        if args.strict:
            raise CliError(traced["warning"] + "; --strict fails")
        warn(traced["warning"])
    r, dr = _cut(*st.valid(), args.r_max)
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
    return r, dr, st.label, c, f"traced from {lens.name}", traced


def _traced_summary(st, fmax: float) -> dict:
    """How far the traced profile ``st`` reaches (JSON ``traced``): the fields asked for, the
    leading run of traced fields the fits use (a failed field ends the profile), where it stops,
    and a one-line ``warning`` (None when every field traced)."""
    from raytrace.trace.results import status_name

    fields, status = st.fields, st.status
    r_ok, _ = st.valid()
    n_ok = int(r_ok.size)
    out = {
        "max_field_deg": float(fmax),
        "n_fields": int(fields.size),
        "n_fields_used": n_ok,
        "last_field_deg": float(fields[n_ok - 1]) if n_ok else None,
        "r_last_mm": float(r_ok[-1]) if n_ok else None,
        "first_failure": None,
        "warning": None,
    }
    if n_ok == fields.size:
        return out
    code = int(status[n_ok])
    out["first_failure"] = {"field_deg": float(fields[n_ok]), "status": status_name(code)}
    names = sorted({status_name(c) for c in status[n_ok:] if c != 0}) or [status_name(code)]
    reach = (
        f"the profile stops at r = {r_ok[-1]:.4g} mm (field {fields[n_ok - 1]:.4g} deg)"
        if n_ok
        else "no field traced"
    )
    out["warning"] = (
        f"{fields.size - n_ok} of {fields.size} fields ({fields[n_ok]:.4g}-{fmax:g} deg) are left "
        f"out: the trace fails from {fields[n_ok]:.4g} deg on ({', '.join(names)}); {reach}, and "
        "the fits cover only that; lower --max-field to fit traced fields only"
    )
    return out


def register(sub: argparse._SubParsersAction) -> None:
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
        epilog=units_epilog(
            "orthoscope coefficients --lens cooke-triplet-f4 --focus 12x --focal-length-px 4000 "
            "--json",
            f"orthoscope coefficients {PENTAX_CSV} --profile 8,1.5 --principal-distance-mm 45",
        ),
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
    add_strict_arg(
        c,
        help="--lens: exit with status 2 when a field up to --max-field cannot be traced "
        "(default: a warning, and the fits use the fields up to the first failure), or when the "
        "lens file names a glass read only as a substitute.",
    )
    c.add_argument(
        "--focal-length-px", type=float, metavar="PX", help="Focal length in pixels (OpenCV fx)."
    )
    c.add_argument("--pixel-pitch-um", type=float, metavar="UM", help="Pixel pitch (micrometres).")
    c.add_argument(
        "--balanced",
        action="store_true",
        help="Derive the OpenCV coefficients from the balanced fit (c_g = c (1 + K0)).",
    )
    add_output_args(
        c,
        csv=False,
        json_help="Print JSON: fits and an 'opencv' block with dist_coeffs [k1,k2,p1,p2,k3].",
    )
    c.set_defaults(func=cmd_coefficients)
