"""The forms of ``orthoscope camera`` (``camera LENS`` and the actions compare, convert,
variation) and the flags each reads: their usage lines, the flags with their help texts
(:func:`add_arguments`, one list for the help pages and the parser), and the refusal of a flag
that the form given does not read."""

from __future__ import annotations

import argparse
import functools

from ..common import (
    CliError,
    add_force_arg,
    add_object_args,
    add_output_args,
    add_strict_arg,
    add_wavelength_arg,
    given_flags,
)
from .files import BUNDLED_CALIBRATIONS
from .values import camera_id, coefficient_count, g_factor

ACTIONS = ("compare", "convert", "variation")
MODEL_WORDS = ("opencv", "fisheye", "colmap", "colmap-fisheye", "metashape", "australis")
PATTERNS = ("grid", "checkerboard")


#: the forms of the command: ``camera LENS`` and the actions
FORMS = ("lens", *ACTIONS)
#: each form as its messages name it
FORM_WORDS = {"lens": "`camera LENS`", **{a: f"`camera {a}`" for a in ACTIONS}}


@functools.cache
def form_flags(form: str) -> frozenset[str]:
    """The option strings the form ``form`` (one of :data:`FORMS`) reads: those
    :func:`add_arguments` gives it, the list its help page shows (one list for the page and
    for :func:`refuse_foreign_flags`)."""
    q = argparse.ArgumentParser(add_help=False)
    add_arguments(q, form)
    return frozenset(o for a in q._actions for o in a.option_strings)


def _owners(flag: str) -> str:
    """The forms that read ``flag``, as the messages name them (`camera LENS` and `camera
    compare`)."""
    names = [FORM_WORDS[f] for f in FORMS if flag in form_flags(f)]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def refuse_foreign_flags(args, form: str) -> None:
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


def foreign_abbreviation(typed: str, flags, form: str) -> str:
    """The refusal of an abbreviation ``typed`` that starts only ``flags`` of other forms than
    ``form`` (:class:`.parser._CameraParser`): what was typed, the flags it would be and their
    forms."""
    each = " or ".join(f"{f}, a flag of {_owners(f)}" for f in dict.fromkeys(flags))
    return f"{typed} is not a flag of {FORM_WORDS[form]} (it would be {each}); drop it"


def form_of_word(word: str) -> str:
    return word if word in ACTIONS else "lens"


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


def add_arguments(q: argparse.ArgumentParser, action: str | None) -> None:
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
