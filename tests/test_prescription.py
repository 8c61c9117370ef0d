"""Prescription files: exact round trip, Gaussian image solve, scaling, and error messages that
name the file, the line and the surface."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from raytrace.errors import PrescriptionError
from raytrace.files.native import dumps, loads, provenance, read_lens, write_lens
from raytrace.lens import Aperture, Field, Lens, Surface
from raytrace.materials import AIR, fixed_index, model_glass
from raytrace.paraxial import paraxial

LENSES = Path(__file__).resolve().parent.parent / "lenses"
COOKE = (LENSES / "cooke-triplet-f4.toml").read_text()


def _line_of(text: str, needle: str) -> int:
    """1-based line of the first line containing ``needle``."""
    for i, line in enumerate(text.splitlines(), start=1):
        if needle in line:
            return i
    raise AssertionError(f"{needle!r} not in text")


def _exotic_lens() -> Lens:
    surfaces = (
        Surface(1.0 / 30.0, 2.5, model_glass(1.5168, 64.17), semi_diameter=4.0, label='front "A"'),
        Surface(
            -0.0123456789012345,
            0.1,
            AIR,
            semi_diameter=4.0,
            conic=-0.987654321,
            aspheric=(1.234567890123e-5, -6.5e-9, 0.0, 3.3e-14),
        ),
        Surface(0.0, 3.0, fixed_index(1.7), stop=True, label="STO"),
        Surface(0.1 + 0.2, 1.5, model_glass(1.62041, 60.32), aspheric=(-2e-6,)),
        Surface(-0.04, 47.123456789, AIR, label="last\\back"),
    )
    return Lens(
        name="exotic 'test' lens",
        surfaces=surfaces,
        aperture=Aperture("epd", 2.0 / 3.0),
        field=Field("height", 12.5),
        object_distance=1234.5678,
        wavelength=656.2725,
        source="made up for the round-trip test; unicode: λ 550 nm, ±",
        notes="provenance: derived\nline two\n\twith tab and a 'quote'",
        object_material=fixed_index(1.333),
    )


# ---------------------------------------------------------------------------------- round trip


@pytest.mark.parametrize("path", sorted(LENSES.glob("*.toml")), ids=lambda p: p.stem)
def test_round_trip_bundled(path: Path) -> None:
    lens = read_lens(path)
    text = dumps(lens)
    again = loads(text)
    assert again == lens
    assert dumps(again) == text
    # the last thickness is re-solved bit for bit
    assert again.surfaces[-1].thickness == lens.surfaces[-1].thickness
    assert again.image_solve == "gaussian"


def test_round_trip_exotic_exact(tmp_path: Path) -> None:
    lens = _exotic_lens()
    text = dumps(lens)
    again = loads(text)
    assert again == lens
    # every float bit for bit (Lens equality already covers them; spell out the risky ones)
    for a, b in zip(again.surfaces, lens.surfaces, strict=True):
        assert a.curvature == b.curvature
        assert a.aspheric == b.aspheric
        assert a.material == b.material
    assert again.object_material == fixed_index(1.333)
    assert provenance(again) == "derived"
    # and through a file
    out = tmp_path / "exotic.toml"
    write_lens(lens, out)
    from_file = read_lens(out)
    assert from_file == lens
    assert from_file.path == str(out)


def test_writer_layout_one_surface_per_line() -> None:
    lens = _exotic_lens()
    text = dumps(lens)
    lines = [ln for ln in text.splitlines() if ln.lstrip().startswith("{")]
    assert len(lines) == lens.n_surfaces
    # the columns line up: 't =' starts at the same place on every surface line
    assert len({ln.index(" t = ") for ln in lines}) == 1
    # the lines recorded by the reader are those lines
    again = loads(text)
    all_lines = text.splitlines()
    for s in again.surfaces:
        assert all_lines[s.line - 1].lstrip().startswith("{")


def test_writer_keeps_short_radii() -> None:
    """1/(1/r) need not be r; the writer searches the nearby floats for the short one."""
    lens = read_lens(LENSES / "topogon-us2031792-fig1.toml")
    text = dumps(lens)
    for r in ("11.25", "16.55", "9.094", "7.35", "-7.35", "-9.094", "-16.55", "-11.25"):
        assert f"r = {r}," in text
    # curvatures a few ulps away still come back bit for bit (as r or as c)
    for steps in range(1, 6):
        c = lens.surfaces[0].curvature
        for _ in range(steps):
            c = math.nextafter(c, 1.0)
        first = replace(lens.surfaces[0], curvature=c)
        lens2 = replace(lens, surfaces=(first,) + lens.surfaces[1:]).with_image_distance(50.0)
        assert loads(dumps(lens2)) == lens2


finite = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False)


@st.composite
def lenses(draw: st.DrawFn) -> Lens:
    n = draw(st.integers(min_value=1, max_value=6))
    stop = draw(st.integers(min_value=0, max_value=n - 1))
    surfaces = []
    for i in range(n):
        kind = draw(st.sampled_from(["air", "model", "index"]))
        if kind == "air":
            mat = AIR
        elif kind == "model":
            mat = model_glass(
                draw(st.floats(min_value=1.0, max_value=2.2)),
                draw(st.floats(min_value=15.0, max_value=95.0)),
            )
        else:
            mat = fixed_index(draw(st.floats(min_value=1.0, max_value=2.2)))
        t = draw(st.floats(min_value=1e-3, max_value=1e3))
        surfaces.append(
            Surface(
                curvature=draw(st.floats(min_value=-0.5, max_value=0.5)),
                thickness=t,
                material=mat,
                stop=(i == stop),
                conic=draw(finite),
                aspheric=tuple(draw(st.lists(finite, max_size=4))),
                label=draw(st.text(max_size=8)),
            )
        )
    return Lens(
        name=draw(st.text(max_size=20)),
        surfaces=tuple(surfaces),
        aperture=Aperture("fnumber", draw(st.floats(min_value=0.5, max_value=64.0))),
        field=Field("angle", draw(st.floats(min_value=0.0, max_value=89.0))),
        object_distance=draw(st.one_of(st.just(math.inf), st.floats(1e-3, 1e9))),
        wavelength=draw(st.floats(min_value=200.0, max_value=20000.0)),
        source=draw(st.text(max_size=30)),
        notes=draw(st.text(max_size=30)),
    )


@settings(max_examples=60, deadline=None)
@given(lenses())
def test_round_trip_property(lens: Lens) -> None:
    assert loads(dumps(lens)) == lens


# ------------------------------------------------------------------------- solve and scaling


def test_gaussian_solve_infinite_object_is_bfl() -> None:
    lens = loads(COOKE)
    assert lens.image_solve == "gaussian"
    assert lens.surfaces[-1].thickness == paraxial(lens).bfl


def test_gaussian_solve_finite_object_obeys_newton() -> None:
    """Newton's equation x·x' = −f² (in air) for the solved image of an object 500 mm away."""
    text = COOKE.replace('object   = { distance = "inf" }', "object   = { distance = 500.0 }")
    lens = loads(text)
    par = paraxial(lens)
    z_image = lens.image_z
    x = -500.0 - par.z_F
    xp = z_image - par.z_Fp
    assert x * xp == pytest.approx(-(par.efl**2), rel=1e-12)
    assert z_image > par.z_Fp  # a real image lies beyond F'


def test_scale_to_efl() -> None:
    text = COOKE.replace('provenance = "derived"\n', "scale_to_efl = 100.0\n")
    lens = loads(text, path="scaled.toml")
    base = loads(COOKE)
    assert paraxial(lens).efl == pytest.approx(100.0, rel=1e-12)
    factor = 100.0 / paraxial(base).efl
    for a, b in zip(lens.surfaces[:-1], base.surfaces[:-1], strict=True):
        assert a.thickness == pytest.approx(b.thickness * factor, rel=1e-14)
        assert a.radius == pytest.approx(b.radius * factor, rel=1e-14)
    assert lens.surfaces[-1].thickness == paraxial(lens).bfl
    assert provenance(lens) == "rescaled"
    assert "scale_to_efl" in lens.notes
    assert loads(dumps(lens)) == lens


def test_scale_to_efl_refuses_patent_provenance() -> None:
    text = COOKE.replace('provenance = "derived"', 'provenance = "patent"\nscale_to_efl = 100.0')
    with pytest.raises(PrescriptionError, match="rescaled") as e:
        loads(text, path="p.toml")
    assert e.value.line == _line_of(text, "provenance =")


# ---------------------------------------------------------------------------------- bad input


def _fails(text: str, name: str = "bad.toml") -> PrescriptionError:
    with pytest.raises(PrescriptionError) as e:
        loads(text, path=name)
    msg = str(e.value)
    assert msg.startswith(name + ":"), msg
    return e.value


def _surface_case(old: str, new: str, surface: int, words: str) -> None:
    text = COOKE.replace(old, new, 1)
    assert text != COOKE
    err = _fails(text)
    line = COOKE.count("\n", 0, COOKE.index(old)) + 1
    assert err.line == line and err.surface == surface
    assert f"bad.toml:{line}, surface {surface}: " in str(err)
    assert words in str(err), str(err)


def _file_case(old: str, new: str, at: str, *words: str) -> PrescriptionError:
    """The bundled Cooke file with ``old`` replaced by ``new`` fails on the line that contains
    ``at``, saying each of ``words``."""
    text = COOKE.replace(old, new)
    assert text != COOKE
    err = _fails(text)
    assert err.line == _line_of(text, at)
    for w in words:
        assert w in str(err), str(err)
    return err


def test_unknown_key_typo_suggests() -> None:
    _surface_case(
        "t = 6.0,        ",
        "thicknes = 6.0, ",
        4,
        "unknown key 'thicknes' in surface (did you mean 'thickness'/'t'?)",
    )


def test_missing_thickness() -> None:
    _surface_case("t = 1.0,", "   ", 3, "missing thickness t")


def test_missing_radius() -> None:
    _surface_case("r = -20.25,", "label = 'x',", 3, "missing radius")


def test_non_numeric_value() -> None:
    _surface_case("r = 21.25,", 'r = "21.25mm",', 1, "r (radius, mm) must be a number")


def test_zero_glass_thickness() -> None:
    _surface_case("t = 2.0,", "t = 0.0,", 1, "glass thickness must be positive")


def test_negative_glass_thickness() -> None:
    _surface_case("t = 1.0,", "t = -1.0,", 3, "glass thickness must be positive")


def test_negative_air_thickness() -> None:
    _surface_case("t = 6.0,", "t = -0.5,", 4, "air thickness must not be negative")


def test_unknown_material() -> None:
    _surface_case('"1.61659/36.63"', '"BK7"', 3, "unknown glass 'BK7'")


def test_gaussian_only_on_last_surface() -> None:
    _surface_case("t = 2.0,", 't = "gaussian",', 1, "only allowed on the last surface")


def test_zero_radius() -> None:
    _surface_case("r = 141.25,", "r = 0,", 5, 'use r = "inf" for a plane')


def test_stop_must_be_boolean() -> None:
    _surface_case("stop = true", 'stop = "yes"', 4, "stop must be true or false")


def test_semi_diameter_beyond_radius() -> None:
    _surface_case("r = 21.25,", "r = 21.25, sd = 30.0,", 1, "larger than the surface allows")


def test_surfaces_crossing_at_semi_diameter() -> None:
    """Surfaces 1 and 2 of the triplet (R +21.25, R −158.65, 2 mm apart) meet near h = 8.6 mm:
    with sd = 10 both, the edge of the crown element would be negative."""
    text = COOKE.replace("r = 21.25,", "r = 21.25, sd = 10.0,").replace(
        "r = -158.65,", "r = -158.65, sd = 10.0,"
    )
    err = _fails(text)
    assert err.surface == 1 and err.line == _line_of(text, "r = 21.25,")
    assert "surfaces 1 and 2 cross" in str(err)
    # with sd = 8 the edge is still positive: accepted
    ok = COOKE.replace("r = 21.25,", "r = 21.25, sd = 8.0,").replace(
        "r = -158.65,", "r = -158.65, sd = 8.0,"
    )
    assert loads(ok).surfaces[0].semi_diameter == 8.0


def test_two_stops() -> None:
    err = _file_case(
        "{ r = 141.25,  t = 2.0,",
        "{ r = 141.25,  t = 2.0, stop = true,",
        "r = 141.25",
        "two or more stops (surfaces 4 and 5)",
    )
    assert err.surface == 5


def test_no_stop() -> None:
    _file_case("stop = true", "label = 'S4'", "surfaces = [", "no surface is the aperture stop")


def test_missing_aperture() -> None:
    text = COOKE.replace("aperture = { fnumber = 4.0 }", "")
    err = _fails(text)
    assert err.line is not None and "missing [aperture] table" in str(err)
    assert "fnumber / epd / na" in str(err)


def test_two_aperture_kinds() -> None:
    _file_case(
        "{ fnumber = 4.0 }",
        "{ fnumber = 4.0, epd = 12.5 }",
        "aperture =",
        "exactly one of fnumber / epd / na / float / working_fnumber / cone_angle ",
        "(got: fnumber, epd)",
    )


def test_units_other_than_mm() -> None:
    _file_case('units      = "mm"', 'units      = "in"', "units", 'units must be "mm"')


def test_unknown_top_level_key() -> None:
    _file_case(
        "wavelength = ",
        "wavelenght = ",
        "wavelenght",
        "unknown key 'wavelenght' in the file (did you mean 'wavelength'?)",
    )


def test_surfaces_after_a_table_header() -> None:
    _file_case(
        "field    = { angle = 20.0 }",
        "[field]\nangle = 20.0",
        "surfaces = [",
        "must come before the first [table] header",
    )


def test_lens_error_is_converted_with_line() -> None:
    # the message is raytrace.units.wavelength_nm's
    _file_case(
        "wavelength = 587.5618", "wavelength = 0.5876", "wavelength =", "looks like micrometres"
    )


def test_virtual_gaussian_image() -> None:
    text = """
name = "single concave surface"
aperture = { fnumber = 4 }
field = { angle = 5 }
surfaces = [
  { r = -50.0, t = "gaussian", n = 1.5, stop = true },
]
"""
    err = _fails(text)
    assert err.surface == 1 and err.line == 6
    assert "virtual" in str(err)


def test_empty_file() -> None:
    err = _fails("")
    assert err.line == 1 and "empty" in str(err)
    err = _fails("# only a comment\n\n")
    assert err.line == 1 and "no prescription" in str(err)


def test_binary_garbage(tmp_path: Path) -> None:
    p = tmp_path / "garbage.toml"
    p.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR")
    with pytest.raises(PrescriptionError) as e:
        read_lens(p)
    assert str(e.value).startswith(f"{p}:3: ")  # the first NUL byte is on line 3
    assert "not a text file" in str(e.value)


def test_invalid_utf8(tmp_path: Path) -> None:
    p = tmp_path / "latin1.toml"
    p.write_bytes(COOKE.replace("Cooke triplet 50", "Cooke triplet \xe9 50").encode("latin-1"))
    with pytest.raises(PrescriptionError) as e:
        read_lens(p)
    line = _line_of(COOKE, 'name       = "Cooke triplet 50')
    assert str(e.value).startswith(f"{p}:{line}: ")
    assert "not valid UTF-8" in str(e.value)


def test_toml_syntax_error_keeps_line() -> None:
    err = _file_case("{ r = -20.25,", "{ r = -20.25 ", "{ r = -20.25 ", "TOML syntax error")
    assert f"at line {err.line}" in str(err)


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(PrescriptionError, match="no such file"):
        read_lens(tmp_path / "nope.toml")


def test_surface_lines_survive_comments_and_strings() -> None:
    text = """# a comment with { braces } and [ brackets ]
name = "x { not a surface"
aperture = { fnumber = 4 }
field = { angle = 5 }
surfaces = [
  # { commented = "out" }
  { r = 50.0, t = 5.0, glass = "1.5/60", label = "a } ] tricky" },  # 1

  { r = "inf", t = 0.0, stop = true },
  { r = -50.0, t = 40.0 },
]
"""
    lens = loads(text)
    assert [s.line for s in lens.surfaces] == [7, 9, 10]


def test_catalog_glasses_round_trip_by_name(tmp_path: Path) -> None:
    """A catalog glass is written by name and catalog (TOML) or name + GCAT (.zmx) and read back
    as the same material; its d-line index is the catalog's printed nd (Schott N-SK16: nd 1.62041,
    SCHOTT.xls as shipped by opticalglass 1.1.1) to the printed 5 decimals."""
    from raytrace.files.zemax import dumps_zmx, loads_zmx, read_zmx

    lens = read_zmx(Path(__file__).parent / "data" / "cooke-triplet-f4.zmx")
    m = lens.surfaces[0].material
    assert (m.kind, m.catalog, m.name) == ("catalog", "Schott", "N-SK16")
    assert m.index(587.5618) == pytest.approx(1.62041, abs=5e-6)
    text = dumps(lens)
    assert 'glass = "N-SK16"' in text and 'catalog = "Schott"' in text
    assert loads(text) == lens
    assert loads_zmx(dumps_zmx(lens)) == lens


def test_listing_and_json_show_mirrors_placements_and_apertures() -> None:
    # ray-optics' threemir.seq (tests/data/corpus/SOURCES.md): three tilted, decentered mirrors
    # with rectangular off-axis apertures and a decentered image surface. The listing showed a
    # plain stack of surfaces (review 2026-11-27); now the notes column and the JSON say it
    import json
    import warnings

    from orthoscope.report.prescription import prescription_to_dict
    from raytrace.files import read_lens_file
    from raytrace.listing import format_prescription

    root = Path(__file__).resolve().parents[1]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lens = read_lens_file(root / "tests/data/corpus/rayoptics/threemir.seq")
    text = format_prescription(lens, summary=False)
    row2 = text.splitlines()[5]  # the primary mirror (after title, aperture, header, rule, row 1)
    assert row2.lstrip().startswith("2 ") and "MIRROR" in row2
    assert "dec (0, 48.6953, 0) tilt (-8.43864, 0, 0); after: return" in row2  # YDE, ADE (-α)
    assert "aperture rectangle 75.7342 x 78.5387 at (0, 99.6024)" in row2  # REX, REY, ADY
    assert "image surface: dec (0, -47.6813, 0)" in text
    d = json.loads(json.dumps(prescription_to_dict(lens)))
    s2 = d["surfaces"][1]
    assert s2["mirror"] and s2["after"] == "return"
    assert s2["placement"]["decenter_mm"] == [0.0, 48.695345, 0.0]
    assert s2["clear_aperture"]["shape"] == "rectangle"
    assert d["image_placement"]["decenter_mm"][1] == -47.681342
