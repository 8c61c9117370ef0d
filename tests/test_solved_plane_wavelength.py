"""A lens file's image solve (native ``t = "gaussian"``, CODE V ``PIM``, the .zmx that
``convert`` writes) is evaluated at the lens's reference (primary) wavelength, whatever
wavelength is traced (docs/design.md, "Vocabulary": the reference wavelength is the one
"paraxial data and solves use"; OpticStudio and CODE V evaluate solves at the primary
wavelength). So ``--wavelength F`` or ``C`` leaves the lens file's image plane where the file
puts it: the command line agrees with the API's ``plane="file"`` and with the same lens stored
with a fixed image distance. ``--gaussian`` still asks for the Gaussian plane of the traced
wavelength, and the solve still follows the traced object (README, "What you type")."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import orthoscope as osc
from orthoscope.cli import main
from raytrace.errors import PrescriptionError
from raytrace.paraxial import ImagePlane, paraxial

DATA = Path(__file__).parent / "data"
LENS = "cooke-triplet-f4"  # lenses/cooke-triplet-f4.toml: last t = "gaussian", reference d
FIXED_ZMX = DATA / "cooke-triplet-f4.zmx"  # the same lens, DISZ 43.080 stored as a number
PIM_SEQ = DATA / "cooke-triplet-f4.seq"  # the same lens, CODE V PIM on the last surface, REF d
F, C = 486.1327, 656.2725  # nm, the Fraunhofer F and C lines
#: the fixed file stores the image distance rounded to 43.080 mm; the solve gives 43.080280
ROUNDING_MM = 5e-4


def _run(capsys, *argv) -> dict:
    rc = main([*argv, "--json"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    return json.loads(out)


def _file_z(lens) -> float:
    """The API's lens-file plane (absolute z, mm)."""
    return float(paraxial(lens).z_image_file)


@pytest.fixture(scope="module")
def converted_zmx(tmp_path_factory) -> Path:
    """The .zmx ``convert`` writes for the bundled lens (its solve kept in a NOTE line)."""
    path = tmp_path_factory.mktemp("solve") / "cooke.zmx"
    assert main(["convert", LENS, str(path)]) == 0
    return path


def _solved_inputs(converted_zmx):
    return [LENS, str(PIM_SEQ), str(converted_zmx)]


def test_the_inputs_solve_their_image_plane(converted_zmx):
    # the premise: three files that solve the image plane, one that stores it as a number
    for name in _solved_inputs(converted_zmx):
        lens = osc.load_lens(name)
        assert lens.image_solve == "gaussian", name
        assert lens.wavelength == pytest.approx(587.5618), name
    assert osc.load_lens(FIXED_ZMX).image_solve is None


@pytest.mark.parametrize("wl", [F, C])
def test_trace_keeps_the_file_plane_at_another_wavelength(capsys, converted_zmx, wl):
    fixed = _run(capsys, "trace", str(FIXED_ZMX), "--wavelength", str(wl), "--fields", "10")
    for name in _solved_inputs(converted_zmx):
        lens = osc.load_lens(name)
        d = _run(capsys, "trace", name, "--wavelength", str(wl), "--fields", "10")
        plane = d["image_plane"]
        assert plane["given_as"] == "lens file"
        assert plane["z_mm"] == pytest.approx(_file_z(lens), abs=1e-9), name
        assert plane["from_last_vertex_mm"] == pytest.approx(lens.surfaces[-1].thickness, abs=1e-9)
        # not the Gaussian plane of the traced wavelength (43.008 mm at F, 43.108 mm at C)
        assert abs(plane["defocus_mm"]) > 0.02
        assert plane["z_mm"] == pytest.approx(fixed["image_plane"]["z_mm"], abs=ROUNDING_MM)
        # the real chief ray lands where the API puts it in the file's plane
        cr = osc.chief_rays(lens, [10.0], wavelength=wl)
        y = float(np.ravel(cr.heights_at(_file_z(lens)))[0])
        assert d["rays"][0]["y_image_mm"] == pytest.approx(y, abs=1e-9)


@pytest.mark.parametrize("wl", [F, C])
def test_spot_and_fan_agree_with_the_api_file_plane(capsys, wl):
    lens = osc.load_lens(LENS)
    api = osc.spot_diagram(lens, 0.0, wavelength=wl, plane="file")
    d = _run(capsys, "spot", LENS, "--wavelength", str(wl), "--fields", "0")["spots"][0]
    assert d["image_plane_z_mm"] == pytest.approx(_file_z(lens), abs=1e-9)
    assert d["rms_radius_mm"] == pytest.approx(api.rms_radius, rel=1e-9)
    fixed = _run(capsys, "spot", str(FIXED_ZMX), "--wavelength", str(wl), "--fields", "0")
    assert d["image_plane_z_mm"] == pytest.approx(
        fixed["spots"][0]["image_plane_z_mm"], abs=ROUNDING_MM
    )
    fan = _run(capsys, "fan", LENS, "--wavelength", str(wl), "--field", "0")["fans"][0]
    api_fan = osc.ray_fan(lens, 0.0, wavelength=wl, plane="file")
    assert fan["image_plane_z_mm"] == pytest.approx(_file_z(lens), abs=1e-9)
    assert api_fan.z_plane == pytest.approx(_file_z(lens), abs=1e-9)
    np.testing.assert_allclose(np.array(fan["eps_y_mm"], float), api_fan.ey, atol=1e-12)


def test_spot_at_f_is_the_sensor_plane_spot(capsys):
    # regression pin (orthoscope's own output, 2026-11-27): RMS 10.82 um in the sensor plane; the
    # old code gave 6.81 um, F's Gaussian plane (the plane itself is checked against the API above)
    d = _run(capsys, "spot", LENS, "--wavelength", "F", "--fields", "0")["spots"][0]
    assert d["rms_radius_mm"] * 1e3 == pytest.approx(10.82, abs=0.01)


@pytest.mark.parametrize("wl", [F, C])
def test_distortion_agrees_with_the_api_file_plane(capsys, converted_zmx, wl):
    fields = [0.0, 10.0, 20.0]
    for name in _solved_inputs(converted_zmx):
        lens = osc.load_lens(name)
        d = _run(capsys, "distortion", name, "--wavelength", str(wl), "--fields", "0,10,20")[
            "distortion"
        ]
        api = osc.characteristic_distortion(lens, fields, wavelength=wl, plane="file")
        (p,) = d["planes"]
        assert p["z_mm"] == pytest.approx(_file_z(lens), abs=1e-9), name
        np.testing.assert_allclose(np.array(p["yp_mm"], float), api.yp[0], atol=1e-9)
        np.testing.assert_allclose(np.array(p["D0_mm"], float), api.D0[0], atol=1e-9)


def test_chief_ray_height_at_f_in_the_sensor_plane(capsys):
    # regression pin (orthoscope's own output, 2026-11-27): 18.3058 mm at 20 deg in the sensor
    # plane; the old code gave 18.2815, F's Gaussian plane
    d = _run(capsys, "distortion", LENS, "--wavelength", "F", "--fields", "20")["distortion"]
    assert d["planes"][0]["yp_mm"][0] == pytest.approx(18.3058, abs=1e-4)


@pytest.mark.parametrize("wl", [F, C])
def test_report_certifies_the_file_plane(capsys, wl):
    lens = osc.load_lens(LENS)
    cond = _run(capsys, "report", LENS, "--wavelength", str(wl))["certificate"]["conditions"]
    par = paraxial(lens, wavelength=wl)
    assert cond["from_last_vertex_mm"] == pytest.approx(lens.surfaces[-1].thickness, abs=1e-9)
    assert cond["s_prime_mm"] == pytest.approx(_file_z(lens) - par.z_Hp, abs=1e-9)
    assert "Gaussian plane" not in cond["plane"]  # a defocus from the traced wavelength's plane
    api = osc.calibration_certificate(lens, wavelength=wl, plane="file")
    assert cond["s_prime_mm"] == pytest.approx(api.s_prime, abs=1e-9)


def test_the_solve_still_follows_the_traced_object(capsys):
    # README: "a file whose last thickness is "gaussian" means the Gaussian plane of whatever
    # object is traced" -- at the reference wavelength, whatever wavelength is traced
    lens = osc.load_lens(LENS)
    ref = paraxial(lens, 1000.0)  # the reference wavelength's Gaussian plane of that object
    for wl in (F, C):
        d = _run(
            capsys, "trace", LENS, "--object-distance", "1000", "--wavelength", str(wl),
            "--fields", "5",
        )  # fmt: skip
        assert d["image_plane"]["z_mm"] == pytest.approx(ref.z_gauss, abs=1e-9)
        assert paraxial(lens, 1000.0, wl).z_gauss_reference == pytest.approx(ref.z_gauss, 1e-12)
        z = ImagePlane("gaussian_reference").z(paraxial(lens, 1000.0, wl))
        assert z == pytest.approx(ref.z_gauss, abs=1e-9)


# --------------------------------------------------------------------------------- guards
# What follows the traced wavelength stays so (these pass before and after the fix).
@pytest.mark.parametrize("wl", [F, C])
def test_gaussian_flag_is_the_traced_wavelengths_plane(capsys, wl):
    lens = osc.load_lens(LENS)
    d = _run(capsys, "trace", LENS, "--wavelength", str(wl), "--fields", "10", "--gaussian")
    assert d["image_plane"]["z_mm"] == pytest.approx(paraxial(lens, None, wl).z_gauss, abs=1e-9)
    assert d["image_plane"]["defocus_mm"] == pytest.approx(0.0, abs=1e-12)


def test_at_the_reference_wavelength_nothing_moves(capsys):
    lens = osc.load_lens(LENS)
    d = _run(capsys, "trace", LENS, "--fields", "10")
    assert d["image_plane"]["z_mm"] == pytest.approx(_file_z(lens), abs=1e-9)
    assert d["image_plane"]["defocus_mm"] == pytest.approx(0.0, abs=1e-9)
    par = paraxial(lens)
    assert par.z_gauss_reference == par.z_gauss


# ------------------------------------------------------------ decentered lens with a solve
def test_a_decentered_lens_with_a_solve_says_what_to_change_in_the_file(tmp_path):
    text = Path(osc.load_lens(LENS).path).read_text(encoding="utf-8")
    text = text.replace("{ r = 141.25,  t = 2.0, ", "{ r = 141.25,  t = 2.0, decenter = [0, 0.1], ")
    assert "decenter" in text
    path = tmp_path / "decentered.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(PrescriptionError) as e:
        osc.load_lens(path)
    msg = str(e.value)
    assert 't = "gaussian"' in msg and "is decentered or tilted" in msg
    assert "give the last thickness as a number" in msg
    assert "nominal()" not in msg and "chief_rays_2d" not in msg
    # the line of the solve (the last surface), where the change is made
    last = next(i for i, t in enumerate(text.splitlines(), 1) if 't = "gaussian"' in t)
    assert f":{last}, surface 6: " in msg
    fifth = next(i for i, t in enumerate(text.splitlines(), 1) if "decenter = [0, 0.1]" in t)
    assert f"surface 5 (line {fifth})" in msg
    # the API's own message for a decentered lens is unchanged (it is about Python calls)
    fixed = tmp_path / "decentered-fixed.toml"
    fixed.write_text(text.replace('t = "gaussian"', "t = 43.08"), encoding="utf-8")
    lens = osc.load_lens(fixed)
    assert lens.surfaces[-1].thickness == 43.08 and lens.image_solve is None
    with pytest.raises(osc.LensError, match=r"use lens\.nominal\(\)"):
        paraxial(lens)
