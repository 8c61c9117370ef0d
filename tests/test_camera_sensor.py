"""The sensor spec and the pixel conventions (docs/design.md, "Camera models").

Sources: the conventions of each target — OpenCV pixel centres at integers (a centred cx is
(W − 1)/2), COLMAP and Metashape at +0.5 (cx = W/2; Metashape's cx is an offset from the image
centre: Agisoft Metashape User Manual, Appendix C), photogrammetric mm with y up — and plain
arithmetic of a 36 × 24 mm, 6000 × 4000 px sensor (6 µm pitch).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from distortion.camera import Sensor
from distortion.camera.conventions import image_centre, pixel_centre_offset
from distortion.errors import DataError


def test_from_strings_two_of_three():
    a = Sensor.from_spec("36x24", "6000x4000")
    b = Sensor.from_spec("36 x 24 mm", pitch_um=6)
    c = Sensor.from_spec(pixels=(6000, 4000), pitch_um="0.006mm")
    d = Sensor.from_spec("36x24mm", "6000x4000px", pitch_um="6x6")
    for s in (a, b, c, d):
        assert (s.width_px, s.height_px) == (6000, 4000)
        assert s.width_mm == pytest.approx(36.0) and s.height_mm == pytest.approx(24.0)
        assert s.pixel_pitch_um == pytest.approx((6.0, 6.0))
    assert "36x24 mm" in repr(a) and "6 µm" in repr(a)


def test_pitch_that_looks_like_mm_is_refused_with_the_fix():
    with pytest.raises(DataError, match="looks like millimetres.*give the pitch in micrometres"):
        Sensor.from_spec("36x24", pitch_um=0.006)
    with pytest.raises(DataError, match="above 1000 µm"):
        Sensor.from_spec(pixels="6000x4000", pitch_um=6000)
    with pytest.raises(DataError, match="pixel pitch 3900 µm is above 1000 µm"):
        Sensor.from_spec(pixels="6000x4000", pitch_um="3.9mm")  # 3.9 µm written as mm


@pytest.mark.parametrize(
    "pitch_um, pixels",
    [
        (139, (3072, 3072)),  # Varex PaxScan 4343 X-ray flat panel (427 mm square)
        (200, (2048, 2048)),  # PerkinElmer XRD 1621 X-ray flat panel (410 mm square)
        ("0.127mm", (1800, 1800)),  # film scanned at 200 dpi (25.4 mm / 200 = 127 µm)
        (1.75, (200, 200)),  # OmniVision OV6948 endoscope sensor: 0.35 x 0.35 mm
    ],
)
def test_real_sensors_at_the_ends_of_the_ranges_are_taken_without_a_warning(pitch_um, pixels):
    """Review of cfa9e08 (F1, F6): pitches above 100 µm and sides below 0.5 mm were refused
    (the OV6948 as "metres? 0.35 m = 350 mm"). Pitches: the makers' data sheets as quoted in the
    review (Varex 4343: 139 µm; XRD 1621: 200 µm; OV6948: 200 x 200 px of 1.75 µm)."""
    import warnings

    from distortion.camera.sensor import parse_size_mm

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s = Sensor.from_spec(pixels=pixels, pitch_um=pitch_um)
        assert s.pixel_size_mm[0] == pytest.approx(s.width_mm / pixels[0])
        assert parse_size_mm((s.width_mm, s.height_mm)) == (s.width_mm, s.height_mm)


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"size": "36x24"}, "give two of"),
        ({"size": "36", "pixels": "6000x4000"}, "width and height"),
        ({"size": "36x24", "pixels": "6000.5x4000"}, "whole numbers"),
        ({"size": "36x24", "pixels": "6000x4000", "pitch_um": 5}, "disagrees"),
        ({"size": "36000x24000", "pixels": "6000x4000"}, "outside"),
        ({"size": "36x24furlong", "pixels": "6000x4000"}, "unknown unit"),
    ],
)
def test_bad_specs_raise_clear_errors(kw, match):
    with pytest.raises(DataError, match=match):
        Sensor.from_spec(**kw)


@pytest.mark.parametrize(
    ("kw", "says"),
    [
        (dict(size=(36j, 24), pixels=(6000, 4000)),
         "sensor size (36j, 24): give (width, height) in mm (36j is a complex number)"),
        (dict(size=(True, True), pixels=(6000, 4000)),
         "sensor size (True, True): give (width, height) in mm (True is a bool, not a number)"),
        (dict(size="36x24", pitch_um=6j),
         "pixel pitch 6j: give one value or (x, y) in µm (6j is a complex number)"),
        (dict(size="36x24", pitch_um=np.True_),
         "pixel pitch np.True_: give one value or (x, y) in µm (np.True_ is a bool, not a number)"),
        (dict(size="36x24", pitch_um=(6, 6j)), "pixel pitch (6, 6j): give one value or (x, y)"),
        (dict(size="36x24", pixels=(6000, True)), "pixel count (6000, True): give (columns, rows)"),
        (dict(size="36x24", pixels="6000x4000", principal_point_offset_mm=(1j, 0)),
         "principal-point offset (1j, 0): give (dx, dy) in mm (x right, y up) (1j is a complex"),
    ],
)  # fmt: skip
def test_sensor_values_that_are_no_numbers_are_refused_naming_the_value(kw, says):
    # (36j, 24) and pitch 6j raised float()'s bare TypeError ("'complex' object is not
    # iterable" for the pitch); a pitch of True was a 1 µm pixel, a size of (True, True) 1 mm
    with pytest.raises(DataError) as e:
        Sensor.from_spec(**kw)
    assert str(e.value) == says or str(e.value).startswith(says), str(e.value)


def test_sensor_numbers_as_numpy_scalars_and_strings_are_taken():
    a = Sensor.from_spec(size=(np.float64(36), "24"), pixels=(np.int64(6000), 4000.0))
    b = Sensor.from_spec(size="36x24", pitch_um=np.float32(6.0))
    c = Sensor.from_spec(size="36x24", pitch_um=np.array(6.0))
    for s in (a, b, c):
        assert (s.width_px, s.height_px) == (6000, 4000)
        assert s.pixel_pitch_um == pytest.approx((6.0, 6.0))


def test_principal_point_in_each_convention():
    # odd, non-square: 3001 x 1999 px of 5 µm, principal point 0.1 mm right and 0.05 mm up
    s = Sensor.from_spec(pixels="3001x1999", pitch_um=5, principal_point_offset_mm=(0.1, 0.05))
    assert s.centre("opencv") == (1500.0, 999.0)  # (W-1)/2, (H-1)/2
    assert s.centre("colmap") == (1500.5, 999.5)  # W/2, H/2
    assert s.principal_point("opencv") == pytest.approx((1520.0, 989.0))  # y up -> v smaller
    assert s.principal_point("colmap") == pytest.approx((1520.5, 989.5))
    assert s.principal_point("metashape") == pytest.approx((20.0, -10.0))  # offset from centre
    assert pixel_centre_offset("colmap") == 0.5 and pixel_centre_offset("metashape") == 0.5
    assert image_centre(3001, 1999, "metashape") == (1500.5, 999.5)


def test_mm_and_pixels_round_trip_with_y_up():
    s = Sensor.from_spec("36x24", "6000x4000")
    mm = np.array([[0.0, 0.0], [18.0, 12.0], [-3.0, 1.5]])
    px = s.mm_to_pixels(mm)
    # the sensor centre is the centre of the pixel array; +y mm is up = smaller v
    np.testing.assert_allclose(px[0], [2999.5, 1999.5])
    np.testing.assert_allclose(px[1], [2999.5 + 3000, 1999.5 - 2000])
    np.testing.assert_allclose(s.pixels_to_mm(px), mm, atol=1e-12)
    np.testing.assert_allclose(s.mm_to_pixels(mm, "colmap"), px + 0.5)
    np.testing.assert_allclose(s.pixels_to_mm(px + 0.5, "colmap"), mm, atol=1e-12)


def test_camera_from_sensor_places_the_principal_point_in_each_convention():
    from distortion.camera import camera_from_sensor, project

    s = Sensor.from_spec(pixels="3001x1999", pitch_um=5, principal_point_offset_mm=(0.1, 0.05))
    c = 25.0  # mm -> f = 5000 px
    cv = camera_from_sensor("opencv", s, c)
    assert (cv["fx"], cv["cx"], cv["cy"]) == pytest.approx((5000.0, 1520.0, 989.0))
    col = camera_from_sensor("colmap:SIMPLE_PINHOLE", s, c)
    assert (col["f"], col["cx"], col["cy"]) == pytest.approx((5000.0, 1520.5, 989.5))
    ms = camera_from_sensor("metashape", s, c)
    assert (ms["f"], ms["b1"], ms["cx"], ms["cy"]) == pytest.approx((5000.0, 0.0, 20.0, -10.0))
    au = camera_from_sensor("australis", s, c)
    assert (au["c"], au["xp"], au["yp"]) == pytest.approx((25.0, 0.1, 0.05))
    # the axis images at the principal point in every model (OpenCV pixels)
    for cam in (cv, col, ms, au):
        np.testing.assert_allclose(
            project(cam, [[0.0, 0.0]], pixels="opencv").points[0], (1520.0, 989.0), atol=1e-9
        )
    centred = camera_from_sensor("colmap:PINHOLE", Sensor.from_spec("36x24", "6000x4000"), 50.0)
    assert (centred["cx"], centred["cy"]) == (3000.0, 2000.0)  # COLMAP: centred cx = W/2


def test_a_size_and_pixel_count_that_make_no_pixel_say_so():
    # no pitch was given: the message names what was (it advised "give the pitch in µm")
    with pytest.raises(DataError, match=r"200x150 mm over 80x60 pixels makes pixels of 2500 x "):
        Sensor.from_spec(size="200x150", pixels="80x60")  # 250 µm pixels are X-ray panels
    with pytest.raises(DataError, match=r"makes pixels of 0.08 x 0.08 µm, outside"):
        Sensor.from_spec(size="24x16", pixels="300000x200000")
    # far from square pixels: width and height swapped in one of the two (a warning)
    from distortion.errors import UnitWarning

    with pytest.warns(UnitWarning, match=r"5.333 x 12 µm, far from square: .* swapped"):
        Sensor.from_spec(size="16x24", pixels="3000x2000")


# ---- values in the wrong unit, refused where they enter (review 2026-12: camera units sweep) ----
@pytest.mark.parametrize(
    "size, match",
    [
        ("0.036x0.024", r"sensor size '0.036x0.024': the width 0.036 mm is outside 0.1\.\.1000 mm;"
         r" metres\? 0.036 m = 36 mm"),
        ((0.036, 0.024), r"the width 0.036 mm is outside .* metres\? 0.036 m = 36 mm"),
        ("36000x24000", r"the width 36000 mm is outside .* micrometres\? 36000 µm = 36 mm"),
    ],
)  # fmt: skip
def test_a_sensor_size_in_metres_or_micrometres_is_refused_where_it_is_parsed(size, match):
    from distortion.camera.sensor import parse_size_mm
    from distortion.grid.field import sensor_size

    with pytest.raises(DataError, match=match):
        parse_size_mm(size)
    with pytest.raises(DataError, match=match):  # distortion_grid(sensor=...) reads it here
        sensor_size(size)


def test_a_sensor_size_in_metres_is_refused_by_distortion_and_its_command(cooke):
    from support import run_cli

    from distortion.grid import distortion_grid

    with pytest.raises(DataError, match=r"0.036 mm is outside 0.1\.\.1000 mm; metres\?"):
        distortion_grid(cooke, sensor="0.036x0.024", grid=(5, 5))
    rc, out, err = run_cli(
        ["distortion", "cooke-triplet-f4", "--sensor", "0.036x0.024", "--grid", "5x5"]
    )
    assert rc == 2 and not out
    assert "0.036 mm is outside 0.1..1000 mm; metres? 0.036 m = 36 mm" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    "offset, match",
    [
        # 10 half-diagonals (216.3 mm) or less: a shift, rise or crop; no unit hint
        ((100, 0), r"^principal-point offset 100,0: \(100, 0\) mm lies off the 36x24 mm sensor "
         r"\(\|dx\| ≤ 18, \|dy\| ≤ 12 mm; the offset is from the sensor centre in mm, x right, "
         r"y up\); taken as given \(a shift or rise, or a cropped image, puts it there\)$"),
        ((0, -13), r"^principal-point offset 0,-13: \(0, -13\) mm lies off the 36x24 mm .* "
         r"taken as given \(a shift"),
        ((216, 0), r"^principal-point offset 216,0: .* taken as given \(a shift"),
        # more, and on the sensor read as µm: the hint
        ((217, 0), r"; taken as given: micrometres\? give \(0.217, 0\) mm$"),
        ("3000,0", r"lies off the 36x24 mm sensor .*; taken as given: micrometres\? give "
         r"\(3, 0\) mm$"),
        # more, and off the sensor read as µm too
        ((0, 30000), r"lies off .*; taken as given, 1387 half-diagonals from the centre: is it in "
         r"mm\?$"),
    ],
)  # fmt: skip
def test_a_principal_point_offset_off_the_sensor_is_taken_with_a_warning(offset, match):
    """Review of cfa9e08 (F3): an offset off the sensor was refused, but shift and rise lenses
    and cropped images put it there; µm is suggested only beyond OFFSET_SLIP_RATIO (10)
    half-diagonals (36x24: 21.63 mm, so 216.3 mm), where no shift or crop reaches."""
    from distortion.errors import UnitWarning

    with pytest.warns(UnitWarning, match=match) as rec:
        s = Sensor.from_spec(size="36x24", pixels="6000x4000", principal_point_offset_mm=offset)
    assert len(rec) == 1 and rec[0].filename == __file__  # the caller's line, not from_spec's
    from distortion.camera.sensor import OFFSET_SLIP_RATIO

    assert OFFSET_SLIP_RATIO * math.hypot(18, 12) == pytest.approx(216.33, abs=0.01)
    want = tuple(float(v) for v in offset.split(",")) if isinstance(offset, str) else offset
    assert s.principal_point_offset_mm == want
    # on the edge is on the sensor (a shift lens at its limit): no warning
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s = Sensor.from_spec(size="36x24", pixels="6000x4000", principal_point_offset_mm=(18, -12))
    assert s.principal_point_offset_mm == (18.0, -12.0)


@pytest.mark.parametrize(
    "size, pitch_um, offset",
    [
        ((53.4, 40.0), 3.76, (0.0, 25.0)),  # technical camera: 25 mm rise on a 53.4x40 back
        ((36.0, 24.0), 6.0, (0.0, 12.5)),  # shift lens, 12.5 mm on 36x24
        ((3.45, 2.76), 3.45, (3.0, 2.0)),  # a 1000x800 px crop whose principal point lies outside
    ],
)
def test_a_shifted_or_cropped_camera_is_built_with_a_plain_warning(size, pitch_um, offset):
    """Review of cfa9e08 (F3): these were refused, two of them saying "micrometres?"; now they
    are built, with a warning that names no other unit, and the camera's principal point lies
    where the offset puts it."""
    from distortion.camera import camera_from_sensor
    from distortion.errors import UnitWarning

    with pytest.warns(UnitWarning, match=r"lies off the .* taken as given \(a shift") as rec:
        s = Sensor.from_spec(size=size, pitch_um=pitch_um, principal_point_offset_mm=offset)
    assert not any("micrometres" in str(w.message) for w in rec)
    cam = camera_from_sensor("opencv", s, 50.0)
    px, py = s.pixel_size_mm
    cu, cv = s.centre("opencv")
    assert (cam["cx"], cam["cy"]) == pytest.approx((cu + offset[0] / px, cv - offset[1] / py))


@pytest.mark.parametrize(
    "c, match",
    [
        (0.05, r"principal_distance_mm=0.05: 0.05 mm is 433 times smaller than the sensor's "
         r"largest radius 21.6 mm \(a field angle of 89.87°\): metres\? 0.05 m = 50 mm; give c in "
         r"mm$"),
        (math.nan, r"principal_distance_mm=nan: give the principal distance c in mm, a positive"),
        (-50, r"principal_distance_mm=-50: give the principal distance c in mm, a positive"),
    ],
)  # fmt: skip
def test_camera_from_sensor_refuses_a_principal_distance_in_the_wrong_unit(c, match):
    from distortion.camera import camera_from_sensor

    s = Sensor.from_spec(size="36x24", pixels="6000x4000")
    with pytest.raises(DataError, match=match):
        camera_from_sensor("opencv", s, c)
    assert camera_from_sensor("opencv", s, 50.0)["fx"] == pytest.approx(50.0 / 0.006)


@pytest.mark.parametrize(
    "pixels, pitch_um, c, match",
    [
        # a 50 mm lens given in µm on full frame: the hint (half-diagonal 21.63 mm)
        ("6000x4000", 6, 50000, r"^principal_distance_mm=50000: 50000 mm is 2311 times the "
         r"sensor's largest radius 21.6 mm \(a field angle of 0.02479°\), more than 1000 times; "
         r"taken as 50000 mm \(a telescope can be that long\): micrometres\? 50000 µm = 50 mm$"),
        # telescopes: ZWO ASI224MC (1304x976 px of 3.75 µm, radius 3.05 mm) on a Celestron C14
        # at f/11 (3910 mm), and at 7000 mm (C11 with a 2.5x Barlow)
        ((1304, 976), 3.75, 3910.0, r"^principal_distance_mm=3910.0: 3910 mm is 1280 times .*"
         r"taken as 3910 mm"),
        ((1304, 976), 3.75, 7000.0, r"^principal_distance_mm=7000.0: 7000 mm is 2292 times .*"
         r"taken as 7000 mm"),
        # far beyond any lens or telescope, and no µm reading fits: still taken
        ("6000x4000", 6, 5e7, r"2.311e\+06 times .* taken as 5e\+07 mm .*: is it in the wrong "
         r"unit\?$"),
    ],
)  # fmt: skip
def test_a_principal_distance_of_a_telescope_is_taken_with_a_warning(pixels, pitch_um, c, match):
    """Review of cfa9e08 (F2): more than 1000 x the sensor's largest radius was refused, but
    telescopes reach 1280..2300 and a lens given in µm 1117..2311 (sensor.py's
    MAX_PRINCIPAL_DISTANCE_RATIO): the two overlap, so it is a warning naming both readings."""
    from distortion.camera import camera_from_sensor
    from distortion.errors import UnitWarning

    s = Sensor.from_spec(pixels=pixels, pitch_um=pitch_um)
    with pytest.warns(UnitWarning, match=match) as rec:
        cam = camera_from_sensor("opencv", s, c)
    assert len(rec) == 1 and rec[0].filename == __file__
    assert cam["fx"] == pytest.approx(c / s.pixel_size_mm[0])
    # a long lens well inside the ratio: no warning (2000 mm on the ASI224: 656 times)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        camera_from_sensor("opencv", s, 2000.0)
