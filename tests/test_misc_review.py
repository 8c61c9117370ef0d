"""Review of coefficients, compensate, colour, glass and prescription (2026-11-28): what each
command said, or did not say, about the inputs it was given. Every test failed on the code the
review ran.

Numbers here are regression pins of orthoscope's own traces (cooke-triplet-f4 focused at 12x:
121 traced fields from 0 to 40 deg, chief-ray aiming fails from 30 deg on), not reference values.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from support import run_cli

import orthoscope as osc
from distortion.compensation import MagnificationWarning, compensate
from distortion.curve import make_curve
from distortion.errors import CalibrationError
from distortion.tablefile import read_distortion_table
from raytrace.errors import OrthoscopeError, TraceError

DATA = Path(__file__).parent / "data"
TRIPLET_12X = ["coefficients", "--lens", "cooke-triplet-f4", "--focus", "12x"]


# ----------------------------------------------------------------------------- coefficients
def test_coefficients_says_when_the_profile_stops_before_max_field():
    # --max-field 40: the trace fails from 30 deg; the fit used 89 of 120 points with no word
    rc, out, err = run_cli([*TRIPLET_12X, "--max-field", "40"])
    assert rc == 0 and "(89 points)" in out
    assert err.count("\n") == 1 and "warning: 31 of 121 fields (30-40 deg) are left out" in err
    assert "aim_failed" in err and "the profile stops at r = 32.03 mm (field 29.67 deg)" in err
    rc, out, err = run_cli([*TRIPLET_12X, "--max-field", "40", "--json"])
    d = json.loads(out)
    t = d["traced"]
    assert (t["n_fields"], t["n_fields_used"], t["max_field_deg"]) == (121, 90, 40.0)
    assert t["first_failure"] == {"field_deg": 30.0, "status": "aim_failed"}
    assert t["r_last_mm"] == pytest.approx(32.0253, abs=1e-4)  # regression pin (our output)
    assert d["warnings"] == [t["warning"]] and len(d["gaussian_fit"]["r_mm"]) == 89
    # --strict refuses it; a profile that traces to the end is silent and says so in JSON
    rc, out, err = run_cli([*TRIPLET_12X, "--max-field", "40", "--strict"])
    assert (rc, out) == (2, "") and "--strict fails" in err and err.count("\n") == 1
    rc, out, err = run_cli([*TRIPLET_12X, "--json"])
    d = json.loads(out)
    assert rc == 0 and err == "" and d["warnings"] == []
    assert d["traced"]["n_fields_used"] == 121 and d["traced"]["first_failure"] is None


@pytest.mark.parametrize("value", ["95", "0", "-5", "90"])
def test_coefficients_max_field_out_of_range_says_the_range(value):
    rc, out, err = run_cli([*TRIPLET_12X, "--max-field", value])
    assert (rc, out) == (2, "") and err.count("\n") == 1
    assert f"--max-field {value}:" in err and "between 0 and 90 degrees" in err


def test_coefficients_strict_goes_with_a_lens():
    rc, _, err = run_cli(["coefficients", str(DATA / "pestrecov_table1.csv"), "--strict"])
    assert rc == 2 and "--strict only apply with --lens" in err


# ----------------------------------------------------------------------------- compensate
@pytest.fixture(scope="module")
def curves():
    camera = read_distortion_table(DATA / "pestrecov_table1.csv", 153.706)
    m2 = -2.5
    printer = make_curve(camera.yp, -m2 * 0.5 * camera.D0, field_kind="height", constant=m2)
    return camera, printer, m2


def test_an_implausible_magnification_warns_or_is_refused(curves):
    camera, printer, m2 = curves
    with pytest.raises(CalibrationError, match=r"M = -1e\+09 is 4e\+08 times the printer's M2"):
        compensate(camera, printer, magnification=-1e9)
    with pytest.raises(CalibrationError, match="within a factor of 2 of M2"):
        compensate(camera, printer, magnification=m2 / 2.01)
    with pytest.warns(MagnificationWarning, match=r"\+20 % from the printer's M2 = -2.5"):
        compensate(camera, printer, magnification=1.2 * m2)
    import warnings

    with warnings.catch_warnings():  # within 10 %: silent
        warnings.simplefilter("error")
        compensate(camera, printer, magnification=1.09 * m2)
    for bad in (0.0, math.nan, math.inf):
        with pytest.raises(CalibrationError, match="is no print magnification factor"):
            compensate(camera, printer, magnification=bad)


def test_compensate_cli_names_the_flag_and_warns():
    pair = ["compensate", "topogon-us2031792-fig1", "twinplex-like-55-525", "--fields", "0,10,20"]
    for value in ("0", "nan"):
        rc, out, err = run_cli([*pair, f"--magnification={value}"])
        assert (rc, out) == (2, "") and f"--magnification {value}: the print magnification" in err
    rc, out, err = run_cli([*pair, "--magnification=-1e9"])
    assert (rc, out) == (2, "") and "no print of this printer has that scale" in err
    rc, out, err = run_cli([*pair, "--magnification=-11"])  # M2 = -9.545
    assert rc == 0 and "warning: the print magnification factor M = -11 is +15.2 %" in err


def test_compensate_json_keys_carry_units():
    pair = ["compensate", "topogon-us2031792-fig1", "twinplex-like-55-525", "--fields", "0,10,20"]
    rc, out, _ = run_cli([*pair, "--json"])
    d = json.loads(out)
    # regression pin (our output): the key's value; the point is the unit-suffixed name
    assert rc == 0 and "F1" not in d and d["F1_mm"] == pytest.approx(66.0378, abs=1e-4)
    assert {"M2", "M", "alpha_deg", "residual_mm"} <= set(d)


# ----------------------------------------------------------------------------- colour
def test_colour_max_field_0_prints_one_row():
    rc, out, _ = run_cli(["colour", "cooke-triplet-f4", "--max-field", "0"])
    assert rc == 0
    lateral = out.split("lateral colour")[1].split("distortion per wavelength")[0]
    rows = [ln for ln in lateral.splitlines() if ln.strip().startswith("0 ")]
    assert len(rows) == 1, lateral


def test_colour_failed_rays_shown_as_dash_with_status_names():
    argv = ["colour", "cooke-triplet-f4", "--fields", "0,10,35", "--wavelengths", "F,d,C"]
    rc, out, _ = run_cli(argv)
    assert rc == 0 and "nan" not in out
    note = "3 wavelength x field ray(s) not traced (shown as -): 35 deg at"
    assert out.count(note) == 2 and "(aim_failed)" in out  # lateral colour and distortion
    rc, out, _ = run_cli([*argv, "--json"])
    d = json.loads(out)
    assert d["distortion"]["status"] == [["ok", "ok", "aim_failed"]] * 3
    assert d["lateral_colour"]["status"] == [["ok", "ok", "aim_failed"]] * 3


@pytest.mark.parametrize("rings", [0, -2, 2.5, True, "8", 10**4])
def test_focal_shift_rings_are_checked(rings):
    lens = osc.load_lens("cooke-triplet-f4")
    with pytest.raises(TraceError, match="rings"):
        osc.focal_shift(lens, kind="best-focus", rings=rings)


def test_focal_shift_accepts_numpy_rings():
    lens = osc.load_lens("cooke-triplet-f4")
    a = osc.focal_shift(lens, "F,d,C", kind="best-focus", rings=np.int64(3))
    b = osc.focal_shift(lens, "F,d,C", kind="best-focus", rings=3)
    np.testing.assert_array_equal(a.shift, b.shift)


# ----------------------------------------------------------------------------- glass
@pytest.mark.parametrize(
    ("args", "kw", "msg"),
    [
        ((math.nan, 60.0), {}, "nd nan is no refractive index"),
        ((16.2, 60.0), {}, "16.2 looks like an Abbe number vd"),
        ((1.62, math.nan), {}, "vd nan is no Abbe number"),
        ((1.62, -60.0), {}, "vd -60 is no Abbe number"),
        ((1.62, 60.0), {"max_price": -1}, "max_price -1: a positive relative price"),
        ((1.62, 60.0), {"max_price": math.nan}, "max_price nan"),
        ((1.62, 60.0), {"n": 0}, "n = 0: ask for at least 1 glass"),
        ((1.62, 60.0), {"n": 2.5}, "n must be a whole number"),
    ],
)
def test_search_glass_refuses_what_is_no_search(args, kw, msg):
    with pytest.raises(ValueError, match=msg) as e:
        osc.search_glass(*args, **kw)
    assert isinstance(e.value, OrthoscopeError) and "\n" not in str(e.value)


def test_search_glass_still_finds():
    hits = osc.search_glass(1.62, 60.0, 3, max_price=math.inf)
    assert len(hits) == 3 and all(math.isfinite(h.distance) for h in hits)


def test_glass_catalog_flag_is_the_fix_the_message_gives():
    rc, out, err = run_cli(["glass", "F2", "--catalog", "Misc"])
    assert (rc, out) == (2, "") and err.count("\n") == 1
    assert "glass F2 is not in the Misc catalog; it is in Schott, CDGM, Hikari" in err
    assert "give --catalog Schott" in err
    rc, out, err = run_cli(["glass", "F2"])
    assert rc == 2 and "Choose one with --catalog Schott (or CDGM, Hikari)" in err
    assert "GCAT" not in err and "F2_SCHOTT" not in err
    rc, out, _ = run_cli(["glass", "F2", "--catalog", "Schott"])
    assert rc == 0 and out.startswith("F2 (Schott)")
    rc, out, _ = run_cli(["glass", "F2", "--catalog", "CDGM,Schott"])  # the first that has it
    assert rc == 0 and out.startswith("F2 (CDGM)")
    rc, _, err = run_cli(["glass", "F2", "--catalog", "Foo"])
    assert rc == 2 and "unknown catalog 'Foo'" in err


@pytest.mark.parametrize("text", ["1.5168/64.17", "517642"])
def test_glass_name_that_is_an_nd_vd_pair_points_to_search(text):
    rc, out, err = run_cli(["glass", text])
    assert (rc, out) == (2, "") and "is an nd/vd pair" in err and "--search nd=1.51" in err
    assert "replace it by a model glass" not in err


@pytest.mark.parametrize("flag", [["--count", "3"], ["--include-retired"]])
def test_search_flags_are_refused_with_a_name(flag):
    rc, out, err = run_cli(["glass", "N-BK7", *flag])
    assert (rc, out) == (2, "") and f"{flag[0]} goes with --search, not with a glass NAME" in err


def test_every_out_of_range_wavelength_is_named():
    rc, out, err = run_cli(["glass", "N-BK7", "--wavelengths", "300,587.6,2500"])
    assert rc == 0 and err.count("\n") == 1
    assert "evaluated at 300, 2500 nm, outside its data range 312.566–2325.42 nm" in err
    rc, out, err = run_cli(["glass", "N-BK7", "--wavelengths", "300,587.6,2500", "--strict"])
    assert (rc, out) == (2, "") and "300, 2500 nm" in err and "--strict fails" in err


# ----------------------------------------------------------------------------- prescription
def test_prescription_json_has_first_order_data_and_wavelengths():
    rc, out, _ = run_cli(["prescription", "cooke-triplet-f4", "--json"])
    d = json.loads(out)
    p = osc.paraxial(osc.load_lens("cooke-triplet-f4"))
    assert rc == 0 and d["wavelengths_nm"] == [587.5618]
    fo = d["first_order"]
    assert fo["efl_mm"] == pytest.approx(p.efl, rel=1e-12)
    assert fo["bfl_mm"] == pytest.approx(p.bfl, rel=1e-12)
    assert fo["f_number"] == pytest.approx(4.0, rel=1e-4) and fo["error"] is None


@pytest.mark.parametrize("cmd", ["trace", "colour", "pupils"])
def test_max_field_zero_is_the_axis_once(cmd):
    # --max-field 0 gave --steps + 1 identical fields in every command (orthoscope.cli.common)
    rc, out, err = run_cli([cmd, "cooke-triplet-f4", "--max-field", "0", "--json"])
    assert rc == 0, err
    d = json.loads(out)
    fields = {
        "trace": lambda: d["rays"],
        "pupils": lambda: d["pupils"]["fields"],
        "colour": lambda: d["lateral_colour"]["fields"],
    }[cmd]()
    assert len(fields) == 1
