"""The Python API as a notebook user drives it (an adversarial review, 2026-11-27): what was a
silent wrong figure, an AttributeError from deep inside, a unit string refused in one function
and taken in the next. Each test names what failed before."""

from __future__ import annotations

import math
import warnings

import matplotlib
import numpy as np
import pytest

import orthoscope as osc
from distortion.errors import CalibrationError, DataError
from raytrace.errors import TraceError
from raytrace.optimize.spec import SpecError

matplotlib.use("Agg")


def test_plot_distortion_refuses_a_calibration_of_another_curve(cooke):
    # it drew the calibration's own (Topogon) curve and ignored the Cooke curve given
    t = osc.load_lens("topogon-us2031792-fig1")
    ct = osc.calibrate(osc.characteristic_distortion(t, fields_deg=[0, 10, 20, 30, 40, 45]))
    d = osc.characteristic_distortion(cooke, fields_deg=[0, 5, 10, 15, 20])
    with pytest.raises(DataError, match="the calibration is of another curve"):
        osc.plot_distortion(d, ct)
    import matplotlib.pyplot as plt

    plt.close(osc.plot_distortion(d, osc.calibrate(d)))  # its own calibration draws


def test_a_name_where_a_lens_or_spec_belongs_is_a_type_error(cooke):
    for call in (
        lambda: osc.paraxial("cooke-triplet-f4"),
        lambda: osc.chief_rays(None, [10]),
        lambda: osc.characteristic_distortion("cooke-triplet-f4", fields_deg=[10]),
        lambda: osc.ray_fan(1, 10),
    ):
        with pytest.raises(TypeError, match="must be a Lens"):
            call()
    with pytest.raises(TypeError, match="load it first, e.g. lens = osc.load_lens"):
        osc.paraxial("cooke-triplet-f4")
    with pytest.raises(TypeError, match="they are swapped"):
        osc.save_lens("out.toml", cooke)
    with pytest.raises(TypeError, match="spec must be a ToleranceSpec"):
        osc.tolerance_sensitivity(cooke, "cooke-triplet-f4")
    with pytest.raises(TypeError, match="spec must be a DesignSpec"):
        osc.optimize(cooke, "spec.toml")


def test_unit_strings_are_taken_wherever_a_value_with_a_unit_enters(cooke):
    # paraxial, trace_rays, ray_fan / spot_diagram and the tolerance runs refused them with
    # "could not convert string to float"; the same values as numbers give the same results
    p1, p2 = osc.paraxial(cooke, "1m"), osc.paraxial(cooke, 1000.0)
    assert p1.bfl == p2.bfl and p1.object_distance == 1000.0
    assert osc.paraxial(cooke, object_scale="12x").efl == osc.paraxial(cooke, "12x").efl
    assert osc.paraxial(cooke, wavelength="F").efl == osc.paraxial(cooke, wavelength=486.1327).efl
    assert osc.paraxial(cooke, wavelength="0.55um").efl == osc.paraxial(cooke, wavelength=550).efl
    with pytest.raises(TraceError, match="looks like micrometres"):
        osc.paraxial(cooke, wavelength=0.5876)  # was computed at 0.5876 nm
    with pytest.raises(TraceError, match="looks like metres: write 550nm"):
        osc.chief_rays(cooke, [10], wavelength=550e-9)
    a = osc.ray_fan(cooke, 14, wavelength="0.55um")
    b = osc.ray_fan(cooke, 14, wavelength=550.0)
    np.testing.assert_array_equal(a.ey, b.ey)
    o, d = [[0.0, 1.0, -10.0]], [[0.0, 0.0, 1.0]]  # rows in nested lists (were refused)
    r = osc.trace_rays(cooke, o, d, wavelength="550nm")
    assert r.status.tolist() == [0]
    lc = osc.lateral_colour(cooke, fields_deg=[10], wavelengths="F,C")  # was read per character
    assert lc.wavelengths == (486.1327, 656.2725)


def test_trace_variation_takes_the_distances_as_typed(cooke):
    # strings and numbers raised AttributeError / TypeError; only Conjugate objects worked
    a = osc.trace_variation(cooke, "12x", ["8x", "16x"], n_r=8)
    b = osc.trace_variation(cooke, osc.Conjugate(12, "x"), "8x,16x", n_r=8)
    ga = [p.estimate.g for p in a.analysis.focus_summaries[0].planes]
    assert ga == [p.estimate.g for p in b.analysis.focus_summaries[0].planes]
    assert len(repr(a)) < 400 and repr(a).startswith("TracedVariation(")  # was 56 kB
    import matplotlib.pyplot as plt

    plt.close(osc.plot_profiles(a))  # a trace_variation result plots as its analysis
    plt.close(osc.plot_g(a))
    with pytest.raises(TypeError, match="give a distance"):
        osc.trace_variation(cooke, None, ["8x"])


def test_bundled_names_where_files_are_taken(tmp_path):
    assert osc.read_spec("twinplex-like-55-525").name == "twinplex-like-55-525"
    lens = osc.convert("cooke-triplet-f4", tmp_path / "c.zmx")
    assert lens.name == "Cooke triplet 50 mm f/4" and (tmp_path / "c.zmx").exists()


def test_calibrate_checks_plane_k_and_says_how_to_pick_a_wavelength():
    t = osc.load_lens("topogon-us2031792-fig1")
    d = osc.characteristic_distortion(t, fields_deg=[0, 10, 20, 30, 40, 45])
    with pytest.raises(CalibrationError, match="plane=1.0"):
        osc.calibrate(d, plane=1.0)
    with pytest.raises(CalibrationError, match="k=-5"):
        osc.calibrate(d, k=-5)
    c = osc.characteristic_distortion(t, fields_deg=[0, 10, 20], wavelengths="F,d")
    with pytest.raises(CalibrationError, match=r"pick one wavelength, e.g. result.at\("):
        osc.calibrate(c)
    assert osc.calibrate(c.at(587.5618)).Kc > 0


def test_optimize_evaluation_limit_is_checked(cooke):
    spec = osc.read_spec("twinplex-like-55-525")
    start = osc.load_lens(spec.start if "/" in spec.start else "lenses/specs/" + spec.start)
    for bad in (0, 2.5, True):
        with pytest.raises(SpecError, match="max_evaluations must be a whole number >= 1"):
            osc.optimize(start, spec, max_evaluations=bad)


def test_camera_focus_in_mm_hints_at_metres(cooke):
    sensor = osc.Sensor.from_spec(size="24x16", pixels="3000x2000")
    with pytest.raises(DataError, match="for metres write focus='2m'"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        osc.camera_model(cooke, sensor, focus=2)
    assert math.isfinite(osc.paraxial(cooke, "2m").efl)


def test_three_rows_of_three_are_ambiguous(cooke):
    rows = [[0.0, 1.0, -10.0], [0.0, 2.0, -10.0], [0.0, 3.0, -10.0]]
    with pytest.raises(TraceError, match="three lists of three numbers are ambiguous"):
        osc.trace_rays(cooke, rows, [[0.0, 0.0, 1.0]] * 3)
    r = osc.trace_rays(cooke, np.array(rows), np.array([[0.0, 0.0, 1.0]] * 3))
    assert r.status.tolist() == [0, 0, 0]


def test_a_format_the_writer_refuses_is_said_as_such(cooke, tmp_path):
    # the read-back check turned the .zmx writer's own refusal into "would not read back ...
    # please report it" (a LensError)
    from dataclasses import replace

    from raytrace.errors import PrescriptionError

    ss = list(cooke.surfaces)
    ss[1] = replace(ss[1], aspheric=(0.0,) * 7 + (1e-20,))
    with pytest.raises(PrescriptionError, match="aspheric coefficients cannot be written"):
        osc.save_lens(replace(cooke, surfaces=tuple(ss)), tmp_path / "x.zmx")


def test_fans_and_spots_take_one_field_and_say_so(cooke):
    # spot_diagram(lens, [0, 20]) was "float() argument must be ... not 'list'"
    with pytest.raises(TraceError, match="one field .* call once per field"):
        osc.spot_diagram(cooke, [0, 20])
    with pytest.raises(TraceError, match="one field"):
        osc.ray_fan(cooke, "10")
    assert osc.ray_fan(cooke, np.float64(10.0)).field == 10.0


def test_plots_say_what_they_need(cooke, tmp_path):
    # matplotlib's "Number of rows must be a positive integer, not 0", an IndexError, and a
    # save_figure refusal that told a Python user to "give --force"
    import matplotlib.pyplot as plt

    for call, msg in (
        (lambda: osc.plot_tolerance(), "needs mc="),
        (lambda: osc.plot_ray_fan([]), "at least one RayFan"),
        (lambda: osc.plot_spot([]), "at least one SpotDiagram"),
    ):
        with pytest.raises(TypeError, match=msg):
            call()
    fig = osc.plot_ray_fan(osc.ray_fan(cooke, 10))
    out = tmp_path / "fan.png"
    osc.save_figure(fig, out)
    with pytest.raises(Exception, match="overwrite=True"):
        osc.save_figure(fig, out)
    plt.close(fig)
    # a finite object's fields are nominal angles (as the pupils and grid plots say)
    lc = osc.lateral_colour(osc.load_lens("twinplex-like-55-525"), fields_deg=[0, 10])
    fig = osc.plot_lateral_colour(lc)
    assert fig.axes[0].get_xlabel() == "nominal field angle (deg)"
    plt.close(fig)


def test_docstring_pass_findings(cooke, tmp_path):
    # found while documenting every public function (2026-11-27)
    spec = osc.read_spec("twinplex-like-55-525")
    with pytest.raises(SpecError, match="unknown method 'lbfgs'"):
        osc.optimize(cooke, spec, method="lbfgs")  # check_spec refuses it (as it should)
    from raytrace.files.library import library_dir

    specs = library_dir() / "specs"
    text = (specs / "twinplex-like-55-525.toml").read_text(encoding="utf-8")
    text = text.replace(f'start = "{spec.start}"', f'start = "{(specs / spec.start).as_posix()}"')
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + text.encode())  # a byte-order mark (Notepad)
    assert osc.read_spec(bom).name == spec.name
    empty = tmp_path / "empty.csv"
    empty.write_text("r_mm,dr_um,focus,object\n")
    with pytest.raises(DataError, match="no profile: the file holds no data rows"):
        osc.read_profiles_csv(empty, min_profiles=1)
    g = osc.distortion_grid(cooke, grid=5)
    with pytest.raises(DataError, match="pixel_mm=0"):
        osc.fit_brown_conrady(g, pixel_mm=0)
    from distortion.coefficients import opencv_model

    r = np.array([4.0, 8.0, 12.0, 16.0, 20.0])
    a = opencv_model(r, r**3 * 1e-3, focal_length_px=9000, pixel_pitch_um="5um")
    b = opencv_model(r, r**3 * 1e-3, focal_length_px=9000, pixel_pitch_um=5.0)
    assert (a.k1, a.k2, a.k3) == (b.k1, b.k2, b.k3)
