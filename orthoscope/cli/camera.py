"""``orthoscope camera``: from a prescription to the camera models of OpenCV, COLMAP, Metashape and
Australis, and back (:mod:`distortion.camera`).

Four actions, chosen by the first word:

- ``orthoscope camera LENS ...`` — real chief rays traced onto a sensor, a model fitted to them
  (``--model``), written as a calibration file (``-o``), a table of models per object distance
  (``--object-distances``), a picture of the distortion (``--picture``) and ``cv2.remap`` maps
  (``--maps``);
- ``orthoscope camera compare LENS CALIBRATION`` — a measured calibration against the
  prescription's prediction at the same focus and object distance;
- ``orthoscope camera convert CALIBRATION --model TARGET`` — any model to any model over the
  sensor, with the residual;
- ``orthoscope camera variation CAL1 CAL2 --calibrated-at S1,S2 ...`` — models per object
  distance from two measured calibrations (Brown; Fraser & Shortis 1992).
"""

from __future__ import annotations

import argparse
import functools
import math

from . import EXIT_USAGE, Parser
from .common import (
    CliError,
    Noted,
    add_force_arg,
    add_object_args,
    add_output_args,
    add_strict_arg,
    add_wavelength_arg,
    as_typed,
    bundled_or_path,
    check_output_path,
    check_plot_path,
    first_repeat,
    given_flags,
    length,
    load_recorded,
    object_flags_given,
    print_json,
    save_plot,
    warn,
    warn_deprecated,
)

#: Quick runs of this command for the per-command tests (tests/test_hardening.py): argv lists
#: with {data} = tests/data, {specs} = lenses/specs, {tmp} = a scratch folder.
SAMPLES = [
    ["camera", "cooke-triplet-f4", "--sensor", "24x16", "--pixels", "1200x800", "--grid", "9x7",
     "-o", "{tmp}/cooke.yml"],
    ["camera", "topogon-like-pestrecov", "--sensor", "200x200", "--pixels", "2000x2000",
     "--model", "fisheye", "--grid", "9x9", "--json"],
    ["camera", "compare", "cooke-triplet-f4", "{data}/camera/cooke-measured-2m.yml",
     "--sensor", "24x16", "--focus", "2m", "--object-distance", "2m", "--grid", "9x7"],
    ["camera", "convert", "{data}/camera/cooke-measured-2m.yml", "--model", "metashape",
     "-o", "{tmp}/cooke.xml"],
    ["camera", "variation", "{data}/camera/cooke-measured-1m.yml",
     "{data}/camera/cooke-measured-5m.yml", "--calibrated-at", "1m,5m", "--focal-length", "50",
     "--focus", "2m", "--object-distances", "1m,2m,5m", "--sensor", "24x16"],
    ["camera", "cooke-triplet-f4", "--sensor", "24x16", "--pixels", "1200x800", "--grid", "9x7",
     "--focus", "2m", "--object-distances", "1m,2m,inf", "--csv"],
]  # fmt: skip
#: Output options (flag, suffix) the tests aim at inputs, existing files and failing disks.
OUTPUTS = [("-o", ".yml"), ("--plot", ".png")]

ACTIONS = ("compare", "convert", "variation")
MODEL_WORDS = ("opencv", "fisheye", "colmap", "colmap-fisheye", "metashape", "australis")
PATTERNS = ("grid", "checkerboard")
#: the calibrations bundled with the lens library (lenses/calibrations/NAME.yml): synthetic
#: examples for compare / convert / variation that work from any folder
BUNDLED_CALIBRATIONS = (
    "cooke-triplet-f4-synthetic-1m",
    "cooke-triplet-f4-synthetic-2m",
    "cooke-triplet-f4-synthetic-5m",
)


# ---------------------------------------------------------------------------------- helpers
def _whole(text: str, how: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number; {how}") from None


def coefficient_count(text: str) -> int:
    """argparse type of --coefficients: a whole number (the counts are checked with --model)."""
    return _whole(text, "give 4, 5, 8, 12 or 14 (--model opencv) or 1 to 4 (--model fisheye)")


def camera_id(text: str) -> int:
    """argparse type of --camera-id: a whole number, a CAMERA_ID of the cameras.txt."""
    return _whole(text, "give the CAMERA_ID of a camera of the cameras.txt (its first column)")


def g_factor(text: str) -> float:
    """argparse type of --g: a number, g_ss' of Fraser & Shortis' Eq. 6."""
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a number; give g_ss' of Fraser & Shortis' Eq. 6, e.g. 0.45"
        ) from None


def calibration_path(word: str) -> str:
    """A CALIBRATION as given, or the bundled calibration of that name
    (``lenses/calibrations/NAME.yml``; :func:`~orthoscope.cli.common.bundled_or_path`)."""
    return bundled_or_path(word, "calibrations", ".yml")


def _write(path, data, args) -> None:
    from raytrace.files.output import write_atomic

    write_atomic(path, data, inputs=args._inputs, overwrite=args.force, flag="--force")
    import sys

    print(f"wrote {path}", file=sys.stderr)


def _grid(text: str | None):
    if text is None:
        return None
    from distortion.camera.sensor import parse_pixels
    from distortion.camera.setup import MAX_GRID

    how = f"write it as columns x rows, each 2..{MAX_GRID}, e.g. 25x17"
    try:
        grid = parse_pixels(text)
    except Exception:  # noqa: BLE001 - DataError in the words of --pixels
        raise CliError(f"--grid {text}: {how}") from None
    if not all(2 <= n <= MAX_GRID for n in grid):
        raise CliError(f"--grid {text}: {how}")
    return grid


#: the focus keywords of CameraSetup (the focused object, or the sensor plane), each a flag
FOCUS_KEYS = ("focus", "focus_s", "focus_scale", "s_prime", "from_last_vertex", "defocus")


def _check_object_flags(args) -> None:
    """The object and focus flags of ``camera LENS`` / ``compare`` before any work: given one
    way, each value readable, named as given (``--s`` where that was typed). Object distances
    are positive and Pestrecov's s negative (a real object); the lens decides the rest."""
    obj = object_flags_given(args)  # --s with --object-s: refused at parse time
    if getattr(args, "object_distances", None) is not None and obj:
        raise CliError(f"--object-distances are the table's rows: leave out {obj[0]}")
    focus = [k for k in FOCUS_KEYS if getattr(args, k, None) is not None]
    if len(focus) > 1:
        flags = ", ".join("--" + k.replace("_", "-") for k in focus)
        raise CliError(f"give the focus one way, not {flags}")
    if args.gaussian and focus:
        raise CliError("--gaussian (focused on the object) goes alone, without another focus flag")
    s_flag = as_typed(args, "--object-s")
    for flag, value, signed in (
        ("--object-distance", args.object_distance, s_flag),
        ("--focus", args.focus, "--focus-s"),
    ):
        if value is not None:
            _object_distance(value, flag, signed)
    for flag, value in ((s_flag, args.object_s), ("--focus-s", args.focus_s)):
        if value is not None and not length(value, flag) < 0:
            raise CliError(
                f"{flag} {value}: Pestrecov's s is negative for a real object (mm from H, left "
                "of it), e.g. -2000 or -2m"
            )
    for flag, value in (("--object-scale", args.object_scale), ("--focus-scale", args.focus_scale)):
        if value is not None:
            _scale(value, flag)
    for flag in ("--s-prime", "--from-last-vertex", "--defocus"):
        value = getattr(args, flag[2:].replace("-", "_"))
        if value is not None:
            length(value, flag)


def _scale(value: str, flag: str) -> float:
    from raytrace.units import UnitError, image_scale

    try:
        return image_scale(str(value).strip(), flag)
    except UnitError as e:
        raise CliError(str(e)) from None


def _object_distance(value: str, flag: str, signed: str | None = None) -> None:
    """An object distance as ``camera LENS`` reads it (mm from the first vertex, with a unit,
    ``inf`` or an image scale ``12x``): a CliError naming ``flag`` for anything else; ``signed``
    the flag of Pestrecov's signed s, the fix for a negative one."""
    t = str(value).strip().lower()
    if t in ("inf", "infinity"):
        return
    if t.endswith(("x", "\u00d7")):
        _scale(t, flag)
        return
    if not length(t, flag, allow_inf=True) > 0:
        fix = f"; for Pestrecov's signed s use {signed}" if signed else ""
        raise CliError(
            f"{flag} {value}: a positive distance in mm from the object plane to the first "
            f"vertex (or 2m, inf, 12x){fix}"
        )


#: the API's keywords of CameraSetup and the flags that give them (its messages in the
#: command line's words, :func:`_api_words`)
SETUP_FLAGS = {
    "object_distance": "--object-distance",
    "object_s": "--object-s",
    "object_scale": "--object-scale",
    "focus": "--focus",
    "focus_s": "--focus-s",
    "focus_scale": "--focus-scale",
    "s_prime": "--s-prime",
    "from_last_vertex": "--from-last-vertex",
    "defocus": "--defocus",
}


#: the same keywords as the TOML camera spec names them (distortion/camera/setup.py)
SPEC_KEYS = {
    "object_distance": "[object] distance",
    "object_s": "[object] s",
    "object_scale": "[object] scale",
    "focus": "[focus] distance",
    "focus_s": "[focus] s",
    "focus_scale": "[focus] scale",
    "s_prime": "[focus] s_prime",
    "from_last_vertex": "[focus] from_last_vertex",
    "defocus": "[focus] defocus",
}


def _api_words(message: str, args) -> str:
    """A message of the camera API (a setup the lens cannot image) in the command line's words:
    ``sensor at s_prime = -5 mm`` -> ``sensor at --s-prime -5 mm``, ``focus_s must be`` ->
    ``--focus-s must be`` (a keyword that the --camera spec gave: its key there, ``cam.toml
    [focus] s``), without the ``CameraSetup:`` prefix."""
    import re

    given = given_flags(args)

    def flag(key: str, value: str = "") -> str:
        f = SETUP_FLAGS[key]
        if f == "--object-s" and "--s" in given:
            f = "--s"
        if f not in given and getattr(args, "camera", None):
            return f"{args.camera} {SPEC_KEYS[key]}" + (f" = {value}" if value else "")
        return f"{f} {value}" if value else f

    keys = "|".join(sorted(SETUP_FLAGS, key=len, reverse=True))
    underscored = "|".join(k for k in SETUP_FLAGS if "_" in k)
    return re.sub(  # "key = value" or a bare keyword with an underscore, in one pass
        rf"(?<![\w-])(?:({keys}) = (\S+)|({underscored})\b(?!=))",
        lambda m: flag(m.group(1), m.group(2)) if m.group(1) else flag(m.group(3)),
        message.replace("CameraSetup: ", ""),
    )


def _setup_keywords(args) -> dict:
    """The object / focus / trace keywords of CameraSetup from the flags (strings are parsed by
    CameraSetup, one path for the API and the command line)."""
    plane = {k: getattr(args, k) for k in FOCUS_KEYS[3:] if getattr(args, k, None) is not None}
    focus = {k: getattr(args, k) for k in FOCUS_KEYS[:3] if getattr(args, k, None) is not None}
    kw = {
        "object_distance": args.object_distance,
        "object_s": args.object_s,
        "object_scale": args.object_scale,
        **focus,
        **plane,
        "wavelength": args.wavelength,
        "grid": _grid(args.grid),
    }
    if args.no_clip:
        kw["clip"] = False
    return {k: v for k, v in kw.items() if v is not None}


#: the sensor flags as the messages of distortion.camera.sensor name them: (head of the
#: message, flag, attribute)
SENSOR_WORDS = (
    ("principal-point offset", "--principal-point", "principal_point"),
    ("sensor size", "--sensor", "sensor"),
    ("Sensor width_mm", "--sensor", "sensor"),
    ("Sensor height_mm", "--sensor", "sensor"),
    ("sensor", "--sensor", "sensor"),
    ("pixel count", "--pixels", "pixels"),
    ("Sensor width_px", "--pixels", "pixels"),
    ("Sensor height_px", "--pixels", "pixels"),
    ("pixel pitch", "--pitch", "pitch"),
)


#: how each sensor flag is written, for a refusal that does not say it
SENSOR_HOW = {
    "--sensor": "give width x height in mm, e.g. 36x24",
    "--pixels": "give columns x rows, e.g. 6000x4000",
    "--pitch": "give the pixel pitch in µm, e.g. 4.35 (or 0.00435mm)",
    "--principal-point": "give dx,dy in mm from the sensor centre (x right, y up), e.g. 0.1,-0.05",
}


def _sensor_words(message: str, args, calibration) -> str:
    """A refusal of the sensor (:mod:`distortion.camera.sensor`) in the flags' words: ``pixel
    count 'abc': give ...`` -> ``--pixels abc: give ...``; the fixes that name the API's
    keywords name the flags."""
    import re

    for head, flag, dest in SENSOR_WORDS:
        value = getattr(args, dest, None)
        if value is None or not message.startswith(head):
            continue
        m = re.match(rf"{re.escape(head)}(=\S+|\s+'[^']*'|\s+\S+):\s+(.*)$", message)
        if m:  # "pixel count 'abc': give ..." -> "--pixels abc: give ..."
            why = m.group(2).replace("a whole number of pixels", "columns and rows are whole "
                                     "numbers of pixels")  # fmt: skip
            if not any(w in why for w in ("e.g.", "give", "write", "pixels, 1..")):
                why += f"; {SENSOR_HOW[flag]}"
            return f"{flag} {value}: {why}"
        if head != "sensor":  # "pixel pitch 0.006 µm looks like ...", "Sensor width_mm=5000 mm"
            what = re.sub(r"^Sensor (width|height)_mm=", r"the \1 ", message)
            return f"{flag} {value}: {what}"
    if calibration is not None:
        pixels = f"{calibration.width}x{calibration.height} px"
        message = message.replace(
            "give two of size, pixels and pitch, or consistent values",
            f"give --sensor or --pitch (the pixel count is the calibration's {pixels})",
        )
        message = message.replace(
            "give the sensor size (e.g. '36x24' mm) or the pixel pitch (um)",
            "give --sensor WxH (mm) or --pitch UM (or --camera SPEC.toml)",
        )
    message = message.replace(
        "give two of size, pixels and pitch", "give two of --sensor, --pixels and --pitch"
    )
    return message.replace(
        "check the size (mm) and the pixel count", "check --sensor (mm) and --pixels"
    )


def _sensor(args, calibration=None):
    """The Sensor from --camera / --sensor / --pixels / --pitch / --principal-point (a
    calibration's pixel count when one is given); its refusals in the flags' words."""
    from distortion.errors import DataError

    try:
        return _sensor_of(args, calibration)
    except DataError as e:
        raise CliError(_sensor_words(str(e), args, calibration)) from e


def _sensor_of(args, calibration=None):
    from distortion.camera import Sensor, read_camera_setup
    from distortion.camera.traced import sensor_for_calibration

    base = read_camera_setup(args.camera).sensor if args.camera else None
    off = args.principal_point
    if calibration is not None:
        if args.pixels is not None:
            from distortion.camera.sensor import parse_pixels

            if parse_pixels(args.pixels) != (calibration.width, calibration.height):
                raise CliError(
                    f"--pixels {args.pixels} differs from the calibration's "
                    f"{calibration.width}x{calibration.height} px"
                )
        if args.sensor is None and args.pitch is None and base is not None:
            s = sensor_for_calibration(calibration, base)
            if off is not None:  # --principal-point replaces the spec's offset
                return Sensor(s.width_mm, s.height_mm, s.width_px, s.height_px, off)
            return s
        return sensor_for_calibration(
            calibration,
            size=args.sensor,
            pitch_um=args.pitch,
            principal_point_offset_mm=off if off is not None else (0.0, 0.0),
        )
    given = [v for v in (args.sensor, args.pixels, args.pitch) if v is not None]
    if not given:
        if base is None:
            raise CliError(
                "give the sensor: --sensor WxH (mm) with --pixels CxR or --pitch UM, or --camera "
                "SPEC.toml"
            )
        if off is not None:
            return Sensor(base.width_mm, base.height_mm, base.width_px, base.height_px, off)
        return base
    if len(given) < 2:
        raise CliError(
            "the sensor flags define the sensor: give two of --sensor WxH (mm), --pixels CxR "
            "and --pitch UM"
        )
    return Sensor.from_spec(
        size=args.sensor,
        pixels=args.pixels,
        pitch_um=args.pitch,
        principal_point_offset_mm=off if off is not None else (0.0, 0.0),
    )


def _setup(args, sensor):
    from distortion.camera import CameraSetup, read_camera_setup

    kw = _setup_keywords(args)
    if args.camera:
        spec = read_camera_setup(args.camera)
        if getattr(args, "gaussian", False):  # replaces the spec's focus, as --defocus does
            spec = spec.replace(**dict.fromkeys(FOCUS_KEYS))
        return spec.replace(sensor=sensor, **kw)
    return CameraSetup(sensor, **kw)


#: the names that tell a calibration file's format (distortion.camera.files.detect_format)
CALIBRATION_NAMES = (
    ".yml, .yaml or .json (OpenCV), .txt (COLMAP cameras.txt), .xml (Metashape) or .aus (Australis)"
)


def _calibration_format(path: str, fmt: str | None) -> str:
    """The format of the calibration file ``-o PATH``: --format, or the name's."""
    from distortion.camera.files import FORMATS, detect_format
    from distortion.errors import DataError

    if fmt is not None:
        if fmt not in FORMATS:
            raise CliError(f"--format {fmt}: use one of {', '.join(FORMATS)}")
        return fmt
    try:
        return detect_format(path)
    except DataError:
        raise CliError(
            f"-o {path}: the name does not tell the calibration format; end it in "
            f"{CALIBRATION_NAMES}, or give --format ({', '.join(FORMATS)})"
        ) from None


def _emit(args, text: str, data: dict, csv: str | None = None, note: str | None = None) -> None:
    """Text, JSON or CSV on stdout; with CSV (which has no room for it) ``note`` — the
    projection centre — goes to stderr, so that every output states it."""
    import sys

    if args.json:
        print_json(data)
    elif getattr(args, "csv", False) and csv is not None:
        print(csv, end="" if csv.endswith("\n") else "\n")
        if note:
            print(f"orthoscope camera: note: {note}", file=sys.stderr)
    else:
        print(text)


def _table_kind(path, what: str) -> str:
    """``"csv"`` or ``"json"``, by the suffix of ``-o PATH``; a CliError for any other suffix
    (``what``: what the command writes there)."""
    suffix = str(path).lower().rsplit(".", 1)[-1]
    if suffix not in ("csv", "json"):
        raise CliError(f"-o {path}: {what} is written as .csv or .json")
    return suffix


#: the flags that set something of another flag's output: the flag each needs, the attribute
#: of its value and what it sets (without that flag it would do nothing)
NEEDS = {
    "--pattern": ("--picture", "picture", "the pattern of --picture"),
    "--maps-direction": ("--maps", "maps", "the direction of --maps"),
    "--format": ("-o", "output", "the file format of -o"),
}


def _refuse_idle_flags(args) -> None:
    """CliError for a flag given (:func:`given_flags`, so also at its default value) without
    the flag whose output it sets (:data:`NEEDS`)."""
    given = given_flags(args)
    for flag, (needs, dest, what) in NEEDS.items():
        if flag in given and not getattr(args, dest, None):
            raise CliError(f"{flag} sets {what}: give {needs}, or drop {flag}")


def _read_calibrations(args, *paths):
    """The calibrations at ``paths`` (--camera-id choosing a camera of a COLMAP cameras.txt);
    a CliError for --camera-id given where none of them is a COLMAP file (it would do
    nothing)."""
    from distortion.camera import read_calibration

    fmts = [_input_format(p) for p in paths]
    for p, f in zip(paths, fmts, strict=True):
        if f is None:  # read_calibration says why it cannot be read
            read_calibration(p)
    if "--camera-id" in given_flags(args) and "colmap" not in fmts:
        what = " and ".join(f"{p} is {f}" for p, f in zip(paths, fmts, strict=True))
        raise CliError(
            f"--camera-id chooses a camera of a COLMAP cameras.txt, and {what}: drop --camera-id"
        )
    return [
        read_calibration(p, camera_id=args.camera_id if f == "colmap" else None)
        for p, f in zip(paths, fmts, strict=True)
    ]


def _input_format(path: str) -> str | None:
    """The format of the calibration file ``path`` as read_calibration tells it (its name,
    and the text of a .txt / .xml); a CliError for a name that tells none (no flag gives the
    format of an input); None for a file that cannot be read as text."""
    from pathlib import Path

    from distortion.camera.files import detect_format
    from distortion.errors import DataError

    try:
        detect_format(path)
    except DataError:
        raise CliError(
            f"{path}: the name does not tell the calibration format; a calibration file ends "
            f"in {CALIBRATION_NAMES}"
        ) from None
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except OSError:
        return None
    except UnicodeError:
        raise CliError(f"{path}: not a text file; a calibration file is text") from None
    return detect_format(path, text)


#: the file names of each model family's calibration files (for the messages)
FAMILY_FILES = {
    "opencv": ".yml, .yaml or .json",
    "colmap": "cameras.txt",
    "metashape": ".xml",
    "australis": ".aus",
}


def _calibration_out_format(args, camera, verb: str, fmt: str) -> str:
    """``fmt``, the format of the calibration file ``-o`` (:func:`_calibration_format`, found
    before the run); a CliError where it is of another model family than ``camera`` (the file
    would hold another model than the one --model asked for and the output states)."""
    from distortion.camera.files import FORMAT_FAMILY  # format -> model family, as files.py writes

    have, want = FORMAT_FAMILY[fmt], camera.spec.target
    if have != want:
        how = f" --format {args.format}" if args.format else ""
        default = "" if "--model" in given_flags(args) else " (the default)"
        raise CliError(
            f"-o {args.output}{how} writes the {have} family but --model {args.model}{default} "
            f"{verb} {camera.model}: give --model {have}, or -o a file of the {want} family "
            f"({FAMILY_FILES[want]})"
        )
    return fmt


#: the flags of ``camera LENS`` that only its one-distance run reads (not the table of models of
#: --object-distances)
ONE_DISTANCE_ONLY = ("--plot", "--picture", "--maps", "--maps-direction", "--pattern", "--format",
                     "--strict")  # fmt: skip


def _model_table_out(args, table, kind: str | None, note: str | None = None) -> None:
    """A table of camera models per object distance: written to ``-o`` as ``kind`` (.csv or
    .json, :func:`_table_kind` before the run) when given, and shown as text, JSON or CSV
    (:func:`_emit`, ``note`` as there)."""
    from ..report.camera import format_model_table, model_table_csv, model_table_to_dict

    data = {"models_by_distance": model_table_to_dict(table)}
    if args.output:
        from ..report.jsonout import dumps

        text = model_table_csv(table) if kind == "csv" else dumps(data) + "\n"
        _write(args.output, text, args)
    _emit(args, format_model_table(table), data, model_table_csv(table), note)


# ---------------------------------------------------------------------------------- actions
def _cmd_lens(args, lens_name: str) -> int:
    from distortion.camera import (
        camera_model,
        distortion_picture,
        remap_maps,
        traced_models_by_distance,
    )
    from distortion.errors import DataError

    from ..report.camera import (
        format_traced_camera,
        points_csv,
        traced_camera_to_dict,
    )

    lens = load_recorded(args, lens_name, args.camera)
    check_plot_path(args.plot, "--plot", args)
    for path in (args.output, args.picture, args.maps):
        check_output_path(path, args)
    if args.picture and not str(args.picture).lower().endswith(".png"):
        raise CliError(f"--picture {args.picture}: the picture is a .png image")
    if args.maps and not str(args.maps).lower().endswith(".npz"):
        raise CliError(f"--maps {args.maps}: the maps are written as a numpy .npz file")
    sensor = _sensor(args)
    setup = _setup(args, sensor)
    n = args.coefficients
    if args.object_distances is not None:
        unread = [f for f in given_flags(args) if f in ONE_DISTANCE_ONLY]
        if unread:
            raise CliError(
                f"with --object-distances the command writes the table of models per distance "
                f"only: {', '.join(unread)} {'is' if len(unread) == 1 else 'are'} read for one "
                f"object distance (--object-distance); drop {'it' if len(unread) == 1 else 'them'}"
            )
        kind = _table_kind(args.output, "a table of models") if args.output else None
        objs = _distances(args.object_distances)
        for d in objs:
            _object_distance(d, "--object-distances")
        try:
            table = traced_models_by_distance(lens, setup, objs, args.model, n_coefficients=n)
        except DataError as e:
            if any(getattr(setup, k) is not None for k in FOCUS_KEYS):
                raise
            import re  # no focus (flag or spec): the table is focused at its first distance

            raise CliError(
                re.sub(
                    r"focused at focus = (\S+):",
                    r"focused at \1 (the first of --object-distances, as no focus is given):",
                    str(e),
                )
            ) from e
        _model_table_out(args, table, kind, setup.resolve(lens).projection_centre)
        return 0
    _refuse_idle_flags(args)
    fmt = _calibration_format(args.output, args.format) if args.output else None
    tc = camera_model(lens, setup, args.model, n_coefficients=n)
    if tc.points.n_failed:
        import numpy as np

        pts = tc.points
        r = np.hypot(*pts.image_mm[pts.ok].T)
        reach = float(r.max()) if r.size else 0.0
        corner = 0.5 * math.hypot(tc.sensor.width_mm, tc.sensor.height_mm)
        what = (
            f"{pts.n_failed} of {pts.status.size} chief rays do not reach the sensor (the lens "
            f"images out to r = {reach:.2f} mm; the sensor's corners are at {corner:.2f} mm)"
        )
        if args.strict:  # before anything is written
            raise CliError(f"{what}; --strict fails")
        warn(
            f"{what}: the model is fitted inside that circle and extrapolated beyond it, where "
            "it (and its maps and picture) is not the lens's; --strict refuses such a run"
        )
    if args.output:
        fmt = _calibration_out_format(args, tc.camera, "fits", fmt)
        _write(args.output, tc.calibration_text(fmt), args)
    _emit(args, format_traced_camera(tc), traced_camera_to_dict(tc), points_csv(tc),
          tc.geometry.projection_centre)  # fmt: skip
    if args.plot:
        from ..plots.camera import plot_camera_residuals

        save_plot(lambda: plot_camera_residuals(tc), args.plot, args)
    if args.picture:
        pic = distortion_picture(tc.camera, args.pattern)
        _write(args.picture, _png(pic.image), args)
    if args.maps:
        maps = remap_maps(tc.camera, args.maps_direction)
        _write(args.maps, _npz(maps), args)
    return 0


def _distances(text: str) -> list[str]:
    """--object-distances D1,D2,...: each once, none empty (one row per distance)."""
    objs = [p.strip() for p in str(text).split(",")]
    if not objs or any(not p for p in objs):
        raise CliError(f"--object-distances {text!r}: an empty entry; write e.g. 1m,2m,5m")
    dup = first_repeat(objs)
    if dup is not None:
        raise CliError(f"--object-distances {text!r}: {dup} is listed twice")
    return objs


def _png(image) -> bytes:
    import cv2

    ok, buf = cv2.imencode(".png", image)
    if not ok:  # pragma: no cover - OpenCV always encodes a uint8 image
        raise CliError("OpenCV could not encode the picture as PNG")
    return buf.tobytes()


def _npz(maps) -> bytes:
    import io

    import numpy as np

    buf = io.BytesIO()
    np.savez(
        buf,
        map1=maps.map1,
        map2=maps.map2,
        camera_matrix=maps.camera_matrix,
        direction=np.array(maps.direction),
        scale=np.array(maps.scale),
    )
    return buf.getvalue()


def _cmd_compare(args, lens_name: str, cal_word: str) -> int:
    from distortion.camera import compare_calibration

    from ..report.camera import comparison_csv, comparison_to_dict, format_comparison

    cal_path = calibration_path(cal_word)
    lens = load_recorded(args, lens_name, cal_path, args.camera)
    check_plot_path(args.plot, "--plot", args)
    check_output_path(args.output, args)
    kind = _table_kind(args.output, "a comparison") if args.output else None  # before the trace
    (cal,) = _read_calibrations(args, cal_path)
    sensor = _sensor(args, cal)
    setup = _setup(args, sensor)
    cmp = compare_calibration(lens, cal, setup, label=f"measured ({cal_word})")
    if args.output:
        from ..report.jsonout import dumps

        data = (
            comparison_csv(cmp) if kind == "csv" else dumps({"comparison": comparison_to_dict(cmp)})
        )
        _write(args.output, data, args)
    _emit(args, format_comparison(cmp), {"comparison": comparison_to_dict(cmp)},
          comparison_csv(cmp), cmp.prediction.geometry.projection_centre)  # fmt: skip
    if args.plot:
        from ..plots.camera import plot_calibration_comparison

        save_plot(lambda: plot_calibration_comparison(cmp), args.plot, args)
    return 0


def _cmd_convert(args, cal_word: str) -> int:
    from distortion.camera import convert_camera_model, smallest_exact
    from distortion.camera.models import CameraModel
    from distortion.errors import DataError

    from ..report.camera import conversion_to_dict, format_conversion

    cal_path = calibration_path(cal_word)
    args._inputs = [p for p in (cal_path, args.camera) if p]
    check_output_path(args.output, args)
    _refuse_idle_flags(args)
    fmt = _calibration_format(args.output, args.format) if args.output else None
    (cal,) = _read_calibrations(args, cal_path)
    target = CONVERT_TARGETS.get(args.model, args.model)
    ps = cal.pixel_size_mm
    if ps is None and (args.sensor is not None or args.pitch is not None or args.camera):
        ps = _sensor(args, cal).pixel_size_mm
    if ps is not None and cal.pixel_size_mm is None:
        cal = CameraModel(cal.model, cal.params, cal.width, cal.height, ps)
    if args.model in ("colmap", "opencv", "metashape", "australis") and args.coefficients is None:
        try:  # the smallest model of the family that holds the calibration exactly
            exact = smallest_exact(cal, args.model).model
        except DataError:
            exact = target
        # a fisheye is of the opencv / colmap family, but --model opencv / colmap is the
        # perspective one (fisheye / colmap-fisheye name the others): refit then
        if "fisheye" not in exact.lower() or "fisheye" in target.lower():
            target = exact
    conv = convert_camera_model(cal, target, free=args.coefficients)
    if args.output:
        fmt = _calibration_out_format(args, conv.camera, "converts to", fmt)
        from distortion.camera import format_calibration

        _write(args.output, format_calibration(conv.camera, fmt), args)
    _emit(args, format_conversion(conv), {"conversion": conversion_to_dict(conv)})
    return 0


def _cmd_variation(args, word1: str, word2: str) -> int:
    from distortion.camera import calibrated_models_by_distance

    cal1, cal2 = calibration_path(word1), calibration_path(word2)
    args._inputs = [cal1, cal2]
    check_output_path(args.output, args)
    kind = _table_kind(args.output, "a table of models") if args.output else None
    at, objs = _variation_distances(args)
    c1, c2 = _read_calibrations(args, cal1, cal2)
    ps = c1.pixel_size_mm or c2.pixel_size_mm
    if args.sensor is not None or args.pitch is not None or args.camera:
        ps = _sensor(args, c1).pixel_size_mm
    if ps is None:
        raise CliError("give the sensor size (--sensor WxH mm) or --pitch UM: profiles are in mm")
    table = calibrated_models_by_distance(
        c1,
        at[0],
        c2,
        at[1],
        focal_length_mm=length(args.focal_length, "--focal-length"),
        focus=args.focus,
        object_distances=objs,
        method=args.method,
        g=args.g,
        pixel_size_mm=ps,
        name=f"{word1} and {word2}",
    )
    _model_table_out(args, table, kind)
    return 0


def _variation_distances(args) -> tuple[list[str], list[str]]:
    """The distances of ``camera variation`` (--calibrated-at S1,S2 and --object-distances,
    from the lens) and its other flags, checked before any file is read: each named by its
    flag."""
    if args.calibrated_at is None or args.focal_length is None or args.focus is None:
        raise CliError("variation needs --calibrated-at S1,S2, --focal-length F and --focus S")
    at = [s.strip() for s in str(args.calibrated_at).split(",") if s.strip()]
    if len(at) != 2:
        raise CliError("--calibrated-at: give the two focus distances S1,S2 of the calibrations")
    s1, s2 = (length(s, "--calibrated-at", allow_inf=True, positive=True) for s in at)
    if s1 == s2:
        raise CliError(
            f"--calibrated-at {args.calibrated_at}: the two calibrations are focused at the same "
            "distance; give two different ones (Brown's Eq. 4 interpolates between them)"
        )
    length(args.focal_length, "--focal-length", positive=True)
    length(args.focus, "--focus", allow_inf=True, positive=True)
    if args.object_distances is None:
        raise CliError("give --object-distances D1,D2,... (distances from the lens)")
    objs = _distances(args.object_distances)
    for d in objs:
        length(d, "--object-distances", allow_inf=True, positive=True)
    if args.method == "fraser-shortis" and args.g is None:
        raise CliError(
            "--method fraser-shortis needs --g G (g_ss' of Fraser & Shortis' Eq. 6, e.g. 0.45)"
        )
    if args.method == "brown" and args.g is not None:
        raise CliError(
            "--g is g_ss' of --method fraser-shortis (Eq. 6); Brown's Eq. 1 has none: give "
            "--method fraser-shortis, or drop --g"
        )
    return at, objs


#: the number of words of each form (the form's word and its inputs)
N_WORDS = {"lens": 1, "compare": 3, "convert": 2, "variation": 3}


def _check_words(form: str, words: list[str]) -> None:
    """The words of ``form``: its inputs, as many as its usage line names."""
    if len(words) == N_WORDS[form]:
        return
    if form == "lens":
        raise CliError(
            f"orthoscope camera takes one LENS (or: {', '.join(ACTIONS)} ...); got "
            + " ".join(words)
        )
    takes = USAGE[form].split(f"camera {form} ", 1)[1].split(" --", 1)[0]
    got = words[1:]
    said = f"got {len(got)}: {' '.join(got)}" if got else "got none"
    raise CliError(f"`camera {form}` takes {takes}; {said} (usage: {USAGE[form]})")


#: the --model words of ``camera convert`` that name a family's model to convert to
CONVERT_TARGETS = {"fisheye": "opencv_fisheye", "colmap": "colmap:FULL_OPENCV",
                   "colmap-fisheye": "colmap:OPENCV_FISHEYE"}  # fmt: skip


def _check_model(args, form: str) -> None:
    """--model and --coefficients of ``camera LENS`` / ``convert`` before any work: a model
    family or one model name, and a coefficient count that family takes (the words of
    distortion.camera: FAMILY_WORDS, COEFFICIENT_COUNTS, model_name)."""
    import difflib

    from distortion.camera.models import MODEL_NAMES, model_name
    from distortion.camera.traced import COEFFICIENT_COUNTS, FAMILY_WORDS
    from distortion.errors import DataError

    model = str(args.model).strip()
    family = FAMILY_WORDS.get(model.lower()) if form == "lens" else None
    if family is None and model not in CONVERT_TARGETS:
        try:
            model_name(model)
        except DataError:
            words = list(dict.fromkeys([*MODEL_WORDS, *MODEL_NAMES]))
            near = difflib.get_close_matches(model, words, n=3)
            hint = f"; did you mean {', '.join(near)}?" if near else ""
            raise CliError(
                f"--model {model}: not a camera model{hint} (a family: {', '.join(MODEL_WORDS)}; "
                f"or one model: {', '.join(MODEL_NAMES)})"
            ) from None
    n = args.coefficients
    if n is None:
        return
    *most, last = COEFFICIENT_COUNTS["opencv"]
    opencv = f"{', '.join(map(str, most))} or {last}"
    if form == "convert":
        if CONVERT_TARGETS.get(model, model) != "opencv" or n not in COEFFICIENT_COUNTS["opencv"]:
            raise CliError(
                f"--coefficients {n} does not apply to --model {model}: it fixes the number of "
                f"coefficients of --model opencv, {opencv}"
            )
        return
    if n not in COEFFICIENT_COUNTS.get(family, ()):
        fisheye = COEFFICIENT_COUNTS["opencv_fisheye"]
        raise CliError(
            f"--coefficients {n} does not apply to --model {model}: give {opencv} with --model "
            f"opencv, or {fisheye[0]} to {fisheye[-1]} with --model fisheye"
        )


def cmd_camera(args) -> int:
    """``orthoscope camera``: the form its first word names, its flags checked before any work
    (the flags of another form, conflicts, values; then the deprecation line of a deprecated
    spelling that passed); a refusal of the API in the flags' words (:func:`_api_words`)."""
    from raytrace.errors import OrthoscopeError

    words = list(args.words)
    form = _form_of_word(words[0])
    _check_words(form, words)
    _refuse_foreign_flags(args, form)
    if form in ("lens", "compare"):
        _check_object_flags(args)
    if form in ("lens", "convert"):
        _check_model(args, form)
    warn_deprecated(args)
    try:
        if form == "compare":
            return _cmd_compare(args, words[1], words[2])
        if form == "convert":
            return _cmd_convert(args, words[1])
        if form == "variation":
            return _cmd_variation(args, words[1], words[2])
        return _cmd_lens(args, words[0])
    except CliError:
        raise
    except OrthoscopeError as e:
        raise CliError(_api_words(str(e), args)) from e


# ------------------------------------------------------------------- the flags each form reads
#: the forms of the command: ``camera LENS`` and the actions
FORMS = ("lens", *ACTIONS)
#: each form as its messages name it
FORM_WORDS = {"lens": "`camera LENS`", **{a: f"`camera {a}`" for a in ACTIONS}}


@functools.cache
def form_flags(form: str) -> frozenset[str]:
    """The option strings the form ``form`` (one of :data:`FORMS`) reads: those
    :func:`_add_arguments` gives it, the list its help page shows (one list for the page and
    for :func:`_refuse_foreign_flags`)."""
    q = argparse.ArgumentParser(add_help=False)
    _add_arguments(q, form)
    return frozenset(o for a in q._actions for o in a.option_strings)


def _owners(flag: str) -> str:
    """The forms that read ``flag``, as the messages name them (`camera LENS` and `camera
    compare`)."""
    names = [FORM_WORDS[f] for f in FORMS if flag in form_flags(f)]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def _refuse_foreign_flags(args, form: str) -> None:
    """CliError naming each flag given (:func:`given_flags`) that ``form`` does not read, the
    form, and the forms it belongs to: the one parser of the command accepts every form's
    flags, and a flag the form does not read would otherwise be silently ignored."""
    given = given_flags(args)  # in the order given, each once
    foreign = [flag for flag in given if flag not in form_flags(form)]
    if not foreign:
        return
    where = FORM_WORDS[form]
    if len(foreign) == 1:
        flag = foreign[0]
        raise CliError(f"{flag} is not read by {where} (it is a flag of {_owners(flag)}); drop it")
    each = ", ".join(f"{flag} (a flag of {_owners(flag)})" for flag in foreign)
    raise CliError(f"{where} does not read {each}; drop them")


def _foreign_abbreviation(typed: str, flags, form: str) -> str:
    """The refusal of an abbreviation ``typed`` that starts only ``flags`` of other forms than
    ``form`` (:class:`_CameraParser`): what was typed, the flags it would be and their forms."""
    each = " or ".join(f"{f}, a flag of {_owners(f)}" for f in dict.fromkeys(flags))
    return f"{typed} is not a flag of {FORM_WORDS[form]} (it would be {each}); drop it"


_NOTED: dict[type, type] = {}


def _note_given(q: argparse.ArgumentParser) -> None:
    """Make every option of ``q`` but the help a :class:`~orthoscope.cli.common.Noted` one (the
    same action, of a subclass that notes it was given, :func:`given_flags`: given is told
    apart from absent even when the value given is the default, ``--model opencv``). Those that
    note themselves already (a deprecated spelling, the flag it spells) are left as they are."""
    for a in q._actions:
        if not a.option_strings or isinstance(a, (_CameraHelp, argparse._HelpAction, Noted)):
            continue
        cls = type(a)
        if cls not in _NOTED:
            _NOTED[cls] = type(f"Noted{cls.__name__}", (Noted, cls), {})
        a.__class__ = _NOTED[cls]


def _form_of_word(word: str) -> str:
    return word if word in ACTIONS else "lens"


class _CameraParser(Parser):
    """The command's one parser, aware of the form it parses: an abbreviated long flag
    (``--calib``) resolves among the flags of that form only (argparse would match every
    form's), and one that starts only flags of other forms is refused, naming what was typed
    and where those flags belong. The form is the first word, found before parsing
    (:meth:`_form_of`); ``-h``/``--help`` (:class:`_CameraHelp`) uses it too."""

    #: the form of the argv being parsed (None: not known, every form's flags)
    _form: str | None = None

    def parse_known_args(self, args=None, namespace=None):
        import sys

        tokens = list(sys.argv[1:] if args is None else args)
        self._form = self._form_of(tokens)
        try:
            return super().parse_known_args(tokens, namespace)
        finally:
            self._form = None

    def _form_of(self, tokens) -> str | None:
        """The form of ``tokens`` (the arguments after ``camera``): its first word, skipping
        the options and their values (an abbreviation counted by what it can stand for);
        None where that is not plain (an unknown option before the first word, or none)."""
        i = 0
        while i < len(tokens):
            tok = tokens[i]
            if tok == "--":
                return _form_of_word(tokens[i + 1]) if i + 1 < len(tokens) else None
            if not tok.startswith("-") or tok == "-" or self._negative_number_matcher.match(tok):
                return _form_of_word(tok)
            if tok.startswith("--"):
                if "=" in tok:  # --flag=value
                    i += 1
                    continue
                acts = [a for o, a in self._option_string_actions.items() if o.startswith(tok)]
                if tok in self._option_string_actions:
                    acts = [self._option_string_actions[tok]]
            else:  # -o FILE, -oFILE, -h
                a = self._option_string_actions.get(tok[:2])
                if a is None:
                    return None
                acts = [a] if len(tok) == 2 or a.nargs == 0 else []
                if not acts:  # the value attached
                    i += 1
                    continue
            values = {0 if a.nargs == 0 else 1 for a in acts}
            if len(values) != 1:
                return None
            i += 1 + values.pop()
        return None

    def _get_option_tuples(self, option_string):
        found = super()._get_option_tuples(option_string)
        form = self._form
        if form is None or not found:
            return found
        own = form_flags(form) | {"-h", "--help"}
        mine = [t for t in found if t[1] in own]
        if mine:
            return mine
        typed = option_string.split("=", 1)[0]
        message = _foreign_abbreviation(typed, [t[1] for t in found], form)
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


# ---------------------------------------------------------------------------------- the parser
#: the usage line of each form of the command: its help page's and its usage error's
USAGE = {
    "lens": "orthoscope camera LENS --sensor WxH --pixels CxR [--model M] [flags]",
    "compare": "orthoscope camera compare LENS CALIBRATION --sensor WxH [flags]",
    "convert": "orthoscope camera convert CALIBRATION --model M [-o FILE]",
    "variation": "orthoscope camera variation CAL1 CAL2 --calibrated-at S1,S2 --focal-length F "
    "--focus S --object-distances D1,D2,... --sensor WxH (or --pitch)",
}

CAL_HELP = (
    "A calibration file: OpenCV .yml/.yaml/.json, COLMAP cameras.txt, Metashape or PhotoScan "
    f".xml, Australis .aus; or a bundled example by name, {BUNDLED_CALIBRATIONS[1]} (also -1m, "
    "-5m: synthetic calibrations of the bundled Cooke triplet, not measurements). An existing "
    "file wins over a name."
)

#: the examples of each form (the general page shows them all; tests/test_docs.py runs them)
EXAMPLES = {
    "lens": [
        "orthoscope camera cooke-triplet-f4 --sensor 24x16 --pixels 3000x2000 --model colmap "
        "-o cameras.txt",
        "orthoscope camera topogon-like-pestrecov --sensor 200x200 --pixels 2000x2000 --model "
        "fisheye --grid 13x13",
        "orthoscope camera cooke-triplet-f4 --sensor 24x16 --pixels 1200x800 --focus 2m "
        "--object-distances 1m,2m,5m,inf --grid 13x9",
    ],
    "compare": [
        "orthoscope camera compare cooke-triplet-f4 cooke-triplet-f4-synthetic-2m --sensor 24x16 "
        "--focus 2m --object-distance 2m --plot compare.png",
    ],
    "convert": [
        "orthoscope camera convert cooke-triplet-f4-synthetic-2m --model metashape -o cooke.xml",
    ],
    "variation": [
        "orthoscope camera variation cooke-triplet-f4-synthetic-1m cooke-triplet-f4-synthetic-5m "
        "--calibrated-at 1m,5m --focal-length 50 --focus 2m --object-distances 1m,2m,5m "
        "--sensor 24x16",
    ],
}

DESCRIPTION = {
    "compare": (
        "A measured calibration against the prescription's prediction at the same focus and "
        "object distance: real chief rays of the lens traced onto the calibration's sensor, the "
        "calibration's own model fitted to them (the prediction), and the two compared - "
        "radial distortion profiles and the difference over the sensor in pixels. The sensor is "
        "the calibration's pixel count with --sensor or --pitch; the focus setting puts it in "
        "the Gaussian image plane of the focused object (default: focused on the object)."
    ),
    "convert": (
        "One camera model into another over the calibration's sensor: exact algebra where the "
        "target holds the model, otherwise a least-squares refit with its residual in pixels. "
        "--model names a family (the smallest model of it that holds the calibration exactly) "
        "or one model."
    ),
    "variation": (
        "Camera models per object distance from two measured calibrations of one lens at two "
        "focus distances: the radial distortion profile at each object distance for a lens "
        "focused at --focus, by Brown's Eqs. 1-4 or Fraser & Shortis' Eq. 6 (with g_ss')."
    ),
}

EXPLAIN = (
    "Real chief rays (through the centre of the real stop) traced onto a sensor give the "
    "correspondences ideal direction <-> image point that a camera model is fitted to by least "
    "squares, with its residual in pixels. The ideal direction is the object-space chief ray's "
    "(object at infinity) or the direction from the projection centre - the paraxial entrance "
    "pupil at the reference wavelength - to the object point; the image point is the chief ray's "
    "intercept with the sensor plane, in the sensor's pixels (OpenCV: pixel centres at integers). "
    "The focus setting puts the sensor in the Gaussian image plane of the focused object (unit "
    "focusing, at the reference wavelength); default: focused on the object. 'compare' fits the "
    "calibration's own model to the traced lens and compares distortion profiles and the "
    "difference over the sensor; 'convert' turns one model into another (exact algebra or a "
    "refit with its residual); 'variation' predicts models per object distance from two "
    "calibrations (Brown Eqs. 1-4; Fraser & Shortis Eq. 6)."
)


def _epilog(forms) -> str:
    lines = [f"  {e}" for form in forms for e in EXAMPLES[form]]
    return "Examples:\n" + "\n".join(lines)


class _CameraHelp(argparse.Action):
    """``-h``/``--help``: the help page of the form the command's first word names (``orthoscope
    camera compare --help`` and ``orthoscope camera --help compare`` print compare's), otherwise
    the command's general page."""

    def __init__(
        self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None
    ):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        words = getattr(namespace, "words", None) or []
        form = words[0] if words else getattr(parser, "_form", None)  # --help before the words
        if form in ACTIONS:
            parser = action_parser(form)
        parser.print_help()
        parser.exit()


def action_parser(action: str) -> argparse.ArgumentParser:
    """The help page of ``orthoscope camera ACTION`` (compare, convert, variation): its usage,
    what it does, the flags it reads and its examples. Only for the help: the command's one
    parser (:func:`register`) parses every form."""
    q = Parser(
        prog=f"orthoscope camera {action}",
        usage=USAGE[action],
        description=DESCRIPTION[action],
        epilog=_epilog([action]) + "\n\nRun 'orthoscope camera --help' for every form.",
        add_help=False,
    )
    q.add_argument("-h", "--help", action="help", help="Show this help and exit.")
    _add_arguments(q, action)
    return q


def _add_arguments(q: argparse.ArgumentParser, action: str | None) -> None:
    """The flags of ``orthoscope camera``: all of them (``action`` None, the parser), or those
    the form ``action`` (one of :data:`FORMS`) reads: its help page (the texts say them for that
    form) and the flags it accepts (:func:`form_flags`)."""

    def on(*forms: str) -> bool:
        return action is None or action in forms

    def say(general: str, **per_action: str) -> str:
        return per_action.get(action, general) if action else general

    if action is None:
        q.add_argument(
            "words",
            nargs="+",
            metavar="LENS",
            help="A lens (file or bundled name); or 'compare LENS CALIBRATION', 'convert "
            "CALIBRATION', 'variation CAL1 CAL2' (each with its own --help).",
        )
    elif action == "lens":
        q.add_argument("lens", metavar="LENS", help="A lens file or bundled lens name.")
    elif action == "compare":
        q.add_argument("lens", metavar="LENS", help="A lens file or bundled lens name.")
        q.add_argument("calibration", metavar="CALIBRATION", help=CAL_HELP)
    elif action == "convert":
        q.add_argument("calibration", metavar="CALIBRATION", help=CAL_HELP)
    else:
        q.add_argument("cal1", metavar="CAL1", help="The calibration focused at S1. " + CAL_HELP)
        q.add_argument("cal2", metavar="CAL2", help="The calibration focused at S2 (likewise).")
    g = q.add_argument_group(
        "sensor",
        say(
            "Two of --sensor, --pixels and --pitch (all three: checked); with a calibration its "
            "pixel count and one of --sensor / --pitch. --camera reads a TOML camera spec "
            "(docs/design.md, 'Camera models from a prescription'): sensor flags replace its "
            "sensor, the other flags what they name.",
            compare="The calibration gives the pixel count; give --sensor or --pitch (or "
            "--camera, a TOML camera spec whose sensor the sensor flags replace).",
            convert="The pixel size, where the calibration file does not hold it and the target "
            "model is in mm (Australis): --sensor or --pitch, or --camera SPEC.toml.",
            variation="The pixel size, where the calibration files do not hold it (the profiles "
            "are in mm): --sensor or --pitch, or --camera SPEC.toml.",
        ),
    )
    g.add_argument("--sensor", metavar="WxH", help="Sensor size in mm, e.g. 36x24.")
    if on("lens", "compare"):
        g.add_argument(
            "--pixels",
            metavar="CxR",
            help=say(
                "Pixel count, columns x rows, e.g. 6000x4000.",
                compare="Pixel count, columns x rows: checked against the calibration's.",
            ),
        )
    g.add_argument("--pitch", metavar="UM", help="Pixel pitch in micrometres (or '0.006mm').")
    if on("lens", "compare"):
        g.add_argument(
            "--principal-point",
            metavar="DX,DY",
            help="Where the lens axis meets the sensor, mm from its centre, x right, y up.",
        )
    g.add_argument("--camera", metavar="SPEC.toml", help="A TOML camera spec (sensor, focus...).")
    m = q.add_argument_group(say("model", compare="chief rays"))
    if on("lens", "convert"):
        m.add_argument(
            "--model",
            default="opencv",
            metavar="M",
            help=say(
                "opencv, fisheye (OpenCV fisheye / Kannala-Brandt), colmap, colmap-fisheye, "
                "metashape, australis - as many terms as the stated criterion needs - or one model "
                "name such as colmap:OPENCV.",
                convert="The target: opencv, fisheye (OpenCV fisheye / Kannala-Brandt), colmap, "
                "colmap-fisheye, metashape, australis - the smallest model of the family that "
                "holds the calibration exactly, else a refit - or one model name such as "
                "colmap:OPENCV.",
            ),
        )
        m.add_argument(
            "--coefficients",
            type=coefficient_count,
            metavar="N",
            help=say(
                "Fix the number of coefficients: OpenCV 4, 5, 8, 12 or 14; fisheye 1-4.",
                convert="--model opencv: fix the number of coefficients, 4, 5, 8, 12 or 14.",
            ),
        )
    if on("lens", "compare"):
        m.add_argument(
            "--grid",
            metavar="CxR",
            help="Chief rays over the sensor, columns x rows (default 25x17).",
        )
        m.add_argument(
            "--no-clip",
            action="store_true",
            help="Ignore the lens's semi-diameters (no vignetting).",
        )
        add_object_args(q)
        f = q.add_argument_group(
            "focus (give at most one; default: focused on the object)",
            "The focused object in the words of the object plane (--focus as --object-distance, "
            "--focus-s as --object-s, --focus-scale as --object-scale) - the sensor sits in its "
            "Gaussian image plane - or the sensor plane itself.",
        )
        f.add_argument(
            "--focus",
            metavar="D",
            help=say(
                "Focused object: mm from the first vertex (or 2m, inf, 12x). 'variation': the "
                "focus distance from the lens.",
                compare="Focused object: mm from the first vertex (or 2m, inf, 12x).",
            ),
        )
        f.add_argument("--focus-s", metavar="S", help="Focused object: Pestrecov's s (mm from H).")
        f.add_argument("--focus-scale", metavar="N", help="Focused object: image scale N (Nx).")
        f.add_argument("--s-prime", metavar="S'", help="Sensor plane: mm from H'.")
        f.add_argument(
            "--from-last-vertex", metavar="D", help="Sensor plane: mm from the last vertex."
        )
        f.add_argument(
            "--defocus", metavar="DZ", help="Sensor plane: mm from the object's Gaussian plane."
        )
        f.add_argument(
            "--gaussian", action="store_true", help="Focused on the object (the default)."
        )
        add_wavelength_arg(q)
    if on("lens"):
        t = q.add_argument_group("per object distance")
        t.add_argument(
            "--object-distances",
            metavar="D1,D2,...",
            help="A table of models, one per object distance (mm from the first vertex; 2m, inf, "
            "12x); 'variation': distances from the lens.",
        )
    if on("variation"):
        v = q.add_argument_group("variation (two measured calibrations)")
        if action == "variation":
            v.add_argument(
                "--focus",
                metavar="S",
                help="The focus distance of the predicted models, from the lens (mm, or 2m).",
            )
            v.add_argument(
                "--object-distances",
                metavar="D1,D2,...",
                help="The table's rows: object distances from the lens (mm, or 1m).",
            )
        v.add_argument(
            "--calibrated-at",
            metavar="S1,S2",
            help="Focus distances of the two calibrations, from the lens (mm, or 1m).",
        )
        v.add_argument("--focal-length", metavar="F", help="f of Brown's formulas (mm).")
        v.add_argument(
            "--method",
            choices=("brown", "fraser-shortis"),
            default="brown",
            help="Brown's Eq. 1, or Fraser & Shortis' Eq. 6 with --g.",
        )
        v.add_argument("--g", type=g_factor, metavar="G", help="g_ss' of Fraser & Shortis' Eq. 6.")
    o = q.add_argument_group("outputs")
    o.add_argument(
        "-o",
        "--output",
        metavar="FILE",
        help=say(
            "Calibration file (.yml/.yaml/.json OpenCV, cameras.txt COLMAP, .xml Metashape, "
            ".aus Australis); a table of models: .csv or .json; compare: .json or .csv.",
            compare="The comparison as .json or .csv.",
            convert="The converted calibration (.yml/.yaml/.json OpenCV, cameras.txt COLMAP, "
            ".xml Metashape, .aus Australis).",
            variation="The table of models as .csv or .json.",
        ),
    )
    if on("compare", "convert", "variation"):
        which = "the camera of a COLMAP cameras.txt that holds several (its CAMERA_ID)."
        o.add_argument(
            "--camera-id",
            type=camera_id,
            metavar="N",
            help=say(
                f"compare / convert / variation: {which}",
                **dict.fromkeys(ACTIONS, which[0].upper() + which[1:]),
            ),
        )
    if on("lens", "convert"):
        o.add_argument("--format", metavar="FMT", help="The calibration file format, when the "
                       "name does not say (opencv-yaml, opencv-json, colmap, metashape, photoscan, "
                       "australis).")  # fmt: skip
    if on("lens", "compare"):
        o.add_argument(
            "--plot",
            metavar="FILE",
            help=say(
                "A chart (.png/.svg/.pdf): the fit residual over the sensor; compare: radial "
                "curves beside the difference map.",
                compare="A chart (.png/.svg/.pdf): radial curves beside the difference map.",
            ),
        )
    if on("lens"):
        o.add_argument(
            "--picture",
            metavar="FILE.png",
            help="A grid of the ideal image as the lens records it, at true scale (needs OpenCV).",
        )
        o.add_argument("--pattern", choices=PATTERNS, default="grid", help="Pattern of --picture.")
        o.add_argument(
            "--maps",
            metavar="FILE.npz",
            help="cv2.remap maps (map1, map2 float32, camera_matrix) of the full image.",
        )
        o.add_argument(
            "--maps-direction",
            choices=("undistort", "distort"),
            default="undistort",
            help="undistort: the ideal image from the camera's; distort: the camera's from an "
            "ideal one.",
        )
    if on("lens", "compare"):
        add_strict_arg(
            o,
            help=say(
                "Exit with status 2 when a chief ray fails, when the lens file names a glass that "
                "can only be read as a substitute (an N- successor, a parent glass, a model of "
                "nd/vd), when a glass is evaluated outside its catalog data range (an nd/vd model "
                "glass outside 365-1014 nm), or when the sensor reaches beyond the lens's image "
                "circle (before anything is written).",
                compare="Exit with status 2 when the lens file names a glass that can only be "
                "read as a substitute (an N- successor, a parent glass, a model of nd/vd), or "
                "when a glass is evaluated outside its catalog data range (an nd/vd model glass "
                "outside 365-1014 nm).",
            ),
        )
    add_force_arg(q)
    if action == "convert":
        add_output_args(q, csv=False)
    else:
        add_output_args(
            q,
            csv_help=say(
                "Print CSV: the traced points with the residual, the table, or the radial "
                "profiles.",
                compare="Print CSV: the radial profiles.",
                variation="Print CSV: the table.",
            ),
        )


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "camera",
        help="Camera models (OpenCV, fisheye, COLMAP, Metashape, Australis) from a lens; "
        "compare, convert, vary with distance.",
        usage="\n       ".join(USAGE.values()),
        description=EXPLAIN,
        epilog=_epilog(EXAMPLES)
        + "\n\nRun 'orthoscope camera compare --help' (convert, variation) for the flags of each.",
        add_help=False,
    )
    q.__class__ = _CameraParser  # the parser of the subcommand, aware of the form it parses
    q.add_argument(
        "-h",
        "--help",
        action=_CameraHelp,
        help="Show this help and exit (with compare, convert or variation: that form's help).",
    )
    _add_arguments(q, None)
    _note_given(q)
    q.set_defaults(func=cmd_camera)
