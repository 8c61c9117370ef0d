"""The values of ``orthoscope camera``'s flags as the command reads them: the argparse types
(``--coefficients``, ``--camera-id``, ``--g``), ``--grid``, image scales, object distances and
the list of ``--object-distances``; each refusal names its flag."""

from __future__ import annotations

import argparse

from ..common import CliError, first_repeat, length


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


def parse_grid(text: str | None):
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


def parse_scale(value: str, flag: str) -> float:
    from raytrace.units import UnitError, image_scale

    try:
        return image_scale(str(value).strip(), flag)
    except UnitError as e:
        raise CliError(str(e)) from None


def check_object_distance(value: str, flag: str, signed: str | None = None) -> None:
    """An object distance as ``camera LENS`` reads it (mm from the first vertex, with a unit,
    ``inf`` or an image scale ``12x``): a CliError naming ``flag`` for anything else; ``signed``
    the flag of Pestrecov's signed s, the fix for a negative one."""
    t = str(value).strip().lower()
    if t in ("inf", "infinity"):
        return
    if t.endswith(("x", "\u00d7")):
        parse_scale(t, flag)
        return
    if not length(t, flag, allow_inf=True) > 0:
        fix = f"; for Pestrecov's signed s use {signed}" if signed else ""
        raise CliError(
            f"{flag} {value}: a positive distance in mm from the object plane to the first "
            f"vertex (or 2m, inf, 12x){fix}"
        )


def parse_distances(text: str) -> list[str]:
    """--object-distances D1,D2,...: each once, none empty (one row per distance)."""
    objs = [p.strip() for p in str(text).split(",")]
    if not objs or any(not p for p in objs):
        raise CliError(f"--object-distances {text!r}: an empty entry; write e.g. 1m,2m,5m")
    dup = first_repeat(objs)
    if dup is not None:
        raise CliError(f"--object-distances {text!r}: {dup} is listed twice")
    return objs
