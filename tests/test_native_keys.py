"""The TOML reader refuses glass keys the medium would ignore, reads catalog names as the .zmx
reader's GCAT does, and refuses a broken [[configurations]] block when the lens is loaded."""

from __future__ import annotations

from pathlib import Path

import pytest

from raytrace.errors import PrescriptionError
from raytrace.files import read_lens_file
from raytrace.files.configurations import read_configurations, read_configured
from raytrace.files.library import load_lens
from raytrace.files.native import loads

LENSES = Path(__file__).resolve().parent.parent / "lenses"

TEMPLATE = """name = "keys"
object = {{ distance = "inf"{obj} }}
aperture = {{ fnumber = 4.0 }}
field = {{ angle = 10.0 }}
surfaces = [
  {{ r = 50.0, t = 5.0, {first} }},
  {{ r = -50.0, t = 40.0, stop = true }},
]
{tail}"""

# Schott N-BK7's Sellmeier coefficients (formula 2), as the catalog gives them
BK7_SELLMEIER = "[1.03961212, 0.00600069867, 0.231792344, 0.0200179144, 1.01046945, 103.560653]"


def _write(tmp_path: Path, first: str, obj: str = "", tail: str = "") -> Path:
    p = tmp_path / "lens.toml"
    p.write_text(TEMPLATE.format(first=first, obj=obj, tail=tail), encoding="utf-8")
    return p


def _refused(path: Path, match: str) -> PrescriptionError:
    with pytest.raises(PrescriptionError, match=match) as e:
        read_lens_file(path)
    msg = str(e.value)
    assert msg.startswith(f"{path}:") and "\n" not in msg  # one line naming the file
    return e.value


# ------------------------------------------------------------------ 1: glass keys without glass


@pytest.mark.parametrize(
    ("first", "match"),
    [
        ('catalog = "Schott"', r"catalog = 'Schott' needs a glass name on the same line"),
        ('model = "cauchy2"', r"model = 'cauchy2' needs a glass name on the same line"),
        (
            f'catalog = "private", formula = 2, coefficients = {BK7_SELLMEIER}',
            r'catalog = .private. needs a glass name on the same line \(e\.g\. glass = "NAME"',
        ),
        ("formula = 2", r"formula = 2 needs a glass name on the same line"),
    ],
    ids=["catalog", "model", "private", "formula"],
)
def test_glass_key_without_glass_is_refused(tmp_path, first, match):
    e = _refused(_write(tmp_path, first), match + r".*without glass the medium is air: add")
    assert e.surface == 1 and e.line == 6


def test_all_stray_keys_are_named(tmp_path):
    first = f'catalog = "private", formula = 2, coefficients = {BK7_SELLMEIER}'
    _refused(_write(tmp_path, first), r"or drop catalog, formula and coefficients$")


def test_object_catalog_without_glass_is_refused(tmp_path):
    p = _write(tmp_path, 'glass = "N-BK7"', obj=', catalog = "Schott"')
    e = _refused(p, r"catalog = 'Schott' needs a glass name in \[object\]")
    assert e.line == 2


# ------------------------------------------------- 2: keys the medium written would ignore


@pytest.mark.parametrize(
    ("first", "match"),
    [
        (
            'glass = "1.5168/64.17", catalog = "Schott"',
            r"catalog does not apply to the model glass '1\.5168/64\.17' \(nd/vd\): drop it, or "
            r"give the catalog glass by name",
        ),
        (
            f'glass = "1.5168/64.17", formula = 2, coefficients = {BK7_SELLMEIER}',
            r"formula and coefficients do not apply to the model glass .*drop them, or define "
            r'the glass by name: glass = "NAME", catalog = "private"',
        ),
        (
            'glass = "1.5168/64.17", model = "cauchy2", range_nm = [400, 700]',
            r"range_nm does not apply to the model glass",
        ),
        ('glass = "air", catalog = "Schott"', r'catalog does not apply to glass = "air": drop it'),
        ('glass = "AIR", model = "cauchy2"', r'model does not apply to glass = "air"'),
        ('n = 1.5, catalog = "Schott"', r"catalog does not apply to a fixed index n = 1\.5"),
        ('n = 1.5, model = "cauchy2"', r"model does not apply to a fixed index n = 1\.5"),
        ("n = 1.5, range_nm = [400, 700]", r"range_nm does not apply to a fixed index"),
    ],
    ids=[
        "ndvd-catalog",
        "ndvd-private",
        "ndvd-range",
        "air-catalog",
        "air-model",
        "n-catalog",
        "n-model",
        "n-range",
    ],
)
def test_ignored_glass_key_is_refused(tmp_path, first, match):
    assert _refused(_write(tmp_path, first), match).surface == 1


def test_object_key_beside_fixed_index_is_refused(tmp_path):
    p = _write(tmp_path, 'glass = "N-BK7"', obj=', n = 1.333, model = "cauchy2"')
    _refused(p, r"model does not apply to a fixed index n = 1\.333")


def test_keys_that_mean_something_still_read(tmp_path):
    # model picks an nd/vd glass's dispersion law; a private glass takes formula + coefficients
    # (+ range_nm) with its name
    lens = read_lens_file(_write(tmp_path, 'glass = "1.5168/64.17", model = "cauchy2"'))
    assert lens.surfaces[0].material.kind == "model"
    p = _write(
        tmp_path,
        f'glass = "MY-BK7", catalog = "private", formula = 2, coefficients = {BK7_SELLMEIER}, '
        "range_nm = [300, 2500]",
    )
    m = read_lens_file(p).surfaces[0].material
    assert (m.name, m.catalog) == ("MY-BK7", "private")
    p = _write(tmp_path, 'glass = "N-BK7"', obj=', glass = "1.5168/64.17", model = "cauchy2"')
    assert read_lens_file(p).object_material.kind == "model"


# ------------------------------------------------------------ 3: catalog names as GCAT reads them


@pytest.mark.parametrize("catalog", ["schott_2017", "SCHOTT", "Schott", "SCHOTT_2017"])
def test_catalog_names_the_zmx_reader_accepts(tmp_path, catalog):
    lens = read_lens_file(_write(tmp_path, f'glass = "N-BK7", catalog = "{catalog}"'))
    plain = read_lens_file(_write(tmp_path, 'glass = "N-BK7", catalog = "Schott"'))
    assert lens.surfaces[0].material == plain.surfaces[0].material
    assert lens.surfaces[0].material.catalog == "Schott"


def test_unknown_catalog_names_the_accepted_spellings(tmp_path):
    _refused(
        _write(tmp_path, 'glass = "N-BK7", catalog = "Foo"'),
        r"unknown catalog 'Foo': the shipped catalogs are Schott, Ohara, .*SCHOTT_2017.*private",
    )


def test_glass_outside_the_named_catalog_is_refused(tmp_path):
    _refused(
        _write(tmp_path, 'glass = "N-BK7", catalog = "ohara_2020"'),
        r"glass 'N-BK7' is not in the Ohara catalog \(found in Schott\): give "
        r'catalog = "Schott"',
    )


# ------------------------------------------------------- 4: a broken [[configurations]] block

CFG = '[[configurations]]\nname = "near"\nthickness = {{ {th} }}\n'


@pytest.mark.parametrize(
    ("tail", "match", "line"),
    [
        ("configurations = 3", r"configurations must be an array of tables", 9),
        ('[configurations]\nname = "a"\n', r"configurations must be an array of tables", 9),
        (
            CFG.format(th="0 = 1000.0") + CFG.format(th="9 = 3.0"),
            r"configuration 'near' changes the thickness of surface 9, but the lens has surfaces "
            r"1–2",
            12,
        ),
        ('[[configurations]]\nnam = "a"\n', r"configuration 1: unknown key\(s\) nam", 9),
        (CFG.format(th="x = 1.0"), r"thickness key 'x' is not a surface number", 9),
    ],
    ids=["not-tables", "one-table", "no-such-surface", "unknown-key", "bad-surface-key"],
)
def test_broken_configurations_are_refused_on_loading(tmp_path, tail, match, line):
    p = _write(tmp_path, 'glass = "N-BK7"', tail=tail)
    e = _refused(p, match)
    assert e.line == line
    with pytest.raises(PrescriptionError) as e2:
        load_lens(p)
    assert str(e2.value) == str(e)
    with pytest.raises(PrescriptionError) as e3:
        read_configured(p)
    assert str(e3.value) == str(e)  # the same one line read_configured gives


def test_good_configurations_still_read(tmp_path):
    p = _write(tmp_path, 'glass = "N-BK7"', tail=CFG.format(th='0 = "inf", 2 = 39.0'))
    lens, confs = read_configured(p)
    assert read_lens_file(p) == lens and confs.configurations[0].thickness(2) == 39.0
    lens, confs = read_configured(LENSES / "tessar-fr1066698-inner-focus.toml")
    assert len(confs) == 5


def test_scale_to_efl_scales_the_configurations(tmp_path):
    # scale_to_efl scales the block's lengths with the lens ("inf" stays); the lens-less reader
    # (read_configurations) builds the lens for the factor and gives the same numbers
    tail = (
        "scale_to_efl = 100.0\n"
        + CFG.format(th="0 = 1000.0, 2 = 39.0")
        + CFG.format(th='0 = "inf"')
    )
    p = _write(tmp_path, 'glass = "N-BK7"', tail=tail)
    lens, confs = read_configured(p)
    factor = lens.surfaces[1].thickness / 40.0  # surface 2's t = 40.0 in the file
    assert factor != pytest.approx(1.0)
    near, far = confs.configurations
    assert near.thickness(2) == pytest.approx(39.0 * factor, rel=1e-15)
    assert near.object_distance == pytest.approx(1000.0 * factor, rel=1e-15)
    assert far.object_distance == float("inf")
    assert read_configurations(p).configurations == confs.configurations


def test_broken_configurations_of_a_scaled_lens_are_refused_the_same_way(tmp_path):
    tail = "scale_to_efl = 100.0\n" + CFG.format(th="0 = 1000.0") + CFG.format(th="9 = 3.0")
    p = _write(tmp_path, 'glass = "N-BK7"', tail=tail)
    e = _refused(p, r"configuration 'near' changes the thickness of surface 9")
    assert e.line == 13
    for read in (read_configured, read_configurations):
        with pytest.raises(PrescriptionError) as e2:
            read(p)
        assert str(e2.value) == str(e)


def test_every_bundled_lens_still_loads():
    files = sorted(LENSES.glob("*.toml")) + sorted((LENSES / "specs").glob("*-start.toml"))
    assert len(files) >= 10
    for p in files:
        assert read_lens_file(p).surfaces, p


def test_loads_without_a_path_names_no_file():
    text = TEMPLATE.format(first='catalog = "Schott"', obj="", tail="")
    with pytest.raises(PrescriptionError, match=r"^line 6, surface 1: catalog = 'Schott' needs"):
        loads(text)
