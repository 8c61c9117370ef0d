"""The image sensor: its size in mm, its pixels, and where the principal point lies on it.

Pixel coordinates follow :mod:`distortion.camera.conventions` (OpenCV pixels are the common frame;
COLMAP and Metashape at +0.5; photogrammetric mm with y up, origin at the sensor centre).
"""

from __future__ import annotations

import math
import os
import re
import sys
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from raytrace.units import number_problem

from ..errors import DataError, UnitWarning
from .conventions import (
    from_opencv_pixels,
    image_centre,
    opencv_pixels_to_photo_mm,
    photo_mm_to_opencv_pixels,
    pixel_centre_offset,
    to_opencv_pixels,
)

#: plausible pixel pitches (µm): phone sensors have ~0.56 µm pixels, scientific CCDs up to
#: ~30 µm, X-ray flat panels 75..200 µm (Varex 4343: 139 µm; PerkinElmer XRD1621: 200 µm), film
#: scanned at 200 dpi 127 µm. A pitch in mm given for µm (6 µm as 6 mm: 6000 µm) lies above.
PITCH_RANGE_UM = (0.3, 1000.0)
#: plausible sensor sides (mm): from a chip-on-tip endoscope sensor (OmniVision OV6948:
#: 200 px of 1.75 µm, 0.35 mm) to ~0.5 m; 36 mm given in metres (0.036) lies below.
SIZE_RANGE_MM = (0.1, 1000.0)
MAX_PIXELS = 1_000_000
#: a pixel pitch (mm) above which :func:`check_pixel_size_mm` also checks the sensor it makes
#: with the image's pixel count (the upper bound of the pitch range before X-ray panels)
LARGE_PITCH_MM = 0.1
#: the principal distance above which a warning asks whether it is in µm, as a multiple of the
#: sensor's largest radius from the principal point: 1000 is a field half-angle of 0.057°. A
#: 50 mm lens given in µm (50000) on a full-frame sensor (half-diagonal 21.6 mm) is 2311, a
#: 4.3 mm phone lens given in µm on a 7.7 mm-diagonal sensor 1117; camera lenses stay far below
#: (2000 mm on APS-C, half-diagonal 14.2 mm: 141), but telescopes do not (an ASI224, radius
#: 3.05 mm, on a C14 at 3910 mm: 1280; at 7000 mm: 2292), so a larger one is warned of, not
#: refused.
MAX_PRINCIPAL_DISTANCE_RATIO = 1000.0
#: a principal-point offset read as µm is suggested only beyond this many sensor half-diagonals
#: (a shift, rise or crop puts it off the sensor by less)
OFFSET_SLIP_RATIO = 10.0

_PAIR = re.compile(r"^\s*([^x×*,]+?)\s*(?:[x×*,]\s*([^x×*,]+?))?\s*$", re.IGNORECASE)
_NUM_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-zA-Zµμ]*)\s*$")
_UM = {
    "": 1.0,
    "um": 1.0,
    "µm": 1.0,
    "μm": 1.0,
    "micron": 1.0,
    "microns": 1.0,
    "mm": 1000.0,
    "nm": 1e-3,
}
_MM = {"": 1.0, "mm": 1.0, "cm": 10.0, "m": 1000.0, "um": 1e-3, "µm": 1e-3, "μm": 1e-3}


def _caller_level() -> int:
    """``stacklevel`` for a warning issued by the function that calls this one: the first frame
    outside :mod:`distortion.camera` (a dataclass's generated ``__init__`` counts as inside),
    so the warning names the user's line and not :meth:`Sensor.from_spec`'s."""
    here = os.path.dirname(os.path.abspath(__file__))
    f, level = sys._getframe(1), 1
    while f is not None:
        name = f.f_code.co_filename
        if not (name.startswith("<") or os.path.dirname(os.path.abspath(name)) == here):
            break
        f, level = f.f_back, level + 1
    return level


def unit_slip(value: float, lo: float, hi: float, factor: float = 1000.0) -> float | None:
    """The value a slip of one unit step would have meant, when ``value`` lies outside
    [lo, hi]: ``value * factor`` when it lies below (metres for mm, mm for µm), ``value /
    factor`` when above (µm for mm, nm for µm) — if that lies inside; None otherwise (and for a
    value inside the range). The one rule behind the "looks like the wrong unit" refusals of
    this module: the pitch (:func:`parse_pitch_um`, :func:`check_pixel_size_mm`), the size
    (:func:`parse_size_mm`) and the principal distance (:func:`check_principal_distance_mm`)."""
    if value < lo:
        alt = value * factor
    elif value > hi:
        alt = value / factor
    else:
        return None
    return alt if lo <= alt <= hi else None


def size_problem(value_mm: float) -> str | None:
    """Why a sensor side of ``value_mm`` is refused (outside :data:`SIZE_RANGE_MM`, with the unit
    it looks like: metres below, µm above), or None."""
    lo, hi = SIZE_RANGE_MM
    if lo <= value_mm <= hi:
        return None
    why = f"{value_mm:g} mm is outside {lo:g}..{hi:g} mm"
    alt = unit_slip(value_mm, lo, hi)
    if alt is not None:
        unit = "metres" if value_mm < lo else "micrometres"
        sym = "m" if value_mm < lo else "µm"
        why += f"; {unit}? {value_mm:g} {sym} = {alt:g} mm"
    return why + "; sizes are in mm (a full-frame sensor is 36x24)"


def _numbers(values, what: str, fix: str, given=None) -> tuple[float, ...]:
    """The items of the sequence ``values`` as floats: numbers, numpy scalars or numeric
    strings, as ``float()`` reads them. The one conversion of this module's number pairs;
    ``given`` is the value as the caller got it, for the message (default ``values``).

    Raises
    ------
    DataError
        ``values`` is no sequence, or an item is a bool, a complex number or no number
        (:func:`raytrace.units.number_problem`): ``"{what} (36j, 24): {fix} (36j is a complex
        number)"``.
    """
    shown = repr(values if given is None else given)
    try:
        items = tuple(values)
    except TypeError:
        items = None
    if items is None or isinstance(values, str | bytes):
        raise DataError(f"{what} {shown}: {fix}")
    for v in items:
        why = number_problem(v)
        if why is not None:
            raise DataError(f"{what} {shown}: {fix} ({v!r} is {why})")
    return tuple(float(v) for v in items)


def _pair_text(value) -> str:
    """``(6, 6)`` of a sequence of numbers, else its repr (for the messages)."""
    if isinstance(value, str | bytes):
        return repr(value)
    try:
        vals = [float(v) for v in value]
    except (TypeError, ValueError):
        return repr(value)
    return "(" + ", ".join(f"{v:g}" for v in vals) + ")"


def check_pixel_size_mm(pixel_size_mm, head: str = "", pixels=None) -> tuple[float, float]:
    """``(pitch_x, pitch_y)`` in mm, checked as :meth:`Sensor.from_spec` checks a pixel pitch:
    two positive finite numbers within :data:`PITCH_RANGE_UM` (0.0003..1 mm); one above that
    reads as micrometres given for mm, one below as metres (the message says which and gives
    the pair in mm). With ``pixels`` (columns, rows), a pitch above :data:`LARGE_PITCH_MM`
    (X-ray panels, scanned film) must make with them a sensor within the upper bound of
    :data:`SIZE_RANGE_MM` (1000 mm), as a :class:`Sensor`'s size must: a sub-µm phone pitch
    given in µm (0.56 for 0.56 µm) passes the pitch range but makes a sensor of metres (16320
    columns: 9139 mm). ``head`` is put before the message (e.g. ``"camera model opencv: "``).

    Raises
    ------
    DataError
        ``pixel_size_mm=(6, 6): a pixel pitch of 6 mm is above 1 mm; micrometres? give
        (0.006, 0.006) mm``.
    """
    label = f"{head}pixel_size_mm={_pair_text(pixel_size_mm)}"
    try:  # a bool or a complex number is no pitch either
        vals = _numbers(pixel_size_mm, "pixel_size_mm", "")
    except DataError:
        vals = ()
    if (
        isinstance(pixel_size_mm, str)
        or len(vals) != 2
        or not all(math.isfinite(v) and v > 0 for v in vals)
    ):
        raise DataError(
            f"{label}: give (pitch_x, pitch_y) in mm, two positive numbers, e.g. (0.006, 0.006)"
        )
    lo, hi = (v / 1000.0 for v in PITCH_RANGE_UM)
    for v in vals:
        if lo <= v <= hi:
            continue
        side = f"above {hi:g} mm" if v > hi else f"below {lo:g} mm"
        # the pair as meant: each value out of range moved by the same unit step
        fixed = [w if lo <= w <= hi else unit_slip(w, lo, hi) for w in vals]
        if None not in fixed and all((w > hi) == (v > hi) for w in vals if not lo <= w <= hi):
            unit = "micrometres" if v > hi else "metres"
            fix = f"{unit}? give ({fixed[0]:g}, {fixed[1]:g}) mm"
        else:
            fix = "give the pitch in mm, e.g. (0.006, 0.006)"
        raise DataError(f"{label}: a pixel pitch of {v:g} mm is {side}; {fix}")
    if pixels is not None and max(vals) > LARGE_PITCH_MM:
        cols, rows = pixels
        w, h = cols * vals[0], rows * vals[1]
        top = SIZE_RANGE_MM[1]
        if max(w, h) > top:
            fix = "check the pitch (mm) and the image size (pixels)"
            if all(v / 1000.0 >= lo for v in vals):
                fix = f"micrometres? give ({vals[0] / 1000.0:g}, {vals[1] / 1000.0:g}) mm"
            raise DataError(
                f"{label}: {cols}x{rows} pixels of that pitch make a {w:.4g}x{h:.4g} mm sensor, "
                f"larger than {top:g} mm; {fix}"
            )
    return vals[0], vals[1]


def check_principal_distance_mm(
    principal_distance_mm, largest_radius_mm: float, what: str = "principal distance:"
) -> float:
    """The principal distance c (mm), checked against the largest image radius it serves: a
    positive finite number, and a field angle atan(r / c) that a camera has — at most
    atan(:data:`distortion.coefficients.MAX_RADIUS_RATIO`) = 87° (the bound of
    :func:`distortion.coefficients.opencv_model`: c in metres, or a pitch in mm for µm, gives
    more; refused). ``what`` names the value (``"principal_distance_mm=0.05:"`` names the
    keyword).

    A c of more than :data:`MAX_PRINCIPAL_DISTANCE_RATIO` × r (a field angle below 0.057°) is
    taken, with a :class:`~distortion.errors.UnitWarning`: a lens given in µm lands there, and
    so does a telescope (3910 mm on a 3.05 mm radius is 1280 × r).

    Raises
    ------
    DataError
        Naming ``what``, the ratio and field angle, and the unit the value looks like.

    Warns
    -----
    UnitWarning
        c above :data:`MAX_PRINCIPAL_DISTANCE_RATIO` × r, naming the µm reading where it fits.
    """
    from ..coefficients import MAX_RADIUS_RATIO  # not at import: coefficients imports models

    try:
        c = float(principal_distance_mm)
    except (TypeError, ValueError):
        c = math.nan
    if number_problem(principal_distance_mm) or not (math.isfinite(c) and c > 0):
        raise DataError(f"{what} give the principal distance c in mm, a positive number (e.g. 50)")
    r = float(largest_radius_mm)
    lo, hi = r / MAX_RADIUS_RATIO, r * MAX_PRINCIPAL_DISTANCE_RATIO  # c in mm
    angle = f"(a field angle of {math.degrees(math.atan(r / c)):.4g}°)"
    alt = unit_slip(c, lo, hi)
    if c < lo:
        fix = (
            f"metres? {c:g} m = {alt:g} mm; give c in mm"
            if alt is not None
            else "is it in the wrong unit (metres for mm, or a pixel pitch in mm for µm)?"
        )
        raise DataError(
            f"{what} {c:g} mm is {r / c:.3g} times smaller than the sensor's largest radius "
            f"{r:.3g} mm {angle}: {fix}"
        )
    if c > hi:
        fix = (
            f"micrometres? {c:g} µm = {alt:g} mm" if alt is not None else "is it in the wrong unit?"
        )
        warnings.warn(
            UnitWarning(
                f"{what} {c:g} mm is {c / r:.4g} times the sensor's largest radius {r:.3g} mm "
                f"{angle}, more than {MAX_PRINCIPAL_DISTANCE_RATIO:g} times; taken as {c:g} mm "
                f"(a telescope can be that long): {fix}"
            ),
            stacklevel=_caller_level(),
        )
    return c


def _split_pair(text: str, what: str, example: str) -> tuple[str, str | None]:
    m = _PAIR.match(text)
    if not m:
        raise DataError(f"{what} {text!r}: not understood; write it as {example}")
    return m.group(1), m.group(2)


def _number(text: str, what: str, units: dict[str, float], default_unit: str) -> tuple[float, bool]:
    """(value in the default unit, True when a unit was written)."""
    m = _NUM_UNIT.match(text)
    if not m:
        raise DataError(f"{what} {text!r}: not a number")
    unit = m.group(2)
    if unit.lower() not in units and unit not in units:
        raise DataError(
            f"{what} {text!r}: unknown unit {unit!r}; use {', '.join(u for u in units if u)} "
            f"(a bare number is {default_unit})"
        )
    scale = units.get(unit, units.get(unit.lower()))
    return float(m.group(1)) * scale, bool(unit)


def parse_size_mm(size: str | Sequence[float]) -> tuple[float, float]:
    """``"36x24"``, ``"36 x 24 mm"``, ``"23.5×15.6"`` or ``(36, 24)`` → (width, height) in mm."""
    if isinstance(size, str):
        a, b = _split_pair(size, "sensor size", "'36x24' (mm)")
        if b is None:
            raise DataError(f"sensor size {size!r}: give width and height, e.g. '36x24' (mm)")
        h, _ = _number(b, "sensor height", _MM, "mm")
        mb, ma = _NUM_UNIT.match(b), _NUM_UNIT.match(a)
        if ma and mb and not ma.group(2) and mb.group(2):
            a = a + mb.group(2)  # '36x24mm': the unit written once applies to both
        w, _ = _number(a, "sensor width", _MM, "mm")
    else:
        vals = _numbers(size, "sensor size", "give (width, height) in mm")
        if len(vals) != 2:
            raise DataError(f"sensor size {size!r}: give (width, height) in mm")
        w, h = vals
    if not (math.isfinite(w) and math.isfinite(h) and w > 0 and h > 0):
        label = size.strip() if isinstance(size, str) else f"{w:g}x{h:g}"
        raise DataError(f"sensor {label}: width and height must be positive (mm)")
    for side, v in (("width", w), ("height", h)):
        why = size_problem(v)
        if why is not None:
            label = repr(size.strip()) if isinstance(size, str) else f"({w:g}, {h:g})"
            raise DataError(f"sensor size {label}: the {side} {why}")
    return w, h


def parse_pixels(pixels: str | Sequence[int]) -> tuple[int, int]:
    """``"6000x4000"`` or ``(6000, 4000)`` → (columns, rows)."""
    if isinstance(pixels, str):
        a, b = _split_pair(pixels.lower().replace("px", ""), "pixel count", "'6000x4000'")
        if b is None:
            raise DataError(f"pixel count {pixels!r}: give columns and rows, e.g. '6000x4000'")
        vals = (a.strip(), b.strip())
        try:
            fv = (float(vals[0]), float(vals[1]))
        except ValueError:
            raise DataError(f"pixel count {pixels!r}: not two numbers; e.g. '6000x4000'") from None
    else:
        fv = _numbers(pixels, "pixel count", "give (columns, rows)")
        if len(fv) != 2:
            raise DataError(f"pixel count {pixels!r}: give (columns, rows)")
    for v in fv:
        if not (math.isfinite(v) and v == int(v)):
            raise DataError(f"pixel count {pixels!r}: pixel counts are whole numbers")
    return int(fv[0]), int(fv[1])


def parse_pitch_um(pitch: str | float | Sequence[float]) -> tuple[float, float]:
    """Pixel pitch → (x, y) in µm. A bare number is µm; ``"6um"``, ``"0.006mm"``, ``"6x6.2"``
    and ``(6, 6.2)`` are accepted. A bare number below 0.3 that would be a plausible pitch in
    mm is refused with that hint (``0.006`` is 6 nm, not 6 µm)."""
    if isinstance(pitch, str):
        a, b = _split_pair(pitch, "pixel pitch", "'6' (µm) or '6x6' or '0.006mm'")
        px, ux = _number(a, "pixel pitch", _UM, "µm")
        py, uy = _number(b, "pixel pitch", _UM, "µm") if b is not None else (px, ux)
        explicit = ux or uy
        vals = (px, py)
    elif np.ndim(pitch) == 0 and not isinstance(pitch, bytes):  # one number
        vals, explicit = (
            _numbers((pitch, pitch), "pixel pitch", "give one value or (x, y) in µm", pitch),
            False,
        )
    else:
        vals = _numbers(pitch, "pixel pitch", "give one value or (x, y) in µm")
        if len(vals) != 2:
            raise DataError(f"pixel pitch {pitch!r}: give one value or (x, y) in µm")
        explicit = False
    lo, hi = PITCH_RANGE_UM
    for v in vals:
        if not (math.isfinite(v) and v > 0):
            raise DataError(f"pixel pitch {pitch!r}: must be positive (µm)")
        if v < lo:
            if not explicit and unit_slip(v, lo, hi) is not None:
                raise DataError(
                    f"pixel pitch {v:g} µm looks like millimetres ({v * 1000:g} µm = {v:g} mm);"
                    f" give the pitch in micrometres ({v * 1000:g}) or write '{v:g}mm'"
                )
            raise DataError(f"pixel pitch {v:g} µm is below {lo} µm; give the pitch in micrometres")
        if v > hi:
            raise DataError(
                f"pixel pitch {v:g} µm is above {hi:g} µm; give the pitch in micrometres (e.g. 4.3)"
            )
    return vals[0], vals[1]


def _parse_offset(off) -> tuple[float, float]:
    if isinstance(off, str):
        parts = [p for p in re.split(r"[,\s]+", off.strip()) if p]
        if len(parts) != 2:
            raise DataError(f"principal-point offset {off!r}: give 'dx,dy' in mm (x right, y up)")
        vals = tuple(_number(p, "principal-point offset", _MM, "mm")[0] for p in parts)
    else:
        vals = _numbers(off, "principal-point offset", "give (dx, dy) in mm (x right, y up)")
        if len(vals) != 2:
            raise DataError(f"principal-point offset {off!r}: give (dx, dy) in mm")
    if not all(math.isfinite(v) for v in vals):
        raise DataError(f"principal-point offset {off!r}: must be finite")
    return vals[0], vals[1]


@dataclass(frozen=True)
class Sensor:
    """An image sensor (the frame of a camera).

    Attributes
    ----------
    width_mm, height_mm:
        Size of the active pixel array in mm (columns × pitch_x, rows × pitch_y).
    width_px, height_px:
        Pixel counts (columns, rows).
    principal_point_offset_mm:
        (dx, dy) of the principal point (where the optical axis meets the sensor) from the sensor
        centre, in mm, photogrammetric axes: **x right, y up** (Australis' xp, yp of a camera
        whose image centre is the sensor centre). An offset off the sensor (|dx| > width/2 or
        |dy| > height/2: a shift or rise, a cropped image) is taken with a
        :class:`~distortion.errors.UnitWarning`, which suggests µm when the offset is more than
        :data:`OFFSET_SLIP_RATIO` half-diagonals and would lie on the sensor read so.

    Build it from strings or numbers with :meth:`from_spec`; the constructor checks
    consistency and ranges and raises :class:`~distortion.errors.DataError` naming the fix.
    """

    width_mm: float
    height_mm: float
    width_px: int
    height_px: int
    principal_point_offset_mm: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        for name in ("width_px", "height_px"):
            v = getattr(self, name)
            if (
                number_problem(v) is not None
                or not math.isfinite(float(v))
                or not float(v) == int(v)
                or not 0 < int(v) <= MAX_PIXELS
            ):
                raise DataError(f"Sensor {name}={v!r}: a whole number of pixels, 1..{MAX_PIXELS}")
            object.__setattr__(self, name, int(v))
        for name in ("width_mm", "height_mm"):
            v = getattr(self, name)
            (v,) = _numbers((v,), f"Sensor {name}", "give a size in mm", v)
            if not (math.isfinite(v) and v > 0):
                raise DataError(f"Sensor {name}={v!r}: must be positive (mm)")
            why = size_problem(v)
            if why is not None:
                raise DataError(f"Sensor {name}={why}")
            object.__setattr__(self, name, v)
        object.__setattr__(
            self, "principal_point_offset_mm", _parse_offset(self.principal_point_offset_mm)
        )
        self._check_offset()
        px, py = self.pixel_pitch_um
        lo, hi = PITCH_RANGE_UM
        if not all(lo <= v <= hi for v in (px, py)):
            raise DataError(
                f"sensor {self.width_mm:g}x{self.height_mm:g} mm over {self.width_px}x"
                f"{self.height_px} pixels makes pixels of {px:g} x {py:g} µm, outside "
                f"{lo:g}..{hi:g} µm: check the size (mm) and the pixel count"
            )
        if max(px, py) > 1.1 * min(px, py):  # sensors have square pixels (a few percent off)
            warnings.warn(
                UnitWarning(
                    f"sensor {self.width_mm:g}x{self.height_mm:g} mm over {self.width_px}x"
                    f"{self.height_px} pixels makes pixels of {px:.4g} x {py:.4g} µm, far from "
                    "square: width and height swapped in one of them?"
                ),
                stacklevel=_caller_level(),
            )

    def _check_offset(self) -> None:
        """Warn (:class:`~distortion.errors.UnitWarning`) of a principal point off the sensor
        (|dx| > width/2 or |dy| > height/2; on the edge is on it). A shift or rise lens, or a
        calibration of a cropped image, puts it there, so it is taken; the warning asks whether
        it is in µm only when the offset is more than :data:`OFFSET_SLIP_RATIO` half-diagonals
        (no shift or crop reaches that) and would lie on the sensor read as µm."""
        dx, dy = self.principal_point_offset_mm
        hw, hh = self.width_mm / 2.0, self.height_mm / 2.0
        if abs(dx) <= hw and abs(dy) <= hh:
            return
        ratio = math.hypot(dx, dy) / math.hypot(hw, hh)  # in half-diagonals
        far = ratio > OFFSET_SLIP_RATIO
        if not far:
            fix = "taken as given (a shift or rise, or a cropped image, puts it there)"
        elif abs(dx) / 1000.0 <= hw and abs(dy) / 1000.0 <= hh:
            fix = f"taken as given: micrometres? give ({dx / 1000.0:g}, {dy / 1000.0:g}) mm"
        else:
            fix = f"taken as given, {ratio:.0f} half-diagonals from the centre: is it in mm?"
        warnings.warn(
            UnitWarning(
                f"principal-point offset {dx:g},{dy:g}: ({dx:g}, {dy:g}) mm lies off the "
                f"{self.width_mm:g}x{self.height_mm:g} mm sensor (|dx| ≤ {hw:g}, |dy| ≤ "
                f"{hh:g} mm; the offset is from the sensor centre in mm, x right, y up); {fix}"
            ),
            stacklevel=_caller_level(),
        )

    # ---- construction -----------------------------------------------------------------------
    @classmethod
    def from_spec(
        cls,
        size: str | Sequence[float] | None = None,
        pixels: str | Sequence[int] | None = None,
        pitch_um: str | float | Sequence[float] | None = None,
        principal_point_offset_mm: str | Sequence[float] = (0.0, 0.0),
    ) -> Sensor:
        """A sensor from any two (or all three, checked) of size, pixel count and pitch.

        Parameters
        ----------
        size:
            ``"36x24"`` (mm; ``"36x24mm"``, ``"23.5×15.6"``) or (w, h) in mm.
        pixels:
            ``"6000x4000"`` or (columns, rows).
        pitch_um:
            Pixel pitch in µm (``6``, ``"6x6"``, ``"6um"``, ``"0.006mm"``). With a size and no
            pixel count the count is size / pitch rounded to whole pixels and the size becomes
            count × pitch.
        principal_point_offset_mm:
            (dx, dy) from the sensor centre in mm, x right, y up (or ``"dx,dy"``); off the
            sensor it is warned of (:class:`Sensor`).
        """
        given = [
            n
            for n, v in (("size", size), ("pixels", pixels), ("pitch_um", pitch_um))
            if v is not None
        ]
        if len(given) < 2:
            raise DataError(
                "Sensor.from_spec: give two of size (e.g. '36x24' mm), pixels (e.g. '6000x4000') "
                "and pitch_um (e.g. 6); got " + (", ".join(given) or "none")
            )
        w_mm = h_mm = None
        if size is not None:
            w_mm, h_mm = parse_size_mm(size)
        cols = rows = None
        if pixels is not None:
            cols, rows = parse_pixels(pixels)
        if pitch_um is not None:
            px, py = parse_pitch_um(pitch_um)
            if cols is None:
                cols_f, rows_f = w_mm / (px / 1000.0), h_mm / (py / 1000.0)
                cols, rows = round(cols_f), round(rows_f)
                if cols < 1 or rows < 1:
                    raise DataError(
                        f"sensor {w_mm:g}x{h_mm:g} mm with a {px:g} µm pitch has no whole pixel"
                    )
            elif w_mm is not None:
                for what, mm, n, p in (("width", w_mm, cols, px), ("height", h_mm, rows, py)):
                    if abs(mm - n * p / 1000.0) > 0.005 * mm:
                        raise DataError(
                            f"sensor {what} {mm:g} mm disagrees with {n} pixels × {p:g} µm = "
                            f"{n * p / 1000.0:g} mm; give two of size, pixels and pitch, or "
                            "consistent values"
                        )
            w_mm, h_mm = cols * px / 1000.0, rows * py / 1000.0
        return cls(w_mm, h_mm, cols, rows, _parse_offset(principal_point_offset_mm))

    # ---- derived ----------------------------------------------------------------------------
    @property
    def pixel_size_mm(self) -> tuple[float, float]:
        """(pitch_x, pitch_y) in mm."""
        return self.width_mm / self.width_px, self.height_mm / self.height_px

    @property
    def pixel_pitch_um(self) -> tuple[float, float]:
        """(pitch_x, pitch_y) in µm."""
        px, py = self.pixel_size_mm
        return px * 1000.0, py * 1000.0

    @property
    def image_size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return self.width_px, self.height_px

    @property
    def diagonal_mm(self) -> float:
        return math.hypot(self.width_mm, self.height_mm)

    def centre(self, convention: str = "opencv") -> tuple[float, float]:
        """The sensor centre in absolute pixels of ``convention``."""
        return image_centre(self.width_px, self.height_px, convention)

    def principal_point(self, convention: str = "opencv") -> tuple[float, float]:
        """The principal point as the target writes cx, cy: absolute pixels for ``"opencv"``
        and ``"colmap"``; for ``"metashape"`` the offset from the image centre in pixels (x
        right, y down)."""
        px, py = self.pixel_size_mm
        dx, dy = self.principal_point_offset_mm
        if convention == "metashape":
            return dx / px, -dy / py
        cu, cv = self.centre(convention)
        return cu + dx / px, cv - dy / py

    def mm_to_pixels(self, xy_mm: np.ndarray, convention: str = "opencv") -> np.ndarray:
        """Photogrammetric image coordinates (mm, x right, y up, origin at the sensor centre)
        → absolute pixels of ``convention`` (…, 2)."""
        cv_px = photo_mm_to_opencv_pixels(xy_mm, self.width_px, self.height_px, self.pixel_size_mm)
        return from_opencv_pixels(cv_px, convention) if pixel_centre_offset(convention) else cv_px

    def pixels_to_mm(self, uv: np.ndarray, convention: str = "opencv") -> np.ndarray:
        """Absolute pixels of ``convention`` → photogrammetric mm (inverse of
        :meth:`mm_to_pixels`)."""
        return opencv_pixels_to_photo_mm(
            to_opencv_pixels(uv, convention), self.width_px, self.height_px, self.pixel_size_mm
        )

    def __repr__(self) -> str:
        px, py = self.pixel_pitch_um
        pitch = f"{px:.4g} µm" if abs(px - py) <= 1e-12 * px else f"{px:.4g}x{py:.4g} µm"
        dx, dy = self.principal_point_offset_mm
        off = "" if dx == dy == 0 else f", principal point offset ({dx:g}, {dy:g}) mm"
        return (
            f"Sensor({self.width_mm:g}x{self.height_mm:g} mm, "
            f"{self.width_px}x{self.height_px} px, pitch {pitch}{off})"
        )
