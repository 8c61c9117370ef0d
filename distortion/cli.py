"""The ``orthoscope`` command line.

Every subcommand prints a readable table by default, ``--json`` (stable keys, documented in the
README) or ``--csv`` for programs. Errors a person can cause print one line naming the file, line or
surface and exit with status 2; there is never a traceback (set ORTHOSCOPE_DEBUG=1 to see one).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections.abc import Callable, Sequence

import numpy as np

from raytrace.errors import OrthoscopeError

EXIT_USAGE = 2

DISTANCE_HELP = (
    "Object distance: 'inf', a positive number of mm from the object plane to the FIRST VERTEX "
    "(a magnitude, as in lens files), or an image scale 'Nx' meaning Gaussian magnification -1/N "
    "(e.g. 12x). Default: the lens file's object."
)
S_HELP = (
    "Object plane as Pestrecov's signed s: mm from the first principal point H, NEGATIVE for a "
    "real object (e.g. -55.0009). Alternative to --object-distance."
)
IMAGE_HELP = (
    "Image plane as Pestrecov's s': mm from the second principal point H', positive to the right "
    "(e.g. 525). Default: the plane the lens file defines (its last thickness; a file whose last "
    'thickness is "gaussian" means the Gaussian plane of whatever object is traced).'
)
VERTEX_HELP = "Image plane as a distance (mm) from the LAST VERTEX, positive to the right."
DEFOCUS_HELP = (
    "Image plane as a defocus (mm) from the Gaussian image plane of the object; positive moves "
    "it away from the lens."
)
FIELDS_HELP = (
    "Comma-separated fields: half-field angles in degrees (chief-ray slope angle in object space) "
    "or object heights in mm (signed; positive above the axis), as --field-kind says."
)


class CliError(OrthoscopeError):
    """A usage error detected after argparse (bad combination of flags, bad value)."""


# ----------------------------------------------------------------------------- helpers
def _float(text: str, what: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise CliError(f"{what}: expected a number, got {text!r}") from None
    if math.isnan(v):
        raise CliError(f"{what}: expected a number, got {text!r}")
    return v


def parse_list(text: str, what: str) -> np.ndarray:
    """'0,10,20' → array; clear error on garbage."""
    parts = [p.strip() for p in text.split(",") if p.strip()]
    if not parts:
        raise CliError(f"{what}: empty list")
    vals = np.array([_float(p, what) for p in parts])
    if not np.all(np.isfinite(vals)):
        raise CliError(f"{what}: values must be finite")
    return vals


def load(name: str):
    """Load a lens by bundled name or path (all readers the project has)."""
    from raytrace.library import load_lens

    return load_lens(name)


def resolve_object_distance(lens, text: str | None, s: float | None) -> float:
    """Object distance (positive magnitude from the first vertex, or inf) from --object-distance
    or --s (Pestrecov's signed s from H). See DISTANCE_HELP / S_HELP."""
    from raytrace.paraxial import paraxial

    if text is not None and s is not None:
        raise CliError("give either --object-distance or --s, not both")
    if s is not None:
        if not (s < 0):
            raise CliError(f"--s must be negative (a real object left of H), got {s}")
        par = paraxial(lens, math.inf)
        od = -(par.z_H + s)
        if not od > 0:
            raise CliError(f"--s {s} puts the object plane behind the first vertex")
        return od
    if text is None:
        return lens.object_distance
    t = text.strip().lower()
    if t in ("inf", "infinity", "infinite"):
        return math.inf
    if t.endswith("x"):
        n = _float(t[:-1], "--object-distance Nx")
        if not n > 0:
            raise CliError(f"--object-distance {text}: the image scale N must be positive")
        par = paraxial(lens, math.inf)
        s_ = -par.efl * (n + 1.0)  # m0 = f/(f+s) = -1/N  (Pestrecov Eq. 5)
        return -(par.z_H + s_)
    v = _float(text, "--object-distance")
    if not v > 0:
        raise CliError(
            f"--object-distance must be a positive magnitude (mm from the object plane to the "
            f"first vertex), 'inf' or 'Nx'; got {text}"
        )
    return v


def add_object_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--object-distance", metavar="D", help=DISTANCE_HELP)
    p.add_argument("--s", type=float, metavar="S", help=S_HELP)


def add_field_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--fields", metavar="F1,F2,...", help=FIELDS_HELP)
    p.add_argument(
        "--max-field", type=float, metavar="F", help="Largest field (default: the lens's)."
    )
    p.add_argument(
        "--steps",
        type=int,
        default=None,
        metavar="N",
        help="Number of equal field steps from 0 to --max-field (default 10).",
    )
    p.add_argument(
        "--field-kind",
        choices=["angle", "height"],
        help="What the fields are: 'angle' (deg) or 'height' (object mm). Default: the "
        "lens file's kind; angles for a finite object are Pestrecov's nominal "
        "angles, y = p0 tan(alpha).",
    )


def resolve_fields(lens, args) -> tuple[np.ndarray, str]:
    kind = args.field_kind or lens.field.kind
    if args.fields is not None:
        if args.max_field is not None or args.steps is not None:
            raise CliError("give either --fields or --max-field/--steps, not both")
        return parse_list(args.fields, "--fields"), kind
    fmax = args.max_field
    if fmax is None:
        if kind != lens.field.kind:
            raise CliError(f"--field-kind {kind} needs --fields or --max-field")
        fmax = lens.field.value
    steps = 10 if args.steps is None else args.steps
    if steps < 1:
        raise CliError("--steps must be at least 1")
    if not math.isfinite(fmax):
        raise CliError("--max-field must be finite")
    return np.linspace(0.0, fmax, steps + 1), kind


def add_output_args(p: argparse.ArgumentParser) -> None:
    g = p.add_mutually_exclusive_group()
    g.add_argument("--json", action="store_true", help="Print JSON (stable keys; see README).")
    g.add_argument("--csv", action="store_true", help="Print CSV.")


def json_clean(obj):
    """Replace non-finite floats by "inf"/"-inf"/null so the output is strict JSON."""
    if isinstance(obj, dict):
        return {k: json_clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_clean(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        v = float(obj)
        if math.isnan(v):
            return None
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return v
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def print_json(obj) -> None:
    print(json.dumps(json_clean(obj), indent=2))


def fmt(v: float, width: int = 12, prec: int = 4) -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return f"{'-':>{width}}"
    if isinstance(v, float) and math.isinf(v):
        return f"{('inf' if v > 0 else '-inf'):>{width}}"
    return f"{v:>{width}.{prec}f}"


def resolve_image_z(par, args, lens) -> tuple[float, str]:
    """Absolute z of the image plane from --image-distance / --image-from-vertex / --defocus (an
    argparse mutually exclusive group: at most one is given); default: the lens file's plane."""
    if args.image_distance is not None:
        z, name = par.z_from_s_prime(args.image_distance), "image-distance"
    elif args.image_from_vertex is not None:
        z, name = par.z_from_last_vertex(args.image_from_vertex), "image-from-vertex"
    elif args.defocus is not None:
        z, name = par.z_from_defocus(args.defocus), "defocus"
    elif lens.image_solve == "gaussian":
        return par.z_gauss, "lens file: Gaussian plane of the object"
    else:
        return par.z_image_file, "lens file"
    check_image_z(par, z)
    return z, name


def check_image_z(par, z: float) -> None:
    if not z > par.z_last:
        raise CliError(
            f"image plane at z = {z:.4f} mm lies on or before the last vertex (z = {par.z_last:.4f}"
            f" mm): it must be behind the last surface"
        )


# ----------------------------------------------------------------------------- commands
def cmd_lenses(args) -> int:
    from raytrace.library import format_lens_table, lens_infos_to_dict, list_lenses

    infos = list_lenses()
    if args.json:
        print_json(lens_infos_to_dict(infos))
    else:
        print(format_lens_table(infos))
    return 0


def paraxial_report(lens, par) -> list[tuple[str, float, str]]:
    rows = [
        ("EFL (1/power)", par.efl, "mm"),
        ("BFL: last vertex -> F'", par.bfl, "mm"),
        ("FFL: first vertex -> F", par.ffl, "mm"),
        ("F  (z from first vertex)", par.z_F, "mm"),
        ("F' (z from first vertex)", par.z_Fp, "mm"),
        ("H  principal point (z)", par.z_H, "mm"),
        ("H' principal point (z)", par.z_Hp, "mm"),
        ("N  nodal point (z)", par.z_N, "mm"),
        ("N' nodal point (z)", par.z_Np, "mm"),
        ("E0  entrance pupil (z)", par.z_E0, "mm"),
        ("E0' exit pupil (z)", par.z_E0p, "mm"),
        ("HE0 (Pestrecov)", par.HE0, "mm"),
        ("H'E0' (Pestrecov)", par.HpE0p, "mm"),
        ("entrance pupil diameter", par.epd, "mm"),
        ("exit pupil diameter", par.xpd, "mm"),
        ("pupil magnification", par.pupil_magnification, ""),
        ("m_e (Pestrecov Eq. 6)", par.m_e, ""),
        ("Lagrange invariant", par.lagrange, "mm"),
        ("stop radius (paraxial)", par.stop_radius, "mm"),
        ("working f-number", par.working_fnumber, ""),
    ]
    if not par.infinite:
        rows += [
            ("object: s from H (Pestrecov)", par.s, "mm"),
            ("p0 = s - HE0", par.p0, "mm"),
            ("Gaussian image: s' from H'", par.s_prime_gauss, "mm"),
            ("Gaussian image from last vertex", par.gaussian_image_distance, "mm"),
            ("m0 (Pestrecov Eq. 5)", par.m0, ""),
        ]
    else:
        rows += [("Gaussian image from last vertex", par.gaussian_image_distance, "mm")]
    rows += [("image plane of the file, from last vertex", par.z_image_file - par.z_last, "mm")]
    return rows


def cmd_paraxial(args) -> int:
    from raytrace.paraxial import paraxial

    lens = load(args.lens)
    od = resolve_object_distance(lens, args.object_distance, args.s)
    wl = args.wavelength
    par = paraxial(lens, od, wl)
    if args.json:
        print_json({"lens": lens.name, "units": "mm", **par.to_dict()})
        return 0
    obj = "infinity" if par.infinite else f"{od:.6g} mm before the first vertex"
    print(f"{lens.name} — paraxial data at {par.wavelength:g} nm, object at {obj}")
    print("(z positions from the first vertex, light travelling toward +z)")
    for label, v, unit in paraxial_report(lens, par):
        print(f"  {label:42} {fmt(v, 14, 6)} {unit}")
    return 0


def cmd_trace(args) -> int:
    from raytrace.paraxial import paraxial
    from raytrace.trace import STATUS_NAMES, chief_rays

    lens = load(args.lens)
    od = resolve_object_distance(lens, args.object_distance, args.s)
    fields, kind = resolve_fields(lens, args)
    par = paraxial(lens, od, args.wavelength)
    z_img, plane_from = resolve_image_z(par, args, lens)
    if kind == "height" and par.infinite:
        raise CliError("object-height fields need a finite object (--object-distance)")
    cr = chief_rays(lens, fields, field_kind=kind, object_distance=od, wavelength=args.wavelength)
    y_img = cr.heights_at(z_img)
    ok = cr.status == 0
    y_obj = cr.y_start if not par.infinite else np.full(len(fields), np.nan)
    landing = cr.landing_angle_deg
    ep = cr.entrance_pupil_z
    status = [STATUS_NAMES[int(s)] for s in cr.status]
    fname = "angle_deg" if kind == "angle" else "object_height_mm"
    rows = []
    for i in range(len(fields)):
        rows.append(
            {
                fname: float(fields[i]),
                "y_object_mm": float(y_obj[i]) if not par.infinite else None,
                "y_image_mm": float(y_img[i]) if ok[i] else None,
                "landing_angle_deg": float(landing[i]) if ok[i] else None,
                "entrance_pupil_z_mm": float(ep[i]) if ok[i] else None,
                "status": status[i],
            }
        )
    plane = {
        "z_mm": z_img,
        "s_prime_mm": z_img - par.z_Hp,
        "from_last_vertex_mm": z_img - par.z_last,
        "defocus_mm": z_img - par.z_gauss,
        "given_as": plane_from,
    }
    if args.json:
        print_json(
            {
                "lens": lens.name,
                "wavelength_nm": par.wavelength,
                "object_distance_mm": od,
                "field_kind": kind,
                "image_plane": plane,
                "rays": rows,
            }
        )
        return 0
    if args.csv:
        cols = [
            fname,
            "y_object_mm",
            "y_image_mm",
            "landing_angle_deg",
            "entrance_pupil_z_mm",
            "status",
        ]
        print(",".join(cols))
        for r in rows:
            print(
                ",".join(
                    "" if r[c] is None else (repr(r[c]) if isinstance(r[c], float) else str(r[c]))
                    for c in cols
                )
            )
        return 0
    obj = "infinity" if par.infinite else f"{od:.6g} mm before the first vertex"
    print(f"{lens.name} — real chief rays at {par.wavelength:g} nm, object at {obj}")
    print(
        f"image plane: {plane['from_last_vertex_mm']:.6f} mm after the last vertex "
        f"(s' = {plane['s_prime_mm']:.6f} mm from H', defocus {plane['defocus_mm']:+.6f} mm; "
        f"from {plane_from})"
    )
    head = "field (deg)" if kind == "angle" else "y obj (mm)"
    print(
        f"{head:>12} {'y obj (mm)' if kind == 'angle' and not par.infinite else '':>12}"
        f" {'y image (mm)':>14} {'landing (deg)':>14} {'EP z (mm)':>12}  status"
    )
    for i, r in enumerate(rows):
        extra = fmt(r["y_object_mm"], 12, 4) if (kind == "angle" and not par.infinite) else " " * 12
        print(
            f"{fields[i]:12.4f} {extra} {fmt(r['y_image_mm'], 14, 6)} "
            f"{fmt(r['landing_angle_deg'], 14, 6)} {fmt(r['entrance_pupil_z_mm'], 12, 4)}  "
            f"{r['status']}"
        )
    return 0


# ----------------------------------------------------------------------------- parser
def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="orthoscope",
        description=(
            "Lens distortion toolkit: paraxial data, real chief rays and Pestrecov's "
            "characteristic and calibrated distortion in Gaussian and non-Gaussian image planes. "
            "LENS is a path to a prescription file or the name of a bundled lens (see "
            "'orthoscope lenses'). Distances in mm; light travels toward +z; signs follow "
            "Pestrecov (1958) Fig. 1."
        ),
        epilog="Run 'orthoscope COMMAND --help' for each command's options.",
    )
    p.add_argument(
        "--threads",
        type=int,
        metavar="N",
        help="Numba threads for bulk traces (default: numba's setting, NUMBA_NUM_THREADS).",
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    q = sub.add_parser("lenses", help="List the bundled lenses.")
    q.add_argument("--json", action="store_true", help="Print JSON.")
    q.set_defaults(func=cmd_lenses)

    q = sub.add_parser(
        "paraxial",
        help="First-order data: EFL, BFL, cardinal points, pupils, m_e, Gaussian image.",
        description="Paraxial (first-order) listing of a lens, Pestrecov's HE0, H'E0', m_e (Eq. 6),"
        " and for a finite object s, p0, s' and m0 (Eqs. 5, 7). Positions are z from the first "
        "vertex.",
    )
    q.add_argument("lens", metavar="LENS", help="Lens file path or bundled lens name.")
    add_object_args(q)
    q.add_argument("--wavelength", type=float, metavar="NM", help="Wavelength in nm.")
    q.add_argument("--json", action="store_true", help="Print JSON (keys as in the README).")
    q.set_defaults(func=cmd_paraxial)

    q = sub.add_parser(
        "trace",
        help="Real chief rays: image height, landing angle, real entrance pupil, status.",
        description="Trace the real chief rays (aimed at the centre of the real stop) and report "
        "per field the real image height y' on the image plane, the landing angle, the real "
        "entrance-pupil position (z from the first vertex) and the ray status.",
    )
    q.add_argument("lens", metavar="LENS", help="Lens file path or bundled lens name.")
    add_object_args(q)
    add_field_args(q)
    g = q.add_mutually_exclusive_group()
    g.add_argument("--image-distance", type=float, metavar="S'", help=IMAGE_HELP)
    g.add_argument("--image-from-vertex", type=float, metavar="D", help=VERTEX_HELP)
    g.add_argument("--defocus", type=float, metavar="DZ", help=DEFOCUS_HELP)
    q.add_argument("--wavelength", type=float, metavar="NM", help="Wavelength in nm.")
    add_output_args(q)
    q.set_defaults(func=cmd_trace)

    for register in EXTRA_COMMANDS:
        register(sub)
    return p


# Other modules append ``register(subparsers)`` callables here (distortion, calibrate, ...).
EXTRA_COMMANDS: list[Callable[[argparse._SubParsersAction], None]] = []


def main(argv: Sequence[str] | None = None) -> int:
    _register_extras()
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        if args.threads is not None:
            _set_threads(args.threads)
        return int(args.func(args) or 0)
    except OrthoscopeError as e:
        print(f"orthoscope {args.command}: error: {e}", file=sys.stderr)
        return EXIT_USAGE
    except BrokenPipeError:
        return 0
    except Exception as e:  # never a traceback for a person
        if os.environ.get("ORTHOSCOPE_DEBUG"):
            raise
        print(
            f"orthoscope {args.command}: internal error: {type(e).__name__}: {e} "
            f"(set ORTHOSCOPE_DEBUG=1 for a traceback and please report it)",
            file=sys.stderr,
        )
        return 1


def _set_threads(n: int) -> None:
    """--threads N: numba threads for this run (1 .. NUMBA_NUM_THREADS)."""
    import numba

    top = numba.config.NUMBA_NUM_THREADS
    if not 1 <= n <= top:
        raise CliError(f"--threads must be between 1 and {top} (NUMBA_NUM_THREADS), got {n}")
    numba.set_num_threads(n)


def _register_extras() -> None:
    if EXTRA_COMMANDS:
        return
    from . import cli_commands

    EXTRA_COMMANDS.extend(cli_commands.REGISTER)


if __name__ == "__main__":
    sys.exit(main())
