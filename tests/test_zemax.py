"""Zemax .zmx import / export (issue 7).

Sources of the numbers: the bundled lenses (lenses/*.toml, each with its source) and the
hand-written fixtures tests/data/cooke-triplet-f4.zmx (ASCII, CRLF, catalog glass N-SK16 whose
Schott catalog values nd 1.62041 / vd 60.32 equal the Cooke triplet's crown) and
tests/data/topogon-us2031792-fig1.zmx (UTF-16 LE with BOM, as OpticStudio writes; US 2,031,792
Fig. 1 as published). The fixtures were typed by hand from the same prescriptions, so their
paraxial data and real chief rays must equal the native files' (to the 16-digit curvatures typed).
"""

from __future__ import annotations

import codecs
import math
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from support import with_model_glasses

from raytrace.errors import PrescriptionError
from raytrace.files import convert
from raytrace.files.library import bundled_names, load_lens
from raytrace.files.text import InteropWarning
from raytrace.files.zemax import dumps_zmx, loads_zmx, parse_zmx, read_zmx, write_zmx
from raytrace.glass import catalog_available
from raytrace.lens import Aperture, Field, Lens, Surface
from raytrace.materials import fixed_index, model_glass
from raytrace.paraxial import paraxial
from raytrace.trace import chief_rays

DATA = Path(__file__).parent / "data"

PARAXIAL_FIELDS = ("efl", "bfl", "ffl", "z_H", "z_Hp", "z_E0", "z_E0p", "epd", "xpd", "m_e")


def asphere_lens() -> Lens:
    """The Cooke triplet (issue 2) with an even asphere, a conic, semi-diameters, a label, a
    fixed-index element, a finite object, an EPD aperture and an object-height field: every
    feature the .zmx writer has to carry."""
    c = model_glass(1.62041, 60.32)
    f = model_glass(1.61659, 36.63)
    s = (
        Surface(1 / 21.25, 2.0, c, semi_diameter=8.0, conic=-0.3, aspheric=(-2.5e-6, 3.1e-9)),
        Surface(1 / -158.65, 6.0, semi_diameter=7.8, label="rear of crown"),
        Surface(1 / -20.25, 1.0, f, semi_diameter=6.0),
        Surface(1 / 19.3, 6.0, stop=True, semi_diameter=5.5),
        Surface(1 / 141.25, 2.0, fixed_index(1.62), aspheric=(0.0, 0.0, 1.7e-11)),
        Surface(1 / -17.285, 44.5),
    )
    return Lens(
        name="Cooke triplet with an asphere",
        surfaces=s,
        aperture=Aperture("epd", 10.0),
        field=Field("height", 150.0),
        object_distance=1000.0,
        wavelength=546.074,
        source="orthoscope test: Cooke triplet of issue 2 plus invented aspheric terms",
        notes='multi-line notes\nwith "quotes", a backslash \\ and ünïcode',
    )


def heights(lens: Lens, fields, z) -> np.ndarray:
    f = np.asarray(fields, dtype=float)
    kw = {"fields_deg": f} if lens.field.kind == "angle" else {"object_heights_mm": f}
    cr = chief_rays(lens, **kw)
    assert np.all(cr.status == 0)
    return cr.heights_at(z)


@pytest.mark.parametrize("name", bundled_names())
def test_bundled_lens_round_trip_is_exact(name, tmp_path):
    lens = load_lens(name)
    back = loads_zmx(dumps_zmx(lens))
    assert back == lens  # every field: surfaces, glasses, aperture, field, wavelength, notes
    # through a UTF-16 file as OpticStudio writes it
    p = tmp_path / f"{name}.zmx"
    write_zmx(lens, p)
    assert p.read_bytes()[:2] == codecs.BOM_UTF16_LE
    assert read_zmx(p) == lens


def test_asphere_round_trip_reproduces_rays(tmp_path):
    lens = asphere_lens()
    p = tmp_path / "asph.zmx"
    write_zmx(lens, p, encoding="ascii")
    back = read_zmx(p)
    # trailing zero aspheric terms are not kept; the surface is the same
    assert back.surfaces[4].aspheric == (0.0, 0.0, 1.7e-11)
    assert back == lens
    ys = np.linspace(-150.0, 150.0, 7)
    z = lens.image_z + np.array([-1.0, 0.0, 2.0])
    np.testing.assert_allclose(heights(back, ys, z), heights(lens, ys, z), rtol=0, atol=1e-12)
    pa, pb = paraxial(lens), paraxial(back)
    for f in PARAXIAL_FIELDS:
        assert getattr(pa, f) == getattr(pb, f), f


def test_zemax_even_asphere_parameters_map_to_a4_a6():
    """Zemax EVENASPH: PARM 1 is the r² term, PARM 2 the r⁴ term (A4), PARM 3 r⁶ (A6)..."""
    text = dumps_zmx(asphere_lens())
    assert "  PARM 1 0\r\n  PARM 2 -2.5e-06\r\n  PARM 3 3.1e-09\r\n  PARM 4 0" in text


@pytest.mark.parametrize("stem", ["cooke-triplet-f4", "topogon-us2031792-fig1"])
def test_hand_written_fixture_matches_native(stem):
    native = load_lens(stem)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a clean user file gives no warning
        imported = read_zmx(DATA / f"{stem}.zmx")
    # The Cooke fixture names Schott catalog glasses (N-SK16, F2); the native file gives the same
    # glasses as nd/vd model glasses. Same glass, same d-line index to the catalog's printed
    # digits (5 decimals); for the exact comparison below use the catalog's nd/vd model.
    for s in imported.surfaces:
        if s.material.kind == "catalog":
            assert s.material.index(587.5618) == pytest.approx(s.material.nd, abs=5e-6)
    imported = with_model_glasses(imported)
    assert imported.name == native.name
    assert imported.aperture == native.aperture
    # the file lists its field points (Field.points); the native file gives the maximum only
    assert (imported.field.kind, imported.field.value) == (native.field.kind, native.field.value)
    assert imported.wavelength == native.wavelength
    assert imported.object_distance == native.object_distance
    assert [s.material for s in imported.surfaces] == [s.material for s in native.surfaces]
    assert imported.stop_index == native.stop_index
    pi, pn = paraxial(imported), paraxial(native)
    for f in PARAXIAL_FIELDS:
        assert getattr(pi, f) == pytest.approx(getattr(pn, f), rel=1e-12, abs=1e-12), f
    fields = np.linspace(0.0, native.field.value, 6)
    z = pn.z_Fp + np.array([-0.5, 0.0, 0.5])  # the paraxial image plane and two defocused ones
    np.testing.assert_allclose(
        heights(imported, fields, z), heights(native, fields, z), rtol=0, atol=1e-10
    )


def test_utf16_without_bom_and_utf8_bom_are_read():
    text = dumps_zmx(load_lens("cooke-triplet-f4"))
    ref = loads_zmx(text)
    assert loads_zmx(text.encode("utf-16-le")) == ref
    assert loads_zmx(text.encode("utf-16-be")) == ref
    assert loads_zmx(codecs.BOM_UTF8 + text.encode()) == ref


def test_units_are_converted_to_mm():
    lens = asphere_lens()
    text = dumps_zmx(lens).replace("UNIT MM", "UNIT CM")
    back = loads_zmx(text)
    assert back.surfaces == lens.scaled(10.0).surfaces
    assert back.aperture == Aperture("epd", 100.0)
    assert back.object_distance == 10000.0


def test_unknown_commands_are_listed_in_a_warning():
    text = dumps_zmx(load_lens("cooke-triplet-f4")).replace("PWAV 1", "PWAV 1\r\nZZZZ 1 2 3")
    with pytest.warns(InteropWarning, match=r"ZZZZ \(line \d+\)"):
        loads_zmx(text)
    res = parse_zmx(text)
    assert any("ZZZZ" in w for w in res.warnings)


def _flint_glass(glas: str) -> str:
    """The Cooke triplet's .zmx with the flint's GLAS line (surface 3) replaced."""
    text = dumps_zmx(load_lens("cooke-triplet-f4"))
    old = "GLAS ___BLANK 1 0 1.61659 36.63 0 0 0 0 0 0"
    assert text.count(old) == 1
    return text.replace(old, glas)


def _zmx_with(surface_line: str, after: str = "  DISZ 6.0") -> str:
    text = dumps_zmx(load_lens("cooke-triplet-f4"))
    assert after in text
    return text.replace(after, after + "\r\n" + surface_line, 1)


@pytest.mark.parametrize(
    ("edit", "needle"),
    [
        (
            lambda t: t.replace("TYPE STANDARD", "TYPE TOROIDAL", 2),
            "STANDARD, EVENASPH and QED_TYPE",
        ),
        (
            lambda t: t.replace("TYPE STANDARD", "TYPE DGRATING", 2),
            "STANDARD, EVENASPH and QED_TYPE",
        ),
        (lambda t: t.replace("TYPE STANDARD", "TYPE GRINSUR1", 2), "gradient-index"),
        (lambda t: t.replace("MODE SEQ", "MODE NSC"), "only sequential"),
        (lambda t: t.replace("FTYP 0", "FTYP 5"), r"Paraxial Image Height \(2\)"),
        (lambda t: t.replace("FNUM 4.0 0", "FNUM 4.0 2"), "unknown aperture flag"),
        (lambda t: _zmx_with("  DECX 0.5"), "Tilt/Decenter tab or as coordinate breaks"),
        (lambda t: _zmx_with("  SCBD 1 1 0 0 1 5 0 0"), "where the order matters"),
    ],
)
def test_unsupported_input_is_refused_with_what_to_do(edit, needle):
    text = edit(dumps_zmx(load_lens("cooke-triplet-f4")))
    with pytest.raises(PrescriptionError, match=needle) as e:
        loads_zmx(text, path="user.zmx")
    assert e.value.path == "user.zmx" and e.value.line is not None
    assert str(e.value).startswith(f"user.zmx:{e.value.line}")


def test_r2_term_of_even_asphere_is_refused():
    text = dumps_zmx(asphere_lens()).replace("PARM 1 0", "PARM 1 0.001", 1)
    with pytest.raises(PrescriptionError, match=r"r² coefficient.*absorb the r² term"):
        loads_zmx(text)


def test_unknown_glass_says_what_to_do():
    text = _flint_glass("GLAS NOSUCHGLASS42 0 0 1.5 40 0 0 0 0 0 0")
    with pytest.raises(PrescriptionError) as e:
        loads_zmx(text, path="u.zmx")
    msg = str(e.value)
    assert "NOSUCHGLASS42" in msg
    if catalog_available():
        assert "unknown glass" in msg and "GLAS ___BLANK 1 0 nd vd" in msg
    else:
        assert "pip install 'orthoscope[glass]'" in msg


def test_ambiguous_glass_lists_candidates_and_gcat_resolves_it():
    # F2 is both Schott F2 (1.62004/36.37) and CDGM F2 (1.61293/36.96) in the vendor catalogs
    text = _flint_glass("GLAS F2 0 0 1.5 40 0 0 0 0 0 0")
    with pytest.raises(PrescriptionError, match="ambiguous glass 'F2'") as e:
        loads_zmx(text)
    assert "Schott F2 (nd 1.62004, vd 36.37)" in str(e.value)
    assert "CDGM F2 (nd 1.61293, vd 36.96)" in str(e.value)
    assert "GCAT" in str(e.value)
    lens = loads_zmx(text.replace("UNIT MM", "GCAT CDGM\r\nUNIT MM"), path="x.zmx")
    m = lens.surfaces[2].material
    assert (m.kind, m.catalog, m.name, m.nd, m.vd) == ("catalog", "CDGM", "F2", 1.61293, 36.96)


def test_model_glass_with_zero_abbe_is_a_fixed_index():
    lens = replace(
        load_lens("cooke-triplet-f4"),
        object_material=fixed_index(1.33),
        object_distance=500.0,
    )
    text = dumps_zmx(lens)
    assert "GLAS ___BLANK 1 0 1.33 0.0" in text
    assert loads_zmx(text) == lens


def test_convert_between_native_and_zmx(tmp_path):
    lens = load_lens("topogon-us2031792-fig1")
    zmx, toml = tmp_path / "t.zmx", tmp_path / "t.toml"
    convert(lens.path, zmx)
    convert(zmx, toml)
    back = load_lens(toml)
    assert back.surfaces == lens.surfaces and back.image_solve == "gaussian"
    with pytest.raises(PrescriptionError, match="can be read, not written"):
        convert(zmx, tmp_path / "t.seq")


def test_field_is_largest_radial_field_of_ftyp_count():
    text = dumps_zmx(load_lens("cooke-triplet-f4"))
    text = text.replace("XFLN 0 0 0", "XFLN 0 0 15").replace("FTYP 0 0 3", "FTYP 0 0 3")
    lens = loads_zmx(text)
    assert lens.field.value == pytest.approx(math.hypot(15.0, 20.0), rel=1e-15)
    # fields beyond the FTYP count are not used
    assert loads_zmx(text.replace("FTYP 0 0 3", "FTYP 0 0 2")).field.value == 14.0


@pytest.mark.parametrize(
    "old,new,words",
    [
        ("DISZ 2", "DISZ 0", "thickness 0 mm"),
        ("GLAS ___BLANK 1 0 1.61659 3.663E+1", "GLAS ___BLANK 1 0 0.5 0", "below 1"),
    ],
)
def test_impossible_lenses_are_refused_as_the_native_format_refuses_them(old, new, words):
    # one validation for every reader (docs/design.md, "Errors and files"): a .zmx file may not
    # hold what a .toml file may not hold
    text = (DATA / "cooke-triplet-f4.zmx").read_text(encoding="utf-8")
    assert old in text
    with pytest.raises(PrescriptionError, match=words):
        loads_zmx(text.replace(old, new, 1))


def test_a_zemax_archive_is_refused_with_what_to_do(tmp_path):
    from raytrace.files import read_lens_file

    p = tmp_path / "lens.zar"
    p.write_bytes(b"\x00ZAR archive bytes")
    with pytest.raises(PrescriptionError, match=r"Zemax archive \(\.zar\).*give the \.zmx") as e:
        read_lens_file(p)
    assert e.value.path == str(p)


def test_ohara_names_with_a_space_are_written_as_opticstudio_spells_them(tmp_path):
    # Ohara's catalog names 39 glasses with a space ("S-LAL 8"); OHARA.AGF and OpticStudio write
    # S-LAL8, and 'GLAS S-LAL 8 ...' read back as the unknown glass "S-LAL" (review 2026-11-27)
    if not catalog_available():
        pytest.skip("glass catalogs not installed")
    from raytrace.glass import resolve_glass

    lens = load_lens("cooke-triplet-f4")
    mat = resolve_glass("S-LAL8", "OHARA").material
    assert mat.name == "S-LAL 8"
    ss = list(lens.surfaces)
    ss[0] = replace(ss[0], material=mat)
    lens = replace(lens, surfaces=tuple(ss))
    text = dumps_zmx(lens)
    assert "GLAS S-LAL8 0 0 1.713 " in text
    assert loads_zmx(text).surfaces[0].material == mat


def test_a_writer_text_that_would_not_read_back_is_not_written(tmp_path, monkeypatch):
    from raytrace.errors import LensError
    from raytrace.files import native, save_lens

    monkeypatch.setattr(native, "dumps", lambda lens: "surfaces = [")  # a broken writer
    out = tmp_path / "x.toml"
    with pytest.raises(LensError, match=r"x\.toml: not written: the file would not read back"):
        save_lens(load_lens("cooke-triplet-f4"), out)
    assert not out.exists()


@pytest.mark.parametrize(
    ("src", "name", "needle"),
    [
        ("cooke-triplet-f4.zmx", "x.seq", "looks like a Zemax .zmx file: give it the suffix .zmx"),
        ("cooke-triplet-f4.seq", "y.zmx", "looks like a CODE V .seq file: give it the suffix .seq"),
        ("cooke-triplet-f4.zmx", "z.txt", "looks like a Zemax .zmx file"),
        ("cooke-triplet-f4.seq", "noext", "looks like a CODE V .seq file"),
        ("corpus/optiland/test_petzval.len", "p.toml", "looks like an OSLO .len file"),
    ],
)
def test_a_file_with_the_wrong_suffix_is_named(tmp_path, src, name, needle):
    # the readers' own errors were about their syntax ("STO must follow a surface line", "TOML
    # syntax error"); the hint names the format the content looks like (review 2026-11-27)
    from raytrace.files import read_lens_file

    p = tmp_path / name
    p.write_bytes((Path(__file__).parent / "data" / src).read_bytes())
    with pytest.raises(PrescriptionError, match=needle):
        read_lens_file(p)
