"""Unit messages never append a unit to a value that already carries one (review:
``report --wavelength 0.55nm`` said "write 0.55nmum or 550nm").

A bare wavelength below 100 nm that is in range read as µm keeps the "looks like micrometres"
advice (and one that looks like metres or millimetres keeps that advice); a value with an
explicit unit is taken as meant, and out of range the message gives the range.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import orthoscope as osc
from orthoscope.cli import main
from raytrace.errors import LensError, OrthoscopeError, TraceError
from raytrace.paraxial import ImagePlane, pestrecov_constants
from raytrace.units import UnitError, image_scale, length_mm, wavelength_nm

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


# ------------------------------------------------------------------------------- image planes
# The API's image-plane keywords take the lengths the command line's --s-prime,
# --from-last-vertex and --defocus take, through the one parser (raytrace.units.length_mm): they
# were read with float() ("could not convert string to float: '50.5mm'", no keyword named).
PLANE_STRINGS = [
    ("s_prime", "50.5mm", 50.5),
    ("s_prime", "5.05cm", 50.5),
    ("from_last_vertex", "0.043m", 43.0),
    ("defocus", "100um", 0.1),
    ("defocus", " -0.1 mm ", -0.1),
]


@pytest.mark.parametrize(("kw", "text", "mm"), PLANE_STRINGS)
def test_api_image_planes_take_the_cli_length_strings(cooke, kw, text, mm):
    assert ImagePlane(kw, text) == ImagePlane(kw, mm)
    assert ImagePlane(kw, text).value == length_mm(text, kw)
    with_unit = osc.characteristic_distortion(cooke, [0, 10], **{kw: text})
    bare = osc.characteristic_distortion(cooke, [0, 10], **{kw: mm})
    assert with_unit.z_planes.tolist() == bare.z_planes.tolist()
    assert with_unit.D0.tolist() == bare.D0.tolist()
    if kw == "s_prime":  # Eq. (8)'s constants in that plane take it too
        par = osc.paraxial(cooke)
        assert pestrecov_constants(par, text) == pestrecov_constants(par, mm)


def test_api_image_plane_lists_may_mix_numbers_and_lengths(cooke):
    r = osc.characteristic_distortion(cooke, [0, 10], s_prime=["50.5mm", 50.6, "5.07cm"])
    assert r.s_prime == pytest.approx([50.5, 50.6, 50.7], rel=1e-12)


@pytest.mark.parametrize(
    ("value", "says"),
    [
        ("50.5nm", "s_prime: unknown length unit 'nm' in '50.5nm'; use mm, cm, m, um or in"),
        ("x", "s_prime: 'x' is not a number (with an optional unit such as mm, m, nm, um)"),
        (1j, "s_prime: expected a length in mm"),
        ("inf", "s_prime: expected a finite length, got 'inf'"),
        (math.nan, "s_prime: expected a finite length, got nan"),
    ],
)
def test_an_image_plane_that_is_no_length_names_the_keyword(cooke, value, says):
    for call in (
        lambda: ImagePlane("s_prime", value),
        lambda: osc.characteristic_distortion(cooke, [0, 10], s_prime=value),
        lambda: osc.spot_diagram(cooke, 10, s_prime=value),
        lambda: pestrecov_constants(osc.paraxial(cooke), value),
    ):
        with pytest.raises(TraceError) as e:
            call()
        assert str(e.value).startswith(says), str(e.value)
        assert "\n" not in str(e.value) and not doubled(str(e.value))


@pytest.mark.parametrize("kw", ["s_prime", "from_last_vertex", "defocus"])
@pytest.mark.parametrize("value", [1e300, -1e300, 1e10, "1e7m"])
def test_an_image_plane_at_the_distance_lens_files_call_infinity_is_refused(cooke, kw, value):
    # 1e300 was traced (max |D0| = 5e296 mm) while inf was refused; Zemax, CODE V and OSLO files
    # put an object at infinity at a distance of 1e10 or more (raytrace/files: zemax.py,
    # codev.py, oslo.py)
    mm = length_mm(value, kw)
    says = f"{kw}={mm:g} mm is not a plane position: 1e10 mm or more is where lens files put"
    for call in (
        lambda: ImagePlane(kw, value),
        lambda: osc.characteristic_distortion(cooke, [0, 10], **{kw: value}),
        lambda: osc.ray_fan(cooke, 10, **{kw: value}),
    ):
        with pytest.raises(TraceError) as e:
            call()
        assert str(e.value).startswith(says), str(e.value)


def test_image_planes_below_the_bound_are_taken_without_a_warning(cooke):
    assert ImagePlane("from_last_vertex", 9.99e9).value == 9.99e9
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = osc.characteristic_distortion(cooke, [0, 10], defocus=500)
    assert r.defocus[0] == pytest.approx(500.0, rel=1e-12)


def test_cli_s_prime_at_infinity_distance_is_refused_in_one_line(capsys):
    rc = main(["distortion", "cooke-triplet-f4", "--s-prime", "1e300"])
    out, err = capsys.readouterr()
    assert rc == 2 and out == ""
    assert err.count("\n") == 1 and "--s-prime 1e+300 mm is not a plane position" in err, err


# ------------------------------------ bools and complex numbers where a number with a unit enters
@pytest.mark.parametrize(
    ("f", "value", "says"),
    [
        (length_mm, True, "x: expected a length in mm (a number, or a string with its unit such "
         "as 50.5mm or 0.05m), got True (a bool, not a number)"),
        (length_mm, np.True_, "got np.True_ (a bool, not a number)"),
        (length_mm, 1j, "got 1j (a complex number)"),
        (length_mm, np.complex128(5), "(a complex number)"),
        (wavelength_nm, True, "x: expected a number of nm, got True (a bool, not a number)"),
        (wavelength_nm, 587j, "x: expected a number of nm, got 587j (a complex number)"),
        (image_scale, True, "x: expected an image scale N such as 12 or '12x', got True (a bool"),
        (image_scale, 12j, "x: expected an image scale N such as 12 or '12x', got 12j (a complex"),
        (image_scale, [12], "x: expected an image scale N such as 12 or '12x', got [12]"),
    ],
)  # fmt: skip
def test_a_bool_or_complex_number_is_no_value_with_a_unit(f, value, says):
    # length_mm(True) was 1 mm and wavelength_nm(True) 1 nm (refused only as out of range);
    # image_scale(12j) raised a bare TypeError from float()
    msg = refusal(f, value, "x")
    assert says in msg and "\n" not in msg, msg


@pytest.mark.parametrize(
    ("f", "value", "expected"),
    [
        (length_mm, "1.5m", 1500.0),
        (length_mm, np.float64(2.5), 2.5),
        (length_mm, np.array(3.0), 3.0),
        (length_mm, np.int64(4), 4.0),
        (length_mm, 5, 5.0),
        (wavelength_nm, np.float32(550.0), 550.0),
        (wavelength_nm, "587.5618", 587.5618),
        (image_scale, np.int64(12), 12.0),
        (image_scale, "12", 12.0),
    ],
)
def test_numpy_scalars_ints_and_numeric_strings_stay_numbers(f, value, expected):
    assert f(value, "x") == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize(
    ("kw", "value", "says"),
    [
        ("object_distance", 1j, "object_distance: expected mm (or a length with its unit: 1.5m, "
         "250mm), 'inf' or an image scale such as '12x', got 1j (a complex number)"),
        ("object_distance", [1000, 2000], "object_distance: expected mm (or a length with its "
         "unit: 1.5m, 250mm), 'inf' or an image scale such as '12x', got [1000, 2000]"),
        ("object_distance", True, "got True (a bool, not a number)"),
        ("object_s", True, "object_s: expected a length in mm"),
        ("object_scale", 12j, "object_scale: expected an image scale N"),
    ],
)  # fmt: skip
def test_an_object_that_is_no_distance_names_the_keyword(cooke, kw, value, says):
    # object_distance=1j and [1000, 2000] raised float()'s bare TypeError (no keyword named);
    # object_distance=True traced an object 1 mm from the first vertex
    # the class of each function's other refusals of the keyword (NaN, a negative distance):
    # TraceError in a trace, LensError in paraxial(), UnitError for object_s / object_scale
    for call, error in (
        (lambda: osc.chief_rays(cooke, [0, 10], **{kw: value}), TraceError),
        (lambda: osc.characteristic_distortion(cooke, [0, 10], **{kw: value}), TraceError),
        (lambda: osc.paraxial(cooke, **{kw: value}), LensError),
    ):
        with pytest.raises(OrthoscopeError) as e:
            call()
        if kw == "object_distance":
            assert isinstance(e.value, error), repr(e.value)
        assert says in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_paraxial_object_distance_keeps_its_error_class(cooke):
    # a number that is no distance is a LensError in paraxial(), as NaN or a negative one is
    for value in (1j, [1000.0], True, math.nan):
        with pytest.raises(LensError, match="object"):
            osc.paraxial(cooke, object_distance=value)
    assert osc.paraxial(cooke, object_distance=np.float64(1000.0)).object_distance == 1000.0


# a count, a distance or a thickness that is no number of the right kind: the module's own
# error naming the keyword, not a bare TypeError from range(), a comparison or a subtraction
_R = np.linspace(0.5, 20, 20)
_DR = -0.5 * _R**3 / 400  # µm


@pytest.mark.parametrize(
    "call, value, error, says",
    [
        ("fit_radial", 2.5, "DataError", "n_terms must be at least 1 (a whole number"),
        ("fit_radial", True, "DataError", "n_terms must be at least 1 (a whole number"),
        ("fit_radial", "3", "DataError", "n_terms must be at least 1 (a whole number"),
        ("decompose", 2.5, "DataError", "radial_terms must be 0 or more (a whole number"),
        ("decompose", True, "DataError", "radial_terms must be 0 or more (a whole number"),
        ("focus", 1j, "DataError", "distance_mm: expected a focus distance in mm"),
        ("focus", [2000], "DataError", "distance_mm: expected a focus distance in mm"),
        ("focus", "2 parsecs", "DataError", "distance_mm: unknown length unit"),
        ("focus_index", 1.5, "DataError", "focus_index must lie in 0–2 (a whole number)"),
        ("insert", "x", "LensError", "the inserted element's thickness must be a length in mm"),
        ("insert", 1j, "LensError", "the inserted element's thickness must be a length in mm"),
    ],
)
def test_a_count_distance_or_thickness_of_the_wrong_kind_names_the_keyword(
    cooke, call, value, error, says
):
    calls = {
        "fit_radial": lambda: osc.fit_radial(_R, _DR, n_terms=value),
        "decompose": lambda: osc.decompose_distortion(
            osc.distortion_grid(cooke, grid=(9, 7)), radial_terms=value
        ),
        "focus": lambda: osc.solve_focus(cooke, value, moving=1),
        "focus_index": lambda: osc.focus_study(
            cooke,
            osc.unit_focus_configurations(cooke, [math.inf, 2000, 1000]),
            focus_index=value,
        ),
        "insert": lambda: osc.insert_element(cooke, 2, osc.fixed_index(1.5), thickness=value),
    }
    with pytest.raises(OrthoscopeError) as e:
        calls[call]()
    assert type(e.value).__name__ == error and says in str(e.value), repr(e.value)
    assert "\n" not in str(e.value)


def test_valid_counts_distances_and_thicknesses_stay_accepted(cooke):
    # numpy integers count; a focus distance may carry its unit as object_distance's does
    assert len(osc.fit_radial(_R, _DR, n_terms=np.int64(2)).k) == 2
    two_m = osc.solve_focus(cooke, 2000, moving=1)
    assert osc.solve_focus(cooke, "2m", moving=1) == two_m
    assert osc.solve_focus(cooke, np.float64(2000.0), moving=1) == two_m
    assert osc.solve_focus(cooke, "inf", moving=1).object_distance == math.inf
    for t in (2, 2.0, np.int64(2), np.float32(2.0)):
        assert osc.insert_element(cooke, 2, osc.fixed_index(1.5), thickness=t).n_surfaces == 8
