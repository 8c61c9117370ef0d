"""Unit messages never append a unit to a value that already carries one (review:
``report --wavelength 0.55nm`` said "write 0.55nmum or 550nm").

A bare wavelength below 100 nm that is in range read as µm keeps the "looks like micrometres"
advice (and one that looks like metres or millimetres keeps that advice); a value with an
explicit unit is taken as meant, and out of range the message gives the range.
"""

from __future__ import annotations

import math

import pytest

from orthoscope.cli import main
from raytrace.units import UnitError, length_mm, wavelength_nm

#: a unit glued to a value that already has one ("0.55nmum", "5mmm", "5mmmm", "0.55nmnm")
DOUBLED = ("nmum", "nmnm", "nmm", "umum", "µmum", "mmum", "mmm", "cmm")


def doubled(msg: str) -> list[str]:
    return [d for d in DOUBLED if d in msg.lower()]


def refusal(f, *a, **kw) -> str:
    with pytest.raises(UnitError) as e:
        f(*a, **kw)
    msg = str(e.value)
    assert not doubled(msg), msg
    return msg


@pytest.mark.parametrize("text", ["0.55nm", "0.55 nm", "0.55NM", " 0.55nm "])
def test_an_explicit_nm_out_of_range_says_the_range(text):
    msg = refusal(wavelength_nm, text, "--wavelength")
    assert msg == "--wavelength: 0.55 nm is outside 100-30000 nm"


@pytest.mark.parametrize(
    ("text", "nm"),
    [("99.9nm", "99.9"), ("5.5e-7nm", "5.5e-07"), ("0.05um", "50"), ("50um", "50000")],
)
def test_other_explicit_units_out_of_range_say_the_range(text, nm):
    msg = refusal(wavelength_nm, text)
    assert msg == f"wavelength: {nm} nm is outside 100-30000 nm"
    assert "looks like" not in msg


@pytest.mark.parametrize(
    ("value", "fix"),
    [
        ("0.55", "write 0.55um or 550nm"),
        (" 0.55 ", "write 0.55um or 550nm"),
        (0.5876, "write 0.5876um or 587.6nm"),
        ("30", "write 30um or 30000nm"),
    ],
)
def test_a_bare_number_below_100_still_looks_like_micrometres(value, fix):
    msg = refusal(wavelength_nm, value)
    assert "looks like micrometres" in msg and fix in msg


@pytest.mark.parametrize(("value", "name"), [("5.5e-7", "metres"), (5.5e-4, "millimetres")])
def test_a_bare_number_that_looks_like_metres_or_millimetres_says_so(value, name):
    msg = refusal(wavelength_nm, value)
    assert f"looks like {name}: write 550nm" in msg


@pytest.mark.parametrize("value", ["99.9", 31.0, "0.05"])
def test_a_bare_number_out_of_range_in_both_units_says_the_range(value):
    # 99.9 um = 99900 nm is out of range too: "write 99.9um" would be wrong advice
    msg = refusal(wavelength_nm, value)
    assert "is outside 100-30000 nm" in msg and "looks like" not in msg


@pytest.mark.parametrize(
    ("text", "nm"), [("550nm", 550.0), ("0.55um", 550.0), ("0.55µm", 550.0), ("550", 550.0)]
)
def test_good_wavelengths_are_read(text, nm):
    assert wavelength_nm(text) == nm


def test_cli_wavelength_with_nm_out_of_range(capsys):
    rc = main(["report", "cooke-triplet-f4", "--wavelength", "0.55nm"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "0.55 nm is outside 100-30000 nm" in err
    assert "nmum" not in err and "looks like" not in err
    rc = main(["paraxial", "cooke-triplet-f4", "--wavelength", "0.55"])
    err = capsys.readouterr().err
    assert rc == 2 and "looks like micrometres: write 0.55um or 550nm" in err


# ------------------------------------------------------------------------------- lengths
@pytest.mark.parametrize("text", ["5mm", "5 mm", "5MM", " 5mm ", "0.5cm", "0.005m", "5000um"])
def test_lengths_with_a_unit_are_read(text):
    assert length_mm(text, "--object-distance") == pytest.approx(5.0, rel=1e-15)


@pytest.mark.parametrize("text", ["5nm", "0.55nm", "5xx"])
def test_an_unknown_length_unit_names_the_value_as_given(text):
    msg = refusal(length_mm, text, "--object-distance")
    unit = text.lstrip("0123456789.")
    assert msg == (
        f"--object-distance: unknown length unit {unit!r} in {text!r}; use mm, cm, m, um or in"
    )


def test_a_bare_length_that_needs_a_unit_gets_the_suffix_once():
    msg = refusal(length_mm, " 5 ", "--object-distance", require_unit=True)
    assert "write e.g. 5m or 5mm" in msg
    assert length_mm("5mm", "d", require_unit=True) == 5.0
    # infinity has no unit to ask for (was "write e.g. infm or infmm")
    assert length_mm("inf", "d", require_unit=True, allow_inf=True) == math.inf
    assert "finite" in refusal(length_mm, "inf", "d", require_unit=True)


@pytest.mark.parametrize(("text", "od"), [("5mm", 5.0), ("5", 5.0), ("0.5cm", 5.0)])
def test_cli_object_distance_with_and_without_a_unit(capsys, text, od):
    import json

    rc = main(["paraxial", "cooke-triplet-f4", "--object-distance", text, "--json"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    assert json.loads(out)["object_distance"] == pytest.approx(od, rel=1e-15)


def test_cli_object_distance_with_a_wavelength_unit_is_refused_once(capsys):
    rc = main(["paraxial", "cooke-triplet-f4", "--object-distance", "5nm"])
    err = capsys.readouterr().err
    assert rc == 2 and "unknown length unit 'nm' in '5nm'" in err
    assert not doubled(err), err
