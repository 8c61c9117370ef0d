"""The sensor and the camera setup of ``orthoscope camera`` from its flags (``--camera``
SPEC.toml, the sensor flags, the object and focus flags): the object and focus flags checked
before any work, and the refusals of :mod:`distortion.camera` in the flags' words."""

from __future__ import annotations

from ..common import CliError, as_typed, given_flags, length, object_flags_given
from .values import check_object_distance, parse_grid, parse_scale

#: the focus keywords of CameraSetup (the focused object, or the sensor plane), each a flag
FOCUS_KEYS = ("focus", "focus_s", "focus_scale", "s_prime", "from_last_vertex", "defocus")


def check_object_flags(args) -> None:
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
            check_object_distance(value, flag, signed)
    for flag, value in ((s_flag, args.object_s), ("--focus-s", args.focus_s)):
        if value is not None and not length(value, flag) < 0:
            raise CliError(
                f"{flag} {value}: Pestrecov's s is negative for a real object (mm from H, left "
                "of it), e.g. -2000 or -2m"
            )
    for flag, value in (("--object-scale", args.object_scale), ("--focus-scale", args.focus_scale)):
        if value is not None:
            parse_scale(value, flag)
    for flag in ("--s-prime", "--from-last-vertex", "--defocus"):
        value = getattr(args, flag[2:].replace("-", "_"))
        if value is not None:
            length(value, flag)


#: the API's keywords of CameraSetup and the flags that give them (its messages in the
#: command line's words, :func:`api_words`)
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


def api_words(message: str, args) -> str:
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
        "grid": parse_grid(args.grid),
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


def sensor_from_flags(args, calibration=None):
    """The Sensor from --camera / --sensor / --pixels / --pitch / --principal-point (a
    calibration's pixel count when one is given); its refusals in the flags' words."""
    return spec_and_sensor(args, calibration)[1]


def spec_and_sensor(args, calibration=None):
    """``(spec, sensor)``: the --camera SPEC.toml read and parsed once (None without --camera),
    for :func:`setup_from_flags` too, and :func:`sensor_from_flags`'s Sensor; the refusals of
    both (the spec's first) in the flags' words."""
    from distortion.camera import read_camera_setup
    from distortion.errors import DataError

    try:
        spec = read_camera_setup(args.camera) if args.camera else None
        return spec, _sensor_of(args, calibration, spec)
    except DataError as e:
        raise CliError(_sensor_words(str(e), args, calibration)) from e


def _sensor_of(args, calibration, spec):
    from distortion.camera import Sensor
    from distortion.camera.traced import sensor_for_calibration

    base = spec.sensor if spec is not None else None
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


def setup_from_flags(args, sensor, spec):
    """The CameraSetup of the flags on ``sensor``: the --camera spec ``spec`` as read by
    :func:`spec_and_sensor` (None without --camera) with the flags' keywords replacing its own."""
    from distortion.camera import CameraSetup

    kw = _setup_keywords(args)
    if spec is not None:
        if getattr(args, "gaussian", False):  # replaces the spec's focus, as --defocus does
            spec = spec.replace(**dict.fromkeys(FOCUS_KEYS))
        return spec.replace(sensor=sensor, **kw)
    return CameraSetup(sensor, **kw)
