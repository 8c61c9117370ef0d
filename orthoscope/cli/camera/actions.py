"""The four actions of ``orthoscope camera`` and their dispatch (:func:`cmd_camera`): the
form's words, flags and --model checked before any work, then the run."""

from __future__ import annotations

import math

from ..common import (
    CliError,
    check_output_path,
    check_plot_path,
    given_flags,
    length,
    load_recorded,
    save_plot,
    warn,
    warn_deprecated,
)
from .files import calibration_format, calibration_out_format, calibration_path, read_calibrations
from .forms import ACTIONS, MODEL_WORDS, USAGE, form_of_word, refuse_foreign_flags
from .output import (
    emit,
    model_table_out,
    npz_bytes,
    png_bytes,
    refuse_idle_flags,
    table_kind,
    write_output,
)
from .setup import (
    FOCUS_KEYS,
    api_words,
    check_object_flags,
    sensor_from_flags,
    setup_from_flags,
    spec_and_sensor,
)
from .values import check_object_distance, parse_distances

#: the flags of ``camera LENS`` that only its one-distance run reads (not the table of models of
#: --object-distances)
ONE_DISTANCE_ONLY = ("--plot", "--picture", "--maps", "--maps-direction", "--pattern", "--format",
                     "--strict")  # fmt: skip


def _cmd_lens(args, lens_name: str) -> int:
    from distortion.camera import (
        camera_model,
        distortion_picture,
        remap_maps,
        traced_models_by_distance,
    )
    from distortion.errors import DataError

    from ...report.camera import (
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
    spec, sensor = spec_and_sensor(args)
    setup = setup_from_flags(args, sensor, spec)
    n = args.coefficients
    if args.object_distances is not None:
        unread = [f for f in given_flags(args) if f in ONE_DISTANCE_ONLY]
        if unread:
            raise CliError(
                f"with --object-distances the command writes the table of models per distance "
                f"only: {', '.join(unread)} {'is' if len(unread) == 1 else 'are'} read for one "
                f"object distance (--object-distance); drop {'it' if len(unread) == 1 else 'them'}"
            )
        kind = table_kind(args.output, "a table of models") if args.output else None
        objs = parse_distances(args.object_distances)
        for d in objs:
            check_object_distance(d, "--object-distances")
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
        model_table_out(args, table, kind, setup.resolve(lens).projection_centre)
        return 0
    refuse_idle_flags(args)
    fmt = calibration_format(args.output, args.format) if args.output else None
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
        fmt = calibration_out_format(args, tc.camera, "fits", fmt)
        write_output(args.output, tc.calibration_text(fmt), args)
    emit(args, format_traced_camera(tc), traced_camera_to_dict(tc), points_csv(tc),
          tc.geometry.projection_centre)  # fmt: skip
    if args.plot:
        from ...plots.camera import plot_camera_residuals

        save_plot(lambda: plot_camera_residuals(tc), args.plot, args)
    if args.picture:
        pic = distortion_picture(tc.camera, args.pattern)
        write_output(args.picture, png_bytes(pic.image), args)
    if args.maps:
        maps = remap_maps(tc.camera, args.maps_direction)
        write_output(args.maps, npz_bytes(maps), args)
    return 0


def _cmd_compare(args, lens_name: str, cal_word: str) -> int:
    from distortion.camera import compare_calibration

    from ...report.camera import comparison_csv, comparison_to_dict, format_comparison

    cal_path = calibration_path(cal_word)
    lens = load_recorded(args, lens_name, cal_path, args.camera)
    check_plot_path(args.plot, "--plot", args)
    check_output_path(args.output, args)
    kind = table_kind(args.output, "a comparison") if args.output else None  # before the trace
    (cal,) = read_calibrations(args, cal_path)
    spec, sensor = spec_and_sensor(args, cal)
    setup = setup_from_flags(args, sensor, spec)
    cmp = compare_calibration(lens, cal, setup, label=f"measured ({cal_word})")
    if args.output:
        from ...report.jsonout import dumps

        data = (
            comparison_csv(cmp) if kind == "csv" else dumps({"comparison": comparison_to_dict(cmp)})
        )
        write_output(args.output, data, args)
    emit(args, format_comparison(cmp), {"comparison": comparison_to_dict(cmp)},
          comparison_csv(cmp), cmp.prediction.geometry.projection_centre)  # fmt: skip
    if args.plot:
        from ...plots.camera import plot_calibration_comparison

        save_plot(lambda: plot_calibration_comparison(cmp), args.plot, args)
    return 0


def _cmd_convert(args, cal_word: str) -> int:
    from distortion.camera import convert_camera_model, smallest_exact
    from distortion.camera.models import CameraModel
    from distortion.errors import DataError

    from ...report.camera import conversion_to_dict, format_conversion

    cal_path = calibration_path(cal_word)
    args._inputs = [p for p in (cal_path, args.camera) if p]
    check_output_path(args.output, args)
    refuse_idle_flags(args)
    fmt = calibration_format(args.output, args.format) if args.output else None
    (cal,) = read_calibrations(args, cal_path)
    target = CONVERT_TARGETS.get(args.model, args.model)
    ps = cal.pixel_size_mm
    if ps is None and (args.sensor is not None or args.pitch is not None or args.camera):
        ps = sensor_from_flags(args, cal).pixel_size_mm
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
        fmt = calibration_out_format(args, conv.camera, "converts to", fmt)
        from distortion.camera import format_calibration

        write_output(args.output, format_calibration(conv.camera, fmt), args)
    emit(args, format_conversion(conv), {"conversion": conversion_to_dict(conv)})
    return 0


def _cmd_variation(args, word1: str, word2: str) -> int:
    from distortion.camera import calibrated_models_by_distance

    cal1, cal2 = calibration_path(word1), calibration_path(word2)
    args._inputs = [cal1, cal2]
    check_output_path(args.output, args)
    kind = table_kind(args.output, "a table of models") if args.output else None
    at, objs = _variation_distances(args)
    c1, c2 = read_calibrations(args, cal1, cal2)
    ps = c1.pixel_size_mm or c2.pixel_size_mm
    if args.sensor is not None or args.pitch is not None or args.camera:
        ps = sensor_from_flags(args, c1).pixel_size_mm
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
    model_table_out(args, table, kind)
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
    objs = parse_distances(args.object_distances)
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
    spelling that passed); a refusal of the API in the flags' words (:func:`api_words`)."""
    from raytrace.errors import OrthoscopeError

    words = list(args.words)
    form = form_of_word(words[0])
    _check_words(form, words)
    refuse_foreign_flags(args, form)
    if form in ("lens", "compare"):
        check_object_flags(args)
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
        raise CliError(api_words(str(e), args)) from e
