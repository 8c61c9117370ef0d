"""The calibration files of ``orthoscope camera``: an input given as a path or a bundled name,
read with its format (--camera-id for a COLMAP cameras.txt), and the format of the calibration
file ``-o``."""

from __future__ import annotations

from ..common import CliError, bundled_or_path, given_flags

#: the calibrations bundled with the lens library (lenses/calibrations/NAME.yml): synthetic
#: examples for compare / convert / variation that work from any folder
BUNDLED_CALIBRATIONS = (
    "cooke-triplet-f4-synthetic-1m",
    "cooke-triplet-f4-synthetic-2m",
    "cooke-triplet-f4-synthetic-5m",
)


def calibration_path(word: str) -> str:
    """A CALIBRATION as given, or the bundled calibration of that name
    (``lenses/calibrations/NAME.yml``; :func:`~orthoscope.cli.common.bundled_or_path`)."""
    return bundled_or_path(word, "calibrations", ".yml")


#: the names that tell a calibration file's format (distortion.camera.files.detect_format)
CALIBRATION_NAMES = (
    ".yml, .yaml or .json (OpenCV), .txt (COLMAP cameras.txt), .xml (Metashape) or .aus (Australis)"
)


def calibration_format(path: str, fmt: str | None) -> str:
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


def read_calibrations(args, *paths):
    """The calibrations at ``paths`` (--camera-id choosing a camera of a COLMAP cameras.txt);
    a CliError for --camera-id given where none of them is a COLMAP file (it would do
    nothing). Each file is read once: the text :func:`_input_format` reads to tell the format
    is the text parsed."""
    from distortion.camera import read_calibration

    read = [_input_format(p) for p in paths]
    fmts = [f for f, _ in read]
    if "--camera-id" in given_flags(args) and "colmap" not in fmts:
        what = " and ".join(f"{p} is {f}" for p, f in zip(paths, fmts, strict=True))
        raise CliError(
            f"--camera-id chooses a camera of a COLMAP cameras.txt, and {what}: drop --camera-id"
        )
    return [
        read_calibration(p, camera_id=args.camera_id if f == "colmap" else None, text=text)
        for p, (f, text) in zip(paths, read, strict=True)
    ]


def _input_format(path: str) -> tuple[str, str]:
    """The format of the calibration file ``path`` as read_calibration tells it (its name,
    and the text of a .txt / .xml), and its text; a CliError for a name that tells none (no
    flag gives the format of an input), a DataError for a file that cannot be read as text."""
    from distortion.camera.files import detect_format
    from distortion.errors import DataError, read_text

    try:
        detect_format(path)
    except DataError:
        raise CliError(
            f"{path}: the name does not tell the calibration format; a calibration file ends "
            f"in {CALIBRATION_NAMES}"
        ) from None
    text = read_text(path, "a calibration file")
    return detect_format(path, text), text


#: the file names of each model family's calibration files (for the messages)
FAMILY_FILES = {
    "opencv": ".yml, .yaml or .json",
    "colmap": "cameras.txt",
    "metashape": ".xml",
    "australis": ".aus",
}


def calibration_out_format(args, camera, verb: str, fmt: str) -> str:
    """``fmt``, the format of the calibration file ``-o`` (:func:`calibration_format`, found
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
